"""The cluster recipe of docs/python.md ("On a real Ray cluster"), followed on this machine:
the cluster's token made with `ray get-auth-token --generate`, a real `ray start --head` in
a process of its own, and a fresh driver that joins it through `RAY_ADDRESS`, as
`python my_islands.py` would. Every command runs with `RAY_AUTH_MODE=token`, as the recipe
says; a driver without it is refused (what issue 29 met with Ray 2.60: `InvalidAuthToken`,
then `ConnectionError`), and `sylva.islands` says what to set.

The head runs with `--block`, so that stopping it (SIGTERM to that process) stops its node
and nothing else: `ray stop` would stop every Ray on the machine."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

import sylva
from test_islands import RUN, fingerprint, small_sphere

ray = pytest.importorskip("ray", minversion="2.52")  # token authentication came in 2.52

TESTS = Path(__file__).resolve().parent

# The driver: the recipe's `python my_islands.py`, with the small run of test_islands.py.
DRIVER = f"""
import json, sys
sys.path.insert(0, {str(TESTS)!r})
import sylva
from test_islands import RUN, fingerprint, small_sphere
try:
    result = sylva.islands(small_sphere(), **RUN)   # backend "auto": Ray, at RAY_ADDRESS
except sylva.SylvaError as e:
    print(json.dumps({{"error": str(e)}}))
else:
    print(json.dumps({{"backend": result.backend, "fingerprint": fingerprint(result)}}))
"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def ray_command() -> str:
    beside = Path(sys.executable).with_name("ray")
    found = str(beside) if beside.exists() else shutil.which("ray")
    if found is None:
        pytest.skip("no `ray` command beside this Python")
    return found


@pytest.fixture(scope="module")
def head():
    """A Ray head on a free port, with token authentication; yields the environment of
    the recipe's shells (`RAY_AUTH_MODE=token`, the token in `~/.ray/auth_token` of a home
    of its own) and the head's address."""
    ray_cli = ray_command()
    home = Path(tempfile.mkdtemp(prefix="sylva-ray-home-"))
    # Ray's sockets live under --temp-dir and their paths may not be long: a short folder.
    temp = Path(tempfile.mkdtemp(prefix="sylva-ray-"))
    env = {k: v for k, v in os.environ.items()
           if k not in ("RAY_ADDRESS", "RAY_AUTH_TOKEN", "RAY_AUTH_TOKEN_PATH")}
    env.update(
        HOME=str(home),
        RAY_AUTH_MODE="token",
        RAY_USAGE_STATS_ENABLED="0",
        # Stop at once on SIGTERM rather than draining the node for 30 s.
        RAY_GRACEFUL_SHUTDOWN_DRAIN_TIMEOUT_S="0",
    )
    subprocess.run([ray_cli, "get-auth-token", "--generate"], env=env, check=True,
                   capture_output=True, timeout=60)
    assert (home / ".ray" / "auth_token").stat().st_size > 0

    port = free_port()
    log = open(temp / "head.log", "w+")
    process = subprocess.Popen(
        [ray_cli, "start", "--head", f"--port={port}", "--node-ip-address=127.0.0.1",
         "--num-cpus=2", "--include-dashboard=false", "--disable-usage-stats",
         f"--temp-dir={temp}", "--block"],
        env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 60
        while "Ray runtime started" not in (temp / "head.log").read_text():
            if process.poll() is not None or time.monotonic() > deadline:
                pytest.fail(f"ray start --head did not start:\n{(temp / 'head.log').read_text()}")
            time.sleep(0.2)
        yield env, f"127.0.0.1:{port}"
    finally:
        process.send_signal(signal.SIGTERM)  # `ray start --block` stops its node's processes
        try:
            process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)  # the session this test started
            process.wait()
        log.close()
        shutil.rmtree(temp, ignore_errors=True)
        shutil.rmtree(home, ignore_errors=True)


def drive(env: dict, address: str, **extra: str) -> dict:
    """Runs the driver against the cluster; returns what it printed."""
    run = subprocess.run([sys.executable, "-c", DRIVER], env=dict(env, RAY_ADDRESS=address,
                         **extra), capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout.strip().splitlines()[-1])


def test_the_cluster_recipe_runs_islands_as_the_local_pool_does(head):
    env, address = head
    joined = drive(env, address)
    assert joined.get("backend") == "ray", joined
    local = sylva.islands(small_sphere(), backend="local", **RUN)
    assert joined["fingerprint"] == json.loads(json.dumps(fingerprint(local)))


def test_a_driver_without_the_token_is_told_what_to_set(head):
    env, address = head
    env = {k: v for k, v in env.items() if k != "RAY_AUTH_MODE"}
    # Ray retries a refused connection for 20 s; one try is enough here.
    refused = drive(env, address, RAY_gcs_server_port_wait_time_s="1")
    assert "RAY_AUTH_MODE=token" in refused.get("error", ""), refused
