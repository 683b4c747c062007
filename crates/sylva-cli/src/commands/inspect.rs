//! `sylva inspect`: how a plant measures against real trees (a plausibility report).

use std::path::{Path, PathBuf};

use sylva::inspect::{AssetFacts, Report};
use sylva::skeleton::{SUFFIX, Skeleton};
use sylva::{Grown, InputError, Registry};

use super::InFile;

/// Largest GLB read: 1 GiB.
const MAX_GLB: u64 = 1 << 30;

/// Arguments of `sylva inspect`.
#[derive(clap::Args)]
pub struct InspectArgs {
    /// The plant: a genome (.json) or species preset (.toml), grown with the flags below; a
    /// GLB Sylva wrote (grown again from the genome in its extras); or a skeleton file
    /// (.skeleton.json, any generator's).
    file: PathBuf,
    /// The asset to weigh (triangles, texture bytes) when FILE is a skeleton [default: a
    /// genome's own mesh, a GLB itself].
    #[arg(long, value_name = "GLB")]
    asset: Option<PathBuf>,
    /// Exit 1 when a figure is implausible, naming each.
    #[arg(long)]
    check: bool,
    /// Print the report as JSON (each figure with its value, ranges, verdict and source).
    #[arg(long)]
    json: bool,
    /// Seed for the model's random choices (genomes only).
    #[arg(long)]
    seed: Option<u64>,
    /// Scale the plant so that its highest point stands this many metres above the ground
    /// (genomes only).
    #[arg(long, value_name = "METRES", value_parser = super::parse_height)]
    height: Option<f32>,
    /// Thicken the branches by the pipe model, E from 2 to 3 (genomes only).
    #[arg(long, value_name = "E", value_parser = super::parse_taper)]
    taper: Option<sylva::core::taper::PipeTaper>,
    #[command(flatten)]
    dress: super::DressArgs,
}

/// What kind of file `path` is, by its name.
enum Input {
    Genome,
    Glb,
    Skeleton,
}

fn input_of(path: &Path) -> Result<Input, InputError> {
    let name = path.to_string_lossy().to_ascii_lowercase();
    if name.ends_with(SUFFIX) {
        Ok(Input::Skeleton)
    } else if name.ends_with(".glb") {
        Ok(Input::Glb)
    } else if name.ends_with(".json") || name.ends_with(".toml") {
        Ok(Input::Genome)
    } else {
        Err(InputError::file(
            path,
            "expected a genome (.json), a species preset (.toml), a GLB (.glb) or a skeleton \
             file (.skeleton.json)",
        ))
    }
}

/// `sylva inspect`.
pub fn run(models: &Registry, args: &InspectArgs) -> anyhow::Result<()> {
    let input = input_of(&args.file)?;
    let given = [
        (args.seed.is_some(), "--seed"),
        (args.height.is_some(), "--height"),
        (args.taper.is_some(), "--taper"),
        (args.dress.foliage.is_some(), "--foliage"),
        (args.dress.bark.is_some(), "--bark"),
    ];
    if !matches!(input, Input::Genome)
        && let Some((_, flag)) = given.iter().find(|(g, _)| *g)
    {
        return Err(InputError::new(
            *flag,
            "grows a genome; a GLB or skeleton file is inspected as it is",
        )
        .into());
    }
    if args.asset.is_some() && !matches!(input, Input::Skeleton) {
        return Err(InputError::new(
            "--asset",
            "weighs the asset of a skeleton file; a genome's or GLB's is its own",
        )
        .into());
    }
    let asset_of = |path: &Path| -> anyhow::Result<AssetFacts> {
        let bytes = sylva::files::read_bytes(path, MAX_GLB)?;
        AssetFacts::of_glb(&bytes).map_err(|e| InputError::file_error(path, &e).into())
    };
    let report = match input {
        Input::Genome => {
            let (genome, base) = super::load_input(models, &args.file)?;
            let options = super::GrowFlags {
                seed: args.seed,
                hide_roots: false,
                taper: args.taper,
                height: args.height,
                dress: &args.dress,
            }
            .over(base);
            let grown = Grown::grow(genome, &options).in_file(&args.file)?;
            Report::of(&grown.plant, Some(AssetFacts::of_mesh(&grown.mesh)))
        }
        Input::Glb => {
            let bytes = sylva::files::read_bytes(&args.file, MAX_GLB)?;
            let extras = sylva::import::first_extras(&bytes)
                .map_err(|e| InputError::file_error(&args.file, &e))?;
            let (genome, options) = sylva::assets::regrow(models, &extras, &args.file)?;
            let grown = Grown::grow(genome, &options).in_file(&args.file)?;
            let asset =
                AssetFacts::of_glb(&bytes).map_err(|e| InputError::file_error(&args.file, &e))?;
            Report::of(&grown.plant, Some(asset))
        }
        Input::Skeleton => {
            let skeleton = Skeleton::read(&args.file)?;
            let plant = skeleton.to_plant(&args.file)?;
            let asset = args.asset.as_deref().map(asset_of).transpose()?;
            Report::of_cards(&plant, &skeleton.cards(), asset)
        }
    };
    if args.json {
        println!("{}", report.to_json());
    } else {
        println!("{}:", args.file.display());
        print!("{}", report.table());
    }
    let failures = report.failures();
    if args.check && !failures.is_empty() {
        let names: Vec<String> = failures
            .iter()
            .map(|f| {
                format!(
                    "{} {} (outside {} to {})",
                    f.name,
                    f.value.map_or("-".into(), |v| format!("{v:.4}")),
                    f.check.0,
                    f.check.1
                )
            })
            .collect();
        anyhow::bail!("implausible: {}", names.join("; "));
    }
    Ok(())
}
