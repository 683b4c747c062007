"""Imports GLBs with Blender's own glTF importer (bpy) and checks what they must give an artist.
Run by scripts/check-blender; what is checked depends on the file's name:
- NAME-wind.glb: an armature per plant with the `wind` action, the meshes bound to it, vertex
  groups named after joints, materials, and the origin extras as custom properties;
- NAME-lean.glb (with NAME.skeleton.json beside it): lean materials, one per organ kind and
  texture, whose base colour times the imported vertex colours gives back every colour the
  plant's own materials have;
- NAME-lod.glb (a `sylva grow --lod N` scene): objects NAME-lod_LOD0 ... as siblings, each
  with its level's screen coverage among its custom properties, triangles halving, the last
  the impostor (its `lod` custom property says so, its material shows a picture);
- NAME-....-instanced.glb and NAME-....-quantized.glb (forests of variants with
  EXT_mesh_gpu_instancing or KHR_mesh_quantization): compared with NAME-plain.glb beside them
  (the same forest as plain nodes and floats): as many plant objects, sharing as many mesh
  datablocks, each in the same place (its world-space box within a millimetre), and the
  origin extras on each plant or its parent."""
import json
import os
import sys

import bpy


def lean(path):
    """Checks that the colours of a lean-material GLB survive Blender's import."""
    skeleton = json.load(open(path.replace("-lean.glb", ".skeleton.json")))
    wanted = {tuple(m["color"]) for m in skeleton["materials"]}
    meshes = [o for o in bpy.data.objects if o.type == "MESH"]
    problems = []
    shades = set()
    wired = 0
    for material in bpy.data.materials:
        nodes = material.node_tree.nodes if material.node_tree else []
        if any(n.type == "VERTEX_COLOR" and n.outputs["Color"].is_linked for n in nodes):
            wired += 1
    for obj in meshes:
        mesh = obj.data
        if not mesh.color_attributes:
            problems.append(f"{obj.name} has no colour attribute")
            continue
        colours = mesh.color_attributes[0]
        for poly in mesh.polygons:
            material = mesh.materials[poly.material_index]
            factor = next(
                (n.inputs[7].default_value[:3] for n in material.node_tree.nodes if n.label == "Color Factor"),
                (1.0, 1.0, 1.0),
            )
            if colours.domain == "CORNER":
                c = colours.data[poly.loop_indices[0]].color
            else:
                c = colours.data[poly.vertices[0]].color
            shades.add(tuple(round(f * x, 4) for f, x in zip(factor, c[:3])))
    close = lambda a, b: all(abs(x - y) <= 0.004 + 0.02 * y for x, y in zip(a, b))
    missing = [w for w in wanted if not any(close(s, w) for s in shades)]
    strays = [s for s in shades if not any(close(s, w) for w in wanted)]
    if missing:
        problems.append(f"{len(missing)} of the plant's {len(wanted)} colours not found, e.g. {missing[0]}")
    if strays:
        problems.append(f"{len(strays)} imported shades match no plant colour, e.g. {strays[0]}")
    if wired != len(bpy.data.materials):
        problems.append(f"vertex colours wired into {wired} of {len(bpy.data.materials)} materials")
    print(
        f"{path}: {len(meshes)} mesh(es), {len(bpy.data.materials)} materials "
        f"({', '.join(sorted(m.name for m in bpy.data.materials))}), vertex colours wired into {wired}, "
        f"{len(shades)} distinct shades after import for the plant's {len(wanted)} colours: "
        + ("FAILED: " + "; ".join(problems) if problems else "ok")
    )
    return bool(problems)


def lod(path):
    """Checks that a levels-of-detail scene imports as named sibling objects."""
    name = os.path.basename(path)[: -len(".glb")]
    levels = sorted(
        (o for o in bpy.data.objects if o.type == "MESH" and o.name.startswith(f"{name}_LOD")),
        key=lambda o: o.name,
    )
    problems = []
    triangles = []
    coverage = []
    for k, obj in enumerate(levels):
        if obj.name != f"{name}_LOD{k}":
            problems.append(f"object {obj.name} where {name}_LOD{k} was expected")
        if obj.parent is not None and obj.parent.type != "ARMATURE":
            problems.append(f"{obj.name} is not at the root")
        info = obj.get("lod")
        if info is None:
            problems.append(f"{obj.name} has no lod custom property")
        else:
            coverage.append(round(info["screen_coverage"], 4))
        obj.data.calc_loop_triangles()
        triangles.append(len(obj.data.loop_triangles))
    if len(levels) < 3:
        problems.append(f"{len(levels)} level objects")
    # The last is the impostor: crossed cards whose material shows the plant's picture.
    impostor = levels[-1] if levels else None
    pictured = impostor is not None and any(
        n.type == "TEX_IMAGE" and n.image is not None
        for m in impostor.data.materials
        if m and m.node_tree
        for n in m.node_tree.nodes
    )
    if impostor is None or not (impostor.get("lod") or {}).get("impostor") or not pictured:
        problems.append("the last level is not an impostor showing a picture")
    if any(b > a for a, b in zip(triangles, triangles[1:])):
        problems.append(f"triangles do not fall: {triangles}")
    if coverage != sorted(coverage, reverse=True):
        problems.append(f"coverage does not fall: {coverage}")
    print(
        f"{path}: {len(levels)} level objects ({', '.join(o.name for o in levels)}), "
        f"triangles {triangles}, screen coverage {coverage}: "
        + ("FAILED: " + "; ".join(problems) if problems else "ok")
    )
    return bool(problems)


def forest_summary():
    """The imported plants: each mesh object's world-space box, the mesh datablocks they
    share, the empties, and the plants whose origin extras (seed) are on them or a parent."""
    plants = [o for o in bpy.data.objects if o.type == "MESH"]
    boxes = []
    for obj in plants:
        world = [obj.matrix_world @ v.co for v in obj.data.vertices]
        boxes.append(tuple(round(f(c[k] for c in world), 4) for f in (min, max) for k in range(3)))
    extras = sum(1 for o in plants if "seed" in o.keys() or (o.parent and "seed" in o.parent.keys()))
    empties = sum(1 for o in bpy.data.objects if o.type == "EMPTY")
    return sorted(boxes), len({o.data.name for o in plants}), empties, extras


def forest(path):
    """Checks an instanced or quantised forest against the plain float one beside it."""
    name = os.path.basename(path)
    reference = os.path.join(os.path.dirname(path), name.split("-")[0] + "-plain.glb")
    boxes, shared, empties, extras = forest_summary()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=reference)
    want, want_shared, _, _ = forest_summary()
    problems = []
    if len(boxes) != len(want):
        problems.append(f"{len(boxes)} plant objects, {len(want)} in {reference}")
    if shared != want_shared:
        problems.append(f"{shared} mesh datablocks, {want_shared} in {reference}")
    worst = max((abs(a - b) for x, y in zip(boxes, want) for a, b in zip(x, y)), default=0.0)
    if worst > 1e-3:
        problems.append(f"a plant's box is {worst:.3g} m away from its place in {reference}")
    if extras != len(boxes):
        problems.append(f"origin extras on {extras} of {len(boxes)} plants")
    print(
        f"{path}: {len(boxes)} plant objects sharing {shared} mesh datablocks ({want_shared} in "
        f"{os.path.basename(reference)}), {empties} empties, every box within {worst:.2g} m of the "
        f"plain forest's, origin extras on {extras}: "
        + ("FAILED: " + "; ".join(problems) if problems else "ok")
    )
    return bool(problems)


failed = False
for path in sys.argv[1:]:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
    if path.endswith("-lean.glb"):
        failed = lean(path) or failed
        continue
    if path.endswith("-lod.glb"):
        failed = lod(path) or failed
        continue
    if path.endswith(("-instanced.glb", "-quantized.glb")):
        failed = forest(path) or failed
        continue
    objects = list(bpy.data.objects)
    armatures = [o for o in objects if o.type == "ARMATURE"]
    # The importer draws bones with a shared shape mesh (an icosphere); it is not a plant.
    shapes = {pb.custom_shape for a in armatures for pb in a.pose.bones if pb.custom_shape}
    meshes = [o for o in objects if o.type == "MESH" and o not in shapes]
    bound = [m for m in meshes if any(mod.type == "ARMATURE" and mod.object for mod in m.modifiers)]
    actions = [a.name for a in bpy.data.actions]
    groups = max((len(m.vertex_groups) for m in meshes), default=0)
    bones = max((len(a.data.bones) for a in armatures), default=0)
    extras = [m for m in meshes if "genome" in m.keys() or (m.parent and "genome" in m.parent.keys())]
    # Blender names actions after the clip (and, in 4.x and later, the object it drives).
    wind = [a for a in actions if a.startswith("wind")]
    moved = 0
    if armatures and wind:
        arm = armatures[0]
        scene = bpy.context.scene
        scene.frame_set(int(scene.frame_start))
        start = [b.matrix.copy() for b in arm.pose.bones]
        scene.frame_set(int(scene.frame_start + (scene.frame_end - scene.frame_start) * 0.37))
        later = [b.matrix.copy() for b in arm.pose.bones]
        moved = sum(1 for a, b in zip(start, later) if (a.to_quaternion().rotation_difference(b.to_quaternion())).angle > 1e-4)
    problems = []
    if not armatures:
        problems.append("no armature")
    if not wind:
        problems.append(f"no wind action (actions: {actions})")
    if len(bound) != len(meshes) or not meshes:
        problems.append(f"{len(meshes) - len(bound)} of {len(meshes)} meshes not bound to an armature")
    if moved == 0:
        problems.append("no bone moves along the action")
    if not extras:
        problems.append("no origin extras")
    print(
        f"{path}: {len(armatures)} armature(s), {bones} bones, {len(meshes)} mesh(es) bound, "
        f"{groups} vertex groups, {len(bpy.data.materials)} materials, actions {sorted(set(a.split('_')[0] for a in actions))}, "
        f"{moved} bones moved at 37% of the clip, extras on {len(extras)} mesh(es): "
        + ("FAILED: " + "; ".join(problems) if problems else "ok")
    )
    failed = failed or bool(problems)
sys.exit(1 if failed else 0)
