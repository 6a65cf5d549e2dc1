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

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .errors import InputError

STATES: tuple[str, ...] = ("RW", "WF", "S")
"""Status codes: index in this tuple.  RW random walk, WF wall following, S stopped."""
RW, WF, S = 0, 1, 2


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
        Metadata (JSON-able): ``units``, ``r_d``, ``duration``, ``agent_count``,
        ``seed``, provenance.  Never ground truth.
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
    ) -> "EncounterLog":
        """Validate raw columns and build a canonical log.

        Parameters
        ----------
        t, a, b
            Event columns in file order (IDs as int or str).
        status
            ``(t, agent, state)`` columns, state as strings RW / WF / S (or None).
        static
            ``(agent, time)`` columns of static agents (or None).
        meta
            Metadata.  If it declares ``agent_ids`` (a list) or ``agent_count`` (IDs
            are then the integers ``0 .. agent_count-1``), every ID must be in it.
        source
            Names used in error messages: keys ``events``, ``status``, ``static``.

        Raises
        ------
        InputError
            Quoting the source, 1-based row, column and value: non-numeric, NaN or
            negative times, a == b, unknown states, undeclared IDs, duplicate events.
            Unsorted input is sorted, not rejected.
        """
        source = {"events": "events", "status": "status", "static": "meta.json static", **(source or {})}
        meta = dict(meta or {})
        src_e = source["events"]
        t = _times(t, src_e, "t")
        a_raw, b_raw = _ids(a, src_e, "a"), _ids(b, src_e, "b")
        if not (len(t) == len(a_raw) == len(b_raw)):
            raise InputError("columns t, a, b have different lengths", file=src_e)
        if status is not None:
            st_t = _times(status[0], source["status"], "t")
            st_agent = _ids(status[1], source["status"], "agent")
            st_state = _states(status[2], source["status"])
        else:
            st_t, st_agent, st_state = np.empty(0), _ids([], "", ""), np.empty(0, np.int8)
        if static is not None:
            sa = _ids(static[0], source["static"], "agent")
            stime = _times(static[1], source["static"], "time")
        else:
            sa, stime = _ids([], "", ""), np.empty(0)

        declared = _declared_ids(meta)
        kinds = {arr.dtype.kind for arr in (a_raw, b_raw, st_agent, sa) if len(arr)}
        if declared is not None and len(declared):
            kinds.add(declared.dtype.kind)
        as_text = "O" in kinds or "U" in kinds
        cols = [_as_kind(x, as_text) for x in (a_raw, b_raw, st_agent, sa)]
        if declared is not None:
            declared = _as_kind(declared, as_text)
            for arr, name, col in ((cols[0], src_e, "a"), (cols[1], src_e, "b"),
                                   (cols[2], source["status"], "agent"), (cols[3], source["static"], "agent")):
                bad = ~np.isin(arr, declared)
                if bad.any():
                    i = int(np.argmax(bad))
                    raise InputError("agent ID is not among the agents the metadata declares",
                                     file=name, row=i + 1, column=col, value=arr[i])
            agent_ids = np.unique(declared)
        else:
            agent_ids = np.unique(np.concatenate(cols)) if any(len(c) for c in cols) else cols[0][:0]
        codes = [np.searchsorted(agent_ids, c).astype(np.int64) for c in cols]
        ca, cb, cst, csa = codes

        self_pair = ca == cb
        if self_pair.any():
            i = int(np.argmax(self_pair))
            raise InputError("an agent cannot encounter itself (a == b)", file=src_e, row=i + 1,
                             column="b", value=b_raw[i])
        lo, hi = np.minimum(ca, cb), np.maximum(ca, cb)
        order = np.lexsort((hi, lo, t))
        t, lo, hi = t[order], lo[order], hi[order]
        dup = (np.diff(t) == 0) & (np.diff(lo) == 0) & (np.diff(hi) == 0)
        if dup.any():
            k = int(np.argmax(dup))
            r1, r2 = sorted((int(order[k]) + 1, int(order[k + 1]) + 1))
            raise InputError(f"duplicate event: same time and pair as row {r1}", file=src_e, row=r2,
                             value=f"{t[k]:g}, {agent_ids[lo[k]]}, {agent_ids[hi[k]]}")

        st_order = np.lexsort((st_t, cst))
        if len(csa) != len(np.unique(csa)):
            _, first = np.unique(csa, return_index=True)
            i = int(np.setdiff1d(np.arange(len(csa)), first)[0])
            raise InputError("agent listed as static twice", file=source["static"], row=i + 1,
                             column="agent", value=sa[i])
        sa_order = np.argsort(csa, kind="stable")
        meta.setdefault("agent_count", int(len(agent_ids)))
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
        """Declared duration (meta ``duration``), else the last event or status time."""
        if "duration" in self.meta:
            return float(self.meta["duration"])
        ends = [x.max() for x in (self.t, self.status_t) if len(x)]
        return float(max(ends)) if ends else 0.0

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
        # consecutive S rows of one agent belong to one stop: keep the first, extend its end
        starts = is_stop & ~(np.r_[False, nxt_same[:-1]] & np.r_[False, is_stop[:-1]])
        idx = np.flatnonzero(starts)
        ends = np.empty(len(idx))
        for n, i in enumerate(idx):
            j = i
            while nxt_same[j] and st[j + 1] == S:
                j += 1
            ends[n] = end[j]
        return ag[idx], t[idx], ends

    def ids_of(self, codes) -> np.ndarray:
        """Original IDs of agent codes."""
        return self.agent_ids[np.asarray(codes, dtype=np.int64)]

    def __repr__(self) -> str:
        return (f"EncounterLog(events={self.n_events}, agents={self.n_agents}, "
                f"status={len(self.status_t)}, static={len(self.static_agent)}, duration={self.duration:g} s)")


# -- column validation ---------------------------------------------------------------
def _times(values, src, col) -> np.ndarray:
    arr = np.asarray(values)
    if arr.dtype.kind in "biuf":
        out = arr.astype(np.float64)
    else:
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
    return out


def _ids(values, src, col) -> np.ndarray:
    arr = np.asarray(values)
    if arr.dtype.kind == "f":
        bad = ~np.isfinite(arr) | (arr != np.round(arr))
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError("agent ID must be an integer or a text label", file=src, row=i + 1,
                             column=col, value=arr[i])
        return arr.astype(np.int64)
    if arr.dtype.kind in "iub":
        return arr.astype(np.int64)
    if len(arr) == 0:
        return np.empty(0, np.int64)
    out = arr.astype(object)
    for i, v in enumerate(out):
        if v is None or (isinstance(v, float) and not np.isfinite(v)) or (isinstance(v, str) and not v.strip()):
            raise InputError("agent ID is missing", file=src, row=i + 1, column=col, value=v)
    return np.array([str(v) for v in out], dtype=object)


def _states(values, src) -> np.ndarray:
    arr = np.asarray(values).astype(object)
    lookup = {s: k for k, s in enumerate(STATES)}
    out = np.empty(len(arr), np.int8)
    for i, v in enumerate(arr):
        code = lookup.get(str(v).strip().upper() if v is not None else None)
        if code is None:
            raise InputError(f"unknown state; expected one of {', '.join(STATES)}", file=src,
                             row=i + 1, column="state", value=v)
        out[i] = code
    return out


def _declared_ids(meta) -> np.ndarray | None:
    if meta.get("agent_ids") is not None:
        return _ids(list(meta["agent_ids"]), "meta.json", "agent_ids")
    if meta.get("agent_count") is not None:
        n = meta["agent_count"]
        if not isinstance(n, int) or n < 0:
            raise InputError("agent_count must be a non-negative integer", file="meta.json",
                             column="agent_count", value=n)
        return np.arange(n, dtype=np.int64)
    return None


def _as_kind(arr: np.ndarray, as_text: bool) -> np.ndarray:
    if as_text and arr.dtype.kind != "O":
        return np.array([str(v) for v in arr], dtype=object)
    return arr
