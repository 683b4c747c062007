//! A config of any model ([`Config`]): read, built in code, changed, and written back.

use std::path::{Path, PathBuf};

use sylva_model::Evolve;

use crate::assets::GrowOptions;
use crate::error::InputError;
use crate::genome::Genome;
use crate::registry::Registry;

use super::face::ConfigFace;
use super::schema::{EvolveConfig, MatchConfig, OutputConfig, RunConfig};
use super::silhouette::Target;
use super::typed::GenerationTime;
use super::typed::Where;

/// An evolution config of any model.
pub struct Config {
    /// The model's `EvolveConfig`.
    face: Box<dyn ConfigFace>,
    /// The file it was read from, named in errors.
    source: Option<PathBuf>,
    /// The folder its files (start genomes, target pictures) are found in, when it is not
    /// the config file's.
    base: Option<PathBuf>,
    /// Its `[match]` pictures, when they were read already (a clone shares them).
    target: Option<Target>,
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
            base: self.base.clone(),
            target: self.target.clone(),
        }
    }
}

impl Config {
    /// The run `sylva evolve` makes without a config (written out in
    /// `examples/bintree/default.toml`): the default config of `registry`'s first model
    /// ([`Registry::default_config`]: what an empty config reads as), its best plant and
    /// contact sheet dressed in oak leaves at 1.5 times the kind's density and the oak's
    /// furrowed bark, as a tree in a scene would be. The evolution itself is the default's
    /// (it scores the plants as grown); `examples/bintree/paper.toml` keeps the paper's bare
    /// figures. An empty registry has none.
    pub fn builtin_run(registry: &Registry) -> Result<Self, InputError> {
        let mut config = registry
            .default_config()
            .ok_or_else(|| InputError::new("model", "this registry has no models"))?;
        let output = config.output_mut();
        output.foliage = Some(sylva_core::species::LeafKind::Oak);
        output.density = 1.5;
        Ok(config)
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
            base: None,
            target: None,
        }
    }

    /// The typed config's face, for starting and resuming runs.
    pub(super) fn face(&self) -> &dyn ConfigFace {
        &*self.face
    }

    /// How errors name the config, and its `[match]` pictures, read if they were not.
    pub(super) fn at(&self) -> Result<Where, InputError> {
        Ok(Where {
            source: self.source(),
            target: self.target()?,
        })
    }

    /// The pictures of its `[match]` (none without one): those it carries when they are the
    /// ones it names ([`Config::with_target`]), else read now from [`Config::base`].
    pub fn target(&self) -> Result<Option<Target>, InputError> {
        let Some(outline) = self.outline() else {
            return Ok(None);
        };
        match &self.target {
            Some(target) if target.is_of(outline) => Ok(Some(target.clone())),
            _ => Target::read(outline, &self.base()).map(Some),
        }
    }

    /// This config carrying `target`, its `[match]` pictures as read already, so that runs,
    /// pictures and files made from it do not read them again.
    pub fn with_target(mut self, target: Option<Target>) -> Config {
        self.target = target;
        self
    }

    /// This config, read from `path` (named in errors; its folder holds the files it names).
    pub(crate) fn read_from(mut self, path: &Path) -> Config {
        self.source = Some(path.to_owned());
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

    /// How errors name the config: its file, or "config" for one built in code.
    pub(super) fn source(&self) -> String {
        self.source
            .as_ref()
            .map_or_else(|| "config".to_owned(), |p| p.display().to_string())
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
        let pruned_to = match (self.outline(), self.target()?) {
            (Some(outline), Some(target)) => target.space(outline)?,
            _ => None,
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
    /// folder) with `registry` (the one the config was read with).
    pub fn load_start(&self, registry: &Registry, base: &Path) -> Result<Vec<Genome>, InputError> {
        let model = self.model();
        self.start_files()
            .iter()
            .map(|file| {
                let path = base.join(file);
                let genome = registry.load_genome(&path)?;
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
