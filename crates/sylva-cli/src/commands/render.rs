//! `sylva render`: a genome (grown first) or a GLB (read as it is) to a picture.

use std::path::PathBuf;

use sylva::assets::{check_png, write_picture};
use sylva::{Grown, InputError, load_genome};
use sylva_mesh::render::View;

use super::InFile;

/// Largest GLB read: 1 GiB.
const MAX_GLB: u64 = 1 << 30;

/// Arguments of `sylva render`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Genome JSON or GLB.
    file: PathBuf,
    /// Output PNG.
    #[arg(short, long)]
    output: PathBuf,
    /// Camera.
    #[arg(long, default_value = "iso")]
    view: View,
    /// Picture size, WIDTHxHEIGHT.
    #[arg(long, default_value = "800x800", value_parser = super::parse_size)]
    size: (u32, u32),
    /// Seed for the model's random choices (genomes only) [default: the genome's own
    /// seed for PlantMaker genomes, 0 otherwise].
    #[arg(long)]
    seed: Option<u64>,
    /// Thicken the branches by the pipe model, radius ∝ (tips above)^(1/E), E from 2 to 3
    /// (off by default: each model's own radii).
    #[arg(long, value_name = "E", value_parser = super::parse_taper)]
    taper: Option<sylva_core::taper::PipeTaper>,
    /// Leave the roots out (genomes only).
    #[arg(long)]
    hide_roots: bool,
}

/// `sylva render`.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    check_png(&args.output)?;
    let is_glb = args
        .file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if is_glb {
        let bytes = sylva::files::read_bytes(&args.file, MAX_GLB)?;
        let imported = sylva_mesh::import::read_glb(&bytes)
            .map_err(|e| InputError::file_error(&args.file, &e))?;
        write_picture(&imported.scene(), &args.output, args.view, args.size)?;
    } else {
        let genome = load_genome(&args.file)?;
        let seed = args.seed.unwrap_or_else(|| genome.default_seed());
        let grown =
            Grown::with_taper(genome, seed, !args.hide_roots, args.taper).in_file(&args.file)?;
        write_picture(&grown.scene(), &args.output, args.view, args.size)?;
    }
    println!("wrote {}", args.output.display());
    Ok(())
}
