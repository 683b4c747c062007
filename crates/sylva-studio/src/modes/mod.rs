//! The studio's modes, each a module behind one seam, [`Mode`]: how a session of it starts,
//! how it starts from an archived plant, its own endpoints, and what it tells a page that
//! begins watching it. The session code holds a mode as a [`ModeName`] and reaches the
//! mode only through here; a mode never calls another mode.
//!
//! - [`breed`]: PlantMaker's main window (the 3×3 grid, cross and mutate), for any model.
//! - [`garden`]: the biomorph loop of L-system plants grown together in a voxel world.
//! - [`family`]: the deciduous-evolution viewer's binary-tree population.
//! - [`design`]: the GP designer's evolutions of automata trees, run in the background.
//! - [`matching`]: design from a picture: an evolution of any model towards a target
//!   outline, run in the background.
//! - [`map`]: variety maps (MAP-Elites) of any model, filled in the background.
//!
//! A new mode is a module implementing [`Mode`], a [`ModeName`], and one arm in each of the
//! dispatches below.

pub mod breed;
pub mod design;
pub mod family;
pub mod garden;
pub mod map;
pub mod matching;

use std::future::Future;

use axum::extract::{Path, State};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::{Json, Router};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::convert::Infallible;
use sylva::Registry;
use tokio_stream::StreamExt;
use tokio_stream::wrappers::BroadcastStream;

pub use crate::archive::ModeName;

use crate::Studio;
use crate::archive::{self, PlantRow};
use crate::error::ApiError;
use crate::events::SessionEvent;
use crate::http::{Body, from_value};
use crate::plants::plant_row;
use crate::sessions::{SessionView, session_row, view};

/// What every mode does, for the session code.
pub trait Mode {
    /// Its name in requests, the archive and the page.
    const NAME: ModeName;

    /// How a session of it starts: the fields of `POST /api/sessions` besides `mode`.
    type Start: DeserializeOwned + Send;

    /// The models whose plants its sessions hold (every model, or one paper's).
    fn models(registry: &Registry) -> Vec<&'static str>;

    /// Creates a session and takes its first step; returns the session's id.
    fn create(
        studio: &Studio,
        start: Self::Start,
    ) -> impl Future<Output = Result<i64, ApiError>> + Send;

    /// A new session whose first plants are `plant` (`POST /api/plants/{id}/branch`).
    fn branch(
        studio: &Studio,
        plant: &PlantRow,
    ) -> impl Future<Output = Result<i64, ApiError>> + Send {
        let _ = (studio, plant);
        async {
            Err(ApiError::bad(
                "mode",
                format!(
                    "a {} session starts from its own settings, not from a plant; branch to a \
                     breed or garden session",
                    Self::NAME.as_str()
                ),
            ))
        }
    }

    /// Its endpoints under `/api/sessions/{id}/`.
    fn routes() -> Router<Studio>;

    /// What a page that begins watching a session is told first (a run's status).
    fn first_event(studio: &Studio, session: i64) -> Result<Option<SessionEvent>, ApiError> {
        let _ = (studio, session);
        Ok(None)
    }

    /// The session's view moved under it (undo, redo): drop what is held in memory.
    fn moved(studio: &Studio, session: i64) {
        let _ = (studio, session);
    }
}

/// Runs `$body` with `$M` the [`Mode`] of `$name`: the one place the modes are listed.
macro_rules! with_mode {
    ($name:expr, $M:ident => $body:expr) => {
        match $name {
            ModeName::Breed => {
                type $M = breed::BreedMode;
                $body
            }
            ModeName::Garden => {
                type $M = garden::GardenMode;
                $body
            }
            ModeName::Family => {
                type $M = family::FamilyMode;
                $body
            }
            ModeName::Design => {
                type $M = design::DesignMode;
                $body
            }
            ModeName::Map => {
                type $M = map::MapMode;
                $body
            }
            ModeName::Match => {
                type $M = matching::MatchMode;
                $body
            }
        }
    };
}

/// Every mode's endpoints.
pub fn routes() -> Router<Studio> {
    ModeName::ALL
        .into_iter()
        .fold(Router::new(), |router, name| {
            router.merge(with_mode!(name, M => M::routes()))
        })
}

/// A session's mode, read from its row.
fn mode_of(row: &archive::SessionRow) -> Result<ModeName, ApiError> {
    ModeName::parse(&row.mode).ok_or_else(|| {
        ApiError::internal(format!(
            "session {} has an unknown mode {:?}",
            row.id, row.mode
        ))
    })
}

async fn create_as<M: Mode>(studio: &Studio, rest: serde_json::Value) -> Result<i64, ApiError> {
    let start: M::Start = from_value(rest, "")?;
    M::create(studio, start).await
}

/// `POST /api/sessions`: `mode` says which mode's fields the rest are. (Read by hand rather
/// than as a serde tagged enum, which would lose the path of an error in the rest.)
pub(crate) async fn create(
    State(studio): State<Studio>,
    Body(request): Body<serde_json::Value>,
) -> Result<Json<SessionView>, ApiError> {
    let serde_json::Value::Object(mut fields) = request else {
        return Err(ApiError::bad("", "expected a JSON object with a `mode`"));
    };
    let modes = ModeName::expected();
    let name = match fields.remove("mode") {
        Some(serde_json::Value::String(mode)) => ModeName::parse(&mode)
            .ok_or_else(|| ApiError::bad("mode", format!("expected {modes}, got {mode:?}")))?,
        Some(other) => {
            return Err(ApiError::bad(
                "mode",
                format!("expected {modes}, got {other}"),
            ));
        }
        None => return Err(ApiError::bad("mode", format!("missing: expected {modes}"))),
    };
    let rest = serde_json::Value::Object(fields);
    let id = with_mode!(name, M => create_as::<M>(&studio, rest).await?);
    Ok(Json(view(&studio, id)?))
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct BranchRequest {
    mode: Option<String>,
}

/// `POST /api/plants/{id}/branch`: a new session of a mode (breed by default) that starts
/// from this plant.
pub(crate) async fn branch(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<BranchRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let row = plant_row(&studio, id)?;
    let name = match request.mode.as_deref() {
        None => ModeName::Breed,
        Some(mode) => ModeName::parse(mode).ok_or_else(|| {
            ApiError::bad(
                "mode",
                format!("expected {}, got {mode:?}", ModeName::expected()),
            )
        })?,
    };
    let session = with_mode!(name, M => M::branch(&studio, &row).await?);
    Ok(Json(view(&studio, session)?))
}

/// `POST /api/sessions/{id}/undo`.
pub(crate) async fn undo(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<SessionView>, ApiError> {
    move_in_history(&studio, id, true).await
}

/// `POST /api/sessions/{id}/redo`.
pub(crate) async fn redo(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<SessionView>, ApiError> {
    move_in_history(&studio, id, false).await
}

async fn move_in_history(
    studio: &Studio,
    id: i64,
    back: bool,
) -> Result<Json<SessionView>, ApiError> {
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let name = studio
        .archive
        .transaction(|c| -> Result<ModeName, ApiError> {
            let row = archive::session(c, id)?
                .ok_or_else(|| ApiError::not_found(format!("session {id}")))?;
            let steps = archive::steps(c, id)?;
            let step = if back {
                steps.iter().rev().find(|s| !s.undone)
            } else {
                steps.iter().find(|s| s.undone)
            };
            let step = step.ok_or_else(|| {
                ApiError::conflict(if back {
                    "nothing to undo"
                } else {
                    "nothing to redo"
                })
            })?;
            archive::set_undone(c, id, step.seq, back)?;
            let state = if back { &step.before } else { &step.after };
            archive::set_state(c, id, state)?;
            mode_of(&row)
        })?;
    with_mode!(name, M => M::moved(studio, id));
    Ok(Json(view(studio, id)?))
}

/// `GET /api/sessions/{id}/events`: the session's events, beginning with what its mode says
/// of where it stands (a design run's status).
pub(crate) async fn events(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Sse<impl tokio_stream::Stream<Item = Result<Event, Infallible>>>, ApiError> {
    let row = session_row(&studio, id)?;
    let receiver = studio.events.channel(id).subscribe();
    let name = mode_of(&row)?;
    let first = with_mode!(name, M => M::first_event(&studio, id)?);
    let rest = BroadcastStream::new(receiver).filter_map(|e| e.ok());
    let stream = tokio_stream::iter(first)
        .chain(rest)
        .map(|e| Ok(Event::default().event(e.name).data(e.data.to_string())));
    Ok(Sse::new(stream).keep_alive(KeepAlive::default()))
}

/// A model as the page sees it: what differs between models, from the models and modes.
#[derive(Serialize)]
pub(crate) struct ModelInfo {
    name: &'static str,
    title: &'static str,
    /// The modes whose sessions hold its plants.
    modes: Vec<ModeName>,
    /// The model a new breed session starts with.
    default: bool,
}

/// `GET /api/models`.
pub(crate) async fn models(State(studio): State<Studio>) -> Json<Vec<ModelInfo>> {
    let registry = &studio.registry;
    let per_mode: Vec<(ModeName, Vec<&str>)> = ModeName::ALL
        .into_iter()
        .map(|name| (name, with_mode!(name, M => M::models(registry))))
        .collect();
    Json(
        registry
            .models()
            .iter()
            .map(|m| ModelInfo {
                name: m.name(),
                title: m.title(),
                modes: per_mode
                    .iter()
                    .filter(|(_, models)| models.contains(&m.name()))
                    .map(|(name, _)| *name)
                    .collect(),
                default: m.name() == breed::default_model(),
            })
            .collect(),
    )
}
