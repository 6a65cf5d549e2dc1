"""A leader's path in: ``swarmtopo simulate --beacon PATH`` (docs/formats.md, "A leader's path").

Two forms:

* a GeoJSON LineString (bare, or a Feature) with ``properties``: ``speed`` (mm/s,
  required), ``start`` (s the leader waits at the first vertex, default 0), ``dwell``
  (s it stops at every later vertex, default 0) and ``units`` (mm, cm or m; the speed
  is in the same length unit per second);
* a ``t, x, y`` table (CSV, CSV.gz or Parquet; seconds and mm): the track itself,
  linear between rows (the form of a log folder's ``beacon.csv``).
"""

from __future__ import annotations

from pathlib import Path

from .._json import read_json
from .._validate import non_negative, positive
from ..arena import MM_PER_UNIT
from ..beacon import BeaconTrack, track_along
from ..errors import InputError
from .logs import read_beacon_table


def read_beacon_path(path) -> BeaconTrack:
    """The leader's track from a GeoJSON path (``.geojson`` / ``.json``) or a ``t, x, y`` table."""
    path = Path(path)
    if path.name.lower().endswith((".geojson", ".json")):
        return _track_from_geojson(read_json(path), str(path))
    return read_beacon_table(path)


def _track_from_geojson(obj, source: str) -> BeaconTrack:
    if isinstance(obj, dict) and obj.get("type") == "FeatureCollection":
        features = obj.get("features")
        if not isinstance(features, list):
            raise InputError("a FeatureCollection's 'features' must be a list", file=source)
        lines = [f for f in features if isinstance(f, dict) and isinstance(f.get("geometry"), dict)
                 and f["geometry"].get("type") == "LineString"]
        if len(lines) != 1:
            raise InputError(f"a beacon path FeatureCollection needs exactly one LineString feature, found "
                             f"{len(lines)}", file=source)
        obj = lines[0]
    props = {}
    if isinstance(obj, dict) and obj.get("type") == "Feature":
        props = obj.get("properties") or {}
        obj = obj.get("geometry")
    if not isinstance(obj, dict) or obj.get("type") != "LineString":
        raise InputError("a beacon path is a GeoJSON LineString (or a Feature holding one)", file=source)
    if not isinstance(props, dict) or "speed" not in props:
        raise InputError("the beacon path's properties need a 'speed' (mm/s)", file=source)
    unit = props.get("units", "mm")
    if not isinstance(unit, str) or unit not in MM_PER_UNIT:
        raise InputError(f"properties.units must be one of {', '.join(MM_PER_UNIT)}", file=source, value=unit)
    scale = MM_PER_UNIT[unit]
    coords = obj.get("coordinates")
    try:
        points = [(float(x) * scale, float(y) * scale) for x, y, *_ in coords]
    except (TypeError, ValueError):
        raise InputError("the LineString's coordinates must be [x, y] numbers", file=source) from None
    values = {}
    for key, default, check in (("speed", None, positive), ("start", 0.0, non_negative), ("dwell", 0.0, non_negative)):
        try:
            values[key] = check(f"properties.{key}", props.get(key, default))
        except InputError as exc:
            raise InputError(exc.reason, file=source, value=exc.value) from None
    return track_along(points, values["speed"] * scale, start=values["start"], dwell=values["dwell"], source=source)
