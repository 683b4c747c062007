//! What to evolve and how to score it.

use std::sync::atomic::{AtomicU64, Ordering};

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

/// Evaluations made by this process's runs so far.
static EVALUATIONS: AtomicU64 = AtomicU64::new(0);

/// Scores `genome` with `problem`, counting the evaluation ([`evaluations`]). The engine
/// evaluates through it.
pub fn evaluate<P: Problem>(problem: &P, genome: &P::Genome) -> Fitness {
    let fitness = problem.evaluate(genome);
    EVALUATIONS.fetch_add(1, Ordering::Relaxed);
    fitness
}

/// Evaluations made so far by every run of this process, counted as each ends: what a
/// progress bar reads from another thread while a generation is bred (runs in parallel add
/// to the same count; it decides nothing).
pub fn evaluations() -> u64 {
    EVALUATIONS.load(Ordering::Relaxed)
}
