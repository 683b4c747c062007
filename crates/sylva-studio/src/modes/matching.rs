//! Match mode, design from a picture (docs/match.md): drop a picture of the tree a scene
//! needs and watch an evolution of any model (or of the model that matches it best) bring
//! its best plant's outline over it, generation by generation, in the background.
//!
//! The pictures are kept in the archive; a run finds them in a folder of the studio's own
//! (written again from the archive whenever it is missing, as after a restart). The run goes
//! on as [`runs`](crate::runs) keeps background runs: checkpointed every generation,
//! resumed after a kill to the bytes of a run never stopped. Each generation's best is
//! archived as a plant, to open, branch into breeding and export.
//!
//! An auto match's trials come first, in the run's thread: each generation they breed is a
//! row of `trial_generations` with its best plant, told to the pages as a `trial` event (the
//! page shows which model is on trial and its best outline so far), and the trials' log
//! (`run_trials`) is kept as each trial ends, so a server killed during the trials goes on
//! from the trials kept. A stop asked for during the trials ends them at their next
//! generation; resumed, they go on from their log.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use axum::Json;
use axum::extract::{Path, Query, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use base64::Engine;
use serde::{Deserialize, Serialize};
use serde_json::json;
use sylva::evolution::outline::{
    self, AutoEvent, AutoMatch, Limit, TrialLog, best_iou, outlines, overlay,
};
use sylva::evolution::{MatchConfig, RunConfig};
use sylva::picture::Threshold;
use sylva::{Config, Evolution};

use crate::Studio;
use crate::archive::{self, GenerationRow, Operator, RunRow, TrialGenerationRow};
use crate::error::ApiError;
use crate::events::SessionEvent;
use crate::http::Body;
use crate::modes::{Mode, Route};
use crate::plants::{genome_of, plant_row};
use crate::pruning::{self, picture_dir};
use crate::runs::{self, Background};
use crate::sessions::{SessionView, session_of, view};

/// Most generations a match is asked for.
const MAX_GENERATIONS: u32 = 10_000;

/// The model that tries every model first.
const AUTO: &str = "auto";

/// A match as the person sets it.
#[derive(Deserialize, Serialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct MatchDesign {
    /// The target seen from the front: a PNG or JPEG, base64 (bare, or a `data:` URL).
    #[serde(skip_serializing)]
    picture: String,
    /// The target seen from the side, the same way. Default: the front picture (a tree looks
    /// much alike from every side).
    #[serde(default, skip_serializing)]
    side: Option<String>,
    /// The model, or `auto`: each model briefly, then on with the best. Default auto.
    model: Option<String>,
    /// What is ink: `"otsu"` (the default) or a luminance 0 to 1 that ink is darker than.
    threshold: Option<Threshold>,
    /// Generations, 1 to 10,000. Default 100.
    generations: Option<u32>,
    /// Individuals per generation, 2 to 5000. Default 100.
    population: Option<u32>,
    /// The run's seed. Default 1.
    seed: Option<u64>,
    /// Whether the plants are clipped to the outlines as a topiary is, pruned where they
    /// would show outside them (`[match] topiary`, docs/match.md). Default false.
    #[serde(alias = "prune")]
    topiary: Option<bool>,
}

/// `POST /api/sessions` in match mode.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct Start {
    #[serde(rename = "match")]
    target: MatchDesign,
}

/// A match session's state: its run and the match as asked (the pictures are in the
/// archive's `pictures`).
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct MatchState {
    /// The run.
    pub run: i64,
    /// The match as asked, less its pictures.
    pub design: serde_json::Value,
    /// Whether the model was chosen by trials (`auto`).
    pub auto: bool,
}

/// A picture's bytes from base64 (bare or a `data:` URL), naming `field` when it is not.
fn picture_bytes(text: &str, field: &str) -> Result<Vec<u8>, ApiError> {
    let data = match text.split_once(";base64,") {
        Some((head, data)) if head.starts_with("data:") => data,
        _ => text,
    };
    base64::engine::general_purpose::STANDARD
        .decode(data.trim())
        .map_err(|e| ApiError::bad(field, format!("expected a PNG or JPEG as base64: {e}")))
}

/// The target a match's config carries: its pictures by name, in the match's folder.
fn target(threshold: Threshold, prune: bool) -> MatchConfig {
    MatchConfig {
        front: PathBuf::from("front"),
        side: Some(PathBuf::from("side")),
        threshold,
        weight: 1.0,
        beside: false,
        rows: MatchConfig::DEFAULT_ROWS,
        closeness: 0.0,
        topiary: Some(prune),
    }
}

/// Checks a match's numbers, naming their fields; its run's size.
fn run_of(design: &MatchDesign) -> Result<RunConfig, ApiError> {
    let generations = design.generations.unwrap_or(100);
    if !(1..=MAX_GENERATIONS).contains(&generations) {
        return Err(ApiError::bad(
            "match.generations",
            format!("expected 1 to {MAX_GENERATIONS}, got {generations}"),
        ));
    }
    let population = design.population.unwrap_or(100);
    if !(2..=5000).contains(&population) {
        return Err(ApiError::bad(
            "match.population",
            format!("expected 2 to 5000, got {population}"),
        ));
    }
    Ok(RunConfig {
        generations,
        population,
        seed: design.seed.unwrap_or(1),
        ..RunConfig::default()
    })
}

/// The config of a match of `model`, its pictures in the session's folder.
fn config_for(
    studio: &Studio,
    model: &str,
    run: &RunConfig,
    threshold: Threshold,
    prune: bool,
) -> Result<Config, ApiError> {
    outline::match_config(&studio.registry, model, run, &target(threshold, prune)).map_err(|e| {
        match e.field.as_str() {
            "model" => ApiError::bad("match.model", e.message),
            field => ApiError::unprocessable(format!("match ({field})"), e.message),
        }
    })
}

/// Creates a match session, keeps its pictures and starts its run.
async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
    let design = start.target;
    let front = picture_bytes(&design.picture, "match.picture")?;
    let side = match &design.side {
        Some(text) => picture_bytes(text, "match.side")?,
        None => front.clone(),
    };
    let run = run_of(&design)?;
    let threshold = design.threshold.unwrap_or_default();
    let prune = design.topiary.unwrap_or(false);
    let model = design.model.clone().unwrap_or_else(|| AUTO.to_owned());
    let auto = model == AUTO;
    // An auto match's config is its first model's until the trials choose.
    let first = studio
        .registry
        .models()
        .first()
        .map(|m| m.name())
        .unwrap_or(AUTO);
    let config = config_for(
        studio,
        if auto { first } else { &model },
        &run,
        threshold,
        prune,
    )?;
    // The pictures are read before anything is kept: a bad one is refused naming its field.
    let check = tempfile_dir()?;
    for (view, bytes, field) in [
        ("front", &front, "match.picture"),
        ("side", &side, "match.side"),
    ] {
        std::fs::write(check.join(view), bytes)
            .map_err(|e| ApiError::internal(format!("checking the picture: {e}")))?;
        let one = MatchConfig {
            side: None,
            front: PathBuf::from(view),
            ..target(threshold, prune)
        };
        outlines(&one, &check).map_err(|e| ApiError::bad(field, e.message))?;
    }
    let _ = std::fs::remove_dir_all(&check);
    let generations = run.generations;
    let (id, run) = studio.archive.transaction(|c| -> Result<_, ApiError> {
        let id = archive::insert_session(c, MatchMode::NAME, config.model(), "Match", &json!({}))?;
        archive::insert_picture(c, id, "front", &front)?;
        archive::insert_picture(c, id, "side", &side)?;
        let run = archive::insert_run(c, id, &config.to_toml(), generations)?;
        let state = MatchState {
            run,
            // Kept explicit: a session stored before topiary was off by default says nothing
            // and was pruned.
            design: json!(MatchDesign {
                topiary: Some(prune),
                ..design
            }),
            auto,
        };
        archive::set_state(c, id, &json!(state))?;
        Ok((id, run))
    })?;
    runs::spawn::<MatchMode>(studio, run)?;
    Ok(id)
}

/// A fresh folder to check pictures in.
fn tempfile_dir() -> Result<PathBuf, ApiError> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let dir = std::env::temp_dir().join(format!(
        "sylva-studio-{}-check-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir)
        .map_err(|e| ApiError::internal(format!("checking the picture: {e}")))?;
    Ok(dir)
}

fn match_state(studio: &Studio, id: i64) -> Result<MatchState, ApiError> {
    let row = session_of(studio, id, MatchMode::NAME)?;
    serde_json::from_value(row.state)
        .map_err(|e| ApiError::internal(format!("session {id}'s state: {e}")))
}

/// The threshold a session's match asked for.
fn threshold_of(state: &MatchState) -> Threshold {
    serde_json::from_value(state.design["threshold"].clone()).unwrap_or_default()
}

/// Whether a match clips its plants to the outlines (`topiary`; a session stored before
/// topiary was off by default, which says nothing, was pruned).
fn prune_of(state: &MatchState) -> bool {
    let design = &state.design;
    (design["topiary"].as_bool())
        .or(design["prune"].as_bool())
        .unwrap_or(true)
}

impl Background for MatchMode {
    const OPERATOR: Operator = Operator::Match;

    fn config(studio: &Studio, row: &RunRow) -> Result<Config, ApiError> {
        pruning::match_config(studio, row)
    }

    /// Auto: the trials of every model (see the module's overview), then on with the best,
    /// whose config the run keeps.
    fn start(
        studio: &Studio,
        row: &RunRow,
        config: &Config,
        stop: &AtomicBool,
    ) -> Result<Option<Evolution>, ApiError> {
        let state = match_state(studio, row.session)?;
        if !state.auto {
            return runs::start_fresh(studio, config);
        }
        let Some(evolution) = trials(studio, row, config, &state, stop)? else {
            return Ok(None);
        };
        let (threshold, prune) = (threshold_of(&state), prune_of(&state));
        let chosen = config_for(
            studio,
            evolution.config().model(),
            config.run(),
            threshold,
            prune,
        )?;
        studio.archive.transaction(|c| -> Result<_, ApiError> {
            archive::set_run_config(c, row.id, &chosen.to_toml())?;
            archive::set_session_model(c, row.session, chosen.model())?;
            // The chosen model's trial generations are the run's first: its run went on
            // from them.
            for t in archive::trial_generations(c, row.id)? {
                if t.model == chosen.model() {
                    let first = GenerationRow {
                        generation: t.generation,
                        best: t.best,
                        mean: t.mean,
                        best_terms: vec![t.iou],
                        plant: t.plant,
                    };
                    archive::insert_generation(c, row.id, &first)?;
                }
            }
            Ok(())
        })?;
        Ok(Some(evolution))
    }
}

/// A library error in a run: the studio's fault or the run's settings, told as they are.
/// Why an auto match's trials ended early.
enum TrialsEnded {
    /// A stop was asked for.
    Stopped,
    /// The library failed.
    Library(sylva::Error),
    /// The studio failed to keep them.
    Studio(ApiError),
}

impl From<sylva::Error> for TrialsEnded {
    fn from(e: sylva::Error) -> Self {
        TrialsEnded::Library(e)
    }
}

impl From<ApiError> for TrialsEnded {
    fn from(e: ApiError) -> Self {
        TrialsEnded::Studio(e)
    }
}

/// The trials of auto match `row`, going on from the log the archive keeps: the run of the
/// model chosen, or `None` when `stop` ended them.
fn trials(
    studio: &Studio,
    row: &RunRow,
    config: &Config,
    state: &MatchState,
    stop: &AtomicBool,
) -> Result<Option<Evolution>, ApiError> {
    // The trials are of the match as asked: resumed to more generations, a match stopped
    // during its trials goes on from them unchanged.
    let asked = (state.design["generations"].as_u64())
        .and_then(|g| u32::try_from(g).ok())
        .unwrap_or(config.run().generations);
    let run = RunConfig {
        generations: asked,
        ..config.run().clone()
    };
    let target = target(threshold_of(state), prune_of(state));
    let dir = picture_dir(studio, row.session)?;
    let mut log = match studio.archive.read(|c| archive::trial_log(c, row.id))? {
        Some(text) => TrialLog::parse(std::path::Path::new("the run's trials"), &text)
            .map_err(|e| ApiError::internal(e.to_string()))?,
        None => TrialLog::new(),
    };
    let auto = AutoMatch {
        registry: &studio.registry,
        target: &target,
        base: &dir,
        run: &run,
        limit: Limit::Generations(asked),
        pool: &studio.pool,
        stop: &sylva::core::par::Stop::new(),
    };
    let started = auto.start(&mut log, |event| -> Result<(), TrialsEnded> {
        // A stop (by hand, or the studio shutting down) ends the trials as the next trial
        // or generation begins (a trial that ended is kept first); the trials kept are gone
        // on from when the run resumes.
        let stopped = || stop.load(Ordering::SeqCst);
        match event {
            AutoEvent::Begun { .. } | AutoEvent::Bred { .. } if stopped() => {
                return Err(TrialsEnded::Stopped);
            }
            AutoEvent::Begun { model, runoff } => {
                let data = json!({"run": row.id, "model": model, "runoff": runoff});
                studio.events.send(row.session, "trial-begun", data);
            }
            AutoEvent::Bred {
                model,
                runoff,
                evolution,
            } => trial_generation(studio, row, model, runoff, evolution)?,
            AutoEvent::Ended {
                log,
                resumed: false,
                ..
            } => keep_log(studio, row.id, log)?,
            AutoEvent::Ended { .. } => {}
        }
        Ok(())
    });
    match started {
        Ok((evolution, _)) => {
            keep_log(studio, row.id, &log)?;
            Ok(Some(evolution))
        }
        Err(TrialsEnded::Stopped) => Ok(None),
        Err(TrialsEnded::Library(e)) => Err(runs::library(e)),
        Err(TrialsEnded::Studio(e)) => Err(e),
    }
}

/// Keeps the trials' log of run `run`, with how each trial that ended did.
fn keep_log(studio: &Studio, run: i64, log: &TrialLog) -> Result<(), ApiError> {
    let text = log.to_json().map_err(runs::library)?;
    let ended: Vec<serde_json::Value> = (log.trials().iter())
        .map(|t| json!({"model": t.model, "runoff": t.runoff, "outcome": t.outcome, "seconds": t.seconds}))
        .collect();
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        Ok(archive::set_trial_log(c, run, &text, &json!(ended))?)
    })
}

/// A generation of a trial: its best archived as a plant, its figures recorded, and the
/// pages watching told (a `trial` event).
fn trial_generation(
    studio: &Studio,
    row: &RunRow,
    model: &str,
    runoff: bool,
    evolution: &Evolution,
) -> Result<(), ApiError> {
    let generation = evolution.generation();
    let phase = if runoff { "runoff" } else { "trial" };
    let plant = runs::archive_member(
        studio,
        row.session,
        row.id,
        generation,
        &evolution.best(),
        Operator::Match,
        Some(json!({ "trial": phase })),
    )?;
    let last = evolution.stats().last();
    let figures = TrialGenerationRow {
        model: model.to_owned(),
        runoff,
        generation,
        best: last.map_or(0.0, |s| runs::finite(s.best)),
        mean: last.map_or(0.0, |s| runs::finite(s.mean)),
        iou: runs::finite(best_iou(evolution)),
        plant: Some(plant),
    };
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        Ok(archive::insert_trial_generation(c, row.id, &figures)?)
    })?;
    let mut data = json!(figures);
    data["run"] = json!(row.id);
    data["status"] = json!("running");
    studio.events.send(row.session, "trial", data);
    Ok(())
}

/// `POST /api/sessions/{id}/match/stop`.
pub(crate) async fn stop(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<SessionView>, ApiError> {
    let state = match_state(&studio, id)?;
    runs::stop_run(&studio, state.run)?;
    Ok(Json(view(&studio, id)?))
}

/// `POST /api/sessions/{id}/match/resume`.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct ResumeRequest {
    /// Run to this many generations in all (more than asked at first, to go on).
    generations: Option<u32>,
}

/// `POST /api/sessions/{id}/match/resume`: a stopped (or done) match goes on.
pub(crate) async fn resume(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<ResumeRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let state = match_state(&studio, id)?;
    runs::resume_run::<MatchMode>(&studio, state.run, request.generations, MAX_GENERATIONS).await?;
    Ok(Json(view(&studio, id)?))
}

/// A match's run as the page shows it: a design run's view, and an auto match's trials.
#[derive(Serialize)]
pub(crate) struct MatchRunView {
    #[serde(flatten)]
    run: runs::RunView,
    /// Every generation the trials bred, in the order bred (empty unless `auto`).
    trials: Vec<TrialGenerationRow>,
    /// How each trial that ended did: `{model, runoff, outcome, seconds}`, in order.
    ended: serde_json::Value,
}

/// `GET /api/sessions/{id}/match/run`: the run and its figures (`best` is the outline score,
/// `best_terms` the IoU), and the trials of an auto match.
pub(crate) async fn run(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<MatchRunView>, ApiError> {
    let state = match_state(&studio, id)?;
    let (trials, ended) = studio.archive.read(|c| {
        Ok((
            archive::trial_generations(c, state.run)?,
            archive::trials_ended(c, state.run)?,
        ))
    })?;
    Ok(Json(MatchRunView {
        run: runs::run_view(&studio, state.run)?,
        trials,
        ended,
    }))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PictureQuery {
    view: Option<String>,
}

/// The view a query names: `front` (the default) or `side`.
fn view_of(q: &PictureQuery) -> Result<&'static str, ApiError> {
    match q.view.as_deref() {
        None | Some("front") => Ok("front"),
        Some("side") => Ok("side"),
        Some(other) => Err(ApiError::bad(
            "view",
            format!("expected front or side, got {other:?}"),
        )),
    }
}

/// `GET /api/sessions/{id}/match/picture?view=front|side`: a target picture as given.
pub(crate) async fn picture(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Query(q): Query<PictureQuery>,
) -> Result<Response, ApiError> {
    match_state(&studio, id)?;
    let view = view_of(&q)?;
    let bytes = studio
        .archive
        .read(|c| archive::picture(c, id, view))?
        .ok_or_else(|| ApiError::not_found(format!("session {id}'s {view} picture")))?;
    let kind = if bytes.starts_with(b"\x89PNG") {
        "image/png"
    } else {
        "image/jpeg"
    };
    Ok(([(header::CONTENT_TYPE, kind)], bytes).into_response())
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct OverlayQuery {
    plant: i64,
}

/// `GET /api/sessions/{id}/match/overlay.png?plant=ID`: the front target and the plant's
/// outline over each other (blue the target, orange the plant, green both), with their IoU
/// in its caption and in the `X-Sylva-IoU` header.
pub(crate) async fn overlay_png(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Query(q): Query<OverlayQuery>,
) -> Result<Response, ApiError> {
    let state = match_state(&studio, id)?;
    let (png, iou) = tokio::task::spawn_blocking(move || -> Result<_, ApiError> {
        let row = plant_row(&studio, q.plant)?;
        let genome = genome_of(&studio.registry, &row)?;
        let dir = picture_dir(&studio, id)?;
        overlay(
            &target(threshold_of(&state), prune_of(&state)),
            &dir,
            &genome,
        )
        .map_err(|e| ApiError::library("plant", e))
    })
    .await??;
    Ok((
        [
            (header::CONTENT_TYPE, "image/png".to_owned()),
            (
                header::HeaderName::from_static("x-sylva-iou"),
                format!("{iou:.4}"),
            ),
        ],
        png,
    )
        .into_response())
}

/// Match mode, behind the studio's mode seam.
pub struct MatchMode;

impl Mode for MatchMode {
    const NAME: &'static str = "match";
    type Start = Start;

    fn models(registry: &sylva::Registry) -> Vec<&'static str> {
        registry.models().iter().map(|m| m.name()).collect()
    }

    async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
        create(studio, start).await
    }

    fn routes() -> Vec<Route> {
        vec![
            Route::post("/sessions/{id}/match/stop", stop),
            Route::post("/sessions/{id}/match/resume", resume),
            Route::get("/sessions/{id}/match/run", run),
            Route::get("/sessions/{id}/match/picture", picture),
            Route::get("/sessions/{id}/match/overlay.png", overlay_png),
        ]
    }

    fn first_event(studio: &Studio, session: i64) -> Result<Option<SessionEvent>, ApiError> {
        let state = match_state(studio, session)?;
        runs::status_event(studio, state.run).map(Some)
    }

    /// Resumes every match that was running when the studio stopped (or was killed).
    fn resume(studio: &Studio) {
        runs::resume_all::<MatchMode>(studio, Self::NAME);
    }
}
