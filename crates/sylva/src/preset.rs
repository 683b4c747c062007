//! Species presets: a genome and how to grow it into a tree of a species, in one small file.
//!
//! A preset is TOML beside its genome (`examples/species/oak.toml`):
//!
//! ```toml
//! # English oak (Quercus robur), about 17 m, in leaf.
//! genome = "oak.genome.json"   # the genome file, relative to this one (required)
//! seed = 0                     # the seed it grows with [default: the genome's own]
//! roots = false                # keep the roots [default: true]
//! height = 17.0                # metres, 0.01 to 1000 [default: the model's own scale]
//! foliage = "oak"              # leaves or needles of a kind [default: the plant's own]
//! bark = "furrowed"            # a tiling bark [default: the foliage kind's own]
//! density = 1.5                # cards per metre of twig, 0.25 to 4 [default: 1]
//! taper = 2.5                  # the pipe model's exponent, 2 to 3 [default: 2.5 dressed]
//! ```
//!
//! [`Preset::load`] reads it (unknown fields refused, every value range-checked, errors with
//! the file, line and column) into a [`Genome`] and the [`GrowOptions`] that grow it; every
//! front end grows a preset as it grows that genome with those options, and a command
//! line's own flags override the file's.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use sylva_core::species::{BarkKind, LeafKind};
use sylva_core::taper::PipeTaper;

use crate::assets::{GrowOptions, HEIGHTS};
use crate::error::InputError;
use crate::genome::Genome;
use crate::registry::Registry;

/// How a preset file's name ends.
pub const SUFFIX: &str = ".toml";

/// A preset file, as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PresetFile {
    genome: PathBuf,
    #[serde(default)]
    seed: Option<u64>,
    #[serde(default = "yes")]
    roots: bool,
    #[serde(default, deserialize_with = "height")]
    height: Option<f32>,
    #[serde(default, deserialize_with = "foliage")]
    foliage: Option<LeafKind>,
    #[serde(default, deserialize_with = "bark")]
    bark: Option<BarkKind>,
    #[serde(default = "one", deserialize_with = "density")]
    density: f32,
    #[serde(default, deserialize_with = "taper")]
    taper: Option<f64>,
}

fn yes() -> bool {
    true
}

fn one() -> f32 {
    1.0
}

fn height<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    let (lo, hi) = HEIGHTS;
    let m = f32::deserialize(d)?;
    if (lo..=hi).contains(&m) {
        Ok(Some(m))
    } else {
        Err(serde::de::Error::custom(format!(
            "`height` must be a number from {lo} to {hi} m, got {m}"
        )))
    }
}

fn foliage<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<LeafKind>, D::Error> {
    let name = String::deserialize(d)?;
    name.parse().map(Some).map_err(serde::de::Error::custom)
}

fn bark<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<BarkKind>, D::Error> {
    let name = String::deserialize(d)?;
    name.parse().map(Some).map_err(serde::de::Error::custom)
}

fn density<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let x = f32::deserialize(d)?;
    if (0.25..=4.0).contains(&x) {
        Ok(x)
    } else {
        Err(serde::de::Error::custom(format!(
            "`density` must be a number from 0.25 to 4, got {x}"
        )))
    }
}

fn taper<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    let e = f64::deserialize(d)?;
    PipeTaper::new(e).map(|_| Some(e)).map_err(|_| {
        serde::de::Error::custom(format!("`taper` must be a number from 2 to 3, got {e}"))
    })
}

/// A species preset, read: the genome and how it grows.
#[derive(Clone, Debug)]
pub struct Preset {
    /// The genome, read from the file the preset names.
    pub genome: Genome,
    /// How it grows: seed, roots, height and dress as the preset says.
    pub options: GrowOptions,
}

impl Preset {
    /// Whether `path` names a preset (its name ends in `.toml`).
    pub fn is_preset(path: &Path) -> bool {
        path.to_string_lossy()
            .to_ascii_lowercase()
            .ends_with(SUFFIX)
    }

    /// Reads a preset and the genome it names.
    pub fn load(registry: &Registry, path: &Path) -> Result<Preset, InputError> {
        let text = crate::files::read_text(path)?;
        let file: PresetFile =
            toml::from_str(&text).map_err(|e| InputError::toml(path, &text, &e))?;
        let genome_path = path.parent().unwrap_or(Path::new(".")).join(&file.genome);
        let genome = registry.load_genome(&genome_path)?;
        let mut options = GrowOptions {
            seed: file.seed,
            roots: file.roots,
            height: file.height,
            ..GrowOptions::default()
        };
        options.dress.foliage = file.foliage;
        options.dress.bark = file.bark;
        options.dress.density = file.density;
        // Dressed wood is thickened by the dress's pipe model; a plain plant by its own.
        if let Some(e) = file.taper.and_then(|e| PipeTaper::new(e).ok()) {
            if options.dress.is_plain() {
                options.taper = Some(e);
            } else {
                options.dress.taper = e;
            }
        }
        Ok(Preset { genome, options })
    }
}
