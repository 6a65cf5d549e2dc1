"""Arenas: the bounded 2-D free space the swarm explores.

An :class:`Arena` is a validated shapely (Multi)Polygon in millimetres: each polygon
is one connected region, each interior ring one obstacle (a hole of the free space).
Its true Betti numbers follow from the geometry: beta_0 = number of regions,
beta_1 = number of holes.  Nothing downstream of the encounter log may look at it;
the simulator uses it, and pictures and scoring use it as ground truth.
"""

from __future__ import annotations

from functools import cached_property
from typing import Any

import numpy as np
import shapely
import shapely.affinity
import shapely.validation
from shapely.geometry import LinearRing, MultiPolygon, Polygon, mapping, shape
from shapely.geometry.polygon import orient

from .errors import ArenaError


class Arena:
    """Free space of a bounded arena: disjoint polygons with disjoint holes.

    Parameters
    ----------
    geometry
        A shapely ``Polygon`` or ``MultiPolygon``.  Rings must be simple, every hole
        must lie strictly inside its shell, holes must not touch each other or the
        shell, and regions must not touch each other.
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

        Row ``[x0, y0, x1, y1]``; float64, C-contiguous, read-only.
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

    def sample_uniform(self, n: int, rng=None, *, clearance: float = 0.0) -> np.ndarray:
        """Draw ``n`` points uniformly in the free space, at least ``clearance`` mm from walls.

        Rejection sampling in the bounding box; returns an (n, 2) float64 array.
        """
        rng = np.random.default_rng(rng)
        region = self.geometry.buffer(-clearance) if clearance > 0 else self.geometry
        if region.is_empty:
            raise ArenaError(f"no free space is farther than {clearance} mm from the walls")
        shapely.prepare(region)
        xmin, ymin, xmax, ymax = region.bounds
        accept_rate = max(region.area / ((xmax - xmin) * (ymax - ymin)), 1e-3)
        out = np.empty((0, 2))
        while len(out) < n:
            m = int((n - len(out)) / accept_rate * 1.2) + 16
            cand = np.column_stack([rng.uniform(xmin, xmax, m), rng.uniform(ymin, ymax, m)])
            keep = shapely.contains_xy(region, cand[:, 0], cand[:, 1])
            out = np.vstack([out, cand[keep]])
        return out[:n]

    def scaled(self, factor: float) -> "Arena":
        """The same arena scaled by ``factor`` about the origin."""
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
            feats = obj.get("features") or []
            geoms = [f.get("geometry") for f in feats if isinstance(f, dict)]
            geoms = [g for g in geoms if g]
            if not geoms:
                raise ArenaError("FeatureCollection holds no geometry", file=source)
            parts = [_geometry_from(g, source) for g in geoms]
            polys = [p for g in parts for p in getattr(g, "geoms", [g])]
            return cls(MultiPolygon(polys), source=source)
        if kind == "Feature":
            if not obj.get("geometry"):
                raise ArenaError("Feature has no geometry", file=source)
            return cls(_geometry_from(obj["geometry"], source), source=source)
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


def _geometry_from(obj: dict, source) -> Polygon | MultiPolygon:
    if obj.get("type") not in ("Polygon", "MultiPolygon"):
        raise ArenaError(
            f"geometry type {obj.get('type')!r} is not supported; expected Polygon or MultiPolygon",
            file=source,
        )
    try:
        return shape(obj)
    except Exception as exc:  # shapely raises several types on malformed coordinates
        raise ArenaError(f"malformed coordinates ({exc})", file=source) from None


def _validated(geometry, source) -> MultiPolygon:
    if isinstance(geometry, Polygon):
        polys = [geometry]
    elif isinstance(geometry, MultiPolygon):
        polys = list(geometry.geoms)
    else:
        raise ArenaError(f"expected a Polygon or MultiPolygon, got {geometry.geom_type}", file=source)
    if not polys:
        raise ArenaError("the arena is empty", file=source)
    clean = []
    for i, poly in enumerate(polys):
        where = f"region {i}"
        _check_ring(poly.exterior, f"{where} outer wall", source)
        if poly.area <= 0:
            raise ArenaError(f"{where} has zero area", file=source)
        shell = Polygon(poly.exterior)
        holes = [Polygon(r) for r in poly.interiors]
        for j, (ring, hole) in enumerate(zip(poly.interiors, holes)):
            _check_ring(ring, f"{where} hole {j}", source)
            if not shell.contains(hole) or hole.intersects(poly.exterior):
                pt = hole.representative_point()
                raise ArenaError(
                    f"{where} hole {j} is not strictly inside its outer wall (near x={pt.x:.6g}, y={pt.y:.6g})",
                    file=source,
                )
        for j in range(len(holes)):
            for k in range(j + 1, len(holes)):
                if holes[j].intersects(holes[k]):
                    pt = holes[j].intersection(holes[k]).representative_point()
                    raise ArenaError(
                        f"{where} holes {j} and {k} overlap or touch (near x={pt.x:.6g}, y={pt.y:.6g})",
                        file=source,
                    )
        # orient: shell counter-clockwise, holes clockwise
        clean.append(orient(Polygon(poly.exterior, list(poly.interiors)), 1.0))
    for i in range(len(clean)):
        for k in range(i + 1, len(clean)):
            if clean[i].intersects(clean[k]):
                pt = clean[i].intersection(clean[k]).representative_point()
                raise ArenaError(
                    f"regions {i} and {k} overlap or touch (near x={pt.x:.6g}, y={pt.y:.6g}); "
                    "disjoint regions must be separated",
                    file=source,
                )
    return MultiPolygon(clean)


def _check_ring(ring: LinearRing, where: str, source) -> None:
    coords = np.asarray(ring.coords)
    if len(coords) < 4:
        raise ArenaError(f"{where} has fewer than 3 distinct corners", file=source)
    if not np.all(np.isfinite(coords)):
        raise ArenaError(f"{where} has a non-finite coordinate", file=source)
    if not ring.is_simple:
        bad = shapely.validation.explain_validity(Polygon(ring))
        raise ArenaError(f"{where} crosses itself ({bad})", file=source)
