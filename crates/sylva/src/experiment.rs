//! Experiments for any model that runs them ([`sylva_model::experiments::Experiments`],
//! said in its registry line; the L-system's herbs under a tree, lateral light, breeding
//! from empty rules) as one workflow: read the config and its genomes, estimate the work,
//! run, and hand back the report, the per-step records and the grown plants as assets. The
//! model runs the experiment; this module finds it in the registry, reads the files and
//! meshes what grew.
//!
//! ```no_run
//! # fn main() -> Result<(), sylva::Error> {
//! let experiment = sylva::Experiment::load(&sylva::Registry::standard(), "examples/lsystem/herbs-under-tree.toml".as_ref())?;
//! let pool = sylva::core::par::Pool::with_threads(0)?;
//! let result = experiment.run(&pool, &mut |_step| {})?;
//! print!("{}", result.report);
//! # Ok(())
//! # }
//! ```

use std::error::Error as StdError;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use sylva_core::par::Pool;
use sylva_model::experiments::{ExperimentOutcome, Experiments};
use sylva_model::{Evolve, MeshHint, Work};

use crate::assets::{Origin, Placed, SceneAssets, check_scene_glb};
use crate::error::{Error, InputError};
use crate::files::read_text;
use crate::genome::Genome;
use crate::registry::{EntryOf, Registry};

/// An experiment config with the genomes it names, ready to run.
pub struct Experiment {
    path: PathBuf,
    loaded: Box<dyn Loaded>,
}

/// What an experiment measured and grew.
pub struct ExperimentResult {
    /// `report.txt`: the measured outcome, one figure a line.
    pub report: String,
    /// `records.csv`: per plant and step records.
    pub records_csv: String,
    /// The grown plants where they grew, each carrying its genome, seed and biomass.
    pub scene: SceneAssets,
    /// Plants the experiment compares, side by side (for the L-system's lateral-light
    /// experiment: tree 1 under lateral light beside tree 1 under vertical light, roots left
    /// out, turned so the light comes from +X, for a front view).
    pub side: Option<SceneAssets>,
}

impl<M: Experiments + Evolve + Default> EntryOf<M> {
    /// It runs experiments from config files (this module).
    pub fn with_experiments(self) -> Self {
        self.offering::<Arc<dyn ExperimentFace>>(Arc::new(M::default()))
    }
}

/// What the registry holds of a model that runs experiments: its typed trait, erased.
pub(crate) trait ExperimentFace: Send + Sync {
    /// The config of `text` with the genome files it names, read by this model; refused as
    /// [`LoadError::NotMine`] when it is not one of this model's experiments.
    fn load(
        &self,
        registry: &Registry,
        path: &Path,
        text: &str,
    ) -> Result<Box<dyn Loaded>, LoadError>;
}

/// Why a model did not load an experiment config.
pub(crate) enum LoadError {
    /// The config is not one of its experiments (the TOML error, pointing into the file).
    NotMine(InputError),
    /// It is, and something it names is wrong.
    Bad(InputError),
}

impl<M: Experiments> ExperimentFace for M {
    fn load(
        &self,
        registry: &Registry,
        path: &Path,
        text: &str,
    ) -> Result<Box<dyn Loaded>, LoadError> {
        let experiment: M::Experiment = toml::from_str(text)
            .map_err(|e| LoadError::NotMine(InputError::toml(path, text, &e)))?;
        let base = path.parent().unwrap_or(Path::new("."));
        let genomes = M::genome_files(&experiment)
            .iter()
            .map(|file| {
                let file = base.join(file);
                let genome = registry.load_genome(&file)?;
                crate::genome::expect_model::<M>(&file, &genome, "experiments grow")
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(LoadError::Bad)?;
        Ok(Box::new(LoadedOf {
            model: self.clone(),
            experiment,
            genomes,
        }))
    }
}

/// An experiment of one model, typed, with its genomes.
pub(crate) trait Loaded: Send + Sync {
    /// How the model's plants are meshed.
    fn mesh_hint(&self) -> MeshHint;
    /// What to change for smaller plants ([`Experiments::SMALLER`]).
    fn smaller(&self) -> &'static str;
    fn work(&self) -> Result<Work, Box<dyn StdError + Send + Sync>>;
    fn run(
        &self,
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<ExperimentOutcome<Genome>, Box<dyn StdError + Send + Sync>>;
}

struct LoadedOf<M: Experiments> {
    model: M,
    experiment: M::Experiment,
    genomes: Vec<M::Genome>,
}

impl<M: Experiments> Loaded for LoadedOf<M> {
    fn mesh_hint(&self) -> MeshHint {
        self.model.mesh_hint()
    }

    fn smaller(&self) -> &'static str {
        M::SMALLER
    }

    fn work(&self) -> Result<Work, Box<dyn StdError + Send + Sync>> {
        self.model.experiment_work(&self.experiment, &self.genomes)
    }

    fn run(
        &self,
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<ExperimentOutcome<Genome>, Box<dyn StdError + Send + Sync>> {
        let o = self
            .model
            .run_experiment(&self.experiment, &self.genomes, pool, on_step)?;
        let plants = o
            .plants
            .into_iter()
            .map(|p| sylva_model::experiments::ExperimentPlant {
                genome: Genome::new(self.model.clone(), p.genome),
                label: p.label,
                position: p.position,
                plant: p.plant,
                biomass: p.biomass,
            })
            .collect();
        Ok(ExperimentOutcome {
            report: o.report,
            records_csv: o.records_csv,
            plants,
            side: o.side,
        })
    }
}

impl Experiment {
    /// Reads an experiment config and the genome files it names, relative to it, by the
    /// first model of `registry` whose experiments it is (for the L-system,
    /// `[herbs-under-tree]`, `[lateral-light]` or `[empty-rules]`). A config none of them
    /// reads is refused with the first one's error.
    pub fn load(registry: &Registry, path: &Path) -> Result<Experiment, InputError> {
        let text = read_text(path)?;
        let mut first_error = None;
        for face in registry
            .models()
            .iter()
            .filter_map(|m| m.offer::<Arc<dyn ExperimentFace>>())
        {
            match face.load(registry, path, &text) {
                Ok(loaded) => {
                    return Ok(Experiment {
                        path: path.to_owned(),
                        loaded,
                    });
                }
                Err(LoadError::Bad(e)) => return Err(e),
                Err(LoadError::NotMine(e)) => {
                    first_error.get_or_insert(e);
                }
            }
        }
        Err(first_error.unwrap_or_else(|| {
            InputError::file(
                path,
                "no model here runs experiments; expected a registry with one",
            )
        }))
    }

    /// The experiment's work at the plants' bounds; its `steps` are the steps
    /// [`Experiment::run`] counts.
    pub fn work(&self) -> Result<Work, InputError> {
        self.loaded
            .work()
            .map_err(|e| InputError::file_error(&self.path, &*e))
    }

    /// Runs the experiment on `pool`, calling `on_step` with the steps done.
    pub fn run(
        &self,
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<ExperimentResult, Error> {
        let path = &self.path;
        let outcome = self
            .loaded
            .run(pool, on_step)
            .map_err(|e| InputError::file_error(path, &*e))?;
        let placed: Vec<Placed> = outcome
            .plants
            .iter()
            .map(|p| {
                // Each plant grew in a shared world; its genome and seed regrow it alone.
                let mut extras = Origin::of(&p.genome, 0).extras();
                extras["biomass_g"] = p.biomass.into();
                Placed {
                    translation: p.position,
                    extras: Some(extras),
                    ..Placed::new(p.label.clone(), &p.plant, p.genome.mesh_hint())
                }
            })
            .collect();
        check_scene_glb(
            &placed,
            false,
            path,
            &format!("grow smaller plants ({})", self.loaded.smaller()),
        )?;
        let scene = SceneAssets::mesh(&placed, None).map_err(|e| e.in_file(path))?;
        let hint = self.loaded.mesh_hint();
        let side = match outcome.side {
            Some(posed) => {
                let placed: Vec<Placed> = posed
                    .iter()
                    .map(|p| Placed {
                        translation: p.translation,
                        rotation: p.rotation,
                        ..Placed::new(p.name.clone(), &p.plant, hint)
                    })
                    .collect();
                Some(SceneAssets::mesh(&placed, None).map_err(|e| e.in_file(path))?)
            }
            None => None,
        };
        Ok(ExperimentResult {
            report: outcome.report,
            records_csv: outcome.records_csv,
            scene,
            side,
        })
    }
}
