"""A grown Sylva plant as Blender data: its mesh from the package's numpy arrays, and its
materials (base colours from Sylva's, Sylva's own pictures multiplied in: grey textures,
leaf and needle atlases whose alpha cuts the cards out, tiling bark with its normal map).

Sylva is Y-up and Blender Z-up: (x, y, z) becomes (x, -z, y), as Blender's glTF importer
turns it, so a plant grown here stands as the same plant's GLB does when imported.
"""

import bpy
import numpy as np

# Material names start with this; the key custom property tells ours from a user's.
MATERIAL_PREFIX = "Sylva "
MATERIAL_KEY = "sylva_material"
IMAGE_KEY = "sylva_texture"  # on an image of a texture design: its id
PICTURE_KEY = "sylva_picture"  # on an image of any other picture: its name (sylva-leaves-oak)
DESIGN_PREFIX = "sylva-texture-"  # a texture design's picture name: sylva-texture-3
# glTF's alphaMode MASK cutoff, which Sylva's GLBs give their cut-out materials.
ALPHA_CUTOFF = 0.5

UV_MAP = "UVMap"  # the mesh's texture coordinates, which normal maps' tangents follow
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
    uv = me.uv_layers.new(name=UV_MAP)
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

    pictures = _picture_images(m.materials)
    known = {mat[MATERIAL_KEY]: mat for mat in bpy.data.materials if MATERIAL_KEY in mat}
    for material in m.materials:
        me.materials.append(material_for(material, pictures, known))
    return t


def _picture(material):
    """The name of the base-colour picture a Sylva material shows, or None. Packages before
    the dressed surfaces name only the texture design."""
    if "picture" in material:
        return material["picture"]
    texture = material.get("texture")
    return None if texture is None else f"{DESIGN_PREFIX}{texture}"


def _key(material):
    # Sylva's names say kind, sRGB colour and texture for PlantMaker, only the kind for the
    # other models: the exact colour keeps two shades that share a name apart, and the
    # pictures two surfaces that share name and colour (a dressed oak's leaves and bark).
    # A texture design is left out: PlantMaker's names say it (`-t4`), the other models
    # have none, and materials made before the dress keep their keys, so plants of files
    # saved then regrow into the materials they have.
    key = material["name"] + "|" + ",".join(f"{c:.9g}" for c in material["color"])
    picture, normal = _picture(material), material.get("normal_map")
    if picture is not None and picture != f"{DESIGN_PREFIX}{material.get('texture')}":
        key += "|" + picture
    if normal is not None:
        key += "|normal " + normal
    if material.get("cut_out"):
        key += "|cut out"
    return key


def _name(material):
    """`Sylva leaf-4a7f35-t4`, `Sylva leaf-oak-0`; a tiling bark's kind said too (`Sylva bark
    furrowed`), as Sylva names a dressed plant's bark only `bark`."""
    name = MATERIAL_PREFIX + material["name"]
    picture = _picture(material) or ""
    if picture.startswith("sylva-bark-"):
        kind = picture[len("sylva-bark-"):]
        if kind not in name:
            name += " " + kind
    return name


def _is_tiled(material):
    """Bark and roots repeat their picture along the tube; leaves, needles and petals span
    their card or organ once."""
    picture = _picture(material) or ""
    return material["kind"] in ("bark", "root") or picture.startswith("sylva-bark-")


def material_for(material, pictures, known):
    """The Blender material of one of Sylva's (kind, linear RGB colour, pictures), shared by
    every plant that uses it: a conifer's 18 shades of bark are 18 materials once in the
    file, not once per plant or per regrowth. `pictures`: Blender images by picture name;
    `known`: ours by key.

    As Sylva's GLB has it, and Blender's glTF importer makes it: the picture multiplies the
    colour (baseColorTexture x baseColorFactor); a cut-out material's picture alpha, cut at
    0.5 (alphaMode MASK), is the BSDF's Alpha, its faces drawn from both sides
    (doubleSided), dithered in EEVEE (Cycles takes the Alpha as it is); a normal map is a
    tangent-space Normal Map node on the UV map (normalTexture)."""
    key = _key(material)
    if key in known:
        return known[key]
    mat = bpy.data.materials.new(_name(material))
    mat[MATERIAL_KEY] = key
    known[key] = mat
    colour = (*material["color"], 1.0)
    mat.diffuse_color = colour  # the Solid and Workbench views show it
    mat.roughness = ROUGHNESS.get(material["kind"], 0.6)
    if mat.node_tree is None:  # Blender 4.x; 5.0 makes the node tree itself
        mat.use_nodes = True
    nodes = mat.node_tree.nodes
    links = mat.node_tree.links
    bsdf = next(node for node in nodes if node.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Base Color"].default_value = colour
    bsdf.inputs["Roughness"].default_value = mat.roughness
    x, y = bsdf.location.x, bsdf.location.y
    tiled = _is_tiled(material)
    image = pictures.get(_picture(material))
    if image is not None:
        # Sylva's pictures are grey light and shade to multiply the colour by, as glTF's
        # baseColorTexture times baseColorFactor.
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = image
        tex.extension = "REPEAT" if tiled else "EXTEND"
        tex.location = (x - 600, y)
        mix = nodes.new("ShaderNodeMix")
        mix.data_type = "RGBA"
        mix.blend_type = "MULTIPLY"
        mix.location = (x - 250, y)
        mix.inputs[0].default_value = 1.0
        a, b = (s for s in mix.inputs if s.type == "RGBA")
        b.default_value = colour
        result = next(s for s in mix.outputs if s.type == "RGBA")
        links.new(tex.outputs["Color"], a)
        links.new(result, bsdf.inputs["Base Color"])
        if material.get("cut_out"):
            _cut_out(mat, tex, bsdf)
    normal = pictures.get(material.get("normal_map"))
    if normal is not None:
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = normal
        tex.extension = "REPEAT" if tiled else "EXTEND"
        tex.location = (x - 600, y - 600)
        node = nodes.new("ShaderNodeNormalMap")
        node.space = "TANGENT"
        node.uv_map = UV_MAP
        node.location = (x - 250, y - 600)
        links.new(tex.outputs["Color"], node.inputs["Color"])
        links.new(node.outputs["Normal"], bsdf.inputs["Normal"])
    return mat


def _cut_out(mat, tex, bsdf):
    """The picture's alpha cuts the card out: alpha >= 0.5 is kept, the rest is not drawn
    (glTF's MASK, made as Blender's glTF importer makes it: 1 - (alpha < cutoff)), and the
    card shows from both sides."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    frame = nodes.new("NodeFrame")
    frame.label = "Alpha Clip"
    below = nodes.new("ShaderNodeMath")
    below.operation = "LESS_THAN"
    below.inputs[1].default_value = ALPHA_CUTOFF
    below.location = (bsdf.location.x - 450, bsdf.location.y - 300)
    kept = nodes.new("ShaderNodeMath")
    kept.operation = "SUBTRACT"
    kept.inputs[0].default_value = 1.0
    kept.location = (bsdf.location.x - 250, bsdf.location.y - 300)
    below.parent = kept.parent = frame
    links.new(tex.outputs["Alpha"], below.inputs[0])
    links.new(below.outputs[0], kept.inputs[1])
    links.new(kept.outputs[0], bsdf.inputs["Alpha"])
    # One-sided cards drawn from both sides, in the viewport, renders and shadows.
    mat.use_backface_culling = False
    if hasattr(mat, "use_backface_culling_shadow"):
        mat.use_backface_culling_shadow = False
    if hasattr(mat, "surface_render_method"):
        # EEVEE (4.2 on): dithered, the render method for alpha-clipped surfaces (blended
        # sorts them, and is for glass); its shadows follow the alpha too. Cycles honours
        # the BSDF's Alpha whatever these say. `blend_method` is deprecated since 4.2.
        mat.surface_render_method = "DITHERED"
        if hasattr(mat, "use_transparent_shadow"):
            mat.use_transparent_shadow = True
    else:
        mat.blend_method = "CLIP"


def _picture_images(materials):
    """Blender images of the pictures `materials` show (base colours and normal maps), by
    name, each made once per file: packed into the .blend from the package's PNG. Texture
    designs keep the images earlier versions made of them (`Sylva texture 4`)."""
    wanted = set()
    for m in materials:
        wanted.update(name for name in (_picture(m), m.get("normal_map")) if name is not None)
    images = {}
    for image in bpy.data.images:
        name = image.get(PICTURE_KEY)
        if name is None and image.get(IMAGE_KEY) is not None:
            name = f"{DESIGN_PREFIX}{image[IMAGE_KEY]}"
        if name in wanted:
            images[name] = image
    # Made only the first time a picture is met in this file.
    for name in sorted(wanted - images.keys()):
        import sylva  # the bundled package, imported already to grow the plant

        if name.startswith(DESIGN_PREFIX):
            tid = int(name[len(DESIGN_PREFIX):])
            png = sylva.texture_png(tid)
            image = bpy.data.images.new(f"{MATERIAL_PREFIX}texture {tid}", 8, 8)
            image[IMAGE_KEY] = tid
        else:
            png = sylva.picture_png(name)
            # Sylva's names all start sylva-: `Sylva leaves-oak`, `Sylva bark-plated-normal`.
            image = bpy.data.images.new(MATERIAL_PREFIX + name.removeprefix("sylva-"), 8, 8)
        image.pack(data=png, data_len=len(png))
        image.source = "FILE"
        image[PICTURE_KEY] = name
        if name.endswith("-normal"):
            # A normal map's RGB is a direction, not a colour: read as it is stored.
            image.colorspace_settings.name = "Non-Color"
        images[name] = image
    return images
