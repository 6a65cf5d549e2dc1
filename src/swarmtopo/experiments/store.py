"""The DuckDB result store of sweeps: one row per job in the table ``jobs``.

Tables
------
``jobs``
    One row per job run, keyed by the job key (:attr:`~.grid.Job.key`).  Columns
    (:data:`JOB_COLUMNS`): the job's identity (``key``, ``sweep`` = the sweep that ran
    it, ``replicate``, ``salt``, ``seed``, ``config`` JSON), one flattened column per
    grid key (:data:`~.grid.PARAMS`; NULL where the job's config does not use it,
    ``landmarks`` NULL for "auto"), the truth and the estimates (``true_betti0/1``,
    ``est_betti0/1``, ``confidence_betti0/1``), the union diagram's dimension-1 SNR
    against the true beta_1 (``snr_h1`` = the paper's ratio, ``noise_power_h1``) and bar
    lengths (``lengths_h1``, decreasing), the regions (``diagrams``: a compressed BLOB,
    see :func:`encode_regions`; ``diagrams_kept`` says which persistence diagrams it
    holds, :data:`~.grid.KEEP_LEVELS`), ``timeline`` JSON (the true Betti numbers over time,
    the map's change points and segments, and at level ``windows`` each timeline window's
    counts: :func:`~.sweep.timeline_record`), ``exploration`` JSON (a swarm with a leader:
    the global map and the true holes, :func:`~.sweep.exploration_record`), sizes (``n_events, n_agents, n_regions, n_landmarks``),
    stage timings in seconds (``t_simulate, t_graph, t_landmarks, t_persistence,
    t_classify, t_total``), ``versions`` JSON (software versions, and the classifier's
    name and Theta), ``worker`` (host:pid), ``finished_at`` (UTC), ``status`` and
    ``error``.
``sweep_jobs``
    ``(sweep, key)``: which jobs each sweep asked for.  A job shared by two sweeps
    (same config, replicate and salt) is computed and stored once.
``runs``
    One row per ``run_sweep`` call: host, pid, scheduler, workers, when it started,
    when it last wrote (``updated_at``) and how it ended (``outcome``; NULL while it
    runs or after it was killed).

``status`` is ``"ok"`` or one of the failure kinds (:data:`FAILURES`): ``"error"``
(the job raised: too little data to map, holes that do not fit, or a bug), ``"crashed"``
(the process running it died: out of memory, a crash inside a compiled library) or
``"timeout"`` (it ran past the sweep's job timeout).  A failed row has the one-line
``error`` message and NULL estimates.

Writing and reading.  The sweep's client holds the file only while it writes a batch
of rows (one transaction: after a crash a batch is there whole or not at all), so
another process can read the store while a sweep runs (``swarmtopo status``,
:func:`iter_jobs`); either side waits its turn when the other holds the file.
:func:`iter_jobs` streams rows a chunk at a time and reads only the columns asked for.
"""

from __future__ import annotations

import json
import os
import re
import socket
import struct
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import lru_cache
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Iterable, Iterator, Sequence

import numpy as np

from ..errors import SwarmtopoError
from ..topology.persistence import Diagram
from .grid import PARAMS

FAULT_PARAMS = tuple(p.name for p in PARAMS if p.table == "faults")

STATUSES = ("ok", "error", "crashed", "timeout")
FAILURES = STATUSES[1:]
"""Kinds of failed rows."""

_IDENTITY = (("key", "TEXT PRIMARY KEY"), ("sweep", "TEXT NOT NULL"), ("replicate", "INTEGER NOT NULL"),
             ("salt", "TEXT NOT NULL"), ("seed", "UBIGINT NOT NULL"), ("config", "JSON NOT NULL"))
_RESULTS = (
    ("true_betti0", "INTEGER"), ("true_betti1", "INTEGER"),
    ("est_betti0", "INTEGER"), ("est_betti1", "INTEGER"),
    ("confidence_betti0", "DOUBLE"), ("confidence_betti1", "DOUBLE"),
    ("snr_h1", "DOUBLE"), ("noise_power_h1", "DOUBLE"), ("lengths_h1", "DOUBLE[]"),
    ("diagrams", "BLOB"), ("diagrams_kept", "TEXT"), ("timeline", "JSON"), ("exploration", "JSON"),
    ("motion_estimate", "JSON"),
    ("sensing", "JSON"),
    ("n_events", "INTEGER"), ("n_agents", "INTEGER"), ("n_regions", "INTEGER"), ("n_landmarks", "INTEGER"),
    ("t_simulate", "DOUBLE"), ("t_graph", "DOUBLE"), ("t_landmarks", "DOUBLE"), ("t_persistence", "DOUBLE"),
    ("t_classify", "DOUBLE"), ("t_total", "DOUBLE"),
    ("versions", "JSON"), ("worker", "TEXT"), ("finished_at", "TIMESTAMP"),
    ("status", "TEXT NOT NULL"), ("error", "TEXT"),
)
JOB_COLUMNS: tuple[tuple[str, str], ...] = (*_IDENTITY, *((p.name, p.sql) for p in PARAMS), *_RESULTS)
"""(name, DuckDB type) of every column of ``jobs``, in order."""
JSON_COLUMNS = ("config", "versions", "timeline", "exploration", "motion_estimate", "sensing")
"""Columns holding JSON text; :func:`iter_jobs` returns them parsed."""
RUN_COLUMNS = ("t_simulate", "t_graph", "t_landmarks", "t_persistence", "t_classify", "t_total",
               "versions", "worker", "finished_at")
"""Columns that describe the run, not the result: they differ between runs of the same job."""
_NAMES = tuple(name for name, _ in JOB_COLUMNS)
_QUOTED = tuple(f'"{name}"' for name in _NAMES)  # some names (outer) are SQL keywords
_TABLES = {"jobs", "sweep_jobs", "runs"}
LOCK_WAIT = 60.0
"""Seconds a reader, or the final write of a sweep, waits for the other side to release the file."""


# -- the compact diagrams column ----------------------------------------------------------
_MAGIC = b"STD1"


def encode_regions(regions: list[dict[str, Any]]) -> bytes:
    """The ``diagrams`` BLOB of a row's regions.

    ``regions`` is a list of dicts whose ``"diagram"`` (and each ``"windows"`` entry's
    ``"diagram"``) is a :class:`Diagram`, where kept.  The BLOB is ``STD1``, the
    uncompressed size (uint64, little endian) and the zstd-compressed body: a JSON header
    (the regions with each diagram replaced by its bar counts per dimension) and every
    bar's (birth, death) as float64 in header order, so diagrams read back bit for bit.
    """
    import pyarrow as pa

    arrays: list[np.ndarray] = []

    def strip(item):
        if isinstance(item, Diagram):
            arrays.extend(np.asarray(p, dtype="<f8").reshape(-1, 2) for p in item.pairs)
            return {"bars": [len(p) for p in item.pairs]}
        if isinstance(item, dict):  # in key order: the order the header is written and read back in
            return {k: strip(item[k]) for k in sorted(item)}
        if isinstance(item, list):
            return [strip(v) for v in item]
        return item

    header = json.dumps(strip(regions), separators=(",", ":"), allow_nan=False).encode()
    body = struct.pack("<I", len(header)) + header + b"".join(a.tobytes() for a in arrays)
    return _MAGIC + struct.pack("<Q", len(body)) + pa.compress(body, codec="zstd", asbytes=True)


def decode_regions(blob: bytes) -> list[dict[str, Any]]:
    """Inverse of :func:`encode_regions`: the regions with :class:`Diagram` objects."""
    import pyarrow as pa

    if blob[:4] != _MAGIC:
        raise SwarmtopoError("a diagrams value is not a swarmtopo STD1 blob")
    (size,) = struct.unpack("<Q", blob[4:12])
    body = pa.decompress(blob[12:], decompressed_size=size, codec="zstd", asbytes=True)
    (n,) = struct.unpack("<I", body[:4])
    header = json.loads(body[4:4 + n])
    values = np.frombuffer(body, dtype="<f8", offset=4 + n).reshape(-1, 2)
    offset = 0

    def restore(item):
        nonlocal offset
        if isinstance(item, dict) and set(item) == {"bars"}:
            pairs = []
            for count in item["bars"]:
                pairs.append(values[offset:offset + count].astype(float))
                offset += count
            return Diagram(tuple(pairs), backend="store")
        if isinstance(item, dict):
            return {k: restore(v) for k, v in item.items()}
        if isinstance(item, list):
            return [restore(v) for v in item]
        return item

    return restore(header)


# -- opening the file ---------------------------------------------------------------------
def _is_lock_conflict(exc: Exception) -> bool:
    """Whether DuckDB refused the file because it is open elsewhere: by another process
    (a lock) or, in this process, by a connection of the other mode."""
    text = str(exc).lower()
    return "could not set lock" in text or "conflicting lock" in text or "different configuration" in text


def _connect(path: Path, *, read_only: bool, wait: float):
    """A DuckDB connection, retrying for ``wait`` s while another process holds the file
    (a sweep writing a batch, or a reader); None if still held after ``wait``."""
    import duckdb

    deadline = time.monotonic() + wait
    delay = 0.01
    while True:
        try:
            return duckdb.connect(str(path), read_only=read_only)
        except duckdb.Error as exc:
            if not _is_lock_conflict(exc):
                raise SwarmtopoError(f"{path}: cannot open the result store ({_first_line(exc)})") from None
            if time.monotonic() >= deadline:
                return None
            time.sleep(delay)
            delay = min(2 * delay, 0.25)


@contextmanager
def _opened(path: Path, *, read_only: bool = False, wait: float = LOCK_WAIT):
    db = _connect(path, read_only=read_only, wait=wait)
    if db is None:
        raise SwarmtopoError(f"{path}: the result store has been held by another process for {wait:g} s "
                             "(a DuckDB session left open?)")
    try:
        yield db
    finally:
        db.close()


class ResultStore:
    """A sweep's store for writing: creates the file and its tables if missing, then
    opens the file only for each operation (so other processes can read it between).

    Raises
    ------
    SwarmtopoError
        If the file cannot be opened (not a DuckDB file) or holds tables of another
        swarmtopo version.
    """

    def __init__(self, path):
        self.path = Path(path)
        with _opened(self.path) as db:
            if not _tables(db):
                columns = ", ".join(f"{quoted} {sql}" for quoted, (_, sql) in zip(_QUOTED, JOB_COLUMNS))
                db.execute("BEGIN")
                db.execute(f"CREATE TABLE jobs ({columns})")
                db.execute("CREATE TABLE sweep_jobs (sweep TEXT, key TEXT, PRIMARY KEY (sweep, key))")
                db.execute("CREATE TABLE runs (id TEXT PRIMARY KEY, host TEXT, pid INTEGER, scheduler TEXT, "
                           "workers INTEGER, started_at TIMESTAMP, updated_at TIMESTAMP, outcome TEXT)")
                db.execute("COMMIT")
            _add_new_columns(db)
            _check_schema(db, self.path)
        # a retried job's new row replaces the old one, but a failed row never replaces a
        # good one (a job rerun to keep more diagrams that then crashed keeps its result)
        updates = ", ".join(f"{q} = excluded.{q}" for q in _QUOTED if q != '"key"')
        self._insert = (f"INSERT INTO jobs ({', '.join(_QUOTED)}) SELECT {', '.join(_QUOTED)} FROM batch "
                        f"ON CONFLICT (key) DO UPDATE SET {updates} "
                        "WHERE excluded.status = 'ok' OR jobs.status <> 'ok'")

    def add_to_sweep(self, sweep: str, keys: Iterable[str]) -> None:
        """Record that ``sweep`` asks for the jobs ``keys`` (one transaction)."""
        with _opened(self.path) as db:
            db.execute("INSERT INTO sweep_jobs SELECT ?, key FROM (SELECT DISTINCT unnest(?::TEXT[]) AS key) "
                       "ON CONFLICT DO NOTHING", [sweep, list(keys)])

    def stored(self) -> dict[str, tuple[str, str | None]]:
        """Key -> (status, diagrams_kept) of every row."""
        with _opened(self.path) as db:
            return {k: (s, kept) for k, s, kept in db.execute("SELECT key, status, diagrams_kept FROM jobs").fetchall()}

    def write(self, rows: Sequence[dict[str, Any]], *, wait: float = 0.0) -> bool:
        """Write rows in one transaction, replacing failed rows of the same keys (a retried
        job) and ok rows by ok rows (a job rerun to keep more diagrams).

        Returns False, writing nothing, if another process still holds the file after
        ``wait`` s (the caller keeps the rows and tries again).  Each row must have
        exactly the columns of ``JOB_COLUMNS``: JSON columns as Python data, ``diagrams``
        as bytes (:func:`encode_regions`) or None.
        """
        if not rows:
            return True
        if len({row["key"] for row in rows}) < len(rows):
            raise ValueError("a batch holds two rows of the same job")
        db = _connect(self.path, read_only=False, wait=wait)
        if db is None:
            return False
        try:
            db.register("batch", _arrow_rows(rows))
            db.execute("BEGIN")
            db.execute(self._insert)
            db.execute("COMMIT")
        finally:
            db.close()
        return True

    def save_aside(self, rows: Sequence[dict[str, Any]]) -> Path:
        """Write rows the store could not take to a Parquet file beside it; its path."""
        import pyarrow.parquet as pq

        aside = self.path.with_name(f"{self.path.name}.unsaved-{os.getpid()}-{time.time_ns()}.parquet")
        pq.write_table(_arrow_rows(rows), aside)
        return aside

    def start_run(self, scheduler: str | None, workers: int) -> str:
        """Record a new run of a sweep on this store; its id."""
        run = f"{socket.gethostname()}:{os.getpid()}:{time.time_ns()}"
        now = utcnow()
        with _opened(self.path) as db:
            db.execute("INSERT INTO runs VALUES (?, ?, ?, ?, ?, ?, ?, NULL)",
                       [run, socket.gethostname(), os.getpid(), scheduler or "local", workers, now, now])
        return run

    def touch_run(self, run: str, workers: int, outcome: str | None = None, *, wait: float = 0.0) -> None:
        """Note that the run is alive (its workers now), or how it ended; skipped if the file is busy."""
        db = _connect(self.path, read_only=False, wait=wait)
        if db is None:
            return
        try:
            db.execute("UPDATE runs SET workers = ?, updated_at = ?, outcome = ? WHERE id = ?",
                       [workers, utcnow(), outcome, run])
        finally:
            db.close()


def _arrow_rows(rows: Sequence[dict[str, Any]]):
    """The rows as an Arrow table with the ``jobs`` columns (JSON columns as text)."""
    import pyarrow as pa

    for row in rows:
        if set(row) != set(_NAMES):
            missing = sorted(set(_NAMES) - set(row))
            extra = sorted(set(row) - set(_NAMES))
            raise ValueError(f"row columns differ from the store's: missing {missing}, unknown {extra}")
    columns = {}
    for name, sql in JOB_COLUMNS:
        values = [row[name] for row in rows]
        if name in JSON_COLUMNS:
            values = [None if v is None else json.dumps(v, sort_keys=True, allow_nan=False) for v in values]
        columns[name] = pa.array(values, type=_arrow_types()[sql.split()[0]])
    return pa.table(columns)


@lru_cache(maxsize=1)
def _arrow_types() -> dict:
    """DuckDB column type -> the Arrow type its values are written as."""
    import pyarrow as pa

    return {"TEXT": pa.string(), "JSON": pa.string(), "INTEGER": pa.int32(), "UBIGINT": pa.uint64(),
            "DOUBLE": pa.float64(), "DOUBLE[]": pa.list_(pa.float64()), "TEXT[]": pa.list_(pa.string()),
            "BLOB": pa.binary(), "TIMESTAMP": pa.timestamp("us")}


# -- reading ------------------------------------------------------------------------------
def iter_jobs(path, *, sweep: str | None = None, keys: Iterable[str] | None = None,
              columns: Sequence[str] | None = None, status: str | None = None,
              chunk_rows: int = 512) -> Iterator[dict[str, Any]]:
    """Stream the rows of a result store as dicts, in the order they were written.

    Parameters
    ----------
    path
        The DuckDB file.
    sweep
        Only the jobs of this sweep (``[sweep] name``); None = every row.
    keys
        Only the rows of these job keys.
    columns
        Only these columns; a store written by another swarmtopo version is read too if it
        has them.  None = every column.
    status
        Only rows of this status (``"ok"`` or a failure kind).
    chunk_rows
        Rows read at a time: with DuckDB's own vector of 2,048 rows, what bounds the
        memory a read takes, whatever the store's size.

    Yields
    ------
    dict
        Column name -> value; JSON columns parsed, ``diagrams`` decoded
        (:func:`decode_regions`: a list of region dicts whose ``"diagram"`` values are
        :class:`Diagram` objects), ``lengths_h1`` a list of floats, ``finished_at`` a naive
        UTC datetime.

    The file is opened (read only) for each chunk, so a sweep writing to it gets its turns
    between them; rows written after the first chunk was read are not yielded, and a row
    a sweep replaces meanwhile (``--retry-failed``, more diagrams kept) may be missed:
    read a store whose sweep is running for a look, and one whose sweep has ended for
    results.  The order is the store's, which depends on the order jobs finished: sort
    what you keep (:func:`read_jobs` sorts by key).
    """
    path = Path(path)
    if not path.exists():
        raise SwarmtopoError(f"{path}: no such result store")
    where, params = [], []
    if sweep is not None:
        where.append("key IN (SELECT key FROM sweep_jobs WHERE sweep = ?)")
        params.append(sweep)
    if keys is not None:
        where.append("key IN (SELECT unnest(?::TEXT[]))")
        params.append(list(keys))
    if status is not None:
        where.append("status = ?")
        params.append(status)
    with _opened(path, read_only=True) as db:
        _check_schema(db, path, columns)
        (last,) = db.execute("SELECT max(rowid) FROM jobs").fetchone()
    selected = "*" if columns is None else ", ".join(f'"{name}"' for name in columns)
    # a range of row ids at a time, in storage order: a range reads only its own part of
    # the file, where sorting rows (or fetching them by key) reads every diagram each time
    seen: set[str] = set()  # a row moved by a replacement between chunks is yielded once
    for start in range(0, -1 if last is None else last + 1, chunk_rows):
        with _opened(path, read_only=True) as db:
            cursor = db.execute(f"SELECT {selected} FROM jobs WHERE rowid >= ? AND rowid < ?"
                                + "".join(f" AND {w}" for w in where), [start, start + chunk_rows, *params])
            names = [d[0] for d in cursor.description]
            chunk = cursor.fetchall()
        chunk.reverse()
        while chunk:  # each row freed once yielded: one chunk in memory, not two
            values = chunk.pop()
            row = dict(zip(names, values))
            if "key" in row:
                if row["key"] in seen:
                    continue
                seen.add(row["key"])
            for name in JSON_COLUMNS:
                if row.get(name) is not None:
                    row[name] = json.loads(row[name])
            if row.get("diagrams") is not None:
                row["diagrams"] = decode_regions(row["diagrams"])
            yield row


def read_jobs(path, sweep: str | None = None, columns: Sequence[str] | None = None,
              keys: Iterable[str] | None = None) -> list[dict[str, Any]]:
    """Every row :func:`iter_jobs` yields, as a list sorted by key (``key`` must be among
    ``columns``): for small stores and selections."""
    if columns is not None and "key" not in columns:
        raise ValueError("read_jobs sorts by key: give it among the columns")
    return sorted(iter_jobs(path, sweep=sweep, columns=columns, keys=keys), key=lambda row: row["key"])


def job_rows(path, jobs) -> list[dict[str, Any]]:
    """The stored rows of these jobs (:func:`iter_jobs`), sorted by key."""
    return read_jobs(path, keys=[job.key for job in jobs])


def job_rows_each(path, *job_lists) -> list[list[dict[str, Any]]]:
    """The stored rows of each list of jobs, from one read of the store, each sorted by key."""
    rows = read_jobs(path, keys={job.key for jobs in job_lists for job in jobs})
    return [[row for row in rows if row["key"] in keys] for keys in ({job.key for job in jobs} for jobs in job_lists)]


def stored_failures(path, keys: Iterable[str]) -> list[FailureGroup]:
    """The failed rows of these job keys, grouped (:func:`group_failures`), from one query."""
    with _opened(Path(path), read_only=True) as db:
        _check_schema(db, Path(path))
        found = db.execute("SELECT status, error, count(*) FROM jobs WHERE key IN (SELECT unnest(?::TEXT[])) "
                           "AND status <> 'ok' GROUP BY ALL", [list(keys)]).fetchall()
    return group_failures(found)


# -- status -------------------------------------------------------------------------------
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def message_pattern(message: str) -> str:
    """A failure message with its numbers replaced by ``#``: messages that differ only in
    per-job numbers ("too little data: 31 encounters") group together."""
    return _NUMBER.sub("#", message)


@dataclass(frozen=True)
class FailureGroup:
    """Failed rows of one kind whose messages differ at most in numbers."""

    status: str
    count: int
    example: str
    varied: bool = False
    """Whether the group's messages differ (in their numbers)."""


def group_failures(failures: Iterable[tuple[str, str, int]]) -> list[FailureGroup]:
    """(status, message, count) triples grouped by status and :func:`message_pattern`,
    largest first; each group's example is its first message in sorted order."""
    groups: dict[tuple[str, str], tuple[int, set[str]]] = {}
    for status, message, count in failures:
        key = (status, message_pattern(message or ""))
        n, messages = groups.get(key, (0, set()))
        messages.add(message or "")
        groups[key] = (n + count, messages)
    return sorted((FailureGroup(status, n, min(messages), len(messages) > 1)
                   for (status, _), (n, messages) in groups.items()),
                  key=lambda g: (-g.count, g.status, g.example))


@dataclass(frozen=True)
class SweepCounts:
    """One sweep's jobs in a store: how many it asked for, and of those how many have a
    row of each status (``pending`` = no row yet)."""

    sweep: str
    asked: int
    counts: dict[str, int]

    @property
    def pending(self) -> int:
        return self.asked - sum(self.counts.values())


@dataclass(frozen=True)
class StoreStatus:
    """What a store holds (:func:`store_status`)."""

    path: Path
    sweeps: list[SweepCounts]
    failures: list[FailureGroup]
    runs: list[dict[str, Any]] = field(default_factory=list)


RUN_STALE = 120.0
"""A run that has not noted it is alive for this long (it does every ``TOUCH_SECONDS`` of
:mod:`.sweep`) and has not ended is reported as stopped: killed."""


def store_status(path) -> StoreStatus:
    """Counts per sweep and status, failures grouped (:func:`group_failures`) and the
    runs, read with SQL aggregates (no row is loaded); works while a sweep runs."""
    path = Path(path)
    if not path.exists():
        raise SwarmtopoError(f"{path}: no such result store")
    with _opened(path, read_only=True) as db:
        _check_schema(db, path)
        asked = dict(db.execute("SELECT sweep, count(*) FROM sweep_jobs GROUP BY sweep").fetchall())
        counts: dict[str, dict[str, int]] = {sweep: {} for sweep in asked}
        for sweep, status, n in db.execute("SELECT s.sweep, j.status, count(*) FROM sweep_jobs s JOIN jobs j "
                                           "USING (key) GROUP BY ALL").fetchall():
            counts[sweep][status] = n
        failures = db.execute("SELECT status, error, count(*) FROM jobs WHERE status <> 'ok' GROUP BY ALL").fetchall()
        cursor = db.execute("SELECT * FROM runs ORDER BY started_at")
        names = [d[0] for d in cursor.description]
        runs = [dict(zip(names, values)) for values in cursor.fetchall()]
    return StoreStatus(path=path, sweeps=[SweepCounts(s, asked[s], counts[s]) for s in sorted(asked)],
                       failures=group_failures(failures), runs=runs)


# -- internals ----------------------------------------------------------------------------
def utcnow() -> datetime:
    """Now in UTC without a time zone: how the store's TIMESTAMP columns hold time."""
    return datetime.now(timezone.utc).replace(tzinfo=None)


def _tables(db) -> set[str]:
    """Which of the store's tables the file holds."""
    return {name for (name,) in db.execute("SELECT table_name FROM information_schema.tables").fetchall()} & _TABLES


NEW_COLUMNS = ("change", "change_time", "timeline", "length", "width", "leash", "leader_speed", "exploration", "motion",
               "speed", "tumble_rate", "diffusion", "levy_exponent", "levy_min_step", "align_radius", "noise",
               "motion_estimate", *FAULT_PARAMS, "sensing")
"""Columns added since stores had a runs table: a store without them gets them (NULL)
when a sweep opens it, so its finished jobs are kept."""


def _add_new_columns(db) -> None:
    """Add ``NEW_COLUMNS`` missing from an existing jobs table (one transaction)."""
    if _tables(db) != _TABLES:
        return
    missing = [name for name in NEW_COLUMNS if name not in _job_columns(db)]
    if missing:
        db.execute("BEGIN")
        for name in missing:
            db.execute(f'ALTER TABLE jobs ADD COLUMN "{name}" {dict(JOB_COLUMNS)[name]}')
        db.execute("COMMIT")


def _check_schema(db, path: Path, columns: Sequence[str] | None = None) -> None:
    """Refuse a file whose tables are not this version's store (with ``columns``: whose
    jobs table lacks one of them)."""
    tables = _tables(db)
    if columns is not None and {"jobs", "sweep_jobs"} <= tables:
        found = _job_columns(db)
        missing = [n for n in columns if n not in found]
        if missing:
            raise SwarmtopoError(f"{path}: its jobs table lacks the columns {', '.join(missing)}")
        return
    if tables != _TABLES:
        if {"jobs", "sweep_jobs"} <= tables:
            raise SwarmtopoError(f"{path}: a result store of an earlier swarmtopo version (no runs table); "
                                 "use a new store file")
        raise SwarmtopoError(f"{path}: not a sweep result store (it lacks the jobs and sweep_jobs tables)")
    found = _job_columns(db)
    if set(found) != set(_NAMES):
        missing = [n for n in _NAMES if n not in found]
        extra = [n for n in found if n not in _NAMES]
        raise SwarmtopoError(
            f"{path}: its jobs table was written by another swarmtopo version (missing columns: "
            f"{', '.join(missing) or 'none'}; unknown: {', '.join(extra) or 'none'}); use a new store file")


def _job_columns(db) -> tuple[str, ...]:
    return tuple(name for (name,) in db.execute(
        "SELECT column_name FROM information_schema.columns WHERE table_name = 'jobs' ORDER BY ordinal_position"
    ).fetchall())


def _first_line(exc: Exception) -> str:
    return str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
