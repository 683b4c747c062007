//! From grown plants to the files people use: meshes carrying their origin, scenes of many
//! plants, exported assets and pictures.
//!
//! [`Grown`] is one genome grown and meshed. [`Placed`] is a plant put somewhere in a
//! scene, with the extras its node carries (usually its [`Origin`]: genome, seed, Sylva's
//! version, and its parents when known); [`SceneAssets::mesh`] meshes many placed plants with one mesher per
//! set of options, and [`SceneAssets::scene`] lends them out as a [`Scene`] to export or
//! picture (gardens, which can also stream, are in [`crate::garden`]).
//! Mesh options follow from each model's [`MeshHint`], never from its name.

use std::path::Path;
use std::sync::Arc;

use serde_json::json;
use sylva_core::dress::{Dress, Dressed, dress};
use sylva_core::glam::{Quat, Vec3};
use sylva_core::taper::PipeTaper;
use sylva_core::{MaterialKind, Plant};
use sylva_evolve::IndividualId;
use sylva_fitness::silhouette::{Outline, prune};
use sylva_gltf::export::{self, GlbOptions};
use sylva_mesh::mesher::{MeshOptions, Mesher};
use sylva_mesh::wind::{Rig, WindOptions};
use sylva_mesh::{Mesh, Scene, SceneNode};
use sylva_model::MeshHint;
use sylva_render::{RenderOptions, View};

use crate::error::{Error, InputError};
use crate::genome::Genome;
use crate::registry::Registry;

/// How plants of a model are meshed: the defaults, with the model's hints applied.
pub fn mesh_options(hint: MeshHint) -> MeshOptions {
    MeshOptions {
        round_caps: hint.round_caps,
        ..MeshOptions::default()
    }
}

/// How a dressed plant ([`GrowOptions::dress`]) is meshed: as [`mesh_options`], but with
/// fewer sides on thinner branches (12 on the trunk's axis, then 8, 6, 5, 4 and 3 for the
/// fifth order of branches on), so that a tree in leaf fits a game's budget; the plants as
/// their models grow them keep their meshes.
pub fn mesh_options_for(hint: MeshHint, dress: &Dress) -> MeshOptions {
    if dress.is_plain() {
        return mesh_options(hint);
    }
    MeshOptions {
        radial_segments_by_order: vec![12, 8, 6, 5, 4, 3],
        ..mesh_options(hint)
    }
}

/// Where a plant came from: enough to grow or breed it again.
#[derive(Clone, Debug, PartialEq)]
pub struct Origin {
    /// The genome, as its file's JSON.
    pub genome: serde_json::Value,
    /// The seed it grew with.
    pub seed: u64,
    /// The ids of its parents in the run or archive it came from, when known.
    pub parents: Vec<IndividualId>,
}

impl Origin {
    /// The origin of `genome` grown with `seed`.
    pub fn of(genome: &Genome, seed: u64) -> Origin {
        Origin {
            genome: genome.to_value(),
            seed,
            parents: Vec::new(),
        }
    }

    /// What an exported node's `extras` hold: `genome`, `seed`, `sylva_version`, and
    /// `parents` when there are any.
    pub fn extras(&self) -> serde_json::Value {
        let mut extras = json!({
            "genome": self.genome,
            "seed": self.seed,
            "sylva_version": env!("CARGO_PKG_VERSION"),
        });
        if !self.parents.is_empty() {
            extras["parents"] = json!(self.parents.iter().map(|p| p.0).collect::<Vec<_>>());
        }
        extras
    }
}

/// How a genome grows into an asset. `GrowOptions::default()` grows it as the genome says:
/// its own seed, roots kept, the model's own radii, no wind, the plant in full, positions as
/// floats. Set the fields that differ:
///
/// ```no_run
/// # use sylva::assets::{GrowOptions, Grown};
/// # let genome = sylva::Registry::standard().load_genome("examples/plantmaker/fern.json".as_ref())?;
/// let grown = Grown::grow(genome, &GrowOptions { seed: Some(7), roots: false, ..Default::default() })?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct GrowOptions {
    /// The seed; the genome's own ([`Genome::default_seed`]) when `None`. Default `None`.
    pub seed: Option<u64>,
    /// Keep the roots in the plant, its mesh, exports and pictures. Default true.
    pub roots: bool,
    /// The pipe model's radii before meshing (`--taper`). Default none: the model's own.
    pub taper: Option<PipeTaper>,
    /// A wind skin and clip (`--wind`). Default none.
    pub wind: Option<WindOptions>,
    /// Levels of detail, 2 to 8, for [`LodAssets`](crate::LodAssets) (`--lod`). Default
    /// none: the plant in full alone.
    pub lod: Option<usize>,
    /// Positions and normals stored as integers in GLB files (`--quantize`,
    /// `KHR_mesh_quantization`). Default false.
    pub quantize: bool,
    /// The plant scaled about its foot so that its highest point stands this many metres
    /// above the ground (`--height`). Default none: the model's own scale.
    pub height: Option<f32>,
    /// Outlines the plant grows inside, pruned where it would show outside their ink
    /// (`[match] prune`, [`crate::evolution::outline::space`]). Default none.
    pub pruned_to: Option<Arc<[Outline]>>,
    /// Leaves or needles of a kind at their real size and a tiling bark, put on last, after
    /// the plant is scaled (`--foliage`, `--bark`; [`sylva_core::dress`]). Default: none,
    /// the plant as its model grew it, or as its genome names ([`GrowOptions::dress_for`]).
    pub dress: Dress,
}

impl Default for GrowOptions {
    fn default() -> Self {
        GrowOptions {
            seed: None,
            roots: true,
            taper: None,
            wind: None,
            lod: None,
            quantize: false,
            height: None,
            pruned_to: None,
            dress: Dress::default(),
        }
    }
}

impl GrowOptions {
    /// How `genome`'s plant is dressed: as these options say, or, when they name no
    /// foliage or bark, as the genome names for itself ([`Genome::own_dress`]).
    pub fn dress_for(&self, genome: &Genome) -> Dress {
        if !self.dress.is_plain() {
            return self.dress;
        }
        let own = genome.own_dress();
        Dress {
            foliage: own.foliage,
            bark: own.bark,
            ..self.dress
        }
    }

    /// How GLB files of the grown asset are written.
    pub fn glb_options(&self) -> GlbOptions {
        GlbOptions {
            quantize: self.quantize,
            ..GlbOptions::default()
        }
    }
}

/// A grown genome: its plant and mesh.
pub struct Grown {
    /// What was grown.
    pub genome: Genome,
    /// The seed it was grown with.
    pub seed: u64,
    /// The plant.
    pub plant: Plant,
    /// Its mesh.
    pub mesh: Mesh,
    /// The pipe-model taper applied before meshing, if any.
    pub taper: Option<PipeTaper>,
    /// Whether the roots were kept (`false`: left out of the plant, its mesh and exports).
    pub roots: bool,
    /// The wind skin and clip, if asked for ([`GrowOptions::wind`]).
    pub rig: Option<Rig>,
    /// The height it was scaled to, if any ([`GrowOptions::height`]).
    pub height: Option<f32>,
    /// How it was dressed ([`GrowOptions::dress`]) and what that did.
    pub dress: (Dress, Dressed),
}

impl Grown {
    /// Grows and meshes a genome as `options` say: with their seed (or the genome's own),
    /// without the roots unless kept, the pipe model's radii with a taper, and a wind skin
    /// and clip with wind (meshed once, recording where each vertex came from).
    pub fn grow(genome: Genome, options: &GrowOptions) -> Result<Grown, Error> {
        let (seed, plant, dressed) = Grown::dressed_plant(&genome, options)?;
        let (roots, taper) = (options.roots, options.taper);
        let dress = options.dress_for(&genome);
        let mut mesher = Mesher::new(mesh_options_for(genome.mesh_hint(), &dress))?;
        let (mesh, rig) = match &options.wind {
            None => (mesher.mesh(&plant)?, None),
            Some(wind) => {
                let (mesh, sources) = mesher.mesh_with_sources(&plant)?;
                let rig = sylva_mesh::wind::rig(&plant, &mesh, sources, wind);
                (mesh, Some(rig))
            }
        };
        Ok(Grown {
            genome,
            seed,
            plant,
            mesh,
            taper,
            roots,
            rig,
            height: options.height,
            dress: (dress, dressed),
        })
    }

    /// The plant [`Grown::grow`] meshes, with the seed it was grown with: grown, pruned,
    /// finished, scaled and dressed as `options` say.
    pub fn plant(genome: &Genome, options: &GrowOptions) -> Result<(u64, Plant), Error> {
        let (seed, plant, _) = Grown::dressed_plant(genome, options)?;
        Ok((seed, plant))
    }

    /// [`Grown::plant`], and what dressing it did.
    pub fn dressed_plant(
        genome: &Genome,
        options: &GrowOptions,
    ) -> Result<(u64, Plant, Dressed), Error> {
        let seed = options.seed.unwrap_or_else(|| genome.default_seed());
        let mut plant = genome.develop(seed)?;
        if let Some(outlines) = &options.pruned_to {
            plant = prune(outlines, &plant);
        }
        let mut plant = finish(plant, options.roots, options.taper);
        if let Some(height) = options.height {
            scale_to_height(&mut plant, height)?;
        }
        let mut dressed = Dressed::default();
        let wear = options.dress_for(genome);
        if !wear.is_plain() {
            (plant, dressed) = dress(&plant, &wear, seed)?;
        }
        Ok((seed, plant, dressed))
    }

    /// A scene holding this plant at the origin, carrying its origin (and its taper, so
    /// that the asset can be grown again).
    pub fn scene(&self) -> Scene<'_> {
        let mut node = SceneNode::new(self.genome.model(), &self.mesh);
        let mut extras = Origin::of(&self.genome, self.seed).extras();
        if let Some(taper) = self.taper {
            extras["taper"] = json!({ "pipe_exponent": taper.exponent });
        }
        if let Some(height) = self.height {
            extras["height"] = json!(height);
        }
        dress_extras(&mut extras, &self.dress.0);
        if let Some(rig) = &self.rig {
            extras["wind"] = wind_extras(rig);
            node.rig = Some(rig);
        }
        node.extras = Some(extras);
        Scene::single(node)
    }
}

/// Grows a genome into its plant, unmeshed, as [`Grown::grow`] does: the roots left
/// out when `roots` is false, then the pipe model's radii with a `taper`. For the work that
/// needs the skeleton only (such as [`crate::skeleton`]).
pub fn grow_plant(
    genome: &Genome,
    seed: u64,
    roots: bool,
    taper: Option<PipeTaper>,
) -> Result<Plant, Error> {
    Ok(finish(genome.develop(seed)?, roots, taper))
}

/// A grown plant made ready as [`grow_plant`] makes it: roots left out unless `roots`, the
/// pipe model's radii with a `taper`.
fn finish(mut plant: Plant, roots: bool, taper: Option<PipeTaper>) -> Plant {
    if !roots {
        plant = plant.without(MaterialKind::Root);
    }
    if let Some(taper) = taper {
        taper.apply(&mut plant);
    }
    plant
}

/// Records a dress in a node's extras (`foliage`, `bark`, and `density` when not 1), so
/// the asset can be grown again as it is.
pub fn dress_extras(extras: &mut serde_json::Value, dress: &Dress) {
    if let Some(kind) = dress.foliage {
        extras["foliage"] = json!(kind.name());
    }
    if let Some(kind) = dress.bark {
        extras["bark"] = json!(kind.name());
    }
    if dress.foliage.is_some() && dress.density != 1.0 {
        extras["density"] = json!(dress.density);
    }
}

/// What a GLB node's extras say of how its plant grew ([`Origin::extras`] and what
/// [`Grown::scene`] adds: seed, taper, height, foliage, bark, density), as the genome and
/// the options that grow it again. `path` names the file in errors.
pub fn regrow(
    registry: &Registry,
    extras: &serde_json::Value,
    path: &Path,
) -> Result<(Genome, GrowOptions), InputError> {
    let genome = extras.get("genome").ok_or_else(|| {
        InputError::file(
            path,
            "its node's extras hold no genome: it is not a plant Sylva grew (inspect its              skeleton file instead)",
        )
    })?;
    let text = genome.to_string();
    let genome = registry.parse_genome_at(path, &text)?;
    let field = |name: &str, why: String| InputError::file(path, format!("extras `{name}`: {why}"));
    let mut options = GrowOptions {
        seed: extras["seed"].as_u64(),
        ..GrowOptions::default()
    };
    if let Some(e) = extras["taper"]["pipe_exponent"].as_f64() {
        options.taper = Some(PipeTaper::new(e).map_err(|e| field("taper", e.to_string()))?);
    }
    if let Some(h) = extras["height"].as_f64() {
        options.height = Some(h as f32);
    }
    if let Some(k) = extras["foliage"].as_str() {
        options.dress.foliage = Some(
            k.parse()
                .map_err(|e: sylva_core::species::UnknownKind| field("foliage", e.to_string()))?,
        );
    }
    if let Some(k) = extras["bark"].as_str() {
        options.dress.bark = Some(
            k.parse()
                .map_err(|e: sylva_core::species::UnknownKind| field("bark", e.to_string()))?,
        );
    }
    if let Some(d) = extras["density"].as_f64() {
        options.dress.density = d as f32;
    }
    Ok((genome, options))
}

/// Lowest and highest height a plant is scaled to (`--height`), metres.
pub const HEIGHTS: (f32, f32) = (0.01, 1000.0);

/// Scales `plant` about its foot so that its highest visible point stands `height` metres
/// above the ground.
pub fn scale_to_height(plant: &mut Plant, height: f32) -> Result<(), InputError> {
    let (lo, hi) = HEIGHTS;
    if !(lo..=hi).contains(&height) {
        return Err(InputError::new(
            "--height",
            format!("expected {lo} to {hi} metres, got {height}"),
        ));
    }
    let top = plant.bounds().max.y;
    if !(top.is_finite() && top > 0.0) {
        return Err(InputError::new(
            "--height",
            "the plant has nothing above the ground to scale to a height",
        ));
    }
    plant
        .scale(height / top)
        .map_err(|e| InputError::new("--height", e))
}

/// What a wind GLB's extras say of its rig: the clip, its period and the joints.
fn wind_extras(rig: &Rig) -> serde_json::Value {
    json!({
        "clip": "wind",
        "period": rig.times.last().copied().unwrap_or(0.0),
        "joints": rig.joints.len(),
        "joints_left_out": rig.dropped,
        "flutter_attribute": "_WIND",
    })
}

/// A plant put in a scene.
#[derive(Clone, Debug)]
pub struct Placed<'a> {
    /// The node's name.
    pub name: String,
    /// The plant, its foot at its own origin.
    pub plant: &'a Plant,
    /// How its model's plants are meshed.
    pub hint: MeshHint,
    /// Where its foot stands, metres.
    pub translation: Vec3,
    /// How it is turned.
    pub rotation: Quat,
    /// What the node's extras hold: its [`Origin::extras`], and anything a front end adds.
    pub extras: Option<serde_json::Value>,
}

impl<'a> Placed<'a> {
    /// A plant at the world's origin, unturned, without extras.
    pub fn new(name: impl Into<String>, plant: &'a Plant, hint: MeshHint) -> Self {
        Placed {
            name: name.into(),
            plant,
            hint,
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            extras: None,
        }
    }
}

/// Meshes of placed plants, ready to be lent out as a scene. Placements that borrow the same
/// plant share one mesh (and rig), which a GLB writes once.
pub struct SceneAssets {
    meshes: Vec<Mesh>,
    rigs: Vec<Option<Rig>>,
    /// Per node: name, place, turn, extras and its mesh.
    nodes: Vec<(String, Vec3, Quat, Option<serde_json::Value>, usize)>,
}

impl SceneAssets {
    /// Meshes every plant (one mesher per set of options, its buffers reused), after
    /// checking that all the meshes together fit the memory budget; each plant with a wind
    /// skin and clip when `wind` is given (one clip, `wind`, moves them all).
    pub fn mesh(placed: &[Placed<'_>], wind: Option<WindOptions>) -> Result<SceneAssets, Error> {
        // Each distinct plant (by address) once, in order of first appearance.
        let mut index_of: std::collections::HashMap<*const Plant, usize> =
            std::collections::HashMap::new();
        let mut distinct: Vec<&Placed<'_>> = Vec::new();
        let mesh_of: Vec<usize> = placed
            .iter()
            .map(|p| {
                *index_of.entry(p.plant as *const Plant).or_insert_with(|| {
                    distinct.push(p);
                    distinct.len() - 1
                })
            })
            .collect();
        let mut meshers: Vec<(MeshHint, Mesher)> = Vec::new();
        let mut needed = 0u64;
        for p in &distinct {
            let mesher = mesher_for(&mut meshers, p.hint)?;
            needed = needed.saturating_add(mesher.bytes_for(p.plant)?);
        }
        sylva_core::budget::check(
            needed,
            format_args!("a scene of {} plants", placed.len()),
            "place fewer or smaller plants",
        )
        .map_err(sylva_mesh::mesher::MeshError::from)?;
        let mut meshes = Vec::with_capacity(distinct.len());
        let mut rigs = Vec::with_capacity(distinct.len());
        for p in &distinct {
            let mesher = mesher_for(&mut meshers, p.hint)?;
            match wind {
                None => {
                    meshes.push(mesher.mesh(p.plant)?);
                    rigs.push(None);
                }
                Some(wind) => {
                    let (mesh, sources) = mesher.mesh_with_sources(p.plant)?;
                    rigs.push(Some(sylva_mesh::wind::rig(p.plant, &mesh, sources, &wind)));
                    meshes.push(mesh);
                }
            }
        }
        let nodes = placed
            .iter()
            .zip(mesh_of)
            .map(|(p, m)| {
                let mut extras = p.extras.clone();
                if let (Some(rig), Some(e)) = (&rigs[m], extras.as_mut()) {
                    e["wind"] = wind_extras(rig);
                }
                (p.name.clone(), p.translation, p.rotation, extras, m)
            })
            .collect();
        Ok(SceneAssets {
            meshes,
            rigs,
            nodes,
        })
    }

    /// Plants placed (nodes of the scene).
    pub fn placed(&self) -> usize {
        self.nodes.len()
    }

    /// The meshes, one per distinct plant, in the order the plants were first given.
    pub fn meshes(&self) -> &[Mesh] {
        &self.meshes
    }

    /// The scene: one node per plant.
    pub fn scene(&self) -> Scene<'_> {
        let nodes = self
            .nodes
            .iter()
            .map(|(name, translation, rotation, extras, m)| {
                let mut node = SceneNode::new(name.clone(), &self.meshes[*m]);
                node.rig = self.rigs[*m].as_ref();
                node.translation = *translation;
                node.rotation = *rotation;
                node.extras = extras.clone();
                node
            })
            .collect();
        Scene { nodes }
    }
}

/// Refuses, before any mesh is made, a scene of `placed` plants whose GLB would pass the
/// 4 GiB a GLB can hold even at the fewest bytes its meshes can take
/// ([`export::mesh_binary_floor`] of their exact counts; plants placed more than once are
/// counted once). Errors name `source`; `advice` says what to change.
pub fn check_scene_glb(
    placed: &[Placed<'_>],
    quantize: bool,
    source: &Path,
    advice: &str,
) -> Result<(), Error> {
    let mut seen = std::collections::HashSet::new();
    let mut meshers: Vec<(MeshHint, Mesher)> = Vec::new();
    let mut floor = 0u64;
    for p in placed {
        if !seen.insert(p.plant as *const Plant) {
            continue;
        }
        let mesher = mesher_for(&mut meshers, p.hint)?;
        let counts = mesher
            .counts(p.plant)
            .map_err(|e| Error::from(e).in_file(source))?;
        floor = floor.saturating_add(export::mesh_binary_floor(
            counts.vertices as u64,
            counts.triangles as u64,
            quantize,
        ));
    }
    if floor > u64::from(u32::MAX) {
        return Err(InputError::file(
            source,
            format!(
                "a scene of {} plants would make a GLB of at least {}, more than the 4 GiB a \
                 GLB can hold; {advice}",
                placed.len(),
                sylva_core::budget::Bytes(floor)
            ),
        )
        .into());
    }
    Ok(())
}

/// The mesher for plants of `hint`, made the first time it is asked for.
fn mesher_for(meshers: &mut Vec<(MeshHint, Mesher)>, hint: MeshHint) -> Result<&mut Mesher, Error> {
    let i = match meshers.iter().position(|(h, _)| *h == hint) {
        Some(i) => i,
        None => {
            meshers.push((hint, Mesher::new(mesh_options(hint))?));
            meshers.len() - 1
        }
    };
    Ok(&mut meshers[i].1)
}

/// Meshes guide wires (a target surface, grid cells) thinly, for pictures.
pub fn guide_mesh(plant: &Plant) -> Result<Mesh, Error> {
    let options = MeshOptions {
        radial_segments: 4,
        cap_ends: false,
        ..Default::default()
    };
    Ok(Mesher::new(options)?.mesh(plant)?)
}

/// Checks that a picture path ends in `.png`.
pub fn check_png(path: &Path) -> Result<(), InputError> {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("png") => Ok(()),
        _ => Err(InputError::file(
            path,
            "pictures are written as PNG; use a .png file name",
        )),
    }
}

/// Renders a scene as a PNG picture (the bytes of the file).
pub fn picture(scene: &Scene<'_>, view: View, size: (u32, u32)) -> Result<Vec<u8>, Error> {
    let options = RenderOptions {
        width: size.0,
        height: size.1,
        view,
        ..RenderOptions::default()
    };
    let image = sylva_render::render(scene, &options)?;
    Ok(sylva_render::encode_png(&image)?)
}

/// Renders a scene and writes it as a PNG file.
pub fn write_picture(
    scene: &Scene<'_>,
    path: &Path,
    view: View,
    size: (u32, u32),
) -> Result<(), Error> {
    crate::files::write(path, &picture(scene, view, size)?)
}
