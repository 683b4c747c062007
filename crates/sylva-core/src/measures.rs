//! Geometric measures of a [`Plant`] that fitness terms share.
//!
//! Surface area and volume treat every segment as a conical frustum and sum them; overlaps at
//! joints are not subtracted, and end caps are not counted in the area (the lateral surface is
//! what a tree exposes). Height and bounds use the skeleton: segment end points, radii and
//! organ bases.

use std::f32::consts::PI;

use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

use crate::plant::Plant;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (min at +inf, max at -inf); growing it by any point gives that point.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    /// Grows the box to hold a sphere of `radius` at `point`.
    #[inline]
    pub fn grow(&mut self, point: Vec3, radius: f32) {
        self.min = self.min.min(point - radius);
        self.max = self.max.max(point + radius);
    }

    /// True when nothing was added.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    /// `max - min`, zero for an empty box.
    pub fn size(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            self.max - self.min
        }
    }

    /// Centre of the box, the origin for an empty box.
    pub fn center(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            (self.min + self.max) * 0.5
        }
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }
}

/// Lateral area of a conical frustum.
#[inline]
pub fn frustum_area(r0: f32, r1: f32, length: f32) -> f32 {
    PI * (r0 + r1) * ((r0 - r1) * (r0 - r1) + length * length).sqrt()
}

/// Volume of a conical frustum.
#[inline]
pub fn frustum_volume(r0: f32, r1: f32, length: f32) -> f32 {
    PI * length * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0
}

impl Plant {
    /// End points of the skeleton: the ends of segments that no segment continues or branches
    /// from. A plant without segments has none.
    pub fn tips(&self) -> impl Iterator<Item = Vec3> + '_ {
        let counts = self.child_counts();
        self.segments()
            .iter()
            .zip(counts)
            .filter(|(_, children)| *children == 0)
            .map(|(s, _)| s.end)
    }

    /// Highest point of the skeleton above y = 0 (segment centre lines; radii ignored).
    /// Zero for a plant without segments.
    pub fn height(&self) -> f32 {
        self.segments()
            .iter()
            .map(|s| s.start.y.max(s.end.y))
            .fold(0.0, f32::max)
    }

    /// Bounds of everything visible: segments with their radii and organs with their sizes.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for s in self.segments() {
            b.grow(s.start, s.start_radius);
            b.grow(s.end, s.end_radius);
        }
        for o in self.organs() {
            b.grow(o.position, o.size.x.max(o.size.y));
        }
        b
    }

    /// Sum of the segments' lateral frustum areas, square metres.
    pub fn surface_area(&self) -> f32 {
        self.segments()
            .iter()
            .map(|s| frustum_area(s.start_radius, s.end_radius, s.length()))
            .sum()
    }

    /// Sum of the segments' frustum volumes, cubic metres.
    pub fn volume(&self) -> f32 {
        self.segments()
            .iter()
            .map(|s| frustum_volume(s.start_radius, s.end_radius, s.length()))
            .sum()
    }

    /// Total length of the skeleton, metres.
    pub fn total_length(&self) -> f32 {
        self.segments().iter().map(|s| s.length()).sum()
    }
}

/// The six measures of Susinno's *Deciduous Evolution*, for any plant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TreeMeasures {
    /// Highest point of the skeleton, metres ([`Plant::height`]).
    pub height: f64,
    /// Lateral area of all segments, square metres ([`Plant::surface_area`]).
    pub surface_area: f64,
    /// Volume of all segments, cubic metres ([`Plant::volume`]).
    pub volume: f64,
    /// How well each fork's second child mirrors its first across the parent's axis, averaged
    /// over forks of exactly two children (see [`fork_symmetry`]); 1 for a plant without such
    /// forks.
    pub symmetry: f64,
    /// `1 - mean deviation / 180°`, the mean over all segments with a parent of the angle
    /// between a segment and its parent: 1 for a straight pole.
    pub straightness: f64,
    /// Mean radius over mean length of the segments (the sum of their mean radii over the
    /// sum of their lengths); 0 for a plant without length.
    pub radius_to_length: f64,
    /// Sylva's addition: how well forks follow Leonardo's rule (the children's cross-sections
    /// at their bases add up to the parent's at its base): the mean over forks of two of
    /// `max(0, 1 - |q - 1|)` with `q = (r₁² + r₂²) / r²`; 1 for a plant without such forks.
    pub pipe_model: f64,
    /// Sylva's addition: how round the crown is seen from above: the ratio of the smaller to
    /// the larger horizontal standard deviation of the skeleton's points (the foot and every
    /// segment end): 1 for a round crown, 0 for a tree that grows in one plane or a pole.
    pub roundness: f64,
}

impl TreeMeasures {
    /// Reads the six measures off a plant.
    pub fn of_plant(plant: &Plant) -> TreeMeasures {
        let dir = |s: &crate::Segment| s.vector().as_dvec3().normalize_or_zero();
        let mut children: Vec<[Option<u32>; 2]> = vec![[None; 2]; plant.segments().len()];
        let counts = plant.child_counts();
        let (mut deviation, mut with_parent) = (0.0, 0usize);
        for (i, s) in plant.segments().iter().enumerate() {
            if let Some(p) = s.parent {
                let parent = plant.segment(p);
                deviation += dir(parent).dot(dir(s)).clamp(-1.0, 1.0).acos();
                with_parent += 1;
                let slot = &mut children[p.index()];
                if slot[0].is_none() {
                    slot[0] = Some(i as u32);
                } else if slot[1].is_none() {
                    slot[1] = Some(i as u32);
                }
            }
        }
        let (mut symmetry, mut pipe, mut forks, mut pipe_forks) = (0.0, 0.0, 0usize, 0usize);
        for (i, pair) in children.iter().enumerate() {
            if let ([Some(a), Some(b)], 2) = (pair, counts[i]) {
                let (p, c1, c2) = (
                    &plant.segments()[i],
                    &plant.segments()[*a as usize],
                    &plant.segments()[*b as usize],
                );
                symmetry += fork_symmetry(dir(p), dir(c1), dir(c2));
                forks += 1;
                let r = f64::from(p.start_radius);
                if r > 0.0 {
                    let q = (f64::from(c1.start_radius).powi(2)
                        + f64::from(c2.start_radius).powi(2))
                        / (r * r);
                    pipe += (1.0 - (q - 1.0).abs()).max(0.0);
                    pipe_forks += 1;
                }
            }
        }
        let roundness = crown_roundness(plant);
        let (radii, lengths) = plant.segments().iter().fold((0.0, 0.0), |(r, l), s| {
            (
                r + 0.5 * f64::from(s.start_radius + s.end_radius),
                l + f64::from(s.length()),
            )
        });
        let mean = |sum: f64, n: usize, empty: f64| if n == 0 { empty } else { sum / n as f64 };
        TreeMeasures {
            height: f64::from(plant.height()),
            surface_area: f64::from(plant.surface_area()),
            volume: f64::from(plant.volume()),
            symmetry: mean(symmetry, forks, 1.0),
            straightness: 1.0 - mean(deviation, with_parent, 0.0) / std::f64::consts::PI,
            radius_to_length: if lengths > 0.0 { radii / lengths } else { 0.0 },
            pipe_model: mean(pipe, pipe_forks, 1.0),
            roundness,
        }
    }
}

/// See [`TreeMeasures::roundness`]: the skeleton's points are the feet of root segments and
/// the ends of all segments.
fn crown_roundness(plant: &Plant) -> f64 {
    let points = plant
        .segments()
        .iter()
        .filter(|s| s.parent.is_none())
        .map(|s| s.start)
        .chain(plant.segments().iter().map(|s| s.end))
        .map(|p| p.as_dvec3());
    let (mut n, mut sx, mut sz, mut sxx, mut szz, mut sxz) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for p in points {
        n += 1.0;
        sx += p.x;
        sz += p.z;
        sxx += p.x * p.x;
        szz += p.z * p.z;
        sxz += p.x * p.z;
    }
    if n == 0.0 {
        return 0.0;
    }
    let (mx, mz) = (sx / n, sz / n);
    spread_ratio(sxx / n - mx * mx, szz / n - mz * mz, sxz / n - mx * mz)
}

/// How well two children (unit directions `d1`, `d2`) mirror each other across their
/// parent's axis `h`: the product of how opposite their leanings are around the axis,
/// `(1 - cos φ) / 2` for the angle φ between the parts of `d1` and `d2` across `h`, and how
/// equal their bends are, `min(δ1, δ2) / max(δ1, δ2)` for their angles δ to `h`. 1 for a
/// perfect mirror image, 0 for two children leaning the same way; two children that do not
/// bend at all (within 1e-6 radians, a single-precision plant's noise) count as mirror images.
pub fn fork_symmetry(h: DVec3, d1: DVec3, d2: DVec3) -> f64 {
    // Unbent is judged by the sine, which is exact near 0 where `acos` is not: a bend of
    // 1e-16 reads as 1.5e-8 through `acos`.
    let unbent = |d: DVec3| d.dot(h) > 0.0 && d.cross(h).length() < 1e-6;
    if unbent(d1) && unbent(d2) {
        return 1.0;
    }
    let bend = |d: DVec3| d.dot(h).clamp(-1.0, 1.0).acos();
    let (b1, b2) = (bend(d1), bend(d2));
    let across = |d: DVec3| (d - d.dot(h) * h).normalize_or_zero();
    let opposite = 0.5 * (1.0 - across(d1).dot(across(d2)));
    opposite * b1.min(b2) / b1.max(b2)
}

/// Ratio of the smaller to the larger standard deviation of a 2D covariance
/// `[[cxx, cxz], [cxz, czz]]`: 1 for a round cloud of points, 0 for a line or a point.
pub fn spread_ratio(cxx: f64, czz: f64, cxz: f64) -> f64 {
    let half_trace = 0.5 * (cxx + czz);
    let gap = (0.25 * (cxx - czz) * (cxx - czz) + cxz * cxz).sqrt();
    let (large, small) = (half_trace + gap, (half_trace - gap).max(0.0));
    if large > 1e-12 {
        (small / large).sqrt()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plant::{PlantMeta, SegmentId};

    fn y_fork() -> Plant {
        let mut p = Plant::new(PlantMeta::default());
        let trunk = p
            .add_segment(
                Vec3::ZERO,
                Vec3::Y * 2.0,
                (0.2, 0.1),
                None,
                false,
                Plant::BARK,
            )
            .unwrap();
        let top = Vec3::Y * 2.0;
        p.add_segment(
            top,
            top + Vec3::new(1.0, 1.0, 0.0),
            (0.1, 0.05),
            Some(trunk),
            false,
            Plant::BARK,
        )
        .unwrap();
        p.add_segment(
            top,
            top + Vec3::new(-1.0, 1.5, 0.0),
            (0.1, 0.05),
            Some(trunk),
            true,
            Plant::BARK,
        )
        .unwrap();
        p
    }

    #[test]
    fn tips_height_bounds() {
        let p = y_fork();
        let tips: Vec<_> = p.tips().collect();
        assert_eq!(
            tips,
            vec![Vec3::new(1.0, 3.0, 0.0), Vec3::new(-1.0, 3.5, 0.0)]
        );
        assert_eq!(p.height(), 3.5);
        let b = p.bounds();
        assert_eq!(b.min, Vec3::new(-1.05, -0.2, -0.2));
        assert_eq!(b.max, Vec3::new(1.05, 3.55, 0.2));
        assert_eq!(p.segment(SegmentId(2)).order, 1);
    }

    #[test]
    fn cylinder_area_and_volume() {
        let mut p = Plant::new(PlantMeta::default());
        p.add_segment(
            Vec3::ZERO,
            Vec3::Y * 3.0,
            (0.5, 0.5),
            None,
            false,
            Plant::BARK,
        )
        .unwrap();
        assert!((p.surface_area() - 2.0 * PI * 0.5 * 3.0).abs() < 1e-5);
        assert!((p.volume() - PI * 0.25 * 3.0).abs() < 1e-5);
    }

    #[test]
    fn cone_area_and_volume() {
        let (r, h) = (1.0f32, 2.0f32);
        assert!((frustum_area(r, 0.0, h) - PI * r * (r * r + h * h).sqrt()).abs() < 1e-5);
        assert!((frustum_volume(r, 0.0, h) - PI * r * r * h / 3.0).abs() < 1e-5);
    }

    #[test]
    fn empty_plant() {
        let p = Plant::default();
        assert_eq!(p.tips().count(), 0);
        assert_eq!(p.height(), 0.0);
        assert!(p.bounds().is_empty());
        assert_eq!(p.bounds().size(), Vec3::ZERO);
    }
}
