"""Islands against one big population on this machine: Poncin's typical run (the automata
sphere problem, 5000 individuals x 100 generations) as 1, 2 and 4 islands of 5000, 2500
and 1250 (migrating the best 2 every 10 generations along a ring), against the single
process run of 5000 x 100 on every core. Ray's own start-up (``ray.init``) is left out;
the islands' start-up (workers, generation 0) is counted.

    python crates/sylva-py/benches/islands.py [--backend local|ray] [--plot FILE.png]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import sylva
from sylva.islands import island_seed

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
TOTAL = 5000
GENERATIONS = 100


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--backend", default="local", choices=["local", "ray"])
    parser.add_argument("--plot", type=Path)
    args = parser.parse_args()
    cores = os.cpu_count() or 1
    config = sylva.Config.load(EXAMPLES / "automata" / "sphere.toml")

    def single(seed: int) -> float:
        start = time.perf_counter()
        run = sylva.Evolution(
            config.with_run(population=TOTAL, generations=GENERATIONS, seed=seed), threads=0
        )
        run.run()
        seconds = time.perf_counter() - start
        print(f"one population of {TOTAL} x {GENERATIONS}, seed {seed}, {cores} threads: "
              f"{seconds:.2f} s, best {run.best().fitness:.4f}")
        return seconds

    # The config's own seed, and the seed of island 0 (a 1-island run is that very run, so
    # the two differ only by what islands add). Runs of the sphere problem differ in cost by
    # seed: evolved automata grow bigger in some runs than in others.
    baseline = single(config.seed)
    same_seed = single(island_seed(1, 0))

    if args.backend == "ray":
        import ray

        ray.init(include_dashboard=False, logging_level="ERROR")
    rows = []
    for n in (1, 2, 4):
        threads = max(1, cores // n)
        result = sylva.islands(
            config.with_run(population=TOTAL // n, generations=GENERATIONS),
            islands=n, migrate_every=10, migrants=2, topology="ring", seed=1,
            threads=threads, backend=args.backend,
        )
        # Each island's own time per round (its generations' wall time; generation 0 counts
        # in the first), the slowest of each round, and what the others waited for it.
        per_round = [
            [sum(row["seconds"] for row in island if (row["generation"] - 1) // 10 == r
                 or (r == 0 and row["generation"] == 0)) for island in result.stats]
            for r in range(result.rounds)
        ]
        slowest = sum(max(times) for times in per_round)
        waited = sum(max(times) - t for times in per_round for t in times)
        rows.append((n, result.seconds))
        print(
            f"{n} island(s) of {TOTAL // n}, {threads} thread(s) each: {result.seconds:.2f} s "
            f"({result.seconds / baseline:.2f}x one population); slowest island per round "
            f"{slowest:.2f} s, islands waiting at the barrier {waited:.2f} island-s, driver, "
            f"workers' start-up and transfers {result.seconds - slowest:.2f} s; best "
            f"{result.fitness:.4f}"
        )
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4), dpi=120)
        ax.plot([n for n, _ in rows], [t for _, t in rows], "o-", label=f"islands ({args.backend})")
        ax.axhline(baseline, color="grey", linestyle="--", label="one population, 2 threads")
        ax.axhline(same_seed, color="grey", linestyle="-.",
                   label="one population, island 0's seed")
        ax.axhline(1.5 * baseline, color="red", linestyle=":", label="1.5 x one population")
        ax.set_xticks([1, 2, 4])
        ax.set_xlabel("islands (5000 individuals in all)")
        ax.set_ylabel("seconds for 100 generations")
        ax.set_ylim(0, max(1.6 * baseline, max(t for _, t in rows) * 1.1))
        ax.set_title(f"Automata sphere problem on {cores} cores")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
