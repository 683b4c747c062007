//! One object-safe face for every model: [`DynModel`], implemented once, for every model
//! that evolves.
//!
//! A [`Genome`], a [`Config`](crate::Config) and an [`Evolution`](crate::Evolution) each hold their model as an
//! `Arc<dyn DynModel>` beside their typed value (the model's genome, its
//! [`EvolveConfig`], its run), erased as `dyn Any`. Every operation on them is one call
//! here, which takes the typed value back and runs the model's own code, so a front end
//! handles every model alike and adding a model adds no code to the library. The registry's
//! entries are these handles.
//!
//! The values are only ever paired with the model that made them, so taking one back
//! cannot fail; the `expect`s below say so.

use std::any::Any;
use std::path::{Path, PathBuf};

use sylva_core::Plant;
use sylva_core::par::Pool;
use sylva_core::rng::ChaCha8Rng;
use sylva_evolve::{GenerationStats, IndividualId};
use sylva_model::{Bred, DevelopError, Evolve, GenomeError, MeshHint, Model, Parent};

use crate::error::{Error, FieldError, InputError};
use crate::evolution::{
    EvolveConfig, GenerationTime, MatchConfig, Member, OutputConfig, RunConfig,
};
use crate::evolution::{MapValue, TypedRun, resume, resume_map, start, start_map};
use crate::evolution::{RunHooks, SpaceOptions, SpaceValue, Stop, new_space};
use crate::genome::{Genome, Settings, settings_of};

/// How many genomes [`DynModel::random`] draws, at most, to find one that grows.
pub(crate) const RANDOM_DRAWS: u32 = 100;

/// A model's genome or config, erased.
pub(crate) type Value = dyn Any + Send + Sync;

/// A model's run, erased (a run is not shared between threads).
pub(crate) type RunValue = dyn Any + Send;

/// Everything the library does with a model, on erased values. Genomes are the model's
/// `M::Genome`, configs its `EvolveConfig<M>`, runs its `TypedRun<M>`.
pub(crate) trait DynModel: Send + Sync {
    // The model.
    fn name(&self) -> &'static str;
    fn title(&self) -> &'static str;
    fn mesh_hint(&self) -> MeshHint;

    // Genomes.
    fn parse_genome(&self, text: &str) -> Result<Box<Value>, GenomeError>;
    fn random(&self, settings: Settings<'_>, seed: u64) -> Result<Box<Value>, InputError>;
    fn write(&self, genome: &Value) -> String;
    fn to_value(&self, genome: &Value) -> serde_json::Value;
    fn packed(&self, genome: &Value) -> Option<String>;
    fn develop(&self, genome: &Value, seed: u64) -> Result<Plant, DevelopError>;
    fn default_seed(&self, genome: &Value) -> u64;
    fn growth_seconds(&self, genome: &Value) -> Option<f64>;
    /// Whether `other` (of any model) is the same genome.
    fn same(&self, genome: &Value, other: &Value) -> bool;
    fn mutate(
        &self,
        genome: &Value,
        settings: Settings<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Box<Value>, InputError>;
    /// A child of `parents`, which may be of any model (another model's is refused).
    fn cross(
        &self,
        parents: &[(&Genome, f64)],
        settings: Settings<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<(Box<Value>, Vec<usize>), Error>;

    // Configs.
    fn parse_config(&self, path: &Path, text: &str) -> Result<Box<Value>, InputError>;
    fn config_from_value(&self, value: serde_json::Value) -> Result<Box<Value>, FieldError>;
    fn default_config(&self) -> Box<Value>;
    fn clone_config(&self, config: &Value) -> Box<Value>;
    fn run_settings<'a>(&self, config: &'a Value) -> &'a RunConfig;
    fn run_settings_mut<'a>(&self, config: &'a mut Value) -> &'a mut RunConfig;
    fn output<'a>(&self, config: &'a Value) -> &'a OutputConfig;
    fn output_mut<'a>(&self, config: &'a mut Value) -> &'a mut OutputConfig;
    fn outline<'a>(&self, config: &'a Value) -> Option<&'a MatchConfig>;
    fn to_toml(&self, config: &Value) -> String;
    fn settings_value(&self, config: &Value) -> serde_json::Value;
    fn start_files(&self, config: &Value) -> Vec<PathBuf>;
    fn generation_time(
        &self,
        config: &Value,
        start: &[Genome],
        threads: usize,
    ) -> Option<GenerationTime>;
    fn start(
        &self,
        config: &Value,
        source: &str,
        base: &Path,
        start: Vec<Genome>,
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Box<RunValue>, Error>;
    #[allow(clippy::too_many_arguments)] // What resuming takes, one argument each.
    fn resume(
        &self,
        config: &Value,
        source: &str,
        base: &Path,
        path: &Path,
        text: &str,
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Box<RunValue>, Error>;

    fn start_map(
        &self,
        config: &Value,
        source: &str,
        base: &Path,
        start: Vec<Genome>,
        pool: Pool,
    ) -> Result<Box<dyn MapValue>, Error>;
    fn resume_map(
        &self,
        config: &Value,
        source: &str,
        base: &Path,
        path: &Path,
        text: &str,
        pool: Pool,
    ) -> Result<Box<dyn MapValue>, Error>;
    fn space(
        &self,
        config: &Value,
        source: &str,
        base: &Path,
        start: Vec<Genome>,
        options: &SpaceOptions,
    ) -> Result<Box<dyn SpaceValue>, Error>;

    // Runs.
    fn effective_config(&self, run: &RunValue) -> Box<Value>;
    fn step(&self, run: &mut RunValue) -> Result<(), Error>;
    fn set_stop(&self, run: &mut RunValue, stop: Option<Stop>);
    fn generation(&self, run: &RunValue) -> u32;
    fn stats<'a>(&self, run: &'a RunValue) -> &'a [GenerationStats];
    fn term_names<'a>(&self, run: &'a RunValue) -> &'a [String];
    fn population(&self, run: &RunValue) -> Vec<Member>;
    fn fittest(&self, run: &RunValue, count: usize) -> Vec<Member>;
    fn best(&self, run: &RunValue) -> Member;
    fn member(&self, run: &RunValue, id: IndividualId) -> Option<Member>;
    fn generation_members(&self, run: &RunValue, generation: u32) -> Option<Vec<Member>>;
    fn keep_history(&self, run: &mut RunValue, generations: usize);
    fn checkpoint(&self, run: &RunValue) -> Result<String, Error>;
    fn guides(&self, run: &RunValue) -> Option<Plant>;
    fn emigrants(&self, run: &RunValue, count: usize) -> Vec<String>;
    fn immigrate(
        &self,
        run: &mut RunValue,
        migrants: &[String],
    ) -> Result<Vec<IndividualId>, Error>;
}

/// The typed genome in `value`, held with its own model.
fn genome<M: Model>(value: &Value) -> &M::Genome {
    value
        .downcast_ref()
        .expect("a genome is held with its own model")
}

fn config<M: Evolve>(value: &Value) -> &EvolveConfig<M> {
    value
        .downcast_ref()
        .expect("a config is held with its own model")
}

fn config_mut<M: Evolve>(value: &mut Value) -> &mut EvolveConfig<M> {
    value
        .downcast_mut()
        .expect("a config is held with its own model")
}

fn run<M: Evolve>(value: &RunValue) -> &TypedRun<M> {
    value
        .downcast_ref()
        .expect("a run is held with its own model")
}

fn run_mut<M: Evolve>(value: &mut RunValue) -> &mut TypedRun<M> {
    value
        .downcast_mut()
        .expect("a run is held with its own model")
}

impl<M: Evolve + Default> DynModel for M {
    fn name(&self) -> &'static str {
        M::NAME
    }

    fn title(&self) -> &'static str {
        M::TITLE
    }

    fn mesh_hint(&self) -> MeshHint {
        Model::mesh_hint(self)
    }

    fn parse_genome(&self, text: &str) -> Result<Box<Value>, GenomeError> {
        Ok(Box::new(self.parse(text)?))
    }

    fn random(&self, settings: Settings<'_>, seed: u64) -> Result<Box<Value>, InputError> {
        let settings = settings_of(self, settings)?;
        let mut rng = sylva_core::rng::seeded(seed);
        // Some models' random genomes often grow nothing (the L-system's paper starts from
        // a genome that does not germinate): draw on from the same stream until one grows.
        for _ in 0..RANDOM_DRAWS {
            let genome = Model::random(self, &settings, &mut rng);
            let seed = Model::default_seed(self, &genome);
            let grows = Model::develop(self, &genome, seed).is_ok_and(|p| !p.segments().is_empty());
            if grows {
                return Ok(Box::new(genome));
            }
        }
        Err(InputError::new(
            "settings",
            format!(
                "none of the {RANDOM_DRAWS} random {} genomes drawn from seed {seed} grows a \
                 segment with these settings; expected settings under which some grow",
                M::NAME
            ),
        ))
    }

    fn write(&self, g: &Value) -> String {
        Model::write(self, genome::<M>(g))
    }

    fn to_value(&self, g: &Value) -> serde_json::Value {
        serde_json::to_value(genome::<M>(g)).unwrap_or(serde_json::Value::Null)
    }

    fn packed(&self, g: &Value) -> Option<String> {
        Model::packed(self, genome::<M>(g))
    }

    fn develop(&self, g: &Value, seed: u64) -> Result<Plant, DevelopError> {
        Model::develop(self, genome::<M>(g), seed)
    }

    fn default_seed(&self, g: &Value) -> u64 {
        Model::default_seed(self, genome::<M>(g))
    }

    fn growth_seconds(&self, g: &Value) -> Option<f64> {
        Model::growth_seconds(self, genome::<M>(g))
    }

    fn same(&self, g: &Value, other: &Value) -> bool {
        other
            .downcast_ref::<M::Genome>()
            .is_some_and(|other| other == genome::<M>(g))
    }

    fn mutate(
        &self,
        g: &Value,
        settings: Settings<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Box<Value>, InputError> {
        let settings = settings_of(self, settings)?;
        Ok(Box::new(Model::mutate(
            self,
            genome::<M>(g),
            &settings,
            rng,
        )))
    }

    fn cross(
        &self,
        parents: &[(&Genome, f64)],
        settings: Settings<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<(Box<Value>, Vec<usize>), Error> {
        let settings = settings_of(self, settings)?;
        let mut typed = Vec::with_capacity(parents.len());
        for (i, (g, dominance)) in parents.iter().enumerate() {
            let genome = g.get::<M>().ok_or_else(|| {
                InputError::new(
                    format!("parent {i}"),
                    format!(
                        "a `{}` genome cannot be crossed with `{}` genomes",
                        g.model(),
                        M::NAME
                    ),
                )
            })?;
            typed.push(Parent {
                genome,
                dominance: *dominance,
            });
        }
        let Bred { genome, parents } = Model::cross(self, &typed, &settings, rng)
            .map_err(|e| InputError::new("parents", e))?;
        Ok((Box::new(genome), parents))
    }

    fn parse_config(&self, path: &Path, text: &str) -> Result<Box<Value>, InputError> {
        Ok(Box::new(EvolveConfig::<M>::parse(path, text)?))
    }

    fn config_from_value(&self, value: serde_json::Value) -> Result<Box<Value>, FieldError> {
        let sent = value.clone();
        match serde_path_to_error::deserialize::<_, EvolveConfig<M>>(value) {
            Ok(config) => Ok(Box::new(config)),
            Err(e) => Err(FieldError::of(&e, &sent)),
        }
    }

    fn default_config(&self) -> Box<Value> {
        Box::new(EvolveConfig::<M>::default())
    }

    fn clone_config(&self, c: &Value) -> Box<Value> {
        Box::new(config::<M>(c).clone())
    }

    fn run_settings<'a>(&self, c: &'a Value) -> &'a RunConfig {
        &config::<M>(c).run
    }

    fn run_settings_mut<'a>(&self, c: &'a mut Value) -> &'a mut RunConfig {
        &mut config_mut::<M>(c).run
    }

    fn output<'a>(&self, c: &'a Value) -> &'a OutputConfig {
        &config::<M>(c).output
    }

    fn output_mut<'a>(&self, c: &'a mut Value) -> &'a mut OutputConfig {
        &mut config_mut::<M>(c).output
    }

    fn outline<'a>(&self, c: &'a Value) -> Option<&'a MatchConfig> {
        config::<M>(c).outline.as_ref()
    }

    fn to_toml(&self, c: &Value) -> String {
        config::<M>(c).to_toml()
    }

    fn settings_value(&self, c: &Value) -> serde_json::Value {
        // Settings are plain data: they serialise.
        serde_json::to_value(&config::<M>(c).settings).unwrap_or_default()
    }

    fn start_files(&self, c: &Value) -> Vec<PathBuf> {
        let c = config::<M>(c);
        Evolve::start_files(&c.model, &c.settings)
    }

    fn generation_time(
        &self,
        c: &Value,
        start: &[Genome],
        threads: usize,
    ) -> Option<GenerationTime> {
        config::<M>(c).generation_time(start, threads)
    }

    fn start(
        &self,
        c: &Value,
        source: &str,
        base: &Path,
        first: Vec<Genome>,
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Box<RunValue>, Error> {
        Ok(Box::new(start(
            config::<M>(c),
            source,
            base,
            first,
            pool,
            hooks,
        )?))
    }

    fn resume(
        &self,
        c: &Value,
        source: &str,
        base: &Path,
        path: &Path,
        text: &str,
        pool: Pool,
        hooks: RunHooks,
    ) -> Result<Box<RunValue>, Error> {
        Ok(Box::new(resume(
            config::<M>(c),
            source,
            base,
            path,
            text,
            pool,
            hooks,
        )?))
    }

    fn start_map(
        &self,
        c: &Value,
        source: &str,
        base: &Path,
        first: Vec<Genome>,
        pool: Pool,
    ) -> Result<Box<dyn MapValue>, Error> {
        start_map(config::<M>(c), source, base, first, pool)
    }

    fn resume_map(
        &self,
        c: &Value,
        source: &str,
        base: &Path,
        path: &Path,
        text: &str,
        pool: Pool,
    ) -> Result<Box<dyn MapValue>, Error> {
        resume_map(config::<M>(c), source, base, path, text, pool)
    }

    fn space(
        &self,
        c: &Value,
        source: &str,
        base: &Path,
        start: Vec<Genome>,
        options: &SpaceOptions,
    ) -> Result<Box<dyn SpaceValue>, Error> {
        new_space(config::<M>(c), source, base, start, options)
    }

    fn effective_config(&self, r: &RunValue) -> Box<Value> {
        Box::new(run::<M>(r).config.clone())
    }

    fn step(&self, r: &mut RunValue) -> Result<(), Error> {
        run_mut::<M>(r).step()
    }

    fn set_stop(&self, r: &mut RunValue, stop: Option<Stop>) {
        run_mut::<M>(r).hooked.stop = stop;
    }

    fn generation(&self, r: &RunValue) -> u32 {
        run::<M>(r).generation()
    }

    fn stats<'a>(&self, r: &'a RunValue) -> &'a [GenerationStats] {
        run::<M>(r).stats()
    }

    fn term_names<'a>(&self, r: &'a RunValue) -> &'a [String] {
        run::<M>(r).run.term_names()
    }

    fn population(&self, r: &RunValue) -> Vec<Member> {
        run::<M>(r).population()
    }

    fn fittest(&self, r: &RunValue, count: usize) -> Vec<Member> {
        run::<M>(r).fittest(count)
    }

    fn best(&self, r: &RunValue) -> Member {
        run::<M>(r).best()
    }

    fn member(&self, r: &RunValue, id: IndividualId) -> Option<Member> {
        run::<M>(r).find(id)
    }

    fn generation_members(&self, r: &RunValue, generation: u32) -> Option<Vec<Member>> {
        run::<M>(r).generation_members(generation)
    }

    fn keep_history(&self, r: &mut RunValue, generations: usize) {
        run_mut::<M>(r).keep_history(generations);
    }

    fn checkpoint(&self, r: &RunValue) -> Result<String, Error> {
        run::<M>(r).checkpoint()
    }

    fn guides(&self, r: &RunValue) -> Option<Plant> {
        let r = run::<M>(r);
        // The model's own guides mean nothing when its terms do not count.
        if r.config.outline.as_ref().is_some_and(|o| !o.beside)
            || r.run.problem().added.as_ref().is_some_and(|a| !a.beside)
        {
            return None;
        }
        Evolve::guides(&r.config.model, &r.run.problem().problem)
    }

    fn emigrants(&self, r: &RunValue, count: usize) -> Vec<String> {
        run::<M>(r).emigrants(count)
    }

    fn immigrate(&self, r: &mut RunValue, migrants: &[String]) -> Result<Vec<IndividualId>, Error> {
        run_mut::<M>(r).immigrate(migrants)
    }
}
