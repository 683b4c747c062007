#![allow(clippy::unwrap_used)]
//! L-system plants in the voxel world: genomes, gardens, conservation, bounds, determinism.

use std::path::PathBuf;

use proptest::prelude::*;
use sylva_core::environment::EnvironmentSettings;
use sylva_core::glam::Vec2;
use sylva_core::par::Pool;
use sylva_evolve::{Mutate, Problem};
use sylva_lsystem::LSystemProblem;
use sylva_lsystem::breed::{BreedSettings, breed_garden, grid_position, largest_biomass};
use sylva_lsystem::experiments::Simulation;
use sylva_lsystem::garden::{Garden, GrowSettings, Sowing};
use sylva_lsystem::genome::{LSystem, LSystemGenome, LSystemMutation, mutate_parameter};
use sylva_lsystem::grammar::Compartment;
use sylva_lsystem::growth::Life;
use sylva_lsystem::mutate::MutationRates;

fn examples() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/lsystem")
}

fn example(name: &str) -> LSystemGenome {
    let text = std::fs::read_to_string(examples().join(name)).unwrap();
    LSystemGenome::from_json(&text).unwrap()
}

/// A 2 m garden: quick to grow.
fn small_world() -> EnvironmentSettings {
    EnvironmentSettings {
        size: [16, 24, 16],
        soil_layers: 8,
        ..EnvironmentSettings::default()
    }
}

fn small() -> GrowSettings {
    GrowSettings {
        world: small_world(),
        steps: 40,
    }
}

#[test]
fn example_genomes_read_and_round_trip() {
    for name in ["bush.json", "tree.json", "herb.json"] {
        let g = example(name);
        let text = g.to_json();
        assert_eq!(LSystemGenome::from_json(&text).unwrap(), g, "{name}");
        assert!(!g.shoot.rules.rules.is_empty() && !g.root.rules.rules.is_empty());
    }
    let bush = example("bush.json");
    assert_eq!(bush.shoot, LSystemGenome::bush().shoot);
    assert_eq!(bush.root, LSystemGenome::bush().root);
    assert!(bush.description.contains("misprint"));
}

#[test]
fn example_configs_read() {
    for name in [
        "herbs-under-tree.toml",
        "lateral-light.toml",
        "from-empty-rules.toml",
    ] {
        let text = std::fs::read_to_string(examples().join(name)).unwrap();
        let sim: Simulation = toml::from_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        match (name, &sim) {
            ("herbs-under-tree.toml", Simulation::HerbsUnderTree(c)) => {
                assert_eq!(c.world.light.elevation, 90.0);
                assert!(c.inner_radius < c.outer_radius);
            }
            ("lateral-light.toml", Simulation::LateralLight(c)) => {
                assert!(c.world.light.elevation < 90.0);
            }
            ("from-empty-rules.toml", Simulation::EmptyRules(c)) => {
                assert_eq!(c.breed.rates, MutationRates::default());
                assert!(c.start.is_none());
            }
            _ => panic!("{name} read as {sim:?}"),
        }
    }
    let bad = "[herbs-under-tree]\ntree = \"t.json\"\nherb = \"h.json\"\nheadstart = 3\n";
    let e = toml::from_str::<Simulation>(bad).unwrap_err();
    assert!(e.to_string().contains("headstart"), "{e}");
}

#[test]
fn empty_rules_do_not_germinate() {
    let plant = LSystemGenome::empty().develop_with(&small(), 7).unwrap();
    assert!(plant.segments().is_empty());
    assert_eq!(plant.meta().model, "lsystem");
    assert_eq!(plant.meta().seed, 7);
    // An empty successor is a rule too, but grows nothing.
    let mut g = LSystemGenome::empty();
    g.shoot = LSystem::parse("[A]", &["A -> "], Compartment::Shoot).unwrap();
    assert!(g.develop_with(&small(), 0).unwrap().segments().is_empty());
}

#[test]
fn the_bush_grows_shoot_and_root() {
    let plant = example("bush.json").develop_with(&small(), 0).unwrap();
    let above = plant.segments().iter().filter(|s| s.end.y > 0.0).count();
    let below = plant.segments().iter().filter(|s| s.end.y < 0.0).count();
    assert!(above > 10 && below > 3, "{above} above, {below} below");
}

#[test]
fn carbon_and_minerals_are_conserved() {
    let mut tree = example("tree.json");
    tree.physiology.life_span = 45; // dies during the run: everything goes back
    let herb = example("herb.json");
    let sowings = vec![
        Sowing::new(tree, Vec2::ZERO),
        Sowing::new(herb.clone(), Vec2::new(0.4, 0.1)),
        Sowing {
            sown_at: 10,
            ..Sowing::new(herb, Vec2::new(-0.5, -0.3))
        },
    ];
    let mut garden = Garden::new(small_world(), sowings).unwrap();
    let start = garden.balance();
    assert!(start.error() < 1e-12);
    for step in 0..70 {
        garden.step(&Pool::Serial).unwrap();
        let b = garden.balance();
        assert!(b.error() < 1e-9, "step {step}: {b:?}");
    }
    let tree = &garden.plants()[0];
    assert_eq!(tree.life(), Life::Dead(45));
    assert_eq!(tree.holdings(), (0.0, 0.0));
    assert!(tree.totals().returned > 0.0 && tree.totals().fixed > 0.0);
    assert!(garden.env().total_litter() > 0.0);
    // The dead tree's records say it stopped growing.
    let last = garden
        .records()
        .iter()
        .rev()
        .find(|r| r.plant == 0)
        .unwrap();
    assert!(!last.growing);
}

#[test]
fn runaway_growth_is_bounded_and_reported() {
    let mut g = LSystemGenome::empty();
    g.shoot = LSystem::parse("[A]", &["A -> AA"], Compartment::Shoot).unwrap();
    g.root = LSystem::parse("[A]", &["A -> cA"], Compartment::Root).unwrap();
    g.physiology.max_symbols = 20;
    g.physiology.max_modules = 10;
    let mut garden = Garden::new(small_world(), vec![Sowing::new(g, Vec2::ZERO)]).unwrap();
    garden.run(60, &Pool::Serial).unwrap();
    let p = &garden.plants()[0];
    assert!(p.words()[0].len() <= 20);
    assert!(p.modules() <= 10);
    let bounded: Vec<_> = garden.bounded().collect();
    assert_eq!(bounded.len(), 1);
    let hit = bounded[0].1;
    assert!(hit.symbols > 0 && hit.modules > 0, "{hit:?}");
    assert!(hit.first_step.is_some());
    // Steps are bounded too.
    assert!(garden.run(200_000, &Pool::Serial).is_err());
}

fn garden_bytes(threads: usize, order: &[usize]) -> (String, Vec<f64>) {
    let genomes = [
        example("tree.json"),
        example("herb.json"),
        example("bush.json"),
    ];
    let spots = [Vec2::ZERO, Vec2::new(0.5, 0.2), Vec2::new(-0.4, -0.45)];
    let sowings = order
        .iter()
        .map(|&i| Sowing::new(genomes[i].clone(), spots[i]))
        .collect();
    let pool = Pool::with_threads(threads).unwrap();
    let mut garden = Garden::new(small_world(), sowings).unwrap();
    garden.run(40, &pool).unwrap();
    let biomass = garden.plants().iter().map(|p| p.biomass()).collect();
    (garden.csv(), biomass)
}

#[test]
fn gardens_are_deterministic_for_any_thread_count() {
    let (one, _) = garden_bytes(1, &[0, 1, 2]);
    let (two, _) = garden_bytes(2, &[0, 1, 2]);
    assert_eq!(one, two);
    assert!(one.starts_with("step,plant,biomass,light,uptake,modules,leaves,fine_roots,growing\n"));
    assert_eq!(one.lines().count(), 1 + 40 * 3);
}

#[test]
fn the_order_of_plants_does_not_bias_them() {
    let (_, forward) = garden_bytes(2, &[0, 1, 2]);
    let (_, backward) = garden_bytes(2, &[2, 1, 0]);
    for (i, &b) in forward.iter().enumerate() {
        let other = backward[2 - i];
        assert!(
            (b - other).abs() <= 1e-9 * b.abs().max(1.0),
            "plant {i}: {b} against {other}"
        );
    }
}

#[test]
fn neighbours_compete_for_light_and_minerals() {
    let herb = example("herb.json");
    let alone = {
        let mut g =
            Garden::new(small_world(), vec![Sowing::new(herb.clone(), Vec2::ZERO)]).unwrap();
        g.run(40, &Pool::Serial).unwrap();
        g.plants()[0].biomass()
    };
    let crowded = {
        let sowings = (0..4)
            .map(|i| Sowing::new(herb.clone(), Vec2::new(0.06 * i as f32, 0.05)))
            .collect();
        let mut g = Garden::new(small_world(), sowings).unwrap();
        g.run(40, &Pool::Serial).unwrap();
        g.plants().iter().map(|p| p.biomass()).sum::<f64>() / 4.0
    };
    assert!(
        crowded < 0.9 * alone,
        "crowded {crowded} against alone {alone}"
    );
}

#[test]
fn the_breeding_garden_follows_the_paper() {
    let settings = BreedSettings {
        grow: small(),
        spacing: 0.6,
        ..BreedSettings::default()
    };
    let mut rng = sylva_core::rng::seeded(4);
    let garden = breed_garden(&LSystemGenome::empty(), &settings, &mut rng, &Pool::Serial).unwrap();
    assert_eq!(garden.specimens.len(), 9);
    assert!(garden.specimens[0].is_mother);
    assert!(
        !garden.specimens[0].stats.germinated(),
        "empty rules do not germinate"
    );
    assert_eq!(garden.specimens[0].genome, LSystemGenome::empty());
    // Mother in a corner, children at even distances on the grid.
    assert_eq!(garden.specimens[0].position, grid_position(0, 0.6));
    assert_eq!(grid_position(0, 0.6), Vec2::new(-0.6, -0.6));
    for (i, s) in garden.specimens.iter().enumerate() {
        assert_eq!(s.position, grid_position(i, 0.6));
    }
    let best = largest_biomass(&garden);
    for s in &garden.specimens {
        assert!(s.stats.biomass <= garden.specimens[best].stats.biomass);
    }
}

#[test]
fn children_of_empty_rules_can_be_bred_until_they_draw() {
    let blank = BreedSettings {
        grow: small(),
        spacing: 0.6,
        ..BreedSettings::default()
    };
    let visible = BreedSettings {
        visible_children: true,
        ..blank
    };
    let grown = |settings: &BreedSettings| {
        let mut rng = sylva_core::rng::seeded(4);
        breed_garden(&LSystemGenome::empty(), settings, &mut rng, &Pool::Serial).unwrap()
    };
    let (paper, shown) = (grown(&blank), grown(&visible));
    let draws = |g: &LSystemGenome| g.shoot.draws_within(8, 4096);
    let germinated = |garden: &sylva_lsystem::breed::BredGarden| {
        garden.specimens[1..]
            .iter()
            .filter(|s| s.stats.germinated())
            .count()
    };
    // The paper's loop: most first steps from empty rules change nothing visible.
    assert!(
        paper.specimens[1..]
            .iter()
            .filter(|s| draws(&s.genome))
            .count()
            <= 2
    );
    // Bred until they draw: every child's shoot writes a module, and they grow.
    assert!(shown.specimens[1..].iter().all(|s| draws(&s.genome)));
    assert!(
        germinated(&shown) >= 6,
        "{} of 8 children germinated (the paper's loop: {})",
        germinated(&shown),
        germinated(&paper)
    );
    // The mother stays as she is, and a mother that draws is bred as in the paper.
    assert_eq!(shown.specimens[0].genome, LSystemGenome::empty());
    let mut a = sylva_core::rng::seeded(9);
    let mut b = sylva_core::rng::seeded(9);
    let bush = LSystemGenome::bush();
    assert_eq!(
        breed_garden(&bush, &blank, &mut a, &Pool::Serial).unwrap(),
        breed_garden(&bush, &visible, &mut b, &Pool::Serial).unwrap()
    );
}

#[test]
fn the_problem_scores_biomass() {
    let problem = LSystemProblem {
        grow: small(),
        ..LSystemProblem::default()
    };
    assert_eq!(problem.term_names().len(), 6);
    let bush = problem.evaluate(&example("bush.json"));
    let empty = problem.evaluate(&LSystemGenome::empty());
    assert!(bush.total() > empty.total(), "{bush:?} {empty:?}");
    assert_eq!(bush.terms()[0], bush.total());
    let mut rng = sylva_core::rng::seeded(1);
    let g = problem.random_genome(&mut rng);
    assert_eq!(LSystemGenome::from_json(&g.to_json()).unwrap(), g);
}

fn rates_high() -> MutationRates {
    MutationRates {
        delete_char: 0.5,
        insert_char: 0.8,
        permute_char: 0.5,
        duplicate_char: 0.5,
        mutate_char: 0.5,
        delete_rule: 0.2,
        insert_rule: 0.4,
        duplicate_rule: 0.2,
        mutate_parameter: 0.8,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Random genomes, mutated again and again, stay well-formed: their JSON reads back
    /// (so every rule parses, brackets balance, modules stay in their compartment) and
    /// their parameters stay in range.
    #[test]
    fn operators_keep_genomes_well_formed(seed in any::<u64>(), start in 0usize..4, rounds in 1usize..30) {
        let mut g = match start {
            0 => LSystemGenome::empty(),
            1 => LSystemGenome::bush(),
            2 => example("tree.json"),
            _ => example("herb.json"),
        };
        let mutation = LSystemMutation { rates: rates_high(), parameter_scale: 0.3 };
        let mut rng = sylva_core::rng::seeded(seed);
        for _ in 0..rounds {
            mutation.mutate(&mut g, &mut rng);
            let text = g.to_json();
            let back = LSystemGenome::from_json(&text);
            prop_assert!(back.is_ok(), "{text}: {back:?}");
            prop_assert_eq!(back.unwrap(), g.clone());
        }
        mutate_parameter(&mut g, 1.0, &mut rng);
        prop_assert!(LSystemGenome::from_json(&g.to_json()).is_ok());
    }

    /// Any mutant grows without error in a tiny world, within its bounds.
    #[test]
    fn mutants_grow_within_bounds(seed in any::<u64>()) {
        let mut g = LSystemGenome::bush();
        let mutation = LSystemMutation { rates: rates_high(), parameter_scale: 0.3 };
        let mut rng = sylva_core::rng::seeded(seed);
        for _ in 0..8 {
            mutation.mutate(&mut g, &mut rng);
        }
        g.physiology.max_modules = 400;
        g.physiology.max_symbols = 3000;
        let settings = GrowSettings {
            world: EnvironmentSettings { size: [8, 12, 8], soil_layers: 4, ..EnvironmentSettings::default() },
            steps: 15,
        };
        let plant = g.develop_with(&settings, seed).unwrap();
        prop_assert!(plant.segments().len() <= 400);
    }
}
