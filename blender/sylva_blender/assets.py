"""Assets for games and films from a plant object: its wind rig (an armature and its action),
its levels of detail (a collection of `NAME_LODn` objects) and forests (collection instances
of its variants scattered over a ground mesh).

Wind and levels of detail come from Sylva's own GLB (the rig and the LOD chain `sylva grow
--wind` and `--lod` write), read by Blender's glTF importer, so the armature, skin weights,
clip and levels are exactly those a game engine gets from the same plant.
"""

import json
import os
import tempfile
from concurrent.futures import ThreadPoolExecutor

import bpy
import numpy as np

from . import plants

WIND_RIG = "sylva_wind_rig"  # on a wind mesh: the JSON of the wind it was grown with
LOD_LEVEL = "sylva_lod"  # on a level of detail: its level, 0 the plant in full
FOREST = "sylva_forest"  # on a forest instance: the plant it is a variant of


def import_glb(context, glb, collection):
    """Imports GLB bytes with Blender's glTF importer into `collection`; returns the new
    objects. The file lives only while importing."""
    before = set(bpy.data.objects)
    fd, path = tempfile.mkstemp(suffix=".glb", prefix="sylva-")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(glb)
        # The importer puts what it makes in the active collection: ours for the import,
        # then the user's again.
        active = context.view_layer.active_layer_collection
        layer = _layer_of(context.view_layer.layer_collection, collection)
        if layer is not None:
            context.view_layer.active_layer_collection = layer
        try:
            bpy.ops.import_scene.gltf(filepath=path)
        finally:
            context.view_layer.active_layer_collection = active
    finally:
        os.remove(path)
    made = [obj for obj in bpy.data.objects if obj not in before]
    for obj in made:
        if collection not in obj.users_collection:
            for other in list(obj.users_collection):
                other.objects.unlink(obj)
            collection.objects.link(obj)
    return made


def _layer_of(layer, collection):
    if layer.collection == collection:
        return layer
    for child in layer.children:
        found = _layer_of(child, collection)
        if found is not None:
            return found
    return None


def _home(context, obj):
    """The collection `obj` is in (the scene's when it is in none)."""
    return obj.users_collection[0] if obj.users_collection else context.scene.collection


def _grow_options(obj):
    genome = plants.genome_of(obj)
    return genome, plants.grow_options(plants.settings_of(obj.sylva), genome)


def _copy_origin(source, target):
    for key in (plants.MODEL, plants.ID, plants.SEED, plants.SOURCE, plants.VERSION):
        if key in source:
            target[key] = source[key]


def wind(context, obj, strength, period):
    """Grows `obj` again with Sylva's wind rig and imports it: an armature with one bone per
    joint and the looping clip as its action, played by an NLA strip repeated over the
    scene's frames, and the skinned mesh as its child. The plant object is hidden (kept for
    regrowing); a rig made before for it is replaced. Returns (armature, mesh, info)."""
    genome, options = _grow_options(obj)
    plant = genome.grow(wind=strength, wind_period=period, **options)
    if plant.segments == 0:
        raise ValueError(f"{obj.name} grew no branches to rig for wind")
    info = plant.wind
    for old in [o for o in bpy.data.objects if o.get(WIND_RIG + "_of") == obj.name]:
        _remove_rig(old)
    made = import_glb(context, plant.glb(), _home(context, obj))
    armature = next(o for o in made if o.type == "ARMATURE")
    mesh = next(o for o in made if o.type == "MESH" and o.parent == armature)
    # The importer shapes bones with a mesh of its own: Blender's plain bones instead.
    for bone in armature.pose.bones:
        bone.custom_shape = None
    for other in made:
        if other not in (armature, mesh):
            bpy.data.objects.remove(other)
    armature.name = f"{obj.name} wind rig"
    mesh.name = f"{obj.name} wind"
    armature.location = obj.location
    armature.rotation_euler = obj.rotation_euler
    armature.scale = obj.scale
    armature[WIND_RIG + "_of"] = obj.name
    _copy_origin(obj, mesh)
    mesh[WIND_RIG] = f'{{"strength": {strength}, "period": {period}, "joints": {info["joints"]}}}'
    action = armature.animation_data.action
    action.name = f"{obj.name} wind"
    _loop(context.scene, armature, action)
    obj.hide_set(True)
    obj.hide_render = True
    return armature, mesh, info


def _loop(scene, armature, action):
    """Plays `action` from the scene's first frame, repeated until its last, as an NLA strip
    (an action alone plays once)."""
    animation = armature.animation_data
    start, end = action.frame_range
    length = max(end - start, 1.0)
    animation.action = None
    for track in list(animation.nla_tracks):  # the importer's, which plays the clip once
        animation.nla_tracks.remove(track)
    track = animation.nla_tracks.new()
    track.name = "wind"
    strip = track.strips.new("wind", int(scene.frame_start), action)
    frames = max(scene.frame_end - scene.frame_start + 1, length)
    strip.repeat = float(np.ceil(frames / length))


def _remove_rig(armature):
    for child in list(armature.children):
        bpy.data.objects.remove(child)
    bpy.data.objects.remove(armature)


def lods(context, obj, levels):
    """Sylva's chain of `levels` levels of detail of `obj` and its impostor (as `sylva grow
    --lod` writes them), imported as objects `NAME_LOD0` (the plant in full) to
    `NAME_LOD{levels}` (the impostor: crossed cards showing its picture) in a collection
    `NAME_LODs` beside the plant's, standing where the plant stands; levels past the first
    are hidden in the viewport. A chain made before is replaced. Returns the objects."""
    genome, options = _grow_options(obj)
    plant = genome.grow(**options)
    if plant.segments == 0:
        raise ValueError(f"{obj.name} grew nothing to make levels of detail of")
    name = obj.name
    glb = plant.lod_glb(levels, name=name)
    collection_name = f"{name}_LODs"
    old = bpy.data.collections.get(collection_name)
    if old is not None:
        for child in list(old.objects):
            bpy.data.objects.remove(child)
        bpy.data.collections.remove(old)
    collection = bpy.data.collections.new(collection_name)
    _home(context, obj).children.link(collection)
    made = import_glb(context, glb, collection)
    made.sort(key=lambda o: o.name)
    for level, lod in enumerate(made):
        lod.name = f"{name}_LOD{level}"
        lod.location = obj.location
        lod.rotation_euler = obj.rotation_euler
        lod.scale = obj.scale
        _copy_origin(obj, lod)
        lod[LOD_LEVEL] = level
        if level > 0:
            lod.hide_set(True)
    return made


# Forests ------------------------------------------------------------------------------------


def surface_points(context, ground, count, seed):
    """`count` points spread evenly over `ground`'s surface in world space (each triangle
    drawn by its area, a point uniform within it), with the surface normals there; the
    same seed gives the same points."""
    depsgraph = context.evaluated_depsgraph_get()
    evaluated = ground.evaluated_get(depsgraph)
    me = evaluated.to_mesh()
    try:
        me.calc_loop_triangles()
        n, t = len(me.vertices), len(me.loop_triangles)
        if t == 0:
            raise ValueError(f"{ground.name} has no faces to scatter plants on")
        corners = np.empty(n * 3, dtype=np.float64)
        me.vertices.foreach_get("co", corners)
        triangles = np.empty(t * 3, dtype=np.int64)
        me.loop_triangles.foreach_get("vertices", triangles)
    finally:
        evaluated.to_mesh_clear()
    matrix = np.array(ground.matrix_world, dtype=np.float64)
    corners = corners.reshape(n, 3) @ matrix[:3, :3].T + matrix[:3, 3]
    a, b, c = (corners[triangles.reshape(t, 3)[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    area = np.linalg.norm(cross, axis=1)
    if area.sum() <= 0:
        raise ValueError(f"{ground.name}'s faces have no area to scatter plants on")
    rng = np.random.default_rng(seed)
    chosen = rng.choice(t, size=count, p=area / area.sum())
    u, v = rng.random(count), rng.random(count)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    points = a[chosen] + u[:, None] * (b - a)[chosen] + v[:, None] * (c - a)[chosen]
    normals = cross[chosen] / np.maximum(area[chosen], 1e-12)[:, None]
    return points, normals, rng


def forest(context, obj, ground, count, variants, seed, variety="SEEDS", scale_range=(0.8, 1.2)):
    """Scatters `count` plants over `ground`: `variants` plants (the plant itself and, by
    `variety`, its genome grown with other seeds or mutants of it, grown on all cores) each
    in a collection of its own, kept out of the view layer, and one collection instance per
    plant, turned and scaled at random, in a collection `NAME Forest`. Instances share their
    variant's mesh: the forest costs the variants' memory, not the plants'. A forest made
    before for the plant is replaced. Returns (the forest collection, the variant
    collections, whether the seeds made no difference)."""
    name = obj.name
    _remove_forest(name)
    grown = _variants(obj, variants, variety, seed)
    alike = variety == "SEEDS" and len(grown) > 2 and np.array_equal(
        grown[1][1].mesh.positions, grown[2][1].mesh.positions)
    library = bpy.data.collections.new(f"{name} Forest Variants")
    context.scene.collection.children.link(library)
    kinds = []
    origin = {"parents": [obj[plants.ID]], "generation": obj.get(plants.GENERATION, 0) + 1,
              "lineage": plants.lineage_of(obj)}
    for k, (child, plant, own_seed) in enumerate(grown):
        collection = bpy.data.collections.new(f"{name} variant {k + 1}")
        library.children.link(collection)
        if plant is None:
            variant = bpy.data.objects.new(f"{name} variant {k + 1}", obj.data)
        else:
            variant = plants.new_object(context, f"{name} variant {k + 1}", collection)
            plants.copy_settings(obj, variant)
            with plants.quiet():
                if own_seed is not None:
                    variant.sylva.own_seed = False
                    variant.sylva.seed = own_seed
            if own_seed is None:
                plants.set_plant(variant, child, plant, dict(origin, operator="mutate"))
            else:
                plants.set_plant(variant, child, plant, {
                    "operator": obj.get(plants.OPERATOR, "example"),
                    "parents": json.loads(obj.get(plants.PARENTS, "[]")),
                    "generation": obj.get(plants.GENERATION, 0),
                    "lineage": plants.lineage_of(obj)})
        if variant.name not in collection.objects:
            collection.objects.link(variant)
        kinds.append(collection)
    # The variants are instanced, not shown themselves.
    layer = _layer_of(context.view_layer.layer_collection, library)
    if layer is not None:
        layer.exclude = True

    points, _normals, rng = surface_points(context, ground, count, seed)
    which = rng.integers(0, len(kinds), size=count)
    turns = rng.uniform(0.0, 2.0 * np.pi, size=count)
    scales = rng.uniform(scale_range[0], scale_range[1], size=count)
    woods = bpy.data.collections.new(f"{name} Forest")
    context.scene.collection.children.link(woods)
    objects = bpy.data.objects
    link = woods.objects.link
    for i in range(count):
        tree = objects.new(f"{name} tree {i + 1}", None)
        tree.instance_type = "COLLECTION"
        tree.instance_collection = kinds[which[i]]
        tree.location = points[i]
        tree.rotation_euler = (0.0, 0.0, turns[i])
        s = scales[i]
        tree.scale = (s, s, s)
        tree.empty_display_size = 0.2
        tree[FOREST] = name
        link(tree)
    return woods, kinds, alike


def _variants(obj, count, variety, seed):
    """[(genome, plant, seed)] of the forest's variants, the plant itself first (no plant:
    its own mesh is used; no seed: a mutant). Grown on all cores; variants that fail to grow
    are left out."""
    genome = plants.genome_of(obj)
    settings = plants.settings_of(obj.sylva)
    first = [(genome, None, None)]
    if variety == "MUTANTS":
        jobs = [("mutate", [genome], 1, seed * 1000 + k, settings) for k in range(count - 1)]
        return first + [(child, plant, None) for child, plant, _ in plants.breed(jobs) if child is not None]
    options = plants.grow_options(settings, genome)
    seeds = [(seed * 1000 + k) % (plants.INT_MAX + 1) for k in range(1, count)]

    def grow(own):
        try:
            return genome, plants.grow(genome, dict(options, seed=own)), own
        except Exception:
            return None
    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        return first + [v for v in pool.map(grow, seeds) if v is not None]


def _remove_forest(name):
    woods = bpy.data.collections.get(f"{name} Forest")
    if woods is not None:
        for tree in list(woods.objects):
            bpy.data.objects.remove(tree)
        bpy.data.collections.remove(woods)
    library = bpy.data.collections.get(f"{name} Forest Variants")
    if library is not None:
        for collection in list(library.children):
            for variant in list(collection.objects):
                if variant.users_collection == (collection,) and plants.CELL not in variant:
                    bpy.data.objects.remove(variant)
            bpy.data.collections.remove(collection)
        bpy.data.collections.remove(library)
