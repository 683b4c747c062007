//! The triangle walker: fixed-point edge functions stepped incrementally over a clamped box.
//!
//! Positions are in sample units with [`SUB`] sub-sample steps (24.8 fixed point), so edge
//! functions are exact `i64` arithmetic: no cracks or double hits along shared edges (one
//! triangle owns each edge), and the same input always covers the same samples. The walker
//! knows nothing about depth or colour; it hands each covered sample's index and barycentric
//! weights to a closure, so the shadow pass and the colour pass share it.
//!
//! ```ignore
//! let tri = Tri::new([a, b, c], Cull::Back, width, height)?;
//! tri.for_each(|index, l1, l2| { /* l0 = 1 - l1 - l2 */ });
//! ```

/// Sub-sample steps per sample (8 bits of sub-pixel precision).
pub(crate) const SUB: f32 = 256.0;
const SUB_I: i64 = 256;
const HALF: i64 = SUB_I / 2;
/// Largest fixed-point coordinate accepted (64k samples either side of the origin); keeps
/// every edge-function product far inside `i64`.
pub(crate) const LIMIT: f32 = (1 << 24) as f32;

/// A vertex in fixed-point sample coordinates (x right, y down).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct ScreenVert {
    /// x in 1/[`SUB`] samples.
    pub x: i32,
    /// y in 1/[`SUB`] samples.
    pub y: i32,
}

impl ScreenVert {
    /// Converts sample coordinates; `None` for non-finite or far out-of-range values.
    #[inline]
    pub(crate) fn from_samples(x: f32, y: f32) -> Option<ScreenVert> {
        let (fx, fy) = (x * SUB, y * SUB);
        // `!(a <= b)` is also true for NaN.
        if !(fx.abs() <= LIMIT && fy.abs() <= LIMIT) {
            return None;
        }
        Some(ScreenVert {
            x: fx.round() as i32,
            y: fy.round() as i32,
        })
    }
}

/// Which screen orientations to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Cull {
    /// Skip triangles that are clockwise on screen (y down), i.e. facing away from the
    /// camera: mesh triangles are counter-clockwise seen from the front.
    Back,
    /// Draw both orientations (one-sided cards of a cut-out material, seen from both
    /// sides).
    None,
}

/// A triangle set up for walking.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tri {
    /// True when vertices 1 and 2 were swapped to make the area positive: the weights the
    /// walker hands out then belong to the original vertices 2 and 1.
    pub flipped: bool,
    x0: usize,
    x1: usize,
    y0: usize,
    y1: usize,
    width: usize,
    /// Edge values at the centre of sample (x0, y0), biased for the fill rule.
    start: [i64; 3],
    /// Per-sample steps in x and in y.
    dx: [i64; 3],
    dy: [i64; 3],
    inv_area: f32,
}

/// Twice the signed area of (a, b, p); positive when p is left of a->b in y-down coordinates
/// with the triangle wound so its area is positive.
#[inline]
fn edge(a: ScreenVert, b: ScreenVert, px: i64, py: i64) -> i64 {
    (i64::from(b.x) - i64::from(a.x)) * (py - i64::from(a.y))
        - (i64::from(b.y) - i64::from(a.y)) * (px - i64::from(a.x))
}

/// Whether a sample centre lying exactly on edge a->b belongs to this triangle. Two
/// triangles sharing an edge walk it in opposite directions, so exactly one owns it.
#[inline]
fn owns(a: ScreenVert, b: ScreenVert) -> bool {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    dy > 0 || (dy == 0 && dx < 0)
}

impl Tri {
    /// Sets up a triangle for a `width` x `height` sample grid; `None` when it is culled,
    /// degenerate (zero area) or covers no sample centre.
    #[inline]
    pub(crate) fn new(v: [ScreenVert; 3], cull: Cull, width: usize, height: usize) -> Option<Tri> {
        let [a, mut b, mut c] = v;
        let area = edge(a, b, i64::from(c.x), i64::from(c.y));
        let flipped = if area < 0 {
            // Counter-clockwise in y-up terms: the front face.
            std::mem::swap(&mut b, &mut c);
            true
        } else if area > 0 {
            if cull == Cull::Back {
                return None;
            }
            false
        } else {
            return None;
        };
        if width == 0 || height == 0 {
            return None;
        }
        // Bounding box of sample centres (k * SUB + HALF) inside the triangle, clamped to
        // the grid before any loop so huge triangles cost nothing extra.
        let min_x = i64::from(a.x.min(b.x).min(c.x));
        let max_x = i64::from(a.x.max(b.x).max(c.x));
        let min_y = i64::from(a.y.min(b.y).min(c.y));
        let max_y = i64::from(a.y.max(b.y).max(c.y));
        let last_x = width as i64 - 1;
        let last_y = height as i64 - 1;
        let x0 = (min_x - HALF + SUB_I - 1).div_euclid(SUB_I).max(0);
        let x1 = (max_x - HALF).div_euclid(SUB_I).min(last_x);
        let y0 = (min_y - HALF + SUB_I - 1).div_euclid(SUB_I).max(0);
        let y1 = (max_y - HALF).div_euclid(SUB_I).min(last_y);
        if x0 > x1 || y0 > y1 {
            return None;
        }
        let (px, py) = (x0 * SUB_I + HALF, y0 * SUB_I + HALF);
        // Edge k is opposite vertex k, so its value is vertex k's (unnormalised) weight.
        let edges = [(b, c), (c, a), (a, b)];
        let mut start = [0i64; 3];
        let mut dx = [0i64; 3];
        let mut dy = [0i64; 3];
        for (k, &(p, q)) in edges.iter().enumerate() {
            let bias = if owns(p, q) { 0 } else { -1 };
            start[k] = edge(p, q, px, py) + bias;
            dx[k] = -(i64::from(q.y) - i64::from(p.y)) * SUB_I;
            dy[k] = (i64::from(q.x) - i64::from(p.x)) * SUB_I;
        }
        Some(Tri {
            flipped,
            x0: x0 as usize,
            x1: x1 as usize,
            y0: y0 as usize,
            y1: y1 as usize,
            width,
            start,
            dx,
            dy,
            inv_area: 1.0 / area.unsigned_abs() as f32,
        })
    }

    /// The triangle's area in samples².
    #[inline]
    pub(crate) fn sample_area(&self) -> f32 {
        // inv_area is 1 / (twice the area in sub-sample units²).
        0.5 / (self.inv_area * SUB * SUB)
    }

    /// Calls `f(index, l1, l2)` for every covered sample, row by row, where `index` is
    /// `y * width + x` and `l1`, `l2` are the weights of (possibly swapped, see
    /// [`Tri::flipped`]) vertices 1 and 2.
    #[inline(always)]
    pub(crate) fn for_each(&self, mut f: impl FnMut(usize, f32, f32)) {
        let mut row = self.start;
        let last = (self.x1 - self.x0) as i64;
        // Long thin slivers (the sides of tubes) cover a small part of their box: for wide
        // boxes, solve each row's span from the edge values instead of testing every sample.
        let solve = last >= SPAN_SOLVE_WIDTH;
        for y in self.y0..=self.y1 {
            let (from, to) = if solve {
                match row_span(row, self.dx, last) {
                    Some(span) => span,
                    None => {
                        row = [
                            row[0] + self.dy[0],
                            row[1] + self.dy[1],
                            row[2] + self.dy[2],
                        ];
                        continue;
                    }
                }
            } else {
                (0, last)
            };
            let mut w = [
                row[0] + from * self.dx[0],
                row[1] + from * self.dx[1],
                row[2] + from * self.dx[2],
            ];
            let base = y * self.width + self.x0;
            for x in from as usize..=to as usize {
                if (w[0] | w[1] | w[2]) >= 0 {
                    f(
                        base + x,
                        w[1] as f32 * self.inv_area,
                        w[2] as f32 * self.inv_area,
                    );
                }
                w[0] += self.dx[0];
                w[1] += self.dx[1];
                w[2] += self.dx[2];
            }
            row = [
                row[0] + self.dy[0],
                row[1] + self.dy[1],
                row[2] + self.dy[2],
            ];
        }
    }
}

/// Boxes at least this many samples wide have their row spans solved, not scanned.
const SPAN_SOLVE_WIDTH: i64 = 8;

/// The range of steps `t` in `0..=last` where every `w[k] + t * dx[k] >= 0`, if any.
#[inline]
fn row_span(w: [i64; 3], dx: [i64; 3], last: i64) -> Option<(i64, i64)> {
    let (mut from, mut to) = (0i64, last);
    for k in 0..3 {
        let (w, d) = (w[k], dx[k]);
        if d > 0 {
            if w < 0 {
                // Smallest t with w + t * d >= 0.
                from = from.max((-w + d - 1) / d);
            }
        } else if d < 0 {
            if w < 0 {
                return None;
            }
            // Largest t with w + t * d >= 0.
            to = to.min(w / -d);
        } else if w < 0 {
            return None;
        }
    }
    (from <= to).then_some((from, to))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32) -> ScreenVert {
        ScreenVert::from_samples(x, y).unwrap()
    }

    fn coverage(tris: &[[ScreenVert; 3]], cull: Cull, w: usize, h: usize) -> Vec<u32> {
        let mut hits = vec![0u32; w * h];
        for &t in tris {
            if let Some(tri) = Tri::new(t, cull, w, h) {
                tri.for_each(|i, _, _| hits[i] += 1);
            }
        }
        hits
    }

    #[test]
    fn shared_edges_are_drawn_exactly_once() {
        // A square split along its diagonal, with corners on sample centres so many centres
        // lie exactly on the shared and outer edges. Screen y is down, so (0,0)-(0,8)-(8,8)
        // is counter-clockwise in y-up terms: a front face.
        let (a, b, c, d) = (v(0.5, 0.5), v(0.5, 8.5), v(8.5, 8.5), v(8.5, 0.5));
        let hits = coverage(&[[a, b, c], [a, c, d]], Cull::Back, 12, 12);
        assert!(hits.iter().all(|&n| n <= 1), "no sample is hit twice");
        assert_eq!(hits.iter().filter(|&&n| n == 1).count(), 64);
    }

    #[test]
    fn back_faces_are_culled_unless_asked() {
        let (a, b, c) = (v(1.0, 1.0), v(1.0, 9.0), v(9.0, 9.0));
        assert!(Tri::new([a, b, c], Cull::Back, 16, 16).is_some());
        assert!(Tri::new([a, c, b], Cull::Back, 16, 16).is_none());
        assert!(Tri::new([a, c, b], Cull::None, 16, 16).is_some());
        assert!(
            Tri::new([a, a, c], Cull::None, 16, 16).is_none(),
            "zero area"
        );
    }

    #[test]
    fn weights_sum_to_one_and_match_vertices() {
        let t = [v(0.0, 0.0), v(0.0, 30.0), v(30.0, 30.0)];
        let tri = Tri::new(t, Cull::Back, 32, 32).unwrap();
        let mut n = 0;
        tri.for_each(|i, l1, l2| {
            let (x, y) = ((i % 32) as f32 + 0.5, (i / 32) as f32 + 0.5);
            let l0 = 1.0 - l1 - l2;
            // Rebuild the sample position from the weights in the original vertex order.
            let (w1, w2) = if tri.flipped { (l2, l1) } else { (l1, l2) };
            let px = l0 * 0.0 + w1 * 0.0 + w2 * 30.0;
            let py = l0 * 0.0 + w1 * 30.0 + w2 * 30.0;
            assert!((px - x).abs() < 1e-3 && (py - y).abs() < 1e-3);
            n += 1;
        });
        assert!(n > 400);
    }

    #[test]
    fn solved_spans_match_a_full_scan() {
        // Slivers at many angles; the row solver must hit exactly the samples a scan does.
        for k in 0..40 {
            let a = k as f32 * 0.157;
            let (c, s) = (a.cos(), a.sin());
            let t = [
                v(32.3 - 30.0 * c, 32.1 - 30.0 * s),
                v(32.3 + 30.0 * c + 2.0 * s, 32.1 + 30.0 * s - 2.0 * c),
                v(32.3 + 30.0 * c - 1.5 * s, 32.1 + 30.0 * s + 1.5 * c),
            ];
            let Some(tri) = Tri::new(t, Cull::None, 64, 64) else {
                continue;
            };
            let mut solved = Vec::new();
            tri.for_each(|i, _, _| solved.push(i));
            let mut scanned = Vec::new();
            let mut row = tri.start;
            for y in tri.y0..=tri.y1 {
                let mut w = row;
                for x in tri.x0..=tri.x1 {
                    if (w[0] | w[1] | w[2]) >= 0 {
                        scanned.push(y * 64 + x);
                    }
                    (0..3).for_each(|e| w[e] += tri.dx[e]);
                }
                (0..3).for_each(|e| row[e] += tri.dy[e]);
            }
            assert_eq!(solved, scanned, "angle {a}");
            assert!(!solved.is_empty());
        }
    }

    #[test]
    fn huge_and_offscreen_triangles_are_clamped() {
        let big = [v(-60000.0, -60000.0), v(-60000.0, 60000.0), v(60000.0, 0.0)];
        let hits = coverage(&[big], Cull::None, 16, 16);
        assert!(hits.iter().all(|&n| n == 1));
        let off = [v(100.0, 100.0), v(100.0, 200.0), v(200.0, 200.0)];
        assert!(Tri::new(off, Cull::None, 16, 16).is_none());
        assert!(ScreenVert::from_samples(f32::NAN, 0.0).is_none());
        assert!(ScreenVert::from_samples(1e30, 0.0).is_none());
    }
}
