"""Installs the Sylva extension zip into bpy and calls every operator it has, checking what
each makes: objects, mesh sizes against the package's own arrays, materials, custom
properties, lineage, and the errors it reports. Prints the timings asked of it. Run by
scripts/check-blender-extension with a fresh BLENDER_USER_RESOURCES.

    python scripts/blender_extension_check.py EXTENSION.zip [--sylva target/release/sylva] [--render DIR]
        [--pictures extension,foliage]

With --sylva, the studio archive is checked against a real studio: it makes the archive,
and reads back what Blender wrote to it while it runs.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request

import bpy
import numpy as np
from mathutils import Vector

zip_path = os.path.abspath(sys.argv[1])
render_dir = sys.argv[sys.argv.index("--render") + 1] if "--render" in sys.argv else None
sylva_cli = sys.argv[sys.argv.index("--sylva") + 1] if "--sylva" in sys.argv else None
pictures = set(sys.argv[sys.argv.index("--pictures") + 1].split(",")) if "--pictures" in sys.argv else None
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)
    return ok


def fails(call, *words):
    """Calls an operator that must refuse, with an error naming `words`."""
    try:
        result = call()
    except RuntimeError as e:  # bpy.ops raises a RuntimeError carrying the ERROR report
        message = str(e)
        return check(all(w in message for w in words), f"refused: {message.strip()}")
    return check(False, f"expected an error naming {words}, got {result}")


# -- Install with Blender's own "Install from Disk" operator --------------------------------
# It works headless: the operator validates the manifest, unpacks the zip into the user
# repository and installs the bundled wheel into extensions/.local the way Blender does.
start = time.perf_counter()
result = bpy.ops.extensions.package_install_files(
    filepath=zip_path, repo="user_default", enable_on_install=True
)
install_s = time.perf_counter() - start
module = "bl_ext.user_default.sylva"
check(result == {"FINISHED"} and module in bpy.context.preferences.addons,
      f"installed and enabled {module} from {os.path.basename(zip_path)} ({install_s:.2f} s)")
# The first grow of the session: it imports the package and makes the textures it uses.
scene = bpy.context.scene
scene.sylva.source, scene.sylva.model, scene.sylva.example = "EXAMPLE", "plantmaker", "flowering-bush"
start = time.perf_counter()
bpy.ops.sylva.grow()
cold_s = time.perf_counter() - start
cold = bpy.context.active_object
import sylva  # noqa: E402  (only importable now: from the extension's bundled wheel)

check(os.path.join("extensions", ".local") in sylva.__file__,
      f"sylva {sylva.__version__} imported from the bundled wheel: {sylva.__file__}")
ext = sys.modules[module]
plants = sys.modules[module + ".plants"]
for panel in ("SYLVA_PT_grow", "SYLVA_PT_plant", "SYLVA_PT_breed", "SYLVA_PT_evolve", "SYLVA_PT_assets"):
    cls = getattr(bpy.types, panel, None)
    check(cls is not None and cls.bl_category == "Sylva" and cls.bl_region_type == "UI"
          and cls.bl_space_type == "VIEW_3D", f"{panel} in the 3D view's sidebar, tab Sylva")
ops = ("grow", "regrow", "save_genome", "breed", "mutate", "cross", "keep", "wind", "lod", "forest",
       "mark_zone", "evolve", "evolve_picture")
for name in ops:
    cls = getattr(bpy.types, f"SYLVA_OT_{name}")
    undo = name == "save_genome" or {"REGISTER", "UNDO"} <= set(cls.bl_options)
    check(undo, f"sylva.{name} registered" + ("" if name == "save_genome" else " with REGISTER and UNDO"))

settings = scene.sylva
tmp = tempfile.mkdtemp(prefix="sylva-blender-")


def grown(source, model=None, **kw):
    before = set(bpy.data.objects)
    settings.source = source
    if model:
        settings.model = model
    for k, v in kw.items():
        setattr(settings, k, v)
    bpy.ops.sylva.grow()
    (obj,) = set(bpy.data.objects) - before
    return obj


def triangles(obj):
    return len(obj.data.polygons)


def image_of(mat, picture):
    """The Image Texture node of `mat` showing Sylva's picture `picture`, packed, or None."""
    return next((n for n in mat.node_tree.nodes if n.type == "TEX_IMAGE" and n.image is not None
                 and n.image.packed_file is not None and n.image.get("sylva_picture") == picture), None)


def check_plant(obj, genome, label, plant=None, **options):
    """The object against the same genome grown by the package itself (with `options`, or
    `plant` as grown)."""
    plant = plant or genome.grow(**options)
    m = plant.mesh
    me = obj.data
    ok = check(len(me.vertices) == len(m.positions) and triangles(obj) == len(m.indices)
               and len(me.loops) == 3 * len(m.indices),
               f"{label}: {len(me.vertices)} vertices, {triangles(obj)} triangles, as plant.mesh")
    if ok and len(m.positions):
        co = np.empty(3 * len(me.vertices), np.float32)
        me.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3)
        p = m.positions
        check(np.allclose(co, np.stack([p[:, 0], -p[:, 2], p[:, 1]], 1), atol=1e-6),
              f"{label}: positions are the package's, Y-up turned Z-up")
        cn = np.empty(3 * len(me.loops), np.float32)
        me.corner_normals.foreach_get("vector", cn)
        n = m.normals[m.indices.ravel()]
        err = np.linalg.norm(cn.reshape(-1, 3) - np.stack([n[:, 0], -n[:, 2], n[:, 1]], 1), axis=1)
        if bpy.app.version >= (5, 0, 0):
            ok = err.max() < 1e-5  # 5.0 keeps them as floats
        else:
            # 4.x encodes a custom normal as two 16-bit angles in its corner fan's frame: most
            # move by up to half a degree, and a rare corner of an odd fan more (6 of the
            # random PlantMaker plant's 1.6 million by over 0.1).
            ok = np.mean(err > 1e-2) < 1e-4
        check(ok, f"{label}: corner normals are the package's (custom normals; "
                  f"largest difference {err.max():.1e}, {np.sum(err > 1e-2)} over 1e-2)")
        uv = np.empty(2 * len(me.loops), np.float32)
        me.uv_layers[0].data.foreach_get("uv", uv)
        u = m.uvs[m.indices.ravel()]
        check(np.allclose(uv.reshape(-1, 2), np.stack([u[:, 0], 1 - u[:, 1]], 1), atol=1e-6),
              f"{label}: texture coordinates are the package's, v flipped as glTF's importer does")
        mi = np.empty(triangles(obj), np.int32)
        me.polygons.foreach_get("material_index", mi)
        check(np.array_equal(mi, m.triangle_materials), f"{label}: each triangle's material as the package's")
    mats = list(me.materials)
    colours_ok = len(mats) == len(m.materials) and all(
        np.allclose(b.diffuse_color[:3], a["color"], atol=1e-6)
        and np.allclose(next(n for n in b.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
                        .inputs["Base Color"].default_value[:3] if a["picture"] is None else
                        next(s for n in b.node_tree.nodes if n.type == "MIX" for s in n.inputs
                             if s.type == "RGBA" and not s.is_linked).default_value[:3],
                        a["color"], atol=1e-6)
        for a, b in zip(m.materials, mats))
    kinds = sorted({a["kind"] for a in m.materials})
    check(colours_ok, f"{label}: {len(mats)} materials ({', '.join(kinds)}), base colours as Sylva's")
    textured = [(a, b) for a, b in zip(m.materials, mats)
                if a["texture"] is not None and a["picture"] == f"sylva-texture-{a['texture']}"]
    tex_ok = all(
        any(n.type == "TEX_IMAGE" and n.image is not None and n.image.packed_file is not None
            and n.image.size[0] == 256 and n.image.get("sylva_texture") == a["texture"]
            for n in b.node_tree.nodes)
        for a, b in textured)
    if textured:
        check(tex_ok, f"{label}: {len(textured)} textured materials show Sylva's 256x256 texture, packed")
    pictured = [(a, b) for a, b in zip(m.materials, mats) if a["picture"] is not None]
    check(all(image_of(b, a["picture"]) is not None for a, b in pictured),
          f"{label}: each of the {len(pictured)} materials with a picture shows it, packed")
    check(obj["sylva_genome"] == genome.to_json() and obj["sylva_model"] == genome.model
          and obj["sylva_seed"] == (plant.seed if plant.seed < 2**31 else str(plant.seed)) and obj["sylva_id"] == plants.genome_id(genome)
          and obj["sylva_version"] == sylva.__version__,
          f"{label}: genome JSON, model, seed {plant.seed}, id and version in custom properties")
    return plant


# -- Grow: every bundled example, a file, a random genome ------------------------------------
examples = {m: plants.examples(m) for m in sylva.models()}
check(sum(map(len, examples.values())) >= 4 and all(examples.values()),
      f"bundled examples: {', '.join(f'{m} {len(e)}' for m, e in examples.items())}")
objects = {}
for model, found in examples.items():
    for name, path in found:
        obj = grown("EXAMPLE", model, example=name)
        check(obj.select_get() and bpy.context.view_layer.objects.active == obj
              and obj.location == scene.cursor.location, f"{name}: selected, active, at the cursor")
        check_plant(obj, sylva.Genome.load(path), name)
        check(obj["sylva_operator"] == "example" and obj["sylva_source"] == name
              and obj["sylva_generation"] == 0 and json.loads(obj["sylva_parents"]) == [],
              f"{name}: origin example, generation 0, no parents")
        objects.setdefault(name, obj)  # the first model's by a name (bintree's oak, not grown's)

path = os.path.join(tmp, "my oak.json")
oak = sylva.Genome.load(dict(examples["bintree"])["oak"]).with_field("depth", 6)
oak.save(path)
obj = grown("FILE", "bintree", genome_file=path)
check_plant(obj, oak, "genome file")
check(obj["sylva_operator"] == "file" and obj["sylva_source"] == path, "genome file: its path in sylva_source")
fails(lambda: grown("FILE", genome_file=os.path.join(tmp, "missing.json")), "not found", "missing.json")
with open(os.path.join(tmp, "bad.json"), "w") as f:
    f.write('{"model": "bintree", "format": 1, "depth": 99}')
fails(lambda: grown("FILE", genome_file=os.path.join(tmp, "bad.json")), "bad.json", "depth")
settings.genome_file = ""
fails(lambda: grown("FILE"), "Choose a genome file")
obj = grown("RANDOM", "plantmaker", random_seed=3)
check_plant(obj, sylva.Genome.random("plantmaker", 3), "random plantmaker 3")
check(isinstance(obj["sylva_seed"], str) or obj["sylva_seed"] >= 0,
      f"random plantmaker: its 64-bit seed kept in full ({obj['sylva_seed']!r})")

obj = grown("RANDOM", "lsystem", random_seed=1)
check_plant(obj, sylva.Genome.random("lsystem", 1), "random lsystem 1")
check(triangles(obj) > 0, f"random lsystem 1 grows: {triangles(obj)} triangles")
# The paper's empty L-system (no rules) does not germinate: an empty mesh, with a warning.
bare = json.loads(sylva.Genome.load(dict(examples["lsystem"])["herb"]).to_json())
bare["shoot"]["rules"] = bare["root"]["rules"] = []
with open(os.path.join(tmp, "bare.json"), "w") as f:
    json.dump(bare, f)
empty = grown("FILE", "lsystem", genome_file=os.path.join(tmp, "bare.json"))
check(triangles(empty) == 0 and empty["sylva_model"] == "lsystem",
      "an L-system without rules grows nothing: an empty mesh, with a warning")

# -- Settings regrow the plant (the update callbacks of obj.sylva) ---------------------------
tree = objects["tree"]
bpy.context.view_layer.objects.active = tree
genome = plants.genome_of(tree)
before = triangles(tree)
tree.sylva.roots = False
no_roots = genome.grow(roots=False)
check(triangles(tree) == len(no_roots.mesh.indices) < before,
      f"tree: Roots off regrows it, {before} -> {triangles(tree)} triangles")
tree.sylva.roots = True
tulip = objects["tulip"]
co0 = [v.co.copy() for v in tulip.data.vertices[:50]]
tulip.sylva.use_taper = True
tapered = sylva.Genome.from_json(tulip["sylva_genome"]).grow(taper=2.5)
check(len(tulip.data.vertices) == len(tapered.mesh.positions)
      and any((v.co - c).length > 1e-6 for v, c in zip(tulip.data.vertices[:50], co0)),
      "tulip: Pipe Taper on regrows it with taper 2.5")
tulip.sylva.use_taper = False
oak_obj = objects["oak"]
oak_obj.sylva.own_seed = False
oak_obj.sylva.seed = 5
check(oak_obj["sylva_seed"] == 5, "oak: a seed of its own regrows it and is kept in sylva_seed")
oak_obj.sylva.own_seed = True
fern = objects["fern"]
fern.sylva.detail = 0.5
depsgraph = bpy.context.evaluated_depsgraph_get()
evaluated = len(fern.evaluated_get(depsgraph).data.polygons)
check(fern.modifiers.get("Sylva Detail") is not None and 0.35 * triangles(fern) < evaluated < 0.65 * triangles(fern),
      f"fern: Detail 0.5 keeps {evaluated} of {triangles(fern)} triangles (Decimate)")
fern.sylva.detail = 1.0
check(fern.modifiers.get("Sylva Detail") is None, "fern: Detail 1 removes the modifier")

# -- Regrow after editing the genome by hand; save the genome ---------------------------------
bpy.context.view_layer.objects.active = oak_obj
oak_obj["sylva_genome"] = json.dumps(dict(json.loads(oak_obj["sylva_genome"]), depth=5))
bpy.ops.sylva.regrow()
check(triangles(oak_obj) == len(sylva.Genome.from_json(oak_obj["sylva_genome"]).grow().mesh.indices)
      and oak_obj["sylva_genome"].count("\n") > 3, "oak: Regrow reads the edited genome JSON (depth 5)")
good = oak_obj["sylva_genome"]
oak_obj["sylva_genome"] = good.replace('"depth": 5', '"depth": 40')
fails(lambda: bpy.ops.sylva.regrow(), "depth", "40")
check("depth" in oak_obj.sylva.error, f"the Plant panel shows it: {oak_obj.sylva.error!r}")
oak_obj["sylva_genome"] = good
bpy.ops.sylva.regrow()
check(oak_obj.sylva.error == "", "a good genome clears the error")
saved = os.path.join(tmp, "saved.json")
bpy.ops.sylva.save_genome(filepath=saved)
check(sylva.Genome.load(saved) == sylva.Genome.from_json(good), "Save Genome writes the genome file")


# -- Breed: nine variants, then favourites mutated and crossed -------------------------------
def select(objs, active=None):
    for o in bpy.context.selected_objects:
        o.select_set(False)
    for o in objs:
        o.select_set(True)
    bpy.context.view_layer.objects.active = active or (objs[0] if objs else None)


def grid():
    return plants.brood(bpy.context)


fails(lambda: bpy.ops.sylva.mutate(), "poll")  # no grid yet: the button is greyed out
select([tulip])
bpy.ops.sylva.breed()
cells = grid()
collection = bpy.data.collections.get("Sylva Brood")
check(sorted(cells) == list(range(9)) and len(collection.objects) == 9, "Breed: nine plants in Sylva Brood, cells 0-8")
check(all(o["sylva_operator"] == "mutate" and json.loads(o["sylva_parents"]) == [tulip["sylva_id"]]
          and o["sylva_generation"] == 1 and tulip["sylva_id"] in plants.lineage_of(o) for o in cells.values()),
      "Breed: each is a mutant of the tulip, generation 1, the tulip in its lineage")
ids = {o["sylva_id"] for o in cells.values()}
check(len(ids) >= 8, f"Breed: {len(ids)} distinct genomes among the nine")
spots = {tuple(round(x, 3) for x in o.location) for o in cells.values()}
xs = sorted({s[0] for s in spots})
check(len(spots) == 9 and len(xs) == 3 and min(xs) > tulip.location.x, "Breed: a 3x3 grid beside the tulip")
for o in cells.values():
    check_plant(o, plants.genome_of(o), f"variant {o['sylva_cell'] + 1}") if o["sylva_cell"] in (0, 8) else None

select([cells[3]])
fails(lambda: bpy.ops.sylva.breed(), "in the breeding grid")
favourites = [cells[0], cells[4]]
select(favourites)
kept = {o.name: o["sylva_id"] for o in favourites}
bpy.ops.sylva.mutate()
cells = grid()
fav_ids = [o["sylva_id"] for o in favourites]
others = [o for k, o in cells.items() if k not in (0, 4)]
check(all(o["sylva_id"] == kept[o.name] for o in favourites), "Mutate: the favourites stay")
check(all(o["sylva_operator"] == "mutate" and json.loads(o["sylva_parents"])[0] in fav_ids
          and o["sylva_generation"] == 2 for o in others),
      "Mutate: the other seven are mutants of the favourites, generation 2")
bpy.ops.sylva.cross()
cells = grid()
others = [o for k, o in cells.items() if k not in (0, 4)]
check(all(o["sylva_operator"] == "cross" and set(json.loads(o["sylva_parents"])) <= set(fav_ids)
          and json.loads(o["sylva_parents"]) for o in others),
      "Cross: the other seven are children of the two favourites")
lineage = plants.lineage_of(others[0])
check(tulip["sylva_id"] in lineage and all(i in lineage for i in fav_ids),
      f"Cross: lineage back to the tulip ({len(lineage)} entries)")
select([cells[1]])
fails(lambda: bpy.ops.sylva.cross(), "at least 2")
select([])
fails(lambda: bpy.ops.sylva.mutate(), "at least 1")
select(list(cells.values()))
fails(lambda: bpy.ops.sylva.mutate(), "All nine")
select([cells[2], objects["oak"]], active=cells[2])
fails(lambda: bpy.ops.sylva.cross(), "one model", "bintree", "plantmaker")
select([cells[2]])
bpy.ops.sylva.keep()
copy = bpy.context.active_object
check(copy is not cells[2] and "sylva_cell" not in copy and copy["sylva_id"] == cells[2]["sylva_id"]
      and copy.data is not cells[2].data, "Keep: a copy out of the grid, with its own mesh")

# -- Leaves and bark: Foliage, Bark, Height and Density regrow the plant, dressed -------------


def bsdf_of(mat):
    return next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")


def feeds(socket, node_type, output=None):
    """The node of `node_type` whose output (named `output`) reaches `socket` through the
    node tree's links, or None."""
    todo = [socket]
    while todo:
        for link in todo.pop().links:
            node = link.from_node
            if node.type == node_type and (output is None or link.from_socket.name == output):
                return node
            todo.extend(i for i in node.inputs if i.is_linked)
    return None


def alpha_of(image):
    px = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(px)
    return px[3::image.channels] if image.channels == 4 else np.ones(1, np.float32)


def check_dress(obj, plant, label):
    """Cut-out materials show their picture's alpha as the BSDF's, from both sides; barks
    their normal map. Returns the figures it saw."""
    pairs = list(zip(plant.mesh.materials, obj.data.materials))
    cut = [(a, b) for a, b in pairs if a["cut_out"]]
    seen = {}
    for a, b in cut:
        bsdf = bsdf_of(b)
        tex = feeds(bsdf.inputs["Alpha"], "TEX_IMAGE", "Alpha")
        colour = feeds(bsdf.inputs["Base Color"], "TEX_IMAGE", "Color")
        alpha = alpha_of(tex.image) if tex is not None else np.ones(1)
        seen[a["picture"]] = float(np.mean(alpha < 0.5))
        method = getattr(b, "surface_render_method", "DITHERED")
        check(tex is not None and tex == colour and tex.image.get("sylva_picture") == a["picture"]
              and tex.extension in ("EXTEND", "CLIP") and not b.use_backface_culling
              and method == "DITHERED" and 0.05 < seen[a["picture"]] < 0.95,
              f"{label}: {b.name} shows {a['picture']} ({tex.image.size[0] if tex else 0} px, "
              f"{seen[a['picture']]:.0%} of it cut away), its alpha linked to the BSDF's Alpha "
              f"(cut at 0.5), both faces drawn (backface culling off), render method {method}")
    bark = [(a, b) for a, b in pairs if a["normal_map"] is not None]
    for a, b in bark:
        bsdf = bsdf_of(b)
        normal = feeds(bsdf.inputs["Normal"], "NORMAL_MAP")
        tex = feeds(normal.inputs["Color"], "TEX_IMAGE", "Color") if normal else None
        colour = feeds(bsdf.inputs["Base Color"], "TEX_IMAGE", "Color")
        check(normal is not None and normal.space == "TANGENT" and normal.uv_map == obj.data.uv_layers[0].name
              and tex is not None and tex.image.get("sylva_picture") == a["normal_map"]
              and tex.image.colorspace_settings.name == "Non-Color" and tex.extension == "REPEAT"
              and colour is not None and colour.image.get("sylva_picture") == a["picture"]
              and colour.extension == "REPEAT",
              f"{label}: {b.name} shows {a['picture']}, repeating, and its normal map {a['normal_map']} "
              f"(Non-Color) through a tangent-space Normal Map node on {normal.uv_map if normal else None}")
    return cut, bark, seen


dress_times = {}
check(set(plants.grow_options(plants.settings_of(objects["tree"].sylva), plants.genome_of(objects["tree"])))
      == {"seed", "roots", "taper"} and objects["tree"].sylva.foliage == "NONE"
      and objects["tree"].sylva.bark == "FOLIAGE" and objects["tree"].sylva.height == 0.0
      and objects["tree"].sylva.density == 1.0,
      "Leaves and bark: a plant's defaults (as grown, foliage's own bark, height 0, density 1) "
      "give Genome.grow no dress arguments: it grows as before them")
oak_genome = sylva.Genome.load(dict(examples["bintree"])["oak"])
dressed = grown("EXAMPLE", "bintree", example="oak")
bare = triangles(dressed)
t = time.perf_counter()
dressed.sylva.foliage = "oak"
dress_times["foliage"] = time.perf_counter() - t
t = time.perf_counter()
dressed.sylva.height = 12.0
dress_times["height"] = time.perf_counter() - t
reference = check_plant(dressed, oak_genome, "oak, Foliage oak, Height 12", foliage="oak", height=12.0)
top = max(v.co.z for v in dressed.data.vertices)
dress_figures = {"bare": bare, "dressed": triangles(dressed), "materials": len(dressed.data.materials),
                 "height": reference.height, "top": top}
check(abs(reference.height - 12.0) < 0.05 and abs(top - reference.bounds[1][1]) < 1e-4,
      f"oak, Height 12: grown {reference.height:.2f} m tall (Sylva's height), the highest leaf "
      f"{top:.2f} m up in Blender ({triangles(dressed)} triangles; {bare} as grown)")
cut, bark, dress_figures["cut away"] = check_dress(dressed, reference, "oak dressed")
check(len(cut) >= 1 and len(bark) >= 1 and {a["picture"] for a, _ in cut} == {"sylva-leaves-oak"}
      and {a["normal_map"] for a, _ in bark} == {"sylva-bark-furrowed-normal"},
      f"oak dressed: {len(cut)} cut-out leaf material(s) of sylva-leaves-oak, {len(bark)} bark "
      "material(s) of sylva-bark-furrowed with its normal map (the oak's own bark)")
leaf_images = [i for i in bpy.data.images if i.get("sylva_picture") == "sylva-leaves-oak"]
materials_before = len(bpy.data.materials)
twin = grown("EXAMPLE", "bintree", example="oak")
twin.sylva.foliage, twin.sylva.height = "oak", 12.0
check(list(twin.data.materials) == list(dressed.data.materials) and len(bpy.data.materials) == materials_before
      and len(leaf_images) == 1 and leaf_images[0].packed_file is not None
      and len([i for i in bpy.data.images if i.get("sylva_picture") == "sylva-leaves-oak"]) == 1,
      f"a second dressed oak shares the first one's {len(twin.data.materials)} materials; the leaf atlas "
      f"is one packed image ({leaf_images[0].size[0]} x {leaf_images[0].size[1]}) in the file")
bpy.data.objects.remove(twin)
t = time.perf_counter()
dressed.sylva.foliage = "pine"
dress_times["pine"] = time.perf_counter() - t
pine = check_plant(dressed, oak_genome, "oak, Foliage pine", foliage="pine", height=12.0)
cut, bark, _ = check_dress(dressed, pine, "oak as a pine")
check({a["picture"] for a, _ in cut} == {"sylva-leaves-pine"} and all(
      "sylva-leaves-oak" not in (m.get("sylva_material") or "") for m in dressed.data.materials),
      f"Foliage pine regrows it with pine needles ({triangles(dressed)} triangles)")
dressed.sylva.bark = "plated"
plated = check_plant(dressed, oak_genome, "oak, Bark plated", foliage="pine", bark="plated", height=12.0)
cut, bark, _ = check_dress(dressed, plated, "oak, Bark plated")
check({a["normal_map"] for a, _ in bark} == {"sylva-bark-plated-normal"}, "Bark plated: its own normal map")
dressed.sylva.foliage, dressed.sylva.bark = "oak", "FOLIAGE"
before = triangles(dressed)
dressed.sylva.density = 2.0
check_plant(dressed, oak_genome, "oak, Density 2", foliage="oak", height=12.0, density=2.0)
check(triangles(dressed) > before, f"Density 2: {before} -> {triangles(dressed)} triangles")
dressed.sylva.density = 1.0
dressed.sylva.foliage = "NONE"
check_plant(dressed, oak_genome, "oak, Foliage as grown, Height 12", height=12.0)
check(not any(m.get("sylva_material", "").endswith("|cut out") for m in dressed.data.materials),
      "Foliage as grown: no cut-out materials left")
dressed.sylva.height = 0.0
check(triangles(dressed) == bare, f"Height 0: the oak as grown again ({bare} triangles)")
dressed.sylva.foliage, dressed.sylva.height = "oak", 12.0


# Breeding a dressed plant: the grid plants take its leaves and bark.
select([dressed])
bpy.ops.sylva.breed()
cells = grid()
check(len(cells) == 9 and all(o.sylva.foliage == "oak" and o.sylva.height == 12.0 and any(
      (m.get("sylva_material") or "").endswith("|cut out") for m in o.data.materials) for o in cells.values()),
      "Breed a dressed oak: the nine mutants grow with its Foliage and Height, cut-out leaves and all")
check_plant(cells[0], plants.genome_of(cells[0]), "dressed variant 1", foliage="oak", height=12.0)
# Wind on a dressed plant: Sylva's GLB of it, read by Blender's glTF importer.
select([dressed])
settings.wind_strength, settings.wind_period = 1.0, 4.0
bpy.ops.sylva.wind()
skinned = [c for c in bpy.context.active_object.children if c.type == "MESH"]
expected = oak_genome.grow(foliage="oak", height=12.0, wind=1.0, wind_period=4.0)
check(len(skinned) == 1 and triangles(skinned[0]) == len(expected.mesh.indices) and any(
      not m.use_backface_culling and feeds(bsdf_of(m).inputs["Alpha"], "TEX_IMAGE", "Alpha") is not None
      for m in skinned[0].data.materials),
      f"Add Wind on the dressed oak: {triangles(skinned[0]) if skinned else 0} triangles skinned, as the "
      "package's; Blender's glTF importer cuts its leaves out too (alpha to the BSDF, two-sided)")
dressed.hide_set(False)
dressed.hide_render = False

# Species presets: a .toml from File, and the bundled ones in the Example menu.
species_dir = os.path.abspath("examples/species")
oak_toml = os.path.join(species_dir, "oak.toml")
t = time.perf_counter()
species_oak = grown("FILE", "lsystem", genome_file=oak_toml)
dress_times["preset"] = time.perf_counter() - t
reference = sylva.Genome.grow_preset(oak_toml)
check_plant(species_oak, sylva.Genome.load(os.path.join(species_dir, "oak.genome.json")), "species oak (File)",
            plant=reference)
group = species_oak.sylva
check(group.foliage == "oak" and group.bark == "FOLIAGE" and abs(group.height - 17.0) < 1e-6
      and abs(group.density - 1.5) < 1e-6 and not group.roots and group.own_seed
      and species_oak["sylva_source"] == oak_toml,
      "species oak (File): the preset's Foliage oak, Height 17, Density 1.5, no roots kept in its settings")
check_dress(species_oak, reference, "species oak")
dress_figures["preset"] = (triangles(species_oak), species_oak.dimensions.z)
select([species_oak])
bpy.ops.sylva.regrow()
co = np.empty(3 * len(species_oak.data.vertices), np.float32)
species_oak.data.vertices.foreach_get("co", co)
p = reference.mesh.positions
check(len(co) == 3 * len(p) and np.allclose(co.reshape(-1, 3), np.stack([p[:, 0], -p[:, 2], p[:, 1]], 1), atol=1e-6),
      "species oak: Regrow from its settings gives grow_preset's plant again, every vertex")
bundled_species = os.path.join(os.path.dirname(plants.__file__), "examples", "species")
bundled = sorted(f for f in os.listdir(bundled_species) if f.endswith(".toml"))
check(bundled == sorted(f for f in os.listdir(species_dir) if f.endswith(".toml")),
      f"the zip bundles every species preset: {', '.join(bundled)}")
settings.model = "lsystem"
items = [i[0] for i in ext._example_items(settings, bpy.context)]
check({"species/oak", "species/birch", "species/spruce"} <= set(items) and "tree" in items,
      f"Example menu of lsystem: {', '.join(items)}")
birch = grown("EXAMPLE", "lsystem", example="species/birch")
check_plant(birch, sylva.Genome.load(os.path.join(species_dir, "birch.genome.json")), "species birch (Example)",
            plant=sylva.Genome.grow_preset(os.path.join(species_dir, "birch.toml")))
check(birch.sylva.foliage == "birch" and birch["sylva_operator"] == "example"
      and birch["sylva_source"] == "species/birch", f"species birch: grown as {birch.name}")
with open(os.path.join(tmp, "bad.toml"), "w") as f:
    f.write('genome = "oak.genome.json"\nfoliage = "palm"\n')
fails(lambda: grown("FILE", genome_file=os.path.join(tmp, "bad.toml")), "bad.toml", "palm")
settings.example = "tree"

# -- A studio archive: plants grown from it, bred plants written back -----------------------------
archive = sys.modules[module + ".archive"]
if sylva_cli:
    db = os.path.join(tmp, "studio.db")
    studio = subprocess.Popen([sylva_cli, "studio", "--port", "0", "--db", db], stdout=subprocess.PIPE, text=True)
    try:
        address = studio.stdout.readline().strip().removeprefix("Sylva studio: http://").rstrip("/")

        def api(method, path, body=None):
            data = None if body is None else json.dumps(body).encode()
            request = urllib.request.Request(f"http://{address}{path}", data=data, method=method,
                                             headers={"Content-Type": "application/json"})
            with urllib.request.urlopen(request, timeout=60) as answer:
                return json.loads(answer.read())

        session = api("POST", "/api/sessions", {"mode": "breed", "model": "plantmaker",
                                                "start": {"examples": ["plantmaker/tulip", "plantmaker/fern"]}})
        studio_ids = [cell["plant"] for cell in session["state"]["grid"]]
        settings.model, settings.source, settings.archive = "plantmaker", "ARCHIVE", db
        items = [i[0] for i in ext._archive_items(settings, bpy.context)]
        check(set(map(str, studio_ids)) <= set(items),
              f"Archive: the studio's {len(studio_ids)} plants offered ({len(items)} in the list)")
        tulip_row = api("GET", f"/api/plants/{studio_ids[0]}")
        from_archive = grown("ARCHIVE", "plantmaker", archive_plant=str(studio_ids[0]))
        check_plant(from_archive, sylva.Genome.from_json(tulip_row["genome_text"]), f"archive plant {studio_ids[0]}")
        check(from_archive["sylva_archive_id"] == studio_ids[0] and from_archive["sylva_archive"] == db,
              f"Archive: the plant knows its row ({from_archive['sylva_archive_id']})")
        select([from_archive])
        bpy.ops.sylva.breed()
        cells = grid()
        rows = [cells[k]["sylva_archive_id"] for k in sorted(cells)]
        seen = [api("GET", f"/api/plants/{r}") for r in rows]
        check(len(set(rows)) == 9 and all(p["parents"][0]["plant"] == studio_ids[0] and p["operator"] == "mutate"
                                          for p in seen),
              f"Archive: nine bred plants written back, rows {rows[0]} to {rows[-1]}, which the running studio "
              f"shows as mutants of plant {studio_ids[0]}")
        check(all(sylva.Genome.from_json(p["genome_text"]) == plants.genome_of(cells[k])
                  for k, p in zip(sorted(cells), seen)),
              "Archive: each row's genome is its plant's")
        select([cells[0], cells[4]])
        bpy.ops.sylva.cross()
        crossed = [o for k, o in sorted(grid().items()) if k not in (0, 4)]
        seen = [api("GET", f"/api/plants/{o['sylva_archive_id']}") for o in crossed]
        check(all(p["operator"] == "cross" and {q["plant"] for q in p["parents"]} <= {rows[0], rows[4]}
                  and p["parents"] for p in seen),
              "Archive: crosses written back with the favourites as parents")
        settings.archive_record = False
        select([cells[0]])
        bpy.ops.sylva.mutate()
        check(all("sylva_archive_id" not in o for k, o in grid().items() if k != 0),
              "Archive: with Record in Archive off, mutants are not written")
        settings.archive_record = True
    finally:
        studio.terminate()
        studio.wait()
else:
    print("note the studio archive is checked with --sylva target/release/sylva (scripts/check-blender-extension passes it)")
settings.archive = os.path.join(tmp, "missing.db")
fails(lambda: grown("ARCHIVE", "plantmaker", archive_plant="none"), "Choose a plant")
check(ext._archive_items(settings, bpy.context)[0][0] == "none", "Archive: a missing file offers no plant")
try:
    archive.plant(settings.archive, 1)
    check(False, "a missing archive refused")
except archive.ArchiveError as e:
    check("not found" in str(e), f"Archive: {e}")
import sqlite3  # noqa: E402
with sqlite3.connect(os.path.join(tmp, "other.db")) as other:  # SQLite, but not the studio's
    other.execute("CREATE TABLE schema_version (version INTEGER)")
    other.execute("INSERT INTO schema_version VALUES (1)")
try:
    archive.plants(os.path.join(tmp, "other.db"))
    check(False, "a SQLite file without the studio's tables refused")
except archive.ArchiveError as e:
    check("other.db" in str(e) and "plants" in str(e), f"Archive: {e}")
with open(os.path.join(tmp, "notes.db"), "w") as f:
    f.write("not sqlite")
try:
    archive.plants(os.path.join(tmp, "notes.db"))
    check(False, "a file that is not an archive refused")
except archive.ArchiveError as e:
    check("not a studio archive" in str(e), f"Archive: {e}")
settings.archive, settings.source = "", "EXAMPLE"

# -- Wind: Sylva's rig as an armature and its action ----------------------------------------
fern = objects["fern"]
select([fern])
settings.wind_strength, settings.wind_period = 1.5, 2.0
bpy.ops.sylva.wind()
rig = bpy.context.active_object
expected = plants.genome_of(fern).grow(wind=1.5, wind_period=2.0)
skinned = [c for c in rig.children if c.type == "MESH"]
check(rig.type == "ARMATURE" and len(rig.data.bones) == expected.wind["joints"] and len(skinned) == 1,
      f"Add Wind: an armature of {len(rig.data.bones)} bones (the rig's {expected.wind['joints']} joints), "
      "the skinned plant its child")
mesh = skinned[0]
modifier = next((m for m in mesh.modifiers if m.type == "ARMATURE"), None)
check(modifier is not None and modifier.object == rig and len(mesh.vertex_groups) > 1
      and triangles(mesh) == len(expected.mesh.indices),
      f"Add Wind: the mesh ({triangles(mesh)} triangles, as the package's) is skinned to it "
      f"({len(mesh.vertex_groups)} vertex groups, an Armature modifier)")
track = rig.animation_data.nla_tracks.get("wind") if rig.animation_data else None
strip = track.strips[0] if track and len(track.strips) else None
action = strip.action if strip else None
frames = scene.frame_end - scene.frame_start + 1
check(action is not None and action.name == f"{fern.name} wind"
      and strip.frame_end >= scene.frame_end,
      f"Add Wind: action '{action.name if action else None}' of {action.frame_range[1] - action.frame_range[0] if action else 0:.0f} "
      f"frames (2 s at {scene.render.fps} fps), an NLA strip repeated {strip.repeat if strip else 0:g} times over "
      f"the scene's {frames} frames")


def pose(frame):
    scene.frame_set(frame)
    tip = rig.pose.bones[-1]
    return np.array(tip.matrix)


half = scene.frame_start + scene.render.fps // 2
swing = np.abs(pose(scene.frame_start) - pose(half)).max()
late = np.abs(pose(half) - pose(half + 4 * scene.render.fps)).max()
check(len(rig.animation_data.nla_tracks) == 1 and swing > 1e-4 and late < 1e-4,
      f"Add Wind: a tip bone sways ({swing:.3f} over half a second) and the clip loops (as it was "
      f"two periods later, within {late:.0e})")
check(fern.hide_get() and fern.hide_render and mesh["sylva_id"] == fern["sylva_id"]
      and json.loads(mesh["sylva_wind_rig"])["joints"] == expected.wind["joints"],
      "Add Wind: the plant is hidden, the skinned mesh carries its id and the wind")
select([fern])
bpy.ops.sylva.wind()
rigs = [o for o in bpy.data.objects if o.type == "ARMATURE" and o.get("sylva_wind_rig_of") == fern.name]
check(len(rigs) == 1, "Add Wind again: the plant's old rig is replaced")
fern.hide_set(False)
fern.hide_render = False

select([empty])
fails(lambda: bpy.ops.sylva.wind(), "grew no branches to rig")
fails(lambda: bpy.ops.sylva.lod(), "grew nothing to make levels of detail of")

# -- Levels of detail: a collection of NAME_LODn objects ------------------------------------
tulip = objects["tulip"]
select([tulip])
settings.lod_levels = 3
active_collection = bpy.context.view_layer.active_layer_collection.name
bpy.ops.sylva.lod()
check(bpy.context.view_layer.active_layer_collection.name == active_collection,
      f"Levels of Detail leaves the active collection as it was ({active_collection})")
lod_collection = bpy.data.collections.get(f"{tulip.name}_LODs")
levels = sorted(lod_collection.objects, key=lambda o: o.name) if lod_collection else []
counts = [triangles(o) for o in levels]
full = len(plants.genome_of(tulip).grow().mesh.indices)
# Three meshed levels, then the impostor: two crossed cards showing the plant's picture.
check([o.name for o in levels] == [f"{tulip.name}_LOD{k}" for k in range(4)]
      and counts[0] == full and counts == sorted(counts, reverse=True) and counts[1] < counts[0]
      and counts[3] == 4,
      f"Levels of Detail: {', '.join(o.name for o in levels)} in {lod_collection.name if lod_collection else None} "
      f"({', '.join(map(str, counts))} triangles; the plant's {full})")
check(all(o.location == tulip.location for o in levels) and not levels[0].hide_get()
      and all(o.hide_get() for o in levels[1:]) and all(o["sylva_id"] == tulip["sylva_id"] for o in levels),
      "Levels of Detail: where the plant stands, LOD0 shown and the rest hidden, each with the plant's id")
select([tulip])
settings.lod_levels = 2
bpy.ops.sylva.lod()
check(len(bpy.data.collections[f"{tulip.name}_LODs"].objects) == 3, "Levels of Detail again: the old chain replaced")

# -- Forest: collection instances of variants over a ground mesh -----------------------------


def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


ground_mesh = bpy.data.meshes.new("hill")
ground_mesh.from_pydata([(-20, -20, 0), (20, -20, 0), (20, 20, 4), (-20, 20, 4)], [], [(0, 1, 2, 3)])
hill = bpy.data.objects.new("hill", ground_mesh)
hill.location = (200, 0, 0)
scene.collection.objects.link(hill)
conifer = objects["conifer"]
select([conifer])
fails(lambda: bpy.ops.sylva.forest(), "Select one ground mesh")
settings.forest_count, settings.forest_variants, settings.forest_seed = 1000, 8, 3
meshes_before = len(bpy.data.meshes)
select([hill, conifer], active=conifer)
rss_before = rss_mb()
t = time.perf_counter()
bpy.ops.sylva.forest()
forest_s = time.perf_counter() - t
rss_after = rss_mb()
woods = bpy.data.collections.get(f"{conifer.name} Forest")
trees = list(woods.objects) if woods else []
kinds = {tree.instance_collection for tree in trees}
library = bpy.data.collections.get(f"{conifer.name} Forest Variants")
check(len(trees) == 1000 and all(t.type == "EMPTY" and t.instance_type == "COLLECTION" for t in trees)
      and len(kinds) == 8 and kinds <= set(library.children),
      f"Plant Forest: {len(trees)} collection instances of {len(kinds)} variants in {woods.name if woods else None}")
check(len(bpy.data.meshes) - meshes_before == 7,
      f"Plant Forest: {len(bpy.data.meshes) - meshes_before} new meshes (the conifer grown with 7 other seeds; "
      "the plant is the 8th), not one per tree")
seeds = sorted(v.objects[0]["sylva_seed"] for v in library.children if "sylva_seed" in v.objects[0])
check(len(set(seeds)) == 7 and all(v.objects[0].get("sylva_id", conifer["sylva_id"]) == conifer["sylva_id"]
                                   for v in library.children),
      f"Plant Forest, varied by seed: one genome, the conifer's, grown with seeds {seeds}")
places = np.array([t.location for t in trees])
on_hill = (np.abs(places[:, 0] - 200) <= 20).all() and (np.abs(places[:, 1]) <= 20).all() \
    and np.allclose(places[:, 2], (places[:, 1] + 20) / 10, atol=1e-3)
check(on_hill, "Plant Forest: every tree stands on the hill's surface")
layer = next(c for c in bpy.context.view_layer.layer_collection.children if c.collection == library)
check(layer.exclude and all(len(c.objects) == 1 and plants.is_plant(c.objects[0]) or c.objects[0].data == conifer.data
                            for c in library.children),
      "Plant Forest: the variants, a plant each, are kept out of the view layer")
select([hill, conifer], active=conifer)
bpy.ops.sylva.forest()
again = np.array([t.location for t in bpy.data.collections[f"{conifer.name} Forest"].objects])
check(len(again) == 1000 and np.allclose(np.sort(again, axis=0), np.sort(places, axis=0)),
      "Plant Forest again with the same seed: the same places, the old forest replaced")
settings.forest_variety, settings.forest_count = "MUTANTS", 50
select([hill, conifer], active=conifer)
bpy.ops.sylva.forest()
library = bpy.data.collections[f"{conifer.name} Forest Variants"]
ids = {v.objects[0].get("sylva_id") for v in library.children} - {None}
check(len(bpy.data.collections[f"{conifer.name} Forest"].objects) == 50 and len(ids) == 7
      and conifer["sylva_id"] not in ids, f"Plant Forest of mutants: 7 genomes of their own beside the conifer")
assets = sys.modules[module + ".assets"]
oak_forest = assets.forest(bpy.context, objects["oak"], hill, 20, 3, 1)
check(oak_forest[2], "Plant Forest of oaks varied by seed: reported alike (the binary tree ignores the seed)")
settings.forest_variety = "SEEDS"

# -- Evolve toward a target and zones in the scene ----------------------------------------------
evolve = sys.modules[module + ".evolve"]
scene.cursor.location = (-60, 0, 0)
bpy.ops.mesh.primitive_uv_sphere_add(radius=1.5, location=(-60, 0, 3.0))
ball = bpy.context.active_object
bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-60, 0, 5.0))
lid = bpy.context.active_object
select([lid])
bpy.ops.sylva.mark_zone(kind="forbidden")
check(lid["sylva_zone"] == "forbidden" and lid.display_type == "WIRE" and lid.hide_render
      and evolve.zones_in(scene) == [lid], "Mark Zone: the box forbidden, drawn as a wire, left out of renders")
select([conifer])
fails(lambda: bpy.ops.sylva.mark_zone(kind="favoured"), "plants cannot be zones")
settings.target = None
fails(lambda: bpy.ops.sylva.evolve(), "Choose a target")
settings.target = hill
fails(lambda: bpy.ops.sylva.evolve(), "Cannot tell the shape of hill", "choose Sphere")
settings.target = ball
made = evolve.config(ball, "AUTO", [lid], scene.cursor.location, 10, 200, 1)
fitness = made["automata"]["fitness"]
target = fitness["target"]
unit = fitness["unit"]
check(target["shape"] == "sphere" and abs(target["radius"] - 150) < 0.5 and abs(unit - 0.01) < 1e-4
      and np.allclose(target["center"], [0, 300, 0], atol=0.5),
      f"Evolve: the UV sphere (radius 1.5 m, 3 m up) is the target sphere of radius {target['radius']:.1f} units "
      f"centred {target['center'][1]:.1f} up, a unit {unit * 100:.2f} cm (the paper's scale)")
cells = fitness["grid"]
check(cells["weight"] == 0 and len(cells["boxes"]) == 1 and cells["boxes"][0]["weight"] == -1
      and cells["boxes"][0]["to"][1] == 4 and cells["boxes"][0]["from"][1] >= 3,
      f"Evolve: the forbidden box is the grid's top cells {cells['boxes'][0]['from']} to {cells['boxes'][0]['to']}")
settings.evolve_population, settings.evolve_generations, settings.evolve_seed = 300, 12, 2
t = time.perf_counter()
bpy.ops.sylva.evolve()
evolved = bpy.context.active_object
ticks = 0
while evolve.tick() is not None and time.perf_counter() - t < 120:
    ticks += 1
    time.sleep(0.05)
evolve_s = time.perf_counter() - t
stats = evolve._current["last"].run.stats
check(plants.is_plant(evolved) and evolved["sylva_model"] == "automata" and evolved["sylva_operator"] == "evolve"
      and evolved.location == scene.cursor.location and triangles(evolved) > 0,
      f"Evolve: the best plant so far stands at the cursor ({triangles(evolved)} triangles), updated "
      f"while the run went on ({ticks} looks)")
check(len(stats) == 13 and stats[-1]["best"] > stats[0]["best"]
      and abs(evolved["sylva_fitness"] - stats[-1]["best"]) < 1e-12,
      f"Evolve: the first generation and 12 more on a worker thread, best fitness {stats[0]['best']:.3g} -> {stats[-1]['best']:.3g} "
      "(the plant shown is the last best)")
check("generation 12 of 12" in evolve.last_status(), f"Evolve: status '{evolve.last_status()}'")
settings.evolve_generations = 10000
bpy.ops.sylva.evolve()
evolve.tick()
bpy.ops.sylva.evolve_stop()
while evolve.tick() is not None:
    time.sleep(0.05)
done = len(evolve._current["last"].run.stats) - 1
check(done < 10000 and not evolve.running(), f"Evolve, Stop: the run ends after generation {done} of 10000")

# Toward a picture, seen from the active camera.
settings.picture = ""
fails(lambda: bpy.ops.sylva.evolve_picture(), "Choose a reference picture")
settings.picture = os.path.join(tmp, "missing.png")
fails(lambda: bpy.ops.sylva.evolve_picture(), "Picture not found", "missing.png")
settings.picture = os.path.abspath("examples/match/round.png")
settings.picture_model = "bintree"
settings.evolve_population, settings.evolve_generations = 60, 6
camera = scene.camera
check(camera is not None, f"the scene has an active camera ({camera.name if camera else None})")
bpy.ops.sylva.evolve_picture()
matched = bpy.context.active_object
while evolve.tick() is not None:
    time.sleep(0.05)
stats = evolve._current["last"].run.stats
front = matched.matrix_world.to_3x3() @ Vector((0.0, -1.0, 0.0))
to_camera = camera.matrix_world.translation - matched.location
facing = (front.x * to_camera.x + front.y * to_camera.y) / (front.to_2d().length * to_camera.to_2d().length)
check(plants.is_plant(matched) and matched["sylva_model"] == "bintree" and len(stats) == 7
      and abs(matched["sylva_fitness"] - stats[-1]["best"]) < 1e-12 and 0 < matched["sylva_fitness"] <= 1,
      f"Evolve Toward Picture: 6 generations of binary trees toward round.png's outline, the best "
      f"(IoU term {matched['sylva_fitness']:.3f}; {stats[0]['best']:.3f} in the first generation) at the cursor")
check(facing > 0.999, f"Evolve Toward Picture: the plant's front faces the active camera (cosine {facing:.4f})")

# -- The Genome panel: the genome's numbers as sliders (sylva.schema) ---------------------------
tulip = objects["tulip"]
bpy.context.view_layer.objects.active = tulip
bpy.ops.sylva.load_fields()
fields = {f.path: f for f in tulip.sylva.fields}
check(len(fields) > 20 and "branches[0].waves" in fields and fields["branches[0].waves"].whole,
      f"Edit Genome Fields: the tulip's {len(fields)} numbers, each list item's")
field = fields["branches[0].max_length"]
genome_before, size_before = tulip["sylva_genome"], tuple(tulip.dimensions)
target = field.soft_high if field.value != field.soft_high else field.soft_low
t = time.perf_counter()
field.value = target
plants.flush_regrow()  # what the timer does once changes rest
genome_regrow_s = time.perf_counter() - t
bpy.context.view_layer.update()  # the object's dimensions follow its new mesh
genome = sylva.Genome.from_json(tulip["sylva_genome"])
check(genome["branches.0.max_length"] == target and triangles(tulip) == len(genome.grow().mesh.indices)
      and tulip["sylva_genome"] != genome_before and tuple(tulip.dimensions) != size_before,
      f"a field's value regrows the plant: max length {target:g}, {size_before[2]:.3f} -> "
      f"{tulip.dimensions.z:.3f} m tall")
check(abs(field.slider - field.share_of(target)) < 1e-6, "the slider follows the typed value")
field.slider = 0.0
plants.flush_regrow()
check(sylva.Genome.from_json(tulip["sylva_genome"])["branches.0.max_length"] == field.soft_low == field.value,
      f"the slider at its left end sets the value to {field.soft_low:g}")
kept = tulip["sylva_genome"]
field.value = field.high + 100
check(tulip["sylva_genome"] == kept and field.value == field.soft_low
      and "branches[0].max_length" in tulip.sylva.error and f"to {field.high:g}" in tulip.sylva.error,
      f"a value out of range is refused, named with its range and value: {tulip.sylva.error!r}")
tulip.sylva.error = ""
# The heaviest example's regrow after a change, for the figure.
tree = objects["tree"]
bpy.context.view_layer.objects.active = tree
bpy.ops.sylva.load_fields()
turn = tree.sylva.fields["angles.turn"]
t = time.perf_counter()
turn.value = turn.value + 5
plants.flush_regrow()
tree_regrow_s = time.perf_counter() - t
check(tree.sylva.error == "" and sylva.Genome.from_json(tree["sylva_genome"])["angles.turn"] == turn.value,
      f"the L-system tree's turn angle set to {turn.value:g}°, regrown")


# -- Panels: drawn into a stand-in layout (headless bpy has no window to draw in) ----------
# It checks that every property a panel shows exists, every button names a registered
# operator, every icon is Blender's, for the states a user meets.
ICONS = set(bpy.types.UILayout.bl_rna.functions["label"].parameters["icon"].enum_items.keys())


class Properties:
    """An operator's properties as a button sets them: only the ones it has."""

    def __init__(self, rna):
        object.__setattr__(self, "rna", rna)

    def __setattr__(self, name, value):
        if name not in self.rna.properties:
            raise AssertionError(f"operator {self.rna.identifier} has no property {name}")


class Layout:
    alert = enabled = active = False

    def __init__(self, seen):
        self.seen = seen

    def _icon(self, kw):
        if kw.get("icon", "NONE") not in ICONS:
            raise AssertionError(f"no icon {kw['icon']}")

    def row(self, **kw):
        return self

    column = box = row

    def prop(self, data, name, **kw):
        if name not in data.bl_rna.properties:
            raise AssertionError(f"{data} has no property {name}")
        getattr(data, name)
        self.seen.append(f"prop {name}")

    def operator(self, idname, **kw):
        self._icon(kw)
        module, name = idname.split(".")
        if not hasattr(getattr(bpy.ops, module), name) or getattr(getattr(bpy.ops, module), name).get_rna_type() is None:
            raise AssertionError(f"no operator {idname}")
        self.seen.append(idname)
        return Properties(getattr(getattr(bpy.ops, module), name).get_rna_type())

    def label(self, text="", **kw):
        self._icon(kw)
        self.seen.append(text)


class Region:
    width = 280


def draw(panel, active, selected):
    seen = []
    context = type("Context", (), {"scene": scene, "active_object": active, "selected_objects": selected,
                                   "region": Region()})()
    if hasattr(panel, "poll") and not panel.poll(context):
        return None
    panel.draw(type("Panel", (), {"layout": Layout(seen)})(), context)
    return seen


try:
    for source in ("EXAMPLE", "FILE", "RANDOM"):
        settings.source = source
        drawn = draw(bpy.types.SYLVA_PT_grow, None, [])
        check("sylva.grow" in drawn, f"Grow panel ({source.lower()}): {', '.join(drawn)}")
    settings.source = "EXAMPLE"
    grid_plant = grid()[1]
    oak_obj.sylva.error = "InputError: sylva_genome:4:12: `depth` must be a whole number from 1 to 14, got 40"
    drawn = draw(bpy.types.SYLVA_PT_plant, oak_obj, [oak_obj])
    check("sylva.regrow" in drawn and "prop detail" in drawn and any("whole number" in d for d in drawn),
          f"Plant panel, with an error: {len(drawn)} items, the error wrapped over "
          f"{len(drawn[drawn.index('prop detail') + 1:drawn.index('sylva.regrow')])} lines")
    oak_obj.sylva.error = ""
    check({"prop foliage", "prop bark", "prop height", "prop density"} <= set(drawn),
          "Plant panel: Foliage, Bark, Height and Density")
    hints = []
    for obj in (objects["tulip"], oak_obj):
        with plants.quiet():
            obj.sylva.foliage = "oak"  # not regrown: the plant as grown, with a kind of leaves chosen
        drawn = draw(bpy.types.SYLVA_PT_plant, obj, [obj])
        with plants.quiet():
            obj.sylva.foliage = "NONE"
        hints.append(" ".join(d for d in drawn if "real size" in d or "it stands" in d))
    check(hints[0] and not hints[1],
          f"Plant panel, Foliage set at Height 0: on the tulip ({objects['tulip'].dimensions.z:.2f} m) "
          f"'{hints[0]}'; none on the oak ({oak_obj.dimensions.z:.2f} m)")
    check(draw(bpy.types.SYLVA_PT_plant, None, []) is None, "Plant panel hidden with no plant active")
    drawn = draw(bpy.types.SYLVA_PT_breed, grid_plant, [grid_plant, grid()[2]])
    check({"sylva.breed", "sylva.mutate", "sylva.cross", "sylva.keep"} <= set(drawn)
          and "2 favourite(s) selected" in drawn, f"Breed panel with a grid: {', '.join(drawn)}")
    drawn = draw(bpy.types.SYLVA_PT_evolve, None, [])
    check({"sylva.evolve", "sylva.evolve_picture", "sylva.mark_zone", "prop target", "prop picture"} <= set(drawn),
          f"Evolve panel: {', '.join(drawn)}")
    drawn = draw(bpy.types.SYLVA_PT_genome, objects["tulip"], [objects["tulip"]])
    check({"prop slider", "prop value", "sylva.field_help"} <= set(drawn),
          f"Genome panel: {len([d for d in drawn if d == 'prop slider'])} sliders, each with its box and help")
    drawn = draw(bpy.types.SYLVA_PT_genome, objects["helix"], [objects["helix"]])
    check(drawn == ["sylva.load_fields"], f"Genome panel before its fields are read: {', '.join(drawn)}")
    drawn = draw(bpy.types.SYLVA_PT_assets, oak_obj, [oak_obj])
    check({"sylva.wind", "sylva.lod", "sylva.forest"} <= set(drawn), f"Assets panel: {', '.join(drawn)}")
except AssertionError as e:
    check(False, f"panels draw: {e}")

# -- Figures ------------------------------------------------------------------------------------
# Timings against the figures are reported, not failed: on a shared machine they
# measure the neighbours too (the load average says how busy it was).
slow = []


def figure(seconds, target, what):
    ok = seconds < target
    print(("ok   " if ok else "SLOW ") + what)
    if not ok:
        slow.append(what)


print("\nfigures (bpy %s, %d cores, load average %.1f)" % (bpy.app.version_string, os.cpu_count(),
                                                         os.getloadavg()[0]))
print(f"     first grow of the session (flowering bush, {triangles(cold)} triangles, 28 textured "
      f"materials; imports sylva, makes the textures): {cold_s * 1000:.0f} ms")
for model, name in (("plantmaker", "tulip"), ("plantmaker", "conifer"), ("bintree", "oak"),
                    ("lsystem", "tree"), ("automata", "helix")):
    times = []
    for _ in range(2):
        t = time.perf_counter()
        obj = grown("EXAMPLE", model, example=name)
        times.append(time.perf_counter() - t)
    figure(times[1], 0.5, f"grow {name} ({triangles(obj)} triangles): first {times[0] * 1000:.0f} ms, "
          f"second {times[1] * 1000:.0f} ms (target under 500)")
for model, name in (("plantmaker", "tulip"), ("plantmaker", "conifer"), ("lsystem", "tree")):
    # Three steps of each kind: each draws other seeds, so other plants, of other sizes.
    mother = grown("EXAMPLE", model, example=name)
    for kind in ("breed", "cross"):
        steps, sizes = [], []
        for _ in range(3):
            select([mother] if kind == "breed" else [grid()[0], grid()[8]])
            t = time.perf_counter()
            getattr(bpy.ops.sylva, kind)()
            steps.append(time.perf_counter() - t)
            sizes.append(sum(triangles(o) for o in grid().values()) // 1000)
        what = "nine variants of the" if kind == "breed" else "two favourites crossed into seven,"
        figure(max(steps), 1.0, f"{kind}: {what} {name} ({'k, '.join(map(str, sizes))}k triangles in the grid): "
               f"{', '.join(f'{x * 1000:.0f}' for x in steps)} ms (target under 1000)")

print(f"     dressed: the binary oak ({dress_figures['bare']} triangles as grown) given Foliage oak "
      f"{dress_times['foliage'] * 1000:.0f} ms, then Height 12 {dress_times['height'] * 1000:.0f} ms: "
      f"{dress_figures['dressed']} triangles, {dress_figures['materials']} materials, "
      f"{dress_figures['height']:.2f} m tall (leaves to {dress_figures['top']:.2f} m); the leaf atlas "
      + ", ".join(f"{k} {v:.0%} cut away" for k, v in dress_figures["cut away"].items()))
print(f"     dressed: Foliage pine {dress_times['pine'] * 1000:.0f} ms; the species oak preset from "
      f"File {dress_times['preset'] * 1000:.0f} ms ({dress_figures['preset'][0]} triangles, "
      f"{dress_figures['preset'][1]:.2f} m)")
print(f"     evolve: 12 generations of 300 automata toward a sphere under a forbidden box, the best "
      f"shown as it improved: {evolve_s:.2f} s")
for what, seconds in (("the tulip's max length", genome_regrow_s), ("the L-system tree's turn angle", tree_regrow_s)):
    after = plants.REGROW_DELAY + seconds
    figure(after, 0.3, f"Genome panel: {what} set, regrown {after * 1000:.0f} ms after the change "
           f"({plants.REGROW_DELAY * 1000:.0f} ms waiting for changes to rest, {seconds * 1000:.0f} ms growing; "
           "target under 300)")
figure(forest_s, 5.0, f"forest: 1000 conifers of 8 variants as instances on a hill: {forest_s:.2f} s (target under 5)")
figure(rss_after / 1024, 1.0, f"forest: Blender's memory {rss_before:.0f} MB before, {rss_after:.0f} MB after "
       "(target under 1 GB)")

# -- Undo -------------------------------------------------------------------------------------
# Blender's window manager pushes an undo step after each UNDO operator run from the UI; bpy
# without a window pushes none, so the check pushes one after each operator, as the UI
# would, and then undoes it: what comes back is what a user's Ctrl-Z gives.


def undone(action):
    bpy.ops.ed.undo_push(message="before")
    action()
    bpy.ops.ed.undo_push(message="after")
    bpy.ops.ed.undo()


tree_name = objects["tree"].name  # Python's references to data do not outlive an undo
tulip_name = objects["tulip"].name
try:
    names = sorted(o.name for o in bpy.data.objects)
    undone(lambda: grown("EXAMPLE", "plantmaker", example="palm"))
    check(sorted(o.name for o in bpy.data.objects) == names, "Undo takes a grown plant back")
    cells_before = {k: (o.name, o["sylva_id"]) for k, o in grid().items()}
    step = bpy.context.scene.sylva.breed_step
    select([grid()[0]])
    undone(lambda: bpy.ops.sylva.mutate())
    cells_after = {k: (o.name, o["sylva_id"]) for k, o in grid().items()}
    check(cells_after == cells_before and bpy.context.scene.sylva.breed_step == step,
          "Undo takes a Mutate step back: the grid's nine plants and the step counter as they were")
    before = triangles(bpy.data.objects[tree_name])
    roots = bpy.data.objects[tree_name].sylva.roots
    undone(lambda: setattr(bpy.data.objects[tree_name].sylva, "roots", not roots))
    back = bpy.data.objects[tree_name]
    check(triangles(back) == before and back.sylva.roots == roots,
          f"Undo takes a setting's change back: the L-system tree's roots and its {before} triangles")
    before = (bpy.data.objects[tulip_name]["sylva_genome"], triangles(bpy.data.objects[tulip_name]))

    def slide():
        bpy.data.objects[tulip_name].sylva.fields["branches[0].max_length"].slider = 1.0
        plants.flush_regrow()

    undone(slide)
    back = bpy.data.objects[tulip_name]
    check((back["sylva_genome"], triangles(back)) == before,
          "Undo takes a Genome slider's change back: the tulip's genome and mesh as they were")
except RuntimeError as e:
    check(False, f"undo: {str(e).strip()}")
settings = bpy.context.scene.sylva

if render_dir:
    sys.path.insert(0, os.path.dirname(__file__))
    import blender_extension_render

    blender_extension_render.render(render_dir, plants, pictures)

print(f"\n{len(failures)} failure(s)" + (": " + "; ".join(failures) if failures else ""))
if slow:
    print(f"{len(slow)} figure(s) over target (load average {os.getloadavg()[0]:.1f}): " + "; ".join(slow))
sys.exit(1 if failures else 0)
