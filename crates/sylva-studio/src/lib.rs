//! Sylva's studio: a web server and a single page where a person breeds plants by eye, in
//! the four ways the papers did, with every plant and choice kept in an SQLite archive.
//!
//! - [`archive`]: the SQLite archive ([`Archive`]): sessions, plants, parentage, steps, runs.
//! - [`modes`]: the modes behind one seam ([`modes::Mode`]), listed once in
//!   [`modes::MODES`]: breed (PlantMaker's main window, for any model), garden (the
//!   biomorph loop of L-system plants), family (the binary-tree population), design (the
//!   GP designer's runs), match (design from a picture) and map (variety maps of any
//!   model); sessions start, branch, undo and redo through it, and `GET /api/modes` gives
//!   the page its tabs from it.
//! - [`sessions`]: sessions as stored and viewed, examples, step seeds.
//! - [`settings`]: model settings a page's form asks for, built typed and read with their
//!   own checks.
//! - [`runs`]: evolution runs in the archive, shared by family and design.
//! - [`events`]: what sessions tell the pages watching them (server-sent events).
//! - [`plants`]: plants as GLB, previews, OBJ, STL, PNG and genome files, and their lineage.
//! - [`edits`]: field edits checked against each model's schema, the schema for the page's
//!   controls, and sketches (a plant with fields set, drawn, recorded nowhere).
//! - [`pruning`]: plants pruned to a match run's outlines, as breed, match and the plant
//!   routes show them.
//! - [`cache`]: what is kept in memory (grown plants, GLBs), bounded.
//! - [`guard`]: who may talk to the studio: Host names, other sites' pages, content types,
//!   the access token.
//! - [`listen`]: connections, with request heads bounded before hyper parses them.
//! - [`http`]: typed JSON bodies and the page's files, built into the binary.
//!
//! The server is a client of the library layer (the `sylva` crate), never of the command
//! line. Heavy work (growing, meshing, evolving) runs on the blocking pool or a run's own
//! thread, so the async threads stay free; every acknowledged step is committed to SQLite
//! before the answer goes out. `docs/studio.md` documents every endpoint.
//!
//! ```no_run
//! let options = sylva_studio::Options::default();
//! sylva_studio::serve(options)?; // prints the address, serves until Ctrl+C
//! # Ok::<(), sylva_studio::StartError>(())
//! ```

pub mod archive;
pub mod cache;
pub mod edits;
pub mod error;
pub mod events;
pub mod guard;
pub mod http;
pub mod listen;
pub mod modes;
pub mod plants;
pub mod pruning;
pub mod runs;
pub mod sessions;
pub mod settings;

use std::any::{Any, TypeId};
use std::collections::HashMap;
use std::net::SocketAddr;
use std::ops::Deref;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use axum::Router;
use rand::RngExt;
use sylva::Registry;

pub use archive::{Archive, ArchiveError};
pub use error::ApiError;

/// How to start the studio.
#[derive(Clone, Debug)]
pub struct Options {
    /// The address to bind: 127.0.0.1 by default. Any other needs the access token.
    pub host: String,
    /// The port; 0 picks a free one.
    pub port: u16,
    /// The archive file.
    pub db: PathBuf,
    /// Host names the studio answers to besides its loopback names and bound address (a
    /// reverse proxy's name).
    pub allow_hosts: Vec<String>,
    /// The models the studio knows. Default: [`Registry::standard`].
    pub registry: Registry,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            host: "127.0.0.1".into(),
            port: 8417,
            db: PathBuf::from("sylva-studio.db"),
            allow_hosts: Vec::new(),
            registry: Registry::standard(),
        }
    }
}

/// Why the studio could not start.
#[derive(Debug, thiserror::Error)]
pub enum StartError {
    /// The archive could not be opened.
    #[error("opening the archive {path}")]
    Archive {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: ArchiveError,
    },
    /// The binary was built without three.js, so the page cannot run.
    #[error(
        "this sylva was built without three.js, which the studio's page needs: in the source \
         checkout, run `npm ci --prefix crates/sylva-studio/web`, then build (or install) again"
    )]
    NoThree,
    /// The address could not be bound.
    #[error("binding {address}")]
    Bind {
        /// host:port.
        address: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The runtime or a worker could not start.
    #[error("starting the server")]
    Runtime(#[source] std::io::Error),
}

/// The studio's shared state: cheap to clone (one `Arc`).
#[derive(Clone)]
pub struct Studio(Arc<Inner>);

/// What the studio holds.
pub struct Inner {
    /// The archive.
    pub archive: Archive,
    /// The models it knows.
    pub registry: Registry,
    /// Who may talk to the studio.
    pub guard: guard::Guard,
    /// Recently served meshes.
    pub meshes: plants::MeshCache,
    /// Recently grown plants.
    pub plants: plants::PlantCache,
    /// Recently drawn pictures (thumbnails).
    pub pictures: plants::PictureCache,
    /// Threads for growing many plants at once.
    pub pool: sylva::core::par::Pool,
    /// One lock per session, so that two tabs' steps on one session queue up.
    locks: Mutex<HashMap<i64, Arc<tokio::sync::Mutex<()>>>>,
    /// What the modes keep in memory beside the archive, one value of each type
    /// ([`Studio::kept`]).
    kept: Mutex<HashMap<TypeId, Arc<dyn Any + Send + Sync>>>,
    /// Design runs and maps going on.
    pub runs: runs::Runs,
    /// The channels of the pages watching sessions.
    pub events: events::Events,
}

impl Deref for Studio {
    type Target = Inner;
    fn deref(&self) -> &Inner {
        &self.0
    }
}

impl Studio {
    /// A studio of the standard models on an archive, guarded by `guard`.
    pub fn new(archive: Archive, guard: guard::Guard) -> Studio {
        Studio::with_registry(archive, guard, Registry::standard())
    }

    /// A studio of the models of `registry` (the standard ones and a user's own).
    pub fn with_registry(archive: Archive, guard: guard::Guard, registry: Registry) -> Studio {
        Studio(Arc::new(Inner {
            archive,
            registry,
            guard,
            meshes: plants::mesh_cache(),
            plants: plants::plant_cache(),
            pictures: plants::picture_cache(),
            pool: sylva::core::par::Pool::with_threads(0).unwrap_or_default(),
            locks: Mutex::default(),
            kept: Mutex::default(),
            runs: runs::Runs::default(),
            events: events::Events::default(),
        }))
    }

    /// The lock of a session's steps.
    pub fn session_lock(&self, session: i64) -> Arc<tokio::sync::Mutex<()>> {
        let mut locks = self.locks.lock().unwrap_or_else(|p| p.into_inner());
        locks.entry(session).or_default().clone()
    }

    /// What a mode keeps in memory beside the archive (family mode's runs), by its type:
    /// one value of each type per studio, made empty when first asked for.
    pub fn kept<T: Any + Default + Send + Sync>(&self) -> Arc<T> {
        let mut kept = self.kept.lock().unwrap_or_else(|p| p.into_inner());
        let value = kept
            .entry(TypeId::of::<T>())
            .or_insert_with(|| Arc::new(T::default()))
            .clone();
        // Each value is kept under its own type's id, so this is always that type.
        value.downcast().unwrap_or_default()
    }
}

/// The studio's routes.
pub fn router(studio: Studio) -> Router {
    use http::Route;
    let api: Vec<Route> = [
        Route::get("/modes", modes::modes),
        Route::get("/models", modes::models),
        Route::get("/examples", sessions::examples),
        Route::get("/sessions", sessions::list),
        Route::post("/sessions", modes::create),
        Route::get("/sessions/{id}", sessions::get),
        Route::post("/sessions/{id}/undo", modes::undo),
        Route::post("/sessions/{id}/redo", modes::redo),
        Route::get("/sessions/{id}/events", modes::events),
        Route::get("/plants", plants::list),
        Route::get("/plants/{id}", plants::get),
        Route::get("/plants/{id}/plant.glb", plants::glb),
        Route::get("/plants/{id}/inspect", plants::inspect),
        Route::get("/kinds", plants::kinds),
        Route::get("/schema/{model}", edits::schema),
        Route::get("/plants/{id}/preview.glb", plants::preview),
        Route::get("/plants/{id}/plant.obj", plants::obj),
        Route::get("/plants/{id}/plant.mtl", plants::mtl),
        Route::get("/plants/{id}/plant.zip", plants::obj_zip),
        Route::get("/plants/{id}/plant.stl", plants::stl),
        Route::get("/plants/{id}/plant.png", plants::png),
        Route::get("/plants/{id}/genome.json", plants::genome),
        Route::post("/plants/{id}/sketch.png", edits::sketch),
        Route::get("/plants/{id}/{file}", plants::texture),
        Route::get("/plants/{id}/lineage", plants::lineage),
        Route::post("/plants/{id}/branch", modes::branch),
    ]
    .into_iter()
    .chain(modes::routes())
    .collect();
    let page = vec![
        Route::get("/vendor/three/{*path}", http::vendor),
        Route::get("/", http::page),
        Route::get("/app/{*path}", http::page),
    ];
    let takes = http::Takes::of(&[("/api", &api), ("", &page)]);
    let api = http::routed(api).fallback(|| async { ApiError::not_found("no such endpoint") });
    http::with_405(http::routed(page).nest("/api", api), takes)
        .layer(axum::middleware::from_fn_with_state(
            studio.clone(),
            guard::check,
        ))
        .layer(axum::middleware::from_fn(http::json_errors))
        .layer(axum::extract::DefaultBodyLimit::max(http::MAX_BODY))
        .with_state(studio)
}

/// Whether `host` is a loopback address (no token needed).
pub fn is_loopback(host: &str) -> bool {
    host == "localhost"
        || host
            .trim_matches(['[', ']'])
            .parse::<std::net::IpAddr>()
            .is_ok_and(|ip| ip.is_loopback())
}

/// A fresh access token: 32 hex digits from the system's randomness.
fn new_token() -> String {
    let mut rng = rand::rng();
    (0..16)
        .map(|_| format!("{:02x}", rng.random::<u8>()))
        .collect()
}

/// Opens the archive, resumes the runs that were running, binds, prints the address and
/// serves until Ctrl+C.
pub fn serve(options: Options) -> Result<(), StartError> {
    if http::THREE.is_empty() {
        return Err(StartError::NoThree);
    }
    let archive = Archive::open(&options.db).map_err(|source| StartError::Archive {
        path: options.db.clone(),
        source,
    })?;
    let token = (!is_loopback(&options.host)).then(new_token);
    let guard = guard::Guard::new(&options.host, &options.allow_hosts, token.clone());
    let studio = Studio::with_registry(archive, guard, options.registry.clone());
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(StartError::Runtime)?;
    runtime.block_on(async move {
        let address = format!("{}:{}", options.host, options.port);
        let listener = tokio::net::TcpListener::bind(&address)
            .await
            .map_err(|source| StartError::Bind {
                address: address.clone(),
                source,
            })?;
        let bound: SocketAddr = listener.local_addr().map_err(StartError::Runtime)?;
        modes::resume_all(&studio);
        warm_textures();
        let query = token.map(|t| format!("?token={t}")).unwrap_or_default();
        // Written, not printed: a closed stdout must not stop the server.
        use std::io::Write;
        let mut out = std::io::stdout();
        let _ = writeln!(out, "Sylva studio: http://{}/{query}", openable(bound));
        if bound.ip().is_unspecified()
            && let Some(name) = guard::machine_name()
        {
            let _ = writeln!(
                out,
                "from other machines: http://{name}:{}/{query}",
                bound.port()
            );
        }
        let _ = writeln!(out, "archive: {}", options.db.display());
        let _ = out.flush();
        listen::serve(listener, router(studio.clone()), async {
            let _ = tokio::signal::ctrl_c().await;
        })
        .await
        .map_err(StartError::Runtime)?;
        studio.runs.stop_all();
        Ok(())
    })
}

/// Sylva's textures a genome can name: PlantMaker's genome texture 1 to 127 is Sylva texture
/// 0 to 126 (the other models name none).
const GENOME_TEXTURES: std::ops::Range<u16> = 0..127;

/// Makes every texture a genome can name, and its PNG, on a thread of its own while the
/// studio waits for its first page. A texture is a pure function of its id, kept once made,
/// and the first of each costs tens of milliseconds (noise, then the best PNG compression):
/// made here, no breeding step pays for them.
fn warm_textures() {
    let _ = std::thread::Builder::new()
        .name("sylva-textures".into())
        .spawn(|| {
            for id in GENOME_TEXTURES {
                let _ = sylva::mesh::texture::texture_png(id);
            }
        });
}

/// An address a browser on this machine can open for `bound`: loopback for a studio bound
/// to every interface (`0.0.0.0` is not an address to open), brackets for IPv6.
fn openable(bound: SocketAddr) -> String {
    match bound {
        SocketAddr::V4(a) if a.ip().is_unspecified() => format!("127.0.0.1:{}", a.port()),
        SocketAddr::V6(a) if a.ip().is_unspecified() => format!("[::1]:{}", a.port()),
        SocketAddr::V6(a) => format!("[{}]:{}", a.ip(), a.port()),
        SocketAddr::V4(a) => a.to_string(),
    }
}
