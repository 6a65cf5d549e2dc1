"""EncounterLog: the one input contract of everything downstream of the swarm.

A log holds what a base station receives and nothing else:

* encounter events ``[t, a, b]`` -- agents ``a`` and ``b`` came within r_d of each
  other at time ``t`` (the start of a contact period, see "Encounter Tracking");
  a pair is unordered;
* status changes ``(t, agent, state)`` with state in RW, WF, S;
* static agents (the hybrid network) with the time they were stopped for good;
* metadata: units, r_d, duration, agent count, seed, provenance.

Agent IDs may be integers or strings.  Inside, every agent is a dense integer
*code*; ``agent_ids[code]`` is its original ID and codes follow the sorted order of
the IDs.  Events are stored canonically: ``a < b`` (codes), sorted by (t, a, b).
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from .beacon import BeaconTrack
from .errors import InputError

LOG_FORMAT = "swarmtopo-log/1"
"""The ``format`` key of a log folder's ``meta.json`` (see :mod:`swarmtopo.io.logs`)."""
STATES: tuple[str, ...] = ("RW", "WF", "S")
"""Status codes: index in this tuple.  RW random walk, WF wall following, S stopped."""
RW, WF, S = 0, 1, 2
_STATE_LABELS = np.asarray(STATES, dtype=object)
MAX_TIME = 2.0 ** 53
"""Times (s) must be below 2^53, where float64 still tells whole seconds apart; a larger
time is in another unit (nanoseconds since 1970 are about 1.4e18)."""
TOO_LATE = "time is 2^53 s or more: times must be in seconds (divide nanoseconds by 1e9)"


@dataclass(frozen=True, eq=False)
class EncounterLog:
    """Encounters, status changes and static agents of one deployment.

    Attributes
    ----------
    t, a, b
        Events: float64 times (s, non-decreasing) and int64 agent codes, ``a < b``.
    agent_ids
        Original agent IDs, indexed by code (int64 or object array of str).
    status_t, status_agent, status_state
        Status changes: float64 time, int64 agent code, int8 state code (see STATES),
        sorted by (agent, t).
    static_agent, static_time
        Agents commanded to stop for good (int64 codes) and when (float64 s).
    meta
        Metadata (JSON-able): ``units``, ``r_d``, ``duration``, ``seed``,
        provenance, and the declaration ``agent_count`` or ``agent_ids`` if the
        source gave one (the number of agents is :attr:`n_agents`, whatever meta
        says).  Never ground truth.
    beacon
        The track of a localized leader the swarm was kept near (``beacon.csv``,
        :mod:`swarmtopo.beacon`), or None: the one position a log may hold.
    """

    t: np.ndarray
    a: np.ndarray
    b: np.ndarray
    agent_ids: np.ndarray
    status_t: np.ndarray = field(default_factory=lambda: np.empty(0))
    status_agent: np.ndarray = field(default_factory=lambda: np.empty(0, np.int64))
    status_state: np.ndarray = field(default_factory=lambda: np.empty(0, np.int8))
    static_agent: np.ndarray = field(default_factory=lambda: np.empty(0, np.int64))
    static_time: np.ndarray = field(default_factory=lambda: np.empty(0))
    meta: dict[str, Any] = field(default_factory=dict)
    beacon: BeaconTrack | None = None

    # -- construction ----------------------------------------------------------------
    @classmethod
    def from_records(
        cls,
        t,
        a,
        b,
        *,
        status: tuple | None = None,
        static: tuple | None = None,
        meta: dict | None = None,
        source: dict[str, str] | None = None,
        event_rows=None,
        status_rows=None,
    ) -> "EncounterLog":
        """Validate raw columns and build a canonical log.

        Parameters
        ----------
        t, a, b
            Event columns in file order (IDs as int or str).  Columns may be
            sequences, numpy arrays or pyarrow arrays (text IDs and states are then
            dictionary-encoded in C: no per-row Python work for 10^6 rows).
        status
            ``(t, agent, state)`` columns, state as strings RW / WF / S (or None).
        static
            ``(agent, time)`` columns of static agents (or None).
        meta
            Metadata.  If it declares ``agent_ids`` (a list) or ``agent_count`` (IDs
            are then the integers ``0 .. agent_count-1``), every ID must be in it.
        source
            Names used in error messages: keys ``events``, ``status``, ``static``.
        event_rows
            The source row of each event (1-based), quoted in error messages instead
            of its position (a reader that dropped blank or skipped lines knows them).
        status_rows
            The same for the status rows.

        Raises
        ------
        InputError
            Quoting the source, 1-based row, column and value: non-numeric, NaN or
            negative times, times of 2^53 s or more, a == b, unknown states, undeclared IDs, duplicate events,
            two status rows for one agent at one time (conflicting or repeated).
            Unsorted input is sorted, not rejected.
        """
        source = {"events": "events", "status": "status", "static": "meta.json static", **(source or {})}
        meta = dict(meta or {})
        src_e = source["events"]

        def row(i) -> int:
            return _source_row(event_rows, i)

        with _rows_of(event_rows):
            t = _times(t, src_e, "t")
            ev_a, ev_b = _factorize_ids(a, src_e, "a"), _factorize_ids(b, src_e, "b")
        if not (len(t) == len(ev_a.index) == len(ev_b.index)):
            raise InputError("columns t, a, b have different lengths", file=src_e)
        if status is not None:
            with _rows_of(status_rows):
                st_t = _times(status[0], source["status"], "t")
                st_agent = _factorize_ids(status[1], source["status"], "agent")
                st_state = parse_states(status[2], source["status"])
        else:
            st_t, st_agent, st_state = np.empty(0), _IdColumn.empty("", ""), np.empty(0, np.int8)
        if static is not None:
            static_ids = _factorize_ids(static[0], source["static"], "agent")
            stime = _times(static[1], source["static"], "time")
        else:
            static_ids, stime = _IdColumn.empty("", ""), np.empty(0)

        id_cols = [ev_a, ev_b, st_agent, static_ids]
        declared = _declared_ids(meta)
        kinds = {c.labels.dtype.kind for c in id_cols if len(c.index)}
        if declared is not None and len(declared):
            kinds.add(declared.dtype.kind)
        as_text = "U" in kinds
        id_cols = [c.as_text() if as_text else c for c in id_cols]
        if declared is not None:
            declared = _as_kind(declared, as_text)
            for col in id_cols:
                bad = ~np.isin(col.labels, declared)[col.index]
                if bad.any():
                    i = int(np.argmax(bad))
                    raise InputError("agent ID is not among the agents the metadata declares",
                                     file=col.src, row=_source_row(event_rows if col.src == src_e else
                                                                   status_rows if col.src == source["status"]
                                                                   else None, i),
                                     column=col.column, value=col.value(i))
            agent_ids = np.unique(declared)
        else:
            agent_ids = np.unique(np.concatenate([c.labels for c in id_cols]))
        ca, cb, cst, csa = (np.searchsorted(agent_ids, c.labels).astype(np.int64)[c.index] for c in id_cols)
        if agent_ids.dtype.kind == "U":
            agent_ids = agent_ids.astype(object)  # text IDs are stored as Python str

        self_pair = ca == cb
        if self_pair.any():
            i = int(np.argmax(self_pair))
            raise InputError("an agent cannot encounter itself (a == b)", file=src_e, row=row(i),
                             column="b", value=id_cols[1].value(i))
        lo, hi = np.minimum(ca, cb), np.maximum(ca, cb)
        pair = lo * max(len(agent_ids), 1) + hi  # orders like (lo, hi)
        dt, dpair = np.diff(t), np.diff(pair)
        if np.all((dt > 0) | ((dt == 0) & (dpair >= 0))):  # already sorted: the usual file
            order = np.arange(len(t))
        else:
            order = np.lexsort((pair, t))
            t, lo, hi, pair = t[order], lo[order], hi[order], pair[order]
            dt, dpair = np.diff(t), np.diff(pair)
        dup = (dt == 0) & (dpair == 0)
        if dup.any():
            k = int(np.argmax(dup))
            r1, r2 = sorted((row(order[k]), row(order[k + 1])))
            raise InputError(f"duplicate event: same time and pair as row {r1} (a pair is unordered: a -> b and "
                             f"b -> a at one time are one encounter; keep one row)", file=src_e, row=r2,
                             value=f"{exact_time(t[k])}, {agent_ids[lo[k]]}, {agent_ids[hi[k]]}")

        st_order = np.lexsort((st_t, cst))
        _refuse_repeated_status(st_t, cst, st_state, st_order, agent_ids, source["status"], status_rows)
        if len(csa) != len(np.unique(csa)):
            _, first = np.unique(csa, return_index=True)
            i = int(np.setdiff1d(np.arange(len(csa)), first)[0])
            raise InputError("agent listed as static twice", file=source["static"], row=i + 1,
                             column="agent", value=id_cols[3].value(i))
        sa_order = np.argsort(csa, kind="stable")
        return cls(
            t=t, a=lo, b=hi, agent_ids=agent_ids,
            status_t=st_t[st_order], status_agent=cst[st_order], status_state=st_state[st_order],
            static_agent=csa[sa_order], static_time=stime[sa_order], meta=meta,
        )

    # -- views ---------------------------------------------------------------------
    @property
    def n_events(self) -> int:
        return int(len(self.t))

    @property
    def n_agents(self) -> int:
        return int(len(self.agent_ids))

    @property
    def duration(self) -> float:
        """Declared duration (meta ``duration``), else :attr:`last_time`."""
        if "duration" in self.meta:
            return float(self.meta["duration"])
        return self.last_time

    @property
    def last_time(self) -> float:
        """The last event or status time (0 for an empty log)."""
        return max((float(x.max()) for x in (self.t, self.status_t) if len(x)), default=0.0)

    def window(self, t0: float | None = None, t1: float | None = None) -> "EncounterLog":
        """Events with t0 <= t <= t1; status and static agents are kept whole."""
        lo = -np.inf if t0 is None else t0
        hi = np.inf if t1 is None else t1
        keep = (self.t >= lo) & (self.t <= hi)
        return replace(self, t=self.t[keep], a=self.a[keep], b=self.b[keep])

    def stop_intervals(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closed stop intervals [start, end] per agent, from the status changes.

        A stop runs from an S status to the agent's next status change; a stop with no
        later change is open (end = +inf).  Static agents are *not* added here (the
        hybrid metric adds them).  Returns (agent, start, end), sorted by (agent, start).
        """
        ag, t, st = self.status_agent, self.status_t, self.status_state
        is_stop = st == S
        nxt_same = np.r_[ag[1:] == ag[:-1], False]
        end = np.where(nxt_same, np.r_[t[1:], np.inf], np.inf)
        # consecutive S rows of one agent form one stop: from its first row to the
        # change after its last row
        prev_stop = np.r_[False, nxt_same[:-1] & is_stop[:-1]]
        next_stop = nxt_same & np.r_[is_stop[1:], False]
        idx = np.flatnonzero(is_stop & ~prev_stop)
        ends = end[is_stop & ~next_stop]
        return ag[idx], t[idx], ends

    def ids_of(self, codes) -> np.ndarray:
        """Original IDs of agent codes."""
        return self.agent_ids[np.asarray(codes, dtype=np.int64)]

    def __repr__(self) -> str:
        return (f"EncounterLog(events={self.n_events}, agents={self.n_agents}, "
                f"status={len(self.status_t)}, static={len(self.static_agent)}, duration={self.duration:g} s)")


def _source_row(rows, i) -> int:
    """The 1-based source row of position ``i``: ``rows[i]``, or ``i + 1`` without ``rows``."""
    return int(rows[i]) if rows is not None else int(i) + 1


@contextmanager
def _rows_of(rows):
    """Re-raise an InputError with its row (a 1-based position) as the source row ``rows`` gives."""
    try:
        yield
    except InputError as exc:
        if rows is None or exc.row is None:
            raise
        raise InputError(exc.reason, file=exc.file, row=_source_row(rows, exc.row - 1), column=exc.column,
                         value=exc.value) from None


# -- column validation ---------------------------------------------------------------
# ID and state columns are factorized (distinct labels + an integer index per row), so
# the per-row work on 10^6 rows is integer numpy work; only distinct labels are Python.
def _times(values, src, col) -> np.ndarray:
    arr = np.asarray(values)
    if arr.dtype.kind in "biuf":
        out = arr.astype(np.float64)
    else:
        if arr.dtype.kind == "O":  # numpy would read None as NaN
            missing = np.fromiter((v is None for v in arr), dtype=bool, count=len(arr))
            if missing.any():
                i = int(np.argmax(missing))
                raise InputError("time is missing", file=src, row=i + 1, column=col)
        try:
            out = arr.astype(np.float64)
        except (TypeError, ValueError):  # convert one by one to locate the bad value
            out = np.empty(len(arr))
            for i, v in enumerate(arr):
                try:
                    out[i] = float(v)
                except (TypeError, ValueError):
                    raise InputError("time is not a number", file=src, row=i + 1, column=col, value=v) from None
    bad = ~np.isfinite(out)
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError("time must be a finite number", file=src, row=i + 1, column=col, value=arr[i])
    neg = out < 0
    if neg.any():
        i = int(np.argmax(neg))
        raise InputError("time must not be negative", file=src, row=i + 1, column=col, value=arr[i])
    huge = out >= MAX_TIME
    if huge.any():
        i = int(np.argmax(huge))
        raise InputError(TOO_LATE, file=src, row=i + 1, column=col, value=arr[i])
    return out + 0.0  # -0.0 -> 0.0


def exact_time(t: float) -> str:
    """A time as its shortest exact decimal (no exponent, no rounding): 1400028780, 0.5."""
    return np.format_float_positional(float(t), trim="-")


@dataclass(frozen=True)
class _IdColumn:
    """One column of agent IDs, factorized: row ``i`` holds ``labels[index[i]]``.

    ``labels`` are the distinct IDs (int64, or a numpy 'U' array of text); all per-row
    work on the column is integer work on ``index``.
    """

    labels: np.ndarray
    index: np.ndarray
    src: str
    column: str

    @classmethod
    def empty(cls, src, column) -> "_IdColumn":
        return cls(np.empty(0, np.int64), np.empty(0, np.int64), src, column)

    def value(self, row: int):
        return self.labels[self.index[row]]

    def as_text(self) -> "_IdColumn":
        return replace(self, labels=_as_kind(self.labels, True))


def _factorize_ids(values, src, col) -> _IdColumn:
    """Validate a column of IDs (ints, text, or a pyarrow array) and factorize it."""
    if isinstance(values, (pa.Array, pa.ChunkedArray)):
        values = _arrow_ids(values, src, col)
        if isinstance(values, _IdColumn):
            return values
    if isinstance(values, (list, tuple)) and any(isinstance(v, str) for v in values):
        arr = np.asarray(values, dtype=object)  # as numpy strings, trailing NULs would already be gone
    else:
        arr = np.asarray(values)
    if len(arr) == 0:
        return _IdColumn.empty(src, col)
    if arr.dtype.kind == "f":
        arr = float_ids(arr, src, col)
    elif arr.dtype.kind in "iub":
        arr = arr.astype(np.int64)
    else:
        if arr.dtype.kind == "O":
            missing = np.fromiter((v is None or (isinstance(v, float) and not np.isfinite(v)) for v in arr),
                                  dtype=bool, count=len(arr))
            if missing.any():
                i = int(np.argmax(missing))
                raise InputError("agent ID is missing", file=src, row=i + 1, column=col, value=arr[i])
            nul = np.fromiter((isinstance(v, str) and "\x00" in v for v in arr), dtype=bool, count=len(arr))
        else:  # numpy strings: a NUL inside an ID (trailing ones are gone already)
            nul = np.strings.find(arr.astype(str), "\x00") >= 0
        if nul.any():
            i = int(np.argmax(nul))
            raise InputError(NUL_ID, file=src, row=i + 1, column=col, value=arr[i])
        arr = arr.astype(str)
    labels, index = np.unique(arr, return_inverse=True)
    return _checked_text(_IdColumn(labels, index.reshape(-1).astype(np.int64), src, col))


def float_ids(arr: np.ndarray, src, col, rows: np.ndarray | None = None) -> np.ndarray:
    """Float agent IDs as int64, each a whole number within int64 (else InputError at its
    row: ``rows[i]``, or i + 1 without ``rows``)."""
    rows = np.arange(1, len(arr) + 1) if rows is None else rows
    bad = ~np.isfinite(arr) | (arr != np.round(arr))
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError("agent ID must be an integer or a text label", file=src, row=int(rows[i]), column=col,
                         value=arr[i])
    huge = (arr >= 2.0 ** 63) | (arr < -(2.0 ** 63))
    if huge.any():  # the cast would wrap them, merging distinct agents
        i = int(np.argmax(huge))
        raise InputError("a float agent ID must be a whole number within the int64 range (|ID| < 2^63): "
                         "write such IDs as integers or text", file=src, row=int(rows[i]), column=col, value=arr[i])
    return arr.astype(np.int64)


def _arrow_ids(arr, src, col):
    """pyarrow column -> numpy numbers, or a factorized text column (no per-row Python)."""
    if isinstance(arr, pa.ChunkedArray):
        arr = arr.combine_chunks()
    if len(arr) == 0:
        return np.empty(0, np.int64)
    if arr.null_count:
        i = int(np.argmax(arr.is_null().to_numpy(zero_copy_only=False)))
        raise InputError("agent ID is missing", file=src, row=i + 1, column=col)
    if pa.types.is_dictionary(arr.type):
        arr = arr.dictionary_decode()
    if pa.types.is_integer(arr.type) or pa.types.is_floating(arr.type) or pa.types.is_boolean(arr.type):
        return arr.to_numpy(zero_copy_only=False)
    try:
        arr = arr.cast(pa.string())
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
        raise InputError(f"agent ID must be an integer or a text label, not {arr.type}", file=src,
                         column=col, value=arr[0].as_py()) from None
    refuse_nul_ids(arr, src, col)
    enc = pc.dictionary_encode(arr)
    labels = np.asarray(enc.dictionary.to_pylist(), dtype=str).reshape(-1)
    order = np.argsort(labels)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    index = rank[enc.indices.to_numpy(zero_copy_only=False).astype(np.int64)]
    return _checked_text(_IdColumn(labels[order], index, src, col))


NUL_ID = ("agent ID contains a NUL character (\\x00), which an ID cannot hold: it would merge with the same ID "
          "without it")
"""Why a text ID holding a NUL is refused: text IDs are held as numpy strings, which drop
trailing NULs, so 'a\\x00' would merge with 'a'."""


def refuse_nul_ids(ids: pa.Array, src, col, rows: np.ndarray | None = None) -> None:
    """InputError (NUL_ID) at the first of the text ``ids`` (no nulls) holding a NUL: at
    row ``rows[i]`` of ``src``'s column ``col``, or i + 1 without ``rows``."""
    nul = pc.match_substring(ids, "\x00").to_numpy(zero_copy_only=False)
    if nul.any():
        i = int(np.argmax(nul))
        raise InputError(NUL_ID, file=src, row=int(rows[i]) if rows is not None else i + 1, column=col,
                         value=ids[i].as_py())


def _checked_text(ids: _IdColumn) -> _IdColumn:
    if ids.labels.dtype.kind == "U":
        blank = np.strings.str_len(np.strings.strip(ids.labels)) == 0
        if blank.any():
            i = int(np.argmax(blank[ids.index]))
            raise InputError("agent ID is missing", file=ids.src, row=i + 1, column=ids.column,
                             value=ids.value(i))
    return ids


def parse_states(values, src) -> np.ndarray:
    """State labels -> int8 codes into STATES, the one parser of state labels.

    Parameters
    ----------
    values
        Labels RW / WF / S (any case, surrounding blanks ignored): a sequence, numpy
        array or pyarrow array (dictionary-encoded in C, no per-row Python).
    src
        File or source name for error messages.

    Raises
    ------
    InputError
        At the first unknown or missing label, with its 1-based row.
    """
    if isinstance(values, (pa.Array, pa.ChunkedArray)):
        if isinstance(values, pa.ChunkedArray):
            values = values.combine_chunks()
        enc = pc.dictionary_encode(values)
        labels = np.array(enc.dictionary.to_pylist() + [None], dtype=object)
        index = enc.indices.fill_null(len(labels) - 1).to_numpy(zero_copy_only=False)
    else:
        labels, index = np.unique(np.asarray(values).astype(str), return_inverse=True)
        labels = labels.astype(object)
    lookup = {s: k for k, s in enumerate(STATES)}
    label_codes = np.array([lookup.get(str(v).strip().upper() if v is not None else None, -1)
                            for v in labels], dtype=np.int8)
    out = label_codes[np.asarray(index).reshape(-1)] if len(labels) else np.empty(0, np.int8)
    bad = out < 0
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError(f"unknown state; expected one of {', '.join(STATES)}", file=src,
                         row=i + 1, column="state", value=labels[index[i]])
    return out


def state_labels(codes) -> np.ndarray:
    """int8 codes into STATES -> object array of the labels RW / WF / S."""
    codes = np.asarray(codes)
    bad = (codes < 0) | (codes >= len(STATES)) if codes.dtype.kind in "iu" else np.ones(codes.shape, bool)
    if bad.any():
        i = int(np.argmax(bad.reshape(-1)))
        raise InputError(f"state code must be an integer 0 .. {len(STATES) - 1} (one of {', '.join(STATES)})",
                         row=i + 1, column="state", value=codes.reshape(-1)[i])
    return _STATE_LABELS[codes]


def _refuse_repeated_status(t, agent, state, order, agent_ids, src, rows) -> None:
    """Two status rows for one agent at one time are either a contradiction or a
    duplicate; either way the log would depend on row order, so refuse them.  ``rows``:
    the source row of each status row (None: its position)."""
    t, agent = t[order], agent[order]
    repeated = (np.diff(t) == 0) & (np.diff(agent) == 0)
    if not repeated.any():
        return
    k = int(np.argmax(repeated))
    i, j = int(order[k]), int(order[k + 1])  # lexsort is stable: i < j
    first, second = _source_row(rows, i), _source_row(rows, j)
    who = agent_ids[agent[k]]
    who = int(who) if isinstance(who, np.integer) else who
    when = float(t[k])
    s1, s2 = STATES[state[i]], STATES[state[j]]
    if s1 == s2:
        raise InputError(f"duplicate status row: row {second} repeats row {first} "
                         f"(t={when!r}, agent {who!r}, {s1})", file=src, row=second)
    raise InputError(f"conflicting status rows: row {first} says agent {who!r} is {s1} at t={when!r}, "
                     f"row {second} says {s2}", file=src, row=second, column="state", value=s2)


def _declared_ids(meta) -> np.ndarray | None:
    if meta.get("agent_ids") is not None:
        return _factorize_ids(list(meta["agent_ids"]), "meta.json", "agent_ids").labels
    if meta.get("agent_count") is not None:
        n = meta["agent_count"]
        if not isinstance(n, int) or n < 0:
            raise InputError("agent_count must be a non-negative integer", file="meta.json",
                             column="agent_count", value=n)
        return np.arange(n, dtype=np.int64)
    return None


def _as_kind(arr: np.ndarray, as_text: bool) -> np.ndarray:
    if as_text and arr.dtype.kind != "U":
        return arr.astype(str)
    return arr
