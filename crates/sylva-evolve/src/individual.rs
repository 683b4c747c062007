//! An individual: a genome, its fitness once known, and where it came from.

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

use crate::fitness::Fitness;

/// The last generation a run (or a map) may reach.
pub const MAX_GENERATION: u32 = 1_000_000_000;

/// A run-wide unique number, given in birth order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct IndividualId(pub u64);

/// How an individual was made: enough to draw its family tree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Origin {
    /// Generation it was born in (0 for the initial population).
    pub generation: u32,
    /// The operator that made it, e.g. `"random"`, `"crossover+mutation"`.
    pub operator: Cow<'static, str>,
    /// Its parents, if any.
    pub parents: Vec<IndividualId>,
}

impl Origin {
    /// Born at random (or given) in `generation`, without parents.
    pub fn new(generation: u32, operator: &'static str) -> Self {
        Origin {
            generation,
            operator: Cow::Borrowed(operator),
            parents: Vec::new(),
        }
    }
}

/// A member of a population.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Individual<G> {
    /// Unique id.
    pub id: IndividualId,
    /// The genome.
    pub genome: G,
    /// `None` until evaluated; set back to `None` whenever the genome changes.
    pub fitness: Option<Fitness>,
    /// Lineage.
    pub origin: Origin,
}

impl<G> Individual<G> {
    /// The total fitness, or negative infinity when not evaluated.
    #[inline]
    pub fn total(&self) -> f64 {
        self.fitness.map_or(f64::NEG_INFINITY, |f| f.total())
    }
}
