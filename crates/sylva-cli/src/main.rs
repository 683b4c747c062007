//! `sylva`: grow and evolve 3D plants from the command line.
//!
//! Flags are parsed by clap into each command's arguments ([`commands`]); the commands read
//! files, call the library (`sylva`), write results and report. Exit codes: 0 success,
//! 1 failure, 2 bad input (a malformed genome, config or flag).

mod commands;
mod diagnostic;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "sylva",
    version,
    about = "Grow and evolve 3D plants from genomes",
    long_about = "Sylva grows plants from genomes and evolves the genomes towards goals, \
                  then exports them as 3D assets (GLB, OBJ, VRML97) and pictures (PNG)."
)]
struct Cli {
    /// Memory Sylva may use, like 4G or 512M [default: half of the machine's memory, of its
    /// cgroup's memory limit or of what its address-space or data rlimit leaves, whichever
    /// is least]. Work that would need more is refused before it starts, with its estimate.
    #[arg(long, global = true, value_parser = sylva::core::budget::parse_bytes)]
    max_memory: Option<u64>,
    /// Longest Sylva may work before it writes results, like 90s, 10m or 2h [default: 1h]:
    /// L-system growth (a breeding round, an experiment, a generation of a run) estimated to
    /// take longer is refused before it starts, with its estimate.
    #[arg(long, global = true, value_parser = sylva::core::budget::parse_duration)]
    max_time: Option<std::time::Duration>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Evolve plants; writes stats.csv, best.json, best.glb, best.png, fitness.svg,
    /// population.png and a checkpoint into the run directory.
    Evolve(commands::evolve::EvolveArgs),
    /// Evolve a plant whose outline matches a picture (PNG or JPEG) in any model, or the
    /// one that matches it best; writes what `evolve` writes and overlay.png.
    Match(commands::matching::MatchArgs),
    /// Grow one genome into a 3D asset (format from the extension: .glb, .obj, .wrl, .stl), or
    /// write its skeleton as data (.skeleton.json).
    Grow(commands::grow::GrowArgs),
    /// Plant a garden: many plants of one or more genomes (each with its own seed) placed on
    /// the ground without overlapping, in one GLB scene. Also writes the garden file
    /// (`OUT.garden.json`: the genomes and seeds, nothing else), which grows the same scene.
    Garden(commands::garden::GardenArgs),
    /// Run one of Bornhofen and Lattaud's experiments (an L-system garden in a voxel world
    /// of light and minerals); writes report.txt, records.csv, scene.glb and scene.png.
    Simulate(commands::simulate::SimulateArgs),
    /// Breed L-system plants like Dawkins' biomorphs: grow the mother (in one corner) and her
    /// mutated children together in one voxel world; writes a picture of the garden and each
    /// specimen's genome, so you can pick the next mother and breed again.
    Breed(commands::breed::BreedArgs),
    /// Render a genome (.json) or a GLB (.glb) to a PNG picture.
    Render(commands::render::RenderArgs),
    /// How a plant measures against real trees: height, crown, trunk, pipe-model exponent,
    /// leaf size and area, triangles and textures, each with the range real trees give;
    /// `--check` exits 1 naming each implausible figure.
    Inspect(commands::inspect::InspectArgs),
    /// Every model's genome field by field (path, group, the values it takes, what it does):
    /// the tables of docs/genomes.md, or JSON with `--json`.
    Schema(commands::schema::SchemaArgs),
    /// Start the studio: a web page where you breed plants by eye (PlantMaker's grid, the
    /// biomorph garden, the binary-tree family, the GP designer), every step kept in an
    /// SQLite archive. Prints the address to open.
    Studio(commands::studio::StudioArgs),
}

fn main() -> ExitCode {
    diagnostic::install();
    let cli = Cli::parse();
    match cli.max_memory {
        Some(bytes) => sylva::core::budget::set_max_memory(bytes),
        // Worked out now, before any thread or buffer, so "mapped at start" is that.
        None => {
            sylva::core::budget::default_budget();
        }
    }
    if let Some(time) = cli.max_time {
        sylva::core::budget::set_max_time(time);
    }
    let command = cli.command;
    // A panic would be a bug in Sylva: it is reported as one, in one line, with exit code 1.
    std::panic::set_hook(Box::new(diagnostic::report_bug));
    let result = std::panic::catch_unwind(|| {
        // The models this program knows, built once here and passed to every command.
        let models = sylva::Registry::standard();
        match command {
            Command::Evolve(args) => commands::evolve::run(&models, &args),
            Command::Grow(args) => commands::grow::run(&models, &args),
            Command::Match(args) => commands::matching::run(&models, &args),
            Command::Garden(args) => commands::garden::run(&models, &args),
            Command::Simulate(args) => commands::simulate::run(&models, &args),
            Command::Breed(args) => commands::breed::run(&models, &args),
            Command::Render(args) => commands::render::run(&models, &args),
            Command::Inspect(args) => commands::inspect::run(&models, &args),
            Command::Schema(args) => commands::schema::run(&models, &args),
            Command::Studio(args) => commands::studio::run(models, &args),
        }
    });
    match result {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(e)) => diagnostic::report(&e),
        Err(_) => ExitCode::FAILURE,
    }
}
