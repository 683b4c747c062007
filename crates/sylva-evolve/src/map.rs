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
//! A generation's figures ([`MapStats`]) are the map's coverage (share of cells filled)
//! and its QD-score (the sum over elites of their fitness less
//! [`MapSettings::qd_offset`], so that filling a cell never lowers it when the offset is
//! below every fitness), as pyribs reports them. A [`MapCheckpoint`] resumes a run exactly.

use std::borrow::Cow;
use std::sync::Arc;
use std::time::Instant;

use rand::RngExt;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::Pool;
use crate::fitness::{Fitness, MAX_TERMS};
use crate::individual::{Individual, IndividualId, Origin};
use crate::problem::{Problem, evaluate};
use crate::rng;
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
}

/// An offspring, scored and described.
struct Offered<G> {
    genome: G,
    fitness: Fitness,
    descriptors: Option<Descriptors>,
    operator: &'static str,
    parents: Vec<IndividualId>,
}

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
}

impl<P: Problem, S: Operators<P::Genome> + Sync> MapRun<P, S> {
    /// Starts a run: `genomes` (extra ones are ignored) and random genomes up to
    /// [`MapSettings::initial`], evaluated and placed.
    pub fn new(
        problem: P,
        operators: S,
        describer: Arc<dyn Describe<P>>,
        evaluator: Pool,
        settings: MapSettings,
        genomes: Vec<P::Genome>,
    ) -> Result<Self, MapError> {
        let mut run = Self::empty(problem, operators, describer, evaluator, settings)?;
        let start = Instant::now();
        let seed = run.settings.seed;
        let given = genomes.len().min(run.settings.initial);
        let mut genomes: Vec<Option<P::Genome>> =
            genomes.into_iter().take(given).map(Some).collect();
        genomes.resize_with(run.settings.initial, || None);
        let offered = {
            let (problem, describer) = (&run.problem, &*run.describer);
            let axes = run.settings.axes.len();
            run.evaluator.map(genomes.len(), |k| {
                let (genome, operator) = match &genomes[k] {
                    Some(g) => (g.clone(), "given"),
                    None => (
                        problem.random_genome(&mut rng::stream(seed, 0, k as u32)),
                        "random",
                    ),
                };
                score(problem, describer, axes, genome, operator, Vec::new())
            })
        };
        let improved = run.offer(offered);
        run.record(improved, run.settings.initial as u64, start);
        Ok(run)
    }

    /// Resumes from a checkpoint: the elites are evaluated again and placed, and the run
    /// continues exactly as the original would have.
    pub fn resume(
        problem: P,
        operators: S,
        describer: Arc<dyn Describe<P>>,
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
        if checkpoint.generation > crate::run::MAX_GENERATION {
            return bad(format!(
                "generation {} is past the last, {}",
                checkpoint.generation,
                crate::run::MAX_GENERATION
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
            evaluator,
            checkpoint.settings,
        )?;
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
        evaluator: Pool,
        settings: MapSettings,
    ) -> Result<Self, MapError> {
        settings.validate()?;
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
        })
    }

    /// Breeds one generation, offers it to the map, and returns its statistics.
    pub fn step(&mut self) -> &MapStats {
        let start = Instant::now();
        self.generation = (self.generation + 1).min(crate::run::MAX_GENERATION);
        let (seed, generation) = (self.settings.seed, self.generation);
        let offered = {
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
                    return score(problem, describer, axes, genome, "random", Vec::new());
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
                score(problem, describer, axes, genome, operator, parents)
            })
        };
        let improved = self.offer(offered);
        self.record(improved, self.settings.batch as u64, start);
        self.stats.last().expect("record pushed a row")
    }

    /// Breeds `generations` generations, calling `on_generation` after each.
    pub fn run_batch(&mut self, generations: u32, mut on_generation: impl FnMut(&MapStats)) {
        for _ in 0..generations {
            on_generation(self.step());
        }
    }

    /// Offers scored offspring to the map in order; returns how many improved it.
    fn offer(&mut self, offered: Vec<Offered<P::Genome>>) -> usize {
        let mut improved = 0;
        for offer in offered {
            let id = IndividualId(self.next_id);
            self.next_id += 1;
            let origin = Origin {
                generation: self.generation,
                operator: Cow::Borrowed(offer.operator),
                parents: offer.parents.clone(),
            };
            improved += usize::from(self.place(id, offer, origin));
        }
        improved
    }

    /// Puts an offspring in its cell if the cell is empty or it beats the elite there;
    /// whether it did.
    fn place(&mut self, id: IndividualId, offer: Offered<P::Genome>, origin: Origin) -> bool {
        let Some(descriptors) = offer.descriptors else {
            return false;
        };
        if !offer.fitness.total().is_finite() {
            return false;
        }
        let axes = self.settings.axes.len();
        let cell = self.settings.cell(&descriptors[..axes]);
        let slot = &mut self.cells[cell];
        match slot {
            Some(elite) if elite.individual.total() >= offer.fitness.total() => return false,
            Some(_) => {}
            None => {
                let at = self.filled.partition_point(|&c| c < cell);
                self.filled.insert(at, cell);
            }
        }
        *slot = Some(Elite {
            individual: Individual {
                id,
                genome: offer.genome,
                fitness: Some(offer.fitness),
                origin,
            },
            descriptors: descriptors[..axes].to_vec(),
        });
        true
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
        }
    }
}

/// Evaluates and describes an offspring.
fn score<P: Problem>(
    problem: &P,
    describer: &dyn Describe<P>,
    axes: usize,
    genome: P::Genome,
    operator: &'static str,
    parents: Vec<IndividualId>,
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
        }
    }

    fn run(pool: Pool) -> MapRun<Halves, Ops> {
        let ops = Ops(OnePoint, BitFlip { rate: 0.05 });
        MapRun::new(Halves, ops, Arc::new(Halves), pool, settings(), Vec::new()).unwrap()
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
        let mut resumed =
            MapRun::resume(Halves, ops, Arc::new(Halves), Pool::Serial, checkpoint).unwrap();
        resumed.run_batch(6, |_| {});
        let strip = |c: MapCheckpoint<BitString<1>>| {
            let mut c = c;
            c.stats.iter_mut().for_each(|s| s.seconds = 0.0);
            c
        };
        assert_eq!(strip(serial.checkpoint()), strip(resumed.checkpoint()));
    }
}
