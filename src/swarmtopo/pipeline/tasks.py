"""The window tasks of one map: pure functions an engine (:mod:`.engine`) runs anywhere.

For each time window, and each region in it::

    cut_window(chains, span)                 the window's graph and its components
    window_part(cut, region_events, log)     the region's largest component in it, or None
    describe_part(part, span, config)        its k-NN scale s, usable bands, start pools
    map_band(part, ..., start)               landmarks + persistence: a WindowMap

The one weighted chain graph and the log are shared with the workers once; a window's
graph stays where it was cut.  Only :func:`describe_part`'s few numbers come back before
the last step, so that the caller draws every landmark start from the map's one random
stream in the order of the windows: the map is the same whatever ran the tasks.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from ..log import EncounterLog
from ..metric.graph import EncounterGraph, WeightedChains
from ..metric.landmarks import Landmarks, knn_distances, knn_maxmin, maxmin, probabilistic_maxmin, start_pool
from ..topology.persistence import rips_persistence
from .config import MapConfig
from .regions import region_part
from .result import RegionScales, WindowMap
from .windows import in_band, usable_bands

AUTO_COVER_FACTOR = 1.5
"""The automatic landmark count stops once r_cover <= AUTO_COVER_FACTOR * s (s: the
window's k-NN scale).  The landmarks' diagram is within bottleneck 2 r_cover of the
whole cloud's, so subsampling moves no bar by more than 3 s: the order of the
cloud's own Rips noise bars."""


@dataclass(frozen=True)
class PartInfo:
    """What the caller needs of a window's region part before mapping it: the k-NN
    scale s, the landmark bands it can be mapped with and each band's start-pool size."""

    knn_scale: float
    bands: tuple[float, ...]
    pool_sizes: tuple[int, ...]


def cut_window(chains: WeightedChains, span: tuple[float, float] | None) -> tuple[EncounterGraph, np.ndarray]:
    """The encounter graph of the events in ``span`` (None: all) and its component labels."""
    graph = chains.graph(span)
    return graph, graph.components()[1]


def window_part(cut: tuple[EncounterGraph, np.ndarray], region_events: np.ndarray, log: EncounterLog,
                min_region_events: int) -> EncounterGraph | None:
    """The region's part of a cut window (:func:`.regions.region_part`), or None."""
    return region_part(*cut, region_events, log, min_region_events)


def describe_part(part: EncounterGraph | None, span, bands: tuple[float, ...], config: MapConfig) -> PartInfo | None:
    """s, the usable bands and their start pools' sizes of a region part (None: None)."""
    if part is None:
        return None
    usable = tuple(usable_bands(part, span, bands))
    pools = tuple(len(start_pool(part, config.subsample, k=config.knn_k, q=config.knn_q,
                                 candidates=_band_candidates(part, span, band))) for band in usable)
    return PartInfo(knn_scale_of(part, config.knn_k), usable, pools)


def map_band(part: EncounterGraph, span, knn_scale: float, n_land: int | None, config: MapConfig, band: float,
             start: int) -> tuple[WindowMap, float, float]:
    """Landmarks and persistence of one region part in one window (span None: all its
    events), the landmarks drawn among the nodes of the window's middle ``band`` share
    from the start pool's node ``start``; with the seconds each took."""
    t0 = time.perf_counter()
    t_lo, t_hi = _span_of(part, span)
    candidates = _band_candidates(part, span, band)
    if n_land is None:  # as many as cover the window to AUTO_COVER_FACTOR s, at most max_landmarks
        land = subsample(part, config, min(config.max_landmarks, part.n_nodes), start, candidates,
                         cover=AUTO_COVER_FACTOR * knn_scale)
    else:
        land = subsample(part, config, int(min(n_land, part.n_nodes)), start, candidates)
    t1 = time.perf_counter()
    persistence = rips_persistence(land.distances, maxdim=config.maxdim)
    t2 = time.perf_counter()
    window = WindowMap(t0=t_lo, t1=t_hi, n_events=part.n_events, landmarks=land,
                       landmark_events=part.representative_event()[land.nodes],
                       scales=RegionScales(knn=knn_scale, cover_radius=float(land.cover_radius)),
                       persistence=persistence, band=float(band))
    return window, t1 - t0, t2 - t1


def subsample(graph: EncounterGraph, config: MapConfig, n_landmarks: int, start: int,
              candidates: np.ndarray | None = None, cover: float | None = None) -> Landmarks:
    """Landmarks by ``config.subsample`` from the start pool's node ``start``;
    ``candidates`` (maxmin only, as validated) restricts the picks; ``cover`` stops them
    once they cover within it."""
    if config.subsample == "knn":
        return knn_maxmin(graph, n_landmarks, k=config.knn_k, q=config.knn_q, start=start, cover=cover)
    if config.subsample == "probabilistic":
        return probabilistic_maxmin(graph, n_landmarks, k=config.knn_k, omega=config.omega, start=start, cover=cover)
    return maxmin(graph, n_landmarks, start=start, candidates=candidates, cover=cover)


def knn_scale_of(graph: EncounterGraph, k: int) -> float:
    """s: median over distinct events (graph nodes) of the mean distance to their k
    nearest other nodes."""
    k = min(k, graph.n_nodes - 1)
    distinct = replace(graph, multiplicity=np.ones_like(graph.multiplicity))
    return float(np.median(knn_distances(distinct, k).mean(axis=1)))


def _span_of(part: EncounterGraph, span) -> tuple[float, float]:
    return (float(part.event_t.min()), float(part.event_t.max())) if span is None else span


def _band_candidates(part: EncounterGraph, span, band: float) -> np.ndarray | None:
    """The nodes of the window's middle ``band`` share (None: every node, band 1)."""
    return None if band == 1 else in_band(part.node_times(), _span_of(part, span), band)
