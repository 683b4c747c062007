//! The crown's envelope: the space a tree grows into, filled with attraction points.
//!
//! An envelope is a stack of rows from the crown's base to its top; at each height it spans
//! a stretch of x (seen from the front) and of z (seen from the side), and holds the ellipse
//! inscribed in that rectangle, as a trunk's crown is round in plan. A crown shape
//! ([`CrownShape`]) makes centred rows from its radius profile; a picture's visual hull makes
//! rows from the front and side outlines, each stretch where the outline's ink is at that
//! height.

use glam::Vec3;
use rand::{Rng, RngExt};

use crate::genome::{CrownShape, Growth, Param};

/// Rows a shape's envelope is drawn with.
const SHAPE_ROWS: usize = 64;

/// The space a crown fills: rows of x and z stretches from `base` to `top`.
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    /// Height of the lowest row, metres.
    pub base: f32,
    /// Height of the highest row, metres.
    pub top: f32,
    /// Per row, bottom to top: the stretch of x `[left, right]` and of z `[back, front]`,
    /// metres (an empty row has left > right).
    pub rows: Vec<[[f32; 2]; 2]>,
}

/// Why an envelope cannot be grown into.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EnvelopeError {
    /// Its rows hold no volume.
    #[error(
        "the crown's envelope is empty or flat (no volume between {base:.2} and {top:.2} m); \
         expected a crown with width and depth"
    )]
    Empty {
        /// The lowest row's height.
        base: f32,
        /// The highest row's height.
        top: f32,
    },
    /// Too few attraction points fell inside it.
    #[error(
        "only {placed} of {asked} attraction points fit in the crown's envelope; expected an \
         envelope of some volume"
    )]
    TooThin {
        /// Points placed.
        placed: usize,
        /// Points asked for.
        asked: usize,
    },
}

impl Envelope {
    /// The envelope of a genome's crown shape and proportions.
    pub fn of(genome: &Growth) -> Envelope {
        let p = &genome.parameters;
        let height = p.f(Param::Height);
        let half_width = 0.5 * p.f(Param::Width) * height;
        let half_depth = half_width * p.f(Param::Depth);
        Envelope::of_shape(
            genome.crown,
            p.f(Param::CrownBase) * height,
            height,
            half_width,
            half_depth,
        )
    }

    /// A shape's envelope from `base` to `top`, `half_width` and `half_depth` at its widest.
    pub fn of_shape(
        shape: CrownShape,
        base: f32,
        top: f32,
        half_width: f32,
        half_depth: f32,
    ) -> Envelope {
        let rows = (0..SHAPE_ROWS)
            .map(|i| {
                let r = shape.radius((i as f32 + 0.5) / SHAPE_ROWS as f32);
                [
                    [-r * half_width, r * half_width],
                    [-r * half_depth, r * half_depth],
                ]
            })
            .collect();
        Envelope { base, top, rows }
    }

    /// The row at height `y`, if `y` is within the envelope.
    fn row(&self, y: f32) -> Option<&[[f32; 2]; 2]> {
        if !(self.base..self.top).contains(&y) {
            return None;
        }
        let t = (y - self.base) / (self.top - self.base);
        let i = ((t * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        Some(&self.rows[i])
    }

    /// Whether `p` lies inside.
    pub fn contains(&self, p: Vec3) -> bool {
        let Some([[x0, x1], [z0, z1]]) = self.row(p.y) else {
            return false;
        };
        if x0 >= x1 || z0 >= z1 {
            return false;
        }
        let u = (2.0 * p.x - (x0 + x1)) / (x1 - x0);
        let v = (2.0 * p.z - (z0 + z1)) / (z1 - z0);
        u * u + v * v <= 1.0
    }

    /// The box around it: least and greatest corners.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::new(f32::MAX, self.base, f32::MAX);
        let mut hi = Vec3::new(f32::MIN, self.top, f32::MIN);
        for [[x0, x1], [z0, z1]] in &self.rows {
            if x0 < x1 && z0 < z1 {
                lo = lo.min(Vec3::new(*x0, self.base, *z0));
                hi = hi.max(Vec3::new(*x1, self.top, *z1));
            }
        }
        (lo, hi)
    }

    /// The volume it holds, cubic metres.
    pub fn volume(&self) -> f32 {
        let dy = (self.top - self.base) / self.rows.len() as f32;
        let area = |[[x0, x1], [z0, z1]]: &[[f32; 2]; 2]| {
            std::f32::consts::FRAC_PI_4 * (x1 - x0).max(0.0) * (z1 - z0).max(0.0)
        };
        self.rows.iter().map(area).sum::<f32>() * dy
    }

    /// `count` points drawn uniformly inside, from `rng`. At most 64 draws a point are
    /// made; an envelope too thin to take a tenth of the points is an error.
    pub fn attraction_points<R: Rng + ?Sized>(
        &self,
        count: usize,
        rng: &mut R,
    ) -> Result<Vec<Vec3>, EnvelopeError> {
        let empty = EnvelopeError::Empty {
            base: self.base,
            top: self.top,
        };
        let volume = self.volume();
        if !(self.top > self.base && volume.is_finite() && volume > 1e-6) {
            return Err(empty);
        }
        let (lo, hi) = self.bounds();
        let mut points = Vec::with_capacity(count);
        for _ in 0..count * 64 {
            if points.len() == count {
                break;
            }
            let p = Vec3::new(
                rng.random_range(lo.x..=hi.x),
                rng.random_range(lo.y..hi.y),
                rng.random_range(lo.z..=hi.z),
            );
            if self.contains(p) {
                points.push(p);
            }
        }
        if points.len() * 10 < count {
            return Err(EnvelopeError::TooThin {
                placed: points.len(),
                asked: count,
            });
        }
        Ok(points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_fill_the_shape_and_nothing_else() {
        let e = Envelope::of_shape(CrownShape::Cone, 2.0, 10.0, 3.0, 3.0);
        let mut rng = sylva_core::rng::seeded(1);
        let points = e.attraction_points(2000, &mut rng).unwrap();
        assert_eq!(points.len(), 2000);
        assert!(points.iter().all(|&p| e.contains(p)));
        // A cone holds a third of its cylinder, most of it low down.
        let low = points.iter().filter(|p| p.y < 6.0).count();
        assert!(low > 1400, "{low}");
        // The volume is what a box's share of random points says it is.
        let (lo, hi) = e.bounds();
        let inside = (0..20_000)
            .filter(|_| {
                let p = Vec3::new(
                    rng.random_range(lo.x..hi.x),
                    rng.random_range(lo.y..hi.y),
                    rng.random_range(lo.z..hi.z),
                );
                e.contains(p)
            })
            .count();
        let measured = (hi - lo).element_product() * inside as f32 / 20_000.0;
        assert!(
            (e.volume() / measured - 1.0).abs() < 0.05,
            "{} {measured}",
            e.volume()
        );
    }

    #[test]
    fn a_flat_envelope_is_refused() {
        let e = Envelope::of_shape(CrownShape::Ellipsoid, 2.0, 10.0, 3.0, 0.0);
        let mut rng = sylva_core::rng::seeded(1);
        let err = e.attraction_points(100, &mut rng).unwrap_err();
        assert!(err.to_string().contains("empty or flat"), "{err}");
    }
}
