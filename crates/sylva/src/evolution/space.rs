//! Genomes as vectors of numbers ([`GenomeSpace`]), so that an optimiser outside Sylva
//! (CMA-ES, pyribs, a loop of one's own) can drive any model: it asks for vectors within
//! the space's bounds, the space decodes them into genomes and scores them, with the
//! config's own fitness (the model's terms and the `[match]` outline, if any) and the
//! descriptors of its `[map]`, exactly as a MAP-Elites run of the config scores its
//! offspring ([`Varieties`](super::Varieties)).
//!
//! Two codings ([`Coding`]):
//!
//! - **Direct**, for a model whose evolved genome is naturally a fixed list of parameters
//!   ([`Evolve::vector_coding`]: the binary tree's fields, PlantMaker's codes): an entry
//!   per parameter, within the parameter's range, so nearby vectors are similar plants and
//!   a genome has a vector ([`GenomeSpace::encode`]).
//! - **Codons**, for every model (the default for those of varying structure: automata
//!   programs, L-system rules): the vector's entries, each from 0 to 1, are the random
//!   draws the model's own random genome generator ([`Problem::random_genome`]) makes, one
//!   entry per 32- or 64-bit draw, read in order ([`Codons`]); draws past the vector's end
//!   come from a fixed stream of the space's seed, so a vector always decodes, and always to
//!   the same genome. This is grammatical evolution's decoder (a codon picks a production)
//!   with the model's generator as the grammar. Its default length is the most draws any
//!   of 64 random genomes of the config took.
//!
//! Everything is a pure function of the vector, the config and the seed: a batch is scored
//! in parallel with results in row order, the same for any number of threads.

use sylva_core::par::Pool;
use sylva_fitness::descriptors::Descriptor;

use crate::error::{Error, InputError};
use crate::genome::Genome;

use super::config::Config;
use super::typed_space::SpaceValue;
pub use super::typed_space::{Coding, Codons, MAX_DIM, Scores, SpaceOptions};

/// A model's genomes as vectors of numbers under a config: decoded, encoded and scored as
/// the config's MAP-Elites run scores them, with a direct coding or codons ([`Coding`]).
pub struct GenomeSpace {
    space: Box<dyn SpaceValue>,
}

impl std::fmt::Debug for GenomeSpace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GenomeSpace")
            .field("model", &self.model())
            .field("coding", &self.coding())
            .field("dim", &self.dim())
            .finish()
    }
}

impl GenomeSpace {
    /// The space of `config`'s genomes, scored with its fitness and measured with its
    /// `[map]`'s descriptors (the default map's if it has none). `start` holds the genomes
    /// the config's `start` files name (see [`Config::load_start`]), which some models'
    /// random genomes grow from (an L-system run's mutants of its start genome).
    pub fn new(
        config: &Config,
        start: Vec<Genome>,
        options: &SpaceOptions,
    ) -> Result<GenomeSpace, Error> {
        let space = config.face().space(&config.at()?, start, options)?;
        Ok(GenomeSpace { space })
    }

    /// The model's name.
    pub fn model(&self) -> &'static str {
        self.space.model()
    }

    /// How vectors become genomes.
    pub fn coding(&self) -> Coding {
        self.space.coding()
    }

    /// Entries per vector.
    pub fn dim(&self) -> usize {
        self.space.bounds().len()
    }

    /// Each entry's lower and upper bound.
    pub fn bounds(&self) -> &[[f64; 2]] {
        self.space.bounds()
    }

    /// The seed decoded genomes take for what the vector does not hold.
    pub fn seed(&self) -> u64 {
        self.space.seed()
    }

    /// Names of the fitness terms the config scores.
    pub fn term_names(&self) -> &[String] {
        self.space.term_names()
    }

    /// The descriptors measured, one per axis of the config's map.
    pub fn descriptors(&self) -> &[Descriptor] {
        self.space.descriptors()
    }

    /// `xs` (rows of [`GenomeSpace::dim`] entries, named `name` in errors) checked and
    /// clamped to the bounds: a length that is not whole rows, or an entry that is not
    /// finite, is refused naming the row and entry.
    fn clamped(&self, name: &str, xs: &[f64]) -> Result<Vec<f64>, InputError> {
        let dim = self.dim();
        if !xs.len().is_multiple_of(dim) {
            return Err(InputError::new(
                name,
                format!(
                    "{} entries are not whole vectors of {dim} (this space's `dim`)",
                    xs.len()
                ),
            ));
        }
        let bounds = self.bounds();
        xs.iter()
            .enumerate()
            .map(|(i, &x)| {
                if !x.is_finite() {
                    let at = if xs.len() == dim {
                        format!("entry {i}")
                    } else {
                        format!("row {}, entry {}", i / dim, i % dim)
                    };
                    return Err(InputError::new(
                        name,
                        format!("{at} is {x}; every entry must be a finite number"),
                    ));
                }
                let [lo, hi] = bounds[i % dim];
                Ok(x.clamp(lo, hi))
            })
            .collect()
    }

    /// The genome of vector `x` (named `x` in errors): [`GenomeSpace::dim`] finite entries,
    /// each clamped to its bounds first.
    pub fn decode(&self, x: &[f64]) -> Result<Genome, InputError> {
        if x.len() != self.dim() {
            return Err(InputError::new(
                "x",
                format!(
                    "a vector of this space has {} entries, got {}",
                    self.dim(),
                    x.len()
                ),
            ));
        }
        let x = self.clamped("x", x)?;
        Ok(self.space.decode(&x))
    }

    /// The genomes of the rows of `xs` (row-major, named `X` in errors), in order, decoded
    /// on `pool`.
    pub fn decode_many(&self, xs: &[f64], pool: &Pool) -> Result<Vec<Genome>, InputError> {
        let xs = self.clamped("X", xs)?;
        let dim = self.dim();
        Ok(pool.map(xs.len() / dim, |i| {
            self.space.decode(&xs[i * dim..(i + 1) * dim])
        }))
    }

    /// The vector of `genome`, for a direct coding; a codon space, a genome of another
    /// model, or one of another shape (PlantMaker's segment counts) is refused naming
    /// `genome`.
    pub fn encode(&self, genome: &Genome) -> Result<Vec<f64>, InputError> {
        self.space.encode(genome)
    }

    /// Scores the rows of `xs` (row-major, named `X` in errors) on `pool`: each row's
    /// fitness and descriptors, exactly as the config's MAP-Elites run scores a genome.
    /// Work estimated to take longer than the time budget (L-system plants) is refused
    /// before it starts.
    pub fn evaluate(&self, xs: &[f64], pool: &Pool) -> Result<Scores, Error> {
        let xs = self.clamped("X", xs)?;
        self.space
            .check_time(xs.len() / self.dim(), pool.threads())?;
        Ok(self.space.evaluate(&xs, pool))
    }
}
