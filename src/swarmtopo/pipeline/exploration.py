r"""Beacon-led exploration: local maps along a leader's path, stitched into a global map.

A swarm kept within a leash R of a moving, localized leader (``beacon.csv`` and
``meta.json`` ``leash``; :mod:`swarmtopo.sim.leash`) sees only the part of the arena
around the leader.  Its log is mapped as usual, and besides:

1. **Local maps.**  The timeline's windows (:mod:`.timeline`) are the local maps: each
   is mapped and read on its own (holes counted, beta_1^w).  Their length is the time
   the leader takes to travel ``EXPLORATION_TRAVEL`` R at its mean moving speed v_L
   (at least the map's own window length W, the time the swarm needs to map anything;
   with the whole log as one window, ``--paper``, the travel alone; without a moving
   leader, W),
   their step half that, at most ``MAX_EXPLORATION_WINDOWS`` of them.
2. **Holes in view.**  The windows' counts, in time order, are cut into segments of
   constant count by the timeline's penalised fit (:func:`.timeline.segment`, with
   ``EXPLORATION_PENALTY`` windows per change).  Windows half overlap, so two consecutive
   windows share half their encounters: a count that stays the same from one to the
   next is the same holes -- for as long as one hole stays in view.  The leader travels
   about ``HANDOVER_TRAVEL`` R while a hole is in the swarm's view (it comes in at the
   swarm's front and leaves at its trailing edge, R behind the leader), so a segment of
   count c over which the leader travels k such distances (k = round(travel /
   (``HANDOVER_TRAVEL`` R)) >= 2) held k x c holes, one after the other: it is cut in k
   equal parts, and at each cut the c holes in view leave and c new ones come in (a hole
   leaving as the next comes in leaves the count unchanged).  Where the count rises by
   d, d holes come into view; where it falls by d, the d holes longest in view leave it
   (first in, first out: the leader moves on, and the holes it reached first fall
   behind first).  A change is dated at the middle of the last window of the one
   segment and the first of the next, as the timeline dates changes.
3. **Where each hole is.**  The leash is the swarm's trailing edge: agents that fall
   more than R behind the leader are steered back, while ahead of it the swarm reaches
   only as far as its agents wander.  A hole leaves the swarm's view when that trailing
   edge passes it, so it lies about R behind the leader's position at that moment,
   measured along the leader's path (kept within the stretch of path the hole was in
   view from): that point is its estimate.  Its uncertainty radius is
   ``LATERAL_FRACTION`` R (it may lie to either side of the path) plus the leader's
   travel in one window step (the resolution of the dates).  A hole still in view at
   the last window (the leader stopped near it) is placed halfway along the stretch of
   path it was in view from, within R plus one step.  Holes in view at the first or the
   last window are ``open``: the time they came into view, or left it, is unknown.
4. **One count per hole.**  A leader that comes back sees a hole again: two holes whose
   times in view do not overlap and whose estimates are closer than
   ``REVISIT_FRACTION`` R are one hole (its estimate the windows-weighted mean, its
   radius the larger).  Holes in view at the same time are different holes.

The global beta_1 is the number of holes; beta_0 is the map's.  Its confidence is not
calibrated (None).  Warnings: a leash shorter than ``SHORT_LEASH`` r_d.  With fewer
than ``MIN_LOCAL_MAPS`` local maps there is no global
count, and the map keeps its pooled beta_1.  The track is first cut to the mapped
events' span (a leader's fix outside it says nothing about them).  Warnings: a leader faster than ``FAST_LEADER`` v_c (when the log
gives v_c); a stretch of the leader's path longer than R without a local map (too few
encounters there); too few local maps to tell a hole from noise.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import shapely

from ..beacon import BeaconTrack
from ..log import EncounterLog
from .result import Exploration, ExploredHole, TimelineWindow
from .timeline import segment

EXPLORATION_TRAVEL = 0.2
"""A local map's window: the time the leader takes to travel this share of the leash R.
It, ``EXPLORATION_PENALTY`` and ``HANDOVER_TRAVEL`` were chosen on the tuning cases of
``swarmtopo bench exploration`` (``lab/tune_exploration.py``, docs/exploration.md)."""
MAX_EXPLORATION_WINDOWS = 240
"""Most local maps of one log (an evenly spaced share of a longer log's windows)."""
HANDOVER_TRAVEL = 1.3
"""How far (a share of R) the leader travels while one hole stays in the swarm's view: a
stretch of constant count c over k such travels held k x c holes, handed over."""
LATERAL_FRACTION = 0.5
"""Uncertainty radius of a hole's position, as a share of R (plus the leader's travel in one window step)."""
REVISIT_FRACTION = 0.5
"""Holes never in view together and closer than this share of R are one hole seen twice."""
FAST_LEADER = 0.25
"""A leader faster than this share of the agents' speed v_c leaves the swarm behind (docs/exploration.md)."""
EXPLORATION_PENALTY = 2.0
"""Windows a change of the count costs in the segmentation of the local counts (:func:`.timeline.segment`)."""
SHORT_LEASH = 5.0
"""A leash shorter than this many detection radii r_d keeps a swarm too small to enclose
most holes (docs/exploration.md, "Limits"): warned of."""
MIN_LOCAL_MAPS = 2 * EXPLORATION_PENALTY + 2
"""Fewest local maps for a hole count: a segment between two changes needs more than 2 x the penalty."""


def leash_of(log: EncounterLog) -> float | None:
    """The leash R (mm) of a beacon-led log, None unless it has a leader's track and ``meta.json`` ``leash``."""
    leash = log.meta.get("leash")
    return float(leash) if log.beacon is not None and isinstance(leash, (int, float)) and leash > 0 else None


def leader_speed(track: BeaconTrack) -> float:
    """The leader's mean speed while moving, mm/s (0 if it never moves)."""
    steps = np.diff(track.arclength())
    moving = float(np.diff(track.t)[steps > 0].sum())
    return float(steps.sum()) / moving if moving > 0 else 0.0


def exploration_windows(log: EncounterLog, window_length: float, span: tuple[float, float]) -> tuple[float, float]:
    """(length, step) s of the local maps over the events' ``span`` (module docstring, 1):
    half a length apart, or further apart if that would make more than
    ``MAX_EXPLORATION_WINDOWS``; an infinite length when the leader does not move and the
    map is one window."""
    track = log.beacon.between(*span)
    speed = leader_speed(track)
    length = window_length
    if speed > 0:
        travel = EXPLORATION_TRAVEL * leash_of(log) / speed
        length = max(window_length, travel) if math.isfinite(window_length) else travel  # --paper: the travel
    if not math.isfinite(length):
        return length, length
    return length, max(length / 2, (span[1] - span[0] - length) / (MAX_EXPLORATION_WINDOWS - 1))


def stitch(windows: list[TimelineWindow], track: BeaconTrack, leash: float, length: float, step: float,
           beta0: int, meta: dict, span: tuple[float, float], penalty: float = EXPLORATION_PENALTY,
           handover: float = HANDOVER_TRAVEL) -> Exploration:
    """The global map of the local maps ``windows`` (read, in order of their middles; module
    docstring) of the events in ``span`` = (first, last) time; the track is cut to it.  With
    fewer than ``MIN_LOCAL_MAPS`` local maps its beta_1 is None (no global count)."""
    warnings = _track_warnings(track, span)
    track = track.between(*span)
    speed = leader_speed(track)
    read = [w for w in windows if 1 in w.betti]
    enough = len(read) >= MIN_LOCAL_MAPS
    resolution = speed * step
    holes: list[ExploredHole] = []
    if enough:
        arc = track.arclength()
        first = np.unique(arc, return_index=True)[1]  # the rows where the path grows: arclength -> time
        cuts = segment([w.betti[1] for w in read], penalty)
        bounds = [read[0].t0] + [(read[j - 1].t0 + read[j].t1) / 2 for _, j, _ in cuts[:-1]] + [read[-1].t1]
        phases = []  # (start, count, windows, handover: every hole in view is a new one)
        for (i, j, value), t0, t1 in zip(cuts, bounds[:-1], bounds[1:]):
            s0, s1 = np.interp([t0, t1], track.t, arc)
            parts = min(max(1, round((s1 - s0) / (handover * leash))), j - i) if value else 1
            cut_times = np.interp(s0 + (s1 - s0) * np.arange(1, parts) / parts, arc[first], track.t[first])
            phases += [(t, value, (j - i) / parts, k > 0) for k, t in enumerate([t0, *cut_times])]
        in_view: list[list] = []  # [t_in, windows] of each hole in view, oldest first
        for t_start, value, count, fresh in phases:
            leaving = len(in_view) if fresh else max(len(in_view) - value, 0)  # the holes longest in view leave
            holes += [_hole(track, arc, first, leash, t_in, t_start, seen, resolution, open_=t_in == read[0].t0)
                      for t_in, seen in in_view[:leaving]]
            in_view = in_view[leaving:] + [[t_start, 0.0] for _ in range(value - len(in_view) + leaving)]
            for hole in in_view:
                hole[1] += count
        holes += [_hole(track, arc, first, leash, t_in, read[-1].t1, count, resolution, open_=True)
                  for t_in, count in in_view]
        holes = _merge_revisits(holes, REVISIT_FRACTION * leash)
    leader_x, leader_y = track.position([(w.t0 + w.t1) / 2 for w in read])
    return Exploration(leash=leash, leader_speed=speed, length=length, step=step,
                       betti={0: beta0, 1: len(holes) if enough else None},
                       holes=sorted(holes, key=lambda h: h.t_in), windows=read,
                       leader_xy=np.column_stack([leader_x, leader_y]),
                       coverage=float(reach(np.column_stack([track.x, track.y]), leash).area),
                       warnings=warnings + _warnings(read, track, leash, speed, meta))


def _hole(track: BeaconTrack, arc: np.ndarray, first: np.ndarray, leash: float, t_in: float, t_out: float,
          windows: float, resolution: float, open_: bool) -> ExploredHole:
    """A hole in view from ``t_in`` to ``t_out`` (module docstring, 3): on the leader's path
    R behind where the leader was when the hole left the swarm's view (its trailing edge, the
    leash), within the part of the path it was in view from; a hole still in view at the end,
    halfway along that part.  ``arc``: the track's arclength at each row, ``first``: the rows
    where it grows."""
    s_in, s_out = np.interp([t_in, t_out], track.t, arc)
    at_end = t_out >= track.t[-1] or s_out >= arc[-1]
    s_hole = (s_in + s_out) / 2 if at_end else min(max(s_out - leash, s_in), s_out)
    x = float(np.interp(s_hole, arc[first], track.x[first]))
    y = float(np.interp(s_hole, arc[first], track.y[first]))
    radius = (leash if at_end else LATERAL_FRACTION * leash) + resolution
    return ExploredHole(x, y, radius, float(t_in), float(t_out), int(round(windows)), bool(open_))


def _merge_revisits(holes: list[ExploredHole], distance: float) -> list[ExploredHole]:
    """One hole for each group of holes never in view together and closer than ``distance`` (module docstring, 4)."""
    groups = [[h] for h in holes]
    while pair := next(((a, b) for a, b in itertools.combinations(range(len(groups)), 2)
                        if _revisit(groups[a], groups[b], distance)), None):
        groups[pair[0]] += groups.pop(pair[1])
    out = []
    for group in groups:
        if len(group) == 1:
            out.append(group[0])
            continue
        w = np.array([max(h.windows, 1) for h in group], dtype=float)
        out.append(ExploredHole(float(np.average([h.x for h in group], weights=w)),
                                float(np.average([h.y for h in group], weights=w)),
                                max(h.radius for h in group), min(h.t_in for h in group),
                                max(h.t_out for h in group), int(w.sum()), any(h.open for h in group)))
    return out


def _revisit(a: list[ExploredHole], b: list[ExploredHole], distance: float) -> bool:
    apart = all(h.t_out <= k.t_in or k.t_out <= h.t_in for h in a for k in b)
    close = math.hypot(np.mean([h.x for h in a]) - np.mean([k.x for k in b]),
                       np.mean([h.y for h in a]) - np.mean([k.y for k in b])) < distance
    return apart and close


def reach(points: np.ndarray, leash: float):
    """The area (a shapely geometry, mm) within R of the leader's positions ``points`` (P, 2),
    taken as a path: what the swarm can have seen."""
    line = shapely.Point(points[0]) if len(np.unique(points, axis=0)) == 1 else shapely.LineString(points)
    return line.buffer(leash)


def _track_warnings(track: BeaconTrack, span: tuple[float, float]) -> list[str]:
    """The leader's track does not cover the mapped events."""
    start, end = span
    if track.t[0] <= start and track.t[-1] >= end:
        return []
    return [f"the leader's track (beacon.csv) runs from {track.t[0]:g} to {track.t[-1]:g} s but the encounters mapped "
            f"run from {start:g} to {end:g} s: outside its rows the leader is taken to stand at its first or last "
            "position"]


def _warnings(read: list[TimelineWindow], track: BeaconTrack, leash: float, speed: float, meta: dict) -> list[str]:
    """Why the global map may miss holes (module docstring)."""
    out = []
    v_c = meta.get("v_c")
    if isinstance(v_c, (int, float)) and v_c > 0 and speed > FAST_LEADER * v_c:
        out.append(f"the leader moved at {speed:.3g} mm/s, faster than {FAST_LEADER:g} x the agents' speed v_c = "
                   f"{v_c:g} mm/s: the swarm trails behind it and holes it passes can go unseen (docs/exploration.md)")
    r_d = meta.get("r_d")
    if isinstance(r_d, (int, float)) and 0 < r_d and leash < SHORT_LEASH * r_d:
        out.append(f"the leash R = {leash:g} mm is less than {SHORT_LEASH:g} x r_d = {SHORT_LEASH * r_d:g} mm: the swarm "
                   f"round the leader is too small to enclose a hole about R or more across, and such holes go unseen")
    if len(read) < MIN_LOCAL_MAPS:
        out.append(f"only {len(read)} local maps along the leader's path (at least {MIN_LOCAL_MAPS:.0f} are needed "
                   "to tell a hole from a misread window): no global count; beta_1 is the pooled map's")
    ends = [track.t[0]] + [t for w in read for t in (w.t0, w.t1)] + [track.t[-1]]
    for gap_start, gap_end in zip(ends[::2], ends[1::2]):  # from each window's end to the next one's start
        travelled = track.distance_travelled(gap_start, gap_end) if gap_end > gap_start else 0.0
        if travelled > leash:
            out.append(f"no local map from {gap_start:.0f} to {gap_end:.0f} s, while the leader travelled "
                       f"{travelled:.0f} mm (more than the leash R = {leash:g} mm): too few encounters there; holes "
                       "it passed are not counted")
    return out

