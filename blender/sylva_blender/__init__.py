"""Sylva inside Blender: grow plants from Sylva's genomes as mesh objects, regrow them when a
setting changes, breed them in a 3 by 3 grid, evolve them toward a target and zones placed in
the scene, and make game and film assets of them: a wind rig, levels of detail and forests of
instances (docs/blender.md).

Stands on the `sylva` Python package, bundled as a wheel (blender_manifest.toml); built into
an extension zip by scripts/blender-extension.
"""

import textwrap

import bpy
import math

from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)

from . import archive, evolve, operators, plants

# Blender keeps only pointers to the strings of dynamic enum items: the lists must outlive
# the callback, or the UI shows garbage.
_items = {}


def _model_items(self, context):
    try:
        models = plants.sylva().models()
    except plants.Unavailable:
        models = {}
    items = [(name, name, title) for name, title in models.items()] or [("none", "(Sylva unavailable)", "")]
    _items["models"] = items
    return items


def _example_items(self, context):
    found = plants.examples(self.model)
    items = [(name, name.replace("-", " ").capitalize(), f"examples/{self.model}/{name}.json")
             for name, _ in found]
    # Species presets whose genome is of this model: a genome and how it grows (height,
    # foliage, bark, density), grown with Genome.grow_preset.
    items += [(plants.SPECIES_PREFIX + name, f"{name.replace('-', ' ').capitalize()} (species)",
               f"examples/species/{name}.toml: a species preset, dressed")
              for name, _ in plants.presets(self.model)]
    items = items or [("none", "(no bundled examples)", "")]
    _items[("examples", self.model)] = items
    return items


def _archive_items(self, context):
    items = []
    if self.archive:
        try:
            rows = archive.plants(bpy.path.abspath(self.archive), self.model)
        except archive.ArchiveError as e:
            rows, items = [], [("none", "(not an archive)", str(e))]
        for row, model, operator, session, created in rows:
            where = f"session {session}" if session is not None else "no session"
            items.append((str(row), f"#{row} {operator}", f"{model}, {where}, {created}"))
    items = items or [("none", "(no plants of this model)", "")]
    _items[("archive", self.archive, self.model)] = items
    return items


def _model_changed(self, context):
    found = plants.examples(self.model)
    if found:
        self.example = found[0][0]


class SylvaSceneSettings(bpy.types.PropertyGroup):
    """What Grow Plant grows, and how breeding mutates."""

    model: EnumProperty(name="Model", description="Sylva's model to grow", items=_model_items,
                        update=_model_changed)
    source: EnumProperty(
        name="From",
        items=[
            ("EXAMPLE", "Example", "One of the example genomes bundled with the extension"),
            ("FILE", "File", "A genome file (.json) of any model"),
            ("RANDOM", "Random", "A random genome of the model, drawn from a seed"),
            ("ARCHIVE", "Archive", "A plant of a studio archive (the file of sylva studio --db)"),
        ],
        default="EXAMPLE",
    )
    example: EnumProperty(name="Example", items=_example_items)
    genome_file: StringProperty(
        name="Genome", subtype="FILE_PATH",
        description="A genome file written by Sylva (sylva evolve, the studio, Save Genome)",
    )
    random_seed: IntProperty(name="Seed", min=0, default=1, description="Seed of the random genome")
    archive: StringProperty(
        name="Archive", subtype="FILE_PATH",
        description=("A studio archive (sylva studio --db FILE): plants grow from it, and plants "
                     "bred here are written back with their parents"),
    )
    archive_plant: EnumProperty(name="Plant", items=_archive_items,
                                description="A plant of the archive, newest first")
    archive_record: BoolProperty(name="Record in Archive", default=True,
                                 description="Write plants bred here, and their parents, to the archive")
    depth: IntProperty(
        name="Depth", min=1, max=5, default=1,
        description=("Intensity of breeding (PlantMaker's Depth): Mutate applies the model's "
                     "mutation this many times; Cross of PlantMaker plants uses low, medium or "
                     "high-level crossover for 1, 2, 3 and up"),
    )
    breed_step: IntProperty(name="Breeding Step", min=0, default=0, options={"HIDDEN"},
                            description="Counts breeding steps, so each draws new seeds")
    wind_strength: FloatProperty(name="Strength", min=0.0, max=10.0, default=1.0,
                                 description="Sway of Sylva's wind: 1 is a breeze, 10 a gale")
    wind_period: FloatProperty(name="Period", min=0.5, max=60.0, default=4.0, unit="TIME_ABSOLUTE",
                               description="Seconds of one sway: the clip's length")
    lod_levels: IntProperty(name="Levels", min=2, max=8, default=4,
                            description="Levels of detail, the plant in full first")
    forest_count: IntProperty(name="Plants", min=1, max=100000, default=1000,
                              description="Plants scattered over the ground")
    forest_variants: IntProperty(name="Variants", min=1, max=32, default=8,
                                 description="Different plants: the active one and as many more")
    target: PointerProperty(
        type=bpy.types.Object, name="Target", poll=lambda self, obj: obj.type == "MESH",
        description="A sphere, box, cylinder or cone mesh: the surface the branch ends should reach",
    )
    target_shape: EnumProperty(
        name="Shape",
        items=[
            ("AUTO", "Auto", "The primitive the mesh was added as (Add > Mesh > UV Sphere, Cube, ...)"),
            ("SPHERE", "Sphere", "A sphere, or an ellipsoid when scaled unevenly"),
            ("BOX", "Box", "A box"),
            ("CYLINDER", "Cylinder", "An upright cylinder"),
            ("CONE", "Cone", "An upright cone, its apex at the top"),
        ],
        default="AUTO",
    )
    evolve_branches: IntProperty(name="Branch Ends", min=1, max=200, default=30,
                                 description="Branch ends the plant should have (Poncin's N_target)")
    picture: StringProperty(
        name="Picture", subtype="FILE_PATH",
        description="A picture of the tree (PNG or JPEG), as the active camera sees it: its outline is matched",
    )
    picture_model: EnumProperty(name="Model", items=_model_items,
                                description="The model whose plants are matched to the picture")
    evolve_population: IntProperty(name="Population", min=10, max=100000, default=1000)
    evolve_generations: IntProperty(name="Generations", min=1, max=10000, default=50)
    evolve_seed: IntProperty(name="Seed", min=0, default=1, description="Seed of the run")
    forest_variety: EnumProperty(
        name="Vary By",
        items=[
            ("SEEDS", "Seeds", "The plant's genome grown with other seeds: one species, each plant "
             "its own (PlantMaker plants differ with their seed; the other models grow alike)"),
            ("MUTANTS", "Mutants", "Mutants of the plant: plants that differ in their genes"),
        ],
        default="SEEDS",
    )
    forest_seed: IntProperty(name="Seed", min=0, default=1,
                             description="Seed of the variants, the places, turns and sizes")


def _regrow(self, context):
    if plants.is_quiet():
        return
    obj = self.id_data
    if not plants.is_plant(obj):
        return
    try:
        plants.regrow(obj)
    except Exception:
        pass  # kept in obj.sylva.error, which the Plant panel shows


def _detail(self, context):
    if not plants.is_quiet() and plants.is_plant(self.id_data):
        plants.apply_detail(self.id_data)


def _field_typed(self, context):
    """A field's number typed or dragged: the genome takes it (or refuses it, and the box
    shows the genome's value again), the slider follows."""
    if plants.is_quiet():
        return
    obj = self.id_data
    value = round(self.value) if self.whole else self.value
    try:
        plants.set_field(obj, self.path, value)
    except Exception:
        value = plants.genome_of(obj)[self.path]  # refused: kept in obj.sylva.error
    with plants.quiet():
        self.value = value
        self.slider = self.share_of(value)


def _field_slid(self, context):
    """A field's slider moved: the value at that point of the field's span."""
    if plants.is_quiet():
        return
    value = self.value_at(self.slider)
    with plants.quiet():
        self.value = value
    try:
        plants.set_field(self.id_data, self.path, value)
    except Exception:
        pass  # kept in obj.sylva.error, which the panel shows


class SylvaGenomeField(bpy.types.PropertyGroup):
    """One number of a plant's genome, as its model's schema describes it."""

    path: StringProperty(name="Path", description="The field's path in the genome file")
    group: StringProperty(name="Group")
    meaning: StringProperty(name="Meaning")
    unit: StringProperty(name="Unit")
    whole: BoolProperty(name="Whole")
    log: BoolProperty(name="Logarithmic")
    shapes: BoolProperty(name="Moves the Shape")
    low: FloatProperty(name="Least")
    high: FloatProperty(name="Greatest")
    soft_low: FloatProperty(name="Slider's Least")
    soft_high: FloatProperty(name="Slider's Greatest")
    value: FloatProperty(name="Value", precision=4, update=_field_typed,
                         description="The field's value: type one anywhere in its range")
    slider: FloatProperty(name="Slider", min=0.0, max=1.0, subtype="FACTOR", update=_field_slid,
                          description="Where the value stands in the span plants worth growing lie in")

    def share_of(self, value):
        lo, hi, v = self.soft_low, self.soft_high, min(max(value, self.soft_low), self.soft_high)
        if self.log:
            lo, hi, v = math.log(lo), math.log(hi), math.log(v)
        return (v - lo) / (hi - lo) if hi > lo else 0.0

    def value_at(self, share):
        lo, hi = self.soft_low, self.soft_high
        v = math.exp(math.log(lo) + share * (math.log(hi) - math.log(lo))) if self.log else lo + share * (hi - lo)
        return round(v) if self.whole else float(f"{v:.4g}")


def _leaves(kind):
    return "needles" if kind in ("pine", "spruce", "fir") else "leaves"


class SylvaPlantSettings(bpy.types.PropertyGroup):
    """How a plant object grows; changing any setting regrows it."""

    own_seed: BoolProperty(name="Genome's Seed", default=True, update=_regrow,
                           description="Grow with the seed the genome carries (PlantMaker's seed field)")
    seed: IntProperty(name="Seed", min=0, default=0, update=_regrow,
                      description="The seed to grow with when not the genome's own")
    use_taper: BoolProperty(name="Pipe Taper", default=False, update=_regrow,
                            description="Thicken branches by the pipe model instead of the model's own radii")
    taper: FloatProperty(name="Exponent", min=2.0, max=3.0, default=2.5, update=_regrow,
                         description="Pipe model exponent E: radius grows as (tips above)^(1/E)")
    roots: BoolProperty(name="Roots", default=True, update=_regrow,
                        description="Keep the roots (L-system plants have them)")
    detail: FloatProperty(
        name="Detail", min=0.02, max=1.0, default=1.0, subtype="FACTOR", update=_detail,
        description=("Share of the triangles kept, by a Decimate modifier (1: Sylva's full mesh). "
                     "Thin twigs and leaves go first at low values"),
    )
    # Leaves and bark (Genome.grow's foliage, bark, height and density). The enums' numbers
    # are fixed, as the .blend stores them; an object saved before these existed reads the
    # defaults, which grow it as it grew.
    foliage: EnumProperty(
        name="Foliage", update=_regrow, default="NONE",
        items=[("NONE", "As grown", "The plant's own leaves, as its model grows them", 0)]
        + [(kind, kind.capitalize(), f"{kind.capitalize()} {_leaves(kind)} at their real size, as "
            "alpha-cut cards (give the plant a tree's height)", k + 1)
           for k, kind in enumerate(plants.FOLIAGE_KINDS)],
        description="Leaves or needles of a kind, at their real size, as alpha-cut cards",
    )
    bark: EnumProperty(
        name="Bark", update=_regrow, default="FOLIAGE",
        items=[("FOLIAGE", "Foliage's own", "The foliage kind's own bark (none without foliage)", 0)]
        + [(kind, kind.capitalize(), f"{kind.capitalize()} bark, tiling, with its normal map", k + 1)
           for k, kind in enumerate(plants.BARK_KINDS)],
        description="A tiling bark with its normal map",
    )
    height: FloatProperty(
        name="Height", min=0.0, max=1000.0, soft_max=60.0, default=0.0, unit="LENGTH",
        subtype="DISTANCE", update=_regrow,
        description=("Grow the plant to this height (0: as grown). Leaves keep their real size, "
                     "so a dressed plant wants a tree's height, 12 m say"),
    )
    density: FloatProperty(
        name="Density", min=0.25, max=4.0, default=1.0, update=_regrow,
        description="Leaf cards per metre of twig, as a multiple of the kind's own",
    )
    error: StringProperty(name="Error", default="", description="Why the last growth failed")
    fields: CollectionProperty(type=SylvaGenomeField)
    fields_of: StringProperty(name="Fields Of", default="",
                              description="The genome (its id) the fields were read from")


def _wrapped(layout, text, context, icon="NONE"):
    width = max(20, int((context.region.width if context.region else 300) / 7))
    col = layout.column(align=True)
    for i, line in enumerate(textwrap.wrap(text, width) or [""]):
        col.label(text=line, icon=icon if i == 0 else "BLANK1")
    return col


class _Panel:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Sylva"


class SYLVA_PT_grow(_Panel, bpy.types.Panel):
    bl_label = "Grow"

    def draw(self, context):
        layout = self.layout
        error = plants.import_error()
        if error:
            box = layout.box()
            box.alert = True
            _wrapped(box, error, context, icon="ERROR")
            return
        settings = context.scene.sylva
        layout.prop(settings, "model")
        layout.row().prop(settings, "source", expand=True)
        if settings.source == "EXAMPLE":
            layout.prop(settings, "example")
        elif settings.source == "FILE":
            layout.prop(settings, "genome_file")
        elif settings.source == "ARCHIVE":
            layout.prop(settings, "archive")
            layout.prop(settings, "archive_plant")
        else:
            layout.prop(settings, "random_seed")
        layout.operator("sylva.grow", icon="OUTLINER_OB_MESH")


class SYLVA_PT_plant(_Panel, bpy.types.Panel):
    bl_label = "Plant"

    @classmethod
    def poll(cls, context):
        return plants.is_plant(context.active_object)

    def draw(self, context):
        obj = context.active_object
        group = obj.sylva
        layout = self.layout
        col = layout.column(align=True)
        col.label(text=f"{obj.get(plants.MODEL, '?')} · {len(obj.data.polygons)} triangles")
        col.label(text=f"Genome {obj.get(plants.ID, '?')} · seed {obj.get(plants.SEED, '?')}")
        row = layout.row(align=True)
        row.prop(group, "own_seed")
        sub = row.row(align=True)
        sub.enabled = not group.own_seed
        sub.prop(group, "seed")
        row = layout.row(align=True)
        row.prop(group, "use_taper")
        sub = row.row(align=True)
        sub.enabled = group.use_taper
        sub.prop(group, "taper")
        layout.prop(group, "roots")
        col = layout.column(align=True)
        col.prop(group, "foliage")
        col.prop(group, "bark")
        col.prop(group, "height")
        sub = col.row(align=True)
        sub.enabled = group.foliage != plants.AS_GROWN
        sub.prop(group, "density")
        if group.foliage != plants.AS_GROWN and group.height == 0.0 and obj.dimensions.z < 3.0:
            _wrapped(layout, f"Leaves are at their real size: give the plant a tree's height "
                     f"(it stands {obj.dimensions.z:.2f} m)", context, icon="INFO")
        layout.prop(group, "detail", slider=True)
        if group.error:
            box = layout.box()
            box.alert = True
            _wrapped(box, group.error, context, icon="ERROR")
        row = layout.row(align=True)
        row.operator("sylva.regrow", icon="FILE_REFRESH")
        row.operator("sylva.save_genome", icon="EXPORT")


class SYLVA_PT_genome(_Panel, bpy.types.Panel):
    """The active plant's genome, number by number as its model's schema describes them: a
    slider over the span plants worth growing lie in and a box for any value in range; the
    plant regrows once changes rest, and Ctrl-Z takes a change back."""

    bl_label = "Genome"

    @classmethod
    def poll(cls, context):
        return plants.is_plant(context.active_object)

    def draw(self, context):
        layout = self.layout
        obj = context.active_object
        if obj.sylva.fields_of != obj.get(plants.ID):
            layout.operator("sylva.load_fields", icon="PROPERTIES")
            return
        if obj.sylva.error:
            _wrapped(layout, obj.sylva.error, context, icon="ERROR")
        box, heading = None, None
        for item in obj.sylva.fields:
            index = item.path.split("]")[0].split("[")[1] if "[" in item.path else ""
            group = f"{item.group} {int(index) + 1}" if index else item.group
            if group != heading:
                heading = group
                box = layout.box()
                box.label(text=group.capitalize())
            row = box.row(align=True)
            name = item.path.rsplit(".", 1)[-1].replace("_", " ")
            row.prop(item, "slider", text=name)
            row.prop(item, "value", text=item.unit)
            row.operator("sylva.field_help", text="", icon="INFO").path = item.path


class SYLVA_PT_breed(_Panel, bpy.types.Panel):
    bl_label = "Breed"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.sylva
        layout.prop(settings, "depth")
        if settings.archive:
            layout.prop(settings, "archive_record")
        layout.operator("sylva.breed", icon="MOD_ARRAY")
        favourites = [o for o in context.selected_objects if plants.is_plant(o)]
        grid = plants.brood(context)
        if grid:
            layout.label(text=f"{len(favourites)} favourite(s) selected")
            row = layout.row(align=True)
            row.operator("sylva.mutate", icon="SHADERFX")
            row.operator("sylva.cross", icon="MOD_BOOLEAN")
            layout.operator("sylva.keep", icon="DUPLICATE")
        else:
            layout.label(text="Breed a plant to start a grid")
        obj = context.active_object
        if plants.is_plant(obj):
            box = layout.box()
            box.label(text=f"Generation {obj.get(plants.GENERATION, 0)} · {obj.get(plants.OPERATOR, '?')}")
            parents = obj.get(plants.PARENTS, "[]")
            if parents != "[]":
                _wrapped(box, f"Parents {parents}", context)
            box.label(text=f"{len(plants.lineage_of(obj))} in its lineage")


class SYLVA_PT_assets(_Panel, bpy.types.Panel):
    bl_label = "Assets"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.sylva
        col = layout.column(align=True)
        row = col.row(align=True)
        row.prop(settings, "wind_strength")
        row.prop(settings, "wind_period")
        col.operator("sylva.wind", icon="FORCE_WIND")
        col = layout.column(align=True)
        col.prop(settings, "lod_levels")
        col.operator("sylva.lod", icon="MOD_DECIM")
        col = layout.column(align=True)
        row = col.row(align=True)
        row.prop(settings, "forest_count")
        row.prop(settings, "forest_variants")
        row = col.row(align=True)
        row.prop(settings, "forest_variety", expand=True)
        col.prop(settings, "forest_seed")
        col.operator("sylva.forest", icon="OUTLINER_OB_GROUP_INSTANCE")
        if not plants.is_plant(context.active_object):
            layout.label(text="Make a plant active first")


class SYLVA_PT_evolve(_Panel, bpy.types.Panel):
    bl_label = "Evolve"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.sylva
        col = layout.column(align=True)
        col.prop(settings, "target")
        col.prop(settings, "target_shape")
        col.prop(settings, "evolve_branches")
        row = layout.row(align=True)
        row.label(text="Zones")
        for kind, icon in (("favoured", "ADD"), ("forbidden", "CANCEL"), ("none", "X")):
            row.operator("sylva.mark_zone", text=kind.capitalize() if kind != "none" else "Clear",
                         icon=icon).kind = kind
        zones = evolve.zones_in(context.scene)
        favoured = sum(1 for z in zones if z[evolve.ZONE] == "favoured")
        layout.label(text=f"{favoured} favoured, {len(zones) - favoured} forbidden box(es)")
        col = layout.column(align=True)
        col.prop(settings, "evolve_population")
        col.prop(settings, "evolve_generations")
        col.prop(settings, "evolve_seed")
        if evolve.running():
            layout.operator("sylva.evolve_stop", icon="CANCEL")
        else:
            layout.operator("sylva.evolve", icon="PLAY")
        col = layout.column(align=True)
        col.prop(settings, "picture")
        col.prop(settings, "picture_model")
        if not evolve.running():
            col.operator("sylva.evolve_picture", icon="IMAGE_DATA")
        if evolve.last_status():
            _wrapped(layout, evolve.last_status(), context, icon="INFO")


classes = (
    SylvaSceneSettings,
    SylvaGenomeField,
    SylvaPlantSettings,
    *operators.classes,
    SYLVA_PT_grow,
    SYLVA_PT_plant,
    SYLVA_PT_genome,
    SYLVA_PT_breed,
    SYLVA_PT_evolve,
    SYLVA_PT_assets,
)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.sylva = PointerProperty(type=SylvaSceneSettings)
    bpy.types.Object.sylva = PointerProperty(type=SylvaPlantSettings)


def unregister():
    del bpy.types.Object.sylva
    del bpy.types.Scene.sylva
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
