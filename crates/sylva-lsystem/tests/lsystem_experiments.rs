#![allow(clippy::unwrap_used)]
//! The paper's simulations show their effects in measured numbers.

use std::path::PathBuf;

use sylva_core::par::Pool;
use sylva_lsystem::LSystemGenome;
use sylva_lsystem::experiments::{CrownShape, Simulation, SimulationOutcome};

fn config(name: &str) -> (Simulation, PathBuf) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/lsystem");
    let text = std::fs::read_to_string(dir.join(name)).unwrap();
    (toml::from_str(&text).unwrap(), dir)
}

/// Runs an experiment with the genome files it names (read here: the model reads none).
fn run(sim: &Simulation, dir: &std::path::Path) -> SimulationOutcome {
    let genomes: Vec<LSystemGenome> = sim
        .genome_files()
        .iter()
        .map(|f| LSystemGenome::from_json(&std::fs::read_to_string(dir.join(f)).unwrap()).unwrap())
        .collect();
    sim.run(&genomes, &Pool::with_threads(0).unwrap()).unwrap()
}

#[test]
fn herbs_under_the_tree_grow_less() {
    let (sim, dir) = config("herbs-under-tree.toml");
    let outcome = run(&sim, &dir);
    let SimulationOutcome::HerbsUnderTree(o) = &outcome else {
        panic!("{outcome:?}")
    };
    let report = format!("{o:?}");
    assert!(o.crown.radius > 1.5, "{report}");
    assert!(o.light_ratio < 0.5, "{report}");
    assert!(o.biomass_ratio < 0.75, "{report}");
    // 1 tree + 12 herbs, a record each per step.
    let Simulation::HerbsUnderTree(c) = &sim else {
        unreachable!()
    };
    assert_eq!(outcome.plants().len(), 13);
    let steps = (c.head_start + c.steps) as usize;
    assert_eq!(outcome.records().len(), 13 * steps);
}

#[test]
fn lateral_light_makes_one_sided_crowns() {
    let (mut sim, dir) = config("lateral-light.toml");
    if let Simulation::LateralLight(c) = &mut sim {
        c.steps = 120; // shorter than the example, same effect
    }
    let outcome = run(&sim, &dir);
    let SimulationOutcome::LateralLight(o) = &outcome else {
        panic!("{outcome:?}")
    };
    let report = format!("{o:?}");
    for s in &o.lateral {
        assert!(s.asymmetry > 0.08, "{report}");
    }
    for s in &o.vertical {
        assert!(s.asymmetry.abs() < 0.05, "{report}");
    }
    assert!(
        o.lateral_asymmetry() > 3.0 * o.vertical_asymmetry().abs(),
        "{report}"
    );
    for s in o.lateral.iter().chain(&o.vertical) {
        assert!(
            s.tips > 0 && s.tips < s.branches && s.volume > 0.0,
            "{report}"
        );
    }
}

/// Grown until both pairs stop at the 4000-module bound, the lateral-light crowns carry as
/// many shoot tips as the vertical-light ones in a smaller hull: they are bushier.
#[test]
fn lateral_light_makes_bushier_crowns_of_equal_size() {
    let (mut sim, dir) = config("lateral-light.toml");
    if let Simulation::LateralLight(c) = &mut sim {
        c.steps = 210;
    }
    let outcome = run(&sim, &dir);
    let SimulationOutcome::LateralLight(o) = &outcome else {
        panic!("{outcome:?}")
    };
    let report = format!("{o:?}");
    let at_bound = o
        .records
        .iter()
        .filter(|r| r.step == 210 && r.modules == 4000);
    assert_eq!(at_bound.count(), 2, "{report}");
    let tips = |s: &[CrownShape; 2]| 0.5 * (s[0].tips + s[1].tips) as f32;
    let volume = |s: &[CrownShape; 2]| 0.5 * (s[0].volume + s[1].volume);
    assert!(
        (tips(&o.lateral) / tips(&o.vertical) - 1.0).abs() < 0.05,
        "{report}"
    );
    assert!(volume(&o.lateral) < 0.9 * volume(&o.vertical), "{report}");
    assert!(
        o.lateral_bushiness() > 1.1 * o.vertical_bushiness(),
        "{report}"
    );
}

#[test]
fn evolution_from_empty_rules_reaches_leaves_and_roots() {
    let (sim, dir) = config("from-empty-rules.toml");
    let outcome = run(&sim, &dir);
    let SimulationOutcome::EmptyRules(o) = &outcome else {
        panic!("{outcome:?}")
    };
    let report = format!("{o:?}");
    let at = o.leaves_and_roots_at.unwrap_or_else(|| panic!("{report}"));
    assert!(at > 1, "the empty mother does not germinate: {report}");
    let first = &o.run.generations[0];
    assert!(!first.stats.germinated() || first.chosen != 0, "{report}");
    let last = o.run.generations.last().unwrap();
    assert!(
        last.stats.biomass > 5.0 * o.run.generations[0].stats.biomass,
        "{report}"
    );
}
