//! Compiling and growing with a warmed-up `Program`, `Simulator` and `Plant` allocates
//! nothing: evolution runs this tens of thousands of times a second. (This binary runs without
//! libtest's harness, on its main thread alone, so the global counts are its own.)
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::alloc::System;

use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};
use sylva_automata::{
    AutomataGenome, Detail, GpConfig, GpTree, GrowOptions, Program, Semantics, Simulator,
};
use sylva_core::rng;
use sylva_core::{Plant, PlantMeta};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

const HELIX: &str = include_str!("../../../examples/automata/helix.json");

fn main() {
    steady_state_growth_does_not_allocate();
    println!("automata_alloc: steady_state_growth_does_not_allocate ... ok");
}

fn steady_state_growth_does_not_allocate() {
    let helix = AutomataGenome::from_json(HELIX).unwrap();
    let config = GpConfig::default();
    let mut r = rng::seeded(3);
    let mut trees: Vec<GpTree> = (0..200).map(|i| config.ramped(i, &mut r)).collect();
    trees.push(helix.program.clone());
    let (sem, options) = (Semantics::default(), GrowOptions::default());
    let mut program = Program::default();
    let mut sim = Simulator::new();
    let mut plant = Plant::new(PlantMeta::default());
    let mut grow = |detail| {
        let mut steps = 0;
        for t in &trees {
            program.recompile(t, &sem);
            steps += sim
                .run(&program, &options, detail, &mut plant)
                .automaton_steps;
        }
        steps
    };
    // Warm up: buffers grow to the largest individual.
    let warm = grow(Detail::Full) + grow(Detail::Chords);
    let region = Region::new(GLOBAL);
    let again = grow(Detail::Full) + grow(Detail::Chords);
    let stats = region.change();
    assert_eq!(again, warm);
    assert_eq!(
        (stats.allocations, stats.reallocations),
        (0, 0),
        "{stats:?}"
    );
}
