//! The studio's archive as the library keeps it: the schema the studio has always written,
//! migrations, what is refused and how it is named, plants and parents written in one
//! transaction, and two programs writing the file at once.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::{Path, PathBuf};
use std::time::Duration;

use rusqlite::Connection;
use sylva::archive::{
    AddedParent, Addition, Archive, ArchiveError, NewPlant, Operator, ParentId, VERSION,
    insert_plant, timestamp,
};
use sylva::{Genome, Registry, Settings};

/// A fresh folder for one test.
fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("archive")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn tulip() -> Genome {
    Registry::standard()
        .load_genome(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/plantmaker/tulip.json"),
        )
        .unwrap()
}

fn addition(genome: &Genome, operator: Operator, parents: &[ParentId]) -> Addition {
    Addition {
        genome: genome.clone(),
        seed: genome.default_seed(),
        operator,
        settings: serde_json::json!({}),
        parents: parents
            .iter()
            .map(|&plant| AddedParent {
                plant,
                dominance: 1.0,
            })
            .collect(),
    }
}

fn count(path: &Path, table: &str) -> i64 {
    let c = Connection::open(path).unwrap();
    c.query_row(&format!("SELECT COUNT(*) FROM {table}"), [], |r| r.get(0))
        .unwrap()
}

/// The file's schema as `sqlite_master` holds it, in the order it was made.
fn schema(path: &Path) -> String {
    let c = Connection::open(path).unwrap();
    let mut stmt = c
        .prepare("SELECT type, name, tbl_name, sql FROM sqlite_master ORDER BY rowid")
        .unwrap();
    let rows = stmt
        .query_map([], |r| {
            let sql: Option<String> = r.get(3)?;
            Ok(format!(
                "-- {} {} on {}\n{}\n",
                r.get::<_, String>(0)?,
                r.get::<_, String>(1)?,
                r.get::<_, String>(2)?,
                sql.unwrap_or_else(|| "-- (made by SQLite)".into())
            ))
        })
        .unwrap()
        .collect::<Result<Vec<_>, _>>()
        .unwrap();
    rows.join("\n")
}

#[test]
fn times_are_civil_dates_in_utc() {
    assert_eq!(timestamp(0), "1970-01-01T00:00:00Z");
    assert_eq!(timestamp(20_417 * 86_400), "2025-11-25T00:00:00Z");
    assert_eq!(timestamp(11_016 * 86_400 + 3_661), "2000-02-29T01:01:01Z");
}

#[test]
fn the_schema_is_the_one_the_studio_wrote_before_the_library_kept_it() {
    // `tests/data/archive-schema-v3.sql` is `sqlite_master` of an archive that
    // `sylva studio --db` wrote before the schema moved into the library (version 3);
    // version 4 added an auto match's trials after it, changing nothing before.
    let dir = folder("schema");
    let path = dir.join("studio.db");
    drop(Archive::open(&path).unwrap());
    let (v3, v4) = (
        include_str!("data/archive-schema-v3.sql"),
        include_str!("data/archive-schema-v4.sql"),
    );
    assert_eq!(VERSION, 4);
    assert!(v4.starts_with(v3));
    assert_eq!(schema(&path), v4);
    let c = Connection::open(&path).unwrap();
    let mode: String = c
        .query_row("PRAGMA journal_mode", [], |r| r.get(0))
        .unwrap();
    assert_eq!(mode, "wal");
}

#[test]
fn migrations_run_once_and_newer_files_are_refused_naming_the_file() {
    let dir = folder("migrations");
    let path = dir.join("a.db");
    drop(Archive::open(&path).unwrap());
    let archive = Archive::open(&path).unwrap();
    let v: i64 = archive
        .read(|c| c.query_row("SELECT version FROM schema_version", [], |r| r.get(0)))
        .unwrap();
    assert_eq!(v, VERSION as i64);
    assert_eq!(archive.version(), VERSION);
    archive
        .read(|c| c.execute("UPDATE schema_version SET version = 99", []))
        .unwrap();
    drop(archive);
    for opened in [Archive::open(&path), Archive::open_existing(&path)] {
        let e = opened.err().unwrap();
        assert!(
            matches!(
                e,
                ArchiveError::TooNew {
                    found: 99,
                    known: 4,
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(e.to_string().contains(&*path.to_string_lossy()), "{e}");
    }
}

#[test]
fn an_older_archive_is_read_and_written_as_it_is_and_brought_up_to_date_by_the_studio() {
    let dir = folder("older");
    let path = dir.join("v1.db");
    drop(Archive::open(&path).unwrap());
    // Version 1: before map_cells, pictures and the trials of auto matches.
    let c = Connection::open(&path).unwrap();
    c.execute_batch(
        "DROP TABLE trial_generations; DROP TABLE run_trials; DROP TABLE pictures;
         DROP TABLE map_cells; UPDATE schema_version SET version = 1;",
    )
    .unwrap();
    drop(c);
    let before = schema(&path);
    let archive = Archive::open_existing(&path).unwrap();
    assert_eq!(archive.version(), 1);
    let ids = archive
        .add_plants(&[addition(&tulip(), Operator::Example, &[])])
        .unwrap();
    assert_eq!(archive.plant(ids[0]).unwrap().model, "plantmaker");
    drop(archive);
    assert_eq!(schema(&path), before, "open_existing changed the schema");
    let archive = Archive::open(&path).unwrap();
    assert_eq!(archive.version(), VERSION);
    assert_eq!(count(&path, "pictures"), 0);
    assert_eq!(archive.newest_plants(None, 10).unwrap().len(), 1);
}

#[test]
fn what_is_not_an_archive_is_refused_naming_the_file_and_left_as_it_was() {
    let dir = folder("refused");
    let named = |e: &ArchiveError, path: &Path| {
        assert!(e.to_string().contains(&*path.to_string_lossy()), "{e}");
    };

    let missing = dir.join("missing.db");
    let e = Archive::open_existing(&missing).err().unwrap();
    assert!(matches!(e, ArchiveError::NotFound { .. }), "{e:?}");
    assert!(e.to_string().starts_with("studio archive not found"), "{e}");
    named(&e, &missing);
    assert!(!missing.exists(), "a missing archive was made");

    let e = Archive::open_existing(&dir).err().unwrap();
    assert!(matches!(e, ArchiveError::NotAnArchive { .. }), "{e:?}");
    named(&e, &dir);

    let notes = dir.join("notes.db");
    std::fs::write(
        &notes,
        "not sqlite, but long enough to be read as a header of a file",
    )
    .unwrap();
    let e = Archive::open_existing(&notes).err().unwrap();
    assert!(matches!(e, ArchiveError::NotAnArchive { .. }), "{e:?}");
    assert!(e.to_string().contains("is not a studio archive"), "{e}");
    named(&e, &notes);

    // SQLite, with a `schema_version`, but not the studio's tables.
    let other = dir.join("other.db");
    let c = Connection::open(&other).unwrap();
    c.execute_batch(
        "CREATE TABLE schema_version (version INTEGER); INSERT INTO schema_version VALUES (1);",
    )
    .unwrap();
    drop(c);
    let before = schema(&other);
    let e = Archive::open_existing(&other).err().unwrap();
    assert!(e.to_string().contains("no `plants` table"), "{e}");
    named(&e, &other);
    assert_eq!(schema(&other), before);

    // The archive's tables, but no version.
    let empty = dir.join("empty.db");
    drop(Archive::open(&empty).unwrap());
    Connection::open(&empty)
        .unwrap()
        .execute("DELETE FROM schema_version", [])
        .unwrap();
    let e = Archive::open_existing(&empty).err().unwrap();
    assert!(e.to_string().contains("no version"), "{e}");
}

#[test]
fn plants_and_their_parents_are_written_in_one_transaction_and_read_back() {
    let dir = folder("plants");
    let path = dir.join("studio.db");
    let studio = Archive::open(&path).unwrap();
    // A plant the studio made in a session of its own.
    let session_plant = studio
        .transaction(|c| -> Result<i64, ArchiveError> {
            c.execute(
                "INSERT INTO sessions (mode, model, title, state, created)
                 VALUES ('breed', 'plantmaker', 't', '{}', '2025-01-01T00:00:00Z')",
                [],
            )
            .map_err(|e| studio.error(e))?;
            let session = c.last_insert_rowid();
            let text = tulip().to_json();
            insert_plant(
                c,
                &NewPlant {
                    session: Some(session),
                    model: "plantmaker",
                    genome: &text,
                    seed: 7,
                    operator: Operator::Example,
                    settings: &serde_json::json!({"example": "plantmaker/tulip"}),
                    parents: &[],
                },
            )
            .map_err(|e| studio.error(e))
        })
        .unwrap();

    let archive = Archive::open_existing(&path).unwrap();
    let mother = archive
        .genome(&Registry::standard(), session_plant)
        .unwrap();
    assert_eq!(mother, tulip());
    let children: Vec<Genome> = (0..2)
        .map(|s| mother.mutate(Settings::Default, s).unwrap())
        .collect();
    let crossed = Genome::cross(
        &[(&children[0], 1.0), (&children[1], 2.0)],
        Settings::Default,
        9,
    )
    .unwrap()
    .0;
    let mut cross = addition(&crossed, Operator::Cross, &[]);
    cross.parents = vec![
        AddedParent {
            plant: ParentId::Earlier(0),
            dominance: 1.0,
        },
        AddedParent {
            plant: ParentId::Earlier(1),
            dominance: 2.0,
        },
    ];
    // A seed past i64's range reads back as itself.
    cross.seed = u64::MAX - 5;
    cross.settings = serde_json::json!({"from": "test"});
    let ids = archive
        .add_plants(&[
            addition(
                &children[0],
                Operator::Mutate,
                &[ParentId::Row(session_plant)],
            ),
            addition(
                &children[1],
                Operator::Mutate,
                &[ParentId::Row(session_plant)],
            ),
            cross,
        ])
        .unwrap();
    assert_eq!(ids.len(), 3);
    assert!(ids.windows(2).all(|w| w[0] < w[1]) && ids[0] > session_plant);

    // What the studio reads of them.
    let row = studio.plant(ids[2]).unwrap();
    assert_eq!(row.model, "plantmaker");
    assert_eq!(row.seed, u64::MAX - 5);
    assert_eq!(row.operator, "cross");
    assert_eq!(row.session, None);
    assert_eq!(row.settings, serde_json::json!({"from": "test"}));
    assert_eq!(row.genome, crossed.to_json());
    assert_eq!(row.created.len(), "2025-01-01T00:00:00Z".len());
    let parents = studio.parents(ids[2]).unwrap();
    assert_eq!(
        parents
            .iter()
            .map(|p| (p.plant, p.dominance))
            .collect::<Vec<_>>(),
        [(ids[0], 1.0), (ids[1], 2.0)]
    );
    assert_eq!(studio.parents(ids[0]).unwrap()[0].plant, session_plant);
    assert_eq!(
        archive.genome(&Registry::standard(), ids[1]).unwrap(),
        children[1]
    );

    // Listed newest first, by model, as many as asked.
    let newest = archive.newest_plants(None, 10).unwrap();
    assert_eq!(
        newest.iter().map(|p| p.id).collect::<Vec<_>>(),
        [ids[2], ids[1], ids[0], session_plant]
    );
    assert_eq!(newest[3].session, Some(1));
    assert_eq!(newest[3].seed, 7);
    assert_eq!(
        archive.newest_plants(Some("plantmaker"), 2).unwrap().len(),
        2
    );
    assert!(
        archive
            .newest_plants(Some("bintree"), 10)
            .unwrap()
            .is_empty()
    );

    let e = archive.plant(999).err().unwrap();
    assert!(matches!(e, ArchiveError::NoPlant { id: 999, .. }), "{e:?}");
    assert!(archive.parents(999).is_err());
}

#[test]
fn a_failed_write_writes_nothing() {
    let dir = folder("failed");
    let path = dir.join("studio.db");
    drop(Archive::open(&path).unwrap());
    let archive = Archive::open_existing(&path).unwrap();
    let tulip = tulip();
    let good = addition(&tulip, Operator::Example, &[]);

    // A parent that is not in the archive, after two good plants: none is written.
    let e = archive
        .add_plants(&[
            good.clone(),
            addition(&tulip, Operator::Mutate, &[ParentId::Earlier(0)]),
            addition(&tulip, Operator::Mutate, &[ParentId::Row(42)]),
        ])
        .err()
        .unwrap();
    assert!(matches!(e, ArchiveError::NoPlant { id: 42, .. }), "{e:?}");
    assert_eq!(count(&path, "plants"), 0);
    assert_eq!(count(&path, "parents"), 0);

    // A parent that comes after its child, or its own.
    for parent in [1, 0] {
        let e = archive
            .add_plants(&[
                addition(&tulip, Operator::Mutate, &[ParentId::Earlier(parent)]),
                good.clone(),
            ])
            .err()
            .unwrap();
        assert!(
            matches!(e, ArchiveError::Addition { index: 0, .. }),
            "{e:?}"
        );
        assert!(e.to_string().contains("does not come before it"), "{e}");
    }
    // A dominance that is not a number SQLite would keep.
    let mut bad = addition(&tulip, Operator::Mutate, &[ParentId::Earlier(0)]);
    bad.parents[0].dominance = f64::NAN;
    let e = archive.add_plants(&[good.clone(), bad]).err().unwrap();
    assert!(
        matches!(e, ArchiveError::Addition { index: 1, .. }),
        "{e:?}"
    );
    assert_eq!(count(&path, "plants"), 0);
}

#[test]
fn a_genome_that_does_not_read_names_the_archive_and_the_plant() {
    let dir = folder("genome");
    let path = dir.join("studio.db");
    let archive = Archive::open(&path).unwrap();
    let id = archive
        .transaction(|c| {
            insert_plant(
                c,
                &NewPlant {
                    session: None,
                    model: "bintree",
                    genome: "{\"model\": \"bintree\", \"format\": 1, \"depth\": 40}",
                    seed: 1,
                    operator: Operator::Upload,
                    settings: &serde_json::json!({}),
                    parents: &[],
                },
            )
            .map_err(|e| archive.error(e))
        })
        .unwrap();
    let e = archive.genome(&Registry::standard(), id).err().unwrap();
    let ArchiveError::Genome {
        id: which, error, ..
    } = &e
    else {
        panic!("{e:?}");
    };
    assert_eq!(*which, id);
    let source = format!("{} plant {id}", path.display());
    assert_eq!(error.path.as_deref(), Some(Path::new(&source)));
    // A registry without the model does not read it either.
    let e = archive.genome(&Registry::new(), id).err().unwrap();
    assert!(matches!(e, ArchiveError::Genome { .. }), "{e:?}");
}

#[test]
fn two_programs_write_the_file_at_once_without_failing() {
    // The studio holds the archive open and, in one transaction, reads and then writes; a
    // second program (Blender, Python) writes in the middle of it. Its write waits for the
    // studio's to commit (the transaction holds the write lock from its start, and the busy
    // timeout waits for it), and the studio's write is not refused for having read a state
    // that changed under it.
    let dir = folder("concurrent");
    let path = dir.join("studio.db");
    let studio = Archive::open(&path).unwrap();
    let other = Archive::open_existing(&path).unwrap();
    let tulip = tulip();
    let text = tulip.to_json();
    let (began, begun) = std::sync::mpsc::channel();
    std::thread::scope(|s| {
        let studio_write = s.spawn(|| {
            studio.transaction(|c| -> Result<i64, ArchiveError> {
                let n: i64 = c
                    .query_row("SELECT COUNT(*) FROM plants", [], |r| r.get(0))
                    .map_err(|e| studio.error(e))?;
                began.send(()).unwrap();
                std::thread::sleep(Duration::from_millis(300));
                insert_plant(
                    c,
                    &NewPlant {
                        session: None,
                        model: "plantmaker",
                        genome: &text,
                        seed: n as u64,
                        operator: Operator::Example,
                        settings: &serde_json::json!({}),
                        parents: &[],
                    },
                )
                .map_err(|e| studio.error(e))
            })
        });
        begun.recv().unwrap();
        // Reading meanwhile is not held up (WAL), and sees the last commit.
        assert!(other.newest_plants(None, 10).unwrap().is_empty());
        let written = other.add_plants(&[addition(&tulip, Operator::Example, &[])]);
        let studio_row = studio_write.join().unwrap().unwrap();
        let other_row = written.unwrap()[0];
        assert_eq!(
            other_row,
            studio_row + 1,
            "the second write waited for the first"
        );
    });
    assert_eq!(count(&path, "plants"), 2);
}
