//! A grown plant's levels of detail as assets: one mesh per level (see [`sylva_gltf::lod`])
//! and, last, an impostor (crossed cards showing the plant's picture, see
//! [`sylva_render::impostor`]) for trees far away; each alone in its own scene, or all of
//! them as sibling nodes named `NAME_LOD0`, `NAME_LOD1`, … (the Unity naming convention)
//! with each level's screen coverage in its node's extras. The last mesh level hands over to
//! the impostor at [`IMPOSTOR_COVERAGE`] of the screen's height (or half the coverage of the
//! level before, when that is less), and the impostor is drawn down to 1%.
//!
//! And a [`Preview`]: the one level a view of a given size needs, meshed without meshing
//! the plant in full.

use serde_json::json;
use sylva_gltf::lod::{LodError, LodLevel, lod_levels};
use sylva_mesh::mesher::Mesher;
use sylva_mesh::wind::Rig;
use sylva_mesh::{Mesh, Scene, SceneNode};

use crate::assets::{GrowOptions, Grown, Origin, grow_plant, mesh_options, mesh_options_for};
use crate::error::{Error, InputError};
use crate::genome::Genome;
use sylva_core::Plant;

pub use sylva_gltf::lod::MAX_LEVELS;

/// The screen coverage (plant height over screen height) below which the impostor stands
/// for the plant: 108 pixels of a 1080-pixel screen, a fifth of the picture's cells.
pub const IMPOSTOR_COVERAGE: f32 = 0.1;

/// One level, meshed.
pub struct LodAsset {
    /// The level's plant, options, detail, triangles and screen coverage.
    pub level: LodLevel,
    /// Its mesh.
    pub mesh: Mesh,
    /// Its wind skin and clip, when the plant has wind.
    pub rig: Option<Rig>,
}

/// The chain's last level: crossed cards showing the plant's picture.
pub struct Impostor {
    /// The cards, their picture in [`Mesh::impostor`].
    pub mesh: Mesh,
    /// The smallest screen coverage it is drawn at (it is culled below).
    pub screen_coverage: f32,
}

/// A grown plant's chain of levels of detail.
pub struct LodAssets {
    /// The meshed levels, level 0 (the plant as grown) first.
    pub levels: Vec<LodAsset>,
    /// The impostor after them (none for a plant with nothing to draw).
    pub impostor: Option<Impostor>,
    /// The extras every level's node carries (genome, seed, taper, wind), before its own.
    extras: serde_json::Value,
}

impl LodAssets {
    /// The chain of `options.lod` meshed levels of `grown` (level 0 is its own mesh and
    /// rig; one level when `lod` is none), each further level rigged for `options.wind` when
    /// `grown` has wind, then the impostor. `options` are those `grown` grew with.
    pub fn new(grown: Grown, options: &GrowOptions) -> Result<Self, Error> {
        let (levels, wind) = (options.lod.unwrap_or(1), options.wind.as_ref());
        let options = mesh_options_for(grown.genome.mesh_hint(), &grown.dress.0);
        let extras = grown.scene().nodes[0].extras.clone().unwrap_or(json!({}));
        let chain = lod_levels(&grown.plant, &options, levels).map_err(|e| match e {
            LodError::Mesh(e) => Error::Mesh(e),
            LodError::Levels(n) => Error::Input(InputError::new(
                "--lod",
                format!("{n} levels asked for, expected 2 to {}", MAX_LEVELS),
            )),
            other => Error::Input(InputError::new("--lod", other.to_string())),
        })?;
        let Grown { mesh, rig, .. } = grown;
        let mut first = Some((mesh, rig));
        let levels = chain
            .into_iter()
            .map(|level| {
                let (mesh, rig) = match first.take() {
                    Some(grown) => grown,
                    None => {
                        let mut mesher = Mesher::new(level.options.clone())?;
                        match wind {
                            Some(wind) => {
                                let (mesh, sources) = mesher.mesh_with_sources(&level.plant)?;
                                let rig = sylva_mesh::wind::rig(&level.plant, &mesh, sources, wind);
                                (mesh, Some(rig))
                            }
                            None => (mesher.mesh(&level.plant)?, None),
                        }
                    }
                };
                Ok(LodAsset { level, mesh, rig })
            })
            .collect::<Result<Vec<_>, Error>>()?;
        LodAssets::ending_in_impostor(levels, extras)
    }

    /// `levels` followed by the impostor of level 0, the last level's coverage moved to
    /// where the impostor takes over.
    fn ending_in_impostor(
        mut levels: Vec<LodAsset>,
        extras: serde_json::Value,
    ) -> Result<Self, Error> {
        let scene = Scene::single(SceneNode::new("plant", &levels[0].mesh));
        let impostor = sylva_render::impostor::impostor(&scene)?;
        if impostor.is_some() {
            let n = levels.len();
            let before = match n {
                1 => f32::INFINITY,
                _ => levels[n - 2].level.screen_coverage,
            };
            levels[n - 1].level.screen_coverage = IMPOSTOR_COVERAGE.min(0.5 * before);
        }
        let impostor = impostor.map(|mesh| Impostor {
            mesh,
            screen_coverage: sylva_gltf::lod::CULL_COVERAGE,
        });
        Ok(LodAssets {
            levels,
            impostor,
            extras,
        })
    }

    /// Levels in the chain: the meshed ones and the impostor.
    pub fn len(&self) -> usize {
        self.levels.len() + usize::from(self.impostor.is_some())
    }

    /// Whether the chain has no levels (never: level 0 is always there).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Level `k`'s mesh: a meshed level's, or the impostor's after them.
    ///
    /// # Panics
    ///
    /// When `k` is not below [`LodAssets::len`].
    pub fn mesh(&self, k: usize) -> &Mesh {
        match (self.levels.get(k), &self.impostor) {
            (Some(level), _) => &level.mesh,
            (None, Some(impostor)) => &impostor.mesh,
            (None, None) => panic!("level {k} of a chain of {}", self.len()),
        }
    }

    /// The node of level `k`, named `NAME_LODk`.
    fn node(&self, k: usize, name: &str) -> SceneNode<'_> {
        let mesh = self.mesh(k);
        let mut node = SceneNode::new(format!("{name}_LOD{k}"), mesh);
        let mut extras = self.extras.clone();
        let mut lod = json!({
            "level": k,
            "levels": self.len(),
            "triangles": mesh.triangle_count(),
        });
        match (self.levels.get(k), &self.impostor) {
            (Some(asset), _) => {
                lod["screen_coverage"] = json!(asset.level.screen_coverage);
                lod["detail"] = json!(asset.level.detail);
                node.rig = asset.rig.as_ref();
            }
            (None, Some(impostor)) => {
                lod["screen_coverage"] = json!(impostor.screen_coverage);
                lod["impostor"] = json!(true);
            }
            (None, None) => {}
        }
        extras["lod"] = lod;
        node.extras = Some(extras);
        node
    }

    /// Level `k` alone, its node named `NAME_LODk`.
    pub fn level_scene(&self, k: usize, name: &str) -> Scene<'_> {
        Scene::single(self.node(k, name))
    }

    /// Every level as sibling nodes at the origin, `NAME_LOD0` first, the impostor last.
    pub fn group_scene(&self, name: &str) -> Scene<'_> {
        Scene {
            nodes: (0..self.len()).map(|k| self.node(k, name)).collect(),
        }
    }
}

/// A plant grown and meshed at the first level of its chain within a triangle budget
/// ([`sylva_gltf::lod::preview`]): what a view a few hundred pixels wide needs, however
/// large the plant. Only the preview is meshed; the plant in full is counted, not meshed.
pub struct Preview {
    /// The preview's mesh.
    pub mesh: Mesh,
    /// Its detail number (1: the plant as it is).
    pub detail: f32,
    /// The triangles of the plant in full.
    pub full_triangles: usize,
    /// The node's extras: the plant's origin, and `preview` (detail and both counts).
    extras: serde_json::Value,
    /// The model's name, for the node.
    model: &'static str,
}

impl Preview {
    /// Grows `genome` with `seed` (roots left out unless `roots`) and meshes the level of at
    /// most about `max_triangles` triangles.
    pub fn grow(
        genome: &Genome,
        seed: u64,
        roots: bool,
        max_triangles: usize,
    ) -> Result<Preview, Error> {
        let plant = grow_plant(genome, seed, roots, None)?;
        Preview::of(genome, seed, &plant, max_triangles)
    }

    /// The preview of `plant`, grown already from `genome` with `seed` (as [`grow_plant`]
    /// grows it), of at most about `max_triangles` triangles.
    pub fn of(
        genome: &Genome,
        seed: u64,
        plant: &Plant,
        max_triangles: usize,
    ) -> Result<Preview, Error> {
        let options = mesh_options(genome.mesh_hint());
        let full_triangles = Mesher::new(options.clone())?.counts(plant)?.triangles;
        let level =
            sylva_gltf::lod::preview(plant, &options, max_triangles).map_err(|e| match e {
                LodError::Mesh(e) => Error::Mesh(e),
                other => Error::Input(InputError::new("preview", other.to_string())),
            })?;
        let mesh = Mesher::new(level.options.clone())?.mesh(&level.plant)?;
        let mut extras = Origin::of(genome, seed).extras();
        extras["preview"] = json!({
            "detail": level.detail,
            "triangles": mesh.triangle_count(),
            "full_triangles": full_triangles,
        });
        Ok(Preview {
            mesh,
            detail: level.detail,
            full_triangles,
            extras,
            model: genome.model(),
        })
    }

    /// The extras its node carries.
    pub fn extras(&self) -> &serde_json::Value {
        &self.extras
    }

    /// A scene of the preview at the origin, its node carrying its origin.
    pub fn scene(&self) -> Scene<'_> {
        let mut node = SceneNode::new(self.model, &self.mesh);
        node.extras = Some(self.extras.clone());
        Scene::single(node)
    }

    /// The preview as a GLB file's bytes: what a front end's 3D view loads.
    pub fn glb(&self) -> Result<Vec<u8>, Error> {
        crate::export::glb(&self.scene())
    }
}
