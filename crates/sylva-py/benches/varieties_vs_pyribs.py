"""Sylva's own MAP-Elites (`sylva.varieties`) against pyribs' MAP-Elites driving the same
Sylva genomes through `sylva.GenomeSpace`, on one plant problem with equal evaluations.

The problem: binary trees scored by their model's own fitness (Susinno's weighted
measures, examples/bintree/default.toml), mapped by height_to_width (0.5 to 4) by porosity
(0 to 1), 10 by 10 cells, QD offset 0 for both. Both start from 200 random genomes and then
breed 100 per generation for the same number of generations, so both make exactly
200 + 100 x generations evaluations, each one the same native code: `GenomeSpace.evaluate`
scores a vector exactly as the native map scores a genome (the config's fitness and
descriptors), on the same 2 threads.

- Sylva: `sylva.varieties(config)`, parents drawn uniformly from the elites, the model's
  own one-point crossover (half the offspring) and bit-flip mutation (0.02 per bit).
- pyribs 0.12: a `GridArchive` of the same cells and offset, one emitter, a `Scheduler`;
  solutions live in the unit cube, mapped onto `GenomeSpace.lower`..`upper` (the binary
  tree's 11 fields, each rounded to its step) before `evaluate`; the first `ask` returns
  200 uniform random solutions (`initial_solutions`). Emitters: `GaussianEmitter`
  (sigma 0.05 of each range, the best of `--tune`) and `IsoLineEmitter` (iso 0.01, line 0.2, the
  values of Vassiliades and Mouret). `--tune` tries sigma 0.05, 0.1, 0.2 and 0.3 on a seed
  outside the table's.

Wall time is each run's whole loop (for pyribs: ask, scaling, evaluate, tell; for Sylva:
generation 0 and every step); for pyribs, the part outside `evaluate` is shown too (its
emitter and archive, and the scaling). Coverage and QD-score are read off each archive at
the end.

    pip install ribs==0.12.0        # not a test dependency: it brings numba, scipy, pandas
    python crates/sylva-py/benches/varieties_vs_pyribs.py [--seeds 1 2 3 4 5] [--generations 100]

scripts/varieties-figures runs it at three budgets and writes docs/varieties.md's tables.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import sylva

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
INITIAL = 200
BATCH = 100
CELLS = 10
SIGMA = 0.05  # the Gaussian emitter's step, the best of --tune


def config(seed: int, generations: int) -> sylva.Config:
    data = sylva.Config.load(EXAMPLES / "bintree" / "default.toml").to_dict()
    data["run"].update(strategy="map-elites", seed=seed, generations=generations, threads=2)
    data["map"] = {
        "descriptors": [
            {"name": "height_to_width", "range": [0.5, 4.0], "cells": CELLS},
            {"name": "porosity", "range": [0.0, 1.0], "cells": CELLS},
        ],
        "initial": INITIAL,
        "batch": BATCH,
        "crossover": 0.5,
        "qd_offset": 0.0,
    }
    return sylva.Config.from_dict(data)


def run_sylva(seed: int, generations: int) -> dict:
    start = time.perf_counter()
    varieties = sylva.varieties(config(seed, generations), threads=2)
    varieties.run(generations)
    seconds = time.perf_counter() - start
    last = varieties.stats[-1]
    archive = varieties.archive()
    return {
        "coverage": last["coverage"],
        "qd_score": last["qd_score"],
        "seconds": seconds,
        "pyribs": 0.0,
        "evaluations": sum(row["evaluations"] for row in varieties.stats),
        "lowest": float(archive.fitness.min()),
    }


def run_pyribs(seed: int, generations: int, emitter: str, sigma: float) -> dict:
    from ribs.archives import GridArchive
    from ribs.emitters import GaussianEmitter, IsoLineEmitter
    from ribs.schedulers import Scheduler

    space = sylva.GenomeSpace(config(seed, generations), threads=2)
    lower, span = space.lower, space.upper - space.lower
    start = time.perf_counter()
    archive = GridArchive(
        solution_dim=space.dim,
        dims=[CELLS, CELLS],
        ranges=[(0.5, 4.0), (0.0, 1.0)],
        qd_score_offset=0.0,
        seed=seed,
    )
    rng = np.random.default_rng(seed)
    common = dict(
        initial_solutions=rng.uniform(0.0, 1.0, size=(INITIAL, space.dim)),
        bounds=[(0.0, 1.0)] * space.dim,
        batch_size=BATCH,
        seed=seed,
    )
    if emitter == "gaussian":
        emitters = [GaussianEmitter(archive, sigma=sigma, **common)]
    else:
        emitters = [IsoLineEmitter(archive, iso_sigma=0.01, line_sigma=0.2, **common)]
    scheduler = Scheduler(archive, emitters)
    evaluations, scoring = 0, 0.0
    for _ in range(generations + 1):
        unit = scheduler.ask()
        before = time.perf_counter()
        objective, measures = space.evaluate(lower + unit * span)
        scoring += time.perf_counter() - before
        scheduler.tell(objective, measures)
        evaluations += len(unit)
    seconds = time.perf_counter() - start
    stats = archive.stats
    best = archive.data(["solution"])["solution"]
    # The elites are Sylva genomes: decoded, they grow.
    assert all(g.model == "bintree" for g in space.decode_many(lower + best * span))
    return {
        "coverage": float(stats.coverage),
        "qd_score": float(stats.qd_score),
        "seconds": seconds,
        "pyribs": seconds - scoring,
        "evaluations": evaluations,
        "lowest": float(archive.data(["objective"])["objective"].min()),
    }


NAMES = {
    "sylva": "Sylva `varieties`",
    "gaussian": "pyribs GaussianEmitter",
    "isoline": "pyribs IsoLineEmitter",
}


def measure(seeds: list[int], generations: int, sigma: float = SIGMA,
            progress=lambda line: None) -> dict[str, list[dict]]:
    """Every run for each seed, in turns (Sylva, Gaussian, Iso+LineDD) so that the machine's
    state weighs on all alike, after a warm-up of each (numba compiles pyribs' archive on
    first use). Each run's result carries its seed."""
    run_sylva(99, 2)
    run_pyribs(99, 2, "gaussian", sigma)
    run_pyribs(99, 2, "isoline", sigma)
    results: dict[str, list[dict]] = {key: [] for key in NAMES}
    for seed in seeds:
        for key in results:
            if key == "sylva":
                r = run_sylva(seed, generations)
            else:
                r = run_pyribs(seed, generations, key, sigma)
            assert r["lowest"] >= 0.0, "every elite above the QD offset"
            assert r["evaluations"] == INITIAL + BATCH * generations, "equal work"
            r["seed"] = seed
            results[key].append(r)
            progress(f"{generations} generations, seed {seed}, {NAMES[key]}: "
                     f"{r['coverage']:.2f} / {r['qd_score']:.1f}")
    return results


TUNE_SIGMAS = (0.05, 0.1, 0.2, 0.3)


def tune(seed: int, generations: int) -> dict:
    """The Gaussian emitter at each sigma on one seed (outside the table's)."""
    return {"seed": seed, "generations": generations,
            "runs": {sigma: run_pyribs(seed, generations, "gaussian", sigma)
                     for sigma in TUNE_SIGMAS}}


def tune_sentence(tuned: dict) -> str:
    runs = tuned["runs"]
    best = max(runs, key=lambda sigma: runs[sigma]["qd_score"])
    tried = ", ".join(f"{sigma}: {r['qd_score']:.0f}" for sigma, r in runs.items())
    advice = ("" if best == SIGMA else
              f" The tables use {SIGMA}: re-run them with `--sigma {best}`.")
    return (f"The Gaussian emitter's sigma (`--tune`, seed {tuned['seed']}, "
            f"{tuned['generations']} generations), QD-score by sigma: {tried}; the best is "
            f"{best}.{advice}")


def means(results: dict[str, list[dict]]) -> dict[str, dict[str, float]]:
    return {key: {field: float(np.mean([r[field] for r in runs]))
                  for field in ("coverage", "qd_score", "seconds", "pyribs")}
            for key, runs in results.items()}


def seed_table(results: dict[str, list[dict]]) -> str:
    """A row per seed and run: coverage, QD-score, wall time and pyribs' own part of it."""
    lines = ["| seed | run | coverage | QD-score | wall time | of it, pyribs' ask and tell |",
             "| --- | --- | --- | --- | --- | --- |"]
    for i, seed in enumerate(r["seed"] for r in results["sylva"]):
        for key, runs in results.items():
            r = runs[i]
            own = f"{r['pyribs'] * 1000:.0f} ms" if key != "sylva" else ""
            lines.append(f"| {seed} | {NAMES[key]} | {r['coverage']:.2f} | {r['qd_score']:.1f} | "
                         f"{r['seconds'] * 1000:.0f} ms | {own} |")
    return "\n".join(lines)


def budget_table(budgets: dict[int, dict[str, list[dict]]]) -> str:
    """Means over the seeds at each budget, and Sylva's against each pyribs emitter."""
    lines = ["| generations (evaluations) | run | coverage | QD-score | wall time | "
             "Sylva's coverage ÷ its | Sylva's QD-score ÷ its | its wall time ÷ Sylva's |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for generations, results in budgets.items():
        m = means(results)
        s = m["sylva"]
        for key, row in m.items():
            first = f"{generations} ({INITIAL + BATCH * generations:,})" if key == "sylva" else ""
            ratios = (" | | |" if key == "sylva" else
                      f" {s['coverage'] / row['coverage']:.2f} | "
                      f"{s['qd_score'] / row['qd_score']:.2f} | "
                      f"{row['seconds'] / s['seconds']:.2f} |")
            lines.append(f"| {first} | {NAMES[key]} | {row['coverage']:.3f} | "
                         f"{row['qd_score']:.1f} | {row['seconds'] * 1000:.0f} ms |" + ratios)
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    parser.add_argument("--generations", type=int, default=100)
    parser.add_argument("--sigma", type=float, default=SIGMA)
    parser.add_argument("--tune", action="store_true")
    args = parser.parse_args()
    import ribs

    if args.tune:
        print(tune_sentence(tune(max(args.seeds) + 100, args.generations)))
        return

    results = measure(args.seeds, args.generations, args.sigma, progress=print)
    print(f"\nbinary trees, height_to_width x porosity, {CELLS}x{CELLS}, {INITIAL} + "
          f"{BATCH} x {args.generations} evaluations, 2 threads; pyribs {ribs.__version__}, "
          f"Gaussian sigma {args.sigma}\n")
    print(seed_table(results))
    print("\nMeans over the seeds, and Sylva's against each:\n")
    print(budget_table({args.generations: results}))


if __name__ == "__main__":
    main()
