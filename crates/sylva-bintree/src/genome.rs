//! The binary tree's genome: its parameters, how it grows, its analytic measures and the
//! bit encoding of the genetic algorithm.
//!
//! One cylinder, then at its top two rotated copies of the whole tree, down to a recursion
//! depth. The paper's parameter vector is: lower and upper cylinder radius, cylinder length,
//! two rotations (an angle about an axis each), and the depth. Read as the paper's OpenGL
//! code would draw it, every cylinder would be the same size; Sylva makes one choice so that
//! the recursion grows a tree rather than a lattice of equal sticks, and says so:
//!
//! - **Taper carries on.** A child starts with its parent's upper radius and tapers by the same
//!   ratio `upper / lower` (at most 1), so level `k` runs from `lower·t^k` to `lower·t^(k+1)`;
//!   no radius falls below `min_radius`, the paper's "minimum radius imposed on all trees".
//! - **Length ratio** (a Sylva addition; 1.0 is the paper): level `k` is `length·ratio^k` long.
//! - **Siblings rotate from the parent's frame.** Each child's frame is the parent's frame
//!   turned by its own rotation, as `glPushMatrix`/`glPopMatrix` around each recursive call
//!   would do. Axes are in the parent's local frame: x right, y along the branch, z up.
//! - The first child continues the parent's axis, the second starts a branch (meshing joins
//!   the first into one tube).
//!
//! [`Geometry::Paper`] switches the first two off for the paper as written: every cylinder
//! runs from the lower to the upper radius, and the genetic algorithm's [`PAPER_LAYOUT`]
//! fixes the length ratio at 1 and lets the rotations take any axis and angle.
//!
//! [`BinTree::measures`] computes the paper's six tree measures analytically (no plant is
//! built, which keeps evolution fast); [`TreeMeasures::of_plant`] computes them from any grown
//! plant, and tests check that the two agree.
//!
//! The genetic algorithm's bit encoding is [`BinTree::decode`] / [`BinTree::encode`], laid
//! out in [`LAYOUT`].

use std::f64::consts::PI;

use glam::{DMat3, DVec3, Vec3};
use serde::{Deserialize, Serialize};
use sylva_core::measures::{fork_symmetry, spread_ratio};
use sylva_core::{Frame, Plant, SegmentId, TreeMeasures};
use sylva_evolve::bits::{BitString, Quantized};

use sylva_core::ranged;

use sylva_model::schema::{FieldSpec, Kind, Schema};
use sylva_model::{DevelopError, FormatV1, model_tag, plant_meta};

/// Model name in genome files.
pub const MODEL: &str = "bintree";

model_tag!(
    /// The `"model": "bintree"` header field.
    BinTreeTag,
    MODEL
);
/// Deepest recursion a genome may ask for: `2^14 - 1` = 16383 cylinders.
pub const MAX_DEPTH: u32 = 14;

/// The bit string the genetic algorithm evolves ([`BITS`] or [`PAPER_BITS`] of its 128 used).
pub type Bits = BitString<2>;

/// A rotation: an angle about an axis in the parent's local frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rotation {
    /// Degrees, -360 to 360.
    #[serde(deserialize_with = "angle")]
    pub angle: f64,
    /// Axis (x right, y along the branch, z up); any non-zero length, each component in -1..=1.
    #[serde(deserialize_with = "axis")]
    pub axis: [f64; 3],
}

impl Rotation {
    /// The unit axis (the axes of valid genomes are never zero).
    fn unit_axis(&self) -> DVec3 {
        DVec3::from_array(self.axis)
            .try_normalize()
            .unwrap_or(DVec3::X)
    }

    /// The rotation as a matrix in the parent's local frame.
    fn matrix(&self) -> DMat3 {
        DMat3::from_axis_angle(self.unit_axis(), self.angle.to_radians())
    }

    /// The same rotation with its angle in 0..=180° (a turn by `a` about an axis is a turn
    /// by `360° − a` about the opposite one): the angle in radians and the unit axis.
    fn folded(&self) -> (f64, DVec3) {
        let a = self.angle.rem_euclid(360.0);
        if a > 180.0 {
            ((360.0 - a).to_radians(), -self.unit_axis())
        } else {
            (a.to_radians(), self.unit_axis())
        }
    }

    /// Where it turns the parent's heading (local +y).
    fn direction(&self) -> DVec3 {
        self.matrix() * DVec3::Y
    }
}

/// How the recursion sizes its cylinders, and which bit layout the genetic algorithm uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Geometry {
    /// Sylva's: the taper carries on from level to level, and evolution explores length
    /// ratios of 0.55 to 0.9 and rotation axes within ±30° of the branch's normal plane
    /// ([`LAYOUT`]).
    #[default]
    Sylva,
    /// The paper's pseudo-code as written: every cylinder runs from the lower to the upper
    /// radius (no smaller than the minimum), and evolution keeps the length ratio at 1 and
    /// explores any axis and any angle from 0 to 180° ([`PAPER_LAYOUT`]).
    Paper,
}

impl Geometry {
    fn is_sylva(&self) -> bool {
        *self == Geometry::Sylva
    }

    /// The genetic algorithm's bit layout.
    pub fn layout(self) -> &'static [Field; 11] {
        match self {
            Geometry::Sylva => &LAYOUT,
            Geometry::Paper => &PAPER_LAYOUT,
        }
    }
}

/// A binary-tree genome: the paper's parameter vector plus Sylva's length ratio and the
/// minimum radius. Lengths are metres, angles degrees.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BinTree {
    /// Always `"bintree"`.
    pub model: BinTreeTag,
    /// Always 1.
    pub format: FormatV1,
    /// Levels of cylinders, 1 to 14 (`2^depth - 1` cylinders).
    #[serde(deserialize_with = "depth")]
    pub depth: u32,
    /// Radius at the foot of the trunk, metres.
    #[serde(deserialize_with = "lower_radius")]
    pub lower_radius: f64,
    /// Radius at the top of the trunk, metres; `upper / lower` is the taper of every level.
    #[serde(deserialize_with = "upper_radius")]
    pub upper_radius: f64,
    /// Trunk length, metres.
    #[serde(deserialize_with = "length")]
    pub length: f64,
    /// Each level is this much as long as its parent (1.0 in the paper).
    #[serde(deserialize_with = "length_ratio")]
    pub length_ratio: f64,
    /// Turns the first child (which continues the axis).
    pub rotation1: Rotation,
    /// Turns the second child (a new branch).
    pub rotation2: Rotation,
    /// No cylinder is thinner than this, metres.
    #[serde(deserialize_with = "min_radius")]
    pub min_radius: f64,
    /// Sylva's geometry (left out of files) or the paper's.
    #[serde(default, skip_serializing_if = "Geometry::is_sylva")]
    pub geometry: Geometry,
}

ranged!(lower_radius: f64, "lower_radius", 0.001, 5.0, " m");
ranged!(upper_radius: f64, "upper_radius", 0.001, 5.0, " m");
ranged!(length: f64, "length", 0.01, 50.0, " m");
ranged!(length_ratio: f64, "length_ratio", 0.1, 1.5, "");
ranged!(min_radius: f64, "min_radius", 0.001, 1.0, " m");
ranged!(angle: f64, "rotation angle", -360.0, 360.0, " degrees");

sylva_core::ranged!(depth: u32, "depth", 1, MAX_DEPTH);

/// The genome field by field, with the ranges files may hold (wider than evolution's
/// [`LAYOUT`]).
pub fn schema() -> Schema {
    // Files may hold what the parser takes; sliders span the sizes of real trees.
    let metres = |path, min, max, slider: f64, meaning| {
        let kind = Kind::number(min, max).slider(min, slider);
        FieldSpec::new(path, "stems", kind, meaning).unit(" m")
    };
    let mut fields = vec![
        FieldSpec::new(
            "depth",
            "shape",
            Kind::integer(1, i64::from(MAX_DEPTH)),
            "Levels of branching: 2^depth − 1 cylinders.",
        )
        .shaping(),
        metres("length", 0.01, 50.0, 10.0, "The trunk's length.").shaping(),
        FieldSpec::new(
            "length_ratio",
            "shape",
            Kind::number(0.1, 1.5),
            "Each level's length over its parent's (1 in the paper).",
        )
        .shaping(),
        metres(
            "lower_radius",
            0.001,
            5.0,
            1.0,
            "The trunk's radius at its foot.",
        ),
        metres(
            "upper_radius",
            0.001,
            5.0,
            1.0,
            "The trunk's radius at its top: top over foot is every level's taper.",
        ),
        metres(
            "min_radius",
            0.001,
            1.0,
            0.1,
            "No cylinder is thinner than this.",
        ),
    ];
    let children = [
        ("rotation1", "the first child (it carries the axis on)"),
        ("rotation2", "the second child (a new branch)"),
    ];
    for (rotation, child) in children {
        let angle = format!("How far {child} turns from its parent.");
        let axis = format!("The axis {child} turns about (x right, y along the branch, z up).");
        fields.push(
            FieldSpec::new(
                format!("{rotation}.angle"),
                "shape",
                Kind::number(-360.0, 360.0).slider(-180.0, 180.0),
                angle,
            )
            .unit("°")
            .shaping(),
        );
        fields.push(FieldSpec::new(
            format!("{rotation}.axis"),
            "shape",
            Kind::Axis,
            axis,
        ));
    }
    fields.push(FieldSpec::new("geometry", "shape", Kind::choice_of(&[Geometry::Sylva, Geometry::Paper]), "Sylva's geometry (the taper carries on from level to level) or the paper's (every cylinder from the lower to the upper radius).").optional());
    Schema::of(fields)
}

/// Reads an axis inside the array's own visitor, so an error points at the array (checks
/// made after the array is read would point at the end of the enclosing object).
fn axis<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
    struct AxisVisitor;
    impl<'de> serde::de::Visitor<'de> for AxisVisitor {
        type Value = [f64; 3];
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an axis: three numbers from -1 to 1, not all zero")
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<[f64; 3], A::Error> {
            use serde::de::Error;
            let mut v = [0.0f64; 3];
            for (i, c) in v.iter_mut().enumerate() {
                *c = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(i, &self))?;
            }
            if seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
                return Err(A::Error::invalid_length(4, &self));
            }
            if v.iter().any(|c| !c.is_finite() || c.abs() > 1.0) {
                return Err(A::Error::custom(format!(
                    "`axis` components must be numbers from -1 to 1, got {v:?}"
                )));
            }
            if DVec3::from_array(v).length() < 1e-6 {
                return Err(A::Error::custom(
                    "`axis` must not be the zero vector (a rotation needs a direction)",
                ));
            }
            Ok(v)
        }
    }
    d.deserialize_seq(AxisVisitor)
}

/// One GA field: its name, width and range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Field {
    /// The genome field it sets.
    pub name: &'static str,
    /// The encoding.
    pub code: Quantized,
}

const fn field(name: &'static str, bits: u8, min: f64, max: f64) -> Field {
    Field {
        name,
        code: Quantized { bits, min, max },
    }
}

/// The bit layout of the genetic algorithm, in order (first bit least significant in each
/// field). Ranges are what evolution explores; hand-written genomes may go wider (see the
/// field docs of [`BinTree`]). The minimum radius is set by the run and takes no bits.
///
/// Each rotation axis is encoded by two angles rather than three components: an azimuth
/// around the branch and an elevation towards it, `axis = (cos e·cos a, sin e, cos e·sin a)`.
/// Three free components let evolution point the axis along the branch, where a rotation
/// only rolls the child and never bends it; with the elevation within ±30° every rotation
/// bends its child by at least 0.87 of its angle, so every tree branches.
pub const LAYOUT: [Field; 11] = [
    field("depth", 3, 3.0, 10.0),
    field("lower_radius", 7, 0.05, 0.6),
    field("upper_radius", 7, 0.02, 0.6),
    field("length", 7, 0.3, 3.0),
    field("length_ratio", 5, 0.55, 0.9),
    field("rotation1.angle", 7, 15.0, 75.0),
    field("rotation1.axis azimuth", 6, 0.0, 354.375),
    field("rotation1.axis elevation", 5, -30.0, 30.0),
    field("rotation2.angle", 7, 15.0, 75.0),
    field("rotation2.axis azimuth", 6, 0.0, 354.375),
    field("rotation2.axis elevation", 5, -30.0, 30.0),
];

/// The bit layout of [`Geometry::Paper`]: [`LAYOUT`]'s fields and widths, but the paper's
/// reach. The length ratio is fixed at 1 (its one bit decodes to 1 either way, so the two
/// layouts share a shape); angles run from 0 to 180° and axes point anywhere (elevation
/// ±90°), which together give every rotation there is.
pub const PAPER_LAYOUT: [Field; 11] = [
    field("depth", 3, 3.0, 10.0),
    field("lower_radius", 7, 0.05, 0.6),
    field("upper_radius", 7, 0.02, 0.6),
    field("length", 7, 0.3, 3.0),
    field("length_ratio", 1, 1.0, 1.0),
    field("rotation1.angle", 7, 0.0, 180.0),
    field("rotation1.axis azimuth", 6, 0.0, 354.375),
    field("rotation1.axis elevation", 5, -90.0, 90.0),
    field("rotation2.angle", 7, 0.0, 180.0),
    field("rotation2.axis azimuth", 6, 0.0, 354.375),
    field("rotation2.axis elevation", 5, -90.0, 90.0),
];

/// Bits a layout uses.
const fn bits_of(layout: &[Field]) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < layout.len() {
        n += layout[i].code.bits as usize;
        i += 1;
    }
    n
}

/// Bits [`LAYOUT`] uses.
pub const BITS: usize = bits_of(&LAYOUT);

/// Bits [`PAPER_LAYOUT`] uses.
pub const PAPER_BITS: usize = bits_of(&PAPER_LAYOUT);

/// The unit axis with this azimuth and elevation (degrees).
fn axis_from_angles(azimuth: f64, elevation: f64) -> [f64; 3] {
    let (a, e) = (azimuth.to_radians(), elevation.to_radians());
    [e.cos() * a.cos(), e.sin(), e.cos() * a.sin()]
}

/// Azimuth and elevation (-90 to 90) of an axis, degrees. The azimuth runs from minus half
/// an azimuth code step to 360 less that, so an axis near 360° encodes as 0°, not as the
/// largest code.
fn angles_of_axis(axis: [f64; 3]) -> (f64, f64) {
    let v = DVec3::from_array(axis).try_normalize().unwrap_or(DVec3::X);
    let half_step = 0.5 * LAYOUT[6].code.step();
    let azimuth = (v.z.atan2(v.x).to_degrees() + half_step).rem_euclid(360.0) - half_step;
    (azimuth, v.y.clamp(-1.0, 1.0).asin().to_degrees())
}

/// The bit string of `values` (one per field, see [`BinTree::values`]) in `geometry`'s
/// layout: each value's nearest code, values outside a field's range clamped to it.
pub fn encode_values(values: &[f64; 11], geometry: Geometry) -> Bits {
    let layout = geometry.layout();
    let mut bits = Bits::zeros(bits_of(layout)).expect("the layout fits in two words");
    let mut offset = 0;
    for (v, f) in values.iter().zip(layout) {
        let width = usize::from(f.code.bits);
        bits.write(offset, width, f.code.encode(*v));
        offset += width;
    }
    bits
}

impl BinTree {
    /// Decodes a GA bit string (see [`LAYOUT`]); `min_radius` comes from the run.
    pub fn decode(bits: &Bits, min_radius: f64) -> BinTree {
        BinTree::decode_as(bits, min_radius, Geometry::Sylva)
    }

    /// Decodes a GA bit string laid out for `geometry`, into a genome of that geometry.
    pub fn decode_as(bits: &Bits, min_radius: f64, geometry: Geometry) -> BinTree {
        let layout = geometry.layout();
        let mut values = [0.0; LAYOUT.len()];
        let mut offset = 0;
        for (v, f) in values.iter_mut().zip(layout) {
            let width = usize::from(f.code.bits);
            *v = f.code.decode(bits.read(offset, width));
            offset += width;
        }
        let [d, lr, ur, len, ratio, a1, az1, el1, a2, az2, el2] = values;
        BinTree {
            model: BinTreeTag,
            format: FormatV1,
            depth: d.round() as u32,
            lower_radius: lr,
            upper_radius: ur,
            length: len,
            length_ratio: ratio,
            rotation1: Rotation {
                angle: a1,
                axis: axis_from_angles(az1, el1),
            },
            rotation2: Rotation {
                angle: a2,
                axis: axis_from_angles(az2, el2),
            },
            min_radius,
            geometry,
        }
    }

    /// The nearest bit string (values outside the GA's ranges are clamped to them).
    pub fn encode(&self) -> Bits {
        encode_values(&self.values(), self.geometry)
    }

    /// The genome's value of each field of the GA's layout, in the layout's order (each
    /// rotation's axis as its azimuth and elevation, degrees).
    pub fn values(&self) -> [f64; 11] {
        [
            f64::from(self.depth),
            self.lower_radius,
            self.upper_radius,
            self.length,
            self.length_ratio,
            self.rotation1.angle,
            angles_of_axis(self.rotation1.axis).0,
            angles_of_axis(self.rotation1.axis).1,
            self.rotation2.angle,
            angles_of_axis(self.rotation2.axis).0,
            angles_of_axis(self.rotation2.axis).1,
        ]
    }

    /// Number of cylinders, `2^depth - 1`.
    pub fn cylinder_count(&self) -> usize {
        (1usize << self.depth.min(MAX_DEPTH)) - 1
    }

    /// Per-level taper ratio: `upper / lower`, at most 1.
    fn taper(&self) -> f64 {
        (self.upper_radius / self.lower_radius).min(1.0)
    }

    /// Radius at the foot of level `k`.
    fn radius_at(&self, k: u32) -> f64 {
        match self.geometry {
            Geometry::Sylva => self.lower_radius * self.taper().powi(k as i32),
            Geometry::Paper => self.lower_radius,
        }
        .max(self.min_radius)
    }

    /// Radius at the top of level `k`.
    fn top_radius_at(&self, k: u32) -> f64 {
        match self.geometry {
            Geometry::Sylva => self.radius_at(k + 1),
            Geometry::Paper => self.upper_radius.max(self.min_radius),
        }
    }

    /// Length of level `k`.
    fn length_at(&self, k: u32) -> f64 {
        self.length * self.length_ratio.powi(k as i32)
    }

    /// The six measures, computed from the parameters without building a plant.
    pub fn measures(&self) -> TreeMeasures {
        let depth = self.depth.clamp(1, MAX_DEPTH);
        let (mut area, mut volume, mut radii, mut lengths) = (0.0, 0.0, 0.0, 0.0);
        for k in 0..depth {
            let n = f64::from(1u32 << k);
            let (r0, r1, len) = (self.radius_at(k), self.top_radius_at(k), self.length_at(k));
            area += n * PI * (r0 + r1) * ((r0 - r1).powi(2) + len * len).sqrt();
            volume += n * PI * len * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
            radii += n * 0.5 * (r0 + r1);
            lengths += n * len;
        }
        // Leonardo's rule at each fork of levels k and k+1: (2 r_{k+1}^2) / r_k^2 against 1.
        let mut pipe_model = 0.0;
        for k in 0..depth.saturating_sub(1) {
            let q = 2.0 * (self.radius_at(k + 1) / self.radius_at(k)).powi(2);
            pipe_model += f64::from(1u32 << k) * (1.0 - (q - 1.0).abs()).max(0.0);
        }
        pipe_model = if depth > 1 {
            pipe_model / f64::from((1u32 << (depth - 1)) - 1)
        } else {
            1.0
        };
        let (height, roundness) = (self.extent(DVec3::Y), self.roundness());
        let (d1, d2) = (self.rotation1.direction(), self.rotation2.direction());
        let (symmetry, straightness) = if depth > 1 {
            let deviation = 0.5 * (angle_between(DVec3::Y, d1) + angle_between(DVec3::Y, d2));
            (fork_symmetry(DVec3::Y, d1, d2), 1.0 - deviation / PI)
        } else {
            (1.0, 1.0)
        };
        TreeMeasures {
            height,
            pipe_model,
            roundness,
            surface_area: area,
            volume,
            symmetry,
            straightness,
            radius_to_length: radii / lengths,
        }
    }

    /// The paper's straightness, "inversely proportional to the average rotation angle":
    /// `1 / θ̄`, the mean of the two rotation angles in radians (each folded into 0..180°),
    /// with `θ̄` no less than 1° so that a pole scores 57.3 rather than infinity.
    pub fn paper_straightness(&self) -> f64 {
        1.0 / self.mean_rotation().max(1f64.to_radians())
    }

    /// The paper's height, "calculated with the sine of the two rotation angles": the trunk,
    /// then every further level rising by its length times the sine of its elevation,
    /// `90° − θ̄`, with `θ̄` the mean of the two rotation angles (at least 0). The paper's
    /// code is not given; this reading uses only the lengths, the depth and the two angles,
    /// and rewards "long cylinder length in conjunction with small rotation angle" as the
    /// paper says it does.
    pub fn paper_height(&self) -> f64 {
        let depth = self.depth.clamp(1, MAX_DEPTH);
        let rise = (0.5 * PI - self.mean_rotation()).sin();
        let levels: f64 = (1..depth).map(|k| self.length_at(k) * rise).sum();
        (self.length + levels).max(0.0)
    }

    /// The paper's symmetry, which "promotes trees in which the two rotation angles and axes
    /// are approximately equivalent, with partial credit for partial matches": the mean of
    /// an angle match, `1 − |θ₁ − θ₂| / 180°`, and an axis match, `(1 + â₁·â₂) / 2`, each
    /// 0 to 1, with both rotations folded to angles of 0..180°. 1 for a tree without forks.
    pub fn paper_symmetry(&self) -> f64 {
        if self.depth <= 1 {
            return 1.0;
        }
        let ((a1, axis1), (a2, axis2)) = (self.rotation1.folded(), self.rotation2.folded());
        let angles = 1.0 - (a1 - a2).abs() / PI;
        let axes = 0.5 * (1.0 + axis1.dot(axis2));
        0.5 * (angles + axes)
    }

    /// Mean of the two rotation angles, each folded into 0..π, radians.
    fn mean_rotation(&self) -> f64 {
        0.5 * (self.rotation1.folded().0 + self.rotation2.folded().0)
    }

    /// The largest `p · w` over the skeleton's points (the foot and every cylinder's top),
    /// by a depth-first walk that tracks only `Mᵀw` for each frame `M` and skips subtrees
    /// that cannot beat the best so far. With `w` = +Y it is the height.
    fn extent(&self, w: DVec3) -> f64 {
        let depth = self.depth.clamp(1, MAX_DEPTH);
        // `below[k]`: total length of levels k.. to the tips, the most a subtree can reach.
        let mut below = [0.0; MAX_DEPTH as usize + 1];
        for k in (0..depth).rev() {
            below[k as usize] = below[k as usize + 1] + self.length_at(k);
        }
        let walk = ExtentWalk {
            rotations: [self.rotation1.matrix(), self.rotation2.matrix()],
            lengths: std::array::from_fn(|k| self.length_at(k as u32)),
            below,
            depth,
        };
        let top = self.length * w.y;
        let mut best = top.max(0.0);
        walk.visit(w, top, 1, &mut best);
        best
    }

    /// Crown roundness (see [`TreeMeasures::roundness`]) from the exact first and second
    /// moments of the skeleton's points, summed level by level from the tips down: a subtree
    /// of level `k` is its cylinder's top plus two rotated subtrees of level `k + 1`, so its
    /// moments follow from theirs without visiting a single branch.
    fn roundness(&self) -> f64 {
        let depth = self.depth.clamp(1, MAX_DEPTH);
        let rotations = [self.rotation1.matrix(), self.rotation2.matrix()];
        // Moments of the subtree below level k, in its own frame with its foot at the origin:
        // point count, sum of points, sum of outer products.
        let (mut n, mut m1, mut m2) = (0.0f64, DVec3::ZERO, DMat3::ZERO);
        for k in (0..depth).rev() {
            let top = DVec3::Y * self.length_at(k);
            let outer = |a: DVec3, b: DVec3| DMat3::from_cols(a * b.x, a * b.y, a * b.z);
            let (mut n2, mut s1, mut s2) = (1.0, top, outer(top, top));
            if n > 0.0 {
                for r in &rotations {
                    let c1 = *r * m1;
                    n2 += n;
                    s1 += top * n + c1;
                    s2 += outer(top, top) * n
                        + outer(top, c1)
                        + outer(c1, top)
                        + *r * m2 * r.transpose();
                }
            }
            (n, m1, m2) = (n2, s1, s2);
        }
        // The foot of the trunk is a point too.
        n += 1.0;
        let mean = m1 / n;
        let cxx = m2.x_axis.x / n - mean.x * mean.x;
        let czz = m2.z_axis.z / n - mean.z * mean.z;
        let cxz = m2.z_axis.x / n - mean.x * mean.z;
        spread_ratio(cxx, czz, cxz)
    }

    /// Grows the tree into a plant.
    pub fn develop(&self, seed: u64) -> Result<Plant, DevelopError> {
        let depth = self.depth.clamp(1, MAX_DEPTH);
        let mut plant = Plant::new(plant_meta::<crate::BinTreeModel>(self, seed));
        plant.reserve(self.cylinder_count(), 0);
        let rotations = [self.rotation1, self.rotation2]
            .map(|r| (r.unit_axis().as_vec3(), r.angle.to_radians() as f32));
        // Explicit stack: (foot, frame, level, parent, lateral).
        let mut stack: Vec<(Vec3, Frame, u32, Option<SegmentId>, bool)> =
            vec![(Vec3::ZERO, Frame::UPRIGHT, 0, None, false)];
        while let Some((foot, frame, k, parent, lateral)) = stack.pop() {
            let top = foot + frame.heading * self.length_at(k) as f32;
            let radii = (self.radius_at(k) as f32, self.top_radius_at(k) as f32);
            let id = plant.add_segment(foot, top, radii, parent, lateral, Plant::BARK)?;
            if k + 1 < depth {
                // Pushed in reverse so the first child is grown first.
                for (child, &(axis, angle)) in rotations.iter().enumerate().rev() {
                    let mut f = frame;
                    f.rotate_local(axis, angle);
                    stack.push((top, f, k + 1, Some(id), child == 1));
                }
            }
        }
        Ok(plant)
    }
}

impl Default for BinTree {
    /// A small, upright, symmetric tree.
    fn default() -> Self {
        BinTree {
            model: BinTreeTag,
            format: FormatV1,
            depth: 8,
            lower_radius: 0.3,
            upper_radius: 0.22,
            length: 2.0,
            length_ratio: 0.8,
            rotation1: Rotation {
                angle: 30.0,
                axis: [0.0, 0.3, 1.0],
            },
            rotation2: Rotation {
                angle: 30.0,
                axis: [0.0, 0.3, -1.0],
            },
            min_radius: 0.01,
            geometry: Geometry::Sylva,
        }
    }
}

fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.dot(b).clamp(-1.0, 1.0).acos()
}

/// The state of [`BinTree::extent`]'s walk.
struct ExtentWalk {
    rotations: [DMat3; 2],
    lengths: [f64; MAX_DEPTH as usize],
    below: [f64; MAX_DEPTH as usize + 1],
    depth: u32,
}

impl ExtentWalk {
    /// Visits the children of a cylinder at level `k - 1` whose top has `p · w = reach` and
    /// whose frame `M` has `Mᵀw = row`.
    fn visit(&self, row: DVec3, reach: f64, k: u32, best: &mut f64) {
        if k >= self.depth || reach + self.below[k as usize] <= *best {
            return;
        }
        let len = self.lengths[k as usize];
        let rows = self.rotations.map(|r| r.transpose() * row);
        // Follow the child heading most along `w` first: it raises `best` sooner.
        let order = if rows[0].y >= rows[1].y {
            [0, 1]
        } else {
            [1, 0]
        };
        for i in order {
            let top = reach + len * rows[i].y;
            *best = best.max(top);
            self.visit(rows[i], top, k + 1, best);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_fits() {
        assert_eq!(BITS, 65);
        assert_eq!(PAPER_BITS, 61);
        const { assert!(BITS <= Bits::CAPACITY) };
    }

    #[test]
    fn paper_geometry_draws_every_cylinder_alike() {
        let t = BinTree {
            geometry: Geometry::Paper,
            depth: 5,
            lower_radius: 0.2,
            upper_radius: 0.16,
            ..BinTree::default()
        };
        let p = t.develop(0).unwrap();
        assert!(p.segments().iter().all(|s| {
            (s.start_radius - 0.2).abs() < 1e-6 && (s.end_radius - 0.16).abs() < 1e-6
        }));
        // Sylva's geometry tapers the same genome from level to level instead.
        let sylva = BinTree {
            geometry: Geometry::Sylva,
            ..t
        };
        let thinnest = sylva
            .develop(0)
            .unwrap()
            .segments()
            .last()
            .unwrap()
            .end_radius;
        assert!((thinnest - 0.2 * 0.8f32.powi(5)).abs() < 1e-6, "{thinnest}");
    }

    #[test]
    fn paper_layout_reaches_the_papers_values() {
        let mut bits = Bits::zeros(PAPER_BITS).unwrap();
        let t = BinTree::decode_as(&bits, 0.02, Geometry::Paper);
        assert_eq!((t.length_ratio, t.rotation1.angle), (1.0, 0.0));
        for i in 0..PAPER_BITS {
            bits.set(i, true);
        }
        let t = BinTree::decode_as(&bits, 0.02, Geometry::Paper);
        assert_eq!((t.length_ratio, t.rotation1.angle), (1.0, 180.0));
        assert!(
            (t.rotation1.axis[1] - 1.0).abs() < 1e-12,
            "an axis along the branch"
        );
        assert_eq!(BinTree::decode_as(&t.encode(), 0.02, Geometry::Paper), t);
    }

    #[test]
    fn paper_forms_of_straightness_and_height() {
        let turn = |angle| Rotation {
            angle,
            axis: [1.0, 0.0, 0.0],
        };
        let t = BinTree {
            depth: 3,
            length: 2.0,
            length_ratio: 1.0,
            rotation1: turn(30.0),
            rotation2: turn(-90.0),
            ..BinTree::default()
        };
        // Mean angle 60°: straightness 1 / (π/3); each of two levels rises 2·sin 30° = 1.
        assert!((t.paper_straightness() - 3.0 / PI).abs() < 1e-12);
        assert!((t.paper_height() - 4.0).abs() < 1e-12);
        let pole = BinTree {
            rotation1: turn(0.0),
            rotation2: turn(360.0),
            ..t
        };
        assert!((pole.paper_straightness() - 180.0 / PI).abs() < 1e-9);
        assert!((pole.paper_height() - 6.0).abs() < 1e-12);
        let drooping = BinTree {
            depth: 8,
            rotation1: turn(180.0),
            rotation2: turn(180.0),
            ..t
        };
        assert_eq!(drooping.paper_height(), 0.0);
    }

    #[test]
    fn paper_symmetry_credits_matching_angles_and_axes() {
        let turn = |angle, axis| Rotation { angle, axis };
        let tree = |r1, r2| BinTree {
            depth: 4,
            rotation1: r1,
            rotation2: r2,
            ..BinTree::default()
        };
        let x = [1.0, 0.0, 0.0];
        assert_eq!(tree(turn(40.0, x), turn(40.0, x)).paper_symmetry(), 1.0);
        // A turn by −40° about x is a turn by 40° about −x: the angles match, the axes not.
        assert!((tree(turn(40.0, x), turn(-40.0, x)).paper_symmetry() - 0.5).abs() < 1e-12);
        // 320° about x is that same turn written another way.
        let same = tree(turn(-40.0, x), turn(320.0, x)).paper_symmetry();
        assert!((same - 1.0).abs() < 1e-12);
        // Half the angle range apart and perpendicular axes: half credit on each.
        let partial = tree(turn(0.0, x), turn(90.0, [0.0, 0.0, 1.0])).paper_symmetry();
        assert!((partial - 0.5).abs() < 1e-12);
        assert_eq!(
            BinTree {
                depth: 1,
                ..tree(turn(0.0, x), turn(180.0, x))
            }
            .paper_symmetry(),
            1.0
        );
    }

    #[test]
    fn develop_counts_and_orders() {
        let t = BinTree::default();
        let p = t.develop(0).unwrap();
        assert_eq!(p.segments().len(), 255);
        assert_eq!(p.tips().count(), 128);
        assert_eq!(p.segments()[0].start, Vec3::ZERO);
        assert_eq!(p.segments().iter().map(|s| s.order).max(), Some(7));
        assert!(p.segments().iter().all(|s| s.start_radius >= s.end_radius));
    }

    #[test]
    fn radii_respect_the_minimum() {
        let t = BinTree {
            depth: 12,
            upper_radius: 0.05,
            ..BinTree::default()
        };
        let p = t.develop(0).unwrap();
        let thinnest = p
            .segments()
            .iter()
            .map(|s| s.end_radius)
            .fold(1.0, f32::min);
        assert!((thinnest - 0.01).abs() < 1e-6, "{thinnest}");
    }

    #[test]
    fn straight_pole() {
        let t = BinTree {
            rotation1: Rotation {
                angle: 0.0,
                axis: [1.0, 0.0, 0.0],
            },
            rotation2: Rotation {
                angle: 0.0,
                axis: [1.0, 0.0, 0.0],
            },
            length_ratio: 1.0,
            depth: 4,
            ..BinTree::default()
        };
        let m = t.measures();
        assert!((m.height - 8.0).abs() < 1e-9);
        assert_eq!(m.straightness, 1.0);
        assert_eq!(m.symmetry, 1.0);
    }
}
