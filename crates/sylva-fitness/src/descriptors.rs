//! Behaviour descriptors: a few numbers measured on a [`Plant`] that say how it looks, for a
//! MAP-Elites (quality-diversity) search filling a grid of plants that a person would call
//! different from one another.
//!
//! Every descriptor reads the *shoot* only: segments of root material and root-tip organs
//! are left out, as the [`silhouette`] leaves them out. A plant with nothing of its shoot
//! measures 0 on every descriptor, and every value is finite.
//!
//! Some terms the descriptors share. The shoot's *height* is the vertical extent of its
//! skeleton (segments' centre lines) and its organs' blades. Its *base* is the start of its
//! first segment (the lowest point of a blade, for a shoot of organs only). Its *mass* is the
//! area each part shows: a segment weighs its length times its mean diameter (spread evenly
//! along it), an organ its blade's length times its width (at the blade's centre); should
//! no part show any area (segments without radius, say), segments weigh their length. Its
//! *wood* is its segments of bark material: leaves and petals drawn as segments (an
//! L-system's leaves, a PlantMaker leaf's midrib) are foliage, not branches.
//!
//! | name | what it measures | unit | default range |
//! | --- | --- | --- | --- |
//! | `height_to_width` | height over the widest horizontal extent (the larger of the x and z extents, radii and blades included); at most [`MAX_HEIGHT_TO_WIDTH`] | ratio | 0.5 to 4 |
//! | `porosity` | how see-through the front view is: drawn [`POROSITY_ROWS`] rows tall, 1 − ink over the pixels between each row's leftmost and rightmost ink, summed over rows | share | 0 to 1 |
//! | `lean` | the horizontal distance from the base to the centre of mass, over the height; at most [`MAX_LEAN`] | ratio | 0 to 0.5 |
//! | `asymmetry` | seen from the front, how the mass's moments about the vertical line through the base differ on its two sides: \|right − left\| / (right + left), the sum at least [`BALANCE_FLOOR`] times the mass times the height | share | 0 to 1 |
//! | `branching_depth` | the highest branch order of the wood (0 for a single axis) | orders | 0 to 8 |
//! | `bare_trunk` | the share of the height below the crown: below the lowest point of a branch (a segment off the main axes, order above 0), of foliage drawn as segments, or of a leaf's or flower's blade; 1 when there is none | share | 0 to 1 |
//! | `leaf_count` | leaf organs (not those of flower material: PlantMaker's petals are leaf-shaped blades) and leaf-material segments bearing no leaf organ (an L-system's leaves; a PlantMaker leaf's midrib bears its blade, so counts once) | leaves | 0 to 2000 |
//! | `tips` | the wood's tips: segments of wood from which no wood grows (foliage does not count) | tips | 1 to 500 |
//!
//! The ranges are what a map uses when its config gives none: a plant outside them lands in
//! the map's edge cells. [`measure`] measures several descriptors at once, drawing the
//! silhouette once and walking the plant once; once its [`Scratch`] is warm it allocates
//! nothing.
//!
//! ```
//! use sylva_bintree::BinTree;
//! use sylva_fitness::descriptors::{self, Descriptor, Scratch};
//!
//! let plant = BinTree::default().develop(0)?;
//! let mut scratch = Scratch::default();
//! let mut out = [0.0; 2];
//! descriptors::measure(&plant, &[Descriptor::Tips, Descriptor::BranchingDepth], &mut scratch, &mut out);
//! assert_eq!(out, [128.0, 7.0]); // 2^7 tips of a binary tree 8 levels deep
//! assert_eq!(Descriptor::from_name("tips"), Some(Descriptor::Tips));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sylva_core::Plant;
use sylva_core::glam::{DVec3, Vec3};
use sylva_core::plant::{MaterialId, MaterialKind, OrganKind};

use crate::silhouette::{self, Side};

/// One descriptor. Serialised as its [`Descriptor::name`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Descriptor {
    /// Height over the widest horizontal extent.
    HeightToWidth,
    /// How see-through the front view is.
    Porosity,
    /// How far the centre of mass lies beside the base, over the height.
    Lean,
    /// How unevenly the mass lies on the two sides of the base, seen from the front.
    Asymmetry,
    /// The highest branch order of the wood.
    BranchingDepth,
    /// The share of the height below the crown.
    BareTrunk,
    /// How many leaves.
    LeafCount,
    /// How many tips the wood has.
    Tips,
}

/// The names of [`Descriptor::ALL`], in order.
const NAMES: [&str; 8] = [
    "height_to_width",
    "porosity",
    "lean",
    "asymmetry",
    "branching_depth",
    "bare_trunk",
    "leaf_count",
    "tips",
];

/// The most `height_to_width` reads: a stem without width would be infinitely slender.
pub const MAX_HEIGHT_TO_WIDTH: f64 = 10.0;

/// The most `lean` reads: a plant lying flat would lean infinitely.
pub const MAX_LEAN: f64 = 10.0;

/// Rows `porosity` draws the front view at: fine enough to see gaps in a crown, coarse
/// enough that a twig is about a pixel.
pub const POROSITY_ROWS: u32 = 64;

/// Moments about the base's vertical line below this share of mass times height count as
/// balanced in proportion, so a stem a hair off vertical is not wholly one-sided.
pub const BALANCE_FLOOR: f64 = 0.02;

impl Descriptor {
    /// Every descriptor, in the order of their names.
    pub const ALL: [Descriptor; 8] = [
        Descriptor::HeightToWidth,
        Descriptor::Porosity,
        Descriptor::Lean,
        Descriptor::Asymmetry,
        Descriptor::BranchingDepth,
        Descriptor::BareTrunk,
        Descriptor::LeafCount,
        Descriptor::Tips,
    ];

    /// Its name in configs and files, snake case.
    pub fn name(self) -> &'static str {
        NAMES[self as usize]
    }

    /// The descriptor of a name, if any.
    pub fn from_name(name: &str) -> Option<Descriptor> {
        NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Descriptor::ALL[i])
    }

    /// The range a map uses when its config gives none, `(low, high)`.
    pub fn range(self) -> (f64, f64) {
        match self {
            Descriptor::HeightToWidth => (0.5, 4.0),
            Descriptor::Porosity => (0.0, 1.0),
            Descriptor::Lean => (0.0, 0.5),
            Descriptor::Asymmetry => (0.0, 1.0),
            Descriptor::BranchingDepth => (0.0, 8.0),
            Descriptor::BareTrunk => (0.0, 1.0),
            Descriptor::LeafCount => (0.0, 2000.0),
            Descriptor::Tips => (1.0, 500.0),
        }
    }

    /// What it means and its unit, in one line.
    pub fn about(self) -> &'static str {
        match self {
            Descriptor::HeightToWidth => {
                "height over the widest horizontal extent (a ratio; 10 at most)"
            }
            Descriptor::Porosity => {
                "how see-through the front view is: 0 solid, toward 1 sparse twigs (a share)"
            }
            Descriptor::Lean => {
                "horizontal distance from the base to the centre of mass, over the height (a ratio)"
            }
            Descriptor::Asymmetry => {
                "imbalance of the mass left and right of the base, seen from the front: 0 balanced, 1 one-sided (a share)"
            }
            Descriptor::BranchingDepth => "the highest branch order: 0 for a single stem (a count)",
            Descriptor::BareTrunk => {
                "the share of the height below the lowest branch, leaf or flower (a share)"
            }
            Descriptor::LeafCount => "the number of leaves (a count)",
            Descriptor::Tips => "the number of branch tips of the wood (a count)",
        }
    }

    /// Measures this descriptor of `plant` (see [`measure`] for several at once).
    pub fn measure(self, plant: &Plant, scratch: &mut Scratch) -> f64 {
        let mut out = [0.0];
        measure(plant, &[self], scratch, &mut out);
        out[0]
    }
}

impl fmt::Display for Descriptor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for Descriptor {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Descriptor {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Descriptor, D::Error> {
        struct Name;
        impl serde::de::Visitor<'_> for Name {
            type Value = Descriptor;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "a descriptor name, one of {}", NAMES.join(", "))
            }
            fn visit_str<E: serde::de::Error>(self, name: &str) -> Result<Descriptor, E> {
                Descriptor::from_name(name).ok_or_else(|| E::unknown_variant(name, &NAMES))
            }
        }
        deserializer.deserialize_str(Name)
    }
}

/// What measuring reuses between plants (a silhouette canvas, buffers); measuring allocates
/// nothing once warm.
#[derive(Debug, Default)]
pub struct Scratch {
    silhouette: silhouette::Scratch,
    /// Per segment: [`SHOOT`], [`BEARS_WOOD`], [`BEARS_BLADE`].
    flags: Vec<u8>,
}

impl Scratch {
    /// Where the buffers are and their capacities (see [`silhouette::Scratch::footprint`]).
    #[cfg(test)]
    fn footprint(&self) -> [(usize, usize); 3] {
        let [canvas, quads, _, _] = self.silhouette.footprint();
        [
            canvas,
            quads,
            (self.flags.as_ptr() as usize, self.flags.capacity()),
        ]
    }
}

/// A segment of the shoot.
const SHOOT: u8 = 1;
/// A segment from which a segment of wood grows.
const BEARS_WOOD: u8 = 2;
/// A segment bearing a leaf organ.
const BEARS_BLADE: u8 = 4;

/// Measures `which` of `plant` into `out` (same length), sharing work between descriptors:
/// the front view is drawn once, for `porosity`, and the plant walked once for the rest.
///
/// # Panics
///
/// When `out` and `which` differ in length.
pub fn measure(plant: &Plant, which: &[Descriptor], scratch: &mut Scratch, out: &mut [f64]) {
    assert_eq!(which.len(), out.len(), "one output per descriptor measured");
    let shape = which
        .iter()
        .any(|d| *d != Descriptor::Porosity)
        .then(|| Shape::of(plant, &mut scratch.flags));
    let porosity = which
        .contains(&Descriptor::Porosity)
        .then(|| porosity(plant, &mut scratch.silhouette));
    for (d, o) in which.iter().zip(out) {
        *o = match (d, &shape) {
            (Descriptor::Porosity, _) => porosity.unwrap_or(0.0),
            (_, Some(shape)) => shape.descriptor(*d),
            (_, None) => 0.0,
        };
    }
}

/// What one walk over the shoot finds; all zero for a plant without a shoot.
#[derive(Clone, Copy, Debug, Default)]
struct Shape {
    /// Whether the plant has a shoot at all.
    present: bool,
    /// Vertical extent, metres.
    height: f64,
    /// The larger horizontal extent, metres.
    width: f64,
    /// The crown's lowest point above the shoot's lowest point, metres, if anything
    /// branches.
    crown_base: Option<f64>,
    /// Mass, and its moments about the base.
    mass: Mass,
    depth: u16,
    leaves: u64,
    tips: u64,
}

/// Weights and their moments about the base, shared by `lean` and `asymmetry`.
#[derive(Clone, Copy, Debug, Default)]
struct Mass {
    total: f64,
    /// Weighted offsets from the base along x and z.
    x: f64,
    z: f64,
    /// Weighted distances right (+x) and left (-x) of the base's vertical line.
    right: f64,
    left: f64,
}

impl Mass {
    /// A weight spread evenly from `a` to `b` (offsets from the base).
    fn add_segment(&mut self, w: f64, a: DVec3, b: DVec3) {
        self.total += w;
        self.x += w * 0.5 * (a.x + b.x);
        self.z += w * 0.5 * (a.z + b.z);
        self.right += w * positive_mean(a.x, b.x);
        self.left += w * positive_mean(-a.x, -b.x);
    }

    /// A weight at one point (an offset from the base).
    fn add_point(&mut self, w: f64, p: DVec3) {
        self.add_segment(w, p, p);
    }
}

/// The mean of `max(0, v)` as `v` runs evenly from `a` to `b`.
fn positive_mean(a: f64, b: f64) -> f64 {
    let (lo, hi) = (a.min(b), a.max(b));
    if lo >= 0.0 {
        0.5 * (lo + hi)
    } else if hi <= 0.0 {
        0.0
    } else {
        // The part above zero: a triangle of height `hi` over `hi / (hi - lo)` of the run.
        hi * hi / (2.0 * (hi - lo))
    }
}

impl Shape {
    /// Walks `plant`'s shoot, with `flags` one byte per segment.
    fn of(plant: &Plant, flags: &mut Vec<u8>) -> Shape {
        let segments = plant.segments();
        flags.clear();
        flags.resize(segments.len(), 0);
        let kind = |m: MaterialId| {
            plant
                .materials()
                .get(m.index())
                .map_or(MaterialKind::Bark, |m| m.kind)
        };
        let organs = || {
            plant
                .organs()
                .iter()
                .filter(|o| o.kind != OrganKind::RootTip)
        };
        // Bounds, the crown's foot, the base, and which segments bear what.
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let (mut y_lo, mut y_hi) = (f32::INFINITY, f32::NEG_INFINITY);
        let mut crown = f32::INFINITY;
        let mut base: Option<Vec3> = None;
        let mut depth = 0u16;
        for (i, s) in segments.iter().enumerate() {
            let k = kind(s.material);
            if k == MaterialKind::Root {
                continue;
            }
            flags[i] |= SHOOT;
            base.get_or_insert(s.start);
            y_lo = y_lo.min(s.start.y).min(s.end.y);
            y_hi = y_hi.max(s.start.y).max(s.end.y);
            lo = lo.min(s.start - s.start_radius).min(s.end - s.end_radius);
            hi = hi.max(s.start + s.start_radius).max(s.end + s.end_radius);
            if k == MaterialKind::Bark {
                depth = depth.max(s.order);
                if let Some(p) = s.parent {
                    flags[p.index()] |= BEARS_WOOD;
                }
            }
            if s.order > 0 || s.lateral || k != MaterialKind::Bark {
                crown = crown.min(s.start.y).min(s.end.y);
            }
        }
        let mut lowest_corner: Option<Vec3> = None;
        for o in organs() {
            let corners = silhouette::blade_corners(o);
            for c in corners {
                y_lo = y_lo.min(c.y);
                y_hi = y_hi.max(c.y);
                lo = lo.min(c);
                hi = hi.max(c);
                if lowest_corner.is_none_or(|l| c.y < l.y) {
                    lowest_corner = Some(c);
                }
                crown = crown.min(c.y);
            }
            if o.kind == OrganKind::Leaf
                && let Some(p) = o.parent
            {
                flags[p.index()] |= BEARS_BLADE;
            }
        }
        let Some(base) = base.or(lowest_corner) else {
            return Shape::default();
        };
        // Counts, and the mass by area and, should that be none, by length.
        let (mut by_area, mut by_length) = (Mass::default(), Mass::default());
        let (mut leaves, mut tips) = (0u64, 0u64);
        let foot = base.as_dvec3();
        for (s, &f) in segments.iter().zip(flags.iter()) {
            if f & SHOOT == 0 {
                continue;
            }
            match kind(s.material) {
                MaterialKind::Bark if f & BEARS_WOOD == 0 => tips += 1,
                MaterialKind::Leaf if f & BEARS_BLADE == 0 => leaves += 1,
                _ => {}
            }
            let (a, b) = (s.start.as_dvec3() - foot, s.end.as_dvec3() - foot);
            let length = a.distance(b);
            let diameter = f64::from(s.start_radius) + f64::from(s.end_radius);
            by_area.add_segment(length * diameter, a, b);
            by_length.add_segment(length, a, b);
        }
        for o in organs() {
            if o.kind == OrganKind::Leaf && kind(o.material) != MaterialKind::Flower {
                leaves += 1;
            }
            let [c0, _, c2, _] = silhouette::blade_corners(o);
            let centre = 0.5 * (c0.as_dvec3() + c2.as_dvec3()) - foot;
            by_area.add_point(f64::from(o.size.x) * f64::from(o.size.y), centre);
        }
        let extent = (hi - lo).as_dvec3();
        Shape {
            present: true,
            height: f64::from(y_hi) - f64::from(y_lo),
            width: extent.x.max(extent.z).max(0.0),
            crown_base: crown
                .is_finite()
                .then(|| f64::from(crown) - f64::from(y_lo)),
            mass: if by_area.total > 0.0 {
                by_area
            } else {
                by_length
            },
            depth,
            leaves,
            tips,
        }
    }

    /// The value of descriptor `d` (any but porosity).
    fn descriptor(&self, d: Descriptor) -> f64 {
        let Shape { height, mass, .. } = *self;
        let value = match d {
            Descriptor::HeightToWidth => ratio(height, self.width, MAX_HEIGHT_TO_WIDTH),
            Descriptor::Lean if mass.total > 0.0 => {
                let offset = mass.x.hypot(mass.z) / mass.total;
                ratio(offset, height, MAX_LEAN)
            }
            Descriptor::Asymmetry => {
                let spread = (mass.right + mass.left).max(BALANCE_FLOOR * mass.total * height);
                if spread > 0.0 {
                    ((mass.right - mass.left).abs() / spread).min(1.0)
                } else {
                    0.0
                }
            }
            Descriptor::BranchingDepth => f64::from(self.depth),
            Descriptor::BareTrunk => match self.crown_base {
                None if self.present => 1.0,
                Some(crown) if height > 0.0 => (crown / height).clamp(0.0, 1.0),
                _ => 0.0,
            },
            Descriptor::LeafCount => self.leaves as f64,
            Descriptor::Tips => self.tips as f64,
            Descriptor::Lean | Descriptor::Porosity => 0.0,
        };
        // Sums of a plant's extreme coordinates stay far inside f64's range, but a measure
        // read by a map must never be NaN.
        if value.is_finite() { value } else { 0.0 }
    }
}

/// `num / den`, at most `max`: `max` for a positive `num` over nothing, 0 for nothing.
fn ratio(num: f64, den: f64, max: f64) -> f64 {
    if den > 0.0 {
        (num / den).min(max)
    } else if num > 0.0 {
        max
    } else {
        0.0
    }
}

/// `porosity`: the front view drawn [`POROSITY_ROWS`] tall (scaled down to fit if wider than
/// the canvas), `1 - ink / span` over the rows, a row's span running from its leftmost to
/// its rightmost ink.
fn porosity(plant: &Plant, scratch: &mut silhouette::Scratch) -> f64 {
    if !silhouette::draw_fitted(plant, Side::Front, POROSITY_ROWS, scratch) {
        return 0.0;
    }
    let canvas = scratch.canvas();
    let (mut ink, mut span) = (0u64, 0u64);
    for y in 0..canvas.height() {
        let row = canvas.row(y);
        let Some(first) = row.iter().position(|&w| w != 0) else {
            continue;
        };
        let last = row.iter().rposition(|&w| w != 0).unwrap_or(first);
        let x0 = first as u64 * 64 + u64::from(row[first].trailing_zeros());
        let x1 = last as u64 * 64 + 64 - u64::from(row[last].leading_zeros());
        span += x1 - x0;
        ink += row.iter().map(|w| u64::from(w.count_ones())).sum::<u64>();
    }
    if span == 0 {
        0.0
    } else {
        1.0 - ink as f64 / span as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sylva_bintree::{BITS, BinTree, Bits, Geometry, PAPER_BITS};
    use sylva_core::glam::{Quat, Vec2};
    use sylva_core::plant::{Material, Organ, SegmentId};
    use sylva_core::{PlantMeta, rng};

    use Descriptor::*;

    fn v(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z)
    }

    /// Adds a segment of constant radius `r`.
    fn seg(
        p: &mut Plant,
        a: Vec3,
        b: Vec3,
        r: f32,
        parent: Option<SegmentId>,
        lateral: bool,
        material: MaterialId,
    ) -> SegmentId {
        p.add_segment(a, b, (r, r), parent, lateral, material)
            .unwrap()
    }

    /// An upright blade 0.2 m long and 0.1 m wide whose base is at `at`.
    fn organ(kind: OrganKind, at: Vec3, material: MaterialId, parent: Option<SegmentId>) -> Organ {
        Organ {
            kind,
            position: at,
            orientation: Quat::IDENTITY,
            size: Vec2::new(0.2, 0.1),
            material,
            parent,
        }
    }

    fn all(p: &Plant) -> [f64; 8] {
        let mut out = [f64::NAN; 8];
        measure(p, &Descriptor::ALL, &mut Scratch::default(), &mut out);
        out
    }

    fn get(p: &Plant, d: Descriptor) -> f64 {
        d.measure(p, &mut Scratch::default())
    }

    fn close(got: f64, want: f64, what: &str) {
        assert!((got - want).abs() < 1e-5, "{what}: got {got}, want {want}");
    }

    /// A stem 4 m tall and 0.2 m wide, in two segments.
    fn stick() -> Plant {
        let mut p = Plant::new(PlantMeta::default());
        let a = seg(
            &mut p,
            Vec3::ZERO,
            v(0.0, 2.0, 0.0),
            0.1,
            None,
            false,
            Plant::BARK,
        );
        seg(
            &mut p,
            v(0.0, 2.0, 0.0),
            v(0.0, 4.0, 0.0),
            0.1,
            Some(a),
            false,
            Plant::BARK,
        );
        p
    }

    #[test]
    fn a_straight_stick() {
        let p = stick();
        let [h2w, porosity, lean, asymmetry, depth, bare, leaves, tips] = all(&p);
        // 4 m over 0.2 m is 20: capped.
        assert_eq!(h2w, MAX_HEIGHT_TO_WIDTH);
        assert_eq!(porosity, 0.0, "a box has no gaps");
        assert_eq!((lean, asymmetry, depth, bare), (0.0, 0.0, 0.0, 1.0));
        assert_eq!((leaves, tips), (0.0, 1.0));
    }

    /// A trunk 2 m tall forking into two branches to (±1, 3, 0), its axis going on to +x.
    fn y_fork() -> Plant {
        let mut p = Plant::new(PlantMeta::default());
        let top = v(0.0, 2.0, 0.0);
        let trunk = seg(&mut p, Vec3::ZERO, top, 0.1, None, false, Plant::BARK);
        seg(
            &mut p,
            top,
            v(1.0, 3.0, 0.0),
            0.05,
            Some(trunk),
            false,
            Plant::BARK,
        );
        seg(
            &mut p,
            top,
            v(-1.0, 3.0, 0.0),
            0.05,
            Some(trunk),
            true,
            Plant::BARK,
        );
        p
    }

    #[test]
    fn a_y_fork() {
        let p = y_fork();
        let [h2w, _, lean, asymmetry, depth, bare, leaves, tips] = all(&p);
        // 3 m tall; 2.1 m across (the branches' ends and their radii).
        close(h2w, 3.0 / 2.1, "height to width");
        close(lean, 0.0, "lean");
        close(asymmetry, 0.0, "asymmetry");
        assert_eq!((depth, leaves, tips), (1.0, 0.0, 2.0));
        // The branch leaves the main axis at 2 m of 3.
        close(bare, 2.0 / 3.0, "bare trunk");
    }

    #[test]
    fn a_leaning_stick() {
        let mut p = Plant::new(PlantMeta::default());
        seg(
            &mut p,
            Vec3::ZERO,
            v(3.0, 4.0, 0.0),
            0.1,
            None,
            false,
            Plant::BARK,
        );
        let [h2w, _, lean, asymmetry, depth, bare, _, tips] = all(&p);
        close(h2w, 4.0 / 3.2, "height to width");
        // The centre of mass is half-way up, 1.5 m aside.
        close(lean, 1.5 / 4.0, "lean");
        close(asymmetry, 1.0, "asymmetry");
        assert_eq!((depth, bare, tips), (0.0, 1.0, 1.0));
        // Leaning away from the viewer it leans as much, but is balanced from the front.
        let mut q = Plant::new(PlantMeta::default());
        seg(
            &mut q,
            Vec3::ZERO,
            v(0.0, 4.0, 3.0),
            0.1,
            None,
            false,
            Plant::BARK,
        );
        close(get(&q, Lean), 1.5 / 4.0, "lean away");
        close(get(&q, Asymmetry), 0.0, "asymmetry away");
    }

    /// A trunk 4 m tall with a branch to the right at 2 m and one at its top, going to
    /// `(top_x, 5, 0)`.
    fn one_sided(top_x: f32) -> Plant {
        let mut p = Plant::new(PlantMeta::default());
        let (mid, top) = (v(0.0, 2.0, 0.0), v(0.0, 4.0, 0.0));
        let a = seg(&mut p, Vec3::ZERO, mid, 0.1, None, false, Plant::BARK);
        let b = seg(&mut p, mid, top, 0.1, Some(a), false, Plant::BARK);
        seg(
            &mut p,
            mid,
            v(2.0, 3.0, 0.0),
            0.05,
            Some(a),
            true,
            Plant::BARK,
        );
        seg(
            &mut p,
            top,
            v(top_x, 5.0, 0.0),
            0.05,
            Some(b),
            true,
            Plant::BARK,
        );
        p
    }

    #[test]
    fn a_one_sided_tree() {
        let p = one_sided(1.5);
        let [_, _, lean, asymmetry, depth, bare, _, tips] = all(&p);
        close(asymmetry, 1.0, "asymmetry");
        assert!(lean > 0.05 && lean < 0.5, "{lean}");
        assert_eq!((depth, tips), (1.0, 2.0));
        close(bare, 2.0 / 5.0, "bare trunk");
        // With its top branch to the left instead it is more balanced and leans less.
        let q = one_sided(-1.5);
        let (a, l) = (get(&q, Asymmetry), get(&q, Lean));
        assert!(a > 0.0 && a < 0.5, "{a}");
        assert!(l < lean, "{l} vs {lean}");
        // A branch off a branch is one order deeper.
        let mut r = one_sided(1.5);
        let from = SegmentId(2);
        let end = r.segment(from).end;
        seg(
            &mut r,
            end,
            end + v(0.5, 0.5, 0.0),
            0.02,
            Some(from),
            true,
            Plant::BARK,
        );
        assert_eq!(get(&r, BranchingDepth), 2.0);
        assert_eq!(
            get(&r, Tips),
            2.0,
            "the twig's end is a tip instead of its branch's"
        );
    }

    #[test]
    fn leaves_are_counted_once_each() {
        let mut p = stick();
        let trunk = Some(SegmentId(0));
        for y in [1.0, 1.5, 2.5] {
            p.add_organ(organ(OrganKind::Leaf, v(0.0, y, 0.0), Plant::LEAF, trunk))
                .unwrap();
        }
        // A flower, and a petal drawn as a leaf-shaped blade: not leaves.
        p.add_organ(organ(
            OrganKind::Flower,
            v(0.0, 3.0, 0.0),
            Plant::FLOWER,
            trunk,
        ))
        .unwrap();
        p.add_organ(organ(
            OrganKind::Leaf,
            v(0.0, 3.0, 0.0),
            Plant::FLOWER,
            trunk,
        ))
        .unwrap();
        // Two leaves drawn as segments (as an L-system draws them).
        for x in [0.3, -0.3] {
            let at = v(0.0, 3.0, 0.0);
            seg(
                &mut p,
                at,
                at + v(x, 0.2, 0.0),
                0.02,
                Some(SegmentId(1)),
                true,
                Plant::LEAF,
            );
        }
        // A midrib bearing its blade (as PlantMaker draws a leaf): one leaf.
        let at = v(0.0, 3.5, 0.0);
        let rib = seg(
            &mut p,
            at,
            at + v(0.0, 0.2, 0.3),
            0.002,
            Some(SegmentId(1)),
            true,
            Plant::LEAF,
        );
        p.add_organ(organ(OrganKind::Leaf, at, Plant::LEAF, Some(rib)))
            .unwrap();
        let [_, _, _, _, depth, bare, leaves, tips] = all(&p);
        assert_eq!(leaves, 6.0);
        // Leaves are not wood: still a single stem with one tip.
        assert_eq!((depth, tips), (0.0, 1.0));
        // The crown starts at the lowest leaf, 1 m up the 4 m stem.
        close(bare, 0.25, "bare trunk");
    }

    #[test]
    fn roots_are_left_out() {
        let root_first = |with: &Plant| {
            let mut p = Plant::new(PlantMeta::default());
            let root = p
                .add_material(Material::of_kind(MaterialKind::Root))
                .unwrap();
            let r = seg(
                &mut p,
                Vec3::ZERO,
                v(3.0, -2.0, 1.0),
                0.5,
                None,
                false,
                root,
            );
            p.add_organ(organ(OrganKind::RootTip, v(3.0, -2.0, 1.0), root, Some(r)))
                .unwrap();
            // The shoot, grown from the root's foot.
            for s in with.segments() {
                let parent = s.parent.map(|i| SegmentId(i.0 + 1));
                p.add_segment(
                    s.start,
                    s.end,
                    (s.start_radius, s.end_radius),
                    parent,
                    s.lateral,
                    s.material,
                )
                .unwrap();
            }
            p
        };
        for shoot in [stick(), y_fork(), one_sided(1.5)] {
            assert_eq!(all(&root_first(&shoot)), all(&shoot));
        }
        // Roots alone are no shoot.
        assert_eq!(
            all(&root_first(&Plant::new(PlantMeta::default()))),
            [0.0; 8]
        );
    }

    #[test]
    fn nothing_measures_zero() {
        assert_eq!(all(&Plant::new(PlantMeta::default())), [0.0; 8]);
        assert_eq!(all(&Plant::default()), [0.0; 8]);
    }

    #[test]
    fn every_value_is_finite_at_the_extremes() {
        let big = MAX_COORD_F;
        let mut p = Plant::new(PlantMeta::default());
        seg(
            &mut p,
            v(-big, -big, -big),
            v(big, big, big),
            big,
            None,
            false,
            Plant::BARK,
        );
        let mut leaf = organ(OrganKind::Leaf, v(big, big, big), Plant::LEAF, None);
        leaf.size = Vec2::splat(big);
        p.add_organ(leaf).unwrap();
        // Flat, without radius: no height, all lean.
        let mut flat = Plant::new(PlantMeta::default());
        seg(
            &mut flat,
            Vec3::ZERO,
            Vec3::X,
            0.0,
            None,
            false,
            Plant::BARK,
        );
        // A point.
        let mut point = Plant::new(PlantMeta::default());
        seg(
            &mut point,
            Vec3::ONE,
            Vec3::ONE,
            0.0,
            None,
            false,
            Plant::BARK,
        );
        for p in [p, flat, point] {
            let values = all(&p);
            assert!(
                values.iter().all(|x| x.is_finite() && *x >= 0.0),
                "{values:?}"
            );
        }
    }

    const MAX_COORD_F: f32 = sylva_core::plant::MAX_COORD;

    #[test]
    fn porosity_sees_gaps() {
        // Two stems 2 m apart, each 0.2 m wide: rows are 0.4 m of ink in 2.2 m.
        let mut p = Plant::new(PlantMeta::default());
        for x in [-1.0, 1.0] {
            seg(
                &mut p,
                v(x, 0.0, 0.0),
                v(x, 4.0, 0.0),
                0.1,
                None,
                false,
                Plant::BARK,
            );
        }
        let porosity = get(&p, Porosity);
        assert!((porosity - (1.0 - 0.4 / 2.2)).abs() < 0.05, "{porosity}");
        // Wider than the canvas: drawn whole, both stems seen.
        let mut wide = Plant::new(PlantMeta::default());
        for x in [-10.0, 10.0] {
            seg(
                &mut wide,
                v(x, 0.0, 0.0),
                v(x, 1.0, 0.0),
                0.1,
                None,
                false,
                Plant::BARK,
            );
        }
        let porosity = get(&wide, Porosity);
        assert!(porosity > 0.9, "{porosity}");
        // Solid: a stem as wide as tall.
        let mut stump = Plant::new(PlantMeta::default());
        seg(
            &mut stump,
            Vec3::ZERO,
            Vec3::Y,
            0.5,
            None,
            false,
            Plant::BARK,
        );
        assert_eq!(get(&stump, Porosity), 0.0);
    }

    #[test]
    fn names_round_trip_and_unknown_names_are_listed() {
        let names: Vec<_> = Descriptor::ALL.iter().map(|d| d.name()).collect();
        assert_eq!(names, NAMES);
        for d in Descriptor::ALL {
            assert_eq!(Descriptor::from_name(d.name()), Some(d));
            assert_eq!(d.to_string(), d.name());
            let json = serde_json::to_string(&d).unwrap();
            assert_eq!(json, format!("\"{}\"", d.name()));
            assert_eq!(serde_json::from_str::<Descriptor>(&json).unwrap(), d);
            let (lo, hi) = d.range();
            assert!(lo < hi && lo >= 0.0, "{d}");
            assert!(!d.about().is_empty() && !d.about().contains('\n'));
        }
        #[derive(Deserialize)]
        struct Map {
            #[allow(dead_code)] // Read for its error.
            descriptors: Vec<Descriptor>,
        }
        let map: Result<Map, _> = toml::from_str("descriptors = [\"lean\", \"tips\"]");
        assert_eq!(map.unwrap().descriptors, [Lean, Tips]);
        let err = toml::from_str::<Map>("descriptors = [\"lean\", \"height\"]")
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("`height`"), "{err}");
        for name in NAMES {
            assert!(err.contains(name), "{name} missing from {err}");
        }
        let err = serde_json::from_str::<Descriptor>("3")
            .unwrap_err()
            .to_string();
        assert!(err.contains("height_to_width, porosity"), "{err}");
    }

    #[test]
    fn measuring_together_equals_measuring_alone() {
        let plant = BinTree::default().develop(0).unwrap();
        let together = all(&plant);
        for (d, value) in Descriptor::ALL.iter().zip(together) {
            assert_eq!(get(&plant, *d), value, "{d}");
        }
        let mut out = [0.0; 3];
        measure(
            &plant,
            &[Tips, Porosity, Tips],
            &mut Scratch::default(),
            &mut out,
        );
        assert_eq!(out, [together[7], together[1], together[7]]);
    }

    #[test]
    fn a_warm_scratch_allocates_nothing() {
        let big = BinTree {
            depth: 10,
            ..BinTree::default()
        };
        let (big, small) = (
            big.develop(0).unwrap(),
            BinTree::default().develop(1).unwrap(),
        );
        let mut scratch = Scratch::default();
        let mut out = [0.0; 8];
        measure(&big, &Descriptor::ALL, &mut scratch, &mut out);
        let warm = scratch.footprint();
        assert!(warm.iter().all(|&(_, capacity)| capacity > 0));
        for plant in [&small, &big, &one_sided(1.0)] {
            measure(plant, &Descriptor::ALL, &mut scratch, &mut out);
            assert_eq!(scratch.footprint(), warm);
        }
    }

    #[test]
    fn grown_binary_trees_measure_within_range() {
        let mut scratch = Scratch::default();
        let mut out = [0.0; 8];
        let mut trees = vec![BinTree::default()];
        for seed in 0..40u64 {
            let (geometry, width) = if seed % 2 == 0 {
                (Geometry::Sylva, BITS)
            } else {
                (Geometry::Paper, PAPER_BITS)
            };
            let bits = Bits::random(width, &mut rng::seeded(seed)).unwrap();
            trees.push(BinTree::decode_as(&bits, 0.01, geometry));
        }
        for tree in trees {
            let plant = tree.develop(0).unwrap();
            measure(&plant, &Descriptor::ALL, &mut scratch, &mut out);
            let [h2w, porosity, lean, asymmetry, depth, bare, leaves, tips] = out;
            assert!(out.iter().all(|x| x.is_finite()), "{out:?}");
            assert!(h2w > 0.0 && h2w <= MAX_HEIGHT_TO_WIDTH, "{out:?}");
            assert!((0.0..1.0).contains(&porosity), "{out:?}");
            assert!((0.0..=MAX_LEAN).contains(&lean), "{out:?}");
            assert!((0.0..=1.0).contains(&asymmetry), "{out:?}");
            assert!((0.0..=1.0).contains(&bare), "{out:?}");
            // A binary tree `depth` levels deep: its second children branch, so orders run
            // to depth - 1; its 2^(depth - 1) top cylinders are its tips; it has no leaves.
            assert_eq!(depth, f64::from(tree.depth - 1));
            assert_eq!(tips, f64::from(1u32 << (tree.depth - 1)));
            assert_eq!(leaves, 0.0);
        }
    }
}
