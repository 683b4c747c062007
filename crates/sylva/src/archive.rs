//! The studio's archive: the SQLite file of `sylva studio --db FILE`, which keeps every
//! session, plant, parentage, step and run of the studio.
//!
//! This module owns the file, so that every front end reads and writes it alike: its schema
//! (ordered migrations; `schema_version` records how far a file has come), how it is opened
//! (WAL with `synchronous = FULL`, so that a committed write survives a kill at any moment;
//! foreign keys; a busy timeout of five seconds, so that two programs share it: the studio
//! keeps it open while Blender or a Python script reads and writes beside it), and its plants
//! with their parents. The studio stores its sessions, steps and runs in the same file on top
//! of this (`sylva-studio`'s `archive.rs`).
//!
//! [`Archive::open`] opens or creates an archive and brings its schema up to date (the
//! studio); [`Archive::open_existing`] opens one that must already be there and changes
//! nothing but the rows it is asked to write (a reader, or a front end writing bred plants
//! into the studio's archive). Every write of more than one row is one transaction, begun
//! `IMMEDIATE`: it takes the file's write lock before it reads, so two programs writing at
//! once wait for each other (within the busy timeout) rather than fail.
//!
//! ```
//! use sylva::archive::{Addition, AddedParent, Archive, Operator, ParentId};
//! use sylva::Registry;
//!
//! let dir = std::env::temp_dir().join(format!("sylva-archive-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! let path = dir.join("studio.db");
//! # let _ = std::fs::remove_file(&path);
//! drop(Archive::open(&path)?); // what `sylva studio --db` makes
//!
//! // Elsewhere (Blender, Python): a plant and its mutant, written in one transaction.
//! let archive = Archive::open_existing(&path)?;
//! let registry = Registry::standard();
//! let mother = registry.load_genome("../../examples/plantmaker/tulip.json".as_ref())?;
//! let child = mother.mutate(sylva::Settings::Default, 3)?;
//! let plant = |genome: &sylva::Genome, operator, parents| Addition {
//!     genome: genome.clone(),
//!     seed: genome.default_seed(),
//!     operator,
//!     settings: serde_json::json!({}),
//!     parents,
//! };
//! let ids = archive.add_plants(&[
//!     plant(&mother, Operator::Example, vec![]),
//!     plant(&child, Operator::Mutate, vec![AddedParent { plant: ParentId::Earlier(0), dominance: 1.0 }]),
//! ])?;
//! assert_eq!(archive.parents(ids[1])?[0].plant, ids[0]);
//! assert_eq!(archive.genome(&registry, ids[1])?, child);
//! assert_eq!(archive.newest_plants(Some("plantmaker"), 10)?.len(), 2);
//! # drop(archive);
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Duration;

use rusqlite::{
    Connection, ErrorCode, OpenFlags, OptionalExtension, Transaction, TransactionBehavior, params,
};
use serde::Serialize;

use crate::{Genome, InputError, Registry};

/// Ordered schema steps: step `i` takes a file from version `i` to `i + 1`. Their text is
/// the file's own (`sqlite_master` keeps it): never edit a step, add one.
const MIGRATIONS: &[&str] = &[
    r#"
CREATE TABLE sessions (
    id INTEGER PRIMARY KEY,
    mode TEXT NOT NULL,
    model TEXT NOT NULL,
    title TEXT NOT NULL,
    state TEXT NOT NULL,
    created TEXT NOT NULL
);
CREATE TABLE plants (
    id INTEGER PRIMARY KEY,
    session INTEGER REFERENCES sessions(id),
    model TEXT NOT NULL,
    genome TEXT NOT NULL,
    seed INTEGER NOT NULL,
    operator TEXT NOT NULL,
    settings TEXT NOT NULL,
    created TEXT NOT NULL
);
CREATE INDEX plants_session ON plants(session);
CREATE TABLE parents (
    child INTEGER NOT NULL REFERENCES plants(id),
    ord INTEGER NOT NULL,
    parent INTEGER NOT NULL REFERENCES plants(id),
    dominance REAL NOT NULL,
    PRIMARY KEY (child, ord)
);
CREATE INDEX parents_parent ON parents(parent);
CREATE TABLE meshes (
    plant INTEGER PRIMARY KEY REFERENCES plants(id),
    glb BLOB NOT NULL
);
CREATE TABLE scenes (
    id INTEGER PRIMARY KEY,
    glb BLOB NOT NULL
);
CREATE TABLE steps (
    id INTEGER PRIMARY KEY,
    session INTEGER NOT NULL REFERENCES sessions(id),
    seq INTEGER NOT NULL,
    action TEXT NOT NULL,
    before TEXT NOT NULL,
    after TEXT NOT NULL,
    undone INTEGER NOT NULL DEFAULT 0,
    created TEXT NOT NULL,
    UNIQUE (session, seq)
);
CREATE TABLE runs (
    id INTEGER PRIMARY KEY,
    session INTEGER NOT NULL REFERENCES sessions(id),
    config TEXT NOT NULL,
    checkpoint TEXT,
    status TEXT NOT NULL,
    generation INTEGER NOT NULL,
    generations INTEGER NOT NULL,
    terms TEXT NOT NULL DEFAULT '[]',
    error TEXT
);
CREATE TABLE run_generations (
    run INTEGER NOT NULL REFERENCES runs(id),
    generation INTEGER NOT NULL,
    best REAL NOT NULL,
    mean REAL NOT NULL,
    best_terms TEXT NOT NULL,
    plant INTEGER REFERENCES plants(id),
    PRIMARY KEY (run, generation)
);
CREATE TABLE run_checkpoints (
    run INTEGER NOT NULL REFERENCES runs(id),
    generation INTEGER NOT NULL,
    checkpoint TEXT NOT NULL,
    PRIMARY KEY (run, generation)
);
"#,
    r#"
CREATE TABLE map_cells (
    run INTEGER NOT NULL REFERENCES runs(id),
    cell INTEGER NOT NULL,
    plant INTEGER NOT NULL REFERENCES plants(id),
    fitness REAL NOT NULL,
    descriptors TEXT NOT NULL,
    PRIMARY KEY (run, cell)
);
"#,
    r#"
CREATE TABLE pictures (
    session INTEGER NOT NULL REFERENCES sessions(id),
    view TEXT NOT NULL,
    bytes BLOB NOT NULL,
    PRIMARY KEY (session, view)
);
"#,
    // An auto match's trials: their log (the library's `TrialLog`, JSON), to resume from,
    // with how each trial that ended did (JSON, small, to show), and each generation they
    // bred, in the order bred (rowid), with its best plant.
    r#"
CREATE TABLE run_trials (
    run INTEGER PRIMARY KEY REFERENCES runs(id),
    log TEXT NOT NULL,
    ended TEXT NOT NULL
);
CREATE TABLE trial_generations (
    run INTEGER NOT NULL REFERENCES runs(id),
    model TEXT NOT NULL,
    runoff INTEGER NOT NULL,
    generation INTEGER NOT NULL,
    best REAL NOT NULL,
    mean REAL NOT NULL,
    iou REAL NOT NULL,
    plant INTEGER REFERENCES plants(id),
    PRIMARY KEY (run, model, generation)
);
"#,
];

/// The newest schema version this Sylva reads and writes.
pub const VERSION: usize = MIGRATIONS.len();

/// How long a write waits for another program's (the studio's, Blender's) to finish.
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(5);

/// Why the archive failed. Every error names the file.
#[derive(Debug, thiserror::Error)]
pub enum ArchiveError {
    /// [`Archive::open_existing`] found no file.
    #[error("studio archive not found: {}", path.display())]
    NotFound {
        /// The file.
        path: PathBuf,
    },
    /// The file is not an archive: not SQLite, or without the archive's tables.
    #[error("{} is not a studio archive (sylva studio --db): {reason}", path.display())]
    NotAnArchive {
        /// The file.
        path: PathBuf,
        /// What is missing or wrong.
        reason: String,
    },
    /// The file was written by a newer Sylva.
    #[error(
        "{}: schema version {found} is newer than {known}, the newest this Sylva knows: \
         update Sylva", path.display()
    )]
    TooNew {
        /// The file.
        path: PathBuf,
        /// The file's version.
        found: usize,
        /// The newest this Sylva knows ([`VERSION`]).
        known: usize,
    },
    /// No plant has this id.
    #[error("{} has no plant {id}", path.display())]
    NoPlant {
        /// The file.
        path: PathBuf,
        /// The id asked for.
        id: i64,
    },
    /// A plant given to [`Archive::add_plants`] cannot be written as it is.
    #[error("{}: plant {index} of those to write: {problem}", path.display())]
    Addition {
        /// The file.
        path: PathBuf,
        /// Its position among those given, from 0.
        index: usize,
        /// What is wrong.
        problem: String,
    },
    /// A plant's genome does not read with the registry given.
    #[error("{}: the genome of plant {id} does not read", path.display())]
    Genome {
        /// The file.
        path: PathBuf,
        /// The plant.
        id: i64,
        /// Where and why: the input error names the file and the plant as its source.
        #[source]
        error: Box<InputError>,
    },
    /// SQLite refused (a file locked past the busy timeout, a full disk).
    #[error("{}: {source}", path.display())]
    Sqlite {
        /// The file.
        path: PathBuf,
        /// SQLite's error.
        #[source]
        source: rusqlite::Error,
    },
}

impl ArchiveError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            ArchiveError::NotFound { path }
            | ArchiveError::NotAnArchive { path, .. }
            | ArchiveError::TooNew { path, .. }
            | ArchiveError::NoPlant { path, .. }
            | ArchiveError::Addition { path, .. }
            | ArchiveError::Genome { path, .. }
            | ArchiveError::Sqlite { path, .. } => path,
        }
    }
}

/// An open archive: one connection, behind a mutex (writes are small and human-paced, and
/// SQLite serialises writers anyway).
pub struct Archive {
    connection: Mutex<Connection>,
    path: PathBuf,
    version: usize,
}

/// A plant as stored.
#[derive(Clone, Debug, Serialize)]
pub struct PlantRow {
    /// Its id.
    pub id: i64,
    /// The studio session it was made in, if any.
    pub session: Option<i64>,
    /// Its model.
    pub model: String,
    /// Its genome file's text.
    #[serde(skip)]
    pub genome: String,
    /// The seed it grows with.
    pub seed: u64,
    /// How it was made: an [`Operator`]'s name.
    pub operator: String,
    /// The settings of the operator.
    pub settings: serde_json::Value,
    /// When (UTC, RFC 3339).
    pub created: String,
}

/// A plant as listed: its row without its genome.
#[derive(Clone, Debug, Serialize)]
pub struct PlantSummary {
    /// Its id.
    pub id: i64,
    /// The studio session it was made in, if any.
    pub session: Option<i64>,
    /// Its model.
    pub model: String,
    /// The seed it grows with.
    pub seed: u64,
    /// How it was made: an [`Operator`]'s name.
    pub operator: String,
    /// The settings of the operator.
    pub settings: serde_json::Value,
    /// When (UTC, RFC 3339).
    pub created: String,
}

/// A parent of a plant.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct ParentRow {
    /// The parent.
    pub plant: i64,
    /// Its dominance.
    pub dominance: f64,
}

/// How a plant was made: its `operator` in the archive and in its exports' extras.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Operator {
    /// A random genome of its model.
    Random,
    /// One of Sylva's example genomes.
    Example,
    /// A genome file a person gave.
    Upload,
    /// A crossover of chosen parents.
    Cross,
    /// A mutant of one parent.
    Mutate,
    /// A genome a person edited.
    Edit,
    /// The same genome grown with another seed.
    Regrow,
    /// A garden's mother as she stands in that garden.
    Mother,
    /// A member of a family's run.
    Family,
    /// A member of a design run.
    Design,
    /// An elite of a variety map.
    Map,
    /// A generation's best of a match to a picture.
    Match,
    /// Empty rules, the biomorph garden's start.
    Empty,
    /// An archived plant, again, at the start of a new session.
    Branch,
}

impl Operator {
    /// Every operator.
    pub const ALL: [Operator; 14] = [
        Operator::Random,
        Operator::Example,
        Operator::Upload,
        Operator::Cross,
        Operator::Mutate,
        Operator::Edit,
        Operator::Regrow,
        Operator::Mother,
        Operator::Family,
        Operator::Design,
        Operator::Map,
        Operator::Match,
        Operator::Empty,
        Operator::Branch,
    ];

    /// Its name in the archive.
    pub fn as_str(self) -> &'static str {
        match self {
            Operator::Random => "random",
            Operator::Example => "example",
            Operator::Upload => "upload",
            Operator::Cross => "cross",
            Operator::Mutate => "mutate",
            Operator::Edit => "edit",
            Operator::Regrow => "regrow",
            Operator::Mother => "mother",
            Operator::Family => "family",
            Operator::Design => "design",
            Operator::Map => "map",
            Operator::Match => "match",
            Operator::Empty => "empty",
            Operator::Branch => "branch",
        }
    }

    /// The operator of a name.
    pub fn parse(name: &str) -> Option<Operator> {
        Operator::ALL.into_iter().find(|o| o.as_str() == name)
    }

    /// The names, for an error: `random, example, ... or branch`.
    pub fn expected() -> String {
        let names: Vec<&str> = Operator::ALL.iter().map(|o| o.as_str()).collect();
        let (last, rest) = names.split_last().unwrap_or((&"", &[]));
        format!("{} or {last}", rest.join(", "))
    }
}

/// A new plant, for [`insert_plant`] inside a transaction of one's own.
pub struct NewPlant<'a> {
    /// The session it is made in.
    pub session: Option<i64>,
    /// Its model.
    pub model: &'a str,
    /// Its genome file's text.
    pub genome: &'a str,
    /// Its seed.
    pub seed: u64,
    /// How it was made.
    pub operator: Operator,
    /// The operator's settings.
    pub settings: &'a serde_json::Value,
    /// Its parents.
    pub parents: &'a [ParentRow],
}

/// A plant to write with [`Archive::add_plants`]: in no session, a row of its own.
#[derive(Clone, Debug)]
pub struct Addition {
    /// Its genome; its model is the genome's.
    pub genome: Genome,
    /// The seed it grows with.
    pub seed: u64,
    /// How it was made.
    pub operator: Operator,
    /// The operator's settings (`{}` for none).
    pub settings: serde_json::Value,
    /// Its parents, in order.
    pub parents: Vec<AddedParent>,
}

/// A parent of an [`Addition`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AddedParent {
    /// Which plant.
    pub plant: ParentId,
    /// Its dominance: finite, 0 or more (1 when the parents are alike).
    pub dominance: f64,
}

/// A parent's plant: one already in the archive, or one of the same call's, before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParentId {
    /// The plant of this id in the archive.
    Row(i64),
    /// The plant at this position among those given to [`Archive::add_plants`], which
    /// must come before its child.
    Earlier(usize),
}

/// The time now as the archive records it: RFC 3339 in UTC, to the second.
pub fn now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    timestamp(secs)
}

/// A time given in seconds since 1970-01-01 UTC, as the archive records times:
/// `2025-11-25T09:30:00Z`.
pub fn timestamp(secs: u64) -> String {
    let (days, rem) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days as i64);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// Days since 1970-01-01 to a civil date (Howard Hinnant's algorithm).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

/// JSON text as stored, read back (`null` if it does not read).
fn json(text: String) -> serde_json::Value {
    serde_json::from_str(&text).unwrap_or(serde_json::Value::Null)
}

/// The tables [`Archive::open_existing`] needs to find.
const NEEDED: [&str; 3] = ["schema_version", "plants", "parents"];

impl Archive {
    /// Opens (or creates) the archive at `path` and brings its schema up to date, as the
    /// studio does; in WAL mode.
    pub fn open(path: &Path) -> Result<Archive, ArchiveError> {
        let sqlite = sqlite_error(path);
        let mut connection = Connection::open(path).map_err(&sqlite)?;
        connection.busy_timeout(BUSY_TIMEOUT).map_err(&sqlite)?;
        connection
            .pragma_update(None, "journal_mode", "WAL")
            .map_err(&sqlite)?;
        configure(&connection).map_err(&sqlite)?;
        migrate(&mut connection, path)?;
        Ok(Archive {
            connection: Mutex::new(connection),
            path: path.to_owned(),
            version: VERSION,
        })
    }

    /// Opens an archive that is already there, changing nothing in it but what is written
    /// to it: the file must exist, be SQLite with the archive's `schema_version`, `plants`
    /// and `parents` tables, and be of a schema version this Sylva knows (an older one is
    /// read and written as it is: its plants and parents are those of today). Made for a
    /// program that works beside the studio, which may have the file open.
    pub fn open_existing(path: &Path) -> Result<Archive, ArchiveError> {
        let not_archive = |reason: String| ArchiveError::NotAnArchive {
            path: path.to_owned(),
            reason,
        };
        match std::fs::metadata(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(ArchiveError::NotFound {
                    path: path.to_owned(),
                });
            }
            Ok(m) if m.is_dir() => return Err(not_archive("it is a folder".into())),
            _ => {}
        }
        let sqlite = sqlite_error(path);
        // Not SQLITE_OPEN_CREATE: a file removed meanwhile is not made again, empty.
        let flags = OpenFlags::default().difference(OpenFlags::SQLITE_OPEN_CREATE);
        let connection = Connection::open_with_flags(path, flags).map_err(&sqlite)?;
        connection.busy_timeout(BUSY_TIMEOUT).map_err(&sqlite)?;
        let tables = (|| -> rusqlite::Result<Vec<String>> {
            let mut stmt = connection.prepare(
                "SELECT name FROM sqlite_master WHERE type = 'table' AND name IN (?1, ?2, ?3)",
            )?;
            stmt.query_map(NEEDED, |r| r.get(0))?.collect()
        })();
        let tables = match tables {
            Ok(tables) => tables,
            Err(e) if e.sqlite_error_code() == Some(ErrorCode::NotADatabase) => {
                return Err(not_archive(e.to_string()));
            }
            Err(e) => return Err(sqlite(e)),
        };
        if let Some(missing) = NEEDED.iter().find(|t| !tables.iter().any(|n| n == *t)) {
            return Err(not_archive(format!("it has no `{missing}` table")));
        }
        let version: Option<i64> = connection
            .query_row("SELECT version FROM schema_version", [], |r| r.get(0))
            .optional()
            .map_err(&sqlite)?;
        let version = match version {
            Some(v) if v >= 1 => usize::try_from(v).unwrap_or(usize::MAX),
            _ => return Err(not_archive("its `schema_version` holds no version".into())),
        };
        if version > VERSION {
            return Err(ArchiveError::TooNew {
                path: path.to_owned(),
                found: version,
                known: VERSION,
            });
        }
        configure(&connection).map_err(&sqlite)?;
        Ok(Archive {
            connection: Mutex::new(connection),
            path: path.to_owned(),
            version,
        })
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's schema version ([`VERSION`] once [`Archive::open`] has brought it up to
    /// date).
    pub fn version(&self) -> usize {
        self.version
    }

    /// An SQLite error of this archive's, naming its file.
    pub fn error(&self, source: rusqlite::Error) -> ArchiveError {
        sqlite_error(&self.path)(source)
    }

    /// Runs `f` in one transaction, committed if it returns `Ok`. The transaction is begun
    /// `IMMEDIATE`: it holds the file's write lock from its start (waiting for another
    /// program's write to finish, within [`BUSY_TIMEOUT`]), so what it read is still so when
    /// it writes.
    pub fn transaction<T, E: From<ArchiveError>>(
        &self,
        f: impl FnOnce(&Transaction<'_>) -> Result<T, E>,
    ) -> Result<T, E> {
        // A poisoned lock means a panic mid-transaction, which SQLite rolled back.
        let mut connection = self
            .connection
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        let tx = connection
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(|e| self.error(e))?;
        let value = f(&tx)?;
        tx.commit().map_err(|e| self.error(e))?;
        Ok(value)
    }

    /// Runs a read.
    pub fn read<T>(
        &self,
        f: impl FnOnce(&Connection) -> rusqlite::Result<T>,
    ) -> Result<T, ArchiveError> {
        let connection = self
            .connection
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        f(&connection).map_err(|e| self.error(e))
    }

    /// The newest `limit` plants, newest first, of `model` or of every model.
    pub fn newest_plants(
        &self,
        model: Option<&str>,
        limit: u32,
    ) -> Result<Vec<PlantSummary>, ArchiveError> {
        self.read(|c| {
            let mut stmt = c.prepare_cached(
                "SELECT id, session, model, seed, operator, settings, created FROM plants
                 WHERE ?1 IS NULL OR model = ?1 ORDER BY id DESC LIMIT ?2",
            )?;
            stmt.query_map(params![model, limit], |r| {
                Ok(PlantSummary {
                    id: r.get(0)?,
                    session: r.get(1)?,
                    model: r.get(2)?,
                    seed: r.get::<_, i64>(3)? as u64,
                    operator: r.get(4)?,
                    settings: json(r.get(5)?),
                    created: r.get(6)?,
                })
            })?
            .collect()
        })
    }

    /// The plant of `id`.
    pub fn plant(&self, id: i64) -> Result<PlantRow, ArchiveError> {
        self.read(|c| plant(c, id))?
            .ok_or_else(|| ArchiveError::NoPlant {
                path: self.path.clone(),
                id,
            })
    }

    /// The parents of the plant of `id`, in order.
    pub fn parents(&self, id: i64) -> Result<Vec<ParentRow>, ArchiveError> {
        self.plant_exists(id)?;
        self.read(|c| parents(c, id))
    }

    /// The genome of the plant of `id`, read with `registry`; an error in it names the
    /// archive and the plant as its file (`studio.db plant 12`).
    pub fn genome(&self, registry: &Registry, id: i64) -> Result<Genome, ArchiveError> {
        let row = self.plant(id)?;
        let source = format!("{} plant {id}", self.path.display());
        registry
            .parse_genome(&row.genome)
            .map_err(|e| ArchiveError::Genome {
                path: self.path.clone(),
                id,
                error: Box::new(InputError::genome(Path::new(&source), &row.genome, e)),
            })
    }

    /// Writes `plants`, each after its parents, in one transaction: all of them or, on any
    /// error, none. A parent is a plant already in the archive or one given before its
    /// child. Returns their ids, in order.
    pub fn add_plants(&self, plants: &[Addition]) -> Result<Vec<i64>, ArchiveError> {
        for (index, plant) in plants.iter().enumerate() {
            let problem = |problem: String| ArchiveError::Addition {
                path: self.path.clone(),
                index,
                problem,
            };
            for parent in &plant.parents {
                if let ParentId::Earlier(i) = parent.plant
                    && i >= index
                {
                    return Err(problem(format!(
                        "its parent is plant {i} of those to write, which does not come \
                         before it"
                    )));
                }
                if !(parent.dominance.is_finite() && parent.dominance >= 0.0) {
                    return Err(problem(format!(
                        "a parent's dominance is {}; expected a number, 0 or more",
                        parent.dominance
                    )));
                }
            }
        }
        self.transaction(|c| {
            let mut ids: Vec<i64> = Vec::with_capacity(plants.len());
            for plant in plants {
                let mut parents = Vec::with_capacity(plant.parents.len());
                for parent in &plant.parents {
                    let id = match parent.plant {
                        ParentId::Earlier(i) => ids[i],
                        ParentId::Row(id) => {
                            if !exists(c, id).map_err(|e| self.error(e))? {
                                return Err(ArchiveError::NoPlant {
                                    path: self.path.clone(),
                                    id,
                                });
                            }
                            id
                        }
                    };
                    parents.push(ParentRow {
                        plant: id,
                        dominance: parent.dominance,
                    });
                }
                let genome = plant.genome.to_json();
                let new = NewPlant {
                    session: None,
                    model: plant.genome.model(),
                    genome: &genome,
                    seed: plant.seed,
                    operator: plant.operator,
                    settings: &plant.settings,
                    parents: &parents,
                };
                ids.push(insert_plant(c, &new).map_err(|e| self.error(e))?);
            }
            Ok(ids)
        })
    }

    fn plant_exists(&self, id: i64) -> Result<(), ArchiveError> {
        if self.read(|c| exists(c, id))? {
            Ok(())
        } else {
            Err(ArchiveError::NoPlant {
                path: self.path.clone(),
                id,
            })
        }
    }
}

fn sqlite_error(path: &Path) -> impl Fn(rusqlite::Error) -> ArchiveError + '_ {
    move |source| ArchiveError::Sqlite {
        path: path.to_owned(),
        source,
    }
}

/// What every connection to an archive sets: committed writes survive a kill; parents
/// and plants point at rows that exist.
fn configure(connection: &Connection) -> rusqlite::Result<()> {
    connection.pragma_update(None, "synchronous", "FULL")?;
    connection.pragma_update(None, "foreign_keys", "ON")
}

fn migrate(connection: &mut Connection, path: &Path) -> Result<(), ArchiveError> {
    let sqlite = sqlite_error(path);
    let tx = connection.transaction().map_err(&sqlite)?;
    tx.execute_batch("CREATE TABLE IF NOT EXISTS schema_version (version INTEGER NOT NULL)")
        .map_err(&sqlite)?;
    let version: Option<i64> = tx
        .query_row("SELECT version FROM schema_version", [], |r| r.get(0))
        .optional()
        .map_err(&sqlite)?;
    let version = version.map(|v| usize::try_from(v).unwrap_or(usize::MAX));
    let version = match version {
        Some(v) => v,
        None => {
            tx.execute("INSERT INTO schema_version (version) VALUES (0)", [])
                .map_err(&sqlite)?;
            0
        }
    };
    if version > VERSION {
        return Err(ArchiveError::TooNew {
            path: path.to_owned(),
            found: version,
            known: VERSION,
        });
    }
    for step in &MIGRATIONS[version..] {
        tx.execute_batch(step).map_err(&sqlite)?;
    }
    tx.execute("UPDATE schema_version SET version = ?1", [VERSION as i64])
        .map_err(&sqlite)?;
    tx.commit().map_err(&sqlite)
}

// Plants and their parents. Free functions over `Connection` (a `Transaction` derefs to
// one), so that a front end composes them with its own rows in one transaction.

fn exists(c: &Connection, id: i64) -> rusqlite::Result<bool> {
    c.query_row(
        "SELECT EXISTS (SELECT 1 FROM plants WHERE id = ?1)",
        [id],
        |r| r.get(0),
    )
}

/// Inserts a plant and its parents; returns its id. Seeds are stored as SQLite's signed
/// integers, bit for bit (a seed of 2^63 or more reads back as itself).
pub fn insert_plant(c: &Connection, p: &NewPlant<'_>) -> rusqlite::Result<i64> {
    c.execute(
        "INSERT INTO plants (session, model, genome, seed, operator, settings, created)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
        params![
            p.session,
            p.model,
            p.genome,
            p.seed as i64,
            p.operator.as_str(),
            p.settings.to_string(),
            now()
        ],
    )?;
    let id = c.last_insert_rowid();
    for (ord, parent) in p.parents.iter().enumerate() {
        c.execute(
            "INSERT INTO parents (child, ord, parent, dominance) VALUES (?1, ?2, ?3, ?4)",
            params![id, ord as i64, parent.plant, parent.dominance],
        )?;
    }
    Ok(id)
}

fn plant_row(r: &rusqlite::Row<'_>) -> rusqlite::Result<PlantRow> {
    Ok(PlantRow {
        id: r.get(0)?,
        session: r.get(1)?,
        model: r.get(2)?,
        genome: r.get(3)?,
        seed: r.get::<_, i64>(4)? as u64,
        operator: r.get(5)?,
        settings: json(r.get(6)?),
        created: r.get(7)?,
    })
}

const PLANT_COLUMNS: &str = "id, session, model, genome, seed, operator, settings, created";

/// A plant by id.
pub fn plant(c: &Connection, id: i64) -> rusqlite::Result<Option<PlantRow>> {
    c.query_row(
        &format!("SELECT {PLANT_COLUMNS} FROM plants WHERE id = ?1"),
        [id],
        plant_row,
    )
    .optional()
}

/// A page of plants, newest first, of one session or all; and how many there are.
pub fn plants(
    c: &Connection,
    session: Option<i64>,
    offset: u32,
    limit: u32,
) -> rusqlite::Result<(u64, Vec<PlantRow>)> {
    let (filter, args): (&str, Vec<i64>) = match session {
        Some(s) => ("WHERE session = ?1", vec![s]),
        None => ("", vec![]),
    };
    let total: i64 = c.query_row(
        &format!("SELECT COUNT(*) FROM plants {filter}"),
        rusqlite::params_from_iter(&args),
        |r| r.get(0),
    )?;
    let mut stmt = c.prepare(&format!(
        "SELECT {PLANT_COLUMNS} FROM plants {filter} ORDER BY id DESC LIMIT {limit} OFFSET {offset}"
    ))?;
    let rows = stmt
        .query_map(rusqlite::params_from_iter(&args), plant_row)?
        .collect::<rusqlite::Result<Vec<_>>>()?;
    Ok((total as u64, rows))
}

/// A plant's parents, in order.
pub fn parents(c: &Connection, child: i64) -> rusqlite::Result<Vec<ParentRow>> {
    let mut stmt =
        c.prepare_cached("SELECT parent, dominance FROM parents WHERE child = ?1 ORDER BY ord")?;
    stmt.query_map([child], |r| {
        Ok(ParentRow {
            plant: r.get(0)?,
            dominance: r.get(1)?,
        })
    })?
    .collect()
}
