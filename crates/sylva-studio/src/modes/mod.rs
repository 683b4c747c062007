//! The studio's modes, each a module behind one seam, [`Mode`]: how a session of it starts,
//! how it starts from an archived plant, its own endpoints, what it tells a page that begins
//! watching it, and what it starts again when the studio does. [`MODES`] is the one list of
//! them: the session code, `GET /api/modes` and the page's tabs all read it, and reach a
//! mode only through its entry.
//!
//! - [`breed`]: PlantMaker's main window (the 3×3 grid, cross and mutate), for any model.
//! - [`garden`]: the biomorph loop of L-system plants grown together in a voxel world.
//! - [`family`]: the deciduous-evolution viewer's binary-tree population.
//! - [`design`]: the GP designer's evolutions of automata trees, run in the background.
//! - [`matching`]: design from a picture: an evolution of any model towards a target
//!   outline, run in the background.
//! - [`map`]: variety maps (MAP-Elites) of any model, filled in the background.
//!
//! A mode never imports another mode, and nothing below the modes imports one: what two
//! modes share lives below them (plants pruned to a match's outlines in
//! [`crate::pruning`], background runs in [`crate::runs`], typed settings in
//! [`crate::settings`]).
//!
//! **Adding a mode** takes three things:
//!
//! 1. a module here implementing [`Mode`]: its `NAME` (a session's `mode` in requests and
//!    the archive, kept once sessions of it are archived), its `Start` (the fields of
//!    `POST /api/sessions` besides `mode`), `create`, and its [`Route`]s; `branch` with its
//!    `BRANCH` button on the plant panel, `first_event`, `moved` and `resume` if it needs
//!    them; what it keeps in memory through
//!    [`Studio::kept`](crate::Studio::kept);
//! 2. one [`ModeEntry::of`] line in [`MODES`]: its tab's label and hint, and its page
//!    module;
//! 3. that page module, `web/app/NAME.js`, whose default export makes the mode's view
//!    (`export default function (ctx, root)`, as `breed.js` does).
//!
//! Nothing else changes: the router, `GET /api/modes`, `GET /api/models`, sessions, undo
//! and redo, and the page's tabs reach the mode through its entry.

pub mod breed;
pub mod design;
pub mod family;
pub mod garden;
pub mod map;
pub mod matching;

use std::convert::Infallible;
use std::future::Future;
use std::pin::Pin;

use axum::Json;
use axum::extract::{Path, State};
use axum::response::sse::{Event, KeepAlive, Sse};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use sylva::Registry;
use tokio_stream::StreamExt;
use tokio_stream::wrappers::BroadcastStream;

use crate::Studio;
use crate::archive::{self, PlantRow};
use crate::error::ApiError;
use crate::events::SessionEvent;
pub use crate::http::Route;
use crate::http::{Body, from_value};
use crate::plants::plant_row;
use crate::sessions::{SessionView, session_row, view};

/// What every mode does, for the session code.
pub trait Mode: 'static {
    /// Its name in requests, the archive and the page: a session's `mode`. Archived
    /// sessions keep it, so it never changes once a studio has stored one.
    const NAME: &'static str;

    /// How a session of it starts: the fields of `POST /api/sessions` besides `mode`.
    type Start: DeserializeOwned + Send;

    /// The models whose plants its sessions hold (every model, or one paper's).
    fn models(registry: &Registry) -> Vec<&'static str>;

    /// Creates a session and takes its first step; returns the session's id.
    fn create(
        studio: &Studio,
        start: Self::Start,
    ) -> impl Future<Output = Result<i64, ApiError>> + Send;

    /// The plant panel's button that starts a session of this mode from a plant
    /// ([`Mode::branch`]); none for a mode whose sessions start from their own settings.
    const BRANCH: Option<Branch> = None;

    /// A new session whose first plants are `plant` (`POST /api/plants/{id}/branch`), for a
    /// mode with a [`Mode::BRANCH`] button.
    fn branch(
        studio: &Studio,
        plant: &PlantRow,
    ) -> impl Future<Output = Result<i64, ApiError>> + Send {
        let _ = (studio, plant);
        async {
            let branching: Vec<&str> = MODES
                .iter()
                .filter(|m| m.branch_button.is_some())
                .map(|m| m.name)
                .collect();
            Err(ApiError::bad(
                "mode",
                format!(
                    "a {} session starts from its own settings, not from a plant; branch to \
                     a session of {}",
                    Self::NAME,
                    branching.join(" or ")
                ),
            ))
        }
    }

    /// Its endpoints under `/api`, which `GET /api/modes` lists.
    fn routes() -> Vec<Route>;

    /// What a page that begins watching a session is told first (a run's status).
    fn first_event(studio: &Studio, session: i64) -> Result<Option<SessionEvent>, ApiError> {
        let _ = (studio, session);
        Ok(None)
    }

    /// The session's view moved under it (undo, redo): drop what is held in memory.
    fn moved(studio: &Studio, session: i64) {
        let _ = (studio, session);
    }

    /// The studio starts: take up again what its sessions had going when it stopped (or
    /// was killed), such as background runs.
    fn resume(studio: &Studio) {
        let _ = studio;
    }
}

/// A button of the plant panel that starts a session of a mode from the plant shown.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Branch {
    /// What the button says.
    pub label: &'static str,
    /// What it says when pointed at.
    pub hint: &'static str,
}

/// A step of a mode that answers later, boxed so that every mode's fits one entry.
type Pending<T> = Pin<Box<dyn Future<Output = Result<T, ApiError>> + Send>>;

/// A mode as the studio lists it: its tab, its page module, and its code behind [`Mode`].
pub struct ModeEntry {
    /// Its name ([`Mode::NAME`]).
    pub name: &'static str,
    /// Its tab's label.
    pub label: &'static str,
    /// What its tab says when pointed at.
    pub hint: &'static str,
    /// Its page module: `web/app/{page}`, served as `/app/{page}`.
    pub page: &'static str,
    /// The plant panel's button that branches to it ([`Mode::BRANCH`]).
    pub branch_button: Option<Branch>,
    models: fn(&Registry) -> Vec<&'static str>,
    routes: fn() -> Vec<Route>,
    create: fn(Studio, serde_json::Value) -> Pending<i64>,
    branch: fn(Studio, PlantRow) -> Pending<i64>,
    first_event: fn(&Studio, i64) -> Result<Option<SessionEvent>, ApiError>,
    moved: fn(&Studio, i64),
    resume: fn(&Studio),
}

impl ModeEntry {
    /// Mode `M`, shown as a tab labelled `label` (pointed at: `hint`) whose view
    /// `web/app/{page}` makes.
    pub const fn of<M: Mode>(label: &'static str, page: &'static str, hint: &'static str) -> Self {
        ModeEntry {
            name: M::NAME,
            label,
            hint,
            page,
            branch_button: M::BRANCH,
            models: M::models,
            routes: M::routes,
            create: create_as::<M>,
            branch: branch_as::<M>,
            first_event: M::first_event,
            moved: M::moved,
            resume: M::resume,
        }
    }
}

/// Every mode, in the order the page shows their tabs: the one list of them (see the
/// module's docs for adding one).
pub static MODES: &[ModeEntry] = &[
    ModeEntry::of::<breed::BreedMode>(
        "Breed",
        "breed.js",
        "PlantMaker's main window (Sipper et al., §2)",
    ),
    ModeEntry::of::<garden::GardenMode>(
        "Garden",
        "garden.js",
        "Bornhofen and Lattaud's biomorph loop (§4.1)",
    ),
    ModeEntry::of::<family::FamilyMode>(
        "Family",
        "family.js",
        "Susinno's deciduous-evolution viewer",
    ),
    ModeEntry::of::<design::DesignMode>("Design", "design.js", "Poncin's designer (§4)"),
    ModeEntry::of::<matching::MatchMode>(
        "Match",
        "match.js",
        "Design from a picture: evolve a plant whose outline matches it",
    ),
    ModeEntry::of::<map::MapMode>(
        "Map",
        "map.js",
        "A variety map: the fittest plant of every kind (MAP-Elites)",
    ),
];

/// The mode named `name`.
pub fn mode(name: &str) -> Option<&'static ModeEntry> {
    MODES.iter().find(|m| m.name == name)
}

/// The modes' names, for an error: `breed, garden, family, design, match or map`.
pub fn expected() -> String {
    let names: Vec<&str> = MODES.iter().map(|m| m.name).collect();
    let (last, rest) = names.split_last().unwrap_or((&"", &[]));
    format!("{} or {last}", rest.join(", "))
}

fn create_as<M: Mode>(studio: Studio, rest: serde_json::Value) -> Pending<i64> {
    Box::pin(async move {
        let start: M::Start = from_value(rest, "")?;
        M::create(&studio, start).await
    })
}

fn branch_as<M: Mode>(studio: Studio, plant: PlantRow) -> Pending<i64> {
    Box::pin(async move { M::branch(&studio, &plant).await })
}

/// Every mode's endpoints, under `/api`.
pub fn routes() -> Vec<Route> {
    MODES.iter().flat_map(|m| (m.routes)()).collect()
}

/// Takes up again what every mode had going when the studio stopped.
pub fn resume_all(studio: &Studio) {
    for m in MODES {
        (m.resume)(studio);
    }
}

/// A session's mode, read from its row.
fn mode_of(row: &archive::SessionRow) -> Result<&'static ModeEntry, ApiError> {
    mode(&row.mode).ok_or_else(|| {
        ApiError::internal(format!(
            "session {} has an unknown mode {:?}",
            row.id, row.mode
        ))
    })
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
    let modes = expected();
    let entry = match fields.remove("mode") {
        Some(serde_json::Value::String(name)) => mode(&name)
            .ok_or_else(|| ApiError::bad("mode", format!("expected {modes}, got {name:?}")))?,
        Some(other) => {
            return Err(ApiError::bad(
                "mode",
                format!("expected {modes}, got {other}"),
            ));
        }
        None => return Err(ApiError::bad("mode", format!("missing: expected {modes}"))),
    };
    let rest = serde_json::Value::Object(fields);
    let id = (entry.create)(studio.clone(), rest).await?;
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
    let name = request.mode.as_deref().unwrap_or(breed::BreedMode::NAME);
    let entry = mode(name)
        .ok_or_else(|| ApiError::bad("mode", format!("expected {}, got {name:?}", expected())))?;
    let session = (entry.branch)(studio.clone(), row).await?;
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
    let entry = studio
        .archive
        .transaction(|c| -> Result<&'static ModeEntry, ApiError> {
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
    (entry.moved)(studio, id);
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
    let first = (mode_of(&row)?.first_event)(&studio, id)?;
    let rest = BroadcastStream::new(receiver).filter_map(|e| e.ok());
    let stream = tokio_stream::iter(first)
        .chain(rest)
        .map(|e| Ok(Event::default().event(e.name).data(e.data.to_string())));
    Ok(Sse::new(stream).keep_alive(KeepAlive::default()))
}

/// An endpoint as `GET /api/modes` lists it.
#[derive(Serialize)]
pub(crate) struct RouteInfo {
    method: String,
    path: String,
}

/// A mode as the page sees it: [`MODES`]' entry, with its endpoints and the models whose
/// plants it holds.
#[derive(Serialize)]
pub(crate) struct ModeInfo {
    name: &'static str,
    label: &'static str,
    hint: &'static str,
    /// The page module that makes its view, which the page imports.
    page: String,
    routes: Vec<RouteInfo>,
    models: Vec<&'static str>,
    /// The plant panel's button that starts a session of it from a plant of its models.
    branch: Option<Branch>,
}

/// `GET /api/modes`: every mode, in the order of their tabs.
pub(crate) async fn modes(State(studio): State<Studio>) -> Json<Vec<ModeInfo>> {
    Json(
        MODES
            .iter()
            .map(|m| ModeInfo {
                name: m.name,
                label: m.label,
                hint: m.hint,
                page: format!("/app/{}", m.page),
                routes: (m.routes)()
                    .iter()
                    .map(|r| RouteInfo {
                        method: r.method.to_string(),
                        path: format!("/api{}", r.path),
                    })
                    .collect(),
                models: (m.models)(&studio.registry),
                branch: m.branch_button,
            })
            .collect(),
    )
}

/// A model as the page sees it: what differs between models, from the models and modes.
#[derive(Serialize)]
pub(crate) struct ModelInfo {
    name: &'static str,
    title: &'static str,
    /// The modes whose sessions hold its plants.
    modes: Vec<&'static str>,
    /// The model a new breed session starts with.
    default: bool,
}

/// `GET /api/models`.
pub(crate) async fn models(State(studio): State<Studio>) -> Json<Vec<ModelInfo>> {
    let registry = &studio.registry;
    let per_mode: Vec<(&str, Vec<&str>)> = MODES
        .iter()
        .map(|m| (m.name, (m.models)(registry)))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::guard::Guard;
    use crate::{Archive, router};
    use axum::body::Body as Bytes;
    use axum::http::{Request, StatusCode};
    use tower::ServiceExt;

    /// A studio on a fresh archive in its own folder.
    fn studio(name: &str) -> (Studio, std::path::PathBuf) {
        let dir = std::env::temp_dir().join(format!("sylva-modes-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let archive = Archive::open(&dir.join("studio.db")).unwrap();
        (Studio::new(archive, Guard::default()), dir)
    }

    /// Sends a request to the studio's router: its status, content type and body.
    fn send(studio: &Studio, method: &str, path: &str) -> (StatusCode, String, Vec<u8>) {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        runtime.block_on(async {
            let request = Request::builder()
                .method(method)
                .uri(path)
                .header("host", "127.0.0.1")
                .header("content-type", "application/json")
                .body(if method == "POST" {
                    Bytes::from("{}")
                } else {
                    Bytes::empty()
                })
                .unwrap();
            let response = router(studio.clone()).oneshot(request).await.unwrap();
            let status = response.status();
            let kind = response
                .headers()
                .get("content-type")
                .and_then(|v| v.to_str().ok())
                .unwrap_or("")
                .to_owned();
            let body = axum::body::to_bytes(response.into_body(), usize::MAX)
                .await
                .unwrap();
            (status, kind, body.to_vec())
        })
    }

    #[test]
    fn the_studio_lists_every_mode_with_its_routes_and_page() {
        let (studio, dir) = studio("list");
        let (status, _, body) = send(&studio, "GET", "/api/modes");
        assert_eq!(status, StatusCode::OK);
        let listed: serde_json::Value = serde_json::from_slice(&body).unwrap();
        let listed = listed.as_array().unwrap();
        // Every mode, once, in the table's order; the archive's names as they always were.
        let names: Vec<&str> = listed.iter().map(|m| m["name"].as_str().unwrap()).collect();
        assert_eq!(
            names,
            ["breed", "garden", "family", "design", "match", "map"]
        );
        let mut every_route = std::collections::HashSet::new();
        for (mode, entry) in listed.iter().zip(MODES) {
            assert_eq!(mode["label"], entry.label);
            assert_eq!(mode["hint"], entry.hint);
            assert!(!mode["models"].as_array().unwrap().is_empty(), "{mode}");
            let routes = mode["routes"].as_array().unwrap();
            assert!(!routes.is_empty(), "{mode}");
            for route in routes {
                let (method, path) = (
                    route["method"].as_str().unwrap(),
                    route["path"].as_str().unwrap(),
                );
                assert!(
                    every_route.insert((method.to_owned(), path.to_owned())),
                    "{method} {path} is listed twice"
                );
                // Each route listed is one the router answers: never the fallback's 404
                // nor a 405 (a session that does not exist is the handler's own answer).
                let (status, _, body) = send(&studio, method, &path.replace("{id}", "999999"));
                let text = String::from_utf8_lossy(&body);
                assert_ne!(status, StatusCode::METHOD_NOT_ALLOWED, "{method} {path}");
                assert!(
                    !text.contains("no such endpoint"),
                    "{method} {path} is listed but not routed: {text}"
                );
            }
            // Its tab's view comes from its page module, served as a module whose default
            // export makes the view.
            let page = mode["page"].as_str().unwrap();
            // The plant panel's button, for a mode that starts from a plant.
            match entry.branch_button {
                Some(button) => assert_eq!(mode["branch"]["label"], button.label),
                None => assert!(mode["branch"].is_null(), "{mode}"),
            }
            let (status, kind, body) = send(&studio, "GET", page);
            assert_eq!(status, StatusCode::OK, "{page}");
            assert!(kind.starts_with("text/javascript"), "{page}: {kind}");
            assert!(
                String::from_utf8_lossy(&body).contains("export default function"),
                "{page} has no default export"
            );
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn methods_a_path_does_not_take_are_405_with_what_it_takes() {
        let (studio, dir) = studio("methods");
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        // No content type, as `curl -X DELETE` sends: the method is what is wrong.
        let answer = |method: &str, path: &str| {
            runtime.block_on(async {
                let request = Request::builder()
                    .method(method)
                    .uri(path)
                    .header("host", "127.0.0.1")
                    .body(Bytes::empty())
                    .unwrap();
                let response = router(studio.clone()).oneshot(request).await.unwrap();
                let status = response.status();
                let allow = response
                    .headers()
                    .get("allow")
                    .map(|v| v.to_str().unwrap().to_owned());
                let body = axum::body::to_bytes(response.into_body(), usize::MAX)
                    .await
                    .unwrap();
                let body: serde_json::Value = serde_json::from_slice(&body).unwrap();
                (
                    status,
                    allow,
                    body["error"].as_str().unwrap_or("").to_owned(),
                )
            })
        };
        for (method, path, allow) in [
            ("DELETE", "/api/sessions", "GET,HEAD,POST"),
            ("TRACE", "/", "GET,HEAD"),
            ("PUT", "/api/plants/1", "GET,HEAD"),
            ("FOO", "/api/sessions/1/undo", "POST"),
            // a path the studio does not know takes nothing
            ("TRACE", "/api/no-such-thing", ""),
            ("FOO", "/nowhere", ""),
        ] {
            let (status, got, error) = answer(method, path);
            assert_eq!(status, StatusCode::METHOD_NOT_ALLOWED, "{method} {path}");
            assert_eq!(got.as_deref(), Some(allow), "{method} {path}");
            assert!(error.contains(method), "{method} {path}: {error}");
        }
        // A method the studio takes on a path it does not know is still 404.
        let (status, _, _) = answer("GET", "/api/no-such-thing");
        assert_eq!(status, StatusCode::NOT_FOUND);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn the_page_names_no_mode_of_its_own() {
        // The tabs and views come from `GET /api/modes`: the page's shell and its main
        // module list none, and import no mode's page module.
        let (studio, dir) = studio("page");
        let (_, _, shell) = send(&studio, "GET", "/");
        let (_, _, main) = send(&studio, "GET", "/app/main.js");
        let (_, _, panel) = send(&studio, "GET", "/app/detail.js");
        let (shell, main, panel) = (
            String::from_utf8_lossy(&shell),
            String::from_utf8_lossy(&main),
            String::from_utf8_lossy(&panel),
        );
        assert!(shell.contains(r#"id="modes""#) && shell.contains(r#"id="main""#));
        for entry in MODES {
            assert!(
                !shell.contains(&format!("view-{}", entry.name)),
                "{}",
                entry.name
            );
            assert!(
                !shell.contains(&format!("mode-{}", entry.name)),
                "{}",
                entry.name
            );
            assert!(
                !main.contains(&format!("./{}", entry.page)),
                "{}",
                entry.page
            );
            // The plant panel's branch buttons come from the list too.
            assert!(
                !panel.contains(&format!("\"{}\"", entry.name)),
                "detail.js names {}",
                entry.name
            );
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn sessions_of_every_mode_are_asked_for_by_its_name() {
        let (studio, dir) = studio("names");
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        let asked = |body: serde_json::Value| {
            runtime
                .block_on(create(State(studio.clone()), Body(body)))
                .err()
                .unwrap()
        };
        let e = asked(serde_json::json!({"mode": "garten"}));
        assert_eq!(e.field, "mode");
        assert!(
            e.error
                .contains("breed, garden, family, design, match or map"),
            "{e}"
        );
        // Each mode's own fields follow its name, and their errors name them.
        for entry in MODES {
            let e = asked(serde_json::json!({"mode": entry.name, "colour": 1}));
            assert_eq!(e.field, "colour", "{}: {e}", entry.name);
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}
