//! Random programs built to grow into trees, for a person who asks for a random plant.
//!
//! A run's random programs are Poncin's ramped half-and-half trees: most draw a stick, a
//! stump or a fan on the ground until evolution makes something of them. [`random_tree`]
//! instead fills a tree's plan with random numbers: a trunk that tapers and bends, setting
//! whorls of branches a roll apart; branches that set twigs the same way; and twigs that
//! bear leaves. Every plant it makes stands and branches, and no two seeds look alike.
//! Numbers in programs stop at ±10, so a count or an angle never passes that.

use rand::{Rng, RngExt};

use crate::tree::GpTree;

/// A random program of three automata in a tree's plan (see the module's overview).
pub fn random_tree<R: Rng + ?Sized>(rng: &mut R) -> GpTree {
    // Thickness 1 is the growth's full radius (0.3 m by default): a trunk starts thinner.
    let trunk = value(rng, 0.25..0.45);
    let branch = value(rng, 0.3..0.6);
    let text = format!(
        "(Top (Seq (Multiply Thickness {trunk}) {}) (Seq (Multiply Thickness {branch}) {}) {})",
        axis(rng, Axis::TRUNK, "A2"),
        axis(rng, Axis::BRANCH, "A3"),
        leafy_twig(rng)
    );
    GpTree::parse(&text).unwrap_or_else(|e| unreachable!("the plan `{text}` parses: {e}"))
}

/// The ranges of one level's numbers.
struct Axis {
    /// Bare steps before the first whorl.
    base: std::ops::RangeInclusive<u32>,
    /// Whorls of laterals.
    whorls: std::ops::RangeInclusive<u32>,
    /// Steps between whorls.
    gap: std::ops::RangeInclusive<u32>,
    /// Thickness kept at each step.
    taper: std::ops::Range<f64>,
    /// Bend per step, in rotation units (10° each by default).
    bend: std::ops::Range<f64>,
    /// Laterals' angle from the axis, in rotation units.
    angle: std::ops::Range<f64>,
}

impl Axis {
    const TRUNK: Axis = Axis {
        base: 2..=10,
        whorls: 3..=8,
        gap: 2..=6,
        taper: 0.95..0.99,
        bend: -0.2..0.2,
        angle: 3.0..8.0,
    };
    const BRANCH: Axis = Axis {
        base: 1..=3,
        whorls: 2..=5,
        gap: 2..=4,
        taper: 0.92..0.98,
        bend: -0.6..0.6,
        angle: 3.0..7.0,
    };
}

/// An axis that tapers and bends, and every few steps rolls and starts `lateral`.
fn axis<R: Rng + ?Sized>(rng: &mut R, a: Axis, lateral: &str) -> String {
    let base = rng.random_range(a.base);
    let whorls = rng.random_range(a.whorls);
    let gap = rng.random_range(a.gap);
    let taper = value(rng, a.taper);
    let bend = value(rng, a.bend);
    let roll = roll(rng);
    let angle = value(rng, a.angle);
    let step = format!("(Seq (Multiply Thickness {taper}) (Seq (RotateL {bend}) (Wait)))");
    format!(
        "(Seq (Repeat {base} {step}) (Repeat {whorls} (Seq (Repeat {gap} {step}) \
         (Seq {roll} (PushPop (Seq (RotateL {angle}) (CreateAutomaton {lateral})))))))"
    )
}

/// The last level: a thin twig with a leaf at each step.
fn leafy_twig<R: Rng + ?Sized>(rng: &mut R) -> String {
    let thickness = value(rng, 0.3..0.6);
    let steps = rng.random_range(3..=8);
    let bend = value(rng, -0.8..0.8);
    let roll = roll(rng);
    let angle = value(rng, 3.0..7.0);
    format!(
        "(Seq (Multiply Thickness {thickness}) (Repeat {steps} (Seq (RotateL {bend}) (Seq (Wait) \
         (Seq {roll} (PushPop (Seq (RotateL {angle}) (CreateAutomaton Leaf))))))))"
    )
}

/// A roll of 110° to 160° (around the golden angle, so laterals spiral), in two halves:
/// values stop at 10 units.
fn roll<R: Rng + ?Sized>(rng: &mut R) -> String {
    let half = value(rng, 5.5..8.0);
    format!("(Seq (RotateH {half}) (RotateH {half}))")
}

/// A random number in `range`, to two decimals (as programs print them).
fn value<R: Rng + ?Sized>(rng: &mut R, range: std::ops::Range<f64>) -> String {
    format!("{:.2}", rng.random_range(range))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::genome::AutomataGenome;
    use sylva_core::Plant;

    /// Ten segments or more, branches that reach past the trunk (the skeleton four times as
    /// wide as the thickest segment's end: the first starts at the full radius, a flare), and
    /// at least a quarter as tall as wide (a shrub may sprawl; a fan lies flat).
    fn stands_and_branches(plant: &Plant) -> bool {
        let mut skeleton = sylva_core::Aabb::EMPTY;
        let mut thickest = 0.0f32;
        for s in plant.segments() {
            skeleton.grow(s.start, 0.0);
            skeleton.grow(s.end, 0.0);
            thickest = thickest.max(s.end_radius);
        }
        let size = skeleton.size();
        let width = size.x.max(size.z);
        plant.segments().len() >= 10 && width >= 4.0 * thickest && 4.0 * size.y >= width
    }

    #[test]
    fn every_plan_parses_stands_and_branches() {
        for seed in 0..200 {
            let tree = random_tree(&mut sylva_core::rng::seeded(seed));
            let genome = AutomataGenome::with_growth(tree, Default::default());
            let plant = genome.develop(0).expect("a plan grows within the limits");
            assert!(stands_and_branches(&plant), "seed {seed}");
            assert!(!plant.organs().is_empty(), "seed {seed} bears leaves");
        }
    }
}
