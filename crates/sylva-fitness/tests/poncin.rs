//! Poncin's fitness terms on hand-built plants with known answers, the config's errors, and
//! random plants that must never score NaN.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use proptest::prelude::*;
use sylva_core::glam::{DVec3, Quat, Vec2, Vec3};
use sylva_core::{Organ, OrganKind, Plant, PlantMeta, SegmentId};
use sylva_fitness::poncin::{
    DensityGrid, EndpointRule, GRID_MAX, GridBox, GridCell, GridConfig, NumTarget, PairMode,
    PairOptions, PoncinContext, PoncinFitness, PoncinScore, PoncinScratch, PoncinWeights,
    TERM_NAMES, TargetShape, ThickMeasure, ThickOptions, WORST_PAIR, f_angle, f_dist, f_grid,
    f_num, f_pos, f_thick,
};

const UNIT: f64 = 0.1;

fn close(a: f64, b: f64) {
    assert!((a - b).abs() <= 1e-6 * b.abs().max(1.0), "{a} vs {b}");
}

/// A trunk from the origin up to `top` (metres) and one lateral branch per entry of `tips`,
/// each from the trunk's top, with the given end radius.
fn fan(top: f32, tips: &[(Vec3, f32)]) -> Plant {
    let mut p = Plant::new(PlantMeta::default());
    let t = Vec3::new(0.0, top, 0.0);
    let trunk = p
        .add_segment(Vec3::ZERO, t, (0.3, 0.1), None, false, Plant::BARK)
        .unwrap();
    for &(tip, radius) in tips {
        p.add_segment(t, tip, (0.05, radius), Some(trunk), true, Plant::BARK)
            .unwrap();
    }
    p
}

fn leaf(p: &mut Plant, at: Vec3) {
    p.add_organ(Organ {
        kind: OrganKind::Leaf,
        position: at,
        orientation: Quat::IDENTITY,
        size: Vec2::new(0.1, 0.05),
        material: Plant::LEAF,
        parent: None,
    })
    .unwrap();
}

/// Two branches from the sphere's centre (20 m up): one to its surface along +x, one 10 m
/// along -z (50 paper units inside).
fn two_branches() -> Plant {
    fan(
        20.0,
        &[
            (Vec3::new(15.0, 20.0, 0.0), 0.3 / 9.0),
            (Vec3::new(0.0, 20.0, -10.0), 0.1),
        ],
    )
}

#[test]
fn f_pos_is_the_mean_distance_to_the_sphere() {
    let p = two_branches();
    close(f_pos(&p, &TargetShape::default(), UNIT), 25.0);
    // Read in metres, the same plant lies 180 m from the centre of a 150 m sphere.
    let metres = ((32625f64.sqrt() - 150.0) + (32500f64.sqrt() - 150.0)) / 2.0;
    close(f_pos(&p, &TargetShape::default(), 1.0), metres);
    // Without endpoints the foot is scored: |150 - 200|.
    close(
        f_pos(&Plant::default(), &TargetShape::default(), UNIT),
        50.0,
    );
}

#[test]
fn f_num_counts_endpoints_in_total_and_per_level() {
    let p = two_branches();
    assert_eq!(f_num(&p, &NumTarget::Total(30)), 28.0);
    assert_eq!(f_num(&p, &NumTarget::Total(0)), 2.0);
    // The trunk's top branched, so level 0 has no endpoint: |1 - 0| + |30 - 2|.
    assert_eq!(f_num(&p, &NumTarget::PerLevel(vec![1, 30])), 29.0);
    // Level-1 endpoints count against 0 when only the trunk is listed.
    assert_eq!(f_num(&p, &NumTarget::PerLevel(vec![0])), 2.0);
}

#[test]
fn f_num_per_branch_counts_each_branchs_sub_branches() {
    // A trunk with two first-order branches: A carries three sub-branches, B one.
    let mut p = Plant::new(PlantMeta::default());
    let (y, bark) = (Vec3::Y, Plant::BARK);
    let t0 = p
        .add_segment(Vec3::ZERO, y, (0.1, 0.1), None, false, bark)
        .unwrap();
    p.add_segment(y, 2.0 * y, (0.1, 0.1), Some(t0), false, bark)
        .unwrap();
    let a = p
        .add_segment(y, y + Vec3::X, (0.1, 0.1), Some(t0), true, bark)
        .unwrap();
    for z in [-1.0, 0.0, 1.0] {
        let end = y + Vec3::new(2.0, 0.5, z);
        p.add_segment(y + Vec3::X, end, (0.1, 0.1), Some(a), true, bark)
            .unwrap();
    }
    let b = p
        .add_segment(y, y - Vec3::X, (0.1, 0.1), Some(t0), true, bark)
        .unwrap();
    let b_end = y - Vec3::X;
    p.add_segment(b_end, b_end + Vec3::Y, (0.1, 0.1), Some(b), true, bark)
        .unwrap();
    let mut scratch = PoncinScratch::new();
    let ends = scratch.read(&p, UNIT, EndpointRule::Axes);
    let subs: Vec<(u16, u32)> = ends.iter().map(|e| (e.level, e.sub_branches)).collect();
    assert_eq!(
        subs,
        [(0, 0), (1, 3), (2, 0), (2, 0), (2, 0), (1, 1), (2, 0)]
    );
    let per_branch = |branches, each| NumTarget::PerBranch { branches, each }.deviation(ends);
    // The per-level form sees 1, 2 and 4 endpoints and is content.
    assert_eq!(NumTarget::PerLevel(vec![1, 2, 4]).deviation(ends), 0.0);
    // Counts met: only the spread is left, B one short of two.
    assert_eq!(per_branch(2, 2), 1.0);
    // Counts not met: the per-level deviation plus the most the spread can cost.
    assert_eq!(per_branch(2, 1), 2.0 + 2.0);
    assert_eq!(per_branch(3, 1), 2.0 + 3.0);
    assert_eq!(per_branch(2, 0), 4.0 + 0.0);
}

#[test]
fn endpoints_are_the_plants_tips() {
    let p = two_branches();
    let mut scratch = PoncinScratch::new();
    let ends = scratch.read(&p, UNIT, EndpointRule::Tips);
    let tips: Vec<Vec3> = p.tips().collect();
    assert_eq!(ends.len(), tips.len());
    for (e, t) in ends.iter().zip(&tips) {
        assert!((e.position - t.as_dvec3() / UNIT).length() < 1e-9);
        assert_eq!(e.level, 1);
    }
    assert!((ends[0].direction - DVec3::X).length() < 1e-9);
    assert!((ends[1].direction + DVec3::Z).length() < 1e-9);
}

#[test]
fn axis_endpoints_are_where_each_axis_was_last_drawn() {
    // A trunk that forks without a lateral (a Push/Pop path, then the trunk goes on), and
    // one lateral branch from the trunk's top.
    let mut p = Plant::new(PlantMeta::default());
    let v = |x: f32, y: f32| Vec3::new(x, y, 0.0);
    let r = (0.1, 0.1);
    let s0 = p
        .add_segment(v(0.0, 0.0), v(0.0, 1.0), r, None, false, Plant::BARK)
        .unwrap();
    p.add_segment(v(0.0, 1.0), v(0.5, 1.5), r, Some(s0), false, Plant::BARK)
        .unwrap();
    let s2 = p
        .add_segment(v(0.0, 1.0), v(0.0, 2.0), r, Some(s0), false, Plant::BARK)
        .unwrap();
    p.add_segment(v(0.0, 2.0), v(1.0, 2.0), r, Some(s2), true, Plant::BARK)
        .unwrap();
    let mut scratch = PoncinScratch::new();
    let at = |ends: &[sylva_fitness::poncin::Endpoint]| -> Vec<(i64, i64, u16)> {
        ends.iter()
            .map(|e| {
                (
                    e.position.x.round() as i64,
                    e.position.y.round() as i64,
                    e.level,
                )
            })
            .collect()
    };
    // Tips: the end of the fork path and of the branch.
    assert_eq!(
        at(scratch.read(&p, UNIT, EndpointRule::Tips)),
        [(5, 15, 0), (10, 20, 1)]
    );
    // Axes: where the trunk ended (though a branch grows there) and the branch; the fork
    // path adds none.
    assert_eq!(
        at(scratch.read(&p, UNIT, EndpointRule::Axes)),
        [(0, 20, 0), (10, 20, 1)]
    );
    let config = |endpoints| PoncinFitness {
        endpoints,
        num_target: NumTarget::Total(0),
        ..PoncinFitness::default()
    };
    let mut score = |rule| config(rule).score(&p, PoncinContext::default(), &mut scratch);
    assert_eq!(score(EndpointRule::Tips).branches, 2);
    assert_eq!(score(EndpointRule::Axes).branches, 2);
    assert_ne!(score(EndpointRule::Tips).pos, score(EndpointRule::Axes).pos);
}

#[test]
fn the_taper_measure_rewards_thinning_gradually_from_the_foot() {
    // A trunk of four 1 m segments (radius per thickness 0.3 m) ending at thickness 1/6:
    // thinning geometrically, or dropping to 1/6 in its first metre (the same endpoint).
    let trunk = |thickness: [f32; 5]| {
        let mut p = Plant::new(PlantMeta::default());
        let mut parent = None;
        for k in 0..4 {
            let (a, b) = (Vec3::Y * k as f32, Vec3::Y * (k + 1) as f32);
            let r = (0.3 * thickness[k], 0.3 * thickness[k + 1]);
            parent = Some(p.add_segment(a, b, r, parent, false, Plant::BARK).unwrap());
        }
        p
    };
    let at = |d: f64| (1.0f64 / 6.0).powf(d / 4.0);
    let even = trunk([
        1.0,
        at(1.0) as f32,
        at(2.0) as f32,
        at(3.0) as f32,
        at(4.0) as f32,
    ]);
    let sudden = trunk([1.0, 1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0]);
    let endpoints = ThickOptions::default();
    let taper = ThickOptions {
        measure: ThickMeasure::Taper,
        ..ThickOptions::default()
    };
    // The paper's measure cannot tell them apart; the taper measure can.
    assert!(f_thick(&even, &endpoints, 0) < 1e-6);
    assert!(f_thick(&sudden, &endpoints, 0) < 1e-6);
    assert!(f_thick(&even, &taper, 0) < 1e-6);
    let expected = (1..=4).map(|d| at(f64::from(d)) - 1.0 / 6.0).sum::<f64>() / 4.0;
    assert!((f_thick(&sudden, &taper, 0) - expected).abs() < 1e-6);
    // A branch from the foot counts its path from the foot too: a level-1 tip farthest out
    // sets the reference to 1/9 there.
    let mut forked = even.clone();
    let top = forked.segments()[3].end;
    let tip = top + Vec3::X * 4.0;
    let r = (0.3 * at(4.0) as f32, 0.3 / 9.0);
    let last = Some(SegmentId(3));
    forked
        .add_segment(top, tip, r, last, true, Plant::BARK)
        .unwrap();
    assert!(f_thick(&forked, &taper, 0) > 0.0);
    // A negative thickness is still penalised.
    let penalty = f_thick(&even, &taper, 2) - f_thick(&even, &taper, 0);
    assert!((penalty - 2.0).abs() < 1e-9);
}

#[test]
fn the_bars_measure_is_zero_exactly_when_the_taper_bars_hold() {
    // A trunk of four 1 m segments, radii given at each joint (thickness × 0.3 m), with a
    // branch of two segments from the trunk's second joint.
    let tree = |trunk: [f32; 5], branch: [f32; 3]| {
        let mut p = Plant::new(PlantMeta::default());
        let mut parent = None;
        for k in 0..4 {
            let (a, b) = (Vec3::Y * k as f32, Vec3::Y * (k + 1) as f32);
            let r = (0.3 * trunk[k], 0.3 * trunk[k + 1]);
            parent = Some(p.add_segment(a, b, r, parent, false, Plant::BARK).unwrap());
        }
        let mut parent = Some(SegmentId(1));
        for k in 0..2 {
            let a = Vec3::new(k as f32, 2.0, 0.0);
            let r = (0.3 * branch[k], 0.3 * branch[k + 1]);
            let lateral = k == 0;
            let s = p.add_segment(a, a + Vec3::X, r, parent, lateral, Plant::BARK);
            parent = Some(s.unwrap());
        }
        p
    };
    let bars = ThickOptions {
        measure: ThickMeasure::Bars,
        ..ThickOptions::default()
    };
    let gradual = tree([1.0, 0.7, 0.5, 0.35, 0.25], [0.5, 0.3, 0.2]);
    assert_eq!(f_thick(&gradual, &bars, 0), 0.0);
    // Each bar broken on its own: a step to less than half at the junction, a branch that
    // thickens, a tip above a quarter of the foot.
    let step = tree([1.0, 0.7, 0.5, 0.35, 0.25], [0.2, 0.15, 0.1]);
    let thickens = tree([1.0, 0.7, 0.5, 0.35, 0.25], [0.3, 0.33, 0.2]);
    let thick_tip = tree([1.0, 0.7, 0.5, 0.35, 0.25], [0.5, 0.4, 0.3]);
    // Per tip (2): 0.5 − 0.2 / 0.5 = 0.1 (or a rise of 0.33 / 0.3 − 1 = 0.1, or a tip 0.05
    // over 0.25) summed and halved, plus the worst.
    close(f_thick(&step, &bars, 0), 0.1 / 2.0 + 0.1);
    close(f_thick(&thickens, &bars, 0), 0.1 / 2.0 + 0.1);
    close(f_thick(&thick_tip, &bars, 0), 0.05 / 2.0 + 0.05);
    // A lower tip ratio leaves a margin: the gradual tree's trunk tip at 0.25 is then over.
    let margin = ThickOptions {
        tip_ratio: 0.2,
        ..bars.clone()
    };
    close(f_thick(&gradual, &margin, 0), 0.05 / 2.0 + 0.05);
    // So does a higher step ratio: the branch's step from 0.5 to 0.3 is then too sudden.
    let step_margin = ThickOptions {
        step_ratio: 0.65,
        ..bars.clone()
    };
    close(f_thick(&gradual, &step_margin, 0), 0.05 / 2.0 + 0.05);
    // Gradual adds the taper measure's deviation to the bars.
    let both = ThickOptions {
        measure: ThickMeasure::Gradual,
        ..ThickOptions::default()
    };
    let taper = ThickOptions {
        measure: ThickMeasure::Taper,
        ..ThickOptions::default()
    };
    close(
        f_thick(&step, &both, 0),
        f_thick(&step, &taper, 0) + f_thick(&step, &bars, 0),
    );
}

#[test]
fn f_dist_and_f_angle_follow_the_pair_formula() {
    let p = two_branches();
    let exact = PairOptions {
        mode: PairMode::Exact,
        ..PairOptions::default()
    };
    let d = (150.0f64.powi(2) + 100.0f64.powi(2)).sqrt();
    close(f_dist(&p, UNIT, &exact, 0), 200.0 / (d + 5.0));
    close(f_angle(&p, &exact, 0), 200.0 / 95.0); // 90 degrees apart

    // Three endpoints: the mean of three pair terms.
    let q = fan(
        20.0,
        &[
            (Vec3::new(10.0, 20.0, 0.0), 0.05),
            (Vec3::new(-10.0, 20.0, 0.0), 0.05),
            (Vec3::new(0.0, 30.0, 0.0), 0.05),
        ],
    );
    let (a, b) = (200.0, 100.0 * 2f64.sqrt());
    let expected = (200.0 / (a + 5.0) + 2.0 * 200.0 / (b + 5.0)) / 3.0;
    close(f_dist(&q, UNIT, &exact, 0), expected);
    let angles = (200.0 / 185.0 + 2.0 * 200.0 / 95.0) / 3.0;
    close(f_angle(&q, &exact, 0), angles);

    // No pair: the worst value, so a single stem never beats a tree.
    let stem = fan(20.0, &[]);
    assert_eq!(f_dist(&stem, UNIT, &exact, 0), WORST_PAIR);
    assert_eq!(f_angle(&stem, &exact, 0), WORST_PAIR);
}

/// `n` branches fanning out in a cone around the trunk's top.
fn many_branches(n: usize) -> Plant {
    let tips: Vec<(Vec3, f32)> = (0..n)
        .map(|i| {
            let a = i as f32 * 2.399; // golden angle
            let up = 20.0 + 10.0 * (i as f32 / n as f32);
            (Vec3::new(12.0 * a.cos(), up, 12.0 * a.sin()), 0.05)
        })
        .collect();
    fan(20.0, &tips)
}

#[test]
fn sampled_pairs_are_reproducible_for_a_seed() {
    let p = many_branches(80);
    let auto = PairOptions::default();
    assert!(!auto.is_exact(80) && auto.is_exact(64));
    assert_eq!(auto.sampled_pairs(80), 240);
    assert_eq!(auto.sampled_pairs(2), 10);
    let a = f_dist(&p, UNIT, &auto, 42);
    assert_eq!(a, f_dist(&p, UNIT, &auto, 42));
    assert_ne!(a, f_dist(&p, UNIT, &auto, 43));
    let exact = PairOptions {
        mode: PairMode::Exact,
        ..auto
    };
    let e = f_dist(&p, UNIT, &exact, 0);
    assert_eq!(
        e,
        f_dist(&p, UNIT, &exact, 99),
        "exact pairs ignore the seed"
    );
    assert!((a - e).abs() < 0.25 * e, "sampled {a} vs exact {e}");

    // Locks the sampler (ChaCha8 seeded from a u64, uniform indices): if this changes,
    // sampled scores of old runs change.
    assert_eq!(a, 1.5167298537180853);
}

#[test]
fn f_thick_uses_level_references_and_penalises_negatives() {
    let thick = ThickOptions::default();
    for (level, reciprocal) in [(0, 6.0), (1, 9.0), (2, 12.0), (3, 15.0), (5, 21.0)] {
        close(thick.reference(level), 1.0 / reciprocal);
    }
    let held = ThickOptions {
        references: vec![0.2],
        ..ThickOptions::default()
    };
    assert_eq!(held.reference(4), 0.2);
    let p = two_branches();
    // One branch ends at 1/9 exactly, the other at 1/3: mean |.| = (0 + 2/9) / 2.
    close(f_thick(&p, &thick, 0), 1.0 / 9.0);
    close(f_thick(&p, &thick, 3), 1.0 / 9.0 + 3.0);
    // The trunk's own tip is level 0.
    let stem = fan(20.0, &[]);
    close(f_thick(&stem, &thick, 0), (0.1 / 0.3 - 1.0 / 6.0f64).abs());
}

/// A grid of two cells side by side: x < 0 favoured (weight 1, target 2), x > 0 forbidden.
fn two_cell_grid() -> DensityGrid {
    DensityGrid::new(GridConfig {
        min: DVec3::new(-100.0, 0.0, -100.0),
        max: DVec3::new(100.0, 400.0, 100.0),
        divisions: [2, 1, 1],
        weight: 1.0,
        target: 2,
        boxes: vec![],
        cells: vec![GridCell {
            at: [1, 0, 0],
            weight: -1.0,
            target: Some(15),
        }],
    })
    .unwrap()
}

fn leafy() -> Plant {
    let mut p = two_branches();
    for x in [-5.0, -6.0, 3.0, 4.0, 5.0] {
        leaf(&mut p, Vec3::new(x, 20.0, 0.0));
    }
    leaf(&mut p, Vec3::new(50.0, 20.0, 0.0)); // outside the grid
    p
}

#[test]
fn f_grid_cells_of_both_signs() {
    let grid = two_cell_grid();
    // Favoured cell on target (e = 0); 3 leaves in the forbidden one (e = 2·3/15).
    close(
        f_grid(&leafy(), &grid, UNIT),
        100.0 * (2.0 * 3.0 / 15.0) / 2.0,
    );
    // No leaf: the favoured cell is empty (e = 1).
    close(f_grid(&two_branches(), &grid, UNIT), 50.0);
}

#[test]
fn the_grid_counts_only_past_its_gate() {
    let mut config = PoncinFitness {
        grid: Some(two_cell_grid()),
        weights: PoncinWeights::TABLE_2,
        ..PoncinFitness::default()
    };
    let plant = leafy();
    config.grid_gate = 1e9;
    let on = config.score_once(&plant, PoncinContext::default());
    assert!(on.grid_counted);
    close(on.grid, 20.0);
    assert_eq!((on.leaves, on.forbidden_leaves), (6, 3));
    config.grid_gate = 0.0;
    let off = config.score_once(&plant, PoncinContext::default());
    assert!(!off.grid_counted);
    assert_eq!(off.grid, GRID_MAX);
    assert_eq!(off.forbidden_leaves, 3, "counted even while gated off");
    close(off.total - on.total, 10.0 * (GRID_MAX - 20.0));
    // Without a grid, F_grid is 0.
    let none = PoncinFitness::default().score_once(&plant, PoncinContext::default());
    assert_eq!((none.grid, none.forbidden_leaves), (0.0, 0));
}

#[test]
fn table_2_adds_up_with_its_weights() {
    let rows = [
        (35.0, 6.0, 5.4, 100.0, 2555.0),
        (27.0, 10.0, 2.9, 59.3, 1808.0),
        (13.0, 0.0, 1.9, 23.9, 684.0),
        (15.0, 0.0, 0.7, 19.5, 410.0),
    ];
    let gate = PoncinFitness::default().grid_gate;
    for (i, (pos, num, dist, grid, total)) in rows.into_iter().enumerate() {
        let s = PoncinScore {
            pos,
            num,
            dist,
            grid,
            ..PoncinScore::default()
        };
        close(PoncinWeights::TABLE_2.total(&s), total);
        // Generation 2 is gated off (F_grid 100), the later ones are past the gate.
        assert_eq!(PoncinWeights::TABLE_2.rest(&s) < gate, i > 0, "row {i}");
    }
}

#[test]
fn score_reports_every_term_by_name() {
    let config = PoncinFitness {
        weights: PoncinWeights {
            angle: 3.0,
            grid: 10.0,
            ..PoncinWeights::TEXT
        },
        pairs: PairOptions {
            mode: PairMode::Exact,
            ..PairOptions::default()
        },
        grid: Some(two_cell_grid()),
        grid_gate: 1e9,
        ..PoncinFitness::default()
    };
    let plant = leafy();
    let ctx = PoncinContext {
        seed: 1,
        negative_thickness: 2,
    };
    let s = config.score_once(&plant, ctx);
    close(s.pos, f_pos(&plant, &config.target, UNIT));
    close(s.num, f_num(&plant, &config.num_target));
    close(s.dist, f_dist(&plant, UNIT, &config.pairs, 1));
    close(s.angle, f_angle(&plant, &config.pairs, 1));
    close(s.thick, f_thick(&plant, &config.thick, 2));
    let w = config.weights;
    close(
        s.total,
        5.0 * s.pos
            + 50.0 * s.num
            + 500.0 * s.dist
            + 1000.0 * s.thick
            + 3.0 * s.angle
            + 10.0 * s.grid,
    );
    close(s.total, w.total(&s));
    close(s.adjusted(), 1.0 / (1.0 + s.total));
    let terms = s.terms();
    assert_eq!(terms.len(), TERM_NAMES.len());
    let at = |name: &str| terms[TERM_NAMES.iter().position(|n| *n == name).unwrap()];
    assert_eq!(at("branches"), 2.0);
    assert_eq!(at("f_total"), s.total);
    assert_eq!(at("f_grid"), s.grid);
    // A reused scratch gives the same score.
    let mut scratch = PoncinScratch::new();
    let first = config.score(&many_branches(40), ctx, &mut scratch);
    config.score(&plant, ctx, &mut scratch);
    assert_eq!(config.score(&many_branches(40), ctx, &mut scratch), first);
}

fn parse(text: &str) -> Result<PoncinFitness, String> {
    toml::from_str::<PoncinFitness>(text).map_err(|e| e.to_string())
}

fn refused(text: &str, needle: &str) {
    let err = parse(text).expect_err(text);
    assert!(err.contains(needle), "expected `{needle}` in:\n{err}");
}

#[test]
fn config_defaults_and_round_trip() {
    assert_eq!(parse("").unwrap(), PoncinFitness::default());
    let config = parse(
        r#"
        unit = 0.05
        num_target = [1, 30]
        grid_gate = 1200
        [weights]
        dist = 200
        thick = 0
        grid = 10
        [target]
        shape = "ellipsoid"
        center = [0, 200, 0]
        radii = [150, 100, 150]
        [pairs]
        mode = "sampled"
        min_pairs = 20
        [thick]
        references = [0.2, 0.1]
        radius_per_thickness = 0.5
        [grid]
        min = [-150, 0, -150]
        max = [150, 375, 150]
        divisions = [5, 5, 5]
        [[grid.boxes]]
        from = [0, 4, 0]
        to = [4, 4, 4]
        weight = -1
        [[grid.cells]]
        at = [2, 2, 2]
        weight = 2
        target = 30
        "#,
    )
    .unwrap();
    assert_eq!(config.num_target, NumTarget::PerLevel(vec![1, 30]));
    let branches: PoncinFitness =
        toml::from_str("num_target = { branches = 8, each = 4 }").unwrap();
    let target = NumTarget::PerBranch {
        branches: 8,
        each: 4,
    };
    assert_eq!(branches.num_target, target);
    let written = toml::to_string(&branches).unwrap();
    assert_eq!(
        toml::from_str::<PoncinFitness>(&written)
            .unwrap()
            .num_target,
        target
    );
    assert_eq!(
        config.weights.pos, 5.0,
        "unnamed weights keep their defaults"
    );
    assert_eq!(config.pairs.per_endpoint, 3);
    let grid = config.grid.as_ref().unwrap();
    assert_eq!(grid.len(), 125);
    assert_eq!(grid.weight(grid.index([3, 4, 1])), -1.0);
    assert_eq!(grid.target(grid.index([2, 2, 2])), 30.0);
    assert_eq!(grid.target(grid.index([1, 1, 1])), 15.0);
    let text = toml::to_string(&config).unwrap();
    assert_eq!(parse(&text).unwrap(), config, "{text}");
    let json = serde_json::to_string(&config).unwrap();
    assert_eq!(
        serde_json::from_str::<PoncinFitness>(&json).unwrap(),
        config
    );
}

#[test]
fn config_errors_are_clear() {
    refused("colour = 3", "unknown field `colour`");
    refused("[weights]\nwidth = 3", "unknown field `width`");
    refused(
        "[weights]\npos = nan",
        "`weight` must be a number from 0 to 1000000",
    );
    refused("[weights]\ndist = -1", "`weight` must be a number from 0");
    refused("unit = inf", "`unit` must be a number");
    refused("unit = 0", "`unit` must be a number from 0.000001");
    refused("grid_gate = -5", "`grid_gate`");
    refused(
        "num_target = -1",
        "`num_target` entries must be whole numbers",
    );
    refused("num_target = []", "`num_target` must list 1 to 16 levels");
    refused(
        "num_target = 2.5",
        "a number of endpoints, a list of them per branch level, or a table",
    );
    refused(
        "num_target = { branches = 8 }",
        "needs both `branches` and `each`",
    );
    refused(
        "num_target = { branches = 8, each = 4, deep = 2 }",
        "unknown field `deep` in `num_target`",
    );
    refused("num_target = { branches = 8, each = -4 }", "whole numbers");
    refused("[thick]\nreferences = []", "`references` must hold 1 to 16");
    refused(
        "[thick]\nreferences = [0.5, 2]",
        "`references` entries must be",
    );
    refused(
        "[thick]\nradius_per_thickness = 0",
        "`radius_per_thickness`",
    );
    refused("[pairs]\nmode = \"fast\"", "unknown variant `fast`");
    refused("[pairs]\nper_endpoint = 0", "`per_endpoint`");
    refused("[target]\nshape = \"torus\"", "unknown variant `torus`");
    refused(
        "[target]\nshape = \"sphere\"\nradus = 3",
        "unknown field `radus`",
    );
    refused("[target]\nshape = \"sphere\"\nradius = -3", "`radius`");
    refused(
        "[target]\nshape = \"ellipsoid\"\ncenter = [0, 0, 0]\nradii = [1, 0, 1]",
        "`radii`",
    );
    refused(
        "[target]\nshape = \"box\"\ncenter = [0, nan, 0]\nsize = [1, 1, 1]",
        "`center` must be three numbers",
    );
    refused(
        "[target]\nshape = \"cone\"\nbase = [0, 0, 0]",
        "missing field",
    );
    let grid = "[grid]\nmin = [0, 0, 0]\nmax = [10, 10, 10]\ndivisions = [2, 2, 2]\n";
    assert!(parse(grid).is_ok());
    refused(
        &format!("{grid}[[grid.cells]]\nat = [2, 0, 0]\nweight = 1"),
        "outside a grid",
    );
    refused(
        &format!("{grid}[[grid.boxes]]\nfrom = [1, 0, 0]\nto = [0, 1, 1]\nweight = 1"),
        "`to` must not be below `from`",
    );
    refused(
        &format!("{grid}[[grid.cells]]\nat = [1, 0, 0]\nweight = 1\ntarget = 0"),
        "`target` must be a whole number from 1",
    );
    refused(
        "[grid]\nmin = [0, 0, 0]\nmax = [10, 0, 10]\ndivisions = [2, 2, 2]",
        "above `min`",
    );
    refused(
        "[grid]\nmin = [0, 0, 0]\nmax = [10, 10, 10]\ndivisions = [0, 2, 2]",
        "`divisions`",
    );
    refused(
        "[grid]\nmin = [0, 0, 0]\nmax = [10, 10, 10]\ndivisions = [1024, 1024, 2]",
        "must have 1 to 1048576 cells",
    );
    refused(&format!("{grid}colour = 1"), "unknown field `colour`");
}

/// A random plant: each segment grows from a random earlier one (or is a root), with random
/// direction, length (tiny to huge) and radius; some leaves.
fn random_plant() -> impl Strategy<Value = Plant> {
    let segment = (
        any::<prop::sample::Index>(),
        any::<bool>(),
        prop::array::uniform3(-1.0f32..1.0),
        prop_oneof![Just(0.0f32), 1e-6f32..1e-3, 0.01f32..5.0, 1e3f32..1e5],
        0.0f32..2.0,
    );
    let leaf = (prop::array::uniform3(-100.0f32..100.0), any::<bool>());
    (
        prop::collection::vec(segment, 0..60),
        prop::collection::vec(leaf, 0..40),
    )
        .prop_map(|(segments, leaves)| {
            let mut p = Plant::new(PlantMeta::default());
            for (k, (parent, lateral, dir, len, radius)) in segments.into_iter().enumerate() {
                let parent =
                    (k > 0 && parent.index(4) != 0).then(|| SegmentId(parent.index(k) as u32));
                let start = parent.map_or(Vec3::ZERO, |q| p.segment(q).end);
                let end = start + Vec3::from_array(dir) * len;
                p.add_segment(start, end, (radius, radius), parent, lateral, Plant::BARK)
                    .unwrap();
            }
            for (at, is_leaf) in leaves {
                p.add_organ(Organ {
                    kind: if is_leaf {
                        OrganKind::Leaf
                    } else {
                        OrganKind::Flower
                    },
                    position: Vec3::from_array(at),
                    orientation: Quat::IDENTITY,
                    size: Vec2::ONE,
                    material: Plant::LEAF,
                    parent: None,
                })
                .unwrap();
            }
            p
        })
}

fn every_option() -> Vec<PoncinFitness> {
    let grid = DensityGrid::new(GridConfig {
        min: DVec3::splat(-500.0),
        max: DVec3::splat(500.0),
        divisions: [3, 4, 5],
        weight: 1.0,
        target: 15,
        boxes: vec![GridBox {
            from: [0, 3, 0],
            to: [2, 3, 4],
            weight: -2.0,
            target: None,
        }],
        cells: vec![],
    })
    .unwrap();
    let weights = PoncinWeights {
        angle: 7.0,
        grid: 10.0,
        ..PoncinWeights::TEXT
    };
    [
        TargetShape::default(),
        TargetShape::Ellipsoid {
            center: DVec3::new(0.0, 200.0, 0.0),
            radii: DVec3::new(150.0, 80.0, 120.0),
        },
        TargetShape::Box {
            center: DVec3::new(0.0, 200.0, 0.0),
            size: DVec3::new(300.0, 0.0, 100.0),
        },
        TargetShape::Cylinder {
            base: DVec3::ZERO,
            radius: 0.0,
            height: 300.0,
        },
        TargetShape::Cone {
            base: DVec3::new(0.0, 100.0, 0.0),
            radius: 150.0,
            height: -250.0,
        },
    ]
    .into_iter()
    .zip(
        [PairMode::Exact, PairMode::Sampled, PairMode::Auto]
            .into_iter()
            .cycle(),
    )
    .map(|(target, mode)| PoncinFitness {
        target,
        weights,
        pairs: PairOptions {
            mode,
            exact_up_to: 10,
            ..PairOptions::default()
        },
        num_target: NumTarget::PerLevel(vec![1, 5, 10]),
        grid: Some(grid.clone()),
        grid_gate: 1e12,
        ..PoncinFitness::default()
    })
    .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn random_plants_never_score_nan(
        plant in random_plant(),
        seed in any::<u64>(),
        negative in 0u32..5,
    ) {
        let mut scratch = PoncinScratch::new();
        let ctx = PoncinContext { seed, negative_thickness: negative };
        for config in every_option() {
            let s = config.score(&plant, ctx, &mut scratch);
            for (name, value) in TERM_NAMES.iter().zip(s.terms()) {
                prop_assert!(value.is_finite() && value >= 0.0, "{name} = {value}");
            }
            prop_assert!(s.grid <= GRID_MAX);
            prop_assert!(s.adjusted() > 0.0 && s.adjusted() <= 1.0);
            prop_assert_eq!(s.branches, plant.tips().count());
        }
    }
}
