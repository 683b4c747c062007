//! What a front end adds to a run beside its config ([`RunHooks`]): a [`Stop`] that cuts a
//! long generation short, and a fitness term of its own ([`OwnTerm`]) that scores grown
//! plants a batch at a time (Python's `Evolution(config, fitness=f)`).
//!
//! The engine scores one genome at a time, inside its breeding, on its worker threads. An own
//! term is scored in batches all the same: before a generation is bred, a second breeding of
//! the same population (the model's strategy on a copy, with a term that only notes what it
//! is asked) names the genomes the generation will evaluate, since the genomes a generation
//! evaluates follow from the population before it, not from their own scores. Those are
//! grown, scored in batches of [`OwnTerm::batch`], and the scores kept by genome, for the
//! real breeding to find. A genome it did not foresee is scored alone, so the scores never
//! depend on the foresight, only the batching does.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, RwLock};

use serde::{Deserialize, Serialize};
use sylva_core::par::Pool;
pub use sylva_core::par::{Stop, Stopped};
use sylva_evolve::{Breeding, Individual, Problem, Strategy, Term, WithTerm};
use sylva_model::Evolve;

use crate::assets::{GrowOptions, Grown};
use crate::error::{Error, InputError};
use crate::genome::Genome;

/// Scores of grown plants, from code outside Sylva (a Python function).
pub trait PlantScorer: Send + Sync {
    /// One score per plant of `plants`, in their order (higher is better; NaN and
    /// infinities are refused: an infinite total cannot be ranked).
    /// An error stops the work that asked, the run as it was before it.
    fn score(&self, plants: Vec<Grown>) -> Result<Vec<f64>, ScorerError>;
}

/// Why a [`PlantScorer`] failed: its own error, kept whole for its front end to raise again.
pub type ScorerError = Box<dyn std::error::Error + Send + Sync>;

/// A fitness term of a front end's own, scored by a [`PlantScorer`].
#[derive(Clone)]
pub struct OwnTerm {
    /// Its name, beside the model's term names (statistics, `Member.terms`).
    pub name: String,
    /// What scores the plants.
    pub scorer: Arc<dyn PlantScorer>,
    /// Its weight in the total, 0 to 1,000,000.
    pub weight: f64,
    /// Whether the model's own terms still count (`false`: this term alone decides, and the
    /// model's own fitness is not computed).
    pub beside: bool,
    /// Most plants given to the scorer at once, 1 to 1,000,000 (plants are held in memory,
    /// meshes and all, while they are scored).
    pub batch: usize,
}

impl std::fmt::Debug for OwnTerm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OwnTerm")
            .field("name", &self.name)
            .field("weight", &self.weight)
            .field("beside", &self.beside)
            .field("batch", &self.batch)
            .finish()
    }
}

/// What a front end adds to a run (every field defaults to none).
#[derive(Clone, Debug, Default)]
pub struct RunHooks {
    /// Cuts the run's long work short: making generation 0, resuming, and each generation
    /// are stopped within one member's evaluation once it is set, and return
    /// [`Error::Stopped`]. A stopped generation leaves the run as it was before it
    /// ([`crate::Evolution::step`]). Default none: work runs to its end.
    pub stop: Option<Stop>,
    /// A term of the front end's own. Default none.
    pub term: Option<OwnTerm>,
}

/// An own term as a checkpoint records it, so that a run is resumed with the same one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct OwnRecord {
    pub(super) name: String,
    pub(super) weight: f64,
    pub(super) beside: bool,
}

impl OwnRecord {
    pub(super) fn of(term: &OwnTerm) -> OwnRecord {
        OwnRecord {
            name: term.name.clone(),
            weight: term.weight,
            beside: term.beside,
        }
    }

    fn describe(&self) -> String {
        let mode = if self.beside {
            "beside the model's terms"
        } else {
            "alone, in place of the model's terms"
        };
        format!("term `{}`, weight {}, {mode}", self.name, self.weight)
    }
}

/// An error unless a checkpoint written with `saved` is resumed with `given`.
pub(super) fn check_resumed(
    saved: Option<&OwnRecord>,
    given: Option<&OwnTerm>,
) -> Result<(), String> {
    let given = given.map(OwnRecord::of);
    match (saved, given.as_ref()) {
        (None, None) => Ok(()),
        (Some(s), Some(g)) if s == g => Ok(()),
        (Some(s), None) => Err(format!(
            "the run was written with a fitness function of its own ({}), which a checkpoint \
             cannot hold: resume it with that function again",
            s.describe()
        )),
        (None, Some(_)) => Err(
            "the run was written without a fitness function of its own: resume it without one"
                .to_owned(),
        ),
        (Some(s), Some(g)) => Err(format!(
            "the run was written with its own fitness {}; resumed with {}: give the same \
             weight and mode",
            s.describe(),
            g.describe()
        )),
    }
}

/// An own term's settings checked, against the model's term names it joins.
pub(super) fn check_term(term: &OwnTerm, model_terms: &[String]) -> Result<(), InputError> {
    if !(term.weight.is_finite() && (0.0..=1e6).contains(&term.weight)) {
        return Err(InputError::new(
            "fitness_weight",
            format!("{}; expected a number from 0 to 1000000", term.weight),
        ));
    }
    if !(1..=1_000_000).contains(&term.batch) {
        return Err(InputError::new(
            "fitness_batch",
            format!("{}; expected a whole number from 1 to 1000000", term.batch),
        ));
    }
    if term.name.is_empty() || (term.beside && model_terms.contains(&term.name)) {
        return Err(InputError::new(
            "fitness",
            format!(
                "the term name `{}` is empty or taken by the model's terms ({})",
                term.name,
                model_terms.join(", ")
            ),
        ));
    }
    Ok(())
}

/// The key an evolved genome's score is kept under: its JSON, as migrants travel.
fn key<G: Serialize>(genome: &G) -> String {
    serde_json::to_string(genome).unwrap_or_default()
}

/// An own term joined to model `M`'s problem: the scores foreseen for the genomes the run is
/// about to evaluate, and the scorer for any it did not foresee.
pub(crate) struct Scored<M> {
    model: M,
    own: OwnTerm,
    /// Scores of the genomes about to be evaluated, by [`key`].
    ready: RwLock<HashMap<String, f64>>,
    /// The first error met scoring a genome alone, for the step to return.
    failed: Mutex<Option<Error>>,
}

impl<M: Evolve + Default> Term<M::Problem> for Scored<M> {
    fn name(&self) -> &str {
        &self.own.name
    }

    fn score(&self, problem: &M::Problem, genome: &<M::Problem as Problem>::Genome) -> f64 {
        let found = self
            .ready
            .read()
            .unwrap_or_else(|e| e.into_inner())
            .get(&key(genome))
            .copied();
        if let Some(score) = found {
            return score;
        }
        match self.score_now(problem, &[genome], &Pool::Serial) {
            Ok(scores) => scores.first().copied().unwrap_or(f64::NAN),
            Err(e) => {
                let mut failed = self.failed.lock().unwrap_or_else(|e| e.into_inner());
                failed.get_or_insert(e);
                f64::NAN
            }
        }
    }
}

impl<M: Evolve + Default> Scored<M> {
    pub(super) fn new(model: &M, own: &OwnTerm) -> Scored<M> {
        Scored {
            model: model.clone(),
            own: own.clone(),
            ready: RwLock::new(HashMap::new()),
            failed: Mutex::new(None),
        }
    }

    /// Scores `genomes` ahead of their evaluation, in batches, the plants grown on `pool`;
    /// the scores replace those kept before. The same genome is scored once.
    pub(super) fn prepare<'g>(
        &self,
        problem: &M::Problem,
        genomes: impl IntoIterator<Item = &'g <M::Problem as Problem>::Genome>,
        pool: &Pool,
    ) -> Result<(), Error> {
        let mut ready = HashMap::new();
        let mut todo = Vec::new();
        for genome in genomes {
            let key = key(genome);
            if !ready.contains_key(&key) {
                ready.insert(key.clone(), f64::NAN);
                todo.push((key, genome));
            }
        }
        for batch in todo.chunks(self.own.batch) {
            let genomes: Vec<_> = batch.iter().map(|(_, g)| *g).collect();
            let scores = self.score_now(problem, &genomes, pool)?;
            for ((key, _), score) in batch.iter().zip(scores) {
                ready.insert(key.clone(), score);
            }
        }
        *self.ready.write().unwrap_or_else(|e| e.into_inner()) = ready;
        Ok(())
    }

    /// The term as the front end gave it.
    pub(super) fn own(&self) -> &OwnTerm {
        &self.own
    }

    /// The error met scoring a genome that was not foreseen, if any, once.
    pub(super) fn take_failure(&self) -> Option<Error> {
        self.failed.lock().unwrap_or_else(|e| e.into_inner()).take()
    }

    /// Scores of `genomes`: grown with their own seeds on `pool`, then scored in one call; a
    /// genome that cannot be grown and meshed scores negative infinity, unseen by the scorer.
    fn score_now(
        &self,
        problem: &M::Problem,
        genomes: &[&<M::Problem as Problem>::Genome],
        pool: &Pool,
    ) -> Result<Vec<f64>, Error> {
        let grown = pool.map(genomes.len(), |i| {
            let file = self.model.genome_file(problem, genomes[i]);
            Grown::grow(
                Genome::new(self.model.clone(), file),
                &GrowOptions::default(),
            )
            .ok()
        });
        let at: Vec<usize> = (0..grown.len()).filter(|&i| grown[i].is_some()).collect();
        let plants: Vec<Grown> = grown.into_iter().flatten().collect();
        let count = plants.len();
        let scores = if count == 0 {
            Vec::new()
        } else {
            self.own.scorer.score(plants).map_err(Error::Scorer)?
        };
        if scores.len() != count {
            return Err(InputError::new(
                "fitness",
                format!(
                    "the fitness function returned {} scores for a batch of {count} plants; \
                     expected one number per plant, in order",
                    scores.len()
                ),
            )
            .into());
        }
        // An infinite score makes an infinite total, which the run cannot rank (one +inf
        // is every member's best, all -inf leave no member with a fitness): refused as NaN is.
        if let Some(i) = scores.iter().position(|s| !s.is_finite()) {
            return Err(InputError::new(
                "fitness",
                format!(
                    "the fitness function returned {} for plant {i} of a batch of {count}; \
                     expected a finite number (a very low one for the worst)",
                    scores[i]
                ),
            )
            .into());
        }
        let mut out = vec![f64::NEG_INFINITY; genomes.len()];
        for (i, score) in at.into_iter().zip(scores) {
            out[i] = score;
        }
        Ok(out)
    }
}

/// A term that scores every genome 0 and notes it: what a generation will evaluate, found by
/// breeding a copy of the population with it alone (the model's own fitness not computed).
struct Noted<G> {
    seen: Mutex<Vec<G>>,
}

impl<P: Problem> Term<P> for Noted<P::Genome> {
    fn name(&self) -> &str {
        "noted"
    }

    fn score(&self, _: &P, genome: &P::Genome) -> f64 {
        self.seen
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(genome.clone());
        0.0
    }
}

/// `problem` with only a [`Noted`] term, and the term to read.
fn noting<P: Problem + Clone>(problem: &P) -> (WithTerm<P>, Arc<Noted<P::Genome>>)
where
    P::Genome: 'static,
{
    let noted = Arc::new(Noted {
        seen: Mutex::new(Vec::new()),
    });
    let added = sylva_evolve::Added {
        term: noted.clone() as Arc<dyn Term<P>>,
        weight: 1.0,
        beside: false,
    };
    (
        WithTerm {
            problem: problem.clone(),
            added: Some(added),
        },
        noted,
    )
}

/// The genomes `strategy` evaluates breeding `population` into generation `generation` of a
/// run seeded `seed`, in the order a serial run evaluates them (what
/// [`sylva_evolve::Run::step`] does, on a copy).
pub(super) fn foreseen<P, S>(
    problem: &P,
    strategy: &S,
    population: &[Individual<P::Genome>],
    seed: u64,
    generation: u32,
) -> Vec<P::Genome>
where
    P: Problem + Clone,
    P::Genome: 'static,
    S: Strategy<WithTerm<P>>,
{
    let (noting, noted) = noting(problem);
    let mut copy = population.to_vec();
    let mut next_id = 0;
    let mut ctx = Breeding::new(seed, generation, &Pool::Serial, &mut next_id);
    strategy.breed(&noting, &mut copy, &mut ctx);
    std::mem::take(&mut *noted.seen.lock().unwrap_or_else(|e| e.into_inner()))
}

/// The members of generation 0 of a run of `problem` started with `first` (slot order), made
/// as [`sylva_evolve::Run::with_genomes`] makes them, unevaluated by the model.
pub(super) fn first_generation<P, S>(
    problem: &P,
    strategy: S,
    pool: &Pool,
    settings: sylva_evolve::RunSettings,
    first: Vec<P::Genome>,
) -> Result<Vec<P::Genome>, sylva_evolve::EvolveError>
where
    P: Problem + Clone,
    P::Genome: 'static,
    S: Strategy<WithTerm<P>>,
{
    let (noting, _) = noting(problem);
    let run = sylva_evolve::Run::with_genomes(noting, strategy, pool.clone(), settings, first)?;
    Ok(run.population().iter().map(|i| i.genome.clone()).collect())
}
