//! Garden mode, the biomorph loop of L-system plants: the mother (in one corner) and her
//! mutated children grow together in one voxel world, shading each other; clicking a
//! specimen makes it the next mother and grows her garden.
//!
//! A specimen's shape depends on its neighbours, so its mesh is stored when the garden
//! grows (it cannot be grown alone again), and so is the whole garden's scene.

use axum::Json;
use axum::extract::{Path, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::json;
use sylva::biomorph::{self, BiomorphOptions, BiomorphSettings, Biomorphs};
use sylva::mesh::{Scene, SceneNode};
use sylva::{Genome, Registry};

use crate::Studio;
use crate::archive::{self, NewPlant, Operator, ParentRow, PlantRow};
use crate::error::ApiError;
use crate::http::Body;
use crate::modes::{Branch, Mode, Route};
use crate::plants::{extras, genome_of, parse_genome, plant_row};
use crate::sessions::{SessionView, example, session_of, step_seed, view};

/// The garden's controls; each optional in a request (the session's otherwise).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GardenSettings {
    /// Steps to grow, 0 to 1000. Default [`DEFAULT_STEPS`].
    pub steps: u32,
    /// Metres between neighbouring seeds, 0.25 to 2.5. Default [`DEFAULT_SPACING`]. (Sessions
    /// archived before it was a control grew 2.5 m apart.)
    #[serde(default = "paper_spacing")]
    pub spacing: f64,
    /// The light's height above the horizon, 0 to 90 degrees. Default 90 (straight down).
    pub elevation: f64,
    /// The compass direction the light comes from, 0 to 360 degrees. Default 0.
    pub azimuth: f64,
    /// Children sown with the mother, 0 to 8. Default 8.
    pub children: u32,
}

/// Steps a new garden grows: long enough that neighbours meet and shade each other.
pub const DEFAULT_STEPS: u32 = 150;
/// Metres between seeds in a new garden: close enough to compete by the end of its steps.
pub const DEFAULT_SPACING: f64 = 1.0;

fn paper_spacing() -> f64 {
    2.5
}

impl Default for GardenSettings {
    fn default() -> Self {
        GardenSettings {
            steps: DEFAULT_STEPS,
            spacing: DEFAULT_SPACING,
            elevation: 90.0,
            azimuth: 0.0,
            children: 8,
        }
    }
}

/// Changes to the controls.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct SettingsChange {
    steps: Option<u32>,
    spacing: Option<f64>,
    elevation: Option<f64>,
    azimuth: Option<f64>,
    children: Option<u32>,
}

impl GardenSettings {
    fn with(self, change: &SettingsChange) -> Result<GardenSettings, ApiError> {
        let s = GardenSettings {
            steps: change.steps.unwrap_or(self.steps),
            spacing: change.spacing.unwrap_or(self.spacing),
            elevation: change.elevation.unwrap_or(self.elevation),
            azimuth: change.azimuth.unwrap_or(self.azimuth),
            children: change.children.unwrap_or(self.children),
        };
        let range = |ok: bool, field: &str, range: &str, got: String| {
            if ok {
                Ok(())
            } else {
                Err(ApiError::bad(
                    format!("settings.{field}"),
                    format!("expected {range}, got {got}"),
                ))
            }
        };
        range(s.steps <= 1000, "steps", "0 to 1000", s.steps.to_string())?;
        range(
            s.spacing.is_finite() && (0.25..=2.5).contains(&s.spacing),
            "spacing",
            "0.25 to 2.5 metres",
            s.spacing.to_string(),
        )?;
        range(
            s.elevation.is_finite() && (0.0..=90.0).contains(&s.elevation),
            "elevation",
            "0 to 90 degrees",
            s.elevation.to_string(),
        )?;
        range(
            s.azimuth.is_finite() && (0.0..=360.0).contains(&s.azimuth),
            "azimuth",
            "0 to 360 degrees",
            s.azimuth.to_string(),
        )?;
        range(
            s.children <= 8,
            "children",
            "0 to 8",
            s.children.to_string(),
        )?;
        Ok(s)
    }

    fn options(&self) -> BiomorphOptions {
        BiomorphOptions {
            settings: BiomorphSettings {
                children: self.children,
                steps: self.steps,
                spacing: self.spacing as f32,
                elevation: self.elevation,
                azimuth: self.azimuth,
                // a person breeding by eye needs something to see, from empty rules too
                visible_children: true,
            },
            roots: false,
        }
    }
}

/// A specimen of the garden shown.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct SpecimenView {
    /// The plant.
    pub plant: i64,
    /// True for the mother.
    pub is_mother: bool,
    /// Where it grew, metres.
    pub x: f32,
    /// Where it grew, metres.
    pub z: f32,
    /// Biomass at the end, grams.
    pub biomass: f64,
    /// Light absorbed over its life.
    pub light: f64,
    /// Leaves.
    pub leaves: u32,
    /// Fine roots.
    pub fine_roots: u32,
}

/// A garden session's view.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct GardenState {
    /// The mother.
    pub mother: i64,
    /// The garden grown from her, mother first.
    pub specimens: Vec<SpecimenView>,
    /// The controls.
    pub settings: GardenSettings,
    /// The session's seed.
    pub seed: u64,
    /// The stored scene of the whole garden.
    pub scene: Option<i64>,
}

/// Where the first mother comes from.
#[derive(Deserialize, Debug)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Mother {
    /// An example genome (`lsystem/herb`).
    Example(String),
    /// A genome file's text.
    Genome(String),
    /// An archived L-system plant.
    Plant(i64),
    /// Empty rules, the paper's start.
    Empty(bool),
}

/// `POST /api/sessions` in garden mode.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct Start {
    start: Option<Mother>,
    #[serde(default)]
    settings: SettingsChange,
    seed: Option<u64>,
}

/// `genome`, when it can grow in a garden (its model grows biomorphs in `registry`).
fn biomorph_genome(registry: &Registry, genome: Genome, field: &str) -> Result<Genome, ApiError> {
    match biomorph::grows(registry, &genome) {
        Ok(()) => Ok(genome),
        Err(e) => Err(ApiError::unprocessable(
            field,
            format!("a {} genome; gardens grow L-system plants", e.model),
        )),
    }
}

/// How a new garden's mother came: made now (archived as a new plant), or archived already.
enum Came {
    Made(Operator, serde_json::Value),
    Archived(i64),
}

/// Creates a garden session and grows its first garden.
async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
    let settings = GardenSettings::default().with(&start.settings)?;
    let seed = start.seed.unwrap_or(1);
    let (mother, made) = match start
        .start
        .unwrap_or(Mother::Example("lsystem/herb".into()))
    {
        Mother::Example(name) => {
            let genome = example(&studio.registry, &name)
                .ok_or_else(|| ApiError::bad("start.example", format!("no example {name:?}")))?;
            (
                biomorph_genome(&studio.registry, genome, "start.example")?,
                Came::Made(Operator::Example, json!({"example": name})),
            )
        }
        Mother::Genome(text) => {
            let genome = parse_genome(&studio.registry, &text, "start.genome")?;
            (
                biomorph_genome(&studio.registry, genome, "start.genome")?,
                Came::Made(Operator::Upload, json!({})),
            )
        }
        Mother::Plant(id) => {
            let row = plant_row(studio, id).map_err(|mut e| {
                e.status = axum::http::StatusCode::BAD_REQUEST;
                e.field = "start.plant".into();
                e
            })?;
            let genome = genome_of(&studio.registry, &row)?;
            (
                biomorph_genome(&studio.registry, genome, "start.plant")?,
                Came::Archived(id),
            )
        }
        Mother::Empty(true) => (
            biomorph::first_mother(&studio.registry).ok_or_else(|| {
                ApiError::bad(
                    "start.empty",
                    "no model here grows biomorphs from empty rules",
                )
            })?,
            Came::Made(Operator::Empty, json!({})),
        ),
        Mother::Empty(false) => {
            return Err(ApiError::bad(
                "start.empty",
                "expected true (a garden from empty rules), or another start",
            ));
        }
    };
    let id = studio.archive.transaction(|c| -> Result<_, ApiError> {
        let model = mother.model();
        let id = archive::insert_session(c, GardenMode::NAME, model, "Garden", &json!({}))?;
        let mother_id = match &made {
            Came::Made(operator, settings) => archive::insert_plant(
                c,
                &NewPlant {
                    session: Some(id),
                    model,
                    genome: &mother.to_json(),
                    seed: 0,
                    operator: *operator,
                    settings,
                    parents: &[],
                },
            )?,
            Came::Archived(plant) => *plant,
        };
        let state = GardenState {
            mother: mother_id,
            specimens: Vec::new(),
            settings,
            seed,
            scene: None,
        };
        archive::set_state(c, id, &json!(state))?;
        Ok(id)
    })?;
    let state = garden_state(studio, id)?.1;
    let grown = grow_garden(studio, id, &state, &mother, 0).await?;
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        let after = store_garden(c, id, &state, grown)?;
        archive::set_state(c, id, &json!(after))?;
        Ok(())
    })?;
    Ok(id)
}

/// A new garden session whose mother is an archived plant.
async fn branch(studio: &Studio, row: &PlantRow) -> Result<i64, ApiError> {
    if !biomorph::models(&studio.registry)
        .iter()
        .any(|m| *m == row.model)
    {
        return Err(ApiError::bad(
            "mode",
            format!(
                "gardens grow L-system plants; plant {} is {}",
                row.id, row.model
            ),
        ));
    }
    create(
        studio,
        Start {
            start: Some(Mother::Plant(row.id)),
            settings: SettingsChange::default(),
            seed: None,
        },
    )
    .await
}

fn garden_state(studio: &Studio, id: i64) -> Result<(archive::SessionRow, GardenState), ApiError> {
    let row = session_of(studio, id, GardenMode::NAME)?;
    let state: GardenState = serde_json::from_value(row.state.clone())
        .map_err(|e| ApiError::internal(format!("session {id}'s state: {e}")))?;
    Ok((row, state))
}

/// A garden grown: each specimen's genome, figures and GLB, and the whole scene's GLB.
struct Grown {
    specimens: Vec<(Genome, bool, SpecimenView, Vec<u8>)>,
    scene: Vec<u8>,
}

/// Grows the mother's garden of `session` on the blocking pool, telling the pages watching
/// the session how far it has grown.
async fn grow_garden(
    studio: &Studio,
    session: i64,
    state: &GardenState,
    mother: &Genome,
    seq: i64,
) -> Result<Grown, ApiError> {
    let studio = studio.clone();
    let settings = state.settings;
    let seed = step_seed(state.seed, seq, 0);
    let mother = mother.clone();
    let mother_id = state.mother;
    tokio::task::spawn_blocking(move || -> Result<Grown, ApiError> {
        let sown = Biomorphs::sow(
            &studio.registry,
            &mother,
            std::path::Path::new("garden"),
            &settings.options(),
            seed,
        )
        .map_err(|e| ApiError::unprocessable("plant", e))?;
        let mut progress = crate::events::progress(&studio, session, "garden", settings.steps);
        let garden = sown
            .grow(&studio.pool, &mut progress)
            .map_err(|e| ApiError::unprocessable("settings", e.message))?;
        let parents = [ParentRow {
            plant: mother_id,
            dominance: 1.0,
        }];
        let node_extras = |specimen: &biomorph::Specimen| {
            let (operator, parents): (Operator, &[ParentRow]) = if specimen.is_mother {
                (Operator::Mother, &[])
            } else {
                (Operator::Mutate, &parents)
            };
            extras(&specimen.genome, seed, parents, operator.as_str())
        };
        let assets = garden
            .assets(|i, _| format!("specimen-{i}"), |_, s| node_extras(s))
            .map_err(|e| ApiError::library("settings", e))?;
        let scene =
            sylva::export::glb(&assets.scene()).map_err(|e| ApiError::library("settings", e))?;
        let mut specimens = Vec::with_capacity(garden.specimens.len());
        for (s, mesh) in garden.specimens.iter().zip(assets.meshes()) {
            let mut node = SceneNode::new(s.genome.model(), mesh);
            node.extras = Some(node_extras(s));
            let glb = sylva::export::glb(&Scene::single(node))
                .map_err(|e| ApiError::library("settings", e))?;
            let view = SpecimenView {
                plant: 0,
                is_mother: s.is_mother,
                x: s.position.x,
                z: s.position.z,
                biomass: s.stats.biomass,
                light: s.stats.light,
                leaves: s.stats.leaves,
                fine_roots: s.stats.fine_roots,
            };
            specimens.push((s.genome.clone(), s.is_mother, view, glb));
        }
        Ok(Grown { specimens, scene })
    })
    .await?
}

/// Archives a grown garden, every specimen with its mesh as it stands in this garden: the
/// children as new plants; the mother as herself the first time she grows (a plant of this
/// session without a mesh yet), else as a new plant of her genome (operator `mother`) whose
/// parent she is, so that her card, picture and export show her as she stands here (and a
/// plant branched from another session keeps its own mesh). Returns the view after,
/// whose mother is that plant.
fn store_garden(
    c: &rusqlite::Connection,
    session: i64,
    state: &GardenState,
    grown: Grown,
) -> Result<GardenState, ApiError> {
    let settings = json!(state.settings);
    let new_plant = |genome: &Genome, operator: Operator, parent: i64| {
        archive::insert_plant(
            c,
            &NewPlant {
                session: Some(session),
                model: genome.model(),
                genome: &genome.to_json(),
                seed: 0,
                operator,
                settings: &settings,
                parents: &[ParentRow {
                    plant: parent,
                    dominance: 1.0,
                }],
            },
        )
    };
    let mut mother = state.mother;
    let mut specimens = Vec::with_capacity(grown.specimens.len());
    // The mother comes first: her children are hers as she stands here.
    for (genome, is_mother, mut view, glb) in grown.specimens {
        let id = if is_mother {
            let ours = archive::plant(c, state.mother)?.is_some_and(|r| r.session == Some(session));
            if !ours || archive::mesh(c, state.mother)?.is_some() {
                mother = new_plant(&genome, Operator::Mother, state.mother)?;
            }
            mother
        } else {
            new_plant(&genome, Operator::Mutate, mother)?
        };
        archive::insert_mesh(c, id, &glb)?;
        view.plant = id;
        specimens.push(view);
    }
    let scene = archive::insert_scene(c, &grown.scene)?;
    Ok(GardenState {
        mother,
        specimens,
        scene: Some(scene),
        ..state.clone()
    })
}

/// `POST /api/sessions/{id}/grow`.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct GrowRequest {
    #[serde(default)]
    settings: SettingsChange,
}

/// Grows a garden from `mother` with `settings` as one step.
async fn step(
    studio: &Studio,
    id: i64,
    mother: i64,
    settings: &SettingsChange,
    action: serde_json::Value,
) -> Result<SessionView, ApiError> {
    let (_, before) = garden_state(studio, id)?;
    let row = plant_row(studio, mother)?;
    let genome = biomorph_genome(
        &studio.registry,
        genome_of(&studio.registry, &row)?,
        "plant",
    )?;
    let state = GardenState {
        mother,
        settings: before.settings.with(settings)?,
        ..before.clone()
    };
    let seq = studio.archive.read(|c| archive::next_seq(c, id))?;
    let grown = grow_garden(studio, id, &state, &genome, seq).await?;
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        let after = store_garden(c, id, &state, grown)?;
        archive::record_step(c, id, &action, &json!(before), &json!(after))?;
        Ok(())
    })?;
    view(studio, id)
}

/// `POST /api/sessions/{id}/grow`: the mother's garden grown again with new children.
pub(crate) async fn grow(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<GrowRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let (_, state) = garden_state(&studio, id)?;
    let action = json!({ "op": "grow", "settings": state.settings.with(&request.settings)? });
    Ok(Json(
        step(&studio, id, state.mother, &request.settings, action).await?,
    ))
}

/// `POST /api/sessions/{id}/pick`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct PickRequest {
    plant: i64,
}

/// `POST /api/sessions/{id}/pick`: a specimen becomes the mother, and her garden grows.
pub(crate) async fn pick(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<PickRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let (_, state) = garden_state(&studio, id)?;
    if !state.specimens.iter().any(|s| s.plant == request.plant) {
        return Err(ApiError::bad(
            "plant",
            format!("plant {} is not in this garden", request.plant),
        ));
    }
    let action = json!({ "op": "pick", "plant": request.plant });
    let change = SettingsChange::default();
    Ok(Json(
        step(&studio, id, request.plant, &change, action).await?,
    ))
}

/// `GET /api/sessions/{id}/garden.glb`.
pub(crate) async fn scene(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Response, ApiError> {
    let (_, state) = garden_state(&studio, id)?;
    let scene = state
        .scene
        .ok_or_else(|| ApiError::not_found("a grown garden"))?;
    let glb = studio
        .archive
        .read(|c| archive::scene(c, scene))?
        .ok_or_else(|| ApiError::not_found(format!("scene {scene}")))?;
    Ok(([(header::CONTENT_TYPE, "model/gltf-binary")], glb).into_response())
}

/// Garden mode, behind the studio's mode seam.
pub struct GardenMode;

impl Mode for GardenMode {
    const NAME: &'static str = "garden";
    type Start = Start;
    const BRANCH: Option<Branch> = Some(Branch {
        label: "Branch to a garden",
        hint: "A new garden with this plant as the mother",
    });

    fn models(registry: &Registry) -> Vec<&'static str> {
        biomorph::models(registry)
    }

    async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
        create(studio, start).await
    }

    async fn branch(studio: &Studio, plant: &PlantRow) -> Result<i64, ApiError> {
        branch(studio, plant).await
    }

    fn routes() -> Vec<Route> {
        vec![
            Route::post("/sessions/{id}/grow", grow),
            Route::post("/sessions/{id}/pick", pick),
            Route::get("/sessions/{id}/garden.glb", scene),
        ]
    }
}
