//! What to evolve and how to score it.

use rand::Rng;

use crate::fitness::Fitness;

/// A problem: a genome type, a way to make random genomes, and a fitness.
///
/// `evaluate` must be a pure function of the genome: the same genome always gets the same
/// fitness, whatever thread runs it.
pub trait Problem: Sync {
    /// The genome evolved.
    type Genome: Clone + Send + Sync;

    /// Names of the fitness terms, in the order [`Fitness::terms`] holds them.
    fn term_names(&self) -> Vec<String>;

    /// Scores a genome; higher totals are better.
    fn evaluate(&self, genome: &Self::Genome) -> Fitness;

    /// A random genome.
    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> Self::Genome;
}
