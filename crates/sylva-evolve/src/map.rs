//! MAP-Elites (Mouret and Clune 2015): a search that keeps the best genome of every kind
//! rather than one best, a map of variety.
//!
//! Each genome is placed by its descriptors (what it looks like: say, how tall for its width
//! and how see-through its crown, measured by a [`Describe`]) in one cell of a grid: one
//! [`Axis`] per descriptor, each cut into equal cells over its range, values outside the
//! range falling in its end cells. A cell keeps the fittest genome that has landed in it,
//! its elite. A run starts from [`MapSettings::initial`] random (or given) genomes; each
//! generation then breeds [`MapSettings::batch`] offspring from elites chosen uniformly,
//! with the model's own operators (a crossover of two elites at rate
//! [`MapSettings::crossover`], then a mutation), and offers them to the map.
//!
//! Determinism, as everywhere in the engine: offspring slot `k` of generation `g` draws
//! from stream `(seed, g, k)` and its parents from the map as it stood before the
//! generation; offspring are evaluated in parallel and offered to the map in slot order, so
//! the map does not depend on the number of threads. A genome whose fitness is not finite,
//! or that cannot be described, stays out of the map.
//!
//! Where a model's genomes have a [`Coding`] as vectors of numbers, offspring can instead
//! come from CMA-ME emitters ([`Emitter::CmaMe`], Fontaine et al. 2020): each emitter is an
//! evolution strategy ([`SepCma`]) that samples vectors around its mean, ranks its samples
//! by what they did to the map (new cells first, by fitness; then improved cells, by the
//! gain; then the rest, by how far they fell short) and moves towards the best, starting
//! again from a random elite when a generation of its samples changes nothing or the
//! strategy collapses. Emitter `e` (re)starts at the end of generation `g` from stream
//! `(seed, g, n + e)`, `n` being the generation's size, so emitters too are deterministic.
//!
//! A generation's figures ([`MapStats`]) are the map's coverage (share of cells filled)
//! and its QD-score (the sum over elites of their fitness less
//! [`MapSettings::qd_offset`], so that filling a cell never lowers it when the offset is
//! below every fitness), as pyribs reports them. A [`MapCheckpoint`] resumes a run exactly.

use std::borrow::Cow;
use std::ops::Range;
use std::sync::Arc;
use std::time::Instant;

use rand::RngExt;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::Pool;
use crate::cma::SepCma;
use crate::fitness::{Fitness, MAX_TERMS};
use crate::individual::{Individual, IndividualId, Origin};
use crate::problem::{Problem, evaluate};
use crate::rng;
pub use crate::variation::Operators;
use crate::variation::{Crossover, Mutate};

/// Most descriptors a map has.
pub const MAX_DESCRIPTORS: usize = 3;

/// Most cells a map has: a million elites of a few kilobytes each is already gigabytes.
pub const MAX_CELLS: usize = 100_000;

/// Most offspring a generation breeds, and most genomes a run starts from.
pub const MAX_BATCH: usize = 1_000_000;

/// The checkpoint format this version writes and reads.
pub const MAP_CHECKPOINT_FORMAT: u32 = 1;

/// Where a genome falls in the map: its descriptors, inline.
pub type Descriptors = [f64; MAX_DESCRIPTORS];

/// Places genomes in the map.
pub trait Describe<P: Problem>: Send + Sync {
    /// Writes the descriptors of `genome` into `out` (one per axis); `false` if it cannot be
    /// described (it then stays out of the map). Must be a pure function of the genome.
    fn describe(&self, problem: &P, genome: &P::Genome, out: &mut [f64]) -> bool;
}

/// A problem's genomes as vectors of numbers, each entry within its bounds: what a CMA-ME
/// emitter searches.
pub trait Coding<P: Problem>: Send + Sync {
    /// Each entry's lower and upper bound (lower ≤ upper); at least one entry.
    fn bounds(&self) -> &[[f64; 2]];
    /// The genome of `x`, one entry per bound, each within its bounds.
    fn decode(&self, x: &[f64]) -> P::Genome;
    /// The vector of `genome`, or `None` if the coding cannot hold it (an emitter then
    /// starts from a random vector instead).
    fn encode(&self, problem: &P, genome: &P::Genome) -> Option<Vec<f64>>;
}

/// Where a map's offspring come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Emitter {
    /// The model's own operators on elites chosen uniformly (MAP-Elites).
    #[default]
    Operators,
    /// CMA-ME: `emitters` evolution strategies share each batch, each starting from an
    /// elite's vector with step size `sigma` (a share of each entry's range). Needs a
    /// [`Coding`].
    CmaMe {
        /// Strategies, 1 to half the batch (each needs two samples a generation).
        emitters: u32,
        /// First step size, as a share of each entry's range, above 0 to 1.
        sigma: f64,
    },
}

impl Emitter {
    /// Whether this is the default, the model's operators.
    pub fn is_operators(&self) -> bool {
        *self == Emitter::Operators
    }
}

/// One descriptor's range, cut into equal cells.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    /// Lower end of the range.
    pub min: f64,
    /// Upper end of the range.
    pub max: f64,
    /// Cells across the range.
    pub cells: u32,
}

impl Axis {
    /// The cell `value` falls in; values outside the range fall in the end cells.
    pub fn cell(&self, value: f64) -> u32 {
        let share = (value - self.min) / (self.max - self.min);
        // Casting saturates: below the range (and -inf) gives 0, above it the last cell.
        ((share * f64::from(self.cells)) as u32).min(self.cells - 1)
    }

    /// The middle of cell `cell`'s stretch of the range.
    pub fn centre(&self, cell: u32) -> f64 {
        self.min + (self.max - self.min) * (f64::from(cell) + 0.5) / f64::from(self.cells)
    }
}

/// What a MAP-Elites run is asked to do.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapSettings {
    /// Seed of every random stream.
    pub seed: u64,
    /// The map's axes, one per descriptor (1 to [`MAX_DESCRIPTORS`]).
    pub axes: Vec<Axis>,
    /// Genomes of generation 0 (given, then random), 1 to [`MAX_BATCH`].
    pub initial: usize,
    /// Offspring per generation, 1 to [`MAX_BATCH`].
    pub batch: usize,
    /// Share of offspring made by crossing two elites (before mutating), 0 to 1.
    pub crossover: f64,
    /// Subtracted from each elite's fitness in the QD-score.
    pub qd_offset: f64,
    /// Where offspring come from.
    #[serde(default, skip_serializing_if = "Emitter::is_operators")]
    pub emitter: Emitter,
}

/// Why map settings are refused.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MapError {
    /// No axis, or too many.
    #[error("a map has 1 to {MAX_DESCRIPTORS} descriptors, got {0}")]
    Axes(usize),
    /// An axis whose range is empty, reversed or not finite, or that has no cell.
    #[error("axis {axis}: {why}")]
    Axis {
        /// Which axis (0-based).
        axis: usize,
        /// What is wrong.
        why: String,
    },
    /// More cells than [`MAX_CELLS`].
    #[error("the map has {0} cells; at most {MAX_CELLS}")]
    Cells(u64),
    /// An initial population or batch of zero or above [`MAX_BATCH`].
    #[error("`{name}` must be 1 to {MAX_BATCH}, got {value}")]
    Size {
        /// Which size.
        name: &'static str,
        /// The value given.
        value: usize,
    },
    /// A crossover rate outside 0..=1, or a QD offset that is not finite.
    #[error("`{name}` must be {expected}, got {value}")]
    Number {
        /// Which number.
        name: &'static str,
        /// What it must be.
        expected: &'static str,
        /// The value given.
        value: f64,
    },
    /// The problem declares more fitness terms than a fitness can keep.
    #[error("the problem declares {0} fitness terms; at most {MAX_TERMS} are supported")]
    TooManyTerms(usize),
    /// A checkpoint that does not fit.
    #[error("checkpoint does not fit this run: {0}")]
    BadCheckpoint(String),
    /// CMA-ME asked of genomes that have no coding as vectors.
    #[error("CMA-ME emitters search genomes as vectors, and these genomes have no such coding")]
    NoCoding,
}

impl MapSettings {
    /// Checks the axes, sizes and rates.
    pub fn validate(&self) -> Result<(), MapError> {
        if self.axes.is_empty() || self.axes.len() > MAX_DESCRIPTORS {
            return Err(MapError::Axes(self.axes.len()));
        }
        for (axis, a) in self.axes.iter().enumerate() {
            let why = if !(a.min.is_finite() && a.max.is_finite()) {
                format!("its range {} to {} is not finite", a.min, a.max)
            } else if a.min >= a.max {
                format!("its range {} to {} is empty", a.min, a.max)
            } else if a.cells == 0 {
                "it has no cells".to_owned()
            } else {
                continue;
            };
            return Err(MapError::Axis { axis, why });
        }
        let cells: u64 = self.axes.iter().map(|a| u64::from(a.cells)).product();
        if cells > MAX_CELLS as u64 {
            return Err(MapError::Cells(cells));
        }
        for (name, value) in [("initial", self.initial), ("batch", self.batch)] {
            if !(1..=MAX_BATCH).contains(&value) {
                return Err(MapError::Size { name, value });
            }
        }
        if !(0.0..=1.0).contains(&self.crossover) {
            return Err(MapError::Number {
                name: "crossover",
                expected: "a number from 0 to 1",
                value: self.crossover,
            });
        }
        if !self.qd_offset.is_finite() {
            return Err(MapError::Number {
                name: "qd_offset",
                expected: "a finite number",
                value: self.qd_offset,
            });
        }
        if let Emitter::CmaMe { emitters, sigma } = self.emitter {
            if emitters == 0 || emitters as usize > self.batch / 2 {
                return Err(MapError::Number {
                    name: "emitters",
                    expected: "1 to half the batch (two samples each a generation)",
                    value: f64::from(emitters),
                });
            }
            if !(sigma > 0.0 && sigma <= 1.0) {
                return Err(MapError::Number {
                    name: "sigma",
                    expected: "above 0 to 1 (a share of each entry's range)",
                    value: sigma,
                });
            }
        }
        Ok(())
    }

    /// Cells in the map.
    pub fn cells(&self) -> usize {
        self.axes.iter().map(|a| a.cells as usize).product()
    }

    /// The cell of `descriptors`: row-major, the first axis slowest.
    pub fn cell(&self, descriptors: &[f64]) -> usize {
        self.axes
            .iter()
            .zip(descriptors)
            .fold(0, |cell, (axis, &d)| {
                cell * axis.cells as usize + axis.cell(d) as usize
            })
    }

    /// The coordinates of `cell` along each axis.
    pub fn coordinates(&self, cell: usize) -> Vec<u32> {
        let mut rest = cell;
        let mut coords: Vec<u32> = self
            .axes
            .iter()
            .rev()
            .map(|axis| {
                let c = rest % axis.cells as usize;
                rest /= axis.cells as usize;
                c as u32
            })
            .collect();
        coords.reverse();
        coords
    }
}

/// The fittest genome found in one cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Elite<G> {
    /// The genome, its fitness and origin.
    pub individual: Individual<G>,
    /// Its descriptors, one per axis.
    pub descriptors: Vec<f64>,
}

/// One generation's figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapStats {
    /// Generation number (0 is the initial population).
    pub generation: u32,
    /// Cells filled.
    pub filled: usize,
    /// Share of the cells filled, 0 to 1.
    pub coverage: f64,
    /// Sum over elites of their fitness less the QD offset.
    pub qd_score: f64,
    /// Best fitness in the map (negative infinity while it is empty).
    pub best: f64,
    /// Mean fitness of the elites (negative infinity while the map is empty).
    pub mean: f64,
    /// Id of the best elite, if any.
    pub best_id: Option<IndividualId>,
    /// Offspring that filled an empty cell or beat its elite this generation.
    pub improved: usize,
    /// Evaluations run to make this generation.
    pub evaluations: u64,
    /// Wall time spent making it (not deterministic).
    pub seconds: f64,
}

/// Everything needed to resume a map run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapCheckpoint<G> {
    /// Checkpoint format version.
    pub format: u32,
    /// The settings the run was started with.
    pub settings: MapSettings,
    /// The last completed generation.
    pub generation: u32,
    /// The next unused individual id.
    pub next_id: u64,
    /// The elites, in cell order.
    pub elites: Vec<Individual<G>>,
    /// Statistics of generations 0 to `generation`.
    pub stats: Vec<MapStats>,
    /// The CMA-ME emitters' strategies (none for the model's operators).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub emitters: Vec<SepCma>,
}

/// An offspring, scored and described.
struct Offered<G> {
    genome: G,
    fitness: Fitness,
    descriptors: Option<Descriptors>,
    operator: &'static str,
    parents: Vec<IndividualId>,
    /// The normal draws a CMA-ME emitter sampled it from.
    draws: Option<Vec<f64>>,
}

/// What offering a genome did to the map, as CMA-ME ranks it: `(rank, value)`, compared
/// in that order, higher first. New cells (rank 3) by fitness, improved cells (2) by the
/// gain, the rest (1) by the (negative) margin to the elite, the undescribable last (0).
type Placement = (u8, f64);

/// A MAP-Elites run over problem `P`, bred with the operators of `S`.
pub struct MapRun<P: Problem, S> {
    problem: P,
    operators: S,
    describer: Arc<dyn Describe<P>>,
    evaluator: Pool,
    settings: MapSettings,
    term_names: Vec<String>,
    generation: u32,
    next_id: u64,
    cells: Vec<Option<Elite<P::Genome>>>,
    /// The filled cells, ascending: where parents are drawn from.
    filled: Vec<usize>,
    stats: Vec<MapStats>,
    coding: Option<Arc<dyn Coding<P>>>,
    emitters: Vec<SepCma>,
}

impl<P: Problem, S: Operators<P::Genome> + Sync> MapRun<P, S> {
    /// Starts a run: `genomes` (extra ones are ignored) and random genomes up to
    /// [`MapSettings::initial`], evaluated and placed.
    /// `coding` is what CMA-ME emitters search ([`Emitter::CmaMe`]; the operators need none).
    pub fn new(
        problem: P,
        operators: S,
        describer: Arc<dyn Describe<P>>,
        coding: Option<Arc<dyn Coding<P>>>,
        evaluator: Pool,
        settings: MapSettings,
        genomes: Vec<P::Genome>,
    ) -> Result<Self, MapError> {
        let mut run = Self::empty(problem, operators, describer, coding, evaluator, settings)?;
        let start = Instant::now();
        let seed = run.settings.seed;
        let given = genomes.len().min(run.settings.initial);
        let mut genomes: Vec<Option<P::Genome>> =
            genomes.into_iter().take(given).map(Some).collect();
        genomes.resize_with(run.settings.initial, || None);
        let offered = {
            let (problem, describer) = (&run.problem, &*run.describer);
            let axes = run.settings.axes.len();
            // CMA-ME searches the coding, so it starts from random vectors of it.
            let coding = (!run.settings.emitter.is_operators())
                .then_some(run.coding.as_deref())
                .flatten();
            run.evaluator.map(genomes.len(), |k| {
                let mut rng = rng::stream(seed, 0, k as u32);
                let (genome, operator) = match (&genomes[k], coding) {
                    (Some(g), _) => (g.clone(), "given"),
                    (None, Some(coding)) => (random_vector(coding, &mut rng), "random"),
                    (None, None) => (problem.random_genome(&mut rng), "random"),
                };
                score(problem, describer, axes, genome, operator, Vec::new(), None)
            })
        };
        let (improved, _) = run.offer(offered);
        if let Emitter::CmaMe { emitters, .. } = run.settings.emitter {
            // Every emitter starts at the best genome found, as CMA-ME's do, and later
            // restarts at a random elite.
            for e in 0..emitters as usize {
                let strategy = run.restart(e, run.settings.initial, true);
                run.emitters.push(strategy);
            }
        }
        run.record(improved, run.settings.initial as u64, start);
        Ok(run)
    }

    /// Resumes from a checkpoint: the elites are evaluated again and placed, and the run
    /// continues exactly as the original would have.
    pub fn resume(
        problem: P,
        operators: S,
        describer: Arc<dyn Describe<P>>,
        coding: Option<Arc<dyn Coding<P>>>,
        evaluator: Pool,
        checkpoint: MapCheckpoint<P::Genome>,
    ) -> Result<Self, MapError> {
        let bad = |why: String| Err(MapError::BadCheckpoint(why));
        if checkpoint.format != MAP_CHECKPOINT_FORMAT {
            return bad(format!(
                "format {} (this version reads {MAP_CHECKPOINT_FORMAT})",
                checkpoint.format
            ));
        }
        if checkpoint.generation > crate::individual::MAX_GENERATION {
            return bad(format!(
                "generation {} is past the last, {}",
                checkpoint.generation,
                crate::individual::MAX_GENERATION
            ));
        }
        if checkpoint.stats.len() != checkpoint.generation as usize + 1 {
            return bad(format!(
                "{} statistics rows for generation {}",
                checkpoint.stats.len(),
                checkpoint.generation
            ));
        }
        let mut run = Self::empty(
            problem,
            operators,
            describer,
            coding,
            evaluator,
            checkpoint.settings,
        )?;
        let wanted = match run.settings.emitter {
            Emitter::CmaMe { emitters, .. } => emitters as usize,
            Emitter::Operators => 0,
        };
        let dim = run.coding.as_ref().map_or(0, |c| c.bounds().len());
        let fits = |es: &SepCma| {
            [&es.mean, &es.variances, &es.sigma_path, &es.covariance_path]
                .iter()
                .all(|v| v.len() == dim)
        };
        if checkpoint.emitters.len() != wanted || !checkpoint.emitters.iter().all(fits) {
            return bad(format!(
                "{} emitters saved for {wanted} of {dim} entries",
                checkpoint.emitters.len()
            ));
        }
        run.emitters = checkpoint.emitters;
        if checkpoint.elites.len() > run.cells.len() {
            return bad(format!(
                "{} elites saved for a map of {} cells",
                checkpoint.elites.len(),
                run.cells.len()
            ));
        }
        run.generation = checkpoint.generation;
        run.next_id = checkpoint.next_id;
        run.stats = checkpoint.stats;
        // Fitness and place are derived again, not trusted.
        let elites = checkpoint.elites;
        let offered = {
            let (problem, describer) = (&run.problem, &*run.describer);
            let axes = run.settings.axes.len();
            run.evaluator.map(elites.len(), |k| {
                score(
                    problem,
                    describer,
                    axes,
                    elites[k].genome.clone(),
                    "",
                    Vec::new(),
                    None,
                )
            })
        };
        for (offer, saved) in offered.into_iter().zip(elites) {
            run.place(saved.id, offer, saved.origin);
        }
        Ok(run)
    }

    fn empty(
        problem: P,
        operators: S,
        describer: Arc<dyn Describe<P>>,
        coding: Option<Arc<dyn Coding<P>>>,
        evaluator: Pool,
        settings: MapSettings,
    ) -> Result<Self, MapError> {
        settings.validate()?;
        let coded = coding.as_ref().is_some_and(|c| !c.bounds().is_empty());
        if !settings.emitter.is_operators() && !coded {
            return Err(MapError::NoCoding);
        }
        let term_names = problem.term_names();
        if term_names.len() > MAX_TERMS {
            return Err(MapError::TooManyTerms(term_names.len()));
        }
        let mut cells = Vec::new();
        cells.resize_with(settings.cells(), || None);
        Ok(MapRun {
            problem,
            operators,
            describer,
            evaluator,
            settings,
            term_names,
            generation: 0,
            next_id: 0,
            cells,
            filled: Vec::new(),
            stats: Vec::new(),
            coding,
            emitters: Vec::new(),
        })
    }

    /// Breeds one generation, offers it to the map, and returns its statistics. The run
    /// changes only once the generation's offspring are made and scored, so a step cut short
    /// while they are (a front end's stop unwinding out of the pool) leaves it as it was.
    pub fn step(&mut self) -> &MapStats {
        let start = Instant::now();
        let generation = (self.generation + 1).min(crate::individual::MAX_GENERATION);
        let improved = match self.settings.emitter {
            Emitter::Operators => {
                let offered = self.breed(generation);
                self.generation = generation;
                self.offer(offered).0
            }
            Emitter::CmaMe { .. } => {
                let mut offered = self.sample(generation);
                self.generation = generation;
                let draws: Vec<Vec<f64>> = (offered.iter_mut())
                    .map(|o| o.draws.take().unwrap_or_default())
                    .collect();
                let (improved, placements) = self.offer(offered);
                self.adapt(&draws, &placements);
                improved
            }
        };
        self.record(improved, self.settings.batch as u64, start);
        self.stats.last().expect("record pushed a row")
    }

    /// Breeds `generations` generations, calling `on_generation` after each.
    pub fn run_batch(&mut self, generations: u32, mut on_generation: impl FnMut(&MapStats)) {
        for _ in 0..generations {
            on_generation(self.step());
        }
    }

    /// Generation `generation` bred with the model's operators from elites chosen uniformly.
    fn breed(&self, generation: u32) -> Vec<Offered<P::Genome>> {
        let seed = self.settings.seed;
        let (problem, describer, cells, filled) =
            (&self.problem, &*self.describer, &self.cells, &self.filled);
        let (crossover, mutation) = (self.operators.crossover(), self.operators.mutation());
        let axes = self.settings.axes.len();
        let rate = self.settings.crossover;
        let elite = |i: usize| {
            &cells[filled[i]]
                .as_ref()
                .expect("filled cells hold elites")
                .individual
        };
        self.evaluator.map(self.settings.batch, |k| {
            let mut rng = rng::stream(seed, generation, k as u32);
            if filled.is_empty() {
                let genome = problem.random_genome(&mut rng);
                return score(problem, describer, axes, genome, "random", Vec::new(), None);
            }
            let a = elite(rng.random_range(0..filled.len()));
            let (mut genome, operator, parents) = if rng.random::<f64>() < rate {
                let b = elite(rng.random_range(0..filled.len()));
                let child = crossover.crossover(&a.genome, &b.genome, &mut rng);
                (child, "crossover+mutation", vec![a.id, b.id])
            } else {
                (a.genome.clone(), "mutation", vec![a.id])
            };
            mutation.mutate(&mut genome, &mut rng);
            score(problem, describer, axes, genome, operator, parents, None)
        })
    }

    /// Generation `generation` sampled by the CMA-ME emitters, each from its share of the
    /// slots.
    fn sample(&self, generation: u32) -> Vec<Offered<P::Genome>> {
        let seed = self.settings.seed;
        let coding = self.coding.as_deref().expect("CMA-ME runs have a coding");
        let bounds = coding.bounds();
        let owner: Vec<usize> = emitter_slots(self.settings.batch, self.emitters.len())
            .enumerate()
            .flat_map(|(e, slots)| slots.map(move |_| e))
            .collect();
        let (problem, describer, emitters) = (&self.problem, &*self.describer, &self.emitters);
        let axes = self.settings.axes.len();
        self.evaluator.map(self.settings.batch, |k| {
            let (mut draws, mut unit) = (vec![0.0; bounds.len()], vec![0.0; bounds.len()]);
            let mut rng = rng::stream(seed, generation, k as u32);
            emitters[owner[k]].sample(&mut rng, &mut draws, &mut unit);
            // The strategy samples the whole space; what leaves the bounds is clamped onto
            // them (its draws still teach the strategy), as pyribs' unbounded emitters do.
            let x: Vec<f64> = (unit.iter().zip(bounds))
                .map(|(u, [lo, hi])| lo + u.clamp(0.0, 1.0) * (hi - lo))
                .collect();
            let genome = coding.decode(&x);
            score(
                problem,
                describer,
                axes,
                genome,
                "cma-me",
                Vec::new(),
                Some(draws),
            )
        })
    }

    /// Moves each emitter towards its samples that did most for the map, or starts it
    /// again if none changed the map or its strategy collapsed.
    fn adapt(&mut self, draws: &[Vec<f64>], placements: &[Placement]) {
        let batch = self.settings.batch;
        for (e, slots) in emitter_slots(batch, self.emitters.len()).enumerate() {
            if slots.clone().all(|k| placements[k].0 < 2) {
                self.emitters[e] = self.restart(e, batch, false);
                continue;
            }
            let mut ranked: Vec<usize> = slots.collect();
            // Stable: ties keep slot order.
            ranked.sort_by(|&a, &b| {
                let (pa, pb) = (placements[a], placements[b]);
                pb.0.cmp(&pa.0).then(pb.1.total_cmp(&pa.1))
            });
            let ranked: Vec<&[f64]> = ranked.iter().map(|&k| &draws[k][..]).collect();
            self.emitters[e].update(&ranked);
            if self.emitters[e].degenerate() {
                self.emitters[e] = self.restart(e, batch, false);
            }
        }
    }

    /// Emitter `e`'s strategy started afresh at the vector of the best elite or a random
    /// one (a random vector if the map is empty or the coding cannot hold the elite),
    /// drawn from stream `(seed, generation, size + e)`, `size` being the generation's.
    fn restart(&self, e: usize, size: usize, best: bool) -> SepCma {
        let Emitter::CmaMe { sigma, .. } = self.settings.emitter else {
            unreachable!("only CMA-ME runs have emitters")
        };
        let coding = self.coding.as_deref().expect("CMA-ME runs have a coding");
        let bounds = coding.bounds();
        let slot = u32::try_from(size + e).unwrap_or(u32::MAX);
        let mut rng = rng::stream(self.settings.seed, self.generation, slot);
        let elite = match best {
            true => self.best(),
            false if self.filled.is_empty() => None,
            false => self.cells[self.filled[rng.random_range(0..self.filled.len())]].as_ref(),
        };
        let elite = elite.map(|elite| coding.encode(&self.problem, &elite.individual.genome));
        let mean = match elite.flatten() {
            Some(x) if x.len() == bounds.len() => (x.iter().zip(bounds))
                .map(|(x, [lo, hi])| {
                    let unit = (x - lo) / (hi - lo);
                    if unit.is_finite() {
                        unit.clamp(0.0, 1.0)
                    } else {
                        0.0
                    }
                })
                .collect(),
            _ => (0..bounds.len()).map(|_| rng.random::<f64>()).collect(),
        };
        SepCma::new(mean, sigma)
    }

    /// Offers scored offspring to the map in order; returns how many improved it, and
    /// what each did.
    fn offer(&mut self, offered: Vec<Offered<P::Genome>>) -> (usize, Vec<Placement>) {
        let placements: Vec<Placement> = offered
            .into_iter()
            .map(|offer| {
                let id = IndividualId(self.next_id);
                self.next_id += 1;
                let origin = Origin {
                    generation: self.generation,
                    operator: Cow::Borrowed(offer.operator),
                    parents: offer.parents.clone(),
                };
                self.place(id, offer, origin)
            })
            .collect();
        let improved = placements.iter().filter(|p| p.0 >= 2).count();
        (improved, placements)
    }

    /// Puts an offspring in its cell if the cell is empty or it beats the elite there;
    /// what it did.
    fn place(&mut self, id: IndividualId, offer: Offered<P::Genome>, origin: Origin) -> Placement {
        let fitness = offer.fitness.total();
        let Some(descriptors) = offer.descriptors.filter(|_| fitness.is_finite()) else {
            return (0, f64::NEG_INFINITY);
        };
        let axes = self.settings.axes.len();
        let cell = self.settings.cell(&descriptors[..axes]);
        let slot = &mut self.cells[cell];
        let placement = match slot {
            Some(elite) if elite.individual.total() >= fitness => {
                return (1, fitness - elite.individual.total());
            }
            Some(elite) => (2, fitness - elite.individual.total()),
            None => {
                let at = self.filled.partition_point(|&c| c < cell);
                self.filled.insert(at, cell);
                (3, fitness)
            }
        };
        *slot = Some(Elite {
            individual: Individual {
                id,
                genome: offer.genome,
                fitness: Some(offer.fitness),
                origin,
            },
            descriptors: descriptors[..axes].to_vec(),
        });
        placement
    }

    fn record(&mut self, improved: usize, evaluations: u64, start: Instant) {
        let offset = self.settings.qd_offset;
        let (mut sum, mut qd, mut best) = (0.0, 0.0, None::<&Individual<P::Genome>>);
        for elite in self.elites() {
            let t = elite.individual.total();
            sum += t;
            qd += t - offset;
            if best.is_none_or(|b| t > b.total()) {
                best = Some(&elite.individual);
            }
        }
        let filled = self.filled.len();
        let row = MapStats {
            generation: self.generation,
            filled,
            coverage: filled as f64 / self.cells.len() as f64,
            qd_score: qd,
            best: best.map_or(f64::NEG_INFINITY, Individual::total),
            mean: if filled == 0 {
                f64::NEG_INFINITY
            } else {
                sum / filled as f64
            },
            best_id: best.map(|b| b.id),
            improved,
            evaluations,
            seconds: start.elapsed().as_secs_f64(),
        };
        self.stats.push(row);
    }

    /// The elites, in cell order.
    pub fn elites(&self) -> impl Iterator<Item = &Elite<P::Genome>> + '_ {
        self.filled
            .iter()
            .map(|&c| self.cells[c].as_ref().expect("filled cells hold elites"))
    }

    /// The elite of `cell`, if the cell is filled.
    pub fn elite(&self, cell: usize) -> Option<&Elite<P::Genome>> {
        self.cells.get(cell).and_then(Option::as_ref)
    }

    /// The filled cells, ascending.
    pub fn filled(&self) -> &[usize] {
        &self.filled
    }

    /// The fittest elite (ties go to the lower cell), if the map holds any.
    pub fn best(&self) -> Option<&Elite<P::Genome>> {
        self.elites().fold(None, |best, e| match best {
            Some(b) if b.individual.total() >= e.individual.total() => Some(b),
            _ => Some(e),
        })
    }

    /// The last completed generation.
    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// Statistics of every generation so far.
    pub fn stats(&self) -> &[MapStats] {
        &self.stats
    }

    /// Names of the fitness terms.
    pub fn term_names(&self) -> &[String] {
        &self.term_names
    }

    /// The problem being solved.
    pub fn problem(&self) -> &P {
        &self.problem
    }

    /// The settings the run started with.
    pub fn settings(&self) -> &MapSettings {
        &self.settings
    }

    /// Everything needed to resume.
    pub fn checkpoint(&self) -> MapCheckpoint<P::Genome> {
        MapCheckpoint {
            format: MAP_CHECKPOINT_FORMAT,
            settings: self.settings.clone(),
            generation: self.generation,
            next_id: self.next_id,
            elites: self.elites().map(|e| e.individual.clone()).collect(),
            stats: self.stats.clone(),
            emitters: self.emitters.clone(),
        }
    }
}

/// The genome of a vector drawn uniformly within `coding`'s bounds.
fn random_vector<P: Problem, R: rand::Rng + ?Sized>(
    coding: &dyn Coding<P>,
    rng: &mut R,
) -> P::Genome {
    let x: Vec<f64> = (coding.bounds().iter())
        .map(|[lo, hi]| lo + rng.random::<f64>() * (hi - lo))
        .collect();
    coding.decode(&x)
}

/// The slots of a generation of `batch` that each of `emitters` emitters samples: equal
/// shares in order, the first ones taking one more while the remainder lasts.
fn emitter_slots(batch: usize, emitters: usize) -> impl Iterator<Item = Range<usize>> {
    let (share, extra) = (batch / emitters.max(1), batch % emitters.max(1));
    (0..emitters).map(move |e| {
        let start = e * share + e.min(extra);
        start..start + share + usize::from(e < extra)
    })
}

/// Evaluates and describes an offspring.
fn score<P: Problem>(
    problem: &P,
    describer: &dyn Describe<P>,
    axes: usize,
    genome: P::Genome,
    operator: &'static str,
    parents: Vec<IndividualId>,
    draws: Option<Vec<f64>>,
) -> Offered<P::Genome> {
    let fitness = evaluate(problem, &genome);
    let mut descriptors = [0.0; MAX_DESCRIPTORS];
    let described = describer.describe(problem, &genome, &mut descriptors[..axes])
        && descriptors[..axes].iter().all(|d| !d.is_nan());
    Offered {
        genome,
        fitness,
        descriptors: described.then_some(descriptors),
        operator,
        parents,
        draws,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bits::{BitFlip, BitString, OnePoint};

    /// Bit strings scored by their ones, placed by the ones in each half.
    struct Halves;

    impl Problem for Halves {
        type Genome = BitString<1>;
        fn term_names(&self) -> Vec<String> {
            vec!["ones".into()]
        }
        fn evaluate(&self, g: &Self::Genome) -> Fitness {
            let ones = (0..g.len()).filter(|&i| g.get(i)).count() as f64;
            Fitness::new(-(ones - 20.0).abs(), &[ones])
        }
        fn random_genome<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> Self::Genome {
            BitString::random(40, rng).expect("40 bits fit")
        }
    }

    impl Describe<Halves> for Halves {
        fn describe(&self, _: &Halves, g: &BitString<1>, out: &mut [f64]) -> bool {
            out[0] = (0..20).filter(|&i| g.get(i)).count() as f64;
            out[1] = (20..40).filter(|&i| g.get(i)).count() as f64;
            true
        }
    }

    struct Ops(OnePoint, BitFlip);

    impl Operators<BitString<1>> for Ops {
        type Crossover = OnePoint;
        type Mutation = BitFlip;
        fn crossover(&self) -> &OnePoint {
            &self.0
        }
        fn mutation(&self) -> &BitFlip {
            &self.1
        }
    }

    fn settings() -> MapSettings {
        let axis = Axis {
            min: 0.0,
            max: 21.0,
            cells: 7,
        };
        MapSettings {
            seed: 3,
            axes: vec![axis, axis],
            initial: 20,
            batch: 30,
            crossover: 0.5,
            qd_offset: -40.0,
            emitter: Emitter::Operators,
        }
    }

    fn run(pool: Pool) -> MapRun<Halves, Ops> {
        let ops = Ops(OnePoint, BitFlip { rate: 0.05 });
        MapRun::new(
            Halves,
            ops,
            Arc::new(Halves),
            None,
            pool,
            settings(),
            Vec::new(),
        )
        .unwrap()
    }

    #[test]
    fn axes_place_values_in_cells_clipping_the_ends() {
        let a = Axis {
            min: 0.0,
            max: 1.0,
            cells: 4,
        };
        assert_eq!(
            [-5.0, 0.0, 0.24, 0.25, 0.99, 1.0, 7.0, f64::INFINITY].map(|v| a.cell(v)),
            [0, 0, 0, 1, 3, 3, 3, 3]
        );
        assert_eq!(a.centre(1), 0.375);
        let s = settings();
        assert_eq!(s.cells(), 49);
        assert_eq!(s.cell(&[3.0, 20.0]), 7 + 6);
        assert_eq!(s.coordinates(13), vec![1, 6]);
    }

    #[test]
    fn bad_settings_are_refused() {
        let mut s = settings();
        s.axes[1].max = s.axes[1].min;
        assert!(matches!(s.validate(), Err(MapError::Axis { axis: 1, .. })));
        let mut s = settings();
        s.axes = vec![
            Axis {
                min: 0.0,
                max: 1.0,
                cells: 1000
            };
            2
        ];
        assert_eq!(s.validate(), Err(MapError::Cells(1_000_000)));
        let mut s = settings();
        s.batch = 0;
        assert!(matches!(
            s.validate(),
            Err(MapError::Size { name: "batch", .. })
        ));
        let mut s = settings();
        s.crossover = f64::NAN;
        assert!(s.validate().is_err());
    }

    #[test]
    fn the_map_fills_and_only_improves() {
        let mut r = run(Pool::Serial);
        let first = r.stats()[0].clone();
        assert!(first.filled > 0 && first.filled <= 20);
        let mut last = first.clone();
        r.run_batch(30, |s| {
            // Elites are only ever replaced by fitter ones, so neither figure falls.
            assert!(s.filled >= last.filled && s.qd_score >= last.qd_score);
            last = s.clone();
        });
        assert!(last.filled > 2 * first.filled, "{last:?}");
        // Every elite sits in the cell its descriptors name.
        for &cell in r.filled() {
            let e = r.elite(cell).unwrap();
            assert_eq!(r.settings().cell(&e.descriptors), cell);
        }
        assert_eq!(r.best().unwrap().individual.total(), last.best);
    }

    #[test]
    fn results_do_not_depend_on_threads_and_resume_exactly() {
        let mut serial = run(Pool::Serial);
        serial.run_batch(10, |_| {});
        let mut parallel = run(Pool::with_threads(3).unwrap());
        parallel.run_batch(4, |_| {});
        let saved = serde_json::to_string(&parallel.checkpoint()).unwrap();
        let ops = Ops(OnePoint, BitFlip { rate: 0.05 });
        let checkpoint = serde_json::from_str(&saved).unwrap();
        let mut resumed = MapRun::resume(
            Halves,
            ops,
            Arc::new(Halves),
            None,
            Pool::Serial,
            checkpoint,
        )
        .unwrap();
        resumed.run_batch(6, |_| {});
        let strip = |c: MapCheckpoint<BitString<1>>| {
            let mut c = c;
            c.stats.iter_mut().for_each(|s| s.seconds = 0.0);
            c
        };
        assert_eq!(strip(serial.checkpoint()), strip(resumed.checkpoint()));
    }

    /// Ten numbers in 0..1 scored by their closeness to 0.3, placed by the mean of each
    /// half: a real-valued problem for CMA-ME.
    struct Reals;

    impl Problem for Reals {
        type Genome = Vec<f64>;
        fn term_names(&self) -> Vec<String> {
            vec!["closeness".into()]
        }
        fn evaluate(&self, g: &Vec<f64>) -> Fitness {
            let d: f64 = g.iter().map(|x| (x - 0.3).powi(2)).sum();
            Fitness::new(-d, &[-d])
        }
        fn random_genome<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> Vec<f64> {
            (0..10).map(|_| rng.random::<f64>()).collect()
        }
    }

    impl Describe<Reals> for Reals {
        fn describe(&self, _: &Reals, g: &Vec<f64>, out: &mut [f64]) -> bool {
            out[0] = g[..5].iter().sum::<f64>() / 5.0;
            out[1] = g[5..].iter().sum::<f64>() / 5.0;
            true
        }
    }

    struct Unit([[f64; 2]; 10]);

    impl Coding<Reals> for Unit {
        fn bounds(&self) -> &[[f64; 2]] {
            &self.0
        }
        fn decode(&self, x: &[f64]) -> Vec<f64> {
            x.to_vec()
        }
        fn encode(&self, _: &Reals, g: &Vec<f64>) -> Option<Vec<f64>> {
            Some(g.clone())
        }
    }

    /// Nudges one number (the operators a CMA-ME run carries but does not use).
    struct Nudge;

    impl Mutate<Vec<f64>> for Nudge {
        fn mutate<R: rand::Rng + ?Sized>(&self, g: &mut Vec<f64>, rng: &mut R) {
            let i = rng.random_range(0..g.len());
            g[i] = (g[i] + rng.random_range(-0.1..0.1)).clamp(0.0, 1.0);
        }
    }

    impl Crossover<Vec<f64>> for Nudge {
        fn crossover<R: rand::Rng + ?Sized>(
            &self,
            a: &Vec<f64>,
            _: &Vec<f64>,
            _: &mut R,
        ) -> Vec<f64> {
            a.clone()
        }
    }

    impl Operators<Vec<f64>> for Nudge {
        type Crossover = Nudge;
        type Mutation = Nudge;
        fn crossover(&self) -> &Nudge {
            self
        }
        fn mutation(&self) -> &Nudge {
            self
        }
    }

    fn cma_settings() -> MapSettings {
        let axis = Axis {
            min: 0.0,
            max: 1.0,
            cells: 10,
        };
        MapSettings {
            seed: 5,
            axes: vec![axis, axis],
            initial: 20,
            batch: 25,
            crossover: 0.0,
            qd_offset: -10.0,
            emitter: Emitter::CmaMe {
                emitters: 3,
                sigma: 0.2,
            },
        }
    }

    fn cma_run(pool: Pool) -> MapRun<Reals, Nudge> {
        let coding: Arc<dyn Coding<Reals>> = Arc::new(Unit([[0.0, 1.0]; 10]));
        MapRun::new(
            Reals,
            Nudge,
            Arc::new(Reals),
            Some(coding),
            pool,
            cma_settings(),
            Vec::new(),
        )
        .unwrap()
    }

    #[test]
    fn cma_me_emitters_fill_the_map_and_resume_exactly() {
        let mut serial = cma_run(Pool::Serial);
        assert_eq!(serial.checkpoint().emitters.len(), 3);
        let first = serial.stats()[0].clone();
        let mut last = first.clone();
        serial.run_batch(40, |s| {
            assert!(s.filled >= last.filled && s.qd_score >= last.qd_score);
            last = s.clone();
        });
        assert!(last.filled > 2 * first.filled, "{first:?} {last:?}");
        let operators: Vec<_> = (serial.elites())
            .map(|e| e.individual.origin.operator.clone())
            .collect();
        assert!(operators.iter().any(|o| o == "cma-me"), "{operators:?}");
        // Samples outside the bounds were clamped onto them.
        for e in serial.elites() {
            assert!(e.individual.genome.iter().all(|x| (0.0..=1.0).contains(x)));
        }
        let mut parallel = cma_run(Pool::with_threads(3).unwrap());
        parallel.run_batch(15, |_| {});
        let saved = serde_json::to_string(&parallel.checkpoint()).unwrap();
        let coding: Arc<dyn Coding<Reals>> = Arc::new(Unit([[0.0, 1.0]; 10]));
        let checkpoint = serde_json::from_str(&saved).unwrap();
        let mut resumed = MapRun::resume(
            Reals,
            Nudge,
            Arc::new(Reals),
            Some(coding),
            Pool::Serial,
            checkpoint,
        )
        .unwrap();
        resumed.run_batch(25, |_| {});
        let strip = |c: MapCheckpoint<Vec<f64>>| {
            let mut c = c;
            c.stats.iter_mut().for_each(|s| s.seconds = 0.0);
            c
        };
        assert_eq!(strip(serial.checkpoint()), strip(resumed.checkpoint()));
    }

    #[test]
    fn cma_me_needs_a_coding_and_sound_emitters() {
        let no_coding = MapRun::new(
            Reals,
            Nudge,
            Arc::new(Reals),
            None,
            Pool::Serial,
            cma_settings(),
            vec![],
        );
        assert_eq!(no_coding.err(), Some(MapError::NoCoding));
        for (emitters, sigma, name) in [
            (0, 0.2, "emitters"),
            (13, 0.2, "emitters"),
            (3, 0.0, "sigma"),
            (3, f64::NAN, "sigma"),
            (3, 1.5, "sigma"),
        ] {
            let mut s = cma_settings();
            s.emitter = Emitter::CmaMe { emitters, sigma };
            assert!(
                matches!(s.validate(), Err(MapError::Number { name: n, .. }) if n == name),
                "{emitters} {sigma}"
            );
        }
        // The operators' settings and checkpoints keep their bytes: no emitter field.
        let text = serde_json::to_string(&settings()).unwrap();
        assert!(!text.contains("emitter"), "{text}");
        let back: MapSettings = serde_json::from_str(&text).unwrap();
        assert_eq!(back.emitter, Emitter::Operators);
    }
}
