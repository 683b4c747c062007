"""Pictures of the Sylva extension at work for docs/blender.md, rendered by bpy headless with
Cycles on the CPU (Eevee and Workbench need a GPU context that bpy has not got without a
display). Called by scripts/blender_extension_check.py --render DIR once the extension is
installed; everything in the scene is grown by the extension's own operators."""

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


def _render(scene, path, samples):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = True
    scene.render.resolution_x, scene.render.resolution_y = 960, 600
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.compression = 100  # smallest file: these go into docs/
    scene.render.filepath = path
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    print(f"rendered {path} ({samples} samples, Cycles CPU) in {time.perf_counter() - start:.1f} s")


def render(out, plants):
    os.makedirs(out, exist_ok=True)
    scene = bpy.context.scene
    settings = scene.sylva
    settings.breed_step = 0  # the same pictures whatever the scene went through before

    _clear()
    _stage(scene)
    scene.cursor.location = (0, 0, 0)
    settings.source = "EXAMPLE"
    settings.model = "plantmaker"
    settings.example = "flowering-bush"
    bpy.ops.sylva.grow()
    bush = bpy.context.active_object
    _frame(scene, [bush], elevation=15, azimuth=-30, margin=0.7)
    _render(scene, os.path.join(out, "blender-grow.png"), 48)

    _clear()
    _stage(scene)
    settings.example = "conifer"
    bpy.ops.sylva.grow()
    conifer = bpy.context.active_object
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
