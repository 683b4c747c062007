"""docs/varieties.md's figures come from scripts/varieties-figures. These re-run the part of
them that is deterministic (Sylva's own coverage and QD-scores; the binary-tree example's map)
and fail when the page no longer says what the code does: run the script again then."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

import sylva

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "crates" / "sylva-py" / "benches"))

import varieties_cma_me as cma  # noqa: E402
import varieties_vs_pyribs as vs  # noqa: E402

DOC = (ROOT / "docs" / "varieties.md").read_text()
AGAIN = "docs/varieties.md has drifted from the code: run scripts/varieties-figures"


def rows(name: str) -> list[list[str]]:
    """The body rows of the Markdown table in the page's `figures:NAME` block."""
    found = re.search(rf"<!-- figures:{name} -->\n(.*?)\n<!-- /figures:{name} -->", DOC, re.S)
    assert found, f"docs/varieties.md has no figures:{name} block"
    table = [line for line in found.group(1).splitlines() if line.startswith("|")]
    assert len(table) > 2, f"the figures:{name} block holds no table"
    return [[cell.strip() for cell in line.strip("|").split("|")] for line in table[2:]]


def test_every_block_is_filled():
    for name in re.findall(r"<!-- figures:([a-z-]+) -->", DOC):
        body = re.search(rf"<!-- figures:{name} -->\n(.*?)<!-- /figures:{name} -->", DOC, re.S)
        assert body and body.group(1).strip(), f"figures:{name} is empty: {AGAIN}"


def test_sylva_against_pyribs_seed_by_seed():
    sylva_rows = [row for row in rows("pyribs-seeds") if row[1] == vs.NAMES["sylva"]]
    assert [int(row[0]) for row in sylva_rows] == [1, 2, 3, 4, 5]
    for row in sylva_rows:
        r = vs.run_sylva(int(row[0]), 100)
        assert [f"{r['coverage']:.2f}", f"{r['qd_score']:.1f}"] == row[2:4], AGAIN


def test_sylva_mean_at_the_smallest_budget():
    (row,) = [row for row in rows("pyribs-budgets") if row[0].startswith("20 (")]
    runs = [vs.run_sylva(seed, 20) for seed in (1, 2, 3, 4, 5)]
    mean = vs.means({"sylva": runs})["sylva"]
    assert [f"{mean['coverage']:.3f}", f"{mean['qd_score']:.1f}"] == row[2:4], AGAIN


@pytest.mark.parametrize("name,sigma", [(cma.RUNS[0], None), (cma.RUNS[1], 0.1)])
def test_cma_me_table_sylva_curves_of_seed_1(name, sigma):
    (row,) = [row for row in rows("cma-seeds") if row[:2] == ["1", name]]
    curve = cma.run_sylva(1, 200, 50, sigma)
    assert [f"{c:.2f} / {q:.3f}" for _, c, q, _ in curve] == row[2:-1], AGAIN


def test_bintree_example_map():
    (row,) = [row for row in rows("examples") if row[0] == "`examples/bintree/varieties.toml`"]
    config = sylva.Config.load(ROOT / "examples" / "bintree" / "varieties.toml")
    varieties = sylva.varieties(config)
    varieties.run(config.to_dict()["run"]["generations"])
    stats = varieties.stats
    filled = f"{stats[-1]['filled']} of 100"
    assert row[3].split(" (")[0] == filled, AGAIN
    assert row[4] == f"{sum(s['evaluations'] for s in stats):,}", AGAIN
    assert row[5] == f"{stats[-1]['qd_score']:.3f}", AGAIN
