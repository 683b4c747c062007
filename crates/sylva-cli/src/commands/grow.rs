//! `sylva grow`: one genome into a 3D asset (and a picture).

use std::path::PathBuf;

use sylva::assets::{asset_format, check_png, picture};
use sylva::files::Outputs;
use sylva::{Grown, load_genome};
use sylva_mesh::render::View;

use super::InFile;

/// Arguments of `sylva grow`.
#[derive(clap::Args)]
pub struct GrowArgs {
    /// Genome JSON.
    genome: PathBuf,
    /// Output asset.
    #[arg(short, long)]
    output: PathBuf,
    /// Also render a picture.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Seed for the model's random choices [default: the genome's own seed for
    /// PlantMaker genomes, 0 otherwise].
    #[arg(long)]
    seed: Option<u64>,
    /// Thicken the branches by the pipe model, radius ∝ (tips above)^(1/E), E from 2 to 3
    /// (off by default: each model's own radii).
    #[arg(long, value_name = "E", value_parser = super::parse_taper)]
    taper: Option<sylva_core::taper::PipeTaper>,
    /// Leave the roots out.
    #[arg(long)]
    hide_roots: bool,
}

/// `sylva grow`.
pub fn run(args: &GrowArgs) -> anyhow::Result<()> {
    asset_format(&args.output)?;
    if let Some(png) = &args.png {
        check_png(png)?;
    }
    let genome = load_genome(&args.genome)?;
    let seed = args.seed.unwrap_or_else(|| genome.default_seed());
    let grown =
        Grown::with_taper(genome, seed, !args.hide_roots, args.taper).in_file(&args.genome)?;
    let mut out = Outputs::new();
    out.add_scene(&args.output, &grown.scene())
        .in_file(&args.genome)?;
    if let Some(png) = &args.png {
        out.add(png, &picture(&grown.scene(), View::Iso, (800, 800))?)?;
    }
    out.commit()?;
    println!(
        "wrote {}: {} segments, {} organs, {} vertices, {} triangles",
        args.output.display(),
        grown.plant.segments().len(),
        grown.plant.organs().len(),
        grown.mesh.vertex_count(),
        grown.mesh.triangle_count()
    );
    Ok(())
}
