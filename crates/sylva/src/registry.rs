//! The one list of models: [`Registry::standard`] holds the five, one line each. Genome
//! files and evolution configs name their model; the registry reads the name and hands the
//! rest to that model.
//!
//! Adding a model is its crate (a type that implements [`Model`](sylva_model::Model) and
//! [`Evolve`]) and one line in [`Registry::standard`]. A front end can also build a registry
//! of its own ([`Registry::with`]), as the test that adds a toy model does.
//!
//! A model's line also says which workflows of its own it offers besides growing and
//! evolving, each a trait of `sylva_model` the model implements ([`EntryOf::with_biomorphs`],
//! [`EntryOf::with_gardens`], [`EntryOf::with_experiments`]); the library's module for that
//! workflow ([`crate::biomorph`], [`crate::garden`], [`crate::experiment`]) finds the models
//! offering it here, never by name.

use std::any::Any;
use std::marker::PhantomData;
use std::path::Path;
use std::sync::Arc;

use serde::Deserialize;
use sylva_automata::AutomataModel;
use sylva_bintree::BinTreeModel;
use sylva_grown::GrownModel;
use sylva_lsystem::LSystemModel;
use sylva_model::{Evolve, GenomeError, Model};

use crate::schema::Schema;
use sylva_plantmaker::PlantMakerModel;

use crate::error::{FieldError, InputError};
use crate::evolution::{Config, EvolveConfig, MatchConfig, RunConfig};
use crate::genome::{Genome, Settings, expect_model, settings_of};

/// A model the library knows: its name and title, how to read its genome files, configs
/// and checkpoints, make random genomes and run its evolution; and the workflows of its own
/// it offers, each found by the module that runs it.
#[derive(Clone)]
pub struct ModelEntry {
    model: Arc<dyn ModelFace>,
    /// The workflows it offers, each as its module's face, one of each type.
    offers: Vec<Arc<dyn Any + Send + Sync>>,
}

/// A model's registry line as it is written: [`ModelEntry::of`] the model, then what it
/// offers besides growing and evolving (each `with_` needs the model to implement that
/// workflow's trait). A [`Registry`] takes it as a [`ModelEntry`].
pub struct EntryOf<M> {
    entry: ModelEntry,
    model: PhantomData<M>,
}

impl<M> EntryOf<M> {
    /// Adds what the model offers of one workflow: `face`, the workflow module's erased
    /// trait over the model, found again by its type ([`ModelEntry::offer`]). Each workflow
    /// module adds its own `with_` method to `EntryOf`, so the registry names none.
    pub(crate) fn offering<F: Any + Send + Sync>(mut self, face: F) -> Self {
        self.entry.offers.push(Arc::new(face));
        self
    }
}

impl<M> From<EntryOf<M>> for ModelEntry {
    fn from(line: EntryOf<M>) -> ModelEntry {
        line.entry
    }
}

/// How many genomes [`ModelEntry::random`] draws, at most, to find one that grows.
const RANDOM_DRAWS: u32 = 100;

/// What the registry does with a model: read its files and make its first values.
trait ModelFace: Send + Sync {
    fn name(&self) -> &'static str;
    fn title(&self) -> &'static str;
    fn schema(&self) -> Schema;
    fn parse_genome(&self, text: &str) -> Result<Genome, GenomeError>;
    fn random(&self, settings: Settings<'_>, seed: u64) -> Result<Genome, InputError>;
    fn parse_config(&self, path: &Path, text: &str) -> Result<Config, InputError>;
    fn config_from_value(&self, value: serde_json::Value) -> Result<Config, FieldError>;
    fn default_config(&self) -> Config;
    fn match_config(&self, run: &RunConfig, outline: &MatchConfig) -> Result<Config, FieldError>;
}

impl<M: Evolve + Default> ModelFace for M {
    fn name(&self) -> &'static str {
        M::NAME
    }

    fn title(&self) -> &'static str {
        M::TITLE
    }

    fn schema(&self) -> Schema {
        Model::schema(self)
    }

    fn parse_genome(&self, text: &str) -> Result<Genome, GenomeError> {
        Ok(Genome::new(self.clone(), self.parse(text)?))
    }

    fn random(&self, settings: Settings<'_>, seed: u64) -> Result<Genome, InputError> {
        let settings = settings_of(self, settings)?;
        let mut rng = sylva_core::rng::seeded(seed);
        // Some models' random genomes often grow nothing (the L-system's paper starts from
        // a genome that does not germinate): draw on from the same stream until one grows.
        for _ in 0..RANDOM_DRAWS {
            let genome = Model::random(self, &settings, &mut rng);
            let seed = Model::default_seed(self, &genome);
            let grows = Model::develop(self, &genome, seed).is_ok_and(|p| !p.segments().is_empty());
            if grows {
                return Ok(Genome::new(self.clone(), genome));
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

    fn parse_config(&self, path: &Path, text: &str) -> Result<Config, InputError> {
        Ok(Config::new(EvolveConfig::<M>::parse(path, text)?))
    }

    fn config_from_value(&self, value: serde_json::Value) -> Result<Config, FieldError> {
        let sent = value.clone();
        match serde_path_to_error::deserialize::<_, EvolveConfig<M>>(value) {
            Ok(config) => Ok(Config::new(config)),
            Err(e) => Err(FieldError::of(&e, &sent)),
        }
    }

    fn default_config(&self) -> Config {
        Config::new(EvolveConfig::<M>::default())
    }

    fn match_config(&self, run: &RunConfig, outline: &MatchConfig) -> Result<Config, FieldError> {
        let mut settings = EvolveConfig::<M>::default().settings;
        self.fitting(&mut settings);
        let field = |name: &'static str| move |e: serde_json::Error| FieldError::new(name, e);
        // Built as values, so the run and outline a front end gave meet a config file's
        // checks, with errors naming the field.
        self.config_from_value(serde_json::json!({
            "model": M::NAME,
            "run": serde_json::to_value(run).map_err(field("run"))?,
            "match": serde_json::to_value(outline).map_err(field("match"))?,
            M::NAME: serde_json::to_value(settings).map_err(field(M::NAME))?,
        }))
    }
}

impl ModelEntry {
    /// Model `M`, with its default settings: a registry line, to which the workflows it
    /// offers are added ([`EntryOf`]).
    pub fn of<M: Evolve + Default>() -> EntryOf<M> {
        EntryOf {
            entry: ModelEntry {
                model: Arc::new(M::default()),
                offers: Vec::new(),
            },
            model: PhantomData,
        }
    }

    /// What the model offers of a workflow, by the type of that workflow's face
    /// ([`EntryOf::offering`]); none when it does not offer it.
    pub(crate) fn offer<F: Any>(&self) -> Option<&F> {
        self.offers.iter().find_map(|face| face.downcast_ref::<F>())
    }

    /// The model's name in files.
    pub fn name(&self) -> &'static str {
        self.model.name()
    }

    /// The model's title.
    pub fn title(&self) -> &'static str {
        self.model.title()
    }

    /// Its genome field by field: each value's kind, range, unit and meaning, for panels,
    /// Python and the docs ([`schema`](crate::schema)).
    pub fn schema(&self) -> Schema {
        self.model.schema()
    }

    /// A random genome that grows: made by the model with `settings` (its settings as JSON,
    /// or its defaults) from the stream of `seed`, which draws on until a genome grows at
    /// least one segment with its default seed. After 100 draws that grow nothing (settings
    /// under which nothing can grow) it is an error.
    pub fn random(&self, settings: Settings<'_>, seed: u64) -> Result<Genome, InputError> {
        self.model.random(settings, seed)
    }

    /// The model's default config.
    pub fn default_config(&self) -> Config {
        self.model.default_config()
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
    /// Self-organising trees.
    pub const GROWN: &str = sylva_grown::GrownModel::NAME;
}

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
    /// The five models of Sylva: the binary tree (first: the default run's), automata,
    /// PlantMaker (which grows gardens), L-systems (biomorph gardens and experiments) and
    /// self-organising trees. There is no global registry: whoever starts (the command
    /// line's `main`, the studio's server, the Python module's init, a test) builds this once
    /// and passes it to what reads genomes and configs.
    pub fn standard() -> Registry {
        Registry::new()
            .with(ModelEntry::of::<BinTreeModel>())
            .with(ModelEntry::of::<AutomataModel>())
            .with(ModelEntry::of::<PlantMakerModel>().with_gardens())
            .with(
                ModelEntry::of::<LSystemModel>()
                    .with_biomorphs()
                    .with_experiments(),
            )
            .with(ModelEntry::of::<GrownModel>())
    }

    /// An empty registry.
    pub fn new() -> Registry {
        Registry { models: Vec::new() }
    }

    /// This registry and one more model (a model of the same name is replaced).
    pub fn with(mut self, entry: impl Into<ModelEntry>) -> Registry {
        let entry = entry.into();
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
        self.parse_genome_at(path, &text)
    }

    /// Parses a genome file already read from `path`; errors name the file, line and column.
    pub fn parse_genome_at(&self, path: &Path, text: &str) -> Result<Genome, InputError> {
        self.parse_genome(text)
            .map_err(|e| InputError::genome(path, text, e))
    }

    /// Reads a genome file that must be of model `M`; `purpose` says what it is for in the
    /// error (like "gardens grow").
    pub fn load_genome_of<M: Model>(
        &self,
        path: &Path,
        purpose: &str,
    ) -> Result<M::Genome, InputError> {
        let genome = self.load_genome(path)?;
        expect_model::<M>(path, &genome, purpose)
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
            Some(entry) => entry.model.parse_genome(text),
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
        Ok(config.read_from(path))
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
        entry.model.config_from_value(value)
    }

    /// The config of a run that evolves `model`'s plants towards `outline` alone: the
    /// model's defaults as it fits an outline (`Evolve::fitting`), and `run`.
    pub fn match_config(
        &self,
        model: &str,
        run: &RunConfig,
        outline: &MatchConfig,
    ) -> Result<Config, FieldError> {
        let entry = self.get(model).ok_or_else(|| {
            FieldError::new(
                "model",
                format!("unknown model `{model}`; expected one of: {}", self.names()),
            )
        })?;
        entry.model.match_config(run, outline)
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
