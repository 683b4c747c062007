//! The one list of models: [`Registry::standard`] holds the four, one line each. Genome
//! files and evolution configs name their model; the registry reads the name and hands the
//! rest to that model.
//!
//! Adding a model is its crate (a type that implements [`Model`](sylva_model::Model) and
//! [`Evolve`]) and one line in [`Registry::standard`]. A front end can also build a registry
//! of its own ([`Registry::with`]), as the test that adds a toy model does.

use std::path::Path;
use std::sync::{Arc, LazyLock};

use serde::Deserialize;
use sylva_automata::AutomataModel;
use sylva_bintree::BinTreeModel;
use sylva_lsystem::LSystemModel;
use sylva_model::{Evolve, GenomeError};
use sylva_plantmaker::PlantMakerModel;

use crate::erased::DynModel;
use crate::error::{FieldError, InputError};
use crate::evolution::Config;
use crate::genome::{Genome, Settings};

/// A model the library knows: its name and title, how to read its genome files, configs
/// and checkpoints, make random genomes and run its evolution.
#[derive(Clone)]
pub struct ModelEntry {
    model: Arc<dyn DynModel>,
}

impl ModelEntry {
    /// Model `M`, with its default settings.
    pub fn of<M: Evolve + Default>() -> ModelEntry {
        ModelEntry {
            model: Arc::new(M::default()),
        }
    }

    /// The model's name in files.
    pub fn name(&self) -> &'static str {
        self.model.name()
    }

    /// The model's title.
    pub fn title(&self) -> &'static str {
        self.model.title()
    }

    /// A random genome that grows: made by the model with `settings` (its settings as JSON,
    /// or its defaults) from the stream of `seed`, which draws on until a genome grows at
    /// least one segment with its default seed. After 100 draws that grow nothing (settings
    /// under which nothing can grow) it is an error.
    pub fn random(&self, settings: Settings<'_>, seed: u64) -> Result<Genome, InputError> {
        let genome = self.model.random(settings, seed)?;
        Ok(Genome::erased(self.model.clone(), genome))
    }

    /// The model's default config.
    pub fn default_config(&self) -> Config {
        Config::erased(self.model.clone(), self.model.default_config())
    }

    fn parse_genome(&self, text: &str) -> Result<Genome, GenomeError> {
        let genome = self.model.parse_genome(text)?;
        Ok(Genome::erased(self.model.clone(), genome))
    }
}

impl std::fmt::Debug for Registry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list()
            .entries(self.models.iter().map(|m| m.name()))
            .finish()
    }
}

/// The models Sylva knows, in the order they are listed.
#[derive(Clone)]
pub struct Registry {
    models: Vec<ModelEntry>,
}

/// The standard models' names in files, for front ends whose modes follow one paper's
/// model (the studio's design mode is Poncin's, its family mode Susinno's).
pub mod names {
    use sylva_model::Model;

    /// Susinno's recursive binary tree.
    pub const BINTREE: &str = sylva_bintree::BinTreeModel::NAME;
    /// Poncin's GP trees compiled into turtle automata.
    pub const AUTOMATA: &str = sylva_automata::AutomataModel::NAME;
    /// Gal, Mahal and Sipper's PlantMaker.
    pub const PLANTMAKER: &str = sylva_plantmaker::PlantMakerModel::NAME;
    /// Bornhofen and Lattaud's L-system plants.
    pub const LSYSTEM: &str = sylva_lsystem::LSystemModel::NAME;
}

static STANDARD: LazyLock<Registry> = LazyLock::new(|| {
    Registry::new()
        .with(ModelEntry::of::<BinTreeModel>())
        .with(ModelEntry::of::<AutomataModel>())
        .with(ModelEntry::of::<PlantMakerModel>())
        .with(ModelEntry::of::<LSystemModel>())
});

/// Reads the header of a genome file (`model` and `format`; every other field is the
/// model's), refusing an unknown model or format where it stands.
struct HeaderSeed<'r>(&'r Registry);

impl<'de> serde::de::DeserializeSeed<'de> for HeaderSeed<'_> {
    type Value = Option<&'static str>;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de> serde::de::Visitor<'de> for HeaderSeed<'_> {
    type Value = Option<&'static str>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a genome: an object with `model` and `format` fields")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        use serde::de::Error;
        let mut model = None;
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "model" => {
                    let name = map.next_value::<String>()?;
                    let entry = self.0.get(&name).ok_or_else(|| {
                        A::Error::custom(format!(
                            "unknown model `{name}`; expected one of: {}",
                            self.0.names()
                        ))
                    })?;
                    model = Some(entry.name());
                }
                "format" => {
                    map.next_value::<sylva_model::FormatV1>()?;
                }
                _ => {
                    map.next_value::<serde::de::IgnoredAny>()?;
                }
            }
        }
        Ok(model)
    }
}

impl Default for Registry {
    fn default() -> Self {
        Registry::new()
    }
}

impl Registry {
    /// The four models of Sylva: the binary tree (first: the default run's), automata,
    /// PlantMaker and L-systems.
    pub fn standard() -> &'static Registry {
        &STANDARD
    }

    /// An empty registry.
    pub fn new() -> Registry {
        Registry { models: Vec::new() }
    }

    /// This registry and one more model (a model of the same name is replaced).
    pub fn with(mut self, entry: ModelEntry) -> Registry {
        self.models.retain(|m| m.name() != entry.name());
        self.models.push(entry);
        self
    }

    /// Every model, in order.
    pub fn models(&self) -> &[ModelEntry] {
        &self.models
    }

    /// A model by name.
    pub fn get(&self, name: &str) -> Option<&ModelEntry> {
        self.models.iter().find(|m| m.name() == name)
    }

    fn names(&self) -> String {
        let names: Vec<&str> = self.models.iter().map(|m| m.name()).collect();
        names.join(", ")
    }

    /// Reads a genome file of any model this registry knows; errors name the file, line and
    /// column.
    pub fn load_genome(&self, path: &Path) -> Result<Genome, InputError> {
        let text = crate::files::read_text(path)?;
        self.parse_genome(&text)
            .map_err(|e| InputError::genome(path, &text, e))
    }

    /// Reads an evolution config file of any model this registry knows that evolves.
    pub fn load_config(&self, path: &Path) -> Result<Config, InputError> {
        let text = crate::files::read_text(path)?;
        self.parse_config(path, &text)
    }

    /// Parses a genome file: the header (`model`, `format`) first, then the model's fields.
    /// Errors carry the line and column.
    pub fn parse_genome(&self, text: &str) -> Result<Genome, GenomeError> {
        use serde::de::DeserializeSeed;
        let mut de = serde_json::Deserializer::from_str(text);
        let name = HeaderSeed(self).deserialize(&mut de)?;
        de.end()?;
        match name.and_then(|n| self.get(n)) {
            Some(entry) => entry.parse_genome(text),
            None => Err(GenomeError {
                message: format!(
                    "missing field `model`: a genome file names its model, one of: {}",
                    self.names()
                ),
                line: 1,
                column: 1,
            }),
        }
    }

    /// Parses an evolution config of any model; `model` defaults to the first model.
    /// Errors point into `text`.
    pub fn parse_config(&self, path: &Path, text: &str) -> Result<Config, InputError> {
        #[derive(Deserialize)]
        struct ConfigHeader {
            model: Option<toml::Spanned<String>>,
        }
        let header: ConfigHeader =
            toml::from_str(text).map_err(|e| InputError::toml(path, text, &e))?;
        let entry = match &header.model {
            Some(name) => self.get(name.get_ref()).ok_or_else(|| {
                InputError::spanned(
                    path,
                    text,
                    name.span(),
                    format!(
                        "unknown model `{}`; expected one of: {}",
                        name.get_ref(),
                        self.names()
                    ),
                )
            })?,
            None => self.first().map_err(|e| InputError::file(path, e))?,
        };
        let config = entry.model.parse_config(path, text)?;
        Ok(Config::erased(entry.model.clone(), config).read_with(Some(path), self))
    }

    /// A config of any model, built as values rather than read from a file (a front end's
    /// form): the same fields and checks as a config file's, as JSON
    /// (`{"model": "automata", "run": {...}, "automata": {...}}`; `model` defaults to the
    /// first model). An error names the field by its path in `value`
    /// (`automata.fitness.target.radius`).
    pub fn config_from_value(&self, value: serde_json::Value) -> Result<Config, FieldError> {
        let entry = match value.get("model") {
            None => self.first().map_err(|e| FieldError::new("model", e))?,
            Some(serde_json::Value::String(name)) => self.get(name).ok_or_else(|| {
                FieldError::new(
                    "model",
                    format!("unknown model `{name}`; expected one of: {}", self.names()),
                )
            })?,
            Some(other) => {
                return Err(FieldError::new(
                    "model",
                    format!("expected a model's name, got {other}"),
                ));
            }
        };
        let config = entry.model.config_from_value(value)?;
        Ok(Config::erased(entry.model.clone(), config).read_with(None, self))
    }

    /// The default config of the first model (none if the registry is empty).
    pub fn default_config(&self) -> Option<Config> {
        self.models.first().map(ModelEntry::default_config)
    }

    /// The first model, the default of configs that name none.
    fn first(&self) -> Result<&ModelEntry, String> {
        self.models
            .first()
            .ok_or_else(|| "this registry has no models".to_owned())
    }
}
