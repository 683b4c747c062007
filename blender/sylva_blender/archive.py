"""A studio archive (the SQLite file of `sylva studio --db FILE`) as a source of plants and a
record of breeding: plants grow from its rows, and plants bred in Blender are written back
with their parents as the studio writes its own (a `plants` row, without a session, and its
`parents` rows, in one transaction), so the studio's lineage views show them beside its own.

Only Python's sqlite3: the studio keeps the file in WAL mode, so Blender reads and writes it
while the studio has it open.
"""

import datetime
import os
import sqlite3

# The studio's schema versions this reads and writes (its archive.rs MIGRATIONS).
KNOWN_VERSION = 3
ARCHIVE_ID = "sylva_archive_id"  # on a plant object: its row in the archive...
ARCHIVE_PATH = "sylva_archive"  # ...of this file
LISTED = 500  # newest plants offered in the Grow panel
# Blender's operators under the studio's names for them.
STUDIO_OPERATOR = {"file": "upload", "evolve": "design"}


class ArchiveError(ValueError):
    """The file is not a studio archive this extension can read, or a row is missing."""


def connect(path):
    """An open archive, checked: it exists and is a studio archive of a known version."""
    path = os.path.abspath(path)
    if not os.path.isfile(path):
        raise ArchiveError(f"Studio archive not found: {path}")
    try:
        c = sqlite3.connect(path, timeout=5.0)
        version = c.execute("SELECT version FROM schema_version").fetchone()
    except sqlite3.DatabaseError as e:
        raise ArchiveError(f"{path} is not a studio archive (sylva studio --db): {e}") from e
    if version is None or version[0] > KNOWN_VERSION:
        c.close()
        raise ArchiveError(f"{path}: schema version {version and version[0]} is newer than this "
                           f"extension's {KNOWN_VERSION}: update the extension")
    return c


class _sqlite_errors:
    """Turns SQLite's errors (a file locked past the timeout, a table missing) into
    ArchiveError naming the file."""

    def __init__(self, path):
        self.path = path

    def __enter__(self):
        return self

    def __exit__(self, kind, error, trace):
        if isinstance(error, sqlite3.Error):
            raise ArchiveError(f"{self.path}: {error}") from error


def plants(path, model=None, limit=LISTED):
    """The newest plants, (id, model, operator, session, created), of one model or all."""
    with _sqlite_errors(path), _closing(connect(path)) as c:
        if model:
            rows = c.execute("SELECT id, model, operator, session, created FROM plants WHERE model = ?"
                             " ORDER BY id DESC LIMIT ?", (model, limit))
        else:
            rows = c.execute("SELECT id, model, operator, session, created FROM plants"
                             " ORDER BY id DESC LIMIT ?", (limit,))
        return rows.fetchall()


def plant(path, plant_id):
    """(genome JSON, seed, model, operator) of plant `plant_id`."""
    with _sqlite_errors(path), _closing(connect(path)) as c:
        row = c.execute("SELECT genome, seed, model, operator FROM plants WHERE id = ?",
                        (plant_id,)).fetchone()
    if row is None:
        raise ArchiveError(f"{path} has no plant {plant_id}")
    genome, seed, model, operator = row
    return genome, seed % 2**64, model, operator  # the studio stores u64 seeds as i64


def record(path, plants_and_parents):
    """Writes bred plants to the archive, each after its parents: `plants_and_parents` is
    [(object, [parent objects])] of plant objects. A parent not yet in this archive is
    written first (without parents of its own). One transaction; each object gets its row's
    id in `sylva_archive_id`. Returns the ids written."""
    path = os.path.abspath(path)
    written = []
    with _sqlite_errors(path), _closing(connect(path)) as c, c:
        def row_of(obj, parents):
            if obj.get(ARCHIVE_PATH) == path and ARCHIVE_ID in obj:
                return obj[ARCHIVE_ID]
            parent_ids = [row_of(p, []) for p in parents]
            seed = int(obj["sylva_seed"])
            operator = obj.get("sylva_operator", "upload")
            c.execute(
                "INSERT INTO plants (session, model, genome, seed, operator, settings, created)"
                " VALUES (NULL, ?, ?, ?, ?, ?, ?)",
                (obj["sylva_model"], obj["sylva_genome"], seed - 2**64 if seed >= 2**63 else seed,
                 STUDIO_OPERATOR.get(operator, operator), '{"from": "blender"}', _now()))
            row = c.execute("SELECT last_insert_rowid()").fetchone()[0]
            for ord_, parent in enumerate(parent_ids):
                c.execute("INSERT INTO parents (child, ord, parent, dominance) VALUES (?, ?, ?, 1.0)",
                          (row, ord_, parent))
            obj[ARCHIVE_ID] = row
            obj[ARCHIVE_PATH] = path
            written.append(row)
            return row

        for obj, parents in plants_and_parents:
            row_of(obj, parents)
    return written


def _now():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


class _closing:
    def __init__(self, c):
        self.c = c

    def __enter__(self):
        return self.c

    def __exit__(self, *exc):
        self.c.close()
