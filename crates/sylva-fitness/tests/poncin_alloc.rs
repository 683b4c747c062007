//! Scoring with a warmed-up scratch allocates nothing: it runs tens of thousands of times a
//! second in the automata pipeline. (This binary runs without libtest's
//! harness, on its main thread alone, so the global counts are its own.)
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::alloc::System;

use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};
use sylva_core::glam::{DVec3, Quat, Vec3};
use sylva_core::{Organ, OrganKind, Plant, PlantMeta};
use sylva_fitness::poncin::{
    DensityGrid, GridConfig, NumTarget, PairMode, PairOptions, PoncinContext, PoncinFitness,
    PoncinScratch, PoncinWeights, TargetShape, ThickMeasure, ThickOptions,
};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// A trunk with `n` branches, each with a leaf at its tip.
fn plant(n: usize) -> Plant {
    let mut p = Plant::new(PlantMeta::default());
    let top = Vec3::new(0.0, 20.0, 0.0);
    let trunk = p
        .add_segment(Vec3::ZERO, top, (0.3, 0.1), None, false, Plant::BARK)
        .unwrap();
    for i in 0..n {
        let a = i as f32 * 2.4;
        let tip = top + Vec3::new(10.0 * a.cos(), 5.0, 10.0 * a.sin());
        let s = p
            .add_segment(top, tip, (0.05, 0.03), Some(trunk), true, Plant::BARK)
            .unwrap();
        p.add_organ(Organ {
            kind: OrganKind::Leaf,
            position: tip,
            orientation: Quat::IDENTITY,
            size: sylva_core::glam::Vec2::new(0.1, 0.05),
            material: Plant::LEAF,
            parent: Some(s),
        })
        .unwrap();
    }
    p
}

fn main() {
    scoring_does_not_allocate_once_warm();
    println!("poncin_alloc: scoring_does_not_allocate_once_warm ... ok");
}

fn scoring_does_not_allocate_once_warm() {
    let grid = DensityGrid::new(GridConfig {
        min: DVec3::new(-150.0, 0.0, -150.0),
        max: DVec3::new(150.0, 375.0, 150.0),
        divisions: [5, 5, 5],
        weight: 1.0,
        target: 15,
        boxes: vec![],
        cells: vec![],
    })
    .unwrap();
    // Every pair mode with every thickness measure.
    let measures = [
        ThickMeasure::Endpoints,
        ThickMeasure::Taper,
        ThickMeasure::Bars,
        ThickMeasure::Gradual,
    ];
    let configs: Vec<PoncinFitness> = [PairMode::Exact, PairMode::Sampled]
        .into_iter()
        .flat_map(|mode| measures.map(|measure| (mode, measure)))
        .map(|(mode, measure)| PoncinFitness {
            weights: PoncinWeights {
                angle: 1.0,
                grid: 10.0,
                ..PoncinWeights::TEXT
            },
            target: TargetShape::Ellipsoid {
                center: DVec3::new(0.0, 200.0, 0.0),
                radii: DVec3::new(150.0, 100.0, 120.0),
            },
            num_target: NumTarget::PerLevel(vec![1, 30]),
            pairs: PairOptions {
                mode,
                ..PairOptions::default()
            },
            grid: Some(grid.clone()),
            grid_gate: 1e12,
            thick: ThickOptions {
                measure,
                ..ThickOptions::default()
            },
            ..PoncinFitness::default()
        })
        .collect();
    let big = plant(60);
    let small = plant(30);
    let mut scratch = PoncinScratch::new();
    for config in &configs {
        config.score(&big, PoncinContext::default(), &mut scratch);
    }
    let region = Region::new(GLOBAL);
    for seed in 0..100 {
        for config in &configs {
            let ctx = PoncinContext {
                seed,
                negative_thickness: 1,
            };
            std::hint::black_box(config.score(&small, ctx, &mut scratch));
            std::hint::black_box(config.score(&big, ctx, &mut scratch));
        }
    }
    let change = region.change();
    assert_eq!(
        configs.len(),
        8,
        "two pair modes by four thickness measures"
    );
    assert_eq!((change.allocations, change.reallocations), (0, 0));
}
