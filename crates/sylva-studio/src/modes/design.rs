//! Design mode, the GP designer: a target surface, favoured and forbidden cells of the
//! density grid and the weights become an evolution of automata trees that runs in the
//! background, one thread per run, and shows each generation's best as it comes.
//!
//! A run goes on in the background as [`runs`](crate::runs) keeps it: checkpointed every
//! generation, resumed after a kill ([`resume_all`]) to the bytes of a run never stopped.

use std::path::Path as FilePath;

use axum::Json;
use axum::extract::{Path, State};
use serde::{Deserialize, Serialize};
use serde_json::json;
use sylva::{Config, Registry};

use crate::Studio;
use crate::archive::{self, ModeName, Operator, RunRow};
use crate::error::ApiError;
use crate::events::SessionEvent;
use crate::http::{Body, first_null, join};
use crate::modes::Mode;
use crate::runs::{self, Background};
use crate::sessions::{SessionView, session_of, view};

const AUTOMATA: &str = sylva::registry::names::AUTOMATA;

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
fn config_of(registry: &Registry, design: &Design, at: &str) -> Result<(Config, u32), ApiError> {
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
    let config = registry
        .config_from_value(doc)
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
    let (config, generations) = config_of(&studio.registry, &start.design, "design")?;
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
    runs::spawn::<DesignMode>(studio, run)?;
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
    let (config, generations) = config_of(&studio.registry, &design, "")?;
    runs::stop_run(&studio, before.run)?;
    let run = studio.archive.transaction(|c| -> Result<_, ApiError> {
        let run = archive::insert_run(c, id, &config.to_toml(), generations)?;
        let after = DesignState {
            run,
            design: json!(design),
        };
        archive::set_state(c, id, &json!(after))?;
        Ok(run)
    })?;
    runs::spawn::<DesignMode>(&studio, run)?;
    Ok(Json(view(&studio, id)?))
}

fn design_state(studio: &Studio, id: i64) -> Result<DesignState, ApiError> {
    let row = session_of(studio, id, ModeName::Design)?;
    serde_json::from_value(row.state)
        .map_err(|e| ApiError::internal(format!("session {id}'s state: {e}")))
}

/// `POST /api/sessions/{id}/stop`.
pub(crate) async fn stop(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<SessionView>, ApiError> {
    let state = design_state(&studio, id)?;
    runs::stop_run(&studio, state.run)?;
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
    runs::resume_run::<DesignMode>(&studio, state.run, request.generations, 1000).await?;
    Ok(Json(view(&studio, id)?))
}

/// `GET /api/sessions/{id}/run`.
pub(crate) async fn run(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<runs::RunView>, ApiError> {
    let state = design_state(&studio, id)?;
    Ok(Json(runs::run_view(&studio, state.run)?))
}

/// Resumes every design run that was running when the studio stopped (or was killed).
pub fn resume_all(studio: &Studio) {
    runs::resume_all::<DesignMode>(studio, ModeName::Design);
}

impl Background for DesignMode {
    const OPERATOR: Operator = Operator::Design;

    fn config(studio: &Studio, row: &RunRow) -> Result<Config, ApiError> {
        (studio.registry)
            .parse_config(FilePath::new("design"), &row.config)
            .map_err(|e| ApiError::internal(e.message))
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
        let state = design_state(studio, session)?;
        runs::status_event(studio, state.run).map(Some)
    }
}
