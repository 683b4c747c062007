//! What an evolution config file holds: the model's name, `[run]`, the model's own
//! section and `[output]`, every number checked as it is read.

use std::marker::PhantomData;
use std::path::{Path, PathBuf};

use serde::de::{self, DeserializeSeed, MapAccess, Visitor};
use serde::ser::SerializeStruct;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sylva_core::dress::Dress;
use sylva_core::species::{BarkKind, LeafKind};
use sylva_core::taper::PipeTaper;
use sylva_mesh::wind::WindOptions;
use sylva_model::Evolve;
use sylva_render::View;

use sylva_fitness::descriptors::Descriptor;

use crate::error::InputError;
use crate::picture::Threshold;

/// Run size and seed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunConfig {
    /// Generations bred after the first, 0 to 1,000,000. Default 150.
    #[serde(deserialize_with = "generations")]
    pub generations: u32,
    /// Individuals per generation, 1 to 1,000,000. Default 400.
    #[serde(deserialize_with = "population")]
    pub population: u32,
    /// Seed of every random choice. Default 1.
    pub seed: u64,
    /// Worker threads, 0 (one per core) to 1024. Default 0. Results do not depend on it.
    #[serde(deserialize_with = "threads")]
    pub threads: u32,
    /// Seconds between checkpoints, 0 (every generation) to 3600. Default 2. A run also
    /// checkpoints when it ends.
    #[serde(deserialize_with = "checkpoint_seconds")]
    pub checkpoint_seconds: f64,
    /// How the run searches: `"model"`, the model's own generation step (the default), or
    /// `"map-elites"`, a map of the fittest plant of every kind (`[map]`;
    /// [docs/varieties.md]). A map breeds `[map] batch` offspring a generation;
    /// `population` is not used.
    #[serde(skip_serializing_if = "is_own")]
    pub strategy: SearchStrategy,
}

/// How a run searches (`[run] strategy`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum SearchStrategy {
    /// The model's own generation step.
    #[default]
    #[serde(rename = "model")]
    Model,
    /// MAP-Elites, over the `[map]` section's descriptors.
    #[serde(rename = "map-elites")]
    MapElites,
}

// The default stays out of written configs, so those keep their bytes.
fn is_own(s: &SearchStrategy) -> bool {
    *s == SearchStrategy::Model
}

impl Default for RunConfig {
    fn default() -> Self {
        RunConfig {
            generations: 150,
            population: 400,
            seed: 1,
            threads: 0,
            checkpoint_seconds: 2.0,
            strategy: SearchStrategy::Model,
        }
    }
}

sylva_core::ranged!(generations: u32, "generations", 0, 1_000_000);
sylva_core::ranged!(population: u32, "population", 1, 1_000_000);
sylva_core::ranged!(threads: u32, "threads", 0, 1024);
sylva_core::ranged!(checkpoint_seconds: f64, "checkpoint_seconds", 0.0, 3600.0, " s");

/// What a run writes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputConfig {
    /// Width and height of `best.png`, 64 to 4096 pixels. Default 800.
    #[serde(deserialize_with = "image_size")]
    pub image_size: u32,
    /// View of `best.png`. Default iso.
    #[serde(with = "view_name")]
    pub view: View,
    /// Individuals shown on the contact sheet (the best ones), 1 to 400. Default 48.
    #[serde(deserialize_with = "sheet_size")]
    pub sheet_size: u32,
    /// The pipe-model exponent `E`, 2 to 3, for the best plant and the sheet: radius ∝
    /// (tips above)^(1/E), as `sylva grow --taper E`. Default none: each model's own radii
    /// (evolution scores the plants as grown, without it).
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "taper")]
    pub taper: Option<f64>,
    /// A wind skin and clip in `best.glb`, as `sylva grow --wind`: `wind = {}` for the
    /// defaults, or `wind = { strength = 2.0, period = 3.0 }`. Default none.
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "wind")]
    pub wind: Option<WindConfig>,
    /// The best plant's assets scaled so that its highest point stands this many metres
    /// above the ground, 0.01 to 1000, as `sylva grow --height`. Default none: the model's
    /// own scale (evolution scores the plants as grown).
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "height")]
    pub height: Option<f32>,
    /// Leaves or needles of a kind at their real size on the best plant and the sheet, as
    /// `sylva grow --foliage` (`"oak"`, `"pine"`, …; [`LeafKind`]). Default none: the
    /// plant's own leaves (evolution scores the plants as grown).
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "foliage")]
    pub foliage: Option<LeafKind>,
    /// A tiling bark, as `sylva grow --bark` (`"smooth"`, `"birch"`, `"furrowed"`,
    /// `"plated"`). Default none: the foliage's own bark, or the model's look.
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "bark")]
    pub bark: Option<BarkKind>,
    /// Leaf cards per metre of twig, as a multiple of the kind's own, 0.25 to 4, as
    /// `sylva grow --density`. Default 1.
    #[serde(skip_serializing_if = "is_one", deserialize_with = "density")]
    pub density: f32,
}

fn is_one(x: &f32) -> bool {
    *x == 1.0
}

/// Reads `foliage` by name, naming the kinds allowed when it is none of them.
fn foliage<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<LeafKind>, D::Error> {
    let name = String::deserialize(d)?;
    name.parse().map(Some).map_err(serde::de::Error::custom)
}

/// Reads `bark` by name, naming the kinds allowed when it is none of them.
fn bark<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<BarkKind>, D::Error> {
    let name = String::deserialize(d)?;
    name.parse().map(Some).map_err(serde::de::Error::custom)
}

/// Reads `density`, checked to lie in 0.25..=4.
fn density<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let x = f32::deserialize(d)?;
    if (0.25..=4.0).contains(&x) {
        Ok(x)
    } else {
        Err(serde::de::Error::custom(format!(
            "`density` must be a number from 0.25 to 4, got {x}"
        )))
    }
}

/// Reads `height`, checked to lie in 0.01..=1000 metres.
fn height<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    let metres = f32::deserialize(d)?;
    let (lo, hi) = crate::assets::HEIGHTS;
    if (lo..=hi).contains(&metres) {
        Ok(Some(metres))
    } else {
        Err(serde::de::Error::custom(format!(
            "`height` must be a number from {lo} to {hi} m, got {metres}"
        )))
    }
}

/// `[output] wind`: the wind of `best.glb`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WindConfig {
    /// Sway, 0 to 10. Default 1.
    pub strength: f32,
    /// Seconds of the clip, 0.5 to 60. Default 4.
    pub period: f32,
}

impl Default for WindConfig {
    fn default() -> Self {
        let d = WindOptions::default();
        WindConfig {
            strength: d.strength,
            period: d.period,
        }
    }
}

/// Reads `wind`, its numbers checked.
fn wind<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<WindConfig>, D::Error> {
    let wind = WindConfig::deserialize(d)?;
    WindOptions::new(wind.strength, wind.period).map_err(serde::de::Error::custom)?;
    Ok(Some(wind))
}

/// `[match]`: a target outline the plant's silhouette should match, as a fitness term
/// (`iou`, 0 to 1) beside the model's own terms or alone ([docs/match.md]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MatchConfig {
    /// The target seen from the front (looking along -Z): a PNG or JPEG file, relative to
    /// the config file. Required.
    pub front: PathBuf,
    /// The target seen from the side (looking along +X), scored too. Default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<PathBuf>,
    /// How ink is told from background: `"otsu"` (the default; a photo against the sky
    /// works) or a luminance 0 to 1 that ink is darker than. Pictures with transparent
    /// pixels use their alpha channel instead.
    #[serde(default)]
    pub threshold: Threshold,
    /// The term's weight in the total, 0 to 1,000,000. Default 1.
    #[serde(default = "one", deserialize_with = "match_weight")]
    pub weight: f64,
    /// Whether the model's own terms count beside the outline. Default true; `false`: the
    /// outline alone decides (what `sylva match` writes).
    #[serde(default = "yes")]
    pub beside: bool,
    /// Rows the outlines are compared at, 16 to 512. Default [`MatchConfig::DEFAULT_ROWS`].
    #[serde(default = "default_rows", deserialize_with = "match_rows")]
    pub rows: u32,
    /// Weight of closeness beside the IoU, 0 to 10: how near the silhouette lies to the
    /// outline by a distance transform, which keeps rising as a plant that misses the
    /// outline moves towards it (docs/match.md). Default 0: the IoU alone.
    #[serde(
        default,
        deserialize_with = "match_closeness",
        skip_serializing_if = "is_zero"
    )]
    pub closeness: f64,
    /// Whether the plant is clipped to the outlines as a topiary is to its form: pruned
    /// where it would show outside their ink ([`sylva_fitness::silhouette::prune`],
    /// docs/match.md), in the outline's scoring and in every plant the run writes. Default
    /// false: the outline is a goal the plant grows towards, and a match writes trees as
    /// they grew. (`prune`, its name before, is read too.)
    #[serde(default, alias = "prune", skip_serializing_if = "Option::is_none")]
    pub topiary: Option<bool>,
}

impl MatchConfig {
    /// The rows outlines are compared at unless `rows` says otherwise: 256, the rows the
    /// plant is pruned at ([`sylva_fitness::silhouette::SPACE_ROWS`]) and its IoU reported
    /// at, so that what the search sees is what it is judged by. Coarser comparisons blur
    /// the gaps of a crown and let combs of thin twigs pass for solid ink (docs/match.md).
    pub const DEFAULT_ROWS: u32 = 256;

    /// Whether the plants are clipped to the outlines (`topiary`; false unless set).
    pub fn prunes(&self) -> bool {
        self.topiary.unwrap_or(false)
    }
}

fn is_zero(value: &f64) -> bool {
    *value == 0.0
}

/// `[map]`: the map of a MAP-Elites run (`[run] strategy = "map-elites"`): its
/// descriptors, and how it is filled ([docs/varieties.md]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MapConfig {
    /// The map's axes, 1 to 3, at most 100,000 cells in all. Default: `height_to_width`
    /// and `porosity`, 10 cells each.
    #[serde(deserialize_with = "map_axes")]
    pub descriptors: Vec<AxisConfig>,
    /// Genomes of generation 0 (start genomes, then random), 1 to 1,000,000. Default 200.
    #[serde(deserialize_with = "map_initial")]
    pub initial: u32,
    /// Offspring bred from the map each generation, 1 to 1,000,000. Default 100.
    #[serde(deserialize_with = "map_batch")]
    pub batch: u32,
    /// Share of offspring crossed from two elites before mutating, 0 to 1; the rest are
    /// mutants of one. Default 0.5.
    #[serde(deserialize_with = "map_crossover")]
    pub crossover: f64,
    /// Subtracted from each elite's fitness in the QD-score (set it below every fitness
    /// the model gives, so that filling a cell always raises the score), -1e12 to 1e12.
    /// Default 0.
    #[serde(deserialize_with = "map_qd_offset")]
    pub qd_offset: f64,
    /// Where offspring come from: `"operators"` (the model's own crossover and mutation
    /// of elites chosen uniformly; the default) or `"cma-me"` (CMA-ME emitters searching
    /// the genomes as vectors, for models that have a direct coding: PlantMaker and binary
    /// trees).
    #[serde(skip_serializing_if = "EmitterKind::is_operators")]
    pub emitter: EmitterKind,
    /// CMA-ME: evolution strategies sharing each batch, 1 to half the batch. Default 5.
    #[serde(
        deserialize_with = "map_emitters",
        skip_serializing_if = "Option::is_none"
    )]
    pub emitters: Option<u32>,
    /// CMA-ME: each strategy's first step size, as a share of each genome entry's range,
    /// 0.001 to 1. Default 0.1.
    #[serde(
        deserialize_with = "map_sigma",
        skip_serializing_if = "Option::is_none"
    )]
    pub sigma: Option<f64>,
}

/// `[map] emitter`: where a map's offspring come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EmitterKind {
    /// The model's own operators.
    #[default]
    Operators,
    /// CMA-ME emitters over the genomes as vectors.
    CmaMe,
}

impl EmitterKind {
    /// Whether this is the default, the model's operators.
    pub fn is_operators(&self) -> bool {
        *self == EmitterKind::Operators
    }
}

impl MapConfig {
    /// CMA-ME's strategies when none are given.
    pub const EMITTERS: u32 = 5;
    /// CMA-ME's first step size when none is given.
    pub const SIGMA: f64 = 0.1;
}

/// One axis of the map: a descriptor, its range and its cells.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisConfig {
    /// The descriptor (see [`Descriptor`]).
    pub name: Descriptor,
    /// Its range, `[low, high]`; values outside fall in the end cells. Default: the
    /// descriptor's own range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<[f64; 2]>,
    /// Cells across the range, 1 to 1000. Default 10.
    #[serde(default = "ten", deserialize_with = "axis_cells")]
    pub cells: u32,
}

impl AxisConfig {
    /// `name` over its own range in `cells` cells.
    pub fn new(name: Descriptor, cells: u32) -> AxisConfig {
        AxisConfig {
            name,
            range: None,
            cells,
        }
    }

    /// The range: the one given, or the descriptor's own.
    pub fn bounds(&self) -> (f64, f64) {
        self.range.map_or(self.name.range(), |[lo, hi]| (lo, hi))
    }
}

impl Default for MapConfig {
    fn default() -> Self {
        MapConfig {
            descriptors: vec![
                AxisConfig::new(Descriptor::HeightToWidth, 10),
                AxisConfig::new(Descriptor::Porosity, 10),
            ],
            initial: 200,
            batch: 100,
            crossover: 0.5,
            qd_offset: 0.0,
            emitter: EmitterKind::Operators,
            emitters: None,
            sigma: None,
        }
    }
}

fn ten() -> u32 {
    10
}

sylva_core::ranged!(map_initial: u32, "initial", 1, 1_000_000);
sylva_core::ranged!(map_batch: u32, "batch", 1, 1_000_000);
sylva_core::ranged!(map_crossover: f64, "crossover", 0.0, 1.0);
sylva_core::ranged!(map_qd_offset: f64, "qd_offset", -1e12, 1e12);
sylva_core::ranged!(axis_cells: u32, "cells", 1, 1000);
sylva_core::ranged!(emitters_value: u32, "emitters", 1, 500_000);
sylva_core::ranged!(sigma_value: f64, "sigma", 0.001, 1.0);

fn map_emitters<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u32>, D::Error> {
    emitters_value(d).map(Some)
}

fn map_sigma<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    sigma_value(d).map(Some)
}

/// Reads `descriptors`: 1 to 3 axes, each range finite and rising, each descriptor once,
/// at most 100,000 cells in all.
fn map_axes<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<AxisConfig>, D::Error> {
    let axes = Vec::<AxisConfig>::deserialize(d)?;
    let max = sylva_evolve::map::MAX_DESCRIPTORS;
    if axes.is_empty() || axes.len() > max {
        return Err(de::Error::custom(format!(
            "`descriptors` must list 1 to {max} descriptors, got {}",
            axes.len()
        )));
    }
    for (i, axis) in axes.iter().enumerate() {
        if let Some([lo, hi]) = axis.range
            && !(lo.is_finite() && hi.is_finite() && lo < hi)
        {
            return Err(de::Error::custom(format!(
                "`range` of `{}` must be two finite numbers, low then high, got [{lo}, {hi}]",
                axis.name.name()
            )));
        }
        if axes[..i].iter().any(|a| a.name == axis.name) {
            return Err(de::Error::custom(format!(
                "`descriptors` names `{}` twice",
                axis.name.name()
            )));
        }
    }
    let cells: u64 = axes.iter().map(|a| u64::from(a.cells)).product();
    let most = sylva_evolve::map::MAX_CELLS;
    if cells > most as u64 {
        return Err(de::Error::custom(format!(
            "the map would have {cells} cells; at most {most} (fewer `cells` per descriptor)"
        )));
    }
    Ok(axes)
}

fn one() -> f64 {
    1.0
}

fn yes() -> bool {
    true
}

fn default_rows() -> u32 {
    MatchConfig::DEFAULT_ROWS
}

sylva_core::ranged!(match_weight: f64, "weight", 0.0, 1_000_000.0);
sylva_core::ranged!(match_rows: u32, "rows", 16, 512);
sylva_core::ranged!(match_closeness: f64, "closeness", 0.0, 10.0);

impl OutputConfig {
    /// The taper the outputs are grown with, if any.
    pub fn pipe_taper(&self) -> Option<PipeTaper> {
        self.taper.and_then(|e| PipeTaper::new(e).ok())
    }

    /// How the outputs are dressed (`foliage`, `bark`, `density`).
    pub fn dress(&self) -> Dress {
        Dress {
            foliage: self.foliage,
            bark: self.bark,
            density: self.density,
            ..Dress::default()
        }
    }

    /// The wind of `best.glb`, if any.
    pub fn wind_options(&self) -> Option<WindOptions> {
        self.wind
            .and_then(|w| WindOptions::new(w.strength, w.period).ok())
    }
}

impl Default for OutputConfig {
    fn default() -> Self {
        OutputConfig {
            image_size: 800,
            view: View::Iso,
            sheet_size: 48,
            taper: None,
            wind: None,
            height: None,
            foliage: None,
            bark: None,
            density: 1.0,
        }
    }
}

/// Reads `taper`, checked to lie in 2..=3.
fn taper<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    let exponent = f64::deserialize(d)?;
    match PipeTaper::new(exponent) {
        Ok(_) => Ok(Some(exponent)),
        Err(_) => Err(serde::de::Error::custom(format!(
            "`taper` must be a number from 2 to 3 (the pipe-model exponent), got {exponent}"
        ))),
    }
}

sylva_core::ranged!(image_size: u32, "image_size", 64, 4096);
sylva_core::ranged!(sheet_size: u32, "sheet_size", 1, 400);

mod view_name {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};
    use sylva_render::View;

    pub fn serialize<S: Serializer>(v: &View, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(v)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<View, D::Error> {
        String::deserialize(d)?.parse().map_err(D::Error::custom)
    }
}

/// An evolution config of model `M`: `model`, `[run]`, the model's settings under its
/// name, and `[output]`.
#[derive(Clone, Debug, Default)]
pub struct EvolveConfig<M: Evolve> {
    /// The model.
    pub model: M,
    /// Run size and seed.
    pub run: RunConfig,
    /// The model's settings.
    pub settings: M::Settings,
    /// What a run writes.
    pub output: OutputConfig,
    /// A target outline to match, if any (`[match]`).
    pub outline: Option<MatchConfig>,
    /// The map of a MAP-Elites run, if one is given (`[map]`).
    pub map: Option<MapConfig>,
}

impl<M: Evolve> PartialEq for EvolveConfig<M> {
    fn eq(&self, other: &Self) -> bool {
        self.run == other.run
            && self.settings == other.settings
            && self.output == other.output
            && self.outline == other.outline
            && self.map == other.map
    }
}

impl<M: Evolve> Serialize for EvolveConfig<M> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut st = s.serialize_struct("EvolveConfig", 5)?;
        st.serialize_field("model", M::NAME)?;
        st.serialize_field("run", &self.run)?;
        st.serialize_field(M::NAME, &self.settings)?;
        st.serialize_field("output", &self.output)?;
        if let Some(outline) = &self.outline {
            st.serialize_field("match", outline)?;
        }
        if let Some(map) = &self.map {
            st.serialize_field("map", map)?;
        }
        st.end()
    }
}

impl<'de, M: Evolve + Default> Deserialize<'de> for EvolveConfig<M> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(ConfigVisitor(PhantomData))
    }
}

struct ConfigVisitor<M>(PhantomData<M>);

/// The keys of a config, in the order they are named in errors.
enum Key {
    Model,
    Run,
    Settings,
    Output,
    Match,
    Map,
}

impl<'de, M: Evolve + Default> Visitor<'de> for ConfigVisitor<M> {
    type Value = EvolveConfig<M>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "an evolution config of `{}`", M::NAME)
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<EvolveConfig<M>, A::Error> {
        let mut config = EvolveConfig::<M>::default();
        while let Some(key) = map.next_key_seed(KeySeed(M::NAME))? {
            match key {
                Key::Model => map.next_value_seed(NameSeed(M::NAME))?,
                Key::Run => config.run = map.next_value_seed(Table::new("run"))?,
                Key::Settings => config.settings = map.next_value_seed(Table::new(M::NAME))?,
                Key::Output => config.output = map.next_value_seed(Table::new("output"))?,
                Key::Match => config.outline = Some(map.next_value_seed(Table::new("match"))?),
                Key::Map => config.map = Some(map.next_value_seed(Table::new("map"))?),
            }
        }
        if config.map.is_some() && config.run.strategy != SearchStrategy::MapElites {
            return Err(de::Error::custom(
                "a `[map]` is drawn by a MAP-Elites run: add `strategy = \"map-elites\"` to \
                 `[run]`, or leave `[map]` out",
            ));
        }
        if let Some(map) = &config.map
            && map.emitter.is_operators()
            && (map.emitters.is_some() || map.sigma.is_some())
        {
            return Err(de::Error::custom(
                "`[map]` `emitters` and `sigma` tune CMA-ME: add `emitter = \"cma-me\"` to \
                 `[map]`, or leave them out",
            ));
        }
        Ok(config)
    }
}

/// Reads a section (`[run]`, `[output]`, the model's) as a table and nothing else: serde's
/// derived structs also take a list, field by field in order (`run = [5, 10]` would be
/// 5 generations of 10), which no one writes on purpose.
struct Table<T> {
    name: &'static str,
    section: PhantomData<T>,
}

impl<T> Table<T> {
    fn new(name: &'static str) -> Self {
        Table {
            name,
            section: PhantomData,
        }
    }
}

impl<'de, T: Deserialize<'de>> DeserializeSeed<'de> for Table<T> {
    type Value = T;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<T, D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de, T: Deserialize<'de>> Visitor<'de> for Table<T> {
    type Value = T;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "a table: `[{}]` with its fields, or `{} = {{ ... }}`",
            self.name, self.name
        )
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
        T::deserialize(de::value::MapAccessDeserializer::new(map))
    }
}

/// Reads a key of a config of the model named `.0`; unknown keys are refused here, so the
/// error points at the key.
struct KeySeed(&'static str);

impl<'de> DeserializeSeed<'de> for KeySeed {
    type Value = Key;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Key, D::Error> {
        let key = String::deserialize(d)?;
        match key.as_str() {
            "model" => Ok(Key::Model),
            "run" => Ok(Key::Run),
            "output" => Ok(Key::Output),
            "match" => Ok(Key::Match),
            "map" => Ok(Key::Map),
            k if k == self.0 => Ok(Key::Settings),
            k => Err(de::Error::custom(format!(
                "unknown field `{k}`: this config evolves `{}` (set `model` to evolve another \
                 model); expected `model`, `run`, `{}`, `output`, `match` or `map`",
                self.0, self.0
            ))),
        }
    }
}

/// Reads the `model` field, which must name the model `.0`.
struct NameSeed(&'static str);

impl<'de> DeserializeSeed<'de> for NameSeed {
    type Value = ();
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        let name = String::deserialize(d)?;
        if name == self.0 {
            Ok(())
        } else {
            Err(de::Error::custom(format!(
                "`model` is `{name}`, but this is a config of `{}`",
                self.0
            )))
        }
    }
}

impl<M: Evolve + Default> EvolveConfig<M> {
    /// Parses a config of model `M` from TOML; errors point into `text`.
    pub fn parse(path: &Path, text: &str) -> Result<Self, InputError> {
        toml::from_str(text).map_err(|e| InputError::toml(path, text, &e))
    }

    /// The config as TOML (what a run records next to its results).
    pub fn to_toml(&self) -> String {
        // Configs hold only range-checked numbers, strings and tables (each after the plain
        // values of its parent), which TOML always writes; failing here is a bug.
        toml::to_string(self).expect("configs serialise as TOML")
    }

    /// The parts that must match for a run to resume: everything but the length of the
    /// run, the thread count and the checkpoint interval.
    pub(super) fn resumable(&self) -> Self {
        let mut c = self.clone();
        c.run.generations = 0;
        c.run.threads = 0;
        c.run.checkpoint_seconds = 0.0;
        c
    }
}
