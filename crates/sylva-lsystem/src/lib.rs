//! Bornhofen and Lattaud's virtual plants: L-system shoots and roots grown in a voxel world
//! of light and minerals by a transport-resistance physiology, bred like biomorphs.
//!
//! Where each element of the paper is in Sylva, and where Sylva chose otherwise and why:
//! `docs/fidelity.md`.
//!
//! - [`grammar`]: the alphabet of Table 1 and rules in the paper's notation.
//! - [`mutate`]: the character and rule operators of section 3.3.
//! - [`interpret`]: strings to sphylls (derivation is kept apart from interpretation).
//! - [`physiology`]: Thornley's two-substrate transport-resistance model.
//! - [`growth`]: one plant growing: apexes paying for their rules, rewriting, re-interpreting.
//! - [`garden`]: plants growing together in a [`sylva_core::environment::Environment`].
//! - [`genome`]: [`LSystemGenome`], its file format and the mutation operator; it grows
//!   alone ([`LSystemGenome::develop`]) as a garden of one, within the time budget.
//! - [`breed`]: the biomorph design loop.
//! - [`problem`]: runs without a person: the model's settings (the `[lsystem]` config) and
//!   an [`sylva_evolve::Problem`] that grows each genome alone and scores it.
//! - [`experiments`]: the paper's two simulations and the run from empty rules.
//! - [`work`]: what growing costs, estimated at the bounds before it starts and held to the
//!   time budget.
//!
//! ```
//! use sylva_lsystem::{LSystemGenome, garden::GrowSettings};
//! use sylva_core::environment::EnvironmentSettings;
//!
//! let bush = LSystemGenome::bush();
//! let small = GrowSettings {
//!     world: EnvironmentSettings { size: [24, 24, 24], soil_layers: 8, ..Default::default() },
//!     steps: 30,
//! };
//! let plant = bush.develop_with(&small, 0)?;
//! assert!(plant.segments().len() > 10);
//! assert!(LSystemGenome::empty().develop_with(&small, 0)?.segments().is_empty());
//! # Ok::<(), sylva_model::DevelopError>(())
//! ```

pub mod breed;
pub mod capabilities;
mod develop;
pub mod experiments;
pub mod garden;
pub mod genome;
pub mod grammar;
pub mod growth;
pub mod interpret;
pub mod mutate;
pub mod physiology;
pub mod problem;
pub mod work;

pub use genome::{CompartmentCrossover, LSystemCrossover, LSystemGenome, LSystemMutation};
pub use problem::{LSystemProblem, LSystemSettings, LSystemStrategy, Score};

use rand::Rng;
use sylva_core::Plant;
use sylva_evolve::{Crossover, Mutate};
use sylva_model::{
    Bred, ConfigError, CrossLevel, DevelopError, EvaluationTime, Evolve, Knobs, MeshHint, Model,
    Parent, Setup, VariationError, two_most_dominant,
};

/// Bornhofen and Lattaud's virtual plants as a Sylva model. A genome grows alone in the
/// default world ([`garden::GrowSettings::default`]); its modules are sphylls.
#[derive(Clone, Copy, Debug, Default)]
pub struct LSystemModel;

impl Model for LSystemModel {
    type Genome = LSystemGenome;
    type Settings = LSystemSettings;
    const NAME: &'static str = genome::MODEL;
    const TITLE: &'static str = "L-system plants (Bornhofen and Lattaud)";

    fn develop(&self, genome: &LSystemGenome, seed: u64) -> Result<Plant, DevelopError> {
        genome.develop(seed)
    }

    /// A random genome built to grow ([`LSystemGenome::random_growing`]). A run's random
    /// genomes are the paper's instead: `random_rounds` mutations of its `start`.
    fn random<R: Rng + ?Sized>(&self, _: &LSystemSettings, rng: &mut R) -> LSystemGenome {
        LSystemGenome::random_growing(rng)
    }

    /// The paper's character and rule mutations at the settings' rates.
    fn mutate<R: Rng + ?Sized>(
        &self,
        genome: &LSystemGenome,
        s: &LSystemSettings,
        rng: &mut R,
    ) -> LSystemGenome {
        let mut child = genome.clone();
        s.mutation().mutate(&mut child, rng);
        child
    }

    /// The settings' crossover of the two most dominant parents.
    fn cross<R: Rng + ?Sized>(
        &self,
        parents: &[Parent<'_, LSystemGenome>],
        s: &LSystemSettings,
        rng: &mut R,
    ) -> Result<Bred<LSystemGenome>, VariationError> {
        let (a, b) = two_most_dominant(parents)?;
        Ok(Bred {
            genome: s
                .crossover
                .crossover(parents[a].genome, parents[b].genome, rng),
            parents: vec![a, b],
        })
    }

    /// Depth d multiplies every mutation probability by d/2 (at most 1: Depth 2 is the
    /// paper's rates; Depth 10, five times as many changes). The level: low takes both
    /// L-systems from one parent and the angles and module shapes from the other, medium
    /// each compartment whole from either (the default), high each rule, axiom, angle and
    /// module shape from either.
    fn schema(&self) -> sylva_model::schema::Schema {
        genome::schema()
    }

    fn hand_settings(&self, knobs: Knobs, base: LSystemSettings) -> LSystemSettings {
        LSystemSettings {
            rates: base.rates.scaled(knobs.depth.scale()),
            crossover: match knobs.level {
                CrossLevel::Low => LSystemCrossover::Halves,
                CrossLevel::Medium => LSystemCrossover::Compartments,
                CrossLevel::High => LSystemCrossover::Rules,
            },
            ..base
        }
    }

    fn mesh_hint(&self) -> MeshHint {
        MeshHint { round_caps: true }
    }

    /// The work of growing it alone in the default world ([`work`]).
    fn growth_seconds(&self, genome: &LSystemGenome) -> Option<f64> {
        let grow = garden::GrowSettings::default();
        let sowing = garden::Sowing::new(genome.clone(), sylva_core::glam::Vec2::ZERO);
        Some(work::garden(&grow.world, &[sowing], grow.steps, work::Rules::Known).seconds(1))
    }
}

impl Evolve for LSystemModel {
    type Problem = LSystemProblem;
    type Strategy = LSystemStrategy;

    fn start_files(&self, settings: &LSystemSettings) -> Vec<std::path::PathBuf> {
        settings.start.iter().cloned().collect()
    }

    fn setup(
        &self,
        settings: &LSystemSettings,
        start: Vec<LSystemGenome>,
        _seed: u64,
        _population: usize,
    ) -> Result<Setup<Self>, ConfigError> {
        // Every genome grows in this world: one that cannot be built would fail them all.
        settings
            .grow
            .world
            .validate()
            .map_err(|e| ConfigError::new("grow.world", e))?;
        let start = start
            .into_iter()
            .next()
            .unwrap_or_else(LSystemGenome::empty);
        start
            .physiology
            .validate()
            .map_err(|e| ConfigError::new("start", e))?;
        let (problem, strategy) = settings
            .run(start)
            .map_err(|e| ConfigError::new("breeding", e))?;
        Ok(Setup {
            problem,
            strategy,
            first: Vec::new(),
        })
    }

    fn genome_file(&self, _problem: &LSystemProblem, genome: &LSystemGenome) -> LSystemGenome {
        genome.clone()
    }

    /// One genome grown alone for the settings' steps, at the start genome's bounds (its
    /// physiology stays over the run) with any rules and module sizes mutation may give it.
    fn evaluation_time(
        &self,
        settings: &LSystemSettings,
        start: Option<&LSystemGenome>,
    ) -> Option<EvaluationTime> {
        let empty = LSystemGenome::empty();
        let start = start.unwrap_or(&empty);
        let grow = &settings.grow;
        let sowing = garden::Sowing::new(start.clone(), sylva_core::glam::Vec2::ZERO);
        let work = work::garden(&grow.world, &[sowing], grow.steps, work::Rules::Any);
        Some(EvaluationTime {
            seconds: work.seconds(1),
            what: format!(
                "growing {} steps (`[lsystem.grow] steps`) in a world of {:?} voxels, up to {}",
                grow.steps,
                grow.world.size,
                work::bounds(&start.physiology)
            ),
            advice: "lower `max_symbols` and `max_modules` in the start genome's `physiology`, \
                     the steps or the world, or breed a smaller `population`"
                .into(),
        })
    }
}
