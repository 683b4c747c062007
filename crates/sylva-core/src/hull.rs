//! The convex hull of a cloud of points, for the volume a crown spans.
//!
//! An incremental hull in double precision: start from four points that span space, then add
//! each remaining point that lies outside, replacing the faces it sees by a fan of faces from
//! their horizon to it. Each point scans every face, so the cost is points times hull faces,
//! which suits the few thousand skeleton points of a plant. The result does not depend on
//! anything but the order of the points given.

use glam::DVec3;

/// Volume of the convex hull of `points`, in the points' units cubed. Zero for fewer than
/// four points, or for points that lie (within 1e-9 of their extent) on a plane, a line or
/// a point.
pub fn convex_hull_volume(points: &[DVec3]) -> f64 {
    let Some(hull) = Hull::new(points) else {
        return 0.0;
    };
    hull.volume()
}

/// Faces wound counter-clockwise seen from outside, as indices into the points.
struct Hull<'a> {
    points: &'a [DVec3],
    faces: Vec<[usize; 3]>,
    /// A point inside, the origin of the volume's tetrahedra.
    inside: DVec3,
}

impl<'a> Hull<'a> {
    fn new(points: &'a [DVec3]) -> Option<Hull<'a>> {
        let finite: Vec<usize> = (0..points.len())
            .filter(|&i| points[i].is_finite())
            .collect();
        let first = *finite.first()?;
        let extent = finite
            .iter()
            .map(|&i| (points[i] - points[first]).abs().max_element())
            .fold(0.0, f64::max);
        if extent == 0.0 {
            return None;
        }
        let eps = 1e-9 * extent;
        // A starting tetrahedron: the two points furthest apart along the widest axis, the
        // point furthest from their line, the point furthest from their plane.
        let axis = {
            let (lo, hi) = finite.iter().fold(
                (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                |(lo, hi), &i| (lo.min(points[i]), hi.max(points[i])),
            );
            (hi - lo).max_position()
        };
        let a = *finite
            .iter()
            .min_by(|&&i, &&j| points[i][axis].total_cmp(&points[j][axis]))?;
        let b = *finite
            .iter()
            .max_by(|&&i, &&j| points[i][axis].total_cmp(&points[j][axis]))?;
        let (pa, pb) = (points[a], points[b]);
        let line = |i: usize| (points[i] - pa).cross(pb - pa).length();
        let c = *finite
            .iter()
            .max_by(|&&i, &&j| line(i).total_cmp(&line(j)))?;
        if line(c) <= eps * (pb - pa).length() {
            return None;
        }
        let normal = (pb - pa).cross(points[c] - pa);
        let plane = |i: usize| (points[i] - pa).dot(normal);
        let d = *finite
            .iter()
            .max_by(|&&i, &&j| plane(i).abs().total_cmp(&plane(j).abs()))?;
        if plane(d).abs() <= eps * normal.length() {
            return None;
        }
        let inside = (pa + pb + points[c] + points[d]) * 0.25;
        let mut hull = Hull {
            points,
            faces: Vec::new(),
            inside,
        };
        for face in [[a, b, c], [a, b, d], [a, c, d], [b, c, d]] {
            hull.faces.push(hull.outward(face));
        }
        for &p in &finite {
            if p != a && p != b && p != c && p != d {
                hull.add(p, eps);
            }
        }
        Some(hull)
    }

    /// `face` wound so that `inside` lies behind it.
    fn outward(&self, [a, b, c]: [usize; 3]) -> [usize; 3] {
        if self.distance([a, b, c], self.inside) > 0.0 {
            [a, c, b]
        } else {
            [a, b, c]
        }
    }

    /// Signed distance of `p` in front of `face`, times twice the face's area.
    fn distance(&self, [a, b, c]: [usize; 3], p: DVec3) -> f64 {
        let (pa, pb, pc) = (self.points[a], self.points[b], self.points[c]);
        (pb - pa).cross(pc - pa).dot(p - pa)
    }

    /// Adds point `p` if it lies further than `eps` outside some face.
    fn add(&mut self, p: usize, eps: f64) {
        let point = self.points[p];
        let visible: Vec<bool> = self
            .faces
            .iter()
            .map(|&f| {
                let (pa, pb, pc) = (self.points[f[0]], self.points[f[1]], self.points[f[2]]);
                let n = (pb - pa).cross(pc - pa);
                n.dot(point - pa) > eps * n.length()
            })
            .collect();
        if !visible.contains(&true) {
            return;
        }
        // The horizon: edges of seen faces whose reverse belongs to an unseen face, that is,
        // is not itself an edge of a seen face. Sorted, so the result does not hang on hashing.
        let mut seen_edges: Vec<(usize, usize)> = self
            .faces
            .iter()
            .zip(&visible)
            .filter(|(_, v)| **v)
            .flat_map(|(f, _)| [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])])
            .collect();
        seen_edges.sort_unstable();
        let horizon: Vec<(usize, usize)> = seen_edges
            .iter()
            .filter(|&&(u, v)| seen_edges.binary_search(&(v, u)).is_err())
            .copied()
            .collect();
        let mut kept: Vec<[usize; 3]> = self
            .faces
            .iter()
            .zip(&visible)
            .filter(|(_, v)| !**v)
            .map(|(f, _)| *f)
            .collect();
        // Each horizon edge keeps the winding it had in its seen face, so the new face faces
        // outwards.
        kept.extend(horizon.iter().map(|&(u, v)| [u, v, p]));
        self.faces = kept;
    }

    fn volume(&self) -> f64 {
        self.faces
            .iter()
            .map(|&f| -self.distance(f, self.inside) / 6.0)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(size: f64) -> Vec<DVec3> {
        (0..8)
            .map(|i| {
                DVec3::new(
                    f64::from(i & 1),
                    f64::from((i >> 1) & 1),
                    f64::from((i >> 2) & 1),
                ) * size
            })
            .collect()
    }

    #[test]
    fn a_cube_holds_its_volume_whatever_lies_inside() {
        let mut points = cube(2.0);
        assert!((convex_hull_volume(&points) - 8.0).abs() < 1e-12);
        // Points inside, on faces and on edges change nothing.
        for i in 0..200 {
            let t = f64::from(i) / 200.0;
            points.push(DVec3::new(
                t * 2.0,
                (t * 7.3).fract() * 2.0,
                (t * 3.1).fract() * 2.0,
            ));
            points.push(DVec3::new(t * 2.0, 0.0, 2.0));
            points.push(DVec3::new(1.0, 1.0, t * 2.0));
        }
        assert!((convex_hull_volume(&points) - 8.0).abs() < 1e-9);
    }

    #[test]
    fn a_tetrahedron_and_a_rotated_box() {
        let tetra = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        assert!((convex_hull_volume(&tetra) - 1.0 / 6.0).abs() < 1e-12);
        // A 1 x 2 x 3 box turned about two axes, then shifted.
        let q = glam::DQuat::from_euler(glam::EulerRot::YXZ, 0.7, 0.3, 0.0);
        let boxed: Vec<DVec3> = cube(1.0)
            .iter()
            .map(|p| q * (*p * DVec3::new(1.0, 2.0, 3.0)) + DVec3::new(5.0, -1.0, 2.0))
            .collect();
        assert!((convex_hull_volume(&boxed) - 6.0).abs() < 1e-9);
    }

    #[test]
    fn points_on_a_sphere_approach_its_volume() {
        // A Fibonacci sphere of radius 1: the hull is a little smaller than 4π/3.
        let n = 2000;
        let points: Vec<DVec3> = (0..n)
            .map(|i| {
                let y = 1.0 - 2.0 * (f64::from(i) + 0.5) / f64::from(n);
                let r = (1.0 - y * y).sqrt();
                let a = f64::from(i) * std::f64::consts::PI * (3.0 - 5f64.sqrt());
                DVec3::new(r * a.cos(), y, r * a.sin())
            })
            .collect();
        let v = convex_hull_volume(&points);
        let sphere = 4.0 / 3.0 * std::f64::consts::PI;
        assert!(v < sphere && v > 0.99 * sphere, "{v}");
    }

    proptest::proptest! {
        /// Within its points' box, never smaller for more points, and blind to their order.
        #[test]
        fn bounded_growing_and_order_free(
            raw in proptest::collection::vec((0.0..1.0f64, 0.0..2.0f64, 0.0..3.0f64), 4..120),
        ) {
            let points: Vec<DVec3> = raw.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect();
            let v = convex_hull_volume(&points);
            proptest::prop_assert!((0.0..=6.0 + 1e-9).contains(&v), "{}", v);
            let half = convex_hull_volume(&points[..points.len() / 2]);
            proptest::prop_assert!(half <= v + 1e-9, "{} > {}", half, v);
            let reversed: Vec<DVec3> = points.iter().rev().copied().collect();
            let r = convex_hull_volume(&reversed);
            proptest::prop_assert!((r - v).abs() <= 1e-9 * v.max(1.0), "{} != {}", r, v);
        }
    }

    #[test]
    fn flat_or_too_few_points_have_no_volume() {
        assert_eq!(convex_hull_volume(&[]), 0.0);
        assert_eq!(convex_hull_volume(&[DVec3::ONE; 5]), 0.0);
        assert_eq!(convex_hull_volume(&[DVec3::ZERO, DVec3::X, DVec3::Y]), 0.0);
        let line: Vec<DVec3> = (0..10).map(|i| DVec3::X * f64::from(i)).collect();
        assert_eq!(convex_hull_volume(&line), 0.0);
        let plane: Vec<DVec3> = (0..20)
            .map(|i| DVec3::new(f64::from(i % 5), 0.0, f64::from(i / 5)))
            .collect();
        assert_eq!(convex_hull_volume(&plane), 0.0);
        // Non-finite points are left out.
        let mut cube = cube(1.0);
        cube.push(DVec3::NAN);
        assert!((convex_hull_volume(&cube) - 1.0).abs() < 1e-12);
    }
}
