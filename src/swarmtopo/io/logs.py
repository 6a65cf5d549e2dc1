"""Files in and out: log folders, arenas (GeoJSON) and JSON.

The log folder is the contract between whoever records a deployment (the simulator,
a real base station, someone's script) and ``swarmtopo map``.  A folder ``DIR`` holds

=====================  ===================================  ==========================
file                   columns / keys                       status
=====================  ===================================  ==========================
``events.<fmt>``       ``t, a, b``                          required
``status.<fmt>``       ``t, agent, state`` (RW, WF, S)      optional
``meta.json``          parameters, ``static`` =             optional
                       ``[{"agent": id, "time": t}, ...]``,
                       units, seed, ``agent_count`` (IDs
                       are 0 .. n-1) or ``agent_ids``,
                       ``format``, ``version``;
                       ``simulation`` (simulator-only
                       ground truth)
``arena.geojson``      the true arena                       optional, ground truth
``truth.<fmt>``        ``t, a, b, xa, ya, xb, yb``, one     optional, ground truth
                       row per event in the events' order
``trajectories.<fmt>`` ``t, agent, x, y[, state]``          optional, ground truth
=====================  ===================================  ==========================

``fmt`` is ``csv`` or ``parquet`` (one of them per file name); text is UTF-8.  Times
are in seconds, positions in millimetres.  The ``meta.json`` keys ``format``
(:data:`LOG_FORMAT`, this layout) and ``version`` (of the swarmtopo that made the log)
are optional; simulated logs carry both, and :func:`read_log` refuses a folder of
another ``format``.  Agent IDs are integers or text: in a CSV file an ID column is
integer only if every ID in the folder is written as an integer (``7``, or ``7.0`` as a
float column is often written: the same agent; not ``007`` or ``-0``) and ``meta.json``
does not declare text ``agent_ids``; otherwise all IDs are text, so ``"007"`` stays
``"007"``.  Blanks round a CSV ID are dropped unless ``meta.json``'s ``agent_ids``
lists the ID with them (so padded text IDs that :func:`write_log` wrote read back
exactly); two text IDs that differ only in such blanks are refused, not merged.  CSV
blank lines count as data rows and are skipped.  Extra columns are ignored by
:func:`read_log` (a name they repeat, such as the empty names of trailing empty
columns, too) and kept by :func:`read_truth` / :func:`read_trajectories`.

CSV and Parquet go through pyarrow (multi-threaded C++ readers) and ID columns are
dictionary-encoded, never turned into Python objects row by row: 10^6 events read in
about a second from CSV and half a second from Parquet.  Every error a file can cause
is an :class:`~.errors.InputError` naming the file, the 1-based data row, the column
and the value; so is a file system refusing a read or a write.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import re
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pcsv
import pyarrow.parquet as pq

from ..arena import Arena
from ..errors import InputError, SwarmtopoError
from ..log import EncounterLog, float_ids, parse_states, refuse_nul_ids, state_labels

FORMATS: tuple[str, ...] = ("csv", "parquet")
LOG_FORMAT = "swarmtopo-log/1"
"""The ``format`` key of ``meta.json`` for the layout this module reads and writes."""
EVENT_COLUMNS = ("t", "a", "b")
STATUS_COLUMNS = ("t", "agent", "state")
TRUTH_COLUMNS = ("t", "a", "b", "xa", "ya", "xb", "yb")
TRAJECTORY_COLUMNS = ("t", "agent", "x", "y")
GROUND_TRUTH_FILES = ("arena.geojson", *(f"{stem}.{fmt}" for stem in ("truth", "trajectories") for fmt in FORMATS))
"""Files that only a simulator can write; ``swarmtopo map`` never reads them."""

_TABLE_STEMS = ("events", "status", "truth", "trajectories")
_ID_COLUMNS = ("a", "b", "agent")
_OTHER_ENCODINGS = ((b"\xff\xfe\x00\x00", "UTF-32"), (b"\x00\x00\xfe\xff", "UTF-32"),
                    (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16"))
_INTEGER_TEXT = r"^(0|-?[1-9][0-9]*)(\.0+)?$"
"""An ID written as an integer: plain (not 017, not -0: those stay text), or with a zero
fraction, as a float column is often written (12.0 is agent 12, as in a Parquet float column)."""
GZIP_MAGIC = b"\x1f\x8b"
SNIFF_BYTES = 1 << 16  # the first block of a CSV file checked for binary data
MAX_TIME_RESOLUTION = 1e-3
"""Coarsest spacing (s) a float16 / float32 time column may have at its largest value:
beyond it the file's times were already rounded when written (float32 epoch seconds are
128 s apart), so they are refused rather than read as fewer, shifted times."""


# -- log folders -------------------------------------------------------------------------
def write_log(
    log: EncounterLog,
    directory,
    *,
    fmt: str = "csv",
    truth: dict | None = None,
    trajectories: dict | None = None,
    arena: Arena | None = None,
) -> list[Path]:
    """Write a log folder (see the module docstring); returns the paths written.

    The folder is created if needed (InputError naming the path if that or a write
    fails).  Its contract files that this call does not write (``truth.*`` from an
    earlier run, ``events.parquet`` when writing CSV, ...) are deleted, so the folder
    always describes exactly this log; other files are left alone.  Identical inputs
    give byte-identical files: ``meta.json`` has sorted keys and no timestamps, floats
    are written in their shortest exact form.

    Parameters
    ----------
    log
        The log.  Events are written in canonical order, status changes sorted by
        (t, agent), agent IDs in their original type.  ``meta.json`` holds ``log.meta``
        plus ``static`` (a list of ``{"agent", "time"}``) and a declaration of exactly
        the log's agents, replacing any in ``log.meta``: ``agent_count`` if the IDs
        are the integers ``0 .. n-1``, else ``agent_ids``.
    fmt
        ``"csv"`` or ``"parquet"``.
    truth
        Ground truth per event, aligned with ``log``'s events: arrays ``xa, ya, xb,
        yb`` (positions of agents ``log.a``, ``log.b`` in mm) and any extra columns.
        ``t, a, b`` are written from the log; if given they must match it.
    trajectories
        Ground-truth positions: arrays ``t, agent, x, y`` and optionally ``state``
        (strings or codes into STATES) and extra columns.
    arena
        The true arena, written as ``arena.geojson``.
    """
    if fmt not in FORMATS:
        raise SwarmtopoError(f"unknown log format {fmt!r}; expected one of {', '.join(FORMATS)}")
    directory = Path(directory)
    make_folder(directory)
    ids_a, ids_b = log.ids_of(log.a), log.ids_of(log.b)
    tables = {"events": {"t": log.t, "a": ids_a, "b": ids_b}}
    if len(log.status_t):
        order = np.lexsort((log.status_agent, log.status_t))
        tables["status"] = {
            "t": log.status_t[order],
            "agent": log.ids_of(log.status_agent[order]),
            "state": state_labels(log.status_state[order]),
        }
    if truth is not None:
        tables["truth"] = _truth_columns(log, truth, ids_a, ids_b)
    if trajectories is not None:
        tables["trajectories"] = _trajectory_columns(trajectories)

    written = [_write_table(columns, directory / f"{stem}.{fmt}") for stem, columns in tables.items()]
    written.append(write_json(_meta_for(log), directory / "meta.json"))
    if arena is not None:
        written.append(write_arena(arena, directory / "arena.geojson"))
    keep = {p.name for p in written}
    for path in log_files(directory):
        if path.name not in keep:
            try:
                path.unlink()
            except OSError as exc:
                raise InputError(f"cannot delete an outdated log file ({_os_reason(exc)})", file=str(path)) from None
    return written


def refuse_protected(directory, protect) -> None:
    """InputError if one of the files ``protect`` is a log file of ``directory``
    (:func:`write_log` would overwrite or delete it)."""
    protected = {Path(p).resolve() for p in protect}
    for path in log_files(directory):
        if path.resolve() in protected:
            raise InputError("the log folder would overwrite or delete this file; write the log to another "
                             "folder", file=str(path))


def log_files(directory) -> list[Path]:
    """The contract files (``events.*``, ``status.*``, ``truth.*``, ``trajectories.*``,
    ``meta.json``, ``arena.geojson``) present in ``directory``: what :func:`write_log`
    writes there or deletes as outdated."""
    names = [f"{stem}.{f}" for stem in _TABLE_STEMS for f in FORMATS] + ["meta.json", "arena.geojson"]
    return [Path(directory) / name for name in names if (Path(directory) / name).is_file()]


def read_log(directory) -> EncounterLog:
    """Read a log folder: ``events.<fmt>`` is required, everything else optional.

    Only ``events``, ``status`` and ``meta.json`` are read -- never ground truth.
    ``meta["static"]`` becomes the log's static agents; the rest of ``meta.json`` is
    ``log.meta``.  Unsorted events are sorted.

    Raises
    ------
    InputError
        Naming the file, the 1-based data row, the column and the value: missing
        file or column, unparsable CSV, non-numeric / NaN / negative / missing times,
        missing IDs, float IDs that are not whole numbers within int64, CSV text IDs
        that differ only in surrounding blanks, a == b, unknown states, IDs outside ``agent_ids`` /
        ``agent_count``, duplicate events, two status rows for one agent at one time,
        text that is not UTF-8, malformed ``meta.json`` or another ``format``; or when
        both ``events.csv`` and ``events.parquet`` exist.
    """
    directory = _log_dir(directory)
    meta_path = directory / "meta.json"
    meta = _read_meta(meta_path)
    events_path = _find_table(directory, "events", required=True)
    status_path = _find_table(directory, "status")
    events, event_rows = _read_table(events_path, EVENT_COLUMNS)
    status, status_rows = _read_table(status_path, STATUS_COLUMNS) if status_path else (None, None)

    id_cols = [(events[c], events_path, c, event_rows) for c in ("a", "b")]
    if status is not None:
        id_cols.append((status["agent"], status_path, "agent", status_rows))
    ids = _id_arrays(id_cols, declared=meta.get("agent_ids"))
    t = _number_column(events["t"], events_path, "t", "time", event_rows)
    status_cols = None
    if status is not None:
        status_cols = (_number_column(status["t"], status_path, "t", "time", status_rows), ids[2], status["state"])
    static = meta.pop("static", None)
    static_cols = None
    if static is not None:
        static_cols = ([entry["agent"] for entry in static], [entry["time"] for entry in static])
    try:
        log = EncounterLog.from_records(
            t, ids[0], ids[1], status=status_cols, static=static_cols, meta=meta,
            source={"events": str(events_path), "status": str(status_path), "static": f"{meta_path} static"},
            event_rows=event_rows, status_rows=status_rows,
        )
    except InputError as exc:
        tables = {str(events_path): (events, event_rows), str(status_path): (status, status_rows)}
        raise _as_written(exc, tables) from None
    if meta.get("agent_ids") is None and meta.get("agent_count") is None:
        _refuse_unmatched_status(log, status_path, events_path)
    if "duration" in meta and meta["duration"] < log.last_time:
        raise InputError(f"key 'duration' is {meta['duration']:g} s but the log runs to t = {log.last_time:g} s",
                         file=str(meta_path), column="duration", value=meta["duration"])
    return log


def _as_written(exc: InputError, tables: dict) -> InputError:
    """``exc`` quoting its value as the file spells it (the log checks parsed numbers and
    IDs: ``-1`` would be quoted as ``-1.0``, ``7.0`` as ``7``).  ``tables``: file name ->
    (columns, source row of each value) of the files read."""
    columns, rows = tables.get(exc.file, (None, None))
    if columns is None or exc.row is None or exc.value is None or exc.column not in columns:
        return exc
    value = columns[exc.column][int(np.searchsorted(rows, exc.row))].as_py()
    return InputError(exc.reason, file=exc.file, row=exc.row, column=exc.column, value=value)


def _refuse_unmatched_status(log: EncounterLog, status_path, events_path) -> None:
    """Without a declared agent set, a status file none of whose agents is in any event
    (while there are events) spells its IDs differently from the events: refused."""
    if not (log.n_events and len(log.status_agent)):
        return
    met = np.zeros(log.n_agents, bool)
    met[log.a] = met[log.b] = True
    if not met[log.status_agent].any():
        example = log.ids_of(log.status_agent[:1])[0]
        raise InputError(f"none of its agents appears in {events_path.name} (are the IDs written the same way in "
                         f"both files?)", file=str(status_path), column="agent",
                         value=int(example) if isinstance(example, np.integer) else example)


def read_truth(directory) -> dict[str, np.ndarray] | None:
    """Ground truth per event (``truth.<fmt>``) as numpy arrays, or None if absent.

    Keys ``t, a, b, xa, ya, xb, yb`` (float64 times and positions, IDs as in the log)
    plus any extra columns of the file.
    """
    found = _read_ground_truth(directory, "truth", TRUTH_COLUMNS, ("a", "b"), ("xa", "ya", "xb", "yb"))
    if found is None:
        return None
    _, table, out = found
    out.update(_extra_columns(table, out))
    return out


def read_trajectories(directory) -> dict[str, np.ndarray] | None:
    """Ground-truth trajectories (``trajectories.<fmt>``) as numpy arrays, or None.

    Keys ``t, x, y`` (float64), ``agent`` (IDs as in the log), ``state`` (int8 codes
    into STATES) when the file has it, plus any extra columns.
    """
    found = _read_ground_truth(directory, "trajectories", TRAJECTORY_COLUMNS, ("agent",), ("x", "y"))
    if found is None:
        return None
    path, table, out = found
    if "state" in table:
        out["state"] = parse_states(table["state"], str(path))
    out.update(_extra_columns(table, out))
    return out


def _read_ground_truth(directory, name: str, columns, id_columns, position_columns):
    """(path, table, arrays) of the ground-truth table ``name.<fmt>``, or None if absent:
    ``t`` and the positions as float64, the ID columns as the log reads IDs."""
    directory = _log_dir(directory)
    path = _find_table(directory, name)
    if path is None:
        return None
    table, rows = _read_table(path, columns, keep_all=True)
    declared = _read_meta(directory / "meta.json").get("agent_ids")
    ids = _id_arrays([(table[col], path, col, rows) for col in id_columns], declared=declared)
    out = {"t": _number_column(table["t"], path, "t", "time", rows)}
    out.update({col: _id_numpy(values, path, col, rows) for col, values in zip(id_columns, ids)})
    for col in position_columns:
        out[col] = _number_column(table[col], path, col, "position", rows)
    return path, table, out


GROUND_TRUTH_META_KEYS = ("simulation", "seed")
"""``meta.json`` keys of a simulated log that a deployment would not have: the
simulator's record (it holds the arena's Betti numbers) and its seed."""


def strip_ground_truth(src_dir, dst_dir) -> None:
    """Copy a log folder without its ground truth.

    ``dst_dir`` gets ``events.*``, ``status.*`` and ``meta.json`` without its
    ``GROUND_TRUTH_META_KEYS`` -- no ``arena.geojson``, ``truth.*``, ``trajectories.*`` and no
    file outside the contract.  Used to prove that ``swarmtopo map`` needs nothing else.
    ``dst_dir`` must not exist yet or be empty.
    """
    src, dst = _log_dir(src_dir), Path(dst_dir)
    if dst.exists() and (not dst.is_dir() or any(dst.iterdir())):
        raise InputError("destination must be a new or empty folder", file=str(dst))
    make_folder(dst)
    for stem in ("events", "status"):
        path = _find_table(src, stem, required=stem == "events")
        if path is not None:
            _atomic_write(dst / path.name, lambda tmp, path=path: shutil.copyfile(path, tmp))
    if (src / "meta.json").is_file():
        meta = read_json(src / "meta.json")
        if isinstance(meta, dict):
            for key in GROUND_TRUTH_META_KEYS:
                meta.pop(key, None)
        write_json(meta, dst / "meta.json")


# -- arenas and JSON -----------------------------------------------------------------------
def read_arena(path) -> Arena:
    """Read an arena from a GeoJSON file (Polygon, MultiPolygon, Feature or FeatureCollection)."""
    return Arena.from_geojson(read_json(path), source=str(path))


def write_arena(arena: Arena, path) -> Path:
    """Write an arena as a GeoJSON Feature; returns the path."""
    return write_json(arena.to_geojson(), path)


def read_json(path) -> Any:
    """Parse a JSON file; errors name the file and the line and column of a syntax error."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError("file not found", file=str(path)) from None
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", file=str(path)) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({_os_reason(exc)})", file=str(path)) from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"invalid JSON: {exc.msg} (line {exc.lineno}, column {exc.colno})", file=str(path)) from None


def write_json(obj, path) -> Path:
    """Write JSON with sorted keys and 2-space indent (byte-stable); returns the path.

    numpy scalars and arrays are written as plain numbers and lists, paths as text;
    NaN and infinities are refused (they are not JSON: pass ``jsonable(obj)`` to
    write them as ``null`` / ``"inf"`` / ``"-inf"``).
    """
    path = Path(path)
    try:
        text = json.dumps(obj, sort_keys=True, indent=2, allow_nan=False, default=_builtin)
    except ValueError as exc:
        raise InputError(f"cannot write JSON: {exc}", file=str(path)) from None
    _atomic_write(path, lambda tmp: tmp.write_text(text + "\n", encoding="utf-8"))
    return path


def jsonable(obj) -> Any:
    """``obj`` as plain JSON data: dict (keys made ``str``), list, str, int, float, bool, None.

    Recursively: dicts -> dicts with ``str(key)`` keys, lists / tuples / numpy arrays ->
    lists, numpy scalars -> int / float / bool, paths -> str, and non-finite floats ->
    ``"inf"``, ``"-inf"`` or ``None`` (NaN).  Anything else raises TypeError.  Use it
    for data that may hold infinities (``tau_stop = inf``, open intervals);
    :func:`write_json` alone refuses them.
    """
    if isinstance(obj, dict):
        return {k if isinstance(k, str) else str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, (np.ndarray, np.generic, Path)):
        return jsonable(_builtin(obj))
    if obj is None or isinstance(obj, (str, bool)):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        if math.isfinite(obj):
            return float(obj)
        return None if math.isnan(obj) else ("inf" if obj > 0 else "-inf")
    raise TypeError(f"object of type {type(obj).__name__} is not JSON serializable")


# -- writing helpers -----------------------------------------------------------------------
def _meta_for(log: EncounterLog) -> dict:
    """log.meta plus ``static`` and a declaration of exactly the log's agents:
    ``agent_count`` if the IDs are the integers 0 .. n-1, else ``agent_ids``."""
    meta = {k: v for k, v in log.meta.items() if k not in ("agent_count", "agent_ids")}
    meta["static"] = [{"agent": _json_id(a), "time": float(t)}
                      for a, t in zip(log.ids_of(log.static_agent), log.static_time)]
    ids = log.agent_ids
    if ids.dtype.kind == "i" and np.array_equal(ids, np.arange(len(ids))):
        meta["agent_count"] = log.n_agents
    else:
        meta["agent_ids"] = [_json_id(v) for v in ids]
    return meta


def _truth_columns(log: EncounterLog, truth: dict, ids_a, ids_b) -> dict:
    missing = [c for c in TRUTH_COLUMNS[3:] if c not in truth]
    if missing:
        raise ValueError(f"truth lacks column(s) {', '.join(missing)}")
    n = log.n_events
    for name, values in truth.items():
        if len(values) != n:
            raise ValueError(f"truth[{name!r}] has {len(values)} rows; the log has {n} events")
    if "t" in truth and not np.array_equal(np.asarray(truth["t"], float), log.t):
        raise ValueError("truth['t'] is not aligned with the log's events (canonical order)")
    for name, codes, ids in (("a", log.a, ids_a), ("b", log.b, ids_b)):
        if name in truth:
            given = np.asarray(truth[name])
            if not (np.array_equal(given, codes) or np.array_equal(given, ids)):
                raise ValueError(f"truth[{name!r}] is not aligned with the log's events (canonical order)")
    columns = {"t": log.t, "a": ids_a, "b": ids_b}
    columns.update({k: v for k, v in truth.items() if k not in columns})
    return columns


def _trajectory_columns(trajectories: dict) -> dict:
    missing = [c for c in TRAJECTORY_COLUMNS if c not in trajectories]
    if missing:
        raise ValueError(f"trajectories lack column(s) {', '.join(missing)}")
    columns = dict(trajectories)
    if "state" in columns:
        state = np.asarray(columns["state"])
        if state.dtype.kind in "iu":
            columns["state"] = state_labels(state)
    return columns


def _write_table(columns: dict, path: Path) -> Path:
    table = pa.table({name: _arrow_column(values) for name, values in columns.items()})
    if path.suffix == ".csv":
        _atomic_write(path, lambda tmp: pcsv.write_csv(table, tmp))
    else:
        _atomic_write(path, lambda tmp: pq.write_table(table, tmp))
    return path


def _arrow_column(values) -> pa.Array:
    arr = np.asarray(values)
    if arr.dtype.kind in "OU":
        return pa.array(arr.astype(object), type=pa.string())
    return pa.array(arr)


def make_folder(directory: Path) -> None:
    """Create ``directory`` (and its parents); InputError naming it if that fails."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        reason = "a file of that name exists" if directory.is_file() else _os_reason(exc)
        raise InputError(f"cannot create the output folder ({reason})", file=str(directory)) from None


def _atomic_write(path: Path, write) -> None:
    """Write through a temporary file in the same folder, then rename over ``path``.

    Raises InputError naming ``path`` if the file system refuses (no such folder, a
    folder of that name, no permission, disk full).
    """
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        try:
            write(tmp)
            os.replace(tmp, path)
        finally:
            tmp.unlink(missing_ok=True)
    except OSError as exc:
        raise InputError(f"cannot write file ({_os_reason(exc)})", file=str(path)) from None


def _os_reason(exc: OSError) -> str:
    return exc.strerror or str(exc)


def _json_id(value):
    return int(value) if isinstance(value, (int, np.integer)) else str(value)


def _builtin(obj):
    """numpy scalar / array or path -> the Python int, float, bool, list or str (the
    ``default`` of json.dumps: called only for objects json cannot write itself)."""
    if isinstance(obj, (np.ndarray, np.generic)):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"object of type {type(obj).__name__} is not JSON serializable")


# -- reading helpers -----------------------------------------------------------------------
def _not_a_folder(path: Path) -> None:
    """A log file that is a folder is refused, not skipped as absent."""
    if path.is_dir():
        raise InputError("is a folder, not a log file", file=str(path))


def _log_dir(directory) -> Path:
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError("is a file, not a log folder" if directory.exists() else "log folder not found",
                         file=str(directory))
    return directory


def _find_table(directory: Path, stem: str, *, required: bool = False) -> Path | None:
    for fmt in FORMATS:
        _not_a_folder(directory / f"{stem}.{fmt}")
    found = [directory / f"{stem}.{fmt}" for fmt in FORMATS if (directory / f"{stem}.{fmt}").is_file()]
    if len(found) > 1:
        raise InputError(f"both {found[0].name} and {found[1].name} exist; keep one", file=str(directory))
    if not found:
        if required:
            raise InputError(f"no {stem}.csv or {stem}.parquet in the log folder", file=str(directory))
        return None
    return found[0]


def _read_table(path: Path, required: tuple[str, ...], *,
                keep_all: bool = False) -> tuple[dict[str, pa.Array], np.ndarray]:
    """Columns of a CSV / Parquet file by (stripped) name, and the 1-based data row of
    each of their values.

    CSV: the ``required`` columns are read as text (so IDs keep leading zeros and a bad
    time can be located), times and states trimmed of surrounding blanks (ID columns
    are trimmed by :func:`_id_arrays`); other columns are inferred.  Blank lines count
    as rows (as ``swarmtopo ingest`` counts them) and are dropped.  Only ``required``
    columns (plus ``state``) are read unless ``keep_all``.
    """
    if path.suffix == ".csv":
        names = _csv_header(path)
    else:
        try:
            names = pq.read_schema(path).names
        except (pa.ArrowException, OSError) as exc:
            raise InputError(f"cannot read Parquet file ({exc})", file=str(path)) from None
    by_name = {}
    for raw in names:
        if raw.strip() in by_name and (keep_all or raw.strip() in (*required, "state")):
            raise InputError("column appears twice", file=str(path), column=raw.strip())
        by_name.setdefault(raw.strip(), raw)  # a name repeated among the ignored columns is never read
    missing = [c for c in required if c not in by_name]
    if missing:
        raise InputError(f"missing column '{missing[0]}'; found columns: {', '.join(map(repr, by_name)) or 'none'}",
                         file=str(path), column=missing[0])
    text = [c for c in dict.fromkeys((*required, "state")) if c in by_name]
    wanted = list(by_name) if keep_all else text
    if path.suffix == ".csv":
        table = _read_csv(path, [by_name[c] for c in wanted], {by_name[c] for c in text})
    else:
        try:
            table = pq.read_table(path, columns=[by_name[c] for c in wanted])
        except (pa.ArrowException, OSError) as exc:
            raise InputError(f"cannot read Parquet file ({exc})", file=str(path)) from None
    out = {}
    for name in wanted:
        col = table.column(by_name[name]).combine_chunks()
        if pa.types.is_dictionary(col.type):
            col = col.dictionary_decode()
        if path.suffix == ".csv" and name in text and name not in _ID_COLUMNS:
            col = pc.utf8_trim_whitespace(col)
        out[name] = col
    rows = np.arange(1, table.num_rows + 1)
    if path.suffix == ".csv":
        blank = np.logical_and.reduce([pc.equal(pc.utf8_length(pc.utf8_trim_whitespace(out[c])), 0)
                                       .to_numpy(zero_copy_only=False) for c in text])
        if blank.any():
            keep = pa.array(~blank)
            out, rows = {name: col.filter(keep) for name, col in out.items()}, rows[~blank]
    return out, rows


def _csv_header(path: Path) -> list[str]:
    try:
        with open(path, "rb") as f:
            refuse_binary(path, f.read(SNIFF_BYTES))
        with pcsv.open_csv(path, read_options=pcsv.ReadOptions(block_size=1 << 16)) as reader:
            return reader.schema.names
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text: the header row holds the byte 0x{exc.object[exc.start]:02x} "
                         f"({exc.reason})", file=str(path)) from None
    except pa.ArrowInvalid as exc:
        raise _csv_problem(path, exc) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({_os_reason(exc)})", file=str(path)) from None


def refuse_binary(path: Path, head: bytes) -> None:
    """InputError naming ``path`` if ``head``, the first block of a text file, starts with
    the byte-order mark of UTF-16 / UTF-32, is gzip, or holds a NUL byte (binary data: a
    spreadsheet, an archive, UTF-16 without a byte-order mark)."""
    for bom, encoding in _OTHER_ENCODINGS:
        if head.startswith(bom):
            raise InputError(f"not UTF-8 text: it starts with the byte-order mark of {encoding}; save it as UTF-8",
                             file=str(path))
    if head.startswith(GZIP_MAGIC):
        raise InputError("gzip-compressed: gunzip it first", file=str(path))
    nul = head.find(b"\0")
    if nul >= 0:
        line = head.count(b"\n", 0, nul) + 1
        raise InputError(f"binary data, not text: line {line} holds a NUL byte (save the table as UTF-8 CSV)",
                         file=str(path))


def non_utf8_problem(blocks) -> str | None:
    """Where the bytes ``blocks`` (an iterable of consecutive blocks) stop being UTF-8
    text, as a message naming the line and the byte; None if they are UTF-8 throughout."""
    line, tail = 1, b""
    for block in itertools.chain(blocks, [b""]):  # b"": the end, where a cut character is an error
        data = tail + block
        try:
            data.decode("utf-8")
            tail = b""
        except UnicodeDecodeError as exc:
            if not (block and exc.reason == "unexpected end of data"):
                line += data.count(b"\n", 0, exc.start)
                return f"not UTF-8 text: line {line} holds the byte 0x{data[exc.start]:02x}; save the file as UTF-8"
            data, tail = data[:exc.start], data[exc.start:]  # a character cut by the block's end
        line += data.count(b"\n")
    return None


def _read_csv(path: Path, columns: list[str], text: set[str]) -> pa.Table:
    convert = pcsv.ConvertOptions(include_columns=columns, column_types={c: pa.string() for c in text},
                                  strings_can_be_null=False)
    try:  # blank lines are read, so that rows are numbered as the file's data lines
        return pcsv.read_csv(path, parse_options=pcsv.ParseOptions(ignore_empty_lines=False),
                             convert_options=convert)
    except pa.ArrowInvalid as exc:
        if "invalid UTF8" in str(exc):
            raise _not_utf8(path, columns, text) from None
        raise _csv_problem(path, exc) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({_os_reason(exc)})", file=str(path)) from None


def _not_utf8(path: Path, columns: list[str], text: set[str]) -> InputError:
    """The error for a text column that is not UTF-8, at its first bad row."""
    try:
        raw = pcsv.read_csv(path, parse_options=pcsv.ParseOptions(ignore_empty_lines=False),
                            convert_options=pcsv.ConvertOptions(
            include_columns=columns, column_types={c: pa.binary() for c in text}))
    except pa.ArrowInvalid as exc:  # a row that does not parse either
        return _csv_problem(path, exc)
    bad = []
    for name in columns:
        if name in text:
            col = raw.column(name).combine_chunks()
            try:
                col.cast(pa.string())
            except pa.ArrowInvalid:
                i = _first_uncastable(col, pa.string())
                bad.append((i, name, col[i].as_py()))
    if not bad:
        return InputError("not UTF-8 text", file=str(path))
    i, name, value = min(bad)
    return InputError("not UTF-8 text", file=str(path), row=i + 1, column=name.strip(), value=value)


def _csv_problem(path: Path, exc: Exception) -> InputError:
    """pyarrow's parse error, with the 1-based data row and its text found by a
    single-threaded re-read; or, in a file that is not UTF-8 throughout (pyarrow cannot
    hand such a row to Python), the first byte that is not."""
    try:
        with open(path, "rb") as f:
            not_utf8 = non_utf8_problem(iter(lambda: f.read(1 << 22), b""))
    except OSError as err:
        return InputError(f"cannot read file ({_os_reason(err)})", file=str(path))
    if not_utf8:
        return InputError(not_utf8, file=str(path))
    bad = []

    def record(row):
        bad.append(row)
        return "error"

    try:
        pcsv.read_csv(path, read_options=pcsv.ReadOptions(use_threads=False),
                      parse_options=pcsv.ParseOptions(invalid_row_handler=record))
    except pa.ArrowInvalid:
        pass
    if bad and bad[0].number is not None:  # number counts the header as row 1
        return InputError(f"cannot parse CSV (expected {bad[0].expected_columns} columns, found "
                          f"{bad[0].actual_columns})", file=str(path), row=bad[0].number - 1, value=bad[0].text)
    # pyarrow >= 26.0.1 prefixes its own "Row #N: " (a file line, header included): dropped, as
    # every message here counts data rows
    reason = re.sub(r"^Row #\d+: ", "", str(exc).removeprefix("CSV parse error: "))
    return InputError(f"cannot parse CSV ({reason})", file=str(path))


def _number_column(col: pa.Array, path: Path, name: str, what: str, rows: np.ndarray) -> np.ndarray:
    """float64 column; text is parsed, and the first bad value is located exactly (at its
    source row: ``rows[i]`` is the 1-based data row of value ``i``)."""
    kind = col.type
    if pa.types.is_string(kind) or pa.types.is_large_string(kind):
        try:
            col = pc.cast(col, pa.float64())
        except pa.ArrowInvalid:
            i = _first_uncastable(col, pa.float64())
            value = col[i].as_py()
            problem = f"{what} is missing" if value == "" else f"{what} is not a number"
            raise InputError(problem, file=str(path), row=int(rows[i]), column=name, value=value) from None
    elif pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_decimal(kind):
        coarse = coarse_time(col) if what == "time" else None
        if coarse is not None:
            i, problem = coarse
            raise InputError(problem, file=str(path), row=int(rows[i]), column=name, value=col[i].as_py())
        col = pc.cast(col, pa.float64(), safe=False)  # integers beyond 2^53 round; times that large are refused
    elif pa.types.is_null(kind) and len(col) == 0:
        col = pa.array([], pa.float64())
    else:
        raise InputError(f"{what} must be a number, not {kind}", file=str(path),
                         row=int(rows[0]) if len(rows) else None, column=name,
                         value=col[0].as_py() if len(col) else None)
    if col.null_count:
        i = int(np.argmax(col.is_null().to_numpy(zero_copy_only=False)))
        raise InputError(f"{what} is missing", file=str(path), row=int(rows[i]), column=name)
    return col.to_numpy(zero_copy_only=False)


def coarse_time(col: pa.Array) -> tuple[int, str] | None:
    """(index of the largest time, message) if ``col`` is a float16 / float32 column whose
    spacing at its largest finite value exceeds ``MAX_TIME_RESOLUTION``; else None (the
    column is read as float64, exactly)."""
    if not (pa.types.is_float16(col.type) or pa.types.is_float32(col.type)):
        return None
    values = col.fill_null(0).to_numpy(zero_copy_only=False)
    finite = np.isfinite(values)
    if not finite.any():
        return None
    i = int(np.argmax(np.where(finite, np.abs(values), -1)))
    spacing = float(np.spacing(np.abs(values[i])))
    if spacing <= MAX_TIME_RESOLUTION:
        return None
    return i, (f"a {col.type} time column tells times apart only to {spacing:g} s at its largest value (the "
               f"file's times were rounded when written); write them as float64 or integers")


def _first_uncastable(col: pa.Array, to_type) -> int:
    """Index of the first value that does not cast; bisection, so O(n) vectorised work."""
    lo, hi = 0, len(col)  # invariant: the first bad value lies in col[lo:hi]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        try:
            pc.cast(col.slice(lo, mid - lo), to_type)
        except pa.ArrowInvalid:
            hi = mid
        else:
            lo = mid
    return lo


def _id_arrays(columns: list[tuple[pa.Array, Path, str, np.ndarray]], *, declared) -> list:
    """Give all ID columns ``(column, file, name, source rows)`` of a folder one kind:
    int64 numpy arrays, or pyarrow text.

    Integer if every column is integer-typed (floats are left to the log's integrality
    check) or, in CSV, holds only IDs written as integers (:func:`integer_ids`), and meta
    declares no text IDs (``declared``: its ``agent_ids``).  Text columns of a Parquet
    file are text whatever they hold; a column that cannot be read as text (a list, a
    struct) is refused.  A CSV ID is trimmed of surrounding blanks unless ``declared``
    lists it as written (so that a log's padded text IDs read back exactly); two text IDs
    that trimming would merge are refused.
    """
    declared = list(declared or [])
    kept = pa.array([str(v) for v in declared], pa.string())
    checked = []  # (column, is numeric, from a CSV file)
    written = []  # (CSV column as written, file, name, source rows)
    for col, path, name, rows in columns:
        if col.null_count:
            i = int(np.argmax(col.is_null().to_numpy(zero_copy_only=False)))
            raise InputError("agent ID is missing", file=str(path), row=int(rows[i]), column=name)
        numeric = pa.types.is_integer(col.type) or pa.types.is_floating(col.type)
        if not numeric:
            try:
                col = pc.cast(col, pa.string())
            except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
                raise InputError(f"agent IDs must be integers or text, not {col.type}", file=str(path),
                                 column=name) from None
        csv = path.suffix == ".csv"
        if csv:
            written.append((col, path, name, rows))
            col = _trimmed_ids(col, kept)
        checked.append((col, numeric, csv))
    declared_text = any(isinstance(v, str) for v in declared)
    if not declared_text and all(numeric or csv for _, numeric, csv in checked):  # CSV has no types
        texts = integer_ids([col for col, numeric, _ in checked if not numeric])
        if texts is not None:
            texts = iter(texts)
            try:
                ints = [col if pa.types.is_floating(col.type) else pc.cast(col, pa.int64()) if numeric else next(texts)
                        for col, numeric, _ in checked]
            except pa.ArrowInvalid:  # an unsigned integer beyond int64: every ID is text
                pass
            else:
                return [col.to_numpy(zero_copy_only=False) for col in ints]
    refuse_merged_by_trimming(written, kept)
    return [pc.cast(col, pa.string()) if numeric else col for col, numeric, _ in checked]


def _trimmed_ids(col: pa.Array, kept: pa.Array) -> pa.Array:
    """CSV ID text trimmed of surrounding blanks, except the IDs in ``kept`` (as written)."""
    return pc.if_else(pc.is_in(col, value_set=kept), col, pc.utf8_trim_whitespace(col))


def refuse_merged_by_trimming(written: list[tuple[pa.Array, Path, str, np.ndarray]], kept: pa.Array) -> None:
    """InputError at the first padded spelling of an ID that another spelling in the CSV
    ID columns ``written`` also trims to: trimming would merge two distinct text IDs."""
    if not written:
        return
    spellings = pc.unique(pa.concat_arrays([col for col, *_ in written]))
    ids = _trimmed_ids(spellings, kept)
    enc = pc.dictionary_encode(ids)
    if len(enc.dictionary) == len(spellings):
        return
    index = enc.indices.to_numpy(zero_copy_only=False)
    merged = np.bincount(index, minlength=len(enc.dictionary))[index] > 1
    padded = spellings.filter(pa.array(merged & ~pc.equal(spellings, ids).to_numpy(zero_copy_only=False)))
    for col, path, name, rows in written:
        hit = pc.is_in(col, value_set=padded).to_numpy(zero_copy_only=False)
        if hit.any():
            i = int(np.argmax(hit))
            trimmed = col[i].as_py().strip()
            raise InputError(f"agent ID differs from the ID {trimmed!r} only in the blanks around it, which a CSV "
                             f"field drops: the two would merge into one agent (spell each agent one way, or use "
                             f"Parquet, which keeps blanks)", file=str(path), row=int(rows[i]), column=name,
                             value=col[i].as_py())


def integer_ids(columns: list[pa.Array]) -> list[pa.Array] | None:
    """Text ID columns as int64, if every ID is written as an integer (``12``, or ``12.0``
    for the same agent; not ``012`` or ``-0``) and fits int64; else None.  Exact: the
    integer part is parsed as text, never through a float.  The text work is done once per
    distinct ID."""
    encoded = [pc.dictionary_encode(col) for col in columns]
    if not all(pc.all(pc.match_substring_regex(enc.dictionary, _INTEGER_TEXT)).as_py() is not False
               for enc in encoded):
        return None
    try:
        return [pc.take(pc.cast(pc.replace_substring_regex(enc.dictionary, r"\.0+$", ""), pa.int64()), enc.indices)
                for enc in encoded]
    except pa.ArrowInvalid:  # beyond int64: every ID is text
        return None


def _id_numpy(ids, path: Path, column: str, rows: np.ndarray) -> np.ndarray:
    """IDs of ``path``'s ``column`` as numpy: int64 (float IDs checked whole, as the log's
    are), or an object array of str (an ID holding a NUL refused, as the log's are); errors
    name the file row ``rows[i]``."""
    if isinstance(ids, np.ndarray):
        return float_ids(ids, str(path), column, rows) if ids.dtype.kind == "f" else ids
    refuse_nul_ids(ids, str(path), column, rows)
    return ids.to_numpy(zero_copy_only=False).astype(object)


def _extra_columns(table: dict[str, pa.Array], known: dict) -> dict[str, np.ndarray]:
    return {name: col.to_numpy(zero_copy_only=False) for name, col in table.items() if name not in known}


NUMBER_META_KEYS = {"r_d": "detection radius, mm", "v_c": "random-walk speed, mm/s",
                    "v_p": "wall-following speed, mm/s", "dt": "time step, s", "duration": "seconds recorded"}
"""Keys of meta.json that, when present, must be finite numbers, positive (duration: >= 0)."""


def _read_meta(path: Path) -> dict:
    """meta.json as a dict ({} if absent), with ``static`` and the ID keys checked."""
    _not_a_folder(path)
    if not path.is_file():
        return {}
    meta = read_json(path)
    if not isinstance(meta, dict):
        raise InputError(f"meta.json must hold a JSON object, not {type(meta).__name__}", file=str(path))
    static = meta.get("static")
    if static is not None:
        if not isinstance(static, list):
            raise InputError("key 'static' must be a list of {\"agent\": id, \"time\": t}", file=str(path),
                             value=static)
        for i, entry in enumerate(static):
            if not (isinstance(entry, dict) and "agent" in entry and "time" in entry):
                raise InputError(f"key 'static': entry {i + 1} must be an object with 'agent' and 'time'",
                                 file=str(path), value=entry)
    units = meta.get("units")
    if units is not None and not isinstance(units, dict):
        raise InputError("key 'units' must be an object such as {\"time\": \"s\", \"length\": \"mm\"}",
                         file=str(path), column="units", value=units)
    if isinstance(units, dict) and units.get("time", "s") != "s":
        raise InputError("key 'units.time' must be \"s\": swarmtopo reads times in seconds", file=str(path),
                         column="units.time", value=units["time"])
    if "format" in meta and meta["format"] != LOG_FORMAT:
        raise InputError(f"key 'format' is not {LOG_FORMAT!r}, the only log format this swarmtopo reads",
                         file=str(path), column="format",
                         value=meta["format"] if isinstance(meta["format"], str) else json.dumps(meta["format"]))
    for key, what in NUMBER_META_KEYS.items():
        value = meta.get(key)
        if key in meta and (isinstance(value, bool) or not isinstance(value, (int, float))
                            or not math.isfinite(value) or value < 0 or (value == 0 and key != "duration")):
            raise InputError(f"key '{key}' must be a {'non-negative' if key == 'duration' else 'positive'} number "
                             f"({what})", file=str(path), column=key, value=value)
    count = meta.get("agent_count")
    if count is not None and (isinstance(count, bool) or not isinstance(count, int) or count < 0):
        raise InputError("key 'agent_count' must be a non-negative integer", file=str(path), value=count)
    ids = meta.get("agent_ids")
    if ids is not None:
        if not isinstance(ids, list):
            raise InputError("key 'agent_ids' must be a list of IDs", file=str(path), value=ids)
        for i, v in enumerate(ids):
            if isinstance(v, bool) or not isinstance(v, (int, str)) or (isinstance(v, str) and not v.strip()):
                raise InputError(f"key 'agent_ids': entry {i + 1} must be an integer or a non-empty text",
                                 file=str(path), value=v)
        seen: set[str] = set()
        for v in ids:
            if str(v) in seen:
                raise InputError("key 'agent_ids' lists an agent twice", file=str(path), column="agent_ids", value=v)
            seen.add(str(v))
        if count is not None and count != len(ids):
            raise InputError(f"key 'agent_count' is {count} but 'agent_ids' lists {len(ids)} agents",
                             file=str(path), value=count)
    return meta

