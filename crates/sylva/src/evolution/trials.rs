//! The trials of an auto match ([`AutoMatch`]): a short trial of each model of the registry,
//! a run-off of the best two, then the better goes on.
//!
//! The trials are a phase of the match like any other: they tell a front end each trial
//! that begins ([`AutoEvent::Begun`]), each generation it breeds ([`AutoEvent::Bred`]:
//! which model, the run, so its best IoU and outline can be shown), and each trial that
//! ends ([`AutoEvent::Ended`]) with the
//! [`TrialLog`] that holds it. The log is the trials' checkpoint: every trial that ended,
//! with how it ended, the generations it bred ([`TrialRow`]) and its run as it left it. A
//! front end keeps it (`sylva match` as `trials.json` in its folder, the studio in its
//! archive) each time a trial ends, and gives it back to [`AutoMatch::start`] after a kill:
//! the trials kept are not bred again, a model goes on to its run-off from its kept run, and
//! a match that counts generations ends with the same bytes as one never killed. A kill
//! loses at most the trial under way.
//!
//! ```no_run
//! use std::path::Path;
//! use sylva::core::par::{Pool, Stop};
//! use sylva::evolution::outline::{AutoEvent, AutoMatch, Limit, TrialLog, best_iou};
//! use sylva::evolution::{MatchConfig, RunConfig};
//! use sylva::picture::Threshold;
//! use sylva::Registry;
//!
//! let registry = Registry::standard();
//! let target = MatchConfig {
//!     front: "examples/match/round.png".into(),
//!     side: None,
//!     threshold: Threshold::default(),
//!     weight: 1.0,
//!     beside: false,
//!     rows: MatchConfig::DEFAULT_ROWS,
//!     closeness: 0.0,
//!     topiary: None,
//! };
//! let run = RunConfig { population: 20, ..RunConfig::default() };
//! let (pool, stop) = (Pool::Serial, Stop::new());
//! let auto = AutoMatch {
//!     registry: &registry,
//!     target: &target,
//!     base: Path::new(""),
//!     run: &run,
//!     limit: Limit::Generations(50),
//!     pool: &pool,
//!     stop: &stop,
//! };
//! // After a kill, the log kept last: `TrialLog::parse(path, &text)?`.
//! let mut log = TrialLog::new();
//! let (evolution, _) = auto.start(&mut log, |event| {
//!     match event {
//!         AutoEvent::Bred { model, evolution, .. } => {
//!             println!("{model}: generation {}, IoU {:.3}", evolution.generation(), best_iou(evolution))
//!         }
//!         AutoEvent::Ended { log, resumed: false, .. } => {
//!             sylva::files::write(Path::new("trials.json"), log.to_json()?.as_bytes())?
//!         }
//!         AutoEvent::Begun { .. } | AutoEvent::Ended { .. } => {}
//!     }
//!     Ok::<_, sylva::Error>(())
//! })?;
//! println!("{} goes on", evolution.title());
//! # Ok::<(), sylva::Error>(())
//! ```

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use sylva_core::budget::Seconds;
use sylva_core::par::{Pool, Stop};

use crate::error::{Error, InputError};
use crate::registry::Registry;

use super::config::Config;
use super::hooks::RunHooks;
use super::outline::{Deadline, Limit, best_iou, deadline, match_config, out_of_time};
use super::run::Evolution;
use super::schema::{MatchConfig, RunConfig};
use super::silhouette::{TERM, Target};

/// The share of a match each model's first trial gets in [`AutoMatch::start`].
pub const TRIAL_SHARE: f64 = 0.08;

/// The further share of a match the best two models of the first trials get in
/// [`AutoMatch::start`], before the better goes on: a slow model's few first generations
/// undersell it (a PlantMaker trial of 6 s lost a round outline to binary trees, which
/// PlantMaker matched better by 20 s).
pub const RUNOFF_SHARE: f64 = 0.12;

/// The format of the [`TrialLog`] this version writes and reads.
const LOG_FORMAT: u32 = 1;

/// How one model did in the trials of an auto match.
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

/// How a trial ended, as a [`TrialLog`] keeps it (a [`Trial`] without its model).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Outcome {
    /// It bred to `generations` and reached `iou`.
    Reached {
        /// Its best plant's outline IoU.
        iou: f64,
        /// The generation its run had reached.
        generations: u32,
    },
    /// Its first generation was not scored within the match's `seconds`.
    OutOfTime {
        /// The match's seconds.
        seconds: f64,
    },
    /// A generation may take `seconds`, more than the `allowance` of a trial.
    LeftOut {
        /// Seconds a generation may take.
        seconds: f64,
        /// Seconds a trial allows a generation.
        allowance: f64,
    },
}

/// One generation a trial bred, as its run's statistics give it (a figure that is not
/// finite, as in a generation where nothing scored, is kept as 0).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrialRow {
    /// The generation.
    pub generation: u32,
    /// Best total fitness (the outline score).
    pub best: f64,
    /// Mean total fitness.
    pub mean: f64,
    /// The best plant's outline IoU (its `iou` term).
    pub iou: f64,
}

/// One model's trial as it ended.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrialRecord {
    /// The model.
    pub model: String,
    /// Whether this was the run-off, the model's second trial.
    pub runoff: bool,
    /// How it ended.
    pub outcome: Outcome,
    /// Wall seconds it took.
    pub seconds: f64,
    /// The generations it bred, in order (a first trial's from generation 0).
    pub rows: Vec<TrialRow>,
    /// The model's run as the trial left it (checkpoint JSON), kept while it may go on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    checkpoint: Option<String>,
}

impl TrialRecord {
    /// The trial, of `model` (this record's, as the registry names it).
    fn trial(&self, model: &'static str) -> Trial {
        match self.outcome {
            Outcome::Reached { iou, generations } => Trial::Reached {
                model,
                iou,
                generations,
                runoff: self.runoff,
            },
            Outcome::OutOfTime { seconds } => Trial::OutOfTime { model, seconds },
            Outcome::LeftOut { seconds, allowance } => Trial::LeftOut {
                model,
                seconds,
                allowance,
            },
        }
    }
}

/// The match a log's trials are of: a log is resumed by the same match only.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Asked {
    limit: Limit,
    population: u32,
    seed: u64,
    target: MatchConfig,
}

/// The model the trials chose, and the seconds they spent on the others.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Chosen {
    model: String,
    elsewhere: f64,
}

/// What the trials of an auto match have done: their checkpoint (JSON, [`TrialLog::to_json`]
/// and [`TrialLog::parse`]). A new log is empty; [`AutoMatch::start`] fills it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrialLog {
    /// The log's format (1).
    format: u32,
    /// The match its trials are of, once one has begun.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    of: Option<Asked>,
    /// Every trial that ended, in the order they ran: the first trials, then the run-off.
    #[serde(default)]
    trials: Vec<TrialRecord>,
    /// The model the trials chose, once they have.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    chosen: Option<Chosen>,
    /// Where it was read from, for errors.
    #[serde(skip)]
    source: Option<PathBuf>,
}

impl Default for TrialLog {
    fn default() -> Self {
        TrialLog::new()
    }
}

impl TrialLog {
    /// An empty log: no trial has ended.
    pub fn new() -> TrialLog {
        TrialLog {
            format: LOG_FORMAT,
            of: None,
            trials: Vec::new(),
            chosen: None,
            source: None,
        }
    }

    /// Reads a log that [`TrialLog::to_json`] wrote, read from `path` (named in errors).
    pub fn parse(path: &Path, text: &str) -> Result<TrialLog, InputError> {
        let mut log: TrialLog = serde_json::from_str(text).map_err(|e| {
            let message = if e.is_syntax() || e.is_eof() {
                "the trials' log is not JSON (cut short?)".to_owned()
            } else {
                format!("not a log of an auto match's trials: {e}")
            };
            InputError::at(path, text, e.line(), e.column(), message)
        })?;
        if log.format != LOG_FORMAT {
            return Err(InputError::file(
                path,
                format!(
                    "the trials' log is of format {}; this Sylva reads format {LOG_FORMAT}",
                    log.format
                ),
            ));
        }
        log.source = Some(path.to_owned());
        Ok(log)
    }

    /// The log as JSON, to keep (refused only for a target whose path is not Unicode).
    pub fn to_json(&self) -> Result<String, Error> {
        serde_json::to_string_pretty(self).map_err(|e| InputError::new("the trials' log", e).into())
    }

    /// Every trial that ended, in the order they ran.
    pub fn trials(&self) -> &[TrialRecord] {
        &self.trials
    }

    /// The model the trials chose and the seconds they spent on the other models, once
    /// they have chosen.
    pub fn chosen(&self) -> Option<(&str, f64)> {
        (self.chosen.as_ref()).map(|c| (c.model.as_str(), c.elsewhere))
    }

    /// An error about the log, naming where it was read from.
    fn error(&self, message: impl ToString) -> InputError {
        match &self.source {
            Some(path) => InputError::file(path, message),
            None => InputError::new("the trials' log", message),
        }
    }

    /// The last trial of `model` that ended, first or (`runoff`) run-off.
    fn find(&self, model: &str, runoff: bool) -> Option<&TrialRecord> {
        (self.trials.iter().rev()).find(|t| t.model == model && t.runoff == runoff)
    }

    /// Takes it for `asked`: an empty log is, a log of another match is refused.
    fn claim(&mut self, asked: Asked) -> Result<(), InputError> {
        match &self.of {
            None if self.trials.is_empty() && self.chosen.is_none() => {
                self.of = Some(asked);
                Ok(())
            }
            None => Err(self.error("the trials' log names no match")),
            Some(of) if *of == asked => Ok(()),
            Some(of) => {
                let differs = if of.limit != asked.limit {
                    format!("{}, not {}", of.limit, asked.limit)
                } else if of.population != asked.population {
                    format!(
                        "a population of {}, not {}",
                        of.population, asked.population
                    )
                } else if of.seed != asked.seed {
                    format!("seed {}, not {}", of.seed, asked.seed)
                } else {
                    "another target (pictures, threshold, rows, closeness or topiary)".to_owned()
                };
                Err(self.error(format!(
                    "these trials were of another match ({differs}): start the match afresh"
                )))
            }
        }
    }

    /// Lets go of the runs no trial will go on from: those of models not in `going`, and
    /// every trial's but the last of each model.
    fn keep_runs(&mut self, going: &[&str]) {
        let mut seen = Vec::new();
        for t in self.trials.iter_mut().rev() {
            if !going.contains(&t.model.as_str()) || seen.contains(&t.model) {
                t.checkpoint = None;
            }
            seen.push(t.model.clone());
        }
    }
}

/// What the trials tell a front end as they go.
#[derive(Debug)]
pub enum AutoEvent<'a> {
    /// A trial begins to breed (its first generation, or its run-off's, is being made):
    /// the model on trial and whether this is its run-off.
    Begun {
        /// The model on trial.
        model: &'static str,
        /// Whether this is the run-off.
        runoff: bool,
    },
    /// A generation of a trial was made (generation 0 too): the model on trial, whether
    /// this is its run-off, and its run (its best plant, [`best_iou`], its statistics).
    Bred {
        /// The model on trial.
        model: &'static str,
        /// Whether this is the run-off.
        runoff: bool,
        /// Its run.
        evolution: &'a Evolution,
    },
    /// A trial ended, and `log` holds it now: keep the log (atomically) to resume from. Or,
    /// `resumed`, a trial found ended in the log given back, told again.
    Ended {
        /// How it did.
        trial: &'a Trial,
        /// The log, this trial in it.
        log: &'a TrialLog,
        /// Whether the trial ended before, as the log given back holds it.
        resumed: bool,
    },
}

/// An auto match: what it is of and where its pictures are found.
#[derive(Clone, Copy, Debug)]
pub struct AutoMatch<'a> {
    /// The models to try, in order.
    pub registry: &'a Registry,
    /// The target.
    pub target: &'a MatchConfig,
    /// The folder the target's relative paths are found in (`""`: the current folder).
    pub base: &'a Path,
    /// The run's size and seed.
    pub run: &'a RunConfig,
    /// How long the whole match breeds.
    pub limit: Limit,
    /// The threads.
    pub pool: &'a Pool,
    /// Set by hand, it ends the trials with [`Error::Stopped`]; a limit in seconds is its
    /// deadline too.
    pub stop: &'a Stop,
}

/// A model still in the running, with its run if this call bred it.
struct Entrant {
    iou: f64,
    model: &'static str,
    run: Option<Evolution>,
}

impl AutoMatch<'_> {
    /// The match by the model that matches the outline best: a short trial of each model
    /// of the registry ([`TRIAL_SHARE`] of the limit; a model whose generation may take
    /// longer than that, or counting generations longer than that share of a minute, is
    /// left out), a run-off of the best two ([`RUNOFF_SHARE`] more each), then the run of
    /// the better (the first on a tie), with the seconds spent on the others.
    ///
    /// `log` holds the trials that ended (empty for a new match; a log of another match is
    /// refused): they are told again and not bred again. `on` hears every trial generation
    /// and every trial's end (see [`AutoEvent`]); an error from it ends the trials with that
    /// error, the log as the last `Ended` left it.
    ///
    /// `stop` set by hand ends the trials with [`Error::Stopped`]. A limit in seconds is
    /// also a deadline on them (less the seconds the log's trials took), however large the
    /// population: a trial cut short by it ends at its last whole generation, a model whose
    /// first generation it cuts is left out ([`Trial::OutOfTime`]), and when it leaves no
    /// model the match is refused, naming the population.
    pub fn start<E: From<Error>>(
        &self,
        log: &mut TrialLog,
        mut on: impl FnMut(AutoEvent<'_>) -> Result<(), E>,
    ) -> Result<(Evolution, f64), E> {
        let started = Instant::now();
        log.claim(Asked {
            limit: self.limit,
            population: self.run.population,
            seed: self.run.seed,
            target: self.target.clone(),
        })
        .map_err(Error::from)?;
        // The seconds the kept trials took count against a limit in seconds.
        let before: f64 = log.trials.iter().map(|t| t.seconds).sum();
        let left = match self.limit {
            Limit::Seconds(s) => Limit::Seconds(s - before),
            generations => generations,
        };
        let _deadline = Deadline::set(self.stop, deadline(left, started));
        // The pictures are read once, for every model's trial.
        let pictures = Target::read(self.target, self.base).map_err(Error::from)?;
        let mut entrants: Vec<Entrant> = Vec::new();
        for entry in self.registry.models() {
            let model = entry.name();
            if let Some(kept) = log.find(model, false) {
                let trial = kept.trial(model);
                if let Outcome::Reached { iou, .. } = kept.outcome {
                    entrants.push(Entrant {
                        iou,
                        model,
                        run: None,
                    });
                }
                on(AutoEvent::Ended {
                    trial: &trial,
                    log,
                    resumed: true,
                })?;
                continue;
            }
            if let Some(entrant) = self.first_trial(model, &pictures, log, &mut on)? {
                entrants.push(entrant);
            }
        }
        // The best two, the first on a tie, go on to the run-off.
        entrants.sort_by(|a, b| b.iou.total_cmp(&a.iou));
        entrants.truncate(2);
        let going: Vec<&str> = entrants.iter().map(|e| e.model).collect();
        log.keep_runs(&going);
        if entrants.len() > 1 {
            for entrant in &mut entrants {
                self.runoff(entrant, &pictures, log, &mut on)?;
            }
        }
        let best = entrants
            .into_iter()
            .reduce(|a, b| if b.iou > a.iou { b } else { a });
        let best = best.ok_or_else(|| self.no_model())?;
        let mut evolution = match best.run {
            Some(run) => run,
            None => self.resume(best.model, &pictures, log)?,
        };
        evolution.set_stop(None);
        let own: f64 = evolution.stats().iter().map(|g| g.seconds).sum();
        let elsewhere = (before + started.elapsed().as_secs_f64() - own).max(0.0);
        log.keep_runs(&[best.model]);
        log.chosen = Some(Chosen {
            model: best.model.to_owned(),
            elsewhere,
        });
        Ok((evolution, elsewhere))
    }

    /// The config of `model`'s trial.
    fn config(&self, model: &str, pictures: &Target) -> Result<Config, Error> {
        let mut config = match_config(self.registry, model, self.run, self.target)
            .map_err(|e| InputError::new(e.field, e.message))?
            .with_target(Some(pictures.clone()));
        config.set_base(self.base);
        Ok(config)
    }

    /// The share `share` of the match's limit.
    fn share(&self, share: f64) -> Limit {
        match self.limit {
            Limit::Generations(n) => Limit::Generations(((f64::from(n) * share) as u32).max(1)),
            Limit::Seconds(s) => Limit::Seconds(s * share),
        }
    }

    /// `model`'s first trial, kept in `log`; the entrant, unless it was left out.
    fn first_trial<E: From<Error>>(
        &self,
        model: &'static str,
        pictures: &Target,
        log: &mut TrialLog,
        on: &mut impl FnMut(AutoEvent<'_>) -> Result<(), E>,
    ) -> Result<Option<Entrant>, E> {
        let begun = Instant::now();
        let config = self.config(model, pictures)?;
        let allowance = match self.limit {
            Limit::Generations(_) => 60.0 * TRIAL_SHARE,
            Limit::Seconds(s) => s * TRIAL_SHARE,
        };
        let left_out = |outcome| TrialRecord {
            model: model.to_owned(),
            runoff: false,
            outcome,
            seconds: begun.elapsed().as_secs_f64(),
            rows: Vec::new(),
            checkpoint: None,
        };
        if let Some(t) = config.generation_time(&[], self.pool.threads())
            && t.seconds > allowance
        {
            let seconds = t.seconds;
            keep(
                log,
                model,
                left_out(Outcome::LeftOut { seconds, allowance }),
                on,
            )?;
            return Ok(None);
        }
        on(AutoEvent::Begun {
            model,
            runoff: false,
        })?;
        let hooks = RunHooks {
            stop: Some(self.stop.clone()),
            term: None,
        };
        let mut evolution =
            match Evolution::start_with(&config, Vec::new(), self.pool.clone(), hooks) {
                Ok(evolution) => evolution,
                Err(Error::Stopped(_)) if out_of_time(self.stop) => {
                    let seconds = match self.limit {
                        Limit::Seconds(s) => s,
                        Limit::Generations(_) => 0.0,
                    };
                    keep(log, model, left_out(Outcome::OutOfTime { seconds }), on)?;
                    return Ok(None);
                }
                Err(e) => return Err(e.into()),
            };
        on(AutoEvent::Bred {
            model,
            runoff: false,
            evolution: &evolution,
        })?;
        let iou = trial(&mut evolution, self.share(TRIAL_SHARE), self.stop, |e| {
            on(AutoEvent::Bred {
                model,
                runoff: false,
                evolution: e,
            })
        })?;
        let record = reached(model, false, &evolution, iou, 0, begun)?;
        keep(log, model, record, on)?;
        Ok(Some(Entrant {
            iou,
            model,
            run: Some(evolution),
        }))
    }

    /// `entrant`'s run-off, kept in `log` (or, kept before, told again).
    fn runoff<E: From<Error>>(
        &self,
        entrant: &mut Entrant,
        pictures: &Target,
        log: &mut TrialLog,
        on: &mut impl FnMut(AutoEvent<'_>) -> Result<(), E>,
    ) -> Result<(), E> {
        let model = entrant.model;
        if let Some(kept) = log.find(model, true) {
            if let Outcome::Reached { iou, .. } = kept.outcome {
                entrant.iou = iou;
            }
            entrant.run = None;
            let trial = kept.trial(model);
            return on(AutoEvent::Ended {
                trial: &trial,
                log,
                resumed: true,
            });
        }
        on(AutoEvent::Begun {
            model,
            runoff: true,
        })?;
        let begun = Instant::now();
        let mut evolution = match entrant.run.take() {
            Some(run) => run,
            None => self.resume(model, pictures, log)?,
        };
        let from = evolution.generation();
        entrant.iou = trial(&mut evolution, self.share(RUNOFF_SHARE), self.stop, |e| {
            on(AutoEvent::Bred {
                model,
                runoff: true,
                evolution: e,
            })
        })?;
        let record = reached(model, true, &evolution, entrant.iou, from + 1, begun)?;
        entrant.run = Some(evolution);
        keep(log, model, record, on)
    }

    /// `model`'s run as its last kept trial left it.
    fn resume(&self, model: &str, pictures: &Target, log: &TrialLog) -> Result<Evolution, Error> {
        let kept = (log.trials.iter().rev())
            .filter(|t| t.model == model)
            .find_map(|t| t.checkpoint.as_deref())
            .ok_or_else(|| log.error(format!("it keeps no run of {model} to go on from")))?;
        let config = self.config(model, pictures)?;
        let path = log
            .source
            .clone()
            .unwrap_or_else(|| "the trials' log".into());
        // Resumed unstopped: its population is scored again whole, as it was when the trial
        // ended, so that the run goes on exactly; it is watched again from its next step.
        let mut evolution =
            Evolution::resume_with(&config, &path, kept, self.pool.clone(), RunHooks::default())?;
        evolution.set_stop(Some(self.stop.clone()));
        Ok(evolution)
    }

    /// Why no model was left to go on.
    fn no_model(&self) -> Error {
        match self.limit {
            Limit::Seconds(s) if out_of_time(self.stop) => InputError::new(
                "population",
                format!(
                    "no model scored its first generation of {} plants within the {} given; \
                     breed a smaller population or give more seconds",
                    self.run.population,
                    Seconds(s)
                ),
            ),
            _ => InputError::new(
                "model",
                "no model's generation fits a trial of the time given",
            ),
        }
        .into()
    }
}

/// The record of a trial of `model` that reached `iou`, its run `evolution` having bred
/// generations `from` on in it since `begun`.
fn reached(
    model: &str,
    runoff: bool,
    evolution: &Evolution,
    iou: f64,
    from: u32,
    begun: Instant,
) -> Result<TrialRecord, Error> {
    let at = evolution.term_names().iter().position(|n| n == TERM);
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    let rows = (evolution.stats().iter())
        .filter(|s| s.generation >= from)
        .map(|s| TrialRow {
            generation: s.generation,
            best: finite(s.best),
            mean: finite(s.mean),
            iou: finite(
                at.and_then(|at| s.best_terms.get(at).copied())
                    .unwrap_or(0.0),
            ),
        })
        .collect();
    Ok(TrialRecord {
        model: model.to_owned(),
        runoff,
        outcome: Outcome::Reached {
            iou,
            generations: evolution.generation(),
        },
        seconds: begun.elapsed().as_secs_f64(),
        rows,
        checkpoint: Some(evolution.checkpoint()?),
    })
}

/// Keeps `record`, a trial of `model`, in `log` and tells `on`.
fn keep<E>(
    log: &mut TrialLog,
    model: &'static str,
    record: TrialRecord,
    on: &mut impl FnMut(AutoEvent<'_>) -> Result<(), E>,
) -> Result<(), E> {
    let trial = record.trial(model);
    log.trials.push(record);
    on(AutoEvent::Ended {
        trial: &trial,
        log,
        resumed: false,
    })
}

/// Breeds `evolution` `more` (generations, or seconds from now), calling `bred` after each
/// generation, and gives its best IoU. The last generation is bred whole: cut short, the
/// run that goes on would score it again. Only the match's own deadline (`stop`'s) cuts
/// one short, and the trial ends at the last whole generation.
fn trial<E: From<Error>>(
    evolution: &mut Evolution,
    more: Limit,
    stop: &Stop,
    mut bred: impl FnMut(&Evolution) -> Result<(), E>,
) -> Result<f64, E> {
    let (begun, from) = (Instant::now(), evolution.generation());
    let done = |evolution: &Evolution| match more {
        Limit::Generations(n) => evolution.generation() >= from.saturating_add(n),
        Limit::Seconds(_) => more.reached(evolution, begun),
    };
    while !done(evolution) {
        match evolution.step() {
            Ok(_) => bred(evolution)?,
            Err(Error::Stopped(_)) if out_of_time(stop) => break,
            Err(e) => return Err(e.into()),
        }
    }
    Ok(best_iou(evolution))
}

/// A match by the model that matches the outline best ([`AutoMatch::start`], with a new
/// log and the target's relative paths found from the current folder); `on_trial` hears
/// how each model did.
pub fn start_auto(
    registry: &Registry,
    target: &MatchConfig,
    run: &RunConfig,
    limit: Limit,
    pool: &Pool,
    stop: &Stop,
    mut on_trial: impl FnMut(&Trial),
) -> Result<(Evolution, f64), Error> {
    let auto = AutoMatch {
        registry,
        target,
        base: Path::new(""),
        run,
        limit,
        pool,
        stop,
    };
    auto.start(&mut TrialLog::new(), |event| {
        if let AutoEvent::Ended { trial, .. } = event {
            on_trial(trial);
        }
        Ok::<_, Error>(())
    })
}
