"""Proximity traces in: CSV / Parquet tables, SocioPatterns and ONE connection events.

Every reader returns an :class:`~.log.EncounterLog` and an :class:`IngestReport`; none
prints or writes.  Files are read in blocks (pyarrow's streaming CSV reader, Parquet
record batches, or 4 MiB blocks of text split into lines in C), every check is a
vectorised pyarrow / numpy operation, and agent IDs stay pyarrow text until they are
dictionary-encoded: 10^6 rows never become 10^6 Python objects.  Bytes, UTF-8, CSV
headers and agent IDs are handled by :mod:`.tables`, as for log folders; this module
adds what is particular to traces (malformed lines skipped with ``skip_bad``, windows
merged, connections matched).

Formats
-------
``csv`` / ``parquet``
    One encounter per row, columns ``t, a, b`` (names configurable).  IDs are text;
    if every ID is written as an integer (``7`` or ``7.0``, not ``007``) they become
    integers.  A CSV file may be gzip-compressed; it must be UTF-8 throughout.
``sociopatterns``
    Lines ``t i j Ci Cj`` (or ``t i j``), fields separated by any blanks: agents
    ``i`` and ``j`` were in contact during the window ``(t - w, t]`` (w = 20 s in the
    SocioPatterns data).  Windows of one pair at ``t`` and ``t + w`` are one contact,
    so consecutive windows merge into one encounter; the encounter's time is the
    start of its first window, ``t_first - w`` (the paper's event is the *start* of a
    contact period).  A time below w would start before 0 and is a malformed line.
    Two windows of one pair further apart than w are two encounters.  The class
    labels ``Ci, Cj`` are not encounters; they go to ``meta["agent_classes"]``.
``one``
    The ONE simulator's connection events ``time CONN a b up|down``.  Each ``up`` of
    a pair that is not already up starts an encounter; a ``down`` closes it.  An
    ``up`` while the pair is up (no ``down`` between) is the same contact, and a
    ``down`` with no open ``up`` closes nothing: both are counted in the report, not
    errors.  Lines of other ONE events (message creation, ...) are counted and
    ignored.  Simultaneous ``up``/``down`` lines of one pair apply in file order.

Malformed lines
---------------
A line is malformed if it has the wrong number of fields, a time that is not a
finite number >= 0 (>= w for SocioPatterns), an empty ID, an ID holding a NUL
character (it would merge with the ID without it), ``a == b``, a ONE state
other than up / down, or text that is not UTF-8 (a CSV file that is not UTF-8 is
refused whole: pyarrow cannot hand such a row back to be skipped; the message names
the line and column of its first such byte).  Without
``skip_bad`` the first one raises an :class:`~.errors.InputError` naming the file, the
line (text formats; for CSV and Parquet the 1-based data row, header not counted), the
field and the value.
With ``skip_bad`` malformed lines are dropped and counted in the report.  Blank
lines are not malformed: they are counted and ignored.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pcsv

from ..errors import InputError, SwarmtopoError
from ..log import MAX_TIME, NUL_ID, TOO_LATE, EncounterLog
from .tables import (BLOCK, IdColumn, blank_rows, blocks, check_text, coarse_time, csv_header, existing_file,
                     find_columns, id_columns, integer_ids, not_utf8, not_utf8_reason, open_bytes, parquet_file,
                     read_error, trim)

FORMATS: tuple[str, ...] = ("csv", "parquet", "sociopatterns", "one")
SOCIOPATTERNS_WINDOW = 20.0
"""Seconds of one SocioPatterns contact window (the sensors' 20 s resolution)."""

_BLOCK = BLOCK  # bytes per block of a streamed file
_EXAMPLES = 5  # messages of skipped lines kept in the report
_NUMBER = r"^[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?$"


@dataclass(frozen=True)
class IngestReport:
    """What an ingest read, skipped and merged.

    Attributes
    ----------
    file, fmt
        The trace file and its format.
    lines
        Data lines (rows) read, blank lines included.
    skipped
        Malformed lines dropped (only with ``skip_bad``; otherwise the first raises).
    examples
        The messages of the first few skipped lines.
    counts
        Format-specific tallies: ``blank_lines``; SocioPatterns ``windows``
        (contact lines) and ``merged_windows``; ONE ``repeated_up``,
        ``unmatched_down``, ``open_at_end``, ``other_events``.
    """

    file: str
    fmt: str
    lines: int
    skipped: int
    examples: tuple[str, ...]
    counts: dict[str, int] = field(default_factory=dict)

    def as_meta(self) -> dict:
        """The JSON-able record that goes to ``meta["ingest"]``."""
        return {"file": Path(self.file).name, "format": self.fmt, "lines": self.lines,
                "skipped_lines": self.skipped, "skipped_examples": list(self.examples), **self.counts}


def read_trace(path, fmt: str, *, skip_bad: bool = False, time_column: str = "t", a_column: str = "a",
               b_column: str = "b", window: float = SOCIOPATTERNS_WINDOW) -> tuple[EncounterLog, IngestReport]:
    """Read a proximity trace of format ``fmt`` (one of :data:`FORMATS`).

    ``time_column, a_column, b_column`` name the columns of ``csv`` / ``parquet``;
    ``window`` is the SocioPatterns window w in seconds.  See the module docstring
    for the formats and what counts as malformed.
    """
    if fmt in ("csv", "parquet"):
        return read_table_trace(path, fmt=fmt, skip_bad=skip_bad, time_column=time_column,
                                a_column=a_column, b_column=b_column)
    if fmt == "sociopatterns":
        return read_sociopatterns(path, window=window, skip_bad=skip_bad)
    if fmt == "one":
        return read_one(path, skip_bad=skip_bad)
    raise SwarmtopoError(f"unknown trace format {fmt!r}; expected one of {', '.join(FORMATS)}")


# -- the three readers --------------------------------------------------------------------
def read_table_trace(path, *, fmt: str = "csv", skip_bad: bool = False, time_column: str = "t",
                     a_column: str = "a", b_column: str = "b") -> tuple[EncounterLog, IngestReport]:
    """A CSV or Parquet table, one encounter ``(t, a, b)`` per row."""
    path = existing_file(path, "trace file")
    names = {"t": time_column, "a": a_column, "b": b_column}
    if len(set(names.values())) < 3:
        raise SwarmtopoError(f"the time and the two ID columns must be three different columns, not "
                             f"{time_column!r}, {a_column!r}, {b_column!r}")
    rows = _Rows(str(path), skip_bad)
    for line, written in (_csv_batches(path, names, rows) if fmt == "csv" else _parquet_batches(path, names, rows)):
        cols = {k: trim(v) for k, v in written.items()} if fmt == "csv" else written
        blank = blank_rows(cols.values()) if fmt == "csv" else np.zeros(len(line), bool)  # Parquet has no blank lines
        rows.counts["blank_lines"] += int(blank.sum())
        line, cols, written = line[~blank], *({k: v.filter(pa.array(~blank)) for k, v in c.items()}
                                              for c in (cols, written))
        t, ok = _times(cols["t"], line, names["t"], rows, minimum=0.0)
        ok &= _ids_ok(cols["a"], cols["b"], line, (names["a"], names["b"]), rows)
        # IDs are kept as written: trimming is checked not to merge two of them
        rows.keep(ok, line, t=t[ok], a=written["a"].filter(pa.array(ok)), b=written["b"].filter(pa.array(ok)))
    t, a, b, line = rows.columns()
    if fmt == "csv":  # trimmed, and two IDs that trimming would merge refused
        a, b = id_columns([IdColumn(col, path, names[key], line, csv=True) for key, col in (("a", a), ("b", b))])
    columns = {"time": names["t"], "a": names["a"], "b": names["b"]}
    if rows.time_type is not None:
        columns["time_type"] = rows.time_type
    log = _build(t, a, b, line, rows, fmt, columns)
    return log, rows.report(fmt)


def read_sociopatterns(path, *, window: float = SOCIOPATTERNS_WINDOW,
                       skip_bad: bool = False) -> tuple[EncounterLog, IngestReport]:
    """SocioPatterns ``t i j Ci Cj`` lines; consecutive windows of a pair merge."""
    if not (np.isfinite(window) and window > 0):
        raise SwarmtopoError(f"the window must be a positive number of seconds, not {window!r}")
    path = existing_file(path, "trace file")
    rows = _Rows(str(path), skip_bad)
    for line, fields, n in _text_batches(path, rows):
        ok = _field_count_ok(n, (3, 5), fields, line, rows, "t i j Ci Cj (or t i j)")
        t_col, a, b = (_field(fields, k, ok) for k in range(3))
        t, t_ok = _times(t_col, line, "t", rows, minimum=window, active=ok,
                         below=f"time is less than the window ({window:g} s): the contact would start before 0")
        ok &= t_ok
        ok &= _ids_ok(a, b, line, ("i", "j"), rows, active=ok)
        has_class = ok & (n == 5)
        ci, cj = (_field(fields, k, has_class) for k in (3, 4))
        sel = pa.array(ok)
        rows.keep(ok, line, t=t[ok], a=a.filter(sel), b=b.filter(sel), ci=ci.filter(sel), cj=cj.filter(sel))
    t, a, b, line = rows.columns()
    ci, cj = rows.extra("ci"), rows.extra("cj")
    rows.counts["windows"] = len(t)
    code_a, code_b, ids = _codes(a, b)
    first = _merge_windows(t, np.minimum(code_a, code_b), np.maximum(code_a, code_b), window)
    rows.counts["merged_windows"] = int(len(t) - first.sum())
    meta_extra = {"window": window, "agent_classes": _classes(ids, code_a, code_b, ci, cj, line, rows.file)}
    sel = pa.array(first)
    log = _build(t[first] - window, a.filter(sel), b.filter(sel), line[first], rows, "sociopatterns", meta_extra)
    return log, rows.report("sociopatterns")


def read_one(path, *, skip_bad: bool = False) -> tuple[EncounterLog, IngestReport]:
    """ONE simulator connection events ``time CONN a b up|down``; an encounter per ``up``."""
    path = existing_file(path, "trace file")
    rows = _Rows(str(path), skip_bad)
    rows.counts["other_events"] = 0
    for line, fields, n in _text_batches(path, rows):
        has_kind = n >= 2
        kind = _field(fields, 1, has_kind)
        conn = has_kind & _flag(pc.equal(kind, "CONN"))
        # a line shaped like a connection (5 fields ending up|down) with another kind is a typo, not a message
        state_like = (n == 5) & _flag(pc.is_in(_field(fields, 4, n == 5), pa.array(["up", "down"])))
        other = ~conn & ~state_like & has_kind & _is_number(_field(fields, 0, has_kind))
        rows.counts["other_events"] += int(other.sum())
        ok = _field_count_ok(np.where(other, 5, n), (5,), fields, line, rows, "time CONN a b up|down") & ~other
        ok &= rows.reject(ok & ~conn, line, "kind", kind, "event kind must be CONN for a connection up|down")
        t_col, a, b, state = (_field(fields, k, ok) for k in (0, 2, 3, 4))
        t, t_ok = _times(t_col, line, "time", rows, minimum=0.0, active=ok)
        ok &= t_ok
        ok &= _ids_ok(a, b, line, ("a", "b"), rows, active=ok)
        up, down = _flag(pc.equal(state, "up")), _flag(pc.equal(state, "down"))
        ok &= rows.reject(ok & ~up & ~down, line, "up|down", state, "connection state must be up or down")
        sel = pa.array(ok)
        rows.keep(ok, line, t=t[ok], a=a.filter(sel), b=b.filter(sel), up=up[ok])
    t, a, b, line = rows.columns()
    up = rows.extra("up", np.bool_)
    code_a, code_b, _ = _codes(a, b)
    start, tallies = _connection_starts(t, np.minimum(code_a, code_b), np.maximum(code_a, code_b), up)
    rows.counts.update(tallies)
    sel = pa.array(start)
    log = _build(t[start], a.filter(sel), b.filter(sel), line[start], rows, "one", {})
    return log, rows.report("one")


# -- vectorised semantics -------------------------------------------------------------------
def _merge_windows(t: np.ndarray, lo: np.ndarray, hi: np.ndarray, window: float) -> np.ndarray:
    """Mask of the windows that start an encounter: the first window of a pair, or one
    more than ``window`` after the pair's previous window (a gap).  Exact repeats
    (same pair, same t) belong to the running encounter."""
    order = np.lexsort((t, hi, lo))
    ts, los, his = t[order], lo[order], hi[order]
    new_pair = np.r_[True, (los[1:] != los[:-1]) | (his[1:] != his[:-1])]
    gap = np.r_[True, np.diff(ts) > window * (1 + 1e-9)]  # 1e-9: times printed in decimal
    first = np.empty(len(t), bool)
    first[order] = new_pair | gap
    return first


def _connection_starts(t, lo, hi, up) -> tuple[np.ndarray, dict[str, int]]:
    """Mask of ``up`` lines that open a connection, and the tallies of the odd lines.

    Per pair, lines in time order (ties in file order): an ``up`` opens iff the pair's
    previous line is not an ``up``; a ``down`` closes iff it is.  An ``up`` that reopens
    a connection at the very time it opened (up, down, up at one t) continues that
    encounter: one event per pair and time.
    """
    order = np.lexsort((np.arange(len(t)), t, hi, lo))
    ts, los, his, ups = t[order], lo[order], hi[order], up[order]
    same_pair = np.r_[False, (los[1:] == los[:-1]) & (his[1:] == his[:-1])]
    prev_up = same_pair & np.r_[False, ups[:-1]]
    last_of_pair = ~np.r_[same_pair[1:], False]
    opens = ups & ~prev_up
    k = np.flatnonzero(opens)  # the opening lines, in (pair, time) order
    at_once = np.zeros(len(k), bool)  # none when no line opens (a trace without an up)
    at_once[1:] = (los[k[1:]] == los[k[:-1]]) & (his[k[1:]] == his[k[:-1]]) & (ts[k[1:]] == ts[k[:-1]])
    opens[k[at_once]] = False
    start = np.empty(len(t), bool)
    start[order] = opens
    return start, {"repeated_up": int((ups & prev_up).sum()),
                   "reopened_at_once": int(at_once.sum()),
                   "unmatched_down": int((~ups & ~prev_up).sum()),
                   "open_at_end": int((ups & last_of_pair).sum())}


def _codes(a: pa.Array, b: pa.Array) -> tuple[np.ndarray, np.ndarray, pa.Array]:
    """Integer codes of two ID columns over one shared dictionary (in C)."""
    enc = pc.dictionary_encode(pa.concat_arrays([a, b]))
    idx = enc.indices.to_numpy(zero_copy_only=False).astype(np.int64)
    return idx[: len(a)], idx[len(a):], enc.dictionary


def _classes(ids: pa.Array, code_a, code_b, ci: pa.Array, cj: pa.Array, line, file) -> dict[str, str]:
    """``{id: class}`` from the lines that carry classes.  An ID given two classes is
    refused at the first line that contradicts its earlier class (lines in file order,
    ``Ci`` before ``Cj`` within a line)."""
    has = ~pc.is_null(ci).to_numpy(zero_copy_only=False)
    n = int(has.sum())
    if not n:
        return {}
    lines = np.r_[line[has], line[has]]
    order = np.lexsort((np.repeat([0, 1], n), lines))  # file order: by line, then Ci before Cj
    codes = np.r_[code_a[has], code_b[has]][order]
    labels = pa.concat_arrays([ci.filter(pa.array(has)), cj.filter(pa.array(has))]).take(pa.array(order))
    enc = pc.dictionary_encode(labels)
    cls = enc.indices.to_numpy(zero_copy_only=False).astype(np.int64)
    agents, first = np.unique(codes, return_index=True)
    expected = np.zeros(len(ids), np.int64)
    expected[agents] = cls[first]
    clash = cls != expected[codes]
    if clash.any():
        k = int(np.argmax(clash))  # the first in file order
        earlier = first[np.searchsorted(agents, codes[k])]
        raise InputError(f"agent {ids[codes[k]].as_py()!r} already has class "
                         f"{enc.dictionary[expected[codes[k]]].as_py()!r} (row {int(lines[order[earlier]])}); an "
                         f"agent has one class", file=file, row=int(lines[order[k]]),
                         column=("Ci", "Cj")[int(order[k] >= n)], value=labels[k].as_py())
    keys = ids.take(pa.array(agents)).to_pylist()
    values = enc.dictionary.take(pa.array(cls[first])).to_pylist()
    return dict(zip(map(str, keys), values))


def _build(t, a, b, line, rows: "_Rows", fmt: str, meta_extra: dict) -> EncounterLog:
    """EncounterLog from the kept lines; its row numbers are mapped back to file lines.

    A trace without a single encounter is refused: its log could not be mapped.
    """
    if not len(t):
        report = rows.report(fmt)
        raise InputError(f"no encounters in the trace ({report.lines} lines read, {report.skipped} skipped as "
                         f"malformed, {report.counts.get('blank_lines', 0)} blank)", file=rows.file)
    if isinstance(a, pa.Array):  # text IDs; CSV IDs come decided by id_columns
        as_int = integer_ids([a, b])
        if as_int is not None:
            a, b = (c.to_numpy(zero_copy_only=False) for c in as_int)
    meta = {"units": {"time": "s"}, "ingest": {**rows.report(fmt).as_meta(), **meta_extra}}
    return EncounterLog.from_records(t, a, b, meta=meta, source={"events": rows.file}, event_rows=line)


# -- line bookkeeping -------------------------------------------------------------------------
class _Rows:
    """Kept columns of the lines read so far, and the malformed lines seen."""

    def __init__(self, file: str, skip_bad: bool):
        self.file, self.skip_bad = file, skip_bad
        self.lines = 0
        self.skipped = 0
        self._examples: list[tuple[int, str]] = []
        self.counts = {"blank_lines": 0}
        self._line: list[np.ndarray] = []
        self._cols: dict[str, list] = {}
        self._pending: list[tuple] = []  # first bad line per check of the current block
        self.time_type: str | None = None  # a Parquet time column's date/time type, read as seconds

    def reject(self, bad: np.ndarray, line: np.ndarray, column: str, values: pa.Array, reason: str) -> np.ndarray:
        """Deal with the lines of mask ``bad``; returns ``~bad`` (the lines still usable).

        Without skip_bad the first bad line of each check is held, and :meth:`keep`
        raises the earliest of them: the error is at the block's first bad line.
        """
        if bad.any():
            idx = np.flatnonzero(bad)
            if not self.skip_bad:
                self._pending.append((int(line[idx[0]]), column, values[int(idx[0])].as_py(), reason))
            else:
                self.skipped += len(idx)
                for i in idx[:_EXAMPLES]:
                    self._add_example(int(line[i]), InputError(reason, file=self.file, row=int(line[i]),
                                                               column=column, value=values[int(i)].as_py()))
        return ~bad

    def skip_raw(self, line_no: int, reason: str, value) -> None:
        """A line that could not even be split into fields (bad UTF-8, bad CSV row);
        like :meth:`reject`, it raises (at the next :meth:`keep`) unless skip_bad."""
        if not self.skip_bad:
            self._pending.append((line_no, None, value, reason))
            return
        self.skipped += 1
        self._add_example(line_no, InputError(reason, file=self.file, row=line_no, value=value))

    def _add_example(self, line_no: int, error: InputError) -> None:
        """Keep the messages of the first _EXAMPLES skipped lines, in line order."""
        self._examples = sorted([*self._examples, (line_no, str(error))])[:_EXAMPLES]

    def keep(self, ok: np.ndarray, line: np.ndarray, **cols) -> None:
        """Store the kept lines of a block (after raising its first bad line, if any)."""
        self._raise_pending()
        self._line.append(line[ok])
        for name, col in cols.items():
            self._cols.setdefault(name, []).append(col)

    def _raise_pending(self) -> None:
        if self._pending:
            line_no, column, value, reason = min(self._pending, key=lambda p: p[0])
            raise InputError(reason, file=self.file, row=line_no, column=column, value=value)

    def columns(self):
        """All kept (t, a, b, line numbers); raises a malformed line not yet raised."""
        self._raise_pending()
        t = np.concatenate(self._cols.get("t", [np.empty(0)]))
        a, b = (_concat(self._cols.get(k, [])) for k in ("a", "b"))
        line = np.concatenate(self._line) if self._line else np.empty(0, np.int64)
        return t, a, b, line

    def extra(self, name: str, dtype=None):
        parts = self._cols.get(name, [])
        if dtype is not None:
            return np.concatenate(parts) if parts else np.empty(0, dtype)
        return _concat(parts)

    def report(self, fmt: str) -> IngestReport:
        return IngestReport(self.file, fmt, self.lines, self.skipped, tuple(m for _, m in self._examples),
                            dict(self.counts))


def _concat(parts) -> pa.Array:
    if not parts:
        return pa.array([], pa.string())
    return pa.chunked_array(parts, type=pa.string()).combine_chunks()


# -- reading blocks -----------------------------------------------------------------------------
def _csv_batches(path: Path, names: dict[str, str], rows: _Rows):
    """(data row numbers, {t, a, b: text columns, untrimmed}) per block of a CSV file.

    Single-threaded parsing, so rows that do not split into the header's columns reach
    the handler in order with their line numbers; blank lines arrive as empty rows.
    """
    check_text(path)  # so that pyarrow can hand every row to the handler as text
    header = find_columns(csv_header(path), list(dict.fromkeys(names.values())), path)
    names = {key: header[col] for key, col in names.items()}
    bad_rows: list[int] = []  # data rows the parser could not split, all so far

    def invalid(row) -> str:
        data_row = row.number - 1  # row.number counts the header as line 1
        bad_rows.append(data_row)
        rows.skip_raw(data_row, f"expected {len(header)} fields, found {row.actual_columns}", row.text)
        return "skip"

    convert = pcsv.ConvertOptions(include_columns=list(dict.fromkeys(names.values())),
                                  column_types={c: pa.string() for c in names.values()}, strings_can_be_null=False)
    try:
        reader = pcsv.open_csv(open_bytes(path), read_options=pcsv.ReadOptions(use_threads=False, block_size=_BLOCK),
                               parse_options=pcsv.ParseOptions(invalid_row_handler=invalid, ignore_empty_lines=False),
                               convert_options=convert)
        delivered = 0
        for batch in reader:
            k = np.arange(delivered + 1, delivered + batch.num_rows + 1)
            # data row of the k-th delivered row: k plus the skipped rows before it
            skipped = np.asarray(bad_rows, np.int64) - np.arange(len(bad_rows))
            line = k + np.searchsorted(skipped, k, side="right")
            delivered += batch.num_rows
            rows.lines += batch.num_rows
            yield line, {key: batch.column(col) for key, col in names.items()}
        rows.lines += len(bad_rows)
    except pa.ArrowInvalid as exc:
        raise InputError(f"cannot parse CSV ({exc})", file=str(path)) from None
    except OSError as exc:  # a truncated or corrupt .gz
        raise read_error(path, exc) from None


def _parquet_batches(path: Path, names: dict[str, str], rows: _Rows):
    """(row numbers, {t, a, b}) per record batch; IDs as text, times as they are."""
    pf = parquet_file(path)
    header = find_columns(pf.schema_arrow.names, list(dict.fromkeys(names.values())), path)
    names = {key: header[col] for key, col in names.items()}
    start = 0
    for batch in pf.iter_batches(batch_size=1 << 18, columns=list(dict.fromkeys(names.values()))):
        cols = {}
        for key, col in names.items():
            arr = batch.column(batch.schema.names.index(col))
            if pa.types.is_dictionary(arr.type):
                arr = arr.dictionary_decode()
            coarse = coarse_time(arr) if key == "t" else None
            if coarse is not None:
                i, problem = coarse
                raise InputError(problem, file=str(path), row=start + i + 1, column=col, value=arr[i].as_py())
            if key == "t" and pa.types.is_temporal(arr.type):
                rows.time_type = f"{arr.type}, read as seconds" + (" since 1970-01-01" if not (
                    pa.types.is_duration(arr.type) or pa.types.is_time(arr.type)) else "")
                arr = _seconds(arr)
            elif key != "t" and pa.types.is_floating(arr.type):
                if pa.types.is_float16(arr.type):  # exact in float32, which arrow computes on
                    arr = pc.cast(arr, pa.float32())
                arr = pc.if_else(pc.is_nan(arr), pa.scalar(None, arr.type), arr)  # NaN: no ID
                arr = pc.add(arr, pa.scalar(0.0, arr.type))  # -0.0 + 0.0 = 0.0: agent 0, as map reads it
            if key != "t" or not (pa.types.is_integer(arr.type) or pa.types.is_floating(arr.type)):
                try:
                    arr = pc.cast(arr, pa.string())  # Parquet values are exact: not trimmed
                except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
                    raise InputError(f"column of type {arr.type} cannot hold {'times' if key == 't' else 'agent IDs'}",
                                     file=str(path), column=col) from None
            cols[key] = arr
        rows.lines += batch.num_rows
        yield np.arange(start + 1, start + batch.num_rows + 1), cols
        start += batch.num_rows


_SECONDS_PER_UNIT = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}


def _seconds(arr: pa.Array) -> pa.Array:
    """A date, time, timestamp or duration column as float64 seconds (dates and
    timestamps since 1970-01-01, times of day since midnight); nulls stay null."""
    kind = arr.type
    if pa.types.is_date32(kind) or pa.types.is_time32(kind):  # no cast to int64 in Arrow: their 32-bit counts
        counts = arr.view(pa.int32())
    else:
        counts = pc.cast(arr, pa.int64())
    seconds = 86400.0 if pa.types.is_date32(kind) else _SECONDS_PER_UNIT["ms" if pa.types.is_date64(kind) else kind.unit]
    return pc.multiply(pc.cast(counts, pa.float64(), safe=False), seconds)


def _text_batches(path: Path, rows: _Rows):
    """(line numbers, fields as a list array, field counts) per block of a text file.

    Blocks are cut after their last newline and split into lines and fields in C;
    blank lines are counted and dropped here.
    """
    line_no = 0
    chunks = blocks(path, _BLOCK)
    tail = b""
    for block in chunks:  # the first 3 bytes, for a byte order mark
        tail += block
        if len(tail) >= 3:
            break
    tail = tail[3:] if tail.startswith(b"\xef\xbb\xbf") else tail  # a UTF-8 byte order mark
    while True:
        block = next(chunks, b"")
        data = tail + block
        if block:
            # cut after the last line end; a final \r waits: a \n may follow in the next block
            cut = max(data.rfind(b"\n"), data.rfind(b"\r", 0, len(data) - 1)) + 1
            data, tail = data[:cut], data[cut:]
            if not data:
                continue
        elif not data:
            return
        data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")  # CRLF and CR-only line ends
        lines = pc.split_pattern(pa.array([data], pa.large_binary()), b"\n").flatten()
        if block or data.endswith(b"\n"):
            lines = lines.slice(0, len(lines) - 1)  # after the final newline: nothing
        numbers = np.arange(line_no + 1, line_no + len(lines) + 1)
        line_no += len(lines)
        rows.lines += len(lines)
        lines, numbers = _utf8_lines(lines, numbers, rows)
        text = pc.utf8_trim_whitespace(lines)
        blank = pc.equal(pc.utf8_length(text), 0).to_numpy(zero_copy_only=False)
        rows.counts["blank_lines"] += int(blank.sum())
        text, numbers = text.filter(pa.array(~blank)), numbers[~blank]
        fields = pc.utf8_split_whitespace(text)
        yield numbers, fields, pc.list_value_length(fields).to_numpy(zero_copy_only=False).astype(np.int64)
        if not block:
            return


def _utf8_lines(lines: pa.Array, numbers: np.ndarray, rows: _Rows):
    """Lines as text; a line that is not UTF-8 is malformed (its first bad byte named)."""
    bad = not_utf8(lines)
    for i in np.flatnonzero(bad):
        rows.skip_raw(int(numbers[i]), not_utf8_reason(lines[int(i)].as_py()), None)
    return pc.cast(lines.filter(pa.array(~bad)), pa.string()), numbers[~bad]


# -- vectorised checks ------------------------------------------------------------------------
def _field(fields: pa.Array, k: int, present: np.ndarray) -> pa.Array:
    """Field ``k`` of every line, null where ``present`` is False (lines too short)."""
    safe = pc.if_else(pa.array(present), fields, pa.scalar([""] * (k + 1), fields.type))
    return pc.if_else(pa.array(present), pc.list_element(safe, k), pa.scalar(None, pa.string()))


def _flag(mask: pa.Array) -> np.ndarray:
    """Boolean pyarrow mask -> numpy bool, null as False."""
    return pc.fill_null(mask, False).to_numpy(zero_copy_only=False)


def _is_number(col: pa.Array) -> np.ndarray:
    return pc.fill_null(pc.match_substring_regex(col, _NUMBER), False).to_numpy(zero_copy_only=False)


def _field_count_ok(n: np.ndarray, allowed: tuple[int, ...], fields: pa.Array, line, rows: _Rows,
                    layout: str) -> np.ndarray:
    """Lines with an allowed number of fields; the others are refused, quoting the line."""
    bad = ~np.isin(n, allowed)
    text = pc.binary_join(fields, " ") if bad.any() else fields
    return rows.reject(bad, line, None, text, f"expected {' or '.join(map(str, allowed))} fields: {layout}")


def _times(col: pa.Array, line, name: str, rows: _Rows, *, minimum: float, active=None,
           below: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """float64 times and the mask of usable lines; bad times are rejected."""
    active = np.ones(len(col), bool) if active is None else active
    ok = rows.reject(active & col.is_null().to_numpy(zero_copy_only=False), line, name, col, "time is missing")
    if pa.types.is_integer(col.type) or pa.types.is_floating(col.type):
        # unsafe: integers beyond 2^53 round, and are refused below as too late
        t = pc.cast(col, pa.float64(), safe=False).fill_null(0.0).to_numpy(zero_copy_only=False)
        ok &= rows.reject(active & ok & ~np.isfinite(t), line, name, col, "time must be a finite number")
    else:
        ok &= rows.reject(active & ok & ~_is_number(col), line, name, col, "time is not a number")
        parsed = pc.cast(pc.if_else(pa.array(active & ok), col, "0"), pa.float64())
        t = parsed.to_numpy(zero_copy_only=False)
        ok &= rows.reject(active & ok & ~np.isfinite(t), line, name, col, "time must be a finite number")
    reason = below or ("time must not be negative" if minimum == 0 else f"time must be >= {minimum:g}")
    ok &= rows.reject(active & ok & ~(t >= minimum), line, name, col, reason)
    ok &= rows.reject(active & ok & (t >= MAX_TIME), line, name, col, TOO_LATE)
    return t, ok & active


def _ids_ok(a: pa.Array, b: pa.Array, line, names: tuple[str, str], rows: _Rows, active=None) -> np.ndarray:
    active = np.ones(len(a), bool) if active is None else active
    ok = active.copy()
    for col, name in zip((a, b), names):
        empty = pc.fill_null(pc.equal(pc.utf8_length(col), 0), True).to_numpy(zero_copy_only=False)
        ok &= rows.reject(ok & empty, line, name, col, "agent ID is missing")
        nul = pc.fill_null(pc.match_substring(col, "\x00"), False).to_numpy(zero_copy_only=False)
        ok &= rows.reject(ok & nul, line, name, col, NUL_ID)
    same = pc.fill_null(pc.equal(a, b), False).to_numpy(zero_copy_only=False)
    ok &= rows.reject(ok & same, line, names[1], b, "an agent cannot encounter itself")
    return ok
