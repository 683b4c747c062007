//! The space of one model's genomes under a config, typed (`TypedSpace`): the codings,
//! decoding, encoding and scoring behind [`GenomeSpace`](super::GenomeSpace).

use std::convert::Infallible;

use rand::TryRng;
use sylva_core::par::Pool;
use sylva_core::rng::{self, ChaCha8Rng};
use sylva_evolve::map::Describe;
use sylva_evolve::{Problem, WithTerm};
use sylva_fitness::descriptors::Descriptor;
use sylva_model::{Evolve, VectorCoding};

use crate::error::{Error, InputError};
use crate::genome::Genome;

use super::schema::EvolveConfig;
use super::typed::{Where, setup, typed_start, with_term};
use super::typed_map::{PlantDescriber, as_map, map_settings};

/// Most entries a codon vector has.
pub const MAX_DIM: usize = 1_000_000;

/// Random genomes whose draws set a codon space's default length.
const DIM_SAMPLES: u32 = 64;

/// How a space turns vectors into genomes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Coding {
    /// An entry per parameter of the model's genome, within its range
    /// ([`Evolve::vector_coding`]: the binary tree's fields, PlantMaker's codes): nearby
    /// vectors are similar plants, and a genome has a vector ([`GenomeSpace::encode`]).
    Direct,
    /// Entries from 0 to 1, read in order as the random draws the model's own random genome
    /// generator makes ([`Codons`]), draws past the end from a fixed stream of the space's
    /// seed: grammatical evolution's decoder, the generator standing for the grammar. Every
    /// model has it; it is the only coding of genomes whose structure varies.
    Codons,
}

impl Coding {
    /// Its name: `direct` or `codons`.
    pub fn name(self) -> &'static str {
        match self {
            Coding::Direct => "direct",
            Coding::Codons => "codons",
        }
    }

    /// The coding named `name`.
    pub fn from_name(name: &str) -> Option<Coding> {
        match name {
            "direct" => Some(Coding::Direct),
            "codons" => Some(Coding::Codons),
            _ => None,
        }
    }
}

/// How a [`GenomeSpace`] is made; every field's default is documented.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpaceOptions {
    /// The coding; default (`None`): direct where the model has one, else codons.
    pub coding: Option<Coding>,
    /// Entries per vector: a direct coding's is the model's and may only be restated; a
    /// codon space's is 1 to [`MAX_DIM`], by default the most draws any of 64 random
    /// genomes of the config took.
    pub dim: Option<usize>,
    /// What decoded genomes take for anything the vector does not hold (a PlantMaker
    /// genome's growth seed; a codon vector's draws past its end). Default: the config's
    /// `[run] seed`.
    pub seed: Option<u64>,
}

/// A random number generator that yields a vector's entries ([`Coding::Codons`]): each
/// entry `e` (0 to 1) is one draw, `e · 2⁶⁴` as a 64-bit word (saturating at 1), the upper
/// half of it for a 32-bit draw. Draws past the end come from `rest`.
///
/// Since `rand` draws a number in a range from the high bits of a word, and a probability
/// test compares a word with the probability, an entry is near enough "where in the range"
/// and "how likely": a small change to an entry is a small change to the draw. (An entry
/// within 2⁻³² of a range's cell edge makes `rand` read the next one as well, to stay
/// unbiased.)
#[derive(Clone, Debug)]
pub struct Codons<'a> {
    entries: &'a [f64],
    drawn: usize,
    rest: ChaCha8Rng,
}

impl<'a> Codons<'a> {
    /// A generator that yields `entries`, then `rest`.
    pub fn new(entries: &'a [f64], rest: ChaCha8Rng) -> Codons<'a> {
        Codons {
            entries,
            drawn: 0,
            rest,
        }
    }

    /// Draws made so far (entries, then words of `rest`).
    pub fn drawn(&self) -> usize {
        self.drawn
    }

    fn word(&mut self) -> u64 {
        let at = self.drawn;
        self.drawn += 1;
        match self.entries.get(at) {
            // 2⁶⁴ · e saturates to u64::MAX at 1 and to 0 below 0 (NaN too, which callers
            // refuse before decoding).
            Some(e) => (e * 18_446_744_073_709_551_616.0) as u64,
            None => rand::Rng::next_u64(&mut self.rest),
        }
    }
}

impl TryRng for Codons<'_> {
    type Error = Infallible;

    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok((self.word() >> 32) as u32)
    }

    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        Ok(self.word())
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        for chunk in dst.chunks_mut(8) {
            let bytes = self.word().to_le_bytes();
            chunk.copy_from_slice(&bytes[..chunk.len()]);
        }
        Ok(())
    }
}

/// Scores of a batch of vectors, in row order.
#[derive(Clone, Debug, PartialEq)]
pub struct Scores {
    /// Each vector's total fitness, as the native run's (not finite for a genome the
    /// model cannot score: an L-system world that cannot be built).
    pub fitness: Vec<f64>,
    /// Each vector's descriptors, row by row (one per axis of the map); NaN for a genome
    /// that cannot be grown and measured, which a native map leaves out.
    pub descriptors: Vec<f64>,
}

/// What the library does with a model's space, object-safe.
pub(crate) trait SpaceValue: Send + Sync {
    fn model(&self) -> &'static str;
    fn coding(&self) -> Coding;
    fn bounds(&self) -> &[[f64; 2]];
    fn seed(&self) -> u64;
    fn term_names(&self) -> &[String];
    fn descriptors(&self) -> &[Descriptor];
    /// The genome file of `x` (of the space's length, finite, clamped to the bounds).
    fn decode(&self, x: &[f64]) -> Genome;
    fn encode(&self, genome: &Genome) -> Result<Vec<f64>, InputError>;
    /// Scores rows of `dim` entries each (finite, clamped).
    fn evaluate(&self, xs: &[f64], pool: &Pool) -> Scores;
    /// Refuses scoring `rows` genomes on `threads` that would take longer than the time
    /// budget.
    fn check_time(&self, rows: usize, threads: usize) -> Result<(), InputError>;
}

/// The space of model `M`'s genomes under a config.
struct TypedSpace<M: Evolve> {
    config: EvolveConfig<M>,
    source: String,
    problem: WithTerm<M::Problem>,
    describer: PlantDescriber<M>,
    direct: Option<Box<dyn VectorCoding<M>>>,
    bounds: Vec<[f64; 2]>,
    seed: u64,
    term_names: Vec<String>,
}

impl<M: Evolve + Default> TypedSpace<M> {
    /// The evolved genome of `x`.
    fn evolved(&self, x: &[f64]) -> <M::Problem as Problem>::Genome {
        match &self.direct {
            Some(coding) => coding.decode(x),
            None => {
                let mut codons = Codons::new(x, rng::seeded(self.seed));
                self.problem.random_genome(&mut codons)
            }
        }
    }
}

impl<M: Evolve + Default> SpaceValue for TypedSpace<M> {
    fn model(&self) -> &'static str {
        M::NAME
    }

    fn coding(&self) -> Coding {
        match self.direct {
            Some(_) => Coding::Direct,
            None => Coding::Codons,
        }
    }

    fn bounds(&self) -> &[[f64; 2]] {
        &self.bounds
    }

    fn seed(&self) -> u64 {
        self.seed
    }

    fn term_names(&self) -> &[String] {
        &self.term_names
    }

    fn descriptors(&self) -> &[Descriptor] {
        &self.describer.descriptors
    }

    fn decode(&self, x: &[f64]) -> Genome {
        let evolved = self.evolved(x);
        let file = self
            .config
            .model
            .genome_file(&self.problem.problem, &evolved);
        Genome::new(self.config.model.clone(), file)
    }

    fn encode(&self, genome: &Genome) -> Result<Vec<f64>, InputError> {
        let Some(coding) = &self.direct else {
            return Err(InputError::new(
                "genome",
                format!(
                    "a codon space has no vector for a genome (its vectors are the random \
                     draws that make one); `{}` genomes have a direct coding only if the \
                     model gives one",
                    M::NAME
                ),
            ));
        };
        let typed = genome.get::<M>().ok_or_else(|| {
            InputError::new(
                "genome",
                format!(
                    "this space holds `{}` genomes; this is a `{}` genome",
                    M::NAME,
                    genome.model()
                ),
            )
        })?;
        coding
            .encode(typed)
            .map_err(|why| InputError::new("genome", why))
    }

    fn evaluate(&self, xs: &[f64], pool: &Pool) -> Scores {
        let dim = self.bounds.len();
        let axes = self.describer.descriptors.len();
        let rows = xs.len() / dim;
        let scored = pool.map(rows, |i| {
            let genome = self.evolved(&xs[i * dim..(i + 1) * dim]);
            let fitness = sylva_evolve::problem::evaluate(&self.problem, &genome).total();
            let mut descriptors = vec![f64::NAN; axes];
            if !self
                .describer
                .describe(&self.problem, &genome, &mut descriptors)
            {
                descriptors.fill(f64::NAN);
            }
            (fitness, descriptors)
        });
        let mut out = Scores {
            fitness: Vec::with_capacity(rows),
            descriptors: Vec::with_capacity(rows * axes),
        };
        for (fitness, descriptors) in scored {
            out.fitness.push(fitness);
            out.descriptors.extend(descriptors);
        }
        out
    }

    fn check_time(&self, rows: usize, threads: usize) -> Result<(), InputError> {
        let mut timed = self.config.clone();
        timed.run.population = u32::try_from(rows).unwrap_or(u32::MAX);
        match timed.generation_time(&[], threads) {
            Some(t) => sylva_core::budget::check_time(t.seconds, t.what, t.advice)
                .map_err(|e| InputError::new(&self.source, e).over_limit()),
            None => Ok(()),
        }
    }
}

/// The space of `config`'s genomes (its `[map]`, or the default map, for descriptors),
/// set up with `start` genomes as a run of it is. A refusal names the config (`source`)
/// or the option.
pub(crate) fn new_space<M: Evolve + Default>(
    config: &EvolveConfig<M>,
    at: &Where,
    start: Vec<Genome>,
    options: &SpaceOptions,
) -> Result<Box<dyn SpaceValue>, Error> {
    let (source, target) = (at.source.as_str(), at.target.as_ref());
    let config = as_map(config);
    let (_, descriptors) = map_settings(&config);
    let seed = options.seed.unwrap_or(config.run.seed);
    let typed = typed_start::<M>(&start)?;
    let setup = setup(&config, target, typed, seed, 0, source)?;
    let problem = with_term(&config, setup.problem, target)?;
    let direct = match options.coding {
        Some(Coding::Codons) => None,
        Some(Coding::Direct) => Some(
            config
                .model
                .vector_coding(&problem.problem, seed)
                .ok_or_else(|| {
                    InputError::new(
                        "coding",
                        format!(
                            "`{}` genomes have no direct coding (their structure varies); \
                             use codons",
                            M::NAME
                        ),
                    )
                })?,
        ),
        None => config.model.vector_coding(&problem.problem, seed),
    };
    let dim = match (&direct, options.dim) {
        (Some(coding), Some(dim)) if dim != coding.bounds().len() => {
            return Err(InputError::new(
                "dim",
                format!(
                    "the direct coding of `{}` genomes has {} entries, got {dim} (leave \
                     `dim` out, or use codons)",
                    M::NAME,
                    coding.bounds().len()
                ),
            )
            .into());
        }
        (Some(coding), _) => coding.bounds().len(),
        (None, Some(dim)) if !(1..=MAX_DIM).contains(&dim) => {
            return Err(InputError::new(
                "dim",
                format!("a codon vector has 1 to {MAX_DIM} entries, got {dim}"),
            )
            .into());
        }
        (None, Some(dim)) => dim,
        (None, None) => (0..DIM_SAMPLES)
            .map(|k| {
                let mut codons = Codons::new(&[], rng::stream(seed, 0, k));
                problem.random_genome(&mut codons);
                codons.drawn()
            })
            .max()
            .unwrap_or(1)
            .clamp(1, MAX_DIM),
    };
    let bounds = match &direct {
        Some(coding) => coding.bounds().to_vec(),
        None => vec![[0.0, 1.0]; dim],
    };
    let term_names = problem.term_names();
    Ok(Box::new(TypedSpace {
        describer: PlantDescriber {
            model: config.model.clone(),
            descriptors,
        },
        source: source.to_owned(),
        config,
        problem,
        direct,
        bounds,
        seed,
        term_names,
    }))
}
