"""Sweeps on Dask: run every job of a grid as a task, one row per job in a DuckDB store.

``run_job(job) -> row`` builds the job's arena, simulates the swarm and maps its
encounter log, all seeded from the job alone (:meth:`~.grid.Job.stream_seeds`), so a
row depends on nothing but its job: not on the worker, the number of workers, the
order of completion or the other jobs.  ``run_sweep(jobs, store)`` skips jobs whose
key is in the store, submits the rest to a Dask cluster (a local one by default, or
an existing scheduler) a window at a time, and writes the rows from the client in
batches (one transaction each, at least every ``FLUSH_SECONDS``): killing the sweep at
any moment loses at most the jobs running and the last second's rows, and running it
again finishes exactly those.

A bad job is a row, not an abort.  Each worker runs its jobs in a child process
(:func:`run_isolated`, :mod:`.isolation`): a job that raises is stored with status
"error" (a SwarmtopoError such as too little data is the method's own answer; anything
else is a bug, named by its type), one whose process dies "crashed", one that runs past
the job timeout "timeout"; the sweep goes on, and a rerun skips failed rows unless
asked to retry them.  A lost scheduler stops the sweep with :class:`SchedulerLost`
after the finished rows are written.
"""

from __future__ import annotations

import math
import os
import socket
import tempfile
import statistics
import threading
import time
from collections import Counter, deque
from contextlib import ExitStack
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Any, Callable, Iterable

from ..arena import Arena, annulus_arena, default_arena, hall_arena, random_arena, square_arena, two_rooms_arena
from ..beacon import long_axis_track
from ..changing import ChangingArena, betti_timeline_of, changing_arena
from ..readers.base import BettiReader
from ..readers.registry import PRESETS, load_classifier
from ..errors import SwarmtopoError
from ..io import GROUND_TRUTH_META_KEYS, read_arena, read_log, write_log
from ..log import EncounterLog
from ..topology.persistence import snr
from ..pipeline import MapConfig, map_encounters
from ..pipeline.engine import POLL_SECONDS, connected_client, deferred_interrupt, local_client
from ..pipeline.result import software_versions
from ..viz.summary import exploration_json, motion_json, sensing_json, timeline_json, window_json
from ..sim import simulate
from ..sim.faults import Faults, perturb
from .grid import (DEFAULT_JOB_TIMEOUT, KEEP_LEVELS, Job, canonical_json, case_streams, flat_columns, job_map_config,
                   job_simulation_args, suite_case_seed)
from .isolation import JobProcess, one_line
from .store import JOB_COLUMNS, LOCK_WAIT, FailureGroup, ResultStore, encode_regions, group_failures, utcnow

_STAGE_COLUMNS = {"graph": "t_graph", "landmarks": "t_landmarks", "persistence": "t_persistence",
                  "classify": "t_classify"}


def build_arena(arena: dict[str, Any], rng, path: str | None = None) -> Arena | ChangingArena:
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
    generator, scale = arena["generator"], arena.get("scale", 1.0)
    if generator == "changing":
        return changing_arena(arena["change"], arena["holes"], arena.get("change_time", math.inf), shapes=arena["shapes"],
                              outer=arena["outer"], scale=scale, rng=rng)
    if generator == "hall":
        return hall_arena(arena["holes"], length=arena["length"], width=arena["width"], shapes=arena["shapes"],
                          rng=rng)
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


def first_placeable(draw: Callable[[int], tuple[dict[str, Any], int]], attempts: int, what: str
                    ) -> tuple[dict[str, Any], int]:
    """The first of ``draw(attempt)`` = (config with an ``arena`` table or an arena table, seed)
    whose arena can be built (some draws cannot hold their holes: three walls in a narrow
    rectangle), attempt 0, 1, ... up to ``attempts``."""
    for attempt in range(attempts):
        config, seed = draw(attempt)
        try:
            build_arena(config.get("arena", config), case_streams(seed)["arena"])
        except SwarmtopoError:
            continue
        return config, seed
    raise SwarmtopoError(f"no placeable arena for {what} in {attempts} attempts")


SUITE_MAP = {"subsample": "maxmin", "landmarks": "auto", "max_landmarks": 400, "maxdim": 1}
"""The ``[map]`` keys every benchmark suite's jobs share (the pipeline adds the rest)."""


def suite_case(suite: str, cell, split: str, index: int, case_config: Callable[..., dict[str, Any]],
               attempts: int) -> tuple[dict[str, Any], int]:
    """(config tables, case seed) of case ``index`` of ``cell`` of a frozen benchmark
    ``suite``: the first attempt whose arena can be built of ``case_config(cell, split,
    index, attempt)``, seeded by :func:`~.grid.suite_case_seed` (suite, cell name, split,
    index, attempt)."""
    return first_placeable(lambda attempt: (case_config(cell, split, index, attempt),
                                            suite_case_seed(suite, cell.name, split, index, attempt)),
                           attempts, f"{suite}: {cell.name} case {index}")


def suite_jobs(suite: str, sweep: str, split: str, per_cell: int, cells, case, pipeline: dict[str, Any]) -> list[Job]:
    """The jobs of ``per_cell`` cases of every cell of a benchmark suite's ``split``, each
    ``case(cell, split, index)`` -> (config tables, seed) mapped by ``pipeline``; jobs of
    sweep ``{sweep}-{split}``, salted by suite, split and cell."""
    out = []
    for cell in cells:
        for index in range(per_cell):
            config, seed = case(cell, split, index)
            config["map"] = {**SUITE_MAP, **pipeline}
            out.append(Job(sweep=f"{sweep}-{split}", config_json=canonical_json(config), replicate=index,
                           salt=f"{suite}/{split}/{cell.name}", case_seed=seed))
    return out


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


def run_job(job: Job, keep: str = "map") -> dict[str, Any]:
    """Simulate and map one job; its row of the store's ``jobs`` table.

    Streams (:meth:`Job.stream_seeds`): the arena's holes, the simulation, the map's
    landmark start and the faults (a ``[faults]`` table: the simulated log goes through
    :func:`~swarmtopo.sim.faults.perturb` before it is mapped).  The map uses no picture (``embed_dim = 0``) and the
    classifier named in ``config["map"]["classifier"]`` ("default": the shipped one for the
    log read, as ``map``'s: ``trace`` for a contact trace), reading the stripped log folder or,
    with ``config["map"]["input"] = "contact-trace"`` (``INPUTS``; set by benchmark code,
    not a grid key), only its encounters; ``snr_h1`` is the paper's SNR
    of the union diagram in dimension 1 given the true beta_1.  ``keep`` (``KEEP_LEVELS``)
    says which persistence diagrams the row's ``diagrams`` holds.

    A SwarmtopoError (too little data, holes that do not fit) is the row's ``error``
    (status "error"); any other exception propagates (:func:`run_isolated` stores it).
    """
    start = time.perf_counter()
    config = job.config
    seeds = job.stream_seeds()
    row = _identity_row(job)
    swarm, mapping = config["swarm"], config["map"]
    try:
        arena = build_arena(config["arena"], seeds["arena"], job.file("arena.path"))
        row["true_betti0"], row["true_betti1"] = arena.betti
        t0 = time.perf_counter()
        leader = {}
        if swarm.get("leash"):
            leader = {"leash": swarm["leash"],
                      "beacon": long_axis_track(arena.bounds, swarm["leash"], swarm["leader_speed"])}
        sim = simulate(arena, **job_simulation_args(swarm), **leader, rng=seeds["simulation"])
        log, shift = sim.log, 0.0
        if "faults" in config:
            log, record = perturb(sim.log, Faults(**config["faults"]), seeds["faults"])
            shift = record["shift"]  # every time of the perturbed log moved by it
        row["t_simulate"] = time.perf_counter() - t0
        row["n_events"], row["n_agents"] = log.n_events, log.n_agents
        true_timeline = [{**segment, "from": segment["from"] + shift, "until": segment["until"] + shift}
                         for segment in betti_timeline_of(arena, sim.log.meta["duration"])]
        log = stripped_log(log)
        tmap = map_encounters(contact_trace(log) if map_input(mapping) == "contact-trace" else log,
                              job_map_config(mapping, seeds["map"]),
                              reader=cached_classifier(job_classifier(mapping), job.file("map.classifier")))
    except SwarmtopoError as exc:
        row.update(status="error", error=" ".join(str(exc).split()))
    else:
        ratio = snr(tmap.diagram, 1, row["true_betti1"])
        regions = [{"events": r.n_events, "agents": r.n_agents, "landmarks": len(r.landmarks.nodes),
                    "window": r.window,
                    "windows": [{**window_json(w), **({"diagram": w.diagram} if keep == "windows" else {})}
                                for w in r.windows],
                    **({"diagram": r.diagram} if keep != "none" else {})}
                   for r in tmap.regions]
        row.update(
            status="ok",
            est_betti0=tmap.betti[0], est_betti1=tmap.betti.get(1),
            confidence_betti0=tmap.confidence.get(0), confidence_betti1=tmap.confidence.get(1),
            snr_h1=ratio.ratio, noise_power_h1=ratio.noise_power,
            lengths_h1=[float(x) for x in tmap.diagram.lengths(1)],
            diagrams=encode_regions(regions), diagrams_kept=keep,
            timeline=timeline_record(tmap.timeline, true_timeline, keep),
            exploration=exploration_record(tmap.exploration, arena, keep) if tmap.exploration else None,
            motion_estimate=motion_json(tmap.motion), sensing=sensing_json(tmap.sensing),
            n_regions=len(tmap.regions), n_landmarks=sum(region["landmarks"] for region in regions),
            **{column: tmap.timings[stage] for stage, column in _STAGE_COLUMNS.items()},
        )
        row["versions"] = {**row["versions"], "classifier": tmap.classifier["classifier"],
                           "theta": tmap.classifier["theta"]}
    row["finished_at"] = utcnow()
    row["t_total"] = time.perf_counter() - start
    return row


def timeline_record(timeline, truth: list[dict[str, Any]], keep: str) -> dict[str, Any]:
    """A row's ``timeline`` column: the true Betti timeline, the map's change points and
    segments, and (``keep = "windows"``) each timeline window's t0, t1, counts and
    confidences (what re-segmenting with another penalty needs)."""
    found = timeline_json(timeline)
    record = {"truth": truth, "changes": found["changes"], "segments": found["segments"],
              "length": found["length"], "step": found["step"]}
    if keep == "windows":
        record["windows"] = [{k: w[k] for k in ("t0", "t1", "betti", "confidence")} for w in found["windows"]]
    return record


def exploration_record(exploration, arena, keep: str) -> dict[str, Any]:
    """A row's ``exploration`` column: the global map (:func:`~swarmtopo.viz.summary.exploration_json`;
    its local maps only at ``keep = "windows"``) and the true holes' centroids (mm; a changing
    arena's at t = 0)."""
    found = exploration_json(exploration)
    if keep != "windows":
        del found["windows"]
    static = arena.at(0.0) if isinstance(arena, ChangingArena) else arena
    return {**found, "true_holes": static.hole_centroids().tolist()}


def failed_row(job: Job, status: str, message: str, seconds: float | None = None) -> dict[str, Any]:
    """The row of a job that did not finish: ``status`` a failure kind (``FAILURES``),
    the one-line ``message``, the truth and estimates NULL."""
    row = _identity_row(job)
    row.update(status=status, error=message, t_total=seconds)
    return row


def _identity_row(job: Job) -> dict[str, Any]:
    """A row with the job's identity and grid columns, the rest NULL (its ``worker`` is set
    by :func:`run_isolated`: NULL in a row the client writes)."""
    row: dict[str, Any] = dict.fromkeys(name for name, _ in JOB_COLUMNS)
    row.update(key=job.key, sweep=job.sweep, replicate=job.replicate, salt=job.salt, seed=job.seed,
               config=job.config, **flat_columns(job.config), versions=dict(_versions()), finished_at=utcnow())
    return row


_PROCESSES = threading.local()


def run_isolated(jobs: list[Job], keep: str, timeout: float | None,
                 runner: Callable[[Job, str], dict] = run_job) -> list[dict[str, Any]]:
    """The Dask task of a few jobs: each ``runner(job, keep)`` in turn in this worker
    thread's child process (:class:`~.isolation.JobProcess`); their rows, a failed row
    for a call that raised ("error"), whose process died ("crashed") or that ran past
    ``timeout`` s ("timeout")."""
    process = getattr(_PROCESSES, "process", None)
    if process is None:
        process = _PROCESSES.process = JobProcess(warm_up)
    rows = []
    for job in jobs:
        start = time.perf_counter()
        try:
            kind, value = process.call(_call_runner, (runner, job, keep), timeout)
        except Exception as exc:  # noqa: BLE001 - the worker could not hand the job over (no memory to fork, ...)
            process.close()
            kind, value = "crashed", f"its worker could not run it ({one_line(exc)})"
        row = value if kind == "ok" else failed_row(job, kind, value, time.perf_counter() - start)
        row["worker"] = f"{socket.gethostname()}:{os.getpid()}"  # the Dask worker, not its job process
        rows.append(row)
    return rows


def _call_runner(args):
    runner, job, keep = args
    return runner(job, keep)


def warm_up() -> None:
    """Load (or compile, on a cold numba cache) the kernels a job uses: map a small
    simulated log once, before any job's timeout runs."""
    log = simulate(square_arena(), 60, 8.0, rng=0).log
    try:
        map_encounters(log, MapConfig(seed=0, embed_dim=0, cycles=False))
    except SwarmtopoError:
        pass


class SchedulerLost(SwarmtopoError):
    """The connection to the Dask scheduler was lost mid-sweep (finished rows are saved)."""

    def __init__(self, address: str, saved: int, remaining: int, reason: str):
        self.address, self.saved, self.remaining = address, saved, remaining
        super().__init__(f"lost the Dask scheduler at {address} ({reason}); {saved} row(s) saved this run, "
                         f"{remaining} job(s) not run")


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
    seconds
        Wall time of running them (cluster start included).
    workers
        Dask workers at the end of the run (0 when nothing had to run).
    failures
        Failed rows of this run grouped by kind and message (:func:`~.store.group_failures`).
    """

    total: int
    skipped: int
    run: int
    seconds: float
    workers: int
    failures: list[FailureGroup] = field(default_factory=list)

    @property
    def failed(self) -> dict[str, int]:
        """Of the jobs run, rows of each failure kind -> count."""
        counts: Counter[str] = Counter()
        for group in self.failures:
            counts[group.status] += group.count
        return dict(counts)

    @property
    def n_failed(self) -> int:
        return sum(group.count for group in self.failures)

    @property
    def jobs_per_minute(self) -> float:
        """Jobs run per minute of wall time."""
        return 60.0 * self.run / self.seconds if self.seconds > 0 else 0.0


FLUSH_SECONDS = 1.0
"""Most seconds a finished row waits in the client before it is written."""
FLUSH_ROWS = 500
"""Rows per write at most (a batch is one transaction)."""
TOUCH_SECONDS = 30.0
"""How often a run notes in the store that it is alive (``swarmtopo status``)."""


def run_suite(suite: str, split: str, per_cell: int, todo: list[Job], store, records, table,
              extra: dict[str, Any], *, scheduler=None, workers=None, progress=None, keep: str = "map"
              ) -> dict[str, Any]:
    """Run (or resume) a benchmark suite's jobs ``todo`` and its summary document: the
    suite, split, cases per cell, ``extra`` (the suite's own settings), the run's seconds,
    jobs and workers, ``table(records(rows))`` and the records (rows sorted by key)."""
    from .store import iter_jobs

    summary = run_sweep(todo, store, scheduler=scheduler, workers=workers, progress=progress, keep=keep)
    recs = records(sorted(iter_jobs(store, keys=[job.key for job in todo]), key=lambda row: row["key"]))
    return {"suite": suite, "split": split, "cases_per_cell": per_cell, **extra, "seconds": summary.seconds,
            "jobs_run": summary.run, "workers": summary.workers, "table": table(recs), "records": recs}


def run_sweep(
    jobs: Iterable[Job],
    store_path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int, int, int], None] | None = None,
    job_timeout: float | None = DEFAULT_JOB_TIMEOUT,
    retry_failed: bool = False,
    keep: str = "map",
    runner: Callable[[Job, str], dict] = run_job,
) -> SweepSummary:
    """Run the jobs not yet in the store on Dask; write their rows in batches as they finish.

    Parameters
    ----------
    jobs
        The jobs (duplicates by key run once); each is recorded as part of its sweep.
    store_path
        The DuckDB result store (created if missing; not created if the scheduler
        cannot be reached).
    scheduler
        Address of an existing Dask scheduler (``tcp://host:port``).  None: start a
        local cluster of processes with one thread each.
    workers
        Processes of the local cluster (default: this machine's cores, at most one
        per job to run).  Not allowed with ``scheduler``.
    progress
        Called as ``progress(done, total, failed)`` before the cluster starts and
        after each finished job (``total`` = jobs to run now).
    job_timeout
        Seconds a job may run (None: no limit); past it, it is killed and stored as a
        "timeout" row.
    retry_failed
        Run again the jobs whose stored row failed (each new row replaces the old);
        otherwise a failed row counts as done.
    keep
        Which diagrams each row keeps (``KEEP_LEVELS``); a stored row that keeps less
        is run again.
    runner
        ``runner(job, keep) -> row``: :func:`run_job`, or a test's stand-in (importable
        by the workers).

    Raises
    ------
    SchedulerLost
        The scheduler went away mid-sweep (finished rows are written first).
    SwarmtopoError
        On a store that cannot be opened, an unreachable scheduler or one without
        workers.  KeyboardInterrupt propagates after the finished rows are written,
        the running tasks cancelled and the cluster shut down.
    """
    if scheduler is not None and workers is not None:
        raise SwarmtopoError(f"--workers sets the size of the local cluster; the scheduler at {scheduler} "
                             "has its own workers (drop --workers)")
    if keep not in KEEP_LEVELS:
        raise SwarmtopoError(f"diagrams to keep must be one of {', '.join(KEEP_LEVELS)}, got {keep!r}")
    if job_timeout is not None and not job_timeout > 0:
        raise SwarmtopoError(f"the job timeout must be a number of seconds > 0, got {job_timeout!r}")
    unique: dict[str, Job] = {}
    members: dict[str, list[str]] = {}  # sweep -> keys: a job shared by sweeps belongs to each
    for job in jobs:
        unique.setdefault(job.key, job)
        members.setdefault(job.sweep, []).append(job.key)
    say = progress or (lambda done, total, failed: None)
    with ExitStack() as stack:
        # an existing scheduler first: one that cannot be reached must not leave a store behind
        client = stack.enter_context(connected_client(scheduler)) if scheduler is not None else None
        store = ResultStore(store_path)
        for sweep, keys in members.items():
            store.add_to_sweep(sweep, keys)
        stored = store.stored()
        pending = [job for key, job in unique.items() if not _finished(stored.get(key), keep, retry_failed)]
        if not pending:
            return SweepSummary(total=len(unique), skipped=len(unique), run=0, seconds=0.0, workers=0)
        start = time.perf_counter()
        say(0, len(pending), 0)
        if client is None:
            client = stack.enter_context(local_client(min(workers or os.cpu_count() or 1, len(pending))))
        batch = _Batches(store, scheduler, client)
        try:
            _run_pending(client, pending, batch, say, keep=keep, timeout=job_timeout, runner=runner,
                         address=scheduler or "the local cluster")
        except BaseException as exc:
            batch.outcome = ("interrupted" if isinstance(exc, KeyboardInterrupt) else
                             "scheduler lost" if isinstance(exc, SchedulerLost) else f"failed: {one_line(exc)}")
            raise
        finally:
            batch.close()
        return SweepSummary(total=len(unique), skipped=len(unique) - len(pending), run=batch.written,
                            seconds=time.perf_counter() - start,
                            workers=batch.workers, failures=group_failures(
                                (status, message, 1) for status, message in batch.failures))


def _finished(stored: tuple[str, str | None] | None, keep: str, retry_failed: bool) -> bool:
    """Whether a job with this stored (status, diagrams_kept) is done."""
    if stored is None:
        return False
    status, kept = stored
    if status != "ok":
        return not retry_failed
    return KEEP_LEVELS.index(kept) >= KEEP_LEVELS.index(keep)


class _Batches:
    """Finished rows on their way to the store: written every ``FLUSH_SECONDS`` (or at
    ``FLUSH_ROWS``), kept in memory and tried again while another process holds the
    file; the run noted alive in the store every ``TOUCH_SECONDS``."""

    def __init__(self, store: ResultStore, scheduler: str | None, client):
        self.store, self.client = store, client
        self.workers = _worker_count(client)
        self.run = store.start_run(scheduler, self.workers)
        self.rows: list[dict[str, Any]] = []
        self.written = 0
        self.failures: list[tuple[str, str]] = []  # (status, error) of each failed row
        self.last = self.touched = time.monotonic()
        self.busy = False  # the last write found the file held by another process
        self.outcome = "finished"

    def add(self, row: dict[str, Any]) -> None:
        self.rows.append(row)
        if row["status"] != "ok":
            self.failures.append((row["status"], row["error"]))
        if len(self.rows) >= FLUSH_ROWS and not self.busy:
            self.flush()

    @property
    def done(self) -> int:
        return self.written + len(self.rows)

    def tick(self) -> None:
        """Write the rows if they have waited FLUSH_SECONDS; note the run alive if due."""
        if self.rows and time.monotonic() - self.last >= FLUSH_SECONDS:
            self.flush()
        if time.monotonic() - self.touched >= TOUCH_SECONDS:
            self.touch()

    def flush(self, wait: float = 0.0) -> None:
        self.last = time.monotonic()
        while self.rows:
            chunk = self.rows[:FLUSH_ROWS]
            self.busy = not self.store.write(chunk, wait=wait)
            if self.busy:
                return  # the rows wait for the next turn
            del self.rows[:FLUSH_ROWS]
            self.written += len(chunk)

    def touch(self, outcome: str | None = None, wait: float = 0.0) -> None:
        self.touched = time.monotonic()
        self.workers = _worker_count(self.client, self.workers)
        self.store.touch_run(self.run, self.workers, outcome, wait=wait)

    def close(self) -> None:
        """Write what is left (waiting up to LOCK_WAIT for the file) and how the run ended;
        rows the file still refuses go to a Parquet file beside it (named in the error)."""
        self.flush(wait=LOCK_WAIT)
        if self.rows:
            aside = self.store.save_aside(self.rows)
            raise SwarmtopoError(f"{self.store.path}: another process has held the store for {LOCK_WAIT:g} s; "
                                 f"{len(self.rows)} finished row(s) are in {aside} instead (a rerun runs those "
                                 "jobs again)")
        self.touch(self.outcome, wait=LOCK_WAIT)


def _run_pending(client, pending: list[Job], batch: _Batches, say, *, keep, timeout, runner, address) -> None:
    """Submit the jobs a window at a time, collect the rows as tasks finish, until all are
    written or something stops the sweep.

    A task runs one job at first, then as many as take about ``TASK_SECONDS`` at the
    median job time seen so far (at most ``MAX_JOBS_PER_TASK``): cheap jobs do not pay
    Dask's per-task cost each.  A task whose workers died (Dask's KilledWorker) is split
    into its jobs, each run as a task of its own; a job whose workers died again is a
    suspect, and suspects run one at a time with nothing else on the cluster, so only a
    job that kills its workers when it runs alone becomes a "crashed" row (a job that
    merely shared a dying worker with the culprit finishes).
    """
    from concurrent.futures import CancelledError

    from dask.base import tokenize
    from distributed import as_completed
    from distributed.scheduler import KilledWorker

    # (job, None) may share a task; (job, 0) runs in a task of its own, its workers having died
    # in a task of several; suspects (their workers died in a task of their own) run alone
    queue: deque[tuple[Job, int | None]] = deque((job, None) for job in pending)
    suspects: deque[Job] = deque()
    window = max(IN_FLIGHT, 4 * sum(client.nthreads().values()))  # tasks in flight at most
    running: dict[str, tuple[Any, list[Job], int | None]] = {}  # task key -> (future, its jobs, deaths)
    seconds: list[float] = []  # the finished jobs' t_total
    finished = as_completed()
    # task keys name the settings too: another sweep on the same cluster may run the same job otherwise
    settings = tokenize(keep, timeout, f"{runner.__module__}.{runner.__qualname__}")

    def submit() -> None:
        if any(deaths == 1 for _, _, deaths in running.values()):
            return  # a suspect runs: nothing beside it
        tasks: list[tuple[list[Job], int | None]] = []
        if suspects:
            if running:
                return  # a suspect waits for the cluster to empty
            tasks.append(([suspects.popleft()], 1))
        else:
            size = _jobs_per_task(seconds)
            while queue and len(running) + len(tasks) < window:
                job, deaths = queue.popleft()
                task = [job]
                while deaths is None and len(task) < size and queue and queue[0][1] is None:
                    task.append(queue.popleft()[0])
                tasks.append((task, deaths))
        if tasks:
            futures = client.map(run_isolated, [task for task, _ in tasks], key=[_task_key(t, settings) for t in tasks],
                                 keep=keep, timeout=timeout, runner=runner)
            running.update((future.key, (future, *task)) for future, task in zip(futures, tasks))
            finished.update(futures)

    submit()
    try:
        with deferred_interrupt() as interrupted:
            while running or suspects or queue:
                if interrupted():
                    raise KeyboardInterrupt
                done = finished.next_batch(block=False)
                if not done:
                    if client.status != "running":
                        raise SchedulerLost(address, batch.done, len(pending) - batch.done, "connection closed")
                    time.sleep(POLL_SECONDS)
                    batch.tick()
                for future in done:
                    _, task, deaths = running.pop(future.key)
                    try:
                        rows = future.result()
                    except KilledWorker as exc:
                        if len(task) > 1:  # which of them? each in a task of its own
                            queue.extendleft((job, 0) for job in reversed(task))
                            continue
                        if deaths != 1:  # a suspect: it will run alone on the cluster
                            suspects.append(task[0])
                            continue
                        rows = [failed_row(task[0], "crashed", "its workers died running it alone on the "
                                           f"cluster ({one_line(exc)})")]
                    except CancelledError:
                        raise SchedulerLost(address, batch.done, len(pending) - batch.done,
                                            "its tasks were cancelled: scheduler-connection-lost") from None
                    except Exception as exc:  # noqa: BLE001 - a task's own failure is its jobs' rows
                        rows = [failed_row(job, "error", one_line(exc)) for job in task]
                    finally:
                        future.release()
                    for row in rows:
                        batch.add(row)
                        if row["t_total"] is not None:
                            seconds.append(row["t_total"])
                    say(batch.done, len(pending), len(batch.failures))
                batch.tick()
                if len(running) < window // 2 or suspects:
                    submit()
    finally:
        if running and client.status == "running":
            client.cancel([future for future, *_ in running.values()])


def _task_key(task: tuple[list[Job], int | None], settings: str) -> str:
    """Dask key of a task: its first job, its size, how often its workers died, the settings."""
    jobs, deaths = task
    return f"swarmtopo-jobs-{jobs[0].key}-{len(jobs)}-{deaths}-{settings}"


IN_FLIGHT = 64
"""Tasks submitted ahead at least (four per worker thread if more): the scheduler holds a
window of the sweep, not all of it, so a 10^5-job sweep costs the client little memory."""
TASK_SECONDS = 0.5
"""Seconds of jobs a task aims at (at the median job time seen so far)."""
MAX_JOBS_PER_TASK = 64


def _jobs_per_task(seconds: list[float]) -> int:
    """Jobs per task: 1 until 8 jobs have finished, then TASK_SECONDS at the median time
    of the last 256."""
    if len(seconds) < 8:
        return 1
    median = statistics.median(seconds[-256:])
    return int(min(MAX_JOBS_PER_TASK, max(1, TASK_SECONDS / max(median, 1e-3))))


def _worker_count(client, default: int = 0) -> int:
    """Workers the scheduler has now (``default`` if it cannot say)."""
    try:
        return len(client.scheduler_info(n_workers=-1)["workers"]) if client.status == "running" else default
    except Exception:  # noqa: BLE001 - a count for the summary, never a reason to fail
        return default


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
