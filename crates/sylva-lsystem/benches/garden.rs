//! A garden of nine L-system plants grown together for 100 steps in a 64 × 64 × 64 voxel
//! world (the target: under one second on the 2-core machine).
//!
//! Run with `cargo bench -p sylva-lsystem --bench garden`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sylva_core::environment::EnvironmentSettings;
use sylva_core::par::Pool;
use sylva_lsystem::LSystemGenome;
use sylva_lsystem::breed::grid_position;
use sylva_lsystem::garden::{Garden, Sowing};

const TREE: &str = include_str!("../../../examples/lsystem/tree.json");
const HERB: &str = include_str!("../../../examples/lsystem/herb.json");
const BUSH: &str = include_str!("../../../examples/lsystem/bush.json");

/// Nine plants on the breeding grid, 2.5 m apart, of the given genomes in turn.
fn sowings(genomes: &[LSystemGenome]) -> Vec<Sowing> {
    (0..9)
        .map(|i| Sowing::new(genomes[i % genomes.len()].clone(), grid_position(i, 2.5)))
        .collect()
}

fn grow(sowings: &[Sowing], pool: &Pool) -> Garden {
    let mut garden = Garden::new(EnvironmentSettings::default(), sowings.to_vec()).unwrap();
    garden.run(100, pool).unwrap();
    garden
}

fn garden(c: &mut Criterion) {
    let tree = LSystemGenome::from_json(TREE).unwrap();
    let herb = LSystemGenome::from_json(HERB).unwrap();
    let bush = LSystemGenome::from_json(BUSH).unwrap();
    let cases = [
        ("nine trees", sowings(std::slice::from_ref(&tree))),
        ("tree, herb and bush", sowings(&[tree, herb, bush])),
    ];
    let mut group = c.benchmark_group("lsystem garden, 100 steps, 64^3 voxels");
    group.sample_size(10);
    let pool = Pool::with_threads(0).unwrap();
    for (name, sowings) in &cases {
        let g = grow(sowings, &pool);
        let modules: u32 = g.plants().iter().map(|p| p.modules()).sum();
        eprintln!("{name}: {modules} modules after 100 steps");
        group.bench_function(*name, |b| b.iter(|| black_box(grow(sowings, &pool))));
    }
    group.finish();
}

criterion_group!(benches, garden);
criterion_main!(benches);
