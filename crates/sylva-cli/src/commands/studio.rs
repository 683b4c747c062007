//! `sylva studio`: the web studio, where a person breeds plants by eye.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `sylva studio`.
#[derive(Args)]
pub struct StudioArgs {
    /// The port to listen on (0 picks a free one).
    #[arg(long, default_value_t = 8417)]
    port: u16,
    /// The address to bind. Any address but loopback needs the access token printed at start.
    #[arg(long, default_value = "127.0.0.1")]
    host: String,
    /// The archive: every plant, step and run, in SQLite.
    #[arg(long, default_value = "sylva-studio.db")]
    db: PathBuf,
    /// A host name the studio answers to besides loopback and the bound address, such as a
    /// reverse proxy's (repeatable). Requests naming any other host get 403.
    #[arg(long = "allow-host", value_name = "NAME")]
    allow_hosts: Vec<String>,
}

/// `sylva studio`.
pub fn run(models: sylva::Registry, args: &StudioArgs) -> anyhow::Result<()> {
    sylva_studio::serve(sylva_studio::Options {
        host: args.host.clone(),
        port: args.port,
        db: args.db.clone(),
        allow_hosts: args.allow_hosts.clone(),
        registry: models,
    })?;
    Ok(())
}
