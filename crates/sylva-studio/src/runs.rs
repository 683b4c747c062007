//! Evolution runs kept in the archive, shared by the modes that run them (family, design
//! and map): a generation's figures as a row, and a run's members archived as plants.

use serde_json::json;
use sylva::{Evolution, Member};

use crate::Studio;
use crate::archive::{self, GenerationRow, NewPlant, Operator};
use crate::error::ApiError;

/// A figure as JSON can hold it (an unscored run's infinities as 0).
pub fn finite(v: f64) -> f64 {
    if v.is_finite() { v } else { 0.0 }
}

/// The last generation's figures.
pub fn generation_row(run: &Evolution) -> GenerationRow {
    let last = run.stats().last();
    GenerationRow {
        generation: run.generation(),
        best: last.map_or(0.0, |s| finite(s.best)),
        mean: last.map_or(0.0, |s| finite(s.mean)),
        best_terms: last.map_or_else(Vec::new, |s| s.best_terms.clone()),
        plant: None,
    }
}

/// Archives a run's member as a plant, once (found again by run and member id), with
/// `extra` fields in its settings (a map's cell).
pub fn archive_member(
    studio: &Studio,
    session: i64,
    run: i64,
    generation: u32,
    member: &Member,
    operator: Operator,
    extra: Option<serde_json::Value>,
) -> Result<i64, ApiError> {
    let text = member.genome.to_json();
    let seed = member.genome.default_seed();
    let mut settings = json!({
        "run": run,
        "generation": generation,
        "member": member.id.0,
        "fitness": finite(member.total()),
    });
    if let Some(serde_json::Value::Object(extra)) = extra {
        for (k, v) in extra {
            settings[k] = v;
        }
    }
    studio.archive.transaction(|c| -> Result<_, ApiError> {
        let found: Option<i64> = c
            .query_row(
                "SELECT id FROM plants WHERE session = ?1 AND json_extract(settings, '$.run') = ?2
                 AND json_extract(settings, '$.member') = ?3",
                rusqlite::params![session, run, member.id.0 as i64],
                |r| r.get(0),
            )
            .ok();
        if let Some(id) = found {
            return Ok(id);
        }
        // Its parents, where they are archived too.
        let mut parents = Vec::new();
        for p in &member.origin.parents {
            let found: Option<i64> = c
                .query_row(
                    "SELECT id FROM plants WHERE session = ?1 AND json_extract(settings, '$.run') = ?2
                     AND json_extract(settings, '$.member') = ?3",
                    rusqlite::params![session, run, p.0 as i64],
                    |r| r.get(0),
                )
                .ok();
            if let Some(plant) = found {
                parents.push(archive::ParentRow { plant, dominance: 1.0 });
            }
        }
        Ok(archive::insert_plant(
            c,
            &NewPlant {
                session: Some(session),
                model: member.genome.model(),
                genome: &text,
                seed,
                operator,
                settings: &settings,
                parents: &parents,
            },
        )?)
    })
}
