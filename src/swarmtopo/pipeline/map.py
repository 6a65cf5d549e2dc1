"""From encounter log to topological map: ``map_encounters(log, config)``.

The stages, in order (paper, "Algorithm Overview", and swarmtopo's windows)::

    resolve settings (h, tau, windows, bands)      pipeline.settings
    weighted chain graph of the mapped events       metric.graph
    components -> regions, beta_0 evidence          pipeline.regions
    per window and region, as tasks on an engine:   pipeline.tasks, pipeline.engine
      the window's graph, cut from the one graph    metric.graph.WeightedChains.graph
      landmarks, persistence                        metric.landmarks, topology.persistence
    per region: Betti numbers and confidence        readers (one reader.read call)
    per region: MDS picture, loops round the holes  topology.embed, topology.cycles
    the timeline: sliding windows, change points    pipeline.timeline
    a leader's log: local maps stitched             pipeline.exploration
    assemble the map                                pipeline.result

Nothing here reads an arena, a truth file or simulator parameters: the map is a
function of the :class:`~swarmtopo.log.EncounterLog`, the :class:`MapConfig` and the
reader only.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import Any, Callable

import numpy as np

from ..log import EncounterLog
from ..metric.graph import weighted_chains
from ..metric.landmarks import MIN_LANDMARKS
from ..readers.base import BettiReader
from ..readers.beta0 import shipped_beta0_model
from ..readers.recalibrated import Recalibrated, recalibration
from ..readers.registry import load_classifier, shipped_reader_for
from ..topology.cycles import region_cycles
from ..topology.embed import mds
from ..topology.persistence import Diagram, rips_persistence
from .config import MapConfig
from .engine import engine_for
from .faults import fault_warnings, screen_faults
from .motion import estimate_motion, motion_warnings
from .exploration import MAX_EXPLORATION_WINDOWS, exploration_windows, leash_of, stitch
from .regions import MIN_REGION_AGENTS, split_regions
from .result import RegionMap, RegionScales, TimelineWindow, TopologicalMap, WindowMap, software_versions
from .settings import Settings, resolve
from .tasks import AUTO_COVER_FACTOR, cut_window, describe_part, map_band, window_part
from .timeline import (MAX_TIMELINE_WINDOWS, build_timeline, no_timeline_note, own_spans, read_component, scaled_h1, split_window,
                       timeline_settings, timeline_window)
from .windows import events_in, silence_warnings
CALIBRATED_HOLES = 3
"""The most holes of any arena the confidence was calibrated on (the accuracy
benchmark's cells: 0-3); a map counting more says its confidence is extrapolated."""
STAGES = ("graph", "landmarks", "persistence", "classify", "embedding", "cycles", "timeline")
"""Stage names passed to ``map_encounters``'s progress callback, in order."""


def map_encounters(
    log: EncounterLog,
    config: MapConfig | None = None,
    *,
    reader: BettiReader | None = None,
    progress: Callable[[str], None] | None = None,
    workers: int | None = None,
    scheduler: Any = None,
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
    workers
        Run the window tasks on an embedded Dask cluster of this many worker processes
        (default: this process's threads, one per numba thread).
    scheduler
        Run them on an existing Dask cluster instead: its scheduler's address, or a
        ``distributed.Client``.  The map is the same bytes on every engine.

    Returns
    -------
    TopologicalMap

    Raises
    ------
    SwarmtopoError
        If the (windowed) log has too few events, or no component is big enough
        to count as a region; or the Dask scheduler cannot be reached.
    """
    config = (config or MapConfig()).validate()
    reader = reader or load_classifier(shipped_reader_for(log))
    motion, log = estimate_motion(log, config.recontacts, config.window)
    screen, log = screen_faults(log, config.uncorroborated, config.window)
    preset = getattr(reader, "shipped_preset", None)
    if screen.suspected and preset:  # faulty sensing first: its fit saw the faults, the flicker's did not
        reader = recalibration("fault", preset, reader) or reader
    elif motion.regime == "flickering" and motion.merged and preset:
        reader = recalibration("flicker", preset, reader) or reader
    recalibrated_for = reader.kind if isinstance(reader, Recalibrated) else None
    settings = resolve(log, config, reader)
    leash = leash_of(log)
    span = (float(settings.times[0]), float(settings.times[-1]))
    timeline_config = config
    if leash is not None and config.timeline_length is None and config.timeline_step is None:
        # a beacon-led log's local maps are the timeline's windows, of a length set by the leader's speed
        length, step = exploration_windows(log, settings.window_length[0], span)
        if math.isfinite(length):
            timeline_config = replace(config, timeline_length=length, timeline_step=step)
    # a timeline of its own windows, decided now: a step too small for the log is refused before any map work
    timeline_spans = own_spans(timeline_config, settings.window_length[0], settings.times,
                               MAX_TIMELINE_WINDOWS if leash is None else MAX_EXPLORATION_WINDOWS)
    rng = np.random.default_rng(config.seed)
    say = progress or (lambda stage: None)
    timings = dict.fromkeys(STAGES, 0.0)

    say("graph")
    t0 = time.perf_counter()
    chains = weighted_chains(log, config.metric, window=config.window, hop_cost=settings.hop_cost[0],
                             diffusion_time=settings.diffusion_time[0], wall_follow_weight=config.wall_follow_weight)
    graph = chains.graph()
    split = split_regions(log, graph, config.min_region_events, settings.agent_gap)
    timings["graph"] = time.perf_counter() - t0

    events_per_region = split.events_per_comp[split.regions]
    shares = (share_landmarks(config.landmarks, events_per_region) if config.landmarks
              else [None] * len(split.regions))
    with engine_for(workers, scheduler) as engine:
        shared_chains, shared_log = engine.share(chains), engine.share(log)
        region_of_event = np.full(log.n_events, -1, np.int64)
        for r, comp in enumerate(split.regions):
            region_of_event[graph.event_index[split.event_comp == comp]] = r
        shared_regions = engine.share(region_of_event)
        plans, splits = _plan_windows(engine, shared_chains, shared_log, shared_regions, graph, split, config,
                                      settings, say, timeline=timeline_spans is None)
        say("persistence")
        regions = []
        for comp, (plan, notes), n_land in zip(split.regions, plans, shares):
            windows = _map_region(engine, plan, n_land, config, rng, timings)
            regions.append(_read_region(comp, split, windows, notes, reader, config, rng, timings, say))
        say("timeline")
        t0 = time.perf_counter()
        # one draw after all the map's others: the rest of the map is the same with or without it
        timeline_windows = _map_timeline(engine, shared_chains, shared_log, shared_regions, splits, timeline_spans,
                                         regions, shares, config, settings, reader, int(rng.integers(2**63)))
        timings["timeline"] = time.perf_counter() - t0

    betti: dict[int, int | None] = {0: len(regions)}
    confidence: dict[int, float | None] = {0: shipped_beta0_model().confidence(split.beta0)}
    for n in range(1, config.maxdim + 1):
        known = all(n in r.betti for r in regions)
        betti[n] = sum(r.betti[n] for r in regions) if known else None
        confidence[n] = reader.map_confidence([r.confidence.get(n) for r in regions], n) if known else None
    length, step = timeline_settings(timeline_config, settings.window_length[0])
    timeline = build_timeline(timeline_windows, length, step, betti, confidence, log,
                              note=None if timeline_windows else no_timeline_note(timeline_config, length))
    warnings = (motion_warnings(motion, recalibrated_for == "flicker")
                + fault_warnings(screen, recalibrated_for == "fault")
                + silence_warnings(settings.times, settings.window_length[0]) + _extrapolation_warnings(betti))
    exploration = None
    if leash is not None and betti.get(1) is not None:
        exploration = stitch(timeline.windows, log.beacon, leash, length, step, len(regions), log.meta, span)
        if exploration.betti[1] is not None:  # the global map's count is the answer
            betti[1], confidence[1] = exploration.betti[1], None
            warnings = (motion_warnings(motion, recalibrated_for == "flicker")
                        + fault_warnings(screen, recalibrated_for == "fault")
                        + silence_warnings(settings.times, settings.window_length[0]))
    elif (log.beacon is None) != ("leash" not in log.meta):
        warnings.append("the log has " + ("a leader's track (beacon.csv) but no 'leash' in meta.json"
                                          if log.beacon is not None else "a 'leash' in meta.json but no beacon.csv")
                        + ": mapped as a log without a leader (docs/exploration.md)")
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
        log_warnings=warnings + (exploration.warnings if exploration else _change_warnings(timeline)),
        beta0_evidence=split.beta0,
        contact_trace=len(log.status_t) == 0,
        software=software_versions(),
        timeline=timeline,
        exploration=exploration,
        motion=motion,
        sensing=screen,
    )


def _plan_windows(engine, shared_chains, shared_log, shared_regions, graph, split, config: MapConfig,
                  settings: Settings, say, timeline: bool) -> tuple[list[tuple[list, list[str]]], list]:
    """Per region: the (part, span, PartInfo) of every window that holds enough of it (its
    whole log instead when none does), the parts left on the engine, and notes on what
    was skipped; and (``timeline``) each window's (span, split into regions), the split a
    task (:func:`.timeline.split_window`).  Every window's graph is cut once and shared by
    the regions and the split."""
    say("landmarks")
    bands = settings.landmark_bands
    cuts = [engine.submit(cut_window, shared_chains, span) for span in settings.spans]
    splits = [(span, engine.submit(split_window, cut, shared_regions, shared_log, config.min_region_events,
                                   settings.agent_gap))
              for cut, span in zip(cuts, settings.spans) if timeline and span is not None]
    parts, infos = [], []
    for comp in split.regions:
        region_events = engine.share(graph.event_index[split.event_comp == comp])
        parts.append([engine.submit(window_part, cut, region_events, shared_log, config.min_region_events)
                      for cut in cuts])
        infos.append([engine.submit(describe_part, part, span, bands, config)
                      for part, span in zip(parts[-1], settings.spans)])
    plans = []
    for comp, region_parts, region_infos in zip(split.regions, parts, infos):
        plan = [(part, span, info) for part, span, info in zip(region_parts, settings.spans,
                                                                 engine.gather(region_infos)) if info is not None]
        notes = []
        if not plan:  # no window holds enough of this region: map its whole log instead
            whole = engine.share(graph.subgraph(np.flatnonzero(split.labels == comp)))
            plan = [(whole, None, engine.gather([engine.submit(describe_part, whole, None, bands, config)])[0])]
            if settings.tried:
                lo, hi = settings.tried[0], settings.tried[-1]
                tried = f"{lo:.3g}" if lo == hi else f"{lo:.3g}-{hi:.3g}"
                notes.append(f"no window ({tried} s long) holds {config.min_region_events} encounters of this "
                             f"region among {MIN_REGION_AGENTS} agents: its whole log was mapped instead")
        quiet = sum(len(info.bands) < len(bands) for _, _, info in plan)
        if quiet:
            notes.append(f"windows of this region with fewer than {MIN_LANDMARKS} encounters in the middle share "
                         f"of their time span a landmark band draws from (a quiet stretch of the log): {quiet}; "
                         f"they were mapped without that band")
        plans.append((plan, notes))
    return plans, splits


def _map_timeline(engine, shared_chains, shared_log, shared_regions, splits: list, spans: list | None,
                  regions: list[RegionMap], shares, config: MapConfig, settings: Settings, reader: BettiReader,
                  entropy: int) -> list[TimelineWindow]:
    """The timeline's windows (:mod:`.timeline`), read, in order of their middles.
    ``spans`` None: the map's own windows (``splits``: their (span, split) tasks), each
    region part the map mapped read again on its own and any other component of a window
    (a region that split) mapped as a task; else windows of the timeline's own, cut,
    split and every component mapped as tasks."""
    mapped: dict[tuple, list[WindowMap]] = {}
    if spans is None:
        for r, region in enumerate(regions):
            for w in region.windows:
                mapped.setdefault((r, (w.t0, w.t1)), []).append(w)
    else:
        splits = [(span, engine.submit(split_window, engine.submit(cut_window, shared_chains, span), shared_regions,
                                       shared_log, config.min_region_events, settings.agent_gap)) for span in spans]
    pairs = [(span, split) for (span, _), split in zip(splits, engine.gather([task for _, task in splits]))
             if split is not None]
    shared_reader = engine.share(reader)
    readings: list[list] = [[None] * len(split.components) for _, split in pairs]
    tasks = []  # (window, component, task) of the components the map did not map
    for k, (span, split) in enumerate(pairs):
        for j, (label, region, own, _) in enumerate(split.components):
            windows = mapped.get((region, span)) if own else None
            if windows:
                readings[k][j] = (reader.read([w.diagram for w in windows], [w.n_events for w in windows]),
                                  scaled_h1(windows[0]))
            else:
                n_land = None if not config.landmarks else int(shares[max(region, 0)])
                tasks.append((k, j, engine.submit(read_component, shared_chains, span, label, n_land, config,
                                                  settings.landmark_bands, shared_reader, entropy, k * 1_000 + j)))
    for (k, j, _), result in zip(tasks, engine.gather([task for *_, task in tasks])):
        readings[k][j] = result
    out = [timeline_window(span, events_in(settings.times, span), split, read, reader, config.maxdim)
           for (span, split), read in zip(pairs, readings)]
    return sorted(out, key=lambda w: (w.t0 + w.t1, w.t1 - w.t0))


def _map_region(engine, plan, n_land: int | None, config: MapConfig, rng, timings) -> list[WindowMap]:
    """A region's planned windows, each mapped once per usable band, as tasks on
    ``engine``.  Each task's landmark start is drawn here, in window then band order,
    from the map's one stream (as the region's MDS draws from it next), so the order in
    which tasks finish changes nothing."""
    tasks = [engine.submit(map_band, part, span, info.knn_scale, n_land, config, band, int(rng.integers(pool)))
             for part, span, info in plan for band, pool in zip(info.bands, info.pool_sizes)]
    results = engine.gather(tasks)
    timings["landmarks"] += sum(seconds for _, seconds, _ in results)
    timings["persistence"] += sum(seconds for _, _, seconds in results)
    return [window for window, _, _ in results]


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


def _extrapolation_warnings(betti: dict[int, int | None]) -> list[str]:
    """A hole count beyond the arenas the confidence was calibrated on."""
    if (betti.get(1) or 0) > CALIBRATED_HOLES:
        return [f"beta_1 = {betti[1]} is beyond the 0-{CALIBRATED_HOLES} holes of the arenas its confidence was "
                "calibrated on (docs/accuracy.md): the confidence is extrapolated, and many holes in one arena "
                "leave narrow passages between them, where holes merge or go unseen"]
    return []


def _change_warnings(timeline) -> list[str]:
    """The arena changed during the log: the pooled Betti numbers mix before and after."""
    if not timeline.changes:
        return []
    return [f"the Betti numbers changed during the log ({timeline.summary()}): the pooled answer mixes the "
            "arena before and after; read the timeline's segments (map.json 'timeline', docs/timeline.md)"]


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
