//! Matches: runs of any model towards target pictures. The config of a match
//! ([`match_config`]), how long it breeds ([`Limit`], [`breed_until`]), and `auto`, which
//! tries every model and keeps the best ([`start_auto`]). The term itself, a plant's
//! silhouette against the pictures, is `silhouette.rs`, re-exported here.

use std::path::Path;
use std::time::{Duration, Instant};

use sylva_core::budget::Seconds;
use sylva_core::par::{Pool, Stop};

use crate::error::{Error, FieldError, InputError};
use crate::registry::Registry;

pub use super::silhouette::{Outline, TERM, Target, outlines, overlay, prune, score_pruned, space};

use super::config::Config;
use super::hooks::RunHooks;
use super::run::Evolution;
use super::schema::{MatchConfig, RunConfig};

/// The config of a run that evolves `model`'s plants towards the outline of `outline`
/// alone (what `sylva match` runs): the model's defaults as the model fits an outline
/// (`Evolve::fitting`), `run`, and `outline` with `beside = false`. Errors name the field.
pub fn match_config(
    registry: &Registry,
    model: &str,
    run: &RunConfig,
    outline: &MatchConfig,
) -> Result<Config, FieldError> {
    let outline = MatchConfig {
        beside: false,
        ..outline.clone()
    };
    registry.match_config(model, run, &outline)
}

/// How long a match breeds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Limit {
    /// Until this generation: the same target, seed and generations give the same bytes.
    Generations(u32),
    /// For this many seconds of breeding.
    Seconds(f64),
}

impl Limit {
    /// Whether `evolution` has bred as long as asked, counting seconds from `started`.
    pub fn reached(self, evolution: &Evolution, started: Instant) -> bool {
        match self {
            Limit::Generations(n) => evolution.generation() >= n,
            Limit::Seconds(s) => started.elapsed().as_secs_f64() >= s,
        }
    }

    /// What is left of this limit after `evolution`'s bred generations and `elsewhere`
    /// seconds spent on other runs (a resumed run; the trials of [`start_auto`]).
    pub fn remaining(self, evolution: &Evolution, elsewhere: f64) -> Limit {
        match self {
            Limit::Seconds(s) => {
                let spent: f64 = evolution.stats().iter().map(|g| g.seconds).sum();
                Limit::Seconds(s - spent - elsewhere)
            }
            generations => generations,
        }
    }
}

/// Steps `evolution` until `limit`, counting seconds from `started`, calling `on_step`
/// after each generation. A time limit also cuts the generation under way short when the
/// time is up (the run stays at its last whole generation), so a match ends on time
/// however long its generations take: `stop` becomes the run's stop, with the limit's
/// deadline while it breeds; stopped by hand ([`Stop::stop`], a front end's Ctrl-C), the
/// breeding still ends with [`Error::Stopped`].
pub fn breed_until<E: From<Error>>(
    evolution: &mut Evolution,
    limit: Limit,
    started: Instant,
    stop: &Stop,
    mut on_step: impl FnMut(&Evolution) -> Result<(), E>,
) -> Result<(), E> {
    let Limit::Seconds(seconds) = limit else {
        while !limit.reached(evolution, started) {
            evolution.step()?;
            on_step(evolution)?;
        }
        return Ok(());
    };
    let deadline = Duration::try_from_secs_f64(seconds.max(0.0)).unwrap_or(Duration::MAX);
    stop.stop_at(started.checked_add(deadline));
    evolution.set_stop(Some(stop.clone()));
    let bred = loop {
        if limit.reached(evolution, started) {
            break Ok(());
        }
        match evolution.step() {
            Ok(_) => {}
            Err(Error::Stopped(_)) if stop.timed_out() && !stop.is_set() => break Ok(()),
            Err(e) => break Err(e.into()),
        }
        if let Err(e) = on_step(evolution) {
            break Err(e);
        }
    };
    stop.stop_at(None);
    bred
}

/// The share of a match each model's first trial gets in [`start_auto`].
pub const TRIAL_SHARE: f64 = 0.08;

/// The further share of a match the best two models of the first trials get in
/// [`start_auto`], before the better goes on: a slow model's few first generations
/// undersell it (a PlantMaker trial of 6 s lost a round outline to binary trees, which
/// PlantMaker matched better by 20 s).
pub const RUNOFF_SHARE: f64 = 0.12;

/// The outline IoU of the run's best member (0 for a run without the term).
pub fn best_iou(evolution: &Evolution) -> f64 {
    let at = evolution.term_names().iter().position(|n| n == TERM);
    match (at, evolution.best().fitness) {
        (Some(at), Some(f)) => f.terms()[at],
        _ => 0.0,
    }
}

/// Breeds `evolution` `more` (generations, or seconds from now) and gives its best IoU. The
/// last generation is bred whole: cut short, the run that goes on would score it again.
/// Only the match's own deadline (`stop`'s, [`start_auto_at`]) cuts one short, and the trial
/// ends at the last whole generation.
fn trial(evolution: &mut Evolution, more: Limit, stop: &Stop) -> Result<f64, Error> {
    let (begun, bred) = (Instant::now(), evolution.generation());
    let done = |evolution: &Evolution| match more {
        Limit::Generations(n) => evolution.generation() >= bred.saturating_add(n),
        Limit::Seconds(_) => more.reached(evolution, begun),
    };
    while !done(evolution) {
        match evolution.step() {
            Ok(_) => {}
            Err(Error::Stopped(_)) if out_of_time(stop) => break,
            Err(e) => return Err(e),
        }
    }
    Ok(best_iou(evolution))
}

/// Whether `stop` ended work because its deadline passed, not by hand.
fn out_of_time(stop: &Stop) -> bool {
    stop.timed_out() && !stop.is_set()
}

/// How one model did in the trials of [`start_auto`].
#[derive(Clone, Debug, PartialEq)]
pub enum Trial {
    /// It had bred `generations` generations and reached `iou`, at the end of its first
    /// trial or (`runoff`) of the run-off between the best two.
    Reached {
        /// The model.
        model: &'static str,
        /// Its best plant's outline IoU.
        iou: f64,
        /// Generations bred.
        generations: u32,
        /// Whether this was the run-off.
        runoff: bool,
    },
    /// It was left out: its first generation was not scored within the match's time.
    OutOfTime {
        /// The model.
        model: &'static str,
        /// The match's seconds.
        seconds: f64,
    },
    /// It was left out: a generation may take `seconds`, more than a trial allows.
    LeftOut {
        /// The model.
        model: &'static str,
        /// Seconds a generation may take.
        seconds: f64,
        /// Seconds a trial allows a generation.
        allowance: f64,
    },
}

/// A match by the model that matches the outline best: a short trial of each model of the
/// registry ([`TRIAL_SHARE`] of `limit`; a model whose generation may take longer than
/// that, or counting generations longer than that share of a minute, is left out), a
/// run-off of the best two ([`RUNOFF_SHARE`] more each), then the run of the better (the
/// first on a tie), with the seconds spent on the others. `on_trial` hears how each model
/// did. The target's pictures are found as their paths say (relative ones from the
/// current folder; [`start_auto_at`] finds them elsewhere).
///
/// The trials watch `stop`: set by hand, they end with [`Error::Stopped`]. A limit in
/// seconds is also a deadline on them, however large the population: a trial cut short by
/// it ends at its last whole generation, a model whose first generation it cuts is left
/// out ([`Trial::OutOfTime`]), and when it leaves no model the match is refused, naming
/// the population.
pub fn start_auto(
    registry: &Registry,
    target: &MatchConfig,
    run: &RunConfig,
    limit: Limit,
    pool: &Pool,
    stop: &Stop,
    on_trial: impl FnMut(&Trial),
) -> Result<(Evolution, f64), Error> {
    start_auto_at(
        registry,
        target,
        Path::new(""),
        run,
        limit,
        pool,
        stop,
        on_trial,
    )
}

/// [`start_auto`], the target's relative paths found in `base` (the studio keeps its
/// pictures in a folder of its own).
#[allow(clippy::too_many_arguments)]
pub fn start_auto_at(
    registry: &Registry,
    target: &MatchConfig,
    base: &Path,
    run: &RunConfig,
    limit: Limit,
    pool: &Pool,
    stop: &Stop,
    mut on_trial: impl FnMut(&Trial),
) -> Result<(Evolution, f64), Error> {
    let started = Instant::now();
    let _deadline = Deadline::set(stop, deadline(limit, started));
    let share = |share: f64| match limit {
        Limit::Generations(n) => Limit::Generations(((f64::from(n) * share) as u32).max(1)),
        Limit::Seconds(s) => Limit::Seconds(s * share),
    };
    let allowance = match limit {
        Limit::Generations(_) => 60.0 * TRIAL_SHARE,
        Limit::Seconds(s) => s * TRIAL_SHARE,
    };
    // The pictures are read once, for every model's trial.
    let pictures = Target::read(target, base)?;
    let mut entrants: Vec<(f64, &'static str, Evolution)> = Vec::new();
    for entry in registry.models() {
        let mut config = match_config(registry, entry.name(), run, target)
            .map_err(|e| InputError::new(e.field, e.message))?
            .with_target(Some(pictures.clone()));
        config.set_base(base);
        if let Some(t) = config.generation_time(&[], pool.threads())
            && t.seconds > allowance
        {
            on_trial(&Trial::LeftOut {
                model: entry.name(),
                seconds: t.seconds,
                allowance,
            });
            continue;
        }
        let hooks = RunHooks {
            stop: Some(stop.clone()),
            term: None,
        };
        let mut evolution = match Evolution::start_with(&config, Vec::new(), pool.clone(), hooks) {
            Ok(evolution) => evolution,
            Err(Error::Stopped(_)) if out_of_time(stop) => {
                on_trial(&Trial::OutOfTime {
                    model: entry.name(),
                    seconds: match limit {
                        Limit::Seconds(s) => s,
                        Limit::Generations(_) => 0.0,
                    },
                });
                continue;
            }
            Err(e) => return Err(e),
        };
        let iou = trial(&mut evolution, share(TRIAL_SHARE), stop)?;
        on_trial(&Trial::Reached {
            model: entry.name(),
            iou,
            generations: evolution.generation(),
            runoff: false,
        });
        entrants.push((iou, entry.name(), evolution));
    }
    // The best two, the first on a tie, go on to the run-off.
    entrants.sort_by(|a, b| b.0.total_cmp(&a.0));
    entrants.truncate(2);
    if entrants.len() > 1 {
        for (iou, model, evolution) in &mut entrants {
            *iou = trial(evolution, share(RUNOFF_SHARE), stop)?;
            on_trial(&Trial::Reached {
                model,
                iou: *iou,
                generations: evolution.generation(),
                runoff: true,
            });
        }
    }
    let best = entrants
        .into_iter()
        .reduce(|a, b| if b.0 > a.0 { b } else { a });
    let (_, _, mut evolution) = best.ok_or_else(|| match limit {
        Limit::Seconds(s) if out_of_time(stop) => InputError::new(
            "population",
            format!(
                "no model scored its first generation of {} plants within the {} given; \
                 breed a smaller population or give more seconds",
                run.population,
                Seconds(s)
            ),
        ),
        _ => InputError::new(
            "model",
            "no model's generation fits a trial of the time given",
        ),
    })?;
    let own: f64 = evolution.stats().iter().map(|g| g.seconds).sum();
    evolution.set_stop(None);
    Ok((evolution, (started.elapsed().as_secs_f64() - own).max(0.0)))
}

/// A deadline on a [`Stop`] while it lives: cleared when dropped, however the work ends.
struct Deadline<'a>(&'a Stop);

impl<'a> Deadline<'a> {
    fn set(stop: &'a Stop, at: Option<Instant>) -> Deadline<'a> {
        stop.stop_at(at);
        Deadline(stop)
    }
}

impl Drop for Deadline<'_> {
    fn drop(&mut self) {
        self.0.stop_at(None);
    }
}

/// When a match of `limit` begun at `started` is over: `None` for a count of generations.
pub fn deadline(limit: Limit, started: Instant) -> Option<Instant> {
    match limit {
        Limit::Seconds(s) => {
            started.checked_add(Duration::try_from_secs_f64(s.max(0.0)).unwrap_or(Duration::MAX))
        }
        Limit::Generations(_) => None,
    }
}

/// Generation 0 of a match of one model (`config`'s), watched by `stop` (a front end's
/// stop by hand) and, for a limit in seconds, cut short when they are up: then refused,
/// naming the population, for a match cannot begin without it.
pub fn start_within(
    config: &Config,
    limit: Limit,
    pool: &Pool,
    stop: &Stop,
) -> Result<Evolution, Error> {
    let deadline = Deadline::set(stop, deadline(limit, Instant::now()));
    let hooks = RunHooks {
        stop: Some(stop.clone()),
        term: None,
    };
    let started = Evolution::start_with(config, Vec::new(), pool.clone(), hooks);
    let late = out_of_time(stop);
    drop(deadline);
    match (started, limit) {
        (Err(Error::Stopped(_)), Limit::Seconds(s)) if late => Err(InputError::new(
            "population",
            format!(
                "generation 0 of {} plants was not scored within the {} given; breed a \
                 smaller population or give more seconds",
                config.run().population,
                Seconds(s)
            ),
        )
        .into()),
        (started, _) => started,
    }
}
