//! Growing and meshing one PlantMaker plant of each example (the target: under 2 ms
//! for a typical example).
//!
//! Run with `cargo bench -p sylva-plantmaker --bench plantmaker`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sylva_mesh::Mesh;
use sylva_mesh::mesher::{MeshOptions, Mesher};
use sylva_plantmaker::PlantMaker;

const EXAMPLES: [(&str, &str); 5] = [
    (
        "fern",
        include_str!("../../../examples/plantmaker/fern.json"),
    ),
    (
        "palm",
        include_str!("../../../examples/plantmaker/palm.json"),
    ),
    (
        "flowering-bush",
        include_str!("../../../examples/plantmaker/flowering-bush.json"),
    ),
    (
        "tulip",
        include_str!("../../../examples/plantmaker/tulip.json"),
    ),
    (
        "conifer",
        include_str!("../../../examples/plantmaker/conifer.json"),
    ),
];

fn grow_and_mesh(c: &mut Criterion) {
    let mut mesher = Mesher::new(MeshOptions::default()).unwrap();
    let mut mesh = Mesh::default();
    let mut group = c.benchmark_group("plantmaker");
    group.sample_size(30);
    for (name, text) in EXAMPLES {
        let genome = PlantMaker::from_json(text).unwrap();
        let plant = genome.develop(genome.seed).unwrap();
        let stats = mesher.mesh_into(&plant, &mut mesh).unwrap();
        eprintln!(
            "{name}: {} segments, {} organs, {} triangles",
            plant.segments().len(),
            plant.organs().len(),
            stats.triangles
        );
        group.bench_function(format!("develop/{name}"), |b| {
            b.iter(|| black_box(&genome).develop(black_box(7)).unwrap())
        });
        group.bench_function(format!("develop+mesh/{name}"), |b| {
            b.iter(|| {
                let plant = black_box(&genome).develop(black_box(7)).unwrap();
                mesher.mesh_into(&plant, &mut mesh).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, grow_and_mesh);
criterion_main!(benches);
