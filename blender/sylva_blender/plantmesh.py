"""A grown Sylva plant as Blender data: its mesh from the package's numpy arrays, and its
materials (base colours from Sylva's, Sylva's own grey textures multiplied in).

Sylva is Y-up and Blender Z-up: (x, y, z) becomes (x, -z, y), as Blender's glTF importer
turns it, so a plant grown here stands as the same plant's GLB does when imported.
"""

import bpy
import numpy as np

# Material names start with this; the key custom property tells ours from a user's.
MATERIAL_PREFIX = "Sylva "
MATERIAL_KEY = "sylva_material"
IMAGE_KEY = "sylva_texture"

ROUGHNESS = {"bark": 0.85, "root": 0.9, "leaf": 0.5, "flower": 0.45}


def _z_up(a):
    """Y-up (n, 3) float32 to Blender's Z-up, in a new C-contiguous array."""
    out = np.empty(a.shape, dtype=np.float32)
    out[:, 0] = a[:, 0]
    out[:, 1] = -a[:, 2]
    out[:, 2] = a[:, 1]
    return out


def _set(me, name, data_type, domain, field, values):
    """Fills attribute `name` (made if missing) with `values`."""
    found = me.attributes.get(name)
    if found is not None and (found.data_type, found.domain) != (data_type, domain):
        me.attributes.remove(found)
        found = None
    if found is None:
        found = me.attributes.new(name, data_type, domain)
    found.data.foreach_set(field, np.ascontiguousarray(values).ravel())


def fill_mesh(me, plant):
    """Replaces the geometry and material slots of mesh `me` with `plant`'s mesh.

    Reusing the datablock (rather than a new one per growth) keeps linked duplicates and
    modifiers pointing at the plant and leaves no orphan meshes behind each regrowth.
    Returns the number of triangles."""
    m = plant.mesh
    positions, normals, uvs = m.positions, m.normals, m.uvs
    indices, triangle_materials = m.indices, m.triangle_materials
    n, t = len(positions), len(indices)

    me.clear_geometry()
    me.materials.clear()
    if n == 0 or t == 0:
        # A plant that grew nothing (an L-system whose shoot draws nothing): an empty mesh,
        # which has no position or corner attributes to fill.
        me.update()
        return 0
    # Blender 4.2 on keeps a mesh as generic attributes: filling them directly is several
    # times faster than MeshVertex/MeshLoop/MeshPolygon.foreach_set.
    me.vertices.add(n)
    corners = indices.astype(np.int32).ravel()
    _set(me, "position", "FLOAT_VECTOR", "POINT", "vector", _z_up(positions))
    me.loops.add(3 * t)
    _set(me, ".corner_vert", "INT", "CORNER", "value", corners)
    me.polygons.add(t)
    me.polygons.foreach_set("loop_start", np.arange(0, 3 * t, 3, dtype=np.int32))
    _set(me, "material_index", "INT", "FACE", "value", triangle_materials.astype(np.int32))
    uv = me.uv_layers.new(name="UVMap")
    corner_uvs = uvs[corners].astype(np.float32)
    # glTF's v runs down the picture, Blender's up (the glTF importer flips it too).
    corner_uvs[:, 1] = 1.0 - corner_uvs[:, 1]
    uv.data.foreach_set("uv", corner_uvs.ravel())
    me.update(calc_edges=True)
    me.shade_smooth()
    # Sylva's normals are smooth across the seams where its vertices are split for texture
    # coordinates; Blender's own would show the seams.
    if bpy.app.version >= (5, 0, 0):
        # 5.0 takes them as a "free" custom normal attribute: 0.5 ms for the L-system tree
        # rather than the 37 ms of normals_split_custom_set_from_vertices.
        _set(me, "custom_normal", "FLOAT_VECTOR", "POINT", "vector", _z_up(normals))
    else:
        me.normals_split_custom_set_from_vertices(_z_up(normals))

    textures = _texture_images(plant, m.materials)
    known = {mat[MATERIAL_KEY]: mat for mat in bpy.data.materials if MATERIAL_KEY in mat}
    for material in m.materials:
        me.materials.append(material_for(material, textures, known))
    return t


def _key(material):
    # Sylva's names say kind, sRGB colour and texture for PlantMaker, only the kind for the
    # other models: the exact colour keeps two shades that share a name apart.
    return material["name"] + "|" + ",".join(f"{c:.9g}" for c in material["color"])


def material_for(material, textures, known):
    """The Blender material of one of Sylva's (kind, linear RGB colour, texture id),
    shared by every plant that uses it: a conifer's 18 shades of bark are 18 materials
    once in the file, not once per plant or per regrowth. `known`: ours by key."""
    key = _key(material)
    if key in known:
        return known[key]
    mat = bpy.data.materials.new(MATERIAL_PREFIX + material["name"])
    mat[MATERIAL_KEY] = key
    known[key] = mat
    colour = (*material["color"], 1.0)
    mat.diffuse_color = colour  # the Solid and Workbench views show it
    mat.roughness = ROUGHNESS.get(material["kind"], 0.6)
    if mat.node_tree is None:  # Blender 4.x; 5.0 makes the node tree itself
        mat.use_nodes = True
    nodes = mat.node_tree.nodes
    bsdf = next(node for node in nodes if node.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Base Color"].default_value = colour
    bsdf.inputs["Roughness"].default_value = mat.roughness
    image = textures.get(material["texture"])
    if image is not None:
        # Sylva's textures are grey light and shade to multiply the colour by, as glTF's
        # baseColorTexture times baseColorFactor.
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = image
        # Bark repeats along its tube; leaves and petals span their organ once.
        tex.extension = "REPEAT" if material["kind"] in ("bark", "root") else "EXTEND"
        tex.location = (bsdf.location.x - 600, bsdf.location.y)
        mix = nodes.new("ShaderNodeMix")
        mix.data_type = "RGBA"
        mix.blend_type = "MULTIPLY"
        mix.location = (bsdf.location.x - 250, bsdf.location.y)
        mix.inputs[0].default_value = 1.0
        a, b = (s for s in mix.inputs if s.type == "RGBA")
        b.default_value = colour
        result = next(s for s in mix.outputs if s.type == "RGBA")
        links = mat.node_tree.links
        links.new(tex.outputs["Color"], a)
        links.new(result, bsdf.inputs["Base Color"])
    return mat


def _texture_images(plant, materials):
    """Blender images of the texture ids `materials` use, by id, made once per file."""
    wanted = {m["texture"] for m in materials if m["texture"] is not None}
    images = {}
    for image in bpy.data.images:
        tid = image.get(IMAGE_KEY)
        if tid in wanted:
            images[tid] = image
    # Made only the first time an id is met in this file.
    for tid in sorted(wanted - images.keys()):
        import sylva  # the bundled package, imported already to grow the plant

        png = sylva.texture_png(tid)
        image = bpy.data.images.new(f"{MATERIAL_PREFIX}texture {tid}", 8, 8)
        image.pack(data=png, data_len=len(png))
        image.source = "FILE"
        image[IMAGE_KEY] = tid
        images[tid] = image
    return images
