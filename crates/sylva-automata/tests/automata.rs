//! The automata model end to end: any random valid tree compiles, grows within its bounds,
//! never panics and gives a valid plant; the text form round-trips; the rules of
//! construction hold through the GP operators; bounds are reported when hit; growth is
//! deterministic.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use proptest::prelude::*;
use sylva_automata::{
    AtEnd, ChildVariables, Detail, ElseEnd, GpConfig, GpTree, GrowOptions, GrowthReport, Limits,
    Node, Program, Semantics, Simulator, Stop, SubtreeCrossover, SubtreeMutation, Target,
};
use sylva_core::{Plant, PlantMeta};
use sylva_evolve::{Crossover, Mutate, rng};

/// A GP configuration drawn from a seed: 1 to 4 automata, depths 0 to 8.
fn config(seed: u64) -> GpConfig {
    let a = (seed % 4) as u8 + 1;
    let lo = ((seed >> 8) % 5) as u32;
    let hi = lo + ((seed >> 16) % 5) as u32;
    GpConfig {
        automata: a,
        min_init_depth: lo,
        max_init_depth: hi,
        max_size: 30 + ((seed >> 24) % 500) as u32,
        ..GpConfig::default()
    }
}

fn random_tree(seed: u64) -> GpTree {
    config(seed).random_tree(&mut rng::seeded(seed))
}

fn semantics(seed: u64) -> Semantics {
    Semantics {
        degrees_per_unit: [10.0, 3.0, 30.0][(seed % 3) as usize],
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
        equal_tolerance: 0.5,
    }
}

fn options(seed: u64) -> GrowOptions {
    GrowOptions {
        iterations: 1 + (seed % 150) as u32,
        gravity: if seed & 32 == 0 { 0.0 } else { 3.0 },
        horizontal_leaves: seed & 64 == 0,
        child_variables: [
            ChildVariables::LengthThickness,
            ChildVariables::All,
            ChildVariables::Fresh,
        ][(seed % 3) as usize],
        limits: Limits {
            states_per_step: 1 + (seed >> 7) as u32 % 300,
            states: 1 + (seed >> 9) % 40_000,
            automata: 1 + (seed >> 11) as u32 % 200,
            points: 1 + (seed >> 13) as u32 % 3000,
            organs: (seed >> 15) as u32 % 300,
        },
        ..GrowOptions::default()
    }
}

/// Rebuilds the plant through `Plant`'s checked constructors: every part must be accepted.
fn assert_valid(plant: &Plant) {
    let mut copy = Plant::new(PlantMeta::default());
    for s in plant.segments() {
        let id = copy
            .add_segment(
                s.start,
                s.end,
                (s.start_radius, s.end_radius),
                s.parent,
                s.lateral,
                s.material,
            )
            .unwrap();
        assert_eq!(copy.segment(id).order, s.order, "order of {id:?}");
        assert_eq!(copy.segment(id).lateral, s.lateral);
        if let Some(p) = s.parent {
            assert!(p.index() < id.index(), "parents first");
        }
    }
    for o in plant.organs() {
        copy.add_organ(*o).unwrap();
    }
    assert_eq!(&copy.segments(), &plant.segments());
}

fn assert_within(report: &GrowthReport, o: &GrowOptions, plant: &Plant) {
    let l = &o.limits;
    assert!(report.max_states_per_step <= l.states_per_step);
    assert!(report.states <= l.states + u64::from(l.states_per_step));
    assert!(report.automata <= l.automata);
    assert!(report.points <= l.points);
    assert!(report.leaves + report.flowers <= l.organs);
    assert!(report.iterations <= o.iterations);
    assert_eq!(report.segments as usize, plant.segments().len());
    assert_eq!(
        (report.leaves + report.flowers) as usize,
        plant.organs().len()
    );
    assert!(plant.segments().len() <= (report.points + report.automata) as usize);
    assert_eq!(report.bounds.points, report.stop == Stop::Points);
    assert_eq!(report.bounds.states, report.stop == Stop::States);
    if report.stop == Stop::AllDead {
        assert_eq!(report.live_at_end, 0);
    }
}

fn sorted(points: impl Iterator<Item = sylva_core::glam::Vec3>) -> Vec<[f32; 3]> {
    let mut v: Vec<[f32; 3]> = points.map(|p| p.to_array()).collect();
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn random_trees_compile_grow_within_bounds_and_give_valid_plants(seed in any::<u64>()) {
        let tree = random_tree(seed);
        let program = Program::compile(&tree, &semantics(seed));
        prop_assert_eq!(program.verify(), Ok(()));
        let o = options(seed);
        let mut sim = Simulator::new();
        let mut full = Plant::new(PlantMeta::default());
        let report = sim.run(&program, &o, Detail::Full, &mut full);
        assert_within(&report, &o, &full);
        assert_valid(&full);
        // Chords: same growth, same tips, organs, levels and end thicknesses.
        let mut chords = Plant::new(PlantMeta::default());
        let r2 = sim.run(&program, &o, Detail::Chords, &mut chords);
        assert_valid(&chords);
        prop_assert_eq!(GrowthReport { segments: 0, ..r2 }, GrowthReport { segments: 0, ..report });
        prop_assert!(chords.segments().len() <= full.segments().len());
        prop_assert_eq!(&chords.organs().iter().map(|o| (o.position, o.kind)).collect::<Vec<_>>(),
            &full.organs().iter().map(|o| (o.position, o.kind)).collect::<Vec<_>>());
        prop_assert_eq!(sorted(chords.tips()), sorted(full.tips()));
        let ends = |p: &Plant| {
            let counts = p.child_counts();
            let mut v: Vec<(u16, u32, [f32; 3])> = p.segments().iter().zip(counts)
                .filter(|(_, c)| *c == 0)
                .map(|(s, _)| (s.order, s.end_radius.to_bits(), s.end.to_array()))
                .collect();
            v.sort_by(|a, b| a.partial_cmp(b).unwrap());
            v
        };
        prop_assert_eq!(ends(&chords), ends(&full));
    }

    #[test]
    fn text_form_round_trips(seed in any::<u64>()) {
        let tree = random_tree(seed);
        let text = tree.to_string();
        let back = GpTree::parse(&text).unwrap();
        prop_assert_eq!(&back, &tree);
        prop_assert_eq!(back.to_string(), text);
    }

    #[test]
    fn gp_operators_keep_trees_legal_and_within_limits(seed in any::<u64>()) {
        let c = config(seed);
        let mut r = rng::seeded(seed ^ 0x5eed);
        let a = c.random_tree(&mut r);
        let b = config(seed.rotate_left(17)).random_tree(&mut r);
        let cross = SubtreeCrossover { config: c };
        let child = cross.crossover(&a, &b, &mut r);
        // Valid by construction (GpTree::new checked it); the limits hold.
        prop_assert!(child.len() <= c.max_size.max(1 + u32::from(c.automata)) as usize || child == a);
        prop_assert!(child.depth() <= c.max_depth as usize || child == a);
        prop_assert_eq!(child.automata(), a.automata());
        let mut m = child.clone();
        SubtreeMutation { config: c }.mutate(&mut m, &mut r);
        prop_assert!(m.len() <= c.max_size.max(1 + u32::from(c.automata)) as usize || m.len() <= child.len());
        prop_assert!(m.depth() <= c.max_depth as usize || m.depth() <= child.depth());
        // Both print and parse back, which re-checks every rule of construction.
        prop_assert_eq!(GpTree::parse(&m.to_string()).unwrap(), m.clone());
        assert_rules(&m);
        let program = Program::compile(&m, &Semantics::default());
        prop_assert_eq!(program.verify(), Ok(()));
    }

    #[test]
    fn node_info_agrees_with_a_walk_from_the_root(seed in any::<u64>()) {
        let tree = random_tree(seed);
        let info = tree.node_info();
        // Depth and automaton by walking down from the root with explicit ranges.
        let mut expected = vec![(0usize, 0u8); tree.len()];
        let mut work = vec![(0usize, 0usize, 0u8)];
        while let Some((i, depth, automaton)) = work.pop() {
            expected[i] = (depth, automaton);
            let mut child = i + 1;
            for k in 0..tree.nodes()[i].arity() {
                let a = if i == 0 { k as u8 } else { automaton };
                work.push((child, depth + 1, a));
                child = tree.subtree_end(child);
            }
        }
        for (i, facts) in info.iter().enumerate() {
            prop_assert_eq!(facts.end as usize, tree.subtree_end(i));
            prop_assert_eq!((usize::from(facts.depth), facts.automaton), expected[i]);
            let height = (i + 1..tree.subtree_end(i))
                .map(|j| usize::from(info[j].depth) - usize::from(facts.depth))
                .max()
                .unwrap_or(0);
            prop_assert_eq!(usize::from(facts.height), height);
        }
    }
}

/// No Top below the root, creations only forward, organs only from the last automaton.
fn assert_rules(tree: &GpTree) {
    let n = tree.automata();
    for (k, body) in tree.bodies().into_iter().enumerate() {
        for node in &tree.nodes()[body] {
            match node {
                Node::Top(_) => panic!("Top below the root"),
                Node::Target(Target::Automaton(j)) => {
                    assert!(usize::from(*j) > k + 1 && usize::from(*j) <= n)
                }
                Node::Target(_) => assert_eq!(k + 1, n, "organ from automaton {}", k + 1),
                _ => {}
            }
        }
    }
}

#[test]
fn initialisation_never_fails() {
    let mut r = rng::seeded(11);
    for automata in 1..=8u8 {
        for lo in 0..=9u32 {
            for hi in lo..=10 {
                for max_size in [1u32, 5, 20, 100, 500] {
                    for max_depth in [1u32, 2, 5, 17] {
                        let c = GpConfig {
                            automata,
                            min_init_depth: lo,
                            max_init_depth: hi,
                            max_size,
                            max_depth,
                            ..GpConfig::default()
                        };
                        for i in 0..3 {
                            let t = c.ramped(i, &mut r);
                            assert_eq!(t.automata(), usize::from(automata));
                            assert!(t.len() <= (max_size as usize).max(1 + usize::from(automata)));
                            assert!(t.depth() <= max_depth as usize);
                            assert_rules(&t);
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn crossover_is_homologous_and_repairs_targets() {
    let a = GpTree::parse(
        "(Top (Seq (CreateAutomaton A2) (Wait)) (Seq (CreateAutomaton A3) (Wait)) \
         (CreateAutomaton Leaf))",
    )
    .unwrap();
    let b = GpTree::parse("(Top (CreateAutomaton A3) (Killme) (CreateAutomaton Flower))").unwrap();
    let cross = SubtreeCrossover::default();
    let mut r = rng::seeded(5);
    for _ in 0..200 {
        let child = cross.crossover(&a, &b, &mut r);
        assert_rules(&child);
        assert_eq!(child.automata(), 3);
    }
}

fn grow(text: &str, o: &GrowOptions, sem: &Semantics) -> (Plant, GrowthReport) {
    let program = Program::compile(&GpTree::parse(text).unwrap(), sem);
    let mut plant = Plant::new(PlantMeta::default());
    let report = Simulator::new().run(&program, o, Detail::Full, &mut plant);
    assert_valid(&plant);
    (plant, report)
}

#[test]
fn creating_every_step_hits_the_automata_bound() {
    // Automaton 1 makes 100 of automaton 2, each of which makes up to 100 of automaton 3.
    let text = "(Top (Repeat 10 (Repeat 10 (Seq (CreateAutomaton A2) (Wait)))) \
                (Repeat 10 (Repeat 10 (Seq (CreateAutomaton A3) (Wait)))) \
                (Repeat 5 (Wait)))";
    let o = GrowOptions::default();
    let (plant, report) = grow(text, &o, &Semantics::default());
    assert_eq!(report.automata, o.limits.automata);
    assert!(report.bounds.automata_refused > 0, "{report:?}");
    assert!(report.bounds.any());
    assert!(report.peak_live <= o.limits.automata);
    assert!(plant.segments().iter().map(|s| s.order).max() == Some(2));
}

#[test]
fn nested_repeats_without_wait_are_killed_and_reported() {
    let text = "(Top (Seq (Wait) (Repeat 10 (Repeat 10 (Repeat 10 (Repeat 10 (RotateH 1)))))))";
    let (plant, report) = grow(text, &GrowOptions::default(), &Semantics::default());
    assert_eq!(report.bounds.state_limit_kills, 1);
    assert_eq!(report.max_states_per_step, 1000);
    assert_eq!(report.stop, Stop::AllDead);
    assert_eq!(plant.segments().len(), 1, "it moved once, then looped");
    // Restarting at the end with no Wait loops for ever: the same bound stops it.
    let restart = Semantics {
        at_end: AtEnd::Restart,
        ..Semantics::default()
    };
    let (plant, report) = grow("(Top (RotateU 1))", &GrowOptions::default(), &restart);
    assert_eq!(report.bounds.state_limit_kills, 1);
    assert!(plant.segments().is_empty());
}

#[test]
fn points_states_organs_and_values_are_bounded() {
    let long = "(Top (Repeat 10 (Repeat 10 (Repeat 10 (Seq (CreateAutomaton Leaf) (Wait))))))";
    let mut o = GrowOptions {
        iterations: 5000,
        ..GrowOptions::default()
    };
    o.limits.points = 50;
    let (plant, report) = grow(long, &o, &Semantics::default());
    assert_eq!((report.points, report.stop), (50, Stop::Points));
    assert!(report.bounds.points);
    assert_eq!(plant.segments().len(), 50);
    o.limits = Limits {
        states: 100,
        organs: 7,
        ..Limits::default()
    };
    let (plant, report) = grow(long, &o, &Semantics::default());
    assert_eq!(report.stop, Stop::States);
    assert!(report.states >= 100 && report.states < 110);
    assert_eq!(plant.organs().len(), 7);
    assert!(report.bounds.organs_refused > 0);
    // Length multiplied by 10 every step: clamped, and positions stay finite.
    let runaway = "(Top (Repeat 10 (Repeat 10 (Seq (Multiply Length 10) (Wait)))))";
    let (plant, report) = grow(runaway, &GrowOptions::default(), &Semantics::default());
    assert!(report.bounds.clamped_values > 0);
    assert!(plant.segments().iter().all(|s| s.end.is_finite()));
    assert_eq!(report.points, 100);
}

#[test]
fn a_plant_that_outgrows_the_world_stops_at_the_extent_bound() {
    // Length 10^6 units (clamped) at 1000 m a unit: 10^9 m a step, past 10^12 m within
    // 1000 steps. Growth stops there, every part kept is legal, and the bound is reported.
    let far = "(Top (Seq (Repeat 7 (Multiply Length 10)) \
               (Repeat 10 (Repeat 10 (Repeat 10 (Repeat 10 (Wait)))))))";
    let o = GrowOptions {
        iterations: 20_000,
        unit: 1000.0,
        ..GrowOptions::default()
    };
    for detail in [Detail::Full, Detail::Chords] {
        let program = Program::compile(&GpTree::parse(far).unwrap(), &Semantics::default());
        let mut plant = Plant::new(PlantMeta::default());
        let report = Simulator::new().run(&program, &o, detail, &mut plant);
        assert_eq!(report.stop, Stop::Extent, "{detail:?}: {report:?}");
        assert!(report.bounds.extent && report.bounds.any());
        assert_valid(&plant);
        let reach = plant
            .segments()
            .iter()
            .map(|s| s.end.y.abs())
            .fold(0.0, f32::max);
        assert!(reach <= sylva_core::plant::MAX_COORD, "{reach}");
        if detail == Detail::Full {
            // A segment a step: growth stops at the step that left the world.
            assert!(report.points > 900 && report.points < 1100, "{report:?}");
            assert!(reach > 1e11, "{reach}");
        }
    }
}

#[test]
fn the_root_starts_with_its_configured_length() {
    let o = GrowOptions {
        root_length: 2.5,
        ..GrowOptions::default()
    };
    let text = "(Top (Seq (Repeat 10 (Wait)) (CreateAutomaton A2)) (Repeat 4 (Wait)))";
    let (plant, _) = grow(text, &o, &Semantics::default());
    let top = |lateral: bool| {
        plant
            .segments()
            .iter()
            .filter(|s| s.order == u16::from(lateral))
            .map(|s| s.end.y)
            .fold(0.0, f32::max)
    };
    // 10 steps of 2.5 units of 0.1 m; the child inherits the Length: 4 more steps.
    assert!((top(false) - 2.5).abs() < 1e-5, "{}", top(false));
    assert!((top(true) - 3.5).abs() < 1e-5, "{}", top(true));
}

#[test]
fn push_pop_with_moves_draws_a_fork() {
    // Two steps up, then a side path of three steps inside a Push/Pop, then two more up.
    let text = "(Top (Seq (Repeat 2 (Wait)) (Seq (PushPop (Seq (RotateL 9) (Repeat 3 (Wait)))) \
                (Repeat 2 (Wait)))))";
    for detail in [Detail::Full, Detail::Chords] {
        let program = Program::compile(&GpTree::parse(text).unwrap(), &Semantics::default());
        let mut plant = Plant::new(PlantMeta::default());
        let report = Simulator::new().run(&program, &GrowOptions::default(), detail, &mut plant);
        assert_eq!(report.points, 7);
        assert_valid(&plant);
        assert_eq!(plant.tips().count(), 2, "{detail:?}");
        let top = plant.tips().map(|p| p.y).fold(0.0, f32::max);
        assert!(
            (top - 0.4).abs() < 1e-5,
            "the main path goes on from the fork: {top}"
        );
        assert!(plant.segments().iter().all(|s| s.order == 0 && !s.lateral));
        if detail == Detail::Chords {
            assert_eq!(plant.segments().len(), 3);
        }
    }
}

#[test]
fn children_start_at_the_creator_with_its_frame_and_next_iteration() {
    // The creator turns 90° then creates before any move: a stub keeps the child's level.
    let text = "(Top (Seq (RotateL 9) (Seq (CreateAutomaton A2) (Wait))) (Wait))";
    let (plant, report) = grow(text, &GrowOptions::default(), &Semantics::default());
    assert_eq!(report.automata, 2);
    // Iteration 1: the root creates and moves; 2: the root ends, the child moves for the
    // first time; 3: the child ends.
    assert_eq!((report.iterations, report.automaton_steps), (3, 4));
    let stub = plant.segments()[0];
    assert_eq!(stub.length(), 0.0);
    let child = plant.segments().iter().find(|s| s.lateral).unwrap();
    assert_eq!(child.order, 1);
    assert_eq!(child.start, stub.end);
    assert!((child.vector().normalize() - sylva_core::glam::Vec3::Z).length() < 1e-5);
}

#[test]
fn the_last_automaton_adds_organs_where_it_stands() {
    let text = "(Top (Seq (Repeat 3 (Wait)) (CreateAutomaton A2)) \
                (Seq (Wait) (Seq (CreateAutomaton Leaf) (Seq (Wait) (CreateAutomaton Flower)))))";
    let (plant, report) = grow(text, &GrowOptions::default(), &Semantics::default());
    assert_eq!((report.leaves, report.flowers), (1, 1));
    let leaf = plant.organs()[0];
    assert!((leaf.position.y - 0.4).abs() < 1e-5);
    let up = leaf.orientation * sylva_core::glam::Vec3::Z;
    assert!(up.y > 0.95, "near horizontal, face up: {up}");
    assert!(leaf.parent.is_some() && plant.organs()[1].parent.is_some());
}

#[test]
fn growth_is_deterministic_and_independent_of_earlier_runs() {
    let mut sim = Simulator::new();
    let bytes = |sim: &mut Simulator, tree: &GpTree, detail| {
        let program = Program::compile(tree, &Semantics::default());
        let mut plant = Plant::new(PlantMeta::default());
        sim.run(&program, &GrowOptions::default(), detail, &mut plant);
        serde_json::to_vec(&plant).unwrap()
    };
    let c = GpConfig::default();
    let mut r = rng::seeded(99);
    let trees: Vec<GpTree> = (0..40).map(|i| c.ramped(i, &mut r)).collect();
    let first: Vec<Vec<u8>> = trees
        .iter()
        .map(|t| bytes(&mut sim, t, Detail::Full))
        .collect();
    for (t, want) in trees.iter().zip(&first).rev() {
        let _ = bytes(&mut sim, t, Detail::Chords);
        assert_eq!(&bytes(&mut sim, t, Detail::Full), want);
        assert_eq!(&bytes(&mut Simulator::new(), t, Detail::Full), want);
    }
}

#[test]
fn random_individuals_look_like_the_paper_s() {
    // Not a tuning target, a sanity check: random trees of the default configuration
    // mostly grow something, and some branch.
    let c = GpConfig::default();
    let mut r = rng::seeded(2024);
    let mut sim = Simulator::new();
    let mut plant = Plant::new(PlantMeta::default());
    let (mut drawn, mut branched) = (0, 0);
    for i in 0..500 {
        let t = c.ramped(i, &mut r);
        let program = Program::compile(&t, &Semantics::default());
        let report = sim.run(
            &program,
            &GrowOptions::default(),
            Detail::Chords,
            &mut plant,
        );
        drawn += usize::from(report.points > 0);
        branched += usize::from(plant.segments().iter().any(|s| s.lateral));
    }
    eprintln!("of 500 random trees: {drawn} draw, {branched} branch");
    assert!(drawn > 250 && branched > 25, "{drawn} {branched}");
}

/// `detail = "full"` makes evaluation grow every step, so a thickness measure sees a taper
/// inside a run: ten halvings are gradual step by step, but one chord from 1 to the tip
/// is a sudden step.
#[test]
fn evaluation_grows_every_step_when_the_settings_ask() {
    let tree = GpTree::parse("(Top (Repeat 10 (Seq (Multiply Thickness 0.5) (Wait))))").unwrap();
    let settings = |detail: &str| -> sylva_automata::AutomataSettings {
        toml::from_str(&format!(
            "automata = 1\ndetail = \"{detail}\"\n[fitness.thick]\nmeasure = \"bars\"\n\
             [fitness.weights]\nthick = 1.0"
        ))
        .unwrap()
    };
    let score = |detail: &str| sylva_automata::AutomataProblem::new(&settings(detail)).score(&tree);
    let (full, chords) = (score("full"), score("chords"));
    let s = settings("full");
    let (plant, report) = grow(
        &tree.to_string(),
        &s.growth.grow_options(),
        &s.growth.semantics(),
    );
    let ctx = sylva_fitness::poncin::PoncinContext {
        seed: 0,
        negative_thickness: report.negative_thickness,
    };
    assert_eq!(full.thick, s.fitness.score_once(&plant, ctx).thick);
    assert_eq!(full.thick, 0.0);
    assert!(chords.thick > 0.3, "{}", chords.thick);
    let err = toml::from_str::<sylva_automata::AutomataSettings>("detail = \"every\"").unwrap_err();
    assert!(err.to_string().contains("chords"), "{err}");
    // Nudges and the step ratio are shares: out of 0..=1 they are refused by name.
    for (text, field) in [
        ("nudge = 1.5", "nudge"),
        ("[fitness.thick]\nstep_ratio = -0.1", "step_ratio"),
    ] {
        let err = toml::from_str::<sylva_automata::AutomataSettings>(text).unwrap_err();
        assert!(err.to_string().contains(field), "{err}");
    }
}
