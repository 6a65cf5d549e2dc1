"""Arenas in and out as GeoJSON (the geometry and its checks live in :mod:`swarmtopo.arena`)."""

from __future__ import annotations

from pathlib import Path

from .._json import read_json, write_json
from ..arena import Arena


def read_arena(path) -> Arena:
    """Read an arena from a GeoJSON file (Polygon, MultiPolygon, Feature or FeatureCollection)."""
    return Arena.from_geojson(read_json(path), source=str(path))


def write_arena(arena: Arena, path) -> Path:
    """Write an arena as a GeoJSON Feature (byte-stable, atomic); returns the path."""
    return write_json(arena.to_geojson(), path)
