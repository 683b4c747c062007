//! Plants pruned to a match run's outlines, wherever they are shown: a match's generation
//! best, and such a plant taken into a breeding session (its settings name the run as
//! `pruned_to`) with the offspring bred from it. Breed mode, match mode and the plant
//! routes all read a plant's outlines here, so that none of them reaches into another.
//!
//! A match run's config names its pictures by file name (`front`, `side`); the files are
//! kept in the archive and written into a folder of the studio's own whenever one is
//! missing (after a restart), which the config is then read against.

use std::path::{Path as FilePath, PathBuf};
use std::sync::Arc;

use sylva::Config;
use sylva::Genome;
use sylva::core::Plant;
use sylva::evolution::outline::{Outline, space};
use sylva::{GrowOptions, Grown};

use crate::Studio;
use crate::archive::{self, Operator, PlantRow, RunRow};
use crate::cache::Bounded;
use crate::error::ApiError;

/// The key of a plant's settings naming the match run whose outlines it grows inside, for
/// a plant of a match taken into another session.
pub const PRUNED_TO: &str = "pruned_to";

/// The two views a match keeps pictures of, as files in its folder.
const VIEWS: [&str; 2] = ["front", "side"];

/// The folder a match session's pictures are found in by its run: written from the
/// archive when a file is missing.
pub fn picture_dir(studio: &Studio, session: i64) -> Result<PathBuf, ApiError> {
    let dir = std::env::temp_dir()
        .join(format!("sylva-studio-{}", std::process::id()))
        .join(format!("match-{session}"));
    let failed = |e: std::io::Error| ApiError::internal(format!("the pictures' folder: {e}"));
    if VIEWS.iter().all(|v| dir.join(v).is_file()) {
        return Ok(dir);
    }
    std::fs::create_dir_all(&dir).map_err(failed)?;
    for v in VIEWS {
        let bytes = studio
            .archive
            .read(|c| archive::picture(c, session, v))?
            .ok_or_else(|| ApiError::internal(format!("session {session} has no {v} picture")))?;
        std::fs::write(dir.join(v), bytes).map_err(failed)?;
    }
    Ok(dir)
}

/// A match run's config, read from its row, its pictures found in the session's folder.
pub fn match_config(studio: &Studio, row: &RunRow) -> Result<Config, ApiError> {
    let mut config = studio
        .registry
        .parse_config(FilePath::new("match"), &row.config)
        .map_err(|e| ApiError::internal(e.to_string()))?;
    config.set_base(picture_dir(studio, row.session)?);
    Ok(config)
}

/// The outlines a plant is pruned to, if any.
pub type Shears = Option<Arc<[Outline]>>;

/// The match run whose outlines `row`'s plant may grow inside: its own run for a
/// generation's best, the run its settings name as [`PRUNED_TO`] for one taken elsewhere.
pub fn pruned_run(row: &PlantRow) -> Option<i64> {
    let key = if row.operator == Operator::Match.as_str() {
        "run"
    } else {
        PRUNED_TO
    };
    row.settings.get(key).and_then(|r| r.as_i64())
}

/// The outlines a plant grows inside: those of the match run it comes from
/// ([`pruned_run`]), when that match prunes; none for any other plant.
pub fn pruned_to(studio: &Studio, row: &PlantRow) -> Result<Shears, ApiError> {
    let Some(run) = pruned_run(row) else {
        return Ok(None);
    };
    let kept = studio.kept::<RunOutlines>();
    if let Some(outlines) = kept.0.get(run) {
        return Ok(Shears::clone(&outlines));
    }
    let Some(run) = studio.archive.read(|c| archive::run(c, run))? else {
        return Ok(None);
    };
    let config = match_config(studio, &run)?;
    let outlines = match config.outline() {
        Some(outline) => space(outline, &config.base())
            .map_err(|e| ApiError::internal(format!("match run {}'s pictures: {e}", run.id)))?,
        None => None,
    };
    kept.0.put(run.id, Arc::new(outlines.clone()), 0);
    Ok(outlines)
}

/// Match runs whose outlines are kept in memory at most; the least recently used goes first.
const KEPT_RUNS: usize = 32;

/// Match runs' outlines (none for a run that does not prune), read from the run's config and
/// pictures once rather than at every plant shown: a run's pictures never change and runs
/// are never deleted, so its id names them for the studio's life. Bounded by count: a run's
/// outlines are a few hundred rows of stretches.
struct RunOutlines(Bounded<i64, Shears>);

impl Default for RunOutlines {
    fn default() -> Self {
        RunOutlines(Bounded::new(KEPT_RUNS, usize::MAX))
    }
}

/// The settings of `model` in match run `run` (its config's model section), which breeding
/// by hand keeps for plants taken from it; none when the run is not archived or evolved
/// another model.
pub fn match_settings(
    studio: &Studio,
    run: i64,
    model: &str,
) -> Result<Option<serde_json::Value>, ApiError> {
    let Some(run) = studio.archive.read(|c| archive::run(c, run))? else {
        return Ok(None);
    };
    let config = match_config(studio, &run)?;
    Ok((config.model() == model).then(|| config.model_settings()))
}

/// Grows a genome as the views show it, as the library grows any plant
/// ([`Grown::plant`]): roots left out, pruned to `outlines` if given.
pub fn grow_shown(
    genome: &Genome,
    seed: u64,
    outlines: Option<Arc<[Outline]>>,
) -> Result<Plant, ApiError> {
    let options = GrowOptions {
        seed: Some(seed),
        roots: false,
        pruned_to: outlines,
        ..GrowOptions::default()
    };
    let (_, plant) = Grown::plant(genome, &options).map_err(|e| ApiError::library("genome", e))?;
    Ok(plant)
}
