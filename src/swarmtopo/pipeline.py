"""From encounter log to topological map: ``map_encounters(log, config)``.

Stages (paper, "Algorithm Overview"): encounter metric -> components -> landmark
subsampling -> Vietoris-Rips persistence -> Betti numbers, plus MDS for pictures.

Nothing here reads an arena, a truth file or simulator parameters: the map is a
function of the :class:`~swarmtopo.log.EncounterLog` and the :class:`MapConfig` only.

Disconnected encounter graphs.  Encounters never cross walls between regions, so
separate regions give separate graph components; too little data can also split one
region.  Components are found first.  A component with at least
``config.min_region_events`` events counts as a region and is mapped on its own; a
smaller one, or one of fewer than three agents (a pair that kept meeting), is reported
as too little data, not as a region.  The diagram of the
whole map is the union of the regions' diagrams -- exactly the Rips diagram of the
disjoint union (points in different regions are infinitely far apart), so H0 has one
infinite bar per region.  No inf or NaN ever reaches a persistence backend.
"""

from __future__ import annotations

import platform
import time
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Callable

import numpy as np

from . import __version__
from .classify import BettiClassifier, RegionScales, load_classifier
from .cycles import Cycle, region_cycles
from .embed import Embedding, mds
from .errors import SwarmtopoError
from .graph import METRICS, EncounterGraph, build_graph
from .io import jsonable
from .landmarks import SUBSAMPLERS, Landmarks, knn_distances, knn_maxmin, maxmin, probabilistic_maxmin
from .log import EncounterLog
from .persistence import Diagram, rips_persistence


MIN_REGION_AGENTS = 3
"""Distinct agents a component needs to count as a region (two agents alone that keep
meeting say nothing about the arena)."""
AUTO_COVER_FACTOR = 1.5
"""The automatic landmark count stops once r_cover <= AUTO_COVER_FACTOR * s (s: the
region's k-NN scale).  The landmarks' diagram is within bottleneck 2 r_cover of the
whole cloud's, so subsampling moves no bar by more than 3 s: the order of the
cloud's own Rips noise bars."""
STAGES = ("graph", "landmarks", "persistence", "embedding", "classify", "cycles")
"""Stage names passed to ``map_encounters``'s progress callback, in order."""


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
        proportion to their events.  None (default): per region, the fewest
        landmarks whose covering radius is at most ``AUTO_COVER_FACTOR`` times the
        region's k-NN scale, at most ``max_landmarks``; maxmin-type selection is
        greedy, so these are the first landmarks of a longer run.
    max_landmarks
        Cap of the automatic landmark count per region (default 1000: persistence
        stays around a second).
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
        map).  It also needs ``MIN_REGION_AGENTS`` distinct agents.
    embed_dim
        Dimension of the MDS picture: 3, 2, or 0 for no picture (sweeps).
    cycles
        Find a representative loop of landmarks for each counted H1 bar (where the
        holes are; :mod:`swarmtopo.cycles`).  Off in sweeps, which store no loops.
    """

    metric: str = "hybrid"
    subsample: str = "maxmin"
    landmarks: int | None = None
    max_landmarks: int = 1000
    window: tuple[float | None, float | None] | None = None
    maxdim: int = 1
    seed: int | None = 0
    knn_k: int = 10
    knn_q: float = 0.9
    omega: float = 1.0
    min_region_events: int = 50
    embed_dim: int = 3
    cycles: bool = True

    def validate(self) -> "MapConfig":
        if self.metric not in METRICS:
            raise SwarmtopoError(f"unknown metric {self.metric!r}; expected one of {', '.join(METRICS)}")
        if self.subsample not in SUBSAMPLERS:
            raise SwarmtopoError(
                f"unknown subsampler {self.subsample!r}; expected one of {', '.join(SUBSAMPLERS)}")
        if self.landmarks is not None and self.landmarks < 3:
            raise SwarmtopoError(f"landmarks must be at least 3, got {self.landmarks}")
        if self.max_landmarks < 3:
            raise SwarmtopoError(f"max_landmarks must be at least 3, got {self.max_landmarks}")
        if self.maxdim not in (1, 2):
            raise SwarmtopoError(f"maxdim must be 1 or 2, got {self.maxdim}")
        if self.embed_dim not in (0, 2, 3):
            raise SwarmtopoError(f"embed_dim must be 0, 2 or 3, got {self.embed_dim}")
        if self.window is not None:
            t0, t1 = self.window
            for end in (t0, t1):
                if end is not None and not np.isfinite(end):
                    raise SwarmtopoError(f"window ends must be finite numbers or None, got {end}")
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
    scales: RegionScales
    thresholds: dict[int, float]  # bar-length threshold per dimension n >= 1
    betti: dict[int, int]
    confidence: dict[int, float | None]  # P(betti[n] is right), n >= 1
    cycles: list[Cycle]  # a loop of landmarks round each counted H1 bar (empty if not asked)
    warnings: list[str]
    embedding: Embedding | None


@dataclass(eq=False)
class TopologicalMap:
    """The result of mapping an encounter log.

    ``betti[n]`` is the estimated n-th Betti number: beta_0 counts regions, beta_1
    holes (None for a dimension the classifier has no Theta_n for).
    ``confidence[n]`` is the probability that ``betti[n]`` is right (see
    :mod:`swarmtopo.classify`; beta_n for n >= 1 is a sum over regions, so its
    confidence is the product of the regions'; None without a calibrated classifier).
    ``diagram`` is the union of the regions' diagrams.
    """

    betti: dict[int, int | None]
    confidence: dict[int, float | None]
    diagram: Diagram
    regions: list[RegionMap]
    too_little_data: list[dict[str, int]]
    classifier: dict[str, Any]
    config: MapConfig
    timings: dict[str, float]
    n_events: int
    n_agents: int
    software: dict[str, str] = field(default_factory=dict)

    @property
    def warnings(self) -> list[str]:
        """Reasons to doubt the map, from every region."""
        return [w for r in self.regions for w in r.warnings]

    def to_json(self) -> dict[str, Any]:
        """The map.json document (deaths of infinite bars as null)."""
        return {
            "betti": {str(k): v for k, v in sorted(self.betti.items())},
            "confidence": {str(k): v for k, v in sorted(self.confidence.items())},
            "diagrams": self.diagram.to_json(),
            "classifier": self.classifier,
            "warnings": self.warnings,
            "regions": [
                {
                    "component": r.component,
                    "events": r.n_events,
                    "agents": r.n_agents,
                    "landmarks": int(len(r.landmarks.nodes)),
                    "cover_radius": float(r.scales.cover_radius),
                    "knn_scale": float(r.scales.knn),
                    "thresholds": {str(n): float(v) for n, v in r.thresholds.items()},
                    "betti": {str(k): int(v) for k, v in sorted(r.betti.items())},
                    "confidence": {str(k): v for k, v in sorted(r.confidence.items())},
                    "cycles": [c.to_json() for c in r.cycles],
                    "diagrams": r.diagram.to_json(),
                    "mds_stress": None if r.embedding is None else float(r.embedding.stress),
                    "warnings": r.warnings,
                }
                for r in self.regions
            ],
            "too_little_data": self.too_little_data,
            "params": jsonable(asdict(self.config)),
            "log": {"events": self.n_events, "agents": self.n_agents},
            "timings": {k: round(v, 6) for k, v in self.timings.items()},
            "software": {**self.software, "persistence_backend": self.diagram.backend},
        }


def map_encounters(
    log: EncounterLog,
    config: MapConfig | None = None,
    *,
    classifier: BettiClassifier | None = None,
    progress: Callable[[str], None] | None = None,
) -> TopologicalMap:
    """Map an encounter log to Betti numbers, diagrams and pictures.

    Parameters
    ----------
    log
        The encounter log (simulated or real).
    config
        Pipeline options; defaults to ``MapConfig()``.
    classifier
        How Betti numbers n >= 1 are read off each region's diagram; defaults to
        the shipped ``load_classifier("default")``.
    progress
        Optional callable receiving the name of each stage (``STAGES``) as it starts.

    Raises
    ------
    SwarmtopoError
        If the (windowed) log has too few events, or no component is big enough
        to count as a region.
    """
    config = (config or MapConfig()).validate()
    classifier = classifier or load_classifier("default")
    rng = np.random.default_rng(config.seed)
    say = progress or (lambda stage: None)
    timings = dict.fromkeys(STAGES, 0.0)

    if log.n_events < 2:
        raise SwarmtopoError(
            f"the log has {log.n_events} event(s); at least 2 encounters are needed to build a map")
    say("graph")
    t0 = time.perf_counter()
    graph = build_graph(log, config.metric, window=config.window)
    n_comp, labels = graph.components()
    event_comp = labels[graph.node_of_event]
    events_per_comp = np.bincount(event_comp, minlength=n_comp)
    agents_per_comp = _agents_per_component(log, graph.event_index, event_comp, n_comp)
    timings["graph"] = time.perf_counter() - t0

    is_region = (events_per_comp >= config.min_region_events) & (agents_per_comp >= MIN_REGION_AGENTS)
    regions_idx = [int(c) for c in np.argsort(-events_per_comp, kind="stable") if is_region[c]]
    if not regions_idx:
        raise SwarmtopoError(
            f"no connected group of encounters has {config.min_region_events} events or more among "
            f"{MIN_REGION_AGENTS} agents or more (largest: {int(events_per_comp.max())} of {graph.n_events} "
            f"events in {n_comp} groups); the log is too short or the agents too few to map: collect more data")

    shares = (_share_landmarks(config.landmarks, events_per_comp[regions_idx]) if config.landmarks
              else [None] * len(regions_idx))
    regions: list[RegionMap] = []
    for comp, n_land in zip(regions_idx, shares):
        sub = graph.subgraph(np.flatnonzero(labels == comp))
        say("landmarks")
        t0 = time.perf_counter()
        knn_scale = _knn_scale(sub, config.knn_k)
        if n_land is None:
            land = _subsample(sub, config, min(config.max_landmarks, sub.n_nodes), rng)
            land = _first_covering(land, AUTO_COVER_FACTOR * knn_scale)
        else:
            land = _subsample(sub, config, int(min(n_land, sub.n_nodes)), rng)
        scales = RegionScales(knn=knn_scale, cover_radius=float(land.cover_radius))
        timings["landmarks"] += time.perf_counter() - t0
        say("persistence")
        t0 = time.perf_counter()
        # with loops asked for, one run that also keeps the cocycles they are found from
        persistence = rips_persistence(land.distances, maxdim=config.maxdim, cocycles=config.cycles)
        dgm = persistence.diagram
        timings["persistence"] += time.perf_counter() - t0
        say("embedding")
        t0 = time.perf_counter()
        emb = (mds(land.distances, dim=config.embed_dim, rng=rng)
               if config.embed_dim and len(land.nodes) > config.embed_dim else None)
        timings["embedding"] += time.perf_counter() - t0
        say("classify")
        t0 = time.perf_counter()
        betti_region = classifier.betti(dgm)
        confidence_region = classifier.confidence(dgm)
        thresholds = classifier.thresholds(dgm)
        timings["classify"] += time.perf_counter() - t0
        regions.append(RegionMap(
            component=comp,
            n_events=int(events_per_comp[comp]),
            n_agents=int(agents_per_comp[comp]),
            landmarks=land,
            landmark_events=sub.representative_event()[land.nodes],
            diagram=dgm,
            scales=scales,
            thresholds=thresholds,
            betti=betti_region,
            confidence=confidence_region,
            cycles=[],
            warnings=_sampling_warnings(scales, len(land.nodes), config),
            embedding=emb,
        ))
        if config.cycles:
            say("cycles")
            t0 = time.perf_counter()
            regions[-1].cycles = region_cycles(regions[-1], persistence)
            timings["cycles"] += time.perf_counter() - t0

    betti: dict[int, int | None] = {0: len(regions)}
    confidence: dict[int, float | None] = {0: classifier.beta0_confidence()}
    for n in range(1, config.maxdim + 1):
        known = all(n in r.betti for r in regions)
        betti[n] = sum(r.betti[n] for r in regions) if known else None
        region_conf = [r.confidence.get(n) for r in regions]
        confidence[n] = (float(np.prod(region_conf)) if known and None not in region_conf else None)
    too_little = [{"component": int(c), "events": int(events_per_comp[c]), "agents": int(agents_per_comp[c])}
                  for c in range(n_comp) if not is_region[c]]
    return TopologicalMap(
        betti=betti,
        confidence=confidence,
        diagram=Diagram(pairs=tuple(np.vstack([r.diagram[n] for r in regions])
                                    for n in range(config.maxdim + 1)),
                        backend=regions[0].diagram.backend),
        regions=regions,
        too_little_data=too_little,
        classifier=classifier.describe(),
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


def _agents_per_component(log: EncounterLog, event_index: np.ndarray, event_comp: np.ndarray,
                          n_comp: int) -> np.ndarray:
    """Distinct agents among each component's events."""
    comp = np.concatenate([event_comp, event_comp])
    agent = np.concatenate([log.a[event_index], log.b[event_index]])
    pairs = np.unique(comp * np.int64(log.n_agents) + agent)
    return np.bincount(pairs // log.n_agents, minlength=n_comp)


def _knn_scale(graph: EncounterGraph, k: int) -> float:
    """s: median over distinct events (graph nodes) of the mean distance to their k
    nearest other nodes (see :mod:`swarmtopo.classify`)."""
    k = min(k, graph.n_nodes - 1)
    distinct = replace(graph, multiplicity=np.ones_like(graph.multiplicity))
    return float(np.median(knn_distances(distinct, k).mean(axis=1)))


def _sampling_warnings(scales: RegionScales, n_landmarks: int, config: MapConfig) -> list[str]:
    """Why a region's answer may be unreliable (empty when it is not)."""
    if scales.cover_radius > AUTO_COVER_FACTOR * scales.knn:
        return [f"landmarks too sparse: {n_landmarks} landmarks leave a covering radius of "
                f"{scales.cover_radius:.3g} s, over {AUTO_COVER_FACTOR:g} x the cloud's k-NN scale "
                f"{scales.knn:.3g} s, so subsampling noise can pass the threshold; use more landmarks"
                + ("" if config.landmarks else f" (raise max_landmarks above {config.max_landmarks})")]
    return []


def _subsample(graph: EncounterGraph, config: MapConfig, n_landmarks: int, rng) -> Landmarks:
    if config.subsample == "knn":
        return knn_maxmin(graph, n_landmarks, k=config.knn_k, q=config.knn_q, rng=rng)
    if config.subsample == "probabilistic":
        return probabilistic_maxmin(graph, n_landmarks, k=config.knn_k, omega=config.omega, rng=rng)
    return maxmin(graph, n_landmarks, rng=rng)


def _first_covering(land: Landmarks, radius: float) -> Landmarks:
    """The first landmarks of a greedy run whose covering radius is <= ``radius``
    (all of them if none is; at least 3)."""
    within = np.flatnonzero(land.cover_radii <= radius)
    n = max(int(within[0]) + 1, 3) if len(within) else len(land.nodes)
    n = min(n, len(land.nodes))
    return replace(land, nodes=land.nodes[:n], distances=land.distances[:n, :n],
                   cover_radius=float(land.cover_radii[n - 1]), cover_radii=land.cover_radii[:n])


def _share_landmarks(total: int, events: np.ndarray) -> np.ndarray:
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
