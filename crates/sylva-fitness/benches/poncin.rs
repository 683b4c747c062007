//! Poncin's fitness on a plant the size the automata pipeline makes: a trunk of 100 steps
//! with 30 branches of 8 steps and a leaf per branch step (30 endpoints, 341 segments,
//! 240 leaves).
//!
//! Run with `cargo bench -p sylva-fitness --bench poncin`; throughput is in plants scored.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sylva_core::glam::{DVec3, Quat, Vec2, Vec3};
use sylva_core::{Organ, OrganKind, Plant, PlantMeta};
use sylva_fitness::poncin::{
    DensityGrid, GridBox, GridConfig, PairMode, PairOptions, PoncinContext, PoncinFitness,
    PoncinScratch, PoncinWeights,
};

/// Metres per step of the trunk and branches.
const STEP: f32 = 0.3;

fn automata_like() -> Plant {
    let mut p = Plant::new(PlantMeta::default());
    let mut prev = None;
    let mut at = Vec3::ZERO;
    let mut trunk = Vec::new();
    for i in 0..100 {
        let next = at + Vec3::Y * STEP;
        let r = 0.3 * (1.0 - i as f32 / 120.0);
        let s = p
            .add_segment(at, next, (r, r * 0.99), prev, false, Plant::BARK)
            .unwrap();
        trunk.push((s, next));
        (prev, at) = (Some(s), next);
    }
    for b in 0..30 {
        let (mut parent, mut pos) = trunk[40 + 2 * b];
        let a = b as f32 * 2.399;
        let dir = Vec3::new(a.cos(), 0.6, a.sin()).normalize() * STEP * 6.0;
        for k in 0..8 {
            let next = pos + dir;
            parent = p
                .add_segment(pos, next, (0.05, 0.04), Some(parent), k == 0, Plant::BARK)
                .unwrap();
            p.add_organ(Organ {
                kind: OrganKind::Leaf,
                position: next,
                orientation: Quat::IDENTITY,
                size: Vec2::new(0.1, 0.05),
                material: Plant::LEAF,
                parent: Some(parent),
            })
            .unwrap();
            pos = next;
        }
    }
    p
}

fn configs() -> Vec<(&'static str, PoncinFitness)> {
    let grid = DensityGrid::new(GridConfig {
        min: DVec3::new(-150.0, 0.0, -150.0),
        max: DVec3::new(150.0, 375.0, 150.0),
        divisions: [5, 5, 5],
        weight: 1.0,
        target: 15,
        boxes: vec![GridBox {
            from: [0, 4, 0],
            to: [4, 4, 4],
            weight: -1.0,
            target: None,
        }],
        cells: vec![],
    })
    .unwrap();
    let sampled = PairOptions {
        mode: PairMode::Sampled,
        ..PairOptions::default()
    };
    vec![
        ("text_exact", PoncinFitness::default()),
        (
            "text_sampled",
            PoncinFitness {
                pairs: sampled,
                ..PoncinFitness::default()
            },
        ),
        (
            "table2_grid_exact",
            PoncinFitness {
                weights: PoncinWeights::TABLE_2,
                grid: Some(grid),
                grid_gate: 1e12,
                ..PoncinFitness::default()
            },
        ),
        (
            "with_angle_exact",
            PoncinFitness {
                weights: PoncinWeights {
                    angle: 1.0,
                    ..PoncinWeights::TEXT
                },
                ..PoncinFitness::default()
            },
        ),
    ]
}

fn score(c: &mut Criterion) {
    let plant = automata_like();
    let mut scratch = PoncinScratch::new();
    let mut group = c.benchmark_group("poncin");
    group.throughput(Throughput::Elements(1));
    for (name, config) in configs() {
        let s = config.score(&plant, PoncinContext::default(), &mut scratch);
        eprintln!(
            "{name}: {} endpoints, {} leaves, total {:.1}",
            s.branches, s.leaves, s.total
        );
        group.bench_function(name, |b| {
            let mut seed = 0;
            b.iter(|| {
                seed += 1;
                let ctx = PoncinContext {
                    seed,
                    negative_thickness: 0,
                };
                config.score(black_box(&plant), ctx, &mut scratch)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, score);
criterion_main!(benches);
