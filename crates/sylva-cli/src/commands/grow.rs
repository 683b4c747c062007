//! `sylva grow`: one genome into a 3D asset (and a picture).

use std::path::PathBuf;
use std::sync::Arc;

use sylva::assets::{check_png, picture};
use sylva::evolution::outline::Outline;
use sylva::files::Outputs;
use sylva::render::View;
use sylva::skeleton::{GrowOutput, Skeleton};
use sylva::{Genome, GrowOptions, Grown, InputError, LodAssets, Registry};

use super::InFile;

/// Arguments of `sylva grow`.
#[derive(clap::Args)]
pub struct GrowArgs {
    /// Genome JSON, or a species preset (.toml: a genome and how to grow it; the flags
    /// below override it).
    genome: PathBuf,
    /// Output: a 3D asset (.glb, .obj, .wrl, .stl), or the skeleton as data (.skeleton.json).
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
    taper: Option<sylva::core::taper::PipeTaper>,
    /// Leave the roots out.
    #[arg(long)]
    hide_roots: bool,
    /// Levels of detail, 2 to 8 (GLB only): writes NAME_LOD0.glb … beside the output, each
    /// at about half the triangles of the one before, then NAME_LOD{N}.glb, an impostor
    /// (crossed cards showing the plant's picture), and the output as one scene with every
    /// level as a sibling node (NAME_LOD0, …) carrying its screen coverage.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=8))]
    lod: Option<u32>,
    /// Scale the plant so that its highest point stands this many metres above the
    /// ground, 0.01 to 1000 [default: the model's own scale].
    #[arg(long, value_name = "METRES", value_parser = super::parse_height)]
    height: Option<f32>,
    /// Grow the plant inside a match's outlines, pruned as that run's files were: the run's
    /// `config.toml` (`sylva match` writes one; docs/match.md) [default: the whole plant].
    #[arg(long, value_name = "CONFIG")]
    pruned_to: Option<PathBuf>,
    #[command(flatten)]
    dress: super::DressArgs,
    #[command(flatten)]
    wind: super::WindArgs,
    #[command(flatten)]
    quantize: super::QuantizeArgs,
}

/// `sylva grow`.
pub fn run(models: &Registry, args: &GrowArgs) -> anyhow::Result<()> {
    let output = GrowOutput::of(&args.output)?;
    let wind = args.wind.options(&args.output)?;
    let (genome, base) = super::load_input(models, &args.genome)?;
    let flags = super::GrowFlags {
        seed: args.seed,
        hide_roots: args.hide_roots,
        taper: args.taper,
        height: args.height,
        dress: &args.dress,
    };
    let options = GrowOptions {
        quantize: args.quantize.check(&args.output, wind.is_some())?,
        lod: args.lod.map(|n| n as usize),
        wind,
        pruned_to: match &args.pruned_to {
            Some(path) => Some(outlines_of(models, path)?),
            None => None,
        },
        ..flags.over(base)
    };
    let glb = options.glb_options();
    if args.lod.is_some() && output != GrowOutput::Asset(sylva::export::Format::Glb) {
        return Err(InputError::new(
            "--lod",
            "levels of detail are written as GLB files: give an output ending in .glb",
        )
        .into());
    }
    if let Some(png) = &args.png {
        check_png(png)?;
    }
    if output == GrowOutput::Skeleton {
        return skeleton(args, &genome, &options);
    }
    let growing = super::growing(&genome);
    let grown = Grown::grow(genome, &options).in_file(&args.genome)?;
    drop(growing);
    if options.lod.is_some() {
        return lod(args, grown, &options);
    }
    let mut out = Outputs::new();
    out.add_scene_with(&args.output, &grown.scene(), &glb)
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
    let (dress, dressed) = grown.dress;
    if let Some(kind) = dress.foliage {
        println!(
            "foliage: {} {kind} cards{}{}",
            dressed.cards,
            if dressed.leaves_replaced > 0 {
                format!(
                    " in place of the plant's {} leaves",
                    dressed.leaves_replaced
                )
            } else {
                " on its last twigs".to_owned()
            },
            if dressed.dropped > 0 {
                format!(
                    " ({} more left out: at most {} cards)",
                    dressed.dropped, dressed.most
                )
            } else {
                String::new()
            }
        );
    }
    if let Some(rig) = &grown.rig {
        println!(
            "wind: {} joints, clip `wind` of {} s{}",
            rig.joints.len(),
            rig.times.last().copied().unwrap_or(0.0),
            if rig.dropped > 0 {
                format!(
                    " ({} finer joints left out: at most {})",
                    rig.dropped,
                    sylva::mesh::wind::MAX_JOINTS
                )
            } else {
                String::new()
            }
        );
    }
    Ok(())
}

/// The outlines the match run of config `path` prunes its plants to.
fn outlines_of(models: &Registry, path: &std::path::Path) -> anyhow::Result<Arc<[Outline]>> {
    let options = models.load_config(path)?.grow_options()?;
    let outlines = options.pruned_to.ok_or_else(|| {
        InputError::file(
            path,
            "expected the config of a match that prunes its plants: it has no `[match]` \
             section, or no `topiary = true`",
        )
    })?;
    Ok(outlines)
}

/// `sylva grow --lod N`: NAME_LOD0.glb … beside the output, and the output as one scene of
/// every level.
fn lod(args: &GrowArgs, grown: Grown, options: &GrowOptions) -> anyhow::Result<()> {
    let glb = &options.glb_options();
    let (segments, organs) = (grown.plant.segments().len(), grown.plant.organs().len());
    let chain = LodAssets::new(grown, options).in_file(&args.genome)?;
    let name = args
        .output
        .file_stem()
        .map_or("plant".into(), |s| s.to_string_lossy().into_owned());
    let mut out = Outputs::new();
    let mut files = Vec::new();
    for k in 0..chain.len() {
        let path = args.output.with_file_name(format!("{name}_LOD{k}.glb"));
        out.add_scene_with(&path, &chain.level_scene(k, &name), glb)
            .in_file(&args.genome)?;
        files.push(path);
    }
    out.add_scene_with(&args.output, &chain.group_scene(&name), glb)
        .in_file(&args.genome)?;
    if let Some(png) = &args.png {
        out.add(
            png,
            &picture(&chain.level_scene(0, &name), View::Iso, (800, 800))?,
        )?;
    }
    out.commit()?;
    println!(
        "wrote {} ({} levels of detail as sibling nodes, the last an impostor): {segments} \
         segments, {organs} organs",
        args.output.display(),
        chain.len()
    );
    let full = chain.levels[0].mesh.triangle_count().max(1) as f64;
    for (k, path) in files.iter().enumerate() {
        let triangles = chain.mesh(k).triangle_count();
        let (coverage, note) = match (chain.levels.get(k), &chain.impostor) {
            (Some(asset), _) => (asset.level.screen_coverage, String::new()),
            (None, Some(impostor)) => {
                let bytes = impostor.mesh.impostor.as_ref().map_or(0, |png| png.len());
                let note = format!(": crossed cards, a {} kB picture", bytes.div_ceil(1000));
                (impostor.screen_coverage, note)
            }
            (None, None) => continue,
        };
        println!(
            "  {}: {triangles} triangles ({:.1}% of LOD0{note}), drawn down to {:.1}% of the \
             screen's height",
            path.display(),
            100.0 * triangles as f64 / full,
            100.0 * coverage
        );
    }
    Ok(())
}

/// `sylva grow -o PLANT.skeleton.json`: the plant as data, unmeshed unless a picture is
/// asked for too.
fn skeleton(args: &GrowArgs, genome: &Genome, options: &GrowOptions) -> anyhow::Result<()> {
    let roots = options.roots;
    let growing = super::growing(genome);
    let (skeleton, png) = match &args.png {
        None => {
            // Grown, pruned, tapered, scaled and dressed as a mesh would be, unmeshed.
            let (_, plant) = Grown::plant(genome, options).in_file(&args.genome)?;
            sylva::skeleton::check_budget(&plant).in_file(&args.genome)?;
            (Skeleton::of(&plant, genome, options.taper, roots), None)
        }
        Some(png) => {
            let plain = GrowOptions {
                wind: None,
                ..options.clone()
            };
            let grown = Grown::grow(genome.clone(), &plain).in_file(&args.genome)?;
            sylva::skeleton::check_budget(&grown.plant).in_file(&args.genome)?;
            let picture = picture(&grown.scene(), View::Iso, (800, 800))?;
            (Skeleton::of_grown(&grown), Some((png, picture)))
        }
    };
    drop(growing);
    let mut out = Outputs::new();
    out.add(&args.output, skeleton.to_json().as_bytes())?;
    if let Some((path, bytes)) = png {
        out.add(path, &bytes)?;
    }
    out.commit()?;
    println!(
        "wrote {}: {} segments, {} organs",
        args.output.display(),
        skeleton.segments.len(),
        skeleton.organs.len()
    );
    Ok(())
}
