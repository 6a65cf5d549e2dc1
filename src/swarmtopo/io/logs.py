"""Log folders in and out: events, status, meta.json and the simulator's ground truth.

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
``beacon.<fmt>``       ``t, x, y``: the track of a          optional (beacon-led
                       localized leader (mm), with          exploration,
                       ``meta.json`` ``leash`` (R, mm)      docs/exploration.md)
=====================  ===================================  ==========================

``fmt`` is ``csv``, ``csv.gz`` (gzip-compressed CSV, read only) or ``parquet``, one of
them per table (two versions of one table are refused); text is UTF-8, and a ``.csv``
file holding gzip data is refused (name it ``.csv.gz``).  Times are in seconds,
positions in millimetres.  The ``meta.json`` keys ``format`` (:data:`LOG_FORMAT`, this
layout) and ``version`` (of the swarmtopo that made the log) are optional; simulated
logs carry both, and :func:`read_log` refuses a folder of another ``format``.

Agent IDs are read by :func:`.tables.id_columns`: integers or text, one kind for the
whole folder (``meta.json``'s text ``agent_ids`` make them text), blanks round a CSV ID
dropped unless ``agent_ids`` lists the ID with them (so padded text IDs that
:func:`write_log` wrote read back exactly).  Without ``agent_ids`` / ``agent_count``,
every agent of the status file must appear in the events: an agent that met nobody is
declared, never guessed.  CSV blank lines count as data rows and are skipped.  Extra
columns are ignored by :func:`read_log` (a name they repeat, such as the empty names
of trailing empty columns, too) and kept by :func:`read_truth` /
:func:`read_trajectories`.

Tables are parsed by :mod:`.tables` (pyarrow's multi-threaded readers, ID columns
dictionary-encoded): 10^6 events read in about a second from CSV and half a second
from Parquet.  Every error a file can cause is an :class:`~.errors.InputError` naming
the file, the 1-based data row, the column and the value; so is a file system refusing
a read or a write.
"""

from __future__ import annotations

import json
import math
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pcsv
import pyarrow.parquet as pq

from .._json import atomic_write, os_reason
from .._json import read_json, write_json
from ..arena import Arena
from ..beacon import BEACON_COLUMNS, BeaconTrack
from ..errors import InputError, SwarmtopoError
from ..log import LOG_FORMAT, EncounterLog, float_ids, parse_states, refuse_nul_ids, state_labels
from .arenas import write_arena
from .tables import (IdColumn, blank_rows, csv_header, existing_file, find_columns, id_columns, is_gzip,
                     number_column, parquet_file, read_csv, read_error, read_parquet, trim)

FORMATS: tuple[str, ...] = ("csv", "parquet")
"""Formats :func:`write_log` writes."""
TABLE_SUFFIXES = (".csv", ".csv.gz", ".parquet")
"""File name endings of a table that :func:`read_log` reads."""
EVENT_COLUMNS = ("t", "a", "b")
STATUS_COLUMNS = ("t", "agent", "state")
TRUTH_COLUMNS = ("t", "a", "b", "xa", "ya", "xb", "yb")
TRAJECTORY_COLUMNS = ("t", "agent", "x", "y")
GROUND_TRUTH_FILES = ("arena.geojson",
                      *(f"{stem}{suffix}" for stem in ("truth", "trajectories") for suffix in TABLE_SUFFIXES))
"""Files that only a simulator can write; ``swarmtopo map`` reads them for pictures only, never to estimate."""

_TABLE_STEMS = ("events", "status", "truth", "trajectories", "beacon")
_ID_COLUMNS = ("a", "b", "agent")


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
    if log.beacon is not None:
        tables["beacon"] = {"t": log.beacon.t, "x": log.beacon.x, "y": log.beacon.y}

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
                raise InputError(f"cannot delete an outdated log file ({os_reason(exc)})", file=str(path)) from None
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
    names = [f"{stem}{suffix}" for stem in _TABLE_STEMS for suffix in TABLE_SUFFIXES] + ["meta.json", "arena.geojson"]
    return [Path(directory) / name for name in names if (Path(directory) / name).is_file()]


def read_log(directory) -> EncounterLog:
    """Read a log folder: ``events.<fmt>`` is required, everything else optional.

    Only ``events``, ``status``, ``beacon`` and ``meta.json`` are read -- never ground truth.
    ``meta["static"]`` becomes the log's static agents; the rest of ``meta.json`` is
    ``log.meta``.  Unsorted events are sorted.

    Raises
    ------
    InputError
        Naming the file, the 1-based data row, the column and the value: missing
        file or column, unparsable CSV, non-numeric / NaN / negative / missing times,
        missing IDs, float IDs that are not whole numbers within int64, CSV text IDs
        that differ only in surrounding blanks, a == b, unknown states, IDs outside
        ``agent_ids`` / ``agent_count``, without them a status agent that never appears
        in the events, duplicate events, two status rows for one agent at one time,
        text that is not UTF-8, malformed ``meta.json`` or another ``format``; or when
        two versions of one table exist (``events.csv`` and ``events.parquet``).
    """
    directory = log_folder(directory)
    meta_path = directory / "meta.json"
    meta = _read_meta(meta_path)
    events_path = _find_table(directory, "events", required=True)
    status_path = _find_table(directory, "status")
    events, event_rows = _read_table(events_path, EVENT_COLUMNS)
    status, status_rows = _read_table(status_path, STATUS_COLUMNS) if status_path else (None, None)

    id_cols = [IdColumn(events[c], events_path, c, event_rows, _is_csv(events_path)) for c in ("a", "b")]
    if status is not None:
        id_cols.append(IdColumn(status["agent"], status_path, "agent", status_rows, _is_csv(status_path)))
    ids = id_columns(id_cols, declared=meta.get("agent_ids"))
    t = number_column(events["t"], events_path, "t", "time", event_rows)
    status_cols = unmet = None
    if status is not None:
        status_cols = (number_column(status["t"], status_path, "t", "time", status_rows), ids[2], status["state"])
        if meta.get("agent_ids") is None and meta.get("agent_count") is None:
            unmet = _unmet(*ids)
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
    if unmet is not None and unmet.any():
        i = int(np.argmax(unmet))
        hint = ("none of this file's agents does: are the IDs written the same way in both files?" if unmet.all()
                else "an agent that met nobody is declared in meta.json's agent_ids or agent_count")
        raise InputError(f"agent never appears in {events_path.name} ({hint})", file=str(status_path),
                         row=int(status_rows[i]), column="agent", value=status["agent"][i].as_py())
    if "duration" in meta and meta["duration"] < log.last_time:
        raise InputError(f"key 'duration' is {meta['duration']:g} s but the log runs to t = {log.last_time:g} s",
                         file=str(meta_path), column="duration", value=meta["duration"])
    beacon_path = _find_table(directory, "beacon")
    if beacon_path is not None:
        log = replace(log, beacon=read_beacon_table(beacon_path))
    return log


def read_beacon_table(path) -> BeaconTrack:
    """A leader's track from a ``t, x, y`` table (CSV, CSV.gz or Parquet; seconds, mm)."""
    path = Path(path)
    table, rows = _read_table(path, BEACON_COLUMNS)
    cols = [number_column(table[c], path, c, "time" if c == "t" else "position", rows) for c in BEACON_COLUMNS]
    return BeaconTrack.from_columns(*cols, source=str(path), rows=rows)


def _as_written(exc: InputError, tables: dict) -> InputError:
    """``exc`` quoting its value as the file spells it (the log checks parsed numbers and
    IDs: ``-1`` would be quoted as ``-1.0``, ``7.0`` as ``7``).  ``tables``: file name ->
    (columns, source row of each value) of the files read."""
    columns, rows = tables.get(exc.file, (None, None))
    if columns is None or exc.row is None or exc.value is None or exc.column not in columns:
        return exc
    value = columns[exc.column][int(np.searchsorted(rows, exc.row))].as_py()
    return InputError(exc.reason, file=exc.file, row=exc.row, column=exc.column, value=value)


def _unmet(a, b, agent) -> np.ndarray:
    """Mask of the status rows whose agent is in no event (IDs as :func:`.tables.id_columns` gives them)."""
    if isinstance(agent, np.ndarray):
        return ~np.isin(agent, np.concatenate([a, b]))
    return ~pc.is_in(agent, value_set=pa.concat_arrays([a, b])).to_numpy(zero_copy_only=False)


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


def _read_ground_truth(directory, name: str, columns, id_names, position_columns):
    """(path, table, arrays) of the ground-truth table ``name.<fmt>``, or None if absent:
    ``t`` and the positions as float64, the ID columns as the log reads IDs."""
    directory = log_folder(directory)
    path = _find_table(directory, name)
    if path is None:
        return None
    table, rows = _read_table(path, columns, keep_all=True)
    declared = _read_meta(directory / "meta.json").get("agent_ids")
    ids = id_columns([IdColumn(table[col], path, col, rows, _is_csv(path)) for col in id_names], declared=declared)
    out = {"t": number_column(table["t"], path, "t", "time", rows)}
    out.update({col: _id_numpy(values, path, col, rows) for col, values in zip(id_names, ids)})
    for col in position_columns:
        out[col] = number_column(table[col], path, col, "position", rows)
    return path, table, out


GROUND_TRUTH_META_KEYS = ("simulation", "seed")
"""``meta.json`` keys of a simulated log that a deployment would not have: the
simulator's record (it holds the arena's Betti numbers) and its seed."""


def strip_ground_truth(src_dir, dst_dir) -> None:
    """Copy a log folder without its ground truth.

    ``dst_dir`` gets ``events.*``, ``status.*``, ``beacon.*`` and ``meta.json`` without its
    ``GROUND_TRUTH_META_KEYS`` -- no ``arena.geojson``, ``truth.*``, ``trajectories.*`` and no
    file outside the contract.  Used to prove that ``swarmtopo map`` needs nothing else.
    ``dst_dir`` must not exist yet or be empty.
    """
    src, dst = log_folder(src_dir), Path(dst_dir)
    if dst.exists() and (not dst.is_dir() or any(dst.iterdir())):
        raise InputError("destination must be a new or empty folder", file=str(dst))
    make_folder(dst)
    for stem in ("events", "status", "beacon"):
        path = _find_table(src, stem, required=stem == "events")
        if path is not None:
            atomic_write(dst / path.name, lambda tmp, path=path: shutil.copyfile(path, tmp))
    if (src / "meta.json").is_file():
        meta = read_json(src / "meta.json")
        if isinstance(meta, dict):
            for key in GROUND_TRUTH_META_KEYS:
                meta.pop(key, None)
        write_json(meta, dst / "meta.json")


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
        atomic_write(path, lambda tmp: pcsv.write_csv(table, tmp))
    else:
        atomic_write(path, lambda tmp: pq.write_table(table, tmp))
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
        reason = "a file of that name exists" if directory.is_file() else os_reason(exc)
        raise InputError(f"cannot create the output folder ({reason})", file=str(directory)) from None


def _json_id(value):
    return int(value) if isinstance(value, (int, np.integer)) else str(value)


# -- reading helpers -----------------------------------------------------------------------
def log_folder(directory) -> Path:
    """``directory`` as a Path if it is a folder; a one-line InputError naming it if it is
    a file or missing."""
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError("is a file, not a log folder" if directory.exists() else "log folder not found",
                         file=str(directory))
    return directory


def _is_csv(path: Path) -> bool:
    return path.name.endswith((".csv", ".csv.gz"))


def _find_table(directory: Path, stem: str, *, required: bool = False) -> Path | None:
    """The one file of table ``stem`` (``events.csv``, ``.csv.gz`` or ``.parquet``), or None."""
    found = [existing_file(directory / f"{stem}{suffix}") for suffix in TABLE_SUFFIXES
             if (directory / f"{stem}{suffix}").exists()]
    if len(found) > 1:
        names = [p.name for p in found]
        listed = f"both {names[0]} and {names[1]}" if len(names) == 2 else f"{', '.join(names[:-1])} and {names[-1]}"
        raise InputError(f"{listed} exist; keep one", file=str(directory))
    if not found:
        if required:
            raise InputError(f"no {stem}.csv or {stem}.parquet (or {stem}.csv.gz) in the log folder",
                             file=str(directory))
        return None
    return found[0]


def _read_table(path: Path, required: tuple[str, ...], *,
                keep_all: bool = False) -> tuple[dict[str, pa.Array], np.ndarray]:
    """Columns of a CSV / Parquet file by (stripped) name, and the 1-based data row of
    each of their values.

    CSV: the ``required`` columns are read as text (so IDs keep leading zeros and a bad
    time can be located), times and states trimmed of surrounding blanks (ID columns
    are trimmed by :func:`.tables.id_columns`); other columns are inferred.  Blank lines
    count as rows (as ``swarmtopo ingest`` counts them) and are dropped.  Only
    ``required`` columns (plus ``state``) are read unless ``keep_all``.
    """
    csv = _is_csv(path)
    if csv:
        if path.suffix != ".gz" and _gzipped(path):
            raise InputError(f"gzip-compressed: gunzip it first, or name it {path.name}.gz", file=str(path))
        names = csv_header(path)
    else:
        pf = parquet_file(path)
        names = pf.schema_arrow.names
    by_name = find_columns(names, required, path, optional=("state",), every=keep_all)
    text = [c for c in dict.fromkeys((*required, "state")) if c in by_name]
    wanted = list(by_name) if keep_all else text
    if csv:
        table = read_csv(path, [by_name[c] for c in wanted], {by_name[c] for c in text})
    else:
        table = read_parquet(pf, [by_name[c] for c in wanted], path)
    out = {}
    for name in wanted:
        col = table.column(by_name[name]).combine_chunks()
        if pa.types.is_dictionary(col.type):
            col = col.dictionary_decode()
        if csv and name in text and name not in _ID_COLUMNS:
            col = trim(col)
        out[name] = col
    rows = np.arange(1, table.num_rows + 1)
    if csv:
        blank = blank_rows([out[c] if c not in _ID_COLUMNS else trim(out[c]) for c in text])
        if blank.any():
            keep = pa.array(~blank)
            out, rows = {name: col.filter(keep) for name, col in out.items()}, rows[~blank]
    return out, rows


def _gzipped(path: Path) -> bool:
    try:
        return is_gzip(path)
    except OSError as exc:
        raise read_error(path, exc) from None


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
                    "v_p": "wall-following speed, mm/s", "dt": "time step, s", "duration": "seconds recorded",
                    "leash": "leash R of a beacon-led swarm, mm"}
"""Keys of meta.json that, when present, must be finite numbers, positive (duration: >= 0)."""


def _read_meta(path: Path) -> dict:
    """meta.json as a dict ({} if absent), with ``static`` and the ID keys checked."""
    if not path.exists():
        return {}
    existing_file(path)
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

