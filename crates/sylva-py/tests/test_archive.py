"""The studio's archive from Python (``sylva.StudioArchive``): an archive a running studio
wrote, read while the studio has it open; plants written here that the studio then reads,
grows and branches from; what is refused and how errors name the file; a write that waits
for another program's."""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path

import pytest

import sylva

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"


def studio_binary() -> Path:
    """The `sylva` binary `cargo test` or `cargo build -p sylva-cli` built (scripts/test builds
    it before the Python tests)."""
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for binary in (os.environ.get("SYLVA_BIN"), target / "debug" / "sylva", target / "release" / "sylva"):
        if binary and Path(binary).is_file():
            return Path(binary)
    pytest.skip("no sylva binary: build it with `cargo build -p sylva-cli` (scripts/test does)")


class Studio:
    """`sylva studio --db FILE` on a free port, and its HTTP API."""

    def __init__(self, db: Path):
        self.process = subprocess.Popen(
            [str(studio_binary()), "studio", "--port", "0", "--db", str(db)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )
        line = self.process.stdout.readline().strip()
        if not line.startswith("Sylva studio: http://"):
            self.process.kill()
            raise AssertionError(f"the studio did not start: {line} {self.process.stderr.read()}")
        self.address = line.removeprefix("Sylva studio: http://").rstrip("/")

    def api(self, method: str, path: str, body: object = None) -> dict:
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(f"http://{self.address}{path}", data=data, method=method,
                                         headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(request, timeout=120) as answer:
            return json.loads(answer.read())

    def close(self) -> None:
        self.process.terminate()
        self.process.wait(timeout=30)
        self.process.stdout.close()
        self.process.stderr.close()


@pytest.fixture
def studio(tmp_path):
    running = Studio(tmp_path / "studio.db")
    try:
        yield running
    finally:
        running.close()


def tulip() -> sylva.Genome:
    return sylva.Genome.load(EXAMPLES / "plantmaker" / "tulip.json")


def test_an_archive_the_studio_wrote_is_read_while_the_studio_has_it_open(studio, tmp_path):
    session = studio.api("POST", "/api/sessions", {
        "mode": "breed", "model": "plantmaker",
        "start": {"examples": ["plantmaker/tulip", "plantmaker/fern"]}})
    grid = [cell["plant"] for cell in session["state"]["grid"]]
    with sylva.StudioArchive(tmp_path / "studio.db") as archive:
        assert archive.version == 4
        assert archive.path == str(tmp_path / "studio.db")
        listed = archive.plants(model="plantmaker")
        ids = [p.id for p in listed]
        assert set(grid) <= set(ids) and ids == sorted(ids, reverse=True)
        assert archive.plants(model="bintree") == []
        assert len(archive.plants(limit=3)) == 3
        for plant in grid:
            seen = studio.api("GET", f"/api/plants/{plant}")
            row = archive.plant(plant)
            assert (row.id, row.model, row.seed, row.operator, row.session, row.created, row.settings) == (
                seen["id"], seen["model"], seen["seed"], seen["operator"], seen["session"],
                seen["created"], seen["settings"])
            assert archive.genome(plant) == sylva.Genome.from_json(seen["genome_text"])
            assert archive.parents(plant) == [(p["plant"], p["dominance"]) for p in seen["parents"]]
        # The grid's mutants are children of the tulip, as the studio recorded them.
        assert any(archive.parents(plant) for plant in grid)
        assert repr(archive.plant(grid[0])).startswith(f"<sylva.ArchivedPlant {grid[0]} plantmaker")


def test_plants_written_here_are_read_grown_and_bred_by_the_running_studio(studio, tmp_path):
    session = studio.api("POST", "/api/sessions", {
        "mode": "breed", "model": "plantmaker", "start": {"examples": ["plantmaker/tulip"]}})
    mother = session["state"]["grid"][0]["plant"]
    with sylva.StudioArchive(tmp_path / "studio.db") as archive:
        genome = archive.genome(mother)
        a, b = genome.mutate(seed=1), genome.mutate(seed=2)
        child, _ = sylva.cross([a, b], seed=3, dominance=[1.0, 2.0])
        fern = sylva.Genome.load(EXAMPLES / "plantmaker" / "fern.json")
        ids = archive.add([
            {"genome": a, "operator": "mutate", "parents": [mother], "key": "a",
             "settings": {"from": "test"}},
            {"genome": b, "operator": "mutate", "parents": [mother], "key": "b", "seed": 2**64 - 1},
            {"genome": fern, "operator": "example", "key": "fern"},
            {"genome": child, "operator": "cross", "parents": ["a", "b"], "dominance": [1.0, 2.0]},
        ])
    assert len(ids) == 4 and ids == sorted(ids) and ids[0] > mother

    seen = [studio.api("GET", f"/api/plants/{i}") for i in ids]
    assert [s["operator"] for s in seen] == ["mutate", "mutate", "example", "cross"]
    assert all(s["session"] is None for s in seen)
    assert seen[0]["parents"] == [{"plant": mother, "dominance": 1.0}]
    assert seen[0]["settings"] == {"from": "test"}
    assert seen[1]["seed"] == 2**64 - 1
    assert seen[2]["seed"] == fern.default_seed and seen[2]["parents"] == []
    assert seen[3]["parents"] == [{"plant": ids[0], "dominance": 1.0}, {"plant": ids[1], "dominance": 2.0}]
    for s, g in zip(seen, [a, b, fern, child]):
        assert sylva.Genome.from_json(s["genome_text"]) == g
    # The studio's lineage reaches back through them to its own plant, and a session of its
    # own starts from the cross (grown from the genome written here).
    lineage = studio.api("GET", f"/api/plants/{ids[3]}/lineage")
    assert {mother, ids[0], ids[1], ids[3]} <= {node["id"] for node in lineage["nodes"]}
    branched = studio.api("POST", f"/api/plants/{ids[3]}/branch", {})
    assert branched["model"] == "plantmaker"
    first = studio.api("GET", f"/api/plants/{branched['state']['grid'][0]['plant']}")
    assert first["operator"] == "branch" and first["parents"] == [{"plant": ids[3], "dominance": 1.0}]
    assert sylva.Genome.from_json(first["genome_text"]) == child


def test_an_archive_made_here_is_opened_by_the_studio(tmp_path):
    db = tmp_path / "made.db"
    with sylva.StudioArchive(db, create=True) as archive:
        assert archive.version == 4
        mother = tulip()
        ids = archive.add([
            {"genome": mother, "operator": "example", "key": "m"},
            {"genome": mother.mutate(seed=5), "operator": "mutate", "parents": ["m"]},
        ])
    studio = Studio(db)
    try:
        listed = studio.api("GET", "/api/plants")
        assert {ids[0], ids[1]} <= {p["id"] for p in listed["plants"]}
        assert studio.api("GET", f"/api/plants/{ids[1]}")["parents"][0]["plant"] == ids[0]
    finally:
        studio.close()


def test_what_is_not_an_archive_is_refused_naming_the_file(tmp_path):
    missing = tmp_path / "missing.db"
    with pytest.raises(sylva.ArchiveError) as e:
        sylva.StudioArchive(missing)
    assert "not found" in str(e.value) and e.value.path == str(missing)
    assert isinstance(e.value, sylva.SylvaError)
    assert not missing.exists()

    notes = tmp_path / "notes.db"
    notes.write_text("not sqlite, but long enough to be read as the header of a file")
    with pytest.raises(sylva.ArchiveError, match="is not a studio archive") as e:
        sylva.StudioArchive(notes)
    assert str(notes) in str(e.value)

    other = tmp_path / "other.db"
    with sqlite3.connect(other) as c:
        c.execute("CREATE TABLE schema_version (version INTEGER)")
        c.execute("INSERT INTO schema_version VALUES (1)")
    c.close()
    with pytest.raises(sylva.ArchiveError, match="no `plants` table"):
        sylva.StudioArchive(other)

    newer = tmp_path / "newer.db"
    sylva.StudioArchive(newer, create=True).close()
    c = sqlite3.connect(newer)
    with c:
        c.execute("UPDATE schema_version SET version = 5")
    c.close()
    with pytest.raises(sylva.ArchiveError, match="schema version 5 is newer than 4") as e:
        sylva.StudioArchive(newer)
    assert e.value.path == str(newer)


def test_rows_that_are_not_there_and_genomes_that_do_not_read(tmp_path):
    db = tmp_path / "a.db"
    sylva.StudioArchive(db, create=True).close()
    # A row of a broken genome, as a hand-edited or damaged archive may hold (written with
    # the archive closed: Python's SQLite and the package's do not share their locks).
    c = sqlite3.connect(db)
    with c:
        c.execute("INSERT INTO plants (session, model, genome, seed, operator, settings, created)"
                  " VALUES (NULL, 'bintree', '{\"model\": \"bintree\", \"format\": 1, \"depth\": 40}',"
                  " 1, 'upload', '{}', '2025-01-01T00:00:00Z')")
        broken = c.execute("SELECT last_insert_rowid()").fetchone()[0]
    c.close()
    archive = sylva.StudioArchive(db)
    with pytest.raises(sylva.ArchiveError, match="has no plant 7"):
        archive.plant(7)
    with pytest.raises(sylva.ArchiveError, match="has no plant 7"):
        archive.genome(7)
    with pytest.raises(sylva.ArchiveError, match="has no plant 7"):
        archive.parents(7)
    with pytest.raises(sylva.InputError) as e:
        archive.genome(broken)
    assert e.value.path == f"{db} plant {broken}"
    archive.close()
    with pytest.raises(sylva.ArchiveError, match="is closed"):
        archive.plants()


def test_add_checks_every_plant_and_writes_none_of_a_bad_call(tmp_path):
    archive = sylva.StudioArchive(tmp_path / "a.db", create=True)
    good = {"genome": tulip(), "operator": "example", "key": "t"}
    bad_calls = {
        "plants[1].parents[0]": [good, {"genome": tulip(), "operator": "mutate", "parents": ["nope"]}],
        "plants[0].parents[0]": [{"genome": tulip(), "operator": "mutate", "parents": ["t"], "key": "t"}],
        "plants[1].operator": [good, {"genome": tulip(), "operator": "grafted"}],
        "plants[0].genome": [{"genome": "{}", "operator": "upload"}],
        "plants[0].colour": [dict(good, colour="red")],
        "plants[1].key": [good, dict(good)],
        "plants[0].dominance": [{"genome": tulip(), "operator": "cross", "parents": [1, 2], "dominance": [1.0]}],
        "plants[0].dominance[0]": [{"genome": tulip(), "operator": "mutate", "parents": [1], "dominance": [-1.0]}],
        "plants[0]": [42],
    }
    for where, plants in bad_calls.items():
        with pytest.raises(sylva.InputError) as e:
            archive.add(plants)
        assert e.value.location == where, (where, str(e.value))
    with pytest.raises(sylva.InputError, match="expected random, example, upload"):
        archive.add([{"genome": tulip(), "operator": "grafted"}])
    # A parent id that is not in the archive, after a good plant: neither is written.
    with pytest.raises(sylva.ArchiveError, match="has no plant 99"):
        archive.add([good, {"genome": tulip(), "operator": "mutate", "parents": [99]}])
    assert archive.plants() == []
    assert archive.add([]) == []


# Another program holding the archive's write lock for some seconds. (Another process: two
# SQLites in one process, Python's and the package's, do not see each other's locks.)
HOLD = """
import sqlite3, sys, time
c = sqlite3.connect(sys.argv[1], isolation_level=None)
c.execute("BEGIN IMMEDIATE")
print("held", flush=True)
time.sleep(float(sys.argv[2]))
c.execute("COMMIT")
"""


def holding(db: Path, seconds: float) -> subprocess.Popen:
    holder = subprocess.Popen([sys.executable, "-c", HOLD, str(db), str(seconds)],
                              stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "held"
    return holder


def test_a_write_waits_for_another_programs_and_gives_up_after_five_seconds(tmp_path):
    db = tmp_path / "a.db"
    archive = sylva.StudioArchive(db, create=True)
    ticks = []
    waiting = threading.Event()

    def tick():
        while not waiting.is_set():
            ticks.append(1)
            time.sleep(0.01)

    holder = holding(db, 0.6)
    ticker = threading.Thread(target=tick)
    ticker.start()
    start = time.perf_counter()
    ids = archive.add([{"genome": tulip(), "operator": "example"}])
    waited = time.perf_counter() - start
    waiting.set()
    ticker.join()
    assert holder.wait(timeout=30) == 0
    holder.stdout.close()
    assert len(ids) == 1 and waited >= 0.3, waited
    # It waited without the GIL: this thread ran meanwhile.
    assert len(ticks) >= 10, len(ticks)

    holder = holding(db, 6.5)
    try:
        # Reads do not wait for a writer (WAL).
        start = time.perf_counter()
        assert [p.id for p in archive.plants()] == ids
        assert time.perf_counter() - start < 1.0
        with pytest.raises(sylva.ArchiveError, match="database is locked") as e:
            archive.add([{"genome": tulip(), "operator": "example"}])
        assert e.value.path == str(db)
    finally:
        holder.wait(timeout=30)
        holder.stdout.close()
    assert [p.id for p in archive.plants()] == ids


def test_the_module_and_its_classes_hold_one_registry():
    module = sylva._sylva
    assert type(module._models).__name__ == "Models"
    for cls in (sylva.Genome, sylva.Config, sylva.StudioArchive, sylva.Evolution):
        assert cls._models is module._models
    assert sorted(sylva.models()) == ["automata", "bintree", "grown", "lsystem", "plantmaker"]
