"""Faulty sensing: the reports a real radio delivers, made from a perfect log.

``perturb(log, Faults(...), seed)`` returns the log a base station would have received
had every encounter of ``log`` gone through a faulty radio, and a record of what was
done.  It works on any log -- a simulation's or a real trace -- and touches nothing but
the events (and the status rows of agents that died).  Each encounter [t, a, b] is one
*report*, sent by one agent of the pair (the *reporter*, drawn at random) and stamped
with the reporter's clock.  The faults, in the order they act:

``dying``
    This share of the agents (rounded to a whole number) dies at a time drawn uniformly
    over the log's span [t_0, t_1]: no encounter of a dead agent is reported from then
    on, nor any of its status changes.
``lost``
    Each report is lost independently with this probability.
``burst_lost``, ``burst_length``
    Each agent's radio is down this share of the time, in outages of mean length
    ``burst_length`` s (an alternating renewal process with exponential up and down
    times, started in its stationary state); a report whose reporter is down is lost.
``duplicated``
    Each delivered report is delivered again with this probability, by the pair's other
    agent (both radios reported the contact), up to ``duplicate_delay`` s later
    (uniform), stamped with that agent's clock -- unless that agent is dead or its radio
    down by then.
``false_encounters``
    For every delivered report, a false one is added with this probability: a pair
    drawn uniformly among the agents alive at a time drawn uniformly over [t_0, t_1],
    redrawn (up to ``FALSE_PAIR_TRIES`` times) while the pair met anywhere in the log.
    Most such pairs are far apart: a false encounter is a wormhole in the encounter
    metric.
``clock_offset``, ``clock_drift``
    Agent k's clock reads t + o_k + d_k (t - t_0), with o_k uniform in [-offset,
    offset] s and d_k uniform in [-drift, drift] (s per s).
``jitter``
    Every report's stamp gets Gaussian noise of this standard deviation (s).

Log times are not negative: if a stamp falls before 0 s, every time of the log (stamps,
status changes, static times, a leader's track, ``duration``) is shifted by one
constant so that the earliest is 0 s (the record's ``shift``).  Each fault draws from
its own random stream (spawned from ``seed``), and the same log, faults and seed give
the same output.  The reporters, deaths, losses and outages are drawn per report of the
input log, so they do not depend on the other faults' levels (the same reports are
lost whatever the jitter); duplicates, false encounters, clocks and jitter are drawn
per delivered report, so they change when the losses do.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validate import fraction, non_negative
from ..errors import InputError
from ..log import EncounterLog

MIN_BURST_LENGTH = 0.01
"""Shortest mean outage (s): the outages are drawn one by one."""
FALSE_PAIR_TRIES = 20
"""Draws of a false encounter's pair before one that met elsewhere in the log is kept."""
FAULT_SHARES = ("lost", "burst_lost", "false_encounters", "dying", "duplicated")
"""The faults given as a share (in [0, 1])."""
FAULT_LEVELS = (*FAULT_SHARES, "jitter", "clock_offset", "clock_drift")
"""The fault levels (0: no such fault); ``burst_length`` and ``duplicate_delay`` only
shape the outages and duplicates."""
STREAMS = ("reporter", "dying", "lost", "burst", "duplicated", "false", "clock", "jitter")
"""The random streams spawned from the seed, one per fault (and one for the reporters)."""


@dataclass(frozen=True)
class Faults:
    """Fault levels of :func:`perturb` (module docstring); all zero: no fault."""

    lost: float = 0.0
    burst_lost: float = 0.0
    burst_length: float = 2.0
    false_encounters: float = 0.0
    jitter: float = 0.0
    clock_offset: float = 0.0
    clock_drift: float = 0.0
    dying: float = 0.0
    duplicated: float = 0.0
    duplicate_delay: float = 0.5

    def __post_init__(self):
        for name in FAULT_SHARES:
            object.__setattr__(self, name, fraction(f"faults.{name}", getattr(self, name)))
        if self.burst_lost == 1.0:
            raise InputError("faults.burst_lost must be below 1 (a radio that is never up reports nothing)",
                             value=self.burst_lost)
        for name in ("burst_length", "jitter", "clock_offset", "clock_drift", "duplicate_delay"):
            object.__setattr__(self, name, non_negative(f"faults.{name}", getattr(self, name)))
        if self.burst_length < MIN_BURST_LENGTH and self.burst_lost > 0:
            raise InputError(f"faults.burst_length must be at least {MIN_BURST_LENGTH:g} s when burst_lost is "
                             "positive (shorter outages are independent losses: use lost)", value=self.burst_length)
        if self.clock_drift >= 1:
            raise InputError("faults.clock_drift must be below 1 s per s (a clock that runs backwards)",
                             value=self.clock_drift)

    @property
    def any(self) -> bool:
        """Whether any fault is set."""
        return any(getattr(self, name) for name in FAULT_LEVELS)

    def to_json(self) -> dict[str, float]:
        return dataclasses.asdict(self)


def perturb(log: EncounterLog, faults: Faults, seed: int = 0) -> tuple[EncounterLog, dict[str, Any]]:
    """The log ``log``'s reports become through ``faults`` (module docstring), and a record:
    the faults, the seed and how many reports each fault removed or added.  The record is
    also appended to the returned log's ``meta["faults"]`` (a list: faults applied in turn)."""
    rng = dict(zip(STREAMS, (np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(len(STREAMS)))))
    n, m = log.n_agents, log.n_events
    t0, t1 = (float(log.t.min()), float(log.t.max())) if m else (0.0, 0.0)
    reporter_is_a = rng["reporter"].random(m) < 0.5
    reporter = np.where(reporter_is_a, log.a, log.b)

    death = np.full(n, np.inf)
    dying = rng["dying"].permutation(n)[:int(round(faults.dying * n))]
    death[dying] = rng["dying"].uniform(t0, t1, len(dying))
    alive = (log.t < death[log.a]) & (log.t < death[log.b])
    lost = rng["lost"].random(m) < faults.lost
    down = _outages(rng["burst"], n, t0, t1, faults.burst_lost, faults.burst_length)
    in_outage = _in_outage(down, reporter, log.t)
    delivered = alive & ~lost & ~in_outage
    t, a, b, rep = log.t[delivered], log.a[delivered], log.b[delivered], reporter[delivered]

    other = np.where(rep == a, b, a)
    late = t + rng["duplicated"].uniform(0.0, faults.duplicate_delay, len(t))
    again = ((rng["duplicated"].random(len(t)) < faults.duplicated) & (late < death[other])
             & ~_in_outage(down, other, late))  # the other agent's radio sends it: alive and up
    t = np.concatenate([t, late[again]])
    a, b, rep = np.concatenate([a, a[again]]), np.concatenate([b, b[again]]), np.concatenate([rep, other[again]])
    duplicated = int(again.sum())

    n_false = int(rng["false"].binomial(len(t), faults.false_encounters)) if faults.false_encounters and n >= 2 else 0
    ft, fa, fb = _false_reports(rng["false"], n_false, t0, t1, death, log)
    n_false = len(ft)
    t, a, b = np.concatenate([t, ft]), np.concatenate([a, fa]), np.concatenate([b, fb])
    rep = np.concatenate([rep, np.where(rng["false"].random(len(ft)) < 0.5, fa, fb)])

    offset = rng["clock"].uniform(-faults.clock_offset, faults.clock_offset, n)
    drift = rng["clock"].uniform(-faults.clock_drift, faults.clock_drift, n)
    stamp = t + offset[rep] + drift[rep] * (t - t0) + faults.jitter * rng["jitter"].standard_normal(len(t))
    s_alive = log.status_t < death[log.status_agent]
    s_agent = log.status_agent[s_alive]
    s_t = log.status_t[s_alive] + offset[s_agent] + drift[s_agent] * (log.status_t[s_alive] - t0)  # own clock
    shift = max([0.0, *(-float(x.min()) for x in (stamp, s_t) if len(x))])
    stamp, s_t = stamp + shift, s_t + shift
    order = np.lexsort((b, a, stamp))
    stamp, a, b = stamp[order], a[order], b[order]
    repeated = np.zeros(len(stamp), bool)  # a duplicate landing on its own report's stamp
    repeated[1:] = (np.diff(stamp) == 0) & (a[1:] == a[:-1]) & (b[1:] == b[:-1])

    record = {"faults": faults.to_json(), "seed": int(seed), "shift": shift,
              "counts": {"reports": m, "died": len(dying), "after_death": int((~alive).sum()),
                         "lost": int((alive & lost).sum()), "lost_in_outages": int((alive & ~lost & in_outage).sum()),
                         "duplicated": duplicated, "false": n_false,
                         "repeated": int(repeated.sum()), "delivered": int((~repeated).sum())}}
    meta = {**log.meta, "faults": [*log.meta.get("faults", []), record]}
    if "duration" in meta:  # the log's end moves with the shift, and a late stamp or status time may pass it
        ends = [float(meta["duration"]) + shift, *(float(x.max()) for x in (stamp, s_t) if len(x))]
        meta["duration"] = max(ends)
    out = dataclasses.replace(log, t=stamp[~repeated], a=np.minimum(a, b)[~repeated], b=np.maximum(a, b)[~repeated],
                              status_t=s_t, status_agent=s_agent, status_state=log.status_state[s_alive],
                              static_time=log.static_time + shift, meta=meta,
                              beacon=None if log.beacon is None else dataclasses.replace(log.beacon,
                                                                                         t=log.beacon.t + shift))
    order = np.lexsort((out.status_t, out.status_agent))
    return dataclasses.replace(out, status_t=out.status_t[order], status_agent=out.status_agent[order],
                               status_state=out.status_state[order]), record


def _outages(rng, n: int, t0: float, t1: float, share: float, length: float) -> list[np.ndarray]:
    """Per agent, the (start, end) rows of its radio's outages over [t0, t1] (empty list: none)."""
    if share == 0 or t1 <= t0:
        return []
    up_mean = length * (1 - share) / share
    out = []
    for _ in range(n):
        down = rng.random() < share  # the stationary state at t0; exponential times are memoryless
        t, spans = t0, []
        while t < t1:
            if down:
                end = t + rng.exponential(length)
                spans.append((t, end))
                t = end
            else:
                t += rng.exponential(up_mean)
            down = not down
        out.append(np.array(spans).reshape(-1, 2))
    return out


def _in_outage(down: list[np.ndarray], reporter: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Per report, whether its reporter's radio was down at its time."""
    out = np.zeros(len(t), bool)
    if not down:
        return out
    order = np.argsort(reporter, kind="stable")
    bounds = np.searchsorted(reporter[order], np.arange(len(down) + 1))
    for k, spans in enumerate(down):
        rows = order[bounds[k]:bounds[k + 1]]
        i = np.searchsorted(spans[:, 0], t[rows], side="right") - 1
        out[rows] = (i >= 0) & (t[rows] < spans[np.maximum(i, 0), 1]) if len(spans) else False
    return out


def _false_reports(rng, count: int, t0: float, t1: float, death: np.ndarray, log: EncounterLog):
    """Up to ``count`` false reports (t, a, b): pairs of agents alive at t that never met in
    the log, where ``FALSE_PAIR_TRIES`` draws find one; a time with fewer than two agents
    alive gets none."""
    n = log.n_agents
    met = set((log.a * n + log.b).tolist())
    t = rng.uniform(t0, t1, count)
    a, b = np.full(count, -1, np.int64), np.full(count, -1, np.int64)
    for i in range(count):
        living = np.flatnonzero(death > t[i])
        if len(living) < 2:
            continue
        for _ in range(FALSE_PAIR_TRIES):
            x, y = rng.choice(living, 2, replace=False)
            if min(x, y) * n + max(x, y) not in met:
                break
        a[i], b[i] = min(x, y), max(x, y)
    drawn = a >= 0
    return t[drawn], a[drawn], b[drawn]
