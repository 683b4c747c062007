"""The walk-through of docs/python.md runs as written."""

from __future__ import annotations

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]


def test_the_walk_through_runs_as_written(tmp_path, monkeypatch):
    text = (ROOT / "docs" / "python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 8
    # From "the repository's root": the examples are there; what it writes lands here.
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "docs/python.md", "exec"), namespace)
    for written in ["tulip.glb", "tulip.png", "run.checkpoint.json", "garden.glb", "best-island.glb"]:
        assert (tmp_path / written).stat().st_size > 0, written
    assert namespace["again"].generation == namespace["run"].generation
    # The fitness function of one's own: crowns under the height cap, in place of the model's.
    shaped, crown = namespace["shaped"], namespace["crown"]
    assert shaped.term_names == ["python"] and crown.terms["python"] > 0
    assert crown.genome.grow().mesh.positions[:, 1].max() <= 4.0
    assert shaped.stats[-1]["best"] >= shaped.stats[0]["best"]
    assert os.path.getsize(tmp_path / "tulip.png") == len(namespace["png"])
