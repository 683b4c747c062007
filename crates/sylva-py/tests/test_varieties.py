"""Maps of varieties (`sylva.varieties`) and genomes as vectors (`sylva.GenomeSpace`) on all
four models: shapes, determinism, resuming, Ctrl-C, decoding, scoring as the native run
scores, and the errors bad input gets."""

from __future__ import annotations

import json
import pickle
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import sylva

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

CONFIGS = {
    "bintree": EXAMPLES / "bintree" / "default.toml",
    "automata": EXAMPLES / "automata" / "sphere.toml",
    "plantmaker": EXAMPLES / "plantmaker" / "evolve.toml",
    "lsystem": EXAMPLES / "lsystem" / "evolve.toml",
}

MODELS = sorted(CONFIGS)


def map_config(model: str, initial: int = 30, batch: int = 20, seed: int = 5, **run) -> sylva.Config:
    """The model's example config with a small map (its start files found beside it)."""
    data = sylva.Config.load(CONFIGS[model]).to_dict()
    data["run"].update(strategy="map-elites", seed=seed, **run)
    data["map"] = {"initial": initial, "batch": batch}
    return sylva.Config.from_dict(data, base=CONFIGS[model].parent)


def archive_arrays(archive: sylva.Archive) -> tuple:
    return (
        archive.cells.tolist(),
        archive.coordinates.tolist(),
        archive.descriptors.tolist(),
        archive.fitness.tolist(),
        archive.terms.tolist(),
        [g.to_json() for g in archive.genomes],
    )


def without_seconds(rows: list[dict]) -> list[dict]:
    return [{k: v for k, v in row.items() if k != "seconds"} for row in rows]


def test_a_map_has_the_arrays_a_pyribs_user_expects():
    varieties = sylva.varieties(map_config("bintree"), threads=2)
    assert varieties.generation == 0 and varieties.model == "bintree"
    row = varieties.step()
    assert row["generation"] == 1 and row["evaluations"] == 20
    varieties.run(2)
    assert varieties.generation == 3
    assert varieties.cells == 100
    assert varieties.descriptors == ["height_to_width", "porosity"]
    assert varieties.axes == [("height_to_width", 0.5, 4.0, 10), ("porosity", 0.0, 1.0, 10)]
    stats = varieties.stats
    assert [r["generation"] for r in stats] == [0, 1, 2, 3]
    assert {"generation", "filled", "coverage", "qd_score", "best", "mean", "improved",
            "evaluations"} <= set(stats[-1])
    # Elites are only replaced by fitter ones: neither figure falls.
    assert all(a["filled"] <= b["filled"] and a["qd_score"] <= b["qd_score"]
               for a, b in zip(stats, stats[1:]))

    archive = varieties.archive()
    n = len(archive)
    assert n == stats[-1]["filled"] and 0 < n <= 100
    assert archive.cells.dtype == np.int64 and archive.cells.shape == (n,)
    assert archive.coordinates.dtype == np.int64 and archive.coordinates.shape == (n, 2)
    assert archive.descriptors.dtype == np.float64 and archive.descriptors.shape == (n, 2)
    assert archive.fitness.dtype == np.float64 and archive.fitness.shape == (n,)
    assert archive.terms.shape == (n, len(varieties.term_names))
    assert archive.term_names == varieties.term_names
    assert len(archive.genomes) == n and all(g.model == "bintree" for g in archive.genomes)
    # In cell order, row-major over the axes, each elite in the cell its descriptors name.
    assert (np.diff(archive.cells) > 0).all()
    assert (archive.cells == archive.coordinates[:, 0] * 10 + archive.coordinates[:, 1]).all()
    low, high = np.array([0.5, 0.0]), np.array([4.0, 1.0])
    place = np.clip(((archive.descriptors - low) / (high - low) * 10).astype(int), 0, 9)
    assert (place == archive.coordinates).all()
    assert archive.fitness.sum() == pytest.approx(stats[-1]["qd_score"])
    data = archive.data()
    assert data["index"] is not None and (data["objective"] == archive.fitness).all()

    best = varieties.best()
    assert best.fitness == archive.fitness.max() == stats[-1]["best"]
    assert varieties.variety(best.cell).genome == best.genome
    assert best.coordinates == archive.coordinates[archive.cells.tolist().index(best.cell)].tolist()
    assert set(best.terms) == set(varieties.term_names)
    empty = next(c for c in range(100) if c not in archive.cells)
    assert varieties.variety(empty) is None


def test_a_map_is_the_same_on_any_number_of_threads():
    one = sylva.varieties(map_config("bintree"), threads=1)
    two = sylva.Varieties(map_config("bintree"), threads=2)
    one.run(3)
    two.run(3)
    assert archive_arrays(one.archive()) == archive_arrays(two.archive())
    assert without_seconds(one.stats) == without_seconds(two.stats)


def test_a_resumed_or_unpickled_map_goes_on_as_a_straight_run(tmp_path):
    config = map_config("bintree", seed=8)
    straight = sylva.varieties(config, threads=1)
    straight.run(4)

    halfway = sylva.varieties(config, threads=1)
    halfway.run(2)
    halfway.save(tmp_path / "map.json")
    copy = pickle.loads(pickle.dumps(halfway))
    assert copy.generation == 2
    resumed = sylva.Varieties.resume(config, path=tmp_path / "map.json", threads=2)
    from_text = sylva.Varieties.resume(config, text=halfway.checkpoint())
    for other in (halfway, copy, resumed, from_text):
        other.run(2)
        assert archive_arrays(other.archive()) == archive_arrays(straight.archive())
        assert without_seconds(other.stats) == without_seconds(straight.stats)
    with pytest.raises(sylva.InputError, match="either `path` or `text`"):
        sylva.Varieties.resume(config)


def test_ctrl_c_stops_a_map_between_generations_and_leaves_it_whole():
    import _thread

    varieties = sylva.varieties(map_config("bintree"), threads=1)
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            varieties.run(10_000_000)
    finally:
        timer.cancel()
    stopped = varieties.generation
    assert 0 < stopped < 10_000_000
    varieties.step()
    assert varieties.generation == stopped + 1
    assert len(varieties.stats) == stopped + 2


def ticks_during(call) -> int:
    """How often another Python thread ran while `call` ran: a tick or two when the call
    holds the GIL (at the bytecode boundaries around it), many when it releases it. No
    clock is read, so a busy machine gives the same verdict."""
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
    call()
    inside = False
    done.set()
    ticker.join()
    return ticks


def test_maps_and_spaces_release_the_gil():
    varieties = sylva.varieties(map_config("automata", initial=200, batch=200), threads=1)
    assert ticks_during(lambda: varieties.run(10)) >= 10
    space = sylva.GenomeSpace(CONFIGS["automata"], threads=1)
    xs = np.random.default_rng(2).uniform(0, 1, size=(3000, space.dim))
    assert ticks_during(lambda: space.evaluate(xs)) >= 10
    # L-system genomes decode slowest (ten rounds of mutation each).
    space = sylva.GenomeSpace(CONFIGS["lsystem"], threads=1)
    xs = np.random.default_rng(2).uniform(0, 1, size=(3000, space.dim))
    assert ticks_during(lambda: space.decode_many(xs)) >= 10


@pytest.mark.parametrize("model", MODELS)
def test_every_model_fills_a_map(model):
    small = model == "lsystem"
    varieties = sylva.varieties(map_config(model, initial=6 if small else 20,
                                           batch=4 if small else 10), threads=2)
    varieties.run(1)
    archive = varieties.archive()
    assert len(archive) > 0 and all(g.model == model for g in archive.genomes)
    assert varieties.best().genome.model == model


@pytest.mark.parametrize("model", MODELS)
def test_a_space_has_bounds_of_its_coding(model):
    space = sylva.GenomeSpace(CONFIGS[model])
    assert space.model == model
    assert space.coding == ("direct" if model in ("bintree", "plantmaker") else "codons")
    for bound in (space.lower, space.upper):
        assert bound.dtype == np.float64 and bound.shape == (space.dim,)
    assert (space.lower <= space.upper).all()
    if space.coding == "codons":
        assert (space.lower == 0).all() and (space.upper == 1).all()
        assert sylva.GenomeSpace(CONFIGS[model], 17).dim == 17
    assert space.descriptors == ["height_to_width", "porosity"]
    assert space.term_names and space.seed == sylva.Config.load(CONFIGS[model]).seed
    assert sylva.GenomeSpace(CONFIGS["bintree"]).dim == 11
    # evolve.toml starts from the flowering bush: 5 branches, 5 fans and 6 inflorescences.
    assert sylva.GenomeSpace(CONFIGS["plantmaker"]).dim == 5 * 23 + 5 * 19 + 6 * 8
    assert sylva.GenomeSpace({"model": "plantmaker"}).dim == 5 * 23 + 5 * 19 + 5 * 8


@pytest.mark.parametrize("model", MODELS)
def test_vectors_decode_alike_every_time(model):
    space = sylva.GenomeSpace(CONFIGS[model], threads=2)
    rng = np.random.default_rng(11)
    xs = rng.uniform(space.lower, space.upper, size=(6, space.dim))
    genomes = space.decode_many(xs)
    assert [g.to_json() for g in genomes] == [space.decode(x).to_json() for x in xs]
    again = sylva.GenomeSpace(CONFIGS[model], threads=1).decode_many(xs)
    assert [g.to_json() for g in again] == [g.to_json() for g in genomes]
    copy = pickle.loads(pickle.dumps(space))
    assert (copy.dim, copy.coding, copy.seed) == (space.dim, space.coding, space.seed)
    assert copy.decode(xs[0]) == genomes[0]
    # Entries past the bounds are clamped to them; lists and other number types are taken.
    assert space.decode(space.lower - 5) == space.decode(space.lower)
    assert space.decode(list(xs[0])) == genomes[0]
    assert space.decode(xs[0].astype(np.float32)) == space.decode(xs[0].astype(np.float32).astype(float))


@pytest.mark.parametrize("model", MODELS)
def test_the_ends_and_the_middle_of_a_space_grow_plants(model):
    space = sylva.GenomeSpace(CONFIGS[model])
    rng = np.random.default_rng(3)
    xs = np.vstack([space.lower, space.upper, rng.uniform(space.lower, space.upper, (4, space.dim))])
    plants = [g.grow() for g in space.decode_many(xs)]
    assert all(p.model == model for p in plants)
    if model != "automata":
        assert all(p.segments > 0 for p in plants)
    else:
        # Random programs, as the model's own random genomes, often draw nothing (a program
        # that only waits); they still grow, as empty plants.
        assert any(p.segments > 0 for p in plants)


def test_scores_are_the_native_maps_for_direct_codings():
    # Binary trees: a map's elites, encoded, score as the map scored them.
    varieties = sylva.varieties(map_config("bintree"), threads=2)
    varieties.run(2)
    archive = varieties.archive()
    space = sylva.GenomeSpace(map_config("bintree"), threads=2)
    xs = np.array([space.encode(g) for g in archive.genomes])
    assert xs.dtype == np.float64 and xs.shape == (len(archive), 11)
    assert ((space.lower <= xs) & (xs <= space.upper)).all()
    assert [space.decode(x) for x in xs] == archive.genomes
    objective, descriptors = space.evaluate(xs)
    assert objective.dtype == np.float64 and objective.shape == (len(archive),)
    assert descriptors.shape == (len(archive), 2)
    assert objective.tolist() == archive.fitness.tolist()
    assert descriptors.tolist() == archive.descriptors.tolist()

    # PlantMaker: decoded genomes started from, scored by the map as given genomes.
    space = sylva.GenomeSpace(map_config("plantmaker"), threads=2)
    rng = np.random.default_rng(4)
    xs = rng.uniform(space.lower, space.upper, size=(8, space.dim))
    genomes = space.decode_many(xs)
    assert all(g["seed"] == space.seed for g in genomes)
    assert [space.decode(space.encode(g)) for g in genomes] == genomes
    varieties = sylva.varieties(map_config("plantmaker", initial=8), start=genomes)
    archive = varieties.archive()
    objective, descriptors = space.evaluate(xs)
    for cell, fitness, place, genome in zip(archive.cells, archive.fitness,
                                             archive.descriptors, archive.genomes):
        row = genomes.index(genome)
        assert objective[row] == fitness and descriptors[row].tolist() == place.tolist()


def test_every_elite_of_the_plantmaker_example_map_encodes():
    # Its five start examples differ in their segment counts, which crossovers mix.
    path = EXAMPLES / "plantmaker" / "varieties.toml"
    data = sylva.Config.load(path).to_dict()
    data["map"].update(initial=30, batch=20)
    config = sylva.Config.from_dict(data, base=path.parent)
    varieties = sylva.varieties(config, threads=2)
    varieties.run(3)
    genomes = varieties.archive().genomes
    shapes = {(len(g["branches"]), len(g["fans"]), len(g["inflorescences"])) for g in genomes}
    assert len(shapes) > 1
    space = sylva.GenomeSpace(config, threads=2)
    assert space.dim == 3 + 5 * 23 + 7 * 19 + 18 * (3 + 7)
    for g in genomes:
        x = space.encode(g)
        assert ((space.lower <= x) & (x <= space.upper)).all()
        back = space.decode(x).to_dict()
        # The genome's own growth seed is no entry: decoded genomes take the space's.
        assert back == {**g.to_dict(), "seed": space.seed}


@pytest.mark.parametrize("model", ["automata", "lsystem"])
def test_scores_of_codons_are_the_native_runs(model):
    space = sylva.GenomeSpace(CONFIGS[model], threads=2)
    rng = np.random.default_rng(6)
    xs = rng.uniform(0, 1, size=(3, space.dim))
    objective, descriptors = space.evaluate(xs)
    assert objective.tolist() == sylva.GenomeSpace(CONFIGS[model], threads=1).evaluate(xs)[0].tolist()
    assert np.isfinite(descriptors).all()
    # A run scores the decoded genomes as immigrants (the genome the engine evolves:
    # an automaton's program, an L-system genome's file).
    config = sylva.Config.load(CONFIGS[model]).with_run(population=4, generations=0)
    run = sylva.Evolution(config, threads=2)
    genomes = space.decode_many(xs)
    evolved = [json.dumps(g["program"]) if model == "automata" else g.to_json() for g in genomes]
    ids = run.immigrate([e.encode() for e in evolved])
    assert [run.member(i).fitness for i in ids] == objective.tolist()


def test_bad_vectors_and_options_are_refused_naming_the_argument():
    space = sylva.GenomeSpace(CONFIGS["bintree"])
    x = (space.lower + space.upper) / 2
    with pytest.raises(sylva.InputError) as bad:
        space.decode(np.append(x, 1.0))
    assert bad.value.location == "x" and "(11,)" in str(bad.value) and "(12,)" in str(bad.value)
    with pytest.raises(sylva.InputError) as bad:
        space.evaluate(x)
    assert bad.value.location == "X" and "(n, 11)" in str(bad.value)
    with pytest.raises(sylva.InputError) as bad:
        space.decode_many(np.zeros((3, 10)))
    assert bad.value.location == "X"
    nan = x.copy()
    nan[3] = np.nan
    with pytest.raises(sylva.InputError) as bad:
        space.decode(nan)
    assert bad.value.location == "x" and "entry 3 is NaN" in str(bad.value)
    with pytest.raises(sylva.InputError) as bad:
        space.evaluate(np.vstack([x, nan]))
    assert bad.value.location == "X" and "row 1, entry 3 is NaN" in str(bad.value)
    with pytest.raises(sylva.InputError, match="inf"):
        space.evaluate(np.vstack([x, np.full(11, np.inf)]))
    with pytest.raises(TypeError, match="`x`.*numbers.*<U1"):
        space.decode(np.array(["a"] * 11))
    with pytest.raises(TypeError, match="`X`.*complex"):
        space.evaluate(np.zeros((2, 11), dtype=complex))
    with pytest.raises(TypeError, match="`x`"):
        space.decode(["a"] * 11)
    with pytest.raises(TypeError, match="`X`"):
        space.evaluate([[0.5] * 11, [0.5] * 3])
    # Encoding needs a direct coding, and a genome of the space's model and shape.
    with pytest.raises(sylva.InputError) as bad:
        space.encode(sylva.Genome.load(EXAMPLES / "plantmaker" / "tulip.json"))
    assert bad.value.location == "genome" and "plantmaker" in str(bad.value)
    codons = sylva.GenomeSpace(CONFIGS["automata"])
    with pytest.raises(sylva.InputError) as bad:
        codons.encode(codons.decode(codons.lower))
    assert bad.value.location == "genome" and "codon" in str(bad.value)
    few = sylva.GenomeSpace({"model": "plantmaker", "plantmaker": {"branches": 2}})
    with pytest.raises(sylva.InputError, match="branches"):
        few.encode(sylva.Genome.load(EXAMPLES / "plantmaker" / "tulip.json"))
    with pytest.raises(sylva.InputError) as bad:
        sylva.GenomeSpace(CONFIGS["bintree"], dim=65)
    assert bad.value.location == "dim" and "11 entries" in str(bad.value)
    with pytest.raises(sylva.InputError) as bad:
        sylva.GenomeSpace(CONFIGS["automata"], dim=0)
    assert bad.value.location == "dim"
    with pytest.raises(sylva.InputError) as bad:
        sylva.GenomeSpace(CONFIGS["lsystem"], coding="direct")
    assert bad.value.location == "coding"
    with pytest.raises(sylva.InputError) as bad:
        sylva.GenomeSpace(CONFIGS["bintree"], coding="bits")
    assert bad.value.location == "coding"
    assert sylva.GenomeSpace(CONFIGS["bintree"], coding="codons").coding == "codons"
    with pytest.raises(TypeError, match="Config, a dict or the path"):
        sylva.GenomeSpace(42)


def sigint_after(seconds: float) -> threading.Timer:
    """A real SIGINT to this process (what Ctrl-C sends) after `seconds`."""
    import os
    import signal

    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def test_ctrl_c_stops_a_map_generation_and_a_batch_leaving_them_whole(tmp_path):
    # L-system plants grow in a voxel world, about 0.2 s each on one core: a generation of
    # 40 takes seconds, so the signal comes while it is under way.
    text = (EXAMPLES / "lsystem" / "varieties.toml").read_text()
    herb = (EXAMPLES / "lsystem" / "herb.json").as_posix()
    text = text.replace('start = "herb.json"', f'start = "{herb}"')
    text = text.replace("initial = 24", "initial = 2").replace("batch = 24", "batch = 40")
    (tmp_path / "map.toml").write_text(text)
    config = sylva.Config.load(tmp_path / "map.toml")
    varieties = sylva.varieties(config, threads=2)
    before = varieties.checkpoint()
    for call in (varieties.step, lambda: varieties.run(5)):
        timer = sigint_after(0.3)
        started = time.perf_counter()
        try:
            with pytest.raises(KeyboardInterrupt):
                call()
        finally:
            timer.cancel()
        assert time.perf_counter() - started < 10
        # The map is as it was before the generation it was breeding.
        assert varieties.generation == 0 and len(varieties.stats) == 1
        assert varieties.checkpoint() == before
    # A batch of genomes to score is stopped alike.
    space = sylva.GenomeSpace(config, threads=2)
    rows = np.random.default_rng(1).uniform(size=(60, space.dim))
    timer = sigint_after(0.3)
    started = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            space.evaluate(rows)
    finally:
        timer.cancel()
    assert time.perf_counter() - started < 10
