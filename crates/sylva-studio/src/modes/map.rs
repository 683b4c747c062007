//! Map mode: a variety map (MAP-Elites, docs/varieties.md) of any model, filled in the
//! background, one thread per run, its cells appearing on the page as they fill.
//!
//! A map starts from the model's example map (`examples/MODEL/varieties.toml`, built into
//! the binary: its fitness, batch and start genomes), with the person's two descriptors,
//! generations and seed. Each filled cell's elite is archived as a plant (so it can be
//! opened, branched into a breeding session and exported like any plant), and the run
//! checkpoints to the archive at most a second apart, at a stop and at its end, in the
//! transaction that records the cells, so a server killed at any moment resumes the map
//! from its last checkpoint when it starts again ([`resume_all`]), to the bytes of a run
//! never stopped.

use std::collections::HashMap;
use std::path::Path as FilePath;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use axum::Json;
use axum::extract::{Path, State};
use serde::{Deserialize, Serialize};
use serde_json::json;
use sylva::evolution::{AxisConfig, Descriptor};
use sylva::{Config, Genome, Varieties};

use crate::Studio;
use crate::archive::{self, GenerationRow, Operator, RunRow};
use crate::error::ApiError;
use crate::events::SessionEvent;
use crate::http::Body;
use crate::modes::{Mode, Route};
use crate::runs::{self, archive_member, finite};
use crate::sessions::{SessionView, example, example_text, session_of, view};

/// Most cells along an axis the page draws.
const MAX_CELLS: u32 = 32;

/// Most generations a map is asked for.
const MAX_GENERATIONS: u32 = 100_000;

/// Longest a run goes without a checkpoint (and its page without news).
const SAVE_EVERY: Duration = Duration::from_secs(1);

/// The figures a map run keeps per saved generation, as the terms of its rows.
const FIGURES: [&str; 3] = ["filled", "coverage", "qd_score"];

/// One axis of a map as the person sets it.
#[derive(Deserialize, Serialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct AxisDesign {
    /// The descriptor's name.
    name: String,
    /// Cells along it, 1 to 32. Default 10.
    cells: Option<u32>,
    /// Its range, low then high. Default the descriptor's own.
    range: Option<[f64; 2]>,
}

/// A map: the model, its axes, and the run's length and seed.
#[derive(Deserialize, Serialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct MapDesign {
    /// The model whose plants fill it.
    model: String,
    /// The axis left to right.
    x: AxisDesign,
    /// The axis bottom to top; none for a map of one row.
    y: Option<AxisDesign>,
    /// Generations, 1 to 100,000. Default the example map's (or 200).
    generations: Option<u32>,
    /// The run's seed. Default 1.
    seed: Option<u64>,
}

/// `POST /api/sessions` in map mode.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct Start {
    map: MapDesign,
}

/// An axis as the page draws it.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct AxisView {
    name: String,
    min: f64,
    max: f64,
    cells: u32,
}

/// A map session's state.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct MapState {
    /// The run.
    pub run: i64,
    /// The map it fills.
    pub design: MapDesign,
    /// Its axes, ranges resolved.
    pub axes: Vec<AxisView>,
}

/// The config a map stands for, its axes and its generations. Errors name fields under
/// `map`, as the request holds them.
fn config_of(
    studio: &Studio,
    design: &MapDesign,
) -> Result<(Config, Vec<AxisView>, u32), ApiError> {
    let registry = &studio.registry;
    let axes: Vec<(&str, &AxisDesign)> = std::iter::once(("x", &design.x))
        .chain(design.y.as_ref().map(|y| ("y", y)))
        .collect();
    let mut descriptors = Vec::new();
    let mut views = Vec::new();
    for (at, axis) in &axes {
        let field = |name: &str| format!("map.{at}.{name}");
        let cells = axis.cells.unwrap_or(10);
        if !(1..=MAX_CELLS).contains(&cells) {
            return Err(ApiError::bad(
                field("cells"),
                format!("expected 1 to {MAX_CELLS}, got {cells}"),
            ));
        }
        let mut value = json!({ "name": axis.name, "cells": cells });
        if let Some(range) = axis.range {
            value["range"] = json!(range);
        }
        let read: AxisConfig = serde_json::from_value(value.clone()).map_err(|e| {
            ApiError::bad(
                field("name"),
                e.to_string()
                    .replace("unknown variant", "unknown descriptor"),
            )
        })?;
        if let Some([lo, hi]) = axis.range
            && !(lo.is_finite() && hi.is_finite() && lo < hi)
        {
            return Err(ApiError::bad(
                field("range"),
                format!("expected two finite numbers, low then high; got [{lo}, {hi}]"),
            ));
        }
        if views.iter().any(|v: &AxisView| v.name == axis.name) {
            return Err(ApiError::bad(
                field("name"),
                format!("`{}` is on both axes", axis.name),
            ));
        }
        let (min, max) = read.bounds();
        views.push(AxisView {
            name: axis.name.clone(),
            min,
            max,
            cells,
        });
        descriptors.push(value);
    }
    let mut doc = base_config(&design.model)?;
    let generations = design
        .generations
        .or_else(|| {
            doc.pointer("/run/generations")
                .and_then(|g| g.as_u64())
                .map(|g| g as u32)
        })
        .unwrap_or(200);
    if !(1..=MAX_GENERATIONS).contains(&generations) {
        return Err(ApiError::bad(
            "map.generations",
            format!("expected 1 to {MAX_GENERATIONS}, got {generations}"),
        ));
    }
    doc["run"] = json!({
        "strategy": "map-elites",
        "generations": generations,
        "seed": design.seed.unwrap_or(1),
    });
    doc["map"]["descriptors"] = json!(descriptors);
    let config = registry
        .config_from_value(doc)
        .map_err(|e| match e.field.as_str() {
            "model" => ApiError::bad("map.model", e.message),
            field => ApiError::unprocessable(format!("map ({field})"), e.message),
        })?;
    Ok((config, views, generations))
}

/// The model's example map as a config value, or its defaults with the default map.
fn base_config(model: &str) -> Result<serde_json::Value, ApiError> {
    let Some(text) = example_text(&format!("{model}/varieties.toml")) else {
        return Ok(json!({ "model": model, "map": {} }));
    };
    let mut doc: serde_json::Value = toml::from_str(&text)
        .map_err(|e| ApiError::internal(format!("{model}'s example map: {e}")))?;
    if doc.get("map").is_none() {
        doc["map"] = json!({});
    }
    Ok(doc)
}

/// The start genomes a map config names, from the examples built into the studio: each
/// file `NAME.json` of the model's `start` is the example `MODEL/NAME`.
fn start_genomes(studio: &Studio, config: &Config) -> Vec<Genome> {
    config
        .start_files()
        .iter()
        .filter_map(|file| {
            let stem = file.file_stem()?.to_str()?;
            example(&studio.registry, &format!("{}/{stem}", config.model()))
        })
        .collect()
}

/// Creates a map session and starts its run.
async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
    let (config, axes, generations) = config_of(studio, &start.map)?;
    let model = config.model();
    let (id, run) = studio.archive.transaction(|c| -> Result<_, ApiError> {
        let id = archive::insert_session(c, MapMode::NAME, model, "Map", &json!({}))?;
        let run = archive::insert_run(c, id, &config.to_toml(), generations)?;
        let state = MapState {
            run,
            design: start.map.clone(),
            axes: axes.clone(),
        };
        archive::set_state(c, id, &json!(state))?;
        Ok((id, run))
    })?;
    spawn(studio, run)?;
    Ok(id)
}

fn map_state(studio: &Studio, id: i64) -> Result<MapState, ApiError> {
    let row = session_of(studio, id, MapMode::NAME)?;
    serde_json::from_value(row.state)
        .map_err(|e| ApiError::internal(format!("session {id}'s state: {e}")))
}

fn run_row(studio: &Studio, run: i64) -> Result<RunRow, ApiError> {
    studio
        .archive
        .read(|c| archive::run(c, run))?
        .ok_or_else(|| ApiError::internal(format!("run {run} is missing")))
}

/// Starts (or resumes) a map run's thread, unless it is going already.
fn spawn(studio: &Studio, run: i64) -> Result<(), ApiError> {
    let Some(stop) = studio.runs.begin(run) else {
        return Ok(());
    };
    let worker = studio.clone();
    let spawned = std::thread::Builder::new()
        .name(format!("sylva-map-{run}"))
        .spawn(move || {
            let result = drive(&worker, run, &stop);
            worker.runs.end(run);
            if let Err(e) = result {
                let _ = worker.archive.transaction(|c| -> Result<(), ApiError> {
                    let generation = archive::run(c, run)?.map_or(0, |r| r.generation);
                    archive::save_run(c, run, None, generation, "failed", Some(&e.error))?;
                    Ok(())
                });
                if let Ok(row) = run_row(&worker, run) {
                    tell_status(&worker, &row);
                }
            }
        });
    if let Err(e) = spawned {
        studio.runs.end(run);
        return Err(ApiError::internal(format!("starting a run: {e}")));
    }
    Ok(())
}

/// Fills a map until it is done or asked to stop, saving at most a second apart.
fn drive(studio: &Studio, run: i64, stop: &AtomicBool) -> Result<(), ApiError> {
    let row = run_row(studio, run)?;
    let path = FilePath::new("map");
    let failed = |e: sylva::Error| ApiError::internal(sylva::error::chain(&e));
    let config = studio
        .registry
        .parse_config(path, &row.config)
        .map_err(|e| ApiError::internal(e.to_string()))?;
    let mut shown = HashMap::new();
    let mut map = match &row.checkpoint {
        Some(text) => {
            Varieties::resume(&config, path, text, studio.pool.clone()).map_err(failed)?
        }
        None => {
            let start = start_genomes(studio, &config);
            let map = Varieties::start(&config, start, studio.pool.clone()).map_err(failed)?;
            let figures: Vec<String> = FIGURES.iter().map(|f| (*f).to_owned()).collect();
            studio.archive.transaction(|c| -> Result<_, ApiError> {
                Ok(archive::set_run_terms(c, run, &figures)?)
            })?;
            save(studio, &row, &map, stop, &mut shown)?;
            map
        }
    };
    let mut saved = Instant::now();
    loop {
        let generations = run_row(studio, run)?.generations;
        let done = map.generation() >= generations;
        if stop.load(Ordering::SeqCst) || done {
            save(studio, &row, &map, stop, &mut shown)?;
            if done && !stop.load(Ordering::SeqCst) {
                studio.archive.transaction(|c| {
                    archive::save_run(c, run, None, map.generation(), "done", None)
                        .map_err(ApiError::from)
                })?;
                tell_status(studio, &run_row(studio, run)?);
            }
            return Ok(());
        }
        map.step();
        if saved.elapsed() >= SAVE_EVERY {
            save(studio, &row, &map, stop, &mut shown)?;
            saved = Instant::now();
        }
    }
}

/// Archives the elites that changed since the last save (`shown`: cell → member id and
/// plant), the
/// generation's figures and the checkpoint, in one transaction; then tells the pages.
fn save(
    studio: &Studio,
    row: &RunRow,
    map: &Varieties,
    stop: &AtomicBool,
    shown: &mut HashMap<usize, (u64, i64)>,
) -> Result<(), ApiError> {
    let generation = map.generation();
    let mut changed = Vec::new();
    for v in map.varieties() {
        if shown.get(&v.cell).map(|&(member, _)| member) == Some(v.member.id.0) {
            continue;
        }
        let extra = json!({ "cell": v.cell, "descriptors": v.descriptors });
        let plant = archive_member(
            studio,
            row.session,
            row.id,
            generation,
            &v.member,
            Operator::Map,
            Some(extra),
        )?;
        shown.insert(v.cell, (v.member.id.0, plant));
        changed.push(json!({
            "cell": v.cell,
            "plant": plant,
            "fitness": finite(v.member.total()),
            "descriptors": v.descriptors,
        }));
    }
    let checkpoint = map
        .checkpoint()
        .map_err(|e| ApiError::internal(sylva::error::chain(&e)))?;
    let stats = map.stats().last().cloned();
    let best_plant = map
        .best()
        .and_then(|b| shown.get(&b.cell))
        .map(|&(_, plant)| plant);
    let figures = stats.as_ref().map(|s| GenerationRow {
        generation,
        best: finite(s.best),
        mean: finite(s.mean),
        best_terms: vec![s.filled as f64, s.coverage, s.qd_score],
        plant: best_plant,
    });
    let status = studio.archive.transaction(|c| -> Result<_, ApiError> {
        for cell in &changed {
            archive::set_map_cell(c, row.id, cell)?;
        }
        if let Some(figures) = &figures {
            archive::insert_generation(c, row.id, figures)?;
        }
        // Read under the archive's lock: a stop acknowledged before this commit is kept.
        let status = if stop.load(Ordering::SeqCst) {
            archive::run(c, row.id)?.map_or_else(|| "stopped".to_owned(), |r| r.status)
        } else {
            "running".to_owned()
        };
        archive::save_run(c, row.id, Some(&checkpoint), generation, &status, None)?;
        Ok(status)
    })?;
    let mut data = json!({
        "run": row.id,
        "status": status,
        "generation": generation,
        "cells": changed,
    });
    if let Some(s) = &stats {
        data["filled"] = json!(s.filled);
        data["coverage"] = json!(s.coverage);
        data["qd_score"] = json!(s.qd_score);
        data["best"] = json!(finite(s.best));
    }
    studio.events.send(row.session, "map", data);
    Ok(())
}

/// A run's status as an event.
fn status_data(row: &RunRow) -> serde_json::Value {
    json!({
        "run": row.id,
        "status": row.status,
        "generation": row.generation,
        "error": row.error,
    })
}

fn tell_status(studio: &Studio, row: &RunRow) {
    studio.events.send(row.session, "status", status_data(row));
}

/// Stops a run: marked stopped now (so a restart does not resume it); its thread saves and
/// ends after the generation it is making.
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

/// `POST /api/sessions/{id}/map/stop`.
pub(crate) async fn stop(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<SessionView>, ApiError> {
    let state = map_state(&studio, id)?;
    stop_run(&studio, state.run)?;
    tell_status(&studio, &run_row(&studio, state.run)?);
    Ok(Json(view(&studio, id)?))
}

/// `POST /api/sessions/{id}/map/resume`.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct ResumeRequest {
    /// Run to this many generations in all (more than asked at first, to go on).
    generations: Option<u32>,
}

/// `POST /api/sessions/{id}/map/resume`: a stopped (or done) map goes on.
pub(crate) async fn resume(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<ResumeRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let state = map_state(&studio, id)?;
    runs::ready_to_resume(&studio, state.run, request.generations, MAX_GENERATIONS).await?;
    spawn(&studio, state.run)?;
    Ok(Json(view(&studio, id)?))
}

/// A figure row of a map run.
#[derive(Serialize)]
pub(crate) struct MapRow {
    generation: u32,
    filled: f64,
    coverage: f64,
    qd_score: f64,
    best: f64,
}

/// `GET /api/sessions/{id}/map`.
#[derive(Serialize)]
pub(crate) struct MapView {
    run: i64,
    model: String,
    status: String,
    generation: u32,
    generations: u32,
    axes: Vec<AxisView>,
    cells: Vec<serde_json::Value>,
    rows: Vec<MapRow>,
    error: Option<String>,
}

/// `GET /api/sessions/{id}/map`: the map as it stands: its axes, filled cells and figures.
pub(crate) async fn get_map(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<MapView>, ApiError> {
    let state = map_state(&studio, id)?;
    let (row, cells, rows) = studio.archive.read(|c| {
        let row = archive::run(c, state.run)?;
        let cells = archive::map_cells(c, state.run)?;
        let rows = archive::generations(c, state.run, u32::MAX)?;
        Ok((row, cells, rows))
    })?;
    let row = row.ok_or_else(|| ApiError::internal(format!("run {} is missing", state.run)))?;
    let rows = rows
        .into_iter()
        .map(|r| {
            let figure = |i: usize| r.best_terms.get(i).copied().unwrap_or(0.0);
            MapRow {
                generation: r.generation,
                filled: figure(0),
                coverage: figure(1),
                qd_score: figure(2),
                best: r.best,
            }
        })
        .collect();
    Ok(Json(MapView {
        run: row.id,
        model: state.design.model,
        status: row.status,
        generation: row.generation,
        generations: row.generations,
        axes: state.axes,
        cells,
        rows,
        error: row.error,
    }))
}

/// A descriptor as the page offers it.
#[derive(Serialize)]
pub(crate) struct DescriptorInfo {
    name: &'static str,
    about: &'static str,
    min: f64,
    max: f64,
}

/// `GET /api/descriptors`: the descriptors a map's axes may be.
pub(crate) async fn descriptors() -> Json<Vec<DescriptorInfo>> {
    Json(
        Descriptor::ALL
            .into_iter()
            .map(|d| {
                let (min, max) = d.range();
                DescriptorInfo {
                    name: d.name(),
                    about: d.about(),
                    min,
                    max,
                }
            })
            .collect(),
    )
}

/// Map mode, behind the studio's mode seam.
pub struct MapMode;

impl Mode for MapMode {
    const NAME: &'static str = "map";
    type Start = Start;

    fn models(registry: &sylva::Registry) -> Vec<&'static str> {
        registry.models().iter().map(|m| m.name()).collect()
    }

    async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
        create(studio, start).await
    }

    fn routes() -> Vec<Route> {
        vec![
            Route::get("/sessions/{id}/map", get_map),
            Route::post("/sessions/{id}/map/stop", stop),
            Route::post("/sessions/{id}/map/resume", resume),
            Route::get("/descriptors", descriptors),
        ]
    }

    fn first_event(studio: &Studio, session: i64) -> Result<Option<SessionEvent>, ApiError> {
        let state = map_state(studio, session)?;
        let row = run_row(studio, state.run)?;
        Ok(Some(SessionEvent {
            name: "status",
            data: status_data(&row),
        }))
    }

    /// Resumes every map that was filling when the studio stopped (or was killed).
    fn resume(studio: &Studio) {
        let Ok(runs) = studio
            .archive
            .read(|c| archive::runs_of_mode(c, Self::NAME, "running"))
        else {
            return;
        };
        for run in runs {
            let _ = spawn(studio, run.id);
        }
    }
}
