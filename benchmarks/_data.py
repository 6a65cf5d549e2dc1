"""Benchmark inputs made with the real simulator, cached on disk as log folders.

``simulated_log(n_events)`` simulates the paper's swarm (motion defaults, r_d = 30 mm,
dt = 0.1 s) in ``random_arena(holes)`` scaled by sqrt(agents / 200), so that the
density stays the paper's 200 agents per 500 x 500 mm square whatever the swarm size.
A fraction of the agents is made static at t = 0 (the paper's hybrid network, 5-20 %).

Size: ``agents = max(200, 2 sqrt(n_events))`` rounded to tens (200 agents for 10^4
events, 630 for 10^5, 2,000 for 10^6), and the simulation runs long enough for the
target at the measured event rate (0.39 events per agent-second at 200 agents,
0.44 at 2,000: walls cost encounters, and small arenas have more wall per area), plus
a margin.  The log is then cut at the time of its ``n_events``-th event (events and
status changes after it dropped), so it holds the target number of events (a few more
when several events share that time step).  A 10^6-event log takes 13-18 s to
simulate; it is written once with ``swarmtopo.io.logs.write_log(fmt="parquet")`` under
``$SWARMTOPO_BENCH_CACHE`` (default ``~/.cache/swarmtopo-bench``), in a folder named
after every parameter and a hash of the simulator's source (``swarmtopo/sim/*.py``
and ``arena.py``: a changed model gives a new log), and read back afterwards.

``landmark_matrices(sizes, seed)``: the maxmin landmark distance matrices the pipeline
gives persistence, on the hybrid metric of a simulated two-hole log.
"""

from __future__ import annotations

import hashlib
import math
import os
import shutil
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

import swarmtopo
from swarmtopo.arena import random_arena
from swarmtopo.metric.graph import build_graph
from swarmtopo.io.logs import read_log, write_log
from swarmtopo.metric.landmarks import maxmin
from swarmtopo.log import EncounterLog
from swarmtopo.sim import simulate

MIN_EVENT_RATE = 0.38
"""Events per agent-second, a lower bound of the rates measured at the paper's density
(0.39 at 200 agents, 0.44 at 2,000, 10 % static); the simulated duration uses it."""
STATIC_FRACTION = 0.1
ARENA_SEED = 1


def cache_dir() -> Path:
    """Where simulated logs are kept: $SWARMTOPO_BENCH_CACHE or ~/.cache/swarmtopo-bench."""
    return Path(os.environ.get("SWARMTOPO_BENCH_CACHE", Path.home() / ".cache" / "swarmtopo-bench"))


def simulator_fingerprint() -> str:
    """Short hash of the simulator's source files (the model that makes the logs)."""
    package = Path(swarmtopo.__file__).parent
    digest = hashlib.sha256()
    for path in sorted(package.joinpath("sim").glob("*.py")) + [package / "arena.py"]:
        digest.update(path.read_bytes())
    return digest.hexdigest()[:10]


def agents_for(n_events: int) -> int:
    """Swarm size for a log of about ``n_events`` events: 2 sqrt(n_events), at least 200."""
    return max(200, int(round(2 * math.sqrt(n_events), -1)))


def simulated_log_dir(n_events: int, *, holes: int = 2, seed: int = 0,
                      static_fraction: float = STATIC_FRACTION, agents: int | None = None) -> Path:
    """The cached log folder of :func:`simulated_log` (simulated and written on first use)."""
    n_agents = agents or agents_for(n_events)
    folder = cache_dir() / (f"sim{simulator_fingerprint()}-events{n_events}-holes{holes}-agents{n_agents}"
                            f"-static{static_fraction:g}-seed{seed}")
    if (folder / "meta.json").is_file():
        return folder
    arena = random_arena(holes, rng=ARENA_SEED).scaled(math.sqrt(n_agents / 200))
    duration = math.ceil(1.1 * n_events / (MIN_EVENT_RATE * n_agents))
    log = simulate(arena, n_agents, duration, static_fraction=static_fraction, rng=seed).log
    log = _first_events(log, n_events)
    folder.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=folder.name + ".", dir=folder.parent))
    write_log(log, staging, fmt="parquet", arena=arena)
    try:
        staging.rename(folder)  # atomic: a folder with meta.json is always complete
    except OSError:  # another process wrote it first
        shutil.rmtree(staging)
    return folder


def simulated_log(n_events: int, *, holes: int = 2, seed: int = 0,
                  static_fraction: float = STATIC_FRACTION, agents: int | None = None) -> EncounterLog:
    """A simulated encounter log of about ``n_events`` events at the paper's density.

    Parameters
    ----------
    n_events
        Target number of events (the log holds at least that many, and more only by
        the events sharing the last time step).
    holes
        Holes of the random square arena (true beta_1).
    seed
        Seed of the simulation (the arena is always ``random_arena(holes, rng=1)``).
    static_fraction
        Fraction of agents made static at t = 0 (hybrid network).
    agents
        Swarm size (default :func:`agents_for`); the arena is scaled to keep the density.
    """
    return read_log(simulated_log_dir(n_events, holes=holes, seed=seed, static_fraction=static_fraction,
                                      agents=agents))


def random_pair_log(n_events: int, *, agents: int = 2000, duration: float = 1000.0, seed: int = 0) -> EncounterLog:
    """A log with no space in it: ``n_events`` encounters of uniformly random pairs of
    ``agents`` agents at uniformly random times in [0, ``duration``] s, no status and no
    meta (a contact trace).  The worst case of the encounter metric: every window's
    graph is an expander, so its searches reach every node in a few hops."""
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, duration, n_events))
    a = rng.integers(agents, size=n_events)
    b = (a + rng.integers(1, agents, size=n_events)) % agents  # never a itself
    return EncounterLog(t=t, a=np.minimum(a, b), b=np.maximum(a, b), agent_ids=np.arange(agents))


def landmark_matrices(sizes, seed: int = 0) -> dict[int, np.ndarray]:
    """Landmark distance matrices of the pipeline: maxmin on the hybrid metric, two holes.

    One simulated two-hole log of 10^5 events (630 agents, 10 % static; about 50 events
    per landmark at the largest size), its hybrid encounter graph restricted to the
    largest component, and maxmin with ``max(sizes)`` landmarks.  The first L maxmin
    landmarks are the maxmin set of size L from the same start, so each size is a
    prefix of the largest matrix.  ``seed`` seeds the simulation and the first landmark.
    The largest matrix is cached beside the log (2,000 landmarks take about a minute).
    """
    folder = simulated_log_dir(10**5, holes=2, seed=seed)
    cached = folder / f"landmarks-maxmin-hybrid-{max(sizes)}-seed{seed}.npy"
    if cached.is_file():
        distances = np.load(cached)
    else:
        graph = build_graph(read_log(folder), "hybrid")
        _, labels = graph.components()
        largest = np.argmax(np.bincount(labels, weights=graph.multiplicity))
        distances = maxmin(graph.subgraph(np.flatnonzero(labels == largest)), max(sizes), rng=seed).distances
        staging = cached.with_suffix(f".{os.getpid()}.npy")
        np.save(staging, distances)
        staging.replace(cached)
    return {size: distances[:size, :size].copy() for size in sizes}


def _first_events(log: EncounterLog, n_events: int) -> EncounterLog:
    """The log up to the time of its n-th event (status changes after it dropped)."""
    if log.n_events < n_events:
        raise RuntimeError(f"the simulation gave {log.n_events} events, fewer than the {n_events} "
                           f"wanted: lower MIN_EVENT_RATE ({MIN_EVENT_RATE})")
    cut = float(log.t[n_events - 1])
    keep, keep_status = log.t <= cut, log.status_t <= cut
    return replace(log, t=log.t[keep], a=log.a[keep], b=log.b[keep],
                   status_t=log.status_t[keep_status], status_agent=log.status_agent[keep_status],
                   status_state=log.status_state[keep_status], meta={**log.meta, "duration": cut})
