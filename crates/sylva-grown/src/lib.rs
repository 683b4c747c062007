//! Self-organising trees: space colonisation of a crown envelope, bud fate by space and
//! light, and the pipe model (Runions, Lane and Prusinkiewicz 2007; Palubicki et al. 2009).
//!
//! Sylva's fifth model, and the first that is not one of the four papers': a tree that
//! grows into the space it is given rather than being drawn by a grammar, so that a crown of
//! any outline is filled by branches that competed for it. Its genome is the growth's
//! parameters (each with a range and a meaning, [`genome::PARAMS`]), the crown's shape and
//! proportions, and the foliage and bark the tree wears; `docs/grown.md` describes the
//! model and its figures.
//!
//! - [`genome`]: [`Growth`], the parameter table, random genomes, mutation and crossover.
//! - [`crown`]: the [`Envelope`] a tree grows into and its attraction points.
//! - [`grow`](mod@grow): the growth itself, [`grow()`] and [`grow_into`], and its [`Report`].
//! - [`problem`]: the `[grown]` settings, the evolution problem, breeding and the vector
//!   coding.
//! - [`GrownModel`]: the model as Sylva's [`Model`] and [`Evolve`].
//!
//! ```
//! use sylva_grown::{Growth, GrownModel};
//! use sylva_model::Model;
//!
//! let genome = Growth::default();
//! let tree = GrownModel.develop(&genome, genome.seed)?;
//! assert!(tree.segments().len() > 100 && !tree.organs().is_empty());
//! # Ok::<(), sylva_model::DevelopError>(())
//! ```

pub mod crown;
pub mod genome;
pub mod grow;
pub mod problem;
pub mod profile;

pub use crown::Envelope;
pub use genome::{CrownShape, Growth, MODEL, PARAMS, Param, ParamSpec, Params};
pub use grow::{MAX_NODES, Report, Stop, grow, grow_into};
pub use problem::{GrownProblem, GrownSettings, GrownStrategy};
pub use profile::{EnvelopeError, Profile};

use rand::{Rng, RngExt};
use sylva_core::Plant;
use sylva_core::dress::Dress;
use sylva_model::{
    Bred, ConfigError, CrossLevel, DevelopError, Evolve, Knobs, Model, Parent, Setup,
    TargetProfile, VariationError, VectorCoding, two_most_dominant,
};

/// Self-organising trees as a Sylva model.
#[derive(Clone, Copy, Debug, Default)]
pub struct GrownModel;

impl Model for GrownModel {
    type Genome = Growth;
    type Settings = GrownSettings;
    const NAME: &'static str = MODEL;
    const TITLE: &'static str = "Self-organising trees";

    fn develop(&self, genome: &Growth, seed: u64) -> Result<Plant, DevelopError> {
        Ok(grow(genome, seed)?.0)
    }

    /// Every parameter and the crown shape, foliage and seed drawn at random; the height
    /// is the default's.
    fn random<R: Rng + ?Sized>(&self, _: &GrownSettings, rng: &mut R) -> Growth {
        let mut g = Growth::random(&Growth::default(), rng);
        let kinds = sylva_core::species::LeafKind::ALL;
        g.foliage = kinds[rng.random_range(0..kinds.len())];
        g
    }

    fn mutate<R: Rng + ?Sized>(&self, g: &Growth, v: &GrownSettings, rng: &mut R) -> Growth {
        let mut g = g.clone();
        g.mutate(v.variation(), rng);
        g
    }

    /// Depth d moves each parameter with probability 0.1·d by 0.05·d of its range (Depth 2
    /// is the default). The level is how often a child's parameter lies between its
    /// parents' rather than being one parent's: never (low: whole values of each), 30%
    /// (medium), 70% (high).
    fn schema(&self) -> sylva_model::schema::Schema {
        genome::schema()
    }

    fn hand_settings(&self, knobs: Knobs, base: GrownSettings) -> GrownSettings {
        let d = f64::from(knobs.depth.get());
        GrownSettings {
            mutation_rate: (0.1 * d).min(1.0),
            mutation_spread: 0.05 * d,
            blend: match knobs.level {
                CrossLevel::Low => 0.0,
                CrossLevel::Medium => 0.3,
                CrossLevel::High => 0.7,
            },
            ..base
        }
    }

    fn cross<R: Rng + ?Sized>(
        &self,
        parents: &[Parent<'_, Growth>],
        v: &GrownSettings,
        rng: &mut R,
    ) -> Result<Bred<Growth>, VariationError> {
        let (a, b) = two_most_dominant(parents)?;
        Ok(Bred {
            genome: Growth::cross(parents[a].genome, parents[b].genome, v.blend, rng),
            parents: vec![a, b],
        })
    }

    fn default_seed(&self, genome: &Growth) -> u64 {
        genome.seed
    }

    fn with_seed(&self, genome: &Growth, seed: u64) -> Growth {
        Growth {
            seed,
            ..genome.clone()
        }
    }

    /// The genome's own foliage and bark.
    fn dress(&self, genome: &Growth) -> Dress {
        Dress {
            bark: genome.bark,
            ..Dress::foliage(genome.foliage)
        }
    }
}

impl Evolve for GrownModel {
    type Problem = GrownProblem;
    type Strategy = GrownStrategy;

    /// Most offspring are small mutants of good trees (an outline is fitted by small
    /// steps), the five best kept.
    fn fitting(&self, settings: &mut GrownSettings) {
        settings.mutation_spread = 0.05;
        settings.breeding = sylva_evolve::GenerationalSettings::mostly_mutants();
    }

    /// Every genome of the run grows into the crown the pictures show: the visual hull of
    /// the front and side outlines above the trunk ([`profile::Profile::from_target`]).
    fn fit_target(
        &self,
        settings: &mut GrownSettings,
        target: &TargetProfile,
    ) -> Result<(), ConfigError> {
        let profile =
            profile::Profile::from_target(target).map_err(|e| ConfigError::new("envelope", e))?;
        settings.envelope = Some(profile);
        Ok(())
    }

    fn start_files(&self, settings: &GrownSettings) -> Vec<std::path::PathBuf> {
        settings.start.clone()
    }

    fn setup(
        &self,
        settings: &GrownSettings,
        start: Vec<Growth>,
        seed: u64,
        population: usize,
    ) -> Result<Setup<Self>, ConfigError> {
        let strategy = problem::strategy(settings).map_err(|e| ConfigError::new("breeding", e))?;
        Ok(Setup {
            problem: GrownProblem {
                settings: settings.clone(),
            },
            strategy,
            first: problem::first_generation(settings, start, seed, population),
        })
    }

    fn genome_file(&self, _problem: &GrownProblem, genome: &Growth) -> Growth {
        genome.clone()
    }

    /// Growing a tree of 20,000 points takes tens of milliseconds; a run's genomes hold
    /// numbers only.
    fn genome_bytes(&self, _settings: &GrownSettings) -> u64 {
        1024
    }

    /// Every parameter, in its own range ([`problem::ParamCoding`]).
    fn vector_coding(
        &self,
        problem: &GrownProblem,
        seed: u64,
    ) -> Option<Box<dyn VectorCoding<Self>>> {
        let template = Growth {
            envelope: problem.settings.envelope.clone(),
            ..Growth::default()
        };
        Some(Box::new(problem::ParamCoding::new(template, seed)))
    }
}
