//! `sylva render`: a genome (grown first) or a GLB (read as it is) to a picture.

use std::path::PathBuf;

use sylva::assets::{check_png, write_picture};
use sylva::render::View;
use sylva::{GrowOptions, Grown, InputError, Registry};

use super::InFile;

/// Largest GLB read: 1 GiB.
const MAX_GLB: u64 = 1 << 30;

/// Arguments of `sylva render`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Genome JSON, species preset (.toml) or GLB.
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
    taper: Option<sylva::core::taper::PipeTaper>,
    /// Leave the roots out (genomes only).
    #[arg(long)]
    hide_roots: bool,
    /// With `--wind` (genomes only): a strip of N frames (2 to 32) of the wind clip, side by
    /// side, each the plant posed at an even step through one period, as a glTF viewer
    /// skins it.
    #[arg(long, value_name = "N", requires = "wind", value_parser = clap::value_parser!(u32).range(2..=32))]
    wind_frames: Option<u32>,
    /// Levels of detail (genomes only): a strip of the N levels (2 to 8) side by side, each
    /// captioned with its triangles, as `sylva grow --lod N` writes them. The size is one
    /// level's picture.
    #[arg(long, value_name = "N", conflicts_with = "wind_frames", value_parser = clap::value_parser!(u32).range(2..=8))]
    lod: Option<u32>,
    /// Scale the plant so that its highest point stands this many metres above the
    /// ground, 0.01 to 1000 (genomes only) [default: the model's own scale].
    #[arg(long, value_name = "METRES", value_parser = super::parse_height)]
    height: Option<f32>,
    #[command(flatten)]
    dress: super::DressArgs,
    #[command(flatten)]
    wind: super::WindArgs,
}

/// How `sylva render` grows a genome (or a preset's): its seed, roots, taper, height and
/// dress flags over what the file gave.
fn grow_options(args: &RenderArgs, base: GrowOptions) -> GrowOptions {
    super::GrowFlags {
        seed: args.seed,
        hide_roots: args.hide_roots,
        taper: args.taper,
        height: args.height,
        dress: &args.dress,
    }
    .over(base)
}

/// `sylva render`.
pub fn run(models: &Registry, args: &RenderArgs) -> anyhow::Result<()> {
    check_png(&args.output)?;
    let is_glb = args
        .file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if let Some(levels) = args.lod {
        if is_glb {
            return Err(InputError::new(
                "--lod",
                "levels of detail are drawn from a genome, not a GLB",
            )
            .into());
        }
        let (genome, base) = super::load_input(models, &args.file)?;
        let options = GrowOptions {
            lod: Some(levels as usize),
            ..grow_options(args, base)
        };
        let growing = super::growing(&genome);
        let grown = Grown::grow(genome, &options).in_file(&args.file)?;
        drop(growing);
        let chain = sylva::LodAssets::new(grown, &options).in_file(&args.file)?;
        let png = lod_strip(&chain, args.view, args.size)?;
        sylva::files::write(&args.output, &png)?;
    } else if let Some(frames) = args.wind_frames {
        if is_glb {
            return Err(InputError::new(
                "--wind-frames",
                "wind frames are drawn from a genome (the GLB reader takes the rest pose)",
            )
            .into());
        }
        let (genome, base) = super::load_input(models, &args.file)?;
        let options = GrowOptions {
            wind: args.wind.options(&args.output)?,
            ..grow_options(args, base)
        };
        let growing = super::growing(&genome);
        let grown = Grown::grow(genome, &options).in_file(&args.file)?;
        drop(growing);
        let png = wind_strip(&grown, frames as usize, args.view, args.size)?;
        sylva::files::write(&args.output, &png)?;
    } else if is_glb {
        for (given, flag) in [
            (args.dress.foliage.is_some(), "--foliage"),
            (args.dress.bark.is_some(), "--bark"),
            (args.height.is_some(), "--height"),
        ] {
            if given {
                return Err(InputError::new(
                    flag,
                    "a GLB is drawn as it is; grow the genome with this flag instead",
                )
                .into());
            }
        }
        let bytes = sylva::files::read_bytes(&args.file, MAX_GLB)?;
        let imported =
            sylva::import::read_glb(&bytes).map_err(|e| InputError::file_error(&args.file, &e))?;
        write_picture(&imported.scene(), &args.output, args.view, args.size)?;
    } else {
        let (genome, base) = super::load_input(models, &args.file)?;
        let growing = super::growing(&genome);
        let grown = Grown::grow(genome, &grow_options(args, base)).in_file(&args.file)?;
        drop(growing);
        write_picture(&grown.scene(), &args.output, args.view, args.size)?;
    }
    println!("wrote {}", args.output.display());
    Ok(())
}

/// The levels of `chain` side by side, each captioned with its triangle count.
fn lod_strip(
    chain: &sylva::LodAssets,
    view: View,
    (width, height): (u32, u32),
) -> anyhow::Result<Vec<u8>> {
    use sylva::render::{self, SheetCell, SheetOptions};
    let cells: Vec<SheetCell> = (0..chain.len())
        .map(|k| SheetCell {
            scene: chain.level_scene(k, "plant"),
            caption: format!(
                "LOD{k}  {} triangles{}",
                chain.mesh(k).triangle_count(),
                if k < chain.levels.len() {
                    ""
                } else {
                    " (impostor)"
                }
            ),
        })
        .collect();
    let options = SheetOptions {
        columns: cells.len() as u32,
        cell_width: width,
        cell_height: height + render::CAPTION_HEIGHT,
        view,
        title: None,
    };
    let image = render::contact_sheet(&cells, &options, &sylva::core::par::Pool::Serial)
        .map_err(sylva::Error::from)?;
    Ok(render::encode_png(&image).map_err(sylva::Error::from)?)
}

/// The plant posed at `frames` even steps through its wind clip, side by side along +X.
fn wind_strip(
    grown: &Grown,
    frames: usize,
    view: View,
    size: (u32, u32),
) -> Result<Vec<u8>, sylva::Error> {
    let Some(rig) = &grown.rig else {
        return sylva::assets::picture(&grown.scene(), view, size);
    };
    let period = rig.times.last().copied().unwrap_or(0.0);
    let posed: Vec<_> = (0..frames)
        .map(|k| rig.pose(&grown.mesh, period * k as f32 / frames as f32))
        .collect();
    let bounds =
        sylva::mesh::Scene::single(sylva::mesh::SceneNode::new("plant", &grown.mesh)).bounds();
    let step = 1.15 * (bounds.max.x - bounds.min.x).max(0.25 * (bounds.max.y - bounds.min.y));
    let nodes = posed
        .iter()
        .enumerate()
        .map(|(k, mesh)| {
            let mut node = sylva::mesh::SceneNode::new(format!("frame-{k}"), mesh);
            node.translation = sylva::core::glam::Vec3::X * (k as f32 * step);
            node
        })
        .collect();
    sylva::assets::picture(&sylva::mesh::Scene { nodes }, view, size)
}
