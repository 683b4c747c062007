//! Matches: runs of any model towards target pictures. The config of a match
//! ([`match_config`]), how long it breeds ([`Limit`], [`breed_until`]), and `auto`, which
//! tries every model and keeps the best ([`start_auto`], [`AutoMatch`]; its trials and
//! their [`TrialLog`] are `trials.rs`, re-exported here). The term itself, a plant's
//! silhouette against the pictures, is `silhouette.rs`, re-exported here too.

use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};
use sylva_core::budget::Seconds;
use sylva_core::par::{Pool, Stop};

use crate::error::{Error, FieldError, InputError};
use crate::registry::Registry;

pub use super::silhouette::{
    IMPLAUSIBLE, Outline, TERM, Target, outlines, overlay, prune, realism, score_pruned, space,
};
pub use super::trials::{
    AutoEvent, AutoMatch, Outcome, RUNOFF_SHARE, TRIAL_SHARE, Trial, TrialLog, TrialRecord,
    TrialRow, start_auto,
};

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

/// How long a match breeds (kept in a [`TrialLog`] as `{"generations": n}` or
/// `{"seconds": s}`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
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

impl std::fmt::Display for Limit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Limit::Generations(n) => write!(f, "{n} generations"),
            Limit::Seconds(s) => write!(f, "{}", Seconds(*s)),
        }
    }
}

/// The outline IoU of the run's best member (0 for a run without the term).
pub fn best_iou(evolution: &Evolution) -> f64 {
    let at = evolution.term_names().iter().position(|n| n == TERM);
    match (at, evolution.best().fitness) {
        (Some(at), Some(f)) => f.terms()[at],
        _ => 0.0,
    }
}

/// Whether `stop` ended work because its deadline passed, not by hand.
pub(super) fn out_of_time(stop: &Stop) -> bool {
    stop.timed_out() && !stop.is_set()
}

/// A deadline on a [`Stop`] while it lives: cleared when dropped, however the work ends.
pub(super) struct Deadline<'a>(&'a Stop);

impl<'a> Deadline<'a> {
    pub(super) fn set(stop: &'a Stop, at: Option<Instant>) -> Deadline<'a> {
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
