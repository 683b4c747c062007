//! Design mode, the GP designer: a target surface, favoured and forbidden cells of the
//! density grid and the weights become an evolution of automata trees that runs in the
//! background, one thread per run, and shows each generation's best as it comes.
//!
//! A run checkpoints to the archive after every generation, in the transaction that records
//! the generation, so a server killed at any moment resumes every running run from its last
//! checkpoint when it starts again ([`resume_all`]), to the bytes of a run never stopped.

use std::collections::HashMap;
use std::path::Path as FilePath;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use axum::Json;
use axum::extract::{Path, State};
use serde::{Deserialize, Serialize};
use serde_json::json;
use sylva::{Config, Evolution};

use crate::Studio;
use crate::archive::{self, GenerationRow, ModeName, Operator, RunRow};
use crate::error::ApiError;
use crate::events::SessionEvent;
use crate::http::{Body, first_null, join};
use crate::modes::Mode;
use crate::runs::{archive_member, generation_row};
use crate::sessions::{SessionView, session_of, view};

const AUTOMATA: &str = sylva::registry::names::AUTOMATA;

/// What a run tells the pages watching it: a generation's figures, or a change of status.
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
}

/// Tells the pages watching `session` of a run.
fn tell(studio: &Studio, session: i64, event: RunEvent) {
    let (name, data) = event.to_sse();
    studio.events.send(session, name, data);
}

/// Where a design session's run stands, as the first event a page watching it gets.
pub fn status_event(studio: &Studio, session: i64) -> Result<SessionEvent, ApiError> {
    let state = design_state(studio, session)?;
    let row = run_row(studio, state.run)?;
    let (name, data) = RunEvent {
        run: row.id,
        status: row.status,
        generation: row.generation,
        row: None,
        error: row.error,
    }
    .to_sse();
    Ok(SessionEvent { name, data })
}

/// The runs going on (design runs and maps).
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

    pub(crate) fn is_running(&self, run: i64) -> bool {
        self.stops
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .contains_key(&run)
    }

    /// Marks `run` as going, with the flag that asks it to stop; `None` if it is going
    /// already.
    pub(crate) fn begin(&self, run: i64) -> Option<Arc<AtomicBool>> {
        let mut stops = self.stops.lock().unwrap_or_else(|p| p.into_inner());
        if stops.contains_key(&run) {
            return None;
        }
        let stop = Arc::new(AtomicBool::new(false));
        stops.insert(run, stop.clone());
        Some(stop)
    }

    /// `run`'s thread has ended.
    pub(crate) fn end(&self, run: i64) {
        self.stops
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .remove(&run);
    }

    /// Asks `run` to stop at its next generation, if it is going.
    pub(crate) fn stop(&self, run: i64) {
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

/// A design: the target, the grid's cells, the weights and the run's size.
#[derive(Deserialize, Serialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct Design {
    /// `[automata.fitness.target]`: a shape and its fields, paper units.
    target: Option<serde_json::Value>,
    /// The density grid, if any.
    grid: Option<GridDesign>,
    /// `[automata.fitness.weights]`.
    weights: Option<serde_json::Value>,
    /// Branches wanted, 1 to 1000. Default 30.
    num_target: Option<u32>,
    /// Individuals, 10 to 20000. Default 1000.
    population: Option<u32>,
    /// Generations, 1 to 1000. Default 50.
    generations: Option<u32>,
    /// The run's seed. Default 1.
    seed: Option<u64>,
}

/// A density grid with painted cells.
#[derive(Deserialize, Serialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct GridDesign {
    min: [f64; 3],
    max: [f64; 3],
    divisions: [u32; 3],
    #[serde(default)]
    cells: Vec<PaintedCell>,
    target: Option<u32>,
}

/// A painted cell: weight 1 favoured, −1 forbidden.
#[derive(Deserialize, Serialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct PaintedCell {
    cell: [u32; 3],
    weight: f64,
}

/// `POST /api/sessions` in design mode.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct Start {
    design: Design,
}

/// A design session's view.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct DesignState {
    /// The run.
    pub run: i64,
    /// The design it runs.
    pub design: serde_json::Value,
}

/// Checks a count against its range, naming `field` (its JSON path in the request).
fn range(value: u32, lo: u32, hi: u32, field: &str) -> Result<u32, ApiError> {
    if (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(ApiError::bad(
            field,
            format!("expected {lo} to {hi}, got {value}"),
        ))
    }
}

/// The config a design stands for: Poncin's typical run (`examples/automata/sphere.toml`)
/// with the design's target, grid, weights and size.
/// Errors name fields under `at`, the design's JSON path in the request (`design` when
/// creating a session, "" when the body is the design).
fn config_of(design: &Design, at: &str) -> Result<(Config, u32), ApiError> {
    let field = |name: &str| join(at, name);
    let population = range(
        design.population.unwrap_or(1000),
        10,
        20_000,
        &field("population"),
    )?;
    let generations = range(
        design.generations.unwrap_or(50),
        1,
        1000,
        &field("generations"),
    )?;
    let num_target = range(
        design.num_target.unwrap_or(30),
        1,
        1000,
        &field("num_target"),
    )?;
    let mut fitness = json!({
        "unit": 0.1,
        "num_target": num_target,
        "endpoints": "axes",
        "weights": { "pos": 5.0, "num": 50.0, "dist": 200.0, "thick": 0.0, "angle": 0.0,
                     "grid": if design.grid.is_some() { 10.0 } else { 0.0 } },
        "target": { "shape": "sphere", "center": [0.0, 200.0, 0.0], "radius": 150.0 },
    });
    for (part, value) in [("target", &design.target), ("weights", &design.weights)] {
        if let Some(null) = value.as_ref().and_then(|v| first_null(v, &field(part))) {
            return Err(ApiError::bad(
                null,
                "null is not a value: leave the field out",
            ));
        }
    }
    if let Some(grid) = &design.grid {
        check_cells(grid, &field("grid"))?;
    }
    if let Some(target) = &design.target {
        fitness["target"] = target.clone();
    }
    if let Some(serde_json::Value::Object(weights)) = &design.weights {
        for (k, v) in weights {
            fitness["weights"][k] = v.clone();
        }
    } else if design.weights.is_some() {
        return Err(ApiError::bad(
            field("weights"),
            "expected an object of weights",
        ));
    }
    if let Some(grid) = &design.grid {
        let cells: Vec<serde_json::Value> = grid
            .cells
            .iter()
            .map(|c| json!({ "at": c.cell, "weight": c.weight }))
            .collect();
        fitness["grid"] = json!({
            "min": grid.min, "max": grid.max, "divisions": grid.divisions,
            "weight": 0.0, "target": grid.target.unwrap_or(15), "cells": cells,
        });
    }
    let doc = json!({
        "model": AUTOMATA,
        "run": { "generations": generations, "population": population,
                 "seed": design.seed.unwrap_or(1) },
        "automata": {
            "automata": 2,
            "breeding": { "mutation": 0.1, "reproduction": 0.02, "reevaluate": false },
            "growth": { "iterations": 100, "root_length": 2.5, "leaf_length": 10.0 },
            "fitness": fitness,
        },
    });
    let config = Config::from_value(doc)
        .map_err(|e| ApiError::unprocessable(join(at, &design_field(&e.field)), e.message))?;
    Ok((config, generations))
}

/// The design's field behind a field of the config it becomes (`automata.fitness.target.radius`
/// is `target.radius`, `automata.fitness.grid.cells[2].at` is `grid.cells[2].cell`); the
/// design as a whole for a field the studio sets itself.
fn design_field(config: &str) -> String {
    let field = match config {
        "run.population" => "population",
        "run.generations" => "generations",
        "run.seed" => "seed",
        "automata.fitness.num_target" => "num_target",
        path => match path.strip_prefix("automata.fitness.") {
            Some(rest)
                if ["target", "weights", "grid"].iter().any(|part| {
                    rest == *part
                        || rest.starts_with(&format!("{part}."))
                        || rest.starts_with(&format!("{part}["))
                }) =>
            {
                return rest
                    .strip_suffix(".at")
                    .map_or_else(|| rest.to_owned(), |cell| format!("{cell}.cell"));
            }
            _ => "",
        },
    };
    field.to_owned()
}

/// Checks painted cells against the grid, naming the cell (the config would only know the
/// grid's list of cells).
fn check_cells(grid: &GridDesign, at: &str) -> Result<(), ApiError> {
    for (i, c) in grid.cells.iter().enumerate() {
        if let Some(axis) = (0..3).find(|&a| c.cell[a] >= grid.divisions[a]) {
            return Err(ApiError::bad(
                format!("{at}.cells[{i}].cell[{axis}]"),
                format!(
                    "expected 0 to {} (the grid has {} divisions along it), got {}",
                    grid.divisions[axis].saturating_sub(1),
                    grid.divisions[axis],
                    c.cell[axis]
                ),
            ));
        }
        if !(c.weight.is_finite() && (-1e6..=1e6).contains(&c.weight)) {
            return Err(ApiError::bad(
                format!("{at}.cells[{i}].weight"),
                format!(
                    "expected a number from -1000000 to 1000000, got {}",
                    c.weight
                ),
            ));
        }
    }
    Ok(())
}

/// Creates a design session and starts its run.
async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
    let (config, generations) = config_of(&start.design, "design")?;
    let (id, run) = studio.archive.transaction(|c| -> Result<_, ApiError> {
        let id = archive::insert_session(c, ModeName::Design, AUTOMATA, "Design", &json!({}))?;
        let run = archive::insert_run(c, id, &config.to_toml(), generations)?;
        let state = DesignState {
            run,
            design: json!(start.design),
        };
        archive::set_state(c, id, &json!(state))?;
        Ok((id, run))
    })?;
    spawn(studio, run)?;
    Ok(id)
}

/// `POST /api/sessions/{id}/design`: a new run of a new design in the session; the old
/// one stops.
pub(crate) async fn redesign(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(design): Body<Design>,
) -> Result<Json<SessionView>, ApiError> {
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let before = design_state(&studio, id)?;
    let (config, generations) = config_of(&design, "")?;
    stop_run(&studio, before.run)?;
    let run = studio.archive.transaction(|c| -> Result<_, ApiError> {
        let run = archive::insert_run(c, id, &config.to_toml(), generations)?;
        let after = DesignState {
            run,
            design: json!(design),
        };
        archive::set_state(c, id, &json!(after))?;
        Ok(run)
    })?;
    spawn(&studio, run)?;
    Ok(Json(view(&studio, id)?))
}

fn design_state(studio: &Studio, id: i64) -> Result<DesignState, ApiError> {
    let row = session_of(studio, id, ModeName::Design)?;
    serde_json::from_value(row.state)
        .map_err(|e| ApiError::internal(format!("session {id}'s state: {e}")))
}

fn run_row(studio: &Studio, run: i64) -> Result<RunRow, ApiError> {
    studio
        .archive
        .read(|c| archive::run(c, run))?
        .ok_or_else(|| ApiError::internal(format!("run {run} is missing")))
}

/// Starts (or resumes) a run's thread, unless it is going already.
fn spawn(studio: &Studio, run: i64) -> Result<(), ApiError> {
    let Some(stop) = studio.runs.begin(run) else {
        return Ok(());
    };
    let worker = studio.clone();
    let spawned = std::thread::Builder::new()
        .name(format!("sylva-run-{run}"))
        .spawn(move || {
            let result = drive(&worker, run, &stop);
            worker.runs.end(run);
            if let Err(e) = result {
                let _ = worker.archive.transaction(|c| -> Result<(), ApiError> {
                    let row = archive::run(c, run)?;
                    let generation = row.map_or(0, |r| r.generation);
                    archive::save_run(c, run, None, generation, "failed", Some(&e.error))?;
                    Ok(())
                });
                if let Ok(row) = run_row(&worker, run) {
                    let event = RunEvent {
                        run,
                        status: "failed".into(),
                        generation: row.generation,
                        row: None,
                        error: Some(e.error),
                    };
                    tell(&worker, row.session, event);
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
fn drive(studio: &Studio, run: i64, stop: &AtomicBool) -> Result<(), ApiError> {
    let row = run_row(studio, run)?;
    let path = FilePath::new("design");
    let config = Config::parse(path, &row.config).map_err(|e| ApiError::internal(e.message))?;
    let mut evolution = match &row.checkpoint {
        Some(text) => Evolution::resume(&config, path, text, studio.pool.clone())
            .map_err(|e| ApiError::internal(sylva::error::chain(&e)))?,
        None => {
            let evolution = Evolution::start(&config, Vec::new(), studio.pool.clone())
                .map_err(|e| ApiError::internal(sylva::error::chain(&e)))?;
            studio.archive.transaction(|c| -> Result<_, ApiError> {
                Ok(archive::set_run_terms(c, run, evolution.term_names())?)
            })?;
            save_generation(studio, &row, &evolution, stop)?;
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
            let done = RunEvent {
                run,
                status: "done".into(),
                generation: evolution.generation(),
                row: None,
                error: None,
            };
            tell(studio, row.session, done);
            return Ok(());
        }
        evolution
            .step()
            .map_err(|e| ApiError::internal(sylva::error::chain(&e)))?;
        save_generation(studio, &row, &evolution, stop)?;
    }
}

/// Archives a generation's best, its figures and the checkpoint, in one transaction; then
/// tells the pages watching.
fn save_generation(
    studio: &Studio,
    row: &RunRow,
    evolution: &Evolution,
    stop: &AtomicBool,
) -> Result<(), ApiError> {
    let best = evolution.best();
    let plant = archive_member(
        studio,
        row.session,
        row.id,
        evolution.generation(),
        &best,
        Operator::Design,
        None,
    )?;
    let checkpoint = evolution
        .checkpoint()
        .map_err(|e| ApiError::internal(sylva::error::chain(&e)))?;
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
        archive::save_run(
            c,
            row.id,
            Some(&checkpoint),
            evolution.generation(),
            &status,
            None,
        )?;
        Ok(status)
    })?;
    let event = RunEvent {
        run: row.id,
        status,
        generation: evolution.generation(),
        row: Some((figures, evolution.term_names().to_vec())),
        error: None,
    };
    tell(studio, row.session, event);
    Ok(())
}

/// Stops a run: marked stopped now (so a restart does not resume it), and its thread ends
/// after the generation it is making.
fn stop_run(studio: &Studio, run: i64) -> Result<(), ApiError> {
    studio.runs.stop(run);
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        let row = archive::run(c, run)?.ok_or_else(|| ApiError::not_found(format!("run {run}")))?;
        if row.status == "running" {
            archive::set_run_status(c, run, "stopped")?;
        }
        Ok(())
    })
}

/// `POST /api/sessions/{id}/stop`.
pub(crate) async fn stop(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<SessionView>, ApiError> {
    let state = design_state(&studio, id)?;
    stop_run(&studio, state.run)?;
    let row = run_row(&studio, state.run)?;
    let event = RunEvent {
        run: row.id,
        status: row.status,
        generation: row.generation,
        row: None,
        error: None,
    };
    tell(&studio, id, event);
    Ok(Json(view(&studio, id)?))
}

/// `POST /api/sessions/{id}/resume`.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct ResumeRequest {
    /// Run to this many generations in all (more than asked at first, to go on), 1 to 1000.
    generations: Option<u32>,
}

/// `POST /api/sessions/{id}/resume`: a stopped (or done) run goes on.
pub(crate) async fn resume(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<ResumeRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let state = design_state(&studio, id)?;
    let row = run_row(&studio, state.run)?;
    let generations = match request.generations {
        Some(g) => range(g, 1, 1000, "generations")?,
        None => row.generations,
    };
    if row.status == "failed" {
        return Err(ApiError::conflict(format!(
            "the run failed ({}); start a new design",
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
    })?;
    spawn(&studio, row.id)?;
    Ok(Json(view(&studio, id)?))
}

#[derive(Serialize)]
pub(crate) struct RunView {
    run: i64,
    status: String,
    generation: u32,
    generations: u32,
    terms: Vec<String>,
    rows: Vec<GenerationRow>,
    error: Option<String>,
}

/// `GET /api/sessions/{id}/run`.
pub(crate) async fn run(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<RunView>, ApiError> {
    let state = design_state(&studio, id)?;
    let (row, terms, rows) = studio.archive.read(|c| {
        let row = archive::run(c, state.run)?;
        let terms = archive::run_terms(c, state.run)?;
        let rows = archive::generations(c, state.run, u32::MAX)?;
        Ok((row, terms, rows))
    })?;
    let row = row.ok_or_else(|| ApiError::internal(format!("run {} is missing", state.run)))?;
    Ok(Json(RunView {
        run: row.id,
        status: row.status,
        generation: row.generation,
        generations: row.generations,
        terms,
        rows,
        error: row.error,
    }))
}

/// Resumes every run that was running when the studio stopped (or was killed).
pub fn resume_all(studio: &Studio) {
    let Ok(runs) = studio
        .archive
        .read(|c| archive::runs_of_mode(c, ModeName::Design, "running"))
    else {
        return;
    };
    for run in runs {
        let _ = spawn(studio, run.id);
    }
}

/// Design mode, behind the studio's mode seam.
pub struct DesignMode;

impl Mode for DesignMode {
    const NAME: ModeName = ModeName::Design;
    type Start = Start;

    fn models(_: &sylva::Registry) -> Vec<&'static str> {
        vec![AUTOMATA]
    }

    async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
        create(studio, start).await
    }

    fn routes() -> axum::Router<Studio> {
        use axum::routing::{get, post};
        axum::Router::new()
            .route("/sessions/{id}/design", post(redesign))
            .route("/sessions/{id}/stop", post(stop))
            .route("/sessions/{id}/resume", post(resume))
            .route("/sessions/{id}/run", get(run))
    }

    fn first_event(studio: &Studio, session: i64) -> Result<Option<SessionEvent>, ApiError> {
        status_event(studio, session).map(Some)
    }
}
