//! Family mode, the deciduous-evolution viewer: a binary-tree population under the genetic
//! algorithm, browsed fittest first (`[` and `]`), with statistics (`s`), one generation
//! (`g`), a batch (`j`) and the batch's size (`J`).
//!
//! The run's checkpoint is kept after every step, so undo goes back to the generation
//! before exactly, and the run in memory is rebuilt from the checkpoint of the session's
//! generation whenever it is not at that generation.

use std::collections::HashMap;
use std::path::Path as FilePath;
use std::sync::{Arc, Mutex};

use axum::Json;
use axum::extract::{Path, State};
use serde::{Deserialize, Serialize};
use serde_json::json;
use sylva::models::BinTreeModel;
use sylva::{Config, Evolution, EvolveConfig, Member};

use crate::Studio;
use crate::archive::{self, GenerationRow, Operator};
use crate::error::ApiError;
use crate::http::{Body, first_null};
use crate::modes::{Mode, Route};
use crate::runs::{archive_member, finite, generation_row};
use crate::sessions::{SessionView, session_of, view};
use crate::settings;

const BINTREE: &str = sylva::registry::names::BINTREE;

/// The largest family population.
pub const MAX_POPULATION: u64 = 10_000;

/// The most generations one request runs.
pub const MAX_BATCH: u32 = 1000;

/// Family runs in memory, by session.
#[derive(Default)]
pub struct Families {
    runs: Mutex<HashMap<i64, Arc<Mutex<Evolution>>>>,
}

impl Families {
    /// Drops a session's run from memory (its view changed under it).
    pub fn forget(&self, session: i64) {
        self.runs
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .remove(&session);
    }

    fn get(&self, session: i64) -> Option<Arc<Mutex<Evolution>>> {
        self.runs
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .get(&session)
            .cloned()
    }

    fn put(&self, session: i64, run: Evolution) -> Arc<Mutex<Evolution>> {
        let run = Arc::new(Mutex::new(run));
        self.runs
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .insert(session, run.clone());
        run
    }
}

/// `POST /api/sessions` in family mode.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct Start {
    #[serde(default)]
    config: FamilyConfig,
}

/// The `[run]` and `[bintree]` sections of an evolution config, as the page sends them.
#[derive(Deserialize, Serialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct FamilyConfig {
    #[serde(skip_serializing_if = "Option::is_none")]
    run: Option<serde_json::Map<String, serde_json::Value>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    bintree: Option<serde_json::Value>,
}

/// A member in the browser.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct MemberView {
    /// Its place, fittest first.
    pub index: usize,
    /// Its total fitness.
    pub fitness: f64,
}

/// A family session's view.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct FamilyState {
    /// The run.
    pub run: i64,
    /// The generation shown.
    pub generation: u32,
    /// Generations a batch (`j`) runs.
    pub batch: u32,
    /// The population, fittest first.
    pub members: Vec<MemberView>,
}

/// Trees in a family whose request names no population.
const POPULATION: u32 = 100;

/// The config a family request asks for: the binary-tree model's typed config, read from
/// the request's sections with their own checks (the model's defaults for what they leave
/// out), a hundred trees unless it says otherwise.
fn config_of(request: &FamilyConfig) -> Result<Config, ApiError> {
    if let Some(null) = request
        .run
        .as_ref()
        .and_then(|r| first_null(&json!(r), "config.run"))
    {
        return Err(ApiError::bad(
            null,
            "null is not a value: leave the field out",
        ));
    }
    if let Some(null) = request
        .bintree
        .as_ref()
        .and_then(|b| first_null(b, "config.bintree"))
    {
        return Err(ApiError::bad(
            null,
            "null is not a value: leave the field out",
        ));
    }
    let mut run = request.run.clone().unwrap_or_default();
    // The page lists every member: a family is a browsable population, not a large search.
    if let Some(population) = run.get("population")
        && population.as_u64().is_some_and(|p| p > MAX_POPULATION)
    {
        return Err(ApiError::bad(
            "config.run.population",
            format!("a family holds at most {MAX_POPULATION} trees, got {population}"),
        ));
    }
    // The studio steps the run by hand; the config's `generations` is its own.
    run.remove("generations");
    let asked = FamilyConfig {
        run: Some(run),
        bintree: request.bintree.clone(),
    };
    let sections = serde_json::to_value(&asked).map_err(ApiError::internal)?;
    let mut typed: EvolveConfig<BinTreeModel> = settings::read(sections, "config")?;
    if !asked
        .run
        .as_ref()
        .is_some_and(|r| r.contains_key("population"))
    {
        typed.run.population = POPULATION;
    }
    typed.run.generations = 1;
    Ok(Config::new(typed))
}

fn members(run: &Evolution) -> Vec<MemberView> {
    let population = run.population().len();
    run.fittest(population)
        .iter()
        .enumerate()
        .map(|(index, m)| MemberView {
            index,
            fitness: finite(m.total()),
        })
        .collect()
}

/// Creates a family session: generation 0 made and evaluated.
async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
    let config = config_of(&start.config)?;
    let pool = studio.pool.clone();
    let (run, checkpoint, toml) = tokio::task::spawn_blocking(move || -> Result<_, ApiError> {
        let run = Evolution::start(&config, Vec::new(), pool)
            .map_err(|e| ApiError::library("config", e))?;
        let checkpoint = run.checkpoint().map_err(ApiError::internal)?;
        Ok((run, checkpoint, config.to_toml()))
    })
    .await??;
    let id = studio.archive.transaction(|c| -> Result<_, ApiError> {
        let id = archive::insert_session(c, FamilyMode::NAME, BINTREE, "Family", &json!({}))?;
        let run_id = archive::insert_run(c, id, &toml, 0)?;
        archive::save_run(c, run_id, Some(&checkpoint), 0, "stopped", None)?;
        archive::insert_checkpoint(c, run_id, 0, &checkpoint)?;
        archive::insert_generation(c, run_id, &generation_row(&run))?;
        let state = FamilyState {
            run: run_id,
            generation: 0,
            batch: 10,
            members: members(&run),
        };
        archive::set_state(c, id, &json!(state))?;
        Ok(id)
    })?;
    studio.kept::<Families>().put(id, run);
    Ok(id)
}

fn family_state(studio: &Studio, id: i64) -> Result<FamilyState, ApiError> {
    let row = session_of(studio, id, FamilyMode::NAME)?;
    serde_json::from_value(row.state)
        .map_err(|e| ApiError::internal(format!("session {id}'s state: {e}")))
}

/// The session's run in memory, at the session's generation (rebuilt from its checkpoint
/// when it is not).
fn evolution(
    studio: &Studio,
    id: i64,
    state: &FamilyState,
) -> Result<Arc<Mutex<Evolution>>, ApiError> {
    if let Some(run) = studio.kept::<Families>().get(id) {
        let at = run.lock().unwrap_or_else(|p| p.into_inner()).generation();
        if at == state.generation {
            return Ok(run);
        }
    }
    let (row, checkpoint) = studio.archive.read(|c| {
        Ok((
            archive::run(c, state.run)?,
            archive::checkpoint_at(c, state.run, state.generation)?,
        ))
    })?;
    let row = row.ok_or_else(|| ApiError::internal(format!("run {} is missing", state.run)))?;
    let checkpoint = checkpoint.ok_or_else(|| {
        ApiError::internal(format!(
            "run {} has no checkpoint at generation {}",
            state.run, state.generation
        ))
    })?;
    let path = FilePath::new("checkpoint");
    let config = (studio.registry)
        .parse_config(path, &row.config)
        .map_err(|e| ApiError::internal(e.message))?;
    let run = Evolution::resume(&config, path, &checkpoint, studio.pool.clone())
        .map_err(ApiError::internal)?;
    Ok(studio.kept::<Families>().put(id, run))
}

/// `POST /api/sessions/{id}/generations`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct GenerationsRequest {
    count: Option<u32>,
}

/// `POST /api/sessions/{id}/generations`: runs 1 (`g`) or more (`j`) generations.
pub(crate) async fn generations(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<GenerationsRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let count = request.count.unwrap_or(1);
    if !(1..=MAX_BATCH).contains(&count) {
        return Err(ApiError::bad(
            "count",
            format!("expected 1 to {MAX_BATCH}, got {count}"),
        ));
    }
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let before = family_state(&studio, id)?;
    let run = evolution(&studio, id, &before)?;
    let worker = run.clone();
    let (rows, checkpoint, members, generation) =
        tokio::task::spawn_blocking(move || -> Result<_, ApiError> {
            let mut run = worker.lock().unwrap_or_else(|p| p.into_inner());
            let mut rows = Vec::with_capacity(count as usize);
            for _ in 0..count {
                run.step().map_err(|e| ApiError::library("config", e))?;
                rows.push(generation_row(&run));
            }
            let checkpoint = run.checkpoint().map_err(ApiError::internal)?;
            Ok((rows, checkpoint, members(&run), run.generation()))
        })
        .await??;
    let after = FamilyState {
        generation,
        members,
        ..before.clone()
    };
    let committed = studio.archive.transaction(|c| -> Result<_, ApiError> {
        for row in &rows {
            archive::insert_generation(c, before.run, row)?;
        }
        archive::insert_checkpoint(c, before.run, generation, &checkpoint)?;
        archive::save_run(
            c,
            before.run,
            Some(&checkpoint),
            generation,
            "stopped",
            None,
        )?;
        let action = json!({ "op": "generations", "count": count });
        archive::record_step(c, id, &action, &json!(before), &json!(after))?;
        Ok(())
    });
    if committed.is_err() {
        // The run in memory is ahead of the archive now.
        studio.kept::<Families>().forget(id);
    }
    committed?;
    Ok(Json(view(&studio, id)?))
}

/// `POST /api/sessions/{id}/batch`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct BatchRequest {
    batch: u32,
}

/// `POST /api/sessions/{id}/batch`: the batch size (`J`).
pub(crate) async fn batch(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<BatchRequest>,
) -> Result<Json<SessionView>, ApiError> {
    if !(1..=MAX_BATCH).contains(&request.batch) {
        return Err(ApiError::bad(
            "batch",
            format!("expected 1 to {MAX_BATCH}, got {}", request.batch),
        ));
    }
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let before = family_state(&studio, id)?;
    let after = FamilyState {
        batch: request.batch,
        ..before.clone()
    };
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        let action = json!({ "op": "batch", "batch": request.batch });
        archive::record_step(c, id, &action, &json!(before), &json!(after))?;
        Ok(())
    })?;
    Ok(Json(view(&studio, id)?))
}

#[derive(Serialize)]
pub(crate) struct Stats {
    terms: Vec<String>,
    generations: Vec<GenerationRow>,
}

/// `GET /api/sessions/{id}/stats`: best and mean fitness of every generation so far.
pub(crate) async fn stats(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<Stats>, ApiError> {
    let state = family_state(&studio, id)?;
    let run = evolution(&studio, id, &state)?;
    let terms = run
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .term_names()
        .to_vec();
    let generations = studio
        .archive
        .read(|c| archive::generations(c, state.run, state.generation))?;
    Ok(Json(Stats { terms, generations }))
}

/// `POST /api/sessions/{id}/member`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct MemberRequest {
    index: usize,
}

#[derive(Serialize)]
pub(crate) struct MemberPlant {
    plant: i64,
    fitness: f64,
    terms: Vec<f64>,
}

/// `POST /api/sessions/{id}/member`: the member at a place (fittest first), archived once.
pub(crate) async fn member(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<MemberRequest>,
) -> Result<Json<MemberPlant>, ApiError> {
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let state = family_state(&studio, id)?;
    let run = evolution(&studio, id, &state)?;
    let member: Member = {
        let run = run.lock().unwrap_or_else(|p| p.into_inner());
        let size = run.population().len();
        if request.index >= size {
            return Err(ApiError::bad(
                "index",
                format!("expected 0 to {}, got {}", size - 1, request.index),
            ));
        }
        run.fittest(request.index + 1).swap_remove(request.index)
    };
    let terms = member
        .fitness
        .map(|f| f.terms().to_vec())
        .unwrap_or_default();
    let fitness = finite(member.total());
    let plant = archive_member(
        &studio,
        id,
        state.run,
        state.generation,
        &member,
        Operator::Family,
        None,
    )?;
    Ok(Json(MemberPlant {
        plant,
        fitness,
        terms,
    }))
}

/// Family mode, behind the studio's mode seam.
pub struct FamilyMode;

impl Mode for FamilyMode {
    const NAME: &'static str = "family";
    type Start = Start;

    fn models(_: &sylva::Registry) -> Vec<&'static str> {
        vec![BINTREE]
    }

    async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
        create(studio, start).await
    }

    fn routes() -> Vec<Route> {
        vec![
            Route::post("/sessions/{id}/generations", generations),
            Route::post("/sessions/{id}/batch", batch),
            Route::get("/sessions/{id}/stats", stats),
            Route::post("/sessions/{id}/member", member),
        ]
    }

    fn moved(studio: &Studio, session: i64) {
        // The run in memory may be at another generation now; it reloads when needed.
        studio.kept::<Families>().forget(session);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(value: serde_json::Value) -> Result<Config, ApiError> {
        config_of(&serde_json::from_value(value).expect("a family config"))
    }

    #[test]
    fn a_family_is_a_hundred_trees_stepped_by_hand_unless_it_asks() {
        let typed = config(json!({})).unwrap();
        let run = &typed.get::<BinTreeModel>().unwrap().run;
        assert_eq!((run.population, run.generations), (POPULATION, 1));
        let asked = json!({"run": {"population": 12, "generations": 500, "seed": 4},
                           "bintree": {"mutation_rate": 0.1}});
        let typed = config(asked).unwrap();
        let typed = typed.get::<BinTreeModel>().unwrap();
        assert_eq!(
            (typed.run.population, typed.run.generations, typed.run.seed),
            (12, 1, 4)
        );
        assert_eq!(typed.settings.mutation_rate, 0.1);
        let e = config(json!({"bintree": {"mutation_rate": 7}})).unwrap_err();
        assert_eq!(
            (e.status.as_u16(), e.field.as_str()),
            (422, "config.bintree.mutation_rate")
        );
        let e = config(json!({"bintree": [0.02]})).unwrap_err();
        assert_eq!(
            (e.status.as_u16(), e.field.as_str()),
            (422, "config.bintree"),
            "{e}"
        );
    }
}
