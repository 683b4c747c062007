//! The seam every Sylva model plugs into.
//!
//! A model is a type that implements [`Model`]: its name, its genome type, how a genome
//! grows into a [`Plant`], its settings, and its own variation operators (random genomes,
//! mutation, crossover of two or more parents with dominance weights, and what a person's
//! [`Knobs`] mean for them). A model that can
//! also be evolved without a person implements [`Evolve`]: the engine's [`Problem`] and
//! [`Strategy`] its settings describe, and how an evolved genome becomes a genome file. A
//! model's settings are one type, the `[name]` section of an evolution config, so a run and
//! a person breeding by hand vary genomes alike. Everything else (files, meshes, pictures, the command line, the
//! studio, Python) reaches models through these two traits; the library layer (the `sylva`
//! crate) keeps the one registry that lists them.
//!
//! - [`file`](mod@file): genome files ([`GenomeError`], [`FormatV1`], [`model_tag!`]).
//! - [`VectorCoding`]: a model's genomes as fixed vectors of parameters, for optimisers
//!   outside Sylva ([`Evolve::vector_coding`]; the library decodes any model's vectors
//!   otherwise).
//!
//! Some models offer a workflow of their own besides growing and evolving. Each is one
//! trait here, with model-neutral options and outcomes; a model implements it and says so
//! in its registry line, and the library runs the workflow for whichever model offers it:
//!
//! - [`Biomorphs`](biomorphs::Biomorphs): a mother and her children grown together in one
//!   world, for a person to breed by eye (the L-system's).
//! - [`Gardens`](gardens::Gardens): many plants of a few genomes on one plot, kept in a
//!   garden file (PlantMaker's).
//! - [`Experiments`](experiments::Experiments): experiments run from a config into a
//!   report, records and plants (the L-system's).
//! - [`Work`]: what growing plants together costs, estimated before it starts.
//!
//! ```
//! use rand::{Rng, RngExt};
//! use sylva_core::{Plant, glam::Vec3};
//! use sylva_model::{Bred, DevelopError, Knobs, Model, Parent, VariationError, plant_meta};
//! use sylva_model::schema::{FieldSpec, Kind, Schema};
//!
//! /// A plant of one cylinder, `height` metres tall.
//! #[derive(Clone, Copy, Debug, Default)]
//! struct Stick;
//!
//! #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
//! struct StickGenome {
//!     height: f32,
//! }
//!
//! impl Model for Stick {
//!     type Genome = StickGenome;
//!     type Settings = ();
//!     const NAME: &'static str = "stick";
//!     const TITLE: &'static str = "Sticks";
//!
//!     fn develop(&self, g: &StickGenome, seed: u64) -> Result<Plant, DevelopError> {
//!         let mut plant = Plant::new(plant_meta::<Self>(g, seed));
//!         plant.add_segment(Vec3::ZERO, Vec3::Y * g.height, (0.1, 0.05), None, false, Plant::BARK)?;
//!         Ok(plant)
//!     }
//!
//!     fn random<R: Rng + ?Sized>(&self, _: &(), rng: &mut R) -> StickGenome {
//!         StickGenome { height: rng.random_range(0.5..3.0) }
//!     }
//!
//!     fn mutate<R: Rng + ?Sized>(&self, g: &StickGenome, _: &(), rng: &mut R) -> StickGenome {
//!         StickGenome { height: (g.height * rng.random_range(0.8..1.25)).clamp(0.1, 10.0) }
//!     }
//!
//!     fn hand_settings(&self, _: Knobs, _: ()) {}
//!
//!     fn schema(&self) -> Schema {
//!         Schema::of(vec![FieldSpec::new("height", "stem", Kind::number(0.1, 10.0), "How tall.").unit(" m")])
//!     }
//!
//!     fn cross<R: Rng + ?Sized>(
//!         &self,
//!         parents: &[Parent<'_, StickGenome>],
//!         _: &(),
//!         _: &mut R,
//!     ) -> Result<Bred<StickGenome>, VariationError> {
//!         let (a, b) = sylva_model::two_most_dominant(parents)?;
//!         let height = 0.5 * (parents[a].genome.height + parents[b].genome.height);
//!         Ok(Bred { genome: StickGenome { height }, parents: vec![a, b] })
//!     }
//! }
//!
//! let plant = Stick.develop(&StickGenome { height: 2.0 }, 7)?;
//! assert_eq!(plant.meta().model, "stick");
//! assert_eq!(plant.segments().len(), 1);
//! # Ok::<(), DevelopError>(())
//! ```

pub mod biomorphs;
pub mod experiments;
pub mod file;
pub mod gardens;
pub mod schema;
mod work;

use std::fmt::Debug;
use std::path::PathBuf;

use rand::Rng;
use serde::{Serialize, de::DeserializeOwned};
use sylva_core::dress::Dress;
use sylva_core::{Plant, PlantError, PlantMeta, hash::stable_hash};
use sylva_evolve::{Operators, Problem, Strategy, WithTerm};

pub use file::{FormatV1, GenomeError};
pub use work::Work;

/// A plant model: a genome type, how it grows, and its own variation operators.
///
/// Models are values (usually unit structs), so that a registry can hold them and a genome
/// can remember which model it belongs to. Every method is deterministic: the same genome,
/// settings and random stream give the same result.
pub trait Model: Clone + Debug + Send + Sync + 'static {
    /// What a genome file of this model holds.
    type Genome: Clone + Debug + PartialEq + Send + Sync + Serialize + DeserializeOwned + 'static;
    /// The model's settings: how random genomes are made and genomes varied (rates,
    /// levels, sizes) and, for a model that evolves, how a run breeds and scores them. It is
    /// the `[name]` section of an evolution config: unknown fields refused, numbers
    /// range-checked while read, every default documented. `Default` is what a person
    /// breeding by hand starts with.
    type Settings: Clone
        + Debug
        + Default
        + PartialEq
        + Send
        + Sync
        + Serialize
        + DeserializeOwned
        + 'static;

    /// The model's name in files (`"model": "..."`).
    const NAME: &'static str;
    /// A short title for plots and pages, e.g. "Binary trees (Susinno)".
    const TITLE: &'static str;

    /// Grows a genome into a plant. `seed` drives the model's own random choices, if it has
    /// any, and is recorded in the plant ([`plant_meta`]).
    fn develop(&self, genome: &Self::Genome, seed: u64) -> Result<Plant, DevelopError>;

    /// A random genome, for a person who asks for one: it should grow into a plant worth
    /// looking at (a run's first generation is [`Problem::random_genome`], the paper's).
    fn random<R: Rng + ?Sized>(&self, settings: &Self::Settings, rng: &mut R) -> Self::Genome;

    /// A mutated copy of `genome`.
    fn mutate<R: Rng + ?Sized>(
        &self,
        genome: &Self::Genome,
        settings: &Self::Settings,
        rng: &mut R,
    ) -> Self::Genome;

    /// A child of two or more parents. Where a model's crossover mixes two parents, it
    /// crosses the two most dominant ([`two_most_dominant`]); a model may use every weight.
    fn cross<R: Rng + ?Sized>(
        &self,
        parents: &[Parent<'_, Self::Genome>],
        settings: &Self::Settings,
        rng: &mut R,
    ) -> Result<Bred<Self::Genome>, VariationError>;

    /// The settings a person breeding by hand means with `knobs` (PlantMaker's crossover
    /// level and mutation Depth, §2): each model gives them its own operators' meaning, so
    /// the studio's controls act on every model. Depth 2 and the medium level are what a
    /// person starts with: a model's default mutation and crossover. What the knobs do not
    /// set is kept from `base`: the model's defaults, or the settings of the run the plants
    /// come from (a match's PlantMaker plants keep to leaf colours).
    fn hand_settings(&self, knobs: Knobs, base: Self::Settings) -> Self::Settings;

    /// Its genome field by field: what a person may set by hand, each value's kind, range
    /// and meaning ([`schema`]).
    fn schema(&self) -> schema::Schema;

    /// Reads a genome file's text. The default is serde's reader, which refuses unknown
    /// fields and reports the line and column of any error.
    fn parse(&self, text: &str) -> Result<Self::Genome, GenomeError> {
        file::parse(text)
    }

    /// The genome file's text: pretty JSON ending with a newline.
    fn write(&self, genome: &Self::Genome) -> String {
        file::pretty(genome)
    }

    /// The seed a genome grows with when none is given: 0, or the genome's own seed for
    /// models whose genomes carry one.
    fn default_seed(&self, _genome: &Self::Genome) -> u64 {
        0
    }

    /// The genome that grows with `seed` when none is given, for models whose genomes carry
    /// their seed (so that a plant regrown with another seed is written, packed and exported
    /// with it); the genome as it is for the others.
    fn with_seed(&self, genome: &Self::Genome, _seed: u64) -> Self::Genome {
        genome.clone()
    }

    /// How the model's plants are best meshed.
    fn mesh_hint(&self) -> MeshHint {
        MeshHint::default()
    }

    /// Seconds growing `genome` may take on one core, estimated before it grows, for a
    /// model whose growth can take long (L-system plants grow step by step in a voxel
    /// world); `None`, the default, for models whose plants grow in milliseconds.
    fn growth_seconds(&self, _genome: &Self::Genome) -> Option<f64> {
        None
    }

    /// How the model's plants are dressed when nobody says otherwise: the leaves or needles
    /// and bark a genome names for itself (the self-organising model's `foliage`). The
    /// default, [`Dress::default`], leaves a plant as it grew, as the papers' models are.
    fn dress(&self, _genome: &Self::Genome) -> Dress {
        Dress::default()
    }

    /// A short text form of `genome` a person can copy and paste, for a model that has one
    /// (PlantMaker's packed string); `None`, the default, otherwise.
    fn packed(&self, _genome: &Self::Genome) -> Option<String> {
        None
    }
}

/// How much of the parents a crossover mixes, as PlantMaker's levels name it (Figure 9):
/// low keeps large parts of each parent together, high mixes the smallest parts. Each model
/// says what its parts are ([`Model::hand_settings`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CrossLevel {
    /// Large parts of each parent together.
    Low,
    /// The model's default crossover.
    #[default]
    Medium,
    /// The smallest parts mixed.
    High,
}

/// How strongly a mutation changes a genome, 1 (the least) to 10, as PlantMaker's Depth
/// control. 2 is a model's default mutation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub struct Depth(u8);

impl Depth {
    /// The least Depth.
    pub const MIN: u8 = 1;
    /// The greatest Depth.
    pub const MAX: u8 = 10;

    /// A Depth of 1 to 10.
    pub fn new(depth: u8) -> Option<Depth> {
        (Self::MIN..=Self::MAX)
            .contains(&depth)
            .then_some(Depth(depth))
    }

    /// Its value, 1 to 10.
    pub fn get(self) -> u8 {
        self.0
    }

    /// Its value as a share of the range above the default: 1 at Depth 2, 5 at Depth 10,
    /// 0.5 at Depth 1 (what most models multiply their rates by).
    pub fn scale(self) -> f64 {
        f64::from(self.0) / 2.0
    }
}

impl Default for Depth {
    fn default() -> Self {
        Depth(2)
    }
}

impl TryFrom<u8> for Depth {
    type Error = String;
    fn try_from(depth: u8) -> Result<Depth, String> {
        Depth::new(depth).ok_or_else(|| format!("expected a Depth of 1 to 10, got {depth}"))
    }
}

impl From<Depth> for u8 {
    fn from(depth: Depth) -> u8 {
        depth.0
    }
}

/// A person's controls when breeding by hand: the crossover level and the mutation Depth.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
pub struct Knobs {
    /// How much a crossover mixes.
    pub level: CrossLevel,
    /// How strongly a mutation changes.
    pub depth: Depth,
}

/// How a model's plants are best meshed: facts about the model's shapes, which the library
/// turns into mesh options (so meshing never asks which model a plant came from).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshHint {
    /// The model's tubes are sphylls (cylinders with spherical ends): round their caps.
    pub round_caps: bool,
}

/// A parent of a crossover and its dominance weight (any finite number of at least 0; the
/// more, the more genes it gives).
#[derive(Clone, Copy, Debug)]
pub struct Parent<'a, G> {
    /// The genome.
    pub genome: &'a G,
    /// Its weight.
    pub dominance: f64,
}

/// A child and the parents that gave it genes.
#[derive(Clone, Debug, PartialEq)]
pub struct Bred<G> {
    /// The child.
    pub genome: G,
    /// Indices (into the parents given) of the parents that gave it genes, ascending.
    pub parents: Vec<usize>,
}

/// Why parents could not be crossed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum VariationError {
    /// Crossover needs two or more parents.
    #[error("crossover needs two or more parents, got {0}")]
    TooFewParents(usize),
    /// Mutation takes exactly one parent.
    #[error("mutation takes one parent, got {0}")]
    NotOneParent(usize),
    /// A dominance weight is negative or not finite.
    #[error("parent {parent}'s dominance must be a finite number of at least 0, got {value}")]
    BadDominance {
        /// Index of the parent.
        parent: usize,
        /// Its weight.
        value: f64,
    },
}

/// Checks the parents of a crossover: two or more, each weight finite and at least 0.
pub fn check_parents<G>(parents: &[Parent<'_, G>]) -> Result<(), VariationError> {
    if parents.len() < 2 {
        return Err(VariationError::TooFewParents(parents.len()));
    }
    match parents
        .iter()
        .position(|p| !(p.dominance.is_finite() && p.dominance >= 0.0))
    {
        Some(i) => Err(VariationError::BadDominance {
            parent: i,
            value: parents[i].dominance,
        }),
        None => Ok(()),
    }
}

/// The two most dominant parents (ties go to the first given), in the order given, after
/// [`check_parents`]: what a two-parent crossover crosses.
pub fn two_most_dominant<G>(parents: &[Parent<'_, G>]) -> Result<(usize, usize), VariationError> {
    check_parents(parents)?;
    let mut order: Vec<usize> = (0..parents.len()).collect();
    order.sort_by(|&a, &b| parents[b].dominance.total_cmp(&parents[a].dominance));
    let (a, b) = (order[0].min(order[1]), order[0].max(order[1]));
    Ok((a, b))
}

/// Why a genome could not be grown.
#[derive(Debug, thiserror::Error)]
pub enum DevelopError {
    /// The plant refused a part (a NaN, negative or far value slipped through).
    #[error("invalid plant part")]
    Plant(#[from] PlantError),
    /// The genome asks for a larger plant than the model allows.
    #[error("the plant would have more than {limit} parts (segments and organs)")]
    TooLarge {
        /// The limit, in segments plus organs.
        limit: usize,
    },
    /// The plant may need more memory than the budget allows.
    #[error("the plant does not fit in memory")]
    OverBudget(#[from] sylva_core::budget::OverBudget),
    /// A model's own reason (an L-system world that cannot be built, say).
    #[error(transparent)]
    Model(Box<dyn std::error::Error + Send + Sync>),
}

/// Where a plant of model `M` grown from `genome` with `seed` came from: the model's name,
/// the stable hash of the genome's compact JSON and the seed.
pub fn plant_meta<M: Model>(genome: &M::Genome, seed: u64) -> PlantMeta {
    PlantMeta {
        model: M::NAME.to_owned(),
        genome_hash: genome_hash(genome),
        seed,
    }
}

/// The stable hash of a genome's compact JSON: its fingerprint in a plant's metadata.
pub fn genome_hash<G: Serialize>(genome: &G) -> u64 {
    // Genomes are structs of strings, numbers and lists, which serde_json always writes.
    stable_hash(&serde_json::to_vec(genome).unwrap_or_default())
}

/// A model that can be evolved without a person (`sylva evolve`).
///
/// The engine may evolve another representation than the genome file (a bit string for the
/// binary tree, a bare GP tree for automata); [`Evolve::genome_file`] turns an evolved
/// genome back into the model's genome.
pub trait Evolve: Model {
    /// The problem the engine solves.
    type Problem: Problem<Genome: Serialize + DeserializeOwned> + Clone + Send + 'static;
    /// How one generation becomes the next: of the problem, and of the problem with one
    /// more term (a target outline; every generic strategy is both). Its variation
    /// operators also breed MAP-Elites maps ([`Operators`]).
    type Strategy: Strategy<Self::Problem>
        + Strategy<WithTerm<Self::Problem>>
        + Operators<<Self::Problem as Problem>::Genome>
        + Send
        + 'static;

    /// The settings a match breeds with (a run towards target outlines, `sylva match`):
    /// `settings`, the model's defaults, changed where fitting an outline wants otherwise.
    /// An outline is fitted by many small steps from good plants rather than by recombining
    /// distant ones, so a model whose defaults are the papers' (made to find a shape's kind)
    /// breeds mostly mutants here. The default changes nothing.
    fn fitting(&self, _settings: &mut Self::Settings) {}

    /// The settings a match towards `target` breeds with, for a model whose plants can
    /// grow into a target's shape (the self-organising model fills the visual hull of the
    /// outlines): called after [`Evolve::fitting`] when a run has a target outline. `Err`
    /// says why the target cannot be grown into (a hull with no volume). The default
    /// changes nothing.
    fn fit_target(
        &self,
        _settings: &mut Self::Settings,
        _target: &TargetProfile,
    ) -> Result<(), ConfigError> {
        Ok(())
    }

    /// Genome files the settings name (relative to the config file), read by the caller and
    /// given to [`Evolve::setup`] as `start`.
    fn start_files(&self, _settings: &Self::Settings) -> Vec<PathBuf> {
        Vec::new()
    }

    /// The problem, its breeding and the first members of generation 0 (the rest is
    /// random) that `settings` describe. `start` holds the genomes of
    /// [`Evolve::start_files`]; `seed` and `population` are the run's.
    fn setup(
        &self,
        settings: &Self::Settings,
        start: Vec<Self::Genome>,
        seed: u64,
        population: usize,
    ) -> Result<Setup<Self>, ConfigError>;

    /// The genome file an evolved genome stands for.
    fn genome_file(
        &self,
        problem: &Self::Problem,
        evolved: &<Self::Problem as Problem>::Genome,
    ) -> Self::Genome;

    /// Guides drawn beside plants in pictures (a target surface, forbidden cells).
    fn guides(&self, _problem: &Self::Problem) -> Option<Plant> {
        None
    }

    /// Bytes an evolved genome may hold at the settings' bounds, for the memory estimate of
    /// a population. The default, 4 KiB, suits small fixed-size genomes.
    fn genome_bytes(&self, _settings: &Self::Settings) -> u64 {
        4096
    }

    /// How long one evaluation may take at the settings' bounds, for a model whose genomes
    /// can take long to grow (an L-system plant grows step by step in a voxel world);
    /// `None`, the default, for models whose genomes grow in milliseconds. `start` is the
    /// run's first start genome, if any. A run whose generation would take longer than the
    /// time budget is refused before it starts.
    fn evaluation_time(
        &self,
        _settings: &Self::Settings,
        _start: Option<&Self::Genome>,
    ) -> Option<EvaluationTime> {
        None
    }

    /// The problem's genomes as vectors of numbers, for a model whose evolved genome is
    /// naturally a fixed list of parameters (the binary tree's fields, PlantMaker's codes),
    /// so that an optimiser outside Sylva (CMA-ES, pyribs) can search them. `seed` is what
    /// a decoded genome takes for any part the vector does not hold (a genome's own growth
    /// seed). `None`, the default, for genomes of varying structure (programs, rule sets):
    /// the library then decodes vectors as the random draws of
    /// [`Problem::random_genome`], which every model has.
    fn vector_coding(
        &self,
        _problem: &Self::Problem,
        _seed: u64,
    ) -> Option<Box<dyn VectorCoding<Self>>> {
        None
    }
}

/// A model's genomes as fixed-length vectors of numbers ([`Evolve::vector_coding`]): one
/// entry per parameter, each within its bounds, so that nearby vectors are similar genomes.
pub trait VectorCoding<M: Evolve>: Send + Sync {
    /// Each entry's lower and upper bound (lower ≤ upper).
    fn bounds(&self) -> &[[f64; 2]];

    /// The evolved genome of `x`: one entry per bound, each finite and within its bounds
    /// (the caller checks and clamps). Every such vector decodes to a legal genome.
    fn decode(&self, x: &[f64]) -> <M::Problem as Problem>::Genome;

    /// The vector of `genome` (a genome file of the model), each entry within its bounds:
    /// the nearest the coding holds, so `decode(encode(g))` is `g` for a genome the coding
    /// can express, or the nearest one it can; `Err` says why a genome has no vector here
    /// (another shape than the problem's genomes), naming what differs.
    fn encode(&self, genome: &M::Genome) -> Result<Vec<f64>, String>;
}

/// A match's target outlines as a model may grow into them ([`Evolve::fit_target`]): for
/// each row of the pictures from the foot (row 0) to the top, the stretches of ink seen
/// from the front and from the side, left to right, as shares of the outline's height
/// measured from the foot (negative to the left, or to the back). A row without ink has no
/// stretches.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetProfile {
    /// Rows of the front view, foot to top.
    pub front: Vec<Vec<[f32; 2]>>,
    /// Rows of the side view, foot to top (the front's again when no side view is given:
    /// the front turned a quarter).
    pub side: Vec<Vec<[f32; 2]>>,
}

/// How long one evaluation may take ([`Evolve::evaluation_time`]).
#[derive(Clone, Debug, PartialEq)]
pub struct EvaluationTime {
    /// Seconds on one core, at the settings' bounds.
    pub seconds: f64,
    /// What an evaluation does, naming the settings it follows.
    pub what: String,
    /// What to change to make it shorter.
    pub advice: String,
}

/// What [`Evolve::setup`] makes.
pub struct Setup<M: Evolve> {
    /// The problem.
    pub problem: M::Problem,
    /// Its breeding.
    pub strategy: M::Strategy,
    /// The first members of generation 0; the rest is random.
    pub first: Vec<<M::Problem as Problem>::Genome>,
}

/// Settings that cannot make a run: which field (relative to the model's section, like
/// `breeding`) and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("`{field}`: {message}")]
pub struct ConfigError {
    /// The field, relative to the model's section.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl ConfigError {
    /// An error about `field`.
    pub fn new(field: impl Into<String>, message: impl ToString) -> Self {
        ConfigError {
            field: field.into(),
            message: message.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_most_dominant_parents_are_crossed() {
        let g = [1, 2, 3];
        let parents = |w: [f64; 3]| {
            [0, 1, 2].map(|i| Parent {
                genome: &g[i],
                dominance: w[i],
            })
        };
        assert_eq!(two_most_dominant(&parents([1.0, 5.0, 3.0])), Ok((1, 2)));
        assert_eq!(two_most_dominant(&parents([1.0, 1.0, 1.0])), Ok((0, 1)));
        assert_eq!(
            two_most_dominant(&parents([1.0, -1.0, 1.0])),
            Err(VariationError::BadDominance {
                parent: 1,
                value: -1.0
            })
        );
        assert_eq!(
            two_most_dominant(&parents([1.0, 1.0, 1.0])[..1]),
            Err(VariationError::TooFewParents(1))
        );
    }
}
