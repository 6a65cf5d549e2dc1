r"""The map's timeline: Betti numbers over sliding windows, and where they change.

An arena can change while the swarm maps it (a door closes, an obstacle appears).  The
map's own answer pools its windows; the timeline says whether and when the answer
changed (Dirafzoon, Bozkurt & Lobaton, "Dynamic Topological Mapping with Biobotic
Swarms", maps sliding windows the same way).

Windows.  By default the timeline's windows are the map's own (:mod:`.windows`: every
length 0.75-1.25 W, starts half a length apart, at most ``MAX_WINDOWS``), read one by
one instead of pooled; ``MapConfig.timeline_length`` / ``timeline_step`` give windows of
their own length and step instead (at most ``MAX_TIMELINE_WINDOWS``, evenly spaced).
Windows are ordered by their middle.  In each window (:func:`split_window`), the
components of its encounter graph that count as regions
(:func:`~.regions.split_regions`) give beta_0^w and its confidence
(:mod:`~swarmtopo.readers.beta0`); each such component is read by the map's reader, its
landmark bands pooled: a component the map already mapped (a region's part of the
window) from the map's own diagrams, any other (a region that split within the window,
or a window of the timeline's own) mapped as a task (:func:`read_component`) with
landmark starts from a stream seeded by one draw from the map's own stream after
everything else the map draws.  So the rest of the map is the same with or without
the timeline, the timeline costs little more than reading (a split window is mapped
again), and it is the same on every engine.  beta_1^w is the sum over the components,
its confidence the reader's combination of theirs.

Segments and change points (:func:`segment`).  Per dimension n, the windows' counts
c_1 .. c_K (in order of their middles; windows without a reading left out) are cut into
segments of constant value u, the cut minimising

    sum over segments of #{windows k in the segment : c_k != u}  +  CHANGE_PENALTY x (segments - 1),

(an exact dynamic programme, vectorised over the start of the last segment; ties go to
its earliest start, then to the smaller value).  A segment must so be backed by more
than CHANGE_PENALTY windows more than contradict it at a log's end, more than
2 x CHANGE_PENALTY in its middle.  A dimension without change has
one segment whose value and confidence are the map's own (pooled) answer.  Otherwise
a segment's confidence is the median confidence of its windows that read its value;
segments run from change point to change point (the first from the first window's
start, the last to the last window's end).

Between segment A (last window i = [s_i, e_i]) and segment B (first window j =
[s_j, e_j]) the change point is ``t = (s_i + e_j) / 2`` with the interval [s_i, e_j]:
a window wholly before the change reads A's value and one wholly after reads B's, so
if windows i and j read right the change lies after s_i (window i is not wholly after
it) and before e_j.  Its ``confidence`` is P(both segments right), the product of
their confidences.  How often the interval holds the true change is measured by
``swarmtopo bench timeline`` (docs/timeline.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import SwarmtopoError
from ..log import EncounterLog
from ..metric.graph import EncounterGraph, WeightedChains
from ..readers.base import BettiReader, RegionReading
from ..readers.beta0 import shipped_beta0_model
from .config import WHOLE_LOG, MapConfig
from .regions import split_regions
from .result import ChangePoint, Segment, Timeline, TimelineWindow, WindowMap
from .tasks import cut_window, describe_part, map_band
from .windows import scaled_windows

MAX_TIMELINE_WINDOWS = 48
"""Most windows of a timeline of its own length and step, as many as the map's own windows
(``MAX_WINDOWS``): a longer log keeps an evenly spaced share."""
CHANGE_PENALTY = 3.0
"""Windows a change point costs in :func:`segment` (module docstring): the least penalty
whose false alarms on the static tuning logs of ``swarmtopo bench timeline`` are at most
5 % (``lab/tune_timeline.py``, docs/timeline.md)."""
CROCKER_BARS = 12
"""Longest H1 bars per timeline window kept for the time x scale picture."""


@dataclass(frozen=True)
class WindowSplit:
    """A window's components that count as regions (:func:`split_window`): beta_0^w and
    its confidence, and per component its label in the window's graph, the map region it
    lies in (-1: none), whether the map mapped it already (the largest of that region's
    components in the window: the region's part, :func:`~.regions.region_part`), and
    its agents."""

    beta0: int
    confidence0: float
    components: list[tuple[int, int, bool, np.ndarray]]


def split_window(cut: tuple[EncounterGraph, np.ndarray], region_of_event: np.ndarray, log: EncounterLog,
                 min_region_events: int, agent_gap: float | None) -> WindowSplit | None:
    """The :class:`WindowSplit` of a cut window (:func:`~.tasks.cut_window`); None when no
    component of it counts as a region.  ``region_of_event``: the map region of each log event."""
    graph, _ = cut
    if graph.n_events < min_region_events:
        return None
    try:
        split = split_regions(log, graph, min_region_events, agent_gap)
    except SwarmtopoError:
        return None
    components, seen = [], set()
    for comp in split.regions:  # most events first, ties by label: each region's first is its part
        events = graph.event_index[split.event_comp == comp]
        region = int(region_of_event[events[0]])
        components.append((int(comp), region, region >= 0 and region not in seen,
                           np.unique(np.concatenate([log.a[events], log.b[events]]))))
        seen.add(region)
    return WindowSplit(len(split.regions), shipped_beta0_model().confidence(split.beta0), components)


def read_component(chains: WeightedChains, span: tuple[float, float], label: int, n_land: int | None,
                   config: MapConfig, bands: tuple[float, ...], reader: BettiReader, entropy: int, index: int
                   ) -> tuple[RegionReading, np.ndarray]:
    """A window component the map did not map (a region split in the window, or a
    timeline window of its own length): mapped once per band, its landmark starts from the
    stream (``entropy``, ``index``), and read; with its scale-free H1 bars."""
    graph, labels = cut_window(chains, span)
    part = graph.subgraph(np.flatnonzero(labels == label))
    info = describe_part(part, span, bands, config)
    rng = np.random.default_rng([entropy, index])
    windows = [map_band(part, span, info.knn_scale, n_land, config, band, int(rng.integers(pool)))[0]
               for band, pool in zip(info.bands, info.pool_sizes)]
    return reader.read([w.diagram for w in windows], [w.n_events for w in windows]), scaled_h1(windows[0])


def scaled_h1(window: WindowMap) -> np.ndarray:
    """A window's finite H1 bar lengths divided by their median, longest first (at most ``CROCKER_BARS``)."""
    lengths = window.diagram.lengths(1)
    lengths = lengths[np.isfinite(lengths) & (lengths > 0)]
    return np.sort(lengths / np.median(lengths))[::-1][:CROCKER_BARS] if len(lengths) else lengths


def timeline_window(span: tuple[float, float], n_events: int, split: WindowSplit,
                    readings: list[tuple[RegionReading, np.ndarray]], reader: BettiReader,
                    maxdim: int) -> TimelineWindow:
    """One timeline window from its split and its components' readings (in the split's order)."""
    betti = {0: split.beta0}
    confidence: dict[int, float | None] = {0: split.confidence0}
    for n in range(1, maxdim + 1):
        if all(n in r.betti for r, _ in readings):
            betti[n] = sum(r.betti[n] for r, _ in readings)
            confidence[n] = reader.map_confidence([r.confidence.get(n) for r, _ in readings], n)
    bars = np.sort(np.concatenate([b for _, b in readings]))[::-1][:CROCKER_BARS] if readings else np.empty(0)
    return TimelineWindow(t0=span[0], t1=span[1], n_events=n_events, betti=betti, confidence=confidence,
                          h1_scaled=bars, region_agents=[agents for *_, agents in split.components])


def segment(values: list[int], penalty: float = CHANGE_PENALTY) -> list[tuple[int, int, int]]:
    """The optimal cut of ``values`` into (start, stop, value) segments (module docstring)."""
    k = len(values)
    if not k:
        return []
    values = np.asarray(values, dtype=np.int64)
    options = np.unique(values)
    # counts[u][i] = #{windows < i reading options[u]}
    counts = np.vstack([np.concatenate([[0], np.cumsum(values == u)]) for u in options])
    best = np.full(k + 1, np.inf)
    best[0] = -penalty
    choice = [(0, 0)] * (k + 1)
    for j in range(1, k + 1):  # every start i < j at once
        agree = counts[:, j:j + 1] - counts[:, :j]  # (values, i)
        u = np.argmax(agree, axis=0)  # the first (smallest) value on ties
        cost = best[:j] + penalty + (j - np.arange(j) - agree[u, np.arange(j)])
        i = int(np.argmin(cost))  # the first (fewest-segment prefix) on ties
        best[j], choice[j] = cost[i], (i, int(u[i]))
    cuts, j = [], k
    while j > 0:
        i, u = choice[j]
        cuts.append((i, j, int(options[u])))
        j = i
    return cuts[::-1]


def build_timeline(windows: list[TimelineWindow | None], length: float, step: float,
                   betti: dict[int, int | None], confidence: dict[int, float | None], log: EncounterLog | None = None,
                   penalty: float = CHANGE_PENALTY, note: str | None = None) -> Timeline:
    """Segments and change points of the mapped timeline windows (module docstring);
    ``betti`` / ``confidence`` are the map's own answer (a dimension's one segment);
    ``log`` dates a change of beta_0 by its encounters (:func:`date_split`)."""
    read = [w for w in windows if w is not None]
    for n, p in confidence.items():  # a confidence the map withholds (uncalibrated), the timeline withholds too
        if p is None:
            for w in read:
                if n in w.confidence:
                    w.confidence[n] = None
    segments: dict[int, list[Segment]] = {}
    changes: list[ChangePoint] = []
    for n, pooled in sorted(betti.items()):
        if pooled is None:
            continue
        mine = [w for w in read if n in w.betti]
        cuts = segment([w.betti[n] for w in mine], penalty)
        if len(cuts) <= 1:
            t_from = mine[0].t0 if mine else math.nan
            t_until = mine[-1].t1 if mine else math.nan
            segments[n] = [Segment(n, pooled, t_from, t_until, confidence.get(n), len(mine))]
            continue
        dated = []
        for (_, j, before), (_, _, after) in zip(cuts[:-1], cuts[1:]):
            last, first = mine[j - 1], mine[j]
            lo, hi = last.t0, first.t1
            t = (lo + hi) / 2
            if n == 0 and log is not None:
                t, lo, hi = date_split(log, last, first, before < after) or (t, lo, hi)
            dated.append((t, lo, hi))
        bounds = [mine[0].t0, *(t for t, _, _ in dated), mine[-1].t1]
        segs = []
        for (i, j, value), t_from, t_until in zip(cuts, bounds[:-1], bounds[1:]):
            known = [w.confidence[n] for w in mine[i:j] if w.betti[n] == value and w.confidence.get(n) is not None]
            segs.append(Segment(n, value, t_from, t_until, float(np.median(known)) if known else None, j - i))
        for (t, lo, hi), a, b in zip(dated, segs[:-1], segs[1:]):
            both = None if a.confidence is None or b.confidence is None else a.confidence * b.confidence
            changes.append(ChangePoint(n, t, a.value, b.value, lo, hi, both))
        segments[n] = segs
    changes.sort(key=lambda c: (c.t, c.dim))
    return Timeline(length=length, step=step, windows=read, segments=segments, changes=changes, note=note)


def date_split(log: EncounterLog, last: TimelineWindow, first: TimelineWindow, split: bool
               ) -> tuple[float, float, float] | None:
    """(t, lo, hi) of a change of beta_0 from the encounters between regions.

    A split (beta_0 grows from window ``last`` to window ``first``): regions are told
    apart by ``first``'s; the last encounter between agents of two of them from the
    start of ``last`` to the end of ``first`` is the last time they were joined, so the
    change is at t = that encounter, within [t, end of ``first``].  A merge (beta_0
    falls): the first such encounter between agents of two of ``last``'s regions, the
    change within [start of ``last``, t].  None when there is no such encounter.
    """
    window = first if split else last
    if len(window.region_agents) < 2:
        return None
    region = np.full(log.n_agents, -1)
    for r, agents in enumerate(window.region_agents):
        region[agents] = r
    ra, rb = region[log.a], region[log.b]
    times = log.t[(ra >= 0) & (rb >= 0) & (ra != rb) & (log.t >= last.t0) & (log.t <= first.t1)]
    if not len(times):
        return None
    return (float(times.max()), float(times.max()), first.t1) if split else (float(times.min()), last.t0,
                                                                             float(times.min()))


def timeline_settings(config: MapConfig, window_length: float) -> tuple[float, float]:
    """(length, step) of the timeline's windows: with ``timeline_length`` or
    ``timeline_step`` set, its own (the length defaulting to the map's window length W);
    else the map's W and ``window_step``; a step of None is half the length."""
    own = config.timeline_length is not None or config.timeline_step is not None
    length = window_length if config.timeline_length is None else config.timeline_length
    step = config.timeline_step if own else config.window_step
    return length, length / 2 if step is None else step


def own_spans(config: MapConfig, window_length: float, times: np.ndarray, cap: int = MAX_TIMELINE_WINDOWS
              ) -> list[tuple[float, float]] | None:
    """The windows of a timeline of its own length and step (``timeline_length`` or
    ``timeline_step`` set) over the sorted event ``times``: at most ``cap``,
    evenly spaced, each holding ``min_region_events`` events (:func:`~.windows.scaled_windows`);
    None for the map's own windows."""
    if config.timeline_length is None and config.timeline_step is None:
        return None
    length, step = timeline_settings(config, window_length)
    if length == WHOLE_LOG:
        return []
    spans, _ = scaled_windows(times, [length], step, cap, config.min_region_events)
    return [span for span in spans if span is not None]


def no_timeline_note(config: MapConfig, length: float) -> str:
    """Why a map has no timeline windows."""
    if config.timeline_length == WHOLE_LOG:
        return "no timeline (--timeline-length none)"
    if length == WHOLE_LOG:
        return "no timeline: the log was mapped as one window (shorter than a window, or --window-length none)"
    return (f"no timeline: no window of {length:.3g} s holds enough encounters to map (or the log is shorter than "
            "one)")
