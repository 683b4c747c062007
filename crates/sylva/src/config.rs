//! The TOML configuration of `sylva evolve`, with documented defaults.
//!
//! Every section and field is optional; unknown fields are refused; every number is checked
//! against its range while it is read, so an error points at the line and column of the
//! offending value. A missing config means the built-in default run.
//!
//! ```toml
//! model = "bintree"          # the model to evolve
//!
//! [run]
//! generations = 150          # generations to breed after the random first one
//! population = 400           # individuals per generation
//! seed = 1                   # seed of every random choice
//! threads = 0                # 0: one per core; results do not depend on it
//! checkpoint_seconds = 2     # 0: checkpoint every generation
//!
//! [bintree]
//! min_radius = 0.02          # metres; no cylinder is thinner
//! mutation_rate = 0.02       # probability of flipping each bit of a child
//! crossover = "one_point"    # or "uniform"
//! cull_clones = true         # replace copies of a genome (false: the paper's step)
//!
//! [bintree.weights]          # Susinno's fitness weights
//! surface_to_volume = 0.02
//! symmetry = 1.0
//! radius_to_length = 2.0
//! volume = 1.0
//! height = 0.5
//! straightness = 1.0
//!
//! [output]
//! image_size = 800           # pixels, square, for best.png
//! view = "iso"               # front, side, top or iso
//! sheet_size = 48            # individuals on the contact sheet
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};
use sylva_fitness::SusinnoWeights;
use sylva_mesh::render::View;

use crate::error::InputError;

/// The whole config.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvolveConfig {
    /// Which model to evolve. Default `"bintree"`.
    #[serde(default)]
    pub model: ModelName,
    /// Run size and seed.
    #[serde(default)]
    pub run: RunConfig,
    /// Settings of the binary-tree model and its genetic algorithm.
    #[serde(default)]
    pub bintree: BinTreeConfig,
    /// Settings of the automata model, its GP and Poncin's fitness.
    #[serde(default)]
    pub automata: AutomataConfig,
    /// Settings of PlantMaker evolution without a person.
    #[serde(default)]
    pub plantmaker: PlantMakerConfig,
    /// Settings of L-system evolution without a person.
    #[serde(default)]
    pub lsystem: LSystemConfig,
    /// What the run writes.
    #[serde(default)]
    pub output: OutputConfig,
}

impl Default for EvolveConfig {
    fn default() -> Self {
        EvolveConfig {
            model: ModelName::BinTree,
            run: RunConfig::default(),
            bintree: BinTreeConfig::default(),
            automata: AutomataConfig::default(),
            plantmaker: PlantMakerConfig::default(),
            lsystem: LSystemConfig::default(),
            output: OutputConfig::default(),
        }
    }
}

/// Models `sylva evolve` can evolve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ModelName {
    /// Susinno's recursive binary tree.
    #[default]
    #[serde(rename = "bintree")]
    BinTree,
    /// Poncin's GP-programmed turtle automata.
    #[serde(rename = "automata")]
    Automata,
    /// PlantMaker genomes (Gal, Mahal and Sipper).
    #[serde(rename = "plantmaker")]
    PlantMaker,
    /// L-system plants grown by their physiology (Bornhofen and Lattaud).
    #[serde(rename = "lsystem")]
    LSystem,
}

impl ModelName {
    /// The model's name in files.
    pub fn name(self) -> &'static str {
        match self {
            ModelName::BinTree => "bintree",
            ModelName::Automata => "automata",
            ModelName::PlantMaker => "plantmaker",
            ModelName::LSystem => "lsystem",
        }
    }
}

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

/// How binary trees are crossed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CrossoverKind {
    /// One cut point.
    #[default]
    OnePoint,
    /// Each bit from either parent.
    Uniform,
}

/// The binary-tree model's settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BinTreeConfig {
    /// No cylinder is thinner, metres, 0.001 to 1. Default 0.02.
    #[serde(deserialize_with = "min_radius")]
    pub min_radius: f64,
    /// Probability of flipping each bit of a child, 0 to 1. Default 0.02.
    #[serde(deserialize_with = "mutation_rate")]
    pub mutation_rate: f64,
    /// Crossover of the two best trees. Default one-point.
    pub crossover: CrossoverKind,
    /// Replace copies of an earlier member's genome, so a converged population keeps
    /// searching (Sylva's addition; `false` is the paper's step). Default true.
    pub cull_clones: bool,
    /// Fitness weights.
    pub weights: SusinnoWeights,
}

impl Default for BinTreeConfig {
    fn default() -> Self {
        BinTreeConfig {
            min_radius: 0.02,
            mutation_rate: 0.02,
            crossover: CrossoverKind::OnePoint,
            cull_clones: true,
            weights: SusinnoWeights::default(),
        }
    }
}

sylva_core::ranged!(checkpoint_seconds: f64, "checkpoint_seconds", 0.0, 3600.0, " s");
sylva_core::ranged!(min_radius: f64, "min_radius", 0.001, 1.0, " m");
sylva_core::ranged!(mutation_rate: f64, "mutation_rate", 0.0, 1.0, "");

/// The automata model's GP run (Poncin): tree shape limits, breeding, growth and fitness.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AutomataConfig {
    /// Automata per individual (children of `Top`), 1 to 8. Default 2.
    #[serde(deserialize_with = "automata_count")]
    pub automata: u32,
    /// Smallest depth of initial bodies (ramped half-and-half), 1 to 16. Default 4.
    #[serde(deserialize_with = "init_depth")]
    pub init_min_depth: u32,
    /// Largest depth of initial bodies, 1 to 16. Default 8.
    #[serde(deserialize_with = "init_depth")]
    pub init_max_depth: u32,
    /// Deepest tree breeding may make, 2 to 64. Default 17.
    #[serde(deserialize_with = "max_depth")]
    pub max_depth: u32,
    /// Most nodes of a tree, 20 to 5000. Default 500 (the paper's largest individuals).
    #[serde(deserialize_with = "max_size")]
    pub max_size: u32,
    /// Tournament selection and the 88 / 10 / 2 operator rates.
    pub breeding: sylva_evolve::GenerationalSettings,
    /// How programs grow.
    pub growth: sylva_automata::Growth,
    /// Poncin's fitness: target shape, counts, spread, thickness and density grid.
    pub fitness: sylva_fitness::PoncinFitness,
}

impl Default for AutomataConfig {
    fn default() -> Self {
        AutomataConfig {
            automata: 2,
            init_min_depth: 4,
            init_max_depth: 8,
            max_depth: 17,
            max_size: 500,
            breeding: sylva_evolve::GenerationalSettings::default(),
            growth: sylva_automata::Growth::default(),
            fitness: sylva_fitness::PoncinFitness::default(),
        }
    }
}

sylva_core::ranged!(automata_count: u32, "automata", 1, 8);
sylva_core::ranged!(init_depth: u32, "init depth", 1, 16);
sylva_core::ranged!(max_depth: u32, "max_depth", 2, 64);
sylva_core::ranged!(max_size: u32, "max_size", 20, 5000);
/// PlantMaker evolution without a person: genome sizes, breeding and a fitness from the
/// shared terms (by default: endpoints on a 1 m sphere centred 1.2 m up, about 30 branch
/// endpoints, spread; lengths in metres, so `fitness.unit` is 1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlantMakerConfig {
    /// Branch prototypes per genome, 1 to 32. Default 5.
    #[serde(deserialize_with = "segment_count")]
    pub branches: u32,
    /// Fans per genome, 1 to 32. Default 5.
    #[serde(deserialize_with = "segment_count")]
    pub fans: u32,
    /// Inflorescences per genome, 1 to 32. Default 5.
    #[serde(deserialize_with = "segment_count")]
    pub inflorescences: u32,
    /// Crossover level: low, medium or high. Default medium.
    pub crossover: sylva_plantmaker::Level,
    /// Probability that a variable changes in a mutation, 0 to 1. Default 0.1.
    #[serde(deserialize_with = "mutation_rate")]
    pub mutation_rate: f64,
    /// Mutation noise as a fraction of a variable's range, 0 to 1. Default 0.15.
    #[serde(deserialize_with = "mutation_spread")]
    pub mutation_spread: f64,
    /// Genome files the first generation starts from, relative to the config file (the
    /// paper's users start from plants they chose); the rest of it is their mutants. Empty
    /// (the default): a random first generation.
    pub start: Vec<std::path::PathBuf>,
    /// Tournament selection and operator rates.
    pub breeding: sylva_evolve::GenerationalSettings,
    /// The fitness (Poncin's terms over the grown plant).
    pub fitness: sylva_fitness::PoncinFitness,
}

sylva_core::ranged!(segment_count: u32, "segment count", 1, 32);
sylva_core::ranged!(mutation_spread: f64, "mutation_spread", 0.0, 1.0, "");

impl Default for PlantMakerConfig {
    fn default() -> Self {
        let mut fitness = sylva_fitness::PoncinFitness {
            unit: 1.0,
            ..Default::default()
        };
        fitness.target = sylva_fitness::poncin::TargetShape::Sphere {
            center: sylva_core::glam::DVec3::new(0.0, 1.2, 0.0),
            radius: 1.0,
        };
        PlantMakerConfig {
            branches: 5,
            fans: 5,
            inflorescences: 5,
            crossover: sylva_plantmaker::Level::Medium,
            mutation_rate: 0.1,
            mutation_spread: 0.15,
            start: Vec::new(),
            breeding: sylva_evolve::GenerationalSettings::default(),
            fitness,
        }
    }
}

/// L-system evolution without a person: every genome grows alone in the voxel world and is
/// scored by its biomass or the light it captured. The paper breeds by mutation alone, so
/// the default breeding has no crossover.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LSystemConfig {
    /// Genome the first generation grows out of, relative to the config file. Default:
    /// empty rules (the paper's start, which does not germinate).
    pub start: Option<std::path::PathBuf>,
    /// What to select for: `"biomass"` or `"light"`. Default biomass.
    pub score: sylva_lsystem::breed::Score,
    /// Rounds of mutation that make a first-generation genome from the start, 0 to 1000.
    /// Default 10.
    #[serde(deserialize_with = "random_rounds")]
    pub random_rounds: u32,
    /// Mutation probabilities (section 3.3).
    pub rates: sylva_lsystem::mutate::MutationRates,
    /// World and time each genome grows in.
    pub grow: sylva_lsystem::garden::GrowSettings,
    /// Tournament selection and operator rates. Default: no crossover, 20% reproduction,
    /// 80% mutation, elitism 1.
    pub breeding: sylva_evolve::GenerationalSettings,
}

sylva_core::ranged!(random_rounds: u32, "random_rounds", 0, 1000);

impl Default for LSystemConfig {
    fn default() -> Self {
        LSystemConfig {
            start: None,
            score: sylva_lsystem::breed::Score::Biomass,
            random_rounds: 10,
            rates: sylva_lsystem::mutate::MutationRates::default(),
            grow: sylva_lsystem::garden::GrowSettings::default(),
            breeding: sylva_evolve::GenerationalSettings {
                crossover: 0.0,
                reproduction: 0.2,
                mutation: 0.8,
                ..Default::default()
            },
        }
    }
}

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
}

impl Default for OutputConfig {
    fn default() -> Self {
        OutputConfig {
            image_size: 800,
            view: View::Iso,
            sheet_size: 48,
        }
    }
}

sylva_core::ranged!(image_size: u32, "image_size", 64, 4096);
sylva_core::ranged!(sheet_size: u32, "sheet_size", 1, 400);

mod view_name {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};
    use sylva_mesh::render::View;

    pub fn serialize<S: Serializer>(v: &View, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(v)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<View, D::Error> {
        String::deserialize(d)?.parse().map_err(D::Error::custom)
    }
}

impl EvolveConfig {
    /// Parses a config file's text; errors point into `text`.
    pub fn parse(path: &Path, text: &str) -> Result<EvolveConfig, InputError> {
        toml::from_str(text).map_err(|e| {
            let message = e.message().to_owned();
            match e.span() {
                Some(span) => InputError::spanned(path, text, span, message),
                None => InputError::new(path.display().to_string(), message),
            }
        })
    }

    /// Reads and parses a config file.
    pub fn load(path: &Path) -> Result<EvolveConfig, InputError> {
        let text = read_text(path)?;
        Self::parse(path, &text)
    }

    /// The config as TOML (what a run records next to its results).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("configs hold only finite numbers and strings")
    }
}

/// Reads a UTF-8 text file, refusing files over 64 MiB.
pub fn read_text(path: &Path) -> Result<String, InputError> {
    const LIMIT: u64 = 64 << 20;
    let shown = path.display().to_string();
    let meta = std::fs::metadata(path)
        .map_err(|e| InputError::new(&shown, format!("cannot read: {e}")))?;
    if meta.len() > LIMIT {
        return Err(InputError::new(
            &shown,
            format!("file is {} bytes; at most {LIMIT} are read", meta.len()),
        ));
    }
    let bytes =
        std::fs::read(path).map_err(|e| InputError::new(&shown, format!("cannot read: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        InputError::new(
            &shown,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<EvolveConfig, InputError> {
        EvolveConfig::parse(Path::new("c.toml"), text)
    }

    #[test]
    fn empty_is_default() {
        assert_eq!(parse("").unwrap(), EvolveConfig::default());
    }

    #[test]
    fn the_written_out_default_is_the_default() {
        let text = include_str!("../../../examples/bintree/default.toml");
        assert_eq!(parse(text).unwrap(), EvolveConfig::default());
        let paper = parse(include_str!("../../../examples/bintree/paper.toml")).unwrap();
        assert_eq!(paper.bintree.weights.pipe_model, 0.0);
        assert!(!paper.bintree.cull_clones);
    }

    #[test]
    fn default_round_trips() {
        let text = EvolveConfig::default().to_toml();
        assert_eq!(parse(&text).unwrap(), EvolveConfig::default());
    }

    #[test]
    fn errors_point_at_the_value() {
        let cases = [
            ("[run]\npopulation = -5\n", "c.toml:2:14", "population"),
            ("[run]\npopulation = 0\n", "c.toml:2:14", "1 to 1000000"),
            ("[bintree.weights]\nheight = nan\n", "c.toml:2:10", "weight"),
            ("[bintree.weights]\nheight = inf\n", "c.toml:2:10", "weight"),
            ("[bintree]\nmin_radius = 1e9\n", "c.toml:2:14", "min_radius"),
            (
                "[run]\npopulaton = 5\n",
                "c.toml:2:1",
                "unknown field `populaton`",
            ),
            ("model = \"oak\"\n", "c.toml:1:9", "unknown variant"),
            ("[output]\nview = \"back\"\n", "c.toml:2:8", "front"),
            ("[run\n", "c.toml:1:", ""),
            ("[run]\nseed = 18446744073709551616\n", "c.toml:2:8", ""),
        ];
        for (text, location, mention) in cases {
            let e = parse(text).unwrap_err();
            assert!(
                e.location.starts_with(location),
                "{text:?}: {} (expected {location})",
                e.location
            );
            assert!(e.message.contains(mention), "{text:?}: {}", e.message);
        }
    }
}
