"""Sweeps on Dask: run every job of a grid as a task, one row per job in a DuckDB store.

``run_job(job) -> row`` builds the job's arena, simulates the swarm and maps its
encounter log, all seeded from the job alone (:meth:`~.grid.Job.stream_seeds`), so a
row depends on nothing but its job: not on the worker, the number of workers, the
order of completion or the other jobs.  ``run_sweep(jobs, store)`` skips jobs whose
key is in the store, submits the rest to a Dask cluster (a local one by default, or
an existing scheduler) and writes each row from the client as soon as its job
finishes, one transaction per row: killing the sweep at any moment loses at most the
jobs still running, and running it again finishes exactly those.

A job that fails with a :class:`~swarmtopo.errors.SwarmtopoError` (too little data to
map, holes that do not fit) is a result: its row has the message in ``error`` and
NULL estimates, and it is not run again.  Any other exception is a bug: the sweep
stops and re-raises it (rows already written stay).
"""

from __future__ import annotations

import logging
import os
import socket
import tempfile
import time
from collections import Counter
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from datetime import datetime, timezone
from functools import lru_cache
from typing import Any, Callable, Iterable

from ..arena import Arena, annulus_arena, default_arena, random_arena, square_arena, two_rooms_arena
from ..readers.base import BettiReader
from ..readers.registry import PRESETS, load_classifier
from ..errors import SwarmtopoError
from ..io import GROUND_TRUTH_META_KEYS, read_arena, read_log, write_log
from ..log import EncounterLog
from ..topology.persistence import snr
from ..pipeline import map_encounters
from ..pipeline.engine import POLL_SECONDS, connected_client, deferred_interrupt
from ..pipeline.result import software_versions
from ..viz.summary import window_json
from ..sim import simulate
from .grid import Job, flat_columns, job_map_config, job_simulation_args
from .store import JOB_COLUMNS, ResultStore

_STAGE_COLUMNS = {"graph": "t_graph", "landmarks": "t_landmarks", "persistence": "t_persistence",
                  "classify": "t_classify"}


def build_arena(arena: dict[str, Any], rng, path: str | None = None) -> Arena:
    """The arena of a canonical ``config["arena"]`` (see :mod:`.grid`).

    Parameters
    ----------
    arena
        The job's arena table: ``generator`` and the keys it uses.
    rng
        Seed of the arena stream (random and two_rooms draw their holes from it).
    path
        Absolute path of the GeoJSON file (``generator = "file"``).
    """
    generator, scale = arena["generator"], arena["scale"]
    if generator == "random":
        return random_arena(arena["holes"], scale=scale, shapes=arena["shapes"], outer=arena["outer"], rng=rng)
    if generator == "two_rooms":
        return two_rooms_arena(scale=scale, n_holes=arena["holes"], shapes=arena["shapes"], rng=rng)
    if generator == "default":
        base = default_arena()
    elif generator == "square":
        base = square_arena()
    elif generator == "annulus":
        base = annulus_arena(arena["r_outer"], arena["r_inner"])
    else:
        base = read_arena(path)
    return base if scale == 1.0 else base.scaled(scale)


def stripped_log(log: EncounterLog) -> EncounterLog:
    """The log as ``swarmtopo map`` reads it from a folder stripped of ground truth.

    Written to a temporary folder without truth, trajectories, arena or
    ``GROUND_TRUTH_META_KEYS`` (as :func:`~swarmtopo.io.logs.strip_ground_truth` leaves a
    folder), and read back with :func:`~swarmtopo.io.logs.read_log`: the map of a sweep sees
    exactly what a user's ``map`` of such a folder would.
    """
    meta = {k: v for k, v in log.meta.items() if k not in GROUND_TRUTH_META_KEYS}
    with tempfile.TemporaryDirectory(prefix="swarmtopo-log-") as folder:
        write_log(replace(log, meta=meta), folder, fmt="parquet")
        return read_log(folder)


CONTACT_TRACE_META_KEYS = ("format", "version", "units", "duration", "agent_count", "agent_ids")
"""What :func:`contact_trace` keeps of ``meta.json``: what a contact trace's own folder says."""


def contact_trace(log: EncounterLog) -> EncounterLog:
    """The log as a real contact trace would give it: encounters only.

    No status changes (so no wall following and no stops), no static agents, and of
    ``meta.json`` only ``CONTACT_TRACE_META_KEYS``: no sensing radius r_d, no speeds, no
    time step, so the hop cost, windows and diffusion time come from the encounters
    themselves, as for a trace read with ``swarmtopo ingest``.
    """
    return EncounterLog(t=log.t, a=log.a, b=log.b, agent_ids=log.agent_ids,
                        meta={k: v for k, v in log.meta.items() if k in CONTACT_TRACE_META_KEYS})


INPUTS = ("log", "contact-trace")
"""What a job's map reads (``config["map"]["input"]``, "log" when absent): the stripped
log folder, or only its encounters (:func:`contact_trace`)."""


def map_input(mapping: dict[str, Any]) -> str:
    """What a job's ``[map]`` table says its map reads (``INPUTS``; "log" when absent)."""
    source = mapping.get("input", "log")
    if source not in INPUTS:
        raise ValueError(f"map input {source!r} is not one of {INPUTS}")
    return source


def job_classifier(mapping: dict[str, Any]) -> str:
    """The classifier a job's map is read with: its ``[map]`` table's, "default" being
    ``map``'s own for what the job reads (:func:`~swarmtopo.readers.registry.shipped_reader_for`:
    ``trace`` for a contact trace; a simulated log always has status rows)."""
    name = mapping["classifier"]
    return "trace" if name == "default" and map_input(mapping) == "contact-trace" else name


def run_job(job: Job) -> dict[str, Any]:
    """Simulate and map one job; its row of the store's ``jobs`` table.

    Streams (:meth:`Job.stream_seeds`): the arena's holes, the simulation, and the
    map's landmark start.  The map uses no picture (``embed_dim = 0``) and the
    classifier named in ``config["map"]["classifier"]`` ("default": the shipped one for the
    log read, as ``map``'s: ``trace`` for a contact trace), reading the stripped log folder or,
    with ``config["map"]["input"] = "contact-trace"`` (``INPUTS``; set by benchmark code,
    not a grid key), only its encounters; ``snr_h1`` is the paper's SNR
    of the union diagram in dimension 1 given the true beta_1.

    Raises
    ------
    Exception
        Anything but a SwarmtopoError (those become the row's ``error``).
    """
    start = time.perf_counter()
    config = job.config
    seeds = job.stream_seeds()
    row: dict[str, Any] = dict.fromkeys(name for name, _ in JOB_COLUMNS)
    row.update(key=job.key, sweep=job.sweep, replicate=job.replicate, salt=job.salt, seed=job.seed,
               config=config, **flat_columns(config))
    row["versions"] = dict(_versions())
    swarm, mapping = config["swarm"], config["map"]
    try:
        arena = build_arena(config["arena"], seeds["arena"], job.file("arena.path"))
        row["true_betti0"], row["true_betti1"] = arena.betti
        t0 = time.perf_counter()
        sim = simulate(arena, **job_simulation_args(swarm), rng=seeds["simulation"])
        row["t_simulate"] = time.perf_counter() - t0
        row["n_events"], row["n_agents"] = sim.log.n_events, sim.log.n_agents
        log = stripped_log(sim.log)
        tmap = map_encounters(contact_trace(log) if map_input(mapping) == "contact-trace" else log,
                              job_map_config(mapping, seeds["map"]),
                              reader=cached_classifier(job_classifier(mapping), job.file("map.classifier")))
    except SwarmtopoError as exc:
        row["error"] = " ".join(str(exc).split())
    else:
        ratio = snr(tmap.diagram, 1, row["true_betti1"])
        row.update(
            est_betti0=tmap.betti[0], est_betti1=tmap.betti.get(1),
            confidence_betti0=tmap.confidence.get(0), confidence_betti1=tmap.confidence.get(1),
            snr_h1=ratio.ratio, noise_power_h1=ratio.noise_power,
            lengths_h1=[float(x) for x in tmap.diagram.lengths(1)],
            diagrams=[{"events": r.n_events, "agents": r.n_agents, "landmarks": len(r.landmarks.nodes),
                       "diagram": r.diagram.to_json(), "window": r.window,
                       "windows": [{**window_json(w), "diagram": w.diagram.to_json()} for w in r.windows]}
                      for r in tmap.regions],
            n_regions=len(tmap.regions),
            **{column: tmap.timings[stage] for stage, column in _STAGE_COLUMNS.items()},
        )
        row["n_landmarks"] = sum(region["landmarks"] for region in row["diagrams"])
        row["versions"] = {**row["versions"], "classifier": tmap.classifier["classifier"],
                           "theta": tmap.classifier["theta"]}
    row["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    row["finished_at"] = datetime.now(timezone.utc).replace(tzinfo=None)
    row["t_total"] = time.perf_counter() - start
    return row


@dataclass(frozen=True)
class SweepSummary:
    """What ``run_sweep`` did.

    Attributes
    ----------
    total
        Distinct jobs asked for.
    skipped
        Jobs already in the store (not run again).
    run
        Jobs run and written now.
    failed
        Of those, rows with an ``error`` (too little data, ...).
    seconds
        Wall time of running them (cluster start included).
    workers
        Dask workers at the start (0 when nothing had to run).
    errors
        Error message -> number of jobs run now that failed with it.
    """

    total: int
    skipped: int
    run: int
    failed: int
    seconds: float
    workers: int
    errors: dict[str, int] = field(default_factory=dict)

    @property
    def jobs_per_minute(self) -> float:
        """Jobs run per minute of wall time."""
        return 60.0 * self.run / self.seconds if self.seconds > 0 else 0.0


def run_sweep(
    jobs: Iterable[Job],
    store_path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int, int, int], None] | None = None,
) -> SweepSummary:
    """Run the jobs not yet in the store on Dask; write one row per job as it finishes.

    Parameters
    ----------
    jobs
        The jobs (duplicates by key run once); each is recorded as part of its sweep.
    store_path
        The DuckDB result store (created if missing).
    scheduler
        Address of an existing Dask scheduler (``tcp://host:port``).  None: start a
        local cluster of processes with one thread each.
    workers
        Processes of the local cluster (default: this machine's cores, at most one
        per job to run).  Not allowed with ``scheduler``.
    progress
        Called as ``progress(done, total, failed)`` once the cluster is up and after
        each row is written (``total`` = jobs to run now).

    Raises
    ------
    SwarmtopoError
        On a store that cannot be opened, an unreachable scheduler or one without
        workers.  KeyboardInterrupt and a job's non-user exception propagate after
        the running tasks are cancelled and the cluster is shut down.
    """
    if scheduler is not None and workers is not None:
        raise SwarmtopoError(f"--workers sets the size of the local cluster; the scheduler at {scheduler} "
                             "has its own workers (drop --workers)")
    unique: dict[str, Job] = {}
    members: dict[str, list[str]] = {}  # sweep -> keys: a job shared by sweeps belongs to each
    for job in jobs:
        unique.setdefault(job.key, job)
        members.setdefault(job.sweep, []).append(job.key)
    with ResultStore(store_path) as store:
        for sweep, keys in members.items():
            store.add_to_sweep(sweep, keys)
        done = store.finished_keys()
        pending = [job for key, job in unique.items() if key not in done]
        if not pending:
            return SweepSummary(total=len(unique), skipped=len(unique), run=0, failed=0, seconds=0.0, workers=0)
        start = time.perf_counter()
        errors: Counter[str] = Counter()
        run = 0
        with _dask_client(scheduler, workers, len(pending)) as (client, n_workers):
            from distributed import as_completed

            say = progress or (lambda done, total, failed: None)
            futures = dict(zip((job.key for job in pending),
                               client.map(run_job, pending, key=[f"swarmtopo-job-{job.key}" for job in pending])))
            say(0, len(pending), 0)
            finished = as_completed(list(futures.values()))
            try:
                with deferred_interrupt() as interrupted:
                    while not finished.is_empty():
                        if interrupted():
                            raise KeyboardInterrupt
                        batch = finished.next_batch(block=False)
                        if not batch:
                            time.sleep(POLL_SECONDS)
                        for future in batch:
                            row = future.result()
                            store.insert(row)
                            futures.pop(row["key"]).release()
                            run += 1
                            if row["error"] is not None:
                                errors[row["error"]] += 1
                            say(run, len(pending), sum(errors.values()))
            finally:
                client.cancel(list(futures.values()))
        return SweepSummary(total=len(unique), skipped=len(unique) - len(pending), run=run,
                            failed=sum(errors.values()), seconds=time.perf_counter() - start,
                            workers=n_workers, errors=dict(errors))


@contextmanager
def _dask_client(scheduler: str | None, workers: int | None, n_jobs: int):
    """(Client, number of workers) on the given scheduler or a new local cluster; closes both."""
    from distributed import Client, LocalCluster

    if scheduler is not None:
        with connected_client(scheduler) as client:  # workers started by hand: one numba thread each too
            yield client, len(client.nthreads())
        return
    n_workers = min(workers or os.cpu_count() or 1, n_jobs)
    # One core per worker: numba's parallel kernels would otherwise start one thread per
    # core in every worker (BLAS / OpenMP threads are already 1 under Dask's nanny).  The
    # scheduler's HTTP server takes any free port (8787 may be another cluster's).  The
    # workers preload this module (its imports take seconds) and swarmtopo._dask_plugin
    # (its dask_setup: they ignore SIGINT, which the client alone handles).
    # Only CRITICAL logs: a job's own exception reaches the client through its future,
    # and after Ctrl-C a worker may log an ERROR with a traceback ("failed to communicate
    # with scheduler during heartbeat") while the cluster it belongs to shuts down.
    with LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.CRITICAL, env={"NUMBA_NUM_THREADS": "1"},
                      preload=["swarmtopo._dask_plugin", __name__]) as cluster:
        with Client(cluster) as client:
            yield client, n_workers


@lru_cache(maxsize=8)
def cached_classifier(name: str, path: str | None = None) -> BettiReader:
    """The classifier of a job: the preset ``name``, else the file at ``path``; loaded
    once per process (per worker, or per store read by the tuning code)."""
    return load_classifier(name if name in PRESETS else path)


@lru_cache(maxsize=1)
def _versions() -> dict[str, str]:
    import numba
    import shapely

    return {**software_versions(), "numba": numba.__version__, "shapely": shapely.__version__}
