//! Susinno's fitness: a weighted sum of six tree measures, and two of Sylva's.
//!
//! Of degree 1: surface-to-volume ratio, symmetry, radius-to-length ratio. Of degree 1/2:
//! volume, height, straightness. Higher is better. Each reported term is its weighted
//! contribution, so the terms add up to the total.
//!
//! The six terms alone have no interior optimum a person would call a tree: thickness is
//! pulled to one end of its range (surface-to-volume falls as `1/r` while √volume grows as
//! `r`, and their sum is convex), and nothing rewards a crown that fills space, so runs end
//! at a flat fan of twigs or a solid mushroom. Sylva adds two terms of degree 1, both off
//! when their weight is 0 (set them to 0 for the paper's fitness):
//! - `pipe_model`: forks that follow Leonardo's rule, which gives branches a natural taper;
//! - `roundness`: a crown as wide in every horizontal direction (a 3D tree, not a fan).

use serde::{Deserialize, Serialize};
pub use sylva_core::TreeMeasures;
use sylva_core::ranged;

ranged!(weight: f64, "weight", -1e6, 1e6, "");

/// Names of the six terms, in the order [`SusinnoScore::terms`] holds them.
pub const TERM_NAMES: [&str; 8] = [
    "surface_to_volume",
    "symmetry",
    "radius_to_length",
    "volume",
    "height",
    "straightness",
    "pipe_model",
    "roundness",
];

/// The six weights (`k_sv`, `k_s`, `k_rl`, `k_v`, `k_h`, `k_st` in the paper).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SusinnoWeights {
    /// Weight of surface area / volume (1/m). Default 0.02.
    #[serde(deserialize_with = "weight")]
    pub surface_to_volume: f64,
    /// Weight of symmetry (0..1). Default 4.0.
    #[serde(deserialize_with = "weight")]
    pub symmetry: f64,
    /// Weight of mean radius / length. Default 0.05.
    #[serde(deserialize_with = "weight")]
    pub radius_to_length: f64,
    /// Weight of √volume (m^1.5). Default 0.1.
    #[serde(deserialize_with = "weight")]
    pub volume: f64,
    /// Weight of √height (m^0.5). Default 1.5.
    #[serde(deserialize_with = "weight")]
    pub height: f64,
    /// Weight of √straightness (0..1). Default 2.0.
    #[serde(deserialize_with = "weight")]
    pub straightness: f64,
    /// Weight of the pipe-model score (0..1), a Sylva addition. Default 3.0.
    #[serde(deserialize_with = "weight")]
    pub pipe_model: f64,
    /// Weight of crown roundness (0..1), a Sylva addition. Default 3.0.
    #[serde(deserialize_with = "weight")]
    pub roundness: f64,
}

impl Default for SusinnoWeights {
    fn default() -> Self {
        SusinnoWeights {
            surface_to_volume: 0.02,
            symmetry: 4.0,
            radius_to_length: 0.05,
            volume: 0.1,
            height: 1.5,
            straightness: 2.0,
            pipe_model: 3.0,
            roundness: 3.0,
        }
    }
}

/// A scored tree: the total and each weighted term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SusinnoScore {
    /// Sum of the terms.
    pub total: f64,
    /// Weighted terms, in [`TERM_NAMES`] order.
    pub terms: [f64; 8],
}

impl SusinnoWeights {
    /// Scores a tree's measures. A tree without volume gets no surface-to-volume credit.
    pub fn score(&self, m: &TreeMeasures) -> SusinnoScore {
        let sv = if m.volume > 0.0 {
            m.surface_area / m.volume
        } else {
            0.0
        };
        let terms = [
            self.surface_to_volume * sv,
            self.symmetry * m.symmetry,
            self.radius_to_length * m.radius_to_length,
            self.volume * m.volume.max(0.0).sqrt(),
            self.height * m.height.max(0.0).sqrt(),
            self.straightness * m.straightness.max(0.0).sqrt(),
            self.pipe_model * m.pipe_model,
            self.roundness * m.roundness,
        ];
        SusinnoScore {
            total: terms.iter().sum(),
            terms,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terms_follow_their_degree() {
        let w = SusinnoWeights {
            surface_to_volume: 1.0,
            symmetry: 1.0,
            radius_to_length: 1.0,
            volume: 1.0,
            height: 1.0,
            straightness: 1.0,
            pipe_model: 2.0,
            roundness: 3.0,
        };
        let m = TreeMeasures {
            height: 16.0,
            surface_area: 10.0,
            volume: 4.0,
            symmetry: 0.5,
            straightness: 0.25,
            radius_to_length: 0.1,
            pipe_model: 0.5,
            roundness: 0.25,
        };
        let s = w.score(&m);
        assert_eq!(s.terms, [2.5, 0.5, 0.1, 2.0, 4.0, 0.5, 1.0, 0.75]);
        assert_eq!(s.total, 11.35);
    }

    #[test]
    fn no_volume_no_ratio() {
        let s = SusinnoWeights::default().score(&TreeMeasures::default());
        assert_eq!(s.terms[0], 0.0);
        assert!(s.total.is_finite());
    }
}
