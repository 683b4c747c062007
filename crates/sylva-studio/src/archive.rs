//! The studio's part of the archive: sessions, their steps (undo and redo), runs, maps,
//! meshes, scenes and pictures, stored on top of the library's archive
//! ([`sylva::archive`]: the file's schema and migrations, how it is opened, the plants and
//! their parents, which Blender and Python read and write too).
//!
//! One connection behind a mutex, in WAL mode with `synchronous = FULL`, so that a committed
//! step survives a kill of the process at any moment. Every multi-row change is one
//! transaction ([`Archive::transaction`]).

use rusqlite::{Connection, OptionalExtension, params};
use serde::Serialize;

pub use sylva::archive::{
    Archive, ArchiveError, NewPlant, Operator, ParentRow, PlantRow, insert_plant, now, parents,
    plant, plants,
};

fn json(text: String) -> serde_json::Value {
    serde_json::from_str(&text).unwrap_or(serde_json::Value::Null)
}

/// A session as stored.
#[derive(Clone, Debug, Serialize)]
pub struct SessionRow {
    /// Its id.
    pub id: i64,
    /// breed, garden, family or design.
    pub mode: String,
    /// The model its plants are of.
    pub model: String,
    /// A title.
    pub title: String,
    /// The current view.
    pub state: serde_json::Value,
    /// When (UTC).
    pub created: String,
}

/// A step of a session's history.
#[derive(Clone, Debug, Serialize)]
pub struct StepRow {
    /// Its number in the session, from 1.
    pub seq: i64,
    /// What the person did.
    pub action: serde_json::Value,
    /// Whether it is undone.
    pub undone: bool,
    /// The view before it.
    #[serde(skip)]
    pub before: serde_json::Value,
    /// The view after it.
    #[serde(skip)]
    pub after: serde_json::Value,
}

/// A run as stored.
#[derive(Clone, Debug)]
pub struct RunRow {
    /// Its id.
    pub id: i64,
    /// Its session.
    pub session: i64,
    /// The effective config (TOML).
    pub config: String,
    /// The last checkpoint (JSON), once written.
    pub checkpoint: Option<String>,
    /// running, stopped, done or failed.
    pub status: String,
    /// The last completed generation.
    pub generation: u32,
    /// The generations it is asked to run.
    pub generations: u32,
    /// Why it failed.
    pub error: Option<String>,
}

/// One generation of a run.
#[derive(Clone, Debug, Serialize)]
pub struct GenerationRow {
    /// The generation.
    pub generation: u32,
    /// Best total fitness.
    pub best: f64,
    /// Mean total fitness.
    pub mean: f64,
    /// The best's terms.
    pub best_terms: Vec<f64>,
    /// The best, archived.
    pub plant: Option<i64>,
}

// What a transaction can do. Free functions over `Connection` (a `Transaction` derefs to
// one), so handlers compose them in one transaction.

/// Stores a plant's mesh (for plants that cannot be grown alone again: garden specimens).
pub fn insert_mesh(c: &Connection, plant: i64, glb: &[u8]) -> rusqlite::Result<()> {
    c.execute(
        "INSERT OR REPLACE INTO meshes (plant, glb) VALUES (?1, ?2)",
        params![plant, glb],
    )?;
    Ok(())
}

/// Stores a scene of many plants (a garden); returns its id.
pub fn insert_scene(c: &Connection, glb: &[u8]) -> rusqlite::Result<i64> {
    c.execute("INSERT INTO scenes (glb) VALUES (?1)", params![glb])?;
    Ok(c.last_insert_rowid())
}

/// A stored scene.
pub fn scene(c: &Connection, id: i64) -> rusqlite::Result<Option<Vec<u8>>> {
    c.query_row("SELECT glb FROM scenes WHERE id = ?1", [id], |r| r.get(0))
        .optional()
}

/// A stored mesh.
pub fn mesh(c: &Connection, plant: i64) -> rusqlite::Result<Option<Vec<u8>>> {
    c.query_row("SELECT glb FROM meshes WHERE plant = ?1", [plant], |r| {
        r.get(0)
    })
    .optional()
}

/// Inserts a session; returns its id.
pub fn insert_session(
    c: &Connection,
    mode: &str,
    model: &str,
    title: &str,
    state: &serde_json::Value,
) -> rusqlite::Result<i64> {
    c.execute(
        "INSERT INTO sessions (mode, model, title, state, created) VALUES (?1, ?2, ?3, ?4, ?5)",
        params![mode, model, title, state.to_string(), now()],
    )?;
    Ok(c.last_insert_rowid())
}

/// Replaces a session's view.
pub fn set_state(c: &Connection, session: i64, state: &serde_json::Value) -> rusqlite::Result<()> {
    c.execute(
        "UPDATE sessions SET state = ?2 WHERE id = ?1",
        params![session, state.to_string()],
    )?;
    Ok(())
}

fn session_row(r: &rusqlite::Row<'_>) -> rusqlite::Result<SessionRow> {
    Ok(SessionRow {
        id: r.get(0)?,
        mode: r.get(1)?,
        model: r.get(2)?,
        title: r.get(3)?,
        state: json(r.get(4)?),
        created: r.get(5)?,
    })
}

/// A session by id.
pub fn session(c: &Connection, id: i64) -> rusqlite::Result<Option<SessionRow>> {
    c.query_row(
        "SELECT id, mode, model, title, state, created FROM sessions WHERE id = ?1",
        [id],
        session_row,
    )
    .optional()
}

/// Every session, newest first, with its number of live steps.
pub fn sessions(c: &Connection) -> rusqlite::Result<Vec<(SessionRow, i64)>> {
    let mut stmt = c.prepare(
        "SELECT id, mode, model, title, state, created,
                (SELECT COUNT(*) FROM steps WHERE steps.session = sessions.id AND undone = 0)
         FROM sessions ORDER BY id DESC",
    )?;
    stmt.query_map([], |r| Ok((session_row(r)?, r.get(6)?)))?
        .collect()
}

/// A session's history, in order.
pub fn steps(c: &Connection, session: i64) -> rusqlite::Result<Vec<StepRow>> {
    let mut stmt = c.prepare_cached(
        "SELECT seq, action, undone, before, after FROM steps WHERE session = ?1 ORDER BY seq",
    )?;
    stmt.query_map([session], |r| {
        Ok(StepRow {
            seq: r.get(0)?,
            action: json(r.get(1)?),
            undone: r.get(2)?,
            before: json(r.get(3)?),
            after: json(r.get(4)?),
        })
    })?
    .collect()
}

/// The last `count` steps of a session's history, in order, and whether any step is live
/// (can be undone) or undone (can be redone).
pub fn recent_steps(
    c: &Connection,
    session: i64,
    count: u32,
) -> rusqlite::Result<(Vec<StepRow>, bool, bool)> {
    let mut stmt = c.prepare_cached(
        "SELECT seq, action, undone FROM steps WHERE session = ?1 ORDER BY seq DESC LIMIT ?2",
    )?;
    let mut rows = stmt
        .query_map(params![session, count], |r| {
            Ok(StepRow {
                seq: r.get(0)?,
                action: json(r.get(1)?),
                undone: r.get(2)?,
                before: serde_json::Value::Null,
                after: serde_json::Value::Null,
            })
        })?
        .collect::<rusqlite::Result<Vec<_>>>()?;
    rows.reverse();
    let any = |undone: bool| -> rusqlite::Result<bool> {
        c.query_row(
            "SELECT EXISTS (SELECT 1 FROM steps WHERE session = ?1 AND undone = ?2)",
            params![session, undone],
            |r| r.get(0),
        )
    };
    Ok((rows, any(false)?, any(true)?))
}

/// Records a step (dropping the undone steps it replaces) and sets the session's view to
/// `after`. Returns the step's number.
pub fn record_step(
    c: &Connection,
    session: i64,
    action: &serde_json::Value,
    before: &serde_json::Value,
    after: &serde_json::Value,
) -> rusqlite::Result<i64> {
    c.execute(
        "DELETE FROM steps WHERE session = ?1 AND undone = 1",
        [session],
    )?;
    let seq: i64 = c.query_row(
        "SELECT COALESCE(MAX(seq), 0) + 1 FROM steps WHERE session = ?1",
        [session],
        |r| r.get(0),
    )?;
    c.execute(
        "INSERT INTO steps (session, seq, action, before, after, created)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
        params![
            session,
            seq,
            action.to_string(),
            before.to_string(),
            after.to_string(),
            now()
        ],
    )?;
    set_state(c, session, after)?;
    Ok(seq)
}

/// The number the next step of a session will have.
pub fn next_seq(c: &Connection, session: i64) -> rusqlite::Result<i64> {
    c.query_row(
        "SELECT COALESCE(MAX(seq), 0) + 1 FROM steps WHERE session = ?1 AND undone = 0",
        [session],
        |r| r.get(0),
    )
}

/// Marks a step undone or done again.
pub fn set_undone(c: &Connection, session: i64, seq: i64, undone: bool) -> rusqlite::Result<()> {
    c.execute(
        "UPDATE steps SET undone = ?3 WHERE session = ?1 AND seq = ?2",
        params![session, seq, undone],
    )?;
    Ok(())
}

/// Inserts a run; returns its id.
pub fn insert_run(
    c: &Connection,
    session: i64,
    config: &str,
    generations: u32,
) -> rusqlite::Result<i64> {
    c.execute(
        "INSERT INTO runs (session, config, status, generation, generations)
         VALUES (?1, ?2, 'running', 0, ?3)",
        params![session, config, generations],
    )?;
    Ok(c.last_insert_rowid())
}

fn run_row(r: &rusqlite::Row<'_>) -> rusqlite::Result<RunRow> {
    Ok(RunRow {
        id: r.get(0)?,
        session: r.get(1)?,
        config: r.get(2)?,
        checkpoint: r.get(3)?,
        status: r.get(4)?,
        generation: r.get(5)?,
        generations: r.get(6)?,
        error: r.get(7)?,
    })
}

const RUN_COLUMNS: &str = "id, session, config, checkpoint, status, generation, generations, error";

/// A run by id.
pub fn run(c: &Connection, id: i64) -> rusqlite::Result<Option<RunRow>> {
    c.query_row(
        &format!("SELECT {RUN_COLUMNS} FROM runs WHERE id = ?1"),
        [id],
        run_row,
    )
    .optional()
}

/// Runs with a status.
pub fn runs_with_status(c: &Connection, status: &str) -> rusqlite::Result<Vec<RunRow>> {
    let mut stmt = c.prepare(&format!(
        "SELECT {RUN_COLUMNS} FROM runs WHERE status = ?1 ORDER BY id"
    ))?;
    stmt.query_map([status], run_row)?.collect()
}

/// Runs of sessions of `mode` with a status.
pub fn runs_of_mode(c: &Connection, mode: &str, status: &str) -> rusqlite::Result<Vec<RunRow>> {
    let columns: Vec<String> = RUN_COLUMNS
        .split(", ")
        .map(|c| format!("runs.{c}"))
        .collect();
    let mut stmt = c.prepare(&format!(
        "SELECT {} FROM runs JOIN sessions ON sessions.id = runs.session
         WHERE runs.status = ?1 AND sessions.mode = ?2 ORDER BY runs.id",
        columns.join(", ")
    ))?;
    stmt.query_map(params![status, mode], run_row)?.collect()
}

/// Keeps a session's target picture of `view` (`front`, `side`).
pub fn insert_picture(
    c: &Connection,
    session: i64,
    view: &str,
    bytes: &[u8],
) -> rusqlite::Result<()> {
    c.execute(
        "INSERT OR REPLACE INTO pictures (session, view, bytes) VALUES (?1, ?2, ?3)",
        params![session, view, bytes],
    )?;
    Ok(())
}

/// A session's target picture of `view`.
pub fn picture(c: &Connection, session: i64, view: &str) -> rusqlite::Result<Option<Vec<u8>>> {
    c.query_row(
        "SELECT bytes FROM pictures WHERE session = ?1 AND view = ?2",
        params![session, view],
        |r| r.get(0),
    )
    .optional()
}

/// Sets a run's config (a match's, once its trials chose the model).
pub fn set_run_config(c: &Connection, id: i64, config: &str) -> rusqlite::Result<()> {
    c.execute(
        "UPDATE runs SET config = ?2 WHERE id = ?1",
        params![id, config],
    )?;
    Ok(())
}

/// Sets a session's model (a match's, once its trials chose it).
pub fn set_session_model(c: &Connection, id: i64, model: &str) -> rusqlite::Result<()> {
    c.execute(
        "UPDATE sessions SET model = ?2 WHERE id = ?1",
        params![id, model],
    )?;
    Ok(())
}

/// Puts a plant in a map's cell: `{cell, plant, fitness, descriptors}`.
pub fn set_map_cell(c: &Connection, run: i64, cell: &serde_json::Value) -> rusqlite::Result<()> {
    c.execute(
        "INSERT OR REPLACE INTO map_cells (run, cell, plant, fitness, descriptors)
         VALUES (?1, ?2, ?3, ?4, ?5)",
        params![
            run,
            cell["cell"].as_i64(),
            cell["plant"].as_i64(),
            cell["fitness"].as_f64().unwrap_or(0.0),
            cell["descriptors"].to_string()
        ],
    )?;
    Ok(())
}

/// A map's filled cells, in cell order: `{cell, plant, fitness, descriptors}` each.
pub fn map_cells(c: &Connection, run: i64) -> rusqlite::Result<Vec<serde_json::Value>> {
    let mut stmt = c.prepare_cached(
        "SELECT cell, plant, fitness, descriptors FROM map_cells WHERE run = ?1 ORDER BY cell",
    )?;
    stmt.query_map([run], |r| {
        let descriptors: String = r.get(3)?;
        Ok(serde_json::json!({
            "cell": r.get::<_, i64>(0)?,
            "plant": r.get::<_, i64>(1)?,
            "fitness": r.get::<_, f64>(2)?,
            "descriptors": serde_json::from_str::<serde_json::Value>(&descriptors)
                .unwrap_or_default(),
        }))
    })?
    .collect()
}

/// Saves a run's progress: its checkpoint, generation and status.
pub fn save_run(
    c: &Connection,
    id: i64,
    checkpoint: Option<&str>,
    generation: u32,
    status: &str,
    error: Option<&str>,
) -> rusqlite::Result<()> {
    c.execute(
        "UPDATE runs SET checkpoint = COALESCE(?2, checkpoint), generation = ?3, status = ?4,
         error = ?5 WHERE id = ?1",
        params![id, checkpoint, generation, status, error],
    )?;
    Ok(())
}

/// Records the names of a run's fitness terms.
pub fn set_run_terms(c: &Connection, id: i64, terms: &[String]) -> rusqlite::Result<()> {
    c.execute(
        "UPDATE runs SET terms = ?2 WHERE id = ?1",
        params![id, serde_json::to_string(terms).unwrap_or_default()],
    )?;
    Ok(())
}

/// The names of a run's fitness terms.
pub fn run_terms(c: &Connection, id: i64) -> rusqlite::Result<Vec<String>> {
    let text: String = c.query_row("SELECT terms FROM runs WHERE id = ?1", [id], |r| r.get(0))?;
    Ok(serde_json::from_str(&text).unwrap_or_default())
}

/// Sets a run's status.
pub fn set_run_status(c: &Connection, id: i64, status: &str) -> rusqlite::Result<()> {
    c.execute(
        "UPDATE runs SET status = ?2 WHERE id = ?1",
        params![id, status],
    )?;
    Ok(())
}

/// Sets how many generations a run is asked to run.
pub fn set_run_generations(c: &Connection, id: i64, generations: u32) -> rusqlite::Result<()> {
    c.execute(
        "UPDATE runs SET generations = ?2 WHERE id = ?1",
        params![id, generations],
    )?;
    Ok(())
}

/// Records one generation of a run.
pub fn insert_generation(c: &Connection, run: i64, row: &GenerationRow) -> rusqlite::Result<()> {
    c.execute(
        "INSERT OR REPLACE INTO run_generations (run, generation, best, mean, best_terms, plant)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
        params![
            run,
            row.generation,
            finite_or_zero(row.best),
            finite_or_zero(row.mean),
            serde_json::to_string(&row.best_terms).unwrap_or_default(),
            row.plant
        ],
    )?;
    Ok(())
}

fn finite_or_zero(v: f64) -> f64 {
    if v.is_finite() { v } else { 0.0 }
}

/// A run's generations up to `last`, in order.
pub fn generations(c: &Connection, run: i64, last: u32) -> rusqlite::Result<Vec<GenerationRow>> {
    let mut stmt = c.prepare_cached(
        "SELECT generation, best, mean, best_terms, plant FROM run_generations
         WHERE run = ?1 AND generation <= ?2 ORDER BY generation",
    )?;
    stmt.query_map(params![run, last], |r| {
        Ok(GenerationRow {
            generation: r.get(0)?,
            best: r.get(1)?,
            mean: r.get(2)?,
            best_terms: serde_json::from_str(&r.get::<_, String>(3)?).unwrap_or_default(),
            plant: r.get(4)?,
        })
    })?
    .collect()
}

/// One generation an auto match's trials bred.
#[derive(Clone, Debug, Serialize)]
pub struct TrialGenerationRow {
    /// The model on trial.
    pub model: String,
    /// Whether it was the run-off.
    pub runoff: bool,
    /// The generation of the model's run.
    pub generation: u32,
    /// Best total fitness (the outline score).
    pub best: f64,
    /// Mean total fitness.
    pub mean: f64,
    /// The best's outline IoU.
    pub iou: f64,
    /// The best, archived.
    pub plant: Option<i64>,
}

/// Records a generation of a run's trials (again, if a trial under way at a kill is bred
/// again: its row is replaced, and comes last).
pub fn insert_trial_generation(
    c: &Connection,
    run: i64,
    row: &TrialGenerationRow,
) -> rusqlite::Result<()> {
    c.execute(
        "INSERT OR REPLACE INTO trial_generations
         (run, model, runoff, generation, best, mean, iou, plant)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
        params![
            run,
            row.model,
            row.runoff,
            row.generation,
            finite_or_zero(row.best),
            finite_or_zero(row.mean),
            finite_or_zero(row.iou),
            row.plant
        ],
    )?;
    Ok(())
}

/// A run's trial generations, in the order they were bred.
pub fn trial_generations(c: &Connection, run: i64) -> rusqlite::Result<Vec<TrialGenerationRow>> {
    let mut stmt = c.prepare_cached(
        "SELECT model, runoff, generation, best, mean, iou, plant FROM trial_generations
         WHERE run = ?1 ORDER BY rowid",
    )?;
    stmt.query_map([run], |r| {
        Ok(TrialGenerationRow {
            model: r.get(0)?,
            runoff: r.get(1)?,
            generation: r.get(2)?,
            best: r.get(3)?,
            mean: r.get(4)?,
            iou: r.get(5)?,
            plant: r.get(6)?,
        })
    })?
    .collect()
}

/// Keeps a run's trials' log (the library's `TrialLog`, JSON) and how each trial that
/// ended did (`ended`, JSON).
pub fn set_trial_log(
    c: &Connection,
    run: i64,
    log: &str,
    ended: &serde_json::Value,
) -> rusqlite::Result<()> {
    c.execute(
        "INSERT OR REPLACE INTO run_trials (run, log, ended) VALUES (?1, ?2, ?3)",
        params![run, log, ended.to_string()],
    )?;
    Ok(())
}

/// A run's trials' log, once a trial has ended.
pub fn trial_log(c: &Connection, run: i64) -> rusqlite::Result<Option<String>> {
    c.query_row("SELECT log FROM run_trials WHERE run = ?1", [run], |r| {
        r.get(0)
    })
    .optional()
}

/// How each of a run's trials that ended did, as [`set_trial_log`] kept it (empty before).
pub fn trials_ended(c: &Connection, run: i64) -> rusqlite::Result<serde_json::Value> {
    let text: Option<String> = c
        .query_row("SELECT ended FROM run_trials WHERE run = ?1", [run], |r| {
            r.get(0)
        })
        .optional()?;
    Ok(text.map_or_else(|| serde_json::json!([]), json))
}

/// Keeps a run's checkpoint at a generation (for undo).
pub fn insert_checkpoint(
    c: &Connection,
    run: i64,
    generation: u32,
    checkpoint: &str,
) -> rusqlite::Result<()> {
    c.execute(
        "INSERT OR REPLACE INTO run_checkpoints (run, generation, checkpoint) VALUES (?1, ?2, ?3)",
        params![run, generation, checkpoint],
    )?;
    Ok(())
}

/// A run's checkpoint kept at a generation.
pub fn checkpoint_at(
    c: &Connection,
    run: i64,
    generation: u32,
) -> rusqlite::Result<Option<String>> {
    c.query_row(
        "SELECT checkpoint FROM run_checkpoints WHERE run = ?1 AND generation = ?2",
        params![run, generation],
        |r| r.get(0),
    )
    .optional()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_step_after_an_undo_drops_the_undone_steps() {
        let dir = std::env::temp_dir().join(format!("sylva-archive-s-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let archive = Archive::open(&dir.join("s.db")).unwrap();
        let v = |n: i64| serde_json::json!({ "n": n });
        archive
            .transaction(|c| -> Result<(), crate::error::ApiError> {
                let s = insert_session(c, "breed", "plantmaker", "t", &v(0))?;
                record_step(c, s, &v(1), &v(0), &v(1))?;
                record_step(c, s, &v(2), &v(1), &v(2))?;
                set_undone(c, s, 2, true)?;
                assert_eq!(next_seq(c, s)?, 2);
                record_step(c, s, &v(3), &v(1), &v(3))?;
                let steps = steps(c, s)?;
                assert_eq!(steps.len(), 2);
                assert_eq!(steps[1].action, v(3));
                assert_eq!(session(c, s)?.unwrap().state, v(3));
                Ok(())
            })
            .unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
