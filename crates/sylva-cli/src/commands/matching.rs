//! `sylva match`: evolve a plant whose outline matches a picture, in any model (or the
//! model that matches it best), for a number of generations or seconds; writes what
//! `sylva evolve` writes and `overlay.png`.
//!
//! `--model auto` first runs the trials of every model: a line says which model is on
//! trial, its generation and best IoU; `trials.json` in the run's folder keeps every trial
//! that ended (the library's `TrialLog`), so `--resume` after a kill during the trials goes
//! on from them, and `trials.csv` records the generations they bred.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use sylva::core::budget::Seconds;
use sylva::core::par::Stop;
use sylva::evolution::outline::{
    AutoEvent, AutoMatch, Limit, Target, Trial, TrialLog, best_iou, breed_until, match_config,
    start_within,
};
use sylva::evolution::{MatchConfig, RunConfig};
use sylva::picture::Threshold;
use sylva::report::trials_csv;
use sylva::{Config, Evolution, InputError, Registry};

use super::evolve::write_results;
use super::run_files::{CHECKPOINT, FILES};

/// The log of an auto match's trials, in its folder: what `--resume` goes on from while
/// the trials are under way.
const TRIALS: &str = "trials.json";

/// The generations the trials of an auto match bred, one row each.
const TRIALS_CSV: &str = "trials.csv";

/// Arguments of `sylva match`.
#[derive(clap::Args)]
pub struct MatchArgs {
    /// The target: a PNG or JPEG of the plant's outline seen from the front (dark ink on a
    /// light background, a photo against the sky, or the opaque pixels of a cut-out).
    target: PathBuf,
    /// The target seen from the side (looking along +X), scored too [default: the front
    /// picture: a tree looks much alike from every side, and a plant matched from one view
    /// alone may be flat or lean away in depth].
    #[arg(long)]
    side: Option<PathBuf>,
    /// The model to evolve, or `auto`: each model briefly, then on with the best.
    #[arg(long, default_value = "auto")]
    model: String,
    /// Generations to breed after the first (instead of --seconds); the same target, seed
    /// and generations give the same bytes.
    #[arg(long, conflicts_with = "seconds",
          value_parser = clap::value_parser!(u32).range(0..=1_000_000))]
    generations: Option<u32>,
    /// Seconds to breed for, 1 to 86400 [default: 60].
    #[arg(long, value_parser = parse_seconds)]
    seconds: Option<f64>,
    /// Individuals per generation.
    #[arg(long, default_value_t = 100,
          value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    population: u32,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// What is ink: `otsu` (the default) or a luminance from 0 to 1 that ink is darker than.
    #[arg(long, default_value = "otsu", value_parser = parse_threshold)]
    threshold: Threshold,
    /// Weight of closeness (a distance transform's) beside the IoU, 0 to 10 (`[match]
    /// closeness`, docs/match.md).
    #[arg(long, default_value_t = 0.0, value_parser = parse_closeness)]
    closeness: f64,
    /// Rows the outlines are compared at while breeding, 16 to 512 (`[match] rows`):
    /// more see finer gaps in a crown and cost more a plant.
    #[arg(long, default_value_t = MatchConfig::DEFAULT_ROWS,
          value_parser = clap::value_parser!(u32).range(16..=512))]
    rows: u32,
    /// Clip the plant to the outline as a topiary is clipped to its form: leaves cut where
    /// they would show over sky, stems at the outline's edge (`[match] topiary = true`,
    /// docs/match.md) [default: off: the outline is a goal, and the plant as it grew is
    /// written]
    #[arg(long)]
    topiary: bool,
    /// The plant as its genome grows it, not clipped (the default now; kept so that older
    /// scripts run).
    #[arg(long, hide = true, conflicts_with = "topiary")]
    no_prune: bool,
    /// Worker threads; 0 means one per core. Results do not depend on it.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=1024))]
    threads: u32,
    /// Run directory [default: runs/match-<target>-seed<seed>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Scale the best plant's assets so that its highest point stands this many metres
    /// above the ground, 0.01 to 1000 [default: the model's own scale]; the outline is
    /// matched whatever the size.
    #[arg(long, value_name = "METRES", value_parser = super::parse_height)]
    height: Option<f32>,
    /// Continue the run saved in the run directory's checkpoint.
    #[arg(long)]
    resume: bool,
    #[command(flatten)]
    dress: super::DressArgs,
}

fn parse_seconds(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(s) if (1.0..=86_400.0).contains(&s) => Ok(s),
        _ => Err(format!("expected seconds from 1 to 86400; got {text:?}")),
    }
}

fn parse_closeness(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(w) if (0.0..=10.0).contains(&w) => Ok(w),
        _ => Err(format!("expected a number from 0 to 10, got `{text}`")),
    }
}

fn parse_threshold(text: &str) -> Result<Threshold, String> {
    match text.trim() {
        "otsu" => Ok(Threshold::Otsu),
        t => match t.parse::<f32>() {
            Ok(l) if (0.0..=1.0).contains(&l) => Ok(Threshold::Level(l)),
            _ => Err(format!(
                "expected `otsu` or a luminance from 0 to 1; got {text:?}"
            )),
        },
    }
}

/// `sylva match`.
pub fn run(registry: &Registry, args: &MatchArgs) -> anyhow::Result<()> {
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_owned());
    let target = MatchConfig {
        front: absolute(&args.target),
        side: Some(absolute(args.side.as_ref().unwrap_or(&args.target))),
        threshold: args.threshold,
        weight: 1.0,
        beside: false,
        rows: args.rows,
        closeness: args.closeness,
        topiary: Some(args.topiary && !args.no_prune),
    };
    // The pictures are read first, once: a bad one is refused before anything is written.
    let pictures = Target::read(&target, Path::new(""))?;
    let limit = match (args.generations, args.seconds) {
        (Some(n), _) => Limit::Generations(n),
        (None, seconds) => Limit::Seconds(seconds.unwrap_or(60.0)),
    };
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = args
            .target
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy();
        PathBuf::from(format!("runs/match-{stem}-seed{}", args.seed))
    });
    sylva::files::check_out_dir(&out)?;
    let run = RunConfig {
        generations: match limit {
            Limit::Generations(n) => n,
            Limit::Seconds(_) => 1_000_000,
        },
        population: args.population,
        seed: args.seed,
        threads: args.threads,
        ..RunConfig::default()
    };
    let pool = super::pool(args.threads)?;
    let checkpoint = out.join(CHECKPOINT);
    // The match's seconds bound its first generations too, however large the population.
    let stop = Stop::new();
    let config_of = |model: &str| {
        match_config(registry, model, &run, &target)
            .map(|config| config.with_target(Some(pictures.clone())))
            .map_err(|e| InputError::new("--model", format!("{}: {}", e.field, e.message)))
    };
    // An auto match's log: resumed, the one its folder keeps; a new auto match starts one.
    let trials_path = out.join(TRIALS);
    let mut log = match (args.resume, trials_path.exists()) {
        (true, true) => Some(TrialLog::parse(
            &trials_path,
            &sylva::files::read_text(&trials_path)?,
        )?),
        _ => (!args.resume && args.model == "auto").then(TrialLog::new),
    };
    let (mut evolution, config, elsewhere) = match &mut log {
        // Trials under way: they go on from the log, whatever `--model` says.
        Some(log) if log.chosen().is_none() => {
            let auto = AutoMatch {
                registry,
                target: &target,
                base: Path::new(""),
                run: &run,
                limit,
                pool: &pool,
                stop: &stop,
            };
            let (evolution, elsewhere) = trials(&auto, log, &out)?;
            // The chosen run is kept before the log that says it was chosen: killed between
            // the two, `--resume` finds the choice again in the trials kept.
            sylva::files::write(&checkpoint, evolution.checkpoint()?.as_bytes())?;
            sylva::files::write(&trials_path, log.to_json()?.as_bytes())?;
            let config = evolution.config();
            (evolution, config, elsewhere)
        }
        _ if args.resume => {
            let text = sylva::files::read_text(&checkpoint)?;
            let model = sylva::evolution::checkpoint_model(&checkpoint, &text)?;
            let config = config_of(&model)?;
            let evolution = Evolution::resume(&config, &checkpoint, &text, pool.clone())?;
            // An auto match's trials are counted against its seconds again.
            let elsewhere = log.as_ref().and_then(|l| l.chosen()).map_or(0.0, |c| c.1);
            (evolution, config, elsewhere)
        }
        _ => {
            let config = config_of(&args.model)?;
            let evolution = start_within(&config, limit, &pool, &stop)?;
            // A match of one model leaves no trials of an earlier match to resume.
            for name in [TRIALS, TRIALS_CSV] {
                let _ = std::fs::remove_file(out.join(name));
            }
            (evolution, config, 0.0)
        }
    };
    sylva::files::create_dir(&out)?;
    let mut files = FILES.to_vec();
    files.extend(["overlay.png", TRIALS, TRIALS_CSV]);
    sylva::files::remove_leftovers(&out, &files);
    breed(
        &mut evolution,
        &config,
        limit,
        &checkpoint,
        elsewhere,
        &stop,
    )?;
    // The config written is the run's: its generations are the ones bred.
    let mut config = evolution.config();
    config.run_mut().generations = evolution.generation();
    config.output_mut().height = args.height;
    args.dress.apply(config.output_mut());
    let best = evolution.best();
    let (picture, iou) = pictures.overlay(&target, &best.genome)?;
    let mut extra = vec![("overlay.png", picture)];
    if let Some(log) = &log {
        extra.push((TRIALS_CSV, trials_csv(log).into_bytes()));
    }
    write_results(&evolution, &config, &out, &pool, extra)?;
    println!("outline IoU {iou:.3} ({}, front view)", evolution.title());
    Ok(())
}

/// The trials of `auto`, going on from `log`: a line shows the model on trial, its
/// generation and best IoU; each trial's end is said, and the log kept in `out` (made
/// then: a match refused before any model bred writes nothing).
fn trials(
    auto: &AutoMatch<'_>,
    log: &mut TrialLog,
    out: &Path,
) -> anyhow::Result<(Evolution, f64)> {
    let bar = ProgressBar::new_spinner().with_style(
        ProgressStyle::with_template("{spinner} auto: {msg} ({elapsed})")
            .expect("the template is valid"),
    );
    bar.enable_steady_tick(Duration::from_millis(200));
    let models: Vec<&str> = auto.registry.models().iter().map(|m| m.name()).collect();
    let which = |model: &str, runoff: bool| {
        if runoff {
            format!("run-off of {model}")
        } else {
            let at = models.iter().position(|m| *m == model).unwrap_or(0);
            format!("trial of {model} ({} of {})", at + 1, models.len())
        }
    };
    bar.set_message("reading the target");
    let started = auto.start(log, |event| {
        match event {
            AutoEvent::Begun { model, runoff } => {
                let doing = if runoff {
                    "going on"
                } else {
                    "making generation 0"
                };
                bar.set_message(format!("{}: {doing}", which(model, runoff)));
            }
            AutoEvent::Bred {
                model,
                runoff,
                evolution,
            } => {
                bar.set_message(format!(
                    "{}: generation {}, best IoU {:.3}",
                    which(model, runoff),
                    evolution.generation(),
                    best_iou(evolution)
                ));
            }
            AutoEvent::Ended {
                trial,
                log,
                resumed,
            } => {
                let kept = if resumed {
                    " (kept in trials.json)"
                } else {
                    ""
                };
                bar.suspend(|| eprintln!("auto: {}{kept}", said(trial)));
                // Kept once a model has bred: a match refused before that writes nothing.
                if !resumed && matches!(trial, Trial::Reached { .. }) {
                    sylva::files::create_dir(out)?;
                    sylva::files::write(&out.join(TRIALS), log.to_json()?.as_bytes())?;
                }
            }
        }
        Ok::<_, anyhow::Error>(())
    });
    bar.finish_and_clear();
    started
}

/// How a trial ended, in words.
fn said(trial: &Trial) -> String {
    match trial {
        Trial::Reached {
            model,
            iou,
            generations,
            runoff,
        } => format!(
            "{model} reached an outline score of {iou:.3} in {generations} generations{}",
            if *runoff { " (run-off)" } else { "" }
        ),
        Trial::OutOfTime { model, seconds } => format!(
            "{model} left out: its first generation was not scored within the {}",
            Seconds(*seconds)
        ),
        Trial::LeftOut {
            model,
            seconds,
            allowance,
        } => format!(
            "{model} left out: a generation may take {} (more than {} of a trial)",
            Seconds(*seconds),
            Seconds(*allowance)
        ),
    }
}

/// Breeds until `limit`, showing the best IoU and checkpointing as it goes; `elsewhere`
/// seconds were spent on other runs (the trials of `--model auto`) and count too.
fn breed(
    evolution: &mut Evolution,
    config: &Config,
    limit: Limit,
    checkpoint: &Path,
    elsewhere: f64,
    stop: &Stop,
) -> anyhow::Result<()> {
    let bar = match limit {
        Limit::Generations(n) => ProgressBar::new(u64::from(n)).with_style(
            ProgressStyle::with_template(
                "{spinner} generation {pos}/{len} {bar:30} best IoU {msg} ({elapsed}, eta {eta})",
            )
            .expect("the template is valid"),
        ),
        Limit::Seconds(s) => ProgressBar::new(s.ceil() as u64).with_style(
            ProgressStyle::with_template("{spinner} {pos}/{len} s {bar:30} best IoU {msg}")
                .expect("the template is valid"),
        ),
    };
    let started = Instant::now();
    let already = elsewhere + evolution.stats().iter().map(|g| g.seconds).sum::<f64>();
    let remaining = limit.remaining(evolution, elsewhere);
    let show = |evolution: &Evolution| {
        bar.set_position(match limit {
            Limit::Generations(_) => u64::from(evolution.generation()),
            Limit::Seconds(_) => (already + started.elapsed().as_secs_f64()) as u64,
        });
        bar.set_message(format!(
            "{:.3} (generation {})",
            best_iou(evolution),
            evolution.generation()
        ));
    };
    show(evolution);
    let mut checkpoints = super::Checkpoints::new(checkpoint, config.run().checkpoint_seconds);
    breed_until(evolution, remaining, started, stop, |evolution| {
        show(evolution);
        checkpoints.due(|| evolution.checkpoint())?;
        Ok::<_, anyhow::Error>(())
    })?;
    checkpoints.save(|| evolution.checkpoint())?;
    bar.finish_and_clear();
    Ok(())
}
