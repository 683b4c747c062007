"""Plant objects: a mesh object whose custom properties hold what it grew from (genome JSON,
seed, model, lineage), so it can be regrown, bred, exported with its origin (glTF extras)
or grown again by `sylva grow` outside Blender.

The Python package is imported lazily: a missing or broken wheel shows as an error in the
panel, naming what failed, instead of stopping the add-on from registering.
"""

import hashlib
import json
import os
from concurrent.futures import ThreadPoolExecutor

import bpy

from . import plantmesh

# Custom properties of a plant object. Strings and ints only, so they survive glTF export
# as extras and show in Object Properties > Custom Properties.
GENOME = "sylva_genome"  # the genome file's JSON text
SEED = "sylva_seed"  # the seed it grew with (int; decimal text when over 2^31 - 1)
MODEL = "sylva_model"
ID = "sylva_id"  # first 12 hex digits of the SHA-1 of the genome JSON
PARENTS = "sylva_parents"  # JSON list of the parents' ids
OPERATOR = "sylva_operator"  # example, file, random, mutate or cross
GENERATION = "sylva_generation"
LINEAGE = "sylva_lineage"  # JSON {id: {operator, parents, generation}}, itself and ancestors
VERSION = "sylva_version"
CELL = "sylva_cell"  # 0..8: its place in the breeding grid
SOURCE = "sylva_source"  # the example's name, the genome file's path, the random draw or the archive row

BROOD = "Sylva Brood"
DETAIL_MODIFIER = "Sylva Detail"
INT_MAX = 2**31 - 1  # Blender's integer properties are 32-bit
LINEAGE_MAX = 256  # ancestors kept per plant; the oldest generations go first
# Tries per variant when a mutant or cross grows nothing (an L-system mutant whose shoot
# draws nothing) or fails to grow; each try draws another seed.
TRIES = 6

class Unavailable(RuntimeError):
    """The sylva package could not be imported."""


def sylva():
    """The sylva package, or Unavailable saying why not."""
    try:
        import sylva as module
    except Exception as e:  # ImportError, or an OSError of a wheel for another machine
        raise Unavailable(f"Sylva's Python package could not be imported: {type(e).__name__}: {e}") from e
    return module


def import_error():
    """Why the package could not be imported, or None."""
    try:
        sylva()
    except Unavailable as e:
        return str(e)
    return None


def genome_id(genome):
    return hashlib.sha1(genome.to_json().encode()).hexdigest()[:12]


def is_plant(obj):
    return obj is not None and obj.type == "MESH" and GENOME in obj


# Settings set by the add-on itself (a new plant's seed, say) must not each regrow it: their
# update callbacks look at this depth and return while it is above 0.
_quiet = 0


class quiet:
    def __enter__(self):
        global _quiet
        _quiet += 1

    def __exit__(self, *exc):
        global _quiet
        _quiet -= 1


def is_quiet():
    return _quiet > 0


def examples_dir():
    return os.path.join(os.path.dirname(__file__), "examples")


def examples(model):
    """(name, path) of the bundled example genomes of `model`, sorted by name."""
    folder = os.path.join(examples_dir(), model)
    if not os.path.isdir(folder):
        return []
    return sorted(
        (name[: -len(".json")], os.path.join(folder, name))
        for name in os.listdir(folder)
        if name.endswith(".json")
    )


# Leaves and needles of a kind (Genome.grow's `foliage`), and the tiling barks (`bark`): the
# identifiers of the object settings' enums, which hold the package's names.
FOLIAGE_KINDS = ("oak", "birch", "aspen", "beech", "maple", "willow", "ash", "privet", "pine",
                 "spruce", "fir")
BARK_KINDS = ("smooth", "birch", "furrowed", "plated")
AS_GROWN = "NONE"  # Foliage: the plant's own leaves
FOLIAGE_BARK = "FOLIAGE"  # Bark: the foliage kind's own (none when there is no foliage)
HEIGHT_MIN = 0.01  # Genome.grow's height, metres: 0.01 to 1000 (0 in the settings: as grown)

# A new plant's settings: the defaults of the object's `sylva` group (see __init__.py).
DEFAULT_SETTINGS = {"own_seed": True, "seed": 0, "roots": True, "taper": None,
                    "height": None, "foliage": None, "bark": None, "density": 1.0}
# The settings of the object's `sylva` group that say how it grows, copied with the plant
# (breeding grid, forest variants).
GROWTH_SETTINGS = ("own_seed", "seed", "use_taper", "taper", "roots", "detail",
                   "foliage", "bark", "height", "density")


def settings_of(group):
    """An object's growth settings (its `sylva` group) as a plain dict, for worker threads.
    Objects saved before the dress have its defaults: they grow as they did."""
    return {
        "own_seed": group.own_seed,
        "seed": group.seed,
        "roots": group.roots,
        "taper": group.taper if group.use_taper else None,
        "height": max(group.height, HEIGHT_MIN) if group.height > 0 else None,
        "foliage": None if group.foliage == AS_GROWN else group.foliage,
        "bark": None if group.bark == FOLIAGE_BARK else group.bark,
        "density": group.density,
    }


def grow_options(settings, genome):
    """Keyword arguments of Genome.grow for settings_of(...) and a genome. The dress's are
    given only when set, so a plain plant grows exactly as before they were."""
    options = {
        "seed": genome.default_seed if settings["own_seed"] else settings["seed"],
        "roots": settings["roots"],
        "taper": settings["taper"],
    }
    if settings.get("height") is not None:
        options["height"] = settings["height"]
    if settings.get("foliage") is not None:
        options["foliage"] = settings["foliage"]
        options["density"] = settings.get("density", 1.0)
    if settings.get("bark") is not None:
        options["bark"] = settings["bark"]
    return options


def copy_settings(source, target):
    """Gives `target` the growth settings of `source` (plant objects), without regrowing it."""
    with quiet():
        for name in GROWTH_SETTINGS:
            setattr(target.sylva, name, getattr(source.sylva, name))


# Species presets (examples/species/*.toml): a genome and how it grows into a tree of a
# species. Grown with Genome.grow_preset; the plant keeps the preset's settings in its own,
# so it regrows, breeds and makes assets as the preset grows.
PRESET_SUFFIX = ".toml"
SPECIES_PREFIX = "species/"  # an Example item that is a species preset: species/oak


def is_preset(path):
    return path.lower().endswith(PRESET_SUFFIX)


def preset_settings(path):
    """(genome, settings dict as settings_of gives it) of a species preset. The package
    checks the file when it grows it (grow_preset); this reads what the object keeps."""
    import tomllib

    with open(path, "rb") as f:
        preset = tomllib.load(f)
    genome = sylva().Genome.load(os.path.join(os.path.dirname(path), preset["genome"]))
    dressed = preset.get("foliage") is not None or preset.get("bark") is not None
    taper = preset.get("taper")
    settings = {
        "own_seed": preset.get("seed") is None or preset["seed"] == genome.default_seed,
        "seed": int(preset.get("seed") or 0),
        "roots": bool(preset.get("roots", True)),
        # Dressed wood is thickened by the dress's own pipe model, exponent 2.5 (a dressed
        # preset's own exponent is not kept: Genome.grow's taper is the plain plant's; none
        # of examples/species sets one).
        "taper": None if dressed else taper,
        "height": preset.get("height"),
        "foliage": preset.get("foliage"),
        "bark": preset.get("bark"),
        "density": float(preset.get("density", 1.0)),
    }
    return genome, settings


def set_settings(obj, settings):
    """Sets an object's `sylva` group from a settings dict (settings_of's), without regrowing."""
    group = obj.sylva
    with quiet():
        group.own_seed = settings["own_seed"]
        group.seed = settings["seed"] % (INT_MAX + 1)
        group.roots = settings["roots"]
        group.use_taper = settings["taper"] is not None
        if settings["taper"] is not None:
            group.taper = settings["taper"]
        group.height = settings.get("height") or 0.0
        group.foliage = settings.get("foliage") or AS_GROWN
        group.bark = settings.get("bark") or FOLIAGE_BARK
        group.density = settings.get("density", 1.0)


_presets = {}


def presets(model=None):
    """(name, path) of the species presets bundled in examples/species, of `model` (the
    model of the genome each names) or all, sorted by name."""
    folder = os.path.join(examples_dir(), "species")
    if "all" not in _presets:
        found = []
        if os.path.isdir(folder):
            for name in sorted(os.listdir(folder)):
                if not is_preset(name):
                    continue
                path = os.path.join(folder, name)
                try:
                    import tomllib

                    with open(path, "rb") as f:
                        genome = tomllib.load(f)["genome"]
                    with open(os.path.join(folder, genome), encoding="utf-8") as f:
                        kind = json.load(f)["model"]
                except Exception:
                    continue  # not a preset this version reads: left out of the menu
                found.append((name[: -len(PRESET_SUFFIX)], path, kind))
        _presets["all"] = found
    return [(name, path) for name, path, kind in _presets["all"] if model in (None, kind)]


def grow(genome, options):
    """Grows and meshes; safe on any thread (no bpy), and releases the GIL. Also makes the
    textures the plant's materials name (cached by the package), so that on a worker thread
    Blender's thread finds them made."""
    return _made_ready(genome.grow(**options))


def grow_preset(path):
    """Grows a species preset (a .toml: a genome and how it grows), as grow() grows."""
    return _made_ready(sylva().Genome.grow_preset(path))


def grow_member(run, member):
    """Grows a run's member as the run's own files grow it (inside a picture's outline, when
    the run matches one: the plant it scored), as grow() does; call it between the run's
    steps."""
    return _made_ready(run.grow(member))


def _made_ready(plant):
    materials = plant.mesh.materials  # gathers the triangle arrays too, off Blender's thread
    for texture in {m["texture"] for m in materials if m["texture"] is not None}:
        sylva().texture_png(texture)
    for m in materials:  # leaf atlases, bark and its normal map: made once per process
        for name in (m.get("picture"), m.get("normal_map")):
            if name is not None and not name.startswith(plantmesh.DESIGN_PREFIX):
                sylva().picture_png(name)
    return plant


def new_object(context, name, collection=None):
    me = bpy.data.meshes.new(name)
    obj = bpy.data.objects.new(name, me)
    (collection or context.collection).objects.link(obj)
    return obj


def object_name(genome, origin):
    return f"{genome.model} {origin['operator']} {genome_id(genome)[:6]}"


def set_plant(obj, genome, plant, origin):
    """Makes `obj` the plant `plant` grown from `genome`; `origin` holds its operator,
    parents (ids), generation and the lineage it inherits."""
    gid = genome_id(genome)
    for key in ("sylva_archive_id", "sylva_archive"):  # a new plant: not that archive row
        obj.pop(key, None)
    obj[GENOME] = genome.to_json()
    obj[MODEL] = genome.model
    obj[ID] = gid
    obj[OPERATOR] = origin["operator"]
    obj[PARENTS] = json.dumps(origin.get("parents", []))
    obj[GENERATION] = origin.get("generation", 0)
    lineage = dict(origin.get("lineage", {}))
    lineage[gid] = {
        "operator": origin["operator"],
        "parents": origin.get("parents", []),
        "generation": origin.get("generation", 0),
    }
    if len(lineage) > LINEAGE_MAX:
        newest = sorted(lineage.items(), key=lambda kv: kv[1]["generation"], reverse=True)
        lineage = dict(newest[:LINEAGE_MAX])
    obj[LINEAGE] = json.dumps(lineage, sort_keys=True)
    obj[VERSION] = sylva().__version__
    _show(obj, plant)


def _show(obj, plant):
    obj[SEED] = plant.seed if plant.seed <= INT_MAX else str(plant.seed)
    if obj.sylva.own_seed:
        # So that unticking "Genome's Seed" starts from the seed it grew with (PlantMaker's
        # random genomes carry 64-bit seeds, which Blender's 32-bit field cannot hold).
        with quiet():
            obj.sylva.seed = plant.seed % (INT_MAX + 1)
    plantmesh.fill_mesh(obj.data, plant)
    obj.sylva.error = ""
    apply_detail(obj)


def lineage_of(obj):
    try:
        return json.loads(obj.get(LINEAGE, "{}"))
    except ValueError:
        return {}


def genome_of(obj):
    """The genome a plant object holds (its custom property, perhaps edited by hand)."""
    return sylva().Genome.from_json(obj[GENOME], source=GENOME)


def regrow(obj):
    """Grows `obj` again from its custom properties and settings. Errors are kept in
    obj.sylva.error, which the panel shows, and raised."""
    try:
        genome = genome_of(obj)
        plant = grow(genome, grow_options(settings_of(obj.sylva), genome))
    except Exception as e:
        obj.sylva.error = f"{type(e).__name__}: {e}"
        raise
    if genome.to_json() != obj[GENOME]:
        obj[GENOME] = genome.to_json()  # normalised, so the id stays the file's hash
    obj[ID] = genome_id(genome)
    obj[MODEL] = genome.model
    _show(obj, plant)
    return plant


def apply_detail(obj):
    """Detail below 1 keeps that share of the triangles through a Decimate modifier (the
    package does not take Sylva's mesh options yet); 1 removes the modifier."""
    detail = obj.sylva.detail
    mod = obj.modifiers.get(DETAIL_MODIFIER)
    if detail >= 0.999:
        if mod is not None:
            obj.modifiers.remove(mod)
        return
    if mod is None:
        mod = obj.modifiers.new(DETAIL_MODIFIER, "DECIMATE")
    mod.ratio = detail


# Breeding ---------------------------------------------------------------------------------

# PlantMaker's crossover level (the paper's Depth button for crossover); the other models
# cross as their configs' defaults say.
CROSS_LEVEL = {"plantmaker": ("crossover", ["low", "medium", "high"])}


def _variant(job):
    """One child, grown: (genome, plant, parent positions) or the error of the last try.
    Runs on a worker thread: sylva only, no bpy."""
    kind, parents, depth, seed, settings = job
    s = sylva()
    error = None
    for attempt in range(TRIES):
        base = seed * 1000 + attempt * 10
        try:
            if kind == "mutate":
                child = parents[0]
                # Depth k: the model's own mutation applied k times (the paper's Depth: a
                # higher value, a stronger mutation), for every model alike.
                for d in range(depth):
                    child = child.mutate(base + d)
                used = [0]
            else:
                level = None
                if parents[0].model in CROSS_LEVEL:
                    name, levels = CROSS_LEVEL[parents[0].model]
                    level = {name: levels[min(depth, len(levels)) - 1]}
                child, used = s.cross(parents, base, settings=level)
            plant = grow(child, grow_options(settings, child))
        except Exception as e:
            error = f"{type(e).__name__}: {e}"
            continue
        if len(plant.mesh.indices):
            return child, plant, used
        error = "grew nothing (no triangles)"
    return None, None, error


def breed(jobs):
    """Grows the children of `jobs` on all cores (growth releases the GIL), yielding each
    in order as soon as it and those before it have grown."""
    with ThreadPoolExecutor(max_workers=min(len(jobs), os.cpu_count() or 1)) as pool:
        yield from pool.map(_variant, jobs)


def brood_collection(context, create=True):
    collection = bpy.data.collections.get(BROOD)
    if collection is None and create:
        collection = bpy.data.collections.new(BROOD)
        context.scene.collection.children.link(collection)
    return collection


def brood(context):
    """The plants of the breeding grid by cell, or {} when there is none."""
    collection = brood_collection(context, create=False)
    if collection is None:
        return {}
    return {obj[CELL]: obj for obj in collection.objects if is_plant(obj) and CELL in obj}


def spacing(plants, at_least=0.3):
    """Metres between grid cells: the widest plant's footprint and a fifth more."""
    widest = at_least
    for plant in plants:
        (x0, _y0, z0), (x1, _y1, z1) = plant.bounds
        widest = max(widest, x1 - x0, z1 - z0)
    return 1.2 * widest


# -- The genome's numbers as sliders (sylva.schema) --------------------------------------------
# The Genome panel shows each number of a plant's genome as its model's schema describes it.
# A change writes the genome (checked: a value out of its field's range is refused, naming
# the field, the range and the value) and regrows the plant once the changes rest.

REGROW_DELAY = 0.1  # seconds after the last change
_waiting = set()  # names of plant objects whose genome changed and which have not regrown


def number_fields(genome):
    """(path, spec) of each number or whole-number field of `genome`, every list item's
    (`branches[0].waves`, `branches[1].waves`, ...), in the schema's order."""
    data = genome.to_dict()
    found = []
    for spec in sylva().schema(genome.model)["fields"]:
        if spec["kind"] in ("number", "integer"):
            found += [(path, spec) for path in _expand(spec["path"], data)]
    return found


def _expand(path, data, at=""):
    head, _, rest = path.partition(".")
    if head.endswith("[]"):
        name = head[:-2]
        for i, item in enumerate(data.get(name, []) if isinstance(data, dict) else []):
            here = f"{at}{name}[{i}]"
            yield from (_expand(rest, item, here + ".") if rest else [here])
    elif isinstance(data, dict) and head in data:
        yield from (_expand(rest, data[head], f"{at}{head}.") if rest else [f"{at}{head}"])


def load_fields(obj):
    """Fills obj.sylva.fields from its genome and schema (without regrowing)."""
    genome = genome_of(obj)
    with quiet():
        obj.sylva.fields.clear()
        for path, spec in number_fields(genome):
            item = obj.sylva.fields.add()
            item.name = item.path = path  # `name` is what obj.sylva.fields[path] finds
            item.group = spec["group"]
            item.meaning = spec["meaning"]
            item.whole = spec["kind"] == "integer"
            item.low, item.high = float(spec["min"]), float(spec["max"])
            item.soft_low, item.soft_high = float(spec["soft_min"]), float(spec["soft_max"])
            item.log = bool(spec.get("log"))
            item.unit = spec["unit"].strip()
            item.shapes = spec["shapes"]
            item.value = float(genome[path])
            item.slider = item.share_of(item.value)
        obj.sylva.fields_of = obj[ID]


def set_field(obj, path, value):
    """Writes one field of obj's genome (checked by the package against the schema and the
    model) and asks for a regrow once changes rest. Errors go to obj.sylva.error and are
    raised; the genome is then unchanged."""
    try:
        genome = genome_of(obj).with_field(path, value)
    except Exception as e:
        obj.sylva.error = f"{type(e).__name__}: {e}"
        raise
    obj[GENOME] = genome.to_json()
    obj.sylva.error = ""
    _waiting.add(obj.name)
    if not bpy.app.timers.is_registered(flush_regrow):
        bpy.app.timers.register(flush_regrow, first_interval=REGROW_DELAY)


def flush_regrow():
    """Regrows every plant whose genome changed since (a timer calls it once changes rest;
    the check calls it directly, as timers do not run without Blender's window)."""
    for name in sorted(_waiting):
        obj = bpy.data.objects.get(name)
        if obj is not None and is_plant(obj):
            try:
                regrow(obj)
                obj.sylva.fields_of = obj[ID]
            except Exception:
                pass  # kept in obj.sylva.error, which the panels show
    _waiting.clear()
    return None  # a timer that runs once
