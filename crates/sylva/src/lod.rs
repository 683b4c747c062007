//! A grown plant's levels of detail as assets: one mesh per level (see [`sylva_gltf::lod`]),
//! each alone in its own scene, or all of them as sibling nodes named `NAME_LOD0`,
//! `NAME_LOD1`, … (the Unity naming convention) with each level's screen coverage in its
//! node's extras. And a [`Preview`]: the one level a view of a given size needs, meshed
//! without meshing the plant in full.

use serde_json::json;
use sylva_gltf::lod::{LodError, LodLevel, lod_levels};
use sylva_mesh::mesher::Mesher;
use sylva_mesh::wind::Rig;
use sylva_mesh::{Mesh, Scene, SceneNode};

use crate::assets::{GrowOptions, Grown, Origin, grow_plant, mesh_options, mesh_options_for};
use crate::error::{Error, InputError};
use crate::genome::Genome;
use sylva_core::Plant;

/// One level, meshed.
pub struct LodAsset {
    /// The level's plant, options, detail, triangles and screen coverage.
    pub level: LodLevel,
    /// Its mesh.
    pub mesh: Mesh,
    /// Its wind skin and clip, when the plant has wind.
    pub rig: Option<Rig>,
}

/// A grown plant's chain of levels of detail.
pub struct LodAssets {
    /// Level 0 (the plant as grown) first.
    pub levels: Vec<LodAsset>,
    /// The extras every level's node carries (genome, seed, taper, wind), before its own.
    extras: serde_json::Value,
}

impl LodAssets {
    /// The chain of `options.lod` levels of `grown` (level 0 is its own mesh and rig; one
    /// level when `lod` is none), each further level rigged for `options.wind` when `grown`
    /// has wind. `options` are those `grown` grew with.
    pub fn new(grown: Grown, options: &GrowOptions) -> Result<Self, Error> {
        let (levels, wind) = (options.lod.unwrap_or(1), options.wind.as_ref());
        let options = mesh_options_for(grown.genome.mesh_hint(), &grown.dress.0);
        let extras = grown.scene().nodes[0].extras.clone().unwrap_or(json!({}));
        let chain = lod_levels(&grown.plant, &options, levels).map_err(|e| match e {
            LodError::Mesh(e) => Error::Mesh(e),
            LodError::Levels(n) => Error::Input(InputError::new(
                "--lod",
                format!(
                    "{n} levels asked for, expected 2 to {}",
                    sylva_gltf::lod::MAX_LEVELS
                ),
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
        Ok(LodAssets { levels, extras })
    }

    /// The node of level `k`, named `NAME_LODk`.
    fn node(&self, k: usize, name: &str) -> SceneNode<'_> {
        let asset = &self.levels[k];
        let mut node = SceneNode::new(format!("{name}_LOD{k}"), &asset.mesh);
        let mut extras = self.extras.clone();
        extras["lod"] = json!({
            "level": k,
            "levels": self.levels.len(),
            "screen_coverage": asset.level.screen_coverage,
            "triangles": asset.mesh.triangle_count(),
            "detail": asset.level.detail,
        });
        node.extras = Some(extras);
        node.rig = asset.rig.as_ref();
        node
    }

    /// Level `k` alone, its node named `NAME_LODk`.
    pub fn level_scene(&self, k: usize, name: &str) -> Scene<'_> {
        Scene::single(self.node(k, name))
    }

    /// Every level as sibling nodes at the origin, `NAME_LOD0` first.
    pub fn group_scene(&self, name: &str) -> Scene<'_> {
        Scene {
            nodes: (0..self.levels.len()).map(|k| self.node(k, name)).collect(),
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
}
