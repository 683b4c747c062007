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
use sylva::core::glam::DVec3;
use sylva::models::{
    AutomataModel, AutomataSettings, DensityGrid, EndpointRule, GenerationalSettings, GridCell,
    GridConfig, Growth, NumTarget, PAPER_TARGET, PoncinFitness, PoncinWeights, TargetShape,
};
use sylva::{Config, EvolveConfig, RunConfig};

use crate::Studio;
use crate::archive::{self, Operator, RunRow};
use crate::error::ApiError;
use crate::events::SessionEvent;
use crate::http::{Body, first_null, join};
use crate::modes::{Mode, Route};
use crate::runs::{self, Background};
use crate::sessions::{SessionView, session_of, view};
use crate::settings;

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
/// with the design's target, grid, weights and size, built as the automata model's typed
/// settings. Errors name fields under `at`, the design's JSON path in the request (`design`
/// when creating a session, "" when the body is the design).
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
    let target = match &design.target {
        Some(target) => settings::read(target.clone(), &field("target"))?,
        None => TargetShape::default(),
    };
    // Table 2's weights; the grid's counts only when there is a grid.
    let weights = PoncinWeights {
        grid: if design.grid.is_some() { 10.0 } else { 0.0 },
        ..PoncinWeights::TABLE_2
    };
    let weights = match &design.weights {
        None => weights,
        Some(serde_json::Value::Object(changes)) => {
            settings::overlay(&weights, changes, &field("weights"))?
        }
        Some(_) => {
            return Err(ApiError::bad(
                field("weights"),
                "expected an object of weights",
            ));
        }
    };
    let grid = match &design.grid {
        Some(grid) => Some(settings::checked_as::<DensityGrid>(
            &grid_config(grid),
            &field("grid"),
        )?),
        None => None,
    };
    let typed = EvolveConfig::<AutomataModel> {
        run: RunConfig {
            generations,
            population,
            seed: design.seed.unwrap_or(1),
            ..RunConfig::default()
        },
        settings: AutomataSettings {
            automata: 2,
            breeding: GenerationalSettings {
                mutation: 0.1,
                reproduction: 0.02,
                reevaluate: false,
                ..GenerationalSettings::default()
            },
            growth: Growth {
                iterations: 100,
                root_length: 2.5,
                leaf_length: 10.0,
                ..Growth::default()
            },
            fitness: PoncinFitness {
                unit: 0.1,
                num_target: NumTarget::Total(num_target),
                endpoints: EndpointRule::Axes,
                weights,
                target,
                grid,
                ..PoncinFitness::default()
            },
            ..AutomataSettings::default()
        },
        ..EvolveConfig::default()
    };
    Ok((Config::new(typed), generations))
}

/// The density grid a painted grid stands for: every cell unweighted, the painted ones
/// favoured or forbidden.
fn grid_config(grid: &GridDesign) -> GridConfig {
    GridConfig {
        min: DVec3::from_array(grid.min),
        max: DVec3::from_array(grid.max),
        divisions: grid.divisions,
        weight: 0.0,
        target: grid.target.unwrap_or(PAPER_TARGET),
        boxes: Vec::new(),
        cells: grid
            .cells
            .iter()
            .map(|c| GridCell {
                at: c.cell,
                weight: c.weight,
                target: None,
            })
            .collect(),
    }
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
        let id = archive::insert_session(c, DesignMode::NAME, AUTOMATA, "Design", &json!({}))?;
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
    let (config, generations) = config_of(&design, "")?;
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
    let row = session_of(studio, id, DesignMode::NAME)?;
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
    const NAME: &'static str = "design";
    type Start = Start;

    fn models(_: &sylva::Registry) -> Vec<&'static str> {
        vec![AUTOMATA]
    }

    async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
        create(studio, start).await
    }

    fn routes() -> Vec<Route> {
        vec![
            Route::post("/sessions/{id}/design", redesign),
            Route::post("/sessions/{id}/stop", stop),
            Route::post("/sessions/{id}/resume", resume),
            Route::get("/sessions/{id}/run", run),
        ]
    }

    fn first_event(studio: &Studio, session: i64) -> Result<Option<SessionEvent>, ApiError> {
        let state = design_state(studio, session)?;
        runs::status_event(studio, state.run).map(Some)
    }

    /// Resumes every design run that was running when the studio stopped (or was killed).
    fn resume(studio: &Studio) {
        runs::resume_all::<DesignMode>(studio, Self::NAME);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn design(value: serde_json::Value) -> Design {
        serde_json::from_value(value).expect("a design")
    }

    #[test]
    fn the_default_design_is_poncin_s_typical_run_with_longer_leaves() {
        let (config, generations) = config_of(&design(json!({})), "design").unwrap();
        let example = sylva::Registry::standard()
            .parse_config(
                FilePath::new("sphere.toml"),
                include_str!("../../../../examples/automata/sphere.toml"),
            )
            .unwrap();
        let (ours, theirs) = (
            config.get::<AutomataModel>().unwrap(),
            example.get::<AutomataModel>().unwrap(),
        );
        assert_eq!(generations, 50);
        assert_eq!(ours.run, theirs.run);
        let mut expected = theirs.settings.clone();
        // Leaves long enough to see in the studio's views.
        expected.growth.leaf_length = 10.0;
        assert_eq!(ours.settings, expected);
    }

    #[test]
    fn a_painted_grid_weighs_in_and_is_held_to_its_ranges() {
        let grid = json!({"min": [-150, 0, -150], "max": [150, 375, 150], "divisions": [5, 5, 5],
                          "cells": [{"cell": [2, 2, 2], "weight": 1}, {"cell": [0, 4, 0], "weight": -1}]});
        let (config, _) = config_of(
            &design(json!({"grid": grid, "weights": {"pos": 7}})),
            "design",
        )
        .unwrap();
        let fitness = &config.get::<AutomataModel>().unwrap().settings.fitness;
        assert_eq!(
            (
                fitness.weights.grid,
                fitness.weights.pos,
                fitness.weights.dist
            ),
            (10.0, 7.0, 200.0)
        );
        let grid = fitness.grid.as_ref().unwrap().config();
        assert_eq!((grid.weight, grid.target), (0.0, PAPER_TARGET));
        let painted: Vec<_> = grid.cells.iter().map(|c| (c.at, c.weight)).collect();
        assert_eq!(painted, [([2, 2, 2], 1.0), ([0, 4, 0], -1.0)]);

        let far = json!({"grid": {"min": [-2e6, 0, 0], "max": [1, 1, 1], "divisions": [2, 2, 2]}});
        let e = config_of(&design(far), "design").unwrap_err();
        assert_eq!(
            (e.status.as_u16(), e.field.as_str()),
            (422, "design.grid.min"),
            "{e}"
        );
        let fine = json!({"grid": {"min": [0, 0, 0], "max": [1, 1, 1], "divisions": [2000, 1, 1]}});
        let e = config_of(&design(fine), "").unwrap_err();
        assert_eq!(
            (e.status.as_u16(), e.field.as_str()),
            (422, "grid.divisions"),
            "{e}"
        );
        let flat = json!({"grid": {"min": [0, 0, 0], "max": [1, 0, 1], "divisions": [2, 2, 2]}});
        let e = config_of(&design(flat), "design").unwrap_err();
        assert_eq!(
            (e.status.as_u16(), e.field.as_str()),
            (422, "design.grid.max"),
            "{e}"
        );
    }
}
