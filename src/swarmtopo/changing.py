"""Arenas that change: obstacles and walls present only for a time interval.

A :class:`ChangingArena` is a static :class:`~swarmtopo.arena.Arena` (its free space at
no change) and :class:`TimedObstacle` s: polygons removed from the free space while
they are present, ``start <= t < end`` (GeoJSON ``"from"`` / ``"until"``, seconds).  An
obstacle that appears inside the free space adds a hole; one spanning a doorway splits
a region in two (a door that closes); one present from the start and removed later
takes its hole away.  Between two consecutive change times the free space is one
valid Arena (:meth:`ChangingArena.at`); its Betti numbers over time are
:meth:`ChangingArena.betti_timeline`.

The simulator (:func:`swarmtopo.sim.simulate`) takes either kind; :func:`changing_arena`
draws the changing arenas of ``swarmtopo bench timeline``.  The file format is in
docs/formats.md ("Arenas that change").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import shapely
from shapely.geometry import MultiPolygon, Polygon, mapping
from shapely.ops import unary_union

from ._validate import positive
from .arena import (MM_PER_UNIT, Arena, _geometry_from, _regular_polygon, _units, default_arena, random_arena,
                    two_rooms_arena)
from .errors import ArenaError, SwarmtopoError

ROLES = ("obstacle", "wall")
"""``properties.role`` of a GeoJSON feature that is removed from the free space while present."""
CHANGES = ("none", "appear", "disappear", "door")
"""Kinds of :func:`changing_arena`: no change, a hole appears, a hole disappears, a door closes."""
DOOR_WIDTH_FRACTION = 0.3
"""Width of :func:`changing_arena`'s doorway / room side (150 mm for 500 mm rooms)."""


@dataclass(frozen=True)
class TimedObstacle:
    """A polygon (mm) removed from the free space while ``start <= t < end`` (seconds)."""

    polygon: Polygon
    start: float = 0.0
    end: float = math.inf
    role: str = "obstacle"

    def present(self, t: float) -> bool:
        return self.start <= t < self.end


class ChangingArena:
    """A static arena and the obstacles present in it only for a time (module docstring).

    Raises
    ------
    ArenaError
        If an obstacle misses the free space, its interval is empty, or the free space
        at some time is not a valid Arena (naming the time and the obstacles present).
    """

    def __init__(self, base: Arena, obstacles, *, source: str | None = None):
        self.base = base
        self.obstacles = tuple(obstacles)
        self.source = source
        self._epochs: dict[tuple[int, ...], Arena] = {(): base}  # the free space per set of obstacles present
        for i, ob in enumerate(self.obstacles):
            if not (0 <= ob.start < ob.end):
                raise ArenaError(f"obstacle {i}: 'from' {ob.start:g} must be >= 0 and before 'until' {ob.end:g}",
                                 file=source)
            if not ob.polygon.intersects(base.geometry) or ob.polygon.intersection(base.geometry).area <= 0:
                raise ArenaError(f"obstacle {i} lies outside the free space: it changes nothing", file=source)
        for t in (0.0, *self.change_times()):
            self.at(t)  # validates every epoch

    def change_times(self) -> list[float]:
        """The times > 0 at which an obstacle appears or goes, sorted."""
        times = {ob.start for ob in self.obstacles} | {ob.end for ob in self.obstacles}
        return sorted(t for t in times if 0 < t < math.inf)

    def present(self, t: float) -> tuple[int, ...]:
        """Indices of the obstacles present at ``t``."""
        return tuple(i for i, ob in enumerate(self.obstacles) if ob.present(t))

    def at(self, t: float) -> Arena:
        """The free space at time ``t``: the base arena minus the obstacles present."""
        return self._epoch(self.present(float(t)))

    def _epoch(self, present: tuple[int, ...]) -> Arena:
        if present not in self._epochs:
            free = self.base.geometry.difference(unary_union([self.obstacles[i].polygon for i in present]))
            free = MultiPolygon([g for g in getattr(free, "geoms", [free]) if isinstance(g, Polygon) and g.area > 0])
            try:
                self._epochs[present] = Arena(free, source=self.source)
            except ArenaError as exc:
                raise ArenaError(f"with obstacle(s) {', '.join(map(str, present))} present the free space is not a "
                                 f"valid arena: {exc.reason}", file=self.source) from None
        return self._epochs[present]

    @property
    def betti(self) -> tuple[int, int]:
        """True Betti numbers at t = 0 (:meth:`betti_timeline` gives them over time)."""
        return self.at(0.0).betti

    def betti_timeline(self, end: float = math.inf) -> list[dict[str, Any]]:
        """The true Betti numbers over [0, end): intervals ``{"from", "until", "beta_0",
        "beta_1"}``, consecutive intervals with the same numbers merged."""
        return betti_timeline_of(self, end)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        return self.base.bounds

    @property
    def area(self) -> float:
        """Free area at t = 0, mm^2."""
        return self.at(0.0).area

    def narrow_passages(self, width: float) -> list[str]:
        """:meth:`Arena.narrow_passages` of the free space at every change time."""
        found = []
        for t in (0.0, *self.change_times()):
            found += [f"at t = {t:g} s: {p}" for p in self.at(t).narrow_passages(width)]
        return found

    def scaled(self, factor: float) -> "ChangingArena":
        """The same changing arena scaled by ``factor`` about the origin."""
        factor = positive("scale factor", factor)
        return ChangingArena(self.base.scaled(factor),
                             [TimedObstacle(shapely.affinity.scale(ob.polygon, factor, factor, origin=(0, 0)),
                                            ob.start, ob.end, ob.role) for ob in self.obstacles], source=self.source)

    def to_geojson(self) -> dict[str, Any]:
        """A FeatureCollection: the base arena's feature, then one feature per obstacle
        (``role``, ``from``, and ``until`` unless it never goes)."""
        features = [self.base.to_geojson()]
        for ob in self.obstacles:
            props: dict[str, Any] = {"role": ob.role, "units": "mm", "from": ob.start}
            if math.isfinite(ob.end):
                props["until"] = ob.end
            features.append({"type": "Feature", "properties": props, "geometry": mapping(ob.polygon)})
        return {"type": "FeatureCollection", "features": features}

    def __repr__(self) -> str:
        return f"ChangingArena({self.base!r}, {len(self.obstacles)} timed obstacle(s), changes at {self.change_times()})"


def betti_timeline_of(arena: Arena | ChangingArena, end: float = math.inf) -> list[dict[str, Any]]:
    """The true Betti numbers over [0, end) of an Arena (one interval) or a ChangingArena."""
    if isinstance(arena, Arena):
        b0, b1 = arena.betti
        return [{"from": 0.0, "until": float(end), "beta_0": b0, "beta_1": b1}]
    bounds = [0.0, *(t for t in arena.change_times() if t < end), float(end)]
    out: list[dict[str, Any]] = []
    for t0, t1 in zip(bounds[:-1], bounds[1:]):
        b0, b1 = arena.at(t0).betti
        if out and (out[-1]["beta_0"], out[-1]["beta_1"]) == (b0, b1):
            out[-1]["until"] = t1
        else:
            out.append({"from": t0, "until": t1, "beta_0": b0, "beta_1": b1})
    return out


def arena_from_geojson(obj: dict, *, source: str | None = None) -> Arena | ChangingArena:
    """An Arena, or a ChangingArena when a feature of a FeatureCollection has a ``role``
    of ``ROLES`` (its ``from`` / ``until`` in seconds default to 0 / never)."""
    features = obj.get("features") if isinstance(obj, dict) and obj.get("type") == "FeatureCollection" else None
    if not isinstance(features, list) or not any(_role(f) is not None for f in features if isinstance(f, dict)):
        return Arena.from_geojson(obj, source=source)
    free = [f for f in features if not (isinstance(f, dict) and _role(f) is not None)]
    if not free:
        raise ArenaError("FeatureCollection holds obstacles but no free space (a feature without 'role')", file=source)
    base = Arena.from_geojson({**obj, "features": free}, source=source)
    collection_units = _units(obj, source)
    obstacles = []
    for i, feat in enumerate(features):
        role = _role(feat) if isinstance(feat, dict) else None
        if role is None:
            continue
        where = f"feature {i}: "
        if role not in ROLES:
            raise ArenaError(f"{where}role {role!r} is not one of {', '.join(ROLES)}", file=source)
        if not feat.get("geometry"):
            raise ArenaError(f"{where}has no geometry", file=source)
        geom = _geometry_from(feat["geometry"], source, where, MM_PER_UNIT[_units(feat, source, where, collection_units)])
        props = feat["properties"]
        start, end = _seconds(props, "from", 0.0, source, where), _seconds(props, "until", math.inf, source, where)
        for poly in getattr(geom, "geoms", [geom]):
            obstacles.append(TimedObstacle(poly, start, end, role))
    permanent = [ob for ob in obstacles if ob.start == 0 and ob.end == math.inf]
    if permanent:  # present throughout: part of the static walls
        base = Arena(base.geometry.difference(unary_union([ob.polygon for ob in permanent])), source=source)
    timed = [ob for ob in obstacles if not (ob.start == 0 and ob.end == math.inf)]
    return ChangingArena(base, timed, source=source) if timed else base


def _role(feature: dict) -> str | None:
    props = feature.get("properties")
    return props.get("role") if isinstance(props, dict) and props.get("role") not in (None, "free") else None


def _seconds(props: dict, key: str, default: float, source, where: str) -> float:
    value = props.get(key, default)
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 0:  # NaN too
        raise ArenaError(f"{where}properties.{key} {value!r} is not a time in seconds >= 0", file=source)
    return float(value)


def changing_arena(change: str, holes: int, change_time: float, *, shapes=("square",), outer: str = "square",
                   scale: float = 1.0, rng=None) -> Arena | ChangingArena:
    """A random arena with one change at ``change_time`` s (``CHANGES``).

    ``appear``: :func:`random_arena` with ``holes + 1`` holes, the last present from
    ``change_time`` on (beta_1: holes -> holes + 1).  ``disappear``: the same hole
    present until ``change_time`` (holes + 1 -> holes).  ``door``: two 500 mm rooms
    (:func:`two_rooms_arena`, ``holes`` holes in all) joined by a doorway
    ``DOOR_WIDTH_FRACTION`` of a side wide that a door fills from ``change_time`` on
    (beta_0: 1 -> 2).  ``none``: the static :func:`random_arena` (a control).
    """
    if change not in CHANGES:
        raise SwarmtopoError(f"unknown change {change!r}; expected one of {', '.join(CHANGES)}")
    if change == "none":
        return random_arena(holes, scale=scale, shapes=shapes, outer=outer, rng=rng)
    if change in ("appear", "disappear"):
        full = random_arena(holes + 1, shapes=shapes, outer=outer, rng=rng)
        region = full.regions[0]
        *kept, timed = region.interiors
        base = Arena(Polygon(region.exterior, kept))
        start, end = (change_time, math.inf) if change == "appear" else (0.0, change_time)
        arena = ChangingArena(base, [TimedObstacle(Polygon(timed), start, end)])
    else:
        rooms = two_rooms_arena(n_holes=holes, shapes=shapes, rng=rng)
        (_, y0, x1, y1), (u0, _, _, _) = rooms.regions[0].bounds, rooms.regions[1].bounds
        width = DOOR_WIDTH_FRACTION * (y1 - y0)
        mid = (y0 + y1) / 2
        corridor = shapely.box(x1, mid - width / 2, u0, mid + width / 2)
        joined = unary_union([*rooms.regions, corridor])
        arena = ChangingArena(Arena(joined), [TimedObstacle(corridor, change_time, math.inf, "wall")])
    return arena if scale == 1.0 else arena.scaled(scale)


def true_betti_text(arena, end: float) -> str:
    """The true Betti numbers of ``arena`` over [0, end) in words (:func:`timeline_text`)."""
    return timeline_text(betti_timeline_of(arena, end))


def timeline_text(timeline: list[dict[str, Any]]) -> str:
    """A Betti timeline in words: "beta_0 = 1, beta_1 = 1", or for a dimension that
    changes "beta_1 = 1 until 70 s, then 2"."""
    parts = []
    for n in (0, 1):
        text = f"beta_{n} = {timeline[0][f'beta_{n}']}"
        for previous, interval in zip(timeline[:-1], timeline[1:]):
            if interval[f"beta_{n}"] != previous[f"beta_{n}"]:
                text += f" until {interval['from']:g} s, then {interval[f'beta_{n}']}"
        parts.append(text)
    return ", ".join(parts)


def changing_demo_arena() -> ChangingArena:
    """``swarmtopo demo --changing``'s arena: the demo arena (:func:`~swarmtopo.arena.default_arena`),
    in which a second hole, an 80 mm disc centred at (400, 400) mm, appears at t = 60 s."""
    disc = shapely.affinity.translate(_regular_polygon(64, 40.0, 0.0), 400.0, 400.0)
    return ChangingArena(default_arena(), [TimedObstacle(disc, 60.0, math.inf)])
