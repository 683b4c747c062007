"""Islands: deterministic on Ray and on the local pool alike, through lost workers and a
stopped driver."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

import sylva
from sylva.islands import island_seed, sources

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def small_sphere() -> sylva.Config:
    """The paper's sphere problem (automata), small enough for a test."""
    return sylva.Config.load(EXAMPLES / "automata" / "sphere.toml").with_run(
        population=24, generations=9
    )


def fingerprint(result: sylva.IslandsResult) -> tuple:
    """What must not depend on where or how the islands ran: the best genome and every
    island's statistics but their timing."""
    rows = [
        [{k: v for k, v in row.items() if k != "seconds"} for row in island]
        for island in result.stats
    ]
    return result.best.to_json(), result.fitness, result.island, rows


RUN = dict(islands=3, migrate_every=3, migrants=2, topology="ring", seed=5)


@pytest.fixture(scope="module")
def local() -> sylva.IslandsResult:
    return sylva.islands(small_sphere(), backend="local", **RUN)


def test_topologies_send_to_every_island():
    assert sources("ring", 4, 0) == [[3], [0], [1], [2]]
    # Over N - 1 rounds of "rotate", every island hears from every other once.
    heard = [set() for _ in range(4)]
    for r in range(3):
        for i, src in enumerate(sources("rotate", 4, r)):
            heard[i].update(src)
    assert heard == [set(range(4)) - {i} for i in range(4)]
    assert sources("full", 3, 7) == [[1, 2], [0, 2], [0, 1]]
    seeds = {island_seed(5, i) for i in range(100)}
    assert len(seeds) == 100 and all(0 <= s < 2**63 for s in seeds)


def test_local_islands_migrate_and_repeat(local):
    assert local.backend == "local"
    assert local.rounds == 3 and local.restarts == 0
    assert all(len(island) == 10 for island in local.stats)  # generations 0 to 9
    again = sylva.islands(small_sphere(), backend="local", threads=2, **RUN)
    assert fingerprint(again) == fingerprint(local)
    # Immigrants arrived: the last checkpoint of some island holds members made so.
    run = local.evolution(0)
    assert run.generation == 9
    other = sylva.islands(small_sphere(), backend="local", **dict(RUN, migrants=0))
    assert fingerprint(other) != fingerprint(local), "migration changes the run"


def test_a_lost_local_worker_is_restarted_from_its_checkpoint(local):
    killed = []

    def kill_one(info):
        if info["round"] == 1:
            os.kill(info["pids"][1], signal.SIGKILL)
            killed.append(info["pids"][1])

    result = sylva.islands(small_sphere(), backend="local", on_round=kill_one, **RUN)
    assert killed and result.restarts == 1
    assert fingerprint(result) == fingerprint(local)


def test_a_stopped_driver_resumes_from_its_checkpoint(local, tmp_path):
    path = tmp_path / "islands.json"

    class Stop(Exception):
        pass

    def stop(info):
        if info["round"] == 2:
            raise Stop

    with pytest.raises(Stop):
        sylva.islands(small_sphere(), backend="local", checkpoint=path, on_round=stop, **RUN)
    assert path.exists()
    result = sylva.islands(small_sphere(), backend="local", checkpoint=path, **RUN)
    assert result.rounds == 1, "only the last round was left"
    assert fingerprint(result) == fingerprint(local)
    with pytest.raises(sylva.InputError, match="different island run"):
        sylva.islands(small_sphere(), backend="local", checkpoint=path, **dict(RUN, migrants=1))


CTRL_C_SCRIPT = """
import sys, sylva
config = sylva.Config.load(sys.argv[1]).with_run(population=200, generations=400)
def on_round(info):
    print("round", info["round"], *info["pids"], flush=True)
try:
    sylva.islands(config, islands=2, migrate_every=2, seed=3, backend=sys.argv[3],
                  checkpoint=sys.argv[2], on_round=on_round)
except KeyboardInterrupt:
    print("stopped", flush=True)
    sys.exit(130)
"""


def test_ctrl_c_stops_local_islands_without_tracebacks_from_workers(tmp_path):
    import subprocess
    import sys

    # The driver in a process group of its own, with its workers: the terminal's Ctrl-C
    # goes to the whole group.
    driver = subprocess.Popen(
        [sys.executable, "-c", CTRL_C_SCRIPT, str(EXAMPLES / "automata" / "sphere.toml"),
         str(tmp_path / "islands.json"), "local"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
    )
    try:
        first = driver.stdout.readline().split()
        assert first[:2] == ["round", "1"], first
        os.killpg(driver.pid, signal.SIGINT)
        out, err = driver.communicate(timeout=60)
    finally:
        if driver.poll() is None:
            driver.kill()
    assert driver.returncode == 130 and out.strip().endswith("stopped"), (out, err)
    # Only the driver heard it: no worker wrote a traceback, and none is left.
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    for pid in map(int, first[2:]):
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)
    # The run resumes from its last round.
    saved = __import__("json").loads((tmp_path / "islands.json").read_text())
    assert saved["round"] >= 1


@pytest.mark.parametrize(
    "change, field",
    [
        (dict(topology="star"), "topology"),
        (dict(islands=0), "islands"),
        (dict(migrants=25), "migrants"),
        (dict(migrate_every=0), "migrate_every"),
        (dict(seed=-1), "seed"),
        (dict(backend="mpi"), "backend"),
    ],
)
def test_bad_settings_are_refused(change, field):
    with pytest.raises(sylva.InputError) as e:
        sylva.islands(small_sphere(), **{**RUN, "backend": "local", **change})
    assert e.value.location == field


def test_an_island_that_cannot_start_reports_why():
    config = sylva.Config.from_dict(
        {"model": "plantmaker", "run": {"population": 4}, "plantmaker": {"start": ["missing.json"]}}
    )
    with pytest.raises(FileNotFoundError, match="missing.json"):
        sylva.islands(config, backend="local", islands=2)


@pytest.fixture(scope="module")
def cluster():
    """Two Ray nodes on this machine."""
    ray = pytest.importorskip("ray")
    from ray.cluster_utils import Cluster

    cluster = Cluster(
        initialize_head=True,
        head_node_args={"num_cpus": 2, "include_dashboard": False},
    )
    cluster.add_node(num_cpus=2)
    ray.init(address=cluster.address, logging_level="ERROR")
    cluster.wait_for_nodes()
    yield cluster
    ray.shutdown()
    cluster.shutdown()


def test_ray_islands_match_the_local_pool_and_survive_a_killed_actor(cluster, local):
    import ray

    assert len([n for n in ray.nodes() if n["Alive"]]) == 2
    undisturbed = sylva.islands(small_sphere(), backend="ray", **RUN)
    assert undisturbed.backend == "ray"
    assert fingerprint(undisturbed) == fingerprint(local)

    killed = []

    def kill_one(info):
        if info["round"] == 1:
            os.kill(info["pids"][2], signal.SIGKILL)
            killed.append(info["pids"][2])

    disturbed = sylva.islands(small_sphere(), backend="ray", on_round=kill_one, **RUN)
    assert killed and disturbed.restarts >= 1
    assert fingerprint(disturbed) == fingerprint(local)


def test_ctrl_c_stops_ray_islands_without_tracebacks(tmp_path):
    import subprocess
    import sys

    pytest.importorskip("ray")
    # A local Ray started by the driver, in a home of its own (Ray writes its token there);
    # the terminal's Ctrl-C goes to the driver's whole process group, Ray's processes too.
    env = dict(os.environ, HOME=str(tmp_path), RAY_USAGE_STATS_ENABLED="0")
    env.pop("RAY_ADDRESS", None)
    driver = subprocess.Popen(
        [sys.executable, "-c", CTRL_C_SCRIPT, str(EXAMPLES / "automata" / "sphere.toml"),
         str(tmp_path / "islands.json"), "ray"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        env=env,
    )
    try:
        first = driver.stdout.readline().split()
        assert first[:2] == ["round", "1"], (first, driver.stderr.read() if not first else "")
        os.killpg(driver.pid, signal.SIGINT)
        out, err = driver.communicate(timeout=120)
    finally:
        if driver.poll() is None:
            os.killpg(driver.pid, signal.SIGKILL)
    assert driver.returncode == 130 and out.strip().endswith("stopped"), (out, err)
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
