//! Compile + simulate throughput of the automata model, one core, reused buffers.
//!
//! Run with `cargo bench -p sylva-automata --bench automata`. Every group measures the
//! simulator beside its baseline, the simulator as it was before straight-line blocks
//! ([`ReferenceSimulator`], kept as the test oracle), in the same run: `…_baseline` is the
//! baseline, the other the simulator. Throughput is in automaton-steps (one automaton running
//! one iteration), so criterion's time per element is the time per automaton-step. Groups:
//! - `random_100`: 1000 random individuals of 80 to 120 nodes (default `GpConfig`, ramped
//!   half-and-half), compiled and grown at `Detail::Chords` for 100 iterations.
//! - `typical`: an individual shaped like the typical one: a trunk of 100 steps
//!   starting 33 branches that grow to the iteration limit (about 30 automata × 100
//!   iterations), at `Chords` (fitness) and `Full` (meshing) detail.
//! - `evolved`: the 40 individuals of `tests/data/evolved.txt`, from the last generation of
//!   the typical run, at `Chords`.
//! - `helix`: the helix of Figures 1-2 (1000 iterations, 15 automata), at `Full` detail.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
#[path = "../tests/reference/mod.rs"]
mod reference;

use reference::ReferenceSimulator;
use sylva_automata::{
    AutomataGenome, Detail, GpConfig, GpTree, GrowOptions, Program, Semantics, Simulator,
};
use sylva_core::rng;
use sylva_core::{Plant, PlantMeta};

const HELIX: &str = include_str!("../../../examples/automata/helix.json");
const EVOLVED: &str = include_str!("../tests/data/evolved.txt");

/// A trunk that starts a branch every third step for 100 steps; branches bend and taper.
const TYPICAL: &str = "(Top (Repeat 10 (Repeat 10 (Seq (RotateH 1.4) (Seq (Add Var1 1) \
    (IfGreater Var1 2.5 (Seq (Assign Var1 0) (Seq (PushPop (Seq (RotateL 4) \
    (CreateAutomaton A2))) (Wait))) (Wait)))))) \
    (Repeat 10 (Repeat 10 (Seq (RotateL 0.1) (Seq (Multiply Thickness 0.99) (Wait))))))";

struct Work {
    program: Program,
    sim: Simulator,
    reference: ReferenceSimulator,
    plant: Plant,
}

impl Work {
    fn new() -> Work {
        Work {
            program: Program::default(),
            sim: Simulator::new(),
            reference: ReferenceSimulator::new(),
            plant: Plant::new(PlantMeta::default()),
        }
    }

    /// Compiles and grows one tree, with the baseline or the simulator; returns its
    /// automaton-steps.
    fn grow(
        &mut self,
        baseline: bool,
        tree: &GpTree,
        semantics: &Semantics,
        o: &GrowOptions,
        d: Detail,
    ) -> u64 {
        self.program.recompile(tree, semantics);
        let report = if baseline {
            self.reference.run(&self.program, o, d, &mut self.plant)
        } else {
            self.sim.run(&self.program, o, d, &mut self.plant)
        };
        report.automaton_steps
    }
}

/// Benchmarks growing `trees` with the baseline and the simulator, side by side.
fn side_by_side(
    c: &mut Criterion,
    group: &str,
    name: &str,
    trees: &[GpTree],
    (sem, o): (&Semantics, &GrowOptions),
    detail: Detail,
) {
    let mut work = Work::new();
    let steps: u64 = trees
        .iter()
        .map(|t| work.grow(false, t, sem, o, detail))
        .sum();
    let mut group = c.benchmark_group(group);
    group.throughput(Throughput::Elements(steps));
    for baseline in [true, false] {
        let id = if baseline {
            format!("{name}_baseline")
        } else {
            name.to_owned()
        };
        group.bench_function(id, |b| {
            b.iter(|| {
                let mut total = 0;
                for t in trees {
                    total += work.grow(baseline, black_box(t), sem, o, detail);
                }
                total
            })
        });
    }
    group.finish();
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
        .map(|t| work.grow(false, t, &sem, &o, Detail::Chords))
        .sum();
    let nodes: usize = trees.iter().map(GpTree::len).sum();
    eprintln!(
        "random_100: {} trees, {:.1} nodes and {:.1} automaton-steps on average",
        trees.len(),
        nodes as f64 / trees.len() as f64,
        steps as f64 / trees.len() as f64
    );
    side_by_side(
        c,
        "random_100",
        "chords",
        &trees,
        (&sem, &o),
        Detail::Chords,
    );
}

fn typical(c: &mut Criterion) {
    let tree = GpTree::parse(TYPICAL).unwrap();
    let (sem, o) = (Semantics::default(), GrowOptions::default());
    let mut work = Work::new();
    work.program.recompile(&tree, &sem);
    let report = work
        .sim
        .run(&work.program, &o, Detail::Chords, &mut work.plant);
    eprintln!(
        "typical: {} automata, {} automaton-steps, {} states, {} chord segments",
        report.automata, report.automaton_steps, report.states, report.segments
    );
    let trees = [tree];
    side_by_side(c, "typical", "chords", &trees, (&sem, &o), Detail::Chords);
    side_by_side(c, "typical", "full", &trees, (&sem, &o), Detail::Full);
}

fn evolved(c: &mut Criterion) {
    let trees: Vec<GpTree> = EVOLVED
        .lines()
        .filter(|l| l.starts_with('('))
        .map(|l| GpTree::parse(l).unwrap())
        .collect();
    // The typical run's growth (examples/automata/sphere.toml).
    let o = GrowOptions {
        root_length: 2.5,
        ..GrowOptions::default()
    };
    let sem = Semantics::default();
    side_by_side(c, "evolved", "chords", &trees, (&sem, &o), Detail::Chords);
}

fn helix(c: &mut Criterion) {
    let genome = AutomataGenome::from_json(HELIX).unwrap();
    let (sem, o) = (genome.growth.semantics(), genome.growth.grow_options());
    let trees = [genome.program];
    side_by_side(c, "helix", "full", &trees, (&sem, &o), Detail::Full);
}

criterion_group!(benches, random_individuals, typical, evolved, helix);
criterion_main!(benches);
