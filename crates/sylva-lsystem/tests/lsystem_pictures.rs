#![allow(clippy::unwrap_used)]
//! Pictures of the L-system plants and of the paper's simulations, written to
//! `/tmp/lsystem-*.png` to be looked at. Each picture is checked not to be blank, and each
//! plant to spread in width as well as height (neither a line nor a dot).

use std::path::{Path, PathBuf};

use sylva_core::Plant;
use sylva_core::glam::Vec3;
use sylva_core::par::Pool;
use sylva_lsystem::LSystemGenome;
use sylva_lsystem::experiments::{Simulation, SimulationOutcome};
use sylva_lsystem::garden::GrowSettings;
use sylva_mesh::mesher::{MeshOptions, mesh_plant};
use sylva_mesh::{Scene, SceneNode};
use sylva_render::{RenderOptions, View, render, write_png};

fn examples() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/lsystem")
}

/// Renders plants placed in the world and checks the picture is not blank.
fn picture(plants: &[(&Plant, Vec3)], name: &str, view: View) {
    let meshes: Vec<_> = plants
        .iter()
        .map(|(p, _)| mesh_plant(p, &MeshOptions::default()).unwrap())
        .collect();
    let mut scene = Scene::default();
    for ((_, at), mesh) in plants.iter().zip(&meshes) {
        let mut node = SceneNode::new(name, mesh);
        node.translation = *at;
        scene.nodes.push(node);
    }
    let options = RenderOptions {
        width: 600,
        height: 600,
        view,
        ..RenderOptions::default()
    };
    let image = render(&scene, &options).unwrap();
    let painted = image.pixels().filter(|p| p.0 != options.background).count();
    assert!(
        painted > 600 * 600 / 20,
        "{name}: only {painted} pixels drawn"
    );
    let path = std::env::temp_dir().join(format!("lsystem-{name}.png"));
    write_png(&path, &image).unwrap();
}

/// A plant spreads sideways as well as up: not a line, not a blob.
fn assert_plant_shaped(plant: &Plant, name: &str) {
    let b = plant.bounds();
    let size = b.size();
    assert!(size.y > 0.2 && size.x.min(size.z) > 0.2, "{name}: {size:?}");
}

fn grow_alone(file: &str, steps: u32) -> Plant {
    let genome = load(&examples().join(file));
    let settings = GrowSettings {
        steps,
        ..GrowSettings::default()
    };
    genome.develop_with(&settings, 0).unwrap()
}

#[test]
fn pictures_of_single_plants() {
    for (file, steps, view) in [
        ("bush.json", 100, View::Iso),
        ("tree.json", 150, View::Iso),
        ("herb.json", 40, View::Iso),
    ] {
        let plant = grow_alone(file, steps);
        let name = file.trim_end_matches(".json");
        assert_plant_shaped(&plant, name);
        picture(&[(&plant, Vec3::ZERO)], name, view);
        picture(
            &[(&plant, Vec3::ZERO)],
            &format!("{name}-front"),
            View::Front,
        );
    }
}

fn run(config: &str) -> SimulationOutcome {
    let text = std::fs::read_to_string(examples().join(config)).unwrap();
    let sim: Simulation = toml::from_str(&text).unwrap();
    let genomes: Vec<_> = sim
        .genome_files()
        .iter()
        .map(|f| load(&examples().join(f)))
        .collect();
    sim.run(&genomes, &Pool::with_threads(0).unwrap()).unwrap()
}

fn load(path: &Path) -> LSystemGenome {
    LSystemGenome::from_json(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn pictures_of_the_simulations() {
    let herbs = run("herbs-under-tree.toml");
    let placed: Vec<_> = herbs
        .plants()
        .iter()
        .map(|p| (&p.plant, p.position))
        .collect();
    assert_plant_shaped(placed[0].0, "tree");
    picture(&placed, "herbs-under-tree", View::Iso);

    let lateral = run("lateral-light.toml");
    let SimulationOutcome::LateralLight(o) = &lateral else {
        panic!("{lateral:?}")
    };
    let placed: Vec<_> = o.plants.iter().map(|p| (&p.plant, p.position)).collect();
    picture(&placed, "lateral-light", View::Front);
    let placed: Vec<_> = o.control.iter().map(|p| (&p.plant, p.position)).collect();
    picture(&placed, "vertical-light", View::Front);

    let evolved = run("from-empty-rules.toml");
    let placed: Vec<_> = evolved
        .plants()
        .iter()
        .map(|p| (&p.plant, p.position))
        .collect();
    picture(&placed, "from-empty-rules", View::Iso);
}
