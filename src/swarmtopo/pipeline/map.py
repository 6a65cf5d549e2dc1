"""From encounter log to topological map: ``map_encounters(log, config)``.

The stages, in order (paper, "Algorithm Overview", and swarmtopo's windows)::

    resolve settings (h, tau, windows, bands)      pipeline.settings
    weighted chain graph of the mapped events       metric.graph
    components -> regions, beta_0 evidence          pipeline.regions
    each window's graph, cut from the one graph     metric.graph.WeightedChains.graph
    per region and window: landmarks, persistence   metric.landmarks, topology.persistence
    per region: Betti numbers and confidence        readers (one reader.read call)
    per region: MDS picture, loops round the holes  topology.embed, topology.cycles
    assemble the map                                pipeline.result

Nothing here reads an arena, a truth file or simulator parameters: the map is a
function of the :class:`~swarmtopo.log.EncounterLog`, the :class:`MapConfig` and the
reader only.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Callable

import numpy as np

from ..log import EncounterLog
from ..metric.graph import EncounterGraph, weighted_chains
from ..metric.landmarks import MIN_LANDMARKS, Landmarks, knn_distances, knn_maxmin, maxmin, probabilistic_maxmin
from ..readers.base import BettiReader
from ..readers.beta0 import shipped_beta0_model
from ..readers.registry import load_classifier, shipped_reader_for
from ..topology.cycles import region_cycles
from ..topology.embed import mds
from ..topology.persistence import Diagram, rips_persistence
from .config import MapConfig
from .regions import MIN_REGION_AGENTS, region_part, split_regions
from .result import RegionMap, RegionScales, TopologicalMap, WindowMap, software_versions
from .settings import Settings, resolve
from .windows import in_band, silence_warnings, usable_bands

AUTO_COVER_FACTOR = 1.5
"""The automatic landmark count stops once r_cover <= AUTO_COVER_FACTOR * s (s: the
window's k-NN scale).  The landmarks' diagram is within bottleneck 2 r_cover of the
whole cloud's, so subsampling moves no bar by more than 3 s: the order of the
cloud's own Rips noise bars."""
CALIBRATED_HOLES = 3
"""The most holes of any arena the confidence was calibrated on (the accuracy
benchmark's cells: 0-3); a map counting more says its confidence is extrapolated."""
STAGES = ("graph", "landmarks", "persistence", "classify", "embedding", "cycles")
"""Stage names passed to ``map_encounters``'s progress callback, in order."""


def map_encounters(
    log: EncounterLog,
    config: MapConfig | None = None,
    *,
    reader: BettiReader | None = None,
    progress: Callable[[str], None] | None = None,
) -> TopologicalMap:
    """Map an encounter log to Betti numbers, diagrams and pictures.

    Parameters
    ----------
    log
        The encounter log (simulated or real).
    config
        Pipeline options; defaults to ``MapConfig()``.
    reader
        How Betti numbers n >= 1 are read off each region's windows; defaults to the
        shipped one for the log (``default`` with status changes, ``trace`` without).
    progress
        Optional callable receiving the name of each stage (``STAGES``) as it starts.

    Returns
    -------
    TopologicalMap

    Raises
    ------
    SwarmtopoError
        If the (windowed) log has too few events, or no component is big enough
        to count as a region.
    """
    config = (config or MapConfig()).validate()
    reader = reader or load_classifier(shipped_reader_for(log))
    settings = resolve(log, config, reader)
    rng = np.random.default_rng(config.seed)
    say = progress or (lambda stage: None)
    timings = dict.fromkeys(STAGES, 0.0)

    say("graph")
    t0 = time.perf_counter()
    chains = weighted_chains(log, config.metric, window=config.window, hop_cost=settings.hop_cost[0],
                             diffusion_time=settings.diffusion_time[0], wall_follow_weight=config.wall_follow_weight)
    graph = chains.graph()
    split = split_regions(log, graph, config.min_region_events, settings.agent_gap)
    window_graphs = [(None, graph, split.labels) if span is None else (span, *_labelled(chains.graph(span)))
                     for span in settings.spans]
    timings["graph"] = time.perf_counter() - t0

    events_per_region = split.events_per_comp[split.regions]
    shares = (share_landmarks(config.landmarks, events_per_region) if config.landmarks
              else [None] * len(split.regions))
    regions = []
    for comp, n_land in zip(split.regions, shares):
        region_events = graph.event_index[split.event_comp == comp]
        windows, notes = _region_windows(comp, region_events, window_graphs, graph, split.labels, log, config,
                                         settings, n_land, rng, timings, say)
        regions.append(_read_region(comp, split, windows, notes, reader, config, rng, timings, say))

    betti: dict[int, int | None] = {0: len(regions)}
    confidence: dict[int, float | None] = {0: shipped_beta0_model().confidence(split.beta0)}
    for n in range(1, config.maxdim + 1):
        known = all(n in r.betti for r in regions)
        betti[n] = sum(r.betti[n] for r in regions) if known else None
        confidence[n] = reader.map_confidence([r.confidence.get(n) for r in regions], n) if known else None
    return TopologicalMap(
        betti=betti,
        confidence=confidence,
        diagram=Diagram(pairs=tuple(np.vstack([r.diagram[n] for r in regions]) for n in range(config.maxdim + 1)),
                        backend=regions[0].diagram.backend),
        regions=regions,
        too_little_data=split.too_little_data(),
        classifier=reader.describe(),
        config=replace(config, landmark_bands=settings.landmark_bands),
        timings=timings,
        n_events=graph.n_events,
        n_agents=log.n_agents,
        hop_cost=settings.hop_cost,
        diffusion_time=settings.diffusion_time,
        window_length=settings.window_length,
        windows_left_out=settings.windows_left_out,
        log_warnings=silence_warnings(settings.times, settings.window_length[0]) + _extrapolation_warnings(betti),
        beta0_evidence=split.beta0,
        contact_trace=len(log.status_t) == 0,
        software=software_versions(),
    )


def _labelled(graph: EncounterGraph) -> tuple[EncounterGraph, np.ndarray]:
    return graph, graph.components()[1]


def _region_windows(comp, region_events, window_graphs, graph, labels, log, config: MapConfig, settings: Settings,
                    n_land, rng, timings, say) -> tuple[list[WindowMap], list[str]]:
    """Every window of one region, mapped once per usable landmark band; the region's
    whole log instead when no window holds enough of it; and notes on what was skipped."""
    bands = settings.landmark_bands
    windows, notes, quiet = [], [], 0
    for span, wgraph, wlabels in window_graphs:
        part = region_part(wgraph, wlabels, region_events, log, config.min_region_events)
        if part is not None:
            knn_scale = _timed(timings, "landmarks", knn_scale_of, part, config.knn_k)  # one per window
            usable = usable_bands(part, span, bands)
            quiet += len(usable) < len(bands)
            windows += [map_window(span, part, knn_scale, n_land, config, rng, timings, say, band) for band in usable]
    if not windows:  # no window holds enough of this region: map its whole log instead
        whole = graph.subgraph(np.flatnonzero(labels == comp))
        knn_scale = _timed(timings, "landmarks", knn_scale_of, whole, config.knn_k)
        usable = usable_bands(whole, None, bands)
        quiet = int(len(usable) < len(bands))
        windows = [map_window(None, whole, knn_scale, n_land, config, rng, timings, say, band) for band in usable]
        if settings.tried:
            lo, hi = settings.tried[0], settings.tried[-1]
            tried = f"{lo:.3g}" if lo == hi else f"{lo:.3g}-{hi:.3g}"
            notes.append(f"no window ({tried} s long) holds {config.min_region_events} encounters of this region "
                         f"among {MIN_REGION_AGENTS} agents: its whole log was mapped instead")
    if quiet:
        notes.append(f"windows of this region with fewer than {MIN_LANDMARKS} encounters in the middle share "
                     f"of their time span a landmark band draws from (a quiet stretch of the log): {quiet}; "
                     f"they were mapped without that band")
    return windows, notes


def _read_region(comp, split, windows: list[WindowMap], notes: list[str], reader: BettiReader, config: MapConfig,
                 rng, timings, say) -> RegionMap:
    """The reader's Betti numbers over the region's windows, its picture and its loops."""
    say("classify")
    t0 = time.perf_counter()
    reading = reader.read([w.diagram for w in windows], [w.n_events for w in windows])
    for w, counts in zip(windows, reading.window_betti):
        w.betti = dict(counts)
    chosen = windows[reading.window]
    sampling = _sampling_warnings(chosen.scales, len(chosen.landmarks.nodes), config)
    # calibrated with the automatic landmark count only: no number to give
    confidence = dict.fromkeys(reading.confidence) if sampling else dict(reading.confidence)
    timings["classify"] += time.perf_counter() - t0

    say("embedding")
    t0 = time.perf_counter()
    embedding = (mds(chosen.landmarks.distances, dim=config.embed_dim, rng=rng)
                 if config.embed_dim and len(chosen.landmarks.nodes) > config.embed_dim else None)
    timings["embedding"] += time.perf_counter() - t0
    region = RegionMap(
        component=comp,
        n_events=int(split.events_per_comp[comp]),
        n_agents=int(split.agents_per_comp[comp]),
        landmarks=chosen.landmarks,
        landmark_events=chosen.landmark_events,
        diagram=chosen.diagram,
        scales=chosen.scales,
        thresholds=reading.thresholds,
        counted=reading.counted,
        betti=reading.betti,
        confidence=confidence,
        cycles=[],
        warnings=notes + sampling,
        embedding=embedding,
        windows=windows,
        window=reading.window,
    )
    if config.cycles:
        say("cycles")
        t0 = time.perf_counter()
        # cocycles of the representative window only: the backend that keeps them is
        # about 2.5x slower (benchmarks/bench_persistence.py), and its diagram is the same
        chosen.persistence = rips_persistence(chosen.landmarks.distances, maxdim=config.maxdim, cocycles=True)
        region.diagram = chosen.diagram
        region.cycles = region_cycles(region, chosen.persistence)
        timings["cycles"] += time.perf_counter() - t0
    return region


def map_window(span, sub: EncounterGraph, knn_scale: float, n_land: int | None, config: MapConfig, rng,
               timings: dict[str, float], say, band: float = 1.0) -> WindowMap:
    """Landmarks and persistence of one region's events in one time window (span None:
    all), the landmarks drawn among the nodes of the window's middle ``band`` share;
    ``knn_scale`` is the window's s, shared by its bands."""
    say("landmarks")
    t0 = time.perf_counter()
    t_lo, t_hi = (float(sub.event_t.min()), float(sub.event_t.max())) if span is None else span
    candidates = None if band == 1 else in_band(sub.node_times(), (t_lo, t_hi), band)
    if n_land is None:  # as many as cover the window to AUTO_COVER_FACTOR s, at most max_landmarks
        land = subsample(sub, config, min(config.max_landmarks, sub.n_nodes), rng, candidates,
                         cover=AUTO_COVER_FACTOR * knn_scale)
    else:
        land = subsample(sub, config, int(min(n_land, sub.n_nodes)), rng, candidates)
    timings["landmarks"] += time.perf_counter() - t0
    say("persistence")
    t0 = time.perf_counter()
    persistence = rips_persistence(land.distances, maxdim=config.maxdim)
    timings["persistence"] += time.perf_counter() - t0
    return WindowMap(t0=t_lo, t1=t_hi, n_events=sub.n_events, landmarks=land,
                     landmark_events=sub.representative_event()[land.nodes],
                     scales=RegionScales(knn=knn_scale, cover_radius=float(land.cover_radius)),
                     persistence=persistence, band=float(band))


def subsample(graph: EncounterGraph, config: MapConfig, n_landmarks: int, rng,
              candidates: np.ndarray | None = None, cover: float | None = None) -> Landmarks:
    """Landmarks by ``config.subsample``; ``candidates`` (maxmin only, as validated) restricts
    the picks; ``cover`` stops them once they cover within it."""
    if config.subsample == "knn":
        return knn_maxmin(graph, n_landmarks, k=config.knn_k, q=config.knn_q, rng=rng, cover=cover)
    if config.subsample == "probabilistic":
        return probabilistic_maxmin(graph, n_landmarks, k=config.knn_k, omega=config.omega, rng=rng, cover=cover)
    return maxmin(graph, n_landmarks, rng=rng, candidates=candidates, cover=cover)


def knn_scale_of(graph: EncounterGraph, k: int) -> float:
    """s: median over distinct events (graph nodes) of the mean distance to their k
    nearest other nodes."""
    k = min(k, graph.n_nodes - 1)
    distinct = replace(graph, multiplicity=np.ones_like(graph.multiplicity))
    return float(np.median(knn_distances(distinct, k).mean(axis=1)))


def share_landmarks(total: int, events: np.ndarray) -> np.ndarray:
    """Split ``total`` landmarks between regions in proportion to their events.

    Largest-remainder rounding; every region gets at least 3 (so the total can
    exceed ``total`` by those minimums).  The caller caps each share at the region's
    number of distinct points.
    """
    events = np.asarray(events, dtype=float)
    raw = total * events / events.sum()
    share = np.floor(raw).astype(np.int64)
    for i in np.argsort(-(raw - share), kind="stable")[: total - share.sum()]:
        share[i] += 1
    return np.maximum(share, 3)


def _timed(timings: dict[str, float], stage: str, function, *args):
    t0 = time.perf_counter()
    value = function(*args)
    timings[stage] += time.perf_counter() - t0
    return value


def _extrapolation_warnings(betti: dict[int, int | None]) -> list[str]:
    """A hole count beyond the arenas the confidence was calibrated on."""
    if (betti.get(1) or 0) > CALIBRATED_HOLES:
        return [f"beta_1 = {betti[1]} is beyond the 0-{CALIBRATED_HOLES} holes of the arenas its confidence was "
                "calibrated on (docs/accuracy.md): the confidence is extrapolated, and many holes in one arena "
                "leave narrow passages between them, where holes merge or go unseen"]
    return []


def _sampling_warnings(scales: RegionScales, n_landmarks: int, config: MapConfig) -> list[str]:
    """Why a region's answer may be unreliable (empty when it is not): a landmark count
    the user fixed is checked against the sampling guarantee; the automatic count's cap
    is the benchmarked setting, so reaching it is not a warning."""
    if config.landmarks and scales.cover_radius > AUTO_COVER_FACTOR * scales.knn:
        return [f"landmarks too sparse: {n_landmarks} landmarks leave a covering radius of "
                f"{scales.cover_radius:.3g} s, over {AUTO_COVER_FACTOR:g} x the cloud's k-NN scale "
                f"{scales.knn:.3g} s, so subsampling noise can pass the threshold; use more landmarks (no beta_1 "
                "confidence is given: it was calibrated with the automatic landmark count)"]
    return []
