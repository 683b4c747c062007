//! A run of any model ([`Evolution`]): the erased face of a typed run (`typed.rs`).

use std::path::Path;

use sylva_core::Plant;
use sylva_core::par::{Pool, Stop};
use sylva_evolve::{GenerationStats, IndividualId};

use crate::error::{Error, InputError};
use crate::genome::Genome;

use super::config::Config;
use super::face::RunFace;
use super::hooks::RunHooks;
use super::silhouette::Target;
use super::typed::Member;
use super::typed::Where;

/// An evolution run of any model.
pub struct Evolution {
    /// The model's `TypedRun`.
    run: Box<dyn RunFace>,
    /// Its config's `[match]` pictures, as read when it started.
    target: Option<Target>,
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
        let at = config.at()?;
        let stop = hooks.stop.clone();
        let make = || config.face().start(&at, start, pool, hooks);
        let run = match &stop {
            Some(stop) => stop.watch(make)??,
            None => make()?,
        };
        Evolution::checked(run, at)
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
        let at = config.at()?;
        let stop = hooks.stop.clone();
        let make = || config.face().resume(&at, (path, text), pool, hooks);
        let run = match &stop {
            Some(stop) => stop.watch(make)??,
            None => make()?,
        };
        Evolution::checked(run, at)
    }

    /// Sets the stop that cuts the run's steps short from now on ([`RunHooks::stop`]).
    pub fn set_stop(&mut self, stop: Option<Stop>) {
        self.run.set_stop(stop);
    }

    /// The run, if its generation has a member with a finite fitness.
    fn checked(run: Box<dyn RunFace>, at: Where) -> Result<Self, Error> {
        let evolution = Evolution {
            run,
            target: at.target,
        };
        evolution.check_finite(&at.source)?;
        Ok(evolution)
    }

    /// The effective config, carrying its `[match]` pictures as read.
    pub fn config(&self) -> Config {
        Config::of(self.run.config()).with_target(self.target.clone())
    }

    /// The model's title, for plots.
    pub fn title(&self) -> &'static str {
        self.run.title()
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
        self.run.step()?;
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
        self.run.generation()
    }

    /// Statistics of every generation so far, one row each.
    pub fn stats(&self) -> &[GenerationStats] {
        self.run.stats()
    }

    /// Names of the fitness terms, in the order of each row's terms.
    pub fn term_names(&self) -> &[String] {
        self.run.term_names()
    }

    /// The current population, in slot order.
    pub fn population(&self) -> Vec<Member> {
        self.run.population()
    }

    /// The `count` fittest members of the current population, fittest first (ties go to the
    /// lower slot).
    pub fn fittest(&self, count: usize) -> Vec<Member> {
        self.run.fittest(count)
    }

    /// The best member of the current population (ties go to the lowest slot).
    pub fn best(&self) -> Member {
        self.run.best()
    }

    /// A member by id, in the current population or a kept generation.
    pub fn member(&self, id: IndividualId) -> Option<Member> {
        self.run.member(id)
    }

    /// The population of `generation`, if it is the current one or still kept.
    pub fn generation_members(&self, generation: u32) -> Option<Vec<Member>> {
        self.run.generation_members(generation)
    }

    /// Keeps the last `generations` generations for browsing (0, the default, keeps only the
    /// current one).
    pub fn keep_history(&mut self, generations: usize) {
        self.run.keep_history(generations);
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
        self.run.checkpoint()
    }

    /// Guides drawn beside plants in pictures (a target surface, forbidden cells), if the
    /// model's fitness has any.
    pub fn guides(&self) -> Option<Plant> {
        self.run.guides()
    }

    /// The `count` fittest genomes of the current population, fittest first, as the engine
    /// evolves them (JSON text): what an island sends to its neighbours.
    pub fn emigrants(&self, count: usize) -> Vec<String> {
        self.run.emigrants(count)
    }

    /// Puts migrants from [`Evolution::emigrants`] of another run of the same config (its
    /// seed may differ) in the places of the current population's worst members, and
    /// evaluates them; returns their new ids. Nothing changes if any migrant is not a genome
    /// of this run.
    pub fn immigrate(&mut self, migrants: &[String]) -> Result<Vec<IndividualId>, Error> {
        self.run.immigrate(migrants)
    }
}
