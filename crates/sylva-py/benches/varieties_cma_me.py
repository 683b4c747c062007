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


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--generations", type=int, default=200)
    parser.add_argument("--every", type=int, default=50)
    parser.add_argument("--sigma", type=float, default=0.1)
    args = parser.parse_args()
    import ribs

    run_cma_me(99, 2, 1, args.sigma)  # numba compiles pyribs' archive on first use
    print(f"PlantMaker, leaf_count x porosity 8x8, {INITIAL} random + {BATCH} x "
          f"{args.generations} evaluations, 2 threads; pyribs {ribs.__version__}, "
          f"CMA-ME sigma0 {args.sigma} of the unit cube\n")
    print("| seed | run | " + " | ".join(f"gen {g}" for g in range(0, args.generations + 1, args.every))
          + " | wall |")
    print("| --- | --- |" + " --- |" * (args.generations // args.every + 2))
    for seed in args.seeds:
        for name, run in (("Sylva, the model's operators",
                           lambda: run_sylva(seed, args.generations, args.every)),
                          ("Sylva CMA-ME", lambda: run_sylva(seed, args.generations, args.every,
                                                             args.sigma)),
                          ("pyribs CMA-ME", lambda: run_cma_me(seed, args.generations, args.every,
                                                              args.sigma))):
            curve = run()
            cells = " | ".join(f"{c:.2f} / {q:.3f}" for _, c, q, _ in curve)
            print(f"| {seed} | {name} | {cells} | {curve[-1][3]:.1f} s |", flush=True)
    print("\n(each cell: coverage / QD-score)")


if __name__ == "__main__":
    main()
