//! The binary tree as an evolution problem: Susinno's GA on a bit string, scored by his six
//! weighted tree measures computed analytically (no plant is built per evaluation).

use rand::Rng;
use sylva_evolve::bits::{BitFlip, OnePoint, Uniform};
use sylva_evolve::{Crossover, Fitness, MeanReplacement, Problem};
use sylva_fitness::{SusinnoWeights, tree::TERM_NAMES};
use sylva_models::Genome;
use sylva_models::bintree::{BITS, BinTree, Bits};

use crate::config::{BinTreeConfig, CrossoverKind};

/// What `sylva evolve` needs from a problem besides the engine's [`Problem`]: how an evolved
/// genome becomes a genome file (to grow, export and picture it) and what to call the run.
pub trait ModelProblem: Problem {
    /// The genome file an evolved genome stands for.
    fn genome_file(&self, genome: &Self::Genome) -> Genome;
    /// A short title for plots, e.g. "Binary trees".
    fn title(&self) -> &'static str;
}

impl ModelProblem for BinTreeProblem {
    fn genome_file(&self, bits: &Bits) -> Genome {
        Genome::BinTree(self.decode(bits))
    }

    fn title(&self) -> &'static str {
        "Binary trees"
    }
}

/// Evolve binary trees towards Susinno's weighted fitness.
#[derive(Clone, Debug, PartialEq)]
pub struct BinTreeProblem {
    /// Minimum radius copied into every genome, metres.
    pub min_radius: f64,
    /// Fitness weights.
    pub weights: SusinnoWeights,
}

impl BinTreeProblem {
    /// The problem a config describes.
    pub fn new(config: &BinTreeConfig) -> Self {
        BinTreeProblem {
            min_radius: config.min_radius,
            weights: config.weights,
        }
    }

    /// The genome a bit string stands for.
    pub fn decode(&self, bits: &Bits) -> BinTree {
        BinTree::decode(bits, self.min_radius)
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
        Bits::random(BITS, rng).expect("the layout fits its bit string")
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

/// The strategy a config describes.
pub fn strategy(config: &BinTreeConfig) -> BinTreeStrategy {
    MeanReplacement {
        crossover: BitCrossover(config.crossover),
        mutation: BitFlip {
            rate: config.mutation_rate,
        },
        cull_clones: config.cull_clones,
    }
}
