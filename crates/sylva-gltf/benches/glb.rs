//! GLB export throughput on a tree of over a million triangles: writing, meshing and
//! writing, with and without wind, and levels of detail (meshing alone is sylva-mesh's
//! `mesh` bench).
//!
//! Run with `cargo bench -p sylva-gltf --bench glb`; throughput is in triangles (elements).
//! The group keeps the name `mesh` it had when meshing and writing were benched together, so
//! the bench ids (`mesh/to_glb`, ...) and saved baselines carry over.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sylva_core::Plant;
use sylva_gltf::{export, lod};
use sylva_mesh::mesher::{MeshOptions, Mesher};
use sylva_mesh::wind;
use sylva_mesh::{Mesh, Scene, SceneNode};

fn glb_tree(c: &mut Criterion) {
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
    let scene = Scene::single(SceneNode::new("tree", &mesh));
    group.sample_size(10);
    group.bench_function("to_glb", |b| {
        b.iter(|| export::to_glb(black_box(&scene)).expect("the bench mesh exports"))
    });
    // Meshing and writing, without and with wind (the sources recorded, the rig built and
    // its skin and clip written): the wind's cost on the whole path to a GLB.
    group.bench_function("mesh_and_glb", |b| {
        b.iter(|| {
            let mesh = mesher
                .mesh(black_box(&plant))
                .expect("the bench tree meshes");
            export::to_glb(&Scene::single(SceneNode::new("tree", &mesh))).expect("exports")
        })
    });
    group.bench_function("mesh_and_glb_wind", |b| {
        b.iter(|| rigged(&mut mesher, &plant, |s| export::to_glb(s).expect("exports")))
    });
    // The same through the streaming writer (as `sylva grow` writes files), into a sink:
    // no GLB-sized buffer is made, so what is measured is the work rather than the kernel
    // handing out fresh pages for one.
    group.bench_function("mesh_and_stream", |b| {
        b.iter(|| {
            let mesh = mesher
                .mesh(black_box(&plant))
                .expect("the bench tree meshes");
            let scene = Scene::single(SceneNode::new("tree", &mesh));
            stream(&scene)
        })
    });
    group.bench_function("mesh_and_stream_wind", |b| {
        b.iter(|| rigged(&mut mesher, &plant, stream))
    });
    group.bench_function("stream", |b| b.iter(|| stream(black_box(&scene))));
    let (rigged, sources) = mesher
        .mesh_with_sources(&plant)
        .expect("the bench tree meshes");
    let rig = wind::rig(&plant, &rigged, sources, &wind::WindOptions::default());
    let mut node = SceneNode::new("tree", &rigged);
    node.rig = Some(&rig);
    let rigged_scene = Scene::single(node);
    group.bench_function("stream_wind", |b| {
        b.iter(|| stream(black_box(&rigged_scene)))
    });
    // Levels of detail: the chain of four found, each level meshed and written as its own
    // GLB; against `mesh_and_glb`, the cost of LOD0 to LOD3 together.
    group.bench_function("lod4_levels_only", |b| {
        b.iter(|| lod::lod_levels(black_box(&plant), &MeshOptions::default(), 4).expect("levels"))
    });
    group.bench_function("lod4_meshes_and_glbs", |b| {
        b.iter(|| {
            let chain = lod::lod_levels(black_box(&plant), &MeshOptions::default(), 4)
                .expect("the bench tree has levels");
            chain
                .iter()
                .map(|level| {
                    let mesh = Mesher::new(level.options.clone())
                        .and_then(|mut m| m.mesh(&level.plant))
                        .expect("levels mesh");
                    export::to_glb(&Scene::single(SceneNode::new("tree", &mesh)))
                        .expect("exports")
                        .len()
                })
                .sum::<usize>()
        })
    });
    group.finish();
}

/// Meshes `plant` recording where vertices came from, rigs it for the default wind (the
/// sources recorded, the rig built) and hands the rigged scene to `write`.
fn rigged<T>(mesher: &mut Mesher, plant: &Plant, write: impl FnOnce(&Scene) -> T) -> T {
    let (mesh, sources) = mesher
        .mesh_with_sources(black_box(plant))
        .expect("the bench tree meshes");
    let rig = wind::rig(plant, &mesh, sources, &wind::WindOptions::default());
    let mut node = SceneNode::new("tree", &mesh);
    node.rig = Some(&rig);
    write(&Scene::single(node))
}

/// Streams the GLB of `scene` into a sink; its length.
fn stream(scene: &Scene) -> u64 {
    let mut glb = export::Glb::of_scene(scene, export::GlbOptions::default()).expect("lays out");
    glb.write_to(&mut std::io::sink()).expect("writes");
    glb.stats().bytes
}

criterion_group!(benches, glb_tree);
criterion_main!(benches);
