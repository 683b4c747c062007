"""Python's overhead on growing and meshing PlantMaker plants.

For each example genome: the library's grow-and-mesh timed in Rust (`_rust_grow_seconds`,
no Python in the loop), then `Genome.grow()` from Python, then `Genome.grow()` with the
mesh taken out as numpy arrays (views of the plant's memory). Each figure is the best of 7 rounds of many calls.

    python crates/sylva-py/benches/overhead.py        # after pip install ./crates/sylva-py
"""

from __future__ import annotations

import time
from pathlib import Path

import sylva
from sylva._sylva import _rust_grow_seconds

EXAMPLES = Path(__file__).resolve().parents[3] / "examples" / "plantmaker"


def best_of(rounds: int, calls: int, f) -> float:
    best = float("inf")
    for _ in range(rounds):
        start = time.perf_counter()
        for _ in range(calls):
            f()
        best = min(best, (time.perf_counter() - start) / calls)
    return best


def main() -> None:
    print(f"{'genome':16} {'rust µs':>9} {'grow µs':>9} {'overhead':>9} {'+mesh µs':>9} {'overhead':>9}")
    for path in sorted(EXAMPLES.glob("*.json")):
        g = sylva.Genome.load(path)
        seed = g.default_seed
        rust = _rust_grow_seconds(g, seed, 50)
        calls = max(20, int(0.2 / max(rust, 1e-6)))
        # Warm-up of every path first: glibc raises its mmap threshold only after the first
        # large blocks are freed, and whichever path ran first would pay the page faults.
        best_of(1, calls, lambda: g.grow(seed).mesh)
        rust = min(_rust_grow_seconds(g, seed, calls) for _ in range(7))
        grow = best_of(7, calls, lambda: g.grow(seed))
        arrays = best_of(7, calls, lambda: g.grow(seed).mesh)
        print(
            f"{path.stem:16} {rust * 1e6:9.1f} {grow * 1e6:9.1f} {grow / rust - 1:9.1%} "
            f"{arrays * 1e6:9.1f} {arrays / rust - 1:9.1%}"
        )


if __name__ == "__main__":
    main()
