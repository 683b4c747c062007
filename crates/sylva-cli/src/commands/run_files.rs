//! A run's folder, shared by `sylva evolve`, its maps of varieties and `sylva match`: the
//! checkpoint's name, the files a run writes, and the best plant's files.

use std::path::Path;

use sylva::assets::{guide_mesh, picture};
use sylva::core::Plant;
use sylva::files::Outputs;
use sylva::mesh::SceneNode;
use sylva::{Config, Genome, Grown};

pub(super) const CHECKPOINT: &str = "checkpoint.json";

/// Every file a run writes in its folder.
pub(super) const FILES: [&str; 8] = [
    CHECKPOINT,
    "config.toml",
    "stats.csv",
    "fitness.svg",
    "best.json",
    "best.glb",
    "best.png",
    "population.png",
];

/// Adds the best plant's files: `best.json`, `best.glb` (with the config's taper, wind and
/// height) and `best.png` (with `guides`, if any). Returns the plant grown.
pub(super) fn add_best(
    files: &mut Outputs,
    out: &Path,
    best: &Genome,
    config: &Config,
    guides: Option<Plant>,
) -> anyhow::Result<Grown> {
    files.add(&out.join("best.json"), best.to_json().as_bytes())?;
    let grown = Grown::grow(best.clone(), &config.grow_options()?)?;
    files.add_scene(&out.join("best.glb"), &grown.scene())?;
    let guides = guides.map(|p| guide_mesh(&p)).transpose()?;
    let mut scene = grown.scene();
    if let Some(mesh) = &guides {
        scene.nodes.push(SceneNode::new("guides", mesh));
    }
    let size = config.output().image_size;
    files.add(
        &out.join("best.png"),
        &picture(&scene, config.output().view, (size, size))?,
    )?;
    Ok(grown)
}
