//! Evolution without a person, for any model that can evolve: configs, runs, checkpoints.
//!
//! A config ([`EvolveConfig`]) is TOML: the model's name, the run's size and seed
//! (`[run]`), the model's settings (its own section, `[bintree]`, `[automata]`, ...) and
//! what a run writes (`[output]`). Every section and field is optional; unknown fields are
//! refused; every number is checked against its range while it is read, so an error points
//! at the line and column of the offending value.
//!
//! ```toml
//! model = "bintree"          # the model to evolve; its section follows
//!
//! [run]
//! generations = 150          # generations to breed after the random first one
//! population = 400           # individuals per generation
//! seed = 1                   # seed of every random choice
//! threads = 0                # 0: one per core; results do not depend on it
//! checkpoint_seconds = 2     # 0: checkpoint every generation
//!
//! [bintree]                  # the model's settings (see its crate)
//! mutation_rate = 0.02
//!
//! [output]
//! image_size = 800           # pixels, square, for best.png
//! view = "iso"               # front, side, top or iso
//! sheet_size = 48            # individuals on the contact sheet
//! taper = 2.5                # optional: the pipe model's radii for best.* and the sheet (2 to 3)
//! ```
//!
//! [`Config`] is a config of any model (it knows which from the `model` field, through the
//! [`Registry`]); [`Evolution`] is a run of any model: step it one generation or a batch,
//! read its statistics, browse its population and each member's family, and write a
//! checkpoint that resumes it exactly.

use std::any::Any;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};

use serde::de::{self, DeserializeSeed, MapAccess, Visitor};
use serde::ser::SerializeStruct;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sylva_core::Plant;
use sylva_core::par::Pool;
use sylva_core::taper::PipeTaper;
use sylva_evolve::{
    Checkpoint, Fitness, GenerationStats, IndividualId, Origin, Problem, Run, RunSettings,
};
use sylva_mesh::wind::WindOptions;
use sylva_model::Evolve;
use sylva_render::View;

use crate::error::{Error, FieldError, InputError};
use crate::genome::Genome;
use crate::registry::Registry;

/// Run size and seed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunConfig {
    /// Generations bred after the first, 0 to 1,000,000. Default 150.
    #[serde(deserialize_with = "generations")]
    pub generations: u32,
    /// Individuals per generation, 1 to 1,000,000. Default 400.
    #[serde(deserialize_with = "population")]
    pub population: u32,
    /// Seed of every random choice. Default 1.
    pub seed: u64,
    /// Worker threads, 0 (one per core) to 1024. Default 0. Results do not depend on it.
    #[serde(deserialize_with = "threads")]
    pub threads: u32,
    /// Seconds between checkpoints, 0 (every generation) to 3600. Default 2. A run also
    /// checkpoints when it ends.
    #[serde(deserialize_with = "checkpoint_seconds")]
    pub checkpoint_seconds: f64,
}

impl Default for RunConfig {
    fn default() -> Self {
        RunConfig {
            generations: 150,
            population: 400,
            seed: 1,
            threads: 0,
            checkpoint_seconds: 2.0,
        }
    }
}

sylva_core::ranged!(generations: u32, "generations", 0, 1_000_000);
sylva_core::ranged!(population: u32, "population", 1, 1_000_000);
sylva_core::ranged!(threads: u32, "threads", 0, 1024);
sylva_core::ranged!(checkpoint_seconds: f64, "checkpoint_seconds", 0.0, 3600.0, " s");

/// What a run writes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputConfig {
    /// Width and height of `best.png`, 64 to 4096 pixels. Default 800.
    #[serde(deserialize_with = "image_size")]
    pub image_size: u32,
    /// View of `best.png`. Default iso.
    #[serde(with = "view_name")]
    pub view: View,
    /// Individuals shown on the contact sheet (the best ones), 1 to 400. Default 48.
    #[serde(deserialize_with = "sheet_size")]
    pub sheet_size: u32,
    /// The pipe-model exponent `E`, 2 to 3, for the best plant and the sheet: radius ∝
    /// (tips above)^(1/E), as `sylva grow --taper E`. Default none: each model's own radii
    /// (evolution scores the plants as grown, without it).
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "taper")]
    pub taper: Option<f64>,
    /// A wind skin and clip in `best.glb`, as `sylva grow --wind`: `wind = {}` for the
    /// defaults, or `wind = { strength = 2.0, period = 3.0 }`. Default none.
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "wind")]
    pub wind: Option<WindConfig>,
}

/// `[output] wind`: the wind of `best.glb`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WindConfig {
    /// Sway, 0 to 10. Default 1.
    pub strength: f32,
    /// Seconds of the clip, 0.5 to 60. Default 4.
    pub period: f32,
}

impl Default for WindConfig {
    fn default() -> Self {
        let d = WindOptions::default();
        WindConfig {
            strength: d.strength,
            period: d.period,
        }
    }
}

/// Reads `wind`, its numbers checked.
fn wind<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<WindConfig>, D::Error> {
    let wind = WindConfig::deserialize(d)?;
    WindOptions::new(wind.strength, wind.period).map_err(serde::de::Error::custom)?;
    Ok(Some(wind))
}

impl OutputConfig {
    /// The taper the outputs are grown with, if any.
    pub fn pipe_taper(&self) -> Option<PipeTaper> {
        self.taper.and_then(|e| PipeTaper::new(e).ok())
    }

    /// The wind of `best.glb`, if any.
    pub fn wind_options(&self) -> Option<WindOptions> {
        self.wind
            .and_then(|w| WindOptions::new(w.strength, w.period).ok())
    }
}

impl Default for OutputConfig {
    fn default() -> Self {
        OutputConfig {
            image_size: 800,
            view: View::Iso,
            sheet_size: 48,
            taper: None,
            wind: None,
        }
    }
}

/// Reads `taper`, checked to lie in 2..=3.
fn taper<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    let exponent = f64::deserialize(d)?;
    match PipeTaper::new(exponent) {
        Ok(_) => Ok(Some(exponent)),
        Err(_) => Err(serde::de::Error::custom(format!(
            "`taper` must be a number from 2 to 3 (the pipe-model exponent), got {exponent}"
        ))),
    }
}

sylva_core::ranged!(image_size: u32, "image_size", 64, 4096);
sylva_core::ranged!(sheet_size: u32, "sheet_size", 1, 400);

mod view_name {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};
    use sylva_render::View;

    pub fn serialize<S: Serializer>(v: &View, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(v)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<View, D::Error> {
        String::deserialize(d)?.parse().map_err(D::Error::custom)
    }
}

/// An evolution config of model `M`: `model`, `[run]`, the model's settings under its
/// name, and `[output]`.
#[derive(Clone, Debug, Default)]
pub struct EvolveConfig<M: Evolve> {
    /// The model.
    pub model: M,
    /// Run size and seed.
    pub run: RunConfig,
    /// The model's settings.
    pub settings: M::Settings,
    /// What a run writes.
    pub output: OutputConfig,
}

impl<M: Evolve> PartialEq for EvolveConfig<M> {
    fn eq(&self, other: &Self) -> bool {
        self.run == other.run && self.settings == other.settings && self.output == other.output
    }
}

impl<M: Evolve> Serialize for EvolveConfig<M> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut st = s.serialize_struct("EvolveConfig", 4)?;
        st.serialize_field("model", M::NAME)?;
        st.serialize_field("run", &self.run)?;
        st.serialize_field(M::NAME, &self.settings)?;
        st.serialize_field("output", &self.output)?;
        st.end()
    }
}

impl<'de, M: Evolve + Default> Deserialize<'de> for EvolveConfig<M> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(ConfigVisitor(PhantomData))
    }
}

struct ConfigVisitor<M>(PhantomData<M>);

/// The keys of a config, in the order they are named in errors.
enum Key {
    Model,
    Run,
    Settings,
    Output,
}

impl<'de, M: Evolve + Default> Visitor<'de> for ConfigVisitor<M> {
    type Value = EvolveConfig<M>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "an evolution config of `{}`", M::NAME)
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<EvolveConfig<M>, A::Error> {
        let mut config = EvolveConfig::<M>::default();
        while let Some(key) = map.next_key_seed(KeySeed(M::NAME))? {
            match key {
                Key::Model => map.next_value_seed(NameSeed(M::NAME))?,
                Key::Run => config.run = map.next_value()?,
                Key::Settings => config.settings = map.next_value()?,
                Key::Output => config.output = map.next_value()?,
            }
        }
        Ok(config)
    }
}

/// Reads a key of a config of the model named `.0`; unknown keys are refused here, so the
/// error points at the key.
struct KeySeed(&'static str);

impl<'de> DeserializeSeed<'de> for KeySeed {
    type Value = Key;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Key, D::Error> {
        let key = String::deserialize(d)?;
        match key.as_str() {
            "model" => Ok(Key::Model),
            "run" => Ok(Key::Run),
            "output" => Ok(Key::Output),
            k if k == self.0 => Ok(Key::Settings),
            k => Err(de::Error::custom(format!(
                "unknown field `{k}`: this config evolves `{}` (set `model` to evolve another \
                 model); expected `model`, `run`, `{}` or `output`",
                self.0, self.0
            ))),
        }
    }
}

/// Reads the `model` field, which must name the model `.0`.
struct NameSeed(&'static str);

impl<'de> DeserializeSeed<'de> for NameSeed {
    type Value = ();
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        let name = String::deserialize(d)?;
        if name == self.0 {
            Ok(())
        } else {
            Err(de::Error::custom(format!(
                "`model` is `{name}`, but this is a config of `{}`",
                self.0
            )))
        }
    }
}

impl<M: Evolve + Default> EvolveConfig<M> {
    /// Parses a config of model `M` from TOML; errors point into `text`.
    pub fn parse(path: &Path, text: &str) -> Result<Self, InputError> {
        toml::from_str(text).map_err(|e| InputError::toml(path, text, &e))
    }

    /// The config as TOML (what a run records next to its results).
    pub fn to_toml(&self) -> String {
        // Configs hold only range-checked numbers, strings and tables (each after the plain
        // values of its parent), which TOML always writes; failing here is a bug.
        toml::to_string(self).expect("configs serialise as TOML")
    }

    /// The parts that must match for a run to resume: everything but the length of the
    /// run, the thread count and the checkpoint interval.
    fn resumable(&self) -> Self {
        let mut c = self.clone();
        c.run.generations = 0;
        c.run.threads = 0;
        c.run.checkpoint_seconds = 0.0;
        c
    }
}

/// An evolution config of any model.
pub struct Config {
    inner: Box<dyn AnyConfig>,
    /// The file it was read from, named in errors.
    source: Option<PathBuf>,
}

/// Evaluations made so far by every run of this process, for a progress bar to read from
/// another thread while a generation is bred ([`sylva_evolve::problem::evaluations`]).
pub fn evaluations_done() -> u64 {
    sylva_evolve::problem::evaluations()
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

/// What every typed config can do, object-safe. Implemented once, for [`EvolveConfig`].
trait AnyConfig: Send + Sync {
    fn model(&self) -> &'static str;
    fn run(&self) -> &RunConfig;
    fn run_mut(&mut self) -> &mut RunConfig;
    fn output(&self) -> &OutputConfig;
    fn to_toml(&self) -> String;
    fn start_files(&self) -> Vec<PathBuf>;
    fn clone_box(&self) -> Box<dyn AnyConfig>;
    fn as_any(&self) -> &dyn Any;
    fn start(&self, source: &str, start: Vec<Genome>, pool: Pool) -> Result<Evolution, Error>;
    fn resume(&self, source: &str, path: &Path, text: &str, pool: Pool)
    -> Result<Evolution, Error>;
    fn generation_time(&self, start: &[Genome], threads: usize) -> Option<GenerationTime>;
}

impl<M: Evolve + Default> AnyConfig for EvolveConfig<M> {
    fn model(&self) -> &'static str {
        M::NAME
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

    fn to_toml(&self) -> String {
        EvolveConfig::to_toml(self)
    }

    fn start_files(&self) -> Vec<PathBuf> {
        self.model.start_files(&self.settings)
    }

    fn clone_box(&self) -> Box<dyn AnyConfig> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn start(&self, source: &str, start: Vec<Genome>, pool: Pool) -> Result<Evolution, Error> {
        let mut typed = Vec::with_capacity(start.len());
        for (i, g) in start.iter().enumerate() {
            typed.push(g.get::<M>().cloned().ok_or_else(|| {
                InputError::new(
                    format!("start genome {}", i + 1),
                    format!(
                        "this run evolves `{}` genomes; this is a `{}` genome",
                        M::NAME,
                        g.model()
                    ),
                )
            })?);
        }
        let (seed, population) = (self.run.seed, self.run.population as usize);
        // A population and its offspring, each genome at the settings' bounds.
        let genome = self.model.genome_bytes(&self.settings);
        sylva_core::budget::check(
            (population as u64).saturating_mul(genome).saturating_mul(2),
            format_args!("a population of {population} (`population`)"),
            "breed a smaller population, or smaller genomes",
        )
        .map_err(|e| InputError::new(source, e))?;
        let setup = setup(&self.model, &self.settings, typed, seed, population, source)?;
        // The settings are valid; generation 0 grows as the run is made.
        if let Some(t) = self.generation_time(&start, pool.threads()) {
            sylva_core::budget::check_time(t.seconds, t.what, t.advice)
                .map_err(|e| InputError::new(source, e))?;
        }
        let settings = RunSettings {
            seed,
            population,
            keep_history: 0,
        };
        let run = Run::with_genomes(setup.problem, setup.strategy, pool, settings, setup.first)
            .map_err(|e| InputError::new("[run]", e))?;
        let evolution = Evolution::typed(self.clone(), run);
        evolution.check_finite(source)?;
        Ok(evolution)
    }

    fn generation_time(&self, start: &[Genome], threads: usize) -> Option<GenerationTime> {
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

    fn resume(
        &self,
        source: &str,
        path: &Path,
        text: &str,
        pool: Pool,
    ) -> Result<Evolution, Error> {
        let saved = SavedRun::<M>::parse(path, text)?;
        if saved.config.resumable() != self.resumable() {
            return Err(InputError::file(
                path,
                "the checkpoint was written by a different config (only `generations`, \
                 `threads` and `checkpoint_seconds` may change when resuming)",
            )
            .into());
        }
        let setup = setup(&self.model, &self.settings, Vec::new(), 0, 0, source)?;
        let run = Run::resume(setup.problem, setup.strategy, pool, saved.checkpoint)
            .map_err(|e| InputError::file(path, e))?;
        let evolution = Evolution::typed(self.clone(), run);
        evolution.check_finite(source)?;
        Ok(evolution)
    }
}

/// The model's problem and strategy for `settings`; a refusal names the config (`source`)
/// and the model's section.
fn setup<M: Evolve>(
    model: &M,
    settings: &M::Settings,
    start: Vec<M::Genome>,
    seed: u64,
    population: usize,
    source: &str,
) -> Result<sylva_model::Setup<M>, InputError> {
    model
        .setup(settings, start, seed, population)
        .map_err(|e| InputError::new(source, format!("[{}.{}]: {}", M::NAME, e.field, e.message)))
}

impl Clone for Config {
    fn clone(&self) -> Self {
        Config {
            inner: self.inner.clone_box(),
            source: self.source.clone(),
        }
    }
}

impl Default for Config {
    /// The built-in default run: the first model of the standard registry (binary trees),
    /// every setting at its default.
    fn default() -> Self {
        Registry::standard()
            .default_config()
            .unwrap_or_else(|| Config::new(EvolveConfig::<sylva_bintree::BinTreeModel>::default()))
    }
}

impl std::fmt::Debug for Config {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.to_toml())
    }
}

impl Config {
    /// A config of model `M`.
    pub fn new<M: Evolve + Default>(config: EvolveConfig<M>) -> Config {
        Config {
            inner: Box::new(config),
            source: None,
        }
    }

    /// A config of any model the standard registry knows, built as values (a front end's
    /// form) with the checks of a config file ([`Registry::config_from_value`]).
    pub fn from_value(value: serde_json::Value) -> Result<Config, FieldError> {
        Registry::standard().config_from_value(value)
    }

    /// Parses a config of any model the standard registry knows; errors point into `text`.
    pub fn parse(path: &Path, text: &str) -> Result<Config, InputError> {
        let mut config = Registry::standard().parse_config(path, text)?;
        config.source = Some(path.to_owned());
        Ok(config)
    }

    /// How errors name the config: its file, or "config" for one built in code.
    fn source(&self) -> String {
        self.source
            .as_ref()
            .map_or_else(|| "config".to_owned(), |p| p.display().to_string())
    }

    /// Reads and parses a config file.
    pub fn load(path: &Path) -> Result<Config, InputError> {
        let text = crate::files::read_text(path)?;
        Config::parse(path, &text)
    }

    /// The model evolved.
    pub fn model(&self) -> &'static str {
        self.inner.model()
    }

    /// Run size and seed.
    pub fn run(&self) -> &RunConfig {
        self.inner.run()
    }

    /// Run size and seed, to change (the command line's flags do).
    pub fn run_mut(&mut self) -> &mut RunConfig {
        self.inner.run_mut()
    }

    /// What a run writes.
    pub fn output(&self) -> &OutputConfig {
        self.inner.output()
    }

    /// The config as TOML.
    pub fn to_toml(&self) -> String {
        self.inner.to_toml()
    }

    /// The typed config, if this is a config of model `M`.
    pub fn get<M: Evolve + Default>(&self) -> Option<&EvolveConfig<M>> {
        self.inner.as_any().downcast_ref()
    }

    /// Genome files the model's settings name as the first generation's origin, relative
    /// to the config file.
    pub fn start_files(&self) -> Vec<PathBuf> {
        self.inner.start_files()
    }

    /// How long a generation of this run may take on `threads` threads, for models whose
    /// genomes can take long to grow (L-system plants); `None` for the others. `start` holds
    /// the start genomes ([`Config::load_start`]). [`Evolution::start`] refuses a run whose
    /// generation is over the time budget.
    pub fn generation_time(&self, start: &[Genome], threads: usize) -> Option<GenerationTime> {
        self.inner.generation_time(start, threads)
    }

    /// Reads the genome files of [`Config::start_files`] from `base` (the config file's
    /// folder).
    pub fn load_start(&self, base: &Path) -> Result<Vec<Genome>, InputError> {
        let model = self.model();
        self.start_files()
            .iter()
            .map(|file| {
                let path = base.join(file);
                let genome = crate::genome::load_genome(&path)?;
                if genome.model() == model {
                    Ok(genome)
                } else {
                    Err(InputError::file(
                        &path,
                        format!(
                            "`start` genomes must be `{model}` genomes, not `{}`",
                            genome.model()
                        ),
                    ))
                }
            })
            .collect()
    }
}

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

/// An evolution run of any model.
pub struct Evolution {
    inner: Box<dyn AnyRun>,
}

/// What every typed run can do, object-safe. Implemented once, for [`TypedRun`].
trait AnyRun: Send {
    fn config(&self) -> Config;
    fn title(&self) -> &'static str;
    fn step(&mut self) -> &GenerationStats;
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
    fn immigrate(&mut self, migrants: &[String]) -> Result<Vec<IndividualId>, InputError>;
}

struct TypedRun<M: Evolve> {
    config: EvolveConfig<M>,
    run: Run<M::Problem, M::Strategy>,
}

impl<M: Evolve + Default> TypedRun<M> {
    fn member(&self, ind: &sylva_evolve::Individual<<M::Problem as Problem>::Genome>) -> Member {
        let model = &self.config.model;
        Member {
            id: ind.id,
            genome: Genome::new(
                model.clone(),
                model.genome_file(self.run.problem(), &ind.genome),
            ),
            fitness: ind.fitness,
            origin: ind.origin.clone(),
        }
    }
}

impl<M: Evolve + Default> AnyRun for TypedRun<M> {
    fn config(&self) -> Config {
        Config::new(self.config.clone())
    }

    fn title(&self) -> &'static str {
        M::TITLE
    }

    fn step(&mut self) -> &GenerationStats {
        self.run.step()
    }

    fn generation(&self) -> u32 {
        self.run.generation()
    }

    fn stats(&self) -> &[GenerationStats] {
        self.run.stats()
    }

    fn term_names(&self) -> &[String] {
        self.run.term_names()
    }

    fn population(&self) -> Vec<Member> {
        self.run
            .population()
            .iter()
            .map(|i| self.member(i))
            .collect()
    }

    fn fittest(&self, count: usize) -> Vec<Member> {
        let population = self.run.population();
        sylva_evolve::fittest(population, count)
            .into_iter()
            .map(|i| self.member(&population[i]))
            .collect()
    }

    fn best(&self) -> Member {
        self.member(self.run.best())
    }

    fn member(&self, id: IndividualId) -> Option<Member> {
        self.run.find(id).map(|i| TypedRun::member(self, i))
    }

    fn generation_members(&self, generation: u32) -> Option<Vec<Member>> {
        let pop = self.run.generation_population(generation)?;
        Some(pop.iter().map(|i| TypedRun::member(self, i)).collect())
    }

    fn keep_history(&mut self, generations: usize) {
        self.run.set_keep_history(generations);
    }

    fn checkpoint(&self) -> Result<String, Error> {
        let saved = SavedRunRef::<M> {
            config: &self.config,
            checkpoint: self.run.checkpoint(),
        };
        serde_json::to_string(&saved)
            .map_err(|e| InputError::new("checkpoint", e))
            .map_err(Error::from)
    }

    fn guides(&self) -> Option<Plant> {
        self.config.model.guides(self.run.problem())
    }

    fn emigrants(&self, count: usize) -> Vec<String> {
        let population = self.run.population();
        sylva_evolve::fittest(population, count)
            .into_iter()
            .map(|i| serde_json::to_string(&population[i].genome).unwrap_or_default())
            .collect()
    }

    fn immigrate(&mut self, migrants: &[String]) -> Result<Vec<IndividualId>, InputError> {
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

/// The checkpoint file: the effective config and the engine's checkpoint.
#[derive(Serialize)]
#[serde(bound = "")]
struct SavedRunRef<'a, M: Evolve> {
    config: &'a EvolveConfig<M>,
    checkpoint: Checkpoint<<M::Problem as Problem>::Genome>,
}

struct SavedRun<M: Evolve> {
    config: EvolveConfig<M>,
    checkpoint: Checkpoint<<M::Problem as Problem>::Genome>,
}

impl<M: Evolve + Default> SavedRun<M> {
    /// Reads a checkpoint. Sections of other models in its config (checkpoints of Sylva
    /// before 0.2 wrote every model's) are passed over.
    fn parse(path: &Path, text: &str) -> Result<Self, InputError> {
        let mut value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| InputError::json(path, text, &e))?;
        let bad = |e: serde_json::Error| InputError::file(path, e);
        if let Some(config) = value.get_mut("config").and_then(|c| c.as_object_mut()) {
            config.retain(|k, _| matches!(k.as_str(), "model" | "run" | "output") || k == M::NAME);
        }
        let config = value.get("config").cloned().unwrap_or_default();
        let checkpoint = value.get("checkpoint").cloned().unwrap_or_default();
        Ok(SavedRun {
            config: serde_json::from_value(config).map_err(bad)?,
            checkpoint: serde_json::from_value(checkpoint).map_err(bad)?,
        })
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
    fn typed<M: Evolve + Default>(
        config: EvolveConfig<M>,
        run: Run<M::Problem, M::Strategy>,
    ) -> Self {
        Evolution {
            inner: Box::new(TypedRun { config, run }),
        }
    }

    /// Starts a run: generation 0 made and evaluated. `start` holds the first members (of
    /// the config's model; the model may add mutants of them), the rest is random.
    pub fn start(config: &Config, start: Vec<Genome>, pool: Pool) -> Result<Evolution, Error> {
        config.inner.start(&config.source(), start, pool)
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
        config.inner.resume(&config.source(), path, text, pool)
    }

    /// The effective config.
    pub fn config(&self) -> Config {
        self.inner.config()
    }

    /// The model's title, for plots.
    pub fn title(&self) -> &'static str {
        self.inner.title()
    }

    /// Breeds one generation and returns its statistics. A generation in which no member
    /// has a finite fitness stops the run with an error: its settings cannot score.
    pub fn step(&mut self) -> Result<&GenerationStats, Error> {
        self.inner.step();
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
        self.inner.generation()
    }

    /// Statistics of every generation so far, one row each.
    pub fn stats(&self) -> &[GenerationStats] {
        self.inner.stats()
    }

    /// Names of the fitness terms, in the order of each row's terms.
    pub fn term_names(&self) -> &[String] {
        self.inner.term_names()
    }

    /// The current population, in slot order.
    pub fn population(&self) -> Vec<Member> {
        self.inner.population()
    }

    /// The `count` fittest members of the current population, fittest first (ties go to the
    /// lower slot).
    pub fn fittest(&self, count: usize) -> Vec<Member> {
        self.inner.fittest(count)
    }

    /// The best member of the current population (ties go to the lowest slot).
    pub fn best(&self) -> Member {
        self.inner.best()
    }

    /// A member by id, in the current population or a kept generation.
    pub fn member(&self, id: IndividualId) -> Option<Member> {
        self.inner.member(id)
    }

    /// The population of `generation`, if it is the current one or still kept.
    pub fn generation_members(&self, generation: u32) -> Option<Vec<Member>> {
        self.inner.generation_members(generation)
    }

    /// Keeps the last `generations` generations for browsing (0, the default, keeps only the
    /// current one).
    pub fn keep_history(&mut self, generations: usize) {
        self.inner.keep_history(generations);
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
        self.inner.checkpoint()
    }

    /// Guides drawn beside plants in pictures (a target surface, forbidden cells), if the
    /// model's fitness has any.
    pub fn guides(&self) -> Option<Plant> {
        self.inner.guides()
    }

    /// The `count` fittest genomes of the current population, fittest first, as the engine
    /// evolves them (JSON text): what an island sends to its neighbours.
    pub fn emigrants(&self, count: usize) -> Vec<String> {
        self.inner.emigrants(count)
    }

    /// Puts migrants from [`Evolution::emigrants`] of another run of the same config (its
    /// seed may differ) in the places of the current population's worst members, and
    /// evaluates them; returns their new ids. Nothing changes if any migrant is not a genome
    /// of this run.
    pub fn immigrate(&mut self, migrants: &[String]) -> Result<Vec<IndividualId>, InputError> {
        self.inner.immigrate(migrants)
    }
}
