//! Self-organising trees evolved without a person: the model's settings (the `[grown]`
//! section of an evolution config), genomes grown with their own seed and scored by
//! Poncin's shared terms over the grown tree, generational breeding with the genome's own
//! mutation and crossover, and genomes as vectors for optimisers outside Sylva.
//!
//! ```toml
//! [grown]
//! mutation_rate = 0.2     # probability that each parameter (and the crown shape) moves
//! mutation_spread = 0.1   # a move's spread, as a share of the parameter's range
//! blend = 0.3             # probability that a child's parameter lies between its parents'
//! start = []              # genome files the first generation starts from (and mutants)
//! ```

use std::path::PathBuf;

use rand::Rng;
use serde::{Deserialize, Serialize};
use sylva_core::glam::DVec3;
use sylva_evolve::{
    Crossover, Fitness, Generational, GenerationalError, GenerationalSettings, Mutate, Problem,
};
use sylva_fitness::PoncinFitness;
use sylva_fitness::poncin::{NumTarget, PoncinContext, TERM_NAMES, TargetShape};
use sylva_model::VectorCoding;

use crate::GrownModel;
use crate::genome::{Growth, PARAMS, Params, Variation};
use crate::profile::Profile;

/// The self-organising model's settings: how genomes are varied, the first generation,
/// breeding and the fitness (by default: twig tips on a sphere of 4.5 m centred 8 m up,
/// about 400 of them, spread; lengths in metres).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GrownSettings {
    /// Probability that each parameter (and the crown shape) changes in a mutation, 0 to 1.
    /// Default 0.2.
    #[serde(deserialize_with = "rate")]
    pub mutation_rate: f64,
    /// A change's spread as a share of the parameter's range, 0 to 1. Default 0.1.
    #[serde(deserialize_with = "spread")]
    pub mutation_spread: f64,
    /// Probability that a child's parameter lies between its parents' rather than being
    /// one parent's, 0 to 1. Default 0.3.
    #[serde(deserialize_with = "blend")]
    pub blend: f64,
    /// Genome files the first generation starts from, relative to the config file; the
    /// rest of it is their mutants. Empty (the default): a random first generation.
    pub start: Vec<PathBuf>,
    /// Tournament selection and operator rates.
    pub breeding: GenerationalSettings,
    /// The fitness (Poncin's terms over the grown tree).
    pub fitness: PoncinFitness,
    /// The crown a match's pictures show, which every genome of the run grows into
    /// ([`GrownModel::fit_target`](sylva_model::Evolve::fit_target)); never in a file.
    #[serde(skip)]
    pub envelope: Option<Profile>,
}

sylva_core::ranged!(rate: f64, "mutation_rate", 0.0, 1.0);
sylva_core::ranged!(spread: f64, "mutation_spread", 0.0, 1.0);
sylva_core::ranged!(blend: f64, "blend", 0.0, 1.0);

impl Default for GrownSettings {
    fn default() -> Self {
        let mut fitness = PoncinFitness {
            unit: 1.0,
            ..PoncinFitness::default()
        };
        fitness.target = TargetShape::Sphere {
            center: DVec3::new(0.0, 8.0, 0.0),
            radius: 4.5,
        };
        fitness.num_target = NumTarget::Total(400);
        GrownSettings {
            mutation_rate: 0.2,
            mutation_spread: 0.1,
            blend: 0.3,
            start: Vec::new(),
            breeding: GenerationalSettings::default(),
            fitness,
            envelope: None,
        }
    }
}

impl GrownSettings {
    /// The mutation.
    pub fn variation(&self) -> Variation {
        Variation {
            rate: self.mutation_rate,
            spread: self.mutation_spread,
        }
    }
}

/// The genome's mutation as an operator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrownMutation(pub Variation);

impl Mutate<Growth> for GrownMutation {
    fn mutate<R: Rng + ?Sized>(&self, genome: &mut Growth, rng: &mut R) {
        genome.mutate(self.0, rng);
    }
}

/// The genome's crossover as an operator: parameters from either parent, or between them
/// with probability `blend`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrownCrossover {
    /// Probability of a blended parameter.
    pub blend: f64,
}

impl Crossover<Growth> for GrownCrossover {
    fn crossover<R: Rng + ?Sized>(&self, a: &Growth, b: &Growth, rng: &mut R) -> Growth {
        Growth::cross(a, b, self.blend, rng)
    }
}

/// Generational breeding with the genome's own operators.
pub type GrownStrategy = Generational<GrownCrossover, GrownMutation>;

/// The breeding the settings describe.
pub fn strategy(settings: &GrownSettings) -> Result<GrownStrategy, GenerationalError> {
    Generational::new(
        GrownCrossover {
            blend: settings.blend,
        },
        GrownMutation(settings.variation()),
        settings.breeding.clone(),
    )
}

thread_local! {
    /// Per-thread fitness buffers, as PlantMaker's problem keeps them; they carry nothing
    /// between evaluations.
    static SCRATCH: std::cell::RefCell<sylva_fitness::PoncinScratch> =
        std::cell::RefCell::new(sylva_fitness::PoncinScratch::new());
}

/// Evolve self-organising trees towards Poncin's shared terms over the grown tree.
#[derive(Clone, Debug)]
pub struct GrownProblem {
    /// The settings.
    pub settings: GrownSettings,
}

impl Problem for GrownProblem {
    type Genome = Growth;

    fn term_names(&self) -> Vec<String> {
        TERM_NAMES.iter().map(|s| (*s).to_owned()).collect()
    }

    /// Grows the genome with its own seed; a genome that cannot grow (an envelope with no
    /// room, a tree past the bound) scores the worst fitness.
    fn evaluate(&self, genome: &Growth) -> Fitness {
        let Ok((plant, _)) = crate::grow::grow(genome, genome.seed) else {
            return Fitness::new(0.0, &[]);
        };
        let ctx = PoncinContext {
            seed: 0,
            negative_thickness: 0,
        };
        SCRATCH.with(|cell| {
            let score = self
                .settings
                .fitness
                .score(&plant, ctx, &mut cell.borrow_mut());
            Fitness::new(score.adjusted(), &score.terms())
        })
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> Growth {
        let mut genome = Growth::random(&Growth::default(), rng);
        genome.envelope.clone_from(&self.settings.envelope);
        genome
    }
}

/// The first generation of a run: each chosen genome, then mutants of them in turn, up to
/// `population`, drawn from the stream `(seed, 0, u32::MAX)`.
pub fn first_generation(
    settings: &GrownSettings,
    chosen: Vec<Growth>,
    seed: u64,
    population: usize,
) -> Vec<Growth> {
    if chosen.is_empty() {
        return chosen;
    }
    let mut chosen = chosen;
    if settings.envelope.is_some() {
        for genome in &mut chosen {
            genome.envelope.clone_from(&settings.envelope);
        }
    }
    let mut rng = sylva_core::rng::stream(seed, 0, u32::MAX);
    let mut first = chosen.clone();
    while first.len() < population {
        let mut g = chosen[first.len() % chosen.len()].clone();
        g.mutate(settings.variation(), &mut rng);
        first.push(g);
    }
    first
}

/// Genomes as vectors of their parameters, one entry each in its own range; the crown
/// shape, foliage and bark are the template's, and decoded genomes grow with the coding's
/// seed.
#[derive(Clone, Debug)]
pub struct ParamCoding {
    template: Growth,
    bounds: Vec<[f64; 2]>,
}

impl ParamCoding {
    /// The coding of genomes like `template`, decoded with seed `seed`.
    pub fn new(template: Growth, seed: u64) -> ParamCoding {
        ParamCoding {
            template: Growth { seed, ..template },
            bounds: PARAMS.iter().map(|p| [p.min, p.max]).collect(),
        }
    }
}

impl VectorCoding<GrownModel> for ParamCoding {
    fn bounds(&self) -> &[[f64; 2]] {
        &self.bounds
    }

    fn decode(&self, x: &[f64]) -> Growth {
        let mut parameters = Params::default();
        for (i, &v) in x.iter().enumerate().take(PARAMS.len()) {
            parameters.set_at(i, v);
        }
        Growth {
            parameters,
            ..self.template.clone()
        }
    }

    fn encode(&self, genome: &Growth) -> Result<Vec<f64>, String> {
        Ok(genome.parameters.values().to_vec())
    }
}
