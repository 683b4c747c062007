"""Poncin's Table 2 run scored on sampled pairs, as the paper did.

Evolves box-above at 8000 x 100 with F_dist on max(3N, 10) random pairs drawn afresh every
generation, then re-scores the best of generations 8, 25 and 100 on every pair, to measure
how much lower a best's sampled F_dist reads. Used in docs/automata.md.

    python scripts/experiments/table2_sampled.py SEED
"""

import sys
from pathlib import Path

import sylva

EXAMPLES = Path(__file__).resolve().parents[2] / "examples/automata"


def main(seed: int) -> None:
    base = sylva.Config.load(EXAMPLES / "box-above.toml").to_dict()
    base["run"].update(population=8000, seed=seed)
    automata = base["automata"]
    sampled = {
        **base,
        "automata": {
            **automata,
            "breeding": {**automata["breeding"], "reevaluate": True},
            "fitness": {**automata["fitness"], "pairs": {"mode": "sampled"}},
        },
    }
    run = sylva.Evolution(sylva.Config.from_dict(sampled, base=EXAMPLES))
    exact = {**base, "run": {**base["run"], "population": 4}}
    for generation in range(1, 101):
        run.step()
        if generation not in (8, 25, 100):
            continue
        judge = sylva.Evolution(sylva.Config.from_dict(exact, base=EXAMPLES))
        judge.immigrate(run.emigrants(1))
        [rescored] = [m.terms for m in judge.population() if m.operator == "immigrant"]
        best = run.best().terms
        print(
            f"seed {seed} gen {generation}: sampled F_dist {best['f_dist']:.2f}"
            f" F_total {best['f_total']:.0f} | all pairs F_dist {rescored['f_dist']:.2f}"
            f" F_total {rescored['f_total']:.0f}",
            flush=True,
        )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1)
