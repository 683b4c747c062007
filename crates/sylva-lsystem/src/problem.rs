//! L-system plants evolved without a person: the model's settings (the `[lsystem]` section
//! of an evolution config), each genome grown alone in the voxel world and scored by its
//! biomass or the light it captured, and breeding by mutation (the paper's) with optional
//! compartment crossover.

use std::path::PathBuf;

use rand::Rng;
use serde::{Deserialize, Serialize};
use sylva_core::glam::Vec2;
use sylva_core::par::Pool;
use sylva_evolve::{
    Fitness, Generational, GenerationalError, GenerationalSettings, Mutate, Problem,
};

use crate::breed::SpecimenStats;
use crate::garden::{Garden, GrowSettings, Sowing};
use crate::genome::{LSystemCrossover, LSystemGenome, LSystemMutation};
use crate::grammar::Module;
use crate::mutate::MutationRates;

/// The L-system model's settings: how random genomes are made and genomes mutated, and
/// for runs without a person, where they start, the world they grow in, what is selected
/// and the breeding. The paper breeds by mutation alone, so the default breeding has no
/// crossover.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LSystemSettings {
    /// Genome the first generation grows out of, relative to the config file. Default:
    /// empty rules (the paper's start, which does not germinate).
    pub start: Option<PathBuf>,
    /// What to select for: `"biomass"` or `"light"`. Default biomass.
    pub score: Score,
    /// Rounds of mutation that make a random genome from the start, 0 to 1000. Default 10.
    #[serde(deserialize_with = "random_rounds")]
    pub random_rounds: u32,
    /// Mutation probabilities (section 3.3).
    pub rates: MutationRates,
    /// How crossover mixes two plants: `"halves"`, `"compartments"` or `"rules"`. Default
    /// compartments.
    #[serde(skip_serializing_if = "is_compartments")]
    pub crossover: LSystemCrossover,
    /// World and time each genome grows in.
    pub grow: GrowSettings,
    /// Tournament selection and operator rates. Default: no crossover, 20% reproduction,
    /// 80% mutation, elitism 1.
    pub breeding: GenerationalSettings,
}

sylva_core::ranged!(random_rounds: u32, "random_rounds", 0, 1000);

/// The default crossover stays out of written configs, which keep their bytes.
fn is_compartments(crossover: &LSystemCrossover) -> bool {
    *crossover == LSystemCrossover::Compartments
}

impl Default for LSystemSettings {
    fn default() -> Self {
        LSystemSettings {
            start: None,
            score: Score::Biomass,
            random_rounds: 10,
            rates: MutationRates::default(),
            crossover: LSystemCrossover::Compartments,
            grow: GrowSettings::default(),
            breeding: GenerationalSettings {
                crossover: 0.0,
                reproduction: 0.2,
                mutation: 0.8,
                ..Default::default()
            },
        }
    }
}

impl LSystemSettings {
    /// The mutation operator: rules and characters, and with the `mutate_parameter` rate a
    /// nudge of the shapes and angles at the default scale.
    pub fn mutation(&self) -> LSystemMutation {
        LSystemMutation {
            rates: self.rates,
            parameter_scale: 0.0,
        }
    }

    /// The problem and breeding of a run from `start` (the genome of `self.start`, or
    /// [`LSystemGenome::empty`]).
    pub fn run(
        &self,
        start: LSystemGenome,
    ) -> Result<(LSystemProblem, LSystemStrategy), GenerationalError> {
        let mutation = self.mutation();
        let problem = LSystemProblem {
            grow: self.grow,
            score: self.score,
            start,
            random_rounds: self.random_rounds,
            mutation,
        };
        let strategy = Generational::new(self.crossover, mutation, self.breeding.clone())?;
        Ok((problem, strategy))
    }
}

/// L-system breeding: mutation (and, if asked, compartment crossover).
pub type LSystemStrategy = Generational<LSystemCrossover, LSystemMutation>;

/// What [`LSystemProblem`] selects for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Score {
    /// Biomass (dry mass: structure and pools) at the end.
    #[default]
    Biomass,
    /// Light absorbed over the plant's life.
    Light,
}

/// Evolving L-system plants without a person: each genome is grown alone and scored.
#[derive(Clone, Debug, PartialEq)]
pub struct LSystemProblem {
    /// World and time each genome grows in.
    pub grow: GrowSettings,
    /// What the total is.
    pub score: Score,
    /// Where random genomes start from ([`LSystemGenome::empty`] in the paper).
    pub start: LSystemGenome,
    /// How random genomes are made from `start`: this many rounds of mutation.
    pub random_rounds: u32,
    /// The operators used to make random genomes.
    pub mutation: LSystemMutation,
}

impl Default for LSystemProblem {
    fn default() -> Self {
        LSystemProblem {
            grow: GrowSettings::default(),
            score: Score::Biomass,
            start: LSystemGenome::empty(),
            random_rounds: 10,
            mutation: LSystemMutation::default(),
        }
    }
}

impl LSystemProblem {
    /// Grows `genome` alone; `None` when it cannot grow (bad physiology or world).
    pub fn grow(&self, genome: &LSystemGenome) -> Option<SpecimenStats> {
        let mut garden = Garden::new(
            self.grow.world,
            vec![Sowing::new(genome.clone(), Vec2::ZERO)],
        )
        .ok()?;
        garden.run(self.grow.steps, &Pool::Serial).ok()?;
        Some(SpecimenStats::of(&garden.plants()[0]))
    }
}

impl Problem for LSystemProblem {
    type Genome = LSystemGenome;

    fn term_names(&self) -> Vec<String> {
        [
            "biomass",
            "light",
            "uptake",
            "leaves",
            "fine_roots",
            "modules",
        ]
        .map(String::from)
        .to_vec()
    }

    fn evaluate(&self, genome: &LSystemGenome) -> Fitness {
        let Some(s) = self.grow(genome) else {
            return Fitness::new(f64::NEG_INFINITY, &[]);
        };
        let total = match self.score {
            Score::Biomass => s.biomass,
            Score::Light => s.light,
        };
        let modules: u32 = s.modules.iter().sum();
        Fitness::new(
            total,
            &[
                s.biomass,
                s.light,
                s.uptake,
                f64::from(s.modules[Module::Leaf.index()]),
                f64::from(s.modules[Module::FineRoot.index()]),
                f64::from(modules),
            ],
        )
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> LSystemGenome {
        let mut g = self.start.clone();
        for _ in 0..self.random_rounds {
            self.mutation.mutate(&mut g, rng);
        }
        g
    }
}
