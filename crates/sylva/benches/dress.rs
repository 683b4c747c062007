//! What dressing costs: the oak preset (`examples/species/oak.toml`: an L-system oak, 17 m,
//! oak leaves at real size, furrowed bark) grown and meshed in leaf, against the same plant
//! at the same height grown and meshed bare, and the dress alone. The bar: in leaf
//! within twice the bare plant. And the impostor of the oak in leaf (the last level of its
//! chain of detail): its two pictures drawn and its cards made. And the plausibility report
//! of the oak in leaf, which a match's term takes of every plant it scores.
//!
//! Run with `cargo bench -p sylva --bench dress`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use sylva::preset::Preset;
use sylva::{Dress, GrowOptions, Grown};

fn dress(c: &mut Criterion) {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let preset = Preset::load(
        &sylva::Registry::standard(),
        &here.join("../../examples/species/oak.toml"),
    )
    .unwrap();
    let dressed = preset.options.clone();
    let bare = GrowOptions {
        dress: Dress::default(),
        ..dressed.clone()
    };
    // Atlases and barks are drawn once per process: draw them before timing.
    let grown = Grown::grow(preset.genome.clone(), &dressed).unwrap();
    let plain = Grown::grow(preset.genome.clone(), &bare).unwrap();
    let mut group = c.benchmark_group("dress");
    group.sample_size(20);
    group.bench_function(
        format!(
            "oak preset bare ({} segments, {} triangles)",
            plain.plant.segments().len(),
            plain.mesh.triangle_count()
        ),
        |b| b.iter(|| black_box(Grown::grow(preset.genome.clone(), &bare).unwrap())),
    );
    group.bench_function(
        format!(
            "oak preset in leaf ({} cards, {} triangles)",
            grown.plant.organs().len(),
            grown.mesh.triangle_count()
        ),
        |b| b.iter(|| black_box(Grown::grow(preset.genome.clone(), &dressed).unwrap())),
    );
    let (_, undressed) = Grown::plant(&preset.genome, &bare).unwrap();
    group.bench_function("the dress alone", |b| {
        b.iter(|| black_box(sylva::core::dress::dress(&undressed, &dressed.dress, 0).unwrap()))
    });
    group.bench_function(
        format!(
            "the plausibility report of the oak in leaf ({} organs)",
            grown.plant.organs().len()
        ),
        |b| b.iter(|| black_box(sylva::inspect::Report::of(&grown.plant, None))),
    );
    let scene = grown.scene();
    group.bench_function("the impostor of the oak in leaf", |b| {
        b.iter(|| black_box(sylva::render::impostor::impostor(&scene).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, dress);
criterion_main!(benches);
