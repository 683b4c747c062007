//! A genome of any model ([`Genome`]), read from files, grown, and varied by hand.
//!
//! A `Genome` holds a model's typed genome beside the model that made it, behind one small
//! object-safe face implemented once for every model (`Face`, below), so front ends handle
//! genomes of any model alike while every operation runs the model's own code.
//! [`Genome::get`] gives the typed genome back for model-specific work; a genome of another
//! model gives `None`, never a panic.

use std::any::Any;
use std::fmt;
use std::path::Path;
use std::sync::Arc;

use sylva_core::Plant;
use sylva_core::dress::Dress;
use sylva_core::rng::ChaCha8Rng;
use sylva_model::{
    Bred, DevelopError, GenomeError, Knobs, MeshHint, Model, Parent, VariationError,
};

use crate::error::{Error, InputError};

/// A genome of any model.
#[derive(Clone)]
pub struct Genome(Arc<dyn Face>);

/// Model `M`'s genome, held with the model that made it.
struct Typed<M: Model> {
    model: M,
    genome: M::Genome,
}

/// What a genome of any model does, each on its own typed value.
trait Face: Send + Sync {
    fn as_any(&self) -> &dyn Any;
    fn model(&self) -> &'static str;
    fn title(&self) -> &'static str;
    fn mesh_hint(&self) -> MeshHint;
    fn dress(&self) -> Dress;
    fn write(&self) -> String;
    fn to_value(&self) -> serde_json::Value;
    fn packed(&self) -> Option<String>;
    fn develop(&self, seed: u64) -> Result<Plant, DevelopError>;
    fn default_seed(&self) -> u64;
    fn with_seed(&self, seed: u64) -> Genome;
    fn growth_seconds(&self) -> Option<f64>;
    fn schema(&self) -> crate::schema::Schema;
    /// Whether `other` (of any model) is the same genome.
    fn same(&self, other: &Genome) -> bool;
    fn reparse(&self, text: &str) -> Result<Genome, GenomeError>;
    fn mutate(&self, settings: Settings<'_>, rng: &mut ChaCha8Rng) -> Result<Genome, InputError>;
    /// A child of `parents` (this genome first), which may be of any model: another
    /// model's is refused, naming the parent.
    fn cross(
        &self,
        parents: &[(&Genome, f64)],
        settings: Settings<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<(Genome, Vec<usize>), Error>;
}

impl<M: Model> Typed<M> {
    /// A genome of this genome's model.
    fn sibling(&self, genome: M::Genome) -> Genome {
        Genome::new(self.model.clone(), genome)
    }
}

impl<M: Model> Face for Typed<M> {
    fn as_any(&self) -> &dyn Any {
        self
    }

    fn model(&self) -> &'static str {
        M::NAME
    }

    fn title(&self) -> &'static str {
        M::TITLE
    }

    fn mesh_hint(&self) -> MeshHint {
        self.model.mesh_hint()
    }

    fn dress(&self) -> Dress {
        self.model.dress(&self.genome)
    }

    fn write(&self) -> String {
        self.model.write(&self.genome)
    }

    fn to_value(&self) -> serde_json::Value {
        // Genomes are plain data: they serialise.
        serde_json::to_value(&self.genome).unwrap_or(serde_json::Value::Null)
    }

    fn packed(&self) -> Option<String> {
        self.model.packed(&self.genome)
    }

    fn develop(&self, seed: u64) -> Result<Plant, DevelopError> {
        self.model.develop(&self.genome, seed)
    }

    fn default_seed(&self) -> u64 {
        self.model.default_seed(&self.genome)
    }

    fn with_seed(&self, seed: u64) -> Genome {
        self.sibling(self.model.with_seed(&self.genome, seed))
    }

    fn growth_seconds(&self) -> Option<f64> {
        self.model.growth_seconds(&self.genome)
    }

    fn schema(&self) -> crate::schema::Schema {
        self.model.schema()
    }

    fn same(&self, other: &Genome) -> bool {
        other.get::<M>().is_some_and(|other| *other == self.genome)
    }

    fn reparse(&self, text: &str) -> Result<Genome, GenomeError> {
        Ok(self.sibling(self.model.parse(text)?))
    }

    fn mutate(&self, settings: Settings<'_>, rng: &mut ChaCha8Rng) -> Result<Genome, InputError> {
        let settings = settings_of(&self.model, settings)?;
        Ok(self.sibling(self.model.mutate(&self.genome, &settings, rng)))
    }

    fn cross(
        &self,
        parents: &[(&Genome, f64)],
        settings: Settings<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<(Genome, Vec<usize>), Error> {
        let settings = settings_of(&self.model, settings)?;
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
        let Bred { genome, parents } = (self.model.cross(&typed, &settings, rng))
            .map_err(|e| InputError::new("parents", e))?;
        Ok((self.sibling(genome), parents))
    }
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
    pub fn new<M: Model>(model: M, genome: M::Genome) -> Genome {
        Genome(Arc::new(Typed { model, genome }))
    }

    /// The model's name in files.
    pub fn model(&self) -> &'static str {
        self.0.model()
    }

    /// The model's title.
    pub fn title(&self) -> &'static str {
        self.0.title()
    }

    /// Its model's genome field by field ([`crate::schema`]).
    pub fn schema(&self) -> crate::schema::Schema {
        self.0.schema()
    }

    /// A short text form a person can copy and paste, for a model that has one
    /// ([`sylva_model::Model::packed`]).
    pub fn packed(&self) -> Option<String> {
        self.0.packed()
    }

    /// The typed genome, if this is a genome of model `M`.
    pub fn get<M: Model>(&self) -> Option<&M::Genome> {
        let typed = self.0.as_any().downcast_ref::<Typed<M>>()?;
        Some(&typed.genome)
    }

    /// The genome file's text: pretty JSON ending with a newline.
    pub fn to_json(&self) -> String {
        self.0.write()
    }

    /// The genome as a JSON value (for the extras of exported assets).
    pub fn to_value(&self) -> serde_json::Value {
        self.0.to_value()
    }

    /// A genome of the same model from a genome file's text (a field changed by hand);
    /// errors carry the line and column.
    pub fn reparse(&self, text: &str) -> Result<Genome, GenomeError> {
        self.0.reparse(text)
    }

    /// Grows the plant with `seed`.
    pub fn develop(&self, seed: u64) -> Result<Plant, Error> {
        self.0.develop(seed).map_err(|source| Error::Develop {
            model: self.model(),
            source,
        })
    }

    /// The seed the genome grows with when none is given.
    pub fn default_seed(&self) -> u64 {
        self.0.default_seed()
    }

    /// The genome that grows with `seed` when none is given: for a model whose genomes
    /// carry their seed (PlantMaker), the same genome with that seed; others as they are.
    pub fn with_seed(&self, seed: u64) -> Genome {
        self.0.with_seed(seed)
    }

    /// How the model's plants are best meshed.
    pub fn mesh_hint(&self) -> MeshHint {
        self.0.mesh_hint()
    }

    /// How its plant is dressed when nobody says otherwise: the foliage and bark the genome
    /// names for itself, or nothing (the papers' models).
    pub fn own_dress(&self) -> Dress {
        self.0.dress()
    }

    /// Seconds growing it may take on one core, for models whose growth can take long
    /// (L-system plants); `None` for the others.
    pub fn growth_seconds(&self) -> Option<f64> {
        self.0.growth_seconds()
    }

    /// A mutated copy, made by the model's own mutation with `settings` (the model's
    /// settings as JSON, or its defaults), drawing from the stream of `seed`.
    pub fn mutate(&self, settings: Settings<'_>, seed: u64) -> Result<Genome, Error> {
        let mut rng = sylva_core::rng::seeded(seed);
        Ok(self.0.mutate(settings, &mut rng)?)
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
        first.0.cross(parents, settings, &mut rng)
    }
}

impl PartialEq for Genome {
    fn eq(&self, other: &Genome) -> bool {
        self.0.same(other)
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
