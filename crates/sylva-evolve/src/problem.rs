//! What to evolve and how to score it, and the one seam where evaluation goes parallel.

use std::sync::Arc;

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

/// Runs jobs serially or on a rayon pool, always returning results in job order, so the
/// outcome never depends on the number of threads.
#[derive(Clone, Debug, Default)]
pub enum Evaluator {
    /// On the calling thread.
    #[default]
    Serial,
    /// On a dedicated rayon pool.
    Parallel(Arc<rayon::ThreadPool>),
}

impl Evaluator {
    /// A pool of `threads` threads; 0 means one per core, 1 means serial.
    pub fn with_threads(threads: usize) -> Result<Self, rayon::ThreadPoolBuildError> {
        if threads == 1 {
            return Ok(Evaluator::Serial);
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("sylva-eval-{i}"))
            .build()?;
        Ok(Evaluator::Parallel(Arc::new(pool)))
    }

    /// Number of threads used.
    pub fn threads(&self) -> usize {
        match self {
            Evaluator::Serial => 1,
            Evaluator::Parallel(pool) => pool.current_num_threads(),
        }
    }

    /// `(0..jobs).map(job)`, in order.
    pub fn map<T, F>(&self, jobs: usize, job: F) -> Vec<T>
    where
        T: Send,
        F: Fn(usize) -> T + Sync + Send,
    {
        match self {
            Evaluator::Serial => (0..jobs).map(job).collect(),
            Evaluator::Parallel(pool) => {
                use rayon::prelude::*;
                pool.install(|| (0..jobs).into_par_iter().map(job).collect())
            }
        }
    }
}
