//! Evolution runs kept in the archive, shared by the modes that run them (family, design,
//! match and map): a generation's figures as a row, a run's members archived as plants, and
//! runs that go on in the background ([`Background`]: design and match), one thread per
//! run, checkpointing every generation in the transaction that records it, so a server
//! killed at any moment resumes every running run from its last checkpoint when it starts
//! again ([`resume_all`]), to the bytes of a run never stopped.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use serde::Serialize;
use serde_json::json;
use sylva::{Config, Evolution, Member};

use crate::Studio;
use crate::archive::{self, GenerationRow, NewPlant, Operator, RunRow};
use crate::error::ApiError;
use crate::events::SessionEvent;

/// A figure as JSON can hold it (an unscored run's infinities as 0).
pub fn finite(v: f64) -> f64 {
    if v.is_finite() { v } else { 0.0 }
}

/// The last generation's figures.
pub fn generation_row(run: &Evolution) -> GenerationRow {
    let last = run.stats().last();
    GenerationRow {
        generation: run.generation(),
        best: last.map_or(0.0, |s| finite(s.best)),
        mean: last.map_or(0.0, |s| finite(s.mean)),
        best_terms: last.map_or_else(Vec::new, |s| s.best_terms.clone()),
        plant: None,
    }
}

/// Archives a run's member as a plant, once (found again by run and member id), with
/// `extra` fields in its settings (a map's cell).
pub fn archive_member(
    studio: &Studio,
    session: i64,
    run: i64,
    generation: u32,
    member: &Member,
    operator: Operator,
    extra: Option<serde_json::Value>,
) -> Result<i64, ApiError> {
    let text = member.genome.to_json();
    let seed = member.genome.default_seed();
    let mut settings = json!({
        "run": run,
        "generation": generation,
        "member": member.id.0,
        "fitness": finite(member.total()),
    });
    if let Some(serde_json::Value::Object(extra)) = extra {
        for (k, v) in extra {
            settings[k] = v;
        }
    }
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        // A member is known by its run, id and model: the trials of an auto match breed
        // runs of several models under one run, each counting ids from 0.
        let model = member.genome.model();
        let archived = |id: sylva::IndividualId| -> Option<i64> {
            c.query_row(
                "SELECT id FROM plants WHERE session = ?1 AND json_extract(settings, '$.run') = ?2
                 AND json_extract(settings, '$.member') = ?3 AND model = ?4",
                rusqlite::params![session, run, id.0 as i64, model],
                |r| r.get(0),
            )
            .ok()
        };
        if let Some(id) = archived(member.id) {
            return Ok(id);
        }
        // Its parents, where they are archived too.
        let mut parents = Vec::new();
        for p in &member.origin.parents {
            let found = archived(*p);
            if let Some(plant) = found {
                parents.push(archive::ParentRow {
                    plant,
                    dominance: 1.0,
                });
            }
        }
        Ok(archive::insert_plant(
            c,
            &NewPlant {
                session: Some(session),
                model,
                genome: &text,
                seed,
                operator,
                settings: &settings,
                parents: &parents,
            },
        )?)
    })
}

/// What a background run tells the pages watching it: a generation's figures, or a change
/// of status.
#[derive(Clone, Debug)]
pub struct RunEvent {
    /// The run.
    pub run: i64,
    /// running, stopped, done or failed.
    pub status: String,
    /// The generation just made (or the last one).
    pub generation: u32,
    /// Its figures and the names of its terms, for a generation event.
    pub row: Option<(GenerationRow, Vec<String>)>,
    /// Why the run failed.
    pub error: Option<String>,
}

impl RunEvent {
    /// The event's name and its data: one JSON object, each key once. A generation event
    /// carries the terms' names, so a page that followed the run from its start can label
    /// the first row.
    fn to_sse(&self) -> (&'static str, serde_json::Value) {
        let mut data = json!({
            "run": self.run,
            "status": self.status,
            "generation": self.generation,
        });
        if let Some(error) = &self.error {
            data["error"] = json!(error);
        }
        match &self.row {
            Some((row, terms)) => {
                data["best"] = json!(row.best);
                data["mean"] = json!(row.mean);
                data["best_terms"] = json!(row.best_terms);
                data["plant"] = json!(row.plant);
                data["terms"] = json!(terms);
                ("generation", data)
            }
            None => ("status", data),
        }
    }

    /// A status event of `row` as it stands.
    fn status_of(row: &RunRow) -> RunEvent {
        RunEvent {
            run: row.id,
            status: row.status.clone(),
            generation: row.generation,
            row: None,
            error: row.error.clone(),
        }
    }
}

/// Tells the pages watching `session` of a run.
fn tell(studio: &Studio, session: i64, event: RunEvent) {
    let (name, data) = event.to_sse();
    studio.events.send(session, name, data);
}

/// Where run `run` stands, as the first event a page watching its session gets.
pub fn status_event(studio: &Studio, run: i64) -> Result<SessionEvent, ApiError> {
    let (name, data) = RunEvent::status_of(&run_row(studio, run)?).to_sse();
    Ok(SessionEvent { name, data })
}

/// The runs going on in the background (design and match runs, maps), each with the flag
/// that asks it to stop.
#[derive(Default)]
pub struct Runs {
    stops: Mutex<HashMap<i64, Arc<AtomicBool>>>,
}

impl Runs {
    /// Asks every run to stop (at its next generation), leaving their status as it is, so
    /// that they resume when the studio starts again.
    pub fn stop_all(&self) {
        for stop in self
            .stops
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .values()
        {
            stop.store(true, Ordering::SeqCst);
        }
    }

    /// Whether `run`'s thread is going.
    pub fn is_running(&self, run: i64) -> bool {
        self.stops
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .contains_key(&run)
    }

    /// Marks `run` as going, with the flag that asks it to stop; `None` if it is going
    /// already.
    pub fn begin(&self, run: i64) -> Option<Arc<AtomicBool>> {
        let mut stops = self.stops.lock().unwrap_or_else(|p| p.into_inner());
        if stops.contains_key(&run) {
            return None;
        }
        let stop = Arc::new(AtomicBool::new(false));
        stops.insert(run, stop.clone());
        Some(stop)
    }

    /// `run`'s thread has ended.
    pub fn end(&self, run: i64) {
        self.stops
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .remove(&run);
    }

    /// Asks `run` to stop at its next generation, if it is going.
    pub fn stop(&self, run: i64) {
        if let Some(stop) = self
            .stops
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .get(&run)
        {
            stop.store(true, Ordering::SeqCst);
        }
    }
}

/// A run by id.
pub fn run_row(studio: &Studio, run: i64) -> Result<RunRow, ApiError> {
    studio
        .archive
        .read(|c| archive::run(c, run))?
        .ok_or_else(|| ApiError::internal(format!("run {run} is missing")))
}

/// A kind of evolution run that goes on in the background, one thread per run, saving
/// every generation: how its config is read and how a new run begins.
pub trait Background: 'static {
    /// The operator its generations' best plants are archived with.
    const OPERATOR: Operator;

    /// The run's config, from its row (and whatever else it needs: a match run's pictures).
    fn config(studio: &Studio, row: &RunRow) -> Result<Config, ApiError>;

    /// A new run of `config`, generation 0 made; `None` if `stop` was set before it was
    /// (a run with work before its generation 0, as an auto match's trials, watches it).
    fn start(
        studio: &Studio,
        row: &RunRow,
        config: &Config,
        stop: &AtomicBool,
    ) -> Result<Option<Evolution>, ApiError> {
        let _ = (row, stop);
        start_fresh(studio, config)
    }
}

/// A library error in a run: the studio's fault or the run's settings, told as they are.
pub(crate) fn library(e: sylva::Error) -> ApiError {
    ApiError::internal(sylva::error::chain(&e))
}

/// A new run of `config` with nothing before its generation 0 ([`Background::start`]'s
/// default, and a mode's when it has no other work first).
pub(crate) fn start_fresh(studio: &Studio, config: &Config) -> Result<Option<Evolution>, ApiError> {
    Evolution::start(config, Vec::new(), studio.pool.clone())
        .map(Some)
        .map_err(library)
}

/// Starts (or resumes) a background run's thread, unless it is going already.
pub fn spawn<B: Background>(studio: &Studio, run: i64) -> Result<(), ApiError> {
    let Some(stop) = studio.runs.begin(run) else {
        return Ok(());
    };
    let worker = studio.clone();
    let spawned = std::thread::Builder::new()
        .name(format!("sylva-run-{run}"))
        .spawn(move || {
            let result = drive::<B>(&worker, run, &stop);
            worker.runs.end(run);
            if let Err(e) = result {
                let _ = worker.archive.transaction(|c| -> Result<(), ApiError> {
                    let generation = archive::run(c, run)?.map_or(0, |r| r.generation);
                    archive::save_run(c, run, None, generation, "failed", Some(&e.error))?;
                    Ok(())
                });
                if let Ok(row) = run_row(&worker, run) {
                    tell(&worker, row.session, RunEvent::status_of(&row));
                }
            }
        });
    if let Err(e) = spawned {
        studio.runs.end(run);
        return Err(ApiError::internal(format!("starting a run: {e}")));
    }
    Ok(())
}

/// Runs a run until it is done or asked to stop, saving every generation.
fn drive<B: Background>(studio: &Studio, run: i64, stop: &AtomicBool) -> Result<(), ApiError> {
    let row = run_row(studio, run)?;
    let config = B::config(studio, &row)?;
    let path = std::path::Path::new("checkpoint");
    let mut evolution = match &row.checkpoint {
        Some(text) => {
            Evolution::resume(&config, path, text, studio.pool.clone()).map_err(library)?
        }
        None => {
            let Some(evolution) = B::start(studio, &row, &config, stop)? else {
                return Ok(());
            };
            studio.archive.transaction(|c| -> Result<_, ApiError> {
                Ok(archive::set_run_terms(c, run, evolution.term_names())?)
            })?;
            save_generation::<B>(studio, &row, &evolution, stop)?;
            evolution
        }
    };
    loop {
        let generations = run_row(studio, run)?.generations;
        if stop.load(Ordering::SeqCst) {
            return Ok(());
        }
        if evolution.generation() >= generations {
            studio.archive.transaction(|c| {
                archive::save_run(c, run, None, evolution.generation(), "done", None)
                    .map_err(ApiError::from)
            })?;
            tell(
                studio,
                row.session,
                RunEvent::status_of(&run_row(studio, run)?),
            );
            return Ok(());
        }
        evolution.step().map_err(library)?;
        save_generation::<B>(studio, &row, &evolution, stop)?;
    }
}

/// Archives a generation's best, its figures and the checkpoint, in one transaction; then
/// tells the pages watching.
fn save_generation<B: Background>(
    studio: &Studio,
    row: &RunRow,
    evolution: &Evolution,
    stop: &AtomicBool,
) -> Result<(), ApiError> {
    let best = evolution.best();
    let generation = evolution.generation();
    let plant = archive_member(
        studio,
        row.session,
        row.id,
        generation,
        &best,
        B::OPERATOR,
        None,
    )?;
    let checkpoint = evolution.checkpoint().map_err(library)?;
    let mut figures = generation_row(evolution);
    figures.plant = Some(plant);
    let status = studio.archive.transaction(|c| -> Result<_, ApiError> {
        archive::insert_generation(c, row.id, &figures)?;
        // Read under the archive's lock: a stop acknowledged before this commit is kept.
        let status = if stop.load(Ordering::SeqCst) {
            archive::run(c, row.id)?.map_or_else(|| "stopped".to_owned(), |r| r.status)
        } else {
            "running".to_owned()
        };
        archive::save_run(c, row.id, Some(&checkpoint), generation, &status, None)?;
        Ok(status)
    })?;
    let event = RunEvent {
        run: row.id,
        status,
        generation,
        row: Some((figures, evolution.term_names().to_vec())),
        error: None,
    };
    tell(studio, row.session, event);
    Ok(())
}

/// Stops a run: marked stopped now (so a restart does not resume it), and its thread ends
/// after the generation it is making. Tells the pages watching.
pub fn stop_run(studio: &Studio, run: i64) -> Result<(), ApiError> {
    studio.runs.stop(run);
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        let row = archive::run(c, run)?.ok_or_else(|| ApiError::not_found(format!("run {run}")))?;
        if row.status == "running" {
            archive::set_run_status(c, run, "stopped")?;
        }
        Ok(())
    })?;
    let row = run_row(studio, run)?;
    tell(studio, row.session, RunEvent::status_of(&row));
    Ok(())
}

/// A stopped (or done) run goes on, to `generations` in all if given (1 to `max`).
pub async fn resume_run<B: Background>(
    studio: &Studio,
    run: i64,
    generations: Option<u32>,
    max: u32,
) -> Result<(), ApiError> {
    ready_to_resume(studio, run, generations, max).await?;
    spawn::<B>(studio, run)
}

/// Checks that a stopped (or done) run may go on to `generations` in all if given (1 to
/// `max`), waits for its thread to finish the generation it was making, and marks it
/// running again: its thread is the caller's to start.
pub async fn ready_to_resume(
    studio: &Studio,
    run: i64,
    generations: Option<u32>,
    max: u32,
) -> Result<(), ApiError> {
    let row = run_row(studio, run)?;
    let generations = generations.unwrap_or(row.generations);
    if !(1..=max).contains(&generations) {
        return Err(ApiError::bad(
            "generations",
            format!("expected 1 to {max}, got {generations}"),
        ));
    }
    if row.status == "failed" {
        return Err(ApiError::conflict(format!(
            "the run failed ({}); start a new one",
            row.error.unwrap_or_default()
        )));
    }
    if studio.runs.is_running(row.id) && row.status == "running" {
        return Err(ApiError::conflict("the run is running"));
    }
    if row.generation >= generations {
        return Err(ApiError::conflict(format!(
            "the run has made its {generations} generations; ask for more with `generations`"
        )));
    }
    // A run still finishing its generation after a stop ends first.
    for _ in 0..600 {
        if !studio.runs.is_running(row.id) {
            break;
        }
        tokio::time::sleep(std::time::Duration::from_millis(50)).await;
    }
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        archive::set_run_generations(c, row.id, generations)?;
        archive::set_run_status(c, row.id, "running")?;
        Ok(())
    })
}

/// A background run as the page shows it: `GET /api/sessions/{id}/run`.
#[derive(Serialize)]
pub struct RunView {
    run: i64,
    status: String,
    generation: u32,
    generations: u32,
    terms: Vec<String>,
    rows: Vec<GenerationRow>,
    error: Option<String>,
}

/// Run `run` with its figures.
pub fn run_view(studio: &Studio, run: i64) -> Result<RunView, ApiError> {
    let (row, terms, rows) = studio.archive.read(|c| {
        let row = archive::run(c, run)?;
        let terms = archive::run_terms(c, run)?;
        let rows = archive::generations(c, run, u32::MAX)?;
        Ok((row, terms, rows))
    })?;
    let row = row.ok_or_else(|| ApiError::internal(format!("run {run} is missing")))?;
    Ok(RunView {
        run: row.id,
        status: row.status,
        generation: row.generation,
        generations: row.generations,
        terms,
        rows,
        error: row.error,
    })
}

/// Resumes every run of the sessions of `mode` that was running when the studio stopped
/// (or was killed).
pub fn resume_all<B: Background>(studio: &Studio, mode: &str) {
    let Ok(runs) = studio
        .archive
        .read(|c| archive::runs_of_mode(c, mode, "running"))
    else {
        return;
    };
    for run in runs {
        let _ = spawn::<B>(studio, run.id);
    }
}
