//! Geometric measures of a [`Plant`] that fitness terms share.
//!
//! Surface area and volume treat every segment as a conical frustum and sum them; overlaps at
//! joints are not subtracted, and end caps are not counted in the area (the lateral surface is
//! what a tree exposes). Height and bounds use the skeleton: segment end points, radii and
//! organ bases.

use std::f32::consts::PI;

use glam::Vec3;
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
        self.segments
            .iter()
            .zip(counts)
            .filter(|(_, children)| *children == 0)
            .map(|(s, _)| s.end)
    }

    /// Highest point of the skeleton above y = 0 (segment centre lines; radii ignored).
    /// Zero for a plant without segments.
    pub fn height(&self) -> f32 {
        self.segments
            .iter()
            .map(|s| s.start.y.max(s.end.y))
            .fold(0.0, f32::max)
    }

    /// Bounds of everything visible: segments with their radii and organs with their sizes.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for s in &self.segments {
            b.grow(s.start, s.start_radius);
            b.grow(s.end, s.end_radius);
        }
        for o in &self.organs {
            b.grow(o.position, o.size.x.max(o.size.y));
        }
        b
    }

    /// Sum of the segments' lateral frustum areas, square metres.
    pub fn surface_area(&self) -> f32 {
        self.segments
            .iter()
            .map(|s| frustum_area(s.start_radius, s.end_radius, s.length()))
            .sum()
    }

    /// Sum of the segments' frustum volumes, cubic metres.
    pub fn volume(&self) -> f32 {
        self.segments
            .iter()
            .map(|s| frustum_volume(s.start_radius, s.end_radius, s.length()))
            .sum()
    }

    /// Total length of the skeleton, metres.
    pub fn total_length(&self) -> f32 {
        self.segments.iter().map(|s| s.length()).sum()
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
