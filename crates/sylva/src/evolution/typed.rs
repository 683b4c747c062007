//! A run of one model, typed ([`TypedRun`]): how it starts from a config of that model, or
//! resumes from a checkpoint, with what a front end hooks in; and its population as
//! [`Member`]s, genomes of any model. [`Evolution`](super::Evolution) is its erased face.

use std::path::Path;
use std::sync::Arc;

use sylva_core::par::{Pool, Stop};
use sylva_evolve::{
    Checkpoint, Fitness, GenerationStats, Individual, IndividualId, Origin, Problem, Run,
    RunSettings, WithTerm,
};
use sylva_model::Evolve;

use crate::error::{Error, InputError};
use crate::genome::Genome;

use super::checkpoint::{SavedRun, SavedRunRef};
use super::hooks::{
    OwnRecord, RunHooks, Scored, check_resumed, check_term, first_generation, foreseen,
};
use super::schema::{EvolveConfig, SearchStrategy};
use super::silhouette::Target;

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

/// The genome model `M` evolves.
type Evolved<M> = <<M as Evolve>::Problem as Problem>::Genome;

/// Where a config came from: how errors name it, and its `[match]` pictures as read.
pub(crate) struct Where {
    pub(crate) source: String,
    pub(crate) target: Option<Target>,
}

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

    /// The run of `config` made of `run` and its hooks, refused if the own term already
    /// failed on a genome it did not foresee.
    fn checked(
        config: &EvolveConfig<M>,
        run: Run<WithTerm<M::Problem>, M::Strategy>,
        hooked: Hooked<M>,
    ) -> Result<Self, Error> {
        let typed = TypedRun {
            config: config.clone(),
            run,
            hooked,
        };
        typed.failure()?;
        Ok(typed)
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
            let setup = setup(config, None, Vec::new(), 0, 0, "the run")?;
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

/// How long a generation of a run may take ([`Config::generation_time`]).
#[derive(Clone, Debug, PartialEq)]
pub struct GenerationTime {
    /// Seconds, at the settings' bounds.
    pub seconds: f64,
    /// What a generation does, naming the settings it follows.
    pub what: String,
    /// What to change to make it shorter.
    pub advice: String,
}

/// Starts a run of `config`: generation 0 made and evaluated. A refusal names the config
/// (`source`).
pub(crate) fn start<M: Evolve + Default>(
    config: &EvolveConfig<M>,
    at: &Where,
    start: Vec<Genome>,
    pool: Pool,
    hooks: RunHooks,
) -> Result<TypedRun<M>, Error> {
    let (source, target) = (at.source.as_str(), at.target.as_ref());
    if config.run.strategy == SearchStrategy::MapElites {
        return Err(InputError::new(
            source,
            "`[run] strategy = \"map-elites\"` fills a map of varieties: run it with `sylva \
             evolve`, or as varieties (sylva.varieties in Python), not as one population",
        )
        .into());
    }
    let typed = typed_start::<M>(&start)?;
    let (seed, population) = (config.run.seed, config.run.population as usize);
    // A population and its offspring, each genome at the settings' bounds.
    let genome = config.model.genome_bytes(&config.settings);
    sylva_core::budget::check(
        (population as u64).saturating_mul(genome).saturating_mul(2),
        format_args!("a population of {population} (`population`)"),
        "breed a smaller population, or smaller genomes",
    )
    .map_err(|e| InputError::new(source, e).over_limit())?;
    let made = |start: Vec<M::Genome>| setup(config, target, start, seed, population, source);
    // With an own term, the model is set up twice more: to make generation 0 once without its
    // fitness, and to foresee each generation's genomes (`hooks.rs`).
    let again = hooks.term.as_ref().map(|_| typed.clone());
    let setup = made(typed)?;
    let scout = || Ok(made(again.clone().unwrap_or_default())?.strategy);
    let (problem, hooked) = with_hooks(config, setup.problem, target, pool, hooks, scout)?;
    // The settings are valid; generation 0 grows as the run is made.
    if let Some(t) = config.generation_time(&start, hooked.pool.threads()) {
        sylva_core::budget::check_time(t.seconds, t.what, t.advice)
            .map_err(|e| InputError::new(source, e).over_limit())?;
    }
    let settings = RunSettings {
        seed,
        population,
        keep_history: 0,
    };
    let refused = |e| InputError::new("[run]", e);
    if let Some(scored) = &hooked.scored {
        // Generation 0 made once more without the model's fitness, to score it in batches.
        let again = made(again.unwrap_or_default())?;
        let first = first_generation(
            &problem.problem,
            again.strategy,
            &hooked.pool,
            settings.clone(),
            again.first,
        )
        .map_err(refused)?;
        scored.prepare(&problem.problem, &first, &hooked.pool)?;
    }
    let run = Run::with_genomes(
        problem,
        setup.strategy,
        hooked.pool.clone(),
        settings,
        setup.first,
    )
    .map_err(refused)?;
    TypedRun::checked(config, run, hooked)
}

/// The problem of `config` with its added term (the `[match]` outline or `hooks`' own term,
/// not both), and the hooks at work; with an own term, a second breeding of the model made
/// by `scout`, to foresee what generations evaluate.
fn with_hooks<M: Evolve + Default>(
    config: &EvolveConfig<M>,
    problem: M::Problem,
    target: Option<&Target>,
    pool: Pool,
    hooks: RunHooks,
    scout: impl FnOnce() -> Result<M::Strategy, InputError>,
) -> Result<(WithTerm<M::Problem>, Hooked<M>), InputError> {
    let mut hooked = Hooked::none(pool);
    hooked.stop = hooks.stop;
    let Some(own) = hooks.term else {
        return Ok((with_term(config, problem, target)?, hooked));
    };
    if config.outline.is_some() {
        return Err(InputError::new(
            "fitness",
            "the config's `[match]` section adds its outline term already, and a run takes one \
             term of its own: leave `[match]` out, or score the outline in the function",
        ));
    }
    check_term(&own, &sylva_evolve::Problem::term_names(&problem))?;
    let scored = Arc::new(Scored::new(&config.model, &own));
    hooked.scored = Some(scored.clone());
    hooked.scout = Some(scout()?);
    let added = sylva_evolve::Added {
        term: scored as Arc<dyn sylva_evolve::Term<M::Problem>>,
        weight: own.weight,
        beside: own.beside,
    };
    Ok((
        WithTerm {
            problem,
            added: Some(added),
        },
        hooked,
    ))
}

/// The start genomes as model `M`'s; another model's is refused.
pub(super) fn typed_start<M: Evolve>(start: &[Genome]) -> Result<Vec<M::Genome>, InputError> {
    start
        .iter()
        .enumerate()
        .map(|(i, g)| {
            g.get::<M>().cloned().ok_or_else(|| {
                InputError::new(
                    format!("start genome {}", i + 1),
                    format!(
                        "this run evolves `{}` genomes; this is a `{}` genome",
                        M::NAME,
                        g.model()
                    ),
                )
            })
        })
        .collect()
}

/// Resumes the run of `config` saved in a checkpoint's `text` (read from `path`).
pub(crate) fn resume<M: Evolve + Default>(
    config: &EvolveConfig<M>,
    at: &Where,
    path: &Path,
    text: &str,
    pool: Pool,
    hooks: RunHooks,
) -> Result<TypedRun<M>, Error> {
    let (source, target) = (at.source.as_str(), at.target.as_ref());
    let saved = SavedRun::<M>::parse(path, text)?;
    if saved.config.resumable() != config.resumable() {
        return Err(InputError::file(
            path,
            "the checkpoint was written by a different config (only `generations`, \
             `threads` and `checkpoint_seconds` may change when resuming)",
        )
        .into());
    }
    check_resumed(saved.own_term.as_ref(), hooks.term.as_ref())
        .map_err(|e| InputError::file(path, e))?;
    let made = || setup(config, target, Vec::new(), 0, 0, source);
    let setup = made()?;
    let scout = || Ok(made()?.strategy);
    let (problem, hooked) = with_hooks(config, setup.problem, target, pool, hooks, scout)?;
    if let Some(scored) = &hooked.scored {
        // The engine scores a resumed population again.
        let genomes = saved.checkpoint.population.iter().map(|i| &i.genome);
        scored.prepare(&problem.problem, genomes, &hooked.pool)?;
    }
    let run = Run::resume(
        problem,
        setup.strategy,
        hooked.pool.clone(),
        saved.checkpoint,
    )
    .map_err(|e| InputError::file(path, e))?;
    TypedRun::checked(config, run, hooked)
}

impl<M: Evolve + Default> EvolveConfig<M> {
    /// How long a generation may take on `threads` threads ([`Config::generation_time`]).
    pub(crate) fn generation_time(
        &self,
        start: &[Genome],
        threads: usize,
    ) -> Option<GenerationTime> {
        let first = start.first().and_then(|g| g.get::<M>());
        let t = self.model.evaluation_time(&self.settings, first)?;
        let population = self.run.population as usize;
        // A generation evaluates up to `population` genomes, side by side on the threads.
        let threads = threads.clamp(1, population.max(1));
        let rounds = population.div_ceil(threads);
        let on = match threads {
            1 => "1 thread".to_owned(),
            n => format!("{n} threads"),
        };
        Some(GenerationTime {
            seconds: t.seconds * rounds as f64,
            what: format!(
                "a generation of {population} genomes (`population`) on {on}, each {}",
                t.what
            ),
            advice: t.advice,
        })
    }
}

/// The model's problem with the config's `[match]` term, if it has one: `target` holds its
/// pictures as read ([`Config::at`](super::Config) reads them for a config with a `[match]`).
pub(super) fn with_term<M: Evolve>(
    config: &EvolveConfig<M>,
    problem: M::Problem,
    target: Option<&Target>,
) -> Result<WithTerm<M::Problem>, InputError> {
    let added = match (&config.outline, target) {
        (Some(outline), Some(target)) => Some(target.added(&config.model, outline)?),
        _ => None,
    };
    Ok(WithTerm { problem, added })
}

/// The model's problem and strategy for the config's settings, fitted to `target` when the
/// config matches one (`Evolve::fit_target`: a self-organising tree grows into the
/// pictures' hull); a refusal names the config (`source`) and the model's section.
pub(super) fn setup<M: Evolve>(
    config: &EvolveConfig<M>,
    target: Option<&Target>,
    start: Vec<M::Genome>,
    seed: u64,
    population: usize,
    source: &str,
) -> Result<sylva_model::Setup<M>, InputError> {
    let model = &config.model;
    let settings = match (&config.outline, target) {
        (Some(_), Some(target)) => {
            let mut fitted = config.settings.clone();
            model
                .fit_target(&mut fitted, &target.profile()?)
                .map_err(|e| InputError::new("match", e.message))?;
            std::borrow::Cow::Owned(fitted)
        }
        _ => std::borrow::Cow::Borrowed(&config.settings),
    };
    model
        .setup(&settings, start, seed, population)
        .map_err(|e| InputError::new(source, format!("[{}.{}]: {}", M::NAME, e.field, e.message)))
}
