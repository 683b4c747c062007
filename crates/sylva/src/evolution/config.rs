//! A config of any model ([`Config`]): read, built in code, changed, and written back.

use std::path::{Path, PathBuf};

use sylva_model::Evolve;

use crate::assets::GrowOptions;
use crate::error::{FieldError, InputError};
use crate::genome::Genome;
use crate::registry::Registry;

use super::face::{ConfigFace, Where};
use super::schema::{EvolveConfig, MatchConfig, OutputConfig, RunConfig};
use super::typed::GenerationTime;

/// An evolution config of any model.
pub struct Config {
    /// The model's `EvolveConfig`.
    face: Box<dyn ConfigFace>,
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

impl Clone for Config {
    fn clone(&self) -> Self {
        Config {
            face: self.face.clone_face(),
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
        Config::of(Box::new(config))
    }

    /// The config `face` stands for.
    pub(super) fn of(face: Box<dyn ConfigFace>) -> Config {
        Config {
            face,
            source: None,
            registry: None,
            base: None,
        }
    }

    /// The typed config's face, for starting and resuming runs.
    pub(super) fn face(&self) -> &dyn ConfigFace {
        &*self.face
    }

    /// How errors name the config and where its files are found.
    pub(super) fn at(&self) -> Where {
        Where {
            source: self.source(),
            base: self.base(),
        }
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
        self.face.model()
    }

    /// Run size and seed.
    pub fn run(&self) -> &RunConfig {
        self.face.run()
    }

    /// Run size and seed, to change (the command line's flags do).
    pub fn run_mut(&mut self) -> &mut RunConfig {
        self.face.run_mut()
    }

    /// What a run writes.
    pub fn output(&self) -> &OutputConfig {
        self.face.output()
    }

    /// The `[match]` section, if any.
    pub fn outline(&self) -> Option<&MatchConfig> {
        self.face.outline()
    }

    /// How the run's best plant is grown for its files: `[output]`'s taper, wind and
    /// height, pruned to `[match]`'s outlines when it prunes (their pictures read from
    /// [`Config::base`]).
    pub fn grow_options(&self) -> Result<GrowOptions, InputError> {
        let output = self.output();
        let pruned_to = match self.outline() {
            Some(outline) => super::silhouette::space(outline, &self.base())?,
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
        self.face.output_mut()
    }

    /// The model's settings (its section of the config) as JSON: what breeding by hand
    /// keeps of a run's settings ([`crate::Settings::KnobsOver`]).
    pub fn model_settings(&self) -> serde_json::Value {
        self.face.settings_value()
    }

    /// The config as TOML.
    pub fn to_toml(&self) -> String {
        self.face.to_toml()
    }

    /// The typed config, if this is a config of model `M`.
    pub fn get<M: Evolve + Default>(&self) -> Option<&EvolveConfig<M>> {
        self.face.as_any().downcast_ref()
    }

    /// Genome files the model's settings name as the first generation's origin, relative
    /// to the config file.
    pub fn start_files(&self) -> Vec<PathBuf> {
        self.face.start_files()
    }

    /// How long a generation of this run may take on `threads` threads, for models whose
    /// genomes can take long to grow (L-system plants); `None` for the others. `start` holds
    /// the start genomes ([`Config::load_start`]). [`Evolution::start`](super::Evolution::start) refuses a run whose
    /// generation is over the time budget.
    pub fn generation_time(&self, start: &[Genome], threads: usize) -> Option<GenerationTime> {
        self.face.generation_time(start, threads)
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
