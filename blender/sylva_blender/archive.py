"""A studio archive (the SQLite file of `sylva studio --db FILE`) as a source of plants and a
record of breeding: plants grow from its rows, and plants bred in Blender are written back
with their parents as the studio writes its own (a plant row without a session, and its
parents, in one transaction), so the studio's lineage views show them beside its own.

The archive is the sylva package's `StudioArchive`, the library's archive that the studio
itself keeps: its schema, its checks and its SQL are there, not here. The studio keeps the
file in WAL mode, so Blender reads it while the studio has it open, and a write waits for
the studio's (up to five seconds).
"""

import contextlib
import os

from .plants import Unavailable
from .plants import sylva as _package

ARCHIVE_ID = "sylva_archive_id"  # on a plant object: its row in the archive...
ARCHIVE_PATH = "sylva_archive"  # ...of this file
LISTED = 500  # newest plants offered in the Grow panel
# Blender's operators under the studio's names for them.
STUDIO_OPERATOR = {"file": "upload", "evolve": "design"}
# What a row written here records of where it came from.
SETTINGS = {"from": "blender"}


class ArchiveError(ValueError):
    """The file is not a studio archive the package can read, a row is missing, or a write
    failed: the package's message, which names the file."""


def _sylva():
    try:
        return _package()
    except Unavailable as e:
        raise ArchiveError(str(e)) from e


@contextlib.contextmanager
def _opened(path):
    """The archive at `path`, open for the block; the package's ArchiveError as this
    module's."""
    s = _sylva()
    try:
        with s.StudioArchive(path) as archive:
            yield archive
    except s.ArchiveError as e:
        raise ArchiveError(str(e)) from e


def plants(path, model=None, limit=LISTED):
    """The newest plants, (id, model, operator, session, created), of one model or all."""
    with _opened(path) as archive:
        return [(p.id, p.model, p.operator, p.session, p.created)
                for p in archive.plants(model=model, limit=limit)]


def plant(path, plant_id):
    """(genome, seed, operator) of plant `plant_id`: its genome read by the package, which
    names the file and the plant if it does not read."""
    with _opened(path) as archive:
        row = archive.plant(plant_id)
        return archive.genome(plant_id), row.seed, row.operator


def record(path, plants_and_parents):
    """Writes bred plants to the archive, each after its parents: `plants_and_parents` is
    [(object, [parent objects])] of plant objects. A parent not yet in this archive is
    written first (without parents of its own). One transaction; once it is committed, each
    object gets its row's id in `sylva_archive_id`. Returns the ids written."""
    path = os.path.abspath(path)
    s = _sylva()
    batch, written = [], []

    def parent_of(obj, parents):
        """`obj`'s row in this archive, or its key among the plants to write (added, after
        its parents, if it is not there yet)."""
        if obj.get(ARCHIVE_PATH) == path and ARCHIVE_ID in obj:
            return obj[ARCHIVE_ID]
        if obj not in written:  # object names are unique in a file: the keys
            parents = [parent_of(p, []) for p in parents]
            operator = obj.get("sylva_operator", "upload")
            batch.append({
                "genome": s.Genome.from_json(obj["sylva_genome"], source=f"the genome of {obj.name}"),
                "seed": int(obj["sylva_seed"]),
                "operator": STUDIO_OPERATOR.get(operator, operator),
                "parents": parents,
                "settings": dict(SETTINGS),
                "key": obj.name,
            })
            written.append(obj)
        return obj.name

    for obj, parents in plants_and_parents:
        parent_of(obj, parents)
    if not batch:
        return []
    with _opened(path) as archive:
        ids = archive.add(batch)
    for obj, row in zip(written, ids):
        obj[ARCHIVE_ID] = row
        obj[ARCHIVE_PATH] = path
    return ids
