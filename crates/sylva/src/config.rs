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

fn generations<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    sylva_core::ranged::integer(d, "generations", 0, 1_000_000)
}
fn population<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    sylva_core::ranged::integer(d, "population", 1, 1_000_000)
}
fn threads<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    sylva_core::ranged::integer(d, "threads", 0, 1024)
}

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

sylva_core::ranged_number!(checkpoint_seconds, "checkpoint_seconds", 0.0, 3600.0, " s");
sylva_core::ranged_number!(min_radius, "min_radius", 0.001, 1.0, " m");
sylva_core::ranged_number!(mutation_rate, "mutation_rate", 0.0, 1.0, "");

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

fn image_size<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    sylva_core::ranged::integer(d, "image_size", 64, 4096)
}
fn sheet_size<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    sylva_core::ranged::integer(d, "sheet_size", 1, 400)
}

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
