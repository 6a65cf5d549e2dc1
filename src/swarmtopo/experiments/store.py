"""The DuckDB result store of sweeps: one row per job in the table ``jobs``.

Tables
------
``jobs``
    One row per finished job, keyed by the job key (:attr:`~.grid.Job.key`).  Columns
    (:data:`JOB_COLUMNS`): the job's identity (``key``, ``sweep`` = the sweep that ran
    it, ``replicate``, ``salt``, ``seed``, ``config`` JSON), one flattened column per
    grid key (:data:`~.grid.PARAMS`; NULL where the job's config does not use it,
    ``landmarks`` NULL for "auto"), the truth and the estimates (``true_betti0/1``,
    ``est_betti0/1``, ``confidence_betti0/1``), the union diagram's dimension-1 SNR
    against the true beta_1 (``snr_h1`` = the paper's ratio, ``noise_power_h1``) and bar
    lengths (``lengths_h1``, decreasing), the regions' diagrams (``diagrams``: a JSON
    list, one ``{"events", "agents", "landmarks", "diagram": Diagram.to_json()}`` per
    region, largest first), sizes (``n_events, n_agents, n_regions, n_landmarks``),
    stage timings in seconds (``t_simulate, t_graph, t_landmarks, t_persistence,
    t_classify, t_total``; landmarks and persistence summed over the map's window
    tasks, which run side by side when a worker has more than one thread),
    ``versions`` JSON (software versions, and the classifier's name and Theta), ``worker`` (host:pid), ``finished_at`` (UTC) and ``error``: the
    one-line message of a job that failed with a user-level error (too little data,
    holes that do not fit), whose estimates are then NULL.
``sweep_jobs``
    ``(sweep, key)``: which jobs each sweep asked for.  A job shared by two sweeps
    (same config, replicate and salt) is computed and stored once;
    ``read_jobs(path, sweep=name)`` returns all of a sweep's finished jobs.

Every row is written in its own transaction, so after a crash a row is there whole or
not at all.  DuckDB allows one writing process per file: while a sweep runs, its store
cannot be opened by another process.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterable, Sequence

from ..errors import SwarmtopoError
from .grid import PARAMS

_IDENTITY = (("key", "TEXT PRIMARY KEY"), ("sweep", "TEXT NOT NULL"), ("replicate", "INTEGER NOT NULL"),
             ("salt", "TEXT NOT NULL"), ("seed", "UBIGINT NOT NULL"), ("config", "JSON NOT NULL"))
_RESULTS = (
    ("true_betti0", "INTEGER"), ("true_betti1", "INTEGER"),
    ("est_betti0", "INTEGER"), ("est_betti1", "INTEGER"),
    ("confidence_betti0", "DOUBLE"), ("confidence_betti1", "DOUBLE"),
    ("snr_h1", "DOUBLE"), ("noise_power_h1", "DOUBLE"), ("lengths_h1", "DOUBLE[]"), ("diagrams", "JSON"),
    ("n_events", "INTEGER"), ("n_agents", "INTEGER"), ("n_regions", "INTEGER"), ("n_landmarks", "INTEGER"),
    ("t_simulate", "DOUBLE"), ("t_graph", "DOUBLE"), ("t_landmarks", "DOUBLE"), ("t_persistence", "DOUBLE"),
    ("t_classify", "DOUBLE"), ("t_total", "DOUBLE"),
    ("versions", "JSON"), ("worker", "TEXT"), ("finished_at", "TIMESTAMP"), ("error", "TEXT"),
)
JOB_COLUMNS: tuple[tuple[str, str], ...] = (*_IDENTITY, *((p.name, p.sql) for p in PARAMS), *_RESULTS)
"""(name, DuckDB type) of every column of ``jobs``, in order."""
JSON_COLUMNS = ("config", "diagrams", "versions")
"""Columns holding JSON text; :func:`read_jobs` returns them parsed."""
RUN_COLUMNS = ("t_simulate", "t_graph", "t_landmarks", "t_persistence", "t_classify", "t_total",
               "versions", "worker", "finished_at")
"""Columns that describe the run, not the result: they differ between runs of the same job."""
_NAMES = tuple(name for name, _ in JOB_COLUMNS)
_QUOTED = tuple(f'"{name}"' for name in _NAMES)  # some names (outer) are SQL keywords


class ResultStore:
    """A sweep's store, open for writing (use as a context manager).

    Parameters
    ----------
    path
        The DuckDB file (created with its tables if missing).

    Raises
    ------
    SwarmtopoError
        If the file cannot be opened (in use by another process, not a DuckDB file)
        or holds a ``jobs`` table with other columns.
    """

    def __init__(self, path):
        import duckdb

        self.path = Path(path)
        try:
            self._db = duckdb.connect(str(self.path))
        except duckdb.Error as exc:
            raise SwarmtopoError(f"{self.path}: cannot open the result store ({_first_line(exc)})") from None
        try:
            if _tables(self._db) == set():
                columns = ", ".join(f"{quoted} {sql}" for quoted, (_, sql) in zip(_QUOTED, JOB_COLUMNS))
                self._db.execute(f"CREATE TABLE jobs ({columns})")
                self._db.execute("CREATE TABLE sweep_jobs (sweep TEXT, key TEXT, PRIMARY KEY (sweep, key))")
            _check_schema(self._db, self.path)
        except BaseException:
            self.close()
            raise
        self._insert = (f"INSERT INTO jobs ({', '.join(_QUOTED)}) VALUES ({', '.join('?' * len(_NAMES))}) "
                        "ON CONFLICT DO NOTHING")

    def __enter__(self) -> "ResultStore":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Close the file (checkpointing DuckDB's write-ahead log)."""
        self._db.close()

    def add_to_sweep(self, sweep: str, keys: Iterable[str]) -> None:
        """Record that ``sweep`` asks for the jobs ``keys`` (one transaction)."""
        self._db.execute("INSERT INTO sweep_jobs SELECT ?, key FROM (SELECT DISTINCT unnest(?::TEXT[]) AS key) "
                         "ON CONFLICT DO NOTHING", [sweep, list(keys)])

    def finished_keys(self) -> set[str]:
        """Keys of every job with a row."""
        return {k for (k,) in self._db.execute("SELECT key FROM jobs").fetchall()}

    def insert(self, row: dict[str, Any]) -> bool:
        """Write one job's row in its own transaction; False if its key was already there.

        ``row`` must have exactly the columns of ``JOB_COLUMNS``; JSON columns as Python
        data (dicts / lists), ``lengths_h1`` as a list of floats.
        """
        if set(row) != set(_NAMES):
            missing = sorted(set(_NAMES) - set(row))
            extra = sorted(set(row) - set(_NAMES))
            raise ValueError(f"row columns differ from the store's: missing {missing}, unknown {extra}")
        values = [json.dumps(row[n], sort_keys=True, allow_nan=False) if n in JSON_COLUMNS and row[n] is not None
                  else row[n] for n in _NAMES]
        return self._db.execute(self._insert, values).fetchone()[0] == 1


def read_jobs(path, sweep: str | None = None, columns: Sequence[str] | None = None) -> list[dict[str, Any]]:
    """Rows of a result store as dicts, sorted by key.

    Parameters
    ----------
    path
        The DuckDB file.
    sweep
        Only the finished jobs of this sweep (``[sweep] name``); None = every row.
    columns
        Only these columns (``key`` among them); a store written by another swarmtopo
        version is read too if it has them.  None = every column of this version's store.

    Returns
    -------
    list of dict
        Column name -> value; JSON columns parsed (``config``, ``diagrams``,
        ``versions``), ``lengths_h1`` a list of floats, ``finished_at`` a naive UTC
        datetime.  A region's diagram is ``Diagram.from_json(row["diagrams"][i]["diagram"])``.
    """
    import duckdb

    path = Path(path)
    if not path.exists():
        raise SwarmtopoError(f"{path}: no such result store")
    try:
        db = duckdb.connect(str(path), read_only=True)
    except duckdb.Error as exc:
        raise SwarmtopoError(f"{path}: cannot open the result store ({_first_line(exc)})") from None
    try:
        _check_schema(db, path, columns)
        selected = "jobs.*" if columns is None else ", ".join(f"jobs.{name}" for name in columns)
        if sweep is None:
            cursor = db.execute(f"SELECT {selected} FROM jobs ORDER BY key")
        else:
            cursor = db.execute(f"SELECT {selected} FROM jobs JOIN sweep_jobs USING (key) "
                                "WHERE sweep_jobs.sweep = ? ORDER BY key", [sweep])
        names = [d[0] for d in cursor.description]
        rows = [dict(zip(names, values)) for values in cursor.fetchall()]
    finally:
        db.close()
    for row in rows:
        for name in JSON_COLUMNS:
            if row.get(name) is not None:
                row[name] = json.loads(row[name])
    return rows


def job_rows(path, jobs) -> list[dict[str, Any]]:
    """The stored rows of these jobs (:func:`read_jobs`, every column), sorted by key."""
    return job_rows_each(path, jobs)[0]


def job_rows_each(path, *job_lists) -> list[list[dict[str, Any]]]:
    """The stored rows of each list of jobs, from one read of the store, each sorted by key."""
    rows = read_jobs(path)
    return [[row for row in rows if row["key"] in keys] for keys in ({job.key for job in jobs} for jobs in job_lists)]


def _tables(db) -> set[str]:
    """Which of the store's tables the file holds."""
    return {name for (name,) in db.execute("SELECT table_name FROM information_schema.tables "
                                           "WHERE table_name IN ('jobs', 'sweep_jobs')").fetchall()}


def _check_schema(db, path: Path, columns: Sequence[str] | None = None) -> None:
    """Refuse a file whose tables are not this version's store (with ``columns``: whose
    jobs table lacks one of them)."""
    if _tables(db) != {"jobs", "sweep_jobs"}:
        raise SwarmtopoError(f"{path}: not a sweep result store (it lacks the jobs and sweep_jobs tables)")
    found = tuple(name for (name,) in db.execute(
        "SELECT column_name FROM information_schema.columns WHERE table_name = 'jobs' ORDER BY ordinal_position"
    ).fetchall())
    if columns is not None:
        missing = [n for n in columns if n not in found]
        if missing:
            raise SwarmtopoError(f"{path}: its jobs table lacks the columns {', '.join(missing)}")
        return
    if found != _NAMES:
        missing = [n for n in _NAMES if n not in found]
        extra = [n for n in found if n not in _NAMES]
        raise SwarmtopoError(
            f"{path}: its jobs table was written by another swarmtopo version (missing columns: "
            f"{', '.join(missing) or 'none'}; unknown: {', '.join(extra) or 'none'}); use a new store file")


def _first_line(exc: Exception) -> str:
    return str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
