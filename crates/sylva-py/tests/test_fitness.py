"""A Python fitness function in a run: batches of grown plants in, one number per plant out,
beside the model's terms or in their place; deterministic, checkpointed, pickled, and its
errors raised as they were."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

import sylva

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def small(population: int = 12, seed: int = 2) -> sylva.Config:
    return sylva.Config.load(EXAMPLES / "plantmaker" / "evolve.toml").with_run(
        population=population, generations=3, seed=seed
    )


def spread(plants):
    """The area of each plant's footprint (its mesh's extent in x times z): a module-level
    function, so runs that use it pickle."""
    return [float(np.ptp(p.mesh.positions[:, 0]) * np.ptp(p.mesh.positions[:, 2])) for p in plants]


def rows(run: sylva.Evolution) -> list[dict]:
    """Every statistics row without its wall-clock seconds."""
    return [{k: v for k, v in r.items() if k != "seconds"} for r in run.stats]


def test_a_fitness_function_joins_the_model_s_terms_in_batches():
    batches = []

    def f(plants):
        batches.append(len(plants))
        assert all(isinstance(p, sylva.Plant) for p in plants)
        # Plants come with their numpy views: the mesh, read-only, and the skeleton.
        assert not plants[0].mesh.positions.flags.writeable
        assert plants[0].skeleton()["segments"]["start"].shape[1] == 3
        return np.asarray(spread(plants))

    plain = sylva.Evolution(small(), threads=1)
    run = sylva.Evolution(small(), threads=1, fitness=f, fitness_weight=2.0, fitness_batch=5)
    assert run.term_names == plain.term_names + ["python"]
    assert run.fitness is f
    # Generation 0 scored in batches of at most 5.
    assert batches and max(batches) <= 5 and sum(batches) <= 12
    # Each member's total is the model's plus twice its own term, which is f of its plant.
    for mine, theirs in zip(run.population(), plain.population()):
        assert mine.genome == theirs.genome
        own = mine.terms["python"]
        assert own == pytest.approx(spread([mine.genome.grow()])[0])
        assert mine.fitness == pytest.approx(theirs.fitness + 2.0 * own)
    run.run()
    assert run.generation == 3 and "python" in run.stats[-1]


def test_a_fitness_function_can_replace_the_model_s_terms_and_is_deterministic():
    runs = [
        sylva.Evolution(small(), threads=threads, fitness=spread, fitness_mode="replace",
                        fitness_weight=0.5)
        for threads in (1, 2)
    ]
    for run in runs:
        run.run()
    assert runs[0].term_names == ["python"]
    best = runs[0].best()
    assert best.fitness == pytest.approx(0.5 * best.terms["python"])
    # The same seed gives the same run, on any number of threads.
    assert rows(runs[0]) == rows(runs[1])
    assert runs[0].best().genome == runs[1].best().genome
    again = sylva.Evolution(small(), fitness=spread, fitness_mode="replace", fitness_weight=0.5)
    again.run()
    assert rows(again) == rows(runs[0])


class Broken(Exception):
    """The user's own error."""


def test_the_function_s_errors_are_raised_as_they_were_and_leave_the_run_whole():
    def broken(plants):
        raise Broken("my bug")

    with pytest.raises(Broken, match="my bug"):
        sylva.Evolution(small(), fitness=broken)

    calls = []

    def later(plants):
        calls.append(1)
        if len(calls) > 1:
            raise Broken("in generation 1")
        return [0.0] * len(plants)

    run = sylva.Evolution(small(), fitness=later)
    before = run.checkpoint()
    with pytest.raises(Broken, match="generation 1"):
        run.step()
    assert run.generation == 0 and run.checkpoint() == before


@pytest.mark.parametrize(
    "answer, error, words",
    [
        (lambda plants: [1.0], sylva.InputError, "1 number for a batch of"),
        (lambda plants: 3.0, sylva.InputError, "a single number"),
        (lambda plants: [[1.0, 2.0]] * len(plants), sylva.InputError, "shape"),
        (lambda plants: [float("nan")] * len(plants), sylva.InputError, "NaN"),
        # One infinity is refused as NaN is, not left to sink the run's ranking.
        (lambda plants: [float("inf")] + [0.0] * (len(plants) - 1), sylva.InputError,
         "returned inf for plant 0"),
        (lambda plants: [0.0] * (len(plants) - 1) + [float("-inf")], sylva.InputError,
         "returned -inf for plant"),
        (lambda plants: np.full(len(plants), -np.inf), sylva.InputError, "returned -inf"),
        (lambda plants: "high", TypeError, "one number per plant"),
        (lambda plants: None, TypeError, "one number per plant"),
        (lambda plants: ["a"] * len(plants), TypeError, "one number per plant"),
    ],
)
def test_wrong_answers_are_refused_saying_what_was_expected(answer, error, words):
    with pytest.raises(error, match=words) as refused:
        sylva.Evolution(small(), fitness=answer)
    assert "fitness" in str(refused.value)


def test_bad_settings_are_refused_naming_them():
    with pytest.raises(TypeError, match="fitness"):
        sylva.Evolution(small(), fitness=42)
    with pytest.raises(sylva.InputError, match="fitness_mode"):
        sylva.Evolution(small(), fitness=spread, fitness_mode="instead")
    with pytest.raises(sylva.InputError, match="fitness_weight"):
        sylva.Evolution(small(), fitness=spread, fitness_weight=float("inf"))
    with pytest.raises(sylva.InputError, match="fitness_batch"):
        sylva.Evolution(small(), fitness=spread, fitness_batch=0)


def test_the_run_cannot_be_read_from_its_own_fitness_function():
    runs = []

    def peek(plants):
        if runs:
            runs[0].best()
        return [0.0] * len(plants)

    runs.append(sylva.Evolution(small(), fitness=peek))
    with pytest.raises(RuntimeError, match="fitness function cannot read it"):
        runs[0].step()


def test_ctrl_c_inside_the_function_stops_the_run():
    def interrupted(plants):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sylva.Evolution(small(), fitness=interrupted)


def test_a_run_with_a_fitness_function_resumes_with_it_and_pickles(tmp_path):
    straight = sylva.Evolution(small(), fitness=spread)
    straight.run()

    run = sylva.Evolution(small(), fitness=spread)
    run.step()
    run.save(tmp_path / "run.json")
    # The checkpoint records the term, not the function: it is given again.
    with pytest.raises(sylva.InputError, match="that function again"):
        sylva.Evolution.resume(small(), path=tmp_path / "run.json")
    with pytest.raises(sylva.InputError, match="same weight and mode"):
        sylva.Evolution.resume(small(), path=tmp_path / "run.json", fitness=spread,
                               fitness_mode="replace")
    resumed = sylva.Evolution.resume(small(), path=tmp_path / "run.json", fitness=spread)
    resumed.run()
    assert rows(resumed) == rows(straight)
    # Pickled, it takes its (module-level) function along.
    copy = pickle.loads(pickle.dumps(run))
    assert copy.fitness is spread
    copy.run()
    assert rows(copy) == rows(straight)
    assert copy.best() == straight.best()
