//! F_dist and F_angle: how spread out the endpoints are, averaged over pairs of endpoints.
//!
//! ```text
//! F_dist  = mean over pairs {A, B} of 200 / (‖A − B‖ + 5)     (paper units)
//! F_angle = mean over pairs {A, B} of 200 / (θ_AB + 5)         (θ in degrees)
//! ```
//!
//! F_dist is the paper's. The paper only says F_angle is "very similar, except it is based on
//! the angles" between branches; Sylva takes the same formula with the angle, in degrees,
//! between the two branches' directions, each from the base of its axis to its endpoint (see
//! [`Endpoint::direction`](super::Endpoint::direction)). Both range from about 1 (far apart, or opposite) up to 40
//! (coincident); a branch without length has no direction and counts as coinciding with
//! every other.
//!
//! Pairs are two *different* endpoints (a pair of an endpoint with itself would add a
//! constant 40 and keep Table 2's F_dist of 0.7 out of reach). With fewer than two
//! endpoints there is no pair, and both terms take their worst value, 40, so that a single
//! stem never looks better spread than a tree.
//!
//! **Which pairs.** The paper samples `max(3N, 10)` random pairs (with replacement) to save
//! time, and reports about 20% error and "some individuals being wrongly marked as very
//! good". [`PairMode::Sampled`] does that, drawing from a ChaCha8 generator seeded by the
//! caller, so a score is reproducible for a given seed. Runs should re-evaluate every
//! generation with a fresh seed rather than cache a sampled score. [`PairMode::Exact`] takes
//! all `N(N−1)/2` pairs: 435 for the paper's 30 endpoints, about a microsecond.
//! [`PairMode::Auto`], the default, is exact up to [`PairOptions::exact_up_to`] endpoints
//! (64, 2016 pairs) and samples beyond.

use glam::DVec3;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};
use sylva_core::rng::ChaCha8Rng;

use super::endpoints::PoncinScratch;

/// The value of either term for coincident endpoints, and with fewer than two.
pub const WORST_PAIR: f64 = 200.0 / 5.0;

sylva_core::ranged!(exact_up_to: u32, "exact_up_to", 0, 100_000);
sylva_core::ranged!(per_endpoint: u32, "per_endpoint", 1, 10_000);
sylva_core::ranged!(min_pairs: u32, "min_pairs", 1, 10_000_000);

/// How pairs of endpoints are chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PairMode {
    /// Every pair.
    Exact,
    /// `max(per_endpoint · N, min_pairs)` random pairs.
    Sampled,
    /// Exact up to `exact_up_to` endpoints, sampled beyond.
    #[default]
    Auto,
}

/// Pair selection for F_dist and F_angle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PairOptions {
    /// Exact, sampled, or exact for small plants. Default `"auto"`.
    pub mode: PairMode,
    /// Most endpoints `"auto"` evaluates exactly. Default 64.
    #[serde(deserialize_with = "exact_up_to")]
    pub exact_up_to: u32,
    /// Sampled pairs per endpoint (the paper's 3). Default 3.
    #[serde(deserialize_with = "per_endpoint")]
    pub per_endpoint: u32,
    /// Fewest sampled pairs (the paper's 10). Default 10.
    #[serde(deserialize_with = "min_pairs")]
    pub min_pairs: u32,
}

impl Default for PairOptions {
    fn default() -> Self {
        PairOptions {
            mode: PairMode::Auto,
            exact_up_to: 64,
            per_endpoint: 3,
            min_pairs: 10,
        }
    }
}

/// Mean F_dist and F_angle over the chosen pairs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    /// F_dist.
    pub dist: f64,
    /// F_angle (0 when not asked for).
    pub angle: f64,
}

/// One pair's F_dist contribution; positions in paper units.
#[inline]
pub fn dist_term(a: DVec3, b: DVec3) -> f64 {
    200.0 / ((a - b).length() + 5.0)
}

/// One pair's F_angle contribution; unit directions (or zero, for no direction).
#[inline]
pub fn angle_term(u: DVec3, v: DVec3) -> f64 {
    let degrees = if u == DVec3::ZERO || v == DVec3::ZERO {
        0.0
    } else {
        u.cross(v).length().atan2(u.dot(v)).to_degrees()
    };
    200.0 / (degrees + 5.0)
}

impl PairOptions {
    /// Whether `n` endpoints are evaluated over every pair.
    pub fn is_exact(&self, n: usize) -> bool {
        match self.mode {
            PairMode::Exact => true,
            PairMode::Sampled => false,
            PairMode::Auto => n <= self.exact_up_to as usize,
        }
    }

    /// Pairs sampled for `n` endpoints: `max(per_endpoint · n, min_pairs)`.
    pub fn sampled_pairs(&self, n: usize) -> usize {
        (self.per_endpoint as usize)
            .saturating_mul(n)
            .max(self.min_pairs as usize)
    }

    /// F_dist, and F_angle when `angle` is true (it costs an `atan2` per pair, so it is
    /// skipped while its weight is 0), over the endpoints `scratch` last read. `seed` drives
    /// the sampled pairs; exact pairs ignore it. Does not allocate.
    pub fn spread(&self, scratch: &PoncinScratch, seed: u64, angle: bool) -> Spread {
        let endpoints = scratch.endpoints();
        let n = endpoints.len();
        if n < 2 {
            return Spread {
                dist: WORST_PAIR,
                angle: if angle { WORST_PAIR } else { 0.0 },
            };
        }
        if self.is_exact(n) {
            let pairs = (n * (n - 1) / 2) as f64;
            let mut angles = 0.0;
            if angle {
                for (i, a) in endpoints.iter().enumerate() {
                    for b in &endpoints[i + 1..] {
                        angles += angle_term(a.direction, b.direction);
                    }
                }
            }
            return Spread {
                dist: exact_dist(&scratch.columns) / pairs,
                angle: angles / pairs,
            };
        }
        let (mut dist, mut angles) = (0.0, 0.0);
        let pairs = self.sampled_pairs(n);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for _ in 0..pairs {
            let i = rng.random_range(0..n);
            let mut j = rng.random_range(0..n - 1);
            if j >= i {
                j += 1;
            }
            let (a, b) = (&endpoints[i], &endpoints[j]);
            dist += dist_term(a.position, b.position);
            if angle {
                angles += angle_term(a.direction, b.direction);
            }
        }
        Spread {
            dist: dist / pairs as f64,
            angle: angles / pairs as f64,
        }
    }
}

/// Lanes of the exact pair loop: the f32 columns are read `LANES` at a time into separate
/// accumulators, which the compiler turns into SIMD (about 4× the scalar f64 loop).
const LANES: usize = 8;

/// Sum of [`dist_term`] over every pair, from f32 columns of x, y and z. Each row is summed
/// in f32 lanes (a row holds at most a few thousand terms below 40) and added up in f64.
fn exact_dist([xs, ys, zs]: &[Vec<f32>; 3]) -> f64 {
    let term = |dx: f32, dy: f32, dz: f32| 200.0 / ((dx * dx + dy * dy + dz * dz).sqrt() + 5.0);
    let mut total = 0.0f64;
    for i in 0..xs.len() {
        let (x, y, z) = (xs[i], ys[i], zs[i]);
        let (rx, ry, rz) = (&xs[i + 1..], &ys[i + 1..], &zs[i + 1..]);
        let mut acc = [0.0f32; LANES];
        let chunks = rx
            .chunks_exact(LANES)
            .zip(ry.chunks_exact(LANES))
            .zip(rz.chunks_exact(LANES));
        for ((cx, cy), cz) in chunks {
            for k in 0..LANES {
                acc[k] += term(cx[k] - x, cy[k] - y, cz[k] - z);
            }
        }
        let tail = rx.len() / LANES * LANES;
        let mut row: f64 = acc.iter().map(|&a| f64::from(a)).sum();
        for j in tail..rx.len() {
            row += f64::from(term(rx[j] - x, ry[j] - y, rz[j] - z));
        }
        total += row;
    }
    total
}
