//! A config of any model ([`Config`]), and what it takes to start or resume a run of it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sylva_core::par::Pool;
use sylva_evolve::{Run, RunSettings, WithTerm};
use sylva_model::Evolve;

use crate::assets::GrowOptions;
use crate::erased::{DynModel, Value};
use crate::error::{Error, FieldError, InputError};
use crate::genome::Genome;
use crate::registry::Registry;

use super::checkpoint::SavedRun;
use super::hooks::{RunHooks, Scored, check_resumed, check_term, first_generation};
use super::run::{Hooked, TypedRun};
use super::schema::{EvolveConfig, MatchConfig, OutputConfig, RunConfig, SearchStrategy};

/// An evolution config of any model.
pub struct Config {
    model: Arc<dyn DynModel>,
    /// The model's `EvolveConfig`.
    config: Box<Value>,
    /// The file it was read from, named in errors.
    source: Option<PathBuf>,
    /// The registry it was read with, which reads its start genomes; `None`: the standard.
    registry: Option<Registry>,
    /// The folder its files (start genomes, target pictures) are found in, when it is not
    /// the config file's.
    base: Option<PathBuf>,
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

/// Starts a run of `config`: generation 0 made and evaluated. A refusal names the config
/// (`source`).
pub(crate) fn start<M: Evolve + Default>(
    config: &EvolveConfig<M>,
    source: &str,
    base: &Path,
    start: Vec<Genome>,
    pool: Pool,
    hooks: RunHooks,
) -> Result<TypedRun<M>, Error> {
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
    let made = |start: Vec<M::Genome>| {
        setup(
            &config.model,
            &config.settings,
            start,
            seed,
            population,
            source,
        )
    };
    // With an own term, the model is set up twice more: to make generation 0 once without its
    // fitness, and to foresee each generation's genomes (`hooks.rs`).
    let again = hooks.term.as_ref().map(|_| typed.clone());
    let setup = made(typed)?;
    let scout = || Ok(made(again.clone().unwrap_or_default())?.strategy);
    let (problem, hooked) = with_hooks(config, setup.problem, base, pool, hooks, scout)?;
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
    let typed = TypedRun {
        config: config.clone(),
        run,
        hooked,
    };
    typed.failure()?;
    Ok(typed)
}

/// The problem of `config` with its added term (the `[match]` outline or `hooks`' own term,
/// not both), and the hooks at work; with an own term, a second breeding of the model made
/// by `scout`, to foresee what generations evaluate.
fn with_hooks<M: Evolve + Default>(
    config: &EvolveConfig<M>,
    problem: M::Problem,
    base: &Path,
    pool: Pool,
    hooks: RunHooks,
    scout: impl FnOnce() -> Result<M::Strategy, InputError>,
) -> Result<(WithTerm<M::Problem>, Hooked<M>), InputError> {
    let mut hooked = Hooked::none(pool);
    hooked.stop = hooks.stop;
    let Some(own) = hooks.term else {
        return Ok((with_term(config, problem, base)?, hooked));
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
#[allow(clippy::too_many_arguments)] // The erased model's call, one argument each.
pub(crate) fn resume<M: Evolve + Default>(
    config: &EvolveConfig<M>,
    source: &str,
    base: &Path,
    path: &Path,
    text: &str,
    pool: Pool,
    hooks: RunHooks,
) -> Result<TypedRun<M>, Error> {
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
    let made = || setup(&config.model, &config.settings, Vec::new(), 0, 0, source);
    let setup = made()?;
    let scout = || Ok(made()?.strategy);
    let (problem, hooked) = with_hooks(config, setup.problem, base, pool, hooks, scout)?;
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
    let typed = TypedRun {
        config: config.clone(),
        run,
        hooked,
    };
    typed.failure()?;
    Ok(typed)
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

/// The model's problem with the config's `[match]` term, if it has one, its pictures read
/// relative to `base`.
pub(super) fn with_term<M: Evolve>(
    config: &EvolveConfig<M>,
    problem: M::Problem,
    base: &Path,
) -> Result<WithTerm<M::Problem>, InputError> {
    let added = config
        .outline
        .as_ref()
        .map(|outline| super::outline::added(&config.model, outline, base))
        .transpose()?;
    Ok(WithTerm { problem, added })
}

/// The model's problem and strategy for `settings`; a refusal names the config (`source`)
/// and the model's section.
pub(super) fn setup<M: Evolve>(
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
            model: self.model.clone(),
            config: self.model.clone_config(&*self.config),
            source: self.source.clone(),
            registry: self.registry.clone(),
            base: self.base.clone(),
        }
    }
}

impl Config {
    /// The run `sylva evolve` makes without a config (written out in
    /// `examples/bintree/default.toml`): [`Config::default`], its best plant and contact
    /// sheet dressed in oak leaves at 1.5 times the kind's density and the oak's furrowed
    /// bark, as a tree in a scene would be. The evolution itself is the default's (it scores
    /// the plants as grown); `examples/bintree/paper.toml` keeps the paper's bare figures.
    pub fn builtin_run() -> Self {
        let mut config = Config::default();
        let output = config.output_mut();
        output.foliage = Some(sylva_core::species::LeafKind::Oak);
        output.density = 1.5;
        config
    }
}

impl Default for Config {
    /// The first model of the standard registry (binary trees), every setting at its
    /// default: what an empty config reads as. (`sylva evolve` without a config runs
    /// [`Config::builtin_run`].)
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
        Config::erased(Arc::new(config.model.clone()), Box::new(config))
    }

    /// `config`, of `model`.
    pub(crate) fn erased(model: Arc<dyn DynModel>, config: Box<Value>) -> Config {
        Config {
            model,
            config,
            source: None,
            registry: None,
            base: None,
        }
    }

    /// The model's handle and its typed config, for starting and resuming runs.
    pub(super) fn parts(&self) -> (&Arc<dyn DynModel>, &Value) {
        (&self.model, &*self.config)
    }

    /// This config, read from `path` with `registry` (which reads its start genomes).
    pub(crate) fn read_with(mut self, path: Option<&Path>, registry: &Registry) -> Config {
        self.source = path.map(Path::to_owned);
        if !std::ptr::eq(registry, Registry::standard()) {
            self.registry = Some(registry.clone());
        }
        self
    }

    /// The folder the files it names (start genomes, target pictures) are found in: the one
    /// set with [`Config::set_base`], else the config file's, else the current folder.
    pub fn base(&self) -> PathBuf {
        match (&self.base, &self.source) {
            (Some(base), _) => base.clone(),
            (None, Some(source)) => source.parent().map(Path::to_owned).unwrap_or_default(),
            (None, None) => PathBuf::new(),
        }
    }

    /// Finds the files the config names in `base` (a config built in code, or read from
    /// text).
    pub fn set_base(&mut self, base: impl Into<PathBuf>) {
        self.base = Some(base.into());
    }

    /// The registry the config was read with.
    pub fn registry(&self) -> &Registry {
        self.registry.as_ref().unwrap_or(Registry::standard())
    }

    /// A config of any model the standard registry knows, built as values (a front end's
    /// form) with the checks of a config file ([`Registry::config_from_value`]).
    pub fn from_value(value: serde_json::Value) -> Result<Config, FieldError> {
        Registry::standard().config_from_value(value)
    }

    /// Parses a config of any model the standard registry knows; errors point into `text`.
    pub fn parse(path: &Path, text: &str) -> Result<Config, InputError> {
        Registry::standard().parse_config(path, text)
    }

    /// How errors name the config: its file, or "config" for one built in code.
    pub(super) fn source(&self) -> String {
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
        self.model.name()
    }

    /// Run size and seed.
    pub fn run(&self) -> &RunConfig {
        self.model.run_settings(&*self.config)
    }

    /// Run size and seed, to change (the command line's flags do).
    pub fn run_mut(&mut self) -> &mut RunConfig {
        self.model.run_settings_mut(&mut *self.config)
    }

    /// What a run writes.
    pub fn output(&self) -> &OutputConfig {
        self.model.output(&*self.config)
    }

    /// The `[match]` section, if any.
    pub fn outline(&self) -> Option<&MatchConfig> {
        self.model.outline(&*self.config)
    }

    /// How the run's best plant is grown for its files: `[output]`'s taper, wind and
    /// height, pruned to `[match]`'s outlines when it prunes (their pictures read from
    /// [`Config::base`]).
    pub fn grow_options(&self) -> Result<GrowOptions, InputError> {
        let output = self.output();
        let pruned_to = match self.outline() {
            Some(outline) => super::outline::space(outline, &self.base())?,
            None => None,
        };
        Ok(GrowOptions {
            taper: output.pipe_taper(),
            wind: output.wind_options(),
            height: output.height,
            pruned_to,
            dress: output.dress(),
            ..GrowOptions::default()
        })
    }

    /// What a run writes, to change (`sylva match --height` does).
    pub fn output_mut(&mut self) -> &mut OutputConfig {
        self.model.output_mut(&mut *self.config)
    }

    /// The model's settings (its section of the config) as JSON: what breeding by hand
    /// keeps of a run's settings ([`crate::Settings::KnobsOver`]).
    pub fn model_settings(&self) -> serde_json::Value {
        self.model.settings_value(&*self.config)
    }

    /// The config as TOML.
    pub fn to_toml(&self) -> String {
        self.model.to_toml(&*self.config)
    }

    /// The typed config, if this is a config of model `M`.
    pub fn get<M: Evolve + Default>(&self) -> Option<&EvolveConfig<M>> {
        self.config.downcast_ref()
    }

    /// Genome files the model's settings name as the first generation's origin, relative
    /// to the config file.
    pub fn start_files(&self) -> Vec<PathBuf> {
        self.model.start_files(&*self.config)
    }

    /// How long a generation of this run may take on `threads` threads, for models whose
    /// genomes can take long to grow (L-system plants); `None` for the others. `start` holds
    /// the start genomes ([`Config::load_start`]). [`Evolution::start`](super::Evolution::start) refuses a run whose
    /// generation is over the time budget.
    pub fn generation_time(&self, start: &[Genome], threads: usize) -> Option<GenerationTime> {
        self.model.generation_time(&*self.config, start, threads)
    }

    /// Reads the genome files of [`Config::start_files`] from `base` (the config file's
    /// folder), with the registry the config was read with.
    pub fn load_start(&self, base: &Path) -> Result<Vec<Genome>, InputError> {
        let model = self.model();
        self.start_files()
            .iter()
            .map(|file| {
                let path = base.join(file);
                let genome = self.registry().load_genome(&path)?;
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
