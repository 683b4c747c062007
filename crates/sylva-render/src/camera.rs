//! The camera: a mild perspective looking at the scene from one of the [`View`]s, framed so
//! every drawn point fits the picture.
//!
//! The eye sits [`DISTANCE`] bounding radii from the centre of the scene, so every point is
//! at least 2.5 radii in front of it (nothing is ever behind the camera) and the perspective
//! is gentle (about 16 degrees half-angle), enough for depth cues without distortion.
//! Framing projects every point once and scales the projected box to the image with a
//! margin, so the picture is filled by what is actually drawn, not by a loose bounding box.
//!
//! ```ignore
//! let mut fit = Fit::default();
//! let camera = Camera::looking(View::Front, centre, radius);
//! for p in points { fit.add(camera.view_xy(p)); }
//! let camera = camera.framed(&fit, width, height, 0.05);
//! ```

use sylva_core::glam::{Vec2, Vec3};

use super::View;

/// Eye distance from the scene centre, in bounding radii.
pub(crate) const DISTANCE: f32 = 3.5;

/// A perspective camera mapping world points to sample coordinates (x right, y down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Unit vector to the right of the picture.
    pub right: Vec3,
    /// Unit vector to the top of the picture.
    pub up: Vec3,
    /// Unit viewing direction.
    pub forward: Vec3,
    /// Samples per unit of `x / z` (and `y / z`).
    scale: f32,
    /// Sample position of the optical axis.
    cx: f32,
    cy: f32,
}

impl View {
    /// Viewing direction and picture-up vector.
    pub(crate) fn basis(self) -> (Vec3, Vec3) {
        match self {
            View::Front => (Vec3::NEG_Z, Vec3::Y),
            View::Side => (Vec3::NEG_X, Vec3::Y),
            // -Z up keeps +X on the right, as in the front view: not mirrored.
            View::Top => (Vec3::NEG_Y, Vec3::NEG_Z),
            View::Iso => {
                let (yaw, pitch) = (45f32.to_radians(), 30f32.to_radians());
                let to_eye = Vec3::new(
                    pitch.cos() * yaw.sin(),
                    pitch.sin(),
                    pitch.cos() * yaw.cos(),
                );
                (-to_eye, Vec3::Y)
            }
        }
    }
}

/// The box of projected points, in `x / z`, `y / z` units.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fit {
    min: Vec2,
    max: Vec2,
}

impl Default for Fit {
    fn default() -> Self {
        Fit {
            min: Vec2::INFINITY,
            max: Vec2::NEG_INFINITY,
        }
    }
}

impl Fit {
    /// Grows the box by a projected point (ignores `None`).
    #[inline]
    pub(crate) fn add(&mut self, p: Option<Vec2>) {
        if let Some(p) = p {
            self.min = self.min.min(p);
            self.max = self.max.max(p);
        }
    }
}

impl Camera {
    /// A camera looking at `centre` from `view`, `DISTANCE * radius` away, not yet framed.
    pub(crate) fn looking(view: View, centre: Vec3, radius: f32) -> Camera {
        let (forward, up_hint) = view.basis();
        let right = forward.cross(up_hint).normalize();
        let up = right.cross(forward);
        Camera {
            eye: centre - forward * (DISTANCE * radius),
            right,
            up,
            forward,
            scale: 1.0,
            cx: 0.0,
            cy: 0.0,
        }
    }

    /// [`Camera::looking`] from `distance` bounding radii away: far enough, the
    /// perspective is all but gone (an impostor's picture).
    pub(crate) fn looking_from(view: View, centre: Vec3, radius: f32, distance: f32) -> Camera {
        let camera = Camera::looking(view, centre, radius);
        Camera {
            eye: centre - camera.forward * (distance * radius),
            ..camera
        }
    }

    /// Depth of a point along the viewing direction.
    #[inline]
    pub(crate) fn depth(&self, p: Vec3) -> f32 {
        (p - self.eye).dot(self.forward)
    }

    /// The perspective-divided position of a point, `None` behind or too near the eye.
    #[inline]
    pub(crate) fn view_xy(&self, p: Vec3) -> Option<Vec2> {
        let d = p - self.eye;
        let z = d.dot(self.forward);
        // Points are at least 2.5 radii away by construction; this only rejects garbage.
        if z.is_nan() || z <= 1e-20 {
            return None;
        }
        let v = Vec2::new(d.dot(self.right), d.dot(self.up)) / z;
        v.is_finite().then_some(v)
    }

    /// Maps a point to sample coordinates and `1 / depth`.
    #[inline]
    pub(crate) fn project(&self, p: Vec3) -> Option<(f32, f32, f32)> {
        let v = self.view_xy(p)?;
        let inv_z = 1.0 / self.depth(p);
        Some((
            self.cx + self.scale * v.x,
            self.cy - self.scale * v.y,
            inv_z,
        ))
    }

    /// Scales and centres the picture so the box `fit` fills a `width` x `height` sample
    /// image less `margin` (a fraction of each side), keeping the aspect ratio.
    pub(crate) fn framed(mut self, fit: &Fit, width: u32, height: u32, margin: f32) -> Camera {
        let (w, h) = (width as f32, height as f32);
        let (mut centre, mut span) = (Vec2::ZERO, Vec2::splat(1.0));
        if fit.min.x <= fit.max.x && fit.min.y <= fit.max.y {
            centre = (fit.min + fit.max) * 0.5;
            // A single point or a flat line still gets a finite scale.
            span = (fit.max - fit.min).max(Vec2::splat(1e-6));
        }
        let usable = 1.0 - 2.0 * margin;
        self.scale = (w * usable / span.x).min(h * usable / span.y);
        self.cx = w * 0.5 - self.scale * centre.x;
        self.cy = h * 0.5 + self.scale * centre.y;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_are_right_handed_and_not_mirrored() {
        for view in View::ALL {
            let cam = Camera::looking(view, Vec3::ZERO, 1.0);
            assert!(
                (cam.right.cross(cam.up) + cam.forward).length() < 1e-5,
                "{view}"
            );
        }
        let right = |v: View| Camera::looking(v, Vec3::ZERO, 1.0).right;
        assert_eq!(right(View::Front), Vec3::X);
        assert_eq!(right(View::Top), Vec3::X);
        assert_eq!(right(View::Side), Vec3::NEG_Z);
        assert_eq!(Camera::looking(View::Top, Vec3::ZERO, 1.0).up, Vec3::NEG_Z);
    }

    #[test]
    fn framing_centres_the_points() {
        let cam = Camera::looking(View::Front, Vec3::new(5.0, 1.0, 0.0), 2.0);
        let pts = [Vec3::new(4.0, 0.0, 0.0), Vec3::new(6.0, 2.0, 0.0)];
        let mut fit = Fit::default();
        pts.iter().for_each(|&p| fit.add(cam.view_xy(p)));
        let cam = cam.framed(&fit, 100, 100, 0.1);
        let (x0, y0, _) = cam.project(pts[0]).unwrap();
        let (x1, y1, _) = cam.project(pts[1]).unwrap();
        assert!((x0 - 10.0).abs() < 1e-3 && (x1 - 90.0).abs() < 1e-3);
        assert!(
            (y0 - 90.0).abs() < 1e-3 && (y1 - 10.0).abs() < 1e-3,
            "y is down"
        );
    }
}
