"""Sylva: grow and evolve 3D plants from genomes.

The heavy work runs in Rust (Sylva's library, the same one the ``sylva`` command line
stands on); long calls release the GIL.

>>> import sylva
>>> g = sylva.Genome.load("examples/plantmaker/tulip.json")
>>> plant = g.grow()
>>> plant.mesh.positions.shape            # doctest: +SKIP
(5230, 3)
>>> plant.export("tulip.glb")

Genomes of the four models (``bintree``, ``automata``, ``plantmaker``, ``lsystem``) are
:class:`Genome`; a grown one is a :class:`Plant`; many plants make a :class:`Scene`
(:func:`garden`, :func:`scene`). :class:`Config` and :class:`Evolution` run evolutions (scored
by a Python function of your own too: ``Evolution(config, fitness=f)``);
:func:`islands` runs several populations at once, on Ray when it is installed and on a
local process pool otherwise. :func:`varieties` fills a map of the fittest plant of every
kind (MAP-Elites, :class:`Varieties`); :class:`GenomeSpace` hands any model's genomes to an
optimiser outside Sylva (pyribs, CMA-ES) as numpy vectors. :class:`StudioArchive` reads the
studio's archive (``sylva studio --db FILE``) and writes plants bred elsewhere into it. Errors
are :class:`SylvaError`, :class:`InputError` (bad input, with its file, line and column),
:class:`LimitError` and :class:`ArchiveError` (a studio archive, naming its file).
"""

from __future__ import annotations

from ._sylva import (
    Archive,
    ArchivedPlant,
    Config,
    Evolution,
    Genome,
    GenomeSpace,
    Member,
    Mesh,
    Plant,
    Scene,
    StudioArchive,
    Varieties,
    Variety,
    __version__,
    cross,
    garden,
    match,
    max_memory,
    models,
    scene,
    schema,
    set_max_memory,
    set_max_time,
    texture_png,
    picture_png,
    varieties,
)
from .errors import ArchiveError, InputError, LimitError, SylvaError
from .islands import IslandsResult, islands

__all__ = [
    "Archive",
    "ArchiveError",
    "ArchivedPlant",
    "Config",
    "Evolution",
    "Genome",
    "GenomeSpace",
    "InputError",
    "IslandsResult",
    "LimitError",
    "Member",
    "Mesh",
    "Plant",
    "Scene",
    "StudioArchive",
    "SylvaError",
    "Varieties",
    "Variety",
    "__version__",
    "cross",
    "garden",
    "islands",
    "match",
    "max_memory",
    "models",
    "scene",
    "schema",
    "set_max_memory",
    "set_max_time",
    "texture_png",
    "picture_png",
    "varieties",
]
