//! Poncin's typical run, the whole pipeline (breed, compile, simulate, score): the sphere
//! problem of `examples/automata/sphere.toml` with 5000 individuals for 100 generations of
//! 100 iterations, on all cores. Throughput is in individuals bred and scored (5000 × 101
//! generations, the first included; copies keep their score, so evaluations are a little
//! fewer); the evaluations and automaton-steps of one run are printed beside it.
//!
//! Run with `cargo bench -p sylva-automata --bench evolve`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::path::Path;
use std::time::Instant;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sylva_automata::problem::{AutomataProblem, AutomataSettings, strategy};
use sylva_evolve::{Pool, Run, RunSettings};

const POPULATION: usize = 5000;
const GENERATIONS: u32 = 100;

/// Runs the typical run; returns its evaluations and automaton-steps.
fn run(settings: &AutomataSettings, evaluator: &Pool) -> (u64, u64) {
    let problem = AutomataProblem::new(settings);
    let strategy = strategy(&problem, settings).unwrap();
    let settings = RunSettings {
        seed: 1,
        population: POPULATION,
        keep_history: 0,
    };
    let mut run = Run::new(problem.clone(), strategy, evaluator.clone(), settings).unwrap();
    run.run_batch(GENERATIONS, |_| {});
    let evaluations = run.stats().iter().map(|s| s.evaluations).sum();
    (evaluations, problem.automaton_steps())
}

fn typical_run(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/automata/sphere.toml");
    // The example's `[automata]` section: the model's settings.
    let text = std::fs::read_to_string(&path).unwrap();
    let table: toml::Table = toml::from_str(&text).unwrap();
    let config: AutomataSettings = table["automata"].clone().try_into().unwrap();
    let evaluator = Pool::with_threads(0).unwrap();
    let start = Instant::now();
    let (evaluations, steps) = run(&config, &evaluator);
    let seconds = start.elapsed().as_secs_f64();
    let individuals = POPULATION as u64 * u64::from(GENERATIONS + 1);
    eprintln!(
        "sphere 5000x100: {individuals} individuals, {evaluations} evaluations, {steps} \
         automaton-steps ({:.0} per evaluation) in {seconds:.2} s: {:.0} individuals/s, \
         {:.1} M automaton-steps/s",
        steps as f64 / evaluations as f64,
        individuals as f64 / seconds,
        steps as f64 / seconds / 1e6
    );
    let mut group = c.benchmark_group("automata_sphere_5000x100");
    group.sample_size(10);
    group.throughput(Throughput::Elements(individuals));
    group.bench_function("all_cores", |b| b.iter(|| run(&config, &evaluator)));
    group.finish();
}

criterion_group!(benches, typical_run);
criterion_main!(benches);
