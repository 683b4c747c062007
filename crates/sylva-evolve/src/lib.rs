//! Sylva's generic evolution engine. It knows genomes and fitness, never plants.
//!
//! - [`Problem`]: a genome type, random genomes, and a fitness ([`Fitness`]: a total and
//!   named terms; higher is better). Runs count their evaluations
//!   ([`problem::evaluations`]), for progress bars.
//! - [`Mutate`] and [`Crossover`]: variation operators, one method each, randomness passed in.
//! - [`Strategy`]: how one generation becomes the next; [`MeanReplacement`] is Susinno's.
//! - [`WithTerm`]: a problem with one more [`Term`] (a target outline) beside its own.
//! - [`Generational`]: lilgp's tournament breeding (crossover, reproduction, mutation,
//!   elitism), as Poncin's GP runs used.
//! - [`MapRun`]: MAP-Elites, a map of the fittest genome of every kind ([`Describe`]
//!   places genomes; [`Operators`] are a strategy's own, bred from), or CMA-ME where the
//!   genomes have a [`Coding`] as vectors ([`Emitter`], [`cma::SepCma`]).
//! - [`Pool`]: the one seam where work goes parallel (serial or rayon), results kept in
//!   order (from `sylva_core::par`).
//! - [`Run`]: generations, batches, statistics, a [`Browser`] over the family, and
//!   [`Checkpoint`]s that resume exactly.
//! - [`bits`]: fixed-length bit strings with bit-flip mutation and crossovers.
//! - [`rng`]: ChaCha8 streams keyed by `(seed, generation, slot)` (from `sylva_core::rng`).
//!
//! Determinism: the same problem, settings and seed give the same populations and
//! statistics (less wall time) for any number of threads.
//!
//! ```
//! use sylva_evolve::{
//!     Pool, Fitness, MeanReplacement, Problem, Run, RunSettings,
//!     bits::{BitFlip, BitString, OnePoint},
//! };
//!
//! /// Count the ones.
//! struct OneMax;
//! impl Problem for OneMax {
//!     type Genome = BitString<1>;
//!     fn term_names(&self) -> Vec<String> { vec!["ones".into()] }
//!     fn evaluate(&self, g: &Self::Genome) -> Fitness {
//!         let ones = (0..g.len()).filter(|&i| g.get(i)).count() as f64;
//!         Fitness::new(ones, &[ones])
//!     }
//!     fn random_genome<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> Self::Genome {
//!         BitString::random(40, rng).expect("40 bits fit in one word")
//!     }
//! }
//!
//! let strategy = MeanReplacement {
//!     crossover: OnePoint,
//!     mutation: BitFlip { rate: 0.02 },
//!     cull_clones: true,
//! };
//! let settings = RunSettings { seed: 1, population: 60, keep_history: 0 };
//! let mut run = Run::new(OneMax, strategy, Pool::Serial, settings)?;
//! let first = run.stats()[0].best;
//! run.run_batch(40, |_| {});
//! assert!(run.best().total() > first);
//! # Ok::<(), sylva_evolve::EvolveError>(())
//! ```

pub mod bits;
pub mod cma;
pub mod fitness;
pub mod generational;
pub mod individual;
pub mod map;
pub mod problem;
pub mod run;
pub mod strategy;
pub mod term;
pub mod variation;

pub use fitness::{Fitness, MAX_TERMS};
pub use generational::{Generational, GenerationalError, GenerationalSettings};
pub use individual::{Individual, IndividualId, Origin};
pub use map::{
    Axis, Coding, Describe, Elite, Emitter, MapCheckpoint, MapError, MapRun, MapSettings, MapStats,
    Operators,
};
pub use problem::Problem;
pub use run::{Browser, Checkpoint, EvolveError, GenerationStats, Run, RunSettings};
pub use strategy::{Breeding, MeanReplacement, Strategy, fittest};
pub use sylva_core::par::Pool;
pub use sylva_core::rng;
pub use term::{Added, Term, WithTerm};
pub use variation::{Crossover, Mutate};
