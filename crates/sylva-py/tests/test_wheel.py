"""scripts/wheel: an abi3 manylinux2014 wheel that installs and grows a plant where no Rust
is on the PATH.

Opt-in, since it is a release build (several minutes on 2 cores from scratch):
`SYLVA_TEST_WHEEL=1 ./scripts/test`, or `SYLVA_TEST_WHEEL=1 pytest tests/test_wheel.py`."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]

pytestmark = pytest.mark.skipif(
    os.environ.get("SYLVA_TEST_WHEEL") != "1",
    reason="a release build of the wheel: set SYLVA_TEST_WHEEL=1 to run it",
)


def test_the_wheel_is_abi3_manylinux2014_and_installs_without_rust(tmp_path):
    out = tmp_path / "dist"
    build = subprocess.run([str(ROOT / "scripts" / "wheel"), "--out", str(out)], cwd=ROOT,
                           capture_output=True, text=True, timeout=3600)
    assert build.returncode == 0, build.stderr[-5000:]
    wheel = Path(build.stdout.strip().splitlines()[-1])
    assert wheel.parent == out and wheel.exists(), build.stdout

    arch = platform.machine()
    with zipfile.ZipFile(wheel) as z:
        info = next(n for n in z.namelist() if n.endswith(".dist-info/WHEEL"))
        tags = {line.split(": ", 1)[1] for line in z.read(info).decode().splitlines()
                if line.startswith("Tag: ")}
        native = [n for n in z.namelist() if n.endswith(".so")]
    assert tags == {f"cp310-abi3-manylinux2014_{arch}", f"cp310-abi3-manylinux_2_17_{arch}"}
    assert native == ["sylva/_sylva.abi3.so"]

    # A fresh venv, and a PATH without cargo or rustc: pip must not build anything.
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    path = [str(venv / "bin")] + [
        p for p in os.environ.get("PATH", "").split(os.pathsep)
        if p and not (Path(p) / "cargo").exists() and not (Path(p) / "rustc").exists()
    ]
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["PATH"] = os.pathsep.join(path)
    install = subprocess.run([str(venv / "bin" / "pip"), "install", "-q", "--only-binary", ":all:",
                              str(wheel)], env=env, capture_output=True, text=True, timeout=600)
    assert install.returncode == 0, install.stderr[-3000:]
    grow = subprocess.run(
        [str(venv / "bin" / "python"), "-c",
         "import sylva\n"
         f"plant = sylva.Genome.load({str(ROOT / 'examples/plantmaker/tulip.json')!r}).grow()\n"
         "print(sylva.__file__, plant.segments, plant.mesh.positions.shape[0])"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300,
    )
    assert grow.returncode == 0, grow.stderr[-3000:]
    module, segments, vertices = grow.stdout.split()
    assert Path(module).is_relative_to(venv), "sylva came from the venv's wheel"
    assert int(segments) > 0 and int(vertices) > 0
