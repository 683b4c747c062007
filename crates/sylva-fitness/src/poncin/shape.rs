//! Target surfaces of F_pos and the unsigned distance of a point to them.
//!
//! All coordinates are in the paper's units (see [`super::PoncinFitness::unit`]); Y is up.
//! Shapes are solids and the distance is to their whole surface, caps included, from inside
//! or outside:
//!
//! - **sphere**: `| ‖p − c‖ − r |`, the paper's formula;
//! - **ellipsoid** (axis-aligned): exact to floating-point precision by Eberly's method
//!   ("Distance from a point to an ellipse, an ellipsoid, or a hyperellipsoid", 2013): the
//!   closest point solves a one-dimensional monotone root problem, found by bisection
//!   (at most [`MAX_BISECTIONS`] steps, about 60 in practice), with the degenerate cases of
//!   a point on a symmetry plane handled in closed form;
//! - **box** (axis-aligned): exact;
//! - **cylinder** and **cone** (vertical axis): exact, as the distance in the meridian
//!   half-plane `(ρ, y)` to the shape's profile (a surface of revolution's nearest point
//!   lies in the point's own meridian plane). The cone's apex is `height` above the centre
//!   of its base disc; a negative height points it down (a vase-shaped crown).

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use sylva_core::ranged;

sylva_core::ranged!(center: DVec3, "center", -1e6, 1e6, " paper units");
sylva_core::ranged!(base: DVec3, "base", -1e6, 1e6, " paper units");
sylva_core::ranged!(radii: DVec3, "radii", 1e-6, 1e6, " paper units");
sylva_core::ranged!(size: DVec3, "size", 0.0, 2e6, " paper units");
ranged!(radius: f64, "radius", 0.0, 1e6, " paper units");
ranged!(height: f64, "height", -1e6, 1e6, " paper units");

/// Bisection steps the ellipsoid distance may take; f64 bisection stops sooner (about 60).
pub const MAX_BISECTIONS: usize = 200;

fn paper_center() -> DVec3 {
    DVec3::new(0.0, 200.0, 0.0)
}

fn paper_radius() -> f64 {
    150.0
}

/// A surface the endpoints should lie on, in paper units. Written in a config as a table
/// with `shape = "sphere" | "ellipsoid" | "box" | "cylinder" | "cone"` and its fields.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum TargetShape {
    /// A sphere; the default is the paper's, centred at (0, 200, 0) with radius 150.
    Sphere {
        /// Centre. Default (0, 200, 0).
        #[serde(default = "paper_center", deserialize_with = "center")]
        center: DVec3,
        /// Radius. Default 150.
        #[serde(default = "paper_radius", deserialize_with = "radius")]
        radius: f64,
    },
    /// An axis-aligned ellipsoid.
    Ellipsoid {
        /// Centre.
        #[serde(deserialize_with = "center")]
        center: DVec3,
        /// Semi-axes along x, y and z (each > 0).
        #[serde(deserialize_with = "radii")]
        radii: DVec3,
    },
    /// An axis-aligned box.
    Box {
        /// Centre.
        #[serde(deserialize_with = "center")]
        center: DVec3,
        /// Edge lengths along x, y and z.
        #[serde(deserialize_with = "size")]
        size: DVec3,
    },
    /// A vertical cylinder with both caps.
    Cylinder {
        /// Centre of the bottom disc.
        #[serde(deserialize_with = "base")]
        base: DVec3,
        /// Radius.
        #[serde(deserialize_with = "radius")]
        radius: f64,
        /// Height of the top disc above the base (negative: below).
        #[serde(deserialize_with = "height")]
        height: f64,
    },
    /// A vertical cone with its base disc.
    Cone {
        /// Centre of the base disc.
        #[serde(deserialize_with = "base")]
        base: DVec3,
        /// Radius of the base disc.
        #[serde(deserialize_with = "radius")]
        radius: f64,
        /// Height of the apex above the base (negative: below).
        #[serde(deserialize_with = "height")]
        height: f64,
    },
}

impl Default for TargetShape {
    fn default() -> Self {
        TargetShape::Sphere {
            center: paper_center(),
            radius: paper_radius(),
        }
    }
}

impl TargetShape {
    /// Unsigned distance from `p` to the surface, paper units.
    pub fn distance(&self, p: DVec3) -> f64 {
        match *self {
            TargetShape::Sphere { center, radius } => ((p - center).length() - radius).abs(),
            TargetShape::Ellipsoid { center, radii } => ellipsoid_distance(radii, p - center),
            TargetShape::Box { center, size } => box_distance(p - center, 0.5 * size),
            TargetShape::Cylinder {
                base,
                radius: r,
                height: h,
            } => profile_distance(
                p - base,
                &[
                    DVec2::ZERO,
                    DVec2::new(r, 0.0),
                    DVec2::new(r, h),
                    DVec2::new(0.0, h),
                ],
            ),
            TargetShape::Cone {
                base,
                radius: r,
                height: h,
            } => profile_distance(
                p - base,
                &[DVec2::ZERO, DVec2::new(r, 0.0), DVec2::new(0.0, h)],
            ),
        }
    }
}

/// Distance from `q` (relative to the centre) to the surface of a box of half-extents `h`.
fn box_distance(q: DVec3, h: DVec3) -> f64 {
    let d = q.abs() - h;
    let outside = d.max_element();
    if outside > 0.0 {
        d.max(DVec3::ZERO).length()
    } else {
        -outside
    }
}

/// Distance from `q` (relative to the base) to the surface of revolution about +Y whose
/// meridian profile is the polyline `profile` in `(ρ, y)`.
fn profile_distance(q: DVec3, profile: &[DVec2]) -> f64 {
    let m = DVec2::new(q.x.hypot(q.z), q.y);
    profile
        .windows(2)
        .map(|w| segment_distance(m, w[0], w[1]))
        .fold(f64::INFINITY, f64::min)
}

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + t * ab)).length()
}

/// Distance from `q` (relative to the centre) to an axis-aligned ellipsoid of semi-axes
/// `radii`, by Eberly's method: fold into the first octant, sort the axes by decreasing
/// semi-axis, and solve there.
fn ellipsoid_distance(radii: DVec3, q: DVec3) -> f64 {
    let e = radii.to_array();
    let y = q.abs().to_array();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| e[b].total_cmp(&e[a]));
    ellipsoid_sorted(order.map(|i| e[i]), order.map(|i| y[i]))
}

/// Eberly's `DistancePointEllipsoid`: `e0 ≥ e1 ≥ e2 > 0`, `y ≥ 0`.
fn ellipsoid_sorted([e0, e1, e2]: [f64; 3], [y0, y1, y2]: [f64; 3]) -> f64 {
    if y2 > 0.0 {
        if y1 > 0.0 {
            if y0 > 0.0 {
                let z = [y0 / e0, y1 / e1, y2 / e2];
                let g = z[0] * z[0] + z[1] * z[1] + z[2] * z[2] - 1.0;
                if g == 0.0 {
                    return 0.0;
                }
                let r = [(e0 / e2) * (e0 / e2), (e1 / e2) * (e1 / e2)];
                let s = ellipsoid_root(r, z, g);
                let x = DVec3::new(
                    r[0] * y0 / (s + r[0]),
                    r[1] * y1 / (s + r[1]),
                    y2 / (s + 1.0),
                );
                (x - DVec3::new(y0, y1, y2)).length()
            } else {
                // On the plane of the largest axis: the closest point stays on it.
                ellipse_distance(e1, e2, y1, y2)
            }
        } else if y0 > 0.0 {
            ellipse_distance(e0, e2, y0, y2)
        } else {
            (y2 - e2).abs()
        }
    } else {
        // On the plane of the two largest axes: near the centre the closest point leaves it.
        let (d0, d1) = (e0 * e0 - e2 * e2, e1 * e1 - e2 * e2);
        let (n0, n1) = (e0 * y0, e1 * y1);
        if n0 < d0 && n1 < d1 {
            let (xde0, xde1) = (n0 / d0, n1 / d1);
            let discr = 1.0 - xde0 * xde0 - xde1 * xde1;
            if discr > 0.0 {
                let x = DVec3::new(e0 * xde0, e1 * xde1, e2 * discr.sqrt());
                return (x - DVec3::new(y0, y1, 0.0)).length();
            }
        }
        ellipse_distance(e0, e1, y0, y1)
    }
}

/// Eberly's `DistancePointEllipse`: `e0 ≥ e1 > 0`, `y ≥ 0`.
fn ellipse_distance(e0: f64, e1: f64, y0: f64, y1: f64) -> f64 {
    if y1 > 0.0 {
        if y0 > 0.0 {
            let z = [y0 / e0, y1 / e1];
            let g = z[0] * z[0] + z[1] * z[1] - 1.0;
            if g == 0.0 {
                return 0.0;
            }
            let r0 = (e0 / e1) * (e0 / e1);
            let s = ellipse_root(r0, z, g);
            let (x0, x1) = (r0 * y0 / (s + r0), y1 / (s + 1.0));
            (x0 - y0).hypot(x1 - y1)
        } else {
            (y1 - e1).abs()
        }
    } else {
        let (n0, d0) = (e0 * y0, e0 * e0 - e1 * e1);
        if n0 < d0 {
            let xde0 = n0 / d0;
            let (x0, x1) = (e0 * xde0, e1 * (1.0 - xde0 * xde0).sqrt());
            (x0 - y0).hypot(x1)
        } else {
            (y0 - e0).abs()
        }
    }
}

/// Root of `Σ (rᵢ zᵢ / (s + rᵢ))² − 1` (with `r₂ = 1`), decreasing in `s`, by bisection.
fn ellipsoid_root(r: [f64; 2], z: [f64; 3], g: f64) -> f64 {
    let n = [r[0] * z[0], r[1] * z[1]];
    let f = |s: f64| {
        let (a, b, c) = (n[0] / (s + r[0]), n[1] / (s + r[1]), z[2] / (s + 1.0));
        a * a + b * b + c * c - 1.0
    };
    let hi = if g < 0.0 {
        0.0
    } else {
        DVec3::new(n[0], n[1], z[2]).length() - 1.0
    };
    bisect(f, z[2] - 1.0, hi)
}

/// Root of `(r₀ z₀ / (s + r₀))² + (z₁ / (s + 1))² − 1` by bisection.
fn ellipse_root(r0: f64, z: [f64; 2], g: f64) -> f64 {
    let n0 = r0 * z[0];
    let f = |s: f64| {
        let (a, b) = (n0 / (s + r0), z[1] / (s + 1.0));
        a * a + b * b - 1.0
    };
    let hi = if g < 0.0 { 0.0 } else { n0.hypot(z[1]) - 1.0 };
    bisect(f, z[1] - 1.0, hi)
}

/// Bisects a decreasing `f` on `[lo, hi]` until the midpoint no longer moves.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let mut s = 0.5 * (lo + hi);
    for _ in 0..MAX_BISECTIONS {
        s = 0.5 * (lo + hi);
        if s == lo || s == hi {
            break;
        }
        let v = f(s);
        if v > 0.0 {
            lo = s;
        } else if v < 0.0 {
            hi = s;
        } else {
            break;
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) {
        assert!((a - b).abs() <= tol, "{a} vs {b}");
    }

    #[test]
    fn sphere_is_the_papers_formula() {
        let s = TargetShape::default();
        close(s.distance(DVec3::ZERO), 50.0, 1e-12);
        close(s.distance(DVec3::new(0.0, 200.0, 0.0)), 150.0, 1e-12);
        close(s.distance(DVec3::new(0.0, 400.0, 0.0)), 50.0, 1e-12);
        close(s.distance(DVec3::new(150.0, 200.0, 0.0)), 0.0, 1e-12);
    }

    #[test]
    fn box_inside_outside_corner() {
        let b = TargetShape::Box {
            center: DVec3::new(0.0, 10.0, 0.0),
            size: DVec3::new(4.0, 2.0, 6.0),
        };
        close(b.distance(DVec3::new(0.0, 10.0, 0.0)), 1.0, 1e-12); // nearest face: y
        close(b.distance(DVec3::new(5.0, 10.0, 0.0)), 3.0, 1e-12);
        close(b.distance(DVec3::new(5.0, 15.0, 0.0)), 5.0, 1e-12); // corner edge (3, 4)
        close(b.distance(DVec3::new(1.5, 10.0, 2.5)), 0.5, 1e-12);
    }

    #[test]
    fn cylinder_side_caps_and_rim() {
        let c = TargetShape::Cylinder {
            base: DVec3::ZERO,
            radius: 3.0,
            height: 10.0,
        };
        close(c.distance(DVec3::new(0.0, 5.0, 0.0)), 3.0, 1e-12); // axis: side is nearest
        close(c.distance(DVec3::new(0.0, 1.0, 0.0)), 1.0, 1e-12); // near the bottom cap
        close(c.distance(DVec3::new(0.0, 12.0, 0.0)), 2.0, 1e-12); // above the top cap
        close(c.distance(DVec3::new(0.0, 5.0, 7.0)), 4.0, 1e-12);
        close(c.distance(DVec3::new(6.0, 14.0, 0.0)), 5.0, 1e-12); // rim (3, 4)
    }

    #[test]
    fn cone_slant_base_and_apex() {
        let c = TargetShape::Cone {
            base: DVec3::ZERO,
            radius: 3.0,
            height: 4.0,
        };
        close(c.distance(DVec3::new(0.0, 6.0, 0.0)), 2.0, 1e-12); // above the apex
        close(c.distance(DVec3::new(1.0, -2.0, 0.0)), 2.0, 1e-12); // under the base
        // Outward normal of the slant is (4, 3) / 5; from the slant's midpoint (1.5, 2):
        let p = DVec2::new(1.5, 2.0) + 2.0 * DVec2::new(0.8, 0.6);
        close(c.distance(DVec3::new(0.0, p.y, p.x)), 2.0, 1e-12);
        // Pointing down: the apex is at y = -4.
        let v = TargetShape::Cone {
            base: DVec3::ZERO,
            radius: 3.0,
            height: -4.0,
        };
        close(v.distance(DVec3::new(0.0, -6.0, 0.0)), 2.0, 1e-12);
    }

    #[test]
    fn ellipsoid_with_equal_radii_is_a_sphere() {
        let e = TargetShape::Ellipsoid {
            center: DVec3::new(1.0, 2.0, 3.0),
            radii: DVec3::splat(5.0),
        };
        for p in [
            DVec3::new(9.0, -4.0, 0.5),
            DVec3::new(1.0, 2.0, 3.5),
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(4.0, 6.0, 3.0),
        ] {
            close(
                e.distance(p),
                ((p - DVec3::new(1.0, 2.0, 3.0)).length() - 5.0).abs(),
                1e-9,
            );
        }
    }

    #[test]
    fn ellipsoid_on_axes_and_inside_near_centre() {
        let radii = DVec3::new(2.0, 5.0, 3.0);
        let e = TargetShape::Ellipsoid {
            center: DVec3::ZERO,
            radii,
        };
        close(e.distance(DVec3::new(0.0, 9.0, 0.0)), 4.0, 1e-9);
        // Near the centre on the x-z plane the nearest point is off-axis: on the ellipse
        // (2 cos t, 3 sin t) it minimises 5 - 6s + 5s² at s = sin t = 0.6.
        close(e.distance(DVec3::new(0.0, 0.0, -1.0)), 3.2f64.sqrt(), 1e-9);
        close(e.distance(DVec3::ZERO), 2.0, 1e-9); // nearest: the shortest semi-axis
        close(e.distance(DVec3::new(2.0, 0.0, 0.0)), 0.0, 1e-9);
    }

    /// Smallest distance to a dense sample of the surface, refined around the best sample.
    fn brute_ellipsoid(radii: DVec3, p: DVec3) -> f64 {
        let at = |u: f64, v: f64| {
            DVec3::new(
                radii.x * u.sin() * v.cos(),
                radii.y * u.cos(),
                radii.z * u.sin() * v.sin(),
            )
        };
        let (mut best, mut bu, mut bv) = (f64::INFINITY, 0.0, 0.0);
        let n = 400;
        for i in 0..=n {
            for j in 0..n {
                let (u, v) = (
                    std::f64::consts::PI * i as f64 / n as f64,
                    std::f64::consts::TAU * j as f64 / n as f64,
                );
                let d = (at(u, v) - p).length();
                if d < best {
                    (best, bu, bv) = (d, u, v);
                }
            }
        }
        let mut step = 0.02;
        while step > 1e-10 {
            let mut moved = false;
            for (du, dv) in [(step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)] {
                let d = (at(bu + du, bv + dv) - p).length();
                if d < best {
                    (best, bu, bv) = (d, bu + du, bv + dv);
                    moved = true;
                }
            }
            if !moved {
                step *= 0.5;
            }
        }
        best
    }

    #[test]
    fn ellipsoid_matches_brute_force() {
        let radii = DVec3::new(150.0, 100.0, 60.0);
        let e = TargetShape::Ellipsoid {
            center: DVec3::ZERO,
            radii,
        };
        for p in [
            DVec3::new(10.0, 20.0, 5.0),
            DVec3::new(200.0, -50.0, 30.0),
            DVec3::new(-90.0, 70.0, -40.0),
            DVec3::new(30.0, 0.0, 0.0),
            DVec3::new(0.0, 40.0, 0.0),
            DVec3::new(120.0, 10.0, 0.0),
            DVec3::new(3.0, 4.0, 0.0),
            DVec3::new(0.0, 150.0, 80.0),
        ] {
            let (fast, slow) = (e.distance(p), brute_ellipsoid(radii, p));
            close(fast, slow, 1e-6 * slow.max(1.0));
        }
    }
}
