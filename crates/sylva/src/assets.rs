//! From a genome to the files people use: a mesh with its origin, exported or pictured.

use std::path::Path;

use crate::genome::Genome;
use anyhow::Context;
use sylva_core::Plant;
use sylva_mesh::export::{self, Format};
use sylva_mesh::mesher::{MeshOptions, Mesher, mesh_plant};
use sylva_mesh::render::{self, RenderOptions, View};
use sylva_mesh::{Mesh, Scene, SceneNode};

use crate::error::InputError;

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
}

impl Grown {
    /// Grows and meshes a genome.
    pub fn new(genome: Genome, seed: u64) -> anyhow::Result<Grown> {
        Self::with_roots(genome, seed, true)
    }

    /// Grows and meshes a genome, leaving out the roots when `roots` is false (they stay
    /// out of the exported asset and the pictures).
    pub fn with_roots(genome: Genome, seed: u64, roots: bool) -> anyhow::Result<Grown> {
        let mut plant = genome
            .develop(seed)
            .with_context(|| format!("growing the {} genome", genome.model()))?;
        if !roots {
            plant = plant.without(sylva_core::MaterialKind::Root);
        }
        let mesh =
            mesh_plant(&plant, &mesh_options(genome.model())).context("meshing the plant")?;
        Ok(Grown {
            genome,
            seed,
            plant,
            mesh,
        })
    }

    /// What the asset carries to be grown again: genome, seed and Sylva version.
    pub fn extras(&self) -> serde_json::Value {
        origin_extras(self.genome.to_value(), self.seed)
    }

    /// A scene holding this plant at the origin.
    pub fn scene(&self) -> Scene<'_> {
        let mut node = SceneNode::new(self.genome.model(), &self.mesh);
        node.extras = Some(self.extras());
        Scene::single(node)
    }

    /// Writes the asset; the format follows the extension.
    pub fn export(&self, path: &Path) -> anyhow::Result<()> {
        export::write_scene(path, &self.scene())
            .with_context(|| format!("writing {}", path.display()))
    }

    /// Renders and writes a picture.
    pub fn picture(&self, path: &Path, view: View, size: (u32, u32)) -> anyhow::Result<()> {
        self.picture_with(path, view, size, None)
    }

    /// Renders and writes a picture, with guides (a target surface, grid cells) beside the
    /// plant.
    pub fn picture_with(
        &self,
        path: &Path,
        view: View,
        size: (u32, u32),
        guides: Option<&Mesh>,
    ) -> anyhow::Result<()> {
        let mut scene = self.scene();
        if let Some(mesh) = guides {
            scene.nodes.push(SceneNode::new("guides", mesh));
        }
        write_picture(&scene, path, view, size)
    }
}

/// What every exported plant carries to be grown again: its genome, seed and Sylva version.
pub fn origin_extras(genome: serde_json::Value, seed: u64) -> serde_json::Value {
    serde_json::json!({
        "genome": genome,
        "seed": seed,
        "sylva_version": env!("CARGO_PKG_VERSION"),
    })
}

/// How plants of a model are meshed: L-system modules are sphylls (cylinders with spherical
/// ends), so their tubes end in domes; every other model uses the defaults.
pub fn mesh_options(model: &str) -> MeshOptions {
    MeshOptions {
        round_caps: model == sylva_lsystem::genome::MODEL,
        ..MeshOptions::default()
    }
}

/// Meshes several plants with one mesher (its buffers are reused).
pub fn mesh_all<'a>(
    plants: impl IntoIterator<Item = &'a Plant>,
    options: &MeshOptions,
) -> anyhow::Result<Vec<Mesh>> {
    let mut mesher = Mesher::new(options.clone()).context("mesh options")?;
    plants
        .into_iter()
        .map(|p| mesher.mesh(p).context("meshing a plant"))
        .collect()
}

/// Renders a scene and writes it as PNG.
pub fn write_picture(
    scene: &Scene,
    path: &Path,
    view: View,
    size: (u32, u32),
) -> anyhow::Result<()> {
    let options = RenderOptions {
        width: size.0,
        height: size.1,
        view,
        ..RenderOptions::default()
    };
    let image = render::render(scene, &options).context("rendering")?;
    render::write_png(path, &image).with_context(|| format!("writing {}", path.display()))
}

/// Reads a genome file; errors point at the line and column.
pub fn load_genome(path: &Path) -> Result<Genome, InputError> {
    let text = crate::config::read_text(path)?;
    genome_from_text(path, &text)
}

/// Parses a genome file already read from `path`.
pub fn genome_from_text(path: &Path, text: &str) -> Result<Genome, InputError> {
    Genome::from_json(text).map_err(|e| {
        if e.line == 0 {
            InputError::new(path.display().to_string(), e.message)
        } else {
            InputError::at(path, text, e.line, e.column, e.message)
        }
    })
}

/// Checks an output path's extension before any work is done.
pub fn asset_format(path: &Path) -> Result<Format, InputError> {
    Format::from_path(path).map_err(|e| InputError::new(path.display().to_string(), e.to_string()))
}

/// Checks that a picture path ends in `.png`.
pub fn check_png(path: &Path) -> Result<(), InputError> {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("png") => Ok(()),
        _ => Err(InputError::new(
            path.display().to_string(),
            "pictures are written as PNG; use a .png file name",
        )),
    }
}
