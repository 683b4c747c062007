//! Meshing throughput on a tree of over a million triangles, into reused buffers and fresh.
//!
//! Run with `cargo bench -p sylva-mesh --bench mesh`; throughput is in triangles (elements).
//! Writing GLB (with wind and levels of detail) is sylva-gltf's `glb` bench.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sylva_mesh::Mesh;
use sylva_mesh::mesher::{MeshOptions, Mesher};

fn mesh_tree(c: &mut Criterion) {
    let plant = sylva_testkit::bench_tree();
    let mut mesher = Mesher::new(MeshOptions::default()).expect("default options are legal");
    let mut mesh = Mesh::default();
    let stats = mesher
        .mesh_into(&plant, &mut mesh)
        .expect("the bench tree meshes");
    eprintln!(
        "bench tree: {} segments, {} organs, {} vertices, {} triangles",
        plant.segments().len(),
        plant.organs().len(),
        stats.vertices,
        stats.triangles
    );

    let mut group = c.benchmark_group("mesh");
    group.throughput(Throughput::Elements(stats.triangles as u64));
    group.sample_size(20);
    group.bench_function("mesh_into_reused", |b| {
        b.iter(|| {
            mesher
                .mesh_into(black_box(&plant), &mut mesh)
                .expect("the bench tree meshes")
        })
    });
    group.bench_function("mesh_fresh", |b| {
        b.iter(|| {
            mesher
                .mesh(black_box(&plant))
                .expect("the bench tree meshes")
        })
    });
    group.finish();
}

criterion_group!(benches, mesh_tree);
criterion_main!(benches);
