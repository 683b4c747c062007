"""Sylva inside Blender: grow plants from Sylva's genomes as mesh objects, regrow them when a
setting changes, and breed them in a 3 by 3 grid (docs/blender.md).

Stands on the `sylva` Python package, bundled as a wheel (blender_manifest.toml); built into
an extension zip by scripts/blender-extension.
"""

import textwrap

import bpy
from bpy.props import (
    BoolProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)

from . import operators, plants

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
             for name, _ in found] or [("none", "(no bundled examples)", "")]
    _items[("examples", self.model)] = items
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
        ],
        default="EXAMPLE",
    )
    example: EnumProperty(name="Example", items=_example_items)
    genome_file: StringProperty(
        name="Genome", subtype="FILE_PATH",
        description="A genome file written by Sylva (sylva evolve, the studio, Save Genome)",
    )
    random_seed: IntProperty(name="Seed", min=0, default=1, description="Seed of the random genome")
    depth: IntProperty(
        name="Depth", min=1, max=5, default=1,
        description=("Intensity of breeding (PlantMaker's Depth): Mutate applies the model's "
                     "mutation this many times; Cross of PlantMaker plants uses low, medium or "
                     "high-level crossover for 1, 2, 3 and up"),
    )
    breed_step: IntProperty(name="Breeding Step", min=0, default=0, options={"HIDDEN"},
                            description="Counts breeding steps, so each draws new seeds")


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
    error: StringProperty(name="Error", default="", description="Why the last growth failed")


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
        layout.prop(group, "detail", slider=True)
        if group.error:
            box = layout.box()
            box.alert = True
            _wrapped(box, group.error, context, icon="ERROR")
        row = layout.row(align=True)
        row.operator("sylva.regrow", icon="FILE_REFRESH")
        row.operator("sylva.save_genome", icon="EXPORT")


class SYLVA_PT_breed(_Panel, bpy.types.Panel):
    bl_label = "Breed"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.sylva
        layout.prop(settings, "depth")
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


classes = (
    SylvaSceneSettings,
    SylvaPlantSettings,
    *operators.classes,
    SYLVA_PT_grow,
    SYLVA_PT_plant,
    SYLVA_PT_breed,
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
