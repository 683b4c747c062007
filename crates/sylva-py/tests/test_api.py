"""The package's API on all four models: genomes, plants, meshes, exports, operators,
evolution runs, gardens, and the errors bad input gets."""

from __future__ import annotations

import gc
import json
import math
import os
import pickle
import signal
import struct
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import sylva

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

GENOMES = {
    "bintree": EXAMPLES / "bintree" / "oak.json",
    "automata": EXAMPLES / "automata" / "helix.json",
    "plantmaker": EXAMPLES / "plantmaker" / "tulip.json",
    "lsystem": EXAMPLES / "lsystem" / "herb.json",
    "grown": EXAMPLES / "grown" / "birch.json",
}

CONFIGS = {
    "bintree": EXAMPLES / "bintree" / "default.toml",
    "automata": EXAMPLES / "automata" / "sphere.toml",
    "plantmaker": EXAMPLES / "plantmaker" / "evolve.toml",
    "lsystem": EXAMPLES / "lsystem" / "evolve.toml",
    "grown": EXAMPLES / "grown" / "evolve.toml",
}

MODELS = sorted(GENOMES)


def glb_json(data: bytes) -> dict:
    """The JSON chunk of a GLB, after checking the header and chunk lengths."""
    magic, version, length = struct.unpack_from("<4sII", data)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    chunk, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    return json.loads(data[20 : 20 + chunk])


def test_models_are_the_five():
    assert sorted(sylva.models()) == MODELS


@pytest.mark.parametrize("model", MODELS)
def test_genome_files_round_trip(model, tmp_path):
    genome = sylva.Genome.load(GENOMES[model])
    assert genome.model == model
    assert sylva.Genome.from_dict(genome.to_dict()) == genome
    assert sylva.Genome.from_json(genome.to_json()) == genome
    assert pickle.loads(pickle.dumps(genome)) == genome
    genome.save(tmp_path / "copy.json")
    assert sylva.Genome.load(tmp_path / "copy.json") == genome
    assert genome.fields() and all(genome[f] is not None for f in genome.fields())


@pytest.mark.parametrize("model", MODELS)
def test_a_plant_grows_meshes_and_exports(model, tmp_path):
    genome = sylva.Genome.load(GENOMES[model])
    plant = genome.grow(seed=3)
    assert (plant.model, plant.seed) == (model, 3)
    assert plant.segments > 0 and plant.height > 0 and plant.volume > 0
    low, high = np.array(plant.bounds[0]), np.array(plant.bounds[1])
    assert (high >= low).all() and (high > low).any()
    measures = plant.measures()
    assert measures["height"] == pytest.approx(plant.height)
    assert all(math.isfinite(v) for v in measures.values())

    mesh = plant.mesh
    # The bounds are the mesh's, what a scene shows (they were the skeleton's, radii
    # swept round every end: a palm's top 0.4 m above its mesh).
    assert np.array_equal(low, mesh.positions.min(axis=0))
    assert np.array_equal(high, mesh.positions.max(axis=0))
    n, t = len(mesh.positions), len(mesh.indices)
    assert mesh.positions.shape == (n, 3) and mesh.positions.dtype == np.float32
    assert mesh.normals.shape == (n, 3) and mesh.uvs.shape == (n, 2)
    assert mesh.indices.shape == (t, 3) and mesh.indices.dtype == np.uint32
    assert mesh.triangle_materials.shape == (t,)
    assert t > 0 and mesh.indices.max() < n
    assert mesh.triangle_materials.max() < len(mesh.materials)
    assert np.allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-3)
    assert (mesh.positions.min(axis=0) >= low - 1e-3).all()
    assert (mesh.positions.max(axis=0) <= high + 1e-3).all()
    assert {m["kind"] for m in mesh.materials} <= {"bark", "leaf", "flower", "root"}
    for array in [mesh.positions, mesh.normals, mesh.uvs, mesh.indices, mesh.triangle_materials]:
        assert not array.flags.writeable and not array.flags.owndata, "a read-only view"
        with pytest.raises(ValueError):
            array.flags.writeable = True
        with pytest.raises(ValueError):
            array[0] = 0

    glb = plant.glb()
    doc = glb_json(glb)
    shared = {p["attributes"]["POSITION"] for m in doc["meshes"] for p in m["primitives"]}
    assert sum(doc["accessors"][a]["count"] for a in shared) == n
    assert glb == genome.grow(seed=3).glb(), "the same genome and seed give the same bytes"
    extras = doc["nodes"][0]["extras"]
    assert sylva.Genome.from_dict(extras["genome"]) == genome and extras["seed"] == 3

    for name in ["plant.glb", "plant.obj", "plant.wrl"]:
        plant.export(tmp_path / name)
        assert (tmp_path / name).stat().st_size > 0
    assert (tmp_path / "plant.glb").read_bytes() == glb
    assert (tmp_path / "plant.mtl").exists()

    png = plant.render(tmp_path / "plant.png", view="front", size=(64, 48))
    assert png.startswith(b"\x89PNG") and (tmp_path / "plant.png").read_bytes() == png
    assert struct.unpack(">II", png[16:24]) == (64, 48)


@pytest.mark.parametrize("model", MODELS)
def test_operators_make_valid_genomes_of_the_model(model):
    genome = sylva.Genome.load(GENOMES[model])
    mutant = genome.mutate(seed=11)
    assert mutant.model == model
    assert mutant == genome.mutate(seed=11), "mutation is seeded"
    assert any(genome.mutate(seed=s) != genome for s in range(5))
    other = sylva.Genome.random(model, seed=2)
    child, parents = sylva.cross([genome, other], seed=4)
    assert child.model == model and set(parents) <= {0, 1}
    assert child == sylva.cross([genome, other], seed=4)[0]
    for g in [mutant, other, child]:
        assert sylva.Genome.from_json(g.to_json()) == g
        g.grow(seed=1)


@pytest.mark.parametrize("model", MODELS)
def test_random_genomes_grow_into_branching_plants(model):
    genomes = [sylva.Genome.random(model, seed) for seed in range(3)]
    for seed, genome in enumerate(genomes):
        assert genome == sylva.Genome.random(model, seed)
        plant = genome.grow()
        assert plant.tips >= 2, f"seed {seed}: {plant.tips} tips"
    assert len(set(genomes)) == 3


def test_wind_and_levels_of_detail_come_as_gltf():
    tulip = sylva.Genome.load(GENOMES["plantmaker"])
    still = tulip.grow()
    assert still.wind is None
    windy = tulip.grow(wind=2.5, wind_period=3)
    assert windy.wind == {"strength": 2.5, "period": 3.0, "joints": windy.wind["joints"],
                          "left_out": 0, "clip": "wind"}
    assert windy.wind["joints"] > 1
    gltf = glb_json(windy.glb())
    assert len(gltf["skins"][0]["joints"]) == windy.wind["joints"]
    assert [a["name"] for a in gltf["animations"]] == ["wind"]
    assert "skins" not in glb_json(still.glb())
    lod = glb_json(still.lod_glb(3, name="tulip"))
    # Three meshed levels, then the impostor: crossed cards showing the plant, unlit.
    names = [n["name"] for n in lod["nodes"] if "mesh" in n]
    assert names == ["tulip_LOD0", "tulip_LOD1", "tulip_LOD2", "tulip_LOD3"]
    assert lod["nodes"][-1]["extras"]["lod"]["impostor"] is True
    assert "KHR_materials_unlit" in lod["extensionsUsed"]
    assert still.lod_glb(3, name="tulip") == still.lod_glb(3, name="tulip")
    assert "skins" in glb_json(windy.lod_glb(2))
    for bad, names in [(dict(wind=11), "wind"), (dict(wind=-1), "wind"),
                       (dict(wind_period=3), "wind_period"), (dict(wind=1, wind_period=100), "wind_period")]:
        with pytest.raises(sylva.InputError, match=names):
            tulip.grow(**bad)
    for levels in (1, 9):
        with pytest.raises(sylva.InputError, match="levels: expected an int from 2 to 8"):
            still.lod_glb(levels)
    with pytest.raises(TypeError, match="wind"):
        pickle.dumps(windy)


def test_texture_png_is_the_picture_the_glb_embeds():
    plant = sylva.Genome.load(GENOMES["plantmaker"]).grow()
    ids = {m["texture"] for m in plant.mesh.materials if m["texture"] is not None}
    assert ids
    glb = plant.glb()
    gltf = glb_json(glb)
    chunk = struct.unpack_from("<I", glb, 12)[0]
    binary = glb[20 + chunk + 8 :]
    embedded = {}
    for image in gltf["images"]:
        view = gltf["bufferViews"][image["bufferView"]]
        start = view.get("byteOffset", 0)
        embedded[int(image["name"].rsplit("-", 1)[1])] = binary[start : start + view["byteLength"]]
    for tid in ids:
        png = sylva.texture_png(tid)
        assert png == embedded[tid]
        assert png.startswith(b"\x89PNG") and struct.unpack(">II", png[16:24]) == (256, 256)
    with pytest.raises(sylva.InputError, match="id"):
        sylva.texture_png(-1)


def test_mesh_arrays_outlive_their_plant():
    plant = sylva.Genome.load(GENOMES["plantmaker"]).grow()
    expected = plant.mesh.positions.copy()
    positions = plant.mesh.positions
    del plant
    gc.collect()
    assert (positions == expected).all()
    scene = sylva.garden([sylva.Genome.load(GENOMES["plantmaker"])], count=2, area=(2, 2))
    meshes = scene.meshes()
    del scene
    gc.collect()
    assert all(len(m.indices) > 0 and m.indices.max() < len(m.positions) for m in meshes)


def test_the_pipe_taper_thickens_the_trunk_and_keeps_the_twigs():
    genome = sylva.Genome.load(EXAMPLES / "lsystem" / "tree.json")
    plain, tapered = genome.grow(roots=False), genome.grow(roots=False, taper=2.5)
    assert tapered.segments == plain.segments
    assert tapered.volume > 1.5 * plain.volume, "the trunk carries every tip above it"
    assert tapered.glb() == genome.grow(roots=False, taper=2.5).glb()
    for bad in (1.5, 3.5, float("nan")):
        with pytest.raises(sylva.InputError, match="taper"):
            genome.grow(taper=bad)


def test_the_skeleton_is_the_plant_as_data():
    genome = sylva.Genome.load(EXAMPLES / "lsystem" / "tree.json")
    plant = genome.grow(roots=False, taper=2.5)
    skeleton = plant.skeleton()
    assert (skeleton["kind"], skeleton["format"]) == ("sylva-skeleton", 1)
    assert skeleton["origin"]["model"] == "lsystem" and skeleton["origin"]["seed"] == plant.seed
    assert skeleton["taper"] == {"pipe_exponent": 2.5} and skeleton["roots"] is False
    segments, organs = skeleton["segments"], skeleton["organs"]
    n = plant.segments
    assert segments["start"].shape == (n, 3) and segments["end"].shape == (n, 3)
    assert segments["start"].dtype == np.float32 and segments["parent"].dtype == np.int64
    assert len(segments["kind"]) == n and organs["position"].shape == (plant.organs, 3)
    assert "root" not in segments["kind"]
    # Parents come first (-1: none); woody radii taper towards the tips.
    assert (segments["parent"] < np.arange(n)).all()
    woody = segments["woody"]
    assert (segments["end_radius"][woody] <= segments["start_radius"][woody]).all()
    # The same plant as the skeleton file says, value for value.
    file = json.loads(plant.skeleton_json())
    assert file["origin"] == skeleton["origin"] and file["materials"] == skeleton["materials"]
    for i in (0, n // 2, n - 1):
        row = file["segments"][i]
        assert segments["start"][i].tolist() == pytest.approx(row["start"])
        assert segments["parent"][i] == (-1 if row["parent"] is None else row["parent"])
        assert segments["kind"][i] == row["kind"] and segments["order"][i] == row["order"]
    assert [o["kind"] for o in file["organs"]] == organs["kind"]
    again = genome.grow(roots=False, taper=2.5).skeleton()
    for part in ("segments", "organs"):
        for field, values in skeleton[part].items():
            assert np.array_equal(np.asarray(values), np.asarray(again[part][field])), field


def test_cross_keeps_models_apart():
    with pytest.raises(sylva.InputError, match="plantmaker|bintree|model"):
        sylva.cross([sylva.Genome.load(GENOMES["plantmaker"]),
                     sylva.Genome.load(GENOMES["bintree"])], seed=1)


def test_plantmaker_cross_takes_dominance_and_level():
    tulip = sylva.Genome.load(GENOMES["plantmaker"])
    fern = sylva.Genome.load(EXAMPLES / "plantmaker" / "fern.json")
    children = {sylva.cross([tulip, fern], seed=s, dominance=[0.9, 0.1],
                            settings={"crossover": "high"})[0].to_json() for s in range(6)}
    assert len(children) > 1


def test_fields_are_read_and_set_with_the_files_checks():
    oak = sylva.Genome.load(GENOMES["bintree"])
    deeper = oak.with_field("depth", oak["depth"] - 1)
    assert deeper["depth"] == oak["depth"] - 1 and deeper != oak
    assert deeper.grow().segments < oak.grow().segments
    with pytest.raises(sylva.InputError) as bad:
        oak["depth"] = 10**9
    assert "depth" in str(bad.value)
    with pytest.raises(sylva.InputError):
        oak["length"] = math.nan
    with pytest.raises(sylva.InputError):
        oak["no_such_field"] = 1
    with pytest.raises(KeyError):
        oak["no_such_field"]
    tulip = sylva.Genome.load(GENOMES["plantmaker"])
    first = tulip["branches.0"]
    assert isinstance(first, dict)


def test_bad_genome_files_name_the_place(tmp_path):
    path = tmp_path / "bad.json"
    text = GENOMES["bintree"].read_text()
    path.write_text(text.replace('"depth": ', '"depth": -', 1))
    with pytest.raises(sylva.InputError) as bad:
        sylva.Genome.load(path)
    e = bad.value
    assert isinstance(e, ValueError) and isinstance(e, sylva.SylvaError)
    assert e.path == str(path) and e.line >= 1 and e.column >= 1
    assert str(e).startswith(f"{path}:{e.line}:{e.column}")

    path.write_text(text[: len(text) // 2])
    with pytest.raises(sylva.InputError, match="bad.json"):
        sylva.Genome.load(path)
    with pytest.raises(sylva.InputError):
        sylva.Genome.from_dict({"model": "bintree", "format": 1, "depth": 3, "extra": 1})
    with pytest.raises(sylva.InputError, match="model"):
        sylva.Genome.from_dict({"model": "fern", "format": 1})
    with pytest.raises(ValueError):
        sylva.Genome.from_dict({"model": "bintree", "depth": math.inf})
    # A file that is not there is Python's own FileNotFoundError (an OSError).
    with pytest.raises(FileNotFoundError, match="missing.json") as missing:
        sylva.Genome.load(tmp_path / "missing.json")
    assert missing.value.filename == str(tmp_path / "missing.json")
    with pytest.raises(OSError):
        sylva.Config.load(tmp_path / "missing.toml")


def test_evolution_steps_checkpoints_and_resumes(tmp_path):
    config = sylva.Config.from_dict(
        {**sylva.Config.load(CONFIGS["bintree"]).to_dict()}, base=EXAMPLES / "bintree"
    ).with_run(population=16, generations=4, seed=9)
    run = sylva.Evolution(config, threads=1)
    row = run.step()
    assert run.generation == 1 and row["generation"] == 1
    run.run(2)
    assert [r["generation"] for r in run.stats] == [0, 1, 2, 3]
    assert set(run.term_names) <= set(run.stats[-1])
    best = run.best()
    assert best.fitness == max(m.fitness for m in run.population())
    assert best.genome.model == "bintree" and len(run.population()) == 16
    assert run.fittest(3)[0].id == best.id
    assert run.family(best.id)[0].id == best.id
    run.save(tmp_path / "run.json")
    resumed = sylva.Evolution.resume(config, path=tmp_path / "run.json", threads=2)
    assert resumed.step() == {**run.step(), "seconds": resumed.stats[-1]["seconds"]}
    assert resumed.best().genome == run.best().genome


@pytest.mark.parametrize("model", MODELS)
def test_every_model_evolves(model):
    config = sylva.Config.load(CONFIGS[model]).with_run(population=8, generations=2, seed=3)
    run = sylva.Evolution(config, threads=2)
    rows = []
    run.run(on_generation=rows.append)
    assert run.generation == 2 and len(rows) == 2
    assert run.best().genome.model == model


def test_bad_configs_name_the_field():
    with pytest.raises(sylva.InputError, match="population") as bad:
        sylva.Config.default().with_run(population=0)
    assert "population" in bad.value.location
    with pytest.raises(sylva.InputError) as bad:
        sylva.Config.from_toml("[run]\npopulation = 10\nbogus = 1\n", source="c.toml")
    assert bad.value.path == "c.toml" and bad.value.line == 3
    with pytest.raises(sylva.InputError):
        sylva.Config.from_dict({"run": {"population": math.nan}})


def test_long_calls_release_the_gil():
    config = sylva.Config.load(CONFIGS["automata"]).with_run(population=1000, generations=40)
    run = sylva.Evolution(config, threads=1)
    run.step()
    ticks = 0
    inside = False
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            if inside:
                ticks += 1
            time.sleep(0.001)

    ticker = threading.Thread(target=count)
    ticker.start()
    inside = True
    run.run(30)
    inside = False
    done.set()
    ticker.join()
    # Held, the GIL would let the ticker in only at the bytecode boundaries just before and
    # after the one Rust call (a tick or two); released, it ticks all through the call's
    # hundreds of milliseconds. No clock is read, so a busy machine gives the same verdict.
    assert ticks >= 10, ticks


def test_gardens_and_scenes():
    tulip = sylva.Genome.load(GENOMES["plantmaker"])
    fern = sylva.Genome.load(EXAMPLES / "plantmaker" / "fern.json")
    garden = sylva.garden([tulip, fern], count=3, area=(4, 4), seed=2)
    assert garden.plants == 6 and garden.triangles > 0
    again = sylva.garden(path=None, genomes=[tulip, fern], count=3, area=(4, 4), seed=2)
    assert again.glb() == garden.glb()
    assert len(garden.meshes()) == 6
    with pytest.raises(sylva.InputError, match="count"):
        sylva.garden([tulip], count=0)
    with pytest.raises(sylva.InputError, match="area"):
        sylva.garden([tulip], area=(math.nan, 1))
    with pytest.raises(sylva.InputError, match="plantmaker"):
        sylva.garden([sylva.Genome.load(GENOMES["bintree"])])

    plants = [tulip.grow(seed=s) for s in range(3)]
    scene = sylva.scene(plants, [(0, 0), (1, 0), (0, 1)], turns=[0, 1, 2])
    assert scene.plants == 3 and len(glb_json(scene.glb())["nodes"]) >= 3
    with pytest.raises(sylva.InputError, match="positions"):
        sylva.scene(plants, [(0, 0)])
    with pytest.raises(sylva.InputError):
        sylva.scene(plants, [(0, 0), (1, math.inf), (0, 1)])


def test_python_values_are_taken_as_python_code_gives_them(tmp_path):
    tulip = sylva.Genome.load(GENOMES["plantmaker"])
    plant = tulip.grow(seed=np.int64(3), taper=np.float32(2.5))
    # A pair is any sequence of two: a tuple, a list, a numpy array.
    png = plant.render(size=[64, 48])
    assert png == plant.render(size=(64, 48)) == plant.render(size=np.array([64, 48]))
    assert struct.unpack(">II", png[16:24]) == (64, 48)
    with pytest.raises(TypeError, match="two values"):
        plant.render(size=[64, 48, 2])
    with pytest.raises(TypeError, match="two values"):
        plant.render(size="64")
    assert sylva.garden([tulip], count=2, area=[4, 4]).plants == 2
    # numpy scalars are the numbers they hold, in fields and dicts.
    oak = sylva.Genome.load(GENOMES["bintree"])
    assert oak.with_field("length_ratio", np.float32(0.75))["length_ratio"] == pytest.approx(0.75)
    assert oak.with_field("depth", np.int64(4))["depth"] == 4
    config = sylva.Config.from_dict({"run": {"population": np.int64(8), "generations": 1}})
    assert config.to_dict()["run"]["population"] == 8
    with pytest.raises(sylva.InputError, match="not JSON"):
        sylva.Config.from_dict({"run": {"population": {1, 2}}})
    # A run starts from a Config, a dict or a config file's path, as islands() does.
    path = tmp_path / "c.toml"
    path.write_text('model = "bintree"\n[run]\npopulation = 8\ngenerations = 1\nseed = 2\n')
    runs = [sylva.Evolution(c, threads=1) for c in (sylva.Config.load(path), str(path), path)]
    runs.append(sylva.Evolution({"model": "bintree", "run": {"population": 8, "seed": 2}}, threads=1))
    assert len({r.best().genome.to_json() for r in runs}) == 1
    with pytest.raises(TypeError, match="Config, a dict or the path"):
        sylva.Evolution(42)


def test_messages_speak_python():
    with pytest.raises(sylva.InputError) as e:
        sylva.Config.from_dict({"run": {"population": "abc"}})
    assert 'str "abc", expected an int' in str(e.value), str(e.value)
    with pytest.raises(sylva.InputError) as e:
        sylva.Config.from_dict({"run": {"seed": -1}})
    assert "expected a non-negative int" in str(e.value) and "u64" not in str(e.value)
    with pytest.raises(sylva.InputError) as e:
        sylva.Genome.from_dict({"model": "bintree", "format": 1, "depth": True})
    assert "bool True" in str(e.value) and "i64" not in e.value.detail


def test_counts_sizes_and_seeds_out_of_range_are_value_errors_naming_the_argument():
    config = {"model": "bintree", "run": {"population": 8, "generations": 2, "seed": 1}}
    run = sylva.Evolution(config, threads=1)
    oak = sylva.Genome.load(GENOMES["bintree"])
    tulip = sylva.Genome.load(GENOMES["plantmaker"])
    varieties = sylva.varieties(config, threads=1)
    calls = {
        "run.run(-3)": (lambda: run.run(-3), "generations"),
        "run.run(2**200)": (lambda: run.run(2**200), "generations"),
        "Evolution(threads=-1)": (lambda: sylva.Evolution(config, threads=-1), "threads"),
        "fitness_batch=-1": (lambda: sylva.Evolution(config, fitness_batch=-1), "fitness_batch"),
        "resume(threads=-1)": (
            lambda: sylva.Evolution.resume(sylva.Config.from_dict(config),
                                           text=run.checkpoint(), threads=-1), "threads"),
        "run.fittest(-1)": (lambda: run.fittest(-1), "count"),
        "run.member(-1)": (lambda: run.member(-1), "id"),
        "run.keep_history(-1)": (lambda: run.keep_history(-1), "generations"),
        "run.emigrants(-1)": (lambda: run.emigrants(-1), "count"),
        "varieties(threads=-1)": (lambda: sylva.varieties(config, threads=-1), "threads"),
        "varieties.run(-1)": (lambda: varieties.run(-1), "generations"),
        "varieties.variety(-1)": (lambda: varieties.variety(-1), "cell"),
        "Genome.random(-1)": (lambda: sylva.Genome.random("bintree", -1), "seed"),
        "grow(seed=-1)": (lambda: oak.grow(seed=-1), "seed"),
        "mutate(-1)": (lambda: oak.mutate(-1), "seed"),
        "cross(seed=-1)": (lambda: sylva.cross([oak, oak], -1), "seed"),
        "garden(count=-1)": (lambda: sylva.garden([tulip], count=-1), "count"),
        "garden(seed=-1)": (lambda: sylva.garden([tulip], count=1, seed=-1), "seed"),
        "lod_glb(-1)": (lambda: oak.grow().lod_glb(-1), "levels"),
        "GenomeSpace(dim=-1)": (lambda: sylva.GenomeSpace(config, dim=-1), "dim"),
        "set_max_memory(-1)": (lambda: sylva.set_max_memory(-1), "bytes"),
        "match(population=-1)": (
            lambda: sylva.match(np.ones((32, 32), bool), population=-1), "population"),
    }
    for call, (make, name) in calls.items():
        with pytest.raises(sylva.InputError) as refused:
            make()
        e = refused.value
        assert isinstance(e, ValueError), call
        assert e.location == name and "expected an int from 0 to" in str(e), f"{call}: {e}"


def test_pictures_exports_and_checkpoints_refuse_bad_input_in_python_s_terms(tmp_path):
    plant = sylva.Genome.load(GENOMES["bintree"]).grow()
    scene = sylva.garden([sylva.Genome.load(GENOMES["plantmaker"])], count=1)
    for size in [(0, 0), (15, 64), (64, 8193), (-1, 64)]:
        for picture in (plant, scene):
            with pytest.raises(sylva.InputError) as refused:
                picture.render(size=size)
            assert refused.value.location == "size" and "16 to 8192" in str(refused.value)
    # A folder that is not there: Python's own error, naming the file.
    for thing in (plant, scene):
        with pytest.raises(FileNotFoundError) as missing:
            thing.export(tmp_path / "missing" / "plant.glb")
        assert "missing" in str(missing.value) and missing.value.filename
    # STL, as the docs say.
    plant.export(tmp_path / "plant.stl")
    stl = (tmp_path / "plant.stl").read_bytes()
    (triangles,) = struct.unpack_from("<I", stl, 80)
    assert triangles > 0 and len(stl) == 84 + 50 * triangles
    # A checkpoint that is not JSON says so, where.
    config = sylva.Config.from_dict({"model": "bintree", "run": {"population": 8}})
    for text, columns in [("not json", [1]), ('{"config": {"model":', range(2, 21))]:
        with pytest.raises(sylva.InputError) as refused:
            sylva.Evolution.resume(config, text=text)
        e = refused.value
        assert "not JSON" in str(e) and "ident" not in str(e) and "EOF" not in str(e), str(e)
        assert e.line == 1 and e.column in columns, str(e)
    with pytest.raises(sylva.InputError, match="not JSON"):
        sylva.Varieties.resume(config, text="not json")


def png(path: Path, pixels: np.ndarray) -> Path:
    """Writes an 8-bit grey (h, w) or RGB (h, w, 3) PNG file, without a picture library."""
    import zlib

    height, width = pixels.shape[:2]
    kind = 0 if pixels.ndim == 2 else 2
    raw = b"".join(b"\x00" + row.tobytes() for row in pixels.astype(np.uint8))

    def chunk(name: bytes, data: bytes) -> bytes:
        body = name + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, kind, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
                     + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
    return path


def test_match_takes_numpy_masks_as_it_takes_pictures(tmp_path):
    # A cone: ink (True) widening downwards, on a 48 x 64 canvas.
    y, x = np.mgrid[0:64, 0:48]
    mask = (np.abs(x - 24) < (y - 4) * 0.35) & (y > 4) & (y < 60)
    trunk = (np.abs(x - 24) < 2) & (y >= 56)
    mask |= trunk
    side = np.abs(x - 24) < (y - 4) * 0.25
    ink = np.where(mask, 0, 255).astype(np.uint8)
    files = png(tmp_path / "cone.png", ink), png(tmp_path / "side.png", np.where(side, 0, 255))
    kwargs = dict(model="bintree", generations=3, population=10, seed=4)

    def result(run):
        return run.best().genome, [{k: v for k, v in r.items() if k != "seconds"} for r in run.stats]

    from_files = result(sylva.match(files[0], side=files[1], **kwargs))
    assert result(sylva.match(mask, side=side, **kwargs)) == from_files
    # Any numbers (ink: nonzero), and a uint8 picture read as its PNG file is.
    assert result(sylva.match(mask * 0.5, side=side.astype(np.int32), **kwargs)) == from_files
    rgb = np.repeat(ink[:, :, None], 3, axis=2)
    png(tmp_path / "rgb.png", rgb)
    assert result(sylva.match(rgb, side=side, **kwargs)) == result(
        sylva.match(tmp_path / "rgb.png", side=side, **kwargs))
    # What a mask cannot be is refused naming the argument.
    with pytest.raises(sylva.InputError, match="astype\\(bool\\)"):
        sylva.match(mask.astype(np.uint8), **kwargs)
    with pytest.raises(sylva.InputError, match="side"):
        sylva.match(mask, side=np.zeros((4, 4, 4)), **kwargs)
    with pytest.raises(TypeError, match="target"):
        sylva.match(np.array([["a"]]), **kwargs)
    with pytest.raises(TypeError, match="target"):
        sylva.match(42, **kwargs)
    with pytest.raises(sylva.InputError):
        sylva.match(np.zeros((64, 48), bool), **kwargs)  # no ink: no outline


def test_a_topiary_match_clips_its_plants_to_the_outline():
    y, x = np.mgrid[0:64, 0:48]
    cone = ((np.abs(x - 24) < (y - 4) * 0.35) & (y > 4) & (y < 60)) | ((np.abs(x - 24) < 2) & (y >= 56))
    kwargs = dict(model="plantmaker", generations=1, population=6, seed=2)
    pruned = sylva.match(cone, topiary=True, **kwargs)
    best = pruned.best()
    inside, whole = pruned.grow(), best.genome.grow()
    assert inside.organs < whole.organs
    assert pruned.grow(best).glb() == inside.glb()
    free = sylva.match(cone, **kwargs)
    assert free.grow().glb() == free.best().genome.grow().glb()


def test_match_evolves_towards_a_picture(tmp_path):
    target = EXAMPLES / "match" / "cone.png"
    run = sylva.match(target, model="bintree", generations=6, population=12, seed=4)
    assert run.term_names == ["iou"]
    best = run.best()
    assert 0.0 < best.terms["iou"] <= 1.0
    assert best.fitness == best.terms["iou"]
    again = sylva.match(str(target), model="bintree", generations=6, population=12, seed=4)
    assert again.best().genome == best.genome
    # The outline joins the config the run records.
    assert "[match]" in run.config.to_toml()
    # A picture that is not one is refused naming the file.
    text = tmp_path / "notes.png"
    text.write_text("not a picture")
    with pytest.raises(sylva.InputError, match="notes.png"):
        sylva.match(text, generations=1)
    with pytest.raises(sylva.InputError, match="seconds"):
        sylva.match(target, generations=1, seconds=5)
    # A first generation that takes minutes is cut when the match's second is up.
    for model in ["plantmaker", "auto"]:
        with pytest.raises(sylva.InputError, match="population"):
            sylva.match(target, model=model, population=200_000, seconds=1)


def test_ctrl_c_stops_a_run_and_leaves_it_whole():
    import _thread

    run = sylva.Evolution(CONFIGS["bintree"], threads=1)
    # Ctrl-C while the run breeds (the main thread is in Rust, the GIL released). Without
    # it, 100,000 generations would take many minutes.
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            run.run(100_000)
    finally:
        timer.cancel()
    stopped = run.generation
    assert 0 < stopped < 100_000
    run.step()
    assert run.generation == stopped + 1


def sigint_after(seconds: float) -> threading.Timer:
    """A real SIGINT to this process (what Ctrl-C sends) after `seconds`."""
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def test_ctrl_c_stops_making_a_huge_population():
    # 400 L-system plants, each grown for 150 steps in a voxel world: about 50 s on two
    # threads uninterrupted. Ctrl-C is heard within one plant's growth.
    config = sylva.Config.load(CONFIGS["lsystem"]).with_run(population=400)
    timer = sigint_after(0.3)
    started = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            sylva.Evolution(config, threads=2)
    finally:
        timer.cancel()
    assert time.perf_counter() - started < 10


def test_ctrl_c_stops_a_long_generation_and_leaves_the_run_as_it_was():
    config = sylva.Config.load(CONFIGS["lsystem"]).with_run(population=16, seed=3)
    run = sylva.Evolution(config, threads=2)
    before = run.checkpoint()
    best = run.best()
    # One generation of these 16 plants takes seconds: it is under way when the signal comes.
    timer = sigint_after(0.1)
    started = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            run.step()
    finally:
        timer.cancel()
    assert time.perf_counter() - started < 10
    # The run reads, checkpoints and pickles as it was before the generation (the library's
    # tests step it on, exactly as if it had not been stopped).
    assert run.generation == 0 and len(run.stats) == 1
    assert run.checkpoint() == before
    assert run.best() == best
    assert pickle.loads(pickle.dumps(run)).checkpoint() == before


def test_budgets_are_set_from_python_and_refusals_say_how():
    default = sylva.max_memory()
    assert default > 0
    try:
        sylva.set_max_memory(1 << 20)
        assert sylva.max_memory() == 1 << 20
        config = sylva.Config.load(CONFIGS["bintree"]).with_run(population=100_000)
        with pytest.raises(sylva.LimitError) as refused:
            sylva.Evolution(config)
        message = str(refused.value)
        assert "sylva.set_max_memory(bytes)" in message and "--max-memory" not in message
    finally:
        sylva.set_max_memory(0)
    assert sylva.max_memory() == default
    # An L-system population of a million is refused before any of it grows.
    config = sylva.Config.load(CONFIGS["lsystem"]).with_run(population=1_000_000)
    with pytest.raises(sylva.LimitError):
        sylva.Evolution(config)
    with pytest.raises(sylva.InputError, match="seconds"):
        sylva.set_max_time(float("nan"))


@pytest.mark.parametrize("model", MODELS)
def test_plants_meshes_and_members_pickle_exactly(model):
    genome = sylva.Genome.load(GENOMES[model])
    plants = [genome.grow(seed=3), genome.grow(seed=4, roots=False, taper=2.5)]
    for plant in plants:
        copy = pickle.loads(pickle.dumps(plant))
        assert (copy.genome, copy.seed) == (plant.genome, plant.seed)
        assert copy.glb() == plant.glb(), "it grows again to the same bytes"
        assert copy.skeleton_json() == plant.skeleton_json()
    mesh = plants[0].mesh
    copy = pickle.loads(pickle.dumps(mesh))
    for name in ["positions", "normals", "uvs", "indices", "triangle_materials"]:
        a, b = getattr(mesh, name), getattr(copy, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name
        assert not b.flags.writeable, name
    assert copy.materials == mesh.materials
    run = sylva.Evolution(sylva.Config.load(CONFIGS[model]).with_run(population=6, seed=2),
                          threads=1)
    for member in run.population():
        copy = pickle.loads(pickle.dumps(member))
        assert copy == member
        assert (copy.id, copy.genome, copy.fitness, copy.terms, copy.operator, copy.parents) == (
            member.id, member.genome, member.fitness, member.terms, member.operator,
            member.parents)


def test_genomes_are_hashable():
    oak = sylva.Genome.load(GENOMES["bintree"])
    same = sylva.Genome.from_json(oak.to_json())
    other = oak.mutate(seed=3)
    assert hash(oak) == hash(same) and {oak, same, other} == {oak, other}
    assert {oak: 1}[same] == 1


def test_plants_meshes_and_members_cross_processes():
    import concurrent.futures
    import copy
    import multiprocessing

    plant = sylva.Genome.load(GENOMES["plantmaker"]).grow(seed=2)
    member = sylva.Evolution(CONFIGS["bintree"], threads=1).best()
    # A fresh interpreter (spawn) unpickles each, copies it, and sends it back.
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=context) as pool:
        back = list(pool.map(copy.copy, [plant, plant.mesh, member, member.genome]))
    assert back[0].glb() == plant.glb()
    assert np.array_equal(back[1].positions, plant.mesh.positions)
    assert back[2] == member and back[3] == member.genome


def test_a_run_pickles_through_its_checkpoint():
    run = sylva.Evolution(CONFIGS["automata"], threads=1)
    run.run(2)
    copy = pickle.loads(pickle.dumps(run))
    assert copy.generation == run.generation == 2
    assert copy.best().genome == run.best().genome
    # Both go on alike, as a resumed run does.
    run.step()
    copy.step()
    assert copy.best().genome == run.best().genome
    assert copy.stats[-1]["best"] == run.stats[-1]["best"]


def test_leaves_needles_and_bark_at_real_size_and_the_plausibility_report(tmp_path):
    oak = sylva.Genome.load(GENOMES["bintree"])
    dressed = oak.grow(height=14.0, foliage="oak")
    bare = oak.grow(height=14.0)
    report = dressed.inspect()
    assert report["leaf_length"]["verdict"] == "real"
    assert 0.08 <= report["leaf_length"]["value"] <= 0.12
    assert all(f["verdict"] != "implausible" for f in report.values())
    assert bare.inspect()["leaf_length"]["value"] is None
    assert report["triangles"]["value"] <= 40_000
    path = tmp_path / "oak.glb"
    dressed.export(path)
    text = path.read_bytes()
    assert b'"alphaMode":"MASK"' in text and b'"foliage":"oak"' in text
    # A species preset, its arguments overriding the file's.
    pine = sylva.Genome.grow_preset(EXAMPLES / "species" / "pine.toml", height=12.0)
    assert 11.0 < pine.inspect()["height"]["value"] < 13.5
    assert pine.inspect()["leaf_length"]["value"] < 0.08
    # Bad kinds and values: ValueError naming the argument and what it takes.
    with pytest.raises(ValueError, match="foliage.*choose one of oak"):
        oak.grow(foliage="palm")
    with pytest.raises(ValueError, match="bark.*smooth, birch, furrowed, plated"):
        oak.grow(bark="cork")
    for density in (0.0, -1.0, float("nan"), 1e40):
        with pytest.raises(ValueError, match="density"):
            oak.grow(foliage="oak", density=density)
    with pytest.raises(ValueError, match="height"):
        oak.grow(height=-3.0)
