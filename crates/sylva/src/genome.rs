//! Genome files: JSON with a `"model"` and a `"format"` field and named values.
//!
//! [`Genome::from_json`] reads the header first, then the model's own fields, refusing
//! unknown fields and out-of-range values. Every error carries the line and column it was
//! found at, and names the field and what was expected.

use serde::Deserialize;
use sylva_core::Plant;

use sylva_model::{DevelopError, GenomeError};
use {
    sylva_automata as automata, sylva_bintree as bintree, sylva_lsystem as lsystem,
    sylva_plantmaker as plantmaker,
};

/// A genome of any model.
#[derive(Clone, Debug, PartialEq)]
pub enum Genome {
    /// Susinno's recursive binary tree.
    BinTree(bintree::BinTree),
    /// Poncin's GP-programmed turtle automata.
    Automata(Box<automata::AutomataGenome>),
    /// PlantMaker's branch, fan and inflorescence genome (Gal, Mahal and Sipper).
    PlantMaker(Box<plantmaker::PlantMaker>),
    /// Bornhofen and Lattaud's L-system plants grown by their physiology.
    LSystem(Box<lsystem::LSystemGenome>),
}

/// The header every genome file starts with; other fields are read by the model.
#[derive(Deserialize)]
struct Header {
    #[serde(deserialize_with = "model_name")]
    model: String,
    #[serde(deserialize_with = "format_version")]
    format: u32,
}

const MODELS: [&str; 4] = [
    bintree::MODEL,
    automata::MODEL,
    plantmaker::MODEL,
    lsystem::genome::MODEL,
];

fn model_name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let name = String::deserialize(d)?;
    if MODELS.contains(&name.as_str()) {
        Ok(name)
    } else {
        Err(serde::de::Error::custom(format!(
            "unknown model `{name}`; expected one of: {}",
            MODELS.join(", ")
        )))
    }
}

fn format_version<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let v = u32::deserialize(d)?;
    if v == 1 {
        Ok(v)
    } else {
        Err(serde::de::Error::custom(format!(
            "unsupported genome `format` {v}; this version of Sylva reads format 1"
        )))
    }
}

impl Genome {
    /// Parses a genome file.
    pub fn from_json(text: &str) -> Result<Genome, GenomeError> {
        let header: Header = serde_json::from_str(text)?;
        let _ = header.format;
        match header.model.as_str() {
            bintree::MODEL => Ok(Genome::BinTree(serde_json::from_str(text)?)),
            automata::MODEL => Ok(Genome::Automata(Box::new(serde_json::from_str(text)?))),
            plantmaker::MODEL => Ok(Genome::PlantMaker(Box::new(
                plantmaker::PlantMaker::from_json(text)?,
            ))),
            lsystem::genome::MODEL => Ok(Genome::LSystem(Box::new(
                lsystem::LSystemGenome::from_json(text)?,
            ))),
            other => Err(GenomeError {
                message: format!("unknown model `{other}`"),
                line: 0,
                column: 0,
            }),
        }
    }

    /// The genome as pretty JSON, ending with a newline. Parsing it gives the same genome.
    pub fn to_json(&self) -> String {
        let mut s = match self {
            Genome::BinTree(g) => serde_json::to_string_pretty(g),
            Genome::Automata(g) => serde_json::to_string_pretty(g),
            Genome::PlantMaker(g) => return g.to_json(),
            Genome::LSystem(g) => return g.to_json(),
        }
        .expect("genomes hold only finite numbers and strings");
        s.push('\n');
        s
    }

    /// The genome as a JSON value (for glTF extras).
    pub fn to_value(&self) -> serde_json::Value {
        match self {
            Genome::BinTree(g) => serde_json::to_value(g),
            Genome::Automata(g) => serde_json::to_value(g),
            Genome::PlantMaker(g) => serde_json::to_value(g),
            Genome::LSystem(g) => serde_json::to_value(g),
        }
        .expect("genomes hold only finite numbers and strings")
    }

    /// The model name.
    pub fn model(&self) -> &'static str {
        match self {
            Genome::BinTree(_) => bintree::MODEL,
            Genome::Automata(_) => automata::MODEL,
            Genome::PlantMaker(_) => plantmaker::MODEL,
            Genome::LSystem(_) => lsystem::genome::MODEL,
        }
    }

    /// Grows the plant.
    pub fn develop(&self, seed: u64) -> Result<Plant, DevelopError> {
        match self {
            Genome::BinTree(g) => g.develop(seed),
            Genome::Automata(g) => g.develop(seed),
            Genome::PlantMaker(g) => g.develop(seed),
            Genome::LSystem(g) => g.develop(seed),
        }
    }

    /// The seed a genome grows with when none is given: its own seed for PlantMaker
    /// genomes (which carry one), 0 for the deterministic models.
    pub fn default_seed(&self) -> u64 {
        match self {
            Genome::PlantMaker(g) => g.seed,
            _ => 0,
        }
    }
}
