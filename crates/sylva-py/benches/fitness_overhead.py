"""What a Python fitness function costs a run, apart from the function's own work.

Runs of one config, in turns: without a Python fitness, then with a trivial one
(``np.zeros(len(plants))``) beside the model's terms and in place of them in batches of 16
(the default), and beside them in batches of 64 and of one plant. For each run with the function it prints, per plant scored:

- ``call µs``: the calling thread's time in the calls (making a ``sylva.Plant`` for each
  grown plant, the list, the call, reading the answer as numbers), less the function's own
  work (timed inside it): the cost of calling Python per plant;
- ``drop µs``: dropping the batch's plants after the call (giving their meshes' memory back);
- ``extra µs``: the whole run's extra wall time over the run without the function, per plant:
  the above, plus growing and meshing each plant for the function (the model's own fitness
  grows it apart, and does not mesh it), foreseeing what each generation evaluates, and
  handing batches between threads.

Each figure is the best of ``--rounds`` rounds.

    python crates/sylva-py/benches/fitness_overhead.py   # after pip install ./crates/sylva-py
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import sylva

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

CONFIGS = {
    "bintree": EXAMPLES / "bintree" / "default.toml",
    "plantmaker": EXAMPLES / "plantmaker" / "evolve.toml",
}


class Zeros:
    """A fitness function that does nothing, timing itself."""

    def __init__(self) -> None:
        self.seconds = 0.0

    def __call__(self, plants: list) -> np.ndarray:
        start = time.perf_counter()
        scores = np.zeros(len(plants))
        self.seconds += time.perf_counter() - start
        return scores


def timed(config: sylva.Config, generations: int, **fitness) -> tuple[float, tuple, float]:
    """Seconds for generation 0 and `generations` more; the function's calls (calls,
    plants, seconds) and its own seconds."""
    zeros = Zeros() if fitness else None
    start = time.perf_counter()
    run = sylva.Evolution(config, fitness=zeros, **fitness)
    run.run(generations)
    seconds = time.perf_counter() - start
    calls = run._fitness_calls if zeros else (0, 0, 0.0, 0.0)
    return seconds, calls, zeros.seconds if zeros else 0.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--population", type=int, default=256)
    parser.add_argument("--generations", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    variants = {
        "none": {},
        "add, batch 16": dict(fitness_mode="add"),
        "replace, batch 16": dict(fitness_mode="replace"),
        "add, batch 64": dict(fitness_mode="add", fitness_batch=64),
        "add, batch 1": dict(fitness_mode="add", fitness_batch=1),
    }
    print(f"population {args.population}, {args.generations} generations, best of {args.rounds}")
    print(f"{'model':11} {'fitness':18} {'run s':>7} {'plants':>7} {'calls':>6} "
          f"{'call µs':>8} {'drop µs':>8} {'extra µs':>9}")
    for model, path in CONFIGS.items():
        config = sylva.Config.load(path).with_run(population=args.population, seed=1)
        timed(config, 1)  # warm-up: the allocator's thresholds, the pool's threads
        best: dict[str, tuple] = {}
        for _ in range(args.rounds):
            for name, fitness in variants.items():
                result = timed(config, args.generations, **fitness)
                if name not in best or result[0] < best[name][0]:
                    best[name] = result
        plain = best["none"][0]
        print(f"{model:11} {'none':18} {plain:7.3f}")
        for name in list(variants)[1:]:
            seconds, (calls, plants, calling, dropping), own = best[name]
            call = (calling - own) / plants * 1e6
            drop = dropping / plants * 1e6
            extra = (seconds - plain) / plants * 1e6
            print(f"{model:11} {name:18} {seconds:7.3f} {plants:7d} {calls:6d} "
                  f"{call:8.2f} {drop:8.2f} {extra:9.1f}")


if __name__ == "__main__":
    main()
