//! PlantMaker evolved without a person: the model's settings (the `[plantmaker]` section of
//! an evolution config), genomes grown with their own seed and scored by Poncin's shared
//! terms over the grown plant, and generational breeding with the paper's crossover and
//! mutation. The first generation may start from genomes a person chose, as the paper's
//! users do, and mutants of them.

use std::cell::RefCell;
use std::path::PathBuf;

use rand::Rng;
use serde::{Deserialize, Serialize};
use sylva_core::glam::DVec3;
use sylva_evolve::{
    Fitness, Generational, GenerationalError, GenerationalSettings, Mutate, Problem,
};
use sylva_fitness::poncin::{PoncinContext, TERM_NAMES, TargetShape};
use sylva_fitness::{PoncinFitness, PoncinScratch};

use crate::PlantMaker;
use crate::palette::{Painted, Palette};
use crate::variation::{Level, Mutation, PlantMakerCrossover};

/// PlantMaker's settings: genome sizes, the crossover level and mutation, and for runs
/// without a person, start genomes, breeding and a fitness from the shared terms (by
/// default: endpoints on a 1 m sphere centred 1.2 m up, about 30 branch endpoints, spread;
/// lengths in metres, so `fitness.unit` is 1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlantMakerSettings {
    /// Branch prototypes per random genome, 1 to 32. Default 5.
    #[serde(deserialize_with = "segment_count")]
    pub branches: u32,
    /// Fans per random genome, 1 to 32. Default 5.
    #[serde(deserialize_with = "segment_count")]
    pub fans: u32,
    /// Inflorescences per random genome, 1 to 32. Default 5.
    #[serde(deserialize_with = "segment_count")]
    pub inflorescences: u32,
    /// Crossover level: low, medium or high. Default medium.
    pub crossover: Level,
    /// Probability that a variable changes in a mutation, 0 to 1. Default 0.1.
    #[serde(deserialize_with = "mutation_rate")]
    pub mutation_rate: f64,
    /// Mutation noise as a fraction of a variable's range, 0 to 1. Default 0.15.
    #[serde(deserialize_with = "mutation_spread")]
    pub mutation_spread: f64,
    /// The colours random genomes and offspring give their fans: `any` (the paper's, the
    /// default) or `foliage` (leaf greens and bark browns; what a match of an outline, which
    /// cannot see colour, breeds with).
    pub palette: Palette,
    /// Genome files the first generation starts from, relative to the config file (the
    /// paper's users start from plants they chose); the rest of it is their mutants. Empty
    /// (the default): a random first generation.
    pub start: Vec<PathBuf>,
    /// Tournament selection and operator rates.
    pub breeding: GenerationalSettings,
    /// The fitness (Poncin's terms over the grown plant).
    pub fitness: PoncinFitness,
}

sylva_core::ranged!(segment_count: u32, "segment count", 1, 32);
sylva_core::ranged!(mutation_rate: f64, "mutation_rate", 0.0, 1.0);
sylva_core::ranged!(mutation_spread: f64, "mutation_spread", 0.0, 1.0);

impl Default for PlantMakerSettings {
    fn default() -> Self {
        let mut fitness = PoncinFitness {
            unit: 1.0,
            ..Default::default()
        };
        fitness.target = TargetShape::Sphere {
            center: DVec3::new(0.0, 1.2, 0.0),
            radius: 1.0,
        };
        PlantMakerSettings {
            branches: 5,
            fans: 5,
            inflorescences: 5,
            crossover: Level::Medium,
            mutation_rate: 0.1,
            mutation_spread: 0.15,
            palette: Palette::Any,
            start: Vec::new(),
            breeding: GenerationalSettings::default(),
            fitness,
        }
    }
}

impl PlantMakerSettings {
    /// The mutation operator.
    pub fn mutation(&self) -> Mutation {
        Mutation {
            rate: self.mutation_rate,
            spread: self.mutation_spread,
        }
    }

    /// A random genome of the settings' sizes, its fans coloured from the palette.
    pub fn random<R: Rng + ?Sized>(&self, rng: &mut R) -> PlantMaker {
        let mut genome = PlantMaker::random(
            self.branches as usize,
            self.fans as usize,
            self.inflorescences as usize,
            rng,
        );
        self.palette.apply(&mut genome);
        genome
    }
}

/// Evolve PlantMaker genomes without a person, towards Poncin's shared terms over the grown
/// plant (a target shape, a number of endpoints, spread, and a density grid of leaves).
#[derive(Clone, Debug)]
pub struct PlantMakerProblem {
    /// Genome sizes and operators.
    pub settings: PlantMakerSettings,
    /// The segment counts (branches, fans, inflorescences) of the start genomes, each once:
    /// a run's offspring take theirs from their parents, so these are every genome's (the
    /// settings' when there are none).
    pub start_counts: Vec<[usize; 3]>,
}

thread_local! {
    /// Per-thread fitness buffers; they carry nothing between evaluations.
    static SCRATCH: RefCell<PoncinScratch> = RefCell::new(PoncinScratch::new());
}

impl Problem for PlantMakerProblem {
    type Genome = PlantMaker;

    fn term_names(&self) -> Vec<String> {
        TERM_NAMES.iter().map(|s| (*s).to_owned()).collect()
    }

    /// Grows the genome with its own seed; a genome that fails to grow (too large) scores
    /// the worst fitness.
    fn evaluate(&self, genome: &PlantMaker) -> Fitness {
        let Ok(plant) = genome.develop(genome.seed) else {
            return Fitness::new(0.0, &[]);
        };
        SCRATCH.with(|cell| {
            let ctx = PoncinContext {
                seed: 0,
                negative_thickness: 0,
            };
            let score = self
                .settings
                .fitness
                .score(&plant, ctx, &mut cell.borrow_mut());
            Fitness::new(score.adjusted(), &score.terms())
        })
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> PlantMaker {
        self.settings.random(rng)
    }
}

/// PlantMaker breeding with the configured crossover level and mutation, the offspring
/// coloured from the palette.
pub type PlantMakerStrategy = Generational<Painted<PlantMakerCrossover>, Painted<Mutation>>;

/// The breeding the settings describe.
pub fn strategy(settings: &PlantMakerSettings) -> Result<PlantMakerStrategy, GenerationalError> {
    let palette = settings.palette;
    Generational::new(
        Painted {
            operator: PlantMakerCrossover {
                level: settings.crossover,
            },
            palette,
        },
        Painted {
            operator: settings.mutation(),
            palette,
        },
        settings.breeding.clone(),
    )
}

/// The first generation of a run: each chosen genome, then mutants of them in turn, up to
/// `population`, drawn from the stream `(seed, 0, u32::MAX)` (no individual's slot).
pub fn first_generation(
    settings: &PlantMakerSettings,
    chosen: Vec<PlantMaker>,
    seed: u64,
    population: usize,
) -> Vec<PlantMaker> {
    if chosen.is_empty() {
        return chosen;
    }
    let mutation = settings.mutation();
    let mut rng = sylva_core::rng::stream(seed, 0, u32::MAX);
    let mut start = chosen.clone();
    while start.len() < population {
        // A population of millions takes seconds to make: a front end's stop is heard.
        if start.len().is_multiple_of(4096) {
            sylva_core::par::stop_point();
        }
        let mut g = chosen[start.len() % chosen.len()].clone();
        mutation.mutate(&mut g, &mut rng);
        settings.palette.apply(&mut g);
        start.push(g);
    }
    start
}
