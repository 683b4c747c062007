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
    give_back_freed_memory();
    sylva_studio::serve(sylva_studio::Options {
        host: args.host.clone(),
        port: args.port,
        db: args.db.clone(),
        allow_hosts: args.allow_hosts.clone(),
        registry: models,
    })?;
    Ok(())
}

/// Has glibc's allocator give back what the studio frees. By default glibc raises the size
/// above which it maps a block apart (up to 32 MB) each time it frees a large one, and then
/// keeps up to twice that unused in each of its arenas (one per thread, up to 16 here): the
/// studio, which makes and drops plants and meshes of megabytes on many threads, held
/// 1.2 GB after the browser test's session and about 300 MB with these fixed thresholds
/// (docs/studio.md, "Memory"). Batch commands keep the defaults, which suit them.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
fn give_back_freed_memory() {
    // SAFETY: `mallopt` only sets the allocator's parameters; it is called before the
    // studio starts its threads, and any value is valid (a refusal leaves the defaults).
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 4 << 20);
    }
}

/// Other allocators than glibc's keep their own defaults.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn give_back_freed_memory() {}
