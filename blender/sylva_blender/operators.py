"""The Sylva tab's operators: grow, regrow, save a genome, breed nine variants, and mutate or
cross the favourites. Every one that changes the scene is REGISTER and UNDO, so Ctrl-Z takes
it back as one step; errors are reported naming what was wrong."""

import os
import time

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ExportHelper
from mathutils import Vector

from . import archive, assets, evolve, plants


def _fail(op, message):
    op.report({"ERROR"}, message)
    return {"CANCELLED"}


def _ms(start):
    return f"{(time.perf_counter() - start) * 1000:.0f} ms"


def _active_plant(context):
    obj = context.active_object
    return obj if plants.is_plant(obj) else None


class _OnActivePlant:
    """An operator on the active plant: greyed out without one, one undo step. Subclasses
    say what they do in `run` and what to select in `missing`."""

    bl_options = {"REGISTER", "UNDO"}
    missing = "Select a Sylva plant first"

    @classmethod
    def poll(cls, context):
        return _active_plant(context) is not None

    def execute(self, context):
        start = time.perf_counter()
        obj = _active_plant(context)
        if obj is None:
            return _fail(self, self.missing)
        return self.run(context, obj, start)


class SYLVA_OT_grow(bpy.types.Operator):
    """Grow a plant from the chosen example, genome file or random genome at the 3D cursor"""

    bl_idname = "sylva.grow"
    bl_label = "Grow Plant"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        start = time.perf_counter()
        settings = context.scene.sylva
        try:
            s = plants.sylva()
        except plants.Unavailable as e:
            return _fail(self, str(e))
        model = settings.model
        preset = None  # a species preset's path, grown with Genome.grow_preset
        try:
            if settings.source == "EXAMPLE":
                found = dict(plants.examples(model))
                species = dict(plants.presets(model))
                name = settings.example.removeprefix(plants.SPECIES_PREFIX)
                if settings.example.startswith(plants.SPECIES_PREFIX) and name in species:
                    preset = species[name]
                elif settings.example not in found:
                    return _fail(self, f"No bundled example named '{settings.example}' for {model} "
                                 f"(examples found: {', '.join([*found, *species]) or 'none'})")
                else:
                    genome = s.Genome.load(found[settings.example])
                source = settings.example
                operator = "example"
            elif settings.source == "FILE":
                path = bpy.path.abspath(settings.genome_file)
                if not settings.genome_file:
                    return _fail(self, "Choose a genome file (a .json of any Sylva model, or a "
                                 "species preset .toml) first")
                if not os.path.isfile(path):
                    return _fail(self, f"Genome file not found: {path}")
                if plants.is_preset(path):
                    preset = path
                else:
                    genome = s.Genome.load(path)
                source = path
                operator = "file"
            elif settings.source == "ARCHIVE":
                if not settings.archive:
                    return _fail(self, "Choose a studio archive (the file of sylva studio --db) first")
                path = bpy.path.abspath(settings.archive)
                if settings.archive_plant in ("", "none"):
                    return _fail(self, f"Choose a plant of {os.path.basename(path)} (it has none of {model})")
                row = int(settings.archive_plant)
                genome, seed, operator = archive.plant(path, row)
                source = f"{os.path.basename(path)} plant {row}"
            else:
                genome = s.Genome.random(model, settings.random_seed)
                source = f"random {model} seed {settings.random_seed}"
                operator = "random"
            if preset is not None:
                # The package reads the preset (every field checked, errors naming the file,
                # line and column) and grows it; the object keeps how it grew in its settings.
                plant = plants.grow_preset(preset)
                genome, grown_with = plants.preset_settings(preset)
        except (s.SylvaError, OSError, ValueError, KeyError, archive.ArchiveError) as e:
            return _fail(self, f"Could not read the genome: {e}")  # where in the file and what

        if preset is None:
            grown_with = dict(plants.DEFAULT_SETTINGS)
            if settings.source == "ARCHIVE":
                # The seed the studio grew it with.
                grown_with.update(own_seed=seed == genome.default_seed, seed=seed)
            try:
                plant = plants.grow(genome, plants.grow_options(grown_with, genome))
            except s.SylvaError as e:
                return _fail(self, f"Could not grow {source}: {e}")
        obj = plants.new_object(context, f"{genome.model} {operator}")
        obj.location = context.scene.cursor.location
        if grown_with != plants.DEFAULT_SETTINGS:
            plants.set_settings(obj, grown_with)
        plants.set_plant(obj, genome, plant, {"operator": operator, "generation": 0})
        obj[plants.SOURCE] = source
        if settings.source == "ARCHIVE":
            obj[archive.ARCHIVE_ID], obj[archive.ARCHIVE_PATH] = row, os.path.abspath(path)
        if settings.source == "ARCHIVE":
            named = f"#{row}"
        else:
            named = source if operator == "example" else operator
        obj.name = plants.object_name(genome, {"operator": named})

        for other in context.selected_objects:
            other.select_set(False)
        obj.select_set(True)
        context.view_layer.objects.active = obj
        triangles = len(plant.mesh.indices)
        if triangles == 0:
            self.report({"WARNING"}, f"{source} grew no triangles: try another seed or genome")
        else:
            self.report({"INFO"}, f"Grew {obj.name}: {triangles} triangles in {_ms(start)}")
        if operator == "file" and genome.model != model:
            self.report({"WARNING"},
                        f"The file holds a {genome.model} genome, not {model}: grown as {genome.model}")
        return {"FINISHED"}


class SYLVA_OT_regrow(_OnActivePlant, bpy.types.Operator):
    """Grow the active plant again from its custom properties (after editing its genome JSON)"""

    bl_idname = "sylva.regrow"
    bl_label = "Regrow"

    def run(self, context, obj, start):
        try:
            plants.regrow(obj)
        except Exception as e:
            return _fail(self, f"Could not regrow {obj.name}: {e}")
        return {"FINISHED"}


class SYLVA_OT_load_fields(_OnActivePlant, bpy.types.Operator):
    """Show the active plant's genome number by number, as its model's schema describes it"""

    bl_idname = "sylva.load_fields"
    bl_label = "Edit Genome Fields"

    def run(self, context, obj, start):
        try:
            plants.load_fields(obj)
        except Exception as e:
            return _fail(self, f"Could not read {obj.name}'s genome: {e}")
        self.report({"INFO"}, f"{len(obj.sylva.fields)} fields of {obj.name}'s genome ({_ms(start)})")
        return {"FINISHED"}


class SYLVA_OT_field_help(bpy.types.Operator):
    """What a genome field does, its range and unit"""

    bl_idname = "sylva.field_help"
    bl_label = "About This Field"
    bl_options = {"INTERNAL"}

    path: StringProperty(name="Path")

    @classmethod
    def description(cls, context, properties):
        obj = context.active_object if context else None
        for item in (obj.sylva.fields if plants.is_plant(obj) else []):
            if item.path == properties.path:
                unit = f" {item.unit}" if item.unit else ""
                return (f"{item.path}: {item.meaning} From {item.low:g} to {item.high:g}{unit}"
                        f"{' (moves the shape most)' if item.shapes else ''}")
        return properties.path

    def execute(self, context):
        self.report({"INFO"}, self.description(context, self))
        return {"FINISHED"}


class SYLVA_OT_save_genome(bpy.types.Operator, ExportHelper):
    """Save the active plant's genome as a genome file (`sylva grow FILE` grows it again)"""

    bl_idname = "sylva.save_genome"
    bl_label = "Save Genome"
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})

    @classmethod
    def poll(cls, context):
        return _active_plant(context) is not None

    def execute(self, context):
        obj = _active_plant(context)
        try:
            plants.genome_of(obj).save(self.filepath)
        except Exception as e:
            return _fail(self, f"Could not save the genome of {obj.name} to {self.filepath}: {e}")
        self.report({"INFO"}, f"Saved {self.filepath}")
        return {"FINISHED"}


_copy_settings = plants.copy_settings


def _place(results, target, op):
    """Puts each child into its object as soon as it has grown (while the workers grow the
    next ones); `target(k)` gives the object and origin of child k, made on first need, so
    nothing changes when no child grows. Returns the plants placed, or the last error."""
    placed, failed, error = [], [], None
    for k, (genome, plant, used_or_error) in enumerate(results):
        if genome is None:
            failed.append(k)
            error = used_or_error
            continue
        obj, origin = target(k)
        parents = origin["parents"]
        origin = dict(origin, parents=[parents[i] for i in used_or_error])
        plants.set_plant(obj, genome, plant, origin)
        obj.name = plants.object_name(genome, origin)
        placed.append((k, obj, plant, used_or_error))
    if placed and failed:
        op.report({"WARNING"}, f"{len(failed)} variant(s) kept their old plant (cells "
                  f"{', '.join(str(k + 1) for k in failed)}): {error}")
    return placed, error


def _record(context, op, children):
    """Writes bred plants and their parents to the open studio archive, if one is open and
    recording is on: `children` is [(object, [parent objects])]. A failure is a warning: the
    plants stay in the scene."""
    settings = context.scene.sylva
    if not (settings.archive and settings.archive_record):
        return 0
    path = bpy.path.abspath(settings.archive)
    try:
        return len(archive.record(path, children))
    except (archive.ArchiveError, ValueError, KeyError) as e:  # ValueError: the package's InputError
        op.report({"WARNING"}, f"The bred plants were not written to {path}: {e}")
        return 0


class SYLVA_OT_breed(_OnActivePlant, bpy.types.Operator):
    """Breed nine mutants of the active plant in a 3 by 3 grid beside it (the Sylva Brood
    collection), replacing the grid's plants if there is one"""

    bl_idname = "sylva.breed"
    bl_label = "Breed Nine Variants"
    missing = "Select a Sylva plant to breed from (grow one first)"

    def run(self, context, mother, start):
        if plants.CELL in mother:
            # Breeding from a grid plant would replace the grid it stands in.
            return _fail(self, f"{mother.name} is in the breeding grid: Mutate or Cross there, "
                         "or Keep it and breed from the copy")
        settings = context.scene.sylva
        try:
            genome = plants.genome_of(mother)
        except Exception as e:
            return _fail(self, f"The genome of {mother.name} does not read: {e}")
        step = settings.breed_step
        grow = plants.settings_of(mother.sylva)
        jobs = [("mutate", [genome], settings.depth, step * 9 + k, grow) for k in range(9)]
        collection = plants.brood_collection(context, create=False)
        cells = plants.brood(context)
        origin = {
            "operator": "mutate",
            "parents": [mother[plants.ID]],
            "generation": mother.get(plants.GENERATION, 0) + 1,
            "lineage": plants.lineage_of(mother),
        }

        def target(k):
            nonlocal collection
            if collection is None:
                collection = plants.brood_collection(context)
            obj = cells.get(k) or plants.new_object(context, f"variant {k + 1}", collection)
            obj[plants.CELL] = k
            _copy_settings(mother, obj)
            return obj, origin

        placed, error = _place(plants.breed(jobs), target, self)
        if not placed:
            return _fail(self, f"No variant of {mother.name} grew: {error}")
        recorded = _record(context, self, [(obj, [mother]) for _, obj, _, _ in placed])
        # Laid out once all have grown: the widest sets the spacing.
        footprint = max(mother.dimensions.x, mother.dimensions.y)
        space = max(plants.spacing([plant for _, _, plant, _ in placed]), 1.2 * footprint)
        centre = mother.location + Vector((2.5 * space, 0.0, 0.0))
        for k, obj in plants.brood(context).items():
            obj.location = centre + Vector((((k % 3) - 1) * space, (1 - k // 3) * space, 0.0))
        for obj in context.selected_objects:
            obj.select_set(False)
        settings.breed_step = step + 1
        kept = f"; {recorded} written to the archive" if recorded else ""
        self.report({"INFO"}, f"Bred nine variants of {mother.name} in {_ms(start)}{kept}: "
                    "select favourites, then Mutate or Cross")
        return {"FINISHED"}


class _Favourites:
    bl_options = {"REGISTER", "UNDO"}
    least = 1

    @classmethod
    def poll(cls, context):
        return bool(plants.brood(context))

    def execute(self, context):
        start = time.perf_counter()
        cells = plants.brood(context)
        if not cells:
            return _fail(self, "No breeding grid: select a plant and Breed Nine Variants first")
        favourites = [obj for obj in context.selected_objects if plants.is_plant(obj)]
        if len(favourites) < self.least:
            return _fail(self, f"Select at least {self.least} favourite plant(s) to {self.verb}")
        targets = [obj for _, obj in sorted(cells.items()) if not obj.select_get()]
        if not targets:
            return _fail(self, f"All nine are selected: select only the favourites to {self.verb}; "
                         "the others are replaced")
        models = sorted({obj[plants.MODEL] for obj in favourites})
        if self.kind == "cross" and len(models) > 1:
            return _fail(self, f"Cross needs favourites of one model; selected: {', '.join(models)}")
        try:
            genomes = [plants.genome_of(obj) for obj in favourites]
        except Exception as e:
            return _fail(self, f"A favourite's genome does not read: {e}")
        settings = context.scene.sylva
        step = settings.breed_step
        lineage = {}
        for obj in favourites:
            lineage.update(plants.lineage_of(obj))
        generation = max(obj.get(plants.GENERATION, 0) for obj in favourites) + 1
        ids = [obj[plants.ID] for obj in favourites]
        jobs, origins = [], []
        for k, obj in enumerate(targets):
            if self.kind == "mutate":
                # Favourites take turns as the mother of the replaced plants.
                parent = k % len(favourites)
                jobs.append(("mutate", [genomes[parent]], settings.depth, step * 9 + k,
                             plants.settings_of(favourites[parent].sylva)))
                parents = [ids[parent]]
            else:
                jobs.append(("cross", genomes, settings.depth, step * 9 + k,
                             plants.settings_of(favourites[0].sylva)))
                parents = ids
            origins.append({"operator": self.kind, "parents": parents,
                            "generation": generation, "lineage": lineage})
        def target(k):
            _copy_settings(favourites[k % len(favourites)], targets[k])
            return targets[k], origins[k]

        placed, error = _place(plants.breed(jobs), target, self)
        if not placed:
            return _fail(self, f"No child grew: {error}")
        if self.kind == "mutate":
            parents = [(obj, [favourites[k % len(favourites)]]) for k, obj, _, _ in placed]
        else:
            parents = [(obj, [favourites[i] for i in used]) for _, obj, _, used in placed]
        _record(context, self, parents)
        settings.breed_step = step + 1
        self.report({"INFO"}, f"{self.verb.capitalize()}: {len(targets)} new plants from "
                    f"{len(favourites)} favourite(s) in {_ms(start)}")
        return {"FINISHED"}


class SYLVA_OT_mutate(_Favourites, bpy.types.Operator):
    """Replace the grid plants that are not selected by mutants of the selected favourites"""

    bl_idname = "sylva.mutate"
    bl_label = "Mutate"
    kind = "mutate"
    verb = "mutate"


class SYLVA_OT_cross(_Favourites, bpy.types.Operator):
    """Replace the grid plants that are not selected by children of all the selected favourites"""

    bl_idname = "sylva.cross"
    bl_label = "Cross"
    kind = "cross"
    verb = "cross"
    least = 2


class SYLVA_OT_keep(bpy.types.Operator):
    """Copy the active grid plant out of the grid, beside it, as a plant of its own"""

    bl_idname = "sylva.keep"
    bl_label = "Keep"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        obj = _active_plant(context)
        return obj is not None and plants.CELL in obj

    def execute(self, context):
        obj = _active_plant(context)
        if obj is None or plants.CELL not in obj:
            return _fail(self, "Make a plant of the breeding grid active to keep it")
        copy = obj.copy()
        copy.data = obj.data.copy()  # its own mesh: the grid's will be replaced
        del copy[plants.CELL]
        context.scene.collection.objects.link(copy)
        copy.location = obj.location + Vector((0.0, -3.0 * max(obj.dimensions.x, obj.dimensions.y, 0.3), 0.0))
        for other in context.selected_objects:
            other.select_set(False)
        copy.select_set(True)
        context.view_layer.objects.active = copy
        self.report({"INFO"}, f"Kept {copy.name}")
        return {"FINISHED"}


class SYLVA_OT_wind(_OnActivePlant, bpy.types.Operator):
    """Rig the active plant for wind: Sylva's armature (one bone per joint) with its looping
    clip as the action, played over the scene's frames, and the skinned plant as its child;
    the plant itself is hidden"""

    bl_idname = "sylva.wind"
    bl_label = "Add Wind"
    missing = "Select a Sylva plant to rig for wind"

    def run(self, context, obj, start):
        settings = context.scene.sylva
        try:
            armature, mesh, info = assets.wind(context, obj, settings.wind_strength, settings.wind_period)
        except Exception as e:
            return _fail(self, f"Could not rig {obj.name} for wind: {e}")
        for other in context.selected_objects:
            other.select_set(False)
        armature.select_set(True)
        context.view_layer.objects.active = armature
        left_out = f" ({info['left_out']} finer joints left out)" if info["left_out"] else ""
        self.report({"INFO"}, f"Wind on {obj.name}: {info['joints']} bones{left_out}, a "
                    f"{info['period']:g} s clip looping over the scene, in {_ms(start)}")
        return {"FINISHED"}


class SYLVA_OT_lod(_OnActivePlant, bpy.types.Operator):
    """Make the active plant's levels of detail: a collection of NAME_LOD0 (the plant in full)
    to NAME_LODn objects of falling triangle counts, as game engines import them"""

    bl_idname = "sylva.lod"
    bl_label = "Levels of Detail"
    missing = "Select a Sylva plant to make levels of detail of"

    def run(self, context, obj, start):
        try:
            levels = assets.lods(context, obj, context.scene.sylva.lod_levels)
        except Exception as e:
            return _fail(self, f"Could not make levels of detail of {obj.name}: {e}")
        counts = ", ".join(str(len(lod.data.polygons)) for lod in levels)
        self.report({"INFO"}, f"{len(levels)} levels of {obj.name} ({counts} triangles) in {_ms(start)}")
        return {"FINISHED"}


class SYLVA_OT_forest(_OnActivePlant, bpy.types.Operator):
    """Scatter a forest of the active plant and its variants over the other selected mesh (the
    ground), as collection instances that share the variants' meshes"""

    bl_idname = "sylva.forest"
    bl_label = "Plant Forest"
    missing = "Make a Sylva plant active, with the ground mesh also selected"

    def run(self, context, obj, start):
        grounds = [o for o in context.selected_objects
                   if o is not obj and o.type == "MESH" and not plants.is_plant(o)]
        if len(grounds) != 1:
            return _fail(self, "Select one ground mesh besides the active plant "
                         f"(selected: {len(grounds)} meshes that are not plants)")
        settings = context.scene.sylva
        try:
            woods, kinds, alike = assets.forest(context, obj, grounds[0], settings.forest_count,
                                                settings.forest_variants, settings.forest_seed,
                                                settings.forest_variety)
        except Exception as e:
            return _fail(self, f"Could not plant a forest of {obj.name} on {grounds[0].name}: {e}")
        note = "" if len(kinds) == settings.forest_variants else \
            f" ({settings.forest_variants - len(kinds)} variant(s) did not grow)"
        self.report({"INFO"}, f"{len(woods.objects)} plants of {len(kinds)} variants{note} on "
                    f"{grounds[0].name} in {_ms(start)}")
        if alike:
            self.report({"WARNING"}, f"{obj[plants.MODEL]} plants grow alike whatever the seed: "
                        "choose Mutants for variants that differ")
        return {"FINISHED"}


class SYLVA_OT_mark_zone(bpy.types.Operator):
    """Mark the selected meshes as boxes of space the plant should fill with leaves
    (favoured) or keep out of (forbidden), or clear the mark"""

    bl_idname = "sylva.mark_zone"
    bl_label = "Mark Zone"
    bl_options = {"REGISTER", "UNDO"}
    kind: bpy.props.EnumProperty(items=[("favoured", "Favoured", ""), ("forbidden", "Forbidden", ""),
                                        ("none", "Clear", "")])

    def execute(self, context):
        boxes = [o for o in context.selected_objects if o.type == "MESH" and not plants.is_plant(o)]
        if not boxes:
            return _fail(self, "Select the meshes (boxes) to mark; plants cannot be zones")
        for box in boxes:
            if self.kind == "none":
                box.pop(evolve.ZONE, None)
                box.display_type, box.hide_render = "TEXTURED", False
            else:
                # Seen through in the viewport, left out of renders: a guide, not scenery.
                box[evolve.ZONE] = self.kind
                box.display_type, box.hide_render = "WIRE", True
        what = "cleared" if self.kind == "none" else f"marked {self.kind}"
        self.report({"INFO"}, f"{len(boxes)} box(es) {what}: {', '.join(b.name for b in boxes)}")
        return {"FINISHED"}


def _start(op, context, begin):
    """Starts a run with `begin()` (which returns the object that shows its best plant),
    makes that object active and has Blender's timer show the run's progress. Returns the
    operator's CANCELLED result on failure, None on success."""
    try:
        obj = begin()
    except (evolve.SceneError, plants.Unavailable) as e:
        return _fail(op, str(e))
    except Exception as e:  # the package refusing the config or picture: it names what and why
        return _fail(op, f"Could not start the run: {e}")
    bpy.app.timers.register(evolve.tick, first_interval=0.1)
    for other in context.selected_objects:
        other.select_set(False)
    obj.select_set(True)
    context.view_layer.objects.active = obj
    return None


class SYLVA_OT_evolve(bpy.types.Operator):
    """Evolve Poncin's automata toward the target mesh (branch ends on its surface) and the
    marked zones (leaves in favoured boxes, none in forbidden ones), in the background: the
    best plant so far stands at the 3D cursor, progress shows in the status bar"""

    bl_idname = "sylva.evolve"
    bl_label = "Evolve Toward Target"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        settings = context.scene.sylva
        target = settings.target
        if target is None or target.type != "MESH":
            return _fail(self, "Choose a target: a sphere, box, cylinder or cone mesh placed and "
                         "scaled where the plant's branch ends should be")
        zones = evolve.zones_in(context.scene)
        failed = _start(self, context, lambda: evolve.begin(
            context, target, settings.target_shape, zones, settings.evolve_generations,
            settings.evolve_population, settings.evolve_seed, settings.evolve_branches))
        if failed:
            return failed
        self.report({"INFO"}, f"Evolving toward {target.name} and {len(zones)} zone(s): "
                    f"{settings.evolve_generations} generations of {settings.evolve_population} "
                    "plants in the background; progress in the status bar")
        return {"FINISHED"}


class SYLVA_OT_evolve_picture(bpy.types.Operator):
    """Evolve plants of the chosen model whose outline matches the reference picture, seen
    from the active camera, in the background: the best plant so far stands at the 3D cursor
    facing the camera, progress in the status bar"""

    bl_idname = "sylva.evolve_picture"
    bl_label = "Evolve Toward Picture"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        settings = context.scene.sylva
        path = bpy.path.abspath(settings.picture) if settings.picture else ""
        if not path:
            return _fail(self, "Choose a reference picture (PNG or JPEG) of the tree, as the active camera sees it")
        if not os.path.isfile(path):
            return _fail(self, f"Picture not found: {path}")
        failed = _start(self, context, lambda: evolve.begin_picture(
            context, path, settings.picture_model, settings.evolve_generations,
            settings.evolve_population, settings.evolve_seed))
        if failed:
            return failed
        facing = "facing the active camera" if context.scene.camera else "facing -Y (no active camera)"
        self.report({"INFO"}, f"Evolving {settings.picture_model} plants toward the outline of "
                    f"{os.path.basename(path)}, {facing}: progress in the status bar")
        return {"FINISHED"}


class SYLVA_OT_evolve_stop(bpy.types.Operator):
    """Stop the run after the generation under way; the best plant so far stays"""

    bl_idname = "sylva.evolve_stop"
    bl_label = "Stop"

    @classmethod
    def poll(cls, context):
        return evolve.running()

    def execute(self, context):
        evolve.stop()
        return {"FINISHED"}


classes = (
    SYLVA_OT_grow,
    SYLVA_OT_regrow,
    SYLVA_OT_load_fields,
    SYLVA_OT_field_help,
    SYLVA_OT_save_genome,
    SYLVA_OT_breed,
    SYLVA_OT_mutate,
    SYLVA_OT_cross,
    SYLVA_OT_keep,
    SYLVA_OT_wind,
    SYLVA_OT_lod,
    SYLVA_OT_forest,
    SYLVA_OT_mark_zone,
    SYLVA_OT_evolve,
    SYLVA_OT_evolve_picture,
    SYLVA_OT_evolve_stop,
)
