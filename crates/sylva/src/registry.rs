//! The one list of models: [`Registry::standard`] holds the four, one line each. Genome
//! files and evolution configs name their model; the registry reads the name and hands the
//! rest to that model.
//!
//! Adding a model is its crate (a type that implements [`Model`], and [`Evolve`] if it
//! evolves) and one line in [`Registry::standard`]. A front end can also build a registry
//! of its own ([`Registry::with`]), as the test that adds a toy model does.

use std::path::Path;
use std::sync::LazyLock;

use serde::Deserialize;
use sylva_automata::AutomataModel;
use sylva_bintree::BinTreeModel;
use sylva_lsystem::LSystemModel;
use sylva_model::{Evolve, GenomeError, Model};
use sylva_plantmaker::PlantMakerModel;

use crate::error::{FieldError, InputError};
use crate::evolution::{Config, EvolveConfig};
use crate::genome::{Genome, Settings};

/// A model the library knows: its name and title, how to read its genome files and make
/// random genomes, and, if it evolves, how to read its configs.
#[derive(Clone, Copy)]
pub struct ModelEntry {
    name: &'static str,
    title: &'static str,
    parse: fn(&str) -> Result<Genome, GenomeError>,
    random: fn(Settings<'_>, u64) -> Result<Genome, InputError>,
    evolve: Option<EvolveEntry>,
}

/// What an entry of a model that evolves adds.
#[derive(Clone, Copy)]
struct EvolveEntry {
    parse_config: fn(&Path, &str) -> Result<Config, InputError>,
    config_from_value: fn(serde_json::Value) -> Result<Config, FieldError>,
    default_config: fn() -> Config,
}

impl ModelEntry {
    /// A model that grows and is varied by hand.
    pub fn model<M: Model + Default>() -> ModelEntry {
        ModelEntry {
            name: M::NAME,
            title: M::TITLE,
            parse: parse::<M>,
            random: random::<M>,
            evolve: None,
        }
    }

    /// A model that also evolves without a person.
    pub fn evolvable<M: Evolve + Default>() -> ModelEntry {
        ModelEntry {
            evolve: Some(EvolveEntry {
                parse_config: parse_config::<M>,
                config_from_value: config_from_value::<M>,
                default_config: || Config::new(EvolveConfig::<M>::default()),
            }),
            ..ModelEntry::model::<M>()
        }
    }

    /// The model's name in files.
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The model's title.
    pub fn title(&self) -> &'static str {
        self.title
    }

    /// Whether the model evolves without a person.
    pub fn evolves(&self) -> bool {
        self.evolve.is_some()
    }

    /// A random genome, made by the model with `settings` (its settings as JSON, or its
    /// defaults) from the stream of `seed`.
    pub fn random(&self, settings: Settings<'_>, seed: u64) -> Result<Genome, InputError> {
        (self.random)(settings, seed)
    }
}

fn parse<M: Model + Default>(text: &str) -> Result<Genome, GenomeError> {
    let model = M::default();
    let genome = model.parse(text)?;
    Ok(Genome::new(model, genome))
}

fn random<M: Model + Default>(settings: Settings<'_>, seed: u64) -> Result<Genome, InputError> {
    let model = M::default();
    let settings = crate::genome::settings_of(&model, settings)?;
    let genome = model.random(&settings, &mut sylva_core::rng::seeded(seed));
    Ok(Genome::new(model, genome))
}

fn parse_config<M: Evolve + Default>(path: &Path, text: &str) -> Result<Config, InputError> {
    EvolveConfig::<M>::parse(path, text).map(Config::new)
}

fn config_from_value<M: Evolve + Default>(value: serde_json::Value) -> Result<Config, FieldError> {
    let sent = value.clone();
    serde_path_to_error::deserialize::<_, EvolveConfig<M>>(value)
        .map(Config::new)
        .map_err(|e| FieldError::of(&e, &sent))
}

impl std::fmt::Debug for Registry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list()
            .entries(self.models.iter().map(|m| m.name))
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
        .with(ModelEntry::evolvable::<BinTreeModel>())
        .with(ModelEntry::evolvable::<AutomataModel>())
        .with(ModelEntry::evolvable::<PlantMakerModel>())
        .with(ModelEntry::evolvable::<LSystemModel>())
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
                    model = Some(entry.name);
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
        self.models.retain(|m| m.name != entry.name);
        self.models.push(entry);
        self
    }

    /// Every model, in order.
    pub fn models(&self) -> &[ModelEntry] {
        &self.models
    }

    /// A model by name.
    pub fn get(&self, name: &str) -> Option<&ModelEntry> {
        self.models.iter().find(|m| m.name == name)
    }

    fn names(&self) -> String {
        let names: Vec<&str> = self.models.iter().map(|m| m.name).collect();
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
            Some(entry) => (entry.parse)(text),
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

    /// Parses an evolution config of any model that evolves; `model` defaults to the first
    /// model. Errors point into `text`.
    pub fn parse_config(&self, path: &Path, text: &str) -> Result<Config, InputError> {
        #[derive(Deserialize)]
        struct ConfigHeader {
            model: Option<toml::Spanned<String>>,
        }
        let header: ConfigHeader =
            toml::from_str(text).map_err(|e| InputError::toml(path, text, &e))?;
        let (entry, span) = match &header.model {
            Some(name) => (self.get(name.get_ref()), Some(name.span())),
            None => (self.models.first(), None),
        };
        let evolvable: Vec<&str> = self
            .models
            .iter()
            .filter(|m| m.evolves())
            .map(|m| m.name)
            .collect();
        let refuse = |message: String| match span.clone() {
            Some(span) => InputError::spanned(path, text, span, message),
            None => InputError::file(path, message),
        };
        let name = header.model.as_ref().map(|n| n.get_ref().as_str());
        match entry.and_then(|e| e.evolve) {
            Some(evolve) => {
                (evolve.parse_config)(path, text).map(|c| c.read_with(Some(path), self))
            }
            None if entry.is_some() => Err(refuse(format!(
                "model `{}` does not evolve without a person; models that do: {}",
                name.unwrap_or_default(),
                evolvable.join(", ")
            ))),
            None => Err(refuse(format!(
                "unknown model `{}`; expected one of: {}",
                name.unwrap_or_default(),
                evolvable.join(", ")
            ))),
        }
    }

    /// A config of any model that evolves, built as values rather than read from a file
    /// (a front end's form): the same fields and checks as a config file's, as JSON
    /// (`{"model": "automata", "run": {...}, "automata": {...}}`; `model` defaults to the
    /// first model). An error names the field by its path in `value`
    /// (`automata.fitness.target.radius`).
    pub fn config_from_value(&self, value: serde_json::Value) -> Result<Config, FieldError> {
        let name = match value.get("model") {
            None => self.models.first().map(|m| m.name),
            Some(serde_json::Value::String(name)) => Some(name.as_str()),
            Some(other) => {
                return Err(FieldError::new(
                    "model",
                    format!("expected a model's name, got {other}"),
                ));
            }
        };
        let entry = name.and_then(|n| self.get(n));
        match entry.and_then(|e| e.evolve) {
            Some(evolve) => (evolve.config_from_value)(value).map(|c| c.read_with(None, self)),
            None => {
                let evolvable: Vec<&str> = self
                    .models
                    .iter()
                    .filter(|m| m.evolves())
                    .map(|m| m.name)
                    .collect();
                Err(FieldError::new(
                    "model",
                    format!(
                        "`{}` is not a model that evolves; expected one of: {}",
                        name.unwrap_or_default(),
                        evolvable.join(", ")
                    ),
                ))
            }
        }
    }

    /// The default config of the first model that evolves (none if no model does).
    pub fn default_config(&self) -> Option<Config> {
        self.models
            .iter()
            .find_map(|m| m.evolve)
            .map(|e| (e.default_config)())
    }
}
