//! Gardens and forests for any model that grows them ([`sylva_model::gardens::Gardens`],
//! said in its registry line; PlantMaker's, after Gal, Mahal and Sipper): many plants of a
//! few genomes on one plot, in one scene. The model plans, places and grows the plants;
//! this module finds it in the registry and does the rest: a garden is planned ([`plant`],
//! or read from a garden file with [`read`]), estimated before it grows ([`check_garden`]),
//! then either held as assets ([`garden_assets`]) or streamed as a GLB, growing and meshing
//! one plant at a time ([`garden_glb`]). The command line's `sylva garden` and Python's
//! `sylva.garden` run it.

use std::path::Path;
use std::sync::Arc;

use serde_json::json;
use sylva_core::Plant;
use sylva_core::glam::Vec3;
use sylva_gltf::export::{self, Glb, GlbNode, GlbOptions, MeshSource};
use sylva_mesh::Mesh;
use sylva_mesh::mesher::Mesher;
use sylva_mesh::wind::WindOptions;
use sylva_model::gardens::{GardenError, GardenPlan, Gardens, MAX_PLANTS};
use sylva_model::{Evolve, GenomeError, MeshHint};

pub use sylva_model::gardens::{GrownGarden, Placement};

use crate::assets::{Origin, Placed, SceneAssets, mesh_options};
use crate::error::{Error, InputError};
use crate::genome::Genome;
use crate::registry::{EntryOf, Registry};

/// A garden of any model that grows them, as its garden file holds it: genomes, each with
/// one seed per plant, the plot, and how its scene is laid out.
pub struct Garden {
    plan: Box<dyn Plan>,
}

impl Clone for Garden {
    fn clone(&self) -> Garden {
        Garden {
            plan: self.plan.clone_plan(),
        }
    }
}

impl Garden {
    /// A garden of model `M`, made by the model (a test's, or a front end's own).
    pub fn of<M: Gardens + Default>(plan: M::Garden) -> Garden {
        Garden {
            plan: Box::new(PlanOf {
                model: M::default(),
                plan,
            }),
        }
    }

    /// Number of plants.
    pub fn count(&self) -> usize {
        self.plan.count()
    }

    /// How many seeds of each genome grow, every plant being one of them (a forest of
    /// variants), or `None`: every plant its own seed.
    pub fn variants(&self) -> Option<u32> {
        self.plan.variants()
    }

    /// Makes the garden a forest of `variants` (or not, with `None`); recorded in its file.
    pub fn set_variants(&mut self, variants: Option<u32>) {
        self.plan.set_variants(variants);
    }

    /// Whether a forest of variants is written as GPU instances (`None`: the default, yes).
    pub fn instancing(&self) -> Option<bool> {
        self.plan.instancing()
    }

    /// Sets [`Garden::instancing`]; recorded in its file.
    pub fn set_instancing(&mut self, instancing: Option<bool>) {
        self.plan.set_instancing(instancing);
    }

    /// Whether its GLB quantises positions and normals.
    pub fn quantize(&self) -> bool {
        self.plan.quantize()
    }

    /// Sets [`Garden::quantize`]; recorded in its file.
    pub fn set_quantize(&mut self, quantize: bool) {
        self.plan.set_quantize(quantize);
    }

    /// The garden file, pretty-printed with a final newline.
    pub fn to_json(&self) -> String {
        self.plan.to_json()
    }
}

impl<M: Gardens + Evolve + Default> EntryOf<M> {
    /// Its plants grow in gardens and forests (this module).
    pub fn with_gardens(self) -> Self {
        self.offering::<Arc<dyn GardenFace>>(Arc::new(M::default()))
    }
}

/// What the registry holds of a model that grows gardens: its typed trait, erased.
pub(crate) trait GardenFace: Send + Sync {
    /// The `model` its garden files name.
    fn garden_file(&self) -> &'static str;
    fn read(&self, text: &str) -> Result<Garden, GenomeError>;
    /// A new garden of `genome`; `None` when it is not this model's.
    fn plant(&self, genome: &Genome, count: usize, area: [f64; 2], seed: u64) -> Option<Garden>;
}

impl<M: Gardens> GardenFace for M {
    fn garden_file(&self) -> &'static str {
        M::GARDEN_FILE
    }

    fn read(&self, text: &str) -> Result<Garden, GenomeError> {
        let plan = M::read_garden(text)?;
        Ok(Garden {
            plan: Box::new(PlanOf {
                model: self.clone(),
                plan,
            }),
        })
    }

    fn plant(&self, genome: &Genome, count: usize, area: [f64; 2], seed: u64) -> Option<Garden> {
        let plan = M::new_garden(genome.get::<M>()?.clone(), count, area, seed);
        Some(Garden {
            plan: Box::new(PlanOf {
                model: self.clone(),
                plan,
            }),
        })
    }
}

/// A garden plan of one model, erased: what this module asks of it.
trait Plan: Send + Sync {
    fn clone_plan(&self) -> Box<dyn Plan>;
    fn mesh_hint(&self) -> MeshHint;
    /// Adds `count` plants of `genome`; false when it is not this garden's model's.
    fn add(&mut self, genome: &Genome, count: usize) -> bool;
    fn count(&self) -> usize;
    /// Per genome, its seeds.
    fn seeds(&self) -> Vec<&[u64]>;
    /// The genome of group `group`, erased.
    fn genome(&self, group: usize) -> Option<Genome>;
    fn variants(&self) -> Option<u32>;
    fn set_variants(&mut self, variants: Option<u32>);
    fn instancing(&self) -> Option<bool>;
    fn set_instancing(&mut self, instancing: Option<bool>);
    fn quantize(&self) -> bool;
    fn set_quantize(&mut self, quantize: bool);
    fn to_json(&self) -> String;
    fn grow(&self) -> Result<GrownGarden, GardenError>;
    fn placements(&self) -> Result<Vec<Placement>, GardenError>;
    fn develop(&self, placement: &Placement) -> Result<Plant, GardenError>;
}

struct PlanOf<M: Gardens> {
    model: M,
    plan: M::Garden,
}

impl<M: Gardens> Plan for PlanOf<M> {
    fn clone_plan(&self) -> Box<dyn Plan> {
        Box::new(PlanOf {
            model: self.model.clone(),
            plan: self.plan.clone(),
        })
    }

    fn mesh_hint(&self) -> MeshHint {
        self.model.mesh_hint()
    }

    fn add(&mut self, genome: &Genome, count: usize) -> bool {
        match genome.get::<M>() {
            Some(g) => {
                self.plan.add(g.clone(), count);
                true
            }
            None => false,
        }
    }

    fn count(&self) -> usize {
        self.plan.count()
    }

    fn seeds(&self) -> Vec<&[u64]> {
        self.plan.groups().into_iter().map(|(_, s)| s).collect()
    }

    fn genome(&self, group: usize) -> Option<Genome> {
        let (genome, _) = self.plan.groups().into_iter().nth(group)?;
        Some(Genome::new(self.model.clone(), genome.clone()))
    }

    fn variants(&self) -> Option<u32> {
        self.plan.variants()
    }

    fn set_variants(&mut self, variants: Option<u32>) {
        self.plan.set_variants(variants);
    }

    fn instancing(&self) -> Option<bool> {
        self.plan.instancing()
    }

    fn set_instancing(&mut self, instancing: Option<bool>) {
        self.plan.set_instancing(instancing);
    }

    fn quantize(&self) -> bool {
        self.plan.quantize()
    }

    fn set_quantize(&mut self, quantize: bool) {
        self.plan.set_quantize(quantize);
    }

    fn to_json(&self) -> String {
        self.plan.to_json()
    }

    fn grow(&self) -> Result<GrownGarden, GardenError> {
        self.plan.grow()
    }

    fn placements(&self) -> Result<Vec<Placement>, GardenError> {
        self.plan.placements()
    }

    fn develop(&self, placement: &Placement) -> Result<Plant, GardenError> {
        self.plan.develop(placement)
    }
}

/// The models of `registry` that grow gardens, in order.
fn offering(registry: &Registry) -> impl Iterator<Item = (&'static str, &dyn GardenFace)> {
    registry
        .models()
        .iter()
        .filter_map(|m| Some((m.name(), m.offer::<Arc<dyn GardenFace>>()?.as_ref())))
}

/// The `model` a file's text names, if it is an object that names one.
fn named_model(text: &str) -> Option<String> {
    #[derive(serde::Deserialize)]
    struct Header {
        model: String,
    }
    serde_json::from_str::<Header>(text).ok().map(|h| h.model)
}

/// True when `text` is a garden file of a model of `registry` (`"model":
/// "plantmaker-garden"`) rather than a genome file.
pub fn is_garden_file(registry: &Registry, text: &str) -> bool {
    named_model(text).is_some_and(|name| offering(registry).any(|(_, f)| f.garden_file() == name))
}

/// Reads a garden file already read from `path`, by the model of `registry` whose garden
/// file it names (or, naming none of them, the first model that grows gardens, whose
/// error says what it expected).
pub fn read(registry: &Registry, path: &Path, text: &str) -> Result<Garden, InputError> {
    let named = named_model(text);
    let face = offering(registry)
        .map(|(_, f)| f)
        .find(|f| named.as_deref() == Some(f.garden_file()))
        .or_else(|| offering(registry).map(|(_, f)| f).next())
        .ok_or_else(|| {
            InputError::file(
                path,
                "no model here grows gardens; expected a registry with one",
            )
        })?;
    face.read(text)
        .map_err(|e| InputError::genome(path, text, e))
}

/// Why genomes cannot be planted as a garden.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PlanError {
    /// No genome was given.
    #[error("a garden needs at least one genome")]
    NoGenomes,
    /// A genome of a model that grows no gardens, or of another model than the first
    /// genome's: its index among those given, and its model.
    #[error("gardens grow {expected} genomes; this is a `{model}` genome")]
    WrongModel {
        /// Which genome, from 0.
        index: usize,
        /// Its model.
        model: &'static str,
        /// The models it could be, as a person reads them (`` `plantmaker` ``).
        expected: String,
    },
}

/// Plans a new garden: `count` plants of each genome on a plot `area` = (width, depth)
/// metres centred on the origin, their seeds, places and turns drawn from `seed`. The
/// first genome's model grows it (one that offers gardens in `registry`), and the others
/// must be of that model.
pub fn plant(
    registry: &Registry,
    genomes: &[Genome],
    count: usize,
    area: [f64; 2],
    seed: u64,
) -> Result<Garden, PlanError> {
    let first = genomes.first().ok_or(PlanError::NoGenomes)?;
    let wrong = |index: usize, expected: String| PlanError::WrongModel {
        index,
        model: genomes[index].model(),
        expected,
    };
    let mut garden = registry
        .get(first.model())
        .and_then(|m| m.offer::<Arc<dyn GardenFace>>())
        .and_then(|face| face.plant(first, count, area, seed))
        .ok_or_else(|| {
            let names: Vec<String> = offering(registry).map(|(n, _)| format!("`{n}`")).collect();
            wrong(0, names.join(" or "))
        })?;
    for (index, genome) in genomes.iter().enumerate().skip(1) {
        if !garden.plan.add(genome, count) {
            return Err(wrong(index, format!("`{}`", first.model())));
        }
    }
    Ok(garden)
}

/// Grows a garden and meshes it: one node per plant (`plant-0`, `plant-1`, ...), each
/// standing at its placement and carrying its genome and seed, with a wind skin when
/// `wind` is given. Errors name `source`, the garden's file (or whatever a front end calls
/// it).
pub fn garden_assets(
    garden: &Garden,
    source: &Path,
    wind: Option<WindOptions>,
) -> Result<SceneAssets, Error> {
    let grown = grow_garden(garden, source)?;
    SceneAssets::mesh(&garden_placed(garden, &grown), wind).map_err(|e| e.in_file(source))
}

/// Grows every plant of a garden and places it, unmeshed. Errors name `source`.
pub fn grow_garden(garden: &Garden, source: &Path) -> Result<GrownGarden, Error> {
    Ok(garden
        .plan
        .grow()
        .map_err(|e| InputError::file_error(source, &e))?)
}

/// Where every plant of a garden stands, without keeping the plants. Errors name `source`.
pub fn garden_placements(garden: &Garden, source: &Path) -> Result<Vec<Placement>, Error> {
    Ok(garden
        .plan
        .placements()
        .map_err(|e| InputError::file_error(source, &e))?)
}

/// The plants of a grown garden as placed in its scene: one per placement (`plant-0`,
/// `plant-1`, ...), each carrying its genome and seed; the plants of one variant share it.
pub fn garden_placed<'g>(garden: &Garden, grown: &'g GrownGarden) -> Vec<Placed<'g>> {
    let hint = garden.plan.mesh_hint();
    grown
        .placements
        .iter()
        .enumerate()
        .map(|(i, placement)| Placed {
            translation: placement.translation,
            rotation: placement.rotation(),
            extras: Some(placement_extras(garden, placement)),
            ..Placed::new(format!("plant-{i}"), &grown.plants[placement.plant], hint)
        })
        .collect()
}

/// The origin a garden plant's node carries: its genome and seed.
fn placement_extras(garden: &Garden, placement: &Placement) -> serde_json::Value {
    match garden.plan.genome(placement.group) {
        Some(genome) => Origin::of(&genome, placement.seed).extras(),
        // A placement is the garden's own, so its genome is there.
        None => serde_json::Value::Null,
    }
}

/// The names and origin extras of a garden's nodes, one per placement (`plant-0`, …), which
/// [`garden_glb`] lends to the GLB writer.
pub struct GardenNodes {
    names: Vec<String>,
    extras: Vec<serde_json::Value>,
}

impl GardenNodes {
    /// The nodes of `placements` (the garden's own).
    pub fn of(garden: &Garden, placements: &[Placement]) -> GardenNodes {
        GardenNodes {
            names: (0..placements.len())
                .map(|i| format!("plant-{i}"))
                .collect(),
            extras: placements
                .iter()
                .map(|p| placement_extras(garden, p))
                .collect(),
        }
    }
}

/// The GLB of a garden from its placements alone ([`garden_placements`]), laid out and ready
/// to stream: each distinct plant is grown and meshed when the writer asks for it (twice:
/// once to lay the file out, once to write its bytes) and dropped after, so memory holds the
/// JSON, one plant and one mesh, however large the garden. The bytes are those of the grown
/// garden's scene ([`garden_placed`]) written with the same options. No wind (a rig is made
/// from its mesh, and the skins are written after every mesh).
pub fn garden_glb<'a>(
    garden: &'a Garden,
    placements: &'a [Placement],
    nodes: &'a GardenNodes,
    options: GlbOptions,
) -> Result<Glb<'a>, Error> {
    // Meshes in order of first appearance, as the writer numbers shared ones.
    let mut mesh_of: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    let mut plants: Vec<&Placement> = Vec::new();
    let glb_nodes = placements
        .iter()
        .zip(&nodes.names)
        .zip(&nodes.extras)
        .map(|((p, name), extras)| {
            let mesh = *mesh_of.entry(p.plant).or_insert_with(|| {
                plants.push(p);
                plants.len() - 1
            });
            GlbNode {
                name,
                mesh,
                rig: None,
                translation: p.translation,
                rotation: p.rotation(),
                extras: Some(extras),
            }
        })
        .collect();
    let source = GardenMeshes {
        garden,
        plants,
        mesher: Mesher::new(mesh_options(garden.plan.mesh_hint()))?,
        mesh: Mesh::default(),
    };
    Ok(Glb::new(glb_nodes, Box::new(source), options)?)
}

/// Grows and meshes a garden's plants when the GLB writer asks for them, into one mesh.
struct GardenMeshes<'a> {
    garden: &'a Garden,
    /// Per mesh, the first placement showing it.
    plants: Vec<&'a Placement>,
    mesher: Mesher,
    mesh: Mesh,
}

impl MeshSource for GardenMeshes<'_> {
    fn mesh(&mut self, index: usize) -> Result<&Mesh, sylva_gltf::export::ExportError> {
        let placement = self
            .plants
            .get(index)
            .ok_or(sylva_gltf::export::ExportError::NoSuchMesh { index })?;
        let plant = self.garden.plan.develop(placement).map_err(|e| {
            sylva_gltf::export::ExportError::Source {
                index,
                source: Box::new(e),
            }
        })?;
        self.mesher.mesh_into(&plant, &mut self.mesh)?;
        Ok(&self.mesh)
    }
}

/// What a garden's scene will cost, estimated before its plants grow ([`estimate_garden`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GardenEstimate {
    /// Plants placed.
    pub plants: usize,
    /// Distinct plants grown and meshed (fewer than `plants` in a forest of variants).
    pub meshes: usize,
    /// Bytes held at once while the scene is made and written.
    pub memory: u64,
    /// Bytes of the GLB file.
    pub glb: u64,
}

/// How a garden's scene is made, for [`estimate_garden`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GardenLayout {
    /// Streamed by [`garden_glb`]: each plant grown and meshed when the writer asks.
    Streamed,
    /// Every plant grown and meshed first ([`grow_garden`], [`SceneAssets`]), as for OBJ,
    /// VRML, wind or a picture.
    Held,
}

/// Estimates what a garden's scene holds and writes from the first plant of each genome
/// (grown and meshed here), before the others grow: its mesh times the genome's distinct
/// plants, its node (name, placement, and the origin extras that carry the genome) times
/// the genome's count. The nodes' JSON is what grows with the count whatever the meshes:
/// each plant's extras hold its genome. Errors name `source`.
pub fn estimate_garden(
    garden: &Garden,
    source: &Path,
    layout: GardenLayout,
    options: &GlbOptions,
) -> Result<GardenEstimate, Error> {
    let count = garden.count();
    if count > MAX_PLANTS {
        let e = GardenError::TooManyPlants(count);
        return Err(InputError::file_error(source, &e).into());
    }
    let hint = garden.plan.mesh_hint();
    let variants = garden.variants();
    let mut mesher = Mesher::new(mesh_options(hint))?;
    let mut estimate = GardenEstimate {
        plants: 0,
        meshes: 0,
        memory: 0,
        glb: GLB_FIXED,
    };
    let mut largest_plant = 0u64;
    let mut textures = 0u64;
    for (group, seeds) in garden.plan.seeds().into_iter().enumerate() {
        let Some(&seed) = seeds.first() else {
            continue;
        };
        let count = seeds.len();
        let distinct = variants.map_or(count, |v| count.min(v as usize));
        // The group's first plant, as the garden grows it (its errors name the plant).
        let first = Placement {
            group,
            index: 0,
            seed,
            plant: 0,
            translation: Vec3::ZERO,
            yaw: 0.0,
            radius: 0.0,
        };
        let plant = garden
            .plan
            .develop(&first)
            .map_err(|e| InputError::file_error(source, &e))?;
        let mesh = mesher
            .mesh(&plant)
            .map_err(|e| Error::from(e).in_file(source))?;
        let (each, once) = export::mesh_binary_bytes(&mesh, options)?;
        textures = textures.max(once);
        let placement = Placement {
            group,
            index: count - 1,
            seed,
            plant: 0,
            translation: Vec3::ZERO,
            yaw: 0.0,
            radius: 0.0,
        };
        let extras = placement_extras(garden, &placement);
        let node = json!({
            "name": format!("plant-{}", MAX_PLANTS),
            "mesh": MAX_PLANTS,
            "translation": [-12345.678, 0.0, 12345.678],
            "rotation": [0.0, -0.70710677, 0.0, 0.70710677],
            "extras": extras,
        });
        let text = serde_json::to_vec(&node).map_or(0, |t| t.len() as u64);
        let extras_heap = json_heap_bytes(&node["extras"]) + VALUE;
        let node_heap = json_heap_bytes(&node) + VALUE;
        // Every plant holds its placement and its node's name and extras, lent to the
        // writer. A node is written as JSON (held as a value, then as text whose buffer
        // grows by doubling) for each plant, or for each variant when the plants of a
        // variant are instanced (their extras are equal). A held scene copies the extras
        // three more times on the way (the placed plants, the assets' nodes, the scene) and
        // keeps every plant and mesh.
        let instanced = variants.is_some() && options.instancing;
        let copies = match layout {
            GardenLayout::Streamed => 1,
            GardenLayout::Held => 4,
        };
        let nodes = if instanced { distinct } else { count } as u64;
        let mesh_bytes = sylva_mesh::mesher::mesh_bytes(
            mesh.positions.len() as u64,
            mesh.triangle_count() as u64,
        );
        let per_mesh = PER_MESH_JSON
            + match layout {
                GardenLayout::Streamed => 0,
                GardenLayout::Held => mesh_bytes + plant_bytes(&plant),
            };
        let memory = (PER_PLACEMENT + copies * extras_heap)
            .saturating_mul(count as u64)
            .saturating_add((node_heap + 2 * text).saturating_mul(nodes))
            .saturating_add(per_mesh.saturating_mul(distinct as u64));
        // An instance is a translation and a rotation in the binary chunk.
        let instances = if instanced {
            INSTANCE * count as u64
        } else {
            0
        };
        estimate.plants += count;
        estimate.meshes += distinct;
        estimate.memory = estimate.memory.saturating_add(memory);
        estimate.glb = estimate
            .glb
            .saturating_add(each.saturating_mul(distinct as u64))
            .saturating_add(text.saturating_mul(nodes))
            .saturating_add(MESH_JSON.saturating_mul(distinct as u64))
            .saturating_add(instances);
        largest_plant = largest_plant.max(mesh_bytes + plant_bytes(&plant));
    }
    // The streamed plant and its mesh, one at a time.
    estimate.memory = estimate.memory.saturating_add(largest_plant);
    estimate.glb = estimate.glb.saturating_add(textures);
    Ok(estimate)
}

/// Refuses, before its plants grow, a garden whose scene would not fit the memory budget or
/// (`glb`) a GLB's 4 GiB by more than 5% ([`estimate_garden`]; the writer refuses the rest
/// when it has counted every byte). Errors name `source` and the flags to change.
pub fn check_garden(
    garden: &Garden,
    source: &Path,
    layout: GardenLayout,
    glb: bool,
    options: &GlbOptions,
) -> Result<GardenEstimate, Error> {
    let estimate = estimate_garden(garden, source, layout, options)?;
    let plants = estimate.plants;
    let variants = if garden.variants().is_some() {
        ""
    } else {
        ", or grow a forest of variants (`--variants K`)"
    };
    // The first plant of a genome stands for its others: an estimate just over the limit is
    // left to the writer's exact count.
    if glb && estimate.glb > u64::from(u32::MAX) / 20 * 21 {
        return Err(InputError::file(
            source,
            format!(
                "a garden of {plants} plants ({} meshes) would make a GLB of about {}, more \
                 than the 4 GiB a GLB can hold; plant fewer (`--count`){variants}",
                estimate.meshes,
                sylva_core::budget::Bytes(estimate.glb)
            ),
        )
        .into());
    }
    sylva_core::budget::check(
        estimate.memory,
        format_args!(
            "a garden of {plants} plants (`--count`; each plant's node carries its genome)"
        ),
        format_args!("plant fewer"),
    )
    .map_err(|e| Error::from(e).in_file(source))?;
    Ok(estimate)
}

/// A `serde_json::Value` itself, where a vector or map holds it.
const VALUE: u64 = std::mem::size_of::<serde_json::Value>() as u64;

/// Bytes a placement holds besides its node: the placement, its footprint, its cell in the
/// placing grid and its entry in the plan.
const PER_PLACEMENT: u64 = std::mem::size_of::<Placement>() as u64 + 128;

/// The JSON a distinct mesh adds to a GLB (its accessors, views and mesh entry): an upper
/// figure (a conifer's mesh writes 1.2 KB).
const MESH_JSON: u64 = 4096;

/// What a distinct mesh's JSON holds in memory while the GLB is laid out (with the rest of
/// the estimate, 1% to 16% above the peaks measured for conifer gardens of 300 to 20,000
/// plants, streamed, instanced or held).
const PER_MESH_JSON: u64 = 16 * 1024;

/// Bytes an instance adds to a GLB's binary chunk: its translation and rotation.
const INSTANCE: u64 = 12 + 16;

/// A GLB's header, chunk headers and the JSON that does not grow with the plants.
const GLB_FIXED: u64 = 4096;

/// Heap bytes a JSON value holds (not counting the value itself): strings, arrays and
/// maps (serde_json's `BTreeMap`, whose nodes hold eleven entries), each allocation rounded
/// as the system allocator rounds it: how [`estimate_garden`] weighs each plant's genome.
pub fn json_heap_bytes(value: &serde_json::Value) -> u64 {
    use serde_json::Value;
    // glibc: 8 bytes of header, 16-byte steps, at least 32.
    let chunk = |n: usize| -> u64 {
        if n == 0 {
            0
        } else {
            ((n as u64 + 8).next_multiple_of(16)).max(32)
        }
    };
    match value {
        Value::Null | Value::Bool(_) | Value::Number(_) => 0,
        Value::String(s) => chunk(s.capacity()),
        Value::Array(a) => {
            chunk(a.capacity() * VALUE as usize) + a.iter().map(json_heap_bytes).sum::<u64>()
        }
        Value::Object(m) if m.is_empty() => 0,
        Value::Object(m) => {
            // A leaf holds 11 keys and values; maps built by insertion are about 2/3 full,
            // and one internal node (a leaf with 12 edges) stands over about six leaves.
            const LEAF: usize = 8 + 2 + 2 + 11 * (24 + 32);
            let leaves = if m.len() <= 11 {
                1
            } else {
                m.len().div_ceil(7)
            };
            let internal = if leaves > 1 { leaves.div_ceil(6) } else { 0 };
            leaves as u64 * chunk(LEAF)
                + internal as u64 * chunk(LEAF + 12 * 8)
                + m.iter()
                    .map(|(k, v)| chunk(k.capacity()) + json_heap_bytes(v))
                    .sum::<u64>()
        }
    }
}

/// Bytes a grown plant holds: its segments and organs.
fn plant_bytes(plant: &Plant) -> u64 {
    (std::mem::size_of_val(plant.segments()) + std::mem::size_of_val(plant.organs())) as u64
}

/// How a garden's GLB is laid out, as its file says: a forest of variants is instanced
/// unless `"instancing": false`; positions are quantised with `"quantize": true`.
pub fn garden_glb_options(garden: &Garden) -> GlbOptions {
    GlbOptions {
        instancing: garden.variants().is_some() && garden.instancing() != Some(false),
        quantize: garden.quantize(),
    }
}
