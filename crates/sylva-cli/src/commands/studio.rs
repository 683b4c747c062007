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
    /// Where three.js is installed [default: the studio crate's web/node_modules/three].
    #[arg(long)]
    three: Option<PathBuf>,
}

/// `sylva studio`.
pub fn run(args: &StudioArgs) -> anyhow::Result<()> {
    let defaults = sylva_studio::Options::default();
    sylva_studio::serve(sylva_studio::Options {
        host: args.host.clone(),
        port: args.port,
        db: args.db.clone(),
        three: args.three.clone().unwrap_or(defaults.three),
    })?;
    Ok(())
}
