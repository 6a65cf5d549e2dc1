"""What the encounters say about faulty sensing, read before the map is built.

A duplicated report -- one contact reported twice, a moment apart -- is a pair meeting
again within a gap or two, which a walker seldom does: on 78 clean cockroach logs of
the accuracy benchmark's tuning cases (200-400 agents) at most 3.9 % of the events repeat
their pair's within ``DUPLICATE_GAPS`` x g (g the median agent gap; 2 % but in the
sparsest cells), against 9-11 % with 10 % of the reports duplicated
(``lab/fault_screen.py``).  Beyond ``CLEAN_DUPLICATE_SHARE`` such repeats are merged into their pair's
first event before anything else (their tiny gaps would shrink g, and with it every
time scale of the map).

A false encounter -- a report of two agents that never met -- is a wormhole in the
encounter metric: it joins two far-apart parts of the arena at the cost of one hop, and
a few percent of them close every hole (or, joining two sides of the arena, open a
hole that is not there).  A true encounter is seldom alone: two agents that met are
near each other, so the rest of the log links them again within a short detour -- a
common partner met soon before or after, a few hops through agents nearby.

The *detour* of an event [t, a, b] is the shortest path from agent a at t to agent b at
t on the chain graph (consecutive events of one agent joined) without the event
itself, each edge costing its time gap |t_i - t_j| plus a hop H = ``HOP_GAPS`` x g
(g the median agent gap of the mapped log,
:func:`~swarmtopo.pipeline.motion.median_agent_gap`, so every length follows the
log's own time scale, losses included).  An event whose detour is longer than
``DETOUR_HOPS`` x H is *uncorroborated* (u: their share).  On the fault benchmark's
tuning cases (``lab/fault_screen.py``) this flags about 2 % of a clean log's encounters
and 94-96 % of false ones.

Clean logs have a few uncorroborated encounters too (1-4 % on the accuracy benchmark's
tuning cases: agents alone in a corner), but few whose detour is longer than
``FAR_HOPS`` x H: a false encounter between far-apart agents has one.  The share of
such *far* encounters is the evidence of false encounters: on 78 clean tuning logs of
200-400 agents it is at most 0.7 % (in the sparsest cells, 200 x 30 s; 0.4 % in the
others), and up to 1.1 % in shorter logs (200 agents x 20 s: events near the log's ends
have fewer detours); 0.4-0.8 % with 0.5 % false encounters, 0.8-1.2 % with 1 %, 2 %
and more with 3 %.  With ``uncorroborated = "auto"`` (the default) a log of at least
``MIN_AGENTS`` agents whose far share exceeds ``CLEAN_FAR_SHARE`` has its
uncorroborated encounters dropped before mapping, and a warning; every other log maps
exactly as before.  False encounters under about 1 % are therefore not found, though
they already add holes that are not there (docs/accuracy.md, "Faulty sensing").
Heavy losses (half the reports) in a sparse swarm can lengthen detours as much, so the
warning names both.

Timing errors -- jitter, clock offsets -- and heavy losses leave far encounters rare
but many encounters without a short detour: the share u rises from 1-4 % (clean
tuning logs) to 4-10 % (1 s of jitter, offsets of up to 5 s, half the reports lost).
A log whose u exceeds ``POOR_SHARE`` is mapped as it is, with a warning naming those
faults.  A map of a log with either sign has its beta_1 confidence recalibrated on
faulty logs (:func:`~swarmtopo.readers.recalibrated.recalibration`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numba import njit

from ..log import EncounterLog
from ..metric._kernels import _heap_pop, _heap_push
from ..metric.graph import event_slice
from .motion import MIN_AGENTS, median_agent_gap, recontact_gaps

DUPLICATE_GAPS = 2.0
"""A pair's event closer than this many median gaps g to the pair's previous one is a repeat."""
CLEAN_DUPLICATE_SHARE = 0.06
"""Largest share of repeats in a log taken as free of duplicated reports (module docstring)."""
HOP_GAPS = 6.0
"""H / g: the hop cost of a detour, in median agent gaps (module docstring)."""
DETOUR_HOPS = 8.0
"""Longest detour of a corroborated event, in hops H."""
FAR_HOPS = 12.0
"""Shortest detour of a *far* event, in hops H."""
CLEAN_FAR_SHARE = 0.012
"""Largest share of far events in a log taken as clean: above every clean log measured
(module docstring)."""
POOR_SHARE = 0.06
"""Largest share u of uncorroborated events in a log taken as well sensed (module docstring)."""
MAX_DROP_SHARE = 0.25
"""Largest share u the screen drops: beyond it the log is too sparse for detours to tell
false encounters from true ones (every fault level of the fault benchmark's tuning cases
stays under 0.14), and nothing is dropped."""


@dataclass(frozen=True)
class FaultScreen:
    """What the encounters say about the sensing (module docstring).

    The shares are None for a swarm of fewer than ``MIN_AGENTS`` (not read);
    ``merged`` is how many repeats were merged as duplicated reports, ``dropped`` how
    many uncorroborated events were left out of the map.
    """

    uncorroborated_share: float | None
    far_share: float | None
    duplicate_share: float | None
    dropped: int
    merged: int

    @property
    def suspected(self) -> bool:
        """Whether the log shows false encounters, timing errors or heavy losses (a map of
        it has its confidence recalibrated)."""
        return self.false_encounters or self.poorly_corroborated

    @property
    def duplicated(self) -> bool:
        """Whether the log shows duplicated reports (repeats above ``CLEAN_DUPLICATE_SHARE``)."""
        return self.duplicate_share is not None and self.duplicate_share > CLEAN_DUPLICATE_SHARE

    @property
    def false_encounters(self) -> bool:
        """Whether the log shows false encounters (far share above ``CLEAN_FAR_SHARE``, in
        a log not too sparse to tell: u at most ``MAX_DROP_SHARE``)."""
        return (self.far_share is not None and self.far_share > CLEAN_FAR_SHARE
                and self.uncorroborated_share <= MAX_DROP_SHARE)

    @property
    def poorly_corroborated(self) -> bool:
        """Whether the log shows timing errors or heavy losses (u above ``POOR_SHARE``)."""
        return self.uncorroborated_share is not None and self.uncorroborated_share > POOR_SHARE

    def describe(self) -> str:
        """One line for the printed verdict and the report."""
        if self.uncorroborated_share is None:
            return f"sensing: not read (fewer than {MIN_AGENTS} agents)"
        text = (f"sensing: {100 * self.uncorroborated_share:.1f} % of the encounters uncorroborated, "
                f"{100 * self.far_share:.2f} % far (clean logs: at most {100 * CLEAN_FAR_SHARE:g} %), "
                f"{100 * self.duplicate_share:.1f} % repeats")
        return (text + (f"; {self.merged} duplicates merged" if self.merged else "")
                + (f"; {self.dropped} uncorroborated left out of the map" if self.dropped else ""))


def screen_faults(log: EncounterLog, mode: str = "auto",
                  window: tuple[float | None, float | None] | None = None) -> tuple[FaultScreen, EncounterLog]:
    """The fault screen of ``log``'s events in ``window`` (None: all) and the log to map:
    inside the window, repeats merged when the log's share of them exceeds
    ``CLEAN_DUPLICATE_SHARE``, then uncorroborated events dropped when its share of far
    events exceeds ``CLEAN_FAR_SHARE`` (``mode`` ``auto``); ``drop`` does both whatever
    the shares, ``keep`` reads nothing."""
    unread = FaultScreen(None, None, None, 0, 0)
    if mode == "keep" or log.n_agents < MIN_AGENTS and mode == "auto":
        return unread, log
    inside = slice(0, log.n_events) if window is None else slice(*event_slice(log, window))
    mapped = replace(log, t=log.t[inside], a=log.a[inside], b=log.b[inside])
    gap = median_agent_gap(mapped)
    if gap is None:
        return unread, log
    repeat = np.zeros(log.n_events, bool)
    repeat[inside] = recontact_gaps(mapped) < DUPLICATE_GAPS * gap
    repeats = float(repeat[inside].mean())
    merged = int(repeat.sum()) if mode == "drop" or repeats > CLEAN_DUPLICATE_SHARE else 0
    if merged:
        log = replace(log, t=log.t[~repeat], a=log.a[~repeat], b=log.b[~repeat])
        inside = slice(0, log.n_events) if window is None else slice(*event_slice(log, window))
        mapped = replace(log, t=log.t[inside], a=log.a[inside], b=log.b[inside])
        gap = median_agent_gap(mapped)
        if gap is None:  # nothing but repeats: no detour to read
            return FaultScreen(None, None, repeats, 0, merged), log
    hop = HOP_GAPS * gap
    detour = detours(mapped, hop, FAR_HOPS * hop) / hop
    lone = np.zeros(log.n_events, bool)
    lone[inside] = detour > DETOUR_HOPS
    share, far = float(lone[inside].mean()), float(np.mean(detour > FAR_HOPS))
    screen = FaultScreen(share, far, repeats, 0, merged)
    if not (mode == "drop" or screen.false_encounters):
        return screen, log
    keep = ~lone
    return (replace(screen, dropped=int(lone.sum())),
            replace(log, t=log.t[keep], a=log.a[keep], b=log.b[keep]))


def fault_warnings(screen: FaultScreen, recalibrated: bool) -> list[str]:
    """The map's warnings about a log whose encounters the rest of the log does not back;
    ``recalibrated``: its beta_1 confidence went through the faulty logs' recalibration."""
    trust = ("its beta_1 confidence is recalibrated on faulty logs" if recalibrated
             else "the confidence was calibrated on clean logs only")
    where = "(docs/model.md, 'Faulty sensing')"
    out = []
    if screen.duplicated:  # read, so merged (uncorroborated = keep reads nothing)
        out.append(f"{100 * screen.duplicate_share:.1f} % of the encounters repeat their pair's within "
                   f"{DUPLICATE_GAPS:g} median gaps (clean logs stay under {100 * CLEAN_DUPLICATE_SHARE:g} %): "
                   f"duplicated reports are suspected; {screen.merged} were merged into their pair's first {where}")
    if screen.false_encounters:  # read, so dropped
        out.append(f"{100 * screen.far_share:.2f} % of the encounters join agents that the rest of the log places "
                   f"far apart (clean logs stay under {100 * CLEAN_FAR_SHARE:g} %): false encounters (or, in a sparse "
                   f"swarm, heavy losses) are suspected; the {screen.dropped} uncorroborated encounters were left "
                   f"out of the map, and {trust} {where}")
    elif screen.poorly_corroborated:
        sparse = ((", or the swarm is too sparse for its encounters to back each other"
                   + ("" if screen.dropped else " (nothing was left out)"))
                  if screen.uncorroborated_share > MAX_DROP_SHARE else "")
        out.append(f"{100 * screen.uncorroborated_share:.1f} % of the encounters have no short detour through the "
                   f"rest of the log (clean logs stay under {100 * POOR_SHARE:g} %): timing errors (jitter, clock "
                   f"offsets) or heavy losses are suspected{sparse}; the map is less certain, and {trust} {where}")
    if screen.dropped and not screen.false_encounters:  # dropped on request (uncorroborated = drop)
        out.append(f"{screen.dropped} uncorroborated encounters were left out of the map (uncorroborated = drop) "
                   f"{where}")
    return out


def detours(log: EncounterLog, hop: float, radius: float) -> np.ndarray:
    """Per event [t, a, b], the length of the shortest path from agent a at t to agent b at
    t that does not use the event itself, on the chain graph (consecutive events of one
    agent joined, each edge costing |t_i - t_j| + ``hop``); inf beyond ``radius``."""
    if log.n_events == 0:
        return np.zeros(0)
    agent = np.concatenate([log.a, log.b])
    event = np.concatenate([np.arange(log.n_events), np.arange(log.n_events)])
    order = np.lexsort((event, agent))
    agent, event = agent[order], event[order]
    same = agent[1:] == agent[:-1]
    prev = np.full((log.n_events, 2), -1, np.int64)  # per event, per side (a, b): previous event
    nxt = np.full((log.n_events, 2), -1, np.int64)
    side = (log.b[event] == agent).astype(np.int64)  # 0: the incidence is the event's a
    prev[event[1:][same], side[1:][same]] = event[:-1][same]
    nxt[event[:-1][same], side[:-1][same]] = event[1:][same]
    return _detours(log.t, prev, nxt, float(hop), float(radius))


@njit(cache=True)
def _detours(t, prev, nxt, hop, radius):
    # the relaxation is written out at both places: a helper returning (size, n_touched)
    # measured 1.8x slower (benchmarks/bench_fault_screen.py)
    m = len(t)
    dist = np.full(m, np.inf)
    touched = np.empty(m, np.int64)
    keys = np.empty(8 * m + 8)
    nodes = np.empty(8 * m + 8, np.int64)
    out = np.full(m, np.inf)
    for e in range(m):
        size = 0
        n_touched = 0
        for v in (prev[e, 0], nxt[e, 0]):  # agent a's events around e
            if v >= 0:
                d = abs(t[e] - t[v]) + hop
                if d < dist[v]:
                    if dist[v] == np.inf:
                        touched[n_touched] = v
                        n_touched += 1
                    dist[v] = d
                    size = _heap_push(keys, nodes, size, d, v)
        best = np.inf
        while size > 0:
            d = keys[0]
            u = nodes[0]
            size = _heap_pop(keys, nodes, size)
            if d > dist[u]:
                continue
            if d >= best or d > radius:
                break
            for target in (prev[e, 1], nxt[e, 1]):  # agent b's events around e
                if u == target:
                    best = min(best, d + abs(t[e] - t[u]) + hop)
            for s in range(2):
                for v in (prev[u, s], nxt[u, s]):
                    if v >= 0 and v != e:
                        nd = d + abs(t[u] - t[v]) + hop
                        if nd < dist[v]:
                            if dist[v] == np.inf:
                                touched[n_touched] = v
                                n_touched += 1
                            dist[v] = nd
                            size = _heap_push(keys, nodes, size, nd, v)
        for i in range(n_touched):
            dist[touched[i]] = np.inf
        out[e] = best if best <= radius else np.inf
    return out
