//! `sylva garden`: many PlantMaker plants on one plot, in one scene, with the garden file
//! that grows the same scene again.

use std::path::PathBuf;

use sylva::assets::{SceneAssets, check_png, picture};
use sylva::export::Format;
use sylva::files::{Outputs, read_text};
use sylva::garden::{
    GardenLayout, GardenNodes, PlanError, check_garden, garden_glb, garden_glb_options,
    garden_placed, garden_placements, grow_garden,
};
use sylva::render::View;
use sylva::{Genome, InputError, Registry};

use super::{InFile, SCENE_PICTURE};

/// Arguments of `sylva garden`.
#[derive(clap::Args)]
pub struct GardenArgs {
    /// PlantMaker genome files, or one garden file (`*.garden.json`).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Plants per genome.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    count: u32,
    /// Plot size in metres, WIDTHxDEPTH, centred on the origin.
    #[arg(long, default_value = "20x20", value_parser = super::parse_area)]
    area: (f64, f64),
    /// Seed of the plants' seeds, positions and turns.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output scene (.glb, .obj, .wrl or .stl).
    #[arg(short, long)]
    output: PathBuf,
    /// Also render a picture.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Grow K seeds of each genome and make every plant one of them, so the scene holds a
    /// few meshes placed many times (1 to 1000; recorded in the garden file).
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(1..=1000))]
    variants: Option<u32>,
    /// With --variants: write each plant as a plain node sharing its variant's mesh, rather
    /// than one node per variant with EXT_mesh_gpu_instancing (recorded in the garden file).
    #[arg(long)]
    no_instancing: bool,
    #[command(flatten)]
    quantize: super::QuantizeArgs,
    #[command(flatten)]
    wind: super::WindArgs,
}

/// `sylva garden`: grows a garden file, or plants genomes into a new one, and writes the
/// scene (one node per plant, or per variant when instanced, each carrying its genome and
/// seed) and the garden file.
pub fn run(models: &Registry, args: &GardenArgs) -> anyhow::Result<()> {
    let format = sylva::export::format(&args.output)?;
    let wind = args.wind.options(&args.output)?;
    let quantize = args.quantize.check(&args.output, wind.is_some())?;
    if let Some(png) = &args.png {
        check_png(png)?;
    }
    let first = &args.inputs[0];
    let text = read_text(first)?;
    let is_garden = sylva::garden::is_garden_file(models, &text);
    let mut garden = if is_garden {
        if args.inputs.len() > 1 {
            return Err(InputError::file(
                first,
                "a garden file is grown on its own; give either one garden file or genome files",
            )
            .into());
        }
        if args.variants.is_some() {
            return Err(InputError::new(
                "--variants",
                "a garden file keeps the variants it was planted with; give genome files to plant a new garden",
            )
            .into());
        }
        sylva::garden::read(models, first, &text)?
    } else {
        // The first file is already read.
        let mut genomes: Vec<Genome> = vec![models.parse_genome_at(first, &text)?];
        for path in &args.inputs[1..] {
            genomes.push(models.load_genome(path)?);
        }
        let area = [args.area.0, args.area.1];
        let mut garden =
            sylva::garden::plant(models, &genomes, args.count as usize, area, args.seed).map_err(
                |e| match e {
                    PlanError::WrongModel { index, .. } => InputError::file(&args.inputs[index], e),
                    PlanError::NoGenomes => InputError::new("inputs", e),
                },
            )?;
        garden.set_variants(args.variants);
        garden
    };
    // The layout flags are recorded in a new garden file, and add to what a garden file says.
    if args.no_instancing {
        if garden.variants().is_none() {
            return Err(InputError::new(
                "--no-instancing",
                "only forests of variants are instanced; add --variants K, or leave the flag out",
            )
            .into());
        }
        garden.set_instancing(Some(false));
    }
    garden.set_quantize(garden.quantize() || quantize);
    if garden.quantize() && wind.is_some() {
        return Err(InputError::new(
            "--wind",
            format!(
                "{} asks for quantised positions (\"quantize\": true), which wind GLBs cannot have",
                first.display()
            ),
        )
        .into());
    }
    let options = garden_glb_options(&garden);
    let mut out = Outputs::new();
    // (plants, distinct plants meshed, triangles, picture)
    let streamed = format == Format::Glb && wind.is_none() && args.png.is_none();
    // Estimated from the first plant of each genome, before the others grow.
    let layout = match streamed {
        true => GardenLayout::Streamed,
        false => GardenLayout::Held,
    };
    check_garden(&garden, first, layout, format == Format::Glb, &options)?;
    let (plants, meshes, triangles, png) = if streamed {
        // Grown, meshed and dropped one plant at a time as the GLB streams out: memory
        // holds the placements, the JSON and one plant with its mesh, not the scene.
        let placements = garden_placements(&garden, first)?;
        let nodes = GardenNodes::of(&garden, &placements);
        let mut glb = garden_glb(&garden, &placements, &nodes, options).in_file(first)?;
        out.add_glb(&args.output, &mut glb)?;
        let meshes = placements.iter().map(|p| p.plant + 1).max().unwrap_or(0);
        (
            placements.len(),
            meshes,
            glb.stats().triangles as usize,
            None,
        )
    } else {
        let grown = grow_garden(&garden, first)?;
        let placed = garden_placed(&garden, &grown);
        let assets = SceneAssets::mesh(&placed, wind).in_file(first)?;
        let scene = assets.scene();
        out.add_scene_with(&args.output, &scene, &options)
            .in_file(first)?;
        let png = match &args.png {
            Some(path) => Some((path, picture(&scene, View::Iso, SCENE_PICTURE)?)),
            None => None,
        };
        (
            placed.len(),
            grown.plants.len(),
            scene.triangle_count(),
            png,
        )
    };
    let garden_path = args.output.with_extension("garden.json");
    if !is_garden {
        out.add(&garden_path, garden.to_json().as_bytes())?;
    }
    if let Some((path, bytes)) = png {
        out.add(path, &bytes)?;
    }
    out.commit()?;
    if !is_garden {
        println!("wrote {}", garden_path.display());
    }
    println!(
        "wrote {}: {plants} plants ({meshes} meshes), {triangles} triangles",
        args.output.display(),
    );
    Ok(())
}
