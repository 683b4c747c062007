"""Island-model evolution: several populations of one config, exchanging their best.

:func:`islands` runs ``N`` populations, each a Rust run stepping ``migrate_every``
generations per call with the GIL released, in Ray actors when Ray is installed and in
local worker processes otherwise. After every round the best ``migrants`` genomes of each
island move along the topology as plain bytes and take the places of the worst members of
the islands they reach. Rounds are synchronous and every island's seed follows from
``seed``, so a run gives the same best genome on Ray, on the local pool, and after any
number of lost and restarted islands: the driver keeps every island's checkpoint of the
last round and restarts a lost island from it.
"""

from __future__ import annotations

import json
import os
import pickle
import signal
import struct
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

from ._sylva import Config, Evolution, Genome
from .errors import InputError, SylvaError

TOPOLOGIES = ("ring", "rotate", "full")
_MASK = (1 << 64) - 1
_MAX_SEED = (1 << 63) - 1  # seeds are TOML integers in configs and checkpoints
_FORMAT = 1


def island_seed(seed: int, island: int) -> int:
    """The seed of island ``island`` of a run seeded ``seed`` (a SplitMix64 step)."""
    z = (seed + (island + 1) * 0x9E3779B97F4A7C15) & _MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK
    return (z ^ (z >> 31)) & _MAX_SEED


def sources(topology: str, islands: int, round_index: int) -> list[list[int]]:
    """For each island, the islands it receives migrants from after round ``round_index``.

    ``ring``: island i hears from i - 1. ``rotate``: from i - 1 - (round mod (N - 1)), so
    that over N - 1 rounds every island hears from every other. ``full``: from all others.
    """
    n = islands
    if n < 2:
        return [[] for _ in range(n)]
    if topology == "ring":
        return [[(i - 1) % n] for i in range(n)]
    if topology == "rotate":
        step = 1 + round_index % (n - 1)
        return [[(i - step) % n] for i in range(n)]
    return [[j for j in range(n) if j != i] for i in range(n)]


class _Island:
    """One island: a run of the config with its own seed (a Ray actor, or a local worker)."""

    def __init__(self, config_toml: str, base: str, threads: int, checkpoint: str | None):
        config = Config.from_toml(config_toml, "<island config>", base)
        if checkpoint is None:
            self.run = Evolution(config, threads=threads)
        else:
            self.run = Evolution.resume(config, text=checkpoint, threads=threads)

    def advance(self, immigrants: list[bytes], steps: int, migrants: int) -> dict[str, Any]:
        """Takes in ``immigrants``, breeds ``steps`` generations, and reports."""
        if immigrants:
            self.run.immigrate(immigrants)
        for _ in range(steps):
            self.run.step()
        best = self.run.best()
        return {
            "checkpoint": self.run.checkpoint(),
            "emigrants": self.run.emigrants(migrants),
            "generation": self.run.generation,
            "best": best.fitness,
            "pid": os.getpid(),
        }

    def final(self) -> dict[str, Any]:
        """The best member and the statistics, for the result."""
        best = self.run.best()
        return {
            "genome": best.genome.to_json(),
            "fitness": best.fitness,
            "terms": dict(best.terms),
            "id": best.id,
            "stats": self.run.stats,
        }


class _Lost(Exception):
    """An island's worker died."""


def _send(stream: Any, value: Any) -> None:
    data = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(struct.pack("<Q", len(data)) + data)
    stream.flush()


def _receive(stream: Any) -> Any:
    head = stream.read(8)
    if len(head) < 8:
        raise EOFError("the worker's channel closed")
    (size,) = struct.unpack("<Q", head)
    data = stream.read(size)
    if len(data) < size:
        raise EOFError("the worker's channel closed mid-message")
    return pickle.loads(data)


def _serve() -> None:
    """A local worker (``python -m sylva._worker``): serves calls to one island, read from
    standard input, until its input closes. An island that could not start answers every
    call with the reason. Standard output is kept for replies: anything printed goes to
    standard error.

    Ctrl-C is the driver's to handle: a terminal sends it to the whole process group, and a
    worker that took it would end with a traceback of its own; the driver ends its workers
    instead (:func:`islands`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    calls = os.fdopen(os.dup(0), "rb")
    replies = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    island, failure = None, None
    try:
        island = _Island(*_receive(calls))
    except BaseException as e:  # noqa: BLE001 (sent back, raised by the driver)
        failure = e
    while True:
        try:
            method, args = _receive(calls)
        except EOFError:
            return
        if failure is not None:
            _send(replies, ("err", failure))
            continue
        try:
            _send(replies, ("ok", getattr(island, method)(*args)))
        except BaseException as e:  # noqa: BLE001
            _send(replies, ("err", e))


class _LocalBackend:
    """Islands in worker processes of this machine, one each: fresh interpreters running
    ``python -m sylva._worker`` (no forked threads, no re-run of the caller's script)."""

    name = "local"

    def start(self, args: tuple) -> Any:
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
        proc = subprocess.Popen(
            [sys.executable, "-m", "sylva._worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            env=env,
        )
        self.submit(proc, "", *args)  # the island's arguments come first
        return proc

    def submit(self, worker: Any, method: str, *args: Any) -> Any:
        try:
            _send(worker.stdin, args if method == "" else (method, args))
        except (BrokenPipeError, OSError, ValueError):
            pass  # found lost when its result is read
        return worker

    def results(self, pending: list) -> list:
        out = []
        for worker in pending:
            try:
                status, value = _receive(worker.stdout)
            except (EOFError, OSError, ValueError) as e:
                raise _Lost(f"worker {worker.pid} ended (exit status {worker.poll()})") from e
            if status == "err":
                raise value
            out.append(value)
        return out

    def stop(self, worker: Any, now: bool = False) -> None:
        """Ends a worker: it exits when its input closes, after the call under way; ``now``
        ends it at once (SIGTERM: no traceback, nothing more written)."""
        if now and worker.poll() is None:
            worker.terminate()
        for stream in (worker.stdin, worker.stdout):
            try:
                stream.close()
            except OSError:
                pass
        try:
            worker.wait(timeout=10)
        except subprocess.TimeoutExpired:
            worker.kill()
            worker.wait()


def _connect(ray: Any) -> None:
    """``ray.init()``: joins the cluster at ``RAY_ADDRESS`` when it is set, else starts a
    local Ray. A cluster that asks for a token this process does not send (Ray 2.52 and
    later: ``RAY_AUTH_MODE=token`` on the cluster, not here) is refused by Ray with a
    ``ConnectionError`` after 20 seconds of retries; that one is raised as a
    :class:`SylvaError` that says what to set."""
    try:
        ray.init()
    except ConnectionError as e:
        if not _refused_for_token(e):
            raise
        address = os.environ.get("RAY_ADDRESS", "the Ray cluster")
        raise SylvaError(
            f"{address} refused this process: the cluster uses token authentication "
            f"(RAY_AUTH_MODE=token) and this process sent no token or the wrong one. Run it "
            f"with RAY_AUTH_MODE=token and the cluster's token in ~/.ray/auth_token (or in "
            f"RAY_AUTH_TOKEN), as every node of the cluster has it; see 'On a real Ray "
            f"cluster' in Sylva's docs/python.md"
        ) from e


def _refused_for_token(error: BaseException) -> bool:
    """Whether ``error`` or one of its causes is Ray's refusal of a missing or wrong token."""
    seen: set[int] = set()
    cause: BaseException | None = error
    while cause is not None and id(cause) not in seen:
        seen.add(id(cause))
        if type(cause).__name__ == "AuthenticationError" or "InvalidAuthToken" in str(cause):
            return True
        cause = cause.__cause__ or cause.__context__
    return False


class _RayBackend:
    """Islands as Ray actors, spread over the cluster's nodes."""

    name = "ray"

    def __init__(self, islands: int, threads: int) -> None:
        import ray

        if not ray.is_initialized():
            _connect(ray)
        self.ray = ray
        cpus = ray.cluster_resources().get("CPU", 1.0)
        # An island asks for its share of the cluster, so that all of them are placed.
        share = min(float(threads or 1), cpus / islands)
        self.actor = ray.remote(num_cpus=share, max_restarts=0, scheduling_strategy="SPREAD")(
            _Island
        )

    def start(self, args: tuple) -> Any:
        handle = self.actor.remote(*args)
        return handle

    def submit(self, worker: Any, method: str, *args: Any) -> Any:
        return getattr(worker, method).remote(*args)

    def results(self, pending: list) -> list:
        out = []
        for ref in pending:
            try:
                out.append(self.ray.get(ref))
            except self.ray.exceptions.RayActorError as e:
                raise _Lost(str(e)) from e
        return out

    def stop(self, worker: Any, now: bool = False) -> None:
        self.ray.kill(worker)


@dataclass
class IslandsResult:
    """What an island run ends with."""

    best: Genome
    """The best genome of all islands (ties go to the lower island)."""
    fitness: float
    """Its total fitness."""
    terms: dict[str, float]
    """Its fitness terms."""
    island: int
    """The island it lives on."""
    stats: list[list[dict[str, Any]]]
    """Each island's statistics, one row per generation (as ``Evolution.stats``)."""
    checkpoints: list[str]
    """Each island's last checkpoint (``Evolution.resume(config, text=...)`` browses it)."""
    configs: list[Config]
    """Each island's config (the run's, with the island's seed)."""
    rounds: int
    """Rounds run (in this call)."""
    restarts: int
    """Islands restarted from their checkpoints after their worker was lost."""
    seconds: float
    """Wall time of the rounds, start-up of the workers included."""
    backend: str
    """``"ray"`` or ``"local"``."""
    round_seconds: list[float] = field(default_factory=list)
    """Wall time of each round."""

    def evolution(self, island: int) -> Evolution:
        """Island ``island``'s run, resumed from its last checkpoint, to browse or go on."""
        return Evolution.resume(self.configs[island], text=self.checkpoints[island])


def _as_config(config: Config | dict | str | os.PathLike) -> Config:
    if isinstance(config, Config):
        return config
    if isinstance(config, dict):
        return Config.from_dict(config)
    return Config.load(os.fspath(config))


def _check(name: str, value: Any, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise InputError(
            f"{name}: {value!r}; expected a whole number from {low} to {high}",
            location=name,
            detail=f"expected a whole number from {low} to {high}",
        )
    return value


def islands(
    config: Config | dict | str | os.PathLike,
    islands: int = 4,
    migrate_every: int = 10,
    migrants: int = 2,
    topology: str = "ring",
    seed: int = 1,
    *,
    generations: int | None = None,
    threads: int = 1,
    backend: str = "auto",
    checkpoint: str | os.PathLike | None = None,
    max_restarts: int = 3,
    on_round: Callable[[dict[str, Any]], None] | None = None,
    progress: bool = False,
) -> IslandsResult:
    """Runs ``islands`` populations of ``config`` that exchange migrants.

    Args:
        config: a :class:`Config`, a dict shaped like a config file, or a config file's path.
            Its population is each island's; its seed is replaced by each island's own.
        islands: populations, 1 to 1024.
        migrate_every: generations each island breeds between migrations.
        migrants: genomes each island sends per round (its fittest).
        topology: ``"ring"``, ``"rotate"`` or ``"full"`` (see :func:`sources`).
        seed: seed of the whole run; island seeds follow from it.
        generations: generations bred after the first (the config's when left out).
        threads: worker threads per island (results do not depend on it).
        backend: ``"ray"``, ``"local"`` (worker processes on this machine), or ``"auto"``
            (Ray when it is installed). Ray is started with ``ray.init()`` unless it is
            already initialised: it joins the cluster at ``RAY_ADDRESS`` when that is set,
            else starts a Ray on this machine.
        checkpoint: a file the driver writes after every round; if it exists when the run
            starts, the run resumes from it.
        max_restarts: restarts allowed per island per round before the run gives up.
        on_round: called after each round with a dict: ``round``, ``generation``, ``best``
            (each island's best fitness), ``pids`` (each island's worker process).
        progress: print one line per round to standard error.

    Returns:
        An :class:`IslandsResult`.

    Ctrl-C raises ``KeyboardInterrupt`` in the caller alone: the workers end at once, without
    tracebacks of their own, and with ``checkpoint`` the run resumes from its last round.
    """
    config = _as_config(config)
    _check("islands", islands, 1, 1024)
    _check("migrate_every", migrate_every, 1, 1_000_000)
    _check("migrants", migrants, 0, config.population)
    _check("seed", seed, 0, _MAX_SEED)
    _check("threads", threads, 0, 1024)
    _check("max_restarts", max_restarts, 0, 1000)
    total = _check("generations", config.generations if generations is None else generations, 0, 1_000_000)
    if topology not in TOPOLOGIES:
        raise InputError(
            f"topology: {topology!r}; expected one of {', '.join(TOPOLOGIES)}",
            location="topology",
        )
    if backend not in ("auto", "ray", "local"):
        raise InputError(f"backend: {backend!r}; expected auto, ray or local", location="backend")
    if backend == "auto":
        try:
            import ray  # noqa: F401

            backend = "ray"
        except ImportError:
            backend = "local"
    runner = _RayBackend(islands, threads) if backend == "ray" else _LocalBackend()

    configs = [config.with_run(seed=island_seed(seed, i), threads=threads) for i in range(islands)]
    texts = [c.to_toml() for c in configs]
    base = os.fspath(config.base)
    states: list[str | None] = [None] * islands
    incoming: list[list[bytes]] = [[] for _ in range(islands)]
    generation = 0
    round_index = 0
    saved = _load(checkpoint, texts, migrate_every, migrants, topology)
    if saved is not None:
        states, incoming = saved["states"], [[m.encode() for m in ms] for ms in saved["incoming"]]
        generation, round_index = saved["generation"], saved["round"]

    started = time.perf_counter()
    workers = [runner.start((texts[i], base, threads, states[i])) for i in range(islands)]
    restarts = 0
    rounds = 0
    round_seconds: list[float] = []
    interrupted = False
    try:
        while generation < total:
            round_start = time.perf_counter()
            steps = min(migrate_every, total - generation)
            reports = _round(runner, workers, states, texts, base, threads, incoming, steps,
                             migrants, max_restarts)
            restarts += reports.pop()
            states = [r["checkpoint"] for r in reports]
            generation += steps
            sent = [r["emigrants"] for r in reports]
            incoming = [
                [m for j in src for m in sent[j]]
                for src in sources(topology, islands, round_index)
            ]
            round_index += 1
            rounds += 1
            round_seconds.append(time.perf_counter() - round_start)
            _save(checkpoint, texts, migrate_every, migrants, topology, states, incoming,
                  generation, round_index)
            info = {
                "round": round_index,
                "generation": generation,
                "best": [r["best"] for r in reports],
                "pids": [r["pid"] for r in reports],
            }
            if progress:
                print(
                    f"round {round_index}: generation {generation}/{total}, best "
                    f"{max(b for b in info['best'] if b is not None):.6g}",
                    file=sys.stderr,
                )
            if on_round is not None:
                on_round(info)
        finals = _call_all(runner, workers, states, texts, base, threads, "final", (),
                           max_restarts)
        restarts += finals.pop()
        if states[0] is None:  # no round ran: the checkpoints are of generation 0
            states = _call_all(runner, workers, states, texts, base, threads, "advance",
                               ([], 0, 0), max_restarts)
            restarts += states.pop()
            states = [s["checkpoint"] for s in states]
    except KeyboardInterrupt:
        # Ctrl-C: the workers end at once, and the run resumes from the last round's
        # checkpoint (``checkpoint=``).
        interrupted = True
        raise
    finally:
        for w in workers:
            try:
                runner.stop(w, now=interrupted)
            except Exception:  # noqa: BLE001 (a lost worker needs no stopping)
                pass
    seconds = time.perf_counter() - started
    best_island = max(range(islands), key=lambda i: (finals[i]["fitness"] or float("-inf"), -i))
    best = finals[best_island]
    return IslandsResult(
        best=Genome.from_json(best["genome"]),
        fitness=best["fitness"],
        terms=best["terms"],
        island=best_island,
        stats=[f["stats"] for f in finals],
        checkpoints=[s for s in states if s is not None],
        configs=configs,
        rounds=rounds,
        restarts=restarts,
        seconds=seconds,
        backend=runner.name,
        round_seconds=round_seconds,
    )


def _round(runner, workers, states, texts, base, threads, incoming, steps, migrants,
           max_restarts) -> list:
    """Every island's ``advance`` of one round; the restart count is the last item."""
    pending = [runner.submit(w, "advance", incoming[i], steps, migrants) for i, w in enumerate(workers)]
    return _gather(runner, workers, pending, states, texts, base, threads,
                   lambda i: ("advance", (incoming[i], steps, migrants)), max_restarts)


def _call_all(runner, workers, states, texts, base, threads, method, args, max_restarts) -> list:
    pending = [runner.submit(w, method, *args) for w in workers]
    return _gather(runner, workers, pending, states, texts, base, threads,
                   lambda i: (method, args), max_restarts)


def _gather(runner, workers, pending, states, texts, base, threads, call, max_restarts) -> list:
    """Results of ``pending`` calls; a lost island is restarted from ``states`` (its last
    round's checkpoint) and its call made again, at most ``max_restarts`` times."""
    results: list = []
    restarts = 0
    for i, ref in enumerate(pending):
        tries = 0
        while True:
            try:
                results.append(runner.results([ref])[0])
                break
            except _Lost as lost:
                tries += 1
                restarts += 1
                if tries > max_restarts:
                    raise SylvaError(
                        f"island {i} was lost {tries} times in one round; last: {lost}"
                    ) from lost
                try:
                    runner.stop(workers[i])
                except Exception:  # noqa: BLE001
                    pass
                workers[i] = runner.start((texts[i], base, threads, states[i]))
                method, args = call(i)
                ref = runner.submit(workers[i], method, *args)
    results.append(restarts)
    return results


def _load(path, texts, migrate_every, migrants, topology) -> dict | None:
    if path is None or not Path(path).exists():
        return None
    try:
        saved = json.loads(Path(path).read_text())
    except (OSError, ValueError) as e:
        raise InputError(f"{os.fspath(path)}: not an islands checkpoint: {e}",
                         location=os.fspath(path), path=os.fspath(path)) from e
    expected = {"format": _FORMAT, "configs": texts, "migrate_every": migrate_every,
                "migrants": migrants, "topology": topology}
    for key, value in expected.items():
        if saved.get(key) != value:
            raise InputError(
                f"{os.fspath(path)}: the checkpoint was written by a different island run "
                f"(`{key}` differs); remove it or run with the same settings",
                location=os.fspath(path), path=os.fspath(path),
            )
    return saved


def _save(path, texts, migrate_every, migrants, topology, states, incoming, generation,
          round_index) -> None:
    if path is None:
        return
    data = {
        "format": _FORMAT, "configs": texts, "migrate_every": migrate_every,
        "migrants": migrants, "topology": topology, "round": round_index,
        "generation": generation, "states": states,
        "incoming": [[m.decode() for m in ms] for ms in incoming],
    }
    path = Path(path)
    temp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(temp, "w") as f:
        json.dump(data, f)
        f.flush()
        os.fsync(f.fileno())
    os.replace(temp, path)


__all__ = ["IslandsResult", "TOPOLOGIES", "island_seed", "islands", "sources"]

