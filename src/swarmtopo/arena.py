"""Arenas: the bounded 2-D free space the swarm explores.

An :class:`Arena` is a validated shapely (Multi)Polygon in millimetres: each polygon
is one connected region, each interior ring one obstacle (a hole of the free space).
Its true Betti numbers follow from the geometry: beta_0 = number of regions,
beta_1 = number of holes.  Nothing downstream of the encounter log may look at it;
the simulator uses it, and pictures and scoring use it as ground truth.

Generators (all lengths in mm; generated arenas have the lower-left corner of their
outer wall's bounding box at the origin, except :func:`annulus_arena`):

* :func:`square_arena` -- a square with the holes you give;
* :func:`default_arena` -- the one-hole arena of the paper's Fig. "encmds";
* :func:`random_arena` -- k non-overlapping holes at random places, as in the paper's
  experiments (random placements of square holes, scaled environments);
* :func:`annulus_arena` -- a ring, the paper's Fig. "enc" (nodes on an annulus);
* :func:`two_rooms_arena` -- two disjoint rooms (beta_0 = 2).
"""

from __future__ import annotations

import warnings
from functools import cached_property
from typing import Any

import numpy as np
import shapely
import shapely.affinity
import shapely.validation
from shapely.geometry import LinearRing, MultiPolygon, Polygon, mapping, shape
from shapely.geometry.polygon import orient

from ._validate import non_negative, non_negative_int, positive
from .errors import ArenaError, SwarmtopoError


class Arena:
    """Free space of a bounded arena: disjoint polygons with disjoint holes.

    Parameters
    ----------
    geometry
        A shapely ``Polygon`` or ``MultiPolygon``.  Rings must be simple, every hole
        must lie strictly inside its shell, holes must not touch each other or the
        shell, and regions must not touch each other.  Z coordinates and repeated
        consecutive vertices are dropped; shells are stored counter-clockwise and
        holes clockwise.
    source
        Name used in error messages (e.g. the GeoJSON file name).

    Raises
    ------
    ArenaError
        On invalid geometry, naming the region, ring and a point where it fails.
    """

    def __init__(self, geometry: Polygon | MultiPolygon, *, source: str | None = None):
        self.geometry: MultiPolygon = _validated(geometry, source)

    # -- topology -------------------------------------------------------------------
    @property
    def regions(self) -> list[Polygon]:
        """The connected regions, one polygon each."""
        return list(self.geometry.geoms)

    @property
    def obstacles(self) -> list[Polygon]:
        """Every hole of every region, as a filled polygon."""
        return [Polygon(ring) for region in self.regions for ring in region.interiors]

    @property
    def betti(self) -> tuple[int, int]:
        """True Betti numbers (beta_0, beta_1) = (regions, holes)."""
        return len(self.regions), sum(len(r.interiors) for r in self.regions)

    @property
    def area(self) -> float:
        """Free area in mm^2."""
        return float(self.geometry.area)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) in mm."""
        return tuple(float(v) for v in self.geometry.bounds)

    # -- geometry used by the simulator ----------------------------------------------
    @cached_property
    def boundary_segments(self) -> np.ndarray:
        """All boundary edges (outer walls and obstacle walls) as an (M, 4) array.

        Row ``[x0, y0, x1, y1]``; float64, C-contiguous, read-only.  One row per ring
        edge.  Shells run counter-clockwise and holes clockwise, so the free space
        always lies to the left of the direction (x0, y0) -> (x1, y1).
        """
        rows = []
        for region in self.regions:
            for ring in (region.exterior, *region.interiors):
                xy = np.asarray(ring.coords, dtype=np.float64)
                rows.append(np.hstack([xy[:-1], xy[1:]]))
        seg = np.ascontiguousarray(np.vstack(rows))
        seg.setflags(write=False)
        return seg

    def contains(self, x, y) -> np.ndarray:
        """True where (x, y) is strictly inside the free space."""
        return shapely.contains_xy(self._prepared, np.asarray(x, float), np.asarray(y, float))

    def region_of(self, x, y) -> np.ndarray:
        """Index of the region containing each point, -1 outside the free space."""
        x, y = np.asarray(x, float), np.asarray(y, float)
        out = np.full(np.shape(x), -1, dtype=np.int64)
        for i, region in enumerate(self.regions):
            out[shapely.contains_xy(region, x, y)] = i
        return out

    def distance_to_boundary(self, x, y) -> np.ndarray:
        """Euclidean distance from each point to the nearest wall."""
        pts = shapely.points(np.asarray(x, float), np.asarray(y, float))
        return shapely.distance(pts, self.geometry.boundary)

    def sample_uniform(self, n: int, rng=None, *, clearance: float = 0.0, within=None) -> np.ndarray:
        """Draw ``n`` points uniformly in the free space, at least ``clearance`` mm from walls
        (and inside the shapely geometry ``within`` when given).

        Rejection sampling in the bounding box of the free space shrunk by
        ``clearance``; returns an (n, 2) float64 array.  The clearance is tested
        exactly (the shrunk polygon cuts the rounded corners with chords).
        """
        n = non_negative_int("number of points", n)
        rng = np.random.default_rng(rng)
        region = self.geometry.buffer(-clearance) if clearance > 0 else self.geometry
        if within is not None:
            region = region.intersection(within)
        if region.is_empty:
            raise ArenaError(f"no free space is farther than {clearance} mm from the walls"
                             + ("" if within is None else " in the area asked for"))
        shapely.prepare(region)
        xmin, ymin, xmax, ymax = region.bounds
        accept_rate = max(region.area / ((xmax - xmin) * (ymax - ymin)), 1e-3)
        out = np.empty((0, 2))
        while len(out) < n:
            m = int((n - len(out)) / accept_rate * 1.2) + 16
            cand = np.column_stack([rng.uniform(xmin, xmax, m), rng.uniform(ymin, ymax, m)])
            keep = shapely.contains_xy(region, cand[:, 0], cand[:, 1])
            if clearance > 0:
                keep[keep] = self.distance_to_boundary(cand[keep, 0], cand[keep, 1]) >= clearance
            out = np.vstack([out, cand[keep]])
        return out[:n]

    def hole_centroids(self) -> np.ndarray:
        """(k, 2) centroids (mm) of the holes, region by region."""
        points = [Polygon(ring).centroid for region in self.regions for ring in region.interiors]
        return np.array([[p.x, p.y] for p in points]).reshape(-1, 2)

    def narrow_passages(self, width: float) -> list[str]:
        """The passages narrower than ``width`` (mm) between a hole and its outer wall or
        another hole of its region, described ("region 0: hole 1 is 15 mm from the outer
        wall"): a swarm whose agents sense each other across r_d may see such a hole as
        part of the wall, or two such holes as one."""
        found = []
        for i, region in enumerate(self.regions):
            walls = [("the outer wall", region.exterior)] + [(f"hole {j}", ring) for j, ring in enumerate(region.interiors)]
            for k, (name, ring) in enumerate(walls[1:], 1):
                for other, other_ring in walls[:k]:
                    gap = ring.distance(other_ring)
                    if gap < width:
                        found.append(f"region {i}: {name} is {gap:.3g} mm from {other}")
        return found

    def scaled(self, factor: float) -> "Arena":
        """The same arena scaled by ``factor`` (> 0) about the origin."""
        factor = positive("scale factor", factor)
        return Arena(shapely.affinity.scale(self.geometry, factor, factor, origin=(0, 0)))

    # -- GeoJSON -------------------------------------------------------------------
    def to_geojson(self) -> dict[str, Any]:
        """A GeoJSON Feature holding the MultiPolygon (coordinates in mm)."""
        return {
            "type": "Feature",
            "properties": {"units": "mm", "betti": list(self.betti)},
            "geometry": mapping(self.geometry),
        }

    @classmethod
    def from_geojson(cls, obj: dict, *, source: str | None = None) -> "Arena":
        """Build from a GeoJSON Polygon, MultiPolygon, Feature or FeatureCollection."""
        if not isinstance(obj, dict) or "type" not in obj:
            raise ArenaError("not a GeoJSON object (no 'type' member)", file=source)
        kind = obj["type"]
        if kind == "FeatureCollection":
            feats = obj.get("features")
            if not isinstance(feats, list) or not feats:
                raise ArenaError("FeatureCollection holds no features", file=source)
            polys = []
            collection_units = _units(obj, source)
            for i, feat in enumerate(feats):
                if not isinstance(feat, dict) or feat.get("type") != "Feature":
                    raise ArenaError(f"feature {i} is not a GeoJSON Feature", file=source)
                if not feat.get("geometry"):
                    raise ArenaError(f"feature {i} has no geometry", file=source)
                units = _units(feat, source, f"feature {i}: ", collection_units)
                geom = _geometry_from(feat["geometry"], source, f"feature {i}: ", MM_PER_UNIT[units])
                polys.extend(geom.geoms if isinstance(geom, MultiPolygon) else [geom])
            return cls(MultiPolygon(polys), source=source)
        if kind == "Feature":
            if not obj.get("geometry"):
                raise ArenaError("Feature has no geometry", file=source)
            return cls(_geometry_from(obj["geometry"], source, "", MM_PER_UNIT[_units(obj, source)]), source=source)
        return cls(_geometry_from(obj, source), source=source)

    @cached_property
    def _prepared(self):
        geom = shapely.from_wkb(shapely.to_wkb(self.geometry))
        shapely.prepare(geom)
        return geom

    def __repr__(self) -> str:
        b0, b1 = self.betti
        return f"Arena(regions={b0}, holes={b1}, area={self.area:.0f} mm^2)"

    def __eq__(self, other) -> bool:
        return isinstance(other, Arena) and self.geometry.equals_exact(other.geometry, 1e-9)

    __hash__ = None


# -- generators ------------------------------------------------------------------------
HOLE_SHAPES: tuple[str, ...] = ("square", "disc", "L", "triangle", "wall")
"""Hole families of :func:`random_arena`; see there for their sizes and orientations."""
OUTER_SHAPES: tuple[str, ...] = ("square", "rectangle", "polygon")
"""Outer walls of :func:`random_arena`, all of area ``side**2``."""
PLACEMENT_TRIES = 20_000
"""Default budget of candidate holes drawn by :func:`random_arena` before giving up."""

_DISC_SEGMENTS = 64   # a disc hole is a regular 64-gon: its area is 0.16 % below the disc's
_TRIES_PER_HOLE = 100  # candidates for one hole before the whole layout is redrawn
_HOLE_FRACTION = 0.25  # default hole size / side: 125 mm holes in the 500 mm arena
_CLEARANCE_FRACTION = 0.12  # default clearance / side: 60 mm = 2 r_d in the 500 mm arena
_GAP_FRACTION = 0.2  # default gap between the two rooms / side: 100 mm > r_d at side 500


def square_arena(side: float = 500.0, holes=()) -> Arena:
    """The square [0, side]^2 with the given holes.

    Parameters
    ----------
    side
        Side length, mm.
    holes
        Iterable of shapely Polygons (their outer rings become the obstacles); they
        must lie strictly inside the square and not touch each other.
    """
    side = positive("side", side)
    rings = [Polygon(h).exterior for h in holes]
    return Arena(Polygon(shapely.box(0.0, 0.0, side, side).exterior, rings))


def default_arena() -> Arena:
    """The demo arena: the paper's one-hole environment (Fig. "encmds").

    The paper gives no dimensions; we use a 500 mm square with one centred,
    axis-aligned square hole of side 150 mm -- the same 500 mm scale as the paper's
    motion parameters (v_c = 15 mm/s, l* = 30 mm) and detection radius r_d = 30 mm.
    True Betti numbers (1, 1).
    """
    return square_arena(500.0, [shapely.box(175.0, 175.0, 325.0, 325.0)])


def random_arena(
    n_holes: int,
    *,
    scale: float = 1.0,
    rng=None,
    side: float = 500.0,
    hole_size: float | None = None,
    clearance: float | None = None,
    shapes=("square",),
    outer: str = "square",
    max_tries: int = PLACEMENT_TRIES,
) -> Arena:
    """An arena with ``n_holes`` non-overlapping holes at random places.

    As in the paper's experiments (random placements of square holes in a square
    environment, scaled copies of it).  Every hole keeps at least ``clearance`` from
    every other hole and from the outer wall, so agents can pass everywhere.

    Parameters
    ----------
    n_holes
        Number of holes k (the true beta_1).
    scale
        The paper's scale factor: multiplies every length (side, hole size,
        clearance), so areas grow with ``scale**2``.  The lengths below are before
        scaling.
    rng
        Seed or Generator; the same seed gives the same arena.
    side
        Side of the square outer wall (mm); the other outer walls have area ``side**2``.
    hole_size
        Size s of each hole (mm), default ``0.25 * side`` (125 mm): the side of a
        square, the diameter of a disc (a 64-gon), the side of the bounding square of
        an L (arms s/2 wide), the side of an equilateral triangle, the length of a wall
        (a thin s x 0.1 s rectangle).
    clearance
        Minimum distance (mm) between holes and between a hole and the outer wall;
        default ``0.12 * side`` (60 mm = 2 r_d for the default r_d = 30 mm).
    shapes
        Hole families to draw from, uniformly and independently per hole (see
        HOLE_SHAPES).  Squares and discs are axis-aligned, like the paper's square
        holes; L, triangle and wall get a uniformly random orientation.
    outer
        ``"square"``; ``"rectangle"`` (aspect ratio uniform in 1:1 .. 1:2, the long side
        along x); ``"polygon"`` (a random star-shaped polygon of 5--9 corners, convex or
        mildly non-convex: corner radii vary by +-20 %).
    max_tries
        Budget of candidate holes.  Holes are placed one by one by rejection sampling;
        after 100 failed candidates for one hole the layout is redrawn from scratch.

    Raises
    ------
    SwarmtopoError
        If the holes cannot be placed within ``max_tries`` candidates, or on bad
        arguments.
    """
    rng = np.random.default_rng(rng)
    n_holes = non_negative_int("n_holes", n_holes)
    scale, side = positive("scale", scale), positive("side", side)
    size = positive("hole_size", _HOLE_FRACTION * side if hole_size is None else hole_size)
    clear = non_negative("clearance", _CLEARANCE_FRACTION * side if clearance is None else clearance)
    shapes = _hole_shapes(shapes)
    if outer not in OUTER_SHAPES:
        raise SwarmtopoError(f"unknown outer wall {outer!r}; expected one of {', '.join(OUTER_SHAPES)}")
    wall, what = _outer_polygon(outer, side, scale, rng)
    holes = _place_holes(wall, n_holes, size, clear, shapes, rng, non_negative_int("max_tries", max_tries))
    if holes is None:
        raise SwarmtopoError(_placement_failure(n_holes, size * scale, clear * scale, what, max_tries))
    arena = Arena(Polygon(wall.exterior, [h.exterior for h in holes]))
    return arena if scale == 1.0 else arena.scaled(scale)


def annulus_arena(r_outer: float, r_inner: float, *, segments: int = 128, center=(0.0, 0.0)) -> Arena:
    """A ring r_inner < |p - center| < r_outer: the paper's Fig. "enc" (nodes on an annulus).

    Both circles are regular ``segments``-gons with corners on the circles (so the
    area is slightly below pi (r_outer^2 - r_inner^2)).  True Betti numbers (1, 1).
    """
    r_outer, r_inner = positive("r_outer", r_outer), positive("r_inner", r_inner)
    if r_inner >= r_outer:
        raise SwarmtopoError(f"r_inner must be smaller than r_outer, got {r_inner:g} >= {r_outer:g}")
    segments = non_negative_int("segments", segments)
    if segments < 3:
        raise SwarmtopoError(f"segments must be at least 3, got {segments}")
    cx, cy = (float(c) for c in center)
    outer = _regular_polygon(segments, r_outer, 0.0)
    inner = _regular_polygon(segments, r_inner, 0.0)
    return Arena(shapely.affinity.translate(Polygon(outer.exterior, [inner.exterior]), cx, cy))


HALL_SHAPES: tuple[str, ...] = ("square", "disc", "L", "triangle")
"""Hole families of :func:`hall_arena` (thin walls are left out: along a hall they close it)."""


def hall_arena(n_holes: int, *, length: float = 3000.0, width: float = 600.0, shapes=HALL_SHAPES,
               hole_size: float | None = None, clearance: float | None = None, rng=None,
               max_tries: int = PLACEMENT_TRIES) -> Arena:
    """A long hall, ``length`` x ``width`` mm, with ``n_holes`` holes at random places
    along it: an arena bigger than a swarm on a leash sees at once (beacon-led exploration).

    Holes are placed as in :func:`random_arena` (families from ``shapes``), of size
    ``hole_size`` (default 0.22 width: 132 mm in a 600 mm hall) and at least
    ``clearance`` (default 0.2 width) from each other and the walls.
    """
    rng = np.random.default_rng(rng)
    n_holes = non_negative_int("n_holes", n_holes)
    length, width = positive("length", length), positive("width", width)
    size = positive("hole_size", 0.22 * width if hole_size is None else hole_size)
    clear = non_negative("clearance", 0.2 * width if clearance is None else clearance)
    wall = shapely.box(0.0, 0.0, length, width)
    holes = _place_holes(wall, n_holes, size, clear, _hole_shapes(shapes), rng, non_negative_int("max_tries", max_tries))
    if holes is None:
        raise SwarmtopoError(_placement_failure(n_holes, size, clear, f"{length:g} x {width:g} mm hall", max_tries))
    return Arena(Polygon(wall.exterior, [h.exterior for h in holes]))


def hall_demo_arena() -> Arena:
    """``swarmtopo demo --beacon``'s arena: a 2,400 x 600 mm hall with a 140 mm square hole
    at x = 700 mm and a 140 mm disc at x = 1,700 mm, both on its middle line."""
    holes = [shapely.box(630.0, 230.0, 770.0, 370.0), shapely.Point(1700.0, 300.0).buffer(70.0, quad_segs=16)]
    return Arena(Polygon(shapely.box(0.0, 0.0, 2400.0, 600.0).exterior, [h.exterior for h in holes]))


def two_rooms_arena(
    side: float = 500.0,
    gap: float | None = None,
    *,
    scale: float = 1.0,
    rng=None,
    n_holes=0,
    hole_size: float | None = None,
    clearance: float | None = None,
    shapes=("square",),
    max_tries: int = PLACEMENT_TRIES,
) -> Arena:
    """Two disjoint square rooms side by side (beta_0 = 2), optionally with random holes.

    Room 0 is [0, side]^2, room 1 is [side + gap, 2 side + gap] x [0, side].

    Parameters
    ----------
    side
        Side of each room (mm).
    gap
        Distance between the rooms (mm), default ``0.2 * side`` (100 mm, well above
        r_d, so agents in different rooms never meet).
    scale
        Multiplies every length, as in :func:`random_arena`.
    n_holes
        Total number of holes, room 0 getting the extra one when odd; or a pair
        ``(holes in room 0, holes in room 1)``.
    hole_size, clearance, shapes, max_tries
        As in :func:`random_arena` (square holes only by default; the budget is per room).
    """
    rng = np.random.default_rng(rng)
    scale, side = positive("scale", scale), positive("side", side)
    gap = positive("gap", _GAP_FRACTION * side if gap is None else gap)
    if isinstance(n_holes, (tuple, list)) and len(n_holes) == 2:
        per_room = [non_negative_int("n_holes[0]", n_holes[0]), non_negative_int("n_holes[1]", n_holes[1])]
    else:
        total = non_negative_int("n_holes", n_holes)
        per_room = [total - total // 2, total // 2]
    size = positive("hole_size", _HOLE_FRACTION * side if hole_size is None else hole_size)
    clear = non_negative("clearance", _CLEARANCE_FRACTION * side if clearance is None else clearance)
    shapes = _hole_shapes(shapes)
    max_tries = non_negative_int("max_tries", max_tries)
    rooms = []
    for k, offset in enumerate((0.0, side + gap)):
        wall = shapely.box(offset, 0.0, offset + side, side)
        holes = _place_holes(wall, per_room[k], size, clear, shapes, rng, max_tries)
        if holes is None:
            what = f"{side * scale:g} mm square room"
            raise SwarmtopoError(_placement_failure(per_room[k], size * scale, clear * scale, what, max_tries))
        rooms.append(Polygon(wall.exterior, [h.exterior for h in holes]))
    arena = Arena(MultiPolygon(rooms))
    return arena if scale == 1.0 else arena.scaled(scale)


def _outer_polygon(outer: str, side: float, scale: float, rng) -> tuple[Polygon, str]:
    """The outer wall (area side^2, bounding box from the origin) and its description."""
    if outer == "square":
        return shapely.box(0.0, 0.0, side, side), f"{side * scale:g} mm square"
    if outer == "rectangle":
        aspect = rng.uniform(1.0, 2.0)
        w, h = side * np.sqrt(aspect), side / np.sqrt(aspect)
        return shapely.box(0.0, 0.0, w, h), f"{w * scale:.0f} x {h * scale:.0f} mm rectangle"
    n = int(rng.integers(5, 10))
    step = 2 * np.pi / n
    angles = step * (np.arange(n) + rng.uniform(-0.3, 0.3, n)) + rng.uniform(0, 2 * np.pi)
    radii = rng.uniform(0.8, 1.2, n)  # star-shaped about the origin, so always simple
    poly = Polygon(np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]))
    poly = shapely.affinity.scale(poly, side / np.sqrt(poly.area), side / np.sqrt(poly.area), origin=(0, 0))
    x0, y0, _, _ = poly.bounds
    poly = shapely.affinity.translate(poly, -x0, -y0)
    return poly, f"random {n}-corner polygon of area {(side * scale) ** 2:.0f} mm^2"


def _place_holes(wall: Polygon, n: int, size: float, clearance: float, shapes, rng, budget: int):
    """n holes inside ``wall``, pairwise and from the wall at least ``clearance`` apart.

    Holes are placed one by one by rejection sampling; after _TRIES_PER_HOLE misses
    for one hole the layout is redrawn from scratch.  None when ``budget`` candidates
    fail.  A candidate is drawn with its bounding box inside the wall's bounding box
    shrunk by ``clearance``, then tested exactly with shapely distances.
    """
    if n == 0:
        return []
    shapely.prepare(wall)
    placed: list[Polygon] = []
    family, misses = None, 0
    for _ in range(budget):
        if family is None:
            family = shapes[int(rng.integers(len(shapes)))]
        hole = _candidate_hole(wall, family, size, clearance, placed, rng)
        if hole is None:
            misses += 1
            if misses == _TRIES_PER_HOLE:  # this hole finds no place: redraw the layout
                placed, family, misses = [], None, 0
            continue
        placed.append(hole)
        family, misses = None, 0
        if len(placed) == n:
            return placed
    return None


def _candidate_hole(wall: Polygon, family: str, size: float, clearance: float, placed, rng):
    """A random hole of ``family`` placed in ``wall``, or None if it violates the clearance."""
    xmin, ymin, xmax, ymax = wall.bounds
    hole = _hole_polygon(family, size, rng)
    bx0, by0, bx1, by1 = hole.bounds
    lo_x, hi_x = xmin + clearance - bx0, xmax - clearance - bx1
    lo_y, hi_y = ymin + clearance - by0, ymax - clearance - by1
    if lo_x > hi_x or lo_y > hi_y:
        return None
    hole = shapely.affinity.translate(hole, rng.uniform(lo_x, hi_x), rng.uniform(lo_y, hi_y))
    if not wall.contains(hole) or wall.exterior.distance(hole) < clearance:
        return None
    if placed:
        gaps = shapely.distance(hole, placed)
        if np.any(gaps < clearance) or np.any(gaps <= 0):
            return None
    return hole


def _hole_polygon(family: str, s: float, rng) -> Polygon:
    """One hole of size s centred near the origin (see random_arena for the families)."""
    if family == "square":
        return shapely.box(-s / 2, -s / 2, s / 2, s / 2)
    if family == "disc":
        return _regular_polygon(_DISC_SEGMENTS, s / 2, 0.0)
    if family == "L":
        poly = Polygon([(0, 0), (s, 0), (s, s / 2), (s / 2, s / 2), (s / 2, s), (0, s)])
        poly = shapely.affinity.translate(poly, -s / 2, -s / 2)
    elif family == "triangle":
        poly = _regular_polygon(3, s / np.sqrt(3), 0.0)  # circumradius of side s
    else:  # wall
        poly = shapely.box(-s / 2, -s / 20, s / 2, s / 20)
    return shapely.affinity.rotate(poly, rng.uniform(0.0, 2 * np.pi), origin=(0, 0), use_radians=True)


def _regular_polygon(n: int, radius: float, phase: float) -> Polygon:
    angles = phase + 2 * np.pi * np.arange(n) / n
    return Polygon(np.column_stack([radius * np.cos(angles), radius * np.sin(angles)]))


def _placement_failure(n: int, size: float, clearance: float, what: str, tries: int) -> str:
    holes = "1 hole" if n == 1 else f"{n} holes"
    return (f"cannot place {holes} of {size:g} mm with {clearance:g} mm clearance in a {what} "
            f"after {tries} tries; use fewer or smaller holes, or a smaller clearance")


def _hole_shapes(shapes) -> tuple[str, ...]:
    shapes = (shapes,) if isinstance(shapes, str) else tuple(shapes)
    unknown = [f for f in shapes if f not in HOLE_SHAPES]
    if not shapes or unknown:
        raise SwarmtopoError(f"unknown hole shape {unknown[0] if unknown else None!r}; "
                             f"expected some of {', '.join(HOLE_SHAPES)}")
    return shapes


MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0}
"""Units a Feature's ``properties.units`` may name; coordinates are converted to mm."""


def _units(feature: dict, source, where: str = "", default: str = "mm") -> str:
    """The units of a Feature's coordinates (``properties.units``; ``default`` when absent):
    a key of ``MM_PER_UNIT``.  A FeatureCollection's own ``properties.units`` (not standard
    GeoJSON, but what a user writes to set them once) is the default of its features."""
    properties = feature.get("properties")
    units = properties.get("units", default) if isinstance(properties, dict) else default
    if not isinstance(units, str) or units not in MM_PER_UNIT:
        raise ArenaError(f"{where}properties.units {units!r} is not supported; expected one of "
                         f"{', '.join(MM_PER_UNIT)}", file=source)
    return units


def _numbers_only(coordinates, source, where: str) -> None:
    """Refuse a coordinate that is not a JSON number (text, true/false, null)."""
    stack = [coordinates]
    while stack:
        item = stack.pop()
        if isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, bool) or not isinstance(item, (int, float)):
            raise ArenaError(f"{where}coordinate {item!r} is not a number", file=source)


def _geometry_from(obj, source, where: str = "", mm_per_unit: float = 1.0) -> Polygon | MultiPolygon:
    if not isinstance(obj, dict):
        raise ArenaError(f"{where}geometry is not a GeoJSON object", file=source)
    kind = obj.get("type")
    if kind not in ("Polygon", "MultiPolygon"):
        raise ArenaError(f"{where}geometry type {kind!r} is not supported; expected Polygon or MultiPolygon",
                         file=source)
    if "coordinates" not in obj:
        raise ArenaError(f"{where}{kind} has no 'coordinates'", file=source)
    _numbers_only(obj["coordinates"], source, where)
    try:
        with warnings.catch_warnings():  # a NaN coordinate is refused by _validated, without shapely's warning
            warnings.simplefilter("ignore", RuntimeWarning)
            geometry = shape(obj)
    except Exception as exc:  # shapely raises several types on malformed coordinates
        raise ArenaError(f"{where}malformed coordinates ({exc})", file=source) from None
    return geometry if mm_per_unit == 1.0 else shapely.affinity.scale(geometry, mm_per_unit, mm_per_unit, origin=(0, 0))


def _validated(geometry, source) -> MultiPolygon:
    if isinstance(geometry, Polygon):
        polys = [geometry]
    elif isinstance(geometry, MultiPolygon):
        polys = list(geometry.geoms)
    else:
        kind = getattr(geometry, "geom_type", type(geometry).__name__)
        raise ArenaError(f"expected a Polygon or MultiPolygon, got {kind}", file=source)
    if not polys:
        raise ArenaError("the arena is empty", file=source)
    clean = []
    for i, poly in enumerate(polys):
        where = f"region {i}"
        shell = _clean_ring(poly.exterior, f"{where} outer wall", source)
        filled = Polygon(shell)
        if filled.area <= 0:
            raise ArenaError(f"{where} has zero area", file=source)
        holes = []
        for j, ring in enumerate(poly.interiors):
            hole = Polygon(_clean_ring(ring, f"{where} hole {j}", source))
            if hole.area <= 0:
                raise ArenaError(f"{where} hole {j} has zero area", file=source)
            if not filled.contains(hole) or hole.intersects(shell):
                contact = hole.intersection(shell)
                pt = (contact if not contact.is_empty else hole).representative_point()
                raise ArenaError(
                    f"{where} hole {j} is not strictly inside its outer wall (near x={pt.x:.6g}, y={pt.y:.6g})",
                    file=source,
                )
            holes.append(hole)
        for j, k in _touching_pairs(holes):
            pt = holes[j].intersection(holes[k]).representative_point()
            raise ArenaError(
                f"{where} holes {j} and {k} overlap or touch (near x={pt.x:.6g}, y={pt.y:.6g})",
                file=source,
            )
        # orient: shell counter-clockwise, holes clockwise
        clean.append(orient(Polygon(shell, [h.exterior for h in holes]), 1.0))
    for i, k in _touching_pairs(clean):
        pt = clean[i].intersection(clean[k]).representative_point()
        raise ArenaError(
            f"regions {i} and {k} overlap or touch (near x={pt.x:.6g}, y={pt.y:.6g}); "
            "disjoint regions must be separated",
            file=source,
        )
    return MultiPolygon(clean)


def _touching_pairs(polys: list[Polygon]):
    """Index pairs (j < k) of polygons that intersect, in order (STRtree: no k^2 tests)."""
    if len(polys) < 2:
        return []
    left, right = shapely.STRtree(polys).query(polys, predicate="intersects")
    keep = left < right
    return sorted(zip(left[keep].tolist(), right[keep].tolist()))


def _clean_ring(ring: LinearRing, where: str, source) -> LinearRing:
    """The ring in 2-D without repeated consecutive vertices; must be simple."""
    coords = np.asarray(ring.coords, dtype=np.float64)
    if coords.ndim != 2:  # an empty ring
        coords = coords.reshape(0, 2)
    if not np.all(np.isfinite(coords)):
        raise ArenaError(f"{where} has a non-finite coordinate", file=source)
    xy = coords[:, :2]
    if len(xy):
        xy = xy[np.r_[True, np.any(np.diff(xy, axis=0) != 0, axis=1)]]
    if len(xy) < 4:
        raise ArenaError(f"{where} has fewer than 3 distinct corners", file=source)
    if shapely.MultiPoint(xy).convex_hull.geom_type != "Polygon":
        raise ArenaError(f"{where} has zero area: its corners are collinear, it encloses no area", file=source)
    clean = LinearRing(xy)
    if not clean.is_simple:
        bad = shapely.validation.explain_validity(Polygon(clean))
        raise ArenaError(f"{where} crosses itself ({bad})", file=source)
    return clean
