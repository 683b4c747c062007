//! The binary tree as an evolution problem: Susinno's GA on a bit string, scored by his six
//! weighted tree measures computed analytically (no plant is built per evaluation).
//!
//! The `[bintree]` section of an evolution config:
//!
//! ```toml
//! [bintree]
//! min_radius = 0.02          # metres; no cylinder is thinner
//! mutation_rate = 0.02       # probability of flipping each bit of a child
//! crossover = "one_point"    # or "uniform"
//! cull_clones = true         # replace copies of a genome (false: the paper's step)
//!
//! [bintree.weights]          # Susinno's fitness weights
//! surface_to_volume = 0.02
//! symmetry = 1.0
//! radius_to_length = 2.0
//! volume = 1.0
//! height = 0.5
//! straightness = 1.0
//! ```

use rand::Rng;
use serde::{Deserialize, Serialize};
use sylva_evolve::bits::{BitFlip, OnePoint, Uniform};
use sylva_evolve::{Crossover, Fitness, MeanReplacement, Problem};
use sylva_fitness::{SusinnoWeights, tree::TERM_NAMES};

use crate::genome::{BITS, BinTree, Bits};

/// How binary trees are crossed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CrossoverKind {
    /// One cut point.
    #[default]
    OnePoint,
    /// Each bit from either parent.
    Uniform,
}

/// The binary tree's settings, the `[bintree]` section of an evolution config: the minimum
/// radius, the genetic algorithm's operators and the fitness weights.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BinTreeSettings {
    /// No cylinder is thinner, metres, 0.001 to 1. Default 0.02.
    #[serde(deserialize_with = "min_radius")]
    pub min_radius: f64,
    /// Probability of flipping each bit of a child, 0 to 1. Default 0.02.
    #[serde(deserialize_with = "mutation_rate")]
    pub mutation_rate: f64,
    /// Crossover of the two best trees. Default one-point.
    pub crossover: CrossoverKind,
    /// Replace copies of an earlier member's genome, so a converged population keeps
    /// searching (Sylva's addition; `false` is the paper's step). Default true.
    pub cull_clones: bool,
    /// Fitness weights.
    pub weights: SusinnoWeights,
}

impl Default for BinTreeSettings {
    fn default() -> Self {
        BinTreeSettings {
            min_radius: 0.02,
            mutation_rate: 0.02,
            crossover: CrossoverKind::OnePoint,
            cull_clones: true,
            weights: SusinnoWeights::default(),
        }
    }
}

sylva_core::ranged!(min_radius: f64, "min_radius", 0.001, 1.0, " m");
sylva_core::ranged!(mutation_rate: f64, "mutation_rate", 0.0, 1.0);

/// Evolve binary trees towards Susinno's weighted fitness.
#[derive(Clone, Debug, PartialEq)]
pub struct BinTreeProblem {
    /// Minimum radius copied into every genome, metres.
    pub min_radius: f64,
    /// Fitness weights.
    pub weights: SusinnoWeights,
}

impl BinTreeProblem {
    /// A problem with the default weights and the given minimum radius.
    pub fn new(min_radius: f64) -> Self {
        BinTreeProblem {
            min_radius,
            weights: SusinnoWeights::default(),
        }
    }

    /// The problem the settings describe.
    pub fn from_settings(settings: &BinTreeSettings) -> Self {
        BinTreeProblem {
            min_radius: settings.min_radius,
            weights: settings.weights,
        }
    }

    /// The genome a bit string stands for.
    pub fn decode(&self, bits: &Bits) -> BinTree {
        BinTree::decode(bits, self.min_radius)
    }

    /// A random bit string of the layout's length.
    pub fn random_bits<R: Rng + ?Sized>(rng: &mut R) -> Bits {
        Bits::random(BITS, rng).expect("the layout fits its bit string")
    }
}

impl Problem for BinTreeProblem {
    type Genome = Bits;

    fn term_names(&self) -> Vec<String> {
        TERM_NAMES.iter().map(|s| (*s).to_owned()).collect()
    }

    fn evaluate(&self, bits: &Bits) -> Fitness {
        let score = self.weights.score(&self.decode(bits).measures());
        Fitness::new(score.total, &score.terms)
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> Bits {
        Self::random_bits(rng)
    }
}

/// The crossover a config names.
#[derive(Clone, Copy, Debug)]
pub struct BitCrossover(pub CrossoverKind);

impl Crossover<Bits> for BitCrossover {
    fn crossover<R: Rng + ?Sized>(&self, a: &Bits, b: &Bits, rng: &mut R) -> Bits {
        match self.0 {
            CrossoverKind::OnePoint => OnePoint.crossover(a, b, rng),
            CrossoverKind::Uniform => Uniform.crossover(a, b, rng),
        }
    }
}

/// Susinno's generation step with the configured operators.
pub type BinTreeStrategy = MeanReplacement<BitCrossover, BitFlip>;

/// The strategy the settings describe.
pub fn strategy(settings: &BinTreeSettings) -> BinTreeStrategy {
    MeanReplacement {
        crossover: BitCrossover(settings.crossover),
        mutation: BitFlip {
            rate: settings.mutation_rate,
        },
        cull_clones: settings.cull_clones,
    }
}
