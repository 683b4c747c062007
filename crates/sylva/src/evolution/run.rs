//! A run of any model ([`Evolution`]) and its members.

use std::path::Path;
use std::sync::Arc;

use sylva_core::Plant;
use sylva_core::par::{Pool, Stop};
use sylva_evolve::{
    Checkpoint, Fitness, GenerationStats, Individual, IndividualId, Origin, Problem, Run, WithTerm,
};
use sylva_model::Evolve;

use crate::erased::{DynModel, RunValue};
use crate::error::{Error, InputError};
use crate::genome::Genome;

use super::checkpoint::SavedRunRef;
use super::config::Config;
use super::hooks::{OwnRecord, RunHooks, Scored, foreseen};
use super::schema::EvolveConfig;

/// A member of a run's population (or of a kept generation), its genome as a genome file.
#[derive(Clone, Debug, PartialEq)]
pub struct Member {
    /// Its run-wide id.
    pub id: IndividualId,
    /// Its genome.
    pub genome: Genome,
    /// Its fitness, once evaluated.
    pub fitness: Option<Fitness>,
    /// How it was made, and its parents.
    pub origin: Origin,
}

impl Member {
    /// Its total fitness (negative infinity before evaluation).
    pub fn total(&self) -> f64 {
        self.fitness.map_or(f64::NEG_INFINITY, |f| f.total())
    }
}

/// Individual `ind` of a run of `model` solving `problem`, its genome as a genome file.
pub(super) fn member_of<M: Evolve + Default>(
    model: &M,
    problem: &M::Problem,
    ind: &sylva_evolve::Individual<<M::Problem as Problem>::Genome>,
) -> Member {
    Member {
        id: ind.id,
        genome: Genome::new(model.clone(), model.genome_file(problem, &ind.genome)),
        fitness: ind.fitness,
        origin: ind.origin.clone(),
    }
}

/// An evolution run of any model.
pub struct Evolution {
    model: Arc<dyn DynModel>,
    /// The model's `TypedRun`.
    run: Box<RunValue>,
}

/// The genome model `M` evolves.
type Evolved<M> = <<M as Evolve>::Problem as Problem>::Genome;

/// A run of model `M` with the config it follows.
pub(crate) struct TypedRun<M: Evolve> {
    pub(crate) config: EvolveConfig<M>,
    pub(crate) run: Run<WithTerm<M::Problem>, M::Strategy>,
    /// What the front end added, and what a stopped step left.
    pub(crate) hooked: Hooked<M>,
}

/// A run's [`RunHooks`] at work.
pub(crate) struct Hooked<M: Evolve> {
    /// Cuts steps short.
    pub(crate) stop: Option<Stop>,
    /// The own term, also held by the run's problem.
    pub(crate) scored: Option<Arc<Scored<M>>>,
    /// A second breeding of the model, to foresee what a generation evaluates.
    pub(crate) scout: Option<M::Strategy>,
    /// Where the run's work goes, to make it again after a stop.
    pub(crate) pool: Pool,
    /// The run as it stood before a step that was stopped, read in its place until the run
    /// steps again: the engine cannot undo a step, only resume from a checkpoint.
    pub(crate) resting: Option<Checkpoint<Evolved<M>>>,
}

impl<M: Evolve> Hooked<M> {
    /// Hooks that do nothing.
    pub(crate) fn none(pool: Pool) -> Self {
        Hooked {
            stop: None,
            scored: None,
            scout: None,
            pool,
            resting: None,
        }
    }
}

impl<M: Evolve + Default> TypedRun<M> {
    pub(crate) fn member(
        &self,
        ind: &sylva_evolve::Individual<<M::Problem as Problem>::Genome>,
    ) -> Member {
        member_of(&self.config.model, &self.run.problem().problem, ind)
    }

    /// The current population: the run's, or the one a stopped step left.
    fn members(&self) -> &[Individual<Evolved<M>>] {
        match &self.hooked.resting {
            Some(saved) => &saved.population,
            None => self.run.population(),
        }
    }

    pub(crate) fn generation(&self) -> u32 {
        match &self.hooked.resting {
            Some(saved) => saved.generation,
            None => self.run.generation(),
        }
    }

    pub(crate) fn stats(&self) -> &[GenerationStats] {
        match &self.hooked.resting {
            Some(saved) => &saved.stats,
            None => self.run.stats(),
        }
    }

    pub(crate) fn population(&self) -> Vec<Member> {
        self.members().iter().map(|i| self.member(i)).collect()
    }

    pub(crate) fn fittest(&self, count: usize) -> Vec<Member> {
        let population = self.members();
        sylva_evolve::fittest(population, count)
            .into_iter()
            .map(|i| self.member(&population[i]))
            .collect()
    }

    pub(crate) fn best(&self) -> Member {
        match &self.hooked.resting {
            // The fittest, ties to the lowest slot, as the run's own `best`.
            Some(saved) => {
                let at = sylva_evolve::fittest(&saved.population, 1);
                self.member(&saved.population[at.first().copied().unwrap_or(0)])
            }
            None => self.member(self.run.best()),
        }
    }

    pub(crate) fn find(&self, id: IndividualId) -> Option<Member> {
        match &self.hooked.resting {
            Some(saved) => saved.population.iter().find(|i| i.id == id),
            None => self.run.find(id),
        }
        .map(|i| self.member(i))
    }

    pub(crate) fn generation_members(&self, generation: u32) -> Option<Vec<Member>> {
        let population = match &self.hooked.resting {
            Some(saved) => (saved.generation == generation).then_some(&saved.population[..]),
            None => self.run.generation_population(generation),
        }?;
        Some(population.iter().map(|i| self.member(i)).collect())
    }

    pub(crate) fn keep_history(&mut self, generations: usize) {
        self.run.set_keep_history(generations);
        if let Some(saved) = &mut self.hooked.resting {
            saved.settings.keep_history = self.run.settings().keep_history;
        }
    }

    pub(crate) fn checkpoint(&self) -> Result<String, Error> {
        let saved = SavedRunRef::<M> {
            config: &self.config,
            checkpoint: match &self.hooked.resting {
                Some(saved) => saved.clone(),
                None => self.run.checkpoint(),
            },
            own_term: self.hooked.scored.as_ref().map(|s| OwnRecord::of(s.own())),
        };
        serde_json::to_string(&saved)
            .map_err(|e| InputError::new("checkpoint", e))
            .map_err(Error::from)
    }

    pub(crate) fn emigrants(&self, count: usize) -> Vec<String> {
        let population = self.members();
        sylva_evolve::fittest(population, count)
            .into_iter()
            .map(|i| serde_json::to_string(&population[i].genome).unwrap_or_default())
            .collect()
    }

    pub(crate) fn immigrate(&mut self, migrants: &[String]) -> Result<Vec<IndividualId>, Error> {
        let genomes = migrants
            .iter()
            .enumerate()
            .map(|(i, text)| {
                serde_json::from_str(text).map_err(|e| {
                    InputError::new(
                        format!("migrant {}", i + 1),
                        format!("not an evolved `{}` genome of this run: {e}", M::NAME),
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        self.settle()?;
        if let Some(scored) = &self.hooked.scored {
            let problem = &self.run.problem().problem;
            scored.prepare(problem, &genomes, &self.hooked.pool)?;
        }
        let slots = self.run.immigrate(genomes);
        self.failure()?;
        Ok(slots
            .into_iter()
            .map(|slot| self.run.population()[slot].id)
            .collect())
    }

    /// `work` watched by the run's stop, if it has one.
    fn watched<T>(stop: Option<&Stop>, work: impl FnOnce() -> T) -> Result<T, Error> {
        match stop {
            Some(stop) => Ok(stop.watch(work)?),
            None => Ok(work()),
        }
    }

    /// The error of the own term met scoring a genome it did not foresee, if any.
    pub(crate) fn failure(&self) -> Result<(), Error> {
        match self.hooked.scored.as_ref().and_then(|s| s.take_failure()) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Breeds one generation. Stopped, the run is left as it was before it (resting).
    pub(crate) fn step(&mut self) -> Result<(), Error> {
        self.settle()?;
        let stop = self.hooked.stop.clone();
        if let (Some(scored), Some(scout)) = (&self.hooked.scored, &self.hooked.scout) {
            let problem = &self.run.problem().problem;
            let (seed, generation) = (self.config.run.seed, self.run.generation());
            let population = self.run.population();
            let pool = &self.hooked.pool;
            Self::watched(stop.as_ref(), || {
                let genomes = foreseen(problem, scout, population, seed, generation + 1);
                scored.prepare(problem, &genomes, pool)
            })??;
        }
        let generation = self.run.generation();
        if let Err(e) = Self::watched(stop.as_ref(), || {
            self.run.step();
        }) {
            // The engine numbers the new generation before breeding it, and replaces members
            // only once its maps (where a stop ends them) are done: the population, its ids
            // and the statistics are the last generation's. Read the run as it was, and
            // resume from it when it steps.
            let mut saved = self.run.checkpoint();
            saved.generation = generation;
            self.hooked.resting = Some(saved);
            return Err(e);
        }
        self.failure()
    }

    /// Resumes the run from what a stopped step left, if it did: its population scored again
    /// (the engine re-derives fitness when it resumes), watched by the run's stop.
    fn settle(&mut self) -> Result<(), Error> {
        let Some(saved) = self.hooked.resting.take() else {
            return Ok(());
        };
        let problem = self.run.problem().clone();
        let config = &self.config;
        let hooked = &self.hooked;
        let made = Self::watched(hooked.stop.as_ref(), || -> Result<_, Error> {
            if let Some(scored) = &hooked.scored {
                let genomes = saved.population.iter().map(|i| &i.genome);
                scored.prepare(&problem.problem, genomes, &hooked.pool)?;
            }
            let setup =
                super::config::setup(&config.model, &config.settings, Vec::new(), 0, 0, "the run")?;
            sylva_evolve::Run::resume(problem, setup.strategy, hooked.pool.clone(), saved.clone())
                .map_err(|e| Error::from(InputError::new("the run", e)))
        });
        match made {
            Ok(Ok(run)) => {
                self.run = run;
                self.failure()
            }
            Ok(Err(e)) | Err(e) => {
                self.hooked.resting = Some(saved);
                Err(e)
            }
        }
    }
}

impl std::fmt::Debug for Evolution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Evolution")
            .field("model", &self.title())
            .field("generation", &self.generation())
            .finish()
    }
}

impl Evolution {
    /// Starts a run: generation 0 made and evaluated. `start` holds the first members (of
    /// the config's model; the model may add mutants of them), the rest is random.
    pub fn start(config: &Config, start: Vec<Genome>, pool: Pool) -> Result<Evolution, Error> {
        Evolution::start_with(config, start, pool, RunHooks::default())
    }

    /// [`Evolution::start`] with what a front end adds ([`RunHooks`]): its stop (stopped,
    /// making generation 0 returns [`Error::Stopped`]) and a fitness term of its own (refused
    /// beside a config's `[match]`: a run takes one added term).
    pub fn start_with(
        config: &Config,
        start: Vec<Genome>,
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Evolution, Error> {
        let (model, typed) = config.parts();
        let source = config.source();
        let base = config.base();
        let stop = hooks.stop.clone();
        let make = || model.start(typed, &source, &base, start, pool, hooks);
        let run = match &stop {
            Some(stop) => stop.watch(make)??,
            None => make()?,
        };
        Evolution::checked(model, run, &source)
    }

    /// Resumes the run saved in a checkpoint's `text` (read from `path`), which must have
    /// been written by the same config (but for the run's length, threads and checkpoint
    /// interval). The run continues exactly as if it had never stopped.
    pub fn resume(
        config: &Config,
        path: &Path,
        text: &str,
        pool: Pool,
    ) -> Result<Evolution, Error> {
        Evolution::resume_with(config, path, text, pool, RunHooks::default())
    }

    /// [`Evolution::resume`] with what a front end adds ([`RunHooks`]). A run checkpointed
    /// with a fitness term of its own is resumed with one of the same name, weight and mode
    /// (the checkpoint records them, not the function), and one without, without.
    pub fn resume_with(
        config: &Config,
        path: &Path,
        text: &str,
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Evolution, Error> {
        let (model, typed) = config.parts();
        let source = config.source();
        let base = config.base();
        let stop = hooks.stop.clone();
        let make = || model.resume(typed, &source, &base, path, text, pool, hooks);
        let run = match &stop {
            Some(stop) => stop.watch(make)??,
            None => make()?,
        };
        Evolution::checked(model, run, &source)
    }

    /// Sets the stop that cuts the run's steps short from now on ([`RunHooks::stop`]).
    pub fn set_stop(&mut self, stop: Option<Stop>) {
        self.model.set_stop(&mut *self.run, stop);
    }

    /// The run, if its generation has a member with a finite fitness.
    fn checked(model: &Arc<dyn DynModel>, run: Box<RunValue>, source: &str) -> Result<Self, Error> {
        let evolution = Evolution {
            model: model.clone(),
            run,
        };
        evolution.check_finite(source)?;
        Ok(evolution)
    }

    /// The effective config.
    pub fn config(&self) -> Config {
        Config::erased(self.model.clone(), self.model.effective_config(&*self.run))
    }

    /// The model's title, for plots.
    pub fn title(&self) -> &'static str {
        self.model.title()
    }

    /// Breeds one generation and returns its statistics. A generation in which no member
    /// has a finite fitness stops the run with an error: its settings cannot score.
    ///
    /// With a [`Stop`] ([`RunHooks::stop`]), a generation stopped part way returns
    /// [`Error::Stopped`] and leaves the run as it was before it: its generation, population,
    /// statistics and checkpoint are those of the last whole generation (generations kept for
    /// browsing are let go). The next step first scores that population again, as resuming
    /// from its checkpoint would (the engine cannot undo half a generation), then breeds; the
    /// run goes on exactly as if it had not been stopped. An own term's error leaves the run
    /// as it was before the step, too.
    pub fn step(&mut self) -> Result<&GenerationStats, Error> {
        self.model.step(&mut *self.run)?;
        self.check_finite("the run")?;
        Ok(self.stats().last().expect("a run has statistics"))
    }

    /// Breeds `generations` generations, calling `on_generation` after each.
    pub fn step_batch(
        &mut self,
        generations: u32,
        mut on_generation: impl FnMut(&GenerationStats),
    ) -> Result<(), Error> {
        for _ in 0..generations {
            on_generation(self.step()?);
        }
        Ok(())
    }

    /// An error if no member of the last generation has a finite fitness.
    fn check_finite(&self, source: &str) -> Result<(), InputError> {
        match self.stats().last() {
            Some(s) if !s.best.is_finite() => Err(InputError::new(
                source,
                format!(
                    "no member of generation {} has a finite fitness (the best is {}): these \
                     settings cannot score a {} genome; check the model's settings and start \
                     genomes",
                    s.generation,
                    s.best,
                    self.title()
                ),
            )),
            _ => Ok(()),
        }
    }

    /// The last completed generation.
    pub fn generation(&self) -> u32 {
        self.model.generation(&*self.run)
    }

    /// Statistics of every generation so far, one row each.
    pub fn stats(&self) -> &[GenerationStats] {
        self.model.stats(&*self.run)
    }

    /// Names of the fitness terms, in the order of each row's terms.
    pub fn term_names(&self) -> &[String] {
        self.model.term_names(&*self.run)
    }

    /// The current population, in slot order.
    pub fn population(&self) -> Vec<Member> {
        self.model.population(&*self.run)
    }

    /// The `count` fittest members of the current population, fittest first (ties go to the
    /// lower slot).
    pub fn fittest(&self, count: usize) -> Vec<Member> {
        self.model.fittest(&*self.run, count)
    }

    /// The best member of the current population (ties go to the lowest slot).
    pub fn best(&self) -> Member {
        self.model.best(&*self.run)
    }

    /// A member by id, in the current population or a kept generation.
    pub fn member(&self, id: IndividualId) -> Option<Member> {
        self.model.member(&*self.run, id)
    }

    /// The population of `generation`, if it is the current one or still kept.
    pub fn generation_members(&self, generation: u32) -> Option<Vec<Member>> {
        self.model.generation_members(&*self.run, generation)
    }

    /// Keeps the last `generations` generations for browsing (0, the default, keeps only the
    /// current one).
    pub fn keep_history(&mut self, generations: usize) {
        self.model.keep_history(&mut *self.run, generations);
    }

    /// A member's family, as far as kept generations reach: the member, then its parents,
    /// their parents and so on, each once, nearest first.
    pub fn family(&self, id: IndividualId) -> Vec<Member> {
        let mut family: Vec<Member> = Vec::new();
        let mut queue = vec![id];
        while let Some(id) = queue.pop() {
            if family.iter().any(|m| m.id == id) {
                continue;
            }
            if let Some(m) = self.member(id) {
                queue.extend(m.origin.parents.iter().rev());
                family.push(m);
            }
        }
        family
    }

    /// The checkpoint file's text (JSON): the effective config and everything needed to
    /// resume.
    pub fn checkpoint(&self) -> Result<String, Error> {
        self.model.checkpoint(&*self.run)
    }

    /// Guides drawn beside plants in pictures (a target surface, forbidden cells), if the
    /// model's fitness has any.
    pub fn guides(&self) -> Option<Plant> {
        self.model.guides(&*self.run)
    }

    /// The `count` fittest genomes of the current population, fittest first, as the engine
    /// evolves them (JSON text): what an island sends to its neighbours.
    pub fn emigrants(&self, count: usize) -> Vec<String> {
        self.model.emigrants(&*self.run, count)
    }

    /// Puts migrants from [`Evolution::emigrants`] of another run of the same config (its
    /// seed may differ) in the places of the current population's worst members, and
    /// evaluates them; returns their new ids. Nothing changes if any migrant is not a genome
    /// of this run.
    pub fn immigrate(&mut self, migrants: &[String]) -> Result<Vec<IndividualId>, Error> {
        self.model.immigrate(&mut *self.run, migrants)
    }
}
