//! The simulator against its reference: for random programs under random semantics, options
//! and bounds, at both levels of detail, [`Simulator`] and the baseline it replaced
//! ([`ReferenceSimulator`], one dispatch per state) grow the same plant and report, bit for
//! bit. Evolution is chaotic, so any other rounding anywhere would change run results.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use proptest::prelude::*;
mod reference;

use reference::ReferenceSimulator;
use sylva_automata::{
    AtEnd, AutomataGenome, ChildVariables, Detail, ElseEnd, GpConfig, GpTree, GrowOptions,
    GrowthReport, Limits, Program, Semantics, Simulator, Stop, SubtreeCrossover, SubtreeMutation,
};
use sylva_core::{Plant, PlantMeta};
use sylva_evolve::{Crossover, Mutate, rng};

const HELIX: &str = include_str!("../../../examples/automata/helix.json");
const EVOLVED: &str = include_str!("data/evolved.txt");

/// Every number of a plant as bits, every index and flag as a number.
fn bits(plant: &Plant) -> Vec<u32> {
    let mut v = Vec::new();
    let vec3 = |v: &mut Vec<u32>, p: sylva_core::glam::Vec3| {
        v.extend(p.to_array().map(f32::to_bits));
    };
    for s in plant.segments() {
        vec3(&mut v, s.start);
        vec3(&mut v, s.end);
        v.extend([s.start_radius.to_bits(), s.end_radius.to_bits()]);
        v.extend([
            u32::from(s.order),
            s.parent.map_or(u32::MAX, |p| p.0),
            u32::from(s.lateral),
            u32::from(s.material.0),
        ]);
    }
    v.push(u32::MAX);
    for o in plant.organs() {
        v.push(o.kind as u32);
        vec3(&mut v, o.position);
        v.extend(o.orientation.to_array().map(f32::to_bits));
        v.extend(o.size.to_array().map(f32::to_bits));
        v.extend([u32::from(o.material.0), o.parent.map_or(u32::MAX, |p| p.0)]);
    }
    v
}

/// Grows `program` with both simulators (the new one reused across calls, as evolution
/// does) and requires the same report, plant and JSON bytes.
fn same(
    sim: &mut Simulator,
    program: &Program,
    o: &GrowOptions,
    detail: Detail,
    what: &str,
) -> GrowthReport {
    let mut want = Plant::new(PlantMeta::default());
    let expected = ReferenceSimulator::new().run(program, o, detail, &mut want);
    let mut got = Plant::new(PlantMeta::default());
    let report = sim.run(program, o, detail, &mut got);
    assert_eq!(report, expected, "{what}: report, {detail:?}");
    assert!(bits(&got) == bits(&want), "{what}: plant, {detail:?}");
    assert_eq!(
        serde_json::to_vec(&got).unwrap(),
        serde_json::to_vec(&want).unwrap(),
        "{what}: JSON, {detail:?}"
    );
    report
}

fn semantics(seed: u64) -> Semantics {
    Semantics {
        degrees_per_unit: [10.0, 3.0, 30.0, 45.0][(seed % 4) as usize],
        else_end: if seed & 8 == 0 {
            ElseEnd::Rejoin
        } else {
            ElseEnd::End
        },
        at_end: if seed & 16 == 0 {
            AtEnd::Die
        } else {
            AtEnd::Restart
        },
        equal_tolerance: [0.5, 0.0, 2.0][((seed >> 5) % 3) as usize],
    }
}

/// Options with every switch drawn from the seed; bounds are loose most of the time (as in
/// evolution) and tight otherwise, so that each bound is hit mid-block and mid-iteration.
fn options(seed: u64) -> GrowOptions {
    let tight = seed & 128 != 0;
    let limits = if tight {
        Limits {
            states_per_step: 1 + (seed >> 8) as u32 % 60,
            states: 1 + (seed >> 14) % 30_000,
            automata: 1 + (seed >> 20) as u32 % 100,
            points: 1 + (seed >> 27) as u32 % 3000,
            organs: (seed >> 40) as u32 % 100,
        }
    } else {
        Limits::default()
    };
    GrowOptions {
        iterations: [100, 1 + (seed >> 45) as u32 % 200][((seed >> 44) & 1) as usize],
        root_length: [1.0, 2.5, 0.0, 400.0][((seed >> 50) % 4) as usize],
        gravity: if seed & 32 == 0 { 0.0 } else { 3.0 },
        horizontal_leaves: seed & 64 == 0,
        child_variables: [
            ChildVariables::LengthThickness,
            ChildVariables::All,
            ChildVariables::Fresh,
        ][((seed >> 53) % 3) as usize],
        limits,
        ..GrowOptions::default()
    }
}

/// A random program: ramped half-and-half from a random configuration, then a few rounds of
/// crossover and mutation with other trees, which nest loops and Ifs the way evolved trees do.
fn tree(seed: u64) -> GpTree {
    let config = GpConfig {
        automata: (seed % 4) as u8 + 1,
        min_init_depth: ((seed >> 3) % 5) as u32,
        max_init_depth: ((seed >> 3) % 5) as u32 + ((seed >> 6) % 5) as u32,
        max_size: 30 + ((seed >> 9) % 500) as u32,
        ..GpConfig::default()
    };
    let mut r = rng::seeded(seed);
    let mut t = config.ramped((seed >> 20) as usize % 64, &mut r);
    for _ in 0..(seed >> 30) % 6 {
        let other = config.random_tree(&mut r);
        t = SubtreeCrossover { config }.crossover(&t, &other, &mut r);
        SubtreeMutation { config }.mutate(&mut t, &mut r);
    }
    t
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn random_programs_grow_as_the_reference_grows_them(seed in any::<u64>()) {
        let program = Program::compile(&tree(seed), &semantics(seed));
        let o = options(seed.rotate_left(17));
        let mut sim = Simulator::new();
        same(&mut sim, &program, &o, Detail::Chords, "random");
        same(&mut sim, &program, &o, Detail::Full, "random");
    }
}

#[test]
fn the_initial_population_grows_as_the_reference_grows_it() {
    // Evolution's own path: one simulator reused over a ramped population at the defaults.
    let config = GpConfig::default();
    let mut r = rng::seeded(5);
    let mut sim = Simulator::new();
    for i in 0..2000 {
        let t = config.ramped(i, &mut r);
        let program = Program::compile(&t, &Semantics::default());
        let o = GrowOptions {
            root_length: 2.5,
            ..GrowOptions::default()
        };
        same(&mut sim, &program, &o, Detail::Chords, &t.to_string());
        if i % 10 == 0 {
            same(&mut sim, &program, &o, Detail::Full, &t.to_string());
        }
    }
}

#[test]
fn evolved_individuals_grow_as_the_reference_grows_them() {
    // Individuals of the last generation of the typical run (`sylva evolve
    // examples/automata/sphere.toml --population 5000 --generations 100`): deep nests of
    // loops, tests and waits, as evolution leaves them.
    let o = GrowOptions {
        root_length: 2.5,
        ..GrowOptions::default()
    };
    let mut sim = Simulator::new();
    let mut n = 0;
    for line in EVOLVED.lines().filter(|l| l.starts_with('(')) {
        let t = GpTree::parse(line).unwrap();
        for seed in 0..4u64 {
            let program = Program::compile(&t, &semantics(seed * 8));
            same(&mut sim, &program, &o, Detail::Chords, line);
            same(
                &mut sim,
                &program,
                &options(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15)),
                Detail::Full,
                line,
            );
        }
        n += 1;
    }
    assert!(n >= 20, "{n} evolved individuals");
}

#[test]
fn hand_written_corners_grow_as_the_reference_grows_them() {
    let helix = AutomataGenome::from_json(HELIX).unwrap();
    let long_run = format!(
        "(Top (Repeat 10 (Seq {} (Wait))))",
        "(Seq (RotateH 1) (Seq (Add Var1 1) (Seq (RotateL 2) ".repeat(12)
            + "(Wait)"
            + &")))".repeat(12)
    );
    let texts = [
        helix.program.to_string(),
        long_run,
        // Loops without a Wait: killed at the state limit, mid-block.
        "(Top (Repeat 10 (Repeat 10 (Seq (RotateH 1) (Seq (Multiply Var1 10) (Seq (Add Var1 9) (RotateL 1)))))))"
            .to_owned(),
        // Restart at the end, with and without a Wait.
        "(Top (Seq (RotateU 2) (Seq (Multiply Length 1.1) (Wait))))".to_owned(),
        "(Top (Seq (RotateU 2) (Multiply Length -1.5)))".to_owned(),
        // Push/Pop forks, creations and organs inside blocks.
        "(Top (Repeat 10 (Repeat 10 (Seq (RotateH 1.4) (Seq (Add Var1 1) (IfGreater Var1 2.5 \
         (Seq (Assign Var1 0) (Seq (PushPop (Seq (RotateL 4) (Seq (Wait) (CreateAutomaton A2)))) \
         (Seq (CreateAutomaton A3) (Wait)))) (Wait)))))) \
         (RepeatIndex 9 (Repeat 10 (Seq (RotateL 0.1) (Seq (Multiply Thickness -0.99) \
         (Seq (CreateAutomaton A3) (Wait)))))) \
         (Repeat 4 (Seq (CreateAutomaton Leaf) (Seq (RotateU 3) (Seq (CreateAutomaton Flower) \
         (Wait))))))"
            .to_owned(),
        // Tests on every variable, empty loops, and a loop test whose body is a loop.
        "(Top (Repeat 3 (Seq (IfEqual Var3 0 (Repeat 0 (Wait)) (Killme)) (Seq (IfLess Length 2 \
         (Seq (Add Length 0.25) (Wait)) (Repeat 2 (Repeat 2 (RepeatIndex 3 (Wait))))) \
         (CreateAutomaton Leaf)))))"
            .to_owned(),
    ];
    let mut sim = Simulator::new();
    for text in &texts {
        let t = GpTree::parse(text).unwrap();
        for seed in 0..64u64 {
            let program = Program::compile(&t, &semantics(seed));
            let o = options(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | (seed & 1) << 7);
            same(&mut sim, &program, &o, Detail::Chords, text);
            same(&mut sim, &program, &o, Detail::Full, text);
        }
        let o = helix.growth.grow_options();
        let program = Program::compile(&t, &helix.growth.semantics());
        same(&mut sim, &program, &o, Detail::Full, text);
    }
}

#[test]
fn growth_stopped_by_a_bound_while_automata_run_ahead_is_grown_again_exactly() {
    // Branches in loops of simple steps run their later steps early; a bound reached before
    // those steps' turn must give the reference's plant all the same.
    let typical = GpTree::parse(
        "(Top (Repeat 10 (Repeat 10 (Seq (RotateH 1.4) (Seq (Add Var1 1) (IfGreater Var1 2.5 \
         (Seq (Assign Var1 0) (Seq (PushPop (Seq (RotateL 4) (CreateAutomaton A2))) (Wait))) \
         (Wait)))))) (Repeat 10 (Repeat 10 (Seq (RotateL 0.1) (Seq (Multiply Thickness 0.99) \
         (Wait))))))",
    )
    .unwrap();
    let mut sim = Simulator::new();
    // One automaton that runs ahead to the end of growth at its first step: no step of
    // another comes after the bound is passed.
    let alone = GpTree::parse("(Top (Repeat 10 (Repeat 10 (Seq (RotateL 0.1) (Wait)))))").unwrap();
    let program = Program::compile(&alone, &Semantics::default());
    for k in 1..40 {
        for limits in [
            Limits {
                points: 3 * k,
                ..Limits::default()
            },
            Limits {
                states: 9 * u64::from(k),
                ..Limits::default()
            },
        ] {
            let o = GrowOptions {
                limits,
                ..GrowOptions::default()
            };
            same(&mut sim, &program, &o, Detail::Chords, "alone, bounded");
        }
    }
    // The second child runs ahead to the end of growth at its first step (its outer loop's
    // block is built by then), and the first from its first outer round: no step runs in
    // its turn after the bound is passed.
    let late = GpTree::parse(
        "(Top (Seq (CreateAutomaton A2) (Seq (Repeat 10 (Repeat 2 (Wait))) (CreateAutomaton A2))) \
         (Repeat 10 (Repeat 10 (Seq (RotateL 0.1) (Wait)))))",
    )
    .unwrap();
    let program = Program::compile(&late, &Semantics::default());
    for k in 1..60 {
        for limits in [
            Limits {
                points: 5 * k,
                ..Limits::default()
            },
            Limits {
                states: 15 * u64::from(k),
                ..Limits::default()
            },
        ] {
            let o = GrowOptions {
                limits,
                ..GrowOptions::default()
            };
            same(&mut sim, &program, &o, Detail::Chords, "late, bounded");
        }
    }
    let program = Program::compile(&typical, &Semantics::default());
    for k in 1..60u32 {
        let limits = Limits {
            points: 37 * k,
            states: 200 * u64::from(k),
            automata: 1 + k,
            ..Limits::default()
        };
        for limits in [
            Limits {
                points: limits.points,
                ..Limits::default()
            },
            Limits {
                states: limits.states,
                ..Limits::default()
            },
            Limits {
                automata: limits.automata,
                ..Limits::default()
            },
        ] {
            let o = GrowOptions {
                limits,
                ..GrowOptions::default()
            };
            same(&mut sim, &program, &o, Detail::Chords, "typical, bounded");
        }
    }
    // Positions beyond the plant's range stop growth at the end of an iteration: a trunk of
    // Length 10^6 units of 1 km passes 10^12 m after a thousand steps (and it may create
    // up to the default 2000 automata before).
    let trunk = "(Repeat 10 (Repeat 10 (Repeat 10 (Repeat 10 (Seq (RotateH 1.4) (Seq \
        (Add Var1 1) (IfGreater Var1 2.5 (Seq (Assign Var1 0) (Seq (PushPop (Seq (RotateL 4) \
        (CreateAutomaton A2))) (Wait))) (Wait))))))))";
    let branch =
        "(Repeat 10 (Repeat 10 (Seq (RotateL 0.1) (Seq (Multiply Thickness 0.99) (Wait)))))";
    let far = GpTree::parse(&format!(
        "(Top (Seq (Repeat 10 (Multiply Length 10)) {trunk}) {branch})"
    ))
    .unwrap();
    let program = Program::compile(&far, &Semantics::default());
    let mut stops = Vec::new();
    for iterations in [990, 1000, 1010, 1100, 1500] {
        let o = GrowOptions {
            unit: 1e3,
            iterations,
            ..GrowOptions::default()
        };
        stops.push(same(&mut sim, &program, &o, Detail::Chords, "far").stop);
    }
    assert!(stops.contains(&Stop::Extent), "{stops:?}");
}
