//! Breed mode, PlantMaker's main window: nine plants in a grid, most dominant first; cross
//! two or more (with a level and a dominance per parent) or mutate one (with a Depth); the
//! offspring take the places of the least dominant plants. Works for any model: the level
//! and Depth are PlantMaker's settings, other models breed with their own defaults.
//!
//! A plant's dominance is the step at which it last took part (born, or chosen as a
//! parent), so a step's parents and offspring lead the grid and the plants left alone
//! longest are replaced (`docs/studio.md`).

use std::sync::Arc;

use axum::Json;
use axum::extract::{Path, State};
use serde::{Deserialize, Serialize};
use serde_json::json;
use sylva::core::Plant;
use sylva::evolution::outline::Outline;
use sylva::{CrossLevel, Depth, Genome, Knobs, Registry, Settings};

use crate::Studio;
use crate::archive::{self, NewPlant, Operator, ParentRow, PlantRow};
use crate::edits::{FieldEdit, check_locked, edited, locked};
use crate::error::{ApiError, input_message};
use crate::http::Body;
use crate::modes::{Branch, Mode, Route};
use crate::plants::{Form, PreviewSize, genome_of, parse_genome, plant_bytes, preview_glb};
use crate::pruning::{PRUNED_TO, grow_shown, match_settings, pruned_run, pruned_to};
use crate::sessions::{SessionView, example, session_of, step_seed, view};

/// The model a new session breeds when the request names none: PlantMaker's, whose main
/// window this mode is.
pub fn default_model() -> &'static str {
    sylva::registry::names::PLANTMAKER
}

/// Plants in the grid.
pub const GRID: usize = 9;

/// Where a breed session's first plants come from (also what `add` takes).
#[derive(Deserialize, Debug)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Plants {
    /// N random genomes of the session's model, 1 to 9.
    Random(u32),
    /// Example genomes by name (`plantmaker/fern`).
    Examples(Vec<String>),
    /// Genome files' text (uploads).
    Genomes(Vec<String>),
    /// Plants already in the archive.
    Plants(Vec<i64>),
}

/// `POST /api/sessions` in breed mode.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct Start {
    /// The model, `plantmaker` by default.
    model: Option<String>,
    /// The first plants: 9 random by default.
    start: Option<Plants>,
    /// The session's seed, 1 by default.
    seed: Option<u64>,
}

/// A cell of the grid.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    /// The plant.
    pub plant: i64,
    /// The step it last took part in.
    pub dominance: i64,
}

/// A breed session's view.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct BreedState {
    /// The grid, most dominant first.
    pub grid: Vec<Cell>,
    /// The session's seed.
    pub seed: u64,
    /// The model's settings that breeding by hand keeps, beside its Depth and level: those
    /// of the match run its first plants were taken from (a match's PlantMaker plants keep
    /// to leaf colours); none for the model's defaults.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hand: Option<serde_json::Value>,
}

/// What breeding by hand with `knobs` follows in a session that keeps `hand`
/// ([`BreedState::hand`]).
fn by_hand(knobs: Knobs, hand: Option<&serde_json::Value>) -> Settings<'_> {
    match hand {
        Some(hand) => Settings::KnobsOver(knobs, hand),
        None => Settings::Knobs(knobs),
    }
}

/// A plant about to be archived: grown, meshed and encoded already.
pub struct Made {
    /// Its genome.
    pub genome: Genome,
    /// Its seed.
    pub seed: u64,
    /// How it was made.
    pub operator: Operator,
    /// The operator's settings.
    pub settings: serde_json::Value,
    /// Its parents.
    pub parents: Vec<ParentRow>,
    /// The plant as the views show it (roots left out).
    pub plant: Plant,
    /// Its preview GLB for the grid's cells ([`PreviewSize::GRID`]).
    pub glb: Vec<u8>,
}

impl Made {
    /// Grows `genome` with its default seed.
    fn grow(
        genome: Genome,
        operator: Operator,
        settings: serde_json::Value,
        parents: Vec<ParentRow>,
    ) -> Result<Made, ApiError> {
        let seed = genome.default_seed();
        Made::grow_with(genome, seed, operator, settings, parents, None)
    }

    /// Grows `genome` with `seed`, pruned to `pruned_to` if given.
    fn grow_with(
        genome: Genome,
        seed: u64,
        operator: Operator,
        settings: serde_json::Value,
        parents: Vec<ParentRow>,
        pruned_to: Option<Arc<[Outline]>>,
    ) -> Result<Made, ApiError> {
        let plant = grow_shown(&genome, seed, pruned_to)?;
        let glb = preview_glb(&genome, seed, &plant, PreviewSize::GRID)?;
        Ok(Made {
            genome,
            seed,
            operator,
            settings,
            parents,
            plant,
            glb,
        })
    }
}

/// Archives plants made in `session`; returns their ids and keeps their GLBs in memory.
pub fn store(c: &rusqlite::Connection, session: i64, made: &[Made]) -> Result<Vec<i64>, ApiError> {
    let mut ids = Vec::with_capacity(made.len());
    for m in made {
        let text = m.genome.to_json();
        let id = archive::insert_plant(
            c,
            &NewPlant {
                session: Some(session),
                model: m.genome.model(),
                genome: &text,
                seed: m.seed,
                operator: m.operator,
                settings: &m.settings,
                parents: &m.parents,
            },
        )?;
        ids.push(id);
    }
    Ok(ids)
}

/// Keeps stored plants and their preview GLBs in memory (after the transaction committed),
/// so that the page's views find them there, or make a preview of their size without
/// growing the plant again.
fn cache(studio: &Studio, ids: &[i64], made: Vec<Made>) {
    for (&id, m) in ids.iter().zip(made) {
        let form = Form::Preview(PreviewSize::GRID);
        let bytes = m.glb.len();
        studio.meshes.put((id, form), Arc::new(m.glb), bytes);
        let bytes = plant_bytes(&m.plant);
        studio.plants.put(id, Arc::new(m.plant), bytes);
    }
}

/// Reads plants of `model` from the archive.
fn archived(
    studio: &Studio,
    ids: &[i64],
    model: &str,
    field: &str,
) -> Result<Vec<PlantRow>, ApiError> {
    let mut rows = Vec::with_capacity(ids.len());
    for (i, &id) in ids.iter().enumerate() {
        let row = studio
            .archive
            .read(|c| archive::plant(c, id))?
            .ok_or_else(|| ApiError::bad(format!("{field}[{i}]"), format!("no plant {id}")))?;
        if row.model != model {
            return Err(ApiError::bad(
                format!("{field}[{i}]"),
                format!(
                    "plant {id} is a {} plant; this session breeds {model}",
                    row.model
                ),
            ));
        }
        rows.push(row);
    }
    Ok(rows)
}

/// The one plant of `model` a request names in `field`.
fn archived_one(studio: &Studio, id: i64, model: &str, field: &str) -> Result<PlantRow, ApiError> {
    let mut rows = archived(studio, &[id], model, field).map_err(|mut e| {
        e.field = field.to_owned();
        e
    })?;
    rows.pop()
        .ok_or_else(|| ApiError::internal("a plant read is missing"))
}

/// A plant to grow for `start`/`add`.
#[derive(Clone)]
struct Sprout {
    genome: Genome,
    /// Its seed; the genome's default when `None`.
    seed: Option<u64>,
    operator: Operator,
    settings: serde_json::Value,
    parents: Vec<ParentRow>,
    /// The outlines it grows inside: those of the match it comes from, if it does.
    pruned_to: Option<Arc<[Outline]>>,
    /// Where the request named it (`start.genomes[2]`), for an error growing it.
    field: String,
}

impl Sprout {
    fn new(
        genome: Genome,
        operator: Operator,
        settings: serde_json::Value,
        field: String,
    ) -> Sprout {
        Sprout {
            genome,
            seed: None,
            operator,
            settings,
            parents: Vec::new(),
            pruned_to: None,
            field,
        }
    }
}

/// New plants for `start`/`add` of `session` (none yet when starting), grown on the
/// blocking pool; and archived plants of the session reused. An archived plant of another
/// session enters as a branch: a plant of this session with its genome and seed, whose
/// parent it is, so the session's population lists it and its lineage leads back.
async fn make_plants(
    studio: &Studio,
    model: &'static str,
    plants: Plants,
    seed: u64,
    seq: i64,
    field: &str,
    session: Option<i64>,
) -> Result<(Vec<Made>, Vec<i64>), ApiError> {
    let mut genomes: Vec<Sprout> = Vec::new();
    let mut reused = Vec::new();
    match plants {
        Plants::Random(n) => {
            if !(1..=GRID as u32).contains(&n) {
                return Err(ApiError::bad(
                    sub(field, "random"),
                    format!("expected 1 to 9, got {n}"),
                ));
            }
            let entry = studio
                .registry
                .get(model)
                .ok_or_else(|| ApiError::internal(format!("no model {model}")))?;
            for i in 0..n {
                let s = step_seed(seed, seq, u64::from(i));
                let genome = entry
                    .random(Settings::Default, s)
                    .map_err(|e| ApiError::unprocessable(field, input_message(&e)))?;
                let at = sub(field, "random");
                genomes.push(Sprout::new(
                    genome,
                    Operator::Random,
                    json!({ "seed": s }),
                    at,
                ));
            }
        }
        Plants::Examples(names) => {
            check_count(names.len(), &sub(field, "examples"))?;
            for (i, name) in names.into_iter().enumerate() {
                let genome = example(&studio.registry, &name).ok_or_else(|| {
                    ApiError::bad(
                        sub(field, &format!("examples[{i}]")),
                        format!("no example {name:?}"),
                    )
                })?;
                if genome.model() != model {
                    return Err(ApiError::bad(
                        sub(field, &format!("examples[{i}]")),
                        format!(
                            "{name} is a {} genome; this session breeds {model}",
                            genome.model()
                        ),
                    ));
                }
                let at = sub(field, &format!("examples[{i}]"));
                genomes.push(Sprout::new(
                    genome,
                    Operator::Example,
                    json!({ "example": name }),
                    at,
                ));
            }
        }
        Plants::Genomes(texts) => {
            check_count(texts.len(), &sub(field, "genomes"))?;
            for (i, text) in texts.iter().enumerate() {
                let f = sub(field, &format!("genomes[{i}]"));
                let genome = parse_genome(&studio.registry, text, &f)?;
                if genome.model() != model {
                    return Err(ApiError::unprocessable(
                        f,
                        format!("a {} genome; this session breeds {model}", genome.model()),
                    ));
                }
                genomes.push(Sprout::new(genome, Operator::Upload, json!({}), f));
            }
        }
        Plants::Plants(ids) => {
            check_count(ids.len(), &sub(field, "plants"))?;
            let rows = archived(studio, &ids, model, &sub(field, "plants"))?;
            for (i, row) in rows.into_iter().enumerate() {
                if session.is_some() && row.session == session {
                    reused.push(row.id);
                } else {
                    let at = sub(field, &format!("plants[{i}]"));
                    // A plant of a match keeps the outlines it grew inside.
                    let mut settings = json!({});
                    if let Some(run) = pruned_run(&row) {
                        settings[PRUNED_TO] = json!(run);
                    }
                    genomes.push(Sprout {
                        seed: Some(row.seed),
                        parents: vec![ParentRow {
                            plant: row.id,
                            dominance: 1.0,
                        }],
                        pruned_to: pruned_to(studio, &row)?,
                        ..Sprout::new(
                            genome_of(&studio.registry, &row)?,
                            Operator::Branch,
                            settings,
                            at,
                        )
                    });
                }
            }
        }
    }
    let made = blocking_grow(studio, genomes).await?;
    Ok((made, reused))
}

/// `name` under `field` (`start.random`), or `name` alone at the top of a request.
fn sub(field: &str, name: &str) -> String {
    if field.is_empty() {
        name.to_owned()
    } else {
        format!("{field}.{name}")
    }
}

fn check_count(n: usize, field: &str) -> Result<(), ApiError> {
    if (1..=GRID).contains(&n) {
        Ok(())
    } else {
        Err(ApiError::bad(
            field,
            format!("expected 1 to 9 entries, got {n}"),
        ))
    }
}

/// Grows sprouts side by side on the blocking pool.
async fn blocking_grow(studio: &Studio, sprouts: Vec<Sprout>) -> Result<Vec<Made>, ApiError> {
    let studio = studio.clone();
    tokio::task::spawn_blocking(move || {
        let jobs = sprouts.len();
        studio
            .pool
            .map(jobs, |i| {
                let Sprout {
                    genome,
                    seed,
                    operator,
                    settings,
                    parents,
                    pruned_to,
                    field,
                } = sprouts[i].clone();
                let seed = seed.unwrap_or_else(|| genome.default_seed());
                Made::grow_with(genome, seed, operator, settings, parents, pruned_to).map_err(
                    |mut e| {
                        e.field = field;
                        e
                    },
                )
            })
            .into_iter()
            .collect::<Result<Vec<Made>, ApiError>>()
    })
    .await?
}

/// The model named in a request, or PlantMaker.
fn model_name(registry: &Registry, name: Option<&str>) -> Result<&'static str, ApiError> {
    let name = name.unwrap_or(default_model());
    registry.get(name).map(|m| m.name()).ok_or_else(|| {
        let known: Vec<_> = registry.models().iter().map(|m| m.name()).collect();
        ApiError::bad("model", format!("expected one of {known:?}, got {name:?}"))
    })
}

/// Puts `first` (in order) at the head of the grid with dominance `step`; the rest keep
/// their order by dominance, and the least dominant fall off.
fn promote(grid: &[Cell], first: &[i64], step: i64) -> Vec<Cell> {
    let mut out: Vec<Cell> = Vec::with_capacity(GRID);
    for &plant in first {
        if !out.iter().any(|c| c.plant == plant) {
            out.push(Cell {
                plant,
                dominance: step,
            });
        }
    }
    let mut rest: Vec<Cell> = grid
        .iter()
        .filter(|c| !first.contains(&c.plant))
        .copied()
        .collect();
    rest.sort_by_key(|c| std::cmp::Reverse(c.dominance));
    out.extend(rest);
    out.truncate(GRID);
    out
}

/// What a breed session starts from when not told: the model's examples, and random
/// genomes up to a full grid when it has fewer than two. (Random PlantMaker genomes grow
/// plants of up to a million triangles; the paper's users, too, began from chosen plants.)
fn default_start(registry: &Registry, model: &str) -> Plants {
    let examples: Vec<String> = crate::sessions::example_list(registry)
        .into_iter()
        .filter(|(_, m)| *m == model)
        .map(|(name, _)| name)
        .take(GRID)
        .collect();
    if examples.len() >= 2 {
        Plants::Examples(examples)
    } else {
        Plants::Random(GRID as u32)
    }
}

/// The Depth that fills a new session's grid, as the page's default.
const FILL_DEPTH: u8 = 2;

/// Creates a breed session: its first plants, then, when they are fewer than the grid holds,
/// mutants of them in turn (Depth 2) until all nine cells are filled.
async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
    let model = model_name(&studio.registry, start.model.as_deref())?;
    let seed = start.seed.unwrap_or(1);
    let plants = match start.start {
        Some(plants) => plants,
        None => default_start(&studio.registry, model),
    };
    let (made, reused) = make_plants(studio, model, plants, seed, 0, "start", None).await?;
    // A new session reuses no plant: archived plants enter it as branches (above).
    debug_assert!(reused.is_empty());
    // Bred from a match's plants, it keeps the match's settings.
    let hand = match made
        .iter()
        .find_map(|m| m.settings.get(PRUNED_TO)?.as_i64())
    {
        Some(run) => match_settings(studio, run, model)?,
        None => None,
    };
    let parents: Vec<Genome> = made.iter().map(|m| m.genome.clone()).collect();
    let fill = GRID.saturating_sub(parents.len());
    let settings = Knobs {
        level: CrossLevel::Medium,
        depth: Depth::new(FILL_DEPTH).unwrap_or_default(),
    };
    let mutants = if fill == 0 {
        Vec::new()
    } else {
        let parents = parents.clone();
        let hand = hand.clone();
        // Drawn as step −1, apart from the start's own streams (step 0).
        breed_children(
            studio,
            fill,
            seed,
            -1,
            move |i, s| {
                let child = parents[i % parents.len()]
                    .mutate(by_hand(settings, hand.as_ref()), s)
                    .map_err(|e| ApiError::library("start", e))?;
                Ok((child, Vec::new()))
            },
            Operator::Mutate,
            json!({ "depth": FILL_DEPTH }),
        )
        .await?
    };
    let (id, ids) = studio.archive.transaction(|c| -> Result<_, ApiError> {
        let title = format!("Breed {model}");
        let id = archive::insert_session(c, BreedMode::NAME, model, &title, &json!({}))?;
        let mut ids = store(c, id, &made)?;
        let mut mutants = mutants;
        for (i, m) in mutants.iter_mut().enumerate() {
            m.parents = vec![ParentRow {
                plant: ids[i % ids.len()],
                dominance: 1.0,
            }];
        }
        ids.extend(store(c, id, &mutants)?);
        let state = BreedState {
            grid: promote(&[], &ids, 0),
            seed,
            hand,
        };
        archive::set_state(c, id, &json!(state))?;
        Ok((
            id,
            (ids, made.into_iter().chain(mutants).collect::<Vec<_>>()),
        ))
    })?;
    let (ids, made) = ids;
    cache(studio, &ids, made);
    Ok(id)
}

/// A new breed session that starts from one archived plant.
async fn branch(studio: &Studio, row: &PlantRow) -> Result<i64, ApiError> {
    create(
        studio,
        Start {
            model: Some(row.model.clone()),
            start: Some(Plants::Plants(vec![row.id])),
            seed: Some(row.seed),
        },
    )
    .await
}

/// The breed session and its state.
fn breed_state(studio: &Studio, id: i64) -> Result<(archive::SessionRow, BreedState), ApiError> {
    let row = session_of(studio, id, BreedMode::NAME)?;
    let state: BreedState = serde_json::from_value(row.state.clone())
        .map_err(|e| ApiError::internal(format!("session {id}'s state: {e}")))?;
    Ok((row, state))
}

/// Records a step that made `made` (and promotes `lead` before them) in one transaction.
fn record(
    studio: &Studio,
    id: i64,
    state: &BreedState,
    action: serde_json::Value,
    lead: &[i64],
    made: Vec<Made>,
    replace: Option<i64>,
) -> Result<SessionView, ApiError> {
    let ids = studio.archive.transaction(|c| -> Result<_, ApiError> {
        let seq = archive::next_seq(c, id)?;
        let ids = store(c, id, &made)?;
        let grid = match replace {
            // An edit takes the edited plant's place.
            Some(old) if state.grid.iter().any(|c| c.plant == old) => state
                .grid
                .iter()
                .map(|cell| {
                    if cell.plant == old {
                        Cell {
                            plant: ids[0],
                            dominance: seq,
                        }
                    } else {
                        *cell
                    }
                })
                .collect(),
            _ => {
                let first: Vec<i64> = lead.iter().chain(&ids).copied().collect();
                promote(&state.grid, &first, seq)
            }
        };
        let after = BreedState {
            grid,
            seed: state.seed,
            hand: state.hand.clone(),
        };
        let mut action = action;
        action["children"] = json!(ids);
        archive::record_step(c, id, &action, &json!(state), &json!(after))?;
        Ok(ids)
    })?;
    cache(studio, &ids, made);
    view(studio, id)
}

/// A parent of a cross.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct CrossParent {
    plant: i64,
    #[serde(default = "one")]
    dominance: f64,
}

fn one() -> f64 {
    1.0
}

/// `POST /api/sessions/{id}/cross`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct CrossRequest {
    parents: Vec<CrossParent>,
    level: Option<CrossLevel>,
    children: Option<u32>,
    seed: Option<u64>,
    /// Fields every child keeps as the most dominant parent has them.
    #[serde(default)]
    locked: Vec<String>,
}

/// Checks a number of children, 1 to 9.
fn children(n: Option<u32>, default: usize) -> Result<usize, ApiError> {
    let n = n.map_or(default, |n| n as usize);
    if (1..=GRID).contains(&n) {
        Ok(n)
    } else {
        Err(ApiError::bad(
            "children",
            format!("Children: expected a whole number from 1 to {GRID}, got {n}"),
        ))
    }
}

/// Breeds children on the blocking pool, each from its own stream; a child that cannot
/// grow (too large a plant, say) is bred again from the next stream, up to four times.
async fn breed_children(
    studio: &Studio,
    count: usize,
    seed: u64,
    seq: i64,
    breed: impl Fn(usize, u64) -> Result<(Genome, Vec<ParentRow>), ApiError> + Send + Sync + 'static,
    operator: Operator,
    settings: serde_json::Value,
) -> Result<Vec<Made>, ApiError> {
    let studio = studio.clone();
    tokio::task::spawn_blocking(move || {
        studio
            .pool
            .map(count, |i| {
                let mut last = None;
                for attempt in 0..4u64 {
                    let s = step_seed(seed, seq, i as u64 + 16 * attempt);
                    let (genome, parents) = breed(i, s)?;
                    let mut settings = settings.clone();
                    settings["seed"] = json!(s);
                    match Made::grow(genome, operator, settings, parents) {
                        Ok(m) => return Ok(m),
                        Err(e) => last = Some(e),
                    }
                }
                Err(last.unwrap_or_else(|| ApiError::internal("no child")))
            })
            .into_iter()
            .collect()
    })
    .await?
}

/// `POST /api/sessions/{id}/cross`.
pub(crate) async fn cross(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<CrossRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let (row, state) = breed_state(&studio, id)?;
    if request.parents.len() < 2 || request.parents.len() > GRID {
        return Err(ApiError::bad(
            "parents",
            format!(
                "a cross takes 2 to 9 parents, got {}",
                request.parents.len()
            ),
        ));
    }
    let ids: Vec<i64> = request.parents.iter().map(|p| p.plant).collect();
    for (i, id) in ids.iter().enumerate() {
        if ids[..i].contains(id) {
            return Err(ApiError::bad(
                format!("parents[{i}].plant"),
                format!("plant {id} is given twice"),
            ));
        }
    }
    for (i, p) in request.parents.iter().enumerate() {
        if !(p.dominance.is_finite() && (0.0..=1e6).contains(&p.dominance)) {
            return Err(ApiError::bad(
                format!("parents[{i}].dominance"),
                format!(
                    "Dominance (parent {}): expected a number from 0 to 1000000, got {}",
                    i + 1,
                    p.dominance
                ),
            ));
        }
    }
    let rows = archived(&studio, &ids, &row.model, "parents")?;
    let genomes = rows
        .iter()
        .map(|row| genome_of(&studio.registry, row))
        .collect::<Result<Vec<_>, _>>()?;
    let level = request.level.unwrap_or_default();
    let count = children(request.children, GRID.saturating_sub(ids.len()).max(1))?;
    let knobs = Knobs {
        level,
        ..Knobs::default()
    };
    let weights: Vec<f64> = request.parents.iter().map(|p| p.dominance).collect();
    check_locked(&request.locked)?;
    let locked_paths = request.locked.clone();
    // Locked fields come from the most dominant parent (the first of equals).
    let dominant = (0..weights.len()).fold(
        0,
        |best, i| if weights[i] > weights[best] { i } else { best },
    );
    let seq = studio.archive.read(|c| archive::next_seq(c, id))?;
    let seed = request.seed.unwrap_or(state.seed);
    let parent_ids = ids.clone();
    let hand = state.hand.clone();
    let made = breed_children(
        &studio,
        count,
        seed,
        seq,
        move |_, s| {
            let pairs: Vec<(&Genome, f64)> = genomes.iter().zip(weights.iter().copied()).collect();
            let (child, used) = Genome::cross(&pairs, by_hand(knobs, hand.as_ref()), s)
                .map_err(|e| ApiError::library("parents", e))?;
            let child = locked(child, &genomes[dominant], &locked_paths)?;
            let parents = used
                .iter()
                .map(|&i| ParentRow {
                    plant: parent_ids[i],
                    dominance: weights[i],
                })
                .collect();
            Ok((child, parents))
        },
        Operator::Cross,
        with_locked(json!({ "level": level }), &request.locked),
    )
    .await?;
    let action = json!({
        "op": "cross",
        "parents": request.parents.iter().map(|p| json!({"plant": p.plant, "dominance": p.dominance})).collect::<Vec<_>>(),
        "level": level,
        "seed": seed,
    });
    Ok(Json(record(&studio, id, &state, action, &ids, made, None)?))
}

/// A step's settings as the archive keeps them, with the fields it kept locked (when any).
fn with_locked(mut settings: serde_json::Value, locked: &[String]) -> serde_json::Value {
    if !locked.is_empty() {
        settings["locked"] = json!(locked);
    }
    settings
}

/// `POST /api/sessions/{id}/mutate`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct MutateRequest {
    plant: i64,
    depth: Option<u32>,
    children: Option<u32>,
    seed: Option<u64>,
    /// Fields every child keeps as the parent has them.
    #[serde(default)]
    locked: Vec<String>,
}

/// `POST /api/sessions/{id}/mutate`.
pub(crate) async fn mutate(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<MutateRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let (row, state) = breed_state(&studio, id)?;
    let depth = request.depth.unwrap_or(2);
    let knobs = Knobs {
        depth: u8::try_from(depth)
            .ok()
            .and_then(Depth::new)
            .ok_or_else(|| ApiError::bad("depth", format!("expected 1 to 10, got {depth}")))?,
        ..Knobs::default()
    };
    let count = children(request.children, GRID - 1)?;
    check_locked(&request.locked)?;
    let locked_paths = request.locked.clone();
    let parent = archived_one(&studio, request.plant, &row.model, "plant")?;
    let genome = genome_of(&studio.registry, &parent)?;
    let seq = studio.archive.read(|c| archive::next_seq(c, id))?;
    let seed = request.seed.unwrap_or(state.seed);
    let parent_id = parent.id;
    let hand = state.hand.clone();
    let made = breed_children(
        &studio,
        count,
        seed,
        seq,
        move |_, s| {
            let child = genome
                .mutate(by_hand(knobs, hand.as_ref()), s)
                .map_err(|e| ApiError::library("plant", e))?;
            let child = locked(child, &genome, &locked_paths)?;
            Ok((
                child,
                vec![ParentRow {
                    plant: parent_id,
                    dominance: 1.0,
                }],
            ))
        },
        Operator::Mutate,
        with_locked(json!({ "depth": depth }), &request.locked),
    )
    .await?;
    let action = json!({ "op": "mutate", "plant": parent_id, "depth": depth, "seed": seed });
    Ok(Json(record(
        &studio,
        id,
        &state,
        action,
        &[parent_id],
        made,
        None,
    )?))
}

/// `POST /api/sessions/{id}/add`.
pub(crate) async fn add(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(plants): Body<Plants>,
) -> Result<Json<SessionView>, ApiError> {
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let (row, state) = breed_state(&studio, id)?;
    let model = model_name(&studio.registry, Some(&row.model))?;
    let seq = studio.archive.read(|c| archive::next_seq(c, id))?;
    let (made, reused) = make_plants(&studio, model, plants, state.seed, seq, "", Some(id)).await?;
    let action = json!({ "op": "add", "plants": reused });
    Ok(Json(record(
        &studio, id, &state, action, &reused, made, None,
    )?))
}

/// `POST /api/sessions/{id}/edit`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct EditRequest {
    plant: i64,
    genome: Option<serde_json::Value>,
    /// Field edits on the stored genome (exact: a page's JSON numbers lose digits past 2^53).
    #[serde(default)]
    fields: Vec<FieldEdit>,
    seed: Option<u64>,
}

/// `POST /api/sessions/{id}/edit`: an edited genome or another seed.
pub(crate) async fn edit(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<EditRequest>,
) -> Result<Json<SessionView>, ApiError> {
    let lock = studio.session_lock(id);
    let _guard = lock.lock().await;
    let (row, state) = breed_state(&studio, id)?;
    let old = archived_one(&studio, request.plant, &row.model, "plant")?;
    let original = genome_of(&studio.registry, &old)?;
    let genome = match (&request.genome, request.fields.is_empty()) {
        (None, true) => original.clone(),
        (None, false) => edited(&studio.registry, &old, &request.fields)?,
        (Some(serde_json::Value::String(text)), true) => {
            parse_genome(&studio.registry, text, "genome")?
        }
        (Some(value), true) => parse_genome(&studio.registry, &value.to_string(), "genome")?,
        (Some(_), false) => {
            return Err(ApiError::bad(
                "fields",
                "give either a genome or field edits, not both",
            ));
        }
    };
    if genome.model() != row.model {
        return Err(ApiError::unprocessable(
            "genome",
            format!(
                "a {} genome; this session breeds {}",
                genome.model(),
                row.model
            ),
        ));
    }
    let same = genome == original;
    let seed = match request.seed {
        // Another seed than the plant's: it grows with that one.
        Some(seed) if seed != old.seed => seed,
        // The genome's own seed edited (a model whose genomes carry one): that one.
        _ if genome.default_seed() != original.default_seed() => genome.default_seed(),
        Some(seed) => seed,
        None if same => old.seed,
        None => genome.default_seed(),
    };
    if same && seed == old.seed {
        return Err(ApiError::bad(
            "genome",
            "nothing changed: edit a field or give another seed",
        ));
    }
    let operator = if same {
        Operator::Regrow
    } else {
        Operator::Edit
    };
    // A genome that carries its seed is written with the plant's, so that the panel's
    // seed, the genome file and the packed string agree.
    let genome = genome.with_seed(seed);
    let parents = vec![ParentRow {
        plant: old.id,
        dominance: 1.0,
    }];
    let made = tokio::task::spawn_blocking(move || {
        Made::grow_with(
            genome,
            seed,
            operator,
            json!({ "seed": seed }),
            parents,
            None,
        )
    })
    .await?
    .map_err(|mut e| {
        e.field = "genome".into();
        e
    })?;
    let action = json!({ "op": operator.as_str(), "plant": old.id, "seed": seed });
    Ok(Json(record(
        &studio,
        id,
        &state,
        action,
        &[],
        vec![made],
        Some(old.id),
    )?))
}

/// Breed mode, behind the studio's mode seam.
pub struct BreedMode;

impl Mode for BreedMode {
    const NAME: &'static str = "breed";
    type Start = Start;
    const BRANCH: Option<Branch> = Some(Branch {
        label: "Branch from here",
        hint: "A new breeding session that starts from this plant",
    });

    fn models(registry: &Registry) -> Vec<&'static str> {
        registry.models().iter().map(|m| m.name()).collect()
    }

    async fn create(studio: &Studio, start: Start) -> Result<i64, ApiError> {
        create(studio, start).await
    }

    async fn branch(studio: &Studio, plant: &PlantRow) -> Result<i64, ApiError> {
        branch(studio, plant).await
    }

    fn routes() -> Vec<Route> {
        vec![
            Route::post("/sessions/{id}/cross", cross),
            Route::post("/sessions/{id}/mutate", mutate),
            Route::post("/sessions/{id}/add", add),
            Route::post("/sessions/{id}/edit", edit),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_dominant_fall_off() {
        let grid: Vec<Cell> = (1..=9)
            .map(|p| Cell {
                plant: p,
                dominance: p,
            })
            .collect();
        let after = promote(&grid, &[3, 100, 101], 10);
        let plants: Vec<i64> = after.iter().map(|c| c.plant).collect();
        assert_eq!(plants, [3, 100, 101, 9, 8, 7, 6, 5, 4]);
        assert!(after[..3].iter().all(|c| c.dominance == 10));
    }
}
