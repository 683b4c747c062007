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
    assert os.path.getsize(tmp_path / "tulip.png") == len(namespace["png"])
