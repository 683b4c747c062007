//! A run: a population evolving generation by generation, with statistics, a bounded
//! history to browse, and checkpoints to resume from.
//!
//! Generation 0 is random (or given). [`Run::step`] breeds one generation; [`Run::run_batch`]
//! breeds several, calling back after each (a progress bar, or an interactive screen's
//! "run a batch of generations"). [`Browser`] walks the population left and right and the
//! kept generations back and forth, as the viewer of Susinno's paper did.
//!
//! Everything random is drawn from streams keyed by `(seed, generation, slot)`, so a run
//! resumed from a checkpoint continues exactly as if it had never stopped.

use std::collections::VecDeque;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::Pool;
use crate::fitness::MAX_TERMS;
use crate::individual::{Individual, IndividualId, Origin};
use crate::problem::Problem;
use crate::rng;
use crate::strategy::{Breeding, Strategy, evaluate_missing, mean_total, two_best};

/// What a run is asked to do.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSettings {
    /// Seed of every random stream.
    pub seed: u64,
    /// Individuals per generation (at least 1).
    pub population: usize,
    /// Past generations kept for browsing (0 keeps none; the current one is always there).
    pub keep_history: usize,
}

/// Why a run cannot start or resume.
#[derive(Debug, Error, PartialEq)]
pub enum EvolveError {
    /// Population size zero.
    #[error("population must hold at least 1 individual")]
    EmptyPopulation,
    /// The problem declares more fitness terms than a fitness can keep.
    #[error("the problem declares {0} fitness terms; at most {MAX_TERMS} are supported")]
    TooManyTerms(usize),
    /// A checkpoint that does not fit.
    #[error("checkpoint does not fit this run: {0}")]
    BadCheckpoint(String),
}

/// One generation's figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GenerationStats {
    /// Generation number (0 is the initial population).
    pub generation: u32,
    /// Best total fitness.
    pub best: f64,
    /// Mean of the finite totals.
    pub mean: f64,
    /// Id of the best individual.
    pub best_id: IndividualId,
    /// The best individual's fitness terms.
    pub best_terms: Vec<f64>,
    /// Evaluations run to make this generation.
    pub evaluations: u64,
    /// Wall time spent making it (not deterministic; excluded from golden comparisons).
    pub seconds: f64,
}

impl GenerationStats {
    /// Evaluations per second (0 when no time was measured).
    pub fn evals_per_second(&self) -> f64 {
        if self.seconds > 0.0 {
            self.evaluations as f64 / self.seconds
        } else {
            0.0
        }
    }
}

/// Everything needed to resume a run (history is not kept).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint<G> {
    /// Checkpoint format version.
    pub format: u32,
    /// The settings the run was started with.
    pub settings: RunSettings,
    /// The last completed generation.
    pub generation: u32,
    /// The next unused individual id.
    pub next_id: u64,
    /// The evaluated population of `generation`.
    pub population: Vec<Individual<G>>,
    /// Statistics of generations 0 to `generation`.
    pub stats: Vec<GenerationStats>,
}

/// The checkpoint format this version writes and reads.
pub const CHECKPOINT_FORMAT: u32 = 1;

/// Most generations a run keeps for browsing.
pub const MAX_HISTORY: usize = 10_000;

pub use crate::individual::MAX_GENERATION;

/// An evolving population.
pub struct Run<P: Problem, S> {
    problem: P,
    strategy: S,
    evaluator: Pool,
    settings: RunSettings,
    term_names: Vec<String>,
    generation: u32,
    next_id: u64,
    population: Vec<Individual<P::Genome>>,
    stats: Vec<GenerationStats>,
    history: VecDeque<(u32, Vec<Individual<P::Genome>>)>,
}

impl<P: Problem, S: Strategy<P>> Run<P, S> {
    /// Starts a run from a random population, evaluated.
    pub fn new(
        problem: P,
        strategy: S,
        evaluator: Pool,
        settings: RunSettings,
    ) -> Result<Self, EvolveError> {
        Self::with_genomes(problem, strategy, evaluator, settings, Vec::new())
    }

    /// Starts a run whose first members are `genomes` (for example favourites a person
    /// picked); the rest of the population is random. Extra genomes are ignored.
    pub fn with_genomes(
        problem: P,
        strategy: S,
        evaluator: Pool,
        settings: RunSettings,
        genomes: Vec<P::Genome>,
    ) -> Result<Self, EvolveError> {
        if settings.population == 0 {
            return Err(EvolveError::EmptyPopulation);
        }
        let term_names = problem.term_names();
        if term_names.len() > MAX_TERMS {
            return Err(EvolveError::TooManyTerms(term_names.len()));
        }
        let given = genomes.len().min(settings.population);
        let random = evaluator.map(settings.population - given, |k| {
            problem.random_genome(&mut rng::stream(settings.seed, 0, (given + k) as u32))
        });
        let population: Vec<_> = genomes
            .into_iter()
            .take(given)
            .map(|g| (g, "given"))
            .chain(random.into_iter().map(|g| (g, "random")))
            .enumerate()
            .map(|(i, (genome, operator))| Individual {
                id: IndividualId(i as u64),
                genome,
                fitness: None,
                origin: Origin::new(0, operator),
            })
            .collect();
        let mut run = Run {
            problem,
            strategy,
            evaluator,
            next_id: population.len() as u64,
            settings,
            term_names,
            generation: 0,
            population,
            stats: Vec::new(),
            history: VecDeque::new(),
        };
        let start = Instant::now();
        let evaluations = evaluate_missing(&run.problem, &mut run.population, &run.evaluator);
        run.record(evaluations, start);
        Ok(run)
    }

    /// Resumes from a checkpoint; the run continues exactly as the original would have.
    pub fn resume(
        problem: P,
        strategy: S,
        evaluator: Pool,
        checkpoint: Checkpoint<P::Genome>,
    ) -> Result<Self, EvolveError> {
        let bad = |why: String| Err(EvolveError::BadCheckpoint(why));
        if checkpoint.format != CHECKPOINT_FORMAT {
            return bad(format!(
                "format {} (this version reads {CHECKPOINT_FORMAT})",
                checkpoint.format
            ));
        }
        if checkpoint.population.len() != checkpoint.settings.population {
            return bad(format!(
                "{} individuals saved for a population of {}",
                checkpoint.population.len(),
                checkpoint.settings.population
            ));
        }
        if checkpoint.settings.keep_history > MAX_HISTORY {
            return bad(format!(
                "it keeps {} generations; at most {MAX_HISTORY}",
                checkpoint.settings.keep_history
            ));
        }
        if checkpoint.generation > MAX_GENERATION {
            return bad(format!(
                "generation {} is past the last, {MAX_GENERATION}",
                checkpoint.generation
            ));
        }
        if checkpoint.stats.len() != checkpoint.generation as usize + 1 {
            return bad(format!(
                "{} statistics rows for generation {}",
                checkpoint.stats.len(),
                checkpoint.generation
            ));
        }
        let term_names = problem.term_names();
        let mut run = Run {
            problem,
            strategy,
            evaluator,
            settings: checkpoint.settings,
            term_names,
            generation: checkpoint.generation,
            next_id: checkpoint.next_id,
            population: checkpoint.population,
            stats: checkpoint.stats,
            history: VecDeque::new(),
        };
        // Fitness is re-derived, not trusted: a checkpoint edited by hand stays consistent.
        for ind in &mut run.population {
            ind.fitness = None;
        }
        evaluate_missing(&run.problem, &mut run.population, &run.evaluator);
        Ok(run)
    }

    /// Breeds one generation and returns its statistics.
    pub fn step(&mut self) -> &GenerationStats {
        let start = Instant::now();
        if self.settings.keep_history > 0 {
            if self.history.len() == self.settings.keep_history {
                self.history.pop_front();
            }
            self.history
                .push_back((self.generation, self.population.clone()));
        }
        // A run stops growing its generation count at the last one (streams then repeat).
        self.generation = (self.generation + 1).min(MAX_GENERATION);
        let mut ctx = Breeding::new(
            self.settings.seed,
            self.generation,
            &self.evaluator,
            &mut self.next_id,
        );
        let evaluations = self
            .strategy
            .breed(&self.problem, &mut self.population, &mut ctx);
        self.record(evaluations, start);
        self.stats.last().expect("record pushed a row")
    }

    /// Breeds `generations` generations, calling `on_generation` after each.
    pub fn run_batch(&mut self, generations: u32, mut on_generation: impl FnMut(&GenerationStats)) {
        for _ in 0..generations {
            on_generation(self.step());
        }
    }

    fn record(&mut self, evaluations: u64, start: Instant) {
        let (best, _) = two_best(&self.population).expect("population is never empty");
        let b = &self.population[best];
        self.stats.push(GenerationStats {
            generation: self.generation,
            best: b.total(),
            mean: mean_total(&self.population),
            best_id: b.id,
            best_terms: b.fitness.map(|f| f.terms().to_vec()).unwrap_or_default(),
            evaluations,
            seconds: start.elapsed().as_secs_f64(),
        });
    }

    /// The last completed generation.
    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// The current population.
    pub fn population(&self) -> &[Individual<P::Genome>] {
        &self.population
    }

    /// The best individual of the current population (ties go to the lowest slot).
    pub fn best(&self) -> &Individual<P::Genome> {
        let (best, _) = two_best(&self.population).expect("population is never empty");
        &self.population[best]
    }

    /// Statistics of every generation so far.
    pub fn stats(&self) -> &[GenerationStats] {
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
    pub fn settings(&self) -> &RunSettings {
        &self.settings
    }

    /// Keeps the last `generations` generations for browsing from now on (0 keeps none;
    /// the current one is always there). Results do not depend on it.
    pub fn set_keep_history(&mut self, generations: usize) {
        let generations = generations.min(MAX_HISTORY);
        self.settings.keep_history = generations;
        while self.history.len() > generations {
            self.history.pop_front();
        }
    }

    /// The population of `generation`, if it is the current one or still kept.
    pub fn generation_population(&self, generation: u32) -> Option<&[Individual<P::Genome>]> {
        if generation == self.generation {
            return Some(&self.population);
        }
        self.history
            .iter()
            .find(|(g, _)| *g == generation)
            .map(|(_, pop)| pop.as_slice())
    }

    /// The oldest generation still available for browsing.
    pub fn oldest_generation(&self) -> u32 {
        self.history.front().map_or(self.generation, |(g, _)| *g)
    }

    /// An individual by id, in the current population or the kept history.
    pub fn find(&self, id: IndividualId) -> Option<&Individual<P::Genome>> {
        self.population
            .iter()
            .chain(self.history.iter().rev().flat_map(|(_, pop)| pop.iter()))
            .find(|ind| ind.id == id)
    }

    /// Puts `genomes` (migrants from another population, as island models exchange them) in
    /// the places of the current population's worst members, one each, and evaluates them.
    /// They get new ids and the operator `"immigrant"`; their evaluations count toward the
    /// current generation's row. Ties among the worst go to the higher slot; genomes beyond
    /// the population's size are ignored. Returns the slots filled, in the order given.
    pub fn immigrate(&mut self, genomes: Vec<P::Genome>) -> Vec<usize> {
        let mut worst = crate::strategy::fittest(&self.population, self.population.len());
        worst.reverse();
        worst.truncate(genomes.len());
        for (&slot, genome) in worst.iter().zip(genomes) {
            self.population[slot] = Individual {
                id: IndividualId(self.next_id),
                genome,
                fitness: None,
                origin: Origin::new(self.generation, "immigrant"),
            };
            self.next_id += 1;
        }
        let evaluations = evaluate_missing(&self.problem, &mut self.population, &self.evaluator);
        if let Some(row) = self.stats.last_mut() {
            row.evaluations += evaluations;
        }
        worst
    }

    /// Everything needed to resume.
    pub fn checkpoint(&self) -> Checkpoint<P::Genome> {
        Checkpoint {
            format: CHECKPOINT_FORMAT,
            settings: self.settings.clone(),
            generation: self.generation,
            next_id: self.next_id,
            population: self.population.clone(),
            stats: self.stats.clone(),
        }
    }
}

/// A cursor over a run's family: left and right through a generation's population, back and
/// forth through the kept generations (the paper's `[` and `]` keys, and its "iterate through
/// generations until the tree changes").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Browser {
    /// The generation looked at.
    pub generation: u32,
    /// The slot looked at.
    pub index: usize,
}

impl Browser {
    /// Starts at the best individual of the current generation.
    pub fn at_best<P: Problem, S: Strategy<P>>(run: &Run<P, S>) -> Self {
        let (best, _) = two_best(run.population()).expect("population is never empty");
        Browser {
            generation: run.generation(),
            index: best,
        }
    }

    /// The individual under the cursor (`None` if its generation is no longer kept).
    pub fn current<'r, P: Problem, S: Strategy<P>>(
        &self,
        run: &'r Run<P, S>,
    ) -> Option<&'r Individual<P::Genome>> {
        run.generation_population(self.generation)?.get(self.index)
    }

    /// One slot left, wrapping around (`[`).
    pub fn left(&mut self, population: usize) {
        if population > 0 {
            self.index = (self.index + population - 1) % population;
        }
    }

    /// One slot right, wrapping around (`]`).
    pub fn right(&mut self, population: usize) {
        if population > 0 {
            self.index = (self.index + 1) % population;
        }
    }

    /// The same slot one generation earlier, if kept; returns whether it moved.
    pub fn earlier<P: Problem, S: Strategy<P>>(&mut self, run: &Run<P, S>) -> bool {
        let moved = self.generation > run.oldest_generation();
        if moved {
            self.generation -= 1;
        }
        moved
    }

    /// The same slot one generation later, if there is one; returns whether it moved.
    pub fn later<P: Problem, S: Strategy<P>>(&mut self, run: &Run<P, S>) -> bool {
        let moved = self.generation < run.generation();
        if moved {
            // A run stops growing its generation count at the last one (streams then repeat).
            self.generation = (self.generation + 1).min(MAX_GENERATION);
        }
        moved
    }
}
