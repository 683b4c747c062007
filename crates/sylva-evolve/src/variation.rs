//! Variation operators: small traits with one required method, generic over the genome, and
//! [`Operators`], the pair a strategy breeds with.
//!
//! Interactive evolution (a person choosing parents) calls the same operators as automatic
//! runs. Randomness is always passed in, never global.

use rand::Rng;

/// Changes a genome in place.
pub trait Mutate<G> {
    /// Mutates `genome` using `rng`.
    fn mutate<R: Rng + ?Sized>(&self, genome: &mut G, rng: &mut R);
}

/// Makes a child from two parents.
pub trait Crossover<G> {
    /// A child of `a` and `b`.
    fn crossover<R: Rng + ?Sized>(&self, a: &G, b: &G, rng: &mut R) -> G;
}

/// The variation operators a strategy breeds with, for a search that chooses its own
/// parents (MAP-Elites breeds with the model's operators, not its generation step).
pub trait Operators<G> {
    /// Makes a child of two parents.
    type Crossover: Crossover<G> + Sync;
    /// Changes a genome.
    type Mutation: Mutate<G> + Sync;
    /// The crossover.
    fn crossover(&self) -> &Self::Crossover;
    /// The mutation.
    fn mutation(&self) -> &Self::Mutation;
}
