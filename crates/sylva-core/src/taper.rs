//! The pipe model's taper for any grown plant: a segment is as thick as the tips it carries.
//!
//! Leonardo's rule, read as Shinozaki's pipe model: a branch's cross-section is the sum of
//! its children's, so the radius where `n` tips lie above goes as `n^(1/e)`; `e = 2` keeps
//! the area (Leonardo), `e` near 2.5 to 3 fits measured trees better. [`PipeTaper::apply`]
//! gives every skeleton (a segment without a parent and all that grows from it) the radii
//!
//! ```text
//! r(n) = r_tip · n^(1/e)
//! ```
//!
//! with `r_tip` the mean radius its tip segments had: twigs keep their size, as a tree's do,
//! and the trunk thickens under the tips it carries. A segment starts at `r(tips above it)`
//! and ends at the start of its thickest continuation (a child on the same axis), so an axis
//! thins along its length rather than in steps at the forks; a segment whose axis ends there
//! keeps one radius.
//! Only woody segments (bark and root) change and count: a tip is the end of a woody
//! segment from which no woody segment grows, and leaves drawn as segments keep their
//! size. Roots, being skeletons of their own, taper from their own base.

use serde::{Deserialize, Serialize};

use crate::plant::{MAX_COORD, MaterialKind, Plant};

/// Smallest exponent: 2, area kept at every fork (Leonardo's rule).
pub const MIN_EXPONENT: f64 = 2.0;
/// Largest exponent: 3, the pipe model's other end (da Vinci–Murray).
pub const MAX_EXPONENT: f64 = 3.0;

/// The pipe model's taper, with its exponent `e`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PipeTaper {
    /// `e` in `radius ∝ tips^(1/e)`, from 2 to 3.
    #[serde(deserialize_with = "exponent")]
    pub exponent: f64,
}

crate::ranged!(exponent: f64, "exponent", MIN_EXPONENT, MAX_EXPONENT);

/// Why a taper was refused.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("the pipe-model exponent must be a number from 2 to 3, got {0}")]
pub struct TaperError(pub f64);

impl PipeTaper {
    /// A taper with exponent `e`, checked to lie in 2..=3.
    pub fn new(exponent: f64) -> Result<PipeTaper, TaperError> {
        if (MIN_EXPONENT..=MAX_EXPONENT).contains(&exponent) {
            Ok(PipeTaper { exponent })
        } else {
            Err(TaperError(exponent))
        }
    }

    /// Sets every segment's radii by the pipe model (see the module docs). Radii stay
    /// finite and within the plant's range (at most a million tips thicken a twig 1000
    /// times, and each is capped), so the plant's checks still hold.
    pub fn apply(&self, plant: &mut Plant) {
        let woody: Vec<bool> = plant
            .segments()
            .iter()
            .map(|s| {
                let kind = plant.materials().get(s.material.index()).map(|m| m.kind);
                kind.is_some_and(MaterialKind::is_woody)
            })
            .collect();
        let segments = plant.segments_mut();
        let n = segments.len();
        // Tips above each woody segment, and the child on its axis that carries the most,
        // found children first (parents come before their children).
        let mut tips = vec![0u32; n];
        let mut continuation: Vec<Option<u32>> = vec![None; n];
        let mut bears_wood = vec![false; n];
        for i in (0..n).rev() {
            if !woody[i] {
                continue;
            }
            if !bears_wood[i] {
                tips[i] = 1;
            }
            let Some(parent) = segments[i].parent else {
                continue;
            };
            let p = parent.index();
            bears_wood[p] = true;
            tips[p] += tips[i];
            let carries_more = continuation[p].is_none_or(|c| tips[c as usize] < tips[i]);
            if !segments[i].lateral && carries_more {
                continuation[p] = Some(i as u32);
            }
        }
        // Each skeleton's mean tip radius, gathered at its first segment and handed down.
        let mut skeleton = vec![0u32; n];
        let mut twigs = vec![(0f64, 0u32); n];
        for i in 0..n {
            skeleton[i] = segments[i].parent.map_or(i as u32, |p| skeleton[p.index()]);
            if woody[i] && !bears_wood[i] {
                let t = &mut twigs[skeleton[i] as usize];
                *t = (t.0 + f64::from(segments[i].start_radius), t.1 + 1);
            }
        }
        let inv = 1.0 / self.exponent;
        let radius = |i: usize| {
            let (sum, count) = twigs[skeleton[i] as usize];
            let tip = sum / f64::from(count.max(1));
            (tip * f64::from(tips[i]).powf(inv)).min(f64::from(MAX_COORD)) as f32
        };
        let starts: Vec<f32> = (0..n).map(radius).collect();
        for (i, s) in segments.iter_mut().enumerate().filter(|(i, _)| woody[*i]) {
            s.start_radius = starts[i];
            s.end_radius = continuation[i].map_or(starts[i], |c| starts[c as usize]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{PlantMeta, SegmentId};
    use glam::Vec3;

    /// A trunk of two segments forking into two branches of one segment each, and a side
    /// branch of three tips from the first segment: 5 tips in all.
    fn plant() -> Plant {
        let mut p = Plant::new(PlantMeta::default());
        let (y, bark) = (Vec3::Y, Plant::BARK);
        let t0 = p
            .add_segment(Vec3::ZERO, y, (0.5, 0.5), None, false, bark)
            .unwrap();
        let t1 = p
            .add_segment(y, 2.0 * y, (0.5, 0.5), Some(t0), false, bark)
            .unwrap();
        for x in [-1.0, 1.0] {
            let end = 2.0 * y + Vec3::new(x, 1.0, 0.0);
            p.add_segment(2.0 * y, end, (0.5, 0.5), Some(t1), true, bark)
                .unwrap();
        }
        let side = p
            .add_segment(y, y + Vec3::X, (0.5, 0.5), Some(t0), true, bark)
            .unwrap();
        for z in [-1.0, 0.0, 1.0] {
            let end = y + Vec3::new(1.5, 0.5, z);
            p.add_segment(y + Vec3::X, end, (0.5, 0.5), Some(side), z == 0.0, bark)
                .unwrap();
        }
        p
    }

    #[test]
    fn radii_follow_the_tips_above() {
        let mut p = plant();
        PipeTaper::new(2.0).unwrap().apply(&mut p);
        // Every tip had radius 0.5, so r(n) = 0.5·√n.
        let r = |n: f32| 0.5 * n.sqrt();
        let s = p.segments();
        assert!(
            (s[0].start_radius - r(5.0)).abs() < 1e-6,
            "the trunk carries all 5"
        );
        // Its continuation carries 2: the trunk thins along its length to r(2).
        assert!((s[0].end_radius - r(2.0)).abs() < 1e-6);
        assert!((s[1].start_radius - r(2.0)).abs() < 1e-6);
        // The top fork ends the trunk's axis (both children lateral): one radius.
        assert_eq!(s[1].end_radius, s[1].start_radius);
        for tip in [2, 3, 5, 6, 7] {
            assert!(
                (s[tip].start_radius - 0.5).abs() < 1e-6,
                "tip {tip} keeps its size"
            );
            assert_eq!(s[tip].end_radius, s[tip].start_radius);
        }
        // The side branch carries 3 tips and continues into its middle child.
        assert!((s[4].start_radius - r(3.0)).abs() < 1e-6);
        assert!((s[4].end_radius - r(1.0)).abs() < 1e-6);
        // Leonardo: at the side fork, the areas of the three children add up to the parent's.
        let area = |r: f32| r * r;
        let children = area(s[5].start_radius) + area(s[6].start_radius) + area(s[7].start_radius);
        assert!((children - area(s[4].start_radius)).abs() < 1e-5);
    }

    #[test]
    fn leaves_keep_their_size_and_do_not_count() {
        let mut p = plant();
        let twig = p.segments()[2];
        let leaf = (twig.end, twig.end + Vec3::Y, (0.3, 0.1));
        p.add_segment(
            leaf.0,
            leaf.1,
            leaf.2,
            Some(SegmentId(2)),
            true,
            Plant::LEAF,
        )
        .unwrap();
        PipeTaper::new(2.0).unwrap().apply(&mut p);
        let s = p.segments();
        assert_eq!((s[8].start_radius, s[8].end_radius), (0.3, 0.1));
        assert!((s[2].start_radius - 0.5).abs() < 1e-6, "still a tip");
        assert!((s[0].start_radius - 0.5 * 5f32.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn each_skeleton_tapers_from_its_own_twigs_and_the_exponent_is_checked() {
        let mut p = plant();
        let root = p
            .add_segment(Vec3::ZERO, -Vec3::Y, (0.2, 0.2), None, false, Plant::BARK)
            .unwrap();
        for x in [-1.0, 1.0] {
            let end = -2.0 * Vec3::Y + x * Vec3::X;
            p.add_segment(-Vec3::Y, end, (0.1, 0.1), Some(root), true, Plant::BARK)
                .unwrap();
        }
        PipeTaper::new(3.0).unwrap().apply(&mut p);
        let s = p.segments();
        assert!((s[8].start_radius - 0.1 * 2f32.cbrt()).abs() < 1e-6);
        assert!((s[9].start_radius - 0.1).abs() < 1e-6);
        assert!((s[0].start_radius - 0.5 * 5f32.cbrt()).abs() < 1e-6);
        assert!(PipeTaper::new(1.9).is_err());
        assert!(PipeTaper::new(f64::NAN).is_err());
        let e: Result<PipeTaper, _> = serde_json::from_str(r#"{"exponent": 4}"#);
        assert!(e.unwrap_err().to_string().contains("exponent"));
    }
}
