//! Pictures of the PlantMaker examples, for people to look at.
//!
//! `cargo test -p sylva-plantmaker --test plantmaker_pictures -- --ignored` writes
//! `/tmp/plantmaker-<name>.png` for every genome in `examples/plantmaker/`, ten seeds of the
//! bush (`/tmp/plantmaker-seeds.png`) and parents with offspring of each operator
//! (`/tmp/plantmaker-offspring.png`) and a garden of three genomes
//! (`/tmp/plantmaker-garden.png`). Set `PLANTMAKER_ONLY=name` to draw one example.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::{Path, PathBuf};

use sylva_core::Plant;
use sylva_mesh::mesher::{MeshOptions, mesh_plant};
use sylva_mesh::{Mesh, Scene, SceneNode};
use sylva_plantmaker::variation::breed;
use sylva_plantmaker::{Garden, Level, Mutation, Operator, Parent, PlantMaker};
use sylva_render::{
    RenderOptions, SheetCell, SheetOptions, View, contact_sheet, render, write_png,
};

fn examples() -> Vec<(String, PlantMaker)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/plantmaker");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            let text = std::fs::read_to_string(&p).unwrap();
            let genome = PlantMaker::from_json(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
            (name, genome)
        })
        .collect()
}

fn mesh(plant: &Plant) -> Mesh {
    mesh_plant(plant, &MeshOptions::default()).unwrap()
}

#[test]
#[ignore = "writes pictures to /tmp; run by hand"]
fn example_pictures() {
    let only = std::env::var("PLANTMAKER_ONLY").ok();
    let mut all = examples();
    all.push(("default".to_owned(), PlantMaker::default()));
    for (name, genome) in all {
        if only.as_ref().is_some_and(|o| *o != name) {
            continue;
        }
        let plant = genome.develop(genome.seed).unwrap();
        let b = plant.bounds();
        eprintln!(
            "{name}: {} segments, {} organs, {} materials, {:.2} m tall, {:.2} x {:.2} m",
            plant.segments().len(),
            plant.organs().len(),
            plant.materials().len(),
            b.max.y,
            b.max.x - b.min.x,
            b.max.z - b.min.z
        );
        let m = mesh(&plant);
        for (view, suffix) in [(View::Front, ""), (View::Iso, "-iso")] {
            let scene = Scene::single(SceneNode::new(name.clone(), &m));
            let options = RenderOptions {
                width: 640,
                height: 640,
                view,
                ..RenderOptions::default()
            };
            let image = render(&scene, &options).unwrap();
            write_png(
                Path::new(&format!("/tmp/plantmaker-{name}{suffix}.png")),
                &image,
            )
            .unwrap();
        }
    }
}

#[test]
#[ignore = "writes pictures to /tmp; run by hand"]
fn seeds_and_offspring_sheets() {
    let all = examples();
    let get = |n: &str| all.iter().find(|(name, _)| name == n).unwrap().1.clone();

    // One genome, ten seeds.
    let bush = get("flowering-bush");
    let plants: Vec<Plant> = (0..10).map(|s| bush.develop(s).unwrap()).collect();
    let meshes: Vec<Mesh> = plants.iter().map(mesh).collect();
    let cells: Vec<SheetCell> = meshes
        .iter()
        .enumerate()
        .map(|(s, m)| SheetCell {
            scene: Scene::single(SceneNode::new("bush", m)),
            caption: format!("seed {s}"),
        })
        .collect();
    let options = SheetOptions {
        columns: 5,
        title: Some("flowering-bush, ten seeds".into()),
        ..SheetOptions::default()
    };
    write_png(
        Path::new("/tmp/plantmaker-seeds.png"),
        &contact_sheet(&cells, &options, &sylva_core::par::Pool::Serial).unwrap(),
    )
    .unwrap();

    // Parents and offspring: a row per operator.
    let (a, b) = (get("palm"), get("tulip"));
    let mut rng = sylva_core::rng::seeded(11);
    let parents = [
        Parent {
            genome: &a,
            dominance: 1.0,
        },
        Parent {
            genome: &b,
            dominance: 1.0,
        },
    ];
    let mut genomes = vec![("parent A: palm".to_owned(), a.clone())];
    genomes.push(("parent B: tulip".to_owned(), b.clone()));
    for level in [Level::Low, Level::Medium, Level::High] {
        for i in 0..2 {
            let child = breed(&parents, Operator::Crossover(level), &mut rng).unwrap();
            genomes.push((
                format!("{} #{}", child.operator.name(), i + 1),
                child.genome,
            ));
        }
    }
    let m = Operator::Mutation(Mutation {
        rate: 0.1,
        spread: 0.1,
    });
    for i in 0..2 {
        let child = breed(&parents[1..], m, &mut rng).unwrap();
        genomes.push((format!("mutation of B #{}", i + 1), child.genome));
    }
    let plants: Vec<Plant> = genomes
        .iter()
        .map(|(_, g)| g.develop(g.seed).unwrap())
        .collect();
    let meshes: Vec<Mesh> = plants.iter().map(mesh).collect();
    let cells: Vec<SheetCell> = meshes
        .iter()
        .zip(&genomes)
        .map(|(m, (caption, _))| SheetCell {
            scene: Scene::single(SceneNode::new("plant", m)),
            caption: caption.clone(),
        })
        .collect();
    let options = SheetOptions {
        columns: 5,
        cell_width: 260,
        cell_height: 280,
        title: Some("parents and offspring".into()),
        ..SheetOptions::default()
    };
    write_png(
        Path::new("/tmp/plantmaker-offspring.png"),
        &contact_sheet(&cells, &options, &sylva_core::par::Pool::Serial).unwrap(),
    )
    .unwrap();
}

#[test]
#[ignore = "writes pictures to /tmp; run by hand"]
fn garden_picture() {
    let all = examples();
    let get = |n: &str| all.iter().find(|(name, _)| name == n).unwrap().1.clone();
    let mut garden = Garden::new(get("conifer"), 7, [16.0, 12.0], 3);
    garden.add(get("fern"), 12);
    garden.add(get("flowering-bush"), 8);
    let grown = garden.grow().unwrap();
    let meshes: Vec<Mesh> = grown.plants.iter().map(mesh).collect();
    let nodes = meshes
        .iter()
        .zip(&grown.placements)
        .map(|(m, p)| SceneNode {
            translation: p.translation,
            rotation: p.rotation(),
            ..SceneNode::new(format!("plant {}-{}", p.group, p.index), m)
        })
        .collect();
    let scene = Scene { nodes };
    let options = RenderOptions {
        width: 900,
        height: 600,
        ..RenderOptions::default()
    };
    write_png(
        Path::new("/tmp/plantmaker-garden.png"),
        &render(&scene, &options).unwrap(),
    )
    .unwrap();
}
