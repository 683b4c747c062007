"""Typed stubs of Sylva's native module (``sylva._sylva``); see the docstrings at run time."""

from __future__ import annotations

import os
from typing import Any, Callable, Sequence, TypedDict

import numpy as np
import numpy.typing as npt

__version__: str

_Path = str | os.PathLike[str]

class Genome:
    """A genome of any of Sylva's models; ``genome["field"]`` reads and sets its fields."""

    @classmethod
    def load(cls, path: _Path) -> Genome:
        """Reads a genome file of any model."""
    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Genome:
        """A genome from a dict shaped like a genome file (with its ``model`` and ``format``)."""
    @classmethod
    def from_json(cls, text: str, source: str = "<json>") -> Genome:
        """A genome from a genome file's JSON text; ``source`` names it in errors."""
    @classmethod
    def random(cls, model: str, seed: int, settings: dict[str, Any] | None = None) -> Genome:
        """A random genome of ``model``, made by the model with ``settings``."""
    @property
    def model(self) -> str:
        """The model's name: "bintree", "automata", "plantmaker" or "lsystem"."""
    @property
    def title(self) -> str:
        """The model's title."""
    @property
    def default_seed(self) -> int:
        """The seed the genome grows with when none is given."""
    def to_dict(self) -> dict[str, Any]:
        """The genome as a dict, exactly as its file holds it."""
    def to_json(self) -> str:
        """The genome file's text."""
    def save(self, path: _Path) -> None:
        """Writes the genome file (atomically)."""
    def fields(self) -> list[str]:
        """The names of the genome's fields (``model`` and ``format`` left out)."""
    def __getitem__(self, field: str) -> Any:
        """A field's value; dotted paths reach into nested fields and lists."""
    def __setitem__(self, field: str, value: Any) -> None:
        """Sets a field in place, checked as the genome file would be."""
    def with_field(self, field: str, value: Any) -> Genome:
        """A copy with ``field`` set to ``value``, checked as the genome file would be."""
    def grow(
        self,
        seed: int | None = None,
        roots: bool = True,
        taper: float | None = None,
        wind: float | None = None,
        wind_period: float | None = None,
        height: float | None = None,
        foliage: str | None = None,
        bark: str | None = None,
        density: float | None = None,
    ) -> Plant:
        """Grows and meshes the plant with ``seed`` (the genome's own when None); ``taper=E``
        thickens the branches by the pipe model, radius ∝ (tips above)^(1/E), E from 2 to 3;
        ``wind=S`` (0 to 10) adds a wind skin and a looping clip of ``wind_period`` seconds;
        ``height=M`` scales it to M metres; ``foliage`` (oak, birch, aspen, beech, maple,
        willow, ash, privet, pine, spruce, fir) puts leaves or needles of that kind on it at
        their real size, as alpha-cut cards; ``bark`` (smooth, birch, furrowed, plated) a
        tiling bark, the foliage's own by default; ``density`` cards per metre of twig,
        0.25 to 4."""
    @staticmethod
    def grow_preset(
        path: str | os.PathLike[str],
        seed: int | None = None,
        height: float | None = None,
        foliage: str | None = None,
        bark: str | None = None,
        density: float | None = None,
    ) -> Plant:
        """Loads a species preset (``examples/species/oak.toml``: a genome and how it
        grows) and grows it; the arguments given override the file's."""
    def mutate(self, seed: int, settings: dict[str, Any] | None = None) -> Genome:
        """A mutated copy, made by the model's own mutation."""
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int:
        """The hash of its genome file's text (do not set a field of a genome in a set)."""

class Mesh:
    """A triangle mesh as read-only numpy arrays that view the plant's memory (no copy);
    ``.copy()`` one to edit it."""

    positions: npt.NDArray[np.float32]
    """(n, 3) vertex positions, metres."""
    normals: npt.NDArray[np.float32]
    """(n, 3) unit vertex normals."""
    uvs: npt.NDArray[np.float32]
    """(n, 2) texture coordinates."""
    indices: npt.NDArray[np.uint32]
    """(t, 3) vertex indices of each triangle."""
    triangle_materials: npt.NDArray[np.uint32]
    """(t,) index into ``materials`` of each triangle."""
    materials: list[dict[str, Any]]
    """Each material: ``name``, ``kind`` (bark, leaf, flower, root), ``color``, ``texture``;
    ``picture`` and ``normal_map``, the names of the pictures it shows (``picture_png``), and
    ``cut_out``, whether its picture's alpha cuts the shape out (leaf cards, petals)."""
    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as its arrays; unpickled, it owns them, read-only."""

class Plant:
    """A grown genome: measures, mesh, exports and pictures."""

    @property
    def genome(self) -> Genome: ...
    @property
    def seed(self) -> int: ...
    @property
    def model(self) -> str: ...
    @property
    def segments(self) -> int: ...
    @property
    def organs(self) -> int: ...
    @property
    def tips(self) -> int: ...
    @property
    def height(self) -> float: ...
    @property
    def bounds(self) -> tuple[list[float], list[float]]: ...
    @property
    def surface_area(self) -> float: ...
    @property
    def volume(self) -> float: ...
    @property
    def total_length(self) -> float: ...
    def inspect(self) -> dict[str, dict[str, Any]]:
        """How the plant measures against real trees (``sylva inspect``): each figure's
        ``value`` (None when not measured), ``unit``, ``label``, ``real`` range, ``check``
        band, ``verdict`` ("real", "unusual", "implausible", "none") and ``source``."""
    def measures(self) -> dict[str, float]:
        """The measures of Susinno's paper, as a dict."""
    def skeleton(self) -> dict[str, Any]:
        """The plant as data (docs/skeleton.md): segments, organs, materials, origin, taper."""
    @property
    def mesh(self) -> Mesh: ...
    def export(self, path: _Path) -> None:
        """Writes GLB, OBJ, VRML97 or STL by the extension; all or nothing. A folder
        that is not there raises ``FileNotFoundError``."""
    def glb(self) -> bytes:
        """The plant as GLB bytes."""
    @property
    def wind(self) -> dict[str, Any] | None:
        """The wind it grew with (strength, period, joints, left_out, clip), or None."""
    def lod_glb(self, levels: int, name: str = "plant") -> bytes:
        """Its levels of detail (2 to 8), then its impostor, as one GLB of nodes NAME_LOD0 to
        NAME_LOD{levels}."""
    def render(
        self, path: _Path | None = None, view: str = "iso", size: tuple[int, int] = (800, 800)
    ) -> bytes:
        """PNG bytes of a picture, also written to ``path`` when given; ``size`` is
        (width, height), each 16 to 8192 pixels."""
    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as its genome, seed, roots and taper; unpickled, it grows again to the
        same bytes."""

class Scene:
    """Many plants in one scene."""

    @property
    def plants(self) -> int: ...
    @property
    def triangles(self) -> int: ...
    @property
    def garden(self) -> str | None:
        """The garden file's text that grows this scene again, for gardens."""
    def meshes(self) -> list[Mesh]: ...
    def export(self, path: _Path) -> None: ...
    def glb(self) -> bytes: ...
    def render(
        self, path: _Path | None = None, view: str = "iso", size: tuple[int, int] = (1200, 800)
    ) -> bytes: ...

class Config:
    """An evolution config of any model that evolves."""

    @classmethod
    def load(cls, path: _Path) -> Config: ...
    @classmethod
    def from_toml(
        cls, text: str, source: str = "<toml>", base: _Path | None = None
    ) -> Config: ...
    @classmethod
    def from_dict(cls, data: dict[str, Any], base: _Path | None = None) -> Config: ...
    @classmethod
    def default(cls) -> Config: ...
    @property
    def model(self) -> str: ...
    @property
    def base(self) -> str:
        """The folder its ``start`` genome files are found in."""
    @property
    def generations(self) -> int: ...
    @property
    def population(self) -> int: ...
    @property
    def seed(self) -> int: ...
    @property
    def threads(self) -> int: ...
    def with_run(self, **fields: Any) -> Config:
        """A copy with ``[run]`` fields changed, each checked against its range."""
    def to_toml(self) -> str: ...
    def to_dict(self) -> dict[str, Any]: ...

class Member:
    """A member of a run's population."""

    id: int
    genome: Genome
    fitness: float | None
    terms: dict[str, float]
    generation: int
    operator: str
    parents: list[int]
    def __eq__(self, other: object) -> bool:
        """Equal when every field is."""
    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as its fields."""

Fitness = Callable[[list[Plant]], Sequence[float] | npt.NDArray[np.floating[Any]]]
"""A Python fitness function: a list of grown plants in, one finite number per plant out
(NaN and infinities raise ``InputError`` naming ``fitness``)."""

class Evolution:
    """An evolution run of any model; ``fitness=f`` adds a Python fitness function."""

    def __init__(
        self,
        config: Config | dict[str, Any] | _Path,
        start: Sequence[Genome] | None = None,
        threads: int | None = None,
        *,
        fitness: Fitness | None = None,
        fitness_weight: float = 1.0,
        fitness_mode: str = "add",
        fitness_batch: int = 16,
    ) -> None:
        """Generation 0 made and scored. ``fitness(plants)`` scores a list of at most
        ``fitness_batch`` grown plants, a term named "python" weighted ``fitness_weight``,
        beside the model's terms (``fitness_mode="add"``) or in their place (``"replace"``).
        Ctrl-C raises KeyboardInterrupt within one member's evaluation."""
    @staticmethod
    def resume(
        config: Config,
        path: _Path | None = None,
        text: str | None = None,
        threads: int | None = None,
        *,
        fitness: Fitness | None = None,
        fitness_weight: float = 1.0,
        fitness_mode: str = "add",
        fitness_batch: int = 16,
    ) -> Evolution:
        """Resumes from a checkpoint; a run with a fitness function is given it again."""
    @property
    def config(self) -> Config: ...
    @property
    def generation(self) -> int: ...
    @property
    def term_names(self) -> list[str]: ...
    @property
    def fitness(self) -> Fitness | None:
        """The Python fitness function, if the run has one."""
    def step(self) -> dict[str, Any]:
        """Breeds one generation; returns its statistics row. Ctrl-C raises
        KeyboardInterrupt within one member's evaluation and leaves the run as it was."""
    def run(
        self,
        generations: int | None = None,
        on_generation: Callable[[dict[str, Any]], Any] | None = None,
    ) -> None: ...
    @property
    def stats(self) -> list[dict[str, Any]]: ...
    def population(self) -> list[Member]: ...
    def best(self) -> Member: ...
    def fittest(self, count: int) -> list[Member]: ...
    def member(self, id: int) -> Member | None: ...
    def family(self, id: int) -> list[Member]: ...
    def generation_members(self, generation: int) -> list[Member] | None: ...
    def keep_history(self, generations: int) -> None: ...
    def checkpoint(self) -> str: ...
    def save(self, path: _Path) -> None: ...
    def emigrants(self, count: int) -> list[bytes]: ...
    def immigrate(self, migrants: Sequence[bytes]) -> list[int]: ...

class Variety:
    """One filled cell of a map: where it is, and its elite."""

    cell: int
    """The cell, row-major over the axes (the first slowest)."""
    coordinates: list[int]
    """The cell's place along each axis."""
    descriptors: list[float]
    """The elite's descriptors, one per axis."""
    genome: Genome
    fitness: float
    terms: dict[str, float]
    id: int
    generation: int
    operator: str
    parents: list[int]

class Archive:
    """A map's filled cells, in cell order, as numpy arrays (n elites, k axes, t terms)."""

    cells: npt.NDArray[np.int64]
    """(n,) each elite's cell, row-major over the axes."""
    coordinates: npt.NDArray[np.int64]
    """(n, k) each elite's cell along each axis."""
    descriptors: npt.NDArray[np.float64]
    """(n, k) each elite's descriptors."""
    fitness: npt.NDArray[np.float64]
    """(n,) each elite's total fitness."""
    terms: npt.NDArray[np.float64]
    """(n, t) each elite's fitness terms, columns named by ``term_names``."""
    term_names: list[str]
    ids: npt.NDArray[np.int64]
    """(n,) each elite's run-wide id."""
    genomes: list[Genome]
    def __len__(self) -> int: ...
    def data(self) -> dict[str, Any]:
        """The columns under pyribs' names: ``index``, ``objective``, ``measures``, ``solution``."""

class Varieties:
    """A MAP-Elites run of any model: a map of the fittest plant of every kind."""

    def __init__(
        self,
        config: Config | dict[str, Any] | _Path,
        start: Sequence[Genome] | None = None,
        threads: int | None = None,
    ) -> None: ...
    @classmethod
    def resume(
        cls,
        config: Config | dict[str, Any] | _Path,
        path: _Path | None = None,
        text: str | None = None,
        threads: int | None = None,
    ) -> Varieties: ...
    @property
    def config(self) -> Config: ...
    @property
    def model(self) -> str: ...
    @property
    def generation(self) -> int: ...
    @property
    def cells(self) -> int: ...
    @property
    def descriptors(self) -> list[str]: ...
    @property
    def axes(self) -> list[tuple[str, float, float, int]]:
        """(descriptor, low, high, cells) of each axis."""
    @property
    def term_names(self) -> list[str]: ...
    def step(self) -> dict[str, Any]:
        """Breeds one generation; returns its statistics row."""
    def run(
        self,
        generations: int | None = None,
        on_generation: Callable[[dict[str, Any]], Any] | None = None,
    ) -> None: ...
    @property
    def stats(self) -> list[dict[str, Any]]:
        """generation, filled, coverage, qd_score, best, mean, best_id, improved,
        evaluations, seconds: one dict per generation."""
    def archive(self) -> Archive: ...
    def variety(self, cell: int) -> Variety | None: ...
    def best(self) -> Variety | None: ...
    def checkpoint(self) -> str: ...
    def save(self, path: _Path) -> None: ...

class GenomeSpace:
    """A model's genomes as vectors of numbers, decoded and scored as a map run scores them."""

    def __init__(
        self,
        config: Config | dict[str, Any] | _Path,
        dim: int | None = None,
        *,
        coding: str | None = None,
        seed: int | None = None,
        threads: int | None = None,
    ) -> None: ...
    @property
    def model(self) -> str: ...
    @property
    def coding(self) -> str:
        """"direct" or "codons"."""
    @property
    def dim(self) -> int: ...
    @property
    def lower(self) -> npt.NDArray[np.float64]: ...
    @property
    def upper(self) -> npt.NDArray[np.float64]: ...
    @property
    def seed(self) -> int: ...
    @property
    def descriptors(self) -> list[str]: ...
    @property
    def term_names(self) -> list[str]: ...
    def decode(self, x: npt.ArrayLike) -> Genome:
        """The genome of a (dim,) vector (entries clamped to the bounds)."""
    def decode_many(self, X: npt.ArrayLike) -> list[Genome]:
        """The genomes of the rows of an (n, dim) array."""
    def encode(self, genome: Genome) -> npt.NDArray[np.float64]:
        """The (dim,) vector of a genome, for a direct coding."""
    def evaluate(
        self, X: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(objective (n,), descriptors (n, k)) of the rows of an (n, dim) array."""

class ArchivedPlant:
    """A plant of a studio archive, as listed: everything but its genome
    (``StudioArchive.genome(id)`` reads it)."""

    id: int
    """Its id (row) in the archive."""
    model: str
    seed: int
    """The seed it grows with."""
    operator: str
    """How it was made: random, example, upload, cross, mutate, edit, regrow, mother,
    family, design, map, match, empty or branch."""
    session: int | None
    """The studio session it was made in; None for plants written by ``add``."""
    created: str
    """When it was written (UTC, ``2025-11-25T09:30:00Z``)."""
    settings: Any
    """The settings of its operator, as recorded."""

class _NewPlant(TypedDict, total=False):
    """A plant ``StudioArchive.add`` writes: ``genome`` and ``operator`` are needed."""

    genome: Genome
    operator: str
    """How it was made: ``"mutate"``, ``"cross"``, ``"example"``, ``"upload"``, ``"random"``,
    ``"design"``, ... (the studio's operators)."""
    seed: int
    """The seed it grows with (the genome's own by default)."""
    parents: Sequence[int | str]
    """Each the id of a plant in the archive, or the ``key`` of a plant given before it."""
    dominance: Sequence[float]
    """One weight per parent, 0 or more (1 each by default)."""
    key: str
    """A name later plants of the same call give as a parent."""
    settings: dict[str, Any]
    """JSON values recorded with it (``{}`` by default)."""

class StudioArchive:
    """A studio archive, the SQLite file of ``sylva studio --db FILE``: its plants, and plants
    bred elsewhere written into it, which the studio shows beside its own. It may be open in
    a running studio meanwhile. Errors are ``ArchiveError``, naming the file."""

    def __init__(self, path: _Path, create: bool = False) -> None:
        """Opens an archive that exists (``create=True``: makes one, or brings an older one
        up to date, as the studio does)."""
    @property
    def path(self) -> str:
        """The file (absolute)."""
    @property
    def version(self) -> int:
        """The file's schema version."""
    def plants(self, model: str | None = None, limit: int = 500) -> list[ArchivedPlant]:
        """The newest ``limit`` plants, newest first, of ``model`` or of every model."""
    def plant(self, id: int) -> ArchivedPlant:
        """The plant of ``id``; ``ArchiveError`` if there is none."""
    def genome(self, id: int) -> Genome:
        """The genome of plant ``id``; ``InputError`` (naming the archive and the plant) if
        it does not read."""
    def parents(self, id: int) -> list[tuple[int, float]]:
        """The parents of plant ``id``, in order: ``(id, dominance)`` each."""
    def add(self, plants: Sequence[_NewPlant]) -> list[int]:
        """Writes plants, each after its parents, in one transaction (all or none), in no
        session; returns their ids."""
    def close(self) -> None:
        """Lets the file go."""
    def __enter__(self) -> StudioArchive: ...
    def __exit__(self, *exc: object) -> bool: ...

def varieties(
    config: Config | dict[str, Any] | _Path,
    *,
    threads: int | None = None,
    start: Sequence[Genome] | None = None,
) -> Varieties:
    """Starts a map of varieties (MAP-Elites) of ``config``."""

def cross(
    parents: Sequence[Genome],
    seed: int,
    dominance: Sequence[float] | None = None,
    settings: dict[str, Any] | None = None,
) -> tuple[Genome, list[int]]:
    """A child of two or more parents of one model, by the model's own crossover."""

def match(
    target: _Path | npt.NDArray[Any],
    side: _Path | npt.NDArray[Any] | None = None,
    model: str = "auto",
    generations: int | None = None,
    seconds: float | None = None,
    population: int = 100,
    seed: int = 1,
    threshold: str | float | None = None,
    threads: int = 0,
    topiary: bool = False,
) -> Evolution:
    """Evolves a plant whose outline matches a picture (a PNG or JPEG file, or a numpy
    mask or uint8 image); returns the run. With `topiary=True` the plants are clipped to
    the outline."""

def set_max_memory(bytes: int) -> None:
    """Sets the memory budget in bytes (0: the default); work over it raises LimitError."""

def max_memory() -> int:
    """The memory budget in force, in bytes."""

def set_max_time(seconds: float) -> None:
    """Sets the time budget in seconds (0: the default hour); work over it raises LimitError."""

def models() -> dict[str, str]:
    """The models Sylva knows: name to title."""

def schema(model: str) -> dict[str, Any]:
    """A model's genome field by field: ``fields`` (each with ``path``, ``group``, ``meaning``,
    ``kind`` and its range, ``unit``, ``shapes``, ``optional``), ``lists`` and ``structures``.
    An unknown model raises ``InputError`` naming ``model``."""

def garden(
    genomes: Sequence[Genome] = ...,
    count: int = 20,
    area: tuple[float, float] = (20.0, 20.0),
    seed: int = 1,
    path: _Path | None = None,
) -> Scene:
    """Grows a PlantMaker garden, from genomes or a garden file."""

def texture_png(id: int) -> bytes:
    """The PNG of Sylva's texture ``id`` (a material's ``texture``): grey, 256 × 256."""

def picture_png(name: str) -> bytes:
    """The PNG of one of Sylva's pictures by name (a material's ``picture`` or
    ``normal_map``: ``sylva-leaves-oak``, ``sylva-bark-furrowed-normal``, ...)."""

def scene(
    plants: Sequence[Plant],
    positions: Sequence[tuple[float, float]],
    turns: Sequence[float] | None = None,
) -> Scene:
    """Puts grown plants in one scene."""
