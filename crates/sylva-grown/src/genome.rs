//! The genome: a crown's shape and proportions, the growth's parameters, and the foliage and
//! bark the tree wears.
//!
//! Every number lives in one table, [`PARAMS`]: its name in files, range, default, unit and
//! meaning. Files, range checks, random genomes, mutation, crossover and the vectors an
//! outside optimiser searches all read that table, so a parameter is added in one line.
//!
//! ```json
//! {
//!   "model": "grown",
//!   "format": 1,
//!   "seed": 1,
//!   "crown": "ellipsoid",
//!   "foliage": "oak",
//!   "parameters": { "height": 12.0, "crown_base": 0.3, "points": 2500 }
//! }
//! ```
//!
//! Parameters left out take their defaults; `bark` may name a bark kind other than the
//! foliage's own.

use std::fmt;

use rand::{Rng, RngExt};
use serde::de::{Error, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sylva_core::species::{BarkKind, LeafKind};
use sylva_model::schema::{FieldSpec, Kind, Schema};
use sylva_model::{FormatV1, model_tag};

use crate::profile::Profile;

/// Model name in genome files.
pub const MODEL: &str = "grown";

model_tag!(
    /// The `"model": "grown"` header field.
    GrownTag,
    MODEL
);

/// A family of crown shapes: the envelope the attraction points fill. Each is a solid of
/// revolution about the trunk (squashed by `depth`), described by its radius at each
/// height between the crown's base and its top ([`CrownShape::radius`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CrownShape {
    /// Round: most broadleaves grown in the open (oak, lime, maple).
    #[default]
    Ellipsoid,
    /// Widest at the base, pointed at the top (spruce, fir, young conifers).
    Cone,
    /// Widest a third of the way up, drawn to a point (birch, cypress, poplar).
    Flame,
    /// A flat-topped spread on a long bole (acacia, stone pine, old oaks).
    Umbrella,
    /// Straight sides with rounded ends (columnar poplar, hedgerow trees).
    Cylinder,
    /// Widest at the top (elm, zelkova: a vase).
    InvertedCone,
}

impl CrownShape {
    /// Every shape.
    pub const ALL: [CrownShape; 6] = [
        CrownShape::Ellipsoid,
        CrownShape::Cone,
        CrownShape::Flame,
        CrownShape::Umbrella,
        CrownShape::Cylinder,
        CrownShape::InvertedCone,
    ];

    /// The crown's radius at `t` (0 at the crown's base, 1 at its top) as a share of its
    /// widest radius.
    pub fn radius(self, t: f32) -> f32 {
        let t = t.clamp(0.0, 1.0);
        match self {
            CrownShape::Ellipsoid => (1.0 - (2.0 * t - 1.0).powi(2)).max(0.0).sqrt(),
            // A little round at the foot, so the lowest branches have room to grow out.
            CrownShape::Cone => (1.0 - t) * (t * 8.0).min(1.0).sqrt(),
            CrownShape::Flame => (std::f32::consts::PI * t.powf(0.6)).sin().max(0.0),
            CrownShape::Umbrella => (1.0 - (1.0 - t).powi(2)).sqrt() * (1.0 - t.powi(6)).sqrt(),
            CrownShape::Cylinder => (1.0 - (2.0 * t - 1.0).powi(8)).max(0.0).sqrt(),
            CrownShape::InvertedCone => t.sqrt() * (1.0 - t.powi(6)).sqrt(),
        }
    }
}

/// Where a parameter belongs, for panels and docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Group {
    /// The crown's size and proportions.
    Crown,
    /// How buds grow and branch.
    Growth,
    /// Stems and leaves.
    Form,
}

/// One parameter of the genome: how files name it, its range and default, and what it
/// means.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamSpec {
    /// Its name in files.
    pub name: &'static str,
    /// The least value.
    pub min: f64,
    /// The greatest value.
    pub max: f64,
    /// Its default.
    pub default: f64,
    /// Whole numbers only.
    pub whole: bool,
    /// Its unit, as written after a number (`" m"`, `"°"`), or `""`.
    pub unit: &'static str,
    /// What it does, in a sentence.
    pub meaning: &'static str,
    /// Its group.
    pub group: Group,
}

macro_rules! params {
    ($($(#[$doc:meta])* $variant:ident = $name:literal, $group:ident, $min:expr, $max:expr,
       $default:expr, $whole:expr, $unit:literal, $meaning:literal;)*) => {
        /// A parameter's place in [`PARAMS`] and in a genome's values.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Param { $($(#[$doc])* $variant),* }

        /// Every parameter, in the order of [`Param`].
        pub const PARAMS: [ParamSpec; [$(Param::$variant),*].len()] = [$(ParamSpec {
            name: $name,
            min: $min,
            max: $max,
            default: $default,
            whole: $whole,
            unit: $unit,
            meaning: $meaning,
            group: Group::$group,
        }),*];
    };
}

params! {
    /// Tree height, metres.
    Height = "height", Crown, 1.0, 40.0, 12.0, false, " m",
        "The tree's height: the top of the crown above the ground.";
    /// Height of the crown's base over the tree's height.
    CrownBase = "crown_base", Crown, 0.05, 0.9, 0.3, false, "",
        "Where the crown begins, as a share of the height: the clear bole below it.";
    /// The crown's widest diameter over the tree's height.
    Width = "width", Crown, 0.1, 1.5, 0.7, false, "",
        "The crown's widest diameter, as a share of the height.";
    /// The crown's depth (front to back) over its width.
    Depth = "depth", Crown, 0.5, 1.5, 1.0, false, "",
        "The crown's depth front to back over its width: 1 is round seen from above.";
    /// Attraction points.
    Points = "points", Growth, 100.0, 20000.0, 2500.0, true, "",
        "Attraction points filling the crown: free space buds grow into. More, denser twigs.";
    /// Internode length over the tree's height.
    Internode = "internode", Growth, 0.005, 0.06, 0.02, false, "",
        "One internode's length, as a share of the height: the step a shoot grows by.";
    /// Perception radius, internodes.
    Reach = "reach", Growth, 2.0, 20.0, 8.0, false, " internodes",
        "How far a bud perceives free space (the attraction points' influence).";
    /// Half-angle of a bud's perception cone, degrees.
    PerceptionAngle = "perception_angle", Growth, 20.0, 180.0, 90.0, false, "°",
        "How wide a bud looks about its heading: points outside the cone are not its own.";
    /// Kill distance, internodes.
    Kill = "kill", Growth, 0.5, 6.0, 2.0, false, " internodes",
        "Points this near a new internode are taken: space is used up as the crown fills.";
    /// Apical control (λ of the extended Borchert–Honda model).
    ApicalControl = "apical_control", Growth, 0.3, 0.8, 0.52, false, "",
        "How much of the resource goes on along an axis rather than into its side branch.";
    /// Vigour (α): resource per unit of light and space.
    Vigour = "vigour", Growth, 0.5, 4.0, 2.0, false, "",
        "Resource the whole tree draws per unit of light and space its buds receive.";
    /// Most internodes a bud makes in one cycle.
    MaxShoot = "max_shoot", Growth, 1.0, 8.0, 3.0, true, " internodes",
        "The most internodes a shoot grows in one cycle.";
    /// Weight of a shoot's own heading.
    Straightness = "straightness", Growth, 0.0, 4.0, 1.0, false, "",
        "How strongly a shoot keeps its heading against the pull of free space.";
    /// Gravitropism: up (positive) or down (negative).
    Gravitropism = "gravitropism", Growth, -1.0, 1.0, 0.15, false, "",
        "Up (positive) or down (negative) pull on every shoot: negative for weeping trees.";
    /// Phototropism: the pull towards light.
    Phototropism = "phototropism", Growth, 0.0, 2.0, 0.3, false, "",
        "Pull towards where the crown's shade is least.";
    /// Branch angle, degrees.
    BranchAngle = "branch_angle", Growth, 10.0, 90.0, 45.0, false, "°",
        "The angle a side bud makes with its shoot.";
    /// Phyllotaxis: divergence between successive side buds, degrees.
    Phyllotaxis = "phyllotaxis", Growth, 60.0, 180.0, 137.5, false, "°",
        "The turn about a shoot from one side bud to the next (137.5° spirals, 180° two ranks).";
    /// Shedding threshold.
    Shedding = "shedding", Growth, 0.0, 0.9, 0.2, false, "",
        "Side branches whose shoot tips get less light than this (1 is open sky) are shed.";
    /// Growth cycles.
    Cycles = "cycles", Growth, 1.0, 60.0, 24.0, true, "",
        "Growth cycles (years); growth also ends when the crown's space is used up.";
    /// Pipe-model exponent.
    PipeExponent = "pipe_exponent", Form, 1.8, 3.5, 2.5, false, "",
        "A stem's radius to this power is the sum of its branches' (the pipe model).";
    /// Radius of a twig's tip, metres.
    TipRadius = "tip_radius", Form, 0.001, 0.02, 0.004, false, " m",
        "The radius of every twig at its tip.";
    /// Internodes from a tip that bear leaves.
    LeafSpan = "leaf_span", Form, 0.0, 12.0, 3.0, true, " internodes",
        "How far back from each tip a shoot keeps its leaves.";
    /// How far inside the envelope attraction points stay, over the tree's height.
    Inset = "inset", Crown, 0.0, 0.1, 0.0, false, "",
        "How far inside its envelope the crown's space stays, as a share of the height: \
         room for the leaves the outermost twigs bear.";
}

impl Group {
    /// Its name in panels and files.
    pub fn name(self) -> &'static str {
        match self {
            Group::Crown => "crown",
            Group::Growth => "growth",
            Group::Form => "form",
        }
    }
}

/// The parameters that move a tree's shape most, first in panels.
const SHAPING: [&str; 7] = [
    "height",
    "crown_base",
    "width",
    "apical_control",
    "branch_angle",
    "gravitropism",
    "points",
];

/// The genome field by field: the crown's shape, the leaves and bark it wears, then every
/// parameter of [`PARAMS`] (a match's `envelope`, drawn from pictures, is not set by hand).
pub fn schema() -> Schema {
    let mut fields = vec![
        FieldSpec::new(
            "crown",
            "crown",
            Kind::choice_of(&CrownShape::ALL),
            "The crown's shape: the envelope the attraction points fill.",
        )
        .shaping(),
        FieldSpec::new(
            "seed",
            "crown",
            Kind::Seed,
            "Places the attraction points: another seed grows another tree of the same kind.",
        ),
        FieldSpec::new(
            "foliage",
            "form",
            Kind::choice_of(&LeafKind::ALL),
            "The leaves or needles it bears, at their real size, and its bark unless `bark` says otherwise.",
        ),
        FieldSpec::new(
            "bark",
            "form",
            Kind::choice_of(&BarkKind::ALL),
            "A bark other than the foliage's own (left out: the foliage's species' bark).",
        )
        .optional(),
    ];
    fields.extend(PARAMS.iter().map(|p| {
        let kind = if p.whole {
            Kind::integer(p.min as i64, p.max as i64)
        } else {
            Kind::number(p.min, p.max)
        };
        let field = FieldSpec::new(
            format!("parameters.{}", p.name),
            p.group.name(),
            kind,
            p.meaning,
        )
        .unit(p.unit)
        .optional();
        if SHAPING.contains(&p.name) {
            field.shaping()
        } else {
            field
        }
    }));
    Schema::of(fields)
}

impl Param {
    /// Its spec in [`PARAMS`].
    pub fn spec(self) -> &'static ParamSpec {
        &PARAMS[self as usize]
    }
}

/// The values of every parameter, each within its range (whole where whole).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params([f64; PARAMS.len()]);

impl Default for Params {
    fn default() -> Self {
        Params(PARAMS.map(|p| p.default))
    }
}

impl Params {
    /// The value of `p`.
    pub fn get(&self, p: Param) -> f64 {
        self.0[p as usize]
    }

    /// The value of `p` as an `f32`.
    pub fn f(&self, p: Param) -> f32 {
        self.0[p as usize] as f32
    }

    /// The value of a whole-number parameter.
    pub fn count(&self, p: Param) -> u32 {
        self.0[p as usize] as u32
    }

    /// Sets `p`, clamped to its range and rounded where whole; a NaN keeps the old value.
    pub fn set(&mut self, p: Param, value: f64) {
        self.set_at(p as usize, value);
    }

    /// Every value, in the order of [`PARAMS`].
    pub fn values(&self) -> &[f64; PARAMS.len()] {
        &self.0
    }

    /// Sets the `i`th value as [`Params::set`] does.
    pub fn set_at(&mut self, i: usize, value: f64) {
        let spec = &PARAMS[i];
        if value.is_nan() {
            return;
        }
        let v = value.clamp(spec.min, spec.max);
        self.0[i] = if spec.whole { v.round() } else { v };
    }
}

impl Serialize for Params {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(PARAMS.len()))?;
        for (spec, &v) in PARAMS.iter().zip(&self.0) {
            if spec.whole {
                map.serialize_entry(spec.name, &(v as u64))?;
            } else {
                map.serialize_entry(spec.name, &v)?;
            }
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for Params {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(ParamsVisitor)
    }
}

struct ParamsVisitor;

impl<'de> Visitor<'de> for ParamsVisitor {
    type Value = Params;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an object of growth parameters")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Params, A::Error> {
        let mut params = Params::default();
        let mut seen = [false; PARAMS.len()];
        while let Some(key) = map.next_key::<String>()? {
            let Some(i) = PARAMS.iter().position(|p| p.name == key) else {
                let names: Vec<_> = PARAMS.iter().map(|p| format!("`{}`", p.name)).collect();
                return Err(A::Error::custom(format!(
                    "unknown parameter `{key}`, expected one of {}",
                    names.join(", ")
                )));
            };
            if std::mem::replace(&mut seen[i], true) {
                return Err(A::Error::custom(format!(
                    "parameter `{key}` is given twice"
                )));
            }
            let spec = &PARAMS[i];
            let value: f64 = map
                .next_value()
                .map_err(|_: A::Error| range_error(spec, None))?;
            let whole_ok = !spec.whole || value.fract() == 0.0;
            if !(spec.min..=spec.max).contains(&value) || !whole_ok {
                return Err(range_error(spec, Some(value)));
            }
            params.0[i] = value;
        }
        Ok(params)
    }
}

/// "`reach` must be a number from 2 to 20 internodes, got 50".
fn range_error<E: Error>(spec: &ParamSpec, got: Option<f64>) -> E {
    let noun = if spec.whole { "whole number" } else { "number" };
    let got = got.map_or_else(|| "something else".to_owned(), |v| v.to_string());
    E::custom(format!(
        "`{}` must be a {noun} from {} to {}{}, got {got}",
        spec.name, spec.min, spec.max, spec.unit
    ))
}

/// A self-organising tree's genome: the crown it fills, how it grows there, and what it
/// wears.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Growth {
    /// Always `"grown"`.
    pub model: GrownTag,
    /// Always 1.
    pub format: FormatV1,
    /// Places the attraction points; the tree's default seed.
    pub seed: u64,
    /// The crown's shape.
    pub crown: CrownShape,
    /// The leaves or needles it bears (their real size) and, unless `bark` says otherwise,
    /// its bark.
    pub foliage: LeafKind,
    /// A bark other than the foliage's own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bark: Option<BarkKind>,
    /// The numbers ([`PARAMS`]); left out, a parameter takes its default.
    #[serde(default)]
    pub parameters: Params,
    /// A crown drawn from pictures (a match's), grown into instead of the crown shape.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub envelope: Option<Profile>,
}

impl Default for Growth {
    /// An oak-leaved tree of 12 m with a round crown, every parameter at its default.
    fn default() -> Self {
        Growth {
            model: GrownTag,
            format: FormatV1,
            seed: 1,
            crown: CrownShape::Ellipsoid,
            foliage: LeafKind::Oak,
            bark: None,
            parameters: Params::default(),
            envelope: None,
        }
    }
}

/// How genomes are varied: the share of parameters a mutation moves and how far.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variation {
    /// Probability that each parameter (and the crown shape) changes, 0 to 1.
    pub rate: f64,
    /// A change's spread as a share of the parameter's range, 0 to 1.
    pub spread: f64,
}

/// A standard normal deviate, near enough: the sum of four uniforms, rescaled.
fn gauss<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    let sum: f64 = (0..4).map(|_| rng.random::<f64>()).sum();
    (sum - 2.0) * 3.0f64.sqrt()
}

impl Growth {
    /// A random genome: every parameter but the height uniform over the middle of its
    /// range (from 40% of the way down to its least to 40% of the way up to its greatest
    /// from its default, where trees grow; the edges are for tuning), a random crown shape
    /// and seed, and the height and leaf of `like`.
    pub fn random<R: Rng + ?Sized>(like: &Growth, rng: &mut R) -> Growth {
        let mut g = like.clone();
        for (i, spec) in PARAMS.iter().enumerate() {
            if i != Param::Height as usize {
                let lo = spec.default - 0.4 * (spec.default - spec.min);
                let hi = spec.default + 0.4 * (spec.max - spec.default);
                g.parameters.set_at(i, rng.random_range(lo..=hi));
            }
        }
        g.crown = CrownShape::ALL[rng.random_range(0..CrownShape::ALL.len())];
        g.seed = rng.random();
        g
    }

    /// Moves each parameter with probability `rate` by a normal step of `spread` times its
    /// range, and picks another crown shape, and another foliage of its kind (broadleaf or
    /// needles, with its own bark), each with the same probability. The seed stays: a
    /// mutant grows into the same space.
    pub fn mutate<R: Rng + ?Sized>(&mut self, v: Variation, rng: &mut R) {
        let rate = sylva_core::rng::probability(v.rate);
        for (i, spec) in PARAMS.iter().enumerate() {
            if rng.random_bool(rate) {
                let step = gauss(rng) * v.spread * (spec.max - spec.min);
                // A whole number moves by at least one when it moves at all.
                let step = if spec.whole && step.abs() < 1.0 {
                    step.signum()
                } else {
                    step
                };
                self.parameters.set_at(i, self.parameters.0[i] + step);
            }
        }
        if rng.random_bool(rate) {
            self.crown = CrownShape::ALL[rng.random_range(0..CrownShape::ALL.len())];
        }
        // The species too, among its own kind: broadleaves for broadleaves, needles for
        // needles (an outline shows no species, and an aspen's picture would otherwise be
        // matched as well by a pine's needles).
        if rng.random_bool(rate) {
            let needles = self.foliage.spec().needles;
            let like = LeafKind::ALL.iter().filter(|k| k.spec().needles == needles);
            let pick = rng.random_range(0..like.clone().count());
            self.foliage = like.copied().nth(pick).unwrap_or(self.foliage);
            self.bark = None;
        }
    }

    /// A child taking each parameter from either parent, or, with probability `blend`,
    /// a point between them; the crown shape, foliage, bark and seed from either.
    pub fn cross<R: Rng + ?Sized>(a: &Growth, b: &Growth, blend: f64, rng: &mut R) -> Growth {
        let mut child = a.clone();
        let blend = sylva_core::rng::probability(blend);
        for i in 0..PARAMS.len() {
            let (x, y) = (a.parameters.0[i], b.parameters.0[i]);
            let v = if rng.random_bool(blend) {
                x + rng.random::<f64>() * (y - x)
            } else if rng.random_bool(0.5) {
                x
            } else {
                y
            };
            child.parameters.set_at(i, v);
        }
        if rng.random_bool(0.5) {
            child.crown = b.crown;
        }
        if rng.random_bool(0.5) {
            (child.foliage, child.bark) = (b.foliage, b.bark);
        }
        if rng.random_bool(0.5) {
            child.seed = b.seed;
        }
        child
    }
}

/// The parameters as a Markdown table (name, group, range, default, meaning), as
/// `docs/grown.md` shows them.
pub fn params_table() -> String {
    let mut table = String::from("| parameter | group | range | default | what it does |\n");
    table.push_str("| --- | --- | --- | --- | --- |\n");
    for p in &PARAMS {
        let group = match p.group {
            Group::Crown => "crown",
            Group::Growth => "growth",
            Group::Form => "form",
        };
        table.push_str(&format!(
            "| `{}` | {group} | {} to {}{} | {} | {} |\n",
            p.name, p.min, p.max, p.unit, p.default, p.meaning
        ));
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_default_is_in_its_range() {
        for p in PARAMS {
            assert!(
                p.min < p.max && (p.min..=p.max).contains(&p.default),
                "{p:?}"
            );
            assert!(!p.whole || p.default.fract() == 0.0, "{p:?}");
        }
    }

    #[test]
    fn files_round_trip_and_errors_name_the_parameter() {
        let g = Growth::default();
        let text = sylva_model::file::pretty(&g);
        assert_eq!(sylva_model::file::parse::<Growth>(&text).unwrap(), g);
        let bad = text.replace("\"reach\": 8.0", "\"reach\": 50.0");
        let e = sylva_model::file::parse::<Growth>(&bad).unwrap_err();
        assert!(
            e.message
                .contains("`reach` must be a number from 2 to 20 internodes, got 50"),
            "{e}"
        );
        assert!(e.line > 1, "{e:?}");
        let bad = text.replace("\"points\": 2500", "\"points\": 2500.5");
        let e = sylva_model::file::parse::<Growth>(&bad).unwrap_err();
        assert!(e.message.contains("`points` must be a whole number"), "{e}");
        let bad = text.replace("\"reach\"", "\"raech\"");
        let e = sylva_model::file::parse::<Growth>(&bad).unwrap_err();
        assert!(e.message.contains("unknown parameter `raech`"), "{e}");
        let bad = text.replace("\"ellipsoid\"", "\"blob\"");
        let e = sylva_model::file::parse::<Growth>(&bad).unwrap_err();
        assert!(e.message.contains("inverted_cone"), "{e}");
        let short = r#"{"model":"grown","format":1,"seed":3,"crown":"cone","foliage":"spruce"}"#;
        let g = sylva_model::file::parse::<Growth>(short).unwrap();
        assert_eq!(g.parameters, Params::default());
    }

    #[test]
    fn variation_stays_in_range() {
        let mut rng = sylva_core::rng::seeded(5);
        let mut g = Growth::default();
        for _ in 0..200 {
            g.mutate(
                Variation {
                    rate: 0.5,
                    spread: 0.5,
                },
                &mut rng,
            );
            let r = Growth::random(&g, &mut rng);
            g = Growth::cross(&g, &r, 0.5, &mut rng);
            for (spec, &v) in PARAMS.iter().zip(g.parameters.values()) {
                assert!((spec.min..=spec.max).contains(&v), "{spec:?} {v}");
                assert!(!spec.whole || v.fract() == 0.0);
            }
        }
    }

    #[test]
    fn mutation_changes_the_species_within_its_sort() {
        let mut rng = sylva_core::rng::seeded(6);
        let often = Variation {
            rate: 0.9,
            spread: 0.1,
        };
        for start in [LeafKind::Oak, LeafKind::Spruce] {
            let mut g = Growth {
                foliage: start,
                ..Growth::default()
            };
            let mut seen = std::collections::BTreeSet::new();
            for _ in 0..100 {
                g.mutate(often, &mut rng);
                assert_eq!(g.foliage.spec().needles, start.spec().needles, "{g:?}");
                seen.insert(g.foliage.name());
            }
            assert!(seen.len() >= 3, "{seen:?}");
        }
    }

    #[test]
    fn the_docs_show_every_parameter_as_the_table_says() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/grown.md");
        let doc = std::fs::read_to_string(path).unwrap_or_default();
        let start = "<!-- parameters: made by sylva_grown::genome::params_table -->\n";
        let table = doc
            .split_once(start)
            .and_then(|(_, rest)| rest.split_once("<!-- end -->"))
            .map(|(table, _)| table);
        assert_eq!(
            table,
            Some(params_table().as_str()),
            "docs/grown.md's table is stale"
        );
    }

    #[test]
    fn shapes_stay_within_their_radius() {
        for shape in CrownShape::ALL {
            for i in 0..=100 {
                let r = shape.radius(i as f32 / 100.0);
                assert!((0.0..=1.0).contains(&r), "{shape:?} {i} {r}");
            }
        }
    }
}
