"""Arenas in and out as GeoJSON (the geometry and its checks live in :mod:`swarmtopo.arena`)."""

from __future__ import annotations

from pathlib import Path

from .._json import read_json, write_json
from ..arena import Arena
from ..changing import ChangingArena, arena_from_geojson


def read_arena(path) -> Arena | ChangingArena:
    """Read an arena from a GeoJSON file (Polygon, MultiPolygon, Feature or FeatureCollection);
    a FeatureCollection with timed obstacles is a :class:`~swarmtopo.changing.ChangingArena`."""
    return arena_from_geojson(read_json(path), source=str(path))


def write_arena(arena: Arena | ChangingArena, path) -> Path:
    """Write an arena as a GeoJSON Feature, a changing one as a FeatureCollection
    (byte-stable, atomic); returns the path."""
    return write_json(arena.to_geojson(), path)
