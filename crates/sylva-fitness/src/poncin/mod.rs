//! Poncin's fitness for GP-grown trees (*Evolving 3D Models of Trees Using Genetic
//! Programming*, section 4.4), each term its own function of a [`Plant`], reported by name.
//!
//! | term | what | formula (paper units) |
//! | --- | --- | --- |
//! | [`f_pos`] | endpoints on the target surface | mean distance of the endpoints to a [`TargetShape`] |
//! | [`f_num`] | number of branches | `abs(30 − N)`, or per branch level ([`NumTarget`]) |
//! | [`f_dist`] | endpoints far apart | mean of `200 / (‖A − B‖ + 5)` over pairs ([`pairs`]) |
//! | [`f_angle`] | branches pointing apart | mean of `200 / (θ° + 5)` over pairs ([`pairs`]) |
//! | [`f_thick`] | thinning branches | mean `abs(thickness − reference(level))` over the endpoints, or along a taper ([`ThickMeasure`]), plus a penalty per negative thickness ([`ThickOptions`]) |
//! | [`f_grid`] | leaves in favoured cells, none in forbidden ones | a cost in 0..=100 from the paper's `F_cell` ([`grid`]) |
//!
//! All terms are costs (0 is perfect). [`PoncinFitness::score`] computes them together,
//! without allocating (given a [`PoncinScratch`]), and adds them up:
//!
//! ```text
//! F = w_pos·F_pos + w_num·F_num + w_dist·F_dist + w_thick·F_thick + w_angle·F_angle + w_grid·F_grid
//! adjusted fitness = 1 / (1 + F)      (higher is better; lilgp's, and Sylva's Fitness::total)
//! ```
//!
//! **Endpoints** are [`Plant::tips`] (ends of segments with no children), their **level**
//! the segment's branch order; **leaves** are organs of kind [`OrganKind::Leaf`].
//!
//! **Units.** Plants are in metres, the paper's formulas in its own units: every term divides
//! plant coordinates by [`PoncinFitness::unit`] (metres per paper unit, default 0.1), so the
//! paper's constants (the sphere of radius 150 at (0, 200, 0), F_dist's `200 / (d + 5)`)
//! apply verbatim and values compare with the paper's Table 2.
//!
//! **Guides.** [`guides::of`] draws a fitness's target surface and forbidden cells as wire
//! frames, for pictures.
//!
//! **Gating.** F_grid counts only once the weighted sum of the other terms is below
//! [`PoncinFitness::grid_gate`]; until then it is at its maximum, 100 (section 4.4.4).
//!
//! **Weights.** The default [`PoncinWeights`] are the text's (section 4.4.3): 5, 50, 500,
//! 1000, with F_angle and F_grid off. Table 2 adds up with w_dist = 200, w_grid = 10 and no
//! thickness term: [`PoncinWeights::TABLE_2`].
//!
//! ```
//! use sylva_core::{Plant, PlantMeta, glam::Vec3};
//! use sylva_fitness::poncin::{PoncinContext, PoncinFitness, PoncinScratch, TERM_NAMES};
//!
//! let config: PoncinFitness = toml::from_str(r#"
//!     num_target = 2
//!     [weights]
//!     dist = 200
//!     [target]
//!     shape = "sphere"
//!     radius = 150
//! "#)?;
//!
//! // A trunk that goes on to 35 m with a branch at 20 m, in metres: both ends lie on the
//! // paper's sphere (15 m from its centre, 20 m up).
//! let mut plant = Plant::new(PlantMeta::default());
//! let top = Vec3::new(0.0, 20.0, 0.0);
//! let trunk = plant.add_segment(Vec3::ZERO, top, (0.3, 0.05), None, false, Plant::BARK)?;
//! plant.add_segment(top, top + Vec3::new(0.0, 15.0, 0.0), (0.05, 0.05), Some(trunk), false, Plant::BARK)?;
//! plant.add_segment(top, top + Vec3::new(15.0, 0.0, 0.0), (0.05, 0.03), Some(trunk), true, Plant::BARK)?;
//!
//! let mut scratch = PoncinScratch::new();
//! let score = config.score(&plant, PoncinContext::default(), &mut scratch);
//! assert_eq!(score.branches, 2);
//! assert_eq!(score.num, 0.0);
//! assert!(score.pos < 1e-5); // both endpoints are on the sphere
//! assert_eq!(score.terms().len(), TERM_NAMES.len());
//! assert!(score.adjusted() > 0.0 && score.adjusted() < 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod endpoints;
pub mod grid;
pub mod guides;
pub mod pairs;
pub mod shape;

use std::fmt;

use glam::DVec3;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Serialize, Serializer};
use sylva_core::{OrganKind, Plant, ranged};

pub use endpoints::{Endpoint, EndpointRule, PoncinScratch};
pub use grid::{
    DensityGrid, GRID_MAX, GridBox, GridCell, GridConfig, GridError, PAPER_TARGET, cell_error,
    f_cell,
};
pub use pairs::{PairMode, PairOptions, Spread, WORST_PAIR};
pub use shape::TargetShape;

ranged!(unit: f64, "unit", 1e-6, 1e6, " metres per paper unit");
ranged!(weight: f64, "weight", 0.0, 1e6, "");
ranged!(gate: f64, "grid_gate", 0.0, 1e15, "");
ranged!(radius_per_thickness: f64, "radius_per_thickness", 1e-6, 1e3, " metres");
ranged!(penalty: f64, "negative_penalty", 0.0, 1e6, "");
ranged!(tip_ratio: f64, "tip_ratio", 0.0, 1.0, "");
ranged!(step_ratio: f64, "step_ratio", 0.0, 1.0, "");

fn references<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    sylva_core::ranged::list(d, "references", 0.0, 1.0, MAX_LEVELS)
}

/// Most branch levels a per-level list may name.
pub const MAX_LEVELS: usize = 16;

/// Largest target number of endpoints.
pub const MAX_NUM_TARGET: u32 = 1_000_000;

/// Names of the reported terms, in the order of [`PoncinScore::terms`]: the paper's Table 2
/// columns (branches, F_pos, F_num, F_dist, F_thick, F_grid, F_total), F_angle, and two
/// counts for the grid.
pub const TERM_NAMES: [&str; 10] = [
    "branches",
    "leaves",
    "forbidden_leaves",
    "f_pos",
    "f_num",
    "f_dist",
    "f_angle",
    "f_thick",
    "f_grid",
    "f_total",
];

/// The weights of the six terms (all ≥ 0, so the total is ≥ 0).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PoncinWeights {
    /// w_pos. Default 5.
    #[serde(deserialize_with = "weight")]
    pub pos: f64,
    /// w_num. Default 50.
    #[serde(deserialize_with = "weight")]
    pub num: f64,
    /// w_dist. Default 500.
    #[serde(deserialize_with = "weight")]
    pub dist: f64,
    /// w_thick. Default 1000.
    #[serde(deserialize_with = "weight")]
    pub thick: f64,
    /// w_angle. Default 0 (the paper gives none).
    #[serde(deserialize_with = "weight")]
    pub angle: f64,
    /// w_grid. Default 0 (the paper's Table 2 uses 10).
    #[serde(deserialize_with = "weight")]
    pub grid: f64,
}

impl PoncinWeights {
    /// The weights of the paper's text (section 4.4.3): 5, 50, 500, 1000; no angle, no grid.
    pub const TEXT: PoncinWeights = PoncinWeights {
        pos: 5.0,
        num: 50.0,
        dist: 500.0,
        thick: 1000.0,
        angle: 0.0,
        grid: 0.0,
    };

    /// The weights Table 2's totals add up with (section 5.4): 5, 50, 200, no thickness,
    /// grid 10.
    pub const TABLE_2: PoncinWeights = PoncinWeights {
        pos: 5.0,
        num: 50.0,
        dist: 200.0,
        thick: 0.0,
        angle: 0.0,
        grid: 10.0,
    };

    /// Weighted sum of every term but F_grid (what the grid gate compares).
    pub fn rest(&self, s: &PoncinScore) -> f64 {
        self.pos * s.pos
            + self.num * s.num
            + self.dist * s.dist
            + self.thick * s.thick
            + self.angle * s.angle
    }

    /// Weighted sum of all terms.
    pub fn total(&self, s: &PoncinScore) -> f64 {
        self.rest(s) + self.grid * s.grid
    }
}

impl Default for PoncinWeights {
    fn default() -> Self {
        Self::TEXT
    }
}

/// F_num's target: a number of endpoints, or one per branch level.
///
/// Written as a number (`num_target = 30`) or a list (`num_target = [1, 30]`). With a list,
/// entry `k` is the target number of endpoints of level `k` (0 is the trunk), F_num is the
/// sum over the listed levels of `|target_k − N_k|`, and endpoints of deeper levels count
/// against a target of 0: the list's length is the paper's "level of branch recursion". The
/// sum keeps the scale of the single-number form, so the same weight serves both.
///
/// Per-level counts can be met by a tree whose sub-branches all crowd onto one or two
/// branches. Sylva's third form, a table (`num_target = { branches = 8, each = 4 }`), asks
/// for `branches` first-order branches with at least `each` sub-branches on every one, in
/// two stages. Until the per-level counts are met, F_num is the per-level form's
/// `|branches − N₁| + |branches · each − N₂|` plus every endpoint deeper than level 2, plus
/// `branches · each`; once they are, it is the branches' shortfall, the sum of
/// `max(0, each − n_b)` over the first-order branches (`n_b` the sub-branch ends of `b`),
/// which is at most `branches · each`. So every tree that meets the counts beats every
/// tree that does not, the road out of the two-endpoint trap stays the per-level form's
/// (a branch may sprout many sub-branches first), and the spread is sorted out last. It
/// reads the ends of first-order branches, so it is meant for `endpoints = "axes"` (one per
/// automaton instance), where every branch has one.
#[derive(Clone, Debug, PartialEq)]
pub enum NumTarget {
    /// Target number of endpoints of any level. The paper's 30.
    Total(u32),
    /// Target number of endpoints of each level, from the trunk's (1 to 16 levels).
    PerLevel(Vec<u32>),
    /// Target first-order branches, and sub-branches on each of them.
    PerBranch {
        /// First-order branches.
        branches: u32,
        /// Sub-branches on each first-order branch.
        each: u32,
    },
}

impl Default for NumTarget {
    fn default() -> Self {
        NumTarget::Total(30)
    }
}

impl NumTarget {
    /// F_num for these endpoints.
    pub fn deviation(&self, endpoints: &[Endpoint]) -> f64 {
        let off = |target: u32, count: usize| (f64::from(target) - count as f64).abs();
        match self {
            NumTarget::Total(t) => off(*t, endpoints.len()),
            NumTarget::PerLevel(targets) => {
                let listed: f64 = targets
                    .iter()
                    .enumerate()
                    .map(|(k, &t)| {
                        off(
                            t,
                            endpoints.iter().filter(|e| e.level as usize == k).count(),
                        )
                    })
                    .sum();
                let deeper = endpoints
                    .iter()
                    .filter(|e| e.level as usize >= targets.len())
                    .count();
                listed + deeper as f64
            }
            NumTarget::PerBranch { branches, each } => {
                let (branches, each) = (f64::from(*branches), f64::from(*each));
                let (mut first, mut second, mut deeper, mut short) = (0.0, 0.0, 0.0, 0.0);
                for e in endpoints {
                    match e.level {
                        0 => {}
                        1 => {
                            first += 1.0;
                            short += (each - f64::from(e.sub_branches)).max(0.0);
                        }
                        2 => second += 1.0,
                        _ => deeper += 1.0,
                    }
                }
                let counts = (branches - first).abs() + (branches * each - second).abs() + deeper;
                // Two stages: the spread counts once the counts are met, and every tree that
                // meets them beats every tree that does not (the shortfall is at most
                // `branches · each`).
                if counts == 0.0 {
                    short
                } else {
                    counts + branches * each
                }
            }
        }
    }
}

impl Serialize for NumTarget {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            NumTarget::Total(t) => s.serialize_u32(*t),
            NumTarget::PerLevel(v) => v.serialize(s),
            NumTarget::PerBranch { branches, each } => {
                let mut map = s.serialize_map(Some(2))?;
                map.serialize_entry("branches", branches)?;
                map.serialize_entry("each", each)?;
                map.end()
            }
        }
    }
}

impl<'de> Deserialize<'de> for NumTarget {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        fn check<E: de::Error>(v: i64) -> Result<u32, E> {
            if (0..=i64::from(MAX_NUM_TARGET)).contains(&v) {
                Ok(v as u32)
            } else {
                Err(E::custom(format!(
                    "`num_target` entries must be whole numbers from 0 to {MAX_NUM_TARGET}, got {v}"
                )))
            }
        }
        impl<'de> Visitor<'de> for V {
            type Value = NumTarget;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a number of endpoints, a list of them per branch level, or a table \
                     { branches = N, each = M }",
                )
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<NumTarget, E> {
                check(v).map(NumTarget::Total)
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<NumTarget, E> {
                check(i64::try_from(v).unwrap_or(i64::MAX)).map(NumTarget::Total)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<NumTarget, A::Error> {
                let mut levels = Vec::new();
                while let Some(v) = seq.next_element::<i64>()? {
                    levels.push(check(v)?);
                }
                if levels.is_empty() || levels.len() > MAX_LEVELS {
                    return Err(de::Error::custom(format!(
                        "`num_target` must list 1 to {MAX_LEVELS} levels, got {}",
                        levels.len()
                    )));
                }
                Ok(NumTarget::PerLevel(levels))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<NumTarget, A::Error> {
                let (mut branches, mut each) = (None, None);
                while let Some(key) = map.next_key::<String>()? {
                    let slot = match key.as_str() {
                        "branches" => &mut branches,
                        "each" => &mut each,
                        other => {
                            return Err(de::Error::custom(format!(
                                "unknown field `{other}` in `num_target`, expected `branches` \
                                 or `each`"
                            )));
                        }
                    };
                    *slot = Some(check(map.next_value::<i64>()?)?);
                }
                match (branches, each) {
                    (Some(branches), Some(each)) => Ok(NumTarget::PerBranch { branches, each }),
                    _ => Err(de::Error::custom(
                        "`num_target` as a table needs both `branches` and `each`",
                    )),
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// F_thick's references and the conversion from radius back to thickness.
///
/// The automata simulator carries a thickness (1 at the trunk's base, mapped into 0.1..1,
/// section 5.2) and stores `radius = thickness × radius_per_thickness`; F_thick divides an
/// endpoint's end radius by the same scale to get its thickness back. A negative thickness
/// cannot be a radius, so the grower counts its occurrences and passes the count in
/// [`PoncinContext::negative_thickness`]; each adds `negative_penalty`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ThickOptions {
    /// Ideal thickness at the end of each level's branches, from the trunk's (0 to 1,
    /// 1 to 16 entries). Default `[1/6, 1/9, 1/12]`. Past the list the reciprocals keep
    /// their last step (6, 9, 12 → 15, 18, …); with one entry, or steps that do not grow,
    /// the last entry holds.
    #[serde(deserialize_with = "references")]
    pub references: Vec<f64>,
    /// Metres of radius at thickness 1; must match the grower's. Default 0.3.
    #[serde(deserialize_with = "radius_per_thickness")]
    pub radius_per_thickness: f64,
    /// Added to F_thick per negative-thickness occurrence. Default 1 (the largest deviation
    /// one endpoint can have in 0..1).
    #[serde(deserialize_with = "penalty")]
    pub negative_penalty: f64,
    /// What is compared with the references. Default [`ThickMeasure::Endpoints`] (the
    /// paper's).
    pub measure: ThickMeasure,
    /// The bars measure's thickest allowed tip, as a share of the foot's, 0 to 1. Default
    /// 0.25 (issue 14's bar); a little less leaves evolution a margin below the bar.
    #[serde(deserialize_with = "tip_ratio", skip_serializing_if = "is_quarter")]
    pub tip_ratio: f64,
    /// The bars measure's smallest allowed step from one radius to the next along a path,
    /// as a share of the one before, 0 to 1. Default 0.5 (issue 14's bar); a little more
    /// leaves evolution a margin above the bar.
    #[serde(deserialize_with = "step_ratio", skip_serializing_if = "is_half")]
    pub step_ratio: f64,
}

/// The default ratios stay out of written configs, so they keep their bytes.
fn is_quarter(ratio: &f64) -> bool {
    *ratio == 0.25
}

fn is_half(ratio: &f64) -> bool {
    *ratio == 0.5
}

/// What F_thick compares with its references.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ThickMeasure {
    /// Each endpoint's thickness against its level's reference (section 4.4.2). A tree that
    /// thins every branch to the minimum just above its foot meets it: only the ends count.
    #[default]
    Endpoints,
    /// Every segment's end against a taper from the foot: the reference falls geometrically
    /// with path length from the foot, from 1 there to the farthest tip's level reference
    /// (`thickness = tip^(d / D)`, as a per-step `Multiply Thickness` gives); the mean
    /// deviation weighted by segment length. Rewards thinning gradually from trunk to twigs.
    /// Sylva's, not the paper's. (A taper along each axis from where it starts was tried
    /// first: evolution met it with a short tapering trunk that all branches hang from.)
    Taper,
    /// How far the plant is from issue 14's taper bars: rises in thickness, steps to less
    /// than half, and tips thicker than a quarter of the foot, per tip (see
    /// [`PoncinScratch::bars_deviation`]); 0 when every bar is met. Sylva's, not the
    /// paper's.
    Bars,
    /// [`ThickMeasure::Taper`] plus [`ThickMeasure::Bars`]: the bars, and a taper that
    /// falls all the way along each path rather than in a few steps near the foot.
    Gradual,
}

impl Default for ThickOptions {
    fn default() -> Self {
        ThickOptions {
            references: vec![1.0 / 6.0, 1.0 / 9.0, 1.0 / 12.0],
            radius_per_thickness: 0.3,
            negative_penalty: 1.0,
            measure: ThickMeasure::Endpoints,
            tip_ratio: 0.25,
            step_ratio: 0.5,
        }
    }
}

impl ThickOptions {
    /// The reference thickness of level `level` (see [`ThickOptions::references`]).
    pub fn reference(&self, level: u16) -> f64 {
        let r = &self.references;
        let (k, n) = (usize::from(level), r.len());
        if k < n {
            return r[k];
        }
        let Some(&last) = r.last() else {
            return 0.0;
        };
        if n >= 2 && last > 0.0 && r[n - 2] > 0.0 {
            let step = 1.0 / last - 1.0 / r[n - 2];
            if step > 0.0 {
                return 1.0 / (1.0 / last + step * (k + 1 - n) as f64);
            }
        }
        last
    }

    /// F_thick: mean `|thickness − reference(level)|` over the endpoints (0 without any),
    /// plus `negative_penalty` per negative-thickness occurrence.
    pub fn deviation(&self, endpoints: &[Endpoint], negative_thickness: u32) -> f64 {
        let mean = if endpoints.is_empty() {
            0.0
        } else {
            endpoints
                .iter()
                .map(|e| (e.radius / self.radius_per_thickness - self.reference(e.level)).abs())
                .sum::<f64>()
                / endpoints.len() as f64
        };
        mean + self.negative_penalty * f64::from(negative_thickness)
    }
}

/// F_pos: mean distance of the endpoints to the shape, paper units. A plant without
/// endpoints is scored at its foot, the origin.
pub fn mean_distance(shape: &TargetShape, endpoints: &[Endpoint]) -> f64 {
    if endpoints.is_empty() {
        return shape.distance(DVec3::ZERO);
    }
    endpoints
        .iter()
        .map(|e| shape.distance(e.position))
        .sum::<f64>()
        / endpoints.len() as f64
}

/// What an evaluation knows besides the plant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PoncinContext {
    /// Seed of the sampled pairs (see [`pairs`]); derive it from the run seed, generation
    /// and slot so re-evaluations draw new pairs. Unused when pairs are exact.
    pub seed: u64,
    /// Negative-thickness occurrences the grower reported (the automata simulator counts
    /// each recorded position whose thickness fell below zero).
    pub negative_thickness: u32,
}

/// Every term of one evaluation, by name; F values are raw (unweighted).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoncinScore {
    /// Number of endpoints (Table 2's "branches").
    pub branches: usize,
    /// Number of leaves.
    pub leaves: usize,
    /// Leaves in forbidden grid cells (0 without a grid), counted even while the grid is
    /// gated off.
    pub forbidden_leaves: usize,
    /// F_pos, paper units.
    pub pos: f64,
    /// F_num.
    pub num: f64,
    /// F_dist.
    pub dist: f64,
    /// F_angle (0 while its weight is 0: it is not computed).
    pub angle: f64,
    /// F_thick.
    pub thick: f64,
    /// F_grid in 0..=100 (0 without a grid; 100 while gated off).
    pub grid: f64,
    /// Whether the grid was past its gate and counted.
    pub grid_counted: bool,
    /// F, the weighted total (≥ 0; infinite if a term was NaN).
    pub total: f64,
}

impl PoncinScore {
    /// lilgp's adjusted fitness, `1 / (1 + F)`, in 0..=1 and higher for better trees: the
    /// total to give `sylva_evolve::Fitness`, with [`PoncinScore::terms`] as its terms.
    pub fn adjusted(&self) -> f64 {
        1.0 / (1.0 + self.total)
    }

    /// The reported terms in [`TERM_NAMES`] order.
    pub fn terms(&self) -> [f64; 10] {
        [
            self.branches as f64,
            self.leaves as f64,
            self.forbidden_leaves as f64,
            self.pos,
            self.num,
            self.dist,
            self.angle,
            self.thick,
            self.grid,
            self.total,
        ]
    }
}

/// Poncin's fitness: targets, options and weights. Every field has a default, so a config
/// names only what it changes; unknown fields and out-of-range values are refused.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PoncinFitness {
    /// Metres per paper unit. Default 0.1 (the paper's sphere is then 15 m in radius,
    /// centred 20 m up).
    #[serde(deserialize_with = "unit")]
    pub unit: f64,
    /// Term weights. Default [`PoncinWeights::TEXT`].
    pub weights: PoncinWeights,
    /// F_pos's surface. Default the paper's sphere.
    pub target: TargetShape,
    /// F_num's target. Default 30 endpoints.
    pub num_target: NumTarget,
    /// What an endpoint is. Default [`EndpointRule::Tips`].
    pub endpoints: EndpointRule,
    /// Pairs for F_dist and F_angle. Default exact up to 64 endpoints.
    pub pairs: PairOptions,
    /// F_thick's references and radius scale.
    pub thick: ThickOptions,
    /// The density grid; none by default (F_grid is then 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid: Option<DensityGrid>,
    /// F_grid counts only while the weighted sum of the other terms is below this.
    /// Default 1500: Table 2's totals put the paper's gate between 1215 (generation 8, grid
    /// counted) and 1555 (generation 2, grid at 100).
    #[serde(deserialize_with = "gate")]
    pub grid_gate: f64,
}

impl Default for PoncinFitness {
    fn default() -> Self {
        PoncinFitness {
            unit: 0.1,
            weights: PoncinWeights::TEXT,
            target: TargetShape::default(),
            num_target: NumTarget::default(),
            endpoints: EndpointRule::Tips,
            pairs: PairOptions::default(),
            thick: ThickOptions::default(),
            grid: None,
            grid_gate: 1500.0,
        }
    }
}

/// NaN becomes +∞, the worst cost, so a broken plant can never win.
fn sane(x: f64) -> f64 {
    if x.is_nan() { f64::INFINITY } else { x }
}

impl PoncinFitness {
    /// Scores a plant. Allocates nothing once `scratch` has grown to the plant's size.
    pub fn score(
        &self,
        plant: &Plant,
        ctx: PoncinContext,
        scratch: &mut PoncinScratch,
    ) -> PoncinScore {
        scratch.read(plant, self.unit, self.endpoints);
        let ends = &scratch.endpoints;
        let spread = self
            .pairs
            .spread(scratch, ctx.seed, self.weights.angle > 0.0);
        let mut s = PoncinScore {
            branches: ends.len(),
            leaves: plant
                .organs()
                .iter()
                .filter(|o| o.kind == OrganKind::Leaf)
                .count(),
            pos: sane(mean_distance(&self.target, ends)),
            num: self.num_target.deviation(ends),
            dist: sane(spread.dist),
            angle: sane(spread.angle),
            ..PoncinScore::default()
        };
        s.thick = sane(match self.thick.measure {
            ThickMeasure::Endpoints => self.thick.deviation(ends, ctx.negative_thickness),
            ThickMeasure::Taper | ThickMeasure::Bars | ThickMeasure::Gradual => {
                scratch.thick_measure(plant, &self.thick)
                    + self.thick.negative_penalty * f64::from(ctx.negative_thickness)
            }
        });
        let rest = self.weights.rest(&s);
        if let Some(grid) = &self.grid {
            grid.count_leaves(plant, self.unit, &mut scratch.cells);
            s.forbidden_leaves = grid.forbidden_leaves(&scratch.cells);
            s.grid_counted = rest < self.grid_gate;
            s.grid = if s.grid_counted {
                grid.cost(&scratch.cells)
            } else {
                GRID_MAX
            };
        }
        s.total = sane(self.weights.total(&s));
        s
    }

    /// [`PoncinFitness::score`] with fresh buffers, for one-off use.
    pub fn score_once(&self, plant: &Plant, ctx: PoncinContext) -> PoncinScore {
        self.score(plant, ctx, &mut PoncinScratch::new())
    }
}

fn endpoints_of(plant: &Plant, unit: f64) -> Vec<Endpoint> {
    read(plant, unit).endpoints
}

fn read(plant: &Plant, unit: f64) -> PoncinScratch {
    let mut scratch = PoncinScratch::new();
    scratch.read(plant, unit, EndpointRule::Tips);
    scratch
}

/// F_pos of a plant: mean distance of its endpoints to `shape`, in paper units of `unit`
/// metres.
pub fn f_pos(plant: &Plant, shape: &TargetShape, unit: f64) -> f64 {
    mean_distance(shape, &endpoints_of(plant, unit))
}

/// F_num of a plant (see [`NumTarget`]).
pub fn f_num(plant: &Plant, target: &NumTarget) -> f64 {
    target.deviation(&endpoints_of(plant, 1.0))
}

/// F_dist of a plant, in paper units of `unit` metres (see [`pairs`]).
pub fn f_dist(plant: &Plant, unit: f64, pairs: &PairOptions, seed: u64) -> f64 {
    pairs.spread(&read(plant, unit), seed, false).dist
}

/// F_angle of a plant (see [`pairs`]).
pub fn f_angle(plant: &Plant, pairs: &PairOptions, seed: u64) -> f64 {
    pairs.spread(&read(plant, 1.0), seed, true).angle
}

/// F_thick of a plant (see [`ThickOptions`] and [`ThickMeasure`]).
pub fn f_thick(plant: &Plant, thick: &ThickOptions, negative_thickness: u32) -> f64 {
    let penalty = thick.negative_penalty * f64::from(negative_thickness);
    match thick.measure {
        ThickMeasure::Endpoints => thick.deviation(&endpoints_of(plant, 1.0), negative_thickness),
        _ => read(plant, 1.0).thick_measure(plant, thick) + penalty,
    }
}

/// F_grid of a plant, ungated: the grid's cost in 0..=100 (see [`grid`]).
pub fn f_grid(plant: &Plant, grid: &DensityGrid, unit: f64) -> f64 {
    let mut counts = Vec::new();
    grid.count_leaves(plant, unit, &mut counts);
    grid.cost(&counts)
}
