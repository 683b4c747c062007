//! The checkpoint file: the effective config and the engine's checkpoint, from which a
//! run resumes exactly.

use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;
use sylva_evolve::{Checkpoint, Problem};
use sylva_model::Evolve;

use crate::error::InputError;

use super::hooks::OwnRecord;
use super::schema::EvolveConfig;

/// The checkpoint file: the effective config and the engine's checkpoint.
#[derive(Serialize)]
#[serde(bound = "")]
pub(super) struct SavedRunRef<'a, M: Evolve> {
    pub(super) config: &'a EvolveConfig<M>,
    pub(super) checkpoint: Checkpoint<<M::Problem as Problem>::Genome>,
    /// The run's own fitness term, if it has one (written only then, so checkpoints of
    /// other runs keep their bytes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) own_term: Option<OwnRecord>,
}

pub(super) struct SavedRun<M: Evolve> {
    pub(super) config: EvolveConfig<M>,
    pub(super) checkpoint: Checkpoint<<M::Problem as Problem>::Genome>,
    pub(super) own_term: Option<OwnRecord>,
}

impl<M: Evolve + Default> SavedRun<M> {
    /// Reads a checkpoint.
    pub(super) fn parse(path: &Path, text: &str) -> Result<Self, InputError> {
        let (config, checkpoint) = parse(path, text)?;
        let own_term = own_term(path, text)?;
        Ok(SavedRun {
            config,
            checkpoint,
            own_term,
        })
    }
}

/// A checkpoint whose text does not parse as JSON, said in those words at its line and
/// column: serde's own (`expected ident`) tell a person nothing of what was wrong.
fn not_json(path: &Path, text: &str, e: &serde_json::Error) -> InputError {
    let message = if e.is_eof() {
        "the checkpoint is not JSON: its text ends before its JSON does (cut short?)"
    } else {
        "the checkpoint is not JSON: its text stops being JSON here"
    };
    InputError::at(path, text, e.line(), e.column(), message.to_owned())
}

/// The own fitness term a checkpoint records, if any.
fn own_term(path: &Path, text: &str) -> Result<Option<OwnRecord>, InputError> {
    // Most checkpoints have none: they are not read twice for it.
    if !text.contains("\"own_term\"") {
        return Ok(None);
    }
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| not_json(path, text, &e))?;
    match value.get("own_term") {
        None => Ok(None),
        Some(term) => serde_json::from_value(term.clone())
            .map(Some)
            .map_err(|e| InputError::file(path, format!("`own_term`: {e}"))),
    }
}

/// Reads a checkpoint file: its config and the engine's checkpoint `C`. Sections of other
/// models in its config (checkpoints of Sylva before 0.2 wrote every model's) are passed
/// over.
pub(super) fn parse<M: Evolve + Default, C: DeserializeOwned>(
    path: &Path,
    text: &str,
) -> Result<(EvolveConfig<M>, C), InputError> {
    let mut value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| not_json(path, text, &e))?;
    let bad = |e: serde_json::Error| InputError::file(path, e);
    if let Some(config) = value.get_mut("config").and_then(|c| c.as_object_mut()) {
        config.retain(|k, _| {
            matches!(k.as_str(), "model" | "run" | "output" | "match" | "map") || k == M::NAME
        });
    }
    let config = value.get("config").cloned().unwrap_or_default();
    let checkpoint = value.get("checkpoint").cloned().unwrap_or_default();
    Ok((
        serde_json::from_value(config).map_err(bad)?,
        serde_json::from_value(checkpoint).map_err(bad)?,
    ))
}

/// The model a checkpoint's run evolves (its `config.model`), to resume it without its
/// config file.
pub fn checkpoint_model(path: &Path, text: &str) -> Result<String, InputError> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| not_json(path, text, &e))?;
    value
        .pointer("/config/model")
        .and_then(|m| m.as_str())
        .map(str::to_owned)
        .ok_or_else(|| InputError::file(path, "not a checkpoint: it names no `config.model`"))
}
