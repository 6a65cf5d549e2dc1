"""Shared fixtures: the command line run in-process, and the logs and maps several tests read.

Under CI, property tests draw the same examples on every run: a red CI is a bug in
the change, never a new random draw (run them locally to explore new examples).

Simulating and mapping take seconds, so the logs and maps that tests only read are
made once per session (once per pytest-xdist worker) here.  They are shared: a test
that changes one copies it first (``shutil.copytree`` into its ``tmp_path``), and
each fixture checks at teardown that no test changed it.
"""

import contextlib
import hashlib
import io
import json
import os
import signal
import socket
import subprocess
import sys
import warnings
from pathlib import Path
from typing import NamedTuple

import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


def pytest_collection_modifyitems(items):
    """Modules holding a test marked ``slow`` first, each module's tests kept together
    and in order: with one module per worker (``--dist loadscope``), a long module
    started last would leave the other worker idle while it finishes."""

    def module(item):
        return item.nodeid.split("::", 1)[0]

    slow = {module(item) for item in items if item.get_closest_marker("slow")}
    rank = {name: (name not in slow, i) for i, name in enumerate(dict.fromkeys(map(module, items)))}
    items.sort(key=lambda item: rank[module(item)])


TWO_ROOMS_GEOJSON = {"type": "MultiPolygon", "coordinates": [
    [[[0, 0], [500, 0], [500, 500], [0, 500], [0, 0]]],
    [[[600, 0], [1100, 0], [1100, 500], [600, 500], [600, 0]],
     [[775, 175], [925, 175], [925, 325], [775, 325], [775, 175]]]]}
"""Two 500 mm rooms 100 mm apart, the second with a 150 mm square hole: beta = (2, 1)."""


def run_cli(*args, cwd=None, env=None) -> subprocess.CompletedProcess:
    """``swarmtopo ARGS`` run in this process: its exit code, stdout and stderr.

    What ``subprocess.run(["swarmtopo", *ARGS], cwd=cwd, env=env, capture_output=True,
    text=True)`` gives, without a new interpreter's start-up (a second or more per run):
    ``swarmtopo.cli.main`` with ``sys.argv`` set, stdout and stderr captured, the
    program named ``swarmtopo`` as the installed script names it, and the warnings
    filters of a fresh interpreter, a warning printed on stderr as there.  Not
    thread-safe (it redirects ``sys.stdout``).  What only a process shows -- signals,
    the imports of start-up, output written by C code straight to the file descriptors,
    the exit code of a crash -- needs ``python -m swarmtopo`` in a subprocess.
    """
    from swarmtopo import cli as command_line

    argv = ["swarmtopo", *map(str, args)]
    stdout, stderr = io.StringIO(), io.StringIO()
    app, saved_argv, saved_env = command_line.app, sys.argv, dict(os.environ)

    def show(message, category, filename, lineno, file=None, line=None):
        stderr.write(warnings.formatwarning(message, category, filename, lineno, line))

    code = 0
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr), \
            contextlib.chdir(cwd or os.getcwd()), warnings.catch_warnings():
        warnings.resetwarnings()  # a fresh interpreter's filters: each warning once, on stderr
        warnings.simplefilter("default")
        for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning):
            warnings.simplefilter("ignore", category)
        warnings.showwarning = show
        if env is not None:
            os.environ.clear()
            os.environ.update(env)
        sys.argv = argv
        command_line.app = lambda **kwargs: app(prog_name="swarmtopo", **kwargs)
        try:
            command_line.main()
        except SystemExit as exc:
            if exc.code is None or isinstance(exc.code, int):
                code = exc.code or 0
            else:  # sys.exit(message): printed, exit status 1
                print(exc.code, file=sys.stderr)
                code = 1
        finally:
            command_line.app, sys.argv = app, saved_argv
            if env is not None:
                os.environ.clear()
                os.environ.update(saved_env)
    return subprocess.CompletedProcess(argv, code, stdout.getvalue(), stderr.getvalue())


@pytest.fixture(scope="session")
def cli():
    """:func:`run_cli`: ``cli("map", folder, "--out", out)`` -> CompletedProcess."""
    return run_cli


def folder_digest(folder: Path) -> dict[str, str]:
    """SHA-256 of every file under ``folder``, by relative path."""
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@contextlib.contextmanager
def unchanged(folder: Path):
    """Yield; then fail if any file under ``folder`` was added, removed or changed."""
    before = folder_digest(folder)
    yield
    after = folder_digest(folder)
    changed = sorted(name for name in before.keys() | after.keys() if before.get(name) != after.get(name))
    assert not changed, f"a test changed the shared {folder}: {changed}; copy it into tmp_path first"


class CliLog(NamedTuple):
    """A log folder ``swarmtopo simulate`` wrote, and that run (its stdout says what it wrote)."""

    folder: Path
    proc: subprocess.CompletedProcess


class CliMap(NamedTuple):
    """The output folder of ``swarmtopo map``, its map.json read, and the run."""

    folder: Path
    doc: dict
    proc: subprocess.CompletedProcess


def simulated_log(folder: Path, *args) -> CliLog:
    proc = run_cli("simulate", *args, "--out", folder)
    assert proc.returncode == 0, proc.stderr
    return CliLog(folder, proc)


def mapped(log: Path, out: Path, *args) -> CliMap:
    proc = run_cli("map", log, "--out", out, *args)
    assert proc.returncode == 0, proc.stderr
    return CliMap(out, json.loads((out / "map.json").read_text(encoding="utf-8")), proc)


@pytest.fixture(scope="session")
def one_hole_log(tmp_path_factory):
    """``swarmtopo simulate --holes 1 --agents 200 --duration 20 --seed 4 --truth
    --trajectories 1``: a random one-hole arena's log folder in csv, with arena.geojson,
    status, truth and trajectories (``folder, proc = one_hole_log``)."""
    run = simulated_log(tmp_path_factory.mktemp("one-hole") / "log", "--holes", 1, "--agents", 200,
                        "--duration", 20, "--seed", 4, "--truth", "--trajectories", 1.0)
    with unchanged(run.folder):
        yield run


@pytest.fixture(scope="session")
def one_hole_map(one_hole_log, tmp_path_factory):
    """``swarmtopo map`` of :func:`one_hole_log` with every option at its default
    (map.json, figures, report.html), run without ``--quiet``."""
    run = mapped(one_hole_log.folder, tmp_path_factory.mktemp("one-hole-map") / "map")
    with unchanged(run.folder):
        yield run


@pytest.fixture(scope="session")
def two_rooms_log(tmp_path_factory):
    """``swarmtopo simulate --arena`` :data:`TWO_ROOMS_GEOJSON` ``--agents 300 --duration
    40 --seed 3`` (the accuracy benchmark's two-rooms budget): a log folder in csv."""
    root = tmp_path_factory.mktemp("two-rooms")
    (root / "rooms.geojson").write_text(json.dumps(TWO_ROOMS_GEOJSON), encoding="utf-8")
    run = simulated_log(root / "log", "--arena", root / "rooms.geojson", "--agents", 300, "--duration", 40,
                        "--seed", 3)
    with unchanged(run.folder):
        yield run


@pytest.fixture(scope="session")
def two_rooms_map(two_rooms_log, tmp_path_factory):
    """``swarmtopo map -q`` of :func:`two_rooms_log`, every option at its default."""
    run = mapped(two_rooms_log.folder, tmp_path_factory.mktemp("two-rooms-map") / "map", "--quiet")
    with unchanged(run.folder):
        yield run


def _log_digest(log) -> str:
    arrays = (log.t, log.a, log.b, log.status_t, log.status_agent, log.status_state, log.static_agent)
    digest = hashlib.sha256(json.dumps(log.meta, sort_keys=True, default=str).encode())
    for array in arrays:
        digest.update(array.tobytes())
    return digest.hexdigest()


@pytest.fixture(scope="session")
def demo_run():
    """The demo's scenario simulated: the one-hole ``default_arena()``, 200 agents, 30 s,
    seed 0, with truth and trajectories every second (a ``Simulation``; read only)."""
    from swarmtopo.arena import default_arena
    from swarmtopo.sim import simulate

    sim = simulate(default_arena(), 200, 30.0, rng=0, truth=True, trajectory_every=1.0)
    before = _log_digest(sim.log)
    yield sim
    assert _log_digest(sim.log) == before, "a test changed the shared demo_run log"


@pytest.fixture(scope="session")
def demo_map(demo_run):
    """``map_encounters(demo_run.log, MapConfig(seed=0))``: the demo's map (read only)."""
    from swarmtopo.pipeline import MapConfig, map_encounters

    return map_encounters(demo_run.log, MapConfig(seed=0))


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def stop_group(proc: subprocess.Popen) -> None:
    """SIGTERM the process group we started, then SIGKILL it if it lingers."""
    for sig, wait in ((signal.SIGTERM, 15), (signal.SIGKILL, 15)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue


TESTS = Path(__file__).resolve().parent


def result_columns(row):
    """A store row's result columns (run columns aside) as plain JSON data: its diagrams
    decoded, Diagram objects as JSON; equal for a row from ``run_job`` and its stored copy."""
    from swarmtopo.experiments.store import RUN_COLUMNS, decode_regions
    from swarmtopo.topology.persistence import Diagram

    out = {k: v for k, v in row.items() if k not in RUN_COLUMNS}
    if isinstance(out.get("diagrams"), bytes):
        out["diagrams"] = decode_regions(out["diagrams"])
    return json.loads(json.dumps(out, default=lambda x: x.to_json() if isinstance(x, Diagram) else str(x)))


def pythonpath_with_tests() -> dict[str, str]:
    """This process's environment with this folder first on PYTHONPATH (for the processes
    it starts: Dask schedulers and workers, and the job processes of workers)."""
    return {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(TESTS), os.environ.get("PYTHONPATH")]))}


@contextlib.contextmanager
def local_dask(logs: Path, workers: int = 2, nanny: bool = True):
    """A real `dask scheduler` and ``workers`` `dask worker` processes of one thread on
    127.0.0.1: yields (address, scheduler process, worker processes).  The workers can import this folder's modules
    (tests/sweep_faults.py: jobs that crash, raise or hang), and so can the scheduler, which
    unpickles the tasks it is sent."""
    from distributed import Client

    address = f"tcp://127.0.0.1:{free_port()}"
    env = pythonpath_with_tests()
    procs = []
    try:
        procs.append(subprocess.Popen(
            ["dask", "scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1], "--no-dashboard"],
            stdout=subprocess.DEVNULL, stderr=open(logs / "scheduler.log", "w"), start_new_session=True, env=env))
        for i in range(workers):
            procs.append(subprocess.Popen(
                ["dask", "worker", address, "--nthreads", "1", "--host", "127.0.0.1", "--no-dashboard",
                 "--local-directory", str(logs), *([] if nanny else ["--no-nanny"])],
                stdout=subprocess.DEVNULL, stderr=open(logs / f"worker{i}.log", "w"), start_new_session=True,
                env=env))
        with Client(address, timeout=60) as client:
            client.wait_for_workers(workers, timeout=120)
        yield address, procs[0], procs[1:]
    finally:
        for proc in reversed(procs):
            stop_group(proc)


@pytest.fixture(scope="module")
def dask_cluster(tmp_path_factory):
    """A real `dask scheduler` and a `dask worker` with 2 processes on 127.0.0.1 (:func:`local_dask`)."""
    with local_dask(tmp_path_factory.mktemp("dask")) as (address, _, _):
        yield address
