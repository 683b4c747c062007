//! Genome files: JSON with a `"model"` and a `"format"` field and named values.
//!
//! - [`GenomeError`]: why a file was refused, with the line and column.
//! - [`parse`] and [`pretty`]: read and write a genome's JSON.
//! - [`model_tag!`](crate::model_tag) and [`FormatV1`]: the zero-sized header fields, written
//!   and checked like any field but costing nothing in memory.

use serde::{Serialize, de::DeserializeOwned};

/// Why a genome file was refused; `line` and `column` are 1-based, 0 when unknown.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
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
        GenomeError::from_json(&e)
    }
}

impl GenomeError {
    /// The message and position of a serde_json error.
    pub fn from_json(e: &serde_json::Error) -> Self {
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

/// Reads a genome (or any file of Sylva's JSON) from its text; errors carry the position.
pub fn parse<T: DeserializeOwned>(text: &str) -> Result<T, GenomeError> {
    Ok(serde_json::from_str(text)?)
}

/// Pretty JSON ending with a newline: how every genome file is written. Parsing it gives
/// the same value.
pub fn pretty<T: Serialize>(value: &T) -> String {
    // Genomes are structs of strings, numbers and lists, which serde_json always writes
    // (a non-finite float becomes `null`, refused on reading); failing here is a bug.
    let mut s = serde_json::to_string_pretty(value).expect("genomes always serialise");
    s.push('\n');
    s
}

/// Declares a zero-sized type that serialises as the string `$name` and accepts only it:
/// the `"model"` field of a model's genome file.
#[macro_export]
macro_rules! model_tag {
    ($(#[$doc:meta])* $ty:ident, $name:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct $ty;

        impl ::serde::Serialize for $ty {
            fn serialize<S: ::serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str($name)
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $ty {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = <String as ::serde::Deserialize>::deserialize(d)?;
                if text == $name {
                    Ok($ty)
                } else {
                    Err(::serde::de::Error::custom(format!(
                        "`model` must be \"{}\" here, got {text:?}",
                        $name
                    )))
                }
            }
        }
    };
}

/// Genome file format 1: serialises as `1` and accepts only `1`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FormatV1;

impl serde::Serialize for FormatV1 {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u32(1)
    }
}

impl<'de> serde::Deserialize<'de> for FormatV1 {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = <i64 as serde::Deserialize>::deserialize(d)?;
        if v == 1 {
            Ok(FormatV1)
        } else {
            Err(serde::de::Error::custom(format!(
                "unsupported genome `format` {v}; this version of Sylva reads format 1"
            )))
        }
    }
}
