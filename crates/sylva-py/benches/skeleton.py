"""The plant as data from Python: `Plant.skeleton()` (numpy arrays, one per field) against
the skeleton file's text read by Python's own JSON reader (what `skeleton()` returned before,
lists of dicts), beside growing and meshing the plant, on a 20,548-segment PlantMaker plant
(the random genome of seed 3). Both are timed in turns in one run (A B A B), best of 7
rounds.

    python crates/sylva-py/benches/skeleton.py        # after pip install ./crates/sylva-py
"""

from __future__ import annotations

import json
import time

import sylva


def best_of(rounds: int, calls: int, f) -> float:
    best = float("inf")
    for _ in range(rounds):
        start = time.perf_counter()
        for _ in range(calls):
            f()
        best = min(best, (time.perf_counter() - start) / calls)
    return best


def main() -> None:
    genome = sylva.Genome.random("plantmaker", seed=3)
    plant = genome.grow()
    print(f"plant: {plant.segments} segments, {plant.organs} organs")
    arrays = lambda: plant.skeleton()
    dicts = lambda: json.loads(plant.skeleton_json())
    grow = lambda: genome.grow().mesh
    for f in (arrays, dicts, grow):  # warm-up
        f()
    times = {"arrays": [], "dicts": [], "grow": []}
    for _ in range(7):
        times["arrays"].append(best_of(1, 10, arrays))
        times["dicts"].append(best_of(1, 3, dicts))
        times["grow"].append(best_of(1, 10, grow))
    best = {k: min(v) * 1000 for k, v in times.items()}
    print(f"skeleton() as numpy arrays: {best['arrays']:.1f} ms")
    print(f"the file's text through json.loads (lists of dicts): {best['dicts']:.1f} ms "
          f"({best['dicts'] / best['arrays']:.1f}x the arrays)")
    print(f"growing and meshing the plant: {best['grow']:.1f} ms")


if __name__ == "__main__":
    main()
