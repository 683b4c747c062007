"""Pictures of the Sylva extension at work for docs/blender.md, rendered by bpy headless with
Cycles on the CPU (Eevee and Workbench need a GPU context that bpy has not got without a
display). Called by scripts/blender_extension_check.py --render DIR once the extension is
installed; everything in the scene is grown by the extension's own operators."""

import importlib
import math
import os
import time

import bpy
from mathutils import Vector


def _clear():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    for collection in list(bpy.data.collections):
        bpy.data.collections.remove(collection)


def _stage(scene):
    """A ground, a sun and a sky: enough light to see the materials by."""
    ground_mesh = bpy.data.meshes.new("ground")
    ground_mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    ground = bpy.data.objects.new("ground", ground_mesh)
    ground.scale = (200, 200, 1)
    scene.collection.objects.link(ground)
    soil = bpy.data.materials.new("ground")
    if soil.node_tree is None:
        soil.use_nodes = True
    bsdf = next(n for n in soil.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Base Color"].default_value = (0.16, 0.13, 0.09, 1)
    bsdf.inputs["Roughness"].default_value = 1.0
    ground_mesh.materials.append(soil)

    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 3.5
    sun.data.angle = math.radians(3)
    sun.rotation_euler = (math.radians(40), math.radians(10), math.radians(35))
    scene.collection.objects.link(sun)
    world = scene.world or bpy.data.worlds.new("world")
    scene.world = world
    if world.node_tree is None:
        world.use_nodes = True
    background = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    background.inputs["Color"].default_value = (0.55, 0.65, 0.8, 1)
    background.inputs["Strength"].default_value = 0.8


def _frame(scene, objects, elevation=18.0, azimuth=-35.0, margin=1.15):
    """A camera looking at the objects' bounding box from the given angles, filling it."""
    points = [obj.matrix_world @ Vector(c) for obj in objects for c in obj.bound_box]
    lo = Vector(min(p[i] for p in points) for i in range(3))
    hi = Vector(max(p[i] for p in points) for i in range(3))
    centre = (lo + hi) / 2
    radius = (hi - lo).length / 2
    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    cam.data.lens = 50
    scene.collection.objects.link(cam)
    scene.camera = cam
    fov = cam.data.angle_y if scene.render.resolution_y < scene.render.resolution_x else cam.data.angle_x
    distance = margin * radius / math.sin(fov / 2)
    e, a = math.radians(elevation), math.radians(azimuth)
    direction = Vector((math.sin(a) * math.cos(e), -math.cos(a) * math.cos(e), math.sin(e)))
    cam.location = centre + distance * direction
    cam.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
    cam.data.clip_end = distance * 10


def _render(scene, path, samples, size=(960, 600)):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = True
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.compression = 100  # smallest file: these go into docs/
    scene.render.filepath = path
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    print(f"rendered {path} ({samples} samples, Cycles CPU) in {time.perf_counter() - start:.1f} s")


def _fresh(scene, example):
    """An empty stage with the example of the model chosen (PlantMaker's, unless set)
    grown at the cursor; returns it."""
    _clear()
    _stage(scene)
    scene.sylva.example = example
    bpy.ops.sylva.grow()
    return bpy.context.active_object


def render(out, plants, pictures=None):
    """Renders the pictures into `out`: all of them, or those of `pictures`, a set of
    "extension" (growing, breeding, assets and evolving) and "foliage" (dressed plants)."""
    os.makedirs(out, exist_ok=True)
    if pictures is None or "extension" in pictures:
        _extension(out, plants)
    if pictures is None or "foliage" in pictures:
        foliage(out, plants)


def foliage(out, plants):
    """Dressed plants: the binary oak as a user dresses it (Foliage oak and Height 12 on the
    plant as grown) beside the species oak preset (examples/species/oak.toml, grown from
    File), and a close look into the binary oak's crown: every leaf cut out of its card by
    the atlas's alpha, not a square."""
    scene = bpy.context.scene
    settings = scene.sylva
    scene.cursor.location = (0, 0, 0)
    settings.source, settings.model = "EXAMPLE", "bintree"
    oak = _fresh(scene, "oak")
    oak.sylva.foliage = "oak"
    oak.sylva.height = 12.0
    scene.cursor.location = (19, 6, 0)
    settings.model = "lsystem"  # the preset's genome's
    settings.source, settings.genome_file = "FILE", os.path.abspath("examples/species/oak.toml")
    bpy.ops.sylva.grow()
    species = bpy.context.active_object
    settings.source = "EXAMPLE"
    # Seen through many leaves at once: Cycles stops a path after this many transparent
    # surfaces (8 by default), which would darken the crowns' middles.
    scene.cycles.transparent_max_bounces = 64
    _frame(scene, [oak, species], elevation=6, azimuth=-8, margin=0.62)
    _render(scene, os.path.join(out, "blender-foliage.png"), 48)
    # The close look: a camera 2.5 m from a leafy twig at the binary oak's crown's front.
    points = [oak.matrix_world @ v.co for v in oak.data.vertices]
    top = max(p.z for p in points)
    side = [p for p in points if top * 0.45 < p.z < top * 0.65]
    edge = min(side, key=lambda p: p.y)
    cam = scene.camera
    cam.location = edge + Vector((0.6, -2.5, 0.3))
    cam.rotation_euler = (edge - cam.location).to_track_quat("-Z", "Y").to_euler()
    _render(scene, os.path.join(out, "blender-foliage-leaves.png"), 32, size=(640, 400))


def _extension(out, plants):
    scene = bpy.context.scene
    settings = scene.sylva
    settings.breed_step = 0  # the same pictures whatever the scene went through before

    scene.cursor.location = (0, 0, 0)
    settings.source = "EXAMPLE"
    settings.model = "plantmaker"
    bush = _fresh(scene, "flowering-bush")
    _frame(scene, [bush], elevation=15, azimuth=-30, margin=0.7)
    _render(scene, os.path.join(out, "blender-grow.png"), 48)

    conifer = _fresh(scene, "conifer")
    settings.depth = 1
    bpy.ops.sylva.breed()
    grid = plants.brood(bpy.context)
    _frame(scene, [conifer, *grid.values()], elevation=28, azimuth=-25, margin=0.7)
    _render(scene, os.path.join(out, "blender-breed.png"), 32)

    # Two favourites kept (the grid's first and last cells), the other seven their crosses.
    for obj in bpy.context.selected_objects:
        obj.select_set(False)
    for k in (0, 8):
        grid[k].select_set(True)
    bpy.context.view_layer.objects.active = grid[0]
    bpy.ops.sylva.cross()
    _render(scene, os.path.join(out, "blender-cross.png"), 32)

    # Wind: the conifer as grown, and beside it its wind rig in a gale, a quarter way into
    # the clip (the sway's far point).
    still = _fresh(scene, "conifer")
    bpy.ops.sylva.grow()
    windy = bpy.context.active_object
    windy.location.x = 1.3 * max(still.dimensions.x, still.dimensions.y)
    bpy.context.view_layer.update()
    settings.wind_strength, settings.wind_period = 8.0, 4.0
    bpy.ops.sylva.wind()
    rig = bpy.context.active_object
    scene.frame_set(scene.frame_start + scene.render.fps)
    bpy.context.view_layer.update()
    _frame(scene, [still, *rig.children], elevation=10, azimuth=0, margin=0.75)
    _render(scene, os.path.join(out, "blender-wind.png"), 32)

    # Levels of detail, laid side by side for the picture (they stand together in a scene).
    bush = _fresh(scene, "flowering-bush")
    settings.lod_levels = 4
    bpy.ops.sylva.lod()
    levels = sorted(bpy.data.collections[f"{bush.name}_LODs"].objects, key=lambda o: o.name)
    bush.hide_render = True
    step = 1.15 * max(bush.dimensions.x, bush.dimensions.y)
    for k, level in enumerate(levels):
        level.hide_set(False)
        level.location.x = k * step
    bpy.context.view_layer.update()
    _frame(scene, levels, elevation=12, azimuth=0, margin=0.62)
    _render(scene, os.path.join(out, "blender-lod.png"), 32)

    # A forest: 600 conifers of 8 variants as instances on a sloping meadow.
    scene.cursor.location = (0, -45, 0)
    conifer = _fresh(scene, "conifer")
    conifer.hide_render = True
    hill_mesh = bpy.data.meshes.new("meadow")
    hill_mesh.from_pydata([(-30, -30, 0), (30, -30, 0), (30, 30, 6), (-30, 30, 6)], [], [(0, 1, 2, 3)])
    hill = bpy.data.objects.new("meadow", hill_mesh)
    scene.collection.objects.link(hill)
    hill_mesh.materials.append(bpy.data.materials["ground"])
    settings.forest_count, settings.forest_variants, settings.forest_seed = 600, 8, 1
    hill.select_set(True)
    bpy.ops.sylva.forest()
    _frame(scene, [hill], elevation=22, azimuth=-20, margin=0.55)
    _render(scene, os.path.join(out, "blender-forest.png"), 24)

    # Evolving toward a sphere under a forbidden box: the target drawn as glass for the
    # picture (in the scene it is any mesh the artist placed).
    _clear()
    _stage(scene)
    scene.cursor.location = (0, 0, 0)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=2.0, location=(0, 0, 4.0), segments=48, ring_count=24)
    ball = bpy.context.active_object
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0, 0, 6.6), scale=(4.0, 4.0, 0.8))
    lid = bpy.context.active_object
    bpy.ops.sylva.mark_zone(kind="forbidden")
    lid.hide_render = False
    lid.display_type = "TEXTURED"
    for obj, colour in ((ball, (0.6, 0.8, 1.0, 1.0)), (lid, (1.0, 0.25, 0.2, 1.0))):
        glass = bpy.data.materials.new(f"{obj.name} glass")
        if glass.node_tree is None:
            glass.use_nodes = True
        bsdf = next(n for n in glass.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
        bsdf.inputs["Base Color"].default_value = colour
        bsdf.inputs["Alpha"].default_value = 0.18
        obj.data.materials.append(glass)
    settings.target, settings.target_shape = ball, "AUTO"
    settings.evolve_population, settings.evolve_generations, settings.evolve_seed = 1000, 60, 1
    bpy.ops.sylva.evolve()
    evolved = bpy.context.active_object
    evolve = importlib.import_module(plants.__name__.rsplit(".", 1)[0] + ".evolve")
    while evolve.tick() is not None:
        time.sleep(0.1)
    print(evolve.last_status())
    _frame(scene, [ball, lid, evolved], elevation=16, azimuth=-20, margin=1.0)
    _render(scene, os.path.join(out, "blender-evolve.png"), 32)

    # Toward a picture: the example outline round.png, matched by binary trees, seen
    # from the camera the run faced them to.
    _clear()
    _stage(scene)
    scene.cursor.location = (0, 0, 0)
    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam.location = (0, -30, 4)
    settings.picture = os.path.abspath("examples/match/round.png")
    settings.picture_model = "bintree"
    settings.evolve_population, settings.evolve_generations, settings.evolve_seed = 100, 30, 1
    bpy.ops.sylva.evolve_picture()
    matched = bpy.context.active_object
    while evolve.tick() is not None:
        time.sleep(0.1)
    print(evolve.last_status())
    bpy.data.objects.remove(cam)
    _frame(scene, [matched], elevation=5, azimuth=0, margin=0.7)
    _render(scene, os.path.join(out, "blender-picture.png"), 32)
