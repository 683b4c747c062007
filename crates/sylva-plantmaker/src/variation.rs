//! Variation: the paper's three crossovers with dominance, mutation, the depth control and
//! lineage.
//!
//! **Crossover** takes two or more parents, each with a dominance weight; wherever a part is
//! drawn from "one parent or the other", parent `p` is chosen with probability
//! `dominance_p / Σ dominance` (all zero counts as all equal), so a more dominant parent
//! gives more genes. The three levels (Figure 9):
//!
//! - [`Level::Low`]: all branches, all fans and the seed from one parent, all
//!   inflorescences from another (both drawn by dominance, the second among the rest).
//! - [`Level::Medium`]: each segment (branch, fan, inflorescence) whole from a parent drawn
//!   for it; the seed likewise.
//! - [`Level::High`]: each variable of each segment from a parent drawn for it.
//!
//! Parents may differ in their numbers of segments: the child has the segment counts of the
//! most dominant parent (the first of equals), and each segment is drawn among the parents
//! that have it. A fan naming a branch beyond the child's count then names branch
//! `((b − 1) mod n) + 1`, and fan sets drop fans beyond the child's m, so the child is always
//! legal.
//!
//! **Mutation** ([`Mutation`]) visits every variable and the seed and changes each with
//! probability `rate` (the paper's intensity): numbers get noise of standard deviation
//! `spread` times their range, reflected at the ends (angles wrap around instead), colours
//! get noise per channel, options and branch numbers jump to another value, fan sets flip one
//! fan, the seed is drawn anew.
//!
//! **Depth** (the paper's footnote: one *Depth* value "translated to the proper level of
//! evolution, depending on the process selected"): [`Operator::from_depth`] maps a depth in
//! 0..=1 to low (below 1/3), medium (below 2/3) or high crossover, and for mutation to a rate
//! equal to the depth with a spread of `0.05 + 0.25 · depth`.
//!
//! **Lineage.** [`breed`] returns a [`Bred`]: the child, its operator and the parents that
//! gave it genes; [`Bred::origin`] turns that into a [`sylva_evolve::Origin`].
//! [`PlantMakerCrossover`] and [`Mutation`] implement the engine's [`Crossover`] and
//! [`Mutate`] traits.

use std::borrow::Cow;

use rand::{Rng, RngExt};
use sylva_evolve::{Crossover, IndividualId, Mutate, Origin};
pub use sylva_model::VariationError;

use crate::PlantMaker;
use crate::genes::{
    BRANCH_VARIABLES, Branch, FAN_VARIABLES, Fan, FanSet, GeneKind, INFLORESCENCE_VARIABLES,
    Inflorescence, Variable, mask_of,
};

/// How much of the genome crossover mixes (Figure 9).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Level {
    /// Branches and fans from one parent, inflorescences from another.
    Low,
    /// Whole segments from either parent.
    Medium,
    /// Single variables from either parent.
    High,
}

/// A parent and its dominance weight (any finite non-negative number; the more, the more
/// genes it gives).
pub type Parent<'a> = sylva_model::Parent<'a, PlantMaker>;

/// Mutation: each variable changes with probability `rate`, by noise of `spread` times its
/// range.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mutation {
    /// Probability that a variable (or the seed) changes, 0..=1. Default 0.1.
    pub rate: f64,
    /// Standard deviation of the noise as a fraction of the variable's range. Default 0.15.
    pub spread: f64,
}

impl Default for Mutation {
    fn default() -> Self {
        Mutation {
            rate: 0.1,
            spread: 0.15,
        }
    }
}

/// One variation operator with its settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operator {
    /// Crossover at a level.
    Crossover(Level),
    /// Mutation.
    Mutation(Mutation),
}

/// The process the depth control applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Process {
    /// Crossover: depth picks the level.
    Crossover,
    /// Mutation: depth sets the rate and spread.
    Mutation,
}

impl Operator {
    /// The paper's depth control: `depth` in 0..=1 (clamped) mapped to the level of the
    /// process (see the [module docs](self)).
    pub fn from_depth(process: Process, depth: f64) -> Operator {
        let d = if depth.is_nan() {
            0.0
        } else {
            depth.clamp(0.0, 1.0)
        };
        match process {
            Process::Crossover if d < 1.0 / 3.0 => Operator::Crossover(Level::Low),
            Process::Crossover if d < 2.0 / 3.0 => Operator::Crossover(Level::Medium),
            Process::Crossover => Operator::Crossover(Level::High),
            Process::Mutation => Operator::Mutation(Mutation {
                rate: d,
                spread: 0.05 + 0.25 * d,
            }),
        }
    }

    /// The name recorded in lineage: `crossover-low`, `crossover-medium`,
    /// `crossover-high` or `mutation`.
    pub fn name(&self) -> &'static str {
        match self {
            Operator::Crossover(Level::Low) => "crossover-low",
            Operator::Crossover(Level::Medium) => "crossover-medium",
            Operator::Crossover(Level::High) => "crossover-high",
            Operator::Mutation(_) => "mutation",
        }
    }
}

/// A child with its lineage.
#[derive(Clone, Debug, PartialEq)]
pub struct Bred {
    /// The child.
    pub genome: PlantMaker,
    /// How it was made.
    pub operator: Operator,
    /// Indices (into the parents given) of the parents that gave it genes, ascending.
    pub parents: Vec<usize>,
}

impl Bred {
    /// The engine's lineage record; `ids[i]` is the id of the `i`-th parent given.
    pub fn origin(&self, generation: u32, ids: &[IndividualId]) -> Origin {
        Origin {
            generation,
            operator: Cow::Borrowed(self.operator.name()),
            parents: self
                .parents
                .iter()
                .filter_map(|&p| ids.get(p).copied())
                .collect(),
        }
    }
}

/// Makes a child: crossover of two or more parents, or mutation of one (its dominance is
/// ignored).
pub fn breed<R: Rng + ?Sized>(
    parents: &[Parent],
    operator: Operator,
    rng: &mut R,
) -> Result<Bred, VariationError> {
    match operator {
        Operator::Crossover(level) => crossover(parents, level, rng),
        Operator::Mutation(m) => match parents {
            [p] => {
                let mut genome = p.genome.clone();
                m.mutate(&mut genome, rng);
                Ok(Bred {
                    genome,
                    operator,
                    parents: vec![0],
                })
            }
            _ => Err(VariationError::NotOneParent(parents.len())),
        },
    }
}

/// Draws a parent among those `allowed`, by dominance.
struct Picker {
    weights: Vec<f64>,
    used: Vec<bool>,
}

impl Picker {
    fn pick<R: Rng + ?Sized>(&mut self, allowed: impl Fn(usize) -> bool, rng: &mut R) -> usize {
        let candidates: Vec<usize> = (0..self.weights.len()).filter(|&p| allowed(p)).collect();
        let total: f64 = candidates.iter().map(|&p| self.weights[p]).sum();
        let chosen = if total > 0.0 {
            let mut x = rng.random::<f64>() * total;
            let mut chosen = candidates[candidates.len() - 1];
            for &p in &candidates {
                if self.weights[p] > 0.0 && x < self.weights[p] {
                    chosen = p;
                    break;
                }
                x -= self.weights[p];
            }
            chosen
        } else {
            candidates[rng.random_range(0..candidates.len())]
        };
        self.used[chosen] = true;
        chosen
    }
}

/// Crossover of two or more parents at `level` (see the [module docs](self)).
pub fn crossover<R: Rng + ?Sized>(
    parents: &[Parent],
    level: Level,
    rng: &mut R,
) -> Result<Bred, VariationError> {
    sylva_model::check_parents(parents)?;
    let mut picker = Picker {
        weights: parents.iter().map(|p| p.dominance).collect(),
        used: vec![false; parents.len()],
    };
    let g = |p: usize| parents[p].genome;
    // The most dominant parent, the first of equals, gives the segment counts.
    let lead = (0..parents.len()).fold(0, |best, p| {
        if parents[p].dominance > parents[best].dominance {
            p
        } else {
            best
        }
    });
    let mut child = g(lead).clone();
    match level {
        Level::Low => {
            let a = picker.pick(|_| true, rng);
            let b = picker.pick(|p| p != a, rng);
            child.seed = g(a).seed;
            child.branches = g(a).branches.clone();
            child.fans = g(a).fans.clone();
            child.inflorescences = g(b).inflorescences.clone();
        }
        Level::Medium | Level::High => {
            let whole = level == Level::Medium;
            child.seed = g(picker.pick(|_| true, rng)).seed;
            for i in 0..child.branches.len() {
                let has = |p: usize| g(p).branches.len() > i;
                child.branches[i] = if whole {
                    g(picker.pick(has, rng)).branches[i]
                } else {
                    let codes = mix(|p| g(p).branches[i].codes(), has, &mut picker, rng);
                    Branch::from_codes(&codes).unwrap_or(child.branches[i])
                };
            }
            // Branch references are made legal below, so fans read with the largest n.
            for i in 0..child.fans.len() {
                let has = |p: usize| g(p).fans.len() > i;
                child.fans[i] = if whole {
                    g(picker.pick(has, rng)).fans[i]
                } else {
                    let codes = mix(|p| g(p).fans[i].codes(), has, &mut picker, rng);
                    Fan::from_codes(&codes, crate::genes::MAX_BRANCHES).unwrap_or(child.fans[i])
                };
            }
            for i in 0..child.inflorescences.len() {
                let has = |p: usize| g(p).inflorescences.len() > i;
                child.inflorescences[i] = if whole {
                    g(picker.pick(has, rng)).inflorescences[i]
                } else {
                    let codes = mix(|p| g(p).inflorescences[i].codes(), has, &mut picker, rng);
                    Inflorescence::from_codes(&codes, crate::genes::MAX_FANS)
                        .unwrap_or(child.inflorescences[i])
                };
            }
        }
    }
    conform(&mut child);
    Ok(Bred {
        genome: child,
        operator: Operator::Crossover(level),
        parents: (0..parents.len()).filter(|&p| picker.used[p]).collect(),
    })
}

/// Each code from a parent drawn for it.
fn mix<const N: usize, R: Rng + ?Sized>(
    codes: impl Fn(usize) -> [u32; N],
    has: impl Fn(usize) -> bool + Copy,
    picker: &mut Picker,
    rng: &mut R,
) -> [u32; N] {
    let mut out = [0; N];
    for (i, slot) in out.iter_mut().enumerate() {
        *slot = codes(picker.pick(has, rng))[i];
    }
    out
}

/// Makes references legal in the child's own counts.
fn conform(g: &mut PlantMaker) {
    let (n, m) = (g.branches.len().max(1), g.fans.len());
    for f in &mut g.fans {
        let b = usize::from(f.branch.max(1));
        if b > n {
            f.branch = ((b - 1) % n + 1) as u8;
        }
    }
    for i in &mut g.inflorescences {
        i.fans = FanSet(i.fans.0 & mask_of(m));
    }
}

/// A standard normal deviate, near enough: the sum of four uniforms, rescaled.
fn gauss<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    let s: f64 = (0..4).map(|_| rng.random::<f64>()).sum();
    (s - 2.0) * 3f64.sqrt()
}

/// `v` folded back into `lo..=hi` at both ends.
fn reflect(v: i64, lo: u32, hi: u32) -> u32 {
    let (lo, hi) = (i64::from(lo), i64::from(hi));
    if hi <= lo {
        return lo as u32;
    }
    let period = 2 * (hi - lo);
    let x = (v - lo).rem_euclid(period);
    (lo + if x > hi - lo { period - x } else { x }) as u32
}

/// A non-zero whole-number step of about `sigma`.
fn step<R: Rng + ?Sized>(sigma: f64, rng: &mut R) -> i64 {
    let d = (gauss(rng) * sigma).round() as i64;
    if d != 0 {
        d
    } else if rng.random_bool(0.5) {
        1
    } else {
        -1
    }
}

/// Another code for one variable.
fn mutate_code<R: Rng + ?Sized>(
    v: &Variable,
    code: u32,
    (n, m): (usize, usize),
    spread: f64,
    rng: &mut R,
) -> u32 {
    let (lo, hi) = v.range(n, m);
    match v.kind {
        GeneKind::Choice | GeneKind::Branch => {
            if hi <= lo {
                return code;
            }
            let r = rng.random_range(lo..hi);
            if r >= code { r + 1 } else { r }
        }
        GeneKind::Integer => {
            let sigma = spread * f64::from(hi - lo);
            reflect(i64::from(code) + step(sigma, rng), lo, hi)
        }
        GeneKind::Angle => {
            let sigma = spread * 360.0;
            (i64::from(code) + step(sigma, rng)).rem_euclid(360) as u32
        }
        GeneKind::Color => {
            let mut channels = [(code >> 16) & 255, (code >> 8) & 255, code & 255];
            let forced = rng.random_range(0..3);
            for (i, c) in channels.iter_mut().enumerate() {
                let d = if i == forced {
                    step(spread * 255.0, rng)
                } else {
                    (gauss(rng) * spread * 255.0).round() as i64
                };
                *c = reflect(i64::from(*c) + d, 0, 255);
            }
            (channels[0] << 16) | (channels[1] << 8) | channels[2]
        }
        GeneKind::FanSet => {
            if m == 0 {
                return code;
            }
            code ^ (1 << rng.random_range(0..m.min(32)))
        }
    }
}

fn mutate_codes<const N: usize, R: Rng + ?Sized>(
    codes: &mut [u32; N],
    table: &[Variable; N],
    shape: (usize, usize),
    m: &Mutation,
    rng: &mut R,
) {
    for (code, v) in codes.iter_mut().zip(table) {
        if rng.random_bool(m.rate) {
            *code = mutate_code(v, *code, shape, m.spread, rng);
        }
    }
}

impl Mutate<PlantMaker> for Mutation {
    /// Mutates every variable and the seed with probability `rate` (clamped to 0..=1).
    fn mutate<R: Rng + ?Sized>(&self, genome: &mut PlantMaker, rng: &mut R) {
        let m = Mutation {
            rate: if self.rate.is_nan() {
                0.0
            } else {
                self.rate.clamp(0.0, 1.0)
            },
            spread: if self.spread.is_finite() {
                self.spread.max(0.0)
            } else {
                0.0
            },
        };
        conform(genome);
        let shape = (genome.branches.len(), genome.fans.len());
        if rng.random_bool(m.rate) {
            genome.seed = rng.random();
        }
        for b in &mut genome.branches {
            let mut c = b.codes();
            mutate_codes(&mut c, &BRANCH_VARIABLES, shape, &m, rng);
            if let Ok(x) = Branch::from_codes(&c) {
                *b = x;
            }
        }
        for f in &mut genome.fans {
            let mut c = f.codes();
            mutate_codes(&mut c, &FAN_VARIABLES, shape, &m, rng);
            if let Ok(x) = Fan::from_codes(&c, shape.0) {
                *f = x;
            }
        }
        for i in &mut genome.inflorescences {
            let mut c = i.codes();
            mutate_codes(&mut c, &INFLORESCENCE_VARIABLES, shape, &m, rng);
            if let Ok(x) = Inflorescence::from_codes(&c, shape.1) {
                *i = x;
            }
        }
    }
}

/// The engine's two-parent crossover: equal dominance at a fixed level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlantMakerCrossover {
    /// The level.
    pub level: Level,
}

impl Crossover<PlantMaker> for PlantMakerCrossover {
    fn crossover<R: Rng + ?Sized>(
        &self,
        a: &PlantMaker,
        b: &PlantMaker,
        rng: &mut R,
    ) -> PlantMaker {
        let parents = [
            Parent {
                genome: a,
                dominance: 1.0,
            },
            Parent {
                genome: b,
                dominance: 1.0,
            },
        ];
        crossover(&parents, self.level, rng)
            .expect("two parents of equal, finite dominance")
            .genome
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflect_folds() {
        assert_eq!(reflect(5, 1, 10), 5);
        assert_eq!(reflect(12, 1, 10), 8);
        assert_eq!(reflect(-1, 1, 10), 3);
        assert_eq!(reflect(7, 4, 4), 4);
    }

    #[test]
    fn depth_maps_to_levels() {
        assert_eq!(
            Operator::from_depth(Process::Crossover, 0.1),
            Operator::Crossover(Level::Low)
        );
        assert_eq!(
            Operator::from_depth(Process::Crossover, 0.5),
            Operator::Crossover(Level::Medium)
        );
        assert_eq!(
            Operator::from_depth(Process::Crossover, 0.9),
            Operator::Crossover(Level::High)
        );
        let Operator::Mutation(m) = Operator::from_depth(Process::Mutation, 0.4) else {
            panic!("mutation expected")
        };
        assert_eq!(m.rate, 0.4);
    }

    #[test]
    fn dominance_is_checked() {
        let g = PlantMaker::default();
        let parents = [
            Parent {
                genome: &g,
                dominance: 1.0,
            },
            Parent {
                genome: &g,
                dominance: -1.0,
            },
        ];
        let mut rng = sylva_core::rng::seeded(0);
        assert!(matches!(
            crossover(&parents, Level::High, &mut rng),
            Err(VariationError::BadDominance { parent: 1, .. })
        ));
        assert_eq!(
            crossover(&parents[..1], Level::High, &mut rng),
            Err(VariationError::TooFewParents(1))
        );
    }
}
