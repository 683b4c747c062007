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
//! geometry = "sylva"         # or "paper": the pseudo-code's cylinders and the paper's reach
//! symmetry = "mirror"        # or "paper": the two rotations' angles and axes match
//! straightness = "bend"      # or "paper": 1 / mean rotation angle
//! height = "skeleton"        # or "paper": from the sines of the rotation angles
//!
//! [bintree.weights]          # Susinno's six weights and Sylva's two (the defaults)
//! surface_to_volume = 0.02
//! symmetry = 4.0
//! radius_to_length = 0.05
//! volume = 0.1
//! height = 1.5
//! straightness = 2.0
//! pipe_model = 3.0           # 0 for the paper's fitness
//! roundness = 3.0            # 0 for the paper's fitness
//! ```

use rand::Rng;
use serde::{Deserialize, Serialize};
use sylva_core::TreeMeasures;
use sylva_evolve::bits::{BitFlip, OnePoint, Uniform};
use sylva_evolve::{Crossover, Fitness, MeanReplacement, Problem};
use sylva_fitness::{SusinnoWeights, tree::TERM_NAMES};

use crate::genome::{BinTree, Bits, Geometry};

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

/// Which straightness a run scores.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Straightness {
    /// Sylva's: `1 − mean bend / 180°` over every child cylinder, 0 to 1, the same measure
    /// read off any plant.
    #[default]
    Bend,
    /// The paper's: inversely proportional to the mean rotation angle
    /// ([`BinTree::paper_straightness`]).
    Paper,
}

/// Which symmetry a run scores.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Symmetry {
    /// Sylva's: the two children mirror each other across the parent's axis, read off the
    /// fork as off any plant's.
    #[default]
    Mirror,
    /// The paper's: the two rotations' angles and axes match ([`BinTree::paper_symmetry`]).
    Paper,
}

/// Which height a run scores.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Height {
    /// Sylva's: the skeleton's highest point, the same measure read off any plant.
    #[default]
    Skeleton,
    /// The paper's: from the sines of the rotation angles ([`BinTree::paper_height`]).
    Paper,
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
    /// Sylva's geometry and search ranges (default) or the paper's.
    #[serde(skip_serializing_if = "is_default")]
    pub geometry: Geometry,
    /// Sylva's symmetry (default) or the paper's.
    #[serde(skip_serializing_if = "is_default")]
    pub symmetry: Symmetry,
    /// Sylva's straightness (default) or the paper's.
    #[serde(skip_serializing_if = "is_default")]
    pub straightness: Straightness,
    /// Sylva's height (default) or the paper's.
    #[serde(skip_serializing_if = "is_default")]
    pub height: Height,
}

/// Settings at their defaults stay out of written configs, which keep their bytes.
fn is_default<T: Default + PartialEq>(value: &T) -> bool {
    *value == T::default()
}

impl Default for BinTreeSettings {
    fn default() -> Self {
        BinTreeSettings {
            min_radius: 0.02,
            mutation_rate: 0.02,
            crossover: CrossoverKind::OnePoint,
            cull_clones: true,
            weights: SusinnoWeights::default(),
            geometry: Geometry::Sylva,
            symmetry: Symmetry::Mirror,
            straightness: Straightness::Bend,
            height: Height::Skeleton,
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
    /// The genomes' geometry and bit layout.
    pub geometry: Geometry,
    /// The symmetry scored.
    pub symmetry: Symmetry,
    /// The straightness scored.
    pub straightness: Straightness,
    /// The height scored.
    pub height: Height,
}

impl BinTreeProblem {
    /// A problem with the default settings and the given minimum radius.
    pub fn new(min_radius: f64) -> Self {
        BinTreeProblem::from_settings(&BinTreeSettings {
            min_radius,
            ..BinTreeSettings::default()
        })
    }

    /// The problem the settings describe.
    pub fn from_settings(settings: &BinTreeSettings) -> Self {
        BinTreeProblem {
            min_radius: settings.min_radius,
            weights: settings.weights,
            geometry: settings.geometry,
            symmetry: settings.symmetry,
            straightness: settings.straightness,
            height: settings.height,
        }
    }

    /// The genome a bit string stands for.
    pub fn decode(&self, bits: &Bits) -> BinTree {
        BinTree::decode_as(bits, self.min_radius, self.geometry)
    }

    /// A random bit string of the geometry's layout.
    pub fn random_bits<R: Rng + ?Sized>(&self, rng: &mut R) -> Bits {
        let width = self
            .geometry
            .layout()
            .iter()
            .map(|f| usize::from(f.code.bits));
        Bits::random(width.sum(), rng).expect("the layout fits its bit string")
    }

    /// The measures the fitness weighs, in the forms the run asks for.
    pub fn measures(&self, tree: &BinTree) -> TreeMeasures {
        let mut m = tree.measures();
        if self.symmetry == Symmetry::Paper {
            m.symmetry = tree.paper_symmetry();
        }
        if self.straightness == Straightness::Paper {
            m.straightness = tree.paper_straightness();
        }
        if self.height == Height::Paper {
            m.height = tree.paper_height();
        }
        m
    }
}

impl Problem for BinTreeProblem {
    type Genome = Bits;

    fn term_names(&self) -> Vec<String> {
        TERM_NAMES.iter().map(|s| (*s).to_owned()).collect()
    }

    fn evaluate(&self, bits: &Bits) -> Fitness {
        let score = self.weights.score(&self.measures(&self.decode(bits)));
        Fitness::new(score.total, &score.terms)
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> Bits {
        self.random_bits(rng)
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
