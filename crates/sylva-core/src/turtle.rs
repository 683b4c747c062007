//! The HLU turtle of *The Algorithmic Beauty of Plants*.
//!
//! A [`Frame`] holds three orthonormal vectors: H (heading), L (left) and U (up), with
//! `H × L = U`. The three rotations of the book turn one pair of them about the third:
//! [`Frame::rotate_u`] turns H towards L (yaw), [`Frame::rotate_l`] turns H towards U (pitch),
//! [`Frame::rotate_h`] turns L towards U (roll). Every rotation re-orthonormalises, so a frame
//! stays orthonormal to within `1e-5` after any number of rotations.
//!
//! Hot loops that turn many times by precomputed angles (the automata simulator) use
//! [`Frame::turn_u`], [`Frame::turn_l`] and [`Frame::turn_h`], which take the angle's sine
//! and cosine and leave the frame as it is, and call [`Frame::renormalise`] every few turns.
//!
//! Local coordinates: a frame maps a local vector `(x, y, z)` to `x·R + y·H + z·U` where
//! `R = -L` is the turtle's right. The upright frame is the identity: H is world +Y, U is world
//! +Z, R is world +X. Angles are radians.

use glam::{Mat3, Quat, Vec3};
use serde::{Deserialize, Serialize};

/// An orthonormal, right-handed HLU frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// Heading: the direction the turtle moves in.
    pub heading: Vec3,
    /// Left of the heading.
    pub left: Vec3,
    /// Up: `heading × left`.
    pub up: Vec3,
}

impl Default for Frame {
    fn default() -> Self {
        Self::UPRIGHT
    }
}

/// Turns the pair `(a, b)` in their plane by the angle of `sin` and `cos`: `a` moves
/// towards `b`.
#[inline(always)]
fn turn_pair(a: &mut Vec3, b: &mut Vec3, sin: f32, cos: f32) {
    let (x, y) = (*a, *b);
    *a = x * cos + y * sin;
    *b = y * cos - x * sin;
}

impl Frame {
    /// Heading +Y (world up), left -X, up +Z: a turtle standing on the ground.
    pub const UPRIGHT: Frame = Frame {
        heading: Vec3::Y,
        left: Vec3::NEG_X,
        up: Vec3::Z,
    };

    /// Builds a frame from a heading and an approximate up vector; `None` when either is not
    /// finite, is zero, or when they are parallel.
    pub fn from_heading_up(heading: Vec3, up: Vec3) -> Option<Frame> {
        let heading = heading.try_normalize()?;
        let left = up.cross(heading).try_normalize()?;
        Some(Frame {
            heading,
            left,
            up: heading.cross(left),
        })
    }

    /// Yaw: turns H towards L by `angle` about U ("+" in the book).
    pub fn rotate_u(&mut self, angle: f32) {
        let (sin, cos) = angle.sin_cos();
        self.turn_u(sin, cos);
        self.orthonormalise();
    }

    /// Pitch: turns H towards U by `angle` about L.
    pub fn rotate_l(&mut self, angle: f32) {
        let (sin, cos) = angle.sin_cos();
        self.turn_l(sin, cos);
        self.orthonormalise();
    }

    /// Roll: turns L towards U by `angle` about H.
    pub fn rotate_h(&mut self, angle: f32) {
        let (sin, cos) = angle.sin_cos();
        self.turn_h(sin, cos);
        self.orthonormalise();
    }

    /// Yaw by the angle of `sin` and `cos`, without re-orthonormalising.
    #[inline(always)]
    pub fn turn_u(&mut self, sin: f32, cos: f32) {
        turn_pair(&mut self.heading, &mut self.left, sin, cos);
    }

    /// Pitch by the angle of `sin` and `cos`, without re-orthonormalising.
    #[inline(always)]
    pub fn turn_l(&mut self, sin: f32, cos: f32) {
        turn_pair(&mut self.heading, &mut self.up, sin, cos);
    }

    /// Roll by the angle of `sin` and `cos`, without re-orthonormalising.
    #[inline(always)]
    pub fn turn_h(&mut self, sin: f32, cos: f32) {
        turn_pair(&mut self.left, &mut self.up, sin, cos);
    }

    /// Makes the frame orthonormal again after turns. Turns keep the vectors within a few
    /// ulps of unit length, so one Newton step (`v × (3 − |v|²) / 2`) restores them without
    /// a square root; a frame that drifted further is normalised exactly.
    #[inline]
    pub fn renormalise(&mut self) {
        let h = self.heading;
        let hh = h.length_squared();
        let l = self.left - h * h.dot(self.left);
        let ll = l.length_squared();
        if (hh - 1.0).abs() < 1e-3 && (ll - 1.0).abs() < 1e-3 {
            self.heading = h * (1.5 - 0.5 * hh);
            let l = self.left - self.heading * self.heading.dot(self.left);
            self.left = l * (1.5 - 0.5 * l.length_squared());
        } else {
            self.heading = h.normalize_or(Vec3::Y);
            self.left = (self.left - self.heading * self.heading.dot(self.left))
                .try_normalize()
                .unwrap_or_else(|| self.heading.any_orthonormal_vector());
        }
        self.up = self.heading.cross(self.left);
    }

    /// Rotates the frame by `angle` about an axis given in the frame's local coordinates
    /// (x right, y heading, z up). A zero or non-finite axis leaves the frame unchanged.
    pub fn rotate_local(&mut self, local_axis: Vec3, angle: f32) {
        let Some(axis) = self.to_world(local_axis).try_normalize() else {
            return;
        };
        let q = Quat::from_axis_angle(axis, angle);
        self.heading = q * self.heading;
        self.left = q * self.left;
        self.orthonormalise();
    }

    /// Maps a local vector (x right, y heading, z up) into world space.
    #[inline]
    pub fn to_world(&self, local: Vec3) -> Vec3 {
        -self.left * local.x + self.heading * local.y + self.up * local.z
    }

    /// The rotation taking local coordinates to world coordinates.
    pub fn matrix(&self) -> Mat3 {
        Mat3::from_cols(-self.left, self.heading, self.up)
    }

    /// The frame as a unit quaternion (local to world).
    pub fn rotation(&self) -> Quat {
        Quat::from_mat3(&self.matrix()).normalize()
    }

    /// Largest deviation from orthonormality: unit lengths and zero dot products.
    pub fn orthonormality_error(&self) -> f32 {
        let lengths = [self.heading, self.left, self.up].map(|v| (v.length() - 1.0).abs());
        let dots = [
            self.heading.dot(self.left),
            self.heading.dot(self.up),
            self.left.dot(self.up),
        ]
        .map(f32::abs);
        let handed = (self.heading.cross(self.left) - self.up).length();
        lengths.into_iter().chain(dots).fold(handed, f32::max)
    }

    /// Gram-Schmidt: H is kept, L is made perpendicular to it, U completes the frame.
    fn orthonormalise(&mut self) {
        self.heading = self.heading.normalize();
        self.left = (self.left - self.heading * self.heading.dot(self.left)).normalize();
        self.up = self.heading.cross(self.left);
    }
}

/// A turtle: a position and a frame, with a stack for `[` and `]`.
#[derive(Clone, Debug, Default)]
pub struct Turtle {
    /// Where the turtle stands.
    pub position: Vec3,
    /// Which way it faces.
    pub frame: Frame,
    stack: Vec<(Vec3, Frame)>,
}

impl Turtle {
    /// A turtle at `position` facing along `frame`.
    pub fn new(position: Vec3, frame: Frame) -> Self {
        Self {
            position,
            frame,
            stack: Vec::new(),
        }
    }

    /// Moves `distance` along the heading and returns the new position.
    pub fn forward(&mut self, distance: f32) -> Vec3 {
        self.position += self.frame.heading * distance;
        self.position
    }

    /// Saves position and frame (`[`).
    pub fn push(&mut self) {
        self.stack.push((self.position, self.frame));
    }

    /// Restores the last saved position and frame (`]`); `false` when the stack is empty, in
    /// which case the turtle is unchanged.
    pub fn pop(&mut self) -> bool {
        match self.stack.pop() {
            Some((position, frame)) => {
                self.position = position;
                self.frame = frame;
                true
            }
            None => false,
        }
    }

    /// How many states are saved.
    pub fn depth(&self) -> usize {
        self.stack.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::FRAC_PI_2;

    #[test]
    fn upright_is_identity() {
        assert_eq!(Frame::UPRIGHT.matrix(), Mat3::IDENTITY);
        assert_eq!(Frame::UPRIGHT.orthonormality_error(), 0.0);
    }

    #[test]
    fn rotations_turn_the_named_pairs() {
        let mut f = Frame::UPRIGHT;
        f.rotate_u(FRAC_PI_2);
        assert!(
            (f.heading - Vec3::NEG_X).length() < 1e-6,
            "yaw turns H to L"
        );
        let mut f = Frame::UPRIGHT;
        f.rotate_l(FRAC_PI_2);
        assert!((f.heading - Vec3::Z).length() < 1e-6, "pitch turns H to U");
        let mut f = Frame::UPRIGHT;
        f.rotate_h(FRAC_PI_2);
        assert!((f.left - Vec3::Z).length() < 1e-6, "roll turns L to U");
        assert!((f.heading - Vec3::Y).length() < 1e-6, "roll keeps H");
    }

    #[test]
    fn a_million_rotations_do_not_drift() {
        let mut f = Frame::UPRIGHT;
        for i in 0..1_000_000u32 {
            let a = 0.1 + (i % 97) as f32 * 0.013;
            match i % 4 {
                0 => f.rotate_u(a),
                1 => f.rotate_l(-a),
                2 => f.rotate_h(a * 0.7),
                _ => f.rotate_local(Vec3::new(0.3, -0.5, 0.8), a),
            }
        }
        assert!(
            f.orthonormality_error() < 1e-5,
            "{}",
            f.orthonormality_error()
        );
    }

    #[test]
    fn rotate_local_matches_named_rotations() {
        // About local z (up), a positive turn moves H towards -x, i.e. towards L.
        let mut a = Frame::UPRIGHT;
        a.rotate_l(0.3);
        a.rotate_h(0.2);
        let mut b = a;
        a.rotate_u(0.5);
        b.rotate_local(Vec3::Z, 0.5);
        assert!((a.heading - b.heading).length() < 1e-6);
        assert!((a.left - b.left).length() < 1e-6);
    }

    #[test]
    fn push_pop_restores() {
        let mut t = Turtle::default();
        t.push();
        t.frame.rotate_u(1.0);
        t.forward(2.0);
        assert!(t.pop());
        assert_eq!(t.position, Vec3::ZERO);
        assert_eq!(t.frame, Frame::UPRIGHT);
        assert!(!t.pop());
    }

    #[test]
    fn from_heading_up_rejects_degenerate() {
        assert!(Frame::from_heading_up(Vec3::Y, Vec3::Y).is_none());
        assert!(Frame::from_heading_up(Vec3::ZERO, Vec3::Z).is_none());
        assert!(Frame::from_heading_up(Vec3::NAN, Vec3::Z).is_none());
        let f = Frame::from_heading_up(Vec3::Y, Vec3::Z).unwrap();
        assert_eq!(f, Frame::UPRIGHT);
    }
}
