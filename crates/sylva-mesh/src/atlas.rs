//! Leaf, needle and petal cut-outs Sylva draws itself: grey shading with an alpha that holds
//! the outline.
//!
//! A **leaf atlas** ([`leaf_atlas`]) is [`ATLAS_SIZE`]² pixels of grey and alpha. Its top
//! half holds [`BRANCHLET_CELLS`] branchlets of the [`LeafKind`] (a twig with side twigs and
//! a few dozen leaves, or a shoot with side shoots of needles), its bottom half
//! [`SPRAY_CELLS`] sprays (a few leaves on a bit of twig, or a tuft of needles), each drawn
//! afresh with other angles, sizes and tones so neighbouring cards differ. A card shows one
//! cell of its size ([`card_uvs`]): its twig enters at the middle of the cell's bottom edge
//! (the card's base) and runs up towards its top (the card's tip). Outlines:
//!
//! | shape | kinds | outline |
//! | --- | --- | --- |
//! | elliptic | birch (toothed), beech, privet | widest a third of the way up, pointed tip |
//! | round | aspen | nearly round, finely scalloped, on a long stalk |
//! | lobed | oak | four or five rounded lobes a side, widest above the middle |
//! | palmate | maple | five pointed lobes spread from the stalk, veins along each |
//! | lanceolate | willow | long and narrow, tapering to both ends |
//! | pinnate | ash | four pairs of leaflets and one at the tip, on a stalk |
//! | needles | pine (pairs in tufts), spruce (all round), fir (two flat ranks) | thin and pointed |
//!
//! Each leaf has its own tone, a pale midrib, side veins, margins a little darker than the
//! middle and one half a little lighter (the blade folds along its midrib). Where alpha is 0
//! the grey is the leaves' mean, so filtering and mipmaps never darken the outline.
//!
//! A **petal cut-out** ([`petal_picture`]) is a petal's outline (rounded, widest two thirds
//! of the way up) over the petal design of a texture id ([`crate::texture`]), or plain.
//!
//! Grey multiplies the material's colour as in [`crate::texture`]; alpha is coverage, so a
//! writer's `alphaCutoff` of one half cuts exactly along the outline. Everything is computed
//! with `+ - * /`, `sqrt` and `floor` (sines and cosines by a polynomial here), so the
//! pictures are the same bytes on every machine.

use std::collections::HashMap;
use std::sync::{Arc, LazyLock, Mutex};

use image::GrayAlphaImage;
use sylva_core::glam::Vec2;
use sylva_core::species::{Card, LeafKind, LeafShape};

use crate::texture::{TEXTURE_SIZE, design, fbm, hash, smooth, to_line, unit};

/// Side of a leaf atlas, pixels.
pub const ATLAS_SIZE: u32 = 1024;
/// Branchlet cells, side by side in the atlas's top half.
pub const BRANCHLET_CELLS: u32 = 2;
/// Spray cells, four by two in the atlas's bottom half.
pub const SPRAY_CELLS: u32 = 8;
/// Side of a petal cut-out, pixels (that of the petal designs).
pub const PETAL_SIZE: u32 = TEXTURE_SIZE;

/// Cells of a card size.
pub fn cells(card: Card) -> u32 {
    match card {
        Card::Branchlet => BRANCHLET_CELLS,
        Card::Spray => SPRAY_CELLS,
    }
}

/// Pixel origin and side of cell `c` of a card size.
fn cell_rect(card: Card, c: u32) -> (u32, u32, u32) {
    match card {
        Card::Branchlet => {
            let side = ATLAS_SIZE / 2;
            ((c % 2) * side, 0, side)
        }
        Card::Spray => {
            let side = ATLAS_SIZE / 4;
            ((c % 4) * side, ATLAS_SIZE / 2 + (c / 4 % 2) * side, side)
        }
    }
}

/// The texture coordinates of a card of size `card` showing cell `variant` (modulo the
/// cells of its size), corner by corner: base left, base right, tip right, tip left (`v`
/// runs down the picture, so the base is the cell's bottom edge).
pub fn card_uvs(card: Card, variant: u32) -> [[f32; 2]; 4] {
    let (x0, y0, side) = cell_rect(card, variant % cells(card));
    let inv = 1.0 / ATLAS_SIZE as f32;
    // Half a texel in from the cell's edges, so filtering never reads the next cell.
    let (u0, u1) = ((x0 as f32 + 0.5) * inv, ((x0 + side) as f32 - 0.5) * inv);
    let (v0, v1) = ((y0 as f32 + 0.5) * inv, ((y0 + side) as f32 - 0.5) * inv);
    [[u0, v1], [u1, v1], [u1, v0], [u0, v0]]
}

/// The UVs of a petal card corner by corner, as [`card_uvs`] (the whole picture).
pub const PETAL_UVS: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];

static LEAF_ATLASES: LazyLock<Mutex<HashMap<LeafKind, Arc<GrayAlphaImage>>>> =
    LazyLock::new(Mutex::default);
static PETALS: LazyLock<Mutex<HashMap<Option<u16>, Arc<GrayAlphaImage>>>> =
    LazyLock::new(Mutex::default);

/// The atlas of a leaf kind, drawn once per process.
pub fn leaf_atlas(kind: LeafKind) -> Arc<GrayAlphaImage> {
    if let Some(a) = LEAF_ATLASES
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .get(&kind)
    {
        return a.clone();
    }
    let atlas = Arc::new(draw_atlas(kind));
    LEAF_ATLASES
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .insert(kind, atlas.clone());
    atlas
}

/// A petal's cut-out over texture `design`'s shading (plain when `None`), drawn once per
/// process. Ids are kept whatever they are: a plant names only a few.
pub fn petal_picture(design: Option<u16>) -> Arc<GrayAlphaImage> {
    // Ids beyond the designs' count only reseed them; keep the cache to the ids in use.
    if let Some(a) = PETALS
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .get(&design)
    {
        return a.clone();
    }
    let picture = Arc::new(draw_petal(design));
    let mut kept = PETALS.lock().unwrap_or_else(|p| p.into_inner());
    if kept.len() >= 256 {
        kept.clear();
    }
    kept.insert(design, picture.clone());
    picture
}

static FILLS: LazyLock<Mutex<HashMap<(LeafKind, Card), f32>>> = LazyLock::new(Mutex::default);

/// The share of a card's area its leaves cover (alpha at least one half), averaged over
/// the cells of its size: a card's leaf area is its area times this. Measured once per
/// process.
pub fn leaf_fill(kind: LeafKind, card: Card) -> f32 {
    if let Some(&f) = FILLS
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .get(&(kind, card))
    {
        return f;
    }
    let fill = measure_fill(kind, card);
    FILLS
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .insert((kind, card), fill);
    fill
}

/// [`leaf_fill`], measured.
fn measure_fill(kind: LeafKind, card: Card) -> f32 {
    let atlas = leaf_atlas(kind);
    let (mut covered, mut all) = (0usize, 0usize);
    for c in 0..cells(card) {
        let (x0, y0, side) = cell_rect(card, c);
        for y in y0..y0 + side {
            for x in x0..x0 + side {
                covered += usize::from(atlas.get_pixel(x, y).0[1] >= 128);
            }
        }
        all += (side * side) as usize;
    }
    covered as f32 / all as f32
}

// ---------------------------------------------------------------------------------------
// Deterministic trigonometry: IEEE operations only.

/// `(sin x, cos x)` to about 1e-7, from a Taylor polynomial on a quarter turn.
pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
    const HALF_PI: f32 = std::f32::consts::FRAC_PI_2;
    let k = (x / HALF_PI + 0.5).floor();
    let r = x - k * HALF_PI;
    let r2 = r * r;
    let s = r * (1.0 - r2 / 6.0 * (1.0 - r2 / 20.0 * (1.0 - r2 / 42.0 * (1.0 - r2 / 72.0))));
    let c = 1.0 - r2 / 2.0 * (1.0 - r2 / 12.0 * (1.0 - r2 / 30.0 * (1.0 - r2 / 56.0)));
    match (k as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// The direction at `angle` radians from +y towards +x (0 is straight up the cell).
fn heading(angle: f32) -> Vec2 {
    let (s, c) = sin_cos(angle);
    Vec2::new(s, c)
}

/// The angle of `v` from +y towards +x, in `-π..=π`, by a polynomial arctangent.
fn angle_of(v: Vec2) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (x, y) = (v.x, v.y);
    if x == 0.0 && y == 0.0 {
        return 0.0;
    }
    // atan2(x, y) with the octant folded onto |t| <= 1.
    let (ax, ay) = (x.abs(), y.abs());
    let t = ax.min(ay) / ax.max(ay);
    let t2 = t * t;
    // Minimax-like polynomial for atan on [0, 1], error about 1e-5 rad.
    let mut a =
        t * (0.999_866 + t2 * (-0.330_299 + t2 * (0.180_141 + t2 * (-0.085_133 + t2 * 0.020_835))));
    if ax > ay {
        a = FRAC_PI_2 - a;
    }
    if y < 0.0 {
        a = PI - a;
    }
    if x < 0.0 { -a } else { a }
}

// ---------------------------------------------------------------------------------------
// The canvas: premultiplied grey and coverage, painted over.

struct Canvas {
    size: usize,
    /// Grey times alpha.
    grey: Vec<f32>,
    alpha: Vec<f32>,
}

/// A cell of the canvas: its pixel origin and side.
#[derive(Clone, Copy)]
struct Cell {
    x0: f32,
    y0: f32,
    side: f32,
}

impl Cell {
    /// A cell point (x across from -½ to ½, y up from 0 at the base to 1) in pixels.
    fn to_pixels(self, p: Vec2) -> Vec2 {
        Vec2::new(
            self.x0 + (p.x + 0.5) * self.side,
            self.y0 + (1.0 - p.y) * self.side,
        )
    }

    /// A pixel centre as a cell point.
    fn to_cell(self, px: usize, py: usize) -> Vec2 {
        Vec2::new(
            (px as f32 + 0.5 - self.x0) / self.side - 0.5,
            1.0 - (py as f32 + 0.5 - self.y0) / self.side,
        )
    }
}

impl Canvas {
    fn new(size: usize) -> Canvas {
        Canvas {
            size,
            grey: vec![0.0; size * size],
            alpha: vec![0.0; size * size],
        }
    }

    /// Paints every pixel of `cell` within `reach` (cell units) of the box from `lo` to
    /// `hi` with what `shade` gives for its cell point: `(grey, coverage)`.
    fn paint(
        &mut self,
        cell: Cell,
        lo: Vec2,
        hi: Vec2,
        shade: impl Fn(Vec2) -> Option<(f32, f32)>,
    ) {
        let a = cell.to_pixels(Vec2::new(lo.x, hi.y));
        let b = cell.to_pixels(Vec2::new(hi.x, lo.y));
        let clamp = |v: f32, lo: f32, hi: f32| v.max(lo).min(hi);
        let x0 = clamp(a.x.floor() - 1.0, cell.x0, cell.x0 + cell.side) as usize;
        let x1 = clamp(b.x.floor() + 2.0, cell.x0, cell.x0 + cell.side) as usize;
        let y0 = clamp(a.y.floor() - 1.0, cell.y0, cell.y0 + cell.side) as usize;
        let y1 = clamp(b.y.floor() + 2.0, cell.y0, cell.y0 + cell.side) as usize;
        for py in y0..y1 {
            for px in x0..x1 {
                let Some((g, cover)) = shade(cell.to_cell(px, py)) else {
                    continue;
                };
                if cover <= 0.0 {
                    continue;
                }
                let i = py * self.size + px;
                let keep = 1.0 - cover;
                self.grey[i] = g * cover + self.grey[i] * keep;
                self.alpha[i] = cover + self.alpha[i] * keep;
            }
        }
    }

    /// A tapered stalk (twig, petiole, rachis or needle) from `a` to `b`, `w0` and `w1` wide
    /// (cell units), of grey `tone`, lighter along its middle.
    fn stalk(&mut self, cell: Cell, a: Vec2, b: Vec2, w0: f32, w1: f32, tone: f32) {
        let pad = Vec2::splat(0.5 * w0.max(w1) + 2.0 / cell.side);
        let (lo, hi) = (a.min(b) - pad, a.max(b) + pad);
        let ab = b - a;
        let len2 = ab.length_squared().max(1e-12);
        let px = 1.0 / cell.side;
        self.paint(cell, lo, hi, |p| {
            let t = ((p - a).dot(ab) / len2).clamp(0.0, 1.0);
            let half = 0.5 * (w0 + (w1 - w0) * t);
            let d = (p - (a + ab * t)).length();
            // At least a pixel wide, fainter when thinner, so fine needles stay visible.
            let (half_px, faint) = if half < 0.5 * px {
                (0.5 * px, (2.0 * half / px).max(0.35))
            } else {
                (half, 1.0)
            };
            let cover = ((half_px - d) / px + 0.5).clamp(0.0, 1.0) * faint;
            let across = (d / half_px).min(1.0);
            Some((tone * (1.08 - 0.2 * across * across), cover))
        });
    }

    /// A blade from `base` along `dir` (unit), `length` long, of `shape`; `seed` varies its
    /// tone and veins.
    #[allow(clippy::too_many_arguments)]
    fn blade(
        &mut self,
        cell: Cell,
        base: Vec2,
        dir: Vec2,
        length: f32,
        width_ratio: f32,
        shape: LeafShape,
        tone: f32,
        seed: u32,
    ) {
        let side = Vec2::new(dir.y, -dir.x);
        let reach = length * (0.6 * width_ratio).max(0.6);
        let corners = [
            base + side * reach,
            base - side * reach,
            base + dir * length + side * reach,
            base + dir * length - side * reach,
            base - dir * (0.4 * length) + side * reach,
            base - dir * (0.4 * length) - side * reach,
        ];
        let lo = corners.iter().fold(Vec2::splat(f32::MAX), |m, c| m.min(*c));
        let hi = corners.iter().fold(Vec2::splat(f32::MIN), |m, c| m.max(*c));
        let px = 1.0 / cell.side;
        let fold = if unit(hash(seed, 1, 3)) < 0.5 {
            1.0
        } else {
            -1.0
        };
        self.paint(cell, lo, hi, |p| {
            let d = p - base;
            let s = d.dot(dir) / length;
            let t = d.dot(side) / length;
            let (half, s_vein, t_off) = match shape {
                LeafShape::Palmate => {
                    let r = d.length() / length;
                    let phi = angle_of(Vec2::new(d.dot(side), d.dot(dir)));
                    let edge = palmate_radius(phi);
                    // Polar: "half" is the radial room left; veins along the lobes.
                    return Some(shade_palmate(r, phi, edge, px / length, tone, seed));
                }
                _ => {
                    if !(0.0..=1.0).contains(&s) {
                        return None;
                    }
                    (profile(shape, s, width_ratio), s, t.abs())
                }
            };
            let cover = ((half - t_off) * length / px + 0.5).clamp(0.0, 1.0);
            if cover <= 0.0 {
                return None;
            }
            Some((shade_blade(s_vein, t, half, tone, fold, seed), cover))
        });
    }
}

/// Half the width of a blade of `shape` at `s` (0 at its base to 1 at its tip), in units of
/// its length.
fn profile(shape: LeafShape, s: f32, w: f32) -> f32 {
    match shape {
        // sqrt(s)(1 - s) peaks at s = 1/3 with 0.385: rounded base, pointed tip.
        LeafShape::Elliptic { toothed } => {
            let h = 1.3 * w * s.sqrt() * (1.0 - s);
            if toothed {
                h * (1.0 - 0.09 * (s * 16.0 - (s * 16.0).floor()))
            } else {
                h
            }
        }
        LeafShape::Round => {
            let h = w * (s * (1.0 - s)).sqrt() * (1.0 - 0.25 * s * s * s);
            h * (1.0 - 0.05 * (1.0 - 2.0 * to_line(s * 11.0)))
        }
        LeafShape::Lobed => {
            let body = w * (s * (1.0 - s)).sqrt() * (0.72 + 0.56 * s);
            let d = 2.0 * to_line(s * 4.6 + 0.3);
            let lobe = 1.0 - d * d;
            // Small ear-like lobes at the very base, as English oak has.
            body * (0.58 + 0.42 * lobe)
                + if s < 0.08 {
                    0.04 * w * (1.0 - s / 0.08)
                } else {
                    0.0
                }
        }
        LeafShape::Lanceolate => w * 2.0 * s * (1.0 - s) * (1.15 - 0.3 * s),
        LeafShape::Pinnate | LeafShape::Needle => w * 1.3 * s.sqrt() * (1.0 - s),
        LeafShape::Palmate => 0.0,
    }
}

/// A maple blade's edge, in units of its length, at angle `phi` from its midrib: five
/// pointed lobes, the middle three long, with small teeth.
fn palmate_radius(phi: f32) -> f32 {
    const LOBES: [(f32, f32); 5] = [
        (0.0, 1.0),
        (1.15, 0.9),
        (-1.15, 0.9),
        (2.2, 0.55),
        (-2.2, 0.55),
    ];
    let mut r = 0.28f32;
    for (at, reach) in LOBES {
        let off = (phi - at).abs();
        let p = (1.0 - off / 0.62).max(0.0);
        r = r.max(0.28 + (reach - 0.28) * p * p * (3.0 - 2.0 * p));
    }
    r * (1.0 - 0.06 * to_line(phi * 9.0))
}

/// Grey and coverage of a palmate blade's pixel at radius `r` and angle `phi`.
fn shade_palmate(r: f32, phi: f32, edge: f32, px: f32, tone: f32, seed: u32) -> (f32, f32) {
    let cover = ((edge - r) / px + 0.5).clamp(0.0, 1.0);
    let mut vein: f32 = 0.0;
    for at in [0.0f32, 1.15, -1.15, 2.2, -2.2] {
        let off = (phi - at).abs() * r;
        vein = vein.max(1.0 - smooth(0.004, 0.012, off));
    }
    let rim = (r / edge.max(1e-3)).min(1.0);
    let mottle = fbm(r * 0.5, phi * 0.15 + 0.5, 6, 6, 2, seed) - 0.5;
    let g = tone * (1.0 - 0.2 * rim * rim) + 0.08 * mottle + 0.14 * vein * (1.0 - rim);
    (g, cover)
}

/// Grey of a blade's pixel at `s` along and `t` across (signed), where the blade is `half`
/// wide a side.
fn shade_blade(s: f32, t: f32, half: f32, tone: f32, fold: f32, seed: u32) -> f32 {
    let off = t.abs();
    let across = (off / half.max(1e-4)).min(1.0);
    let midrib = 1.0 - smooth(0.005, 0.014, off);
    // Side veins leave the midrib towards the tip: lines of s − 1.1·|t| = const.
    let w = (s - 1.1 * off) * 8.0;
    let side = (1.0 - smooth(0.06, 0.16, to_line(w))) * smooth(0.01, 0.03, off) * (1.0 - across);
    let mottle = fbm(s, t + 0.5, 5, 5, 2, seed) - 0.5;
    let lit = if t * fold > 0.0 { 0.05 } else { -0.03 };
    let base = 0.9 + 0.1 * smooth(0.0, 0.25, s);
    (tone * (1.0 - 0.22 * across * across) + lit + 0.07 * mottle) * base
        + 0.14 * midrib
        + 0.06 * side
}

// ---------------------------------------------------------------------------------------
// Sprays.

/// How one kind's spray is laid out on its twig (cell units: the card is 1 by 1).
struct Layout {
    /// Twig length from the base.
    twig: f32,
    /// Nodes along the twig.
    nodes: u32,
    /// Where the first and last node sit.
    first: f32,
    last: f32,
    /// Angle of a leaf from the twig at the first and last node, degrees.
    angle: (f32, f32),
    /// Stalk length.
    petiole: f32,
    /// A leaf at the twig's tip.
    terminal: bool,
}

fn layout(kind: LeafKind) -> Layout {
    let l = |twig, nodes, first, last, angle, petiole, terminal| Layout {
        twig,
        nodes,
        first,
        last,
        angle,
        petiole,
        terminal,
    };
    match kind {
        LeafKind::Oak => l(0.5, 4, 0.26, 0.46, (72.0, 38.0), 0.02, true),
        LeafKind::Birch => l(0.74, 7, 0.1, 0.68, (55.0, 35.0), 0.05, true),
        LeafKind::Aspen => l(0.56, 5, 0.1, 0.5, (62.0, 34.0), 0.1, true),
        LeafKind::Beech => l(0.66, 6, 0.08, 0.6, (66.0, 40.0), 0.02, true),
        LeafKind::Maple => l(0.3, 1, 0.22, 0.22, (62.0, 62.0), 0.12, true),
        LeafKind::Willow => l(0.68, 8, 0.05, 0.62, (36.0, 18.0), 0.02, true),
        LeafKind::Privet => l(0.72, 4, 0.1, 0.58, (55.0, 38.0), 0.01, true),
        LeafKind::Ash => l(0.0, 0, 0.0, 0.0, (0.0, 0.0), 0.0, false),
        LeafKind::Pine | LeafKind::Spruce | LeafKind::Fir => {
            l(0.0, 0, 0.0, 0.0, (0.0, 0.0), 0.0, false)
        }
    }
}

/// Which side of its twig leaf `k` of node `n` goes (1 right, -1 left): alternate leaves
/// take turns, opposite pairs go both ways.
fn side_of(per_node: u32, n: u32, k: u32) -> f32 {
    let right = if per_node == 2 {
        k == 0
    } else {
        n.is_multiple_of(2)
    };
    if right { 1.0 } else { -1.0 }
}

/// A random number in `lo..hi` from a hash.
fn pick(h: u32, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * unit(h)
}

/// Draws one cell's spray of a broadleaf kind.
fn broadleaf_cell(canvas: &mut Canvas, cell: Cell, kind: LeafKind, seed: u32) {
    let spec = kind.spec();
    let lay = layout(kind);
    let leaf = spec.leaf_of_spray;
    let bend = pick(hash(seed, 9, 1), -0.12, 0.12);
    let twig_at = |y: f32| Vec2::new(bend * y * y, y);
    let twig_tone = 0.42;
    // The twig in a few straight pieces.
    let pieces = 6;
    for k in 0..pieces {
        let (a, b) = (
            lay.twig * k as f32 / pieces as f32,
            lay.twig * (k + 1) as f32 / pieces as f32,
        );
        let w = |y: f32| 0.02 - 0.012 * y / lay.twig.max(1e-3);
        canvas.stalk(cell, twig_at(a), twig_at(b), w(a), w(b), twig_tone);
    }
    let per_node = spec.arrangement.per_node();
    let mut leaves: Vec<(Vec2, f32, f32)> = Vec::new(); // base, angle, length
    for n in 0..lay.nodes {
        let f = if lay.nodes > 1 {
            n as f32 / (lay.nodes - 1) as f32
        } else {
            0.0
        };
        let y = lay.first + (lay.last - lay.first) * f;
        let angle = (lay.angle.0 + (lay.angle.1 - lay.angle.0) * f).to_radians();
        for k in 0..per_node {
            let h = hash(seed, n * 2 + k, 7);
            let sign = side_of(per_node, n, k);
            let a = sign * (angle + pick(h, -0.15, 0.15));
            let size = leaf * (0.82 + 0.18 * f) * pick(hash(h, 2, 2), 0.9, 1.1);
            leaves.push((twig_at(y), a, size));
        }
    }
    if lay.terminal {
        let h = hash(seed, 99, 7);
        leaves.push((
            twig_at(lay.twig),
            pick(h, -0.15, 0.15),
            leaf * pick(hash(h, 1, 1), 0.95, 1.08),
        ));
    }
    for (i, (base, angle, size)) in leaves.into_iter().enumerate() {
        let h = hash(seed, i as u32, 11);
        let dir = heading(angle);
        let stalk_end = base + dir * lay.petiole;
        // Shrink a leaf that would leave its cell.
        let room = room(stalk_end, dir);
        let size = size.min(room);
        if lay.petiole > 0.0 {
            canvas.stalk(cell, base, stalk_end, 0.008, 0.006, twig_tone + 0.1);
        }
        let tone = pick(h, 0.74, 0.94);
        canvas.blade(
            cell,
            stalk_end,
            dir,
            size,
            spec.width_ratio,
            spec.shape,
            tone,
            h,
        );
    }
}

/// How long a leaf starting at `from` going along `dir` may be and stay in its cell (with a
/// margin of 1.5% of the cell).
fn room(from: Vec2, dir: Vec2) -> f32 {
    let m = 0.485;
    let mut t = f32::MAX;
    if dir.x > 1e-6 {
        t = t.min((m - from.x) / dir.x);
    }
    if dir.x < -1e-6 {
        t = t.min((-m - from.x) / dir.x);
    }
    if dir.y > 1e-6 {
        t = t.min((0.985 - from.y) / dir.y);
    }
    if dir.y < -1e-6 {
        t = t.min((0.015 - from.y) / dir.y);
    }
    t.max(0.0)
}

/// Draws one cell's ash leaf: a rachis with four pairs of leaflets and one at its tip.
fn ash_cell(canvas: &mut Canvas, cell: Cell, seed: u32) {
    let length = LeafKind::Ash.spec().leaf_of_spray;
    let bend = pick(hash(seed, 3, 3), -0.1, 0.1);
    compound_leaf(canvas, cell, Vec2::ZERO, Vec2::Y, length, bend, seed);
}

/// An ash leaf from `base` along `dir`, `length` long, bending `bend` sideways: a rachis
/// with four pairs of leaflets and one at its tip.
fn compound_leaf(
    canvas: &mut Canvas,
    cell: Cell,
    base: Vec2,
    dir: Vec2,
    length: f32,
    bend: f32,
    seed: u32,
) {
    let side = Vec2::new(dir.y, -dir.x);
    let rachis = |y: f32| base + dir * y + side * (bend * y * y / length.max(1e-3));
    let top = 0.72 * length;
    let w = (length * 0.016).max(0.004);
    canvas.stalk(cell, rachis(0.0), rachis(top * 0.5), w, 0.8 * w, 0.5);
    canvas.stalk(cell, rachis(top * 0.5), rachis(top), 0.8 * w, 0.5 * w, 0.5);
    let leaflet = 0.28 * length;
    let a0 = angle_of(dir);
    for pair in 0..4 {
        let y = (0.18 + 0.16 * pair as f32) * length;
        for sign in [1.0f32, -1.0] {
            let h = hash(seed, pair * 2 + (sign > 0.0) as u32, 5);
            let d = heading(a0 + sign * pick(h, 0.95, 1.2));
            let size = (leaflet * pick(hash(h, 4, 4), 0.88, 1.05)).min(room(rachis(y), d));
            canvas.blade(
                cell,
                rachis(y),
                d,
                size,
                0.32,
                LeafShape::Lanceolate,
                pick(h, 0.76, 0.94),
                h,
            );
        }
    }
    let h = hash(seed, 77, 5);
    let d = heading(a0 + pick(h, -0.1, 0.1));
    let size = (leaflet * 1.05).min(room(rachis(top), d));
    canvas.blade(
        cell,
        rachis(top),
        d,
        size,
        0.32,
        LeafShape::Lanceolate,
        pick(h, 0.76, 0.94),
        h,
    );
}

/// Draws needles along a shoot from `a` to `b`: `count` needles `length` long leaving at
/// `angle` (radians, either side) from the shoot.
#[allow(clippy::too_many_arguments)]
fn needles_along(
    canvas: &mut Canvas,
    cell: Cell,
    a: Vec2,
    b: Vec2,
    count: u32,
    length: f32,
    angle: (f32, f32),
    width: f32,
    per_place: u32,
    seed: u32,
) {
    let dir = (b - a).normalize_or(Vec2::Y);
    let shoot_angle = angle_of(dir);
    for i in 0..count {
        let f = (i as f32 + 0.5) / count as f32;
        let base = a + (b - a) * f;
        for k in 0..per_place {
            let h = hash(seed, i * 4 + k, 13);
            let sign = if (i + k) % 2 == 0 { 1.0 } else { -1.0 };
            let spread = pick(h, angle.0, angle.1);
            // Needles near the tip point further forward.
            let lean = spread * (1.0 - 0.4 * f * f);
            let d = heading(shoot_angle + sign * lean);
            let len = (length * pick(hash(h, 1, 1), 0.8, 1.1)).min(room(base, d));
            let tone = pick(hash(h, 2, 2), 0.72, 0.92);
            canvas.stalk(cell, base, base + d * len, width, width * 0.25, tone);
        }
    }
}

/// Draws one cell's needles of a conifer kind.
fn needle_cell(canvas: &mut Canvas, cell: Cell, kind: LeafKind, seed: u32) {
    let spec = kind.spec();
    let len = spec.leaf_of_spray;
    let bend = pick(hash(seed, 5, 5), -0.06, 0.06);
    let at = |y: f32| Vec2::new(bend * y * y, y);
    let twig = 0.45;
    match kind {
        LeafKind::Pine => {
            canvas.stalk(cell, at(0.0), at(0.62), 0.022, 0.014, twig);
            // Pairs of long needles in tufts, thicker towards the shoot's tip.
            needles_along(
                canvas,
                cell,
                at(0.04),
                at(0.6),
                36,
                len,
                (0.35, 0.8),
                0.014,
                2,
                seed,
            );
            needles_along(
                canvas,
                cell,
                at(0.5),
                at(0.64),
                12,
                len * 1.05,
                (0.05, 0.4),
                0.014,
                2,
                seed ^ 7,
            );
        }
        LeafKind::Spruce => {
            canvas.stalk(cell, at(0.0), at(0.92), 0.016, 0.008, twig);
            needles_along(
                canvas,
                cell,
                at(0.02),
                at(0.92),
                110,
                len,
                (0.7, 1.15),
                0.015,
                1,
                seed,
            );
            for (y, s) in [(0.3f32, 1.0f32), (0.55, -1.0)] {
                let h = hash(seed, (y * 100.0) as u32, 17);
                let d = heading(s * pick(h, 0.6, 0.8));
                let end = at(y) + d * (0.34f32).min(room(at(y), d));
                canvas.stalk(cell, at(y), end, 0.01, 0.006, twig);
                needles_along(
                    canvas,
                    cell,
                    at(y),
                    end,
                    44,
                    len * 0.85,
                    (0.7, 1.15),
                    0.014,
                    1,
                    h,
                );
            }
        }
        _ => {
            canvas.stalk(cell, at(0.0), at(0.9), 0.016, 0.008, twig);
            needles_along(
                canvas,
                cell,
                at(0.02),
                at(0.9),
                60,
                len,
                (1.25, 1.5),
                0.019,
                2,
                seed,
            );
            for (y, s) in [(0.32f32, 1.0f32), (0.56, -1.0), (0.42, -1.0)] {
                let h = hash(seed, (y * 100.0) as u32, 19);
                let d = heading(s * pick(h, 0.75, 0.95));
                let end = at(y) + d * (0.3f32).min(room(at(y), d));
                canvas.stalk(cell, at(y), end, 0.01, 0.006, twig);
                needles_along(
                    canvas,
                    cell,
                    at(y),
                    end,
                    26,
                    len * 0.9,
                    (1.25, 1.5),
                    0.018,
                    2,
                    h,
                );
            }
        }
    }
}

/// A twig from `a` to `b` clothed in the kind's leaves (or needles) `leaf` long, by its
/// arrangement, with a leaf at its end.
#[allow(clippy::too_many_arguments)]
fn leafy_twig(
    canvas: &mut Canvas,
    cell: Cell,
    kind: LeafKind,
    a: Vec2,
    b: Vec2,
    leaf: f32,
    width: f32,
    seed: u32,
) {
    let spec = kind.spec();
    canvas.stalk(cell, a, b, width, 0.5 * width, 0.42);
    let length = (b - a).length();
    let dir = (b - a).normalize_or(Vec2::Y);
    if spec.needles {
        let (count, spread, thick, per) = match kind {
            // Dense mats of needles drawn a little thicker than life: an engine's mipmaps
            // average alpha, and sparse needles would fade away with distance.
            LeafKind::Pine => ((length / (0.05 * leaf)) as u32, (0.35, 0.8), 0.13, 2),
            LeafKind::Spruce => ((length / (0.045 * leaf)) as u32, (0.7, 1.15), 0.16, 2),
            _ => ((length / (0.05 * leaf)) as u32, (1.25, 1.5), 0.17, 2),
        };
        needles_along(
            canvas,
            cell,
            a,
            b,
            count.max(2),
            leaf,
            spread,
            thick * leaf,
            per,
            seed,
        );
        return;
    }
    let a0 = angle_of(dir);
    let petiole = leaf
        * match spec.shape {
            LeafShape::Round => 0.35,
            LeafShape::Palmate => 0.45,
            LeafShape::Pinnate => 0.0,
            _ => 0.08,
        };
    let spacing = leaf
        * match spec.shape {
            LeafShape::Pinnate => 0.5,
            LeafShape::Palmate => 0.7,
            // Willow's narrow leaves crowd their twigs close and steep, strands that
            // still read as foliage from afar.
            LeafShape::Lanceolate => 0.14,
            _ => 0.5,
        };
    let spread = match spec.shape {
        LeafShape::Lanceolate => (0.3, 0.6),
        _ => (0.7, 1.15),
    };
    let nodes = ((length - 0.3 * leaf) / spacing).max(1.0) as u32;
    let per_node = spec.arrangement.per_node();
    let draw = |canvas: &mut Canvas, base: Vec2, angle: f32, size: f32, h: u32| {
        let d = heading(angle);
        let stalk_end = base + d * petiole;
        let size = size.min(room(stalk_end, d));
        if size < 0.25 * leaf {
            return;
        }
        if petiole > 0.0 {
            canvas.stalk(cell, base, stalk_end, 0.006, 0.004, 0.52);
        }
        if spec.shape == LeafShape::Pinnate {
            compound_leaf(
                canvas,
                cell,
                stalk_end,
                d,
                size,
                pick(h, -0.1, 0.1) * size,
                h,
            );
        } else {
            canvas.blade(
                cell,
                stalk_end,
                d,
                size,
                spec.width_ratio,
                spec.shape,
                pick(h, 0.72, 0.94),
                h,
            );
        }
    };
    for n in 0..nodes {
        let t = (n as f32 + 0.6) / nodes as f32;
        let base = a + (b - a) * t;
        for k in 0..per_node {
            let h = hash(seed, n * 2 + k, 23);
            let sign = side_of(per_node, n, k);
            let angle = a0 + sign * pick(h, spread.0, spread.1) * (1.0 - 0.3 * t);
            draw(
                canvas,
                base,
                angle,
                leaf * pick(hash(h, 3, 3), 0.8, 1.08),
                h,
            );
        }
    }
    let h = hash(seed, 999, 23);
    draw(
        canvas,
        b,
        a0 + pick(h, -0.2, 0.2),
        leaf * pick(hash(h, 1, 1), 0.9, 1.05),
        h,
    );
}

/// Draws one branchlet cell: a main twig with side twigs, all clothed in leaves.
fn branchlet_cell(canvas: &mut Canvas, cell: Cell, kind: LeafKind, seed: u32) {
    let spec = kind.spec();
    let leaf = spec.leaf_of_branchlet;
    let bend = pick(hash(seed, 1, 31), -0.1, 0.1);
    let main = |y: f32| Vec2::new(bend * y * y, y);
    let top = 0.9 - 0.8 * leaf;
    let sides = 5u32;
    // Side twigs first, so the main twig's leaves lie over their bases.
    for i in 0..sides {
        let h = hash(seed, i, 37);
        let y = 0.12 + (top - 0.3) * i as f32 / (sides - 1) as f32 + pick(h, -0.03, 0.03);
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        let d = heading(sign * pick(hash(h, 1, 1), 0.65, 0.95) + bend * y);
        let reach = (0.46 - 0.05 * i as f32) * pick(hash(h, 2, 2), 0.85, 1.05);
        let from = main(y);
        let length = reach.min(room(from, d) - 0.6 * leaf);
        if length < 2.0 * leaf {
            continue;
        }
        leafy_twig(canvas, cell, kind, from, from + d * length, leaf, 0.011, h);
    }
    leafy_twig(
        canvas,
        cell,
        kind,
        main(0.0),
        main(top),
        leaf,
        0.018,
        hash(seed, 99, 37),
    );
}

/// Draws a kind's whole atlas.
fn draw_atlas(kind: LeafKind) -> GrayAlphaImage {
    let size = ATLAS_SIZE as usize;
    let mut canvas = Canvas::new(size);
    for card in [Card::Branchlet, Card::Spray] {
        for c in 0..cells(card) {
            let (x0, y0, side) = cell_rect(card, c);
            let cell = Cell {
                x0: x0 as f32,
                y0: y0 as f32,
                side: side as f32,
            };
            let seed = hash(kind as u32, c + 16 * card as u32, 0x1eaf);
            match (card, kind.spec().shape) {
                (Card::Branchlet, _) => branchlet_cell(&mut canvas, cell, kind, seed),
                (Card::Spray, LeafShape::Needle) => needle_cell(&mut canvas, cell, kind, seed),
                (Card::Spray, LeafShape::Pinnate) => ash_cell(&mut canvas, cell, seed),
                (Card::Spray, _) => broadleaf_cell(&mut canvas, cell, kind, seed),
            }
        }
    }
    finish(&canvas, ATLAS_SIZE)
}

/// Un-premultiplies a canvas into grey and alpha, filling fully clear pixels with the mean
/// grey of the painted ones.
fn finish(canvas: &Canvas, size: u32) -> GrayAlphaImage {
    let (mut sum, mut weight) = (0.0f64, 0.0f64);
    for (g, a) in canvas.grey.iter().zip(&canvas.alpha) {
        sum += f64::from(*g);
        weight += f64::from(*a);
    }
    let fill = if weight > 0.0 {
        (sum / weight) as f32
    } else {
        1.0
    };
    let to8 = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    let mut image = GrayAlphaImage::new(size, size);
    for (i, px) in image.pixels_mut().enumerate() {
        let a = canvas.alpha[i];
        let g = if a > 1e-4 { canvas.grey[i] / a } else { fill };
        // Half-covered edge pixels lean towards the fill, so edges never ring dark.
        let g = if a < 1.0 {
            fill + (g - fill) * a.sqrt()
        } else {
            g
        };
        px.0 = [to8(g), to8(a)];
    }
    image
}

/// Draws a petal's cut-out over a design's shading.
fn draw_petal(design_id: Option<u16>) -> GrayAlphaImage {
    let size = PETAL_SIZE as usize;
    let mut canvas = Canvas::new(size);
    let cell = Cell {
        x0: 0.0,
        y0: 0.0,
        side: size as f32,
    };
    let seed = design_id.map_or(0, u32::from);
    let shade = design_id.map(design);
    let px = 1.0 / size as f32;
    canvas.paint(cell, Vec2::new(-0.5, 0.0), Vec2::new(0.5, 1.0), |p| {
        // Obovate: a narrow claw at the base, widest two thirds up, a rounded end short of
        // the picture's top edge.
        let s = (p.y / 0.96).clamp(0.0, 1.0);
        let half = (0.5 * (4.0 * s * (1.0 - s)).sqrt() * (0.55 + 0.45 * s) * 1.05).min(0.49);
        let cover = ((half - p.x.abs()) / px + 0.5).clamp(0.0, 1.0);
        // The designs run v from 0 at the petal's base to 1 at its tip.
        let g = match shade {
            Some(f) => f(p.x + 0.5, s, seed),
            None => 0.92 - 0.1 * (1.0 - smooth(0.0, 0.3, s)),
        };
        Some((g, cover))
    });
    finish(&canvas, PETAL_SIZE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trigonometry_is_close_to_the_library_s() {
        for i in -2000..2000 {
            let x = i as f32 * 0.01;
            let (s, c) = sin_cos(x);
            assert!(
                (s - x.sin()).abs() < 2e-6 && (c - x.cos()).abs() < 2e-6,
                "{x}"
            );
            let v = Vec2::new(x.cos(), x.sin());
            let expect = v.x.atan2(v.y);
            assert!(
                (angle_of(v) - expect).abs() < 1e-4,
                "{x}: {} vs {expect}",
                angle_of(v)
            );
        }
    }

    #[test]
    fn card_uvs_stay_inside_their_cell() {
        for card in [Card::Spray, Card::Branchlet] {
            for variant in 0..2 * cells(card) {
                let uv = card_uvs(card, variant);
                let (x0, y0, side) = cell_rect(card, variant % cells(card));
                let inv = 1.0 / ATLAS_SIZE as f32;
                for [u, v] in uv {
                    assert!(u > x0 as f32 * inv && u < (x0 + side) as f32 * inv);
                    assert!(v > y0 as f32 * inv && v < (y0 + side) as f32 * inv);
                }
                assert!(uv[0][1] > uv[3][1], "the base is the cell's bottom edge");
            }
        }
        // The cells tile the atlas without overlapping.
        let mut area = 0;
        for card in [Card::Spray, Card::Branchlet] {
            for c in 0..cells(card) {
                area += cell_rect(card, c).2.pow(2);
            }
        }
        assert_eq!(area, ATLAS_SIZE * ATLAS_SIZE);
    }

    #[test]
    fn atlases_hold_leaves_within_each_cell_and_are_made_once() {
        for kind in LeafKind::ALL {
            let a = leaf_atlas(kind);
            assert!(Arc::ptr_eq(&a, &leaf_atlas(kind)));
            assert_eq!(a.dimensions(), (ATLAS_SIZE, ATLAS_SIZE));
            for card in [Card::Spray, Card::Branchlet] {
                let fill = leaf_fill(kind, card);
                assert!((0.03..0.7).contains(&fill), "{kind} {card:?}: {fill}");
                // Every cell has leaves, and its border rows and columns are clear (no leaf
                // is cut by the cell's edge, so cards never show a straight edge).
                for c in 0..cells(card) {
                    let (x0, y0, side) = cell_rect(card, c);
                    let mut inked = 0;
                    for y in y0..y0 + side {
                        for x in x0..x0 + side {
                            let alpha = a.get_pixel(x, y).0[1];
                            inked += usize::from(alpha >= 128);
                            let border = x == x0 || y == y0 || x == x0 + side - 1;
                            assert!(
                                !border || alpha < 128,
                                "{kind}: {card:?} cell {c} inked at its edge ({x}, {y})"
                            );
                        }
                    }
                    assert!(
                        inked as u32 > side * side / 40,
                        "{kind} {card:?} cell {c}: {inked}"
                    );
                }
            }
        }
    }

    /// The share of a cell's area whose alpha, box-filtered down `halvings` times as an
    /// engine's mipmaps are, still passes the cut-off.
    fn coverage_after(atlas: &GrayAlphaImage, card: Card, c: u32, halvings: u32) -> f32 {
        let (x0, y0, side) = cell_rect(card, c);
        let k = 1u32 << halvings;
        let n = side / k;
        let mut passed = 0;
        for by in 0..n {
            for bx in 0..n {
                let mut sum = 0u32;
                for y in 0..k {
                    for x in 0..k {
                        sum += u32::from(atlas.get_pixel(x0 + bx * k + x, y0 + by * k + y).0[1]);
                    }
                }
                passed += u32::from(sum >= 128 * k * k);
            }
        }
        passed as f32 / (n * n) as f32
    }

    #[test]
    fn leaves_and_needles_survive_an_engine_s_mipmaps() {
        // With each branchlet drawn 16 pixels wide (a tree a few hundred pixels tall),
        // every kind's branchlets keep at least half the cover they have at full size, so
        // distant crowns do not thin out in viewers that build plain mipmaps. (Sparse
        // needles, a pixel or two wide at full size, vanished entirely there.)
        for kind in LeafKind::ALL {
            let atlas = leaf_atlas(kind);
            for c in 0..BRANCHLET_CELLS {
                let full = coverage_after(&atlas, Card::Branchlet, c, 0);
                let far = coverage_after(&atlas, Card::Branchlet, c, 5);
                assert!(far >= 0.5 * full, "{kind} cell {c}: {far} of {full}");
            }
        }
    }

    #[test]
    fn atlases_differ_by_kind_and_cell() {
        let oak = leaf_atlas(LeafKind::Oak);
        let maple = leaf_atlas(LeafKind::Maple);
        assert_ne!(oak.as_raw(), maple.as_raw());
        let cell = |c: u32| {
            let (x0, y0, side) = cell_rect(Card::Spray, c);
            (0..side * side)
                .map(|k| oak.get_pixel(x0 + k % side, y0 + k / side).0[1])
                .collect::<Vec<_>>()
        };
        assert_ne!(cell(0), cell(1));
    }

    #[test]
    fn petals_are_cut_out_over_their_design() {
        let plain = petal_picture(None);
        let streaked = petal_picture(Some(7));
        assert_eq!(plain.dimensions(), (PETAL_SIZE, PETAL_SIZE));
        let alpha = |p: &GrayAlphaImage, x, y| p.get_pixel(x, y).0[1];
        // Clear at the base's corners, solid in the middle.
        assert_eq!(alpha(&plain, 0, PETAL_SIZE - 1), 0);
        assert_eq!(alpha(&plain, PETAL_SIZE / 2, PETAL_SIZE / 3), 255);
        assert_ne!(plain.as_raw(), streaked.as_raw());
    }
}
