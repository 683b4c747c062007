//! Susinno's GA on binary trees: population 1000 for 100 generations with the default config,
//! on one thread and on all cores. Throughput is in evaluations.
//!
//! Run with `cargo bench -p sylva-bintree --bench ga`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sylva_bintree::problem::strategy;
use sylva_bintree::{BinTreeProblem, BinTreeSettings};
use sylva_evolve::{Pool, Run, RunSettings};

const POPULATION: usize = 1000;
const GENERATIONS: u32 = 100;

/// Runs the GA and returns how many evaluations it made.
fn run(evaluator: &Pool) -> u64 {
    let config = BinTreeSettings::default();
    let settings = RunSettings {
        seed: 1,
        population: POPULATION,
        keep_history: 0,
    };
    let mut run = Run::new(
        BinTreeProblem::from_settings(&config),
        strategy(&config),
        evaluator.clone(),
        settings,
    )
    .unwrap();
    run.run_batch(GENERATIONS, |_| {});
    run.stats().iter().map(|s| s.evaluations).sum()
}

fn ga(c: &mut Criterion) {
    let mut group = c.benchmark_group("bintree_ga_1000x100");
    group.sample_size(10);
    for (name, threads) in [("1_thread", 1), ("all_cores", 0)] {
        let evaluator = Pool::with_threads(threads).unwrap();
        let evaluations = run(&evaluator);
        eprintln!("{name}: {evaluations} evaluations per run");
        group.throughput(Throughput::Elements(evaluations));
        group.bench_function(name, |b| b.iter(|| run(&evaluator)));
    }
    group.finish();
}

criterion_group!(benches, ga);
criterion_main!(benches);
