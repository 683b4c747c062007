//! The three segment kinds of a PlantMaker genome, variable by variable as the paper's
//! Tables 1–3 give them.
//!
//! Each segment has two views that convert into each other exactly:
//!
//! - **Named fields** ([`Branch`], [`Fan`], [`Inflorescence`]), which is what the JSON face
//!   shows: options as words (`"segment_pattern": "diamond"`), factors as decimals (`1.5`),
//!   colours as `"#rrggbb"`, fan sets as lists of fan numbers.
//! - **Codes**: one unsigned number per variable in table order, the value the table's bits
//!   hold (options as their table code, factors in tenths, colours as 24-bit RGB, fan sets
//!   as bit masks). The packed face prints codes, and crossover and mutation work on them,
//!   which keeps every operator inside the ranges of [`BRANCH_VARIABLES`],
//!   [`FAN_VARIABLES`] and [`INFLORESCENCE_VARIABLES`].
//!
//! Where the tables are loose, this is what Sylva reads (the tables' own words in quotes):
//!
//! - **Ranges in either order.** A `min` larger than its `max` is legal; values are drawn or
//!   interpolated between the two all the same. Genes stay independent, so crossover and
//!   mutation never make an illegal pair.
//! - **Angles** are whole degrees 0–360 in 9 bits; between segments and for fan slants a value
//!   above 180 turns the other way (350 is −10), so a range 350–10 is a symmetric ±10.
//! - **Table 1, variable 11** is given 4 bits for four options; the codes are 0–3.
//! - **Table 2, variables 4 and 5** ("4 bits", "{1–30}") need 5 bits for 30 values; Sylva
//!   counts 5.
//! - **Colours** ("24 bits", "{1–256³}") are the 256³ RGB colours, codes 0 to 0xffffff.
//! - **Table 3, variable 4** ("m bits", "{1–2^m}") is a mask of the m fans, first fan in the
//!   leftmost digit as in the paper's `10100`; the empty set (no fans) is legal and draws
//!   nothing.
//! - **Table 3, variable 2** keeps the table's inverted code in the packed face: 0 = yes,
//!   1 = no. The JSON face says `"expressed": true`.

use std::fmt;

use serde::{Deserialize, Serialize};
use sylva_model::schema::{FieldSpec, Kind, ListSpec, Schema};

/// Most branch prototypes a genome may hold.
pub const MAX_BRANCHES: usize = 32;
/// Most fans a genome may hold (an inflorescence's fan set is a 32-bit mask).
pub const MAX_FANS: usize = 32;
/// Most inflorescences a genome may hold.
pub const MAX_INFLORESCENCES: usize = 32;

/// How a variable is read and how mutation changes it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GeneKind {
    /// One of a few named options; mutation picks another.
    Choice,
    /// A whole number; mutation adds noise and reflects at the ends of the range.
    Integer,
    /// Degrees 0–360, where 360 is 0 again; mutation adds noise and wraps around.
    Angle,
    /// A 24-bit RGB colour; mutation adds noise to each channel.
    Color,
    /// A branch number, 1 to the genome's branch count n.
    Branch,
    /// A set of fans, one bit per fan of the genome's m; mutation flips one.
    FanSet,
}

/// One row of a table: a variable's number, name, size and legal codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Variable {
    /// 1-based number in its table.
    pub number: u8,
    /// The JSON field name.
    pub name: &'static str,
    /// Size in bits as Sylva counts it (0 when it depends on n or m; see [`Variable::bits`]).
    pub bits: u8,
    /// Smallest legal code (fixed ranges only).
    pub min: u32,
    /// Largest legal code (fixed ranges only).
    pub max: u32,
    /// How it is read and varied.
    pub kind: GeneKind,
}

impl Variable {
    /// The legal codes in a genome with `branches` prototypes and `fans` fans.
    pub fn range(&self, branches: usize, fans: usize) -> (u32, u32) {
        match self.kind {
            GeneKind::Branch => (1, branches.max(1) as u32),
            GeneKind::FanSet => (0, mask_of(fans)),
            _ => (self.min, self.max),
        }
    }

    /// Size in bits for a genome with `branches` prototypes and `fans` fans:
    /// `ceil(log2 n)` for a branch number, `m` for a fan set.
    pub fn bits(&self, branches: usize, fans: usize) -> u32 {
        match self.kind {
            GeneKind::Branch => usize::BITS - branches.saturating_sub(1).leading_zeros(),
            GeneKind::FanSet => fans as u32,
            _ => u32::from(self.bits),
        }
    }
}

/// All `m` fan bits set.
pub(crate) fn mask_of(fans: usize) -> u32 {
    if fans >= 32 {
        u32::MAX
    } else {
        (1u32 << fans) - 1
    }
}

const fn var(
    number: u8,
    name: &'static str,
    bits: u8,
    min: u32,
    max: u32,
    kind: GeneKind,
) -> Variable {
    Variable {
        number,
        name,
        bits,
        min,
        max,
        kind,
    }
}

use GeneKind::{Angle, Choice, Color, Integer};

/// Table 1: the 23 variables of a branch segment.
pub const BRANCH_VARIABLES: [Variable; 23] = [
    var(1, "segment_pattern", 2, 0, 3, Choice),
    var(2, "branch_shape", 2, 0, 2, Choice),
    var(3, "min_x_angle", 9, 0, 360, Angle),
    var(4, "max_x_angle", 9, 0, 360, Angle),
    var(5, "min_y_angle", 9, 0, 360, Angle),
    var(6, "max_y_angle", 9, 0, 360, Angle),
    var(7, "waves", 4, 1, 16, Integer),
    var(8, "segment_count", 1, 0, 1, Choice),
    var(9, "min_segments", 7, 1, 128, Integer),
    var(10, "max_segments", 7, 1, 128, Integer),
    var(11, "thickness", 4, 0, 3, Choice),
    var(12, "min_base_thickness", 8, 1, 250, Integer),
    var(13, "max_base_thickness", 8, 1, 250, Integer),
    var(14, "min_apex_thickness", 8, 1, 250, Integer),
    var(15, "max_apex_thickness", 8, 1, 250, Integer),
    var(16, "length", 1, 0, 1, Choice),
    var(17, "min_length", 5, 1, 30, Integer),
    var(18, "max_length", 5, 1, 30, Integer),
    var(19, "noise", 1, 0, 1, Choice),
    var(20, "min_noise_x_angle", 9, 0, 360, Angle),
    var(21, "max_noise_x_angle", 9, 0, 360, Angle),
    var(22, "min_noise_y_angle", 9, 0, 360, Angle),
    var(23, "max_noise_y_angle", 9, 0, 360, Angle),
];

/// Table 2: the 15 variables of a fan segment.
pub const FAN_VARIABLES: [Variable; 15] = [
    var(1, "branch", 0, 1, 1, GeneKind::Branch),
    var(2, "count", 7, 1, 72, Integer),
    var(3, "length_mode", 3, 0, 4, Choice),
    var(4, "min_length_factor", 5, 1, 30, Integer),
    var(5, "max_length_factor", 5, 1, 30, Integer),
    var(6, "angle_mode", 3, 0, 4, Choice),
    var(7, "min_angle", 9, 0, 360, Angle),
    var(8, "max_angle", 9, 0, 360, Angle),
    var(9, "thickness_mode", 3, 0, 4, Choice),
    var(10, "min_thickness_factor", 6, 1, 50, Integer),
    var(11, "max_thickness_factor", 6, 1, 50, Integer),
    var(12, "color_mode", 3, 0, 4, Choice),
    var(13, "min_color", 24, 0, 0xff_ffff, Color),
    var(14, "max_color", 24, 0, 0xff_ffff, Color),
    var(15, "texture", 7, 0, 127, Integer),
];

/// Table 3: the 4 variables of an inflorescence segment.
pub const INFLORESCENCE_VARIABLES: [Variable; 4] = [
    var(1, "start_angle", 9, 0, 360, Angle),
    var(2, "expressed", 1, 0, 1, Choice),
    var(3, "position", 7, 0, 100, Integer),
    var(4, "fans", 0, 0, 0, GeneKind::FanSet),
];

/// A code outside its variable's range (or naming a branch or fan the genome lacks).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CodeError {
    /// Index of the variable in its table (0-based).
    pub index: usize,
    /// The code found.
    pub value: u32,
    /// Smallest legal code.
    pub min: u32,
    /// Largest legal code.
    pub max: u32,
}

impl fmt::Display for CodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} is out of range (expected {} to {})",
            self.value, self.min, self.max
        )
    }
}

/// Declares an enum of named options with its table codes.
macro_rules! options {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident = $code:literal),+ $(,)? }) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[serde(rename_all = "snake_case")]
        pub enum $name {
            $($(#[$vdoc])* $variant),+
        }

        impl $name {
            /// Every option, in code order.
            pub const ALL: &'static [$name] = &[$($name::$variant),+];

            /// The table code.
            pub fn code(self) -> u32 {
                match self {
                    $($name::$variant => $code),+
                }
            }

            /// The option with this table code.
            pub fn from_code(code: u32) -> Option<Self> {
                match code {
                    $($code => Some($name::$variant),)+
                    _ => None,
                }
            }
        }
    };
}

options!(
    /// Table 1, variable 1: the outline of each cone of a branch (Figure 4).
    SegmentPattern {
        /// Cones blend into one smooth, tapering tube.
        Straight = 0,
        /// Each cone runs from its base to its apex thickness and is pinched at the joints,
        /// like the nodes of a cane.
        Segmented = 1,
        /// Each cone narrows from its base to its apex thickness and the next steps back
        /// out, a saw-tooth of stacked cones.
        Triangular = 2,
        /// Each cone swells from its apex thickness at the ends to its base thickness at
        /// mid-length: a string of diamonds (a single one makes a rhombic leaf).
        Diamond = 3,
    }
);

options!(
    /// Table 1, variable 2: how the angles between successive cones are set (Figure 5).
    BranchShape {
        /// No bend between cones (noise still applies).
        Straight = 0,
        /// Rolls up into `waves` full turns about the x axis, tighter towards the tip.
        Curled = 1,
        /// Each of `waves` waves bends from the minimum to the maximum x and y angles.
        Curved = 2,
    }
);

options!(
    /// Table 1, variables 8 and 16: a constant or a random number within the range.
    Amount {
        /// The average of the range.
        Constant = 0,
        /// Drawn within the range from the plant's seed.
        Random = 1,
    }
);

options!(
    /// Table 1, variable 11: how thickness runs along a branch.
    Thickness {
        /// The average of each range on every cone.
        Constant = 0,
        /// From the maxima at the first cone to the minima at the last.
        Thinner = 1,
        /// From the minima at the first cone to the maxima at the last.
        Thicker = 2,
        /// Drawn within the ranges for every cone.
        Random = 3,
    }
);

options!(
    /// Table 2, variables 3, 6, 9 and 12: how a property runs across the branches of a fan.
    Progression {
        /// The same for every branch.
        Constant = 0,
        /// From the minimum at the first branch to the maximum at the last.
        Increasing = 1,
        /// From the maximum at the first branch to the minimum at the last.
        Decreasing = 2,
        /// Up and down in half-range steps: min, mid, max, mid, min, …
        Alternating = 3,
        /// Drawn within the range for every branch.
        Random = 4,
    }
);

/// A colour, 8-bit sRGB; `"#rrggbb"` in files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Rgb(pub [u8; 3]);

impl Rgb {
    /// The 24-bit code `0xrrggbb`.
    pub fn code(self) -> u32 {
        let [r, g, b] = self.0;
        (u32::from(r) << 16) | (u32::from(g) << 8) | u32::from(b)
    }

    /// The colour of a 24-bit code (higher bits are ignored).
    pub fn from_code(code: u32) -> Rgb {
        Rgb([(code >> 16) as u8, (code >> 8) as u8, code as u8])
    }

    /// Parses `#rrggbb`.
    pub fn parse(text: &str) -> Option<Rgb> {
        let hex = text.strip_prefix('#')?;
        if hex.len() != 6 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
            return None;
        }
        u32::from_str_radix(hex, 16).ok().map(Rgb::from_code)
    }
}

impl fmt::Display for Rgb {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{:06x}", self.code())
    }
}

impl Serialize for Rgb {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Rgb {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = <std::borrow::Cow<'de, str>>::deserialize(d)?;
        Rgb::parse(&text).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "a colour must be written \"#rrggbb\" (six hexadecimal digits), got {text:?}"
            ))
        })
    }
}

/// A factor in tenths (Table 2: code 1 is 0.1, code 30 is 3.0); a decimal in files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Tenths(pub u8);

impl Tenths {
    /// The factor.
    pub fn value(self) -> f32 {
        f32::from(self.0) / 10.0
    }
}

impl Serialize for Tenths {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(f64::from(self.0) / 10.0)
    }
}

/// A multiple of 0.1, read with its range in tenths (`ranged!(f: Tenths, "f", 1, 30)` is 0.1
/// to 3.0).
impl sylva_core::ranged::Ranged for Tenths {
    type Bound = u8;
    fn read<'de, D: serde::Deserializer<'de>>(
        d: D,
        field: &str,
        min: u8,
        max: u8,
        _unit: &str,
    ) -> Result<Tenths, D::Error> {
        let v = f64::deserialize(d)?;
        let code = (v * 10.0).round();
        if v.is_finite()
            && (v * 10.0 - code).abs() < 1e-6
            && (f64::from(min)..=f64::from(max)).contains(&code)
        {
            Ok(Tenths(code as u8))
        } else {
            Err(serde::de::Error::custom(format!(
                "`{field}` must be a multiple of 0.1 from {} to {}, got {v}",
                f64::from(min) / 10.0,
                f64::from(max) / 10.0
            )))
        }
    }
}

/// A set of fans by number, 1 to m (bit `i` is fan `i + 1`); a sorted list in JSON.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct FanSet(pub u32);

impl FanSet {
    /// The set of the given fan numbers (1-based; numbers above 32 are ignored).
    pub fn of(fans: &[usize]) -> FanSet {
        FanSet(
            fans.iter()
                .filter(|&&f| (1..=MAX_FANS).contains(&f))
                .fold(0, |m, &f| m | 1 << (f - 1)),
        )
    }

    /// Whether fan `number` (1-based) is in the set.
    pub fn contains(self, number: usize) -> bool {
        (1..=MAX_FANS).contains(&number) && self.0 & (1 << (number - 1)) != 0
    }

    /// The fan numbers, ascending.
    pub fn numbers(self) -> impl Iterator<Item = usize> {
        (1..=MAX_FANS).filter(move |&f| self.contains(f))
    }

    /// The paper's digits for `m` fans: the first fan leftmost, `1` when included.
    pub fn digits(self, m: usize) -> String {
        (1..=m)
            .map(|f| if self.contains(f) { '1' } else { '0' })
            .collect()
    }
}

impl Serialize for FanSet {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.numbers())
    }
}

impl<'de> Deserialize<'de> for FanSet {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = FanSet;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "a list of distinct fan numbers from 1 to {MAX_FANS}")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<FanSet, A::Error> {
                use serde::de::Error;
                let mut set = 0u32;
                while let Some(f) = seq.next_element::<i64>()? {
                    if !(1..=MAX_FANS as i64).contains(&f) {
                        return Err(A::Error::custom(format!(
                            "`fans` lists fan numbers from 1 to {MAX_FANS}, got {f}"
                        )));
                    }
                    let bit = 1u32 << (f - 1);
                    if set & bit != 0 {
                        return Err(A::Error::custom(format!("`fans` lists fan {f} twice")));
                    }
                    set |= bit;
                }
                Ok(FanSet(set))
            }
        }
        d.deserialize_seq(Visitor)
    }
}

sylva_core::ranged!(min_x_angle: u16, "min_x_angle", 0, 360);
sylva_core::ranged!(max_x_angle: u16, "max_x_angle", 0, 360);
sylva_core::ranged!(min_y_angle: u16, "min_y_angle", 0, 360);
sylva_core::ranged!(max_y_angle: u16, "max_y_angle", 0, 360);
sylva_core::ranged!(waves: u8, "waves", 1, 16);
sylva_core::ranged!(min_segments: u8, "min_segments", 1, 128);
sylva_core::ranged!(max_segments: u8, "max_segments", 1, 128);
sylva_core::ranged!(min_base_thickness: u8, "min_base_thickness", 1, 250);
sylva_core::ranged!(max_base_thickness: u8, "max_base_thickness", 1, 250);
sylva_core::ranged!(min_apex_thickness: u8, "min_apex_thickness", 1, 250);
sylva_core::ranged!(max_apex_thickness: u8, "max_apex_thickness", 1, 250);
sylva_core::ranged!(min_length: u8, "min_length", 1, 30);
sylva_core::ranged!(max_length: u8, "max_length", 1, 30);
sylva_core::ranged!(min_noise_x_angle: u16, "min_noise_x_angle", 0, 360);
sylva_core::ranged!(max_noise_x_angle: u16, "max_noise_x_angle", 0, 360);
sylva_core::ranged!(min_noise_y_angle: u16, "min_noise_y_angle", 0, 360);
sylva_core::ranged!(max_noise_y_angle: u16, "max_noise_y_angle", 0, 360);
sylva_core::ranged!(fan_branch: u8, "branch", 1, MAX_BRANCHES as u8);
sylva_core::ranged!(fan_count: u8, "count", 1, 72);
sylva_core::ranged!(min_angle: u16, "min_angle", 0, 360);
sylva_core::ranged!(max_angle: u16, "max_angle", 0, 360);
sylva_core::ranged!(texture: u8, "texture", 0, 127);
sylva_core::ranged!(start_angle: u16, "start_angle", 0, 360);
sylva_core::ranged!(position: u8, "position", 0, 100);

sylva_core::ranged!(min_length_factor: Tenths, "min_length_factor", 1, 30);
sylva_core::ranged!(max_length_factor: Tenths, "max_length_factor", 1, 30);
sylva_core::ranged!(min_thickness_factor: Tenths, "min_thickness_factor", 1, 50);
sylva_core::ranged!(max_thickness_factor: Tenths, "max_thickness_factor", 1, 50);

/// A branch prototype (Table 1): a chain of connected cones. Lengths are in centimetres
/// per cone, thicknesses in millimetres of diameter, angles in degrees.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Branch {
    /// 1: the outline of each cone.
    pub segment_pattern: SegmentPattern,
    /// 2: straight, curled or curved.
    pub branch_shape: BranchShape,
    /// 3: bend about the branch's x axis (towards its up side) at the start of each wave.
    #[serde(deserialize_with = "min_x_angle")]
    pub min_x_angle: u16,
    /// 4: x bend at the end of each wave.
    #[serde(deserialize_with = "max_x_angle")]
    pub max_x_angle: u16,
    /// 5: bend about the branch's up axis (sideways) at the start of each wave.
    #[serde(deserialize_with = "min_y_angle")]
    pub min_y_angle: u16,
    /// 6: y bend at the end of each wave.
    #[serde(deserialize_with = "max_y_angle")]
    pub max_y_angle: u16,
    /// 7: number of waves (curved) or curls (curled), 1–16.
    #[serde(deserialize_with = "waves")]
    pub waves: u8,
    /// 8: constant (the average of 9 and 10) or random number of cones.
    pub segment_count: Amount,
    /// 9: fewest cones, 1–128.
    #[serde(deserialize_with = "min_segments")]
    pub min_segments: u8,
    /// 10: most cones, 1–128.
    #[serde(deserialize_with = "max_segments")]
    pub max_segments: u8,
    /// 11: how thickness runs along the branch.
    pub thickness: Thickness,
    /// 12: smallest base thickness of a cone, mm, 1–250.
    #[serde(deserialize_with = "min_base_thickness")]
    pub min_base_thickness: u8,
    /// 13: largest base thickness, mm.
    #[serde(deserialize_with = "max_base_thickness")]
    pub max_base_thickness: u8,
    /// 14: smallest apex thickness, mm.
    #[serde(deserialize_with = "min_apex_thickness")]
    pub min_apex_thickness: u8,
    /// 15: largest apex thickness, mm.
    #[serde(deserialize_with = "max_apex_thickness")]
    pub max_apex_thickness: u8,
    /// 16: constant (the average of 17 and 18) or random length of each cone.
    pub length: Amount,
    /// 17: shortest cone, cm, 1–30.
    #[serde(deserialize_with = "min_length")]
    pub min_length: u8,
    /// 18: longest cone, cm, 1–30.
    #[serde(deserialize_with = "max_length")]
    pub max_length: u8,
    /// 19: whether noise is added to the angles between cones.
    pub noise: bool,
    /// 20: smallest x-angle noise.
    #[serde(deserialize_with = "min_noise_x_angle")]
    pub min_noise_x_angle: u16,
    /// 21: largest x-angle noise.
    #[serde(deserialize_with = "max_noise_x_angle")]
    pub max_noise_x_angle: u16,
    /// 22: smallest y-angle noise.
    #[serde(deserialize_with = "min_noise_y_angle")]
    pub min_noise_y_angle: u16,
    /// 23: largest y-angle noise.
    #[serde(deserialize_with = "max_noise_y_angle")]
    pub max_noise_y_angle: u16,
}

/// A fan (Table 2): copies of one branch prototype around a point on the stem.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fan {
    /// 1: which branch prototype, 1 to n.
    #[serde(deserialize_with = "fan_branch")]
    pub branch: u8,
    /// 2: how many branches, 1–72.
    #[serde(deserialize_with = "fan_count")]
    pub count: u8,
    /// 3: how the length factor runs across the fan (constant uses the maximum).
    pub length_mode: Progression,
    /// 4: smallest length factor, 0.1–3.0.
    #[serde(deserialize_with = "min_length_factor")]
    pub min_length_factor: Tenths,
    /// 5: largest length factor, 0.1–3.0.
    #[serde(deserialize_with = "max_length_factor")]
    pub max_length_factor: Tenths,
    /// 6: how the upward slant runs across the fan (constant uses the minimum).
    pub angle_mode: Progression,
    /// 7: smallest slant above the plane across the stem, degrees (above 180 slants down).
    #[serde(deserialize_with = "min_angle")]
    pub min_angle: u16,
    /// 8: largest slant, degrees.
    #[serde(deserialize_with = "max_angle")]
    pub max_angle: u16,
    /// 9: how the thickness factor runs across the fan (constant uses the maximum).
    pub thickness_mode: Progression,
    /// 10: smallest thickness factor, 0.1–5.0.
    #[serde(deserialize_with = "min_thickness_factor")]
    pub min_thickness_factor: Tenths,
    /// 11: largest thickness factor, 0.1–5.0.
    #[serde(deserialize_with = "max_thickness_factor")]
    pub max_thickness_factor: Tenths,
    /// 12: how colour runs across the fan (constant uses the minimum colour).
    pub color_mode: Progression,
    /// 13: first colour.
    pub min_color: Rgb,
    /// 14: last colour.
    pub max_color: Rgb,
    /// 15: texture, 0 = none; 1–127 is Sylva texture id 0–126 (see `develop`).
    #[serde(deserialize_with = "texture")]
    pub texture: u8,
}

/// An inflorescence (Table 3): fans placed together at one point of the stem.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Inflorescence {
    /// 1: angle around the stem where the first fan starts, degrees.
    #[serde(deserialize_with = "start_angle")]
    pub start_angle: u16,
    /// 2: whether it is drawn (the packed code is 0 for yes, as in the table).
    pub expressed: bool,
    /// 3: where on the stem, 0 (bottom) to 100 (top) per cent of its length.
    #[serde(deserialize_with = "position")]
    pub position: u8,
    /// 4: which fans it places, by number.
    pub fans: FanSet,
}

/// The genome field by field: the seed, then every variable of Tables 1 to 3 for each item
/// of its list, in table order, with the values files write (options by name, factors as
/// decimals, colours as `#rrggbb`).
pub fn schema() -> Schema {
    let mut fields = vec![FieldSpec::new(
        "seed",
        "plant",
        Kind::Seed,
        "The random draws within every range: another seed grows another plant of the same kind.",
    )];
    let tables: [(&str, &str, &[Variable]); 3] = [
        ("branches", "branch", &BRANCH_VARIABLES),
        ("fans", "fan", &FAN_VARIABLES),
        ("inflorescences", "inflorescence", &INFLORESCENCE_VARIABLES),
    ];
    for (list, group, table) in tables {
        for v in table {
            let (kind, unit, meaning) = describe(v);
            let field =
                FieldSpec::new(format!("{list}[].{}", v.name), group, kind, meaning).unit(unit);
            let shaping = [
                "branch_shape",
                "waves",
                "min_length",
                "max_length",
                "count",
                "min_angle",
                "max_angle",
                "position",
            ];
            fields.push(if shaping.contains(&v.name) {
                field.shaping()
            } else {
                field
            });
        }
    }
    let list = |path, meaning, max| ListSpec {
        path,
        meaning,
        min: 1,
        max,
    };
    Schema {
        fields,
        lists: vec![
            list(
                "branches",
                "A branch prototype (Table 1): a chain of cones.",
                MAX_BRANCHES,
            ),
            list(
                "fans",
                "A fan (Table 2): copies of one branch prototype around a point of the stem.",
                MAX_FANS,
            ),
            list(
                "inflorescences",
                "An inflorescence (Table 3): fans placed together at one point of the stem.",
                MAX_INFLORESCENCES,
            ),
        ],
        structures: Vec::new(),
    }
}

/// A variable's kind, unit and meaning as a panel shows it.
fn describe(v: &Variable) -> (Kind, &'static str, &'static str) {
    let whole = |min: u32, max: u32| Kind::integer(i64::from(min), i64::from(max));
    let tenths = |max| Kind::Number {
        min: 0.1,
        max,
        soft_min: 0.1,
        soft_max: max,
        step: 0.1,
        log: false,
    };
    let (kind, unit) = match (v.kind, v.name) {
        (Choice, "segment_pattern") => (Kind::choice_of(SegmentPattern::ALL), ""),
        (Choice, "branch_shape") => (Kind::choice_of(BranchShape::ALL), ""),
        (Choice, "segment_count" | "length") => (Kind::choice_of(Amount::ALL), ""),
        (Choice, "thickness") => (Kind::choice_of(Thickness::ALL), ""),
        (Choice, "noise" | "expressed") => (Kind::Flag, ""),
        (Choice, _) => (Kind::choice_of(Progression::ALL), ""),
        (Angle, _) => (whole(v.min, v.max), "°"),
        (Color, _) => (Kind::Colour, ""),
        (GeneKind::Branch, _) => (
            Kind::Item {
                list: "branches",
                max: MAX_BRANCHES as i64,
            },
            "",
        ),
        (GeneKind::FanSet, _) => (
            Kind::Items {
                list: "fans",
                max: MAX_FANS as i64,
            },
            "",
        ),
        (Integer, "min_length_factor" | "max_length_factor") => (tenths(3.0), ""),
        (Integer, "min_thickness_factor" | "max_thickness_factor") => (tenths(5.0), ""),
        (Integer, name) if name.ends_with("thickness") => (whole(v.min, v.max), " mm"),
        (Integer, "min_length" | "max_length") => (whole(v.min, v.max), " cm"),
        (Integer, "position") => (whole(v.min, v.max), " %"),
        (Integer, _) => (whole(v.min, v.max), ""),
    };
    (kind, unit, meaning(v.name))
}

/// What each variable of Tables 1 to 3 does, in a sentence.
fn meaning(name: &str) -> &'static str {
    match name {
        "segment_pattern" => "The outline of each cone of the branch.",
        "branch_shape" => "Straight, curled or curved.",
        "min_x_angle" => {
            "Bend about the branch's x axis (towards its up side) at the start of each wave."
        }
        "max_x_angle" => "Bend about the branch's x axis at the end of each wave.",
        "min_y_angle" => "Bend about the branch's up axis (sideways) at the start of each wave.",
        "max_y_angle" => "Sideways bend at the end of each wave.",
        "waves" => "Waves (curved) or curls (curled) along the branch.",
        "segment_count" => {
            "A constant number of cones (the mean of the two bounds) or a random one."
        }
        "min_segments" => "Fewest cones.",
        "max_segments" => "Most cones.",
        "thickness" => "How thickness runs along the branch.",
        "min_base_thickness" => "Smallest diameter at the base of a cone.",
        "max_base_thickness" => "Largest diameter at the base of a cone.",
        "min_apex_thickness" => "Smallest diameter at the apex of a cone.",
        "max_apex_thickness" => "Largest diameter at the apex of a cone.",
        "length" => "A constant length of each cone (the mean of the two bounds) or a random one.",
        "min_length" => "Shortest cone.",
        "max_length" => "Longest cone.",
        "noise" => "Whether noise is added to the angles between cones.",
        "min_noise_x_angle" => "Smallest noise on the x angle.",
        "max_noise_x_angle" => "Largest noise on the x angle.",
        "min_noise_y_angle" => "Smallest noise on the y angle.",
        "max_noise_y_angle" => "Largest noise on the y angle.",
        "branch" => "Which branch prototype the fan copies, by number.",
        "count" => "How many branches the fan holds.",
        "length_mode" => "How the length factor runs across the fan (constant uses the largest).",
        "min_length_factor" => "Smallest length factor across the fan.",
        "max_length_factor" => "Largest length factor across the fan.",
        "angle_mode" => "How the upward slant runs across the fan (constant uses the smallest).",
        "min_angle" => "Smallest slant above the plane across the stem (above 180° slants down).",
        "max_angle" => "Largest slant above the plane across the stem.",
        "thickness_mode" => {
            "How the thickness factor runs across the fan (constant uses the largest)."
        }
        "min_thickness_factor" => "Smallest thickness factor across the fan.",
        "max_thickness_factor" => "Largest thickness factor across the fan.",
        "color_mode" => "How colour runs across the fan (constant uses the first colour).",
        "min_color" => "The fan's first colour.",
        "max_color" => "The fan's last colour.",
        "texture" => "Texture: 0 none, 1 to 127 one of Sylva's textures.",
        "start_angle" => "The angle around the stem where the first fan starts.",
        "expressed" => "Whether the inflorescence is drawn.",
        "position" => "Where on the stem, from its foot (0) to its top (100).",
        "fans" => "Which fans it places, by number.",
        _ => "",
    }
}

/// Checks each code against its table row.
fn check(codes: &[u32], table: &[Variable], branches: usize, fans: usize) -> Result<(), CodeError> {
    for (index, (&value, v)) in codes.iter().zip(table).enumerate() {
        let (min, max) = v.range(branches, fans);
        if !(min..=max).contains(&value) {
            return Err(CodeError {
                index,
                value,
                min,
                max,
            });
        }
    }
    Ok(())
}

/// An option by code, after [`check`] has passed.
fn option<T>(code: u32, from: fn(u32) -> Option<T>, fallback: T) -> T {
    from(code).unwrap_or(fallback)
}

impl Branch {
    /// The 23 codes in table order.
    pub fn codes(&self) -> [u32; 23] {
        [
            self.segment_pattern.code(),
            self.branch_shape.code(),
            self.min_x_angle.into(),
            self.max_x_angle.into(),
            self.min_y_angle.into(),
            self.max_y_angle.into(),
            self.waves.into(),
            self.segment_count.code(),
            self.min_segments.into(),
            self.max_segments.into(),
            self.thickness.code(),
            self.min_base_thickness.into(),
            self.max_base_thickness.into(),
            self.min_apex_thickness.into(),
            self.max_apex_thickness.into(),
            self.length.code(),
            self.min_length.into(),
            self.max_length.into(),
            u32::from(self.noise),
            self.min_noise_x_angle.into(),
            self.max_noise_x_angle.into(),
            self.min_noise_y_angle.into(),
            self.max_noise_y_angle.into(),
        ]
    }

    /// The branch of 23 codes, refusing any outside [`BRANCH_VARIABLES`].
    pub fn from_codes(c: &[u32; 23]) -> Result<Branch, CodeError> {
        check(c, &BRANCH_VARIABLES, 1, 0)?;
        Ok(Branch {
            segment_pattern: option(c[0], SegmentPattern::from_code, SegmentPattern::Straight),
            branch_shape: option(c[1], BranchShape::from_code, BranchShape::Straight),
            min_x_angle: c[2] as u16,
            max_x_angle: c[3] as u16,
            min_y_angle: c[4] as u16,
            max_y_angle: c[5] as u16,
            waves: c[6] as u8,
            segment_count: option(c[7], Amount::from_code, Amount::Constant),
            min_segments: c[8] as u8,
            max_segments: c[9] as u8,
            thickness: option(c[10], Thickness::from_code, Thickness::Constant),
            min_base_thickness: c[11] as u8,
            max_base_thickness: c[12] as u8,
            min_apex_thickness: c[13] as u8,
            max_apex_thickness: c[14] as u8,
            length: option(c[15], Amount::from_code, Amount::Constant),
            min_length: c[16] as u8,
            max_length: c[17] as u8,
            noise: c[18] == 1,
            min_noise_x_angle: c[19] as u16,
            max_noise_x_angle: c[20] as u16,
            min_noise_y_angle: c[21] as u16,
            max_noise_y_angle: c[22] as u16,
        })
    }
}

impl Fan {
    /// The 15 codes in table order.
    pub fn codes(&self) -> [u32; 15] {
        [
            self.branch.into(),
            self.count.into(),
            self.length_mode.code(),
            self.min_length_factor.0.into(),
            self.max_length_factor.0.into(),
            self.angle_mode.code(),
            self.min_angle.into(),
            self.max_angle.into(),
            self.thickness_mode.code(),
            self.min_thickness_factor.0.into(),
            self.max_thickness_factor.0.into(),
            self.color_mode.code(),
            self.min_color.code(),
            self.max_color.code(),
            self.texture.into(),
        ]
    }

    /// The fan of 15 codes in a genome of `branches` prototypes, refusing any outside
    /// [`FAN_VARIABLES`].
    pub fn from_codes(c: &[u32; 15], branches: usize) -> Result<Fan, CodeError> {
        check(c, &FAN_VARIABLES, branches, 0)?;
        let progression = |code| option(code, Progression::from_code, Progression::Constant);
        Ok(Fan {
            branch: c[0] as u8,
            count: c[1] as u8,
            length_mode: progression(c[2]),
            min_length_factor: Tenths(c[3] as u8),
            max_length_factor: Tenths(c[4] as u8),
            angle_mode: progression(c[5]),
            min_angle: c[6] as u16,
            max_angle: c[7] as u16,
            thickness_mode: progression(c[8]),
            min_thickness_factor: Tenths(c[9] as u8),
            max_thickness_factor: Tenths(c[10] as u8),
            color_mode: progression(c[11]),
            min_color: Rgb::from_code(c[12]),
            max_color: Rgb::from_code(c[13]),
            texture: c[14] as u8,
        })
    }
}

impl Inflorescence {
    /// The 4 codes in table order (variable 2 is 0 when expressed, as in the table).
    pub fn codes(&self) -> [u32; 4] {
        [
            self.start_angle.into(),
            u32::from(!self.expressed),
            self.position.into(),
            self.fans.0,
        ]
    }

    /// The inflorescence of 4 codes in a genome of `fans` fans, refusing any outside
    /// [`INFLORESCENCE_VARIABLES`].
    pub fn from_codes(c: &[u32; 4], fans: usize) -> Result<Inflorescence, CodeError> {
        check(c, &INFLORESCENCE_VARIABLES, 1, fans)?;
        Ok(Inflorescence {
            start_angle: c[0] as u16,
            expressed: c[1] == 0,
            position: c[2] as u8,
            fans: FanSet(c[3]),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_sizes() {
        let branch: u32 = BRANCH_VARIABLES.iter().map(|v| v.bits(5, 5)).sum();
        let fan: u32 = FAN_VARIABLES.iter().map(|v| v.bits(5, 5)).sum();
        let infl: u32 = INFLORESCENCE_VARIABLES.iter().map(|v| v.bits(5, 5)).sum();
        assert_eq!(branch, 143);
        // ceil(log2 5) = 3 bits for the branch number.
        assert_eq!(
            fan,
            3 + 7 + 3 + 5 + 5 + 3 + 9 + 9 + 3 + 6 + 6 + 3 + 24 + 24 + 7
        );
        assert_eq!(infl, 9 + 1 + 7 + 5);
        assert_eq!(FAN_VARIABLES[0].bits(1, 0), 0);
        assert_eq!(FAN_VARIABLES[0].bits(2, 0), 1);
        assert_eq!(FAN_VARIABLES[0].bits(32, 0), 5);
    }

    #[test]
    fn every_variable_fits_its_bits() {
        for v in BRANCH_VARIABLES
            .iter()
            .chain(&FAN_VARIABLES)
            .chain(&INFLORESCENCE_VARIABLES)
        {
            let (min, max) = v.range(5, 5);
            let values = u64::from(max - min) + 1;
            assert!(values <= 1 << v.bits(5, 5), "{}", v.name);
        }
    }

    #[test]
    fn colours_and_fan_sets() {
        assert_eq!(Rgb::parse("#a0C040"), Some(Rgb([0xa0, 0xc0, 0x40])));
        assert_eq!(Rgb([1, 2, 3]).to_string(), "#010203");
        assert_eq!(Rgb::parse("a0c040"), None);
        assert_eq!(Rgb::parse("#a0c04"), None);
        let s = FanSet::of(&[1, 3]);
        assert_eq!(s.digits(5), "10100");
        assert_eq!(s.numbers().collect::<Vec<_>>(), vec![1, 3]);
        assert_eq!(mask_of(5), 0b11111);
        assert_eq!(mask_of(32), u32::MAX);
    }
}
