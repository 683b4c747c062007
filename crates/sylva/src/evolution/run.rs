//! A run of any model ([`Evolution`]) and its members.

use std::path::Path;
use std::sync::Arc;

use sylva_core::Plant;
use sylva_core::par::Pool;
use sylva_evolve::{Fitness, GenerationStats, IndividualId, Origin, Problem, Run, WithTerm};
use sylva_model::Evolve;

use crate::erased::{DynModel, RunValue};
use crate::error::{Error, InputError};
use crate::genome::Genome;

use super::checkpoint::SavedRunRef;
use super::config::Config;
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

/// A run of model `M` with the config it follows.
pub(crate) struct TypedRun<M: Evolve> {
    pub(crate) config: EvolveConfig<M>,
    pub(crate) run: Run<WithTerm<M::Problem>, M::Strategy>,
}

impl<M: Evolve + Default> TypedRun<M> {
    pub(crate) fn member(
        &self,
        ind: &sylva_evolve::Individual<<M::Problem as Problem>::Genome>,
    ) -> Member {
        member_of(&self.config.model, &self.run.problem().problem, ind)
    }

    pub(crate) fn population(&self) -> Vec<Member> {
        self.run
            .population()
            .iter()
            .map(|i| self.member(i))
            .collect()
    }

    pub(crate) fn fittest(&self, count: usize) -> Vec<Member> {
        let population = self.run.population();
        sylva_evolve::fittest(population, count)
            .into_iter()
            .map(|i| self.member(&population[i]))
            .collect()
    }

    pub(crate) fn checkpoint(&self) -> Result<String, Error> {
        let saved = SavedRunRef::<M> {
            config: &self.config,
            checkpoint: self.run.checkpoint(),
        };
        serde_json::to_string(&saved)
            .map_err(|e| InputError::new("checkpoint", e))
            .map_err(Error::from)
    }

    pub(crate) fn emigrants(&self, count: usize) -> Vec<String> {
        let population = self.run.population();
        sylva_evolve::fittest(population, count)
            .into_iter()
            .map(|i| serde_json::to_string(&population[i].genome).unwrap_or_default())
            .collect()
    }

    pub(crate) fn immigrate(
        &mut self,
        migrants: &[String],
    ) -> Result<Vec<IndividualId>, InputError> {
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
        let slots = self.run.immigrate(genomes);
        Ok(slots
            .into_iter()
            .map(|slot| self.run.population()[slot].id)
            .collect())
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
        let (model, typed) = config.parts();
        let source = config.source();
        let run = model.start(typed, &source, &config.base(), start, pool)?;
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
        let (model, typed) = config.parts();
        let source = config.source();
        let run = model.resume(typed, &source, &config.base(), path, text, pool)?;
        Evolution::checked(model, run, &source)
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
    pub fn step(&mut self) -> Result<&GenerationStats, Error> {
        self.model.step(&mut *self.run);
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
    pub fn immigrate(&mut self, migrants: &[String]) -> Result<Vec<IndividualId>, InputError> {
        self.model.immigrate(&mut *self.run, migrants)
    }
}
