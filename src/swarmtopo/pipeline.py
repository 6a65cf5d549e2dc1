"""From encounter log to topological map: ``map_encounters(log, config)``.

Stages (paper, "Algorithm Overview"): encounter metric -> components -> landmark
subsampling -> Vietoris-Rips persistence -> Betti numbers, plus MDS for pictures.

Nothing here reads an arena, a truth file or simulator parameters: the map is a
function of the :class:`~swarmtopo.log.EncounterLog` and the :class:`MapConfig` only.

Disconnected encounter graphs.  Encounters never cross walls between regions, so
separate regions give separate graph components; too little data can also split one
region.  Components are found first.  A component with at least
``config.min_region_events`` events counts as a region and is mapped on its own; a
smaller one is reported as too little data, not as a region.  The diagram of the
whole map is the union of the regions' diagrams -- exactly the Rips diagram of the
disjoint union (points in different regions are infinitely far apart), so H0 has one
infinite bar per region.  No inf or NaN ever reaches a persistence backend.
"""

from __future__ import annotations

import platform
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Callable

import numpy as np

from . import __version__
from .classify import BettiRule, default_rule
from .embed import Embedding, mds
from .errors import SwarmtopoError
from .graph import METRICS, EncounterGraph, build_graph
from .landmarks import SUBSAMPLERS, Landmarks
from .log import EncounterLog
from .persistence import Diagram, rips_persistence


@dataclass(frozen=True)
class MapConfig:
    """Options of the mapping pipeline.

    Attributes
    ----------
    metric
        Encounter metric: ``plain``, ``contracted`` or ``hybrid`` (paper definitions;
        hybrid = contracted + static agents as unbounded stops; it falls back to
        contracted without static agents and to plain without status).
    subsample
        Landmark subsampler: ``maxmin``, ``knn`` (KNN-filtered maxmin) or
        ``probabilistic`` (probabilistic maxmin).
    landmarks
        Number of landmarks L for the whole map, shared between regions in
        proportion to their events.
    window
        Optional time window (t0, t1) on the events, seconds; None = whole log.
    maxdim
        Highest homology dimension (1, or 2 on request).
    seed
        Seed of the landmark start and the MDS.
    knn_k, knn_q, omega
        Subsampler parameters (paper: k = 10, q = 0.9).
    min_region_events
        Events a graph component needs to count as a region (default 50: below
        that a component is a few agents that met only each other, too little to
        map).
    embed_dim
        Dimension of the MDS picture: 3, 2, or 0 for no picture (sweeps).
    """

    metric: str = "hybrid"
    subsample: str = "maxmin"
    landmarks: int = 300
    window: tuple[float | None, float | None] | None = None
    maxdim: int = 1
    seed: int | None = 0
    knn_k: int = 10
    knn_q: float = 0.9
    omega: float = 1.0
    min_region_events: int = 50
    embed_dim: int = 3

    def validate(self) -> "MapConfig":
        if self.metric not in METRICS:
            raise SwarmtopoError(f"unknown metric {self.metric!r}; expected one of {', '.join(METRICS)}")
        if self.subsample not in SUBSAMPLERS:
            raise SwarmtopoError(
                f"unknown subsampler {self.subsample!r}; expected one of {', '.join(SUBSAMPLERS)}")
        if self.landmarks < 3:
            raise SwarmtopoError(f"landmarks must be at least 3, got {self.landmarks}")
        if self.maxdim not in (0, 1, 2):
            raise SwarmtopoError(f"maxdim must be 0, 1 or 2, got {self.maxdim}")
        if self.embed_dim not in (0, 2, 3):
            raise SwarmtopoError(f"embed_dim must be 0, 2 or 3, got {self.embed_dim}")
        if self.window is not None:
            t0, t1 = self.window
            if t0 is not None and t1 is not None and t1 < t0:
                raise SwarmtopoError(f"window end {t1} is before its start {t0}")
        return self


@dataclass(eq=False)
class RegionMap:
    """One region: a connected component of the encounter graph with enough events."""

    component: int
    n_events: int
    n_agents: int
    landmarks: Landmarks
    landmark_events: np.ndarray  # (L,) original log event index of each landmark
    diagram: Diagram
    betti: dict[int, int]
    embedding: Embedding | None


@dataclass(eq=False)
class TopologicalMap:
    """The result of mapping an encounter log.

    ``betti[n]`` is the estimated n-th Betti number: beta_0 counts regions, beta_1
    holes.  ``diagram`` is the union of the regions' diagrams.
    """

    betti: dict[int, int]
    diagram: Diagram
    regions: list[RegionMap]
    too_little_data: list[dict[str, int]]
    thresholds: dict[str, Any]
    config: MapConfig
    timings: dict[str, float]
    n_events: int
    n_agents: int
    software: dict[str, str] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The map.json document (deaths of infinite bars as null)."""
        return {
            "betti": {str(k): int(v) for k, v in sorted(self.betti.items())},
            "diagrams": self.diagram.to_json(),
            "thresholds": self.thresholds,
            "regions": [
                {
                    "component": r.component,
                    "events": r.n_events,
                    "agents": r.n_agents,
                    "landmarks": int(len(r.landmarks.nodes)),
                    "cover_radius": float(r.landmarks.cover_radius),
                    "betti": {str(k): int(v) for k, v in sorted(r.betti.items())},
                    "diagrams": r.diagram.to_json(),
                    "mds_stress": None if r.embedding is None else float(r.embedding.stress),
                }
                for r in self.regions
            ],
            "too_little_data": self.too_little_data,
            "params": _jsonable(asdict(self.config)),
            "log": {"events": self.n_events, "agents": self.n_agents},
            "timings": {k: round(v, 6) for k, v in self.timings.items()},
            "software": self.software,
        }


def map_encounters(
    log: EncounterLog,
    config: MapConfig | None = None,
    *,
    rule: BettiRule | None = None,
    progress: Callable[[str], None] | None = None,
) -> TopologicalMap:
    """Map an encounter log to Betti numbers, diagrams and pictures.

    Parameters
    ----------
    log
        The encounter log (simulated or real).
    config
        Pipeline options; defaults to ``MapConfig()``.
    rule
        How Betti numbers are read off the diagrams; defaults to
        :func:`swarmtopo.classify.default_rule`.
    progress
        Optional callable receiving the name of each stage as it starts.

    Raises
    ------
    SwarmtopoError
        If the (windowed) log has too few events, or no component is big enough
        to count as a region.
    """
    config = (config or MapConfig()).validate()
    rule = rule or default_rule()
    rng = np.random.default_rng(config.seed)
    say = progress or (lambda stage: None)
    timings: dict[str, float] = {}

    if log.n_events < 2:
        raise SwarmtopoError(
            f"the log has {log.n_events} event(s); at least 2 encounters are needed to build a map")
    say("graph")
    t0 = time.perf_counter()
    graph = build_graph(log, config.metric, window=config.window)
    n_comp, labels = graph.components()
    timings["graph"] = time.perf_counter() - t0

    events_per_comp = np.bincount(labels, weights=graph.multiplicity, minlength=n_comp).astype(np.int64)
    regions_idx = [c for c in np.argsort(-events_per_comp, kind="stable")
                   if events_per_comp[c] >= config.min_region_events]
    small = [c for c in range(n_comp) if events_per_comp[c] < config.min_region_events]
    if not regions_idx:
        raise SwarmtopoError(
            f"no connected group of encounters has {config.min_region_events} events or more "
            f"(largest: {int(events_per_comp.max())} of {graph.n_events} events in {n_comp} groups); "
            "the log is too short or the agents too few to map: collect more data")
    budget = _share_landmarks(config.landmarks, events_per_comp[regions_idx])

    regions: list[RegionMap] = []
    region_thresholds: list[dict] = []
    timings.update(landmarks=0.0, persistence=0.0, embedding=0.0)
    for comp, n_land in zip(regions_idx, budget):
        nodes = np.flatnonzero(labels == comp)
        sub = graph.subgraph(nodes)
        say("landmarks")
        t0 = time.perf_counter()
        land = _subsample(sub, config, int(n_land), rng)
        timings["landmarks"] += time.perf_counter() - t0
        say("persistence")
        t0 = time.perf_counter()
        dgm = rips_persistence(land.distances, maxdim=config.maxdim).diagram
        timings["persistence"] += time.perf_counter() - t0
        say("embedding")
        t0 = time.perf_counter()
        emb = (mds(land.distances, dim=config.embed_dim, rng=rng)
               if config.embed_dim and len(land.nodes) > config.embed_dim else None)
        timings["embedding"] += time.perf_counter() - t0
        rep = sub.representative_event()
        regions.append(RegionMap(
            component=int(comp),
            n_events=int(events_per_comp[comp]),
            n_agents=_count_agents(log, sub.event_index),
            landmarks=land,
            landmark_events=rep[land.nodes],
            diagram=dgm,
            betti=rule.betti(dgm, land.cover_radius),
            embedding=emb,
        ))
        region_thresholds.append({"component": int(comp), "cover_radius": float(land.cover_radius),
                                  "length": {str(n): v for n, v in rule.thresholds(dgm, land.cover_radius).items()}})

    betti = {0: len(regions)}
    for n in range(1, config.maxdim + 1):
        betti[n] = sum(r.betti.get(n, 0) for r in regions)
    event_component = labels[graph.node_of_event]
    too_little = [
        {"component": int(c), "events": int(events_per_comp[c]),
         "agents": _count_agents(log, graph.event_index[event_component == c])}
        for c in small
    ]
    return TopologicalMap(
        betti=betti,
        diagram=_union(r.diagram for r in regions),
        regions=regions,
        too_little_data=too_little,
        thresholds={**rule.describe(), "regions": region_thresholds},
        config=config,
        timings=timings,
        n_events=graph.n_events,
        n_agents=log.n_agents,
        software=software_versions(),
    )


def software_versions() -> dict[str, str]:
    """Versions of swarmtopo and the libraries whose numbers it reports."""
    import gudhi
    import scipy
    import sklearn

    return {
        "swarmtopo": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "gudhi": gudhi.__version__,
        "scikit-learn": sklearn.__version__,
    }


def _count_agents(log: EncounterLog, events: np.ndarray) -> int:
    return int(len(np.union1d(log.a[events], log.b[events])))


def _subsample(graph: EncounterGraph, config: MapConfig, n_landmarks: int, rng) -> Landmarks:
    if config.subsample == "maxmin":
        return SUBSAMPLERS["maxmin"](graph, n_landmarks, rng=rng)
    if config.subsample == "knn":
        return SUBSAMPLERS["knn"](graph, n_landmarks, k=config.knn_k, q=config.knn_q, rng=rng)
    return SUBSAMPLERS["probabilistic"](graph, n_landmarks, k=config.knn_k, omega=config.omega, rng=rng)


def _share_landmarks(total: int, events: np.ndarray) -> np.ndarray:
    """Split ``total`` landmarks between regions in proportion to their events.

    Largest-remainder rounding; every region gets at least 3 and at most its events.
    """
    events = np.asarray(events, dtype=float)
    raw = total * events / events.sum()
    share = np.floor(raw).astype(np.int64)
    for i in np.argsort(-(raw - share), kind="stable")[: total - share.sum()]:
        share[i] += 1
    return np.clip(share, 3, events.astype(np.int64))


def _union(diagrams) -> Diagram:
    diagrams = list(diagrams)
    maxdim = max(d.maxdim for d in diagrams)
    pairs = []
    for n in range(maxdim + 1):
        stacked = np.vstack([d[n] for d in diagrams if n <= d.maxdim] or [np.empty((0, 2))])
        length = stacked[:, 1] - stacked[:, 0]
        pairs.append(stacked[np.lexsort((stacked[:, 0], -length))])
    return Diagram(pairs=tuple(pairs), backend=diagrams[0].backend)


def _jsonable(value):
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (np.floating,)):
        return float(value)
    return value
