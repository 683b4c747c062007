//! Variation operators: small traits with one required method, generic over the genome.
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
