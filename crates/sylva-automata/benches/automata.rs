//! Compile + simulate throughput of the automata model, one core, reused buffers.
//!
//! Run with `cargo bench -p sylva-automata --bench automata`. Groups:
//! - `random_100`: 1000 random individuals of 80 to 120 nodes (default `GpConfig`, ramped
//!   half-and-half), compiled and grown at `Detail::Chords` for 100 iterations; throughput in
//!   individuals, then the same work in automaton-steps.
//! - `typical`: an individual shaped like the typical one: a trunk of 100 steps
//!   starting 33 branches that grow to the iteration limit (about 30 automata × 100
//!   iterations), at `Chords` (fitness) and `Full` (meshing) detail.
//! - `helix`: the helix of Figures 1-2 (1000 iterations, 15 automata), at `Full` detail.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sylva_automata::{
    AutomataGenome, Detail, GpConfig, GpTree, GrowOptions, Program, Semantics, Simulator,
};
use sylva_core::rng;
use sylva_core::{Plant, PlantMeta};

const HELIX: &str = include_str!("../../../examples/automata/helix.json");

/// A trunk that starts a branch every third step for 100 steps; branches bend and taper.
const TYPICAL: &str = "(Top (Repeat 10 (Repeat 10 (Seq (RotateH 1.4) (Seq (Add Var1 1) \
    (IfGreater Var1 2.5 (Seq (Assign Var1 0) (Seq (PushPop (Seq (RotateL 4) \
    (CreateAutomaton A2))) (Wait))) (Wait)))))) \
    (Repeat 10 (Repeat 10 (Seq (RotateL 0.1) (Seq (Multiply Thickness 0.99) (Wait))))))";

struct Work {
    program: Program,
    sim: Simulator,
    plant: Plant,
}

impl Work {
    fn new() -> Work {
        Work {
            program: Program::default(),
            sim: Simulator::new(),
            plant: Plant::new(PlantMeta::default()),
        }
    }

    /// Compiles and grows one tree; returns its automaton-steps.
    fn grow(&mut self, tree: &GpTree, semantics: &Semantics, o: &GrowOptions, d: Detail) -> u64 {
        self.program.recompile(tree, semantics);
        self.sim
            .run(&self.program, o, d, &mut self.plant)
            .automaton_steps
    }
}

fn random_individuals(c: &mut Criterion) {
    let config = GpConfig::default();
    let mut r = rng::seeded(7);
    let mut trees = Vec::new();
    let mut i = 0;
    while trees.len() < 1000 {
        let t = config.ramped(i, &mut r);
        i += 1;
        if (80..=120).contains(&t.len()) {
            trees.push(t);
        }
    }
    let (sem, o) = (Semantics::default(), GrowOptions::default());
    let mut work = Work::new();
    let steps: u64 = trees
        .iter()
        .map(|t| work.grow(t, &sem, &o, Detail::Chords))
        .sum();
    let nodes: usize = trees.iter().map(GpTree::len).sum();
    eprintln!(
        "random_100: {} trees, {:.1} nodes and {:.1} automaton-steps on average",
        trees.len(),
        nodes as f64 / trees.len() as f64,
        steps as f64 / trees.len() as f64
    );
    let mut group = c.benchmark_group("random_100");
    group.sample_size(20);
    for (name, throughput) in [
        ("individuals", Throughput::Elements(trees.len() as u64)),
        ("automaton_steps", Throughput::Elements(steps)),
    ] {
        group.throughput(throughput);
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut total = 0;
                for t in &trees {
                    total += work.grow(black_box(t), &sem, &o, Detail::Chords);
                }
                total
            })
        });
    }
    group.finish();
}

fn typical(c: &mut Criterion) {
    let tree = GpTree::parse(TYPICAL).unwrap();
    let (sem, o) = (Semantics::default(), GrowOptions::default());
    let mut work = Work::new();
    let steps = work.grow(&tree, &sem, &o, Detail::Chords);
    let report = work
        .sim
        .run(&work.program, &o, Detail::Chords, &mut work.plant);
    eprintln!(
        "typical: {} automata, {steps} automaton-steps, {} states, {} chord segments",
        report.automata, report.states, report.segments
    );
    let mut group = c.benchmark_group("typical");
    for detail in [Detail::Chords, Detail::Full] {
        group.throughput(Throughput::Elements(1));
        group.bench_function(format!("{detail:?}_individuals"), |b| {
            b.iter(|| work.grow(black_box(&tree), &sem, &o, detail))
        });
        group.throughput(Throughput::Elements(steps));
        group.bench_function(format!("{detail:?}_automaton_steps"), |b| {
            b.iter(|| work.grow(black_box(&tree), &sem, &o, detail))
        });
    }
    group.finish();
}

fn helix(c: &mut Criterion) {
    let genome = AutomataGenome::from_json(HELIX).unwrap();
    let (sem, o) = (genome.growth.semantics(), genome.growth.grow_options());
    let mut work = Work::new();
    let steps = work.grow(&genome.program, &sem, &o, Detail::Full);
    let mut group = c.benchmark_group("helix");
    group.throughput(Throughput::Elements(steps));
    group.bench_function("full_automaton_steps", |b| {
        b.iter(|| work.grow(black_box(&genome.program), &sem, &o, Detail::Full))
    });
    group.finish();
}

criterion_group!(benches, random_individuals, typical, helix);
criterion_main!(benches);
