//! `sylva`: grow and evolve 3D plants from the command line.
//!
//! Exit codes: 0 success, 1 failure, 2 bad input (a malformed genome, config or flag).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use sylva::commands::{self, EvolveArgs, GardenArgs, GrowArgs, RenderArgs};
use sylva::error::InputError;
use sylva_mesh::render::View;

#[derive(Parser)]
#[command(
    name = "sylva",
    version,
    about = "Grow and evolve 3D plants from genomes",
    long_about = "Sylva grows plants from genomes and evolves the genomes towards goals, \
                  then exports them as 3D assets (GLB, OBJ, VRML97) and pictures (PNG)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Evolve plants; writes stats.csv, best.json, best.glb, best.png, fitness.svg,
    /// population.png and a checkpoint into the run directory.
    Evolve {
        /// TOML config; without one, the built-in default run (binary trees).
        config: Option<PathBuf>,
        /// Run directory [default: runs/<model>-seed<seed>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Generations to breed after the random first one (overrides the config).
        #[arg(long, value_parser = clap::value_parser!(u32).range(0..=1_000_000))]
        generations: Option<u32>,
        /// Individuals per generation (overrides the config).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
        population: Option<u32>,
        /// Seed of every random choice (overrides the config).
        #[arg(long)]
        seed: Option<u64>,
        /// Worker threads; 0 means one per core. Results do not depend on it.
        #[arg(long, value_parser = clap::value_parser!(u32).range(0..=1024))]
        threads: Option<u32>,
        /// Continue the run saved in the run directory's checkpoint.
        #[arg(long)]
        resume: bool,
    },
    /// Grow one genome into a 3D asset (format from the extension: .glb, .obj, .wrl).
    Grow {
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
        /// Leave the roots out.
        #[arg(long)]
        hide_roots: bool,
    },
    /// Plant a garden: many plants of one or more genomes (each with its own seed) placed on
    /// the ground without overlapping, in one GLB scene. Also writes the garden file
    /// (`OUT.garden.json`: the genomes and seeds, nothing else), which grows the same scene.
    Garden {
        /// PlantMaker genome files, or one garden file (`*.garden.json`).
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// Plants per genome.
        #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=100_000))]
        count: u32,
        /// Plot size in metres, WIDTHxDEPTH, centred on the origin.
        #[arg(long, default_value = "20x20", value_parser = commands::parse_area)]
        area: (f64, f64),
        /// Seed of the plants' seeds, positions and turns.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output scene (.glb, .obj or .wrl).
        #[arg(short, long)]
        output: PathBuf,
        /// Also render a picture.
        #[arg(long)]
        png: Option<PathBuf>,
    },
    /// Run one of Bornhofen and Lattaud's experiments (an L-system garden in a voxel world
    /// of light and minerals); writes report.txt, records.csv, scene.glb and scene.png.
    Simulate {
        /// Experiment config (`[herbs-under-tree]`, `[lateral-light]` or `[empty-rules]`).
        config: PathBuf,
        /// Output directory [default: runs/<config name>].
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Breed L-system plants like Dawkins' biomorphs: grow the mother (in one corner) and her
    /// mutated children together in one voxel world; writes a picture of the garden and each
    /// specimen's genome, so you can pick the next mother and breed again.
    Breed {
        /// The mother's genome (an L-system genome file).
        mother: PathBuf,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Children sown with the mother (at most 8: nine specimens in all).
        #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(0..=8))]
        children: u32,
        /// Seed of the mutations.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Leave the roots out of the picture and the GLB.
        #[arg(long)]
        hide_roots: bool,
    },
    /// Render a genome (.json) or a GLB (.glb) to a PNG picture.
    Render {
        /// Genome JSON or GLB.
        file: PathBuf,
        /// Output PNG.
        #[arg(short, long)]
        output: PathBuf,
        /// Camera.
        #[arg(long, default_value = "iso")]
        view: View,
        /// Picture size, WIDTHxHEIGHT.
        #[arg(long, default_value = "800x800", value_parser = commands::parse_size)]
        size: (u32, u32),
        /// Seed for the model's random choices (genomes only) [default: the genome's own
        /// seed for PlantMaker genomes, 0 otherwise].
        #[arg(long)]
        seed: Option<u64>,
        /// Leave the roots out (genomes only).
        #[arg(long)]
        hide_roots: bool,
    },
}

fn main() -> ExitCode {
    // Long messages stay on one line, so they can be searched for and copied whole.
    let _ = miette::set_hook(Box::new(|_| {
        Box::new(miette::MietteHandlerOpts::new().wrap_lines(false).build())
    }));
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Evolve {
            config,
            out,
            generations,
            population,
            seed,
            threads,
            resume,
        } => commands::evolve(&EvolveArgs {
            config,
            out,
            generations,
            population,
            seed,
            threads,
            resume,
        }),
        Command::Grow {
            genome,
            output,
            png,
            seed,
            hide_roots,
        } => commands::grow(&GrowArgs {
            genome,
            output,
            png,
            seed,
            hide_roots,
        }),
        Command::Garden {
            inputs,
            count,
            area,
            seed,
            output,
            png,
        } => commands::garden(&GardenArgs {
            inputs,
            count,
            area,
            seed,
            output,
            png,
        }),
        Command::Simulate { config, out } => commands::simulate(&config, out.as_deref()),
        Command::Breed {
            mother,
            out,
            children,
            seed,
            hide_roots,
        } => commands::breed(&mother, &out, children as usize, seed, hide_roots),
        Command::Render {
            file,
            output,
            view,
            size,
            seed,
            hide_roots,
        } => commands::render(&RenderArgs {
            file,
            output,
            view,
            size,
            seed,
            hide_roots,
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => match e.downcast::<InputError>() {
            Ok(input) => {
                eprintln!("{:?}", miette::Report::new(input));
                ExitCode::from(2)
            }
            Err(other) => {
                eprintln!("error: {other:#}");
                ExitCode::from(1)
            }
        },
    }
}
