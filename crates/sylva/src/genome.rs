//! A genome of any model ([`Genome`]), read from files, grown, and varied by hand.
//!
//! A `Genome` holds a model's typed genome beside the model's handle (the crate's one
//! object-safe face of a model, `erased.rs`), so front ends handle genomes of any model
//! alike while every operation runs the model's own code. [`Genome::get`] gives the typed genome back for model-specific work.

use std::fmt;
use std::path::Path;
use std::sync::Arc;

use sylva_core::Plant;
use sylva_model::{Evolve, GenomeError, Knobs, MeshHint, Model, VariationError};

use crate::erased::{DynModel, Value};
use crate::error::{Error, InputError};
use crate::registry::Registry;

/// A genome of any model.
#[derive(Clone)]
pub struct Genome {
    model: Arc<dyn DynModel>,
    genome: Arc<Value>,
}

/// What breeding by hand follows.
#[derive(Clone, Copy, Debug, Default)]
pub enum Settings<'a> {
    /// The model's defaults.
    #[default]
    Default,
    /// A person's controls, which each model turns into its own settings
    /// ([`sylva_model::Model::hand_settings`]).
    Knobs(Knobs),
    /// A person's controls over the model's settings as JSON (those of the run the plants
    /// come from, [`crate::Config::model_settings`]): what the knobs do not set is kept.
    KnobsOver(Knobs, &'a serde_json::Value),
    /// The model's settings as JSON (its config section; a Python dict), read as a config
    /// section is: unknown fields refused, numbers checked.
    Json(&'a serde_json::Value),
}

impl<'a> From<Option<&'a serde_json::Value>> for Settings<'a> {
    fn from(json: Option<&'a serde_json::Value>) -> Settings<'a> {
        json.map_or(Settings::Default, Settings::Json)
    }
}

/// Model `M`'s settings for `settings`.
pub(crate) fn settings_of<M: Model>(
    model: &M,
    settings: Settings<'_>,
) -> Result<M::Settings, InputError> {
    let from_json = |v: &serde_json::Value| {
        serde_json::from_value(v.clone())
            .map_err(|e| InputError::new(format!("{} settings", M::NAME), e.to_string()))
    };
    match settings {
        Settings::Default => Ok(M::Settings::default()),
        Settings::Knobs(knobs) => Ok(model.hand_settings(knobs, M::Settings::default())),
        Settings::KnobsOver(knobs, v) => Ok(model.hand_settings(knobs, from_json(v)?)),
        Settings::Json(v) => from_json(v),
    }
}

impl Genome {
    /// A genome of `model`.
    pub fn new<M: Evolve + Default>(model: M, genome: M::Genome) -> Genome {
        Genome::erased(Arc::new(model), Box::new(genome))
    }

    /// `genome`, made by `model`.
    pub(crate) fn erased(model: Arc<dyn DynModel>, genome: Box<Value>) -> Genome {
        Genome {
            model,
            genome: genome.into(),
        }
    }

    /// A genome of this genome's model.
    fn sibling(&self, genome: Box<Value>) -> Genome {
        Genome::erased(self.model.clone(), genome)
    }

    /// The model's name in files.
    pub fn model(&self) -> &'static str {
        self.model.name()
    }

    /// The model's title.
    pub fn title(&self) -> &'static str {
        self.model.title()
    }

    /// A short text form a person can copy and paste, for a model that has one
    /// ([`sylva_model::Model::packed`]).
    pub fn packed(&self) -> Option<String> {
        self.model.packed(&*self.genome)
    }

    /// The typed genome, if this is a genome of model `M`.
    pub fn get<M: Model>(&self) -> Option<&M::Genome> {
        if self.model() != M::NAME {
            return None;
        }
        self.genome.downcast_ref::<M::Genome>()
    }

    /// The genome file's text: pretty JSON ending with a newline.
    pub fn to_json(&self) -> String {
        self.model.write(&*self.genome)
    }

    /// The genome as a JSON value (for the extras of exported assets).
    pub fn to_value(&self) -> serde_json::Value {
        self.model.to_value(&*self.genome)
    }

    /// A genome of the same model from a genome file's text (a field changed by hand);
    /// errors carry the line and column.
    pub fn reparse(&self, text: &str) -> Result<Genome, GenomeError> {
        Ok(self.sibling(self.model.parse_genome(text)?))
    }

    /// Grows the plant with `seed`.
    pub fn develop(&self, seed: u64) -> Result<Plant, Error> {
        self.model
            .develop(&*self.genome, seed)
            .map_err(|source| Error::Develop {
                model: self.model(),
                source,
            })
    }

    /// The seed the genome grows with when none is given.
    pub fn default_seed(&self) -> u64 {
        self.model.default_seed(&*self.genome)
    }

    /// How the model's plants are best meshed.
    pub fn mesh_hint(&self) -> MeshHint {
        self.model.mesh_hint()
    }

    /// Seconds growing it may take on one core, for models whose growth can take long
    /// (L-system plants); `None` for the others.
    pub fn growth_seconds(&self) -> Option<f64> {
        self.model.growth_seconds(&*self.genome)
    }

    /// A mutated copy, made by the model's own mutation with `settings` (the model's
    /// settings as JSON, or its defaults), drawing from the stream of `seed`.
    pub fn mutate(&self, settings: Settings<'_>, seed: u64) -> Result<Genome, Error> {
        let mut rng = sylva_core::rng::seeded(seed);
        let child = self.model.mutate(&*self.genome, settings, &mut rng)?;
        Ok(self.sibling(child))
    }

    /// A child of two or more parents of one model, each with a dominance weight, made by
    /// the model's own crossover with `settings`; also says which parents gave it genes.
    pub fn cross(
        parents: &[(&Genome, f64)],
        settings: Settings<'_>,
        seed: u64,
    ) -> Result<(Genome, Vec<usize>), Error> {
        let Some((first, _)) = parents.first() else {
            return Err(InputError::new("parents", VariationError::TooFewParents(0)).into());
        };
        let mut rng = sylva_core::rng::seeded(seed);
        let (child, gave) = first.model.cross(parents, settings, &mut rng)?;
        Ok((first.sibling(child), gave))
    }
}

impl PartialEq for Genome {
    fn eq(&self, other: &Genome) -> bool {
        self.model() == other.model() && self.model.same(&*self.genome, &*other.genome)
    }
}

impl fmt::Debug for Genome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Genome")
            .field("model", &self.model())
            .field("genome", &self.to_value())
            .finish()
    }
}

/// Reads a genome file of any model the standard registry knows; errors point at the line
/// and column.
pub fn load_genome(path: &Path) -> Result<Genome, InputError> {
    Registry::standard().load_genome(path)
}

/// Parses a genome file already read from `path`.
pub fn parse_genome(path: &Path, text: &str) -> Result<Genome, InputError> {
    Registry::standard()
        .parse_genome(text)
        .map_err(|e: GenomeError| InputError::genome(path, text, e))
}

/// Reads a genome file that must be of model `M`; `purpose` says what it is for in the
/// error (like "gardens grow").
pub fn load_genome_of<M: Model>(path: &Path, purpose: &str) -> Result<M::Genome, InputError> {
    let genome = load_genome(path)?;
    expect_model::<M>(path, &genome, purpose)
}

/// The typed genome of model `M`, or an error naming `path` and the model it is.
pub fn expect_model<M: Model>(
    path: &Path,
    genome: &Genome,
    purpose: &str,
) -> Result<M::Genome, InputError> {
    genome.get::<M>().cloned().ok_or_else(|| {
        InputError::file(
            path,
            format!(
                "{purpose} `{}` genomes; this is a `{}` genome",
                M::NAME,
                genome.model()
            ),
        )
    })
}
