//! Genome files: JSON with a `"model"` and a `"format"` field and named values.
//!
//! [`Genome::from_json`] reads the header first, then the model's own fields, refusing
//! unknown fields and out-of-range values. Every error carries the line and column it was
//! found at, and names the field and what was expected.

use serde::Deserialize;
use sylva_core::Plant;

use crate::{DevelopError, automata, bintree};

/// A genome of any model.
#[derive(Clone, Debug, PartialEq)]
pub enum Genome {
    /// Susinno's recursive binary tree.
    BinTree(bintree::BinTree),
    /// Poncin's GP-programmed turtle automata.
    Automata(Box<automata::AutomataGenome>),
}

/// Why a genome file was refused; `line` and `column` are 1-based, 0 when unknown.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("{message}")]
pub struct GenomeError {
    /// What is wrong and what was expected.
    pub message: String,
    /// Line of the offending text.
    pub line: usize,
    /// Column of the offending text.
    pub column: usize,
}

impl From<serde_json::Error> for GenomeError {
    fn from(e: serde_json::Error) -> Self {
        // serde_json appends " at line L column C"; keep the message without it.
        let text = e.to_string();
        let message = match text.rfind(" at line ") {
            Some(i) => text[..i].to_owned(),
            None => text,
        };
        GenomeError {
            message,
            line: e.line(),
            column: e.column(),
        }
    }
}

/// The header every genome file starts with; other fields are read by the model.
#[derive(Deserialize)]
struct Header {
    #[serde(deserialize_with = "model_name")]
    model: String,
    #[serde(deserialize_with = "format_version")]
    format: u32,
}

const MODELS: [&str; 2] = [bintree::MODEL, automata::MODEL];

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
        }
        .expect("genomes hold only finite numbers and strings")
    }

    /// The model name.
    pub fn model(&self) -> &'static str {
        match self {
            Genome::BinTree(_) => bintree::MODEL,
            Genome::Automata(_) => automata::MODEL,
        }
    }

    /// Grows the plant.
    pub fn develop(&self, seed: u64) -> Result<Plant, DevelopError> {
        match self {
            Genome::BinTree(g) => g.develop(seed),
            Genome::Automata(g) => g.develop(seed),
        }
    }
}
