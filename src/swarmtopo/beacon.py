"""The leader's track: where a localized beacon was, over time.

In beacon-led exploration (docs/exploration.md) a leader -- a cart or a UAV carrying a
beacon, positioned by GPS or tracking -- moves through an arena too large for the swarm
to cover at once, and the agents are kept within a leash of it.  Its position is the
one localized quantity of the deployment: a log folder's ``beacon.csv`` (``t, x, y``,
seconds and mm) and :attr:`swarmtopo.log.EncounterLog.beacon`.

A :class:`BeaconTrack` is piecewise linear between its rows (the leader moves at a
constant velocity between two fixes) and stays at its first and last rows before and
after them.  :func:`track_along` makes one from a path and a speed (the GeoJSON form
of ``swarmtopo simulate --beacon``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validate import non_negative, positive
from .errors import InputError

BEACON_COLUMNS = ("t", "x", "y")


@dataclass(frozen=True, eq=False)
class BeaconTrack:
    """Leader positions (mm) at strictly increasing times (s), linear between rows."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray

    @classmethod
    def from_columns(cls, t, x, y, *, source: str = "beacon", rows=None) -> "BeaconTrack":
        """A checked track: InputError naming the source, 1-based row, column and value
        unless times are finite, >= 0 and strictly increasing and positions finite."""
        cols = {name: np.asarray(values, dtype=np.float64) for name, values in zip(BEACON_COLUMNS, (t, x, y))}
        n = len(cols["t"])
        rows = np.arange(1, n + 1) if rows is None else np.asarray(rows)
        if n == 0:
            raise InputError("the leader's track has no rows", file=source)
        if not len(cols["x"]) == len(cols["y"]) == n:
            raise InputError("the leader's track needs as many x and y as t", file=source)
        for name, values in cols.items():
            bad = ~np.isfinite(values) | ((values < 0) if name == "t" else False)
            if bad.any():
                i = int(np.argmax(bad))
                what = "a time in seconds >= 0" if name == "t" else "a finite position in mm"
                raise InputError(f"not {what}", file=source, row=int(rows[i]), column=name, value=float(values[i]))
        steps = np.diff(cols["t"])
        if (steps <= 0).any():
            i = int(np.argmax(steps <= 0)) + 1
            raise InputError(f"times must increase from row to row (the row before has t = {cols['t'][i - 1]:g})",
                             file=source, row=int(rows[i]), column="t", value=float(cols["t"][i]))
        return cls(cols["t"], cols["x"], cols["y"])

    def position(self, t) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) of the leader at time(s) ``t``: linear between rows, held outside them."""
        t = np.asarray(t, dtype=np.float64)
        return np.interp(t, self.t, self.x), np.interp(t, self.t, self.y)

    def between(self, start: float, end: float) -> "BeaconTrack":
        """The track on [start, end] (start <= end): its rows inside, and its positions at
        ``start`` and ``end`` (held before its first row and after its last)."""
        inside = (self.t > start) & (self.t < end)
        t = np.r_[start, self.t[inside], end] if end > start else np.array([start])
        x, y = self.position(t)
        return BeaconTrack(t, x, y)

    def arclength(self) -> np.ndarray:
        """Path length (mm) the leader has travelled at each row (non-decreasing, 0 at the first)."""
        return np.r_[0.0, np.cumsum(np.hypot(np.diff(self.x), np.diff(self.y)))]

    def distance_travelled(self, t0: float, t1: float) -> float:
        """Path length (mm) of the leader between times ``t0`` <= ``t1``."""
        s0, s1 = np.interp([t0, t1], self.t, self.arclength())
        return float(s1 - s0)

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        return f"BeaconTrack(rows={len(self.t)}, t={self.t[0]:g}..{self.t[-1]:g} s)"


def track_along(path, speed: float, *, start: float = 0.0, dwell: float = 0.0,
                source: str = "beacon path") -> BeaconTrack:
    """The track of a leader that waits at the first vertex of ``path`` (mm, at least one
    point) until ``start`` s, then walks the polyline at ``speed`` mm/s, stopping ``dwell``
    s at every later vertex, and stays at its end."""
    speed = positive("speed", speed)
    start = non_negative("start", start)
    dwell = non_negative("dwell", dwell)
    xy = np.asarray(path, dtype=np.float64)
    if xy.ndim != 2 or xy.shape[1] != 2 or not len(xy) or not np.isfinite(xy).all():
        raise InputError("a beacon path is a list of finite [x, y] points", file=source)
    steps = np.hypot(*np.diff(xy, axis=0).T)
    xy = xy[np.r_[True, steps > 0]]  # repeated vertices add no time
    legs = steps[steps > 0] / speed
    times, points, t = [0.0], [xy[0]], start
    if start > 0:
        times.append(start)
        points.append(xy[0])
    for leg, point in zip(legs, xy[1:]):
        t += leg
        times.append(t)
        points.append(point)
        if dwell > 0:
            t += dwell
            times.append(t)
            points.append(point)
    points = np.asarray(points)
    return BeaconTrack.from_columns(times, points[:, 0], points[:, 1], source=source)


LEADER_SPEED = 2.0
"""Default speed (mm/s) of :func:`long_axis_track`: v_c / 7.5, slow enough for the paper's swarm
(v_c = 15 mm/s, l* = 30 mm) to keep round the leader (docs/exploration.md)."""
LEADER_SETTLE = 30.0
"""Seconds :func:`long_axis_track`'s leader waits at its start while the swarm spreads round it."""


def long_axis_track(bounds, leash: float, speed: float = LEADER_SPEED, *, start: float = LEADER_SETTLE
                    ) -> BeaconTrack:
    """A leader that sweeps an arena once along the middle of the long axis of its bounding
    box ``(xmin, ymin, xmax, ymax)``: from ``leash`` in from one end to ``leash`` in from the
    other (from the middle to the middle when the box is shorter than 2 leash), after
    waiting ``start`` s."""
    xmin, ymin, xmax, ymax = (float(v) for v in bounds)
    leash = positive("leash", leash)
    along_x = xmax - xmin >= ymax - ymin
    lo, hi = (xmin, xmax) if along_x else (ymin, ymax)
    middle = (ymin + ymax) / 2 if along_x else (xmin + xmax) / 2
    inset = min(leash, (hi - lo) / 2)
    ends = [lo + inset, hi - inset]
    path = [(e, middle) for e in ends] if along_x else [(middle, e) for e in ends]
    return track_along(path, speed, start=start)

