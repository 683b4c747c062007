"""Imports GLBs with Blender's own glTF importer (bpy) and checks what a wind GLB must give an
artist: an armature per plant with the `wind` action, the meshes bound to it, vertex groups
named after joints, materials, and the origin extras as custom properties. Run by
scripts/check-blender."""
import sys

import bpy

failed = False
for path in sys.argv[1:]:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
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
