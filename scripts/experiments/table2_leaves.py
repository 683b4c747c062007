"""How leaves spread through Poncin's Table 2 run (box-above at 8000 x 100).

Per generation: the share of the population with a leaf and their median count, the share
past the grid gate, the best's leaves, F_grid and F_total; at generations 4, 8 and 12 also
how many leafy trees score an F_grid no better than a bare tree's. Used in docs/automata.md.

    python scripts/experiments/table2_leaves.py SEED
"""

import statistics
import sys
from pathlib import Path

import sylva

CONFIG = Path(__file__).resolve().parents[2] / "examples/automata/box-above.toml"


def main(seed: int) -> None:
    config = sylva.Config.load(CONFIG).with_run(population=8000, seed=seed)
    run = sylva.Evolution(config)
    show(run)
    for generation in range(1, 101):
        run.step()
        if generation in (1, 2, 4, 8, 12, 16, 25, 50, 75, 100):
            show(run)


def show(run: sylva.Evolution) -> None:
    terms = [m.terms for m in run.population()]
    leafy = [t for t in terms if t["leaves"] > 0]
    past_gate = sum(t["f_grid"] < 100 for t in terms) / len(terms)
    best = run.best().terms
    line = (
        f"gen {run.generation:3d}: leafy {100 * len(leafy) / len(terms):5.1f}%"
        f"  median leaves {statistics.median(t['leaves'] for t in leafy) if leafy else 0:5.0f}"
        f"  past gate {100 * past_gate:5.1f}%"
        f"  best: leaves {best['leaves']:4.0f} F_grid {best['f_grid']:5.1f}"
        f" F_total {best['f_total']:5.0f}"
    )
    if run.generation in (4, 8, 12) and leafy:
        no_better = sum(t["f_grid"] >= 80 for t in leafy) / len(leafy)
        line += f"  leafy with F_grid >= 80: {100 * no_better:.0f}%"
    print(line, flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1)
