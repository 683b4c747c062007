"""Does a CMA-ME emitter fill a PlantMaker map faster or better than Sylva's own MAP-Elites?

Issue 28 asks for an emitter of the CMA-ME family where a model's genome is real-valued
(PlantMaker), if it measurably fills the map faster or better. This measured that before
Sylva had one, and now sets Sylva's own (`[map] emitter = "cma-me"`: five separable CMA-ES
of 10, the same ranking) beside pyribs': pyribs' CMA-ME (Fontaine et al. 2020: `EvolutionStrategyEmitter`, CMA-ES,
the two-stage improvement ranker, five emitters of 10) drives PlantMaker genomes through
`sylva.GenomeSpace` (its direct coding: one entry per code of the genome), against
`sylva.varieties` (parents drawn uniformly from the elites, PlantMaker's own crossover for
half the offspring, then its mutation), with equal evaluations, on the PlantMaker example
map's fitness and axes (examples/plantmaker/varieties.toml: leaf_count x porosity, 8 x 8),
from 100 random genomes each (not the example's start genomes, which pyribs could not be
given alike). Coverage and QD-score (offset 0) are read off each archive every 50
generations.

    pip install ribs==0.12.0        # not a test dependency
    python crates/sylva-py/benches/varieties_cma_me.py [--seeds 1 2 3] [--generations 200]

scripts/varieties-figures runs it for five seeds and writes docs/varieties.md's tables.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import sylva

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
INITIAL = 100
BATCH = 50
EMITTERS = 5


def config(seed: int, generations: int, cma_me_sigma: float | None = None) -> sylva.Config:
    data = sylva.Config.load(EXAMPLES / "plantmaker" / "varieties.toml").to_dict()
    data["plantmaker"].pop("start", None)
    data["run"].update(seed=seed, generations=generations, threads=2)
    data["map"].update(initial=INITIAL, batch=BATCH, qd_offset=0.0)
    if cma_me_sigma is not None:
        data["map"].update(emitter="cma-me", emitters=EMITTERS, sigma=cma_me_sigma)
    return sylva.Config.from_dict(data)


def axes(cfg: sylva.Config):
    ds = cfg.to_dict()["map"]["descriptors"]
    return [d["cells"] for d in ds], [tuple(d["range"]) for d in ds]


def run_sylva(seed: int, generations: int, every: int, sigma: float | None = None) -> list[tuple]:
    start = time.perf_counter()
    varieties = sylva.varieties(config(seed, generations, sigma), threads=2)
    curve = []
    for g in range(0, generations + 1, every):
        if g:
            varieties.run(every)
        s = varieties.stats[-1]
        curve.append((g, s["coverage"], s["qd_score"], time.perf_counter() - start))
    return curve


def run_cma_me(seed: int, generations: int, every: int, sigma: float) -> list[tuple]:
    from ribs.archives import GridArchive
    from ribs.emitters import EvolutionStrategyEmitter
    from ribs.schedulers import Scheduler

    cfg = config(seed, generations)
    space = sylva.GenomeSpace(cfg, threads=2)
    lower, span = space.lower, space.upper - space.lower
    cells, ranges = axes(cfg)
    start = time.perf_counter()
    archive = GridArchive(solution_dim=space.dim, dims=cells, ranges=ranges,
                          qd_score_offset=0.0, seed=seed)
    rng = np.random.default_rng(seed)
    first = rng.uniform(0.0, 1.0, size=(INITIAL, space.dim))
    objective, measures = space.evaluate(lower + first * span)
    archive.add(first, objective, measures)
    x0 = first[int(np.argmax(objective))]
    emitters = [
        # Unbounded: CMA-ES resamples until a whole 250-entry vector is in bounds, which
        # almost never happens; the space clamps each entry to its bounds instead.
        EvolutionStrategyEmitter(archive, x0=x0, sigma0=sigma, ranker="2imp",
                                 batch_size=BATCH // EMITTERS, seed=seed * 100 + i)
        for i in range(EMITTERS)
    ]
    scheduler = Scheduler(archive, emitters)
    curve = [(0, float(archive.stats.coverage), float(archive.stats.qd_score),
              time.perf_counter() - start)]
    for g in range(1, generations + 1):
        unit = scheduler.ask()
        objective, measures = space.evaluate(lower + np.clip(unit, 0.0, 1.0) * span)
        scheduler.tell(objective, measures)
        if g % every == 0:
            curve.append((g, float(archive.stats.coverage), float(archive.stats.qd_score),
                          time.perf_counter() - start))
    return curve


RUNS = ("Sylva, the model's operators", "Sylva CMA-ME", "pyribs CMA-ME")


def measure(seeds: list[int], generations: int, every: int, sigma: float,
            progress=lambda line: None) -> dict[str, list[dict]]:
    """Each run's curve for each seed, in turns, after a warm-up of pyribs (numba compiles
    its archive on first use): {run: [{"seed", "curve": [(generation, coverage, QD-score,
    seconds)]}]}."""
    run_cma_me(99, 2, 1, sigma)
    results: dict[str, list[dict]] = {name: [] for name in RUNS}
    for seed in seeds:
        for name, run in zip(RUNS, (lambda: run_sylva(seed, generations, every),
                                    lambda: run_sylva(seed, generations, every, sigma),
                                    lambda: run_cma_me(seed, generations, every, sigma))):
            curve = run()
            results[name].append({"seed": seed, "curve": curve})
            progress(f"seed {seed}, {name}: {curve[-1][1]:.2f} / {curve[-1][2]:.3f}")
    return results


def seed_table(results: dict[str, list[dict]]) -> str:
    """A row per seed and run: coverage / QD-score at every recorded generation, wall time."""
    first = results[RUNS[0]][0]["curve"]
    lines = ["| seed | run | " + " | ".join(f"gen {g}" for g, *_ in first) + " | wall |",
             "| --- | --- |" + " --- |" * (len(first) + 1)]
    for i in range(len(results[RUNS[0]])):
        for name in RUNS:
            run = results[name][i]
            cells = " | ".join(f"{c:.2f} / {q:.3f}" for _, c, q, _ in run["curve"])
            lines.append(f"| {run['seed']} | {name} | {cells} | {run['curve'][-1][3]:.1f} s |")
    return "\n".join(lines)


def mean_at(runs: list[dict], generation: int) -> tuple[float, float]:
    """Mean coverage and QD-score over the seeds at one recorded generation."""
    points = [next(p for p in run["curve"] if p[0] == generation) for run in runs]
    return (float(np.mean([p[1] for p in points])), float(np.mean([p[2] for p in points])))


def means_table(results: dict[str, list[dict]], generations: list[int]) -> str:
    lines = ["| run | " + " | ".join(f"generation {g}" for g in generations) + " |",
             "| --- |" + " --- |" * len(generations)]
    for name in RUNS:
        cells = (mean_at(results[name], g) for g in generations)
        lines.append(f"| {name} | " + " | ".join(f"{c:.2f} / {q:.3f}" for c, q in cells) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--generations", type=int, default=200)
    parser.add_argument("--every", type=int, default=50)
    parser.add_argument("--sigma", type=float, default=0.1)
    args = parser.parse_args()
    import ribs

    results = measure(args.seeds, args.generations, args.every, args.sigma, progress=print)
    print(f"\nPlantMaker, leaf_count x porosity 8x8, {INITIAL} random + {BATCH} x "
          f"{args.generations} evaluations, 2 threads; pyribs {ribs.__version__}, "
          f"CMA-ME sigma0 {args.sigma} of the unit cube\n")
    print(seed_table(results))
    print("\n(each cell: coverage / QD-score)\n")
    print(means_table(results, [args.every, args.generations]))


if __name__ == "__main__":
    main()
