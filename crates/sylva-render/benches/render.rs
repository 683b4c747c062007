//! Rendering throughput: the evolved default oak (36,840 triangles) and a 202k-triangle
//! test tree at 800 x 800 with 2x supersampling, with and without ground and shadows, and
//! with textured bark, leaves and flowers.
//!
//! Run with `cargo bench -p sylva-render --bench render`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sylva_core::MaterialId;
use sylva_mesh::mesher::{MeshOptions, mesh_plant};
use sylva_mesh::{Scene, SceneNode};
use sylva_render::{RenderOptions, Renderer};

fn render(c: &mut Criterion) {
    let plant = sylva_testkit::binary_tree(9, 8);
    let mesh = mesh_plant(&plant, &MeshOptions::default()).unwrap();
    eprintln!("render tree: {} triangles", mesh.triangle_count());
    let scene = Scene::single(SceneNode::new("tree", &mesh));
    let mut group = c.benchmark_group("render_800x800_ss2");
    group.sample_size(10);
    let base = RenderOptions::default();
    let variants = [
        ("ground_and_shadows", base.clone()),
        (
            "no_shadows",
            RenderOptions {
                shadows: false,
                ..base.clone()
            },
        ),
        (
            "plant_only",
            RenderOptions {
                ground: false,
                shadows: false,
                ..base
            },
        ),
    ];
    let mut renderer = Renderer::new();
    for (name, options) in variants {
        group.bench_function(name, |b| {
            b.iter(|| renderer.render(black_box(&scene), &options).unwrap())
        });
    }
    // The same tree with bark, leaf and petal textures (made once, kept by the renderer).
    let mut textured = plant;
    for (m, id) in [0, 3, 6].into_iter().enumerate() {
        textured
            .set_texture(MaterialId(m as u16), Some(id))
            .unwrap();
    }
    let textured = mesh_plant(&textured, &MeshOptions::default()).unwrap();
    let scene = Scene::single(SceneNode::new("tree", &textured));
    let options = RenderOptions::default();
    group.bench_function("textured", |b| {
        b.iter(|| renderer.render(black_box(&scene), &options).unwrap())
    });
    group.finish();
}

criterion_group!(benches, render);
criterion_main!(benches);
