//! Sessions: one line of breeding in one mode (started, stepped and moved in history by
//! [`crate::modes`]). A session's `state` is its view (the grid,
//! the garden, the family's generation, the design's run); every step a person takes is
//! recorded with the view before and after it, so undo and redo move between views while
//! every plant made stays in the archive.

use axum::Json;
use axum::extract::{Path, State};
use rust_embed::RustEmbed;
use serde::Serialize;
use sylva::{Genome, Registry};

use crate::Studio;
use crate::archive::{self, StepRow};
use crate::error::ApiError;

/// A session as the page sees it.
#[derive(Serialize)]
pub struct SessionView {
    /// Its id.
    pub id: i64,
    /// Its mode's name ([`crate::modes::MODES`]).
    pub mode: String,
    /// The model of its plants.
    pub model: String,
    /// Its title.
    pub title: String,
    /// The mode's view.
    pub state: serde_json::Value,
    /// Whether there is a step to undo.
    pub can_undo: bool,
    /// Whether there is a step to redo.
    pub can_redo: bool,
    /// The last [`HISTORY_SHOWN`] steps, in order.
    pub history: Vec<StepRow>,
}

/// Steps a session's view lists: the most recent (the archive keeps them all).
pub const HISTORY_SHOWN: u32 = 100;

/// A session's view, read from the archive.
pub fn view(studio: &Studio, id: i64) -> Result<SessionView, ApiError> {
    let (row, history) = studio
        .archive
        .read(|c| Ok((archive::session(c, id)?, archive::steps(c, id)?)))?;
    let row = row.ok_or_else(|| ApiError::not_found(format!("session {id}")))?;
    Ok(SessionView {
        id: row.id,
        mode: row.mode,
        model: row.model,
        title: row.title,
        state: row.state,
        can_undo: history.iter().any(|s| !s.undone),
        can_redo: history.iter().any(|s| s.undone),
        history,
    })
}

/// A session, or 404.
pub fn session_row(studio: &Studio, id: i64) -> Result<archive::SessionRow, ApiError> {
    studio
        .archive
        .read(|c| archive::session(c, id))?
        .ok_or_else(|| ApiError::not_found(format!("session {id}")))
}

/// A session that must be of `mode`.
pub fn session_of(studio: &Studio, id: i64, mode: &str) -> Result<archive::SessionRow, ApiError> {
    let row = studio
        .archive
        .read(|c| archive::session(c, id))?
        .ok_or_else(|| ApiError::not_found(format!("session {id}")))?;
    if row.mode != mode {
        return Err(ApiError::conflict(format!(
            "session {id} is a {} session, not {mode}",
            row.mode
        )));
    }
    Ok(row)
}

/// The examples folder shipped with Sylva (genomes, configs, pictures: 320 kB), built into the
/// binary whole: picking files by pattern at build time would cost the build a glob and regex
/// engine.
#[derive(RustEmbed)]
#[folder = "../../examples/"]
struct ExampleFiles;

/// An example file's text by its path in the examples folder (`bintree/varieties.toml`).
pub fn example_text(path: &str) -> Option<String> {
    String::from_utf8(ExampleFiles::get(path)?.data.into_owned()).ok()
}

/// An example genome by name (`plantmaker/fern`).
pub fn example(registry: &Registry, name: &str) -> Option<Genome> {
    registry
        .parse_genome(&example_text(&format!("{name}.json"))?)
        .ok()
}

/// Every example's name and model, sorted by name.
pub fn example_list(registry: &Registry) -> Vec<(String, &'static str)> {
    let mut list: Vec<(String, &'static str)> = ExampleFiles::iter()
        .filter_map(|path| {
            let name = path.strip_suffix(".json")?.to_owned();
            let genome = example(registry, &name)?;
            Some((name, genome.model()))
        })
        .collect();
    list.sort();
    list
}

#[derive(Serialize)]
pub(crate) struct ExampleInfo {
    name: String,
    model: &'static str,
}

/// `GET /api/examples`.
pub(crate) async fn examples(State(studio): State<Studio>) -> Json<Vec<ExampleInfo>> {
    Json(
        example_list(&studio.registry)
            .into_iter()
            .map(|(name, model)| ExampleInfo { name, model })
            .collect(),
    )
}

#[derive(Serialize)]
pub(crate) struct SessionSummary {
    id: i64,
    mode: String,
    model: String,
    title: String,
    created: String,
    steps: i64,
}

/// `GET /api/sessions`.
pub(crate) async fn list(
    State(studio): State<Studio>,
) -> Result<Json<Vec<SessionSummary>>, ApiError> {
    let rows = studio.archive.read(archive::sessions)?;
    Ok(Json(
        rows.into_iter()
            .map(|(s, steps)| SessionSummary {
                id: s.id,
                mode: s.mode,
                model: s.model,
                title: s.title,
                created: s.created,
                steps,
            })
            .collect(),
    ))
}

/// `GET /api/sessions/{id}`.
pub(crate) async fn get(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<SessionView>, ApiError> {
    Ok(Json(view(&studio, id)?))
}

/// Seeds a step's random choices: the session's seed, the step's number and a stream, mixed
/// (SplitMix64), so that a session replays to the same plants.
pub fn step_seed(session_seed: u64, seq: i64, stream: u64) -> u64 {
    let mut z = session_seed
        ^ (seq as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ stream.wrapping_mul(0xD1B5_4A32_D192_ED03);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
