//! The faces by which a config, a run and a map of one model are handled as any model's:
//! small object-safe traits, each implemented once for the typed value it stands for
//! ([`EvolveConfig`], [`TypedRun`], [`TypedMap`]), so [`Config`](super::Config),
//! [`Evolution`](super::Evolution) and [`Varieties`](super::Varieties) hold a
//! `Box<dyn …>` and every call runs the model's own code. A face holds its typed value:
//! nothing is downcast, so nothing can be handed the wrong model's value.

use std::any::Any;
use std::path::{Path, PathBuf};

use sylva_core::Plant;
use sylva_core::par::{Pool, Stop};
use sylva_evolve::{GenerationStats, IndividualId, MapSettings, MapStats};
use sylva_fitness::descriptors::Descriptor;
use sylva_model::Evolve;

use crate::error::Error;
use crate::genome::Genome;

use super::hooks::RunHooks;
use super::schema::{EvolveConfig, MatchConfig, OutputConfig, RunConfig};
use super::typed::{GenerationTime, Member, TypedRun, Where, resume, start};
use super::typed_map::{TypedMap, Variety, resume_map, start_map};
use super::typed_space::{SpaceOptions, SpaceValue, new_space};

/// A config of one model, as any model's.
pub(crate) trait ConfigFace: Send + Sync {
    /// The typed config, for [`Config::get`](super::Config::get).
    fn as_any(&self) -> &dyn Any;
    fn model(&self) -> &'static str;
    fn clone_face(&self) -> Box<dyn ConfigFace>;
    fn run(&self) -> &RunConfig;
    fn run_mut(&mut self) -> &mut RunConfig;
    fn output(&self) -> &OutputConfig;
    fn output_mut(&mut self) -> &mut OutputConfig;
    fn outline(&self) -> Option<&MatchConfig>;
    fn to_toml(&self) -> String;
    fn settings_value(&self) -> serde_json::Value;
    fn start_files(&self) -> Vec<PathBuf>;
    fn generation_time(&self, start: &[Genome], threads: usize) -> Option<GenerationTime>;
    fn start(
        &self,
        at: &Where,
        start: Vec<Genome>,
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Box<dyn RunFace>, Error>;
    fn resume(
        &self,
        at: &Where,
        checkpoint: (&Path, &str),
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Box<dyn RunFace>, Error>;
    fn start_map(
        &self,
        at: &Where,
        start: Vec<Genome>,
        pool: Pool,
    ) -> Result<Box<dyn MapFace>, Error>;
    fn resume_map(
        &self,
        at: &Where,
        checkpoint: (&Path, &str),
        pool: Pool,
    ) -> Result<Box<dyn MapFace>, Error>;
    fn space(
        &self,
        at: &Where,
        start: Vec<Genome>,
        options: &SpaceOptions,
    ) -> Result<Box<dyn SpaceValue>, Error>;
}

/// A run of one model, as any model's.
pub(crate) trait RunFace: Send {
    fn title(&self) -> &'static str;
    /// The effective config.
    fn config(&self) -> Box<dyn ConfigFace>;
    fn step(&mut self) -> Result<(), Error>;
    fn set_stop(&mut self, stop: Option<Stop>);
    fn generation(&self) -> u32;
    fn stats(&self) -> &[GenerationStats];
    fn term_names(&self) -> &[String];
    fn population(&self) -> Vec<Member>;
    fn fittest(&self, count: usize) -> Vec<Member>;
    fn best(&self) -> Member;
    fn member(&self, id: IndividualId) -> Option<Member>;
    fn generation_members(&self, generation: u32) -> Option<Vec<Member>>;
    fn keep_history(&mut self, generations: usize);
    fn checkpoint(&self) -> Result<String, Error>;
    fn guides(&self) -> Option<Plant>;
    fn emigrants(&self, count: usize) -> Vec<String>;
    fn immigrate(&mut self, migrants: &[String]) -> Result<Vec<IndividualId>, Error>;
}

/// A map run of one model, as any model's.
pub(crate) trait MapFace: Send {
    fn title(&self) -> &'static str;
    /// The effective config (its `[map]` filled in).
    fn config(&self) -> Box<dyn ConfigFace>;
    fn step(&mut self) -> &MapStats;
    fn stats(&self) -> &[MapStats];
    fn term_names(&self) -> &[String];
    fn settings(&self) -> &MapSettings;
    fn descriptors(&self) -> &[Descriptor];
    fn varieties(&self) -> Vec<Variety>;
    fn variety(&self, cell: usize) -> Option<Variety>;
    fn checkpoint(&self) -> Result<String, Error>;
    fn guides(&self) -> Option<Plant>;
}

impl<M: Evolve + Default> ConfigFace for EvolveConfig<M> {
    fn as_any(&self) -> &dyn Any {
        self
    }

    fn model(&self) -> &'static str {
        M::NAME
    }

    fn clone_face(&self) -> Box<dyn ConfigFace> {
        Box::new(self.clone())
    }

    fn run(&self) -> &RunConfig {
        &self.run
    }

    fn run_mut(&mut self) -> &mut RunConfig {
        &mut self.run
    }

    fn output(&self) -> &OutputConfig {
        &self.output
    }

    fn output_mut(&mut self) -> &mut OutputConfig {
        &mut self.output
    }

    fn outline(&self) -> Option<&MatchConfig> {
        self.outline.as_ref()
    }

    fn to_toml(&self) -> String {
        EvolveConfig::to_toml(self)
    }

    fn settings_value(&self) -> serde_json::Value {
        // Settings are plain data: they serialise.
        serde_json::to_value(&self.settings).unwrap_or_default()
    }

    fn start_files(&self) -> Vec<PathBuf> {
        Evolve::start_files(&self.model, &self.settings)
    }

    fn generation_time(&self, start: &[Genome], threads: usize) -> Option<GenerationTime> {
        EvolveConfig::generation_time(self, start, threads)
    }

    fn start(
        &self,
        at: &Where,
        first: Vec<Genome>,
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Box<dyn RunFace>, Error> {
        Ok(Box::new(start(self, at, first, pool, hooks)?))
    }

    fn resume(
        &self,
        at: &Where,
        (path, text): (&Path, &str),
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Box<dyn RunFace>, Error> {
        Ok(Box::new(resume(self, at, path, text, pool, hooks)?))
    }

    fn start_map(
        &self,
        at: &Where,
        first: Vec<Genome>,
        pool: Pool,
    ) -> Result<Box<dyn MapFace>, Error> {
        Ok(Box::new(start_map(self, at, first, pool)?))
    }

    fn resume_map(
        &self,
        at: &Where,
        (path, text): (&Path, &str),
        pool: Pool,
    ) -> Result<Box<dyn MapFace>, Error> {
        Ok(Box::new(resume_map(self, at, path, text, pool)?))
    }

    fn space(
        &self,
        at: &Where,
        first: Vec<Genome>,
        options: &SpaceOptions,
    ) -> Result<Box<dyn SpaceValue>, Error> {
        new_space(self, at, first, options)
    }
}

impl<M: Evolve + Default> RunFace for TypedRun<M> {
    fn title(&self) -> &'static str {
        M::TITLE
    }

    fn config(&self) -> Box<dyn ConfigFace> {
        Box::new(self.config.clone())
    }

    fn step(&mut self) -> Result<(), Error> {
        TypedRun::step(self)
    }

    fn set_stop(&mut self, stop: Option<Stop>) {
        self.hooked.stop = stop;
    }

    fn generation(&self) -> u32 {
        TypedRun::generation(self)
    }

    fn stats(&self) -> &[GenerationStats] {
        TypedRun::stats(self)
    }

    fn term_names(&self) -> &[String] {
        self.run.term_names()
    }

    fn population(&self) -> Vec<Member> {
        TypedRun::population(self)
    }

    fn fittest(&self, count: usize) -> Vec<Member> {
        TypedRun::fittest(self, count)
    }

    fn best(&self) -> Member {
        TypedRun::best(self)
    }

    fn member(&self, id: IndividualId) -> Option<Member> {
        self.find(id)
    }

    fn generation_members(&self, generation: u32) -> Option<Vec<Member>> {
        TypedRun::generation_members(self, generation)
    }

    fn keep_history(&mut self, generations: usize) {
        TypedRun::keep_history(self, generations);
    }

    fn checkpoint(&self) -> Result<String, Error> {
        TypedRun::checkpoint(self)
    }

    fn guides(&self) -> Option<Plant> {
        // The model's own guides mean nothing when its terms do not count.
        if self.config.outline.as_ref().is_some_and(|o| !o.beside)
            || self.run.problem().added.as_ref().is_some_and(|a| !a.beside)
        {
            return None;
        }
        Evolve::guides(&self.config.model, &self.run.problem().problem)
    }

    fn emigrants(&self, count: usize) -> Vec<String> {
        TypedRun::emigrants(self, count)
    }

    fn immigrate(&mut self, migrants: &[String]) -> Result<Vec<IndividualId>, Error> {
        TypedRun::immigrate(self, migrants)
    }
}

impl<M: Evolve + Default> MapFace for TypedMap<M> {
    fn title(&self) -> &'static str {
        M::TITLE
    }

    fn config(&self) -> Box<dyn ConfigFace> {
        Box::new(self.config.clone())
    }

    fn step(&mut self) -> &MapStats {
        self.run.step()
    }

    fn stats(&self) -> &[MapStats] {
        self.run.stats()
    }

    fn term_names(&self) -> &[String] {
        self.run.term_names()
    }

    fn settings(&self) -> &MapSettings {
        self.run.settings()
    }

    fn descriptors(&self) -> &[Descriptor] {
        &self.descriptors
    }

    fn varieties(&self) -> Vec<Variety> {
        TypedMap::varieties(self)
    }

    fn variety(&self, cell: usize) -> Option<Variety> {
        self.variety_of(cell)
    }

    fn checkpoint(&self) -> Result<String, Error> {
        TypedMap::checkpoint(self)
    }

    fn guides(&self) -> Option<Plant> {
        self.config.model.guides(&self.run.problem().problem)
    }
}
