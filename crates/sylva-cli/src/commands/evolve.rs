//! `sylva evolve`: a run of any model that evolves, with a progress bar, checkpoints while
//! it runs, and every result file when it ends. A config whose `[run] strategy` is
//! `"map-elites"` fills a map of varieties instead (`varieties.rs`).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use sylva::core::budget::Seconds;
use sylva::evolution::SearchStrategy;
use sylva::lod::Preview;
use sylva::render::{self, SheetCell, SheetOptions};
use sylva::report::{fitness_svg, stats_csv};
use sylva::{Config, Evolution, GrowOptions, Grown, InputError, Registry};

use sylva::files::Outputs;

use super::run_files::{CHECKPOINT, FILES, add_best};

/// Arguments of `sylva evolve`; a flag left out keeps the config's value.
#[derive(clap::Args)]
pub struct EvolveArgs {
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
    #[command(flatten)]
    dress: super::DressArgs,
}

/// `sylva evolve`.
pub fn run(models: &Registry, args: &EvolveArgs) -> anyhow::Result<()> {
    let mut config = match &args.config {
        Some(path) => models.load_config(path)?,
        None => Config::builtin_run(models)?,
    };
    let run = config.run_mut();
    run.generations = args.generations.unwrap_or(run.generations);
    run.population = args.population.unwrap_or(run.population);
    run.seed = args.seed.unwrap_or(run.seed);
    run.threads = args.threads.unwrap_or(run.threads);
    args.dress.apply(config.output_mut());
    let out = args.out.clone().unwrap_or_else(|| {
        PathBuf::from(format!("runs/{}-seed{}", config.model(), config.run().seed))
    });
    sylva::files::check_out_dir(&out)?;
    let pool = super::pool(config.run().threads)?;
    let base = args
        .config
        .as_ref()
        .and_then(|p| p.parent())
        .unwrap_or(Path::new("."));
    if config.run().strategy == SearchStrategy::MapElites {
        return super::varieties::run(models, &config, &out, base, args.resume, &pool);
    }
    let checkpoint = out.join(CHECKPOINT);
    let target = config.run().generations;
    let population = u64::from(config.run().population);
    let mut evolution = if args.resume {
        let text = sylva::files::read_text(&checkpoint)?;
        Evolution::resume(&config, &checkpoint, &text, pool.clone())?
    } else {
        let start = config.load_start(models, base)?;
        if let Some(t) = config.generation_time(&start, pool.threads()) {
            super::announce(
                t.seconds * (f64::from(target) + 1.0),
                format_args!(
                    "this run of {} generations (each up to about {})",
                    u64::from(target) + 1,
                    Seconds(t.seconds)
                ),
                &t.advice,
            );
        }
        // Generation 0 is grown as the run starts.
        let ticker = Ticker::start(bar(population, 1, 0, target), population);
        let evolution = Evolution::start(&config, start, pool.clone())?;
        ticker.finish();
        evolution
    };
    sylva::files::create_dir(&out)?;
    // A run killed while writing left temporary files: they go.
    sylva::files::remove_leftovers(&out, &FILES);
    breed(&mut evolution, &config, &checkpoint)?;
    write_results(&evolution, &config, &out, &pool, Vec::new())
}

/// A bar over the genomes of `generations` generations of `population`, showing generation
/// `first` (the one being bred) of a run of `target`.
fn bar(population: u64, generations: u32, first: u32, target: u32) -> ProgressBar {
    ProgressBar::new(population.saturating_mul(u64::from(generations.max(1))))
        .with_style(
            ProgressStyle::with_template(
                "{spinner} generation {prefix}/{len_generations} {bar:30} {pos}/{len} genomes, \
                 best {msg} ({elapsed}, eta {eta})",
            )
            .expect("the template is valid")
            .with_key(
                "len_generations",
                move |_: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{target}");
                },
            ),
        )
        .with_prefix(first.to_string())
        .with_message("-")
}

/// Moves a bar counted in genomes evaluated, reading the engine's count four times a second
/// while a generation is bred on the calling thread.
struct Ticker {
    bar: ProgressBar,
    population: u64,
    /// Generations finished since the bar started.
    finished: Arc<AtomicU64>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Ticker {
    fn start(bar: ProgressBar, population: u64) -> Ticker {
        let finished = Arc::new(AtomicU64::new(0));
        let stop = Arc::new(AtomicBool::new(false));
        let base = sylva::evolution::evaluations_done();
        let thread = {
            let (bar, finished, stop) = (bar.clone(), finished.clone(), stop.clone());
            std::thread::spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    // Within the current generation's share of the bar, whatever the
                    // strategy evaluates (copies are not evaluated again).
                    let done = finished.load(Ordering::Relaxed) * population;
                    let evaluated = sylva::evolution::evaluations_done() - base;
                    bar.set_position(evaluated.clamp(done, done + population));
                    std::thread::sleep(Duration::from_millis(250));
                }
            })
        };
        Ticker {
            bar,
            population,
            finished,
            stop,
            thread: Some(thread),
        }
    }

    /// Generation `generation` is done, with best fitness `best`.
    fn generation(&self, generation: u32, best: f64) {
        let finished = self.finished.fetch_add(1, Ordering::Relaxed) + 1;
        self.bar.set_position(finished * self.population);
        self.bar.set_prefix((generation + 1).to_string());
        self.bar.set_message(format!("{best:.4}"));
    }

    /// Stops the ticking and takes the bar off the screen.
    fn finish(mut self) {
        self.stop_thread();
        self.bar.finish_and_clear();
    }

    fn stop_thread(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

impl Drop for Ticker {
    fn drop(&mut self) {
        self.stop_thread();
    }
}

/// Breeds up to the config's generation, showing progress and checkpointing as it goes.
fn breed(evolution: &mut Evolution, config: &Config, checkpoint: &Path) -> anyhow::Result<()> {
    let target = config.run().generations;
    let population = u64::from(config.run().population);
    let done = evolution.generation().min(target);
    let ticker = Ticker::start(bar(population, target - done, done + 1, target), population);
    let mut checkpoints = super::Checkpoints::new(checkpoint, config.run().checkpoint_seconds);
    while evolution.generation() < target {
        let best = evolution.step()?.best;
        ticker.generation(evolution.generation(), best);
        checkpoints.due(|| evolution.checkpoint())?;
    }
    checkpoints.save(|| evolution.checkpoint())?;
    ticker.finish();
    Ok(())
}

/// Writes the config, statistics, plot, best genome with its asset and picture, the
/// contact sheet of the best members, and `extra` files (name, bytes), all or none.
pub(super) fn write_results(
    evolution: &Evolution,
    config: &Config,
    out: &Path,
    pool: &sylva::core::par::Pool,
    extra: Vec<(&str, Vec<u8>)>,
) -> anyhow::Result<()> {
    let mut files = Outputs::new();
    for (name, bytes) in &extra {
        files.add(&out.join(name), bytes)?;
    }
    files.add(&out.join("config.toml"), config.to_toml().as_bytes())?;
    let stats = evolution.stats();
    files.add(
        &out.join("stats.csv"),
        stats_csv(evolution.term_names(), stats).as_bytes(),
    )?;
    let title = format!("{}, seed {}", evolution.title(), config.run().seed);
    files.add(
        &out.join("fitness.svg"),
        fitness_svg(stats, &title)?.as_bytes(),
    )?;
    let grown = add_best(
        &mut files,
        out,
        &evolution.best().genome,
        config,
        evolution.guides(),
    )?;
    let options = GrowOptions {
        wind: None,
        height: None,
        ..config.grow_options()?
    };
    let sheet = population_sheet(
        evolution,
        config.output().sheet_size as usize,
        &options,
        pool,
    )?;
    files.add(&out.join("population.png"), &sheet)?;
    files.commit()?;

    let last = stats
        .last()
        .ok_or_else(|| InputError::new("run", "no statistics"))?;
    let evaluations: u64 = stats.iter().map(|s| s.evaluations).sum();
    let seconds: f64 = stats.iter().map(|s| s.seconds).sum();
    println!(
        "generation {}: best fitness {:.4} (individual #{}), mean {:.4}; {} evaluations, {:.0}/s",
        last.generation,
        last.best,
        last.best_id.0,
        last.mean,
        evaluations,
        evaluations as f64 / seconds.max(1e-9),
    );
    let extra: String = extra.iter().map(|(name, _)| format!(", {name}")).collect();
    println!(
        "best plant: {} segments, {} organs, {} triangles; wrote {}/{{stats.csv, best.json, \
         best.glb, best.png, fitness.svg, population.png, config.toml, checkpoint.json{extra}}}",
        grown.plant.segments().len(),
        grown.plant.organs().len(),
        grown.mesh.triangle_count(),
        out.display()
    );
    Ok(())
}

/// The most triangles a plant of the contact sheet is drawn with, about: a cell a few
/// hundred pixels wide shows no more. A match's crowns reach millions, and drawing 48 of
/// them in full took most of the time a run spent writing its files (46 s of a 60 s
/// match's 106; 12 s so).
const SHEET_TRIANGLES: usize = 250_000;

/// A contact sheet (PNG) of the best `count` members of the current population, each plant
/// drawn from its preview ([`Preview`]).
fn population_sheet(
    evolution: &Evolution,
    count: usize,
    options: &GrowOptions,
    pool: &sylva::core::par::Pool,
) -> anyhow::Result<Vec<u8>> {
    let chosen = evolution.fittest(count);
    let previews = pool
        .map(chosen.len(), |i| {
            let genome = &chosen[i].genome;
            let (seed, plant) = Grown::plant(genome, options)?;
            Preview::of(genome, seed, &plant, SHEET_TRIANGLES)
        })
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?;
    let cells: Vec<SheetCell> = chosen
        .iter()
        .zip(&previews)
        .map(|(m, preview)| SheetCell {
            scene: preview.scene(),
            caption: format!("#{} {:.3}", m.id.0, m.total()),
        })
        .collect();
    let options = SheetOptions {
        title: Some(format!(
            "Generation {}: best {} of {}",
            evolution.generation(),
            cells.len(),
            evolution.config().run().population
        )),
        ..SheetOptions::default()
    };
    let image = render::contact_sheet(&cells, &options, pool).map_err(sylva::Error::from)?;
    Ok(render::encode_png(&image).map_err(sylva::Error::from)?)
}
