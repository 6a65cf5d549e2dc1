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

from .. import __version__
from ..readers.beta0 import BETA0_DEFINITION, Beta0Evidence, beta0_evidence, shipped_beta0_model
from ..readers.paper import BettiClassifier, RegionScales, load_classifier
from ..topology.cycles import Cycle, region_cycles
from ..topology.embed import Embedding, mds
from ..errors import InputError, SwarmtopoError
from ..metric.graph import METRICS, EncounterGraph, agent_gaps, build_graph
from ..io.logs import jsonable
from ..metric.landmarks import (MIN_LANDMARKS, SUBSAMPLERS, Landmarks, knn_distances, knn_maxmin, maxmin,
                        probabilistic_maxmin)
from ..log import EncounterLog, exact_time
from ..topology.persistence import Diagram, PersistenceResult, rips_persistence
from ..readers.agreement import overlapping, rank_agreement, window_coordinates
from ..readers.ratio import (RESOLUTION_CAP, RatioClassifier, below_full_resolution, longest_bars, map_confidence, region_reader,
                    resolution, vote)


MIN_REGION_AGENTS = 3
"""Distinct agents a component needs to count as a region (two agents alone that keep
meeting say nothing about the arena)."""
MAX_HOP_COST, MAX_WALL_FOLLOW_WEIGHT = 1e9, 1e6
"""Bounds of the per-hop cost (s, about 30 years) and of the wall-following charge (s/s):
far beyond any log, and far below where squared distances overflow in MDS."""
MAX_LANDMARKS = 2000
"""Bound of ``MapConfig.landmarks`` and ``max_landmarks`` (``map --landmarks``'s too):
persistence time grows about as L^3."""
MAX_WINDOWS_LISTED = 100_000
"""Most windows of one length a log may be cut into before the cap picks its share."""
AUTO_COVER_FACTOR = 1.5
"""The automatic landmark count stops once r_cover <= AUTO_COVER_FACTOR * s (s: the
region's k-NN scale).  The landmarks' diagram is within bottleneck 2 r_cover of the
whole cloud's, so subsampling moves no bar by more than 3 s: the order of the
cloud's own Rips noise bars."""
ADVICE_BELOW = 0.9
"""A Betti number reported with less confidence than this comes with advice."""
CALIBRATED_HOLES = 3
"""The most holes of any arena the confidence was calibrated on (the accuracy
benchmark's cells: 0-3); a map counting more says its confidence is extrapolated."""
HOP_GAP_FACTOR = 2.0
"""Without r_d and v_c in meta.json, the per-hop cost h is this many times the mean time
between an agent's consecutive encounters (docs/accuracy.md, "Real traces")."""
DIFFUSION_GAP_FACTOR = 0.5
"""The automatic diffusion time tau is this many times the mean time between an agent's
consecutive encounters (docs/tuning.md)."""
WALL_FOLLOW_WEIGHT = 2.0
"""Default ``MapConfig.wall_follow_weight``: seconds charged per second of wall following
inside a chain gap, outside the diffusive compression (docs/tuning.md)."""
WINDOW_SCALES = (0.75, 1.0, 1.25)
"""Default ``MapConfig.window_scales``: multipliers of the window length whose windows
are all pooled (windows of 15, 20 and 25 encounters per agent; docs/tuning.md)."""
MAX_WINDOWS = 48
"""Default ``MapConfig.max_windows``: more than any map of the accuracy benchmark pools
(at most 44), so its measured accuracy holds; a longer log maps an evenly spaced subset."""
AGREEMENT_MODES = ("auto", "always")
"""``MapConfig.agreement``: compute A_k when the classifier's vote needs it, or for every region."""
WHOLE_LOG = float("inf")
"""``MapConfig.window_length`` that maps the whole log at once (the paper)."""


def seconds_option(value: str | float | None) -> float | None:
    """A ``MapConfig`` time in seconds (``hop_cost``, ``diffusion_time``, ``window_length``,
    ``window_step``) from a command-line or sweep value: "auto" (or None) -> None (from the
    data), "none" -> inf (``WHOLE_LOG``; no diffusive weights), a number -> that many seconds."""
    if value is None or value == "auto":
        return None
    return WHOLE_LOG if value == "none" else float(value)


def wall_follow_option(value: str | float | None) -> float | None:
    """``MapConfig.wall_follow_weight`` from a command-line or sweep value: None -> the
    default (``WALL_FOLLOW_WEIGHT``), "none" -> None (charged like any time, the paper), a
    number -> that weight."""
    if value is None:
        return WALL_FOLLOW_WEIGHT
    return None if value == "none" else float(value)


def max_windows_option(value: str | int | None) -> int | None:
    """``MapConfig.max_windows`` from a command-line value: None -> the default
    (``MAX_WINDOWS``), "none" -> None (every window), a whole number -> that cap."""
    if value is None:
        return MAX_WINDOWS
    return None if value == "none" else int(value)


STAGES = ("graph", "landmarks", "persistence", "agreement", "classify", "embedding", "cycles")
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
    hop_cost
        Per-hop cost h (seconds) added to every chain edge of the graph
        (:mod:`swarmtopo.metric.graph`); 0 is the paper's metric; None (default) takes
        r_d / v_c from the log's meta.json, or, for a trace without them,
        ``HOP_GAP_FACTOR`` x the mean time between an agent's encounters.
    diffusion_time
        tau (seconds) of the diffusive chain weights D_tau(w) = tau (sqrt(1 + 2 w / tau)
        - 1) (:mod:`swarmtopo.metric.graph`): a long gap between an agent's encounters costs
        about a random walk's displacement, not its duration.  inf is the paper's
        weight; None (default) is ``DIFFUSION_GAP_FACTOR`` x the mean time between an
        agent's consecutive encounters in the mapped events (:func:`resolve_diffusion_time`).
    wall_follow_weight
        c: the part of a chain gap an agent spent wall following (status WF) weighs c
        per second, outside D_tau: along a wall an agent walks, it does not diffuse
        (:mod:`swarmtopo.metric.graph`).  Default ``WALL_FOLLOW_WEIGHT``; None charges it like
        any other time (the paper).  A log without status changes is unaffected.
    window_length
        Length (s) of the time windows each region is mapped in; the region's Betti
        numbers pool them (:func:`swarmtopo.readers.ratio.vote`).  None (default):
        from the data, ``window_encounters`` times the mean time between an agent's
        consecutive encounters, so a window holds about that many encounters per
        agent whatever the swarm's density (:func:`resolve_window`).  ``WHOLE_LOG``
        (inf) maps the whole log at once (the paper); so does any length not shorter
        than the log.
    window_encounters
        K, the encounters per agent an automatic window holds (default 20, chosen on
        the benchmark's tuning cases: docs/tuning.md).
    window_scales
        Multipliers s of the window length: the windows of every length s x W (s x K
        encounters per agent when automatic; each its own ``window_step``, default half
        its length) are pooled together, each distinct window once.  A scale whose
        windows would not be shorter than the log maps the whole log.  Default
        ``WINDOW_SCALES`` = (0.75, 1, 1.25): with the classifier's mean pooling, more
        accurate on the tuning cases than one length, at about three times the time
        (docs/tuning.md).
    window_step
        Seconds between the starts of consecutive windows; None (default) = half the
        window length, so windows overlap by half and a log of T seconds gets
        ceil(2 T / window_length) - 1 of them, evenly spaced from the first event to
        the last.
    max_windows
        Cap of the windows mapped, all lengths together (default ``MAX_WINDOWS``; at
        least the number of ``window_scales``): a log with more keeps of each length's
        windows an evenly spaced share in proportion to their number, at least one
        each, ``max_windows`` in all, so the map's time stops growing with the log's
        length while the pooled windows still span it.  None maps every window.
    subsample
        Landmark subsampler: ``maxmin``, ``knn`` (KNN-filtered maxmin) or
        ``probabilistic`` (probabilistic maxmin).
    landmark_bands
        Shares B of each window's length: every window is mapped once per band, its
        landmarks drawn (maxmin) only among the nodes of the window's middle B x its
        length, distances still on the whole window's graph, and all of them are
        pooled.  (1,): the whole window, once.  (1, 0.5) adds landmarks that differ in
        place more than in time (the metric grows about 0.35 s per second between two
        events at one place).  Bands below 1 need ``subsample="maxmin"``.  None
        (default): with maxmin, the bands the classifier that reads the map was fitted
        with (:func:`fitted_landmark_bands`), whose thresholds are those bands' (the
        shipped ``default``: (1, 0.5); ``trace``: (1,); docs/accuracy.md); with
        another subsampler, (1,).
    landmarks
        Number of landmarks L (3 .. ``MAX_LANDMARKS``) for the whole map, shared between regions in
        proportion to their events.  None (default): per region, the fewest
        landmarks whose covering radius is at most ``AUTO_COVER_FACTOR`` times the
        region's k-NN scale, at most ``max_landmarks``; maxmin-type selection is
        greedy, so these are the first landmarks of a longer run.
    max_landmarks
        Cap of the automatic landmark count per region and window (3 .. ``MAX_LANDMARKS``; default 400, the
        setting the accuracy benchmark measured; persistence stays well under a
        second).
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
        holes are; :mod:`swarmtopo.topology.cycles`).  Off in sweeps, which store no loops.
    agreement
        When to compute each region's cross-window cycle agreement A_1 .. A_5
        (:mod:`swarmtopo.readers.agreement`): ``"auto"`` (default) only where the classifier's
        gate needs it (a gated classifier, and a rank whose score passes), ``"always"``
        for every region (fitting the gate: ``lab/fit_agreement_gate.py``).
    """

    metric: str = "hybrid"
    hop_cost: float | None = None
    diffusion_time: float | None = None
    wall_follow_weight: float | None = WALL_FOLLOW_WEIGHT
    window_length: float | None = None
    window_encounters: float = 20.0
    window_scales: tuple[float, ...] = WINDOW_SCALES
    window_step: float | None = None
    max_windows: int | None = MAX_WINDOWS
    subsample: str = "maxmin"
    landmark_bands: tuple[float, ...] | None = None
    landmarks: int | None = None
    max_landmarks: int = 400
    window: tuple[float | None, float | None] | None = None
    maxdim: int = 1
    seed: int | None = 0
    knn_k: int = 10
    knn_q: float = 0.9
    omega: float = 1.0
    min_region_events: int = 50
    embed_dim: int = 3
    cycles: bool = True
    agreement: str = "auto"

    def __post_init__(self):
        scales = self.window_scales
        object.__setattr__(self, "window_scales",
                           tuple(scales) if isinstance(scales, (list, tuple, np.ndarray)) else (scales,))
        bands = self.landmark_bands
        if bands is not None:
            object.__setattr__(self, "landmark_bands",
                               tuple(bands) if isinstance(bands, (list, tuple, np.ndarray)) else (bands,))

    def validate(self) -> "MapConfig":
        if self.metric not in METRICS:
            raise SwarmtopoError(f"unknown metric {self.metric!r}; expected one of {', '.join(METRICS)}")
        if self.subsample not in SUBSAMPLERS:
            raise SwarmtopoError(
                f"unknown subsampler {self.subsample!r}; expected one of {', '.join(SUBSAMPLERS)}")
        for name, count in (("landmarks", self.landmarks), ("max_landmarks", self.max_landmarks)):
            if count is not None and not 3 <= count <= MAX_LANDMARKS:
                raise SwarmtopoError(f"{name} must be in 3..{MAX_LANDMARKS} (persistence time grows about as L^3), "
                                     f"got {count}")
        if self.hop_cost is not None and not (np.isfinite(self.hop_cost) and 0 <= self.hop_cost <= MAX_HOP_COST):
            raise SwarmtopoError(f"hop_cost must be a number of seconds in [0, {MAX_HOP_COST:g}], got {self.hop_cost}")
        if self.diffusion_time is not None and not self.diffusion_time > 0:
            raise SwarmtopoError(f"diffusion_time must be a positive number of seconds or inf, got "
                                 f"{self.diffusion_time}")
        if self.wall_follow_weight is not None and not (np.isfinite(self.wall_follow_weight)
                                                        and 0 <= self.wall_follow_weight <= MAX_WALL_FOLLOW_WEIGHT):
            raise SwarmtopoError(f"wall_follow_weight must be a number in [0, {MAX_WALL_FOLLOW_WEIGHT:g}] or None, "
                                 f"got {self.wall_follow_weight}")
        if self.window_length is not None and not self.window_length > 0:
            raise SwarmtopoError(f"window_length must be a positive number of seconds, got {self.window_length}")
        if not (np.isfinite(self.window_encounters) and self.window_encounters > 0):
            raise SwarmtopoError(f"window_encounters must be a positive number, got {self.window_encounters}")
        scales = self.window_scales
        if not scales or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) and x > 0
                                 for x in scales):
            raise SwarmtopoError(f"window_scales must be one or more positive numbers, got {list(scales)}")
        if len(set(scales)) < len(scales):
            raise SwarmtopoError(f"window_scales must be distinct, got {list(scales)}")
        bands = (1.0,) if self.landmark_bands is None else self.landmark_bands
        if not bands or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and 0 < x <= 1
                                for x in bands) or len(set(bands)) < len(bands):
            raise SwarmtopoError(f"landmark_bands must be one or more distinct numbers in (0, 1], got {list(bands)}")
        if any(x < 1 for x in bands) and self.subsample != "maxmin":
            raise SwarmtopoError(f"landmark_bands below 1 draw maxmin landmarks from the middle of each window; "
                                 f"subsample {self.subsample!r} cannot, use maxmin")
        if self.window_step is not None and not (np.isfinite(self.window_step) and self.window_step > 0):
            raise SwarmtopoError(f"window_step must be a positive number of seconds, got {self.window_step}")
        if self.max_windows is not None and (isinstance(self.max_windows, bool) or
                                             not isinstance(self.max_windows, (int, np.integer)) or
                                             self.max_windows < len(scales)):
            raise SwarmtopoError(f"max_windows must be a whole number, at least the number of window scales "
                                 f"({len(scales)}: one window per length), or None; got {self.max_windows}")
        if self.maxdim not in (1, 2):
            raise SwarmtopoError(f"maxdim must be 1 or 2, got {self.maxdim}")
        if self.embed_dim not in (0, 2, 3):
            raise SwarmtopoError(f"embed_dim must be 0, 2 or 3, got {self.embed_dim}")
        if self.agreement not in AGREEMENT_MODES:
            raise SwarmtopoError(f"agreement must be one of {', '.join(AGREEMENT_MODES)}, got {self.agreement!r}")
        if self.window is not None:
            t0, t1 = self.window
            for end in (t0, t1):
                if end is not None and not np.isfinite(end):
                    raise SwarmtopoError(f"window ends must be finite numbers or None, got {end}")
            if t0 is not None and t1 is not None and t1 < t0:
                raise SwarmtopoError(f"window end {t1} is before its start {t0}")
        return self


@dataclass(eq=False)
class WindowMap:
    """One region's events in one time window [t0, t1]: landmarks and persistence."""

    t0: float
    t1: float
    n_events: int
    landmarks: Landmarks
    landmark_events: np.ndarray  # (L,) original log event index of each landmark
    scales: RegionScales
    persistence: PersistenceResult
    betti: dict[int, int] = field(default_factory=dict)  # this window's count, set by the vote
    band: float = 1.0  # the middle share of the window its landmarks were drawn from (MapConfig.landmark_bands)

    @property
    def diagram(self) -> Diagram:
        return self.persistence.diagram

    def to_json(self) -> dict[str, Any]:
        return {"t0": self.t0, "t1": self.t1, "band": self.band, "events": self.n_events,
                "landmarks": int(len(self.landmarks.nodes)),
                "cover_radius": float(self.scales.cover_radius), "knn_scale": float(self.scales.knn),
                "betti": {str(n): int(v) for n, v in self.betti.items()}}


@dataclass(eq=False)
class RegionMap:
    """One region: a connected component of the encounter graph with enough events.

    Its landmarks, diagram, loops and picture are those of its representative window
    ``windows[window]`` (the only one without windowing); ``betti`` is the vote.
    """

    component: int
    n_events: int
    n_agents: int
    landmarks: Landmarks
    landmark_events: np.ndarray  # (L,) original log event index of each landmark
    diagram: Diagram
    scales: RegionScales
    thresholds: dict[int, float]  # bar-length threshold per dimension n >= 1
    counted: dict[int, np.ndarray]  # indices of the counted bars of the diagram, per dimension n >= 1
    betti: dict[int, int]
    confidence: dict[int, float | None]  # P(betti[n] is right), n >= 1
    cycles: list[Cycle]  # a loop of landmarks round each counted H1 bar (empty if not asked)
    warnings: list[str]
    embedding: Embedding | None
    windows: list[WindowMap]
    window: int  # index of the representative window
    agreement: np.ndarray | None = None  # A_1 .. A_5 (swarmtopo.readers.agreement); None where not computed
    vetoed: tuple[int, ...] = ()  # ranks k (1-based, as A_k) whose pooled score passed, vetoed by agreement


@dataclass(eq=False)
class TopologicalMap:
    """The result of mapping an encounter log.

    ``betti[n]`` is the estimated n-th Betti number: beta_0 counts regions, beta_1
    holes (None for a dimension the classifier has no Theta_n for).
    ``confidence[n]`` is the probability that ``betti[n]`` is right: beta_0's from
    :mod:`swarmtopo.readers.beta0` (read from ``beta0_evidence``); beta_n for n >= 1 is a sum
    over regions, so its confidence is one region's, or for several the product of the
    regions' raised to a calibrated power (:func:`~swarmtopo.readers.ratio.map_confidence`; None
    without a calibrated classifier).
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
    hop_cost: tuple[float, str] = (0.0, "given")  # (h used, where it came from)
    diffusion_time: tuple[float, str] = (WHOLE_LOG, "given")  # (tau used, where it came from)
    window_length: tuple[float, str] = (WHOLE_LOG, "given")  # (window length used, where it came from)
    windows_left_out: int = 0  # windows the cap (MapConfig.max_windows) left unmapped
    software: dict[str, str] = field(default_factory=dict)
    log_warnings: list[str] = field(default_factory=list)  # about the mapped log as a whole
    beta0_evidence: Beta0Evidence | None = None  # what beta_0's confidence was read from
    contact_trace: bool = False  # the log has no status changes: its advice names plan --input contact-trace

    @property
    def warnings(self) -> list[str]:
        """Reasons to doubt the map: the log's, then every region's."""
        return self.log_warnings + [w for r in self.regions for w in r.warnings]

    def advice(self) -> list[str]:
        """What would raise a confidence below ``ADVICE_BELOW`` (empty otherwise)."""
        low = [n for n, p in sorted(self.confidence.items()) if p is not None and p < ADVICE_BELOW]
        if not low:
            return []
        lines = [f"beta_{n} = {self.betti[n]} is uncertain ({100 * self.confidence[n]:.0f}% confidence)" for n in low]
        evidence = self.beta0_evidence
        if 0 in low and evidence is not None:
            apart = (f"have stayed apart for only {evidence.settled:.3g} mean gaps between an agent's encounters since "
                     "they formed" if evidence.settled else "formed at the log's end (or no agent met twice)")
            lines.append(
                f"the {evidence.regions} regions {apart}; groups in one room merge when their agents meet, so only a "
                "longer log tells one room from several" if evidence.regions >= 2 else
                f"{100 * evidence.fragments:.0f}% of the events are in groups too small to map (too_little_data); "
                "a room only a few agents saw would hide there")
        for r in self.regions:
            counts = [w.betti.get(1) for w in r.windows]
            if len(set(counts)) > 1:
                lines.append(f"region {r.component}: its {len(counts)} time windows counted {counts} holes each")
            if 1 in low and below_full_resolution(diagrams := [w.diagram for w in r.windows]):
                lines.append(f"region {r.component}: its windows tell about {np.exp(resolution(diagrams)):.0f} places "
                             f"apart (landmarks; {RESOLUTION_CAP} at full resolution): with few places a hole can go "
                             "unseen in every window alike, so agreeing windows are no proof")
        length = self.window_length[0]
        more_time = ("" if self.windows_left_out else
                     f"record longer (each extra {self.config.window_step or length / 2:.3g} s adds a window to "
                     "the pooling), " if np.isfinite(length) else "record longer, ")
        how_much = ("'swarmtopo plan " + ("--input contact-trace " if self.contact_trace else "")
                    + "--area A --agents N --target 0.95' tells how much")
        lines.append(f"to raise it: {more_time}use more agents than {self.n_agents} (denser windows); {how_much}")
        return lines

    def to_json(self) -> dict[str, Any]:
        """The map.json document (deaths of infinite bars as null)."""
        return {
            "betti": {str(k): v for k, v in sorted(self.betti.items())},
            "confidence": {str(k): v for k, v in sorted(self.confidence.items())},
            "diagrams": self.diagram.to_json(),
            "classifier": self.classifier,
            "warnings": self.warnings,
            "advice": self.advice(),
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
                    "windows": [w.to_json() for w in r.windows],
                    "window": r.window,
                    "agreement": agreement_json(r.agreement),
                    "vetoed": list(r.vetoed),
                    "diagrams": r.diagram.to_json(),
                    "mds_stress": None if r.embedding is None else float(r.embedding.stress),
                    "warnings": r.warnings,
                }
                for r in self.regions
            ],
            "too_little_data": self.too_little_data,
            "beta0_evidence": None if self.beta0_evidence is None else {**self.beta0_evidence.to_json(),
                                                                          "definition": BETA0_DEFINITION},
            "params": {**jsonable(asdict(self.config)), "hop_cost_used": self.hop_cost[0],
                       "hop_cost_source": self.hop_cost[1],
                       "diffusion_time_used": self.diffusion_time[0] if np.isfinite(self.diffusion_time[0]) else None,
                       "diffusion_time_source": self.diffusion_time[1],
                       "window_length_used": self.window_length[0] if np.isfinite(self.window_length[0]) else None,
                       "window_source": self.window_length[1], "windows_left_out": self.windows_left_out},
            "log": {"events": self.n_events, "agents": self.n_agents, "contact_trace": self.contact_trace},
            "timings": {k: round(v, 6) for k, v in self.timings.items()},
            "software": {**self.software, "persistence_backend": self.diagram.backend},
        }


@dataclass(frozen=True)
class RegionSplit:
    """The mapped log's encounter graph cut into components, and which are regions
    (module docstring): what ``map_encounters`` maps and what beta_0 counts."""

    graph: EncounterGraph
    labels: np.ndarray  # component of each graph node
    event_comp: np.ndarray  # component of each mapped event
    events_per_comp: np.ndarray
    agents_per_comp: np.ndarray
    regions: list[int]  # the components that count as regions, most events first
    times: np.ndarray  # the mapped events' times, sorted
    agent_gap: float | None  # mean time between an agent's consecutive encounters
    hop_cost: tuple[float, str]  # (h, where it came from)
    diffusion_time: tuple[float, str]  # (tau, where it came from)
    beta0: Beta0Evidence


def split_regions(log: EncounterLog, config: MapConfig) -> RegionSplit:
    """Build the encounter graph of ``log`` (``config.window`` applied) and find its regions.

    Raises
    ------
    SwarmtopoError
        If there are fewer than 2 events, all at one instant, or no component is big
        enough to count as a region.
    """
    if log.n_events < 2:
        raise SwarmtopoError(
            f"the log has {log.n_events} event(s); at least 2 encounters are needed to build a map")
    mapped = log if config.window is None else log.window(*config.window)
    hop_cost = resolve_hop_cost(mapped, config.hop_cost)
    agent_gap = mean_agent_gap(mapped)
    diffusion_time = resolve_diffusion_time(agent_gap, config.diffusion_time)
    graph = build_graph(log, config.metric, window=config.window, hop_cost=hop_cost[0],
                        diffusion_time=diffusion_time[0], wall_follow_weight=config.wall_follow_weight)
    n_comp, labels = graph.components()
    event_comp = labels[graph.node_of_event]
    events_per_comp = np.bincount(event_comp, minlength=n_comp)
    agents_per_comp = _agents_per_component(log, graph.event_index, event_comp, n_comp)

    times = np.sort(graph.event_t)  # the mapped events' times, for the span, the windows and the silences
    if graph.n_events >= 2 and times[0] == times[-1]:
        raise SwarmtopoError(f"all {graph.n_events} encounters are at one time (t = {exact_time(times[0])} s); "
                             f"a map needs encounters spread over time")
    is_region = ((events_per_comp >= config.min_region_events) & (agents_per_comp >= MIN_REGION_AGENTS)
                 & (np.bincount(labels, minlength=n_comp) >= 2))  # one node: its encounters all at one instant
    regions = [int(c) for c in np.argsort(-events_per_comp, kind="stable") if is_region[c]]
    if not regions:
        largest = int(np.argmax(events_per_comp))
        if np.count_nonzero(labels == largest) == 1 and agents_per_comp[largest] >= MIN_REGION_AGENTS:
            raise SwarmtopoError(
                f"the largest connected group of encounters ({int(events_per_comp[largest])} events among "
                f"{int(agents_per_comp[largest])} agents) is a single point of the encounter metric: its agents never "
                f"moved between their encounters (static from the start, as meta.json 'static' says, or stopped), so "
                f"there is nothing to map")
        raise SwarmtopoError(
            f"no connected group of encounters has {config.min_region_events} events or more among "
            f"{MIN_REGION_AGENTS} agents or more (largest: {int(events_per_comp[largest])} events among "
            f"{int(agents_per_comp[largest])} agents, of {graph.n_events} events in {n_comp} groups); "
            f"the log is too short or the agents too few to map: collect more data")
    a, b = log.a[graph.event_index], log.b[graph.event_index]
    region_of_comp = np.full(n_comp, -1)
    region_of_comp[regions] = np.arange(len(regions))
    region_of_agent = np.full(log.n_agents, -1)
    region_of_agent[a] = region_of_agent[b] = region_of_comp[event_comp]  # an agent's events share a component
    evidence = beta0_evidence(a, b, graph.event_t, region_of_agent, len(regions),
                              int(events_per_comp[regions].sum()), agent_gap)
    return RegionSplit(graph, labels, event_comp, events_per_comp, agents_per_comp, regions, times, agent_gap,
                       hop_cost, diffusion_time, evidence)


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
        the shipped one for the log (:func:`shipped_classifier_for`).
    progress
        Optional callable receiving the name of each stage (``STAGES``) as it starts.

    Raises
    ------
    SwarmtopoError
        If the (windowed) log has too few events, or no component is big enough
        to count as a region.
    """
    config = (config or MapConfig()).validate()
    classifier = classifier or load_classifier(shipped_classifier_for(log))
    config = replace(config, landmark_bands=resolve_landmark_bands(config, classifier))
    beta0_model = shipped_beta0_model()
    rng = np.random.default_rng(config.seed)
    say = progress or (lambda stage: None)
    timings = dict.fromkeys(STAGES, 0.0)
    say("graph")
    t0 = time.perf_counter()
    split = split_regions(log, config)
    graph, labels, event_comp = split.graph, split.labels, split.event_comp
    events_per_comp, agents_per_comp, regions_idx = split.events_per_comp, split.agents_per_comp, split.regions
    hop_cost, hop_source = split.hop_cost
    diffusion_time, diffusion_source = split.diffusion_time
    agent_gap, times = split.agent_gap, split.times
    timings["graph"] = time.perf_counter() - t0

    shares = (_share_landmarks(config.landmarks, events_per_comp[regions_idx]) if config.landmarks
              else [None] * len(regions_idx))
    log_span = float(times[-1] - times[0])
    window_length, window_source = resolve_window(agent_gap, config.window_length, config.window_encounters, log_span)
    lengths = [resolve_window(agent_gap, None if config.window_length is None else scale * config.window_length,
                              scale * config.window_encounters, log_span)[0] for scale in config.window_scales]
    spans, left_out = _scaled_windows(times, lengths, config.window_step, config.max_windows,
                                      config.min_region_events)
    lengths_tried = sorted(length for length in lengths if length < log_span)  # the others map the whole log
    window_graphs = []  # (span, graph, component labels) of each window
    for span in spans:
        if span is None:  # the whole log: a scale whose windows would not be shorter than it
            window_graphs.append((None, graph, labels))
        else:
            wgraph = build_graph(log, config.metric, window=span, hop_cost=hop_cost,
                                 diffusion_time=diffusion_time, wall_follow_weight=config.wall_follow_weight)
            window_graphs.append((span, wgraph, wgraph.components()[1]))
    regions: list[RegionMap] = []
    gated = isinstance(classifier, RatioClassifier) and classifier.gated
    keep_graphs = gated or config.agreement == "always"  # A_k may be asked for: keep each window's graph
    for comp, n_land in zip(regions_idx, shares):
        region_events = graph.event_index[event_comp == comp]
        windows, parts = [], []  # the region's windows and (if kept) the graphs they were mapped on
        quiet = 0  # windows with a band left out (too few nodes in its middle share)
        for span, wgraph, wlabels in window_graphs:
            part = _region_part(wgraph, wlabels, region_events, log, config)
            if part is not None:
                knn_scale = _timed_knn_scale(part, config, timings)  # one per window, whatever its bands
                bands = usable_bands(part, span, config.landmark_bands)
                quiet += len(bands) < len(config.landmark_bands)
                for band in bands:
                    windows.append(_map_window(span, part, knn_scale, n_land, config, rng, timings, say, band))
                    parts.append(part if keep_graphs else None)
        fallback = []
        if not windows:  # no window holds enough of this region: map its whole log instead
            whole = graph.subgraph(np.flatnonzero(labels == comp))
            knn_scale = _timed_knn_scale(whole, config, timings)
            bands = usable_bands(whole, None, config.landmark_bands)
            quiet = int(len(bands) < len(config.landmark_bands))
            windows = [_map_window(None, whole, knn_scale, n_land, config, rng, timings, say, band)
                       for band in bands]
            parts = [whole] * len(windows)
            if lengths_tried:
                lo, hi = lengths_tried[0], lengths_tried[-1]
                tried = f"{lo:.3g}" if lo == hi else f"{lo:.3g}-{hi:.3g}"
                fallback = [f"no window ({tried} s long) holds {config.min_region_events} encounters of this region "
                            f"among {MIN_REGION_AGENTS} agents: its whole log was mapped instead"]
        if quiet:
            fallback.append(f"windows of this region with fewer than {MIN_LANDMARKS} encounters in the middle share "
                            f"of their time span a landmark band draws from (a quiet stretch of the log): {quiet}; "
                            f"they were mapped without that band")
        diagrams = [w.diagram for w in windows]
        agreement = None
        if config.agreement == "always" or (gated and classifier.needs_agreement(diagrams)):
            say("agreement")
            t0 = time.perf_counter()
            spans = [(w.t0, w.t1) for w in windows]
            first_band = [i for i, span in enumerate(spans) if span not in spans[:i]]  # one map per window
            agreement = region_agreement([windows[i] for i in first_band], [parts[i] for i in first_band])
            timings["agreement"] += time.perf_counter() - t0
        del parts
        say("classify")
        t0 = time.perf_counter()
        region_classifier = region_reader(classifier, diagrams, agreement)
        voted = vote(region_classifier, diagrams, [w.n_events for w in windows])
        betti_region, rep, counts = voted
        for w, *window_counts in zip(windows, *counts.values()):
            w.betti = dict(zip(counts, window_counts))
        chosen = windows[rep]
        confidence_region = region_classifier.region_confidence(diagrams, voted)
        sampling = _sampling_warnings(chosen.scales, len(chosen.landmarks.nodes), config)
        if sampling:  # calibrated with the automatic landmark count only: no number to give
            confidence_region = dict.fromkeys(confidence_region)
        counted = {n: (region_classifier.counted_bars(chosen.diagram, n, count) if gated
                       else longest_bars(chosen.diagram, n, count)) for n, count in betti_region.items()}
        thresholds = classifier.length_thresholds(chosen.diagram)
        vetoed = tuple(k + 1 for k in region_classifier.vetoed_.get(1, ())) if gated else ()
        veto_note = [_veto_warning(vetoed, agreement, classifier.thresholds_[1].agreement)] if vetoed else []
        timings["classify"] += time.perf_counter() - t0
        say("embedding")
        t0 = time.perf_counter()
        emb = (mds(chosen.landmarks.distances, dim=config.embed_dim, rng=rng)
               if config.embed_dim and len(chosen.landmarks.nodes) > config.embed_dim else None)
        timings["embedding"] += time.perf_counter() - t0
        regions.append(RegionMap(
            component=comp,
            n_events=int(events_per_comp[comp]),
            n_agents=int(agents_per_comp[comp]),
            landmarks=chosen.landmarks,
            landmark_events=chosen.landmark_events,
            diagram=chosen.diagram,
            scales=chosen.scales,
            thresholds=thresholds,
            counted=counted,
            betti=betti_region,
            confidence=confidence_region,
            cycles=[],
            warnings=fallback + sampling + veto_note,
            embedding=emb,
            windows=windows,
            window=rep,
            agreement=agreement,
            vetoed=vetoed,
        ))
        if config.cycles:
            say("cycles")
            t0 = time.perf_counter()
            # the cocycles the loops are found from: the same diagram, from the backend that keeps them
            chosen.persistence = rips_persistence(chosen.landmarks.distances, maxdim=config.maxdim, cocycles=True)
            regions[-1].diagram = chosen.diagram
            regions[-1].cycles = region_cycles(regions[-1], chosen.persistence)
            timings["cycles"] += time.perf_counter() - t0
    betti: dict[int, int | None] = {0: len(regions)}
    confidence: dict[int, float | None] = {0: beta0_model.confidence(split.beta0)}
    for n in range(1, config.maxdim + 1):
        known = all(n in r.betti for r in regions)
        betti[n] = sum(r.betti[n] for r in regions) if known else None
        confidence[n] = map_confidence(classifier, [r.confidence.get(n) for r in regions], n) if known else None
    too_little = [{"component": int(c), "events": int(events_per_comp[c]), "agents": int(agents_per_comp[c])}
                  for c in np.setdiff1d(np.arange(len(events_per_comp)), regions_idx)]
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
        hop_cost=(hop_cost, hop_source),
        diffusion_time=(diffusion_time, diffusion_source),
        window_length=(window_length, window_source),
        windows_left_out=left_out,
        log_warnings=_silence_warnings(times, window_length) + _extrapolation_warnings(betti),
        beta0_evidence=split.beta0,
        contact_trace=shipped_classifier_for(log) == "trace",
        software=software_versions(),
    )


def _veto_warning(vetoed: tuple[int, ...], agreement: np.ndarray, b: float) -> str:
    """The region warning naming the ranks k (1-based) its agreement A_k <= b vetoed."""
    values = ", ".join(f"{agreement[k - 1]:.2f}" for k in vetoed)
    return (f"{len(vetoed)} loop(s) whose pooled score passed were not counted: not the same loop in the "
            f"overlapping windows (A_k = {values} for rank(s) {', '.join(map(str, vetoed))}, at most b = {b:g}); "
            "agents that follow walls for long leave such loops")


def _timed_knn_scale(sub: EncounterGraph, config: MapConfig, timings: dict[str, float]) -> float:
    """The window's k-NN scale s (:func:`_knn_scale`), its time counted in the landmarks stage."""
    t0 = time.perf_counter()
    knn_scale = _knn_scale(sub, config.knn_k)
    timings["landmarks"] += time.perf_counter() - t0
    return knn_scale


def _map_window(span, sub: EncounterGraph, knn_scale: float, n_land: int | None, config: MapConfig, rng,
                timings: dict[str, float], say, band: float = 1.0) -> WindowMap:
    """Landmarks and persistence of one region's events in one time window (span None: all),
    the landmarks drawn among the nodes of the window's middle ``band`` share; ``knn_scale``
    is the window's s (:func:`_timed_knn_scale`, shared by its bands)."""
    say("landmarks")
    t0 = time.perf_counter()
    t_lo, t_hi = (float(sub.event_t.min()), float(sub.event_t.max())) if span is None else span
    candidates = None if band == 1 else in_band(sub.node_times(), (t_lo, t_hi), band)
    if n_land is None:  # as many as cover the window to AUTO_COVER_FACTOR s, at most max_landmarks
        land = _subsample(sub, config, min(config.max_landmarks, sub.n_nodes), rng, candidates,
                          cover=AUTO_COVER_FACTOR * knn_scale)
    else:
        land = _subsample(sub, config, int(min(n_land, sub.n_nodes)), rng, candidates)
    timings["landmarks"] += time.perf_counter() - t0
    say("persistence")
    t0 = time.perf_counter()
    # the fastest backend; the window the loops are drawn from is run again with cocycles
    persistence = rips_persistence(land.distances, maxdim=config.maxdim)
    timings["persistence"] += time.perf_counter() - t0
    return WindowMap(t0=t_lo, t1=t_hi, n_events=sub.n_events, landmarks=land,
                     landmark_events=sub.representative_event()[land.nodes],
                     scales=RegionScales(knn=knn_scale, cover_radius=float(land.cover_radius)),
                     persistence=persistence, band=float(band))


def usable_bands(sub: EncounterGraph, span: tuple[float, float] | None, bands: tuple[float, ...]) -> list[float]:
    """The landmark ``bands`` a window can be mapped with: those whose middle share of the
    window's span (None: its events' first to last time) holds at least ``MIN_LANDMARKS``
    nodes -- a quiet stretch of the log can leave it (nearly) empty; whole-window
    landmarks (band 1) if none does."""
    t_lo, t_hi = (float(sub.event_t.min()), float(sub.event_t.max())) if span is None else span
    times = sub.node_times()
    usable = [band for band in bands
              if band == 1 or np.count_nonzero(in_band(times, (t_lo, t_hi), band)) >= MIN_LANDMARKS]
    return usable or [1.0]


def in_band(times: np.ndarray, span: tuple[float, float], band: float) -> np.ndarray:
    """Whether each time lies in the middle ``band`` share of ``span`` = (t0, t1), ends included."""
    t0, t1 = span
    margin = (1 - band) / 2 * (t1 - t0)
    return (times >= t0 + margin) & (times <= t1 - margin)


def region_agreement(windows: list[WindowMap], graphs: list[EncounterGraph]) -> np.ndarray:
    """A_1 .. A_5 of a region from its windows and the graphs they were mapped on (:mod:`swarmtopo.readers.agreement`);
    only windows that overlap another get coordinates."""
    spans = [(w.t0, w.t1) for w in windows]
    coordinates = [window_coordinates(w.landmarks.distances, w.diagram, w.landmarks.nodes, g)
                   if overlapping(spans, i) else None for i, (w, g) in enumerate(zip(windows, graphs))]
    return rank_agreement(coordinates, spans)


def agreement_json(agreement: np.ndarray | None) -> list[float | None] | None:
    """A_k as JSON: null where undefined (no two windows overlap), the whole list null if not computed."""
    return None if agreement is None else [None if np.isnan(a) else float(a) for a in agreement]


def shipped_classifier_for(log: EncounterLog) -> str:
    """The shipped classifier ``map`` reads a log with: "default", fitted on logs with
    status changes, or "trace" for a log without any (a contact trace: no wall following
    to weigh), fitted on the same tuning cases read as encounters only."""
    return "default" if len(log.status_t) else "trace"


def fitted_landmark_bands(classifier: BettiClassifier | RatioClassifier) -> tuple[float, ...]:
    """The landmark bands (``MapConfig.landmark_bands``) a classifier was fitted with: its
    provenance's ``pipeline.landmark_bands``, (1,) when it names none."""
    pipeline = getattr(classifier, "provenance_", {}).get("pipeline") or {}
    return tuple(float(b) for b in pipeline.get("landmark_bands", (1.0,)))


def resolve_landmark_bands(config: MapConfig, classifier: BettiClassifier | RatioClassifier) -> tuple[float, ...]:
    """The landmark bands a map uses: ``config.landmark_bands``, or when unset, with maxmin
    the bands ``classifier`` was fitted with (:func:`fitted_landmark_bands`), else (1,)."""
    if config.landmark_bands is not None:
        return config.landmark_bands
    return fitted_landmark_bands(classifier) if config.subsample == "maxmin" else (1.0,)


def resolve_hop_cost(log: EncounterLog, hop_cost: float | None) -> tuple[float, str]:
    """(h, where it came from): the given value, else r_d / v_c from the log's meta.json,
    else HOP_GAP_FACTOR x the mean time between an agent's consecutive encounters."""
    if hop_cost is not None:
        return float(hop_cost), "given"
    r_d, v_c = log.meta.get("r_d"), log.meta.get("v_c")
    if all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) and x > 0 for x in (r_d, v_c)):
        h = float(r_d) / float(v_c)
        if not h <= MAX_HOP_COST:  # inf too; no file named: the caller knows the log's folder
            raise InputError(f"meta.json: r_d = {r_d:g} and v_c = {v_c:g} give a per-hop cost r_d / v_c of {h:.3g} s, "
                             f"more than {MAX_HOP_COST:g} s (the bound of --hop-cost): r_d must be in mm, v_c in mm/s")
        return h, "r_d / v_c from meta.json"
    gap = mean_agent_gap(log)
    if gap is None:
        return 0.0, "no agent met twice at different times: 0"
    return HOP_GAP_FACTOR * gap, f"{HOP_GAP_FACTOR:g} x mean time between an agent's encounters"


def resolve_diffusion_time(gap: float | None, diffusion_time: float | None) -> tuple[float, str]:
    """(tau used, where it came from): the given value, else ``DIFFUSION_GAP_FACTOR`` x
    ``gap``, the mean time between an agent's consecutive encounters in the mapped events
    (:func:`mean_agent_gap`); inf (the paper's weights) when no agent met twice at
    different times (``gap`` None)."""
    if diffusion_time is not None:
        return float(diffusion_time), "given"
    if gap is None:
        return WHOLE_LOG, "no agent met twice at different times: none"
    return DIFFUSION_GAP_FACTOR * gap, f"{DIFFUSION_GAP_FACTOR:g} x mean time between an agent's encounters"


def resolve_window(gap: float | None, window_length: float | None, encounters: float,
                   span: float) -> tuple[float, str]:
    """(window length W used, where it came from): the given length, else W = K x ``gap``,
    the mean time between an agent's consecutive encounters in the mapped events
    (:func:`mean_agent_gap`; K = ``encounters``), so a window holds about K encounters per
    agent; ``WHOLE_LOG`` when W is not shorter than ``span``, the seconds the mapped
    events cover, or when no agent met twice at different times (``gap`` None)."""
    if window_length is not None:
        return (float(window_length) if window_length < span else WHOLE_LOG), "given"
    if gap is None:
        return WHOLE_LOG, "no agent met twice at different times: the whole log"
    length = encounters * gap
    source = f"{encounters:g} x mean time between an agent's encounters"
    return (length, source) if length < span else (WHOLE_LOG, source + " (longer than the log: the whole log)")


def mean_agent_gap(log: EncounterLog) -> float | None:
    """Mean time between an agent's consecutive encounters at different times (None: none)."""
    gaps = agent_gaps(log)
    gaps = gaps[gaps > 0]
    return float(gaps.mean()) if len(gaps) else None


def _windows(event_t: np.ndarray, length: float, step: float | None = None) -> list[tuple[float, float] | None]:
    """Time windows of ``length`` s over [t_first, t_last], starts at most ``step`` apart
    (default length / 2): 1 + ceil((span - length) / step) of them, evenly spaced from
    the first event to the last; [None] (the whole log) when the span is not longer
    than one window."""
    t_first, t_last = float(event_t.min()), float(event_t.max())
    if t_last - t_first <= length:
        return [None]
    step = length / 2 if step is None else step
    count = 1 + np.ceil((t_last - t_first - length) / step - 1e-9)  # a float: inf for a length of 1e-320 s
    if count > MAX_WINDOWS_LISTED:
        raise SwarmtopoError(f"windows of {length:.3g} s every {step:.3g} s over the log's {t_last - t_first:.6g} s "
                             f"would be {f'{int(count):,}' if count < 1e12 else f'{count:.3g}'}, "
                             f"more than {MAX_WINDOWS_LISTED:,}: use longer windows")
    n = int(count)
    return [(float(s), float(s) + length) for s in np.linspace(t_first, t_last - length, n)]


def _scaled_windows(times: np.ndarray, lengths, step: float | None = None, cap: int | None = None,
                    min_events: int = 0) -> tuple[list[tuple[float, float] | None], int]:
    """The distinct windows of every length in ``lengths`` (:func:`_windows`) over the
    sorted event ``times`` that hold at least ``min_events`` events (a gap in a real trace
    is skipped), in order: by length as given, then by start; and how many the cap left out.

    With more than ``cap`` distinct windows, each length keeps a share of its windows
    in proportion to their number, at least one (largest remainders, so the shares sum
    to ``cap``; ``MapConfig.validate`` asks for at least one per length), evenly spaced
    from its first window to its last (one window: the middle one)."""
    seen: set = set()
    per_length = []

    def enough(span) -> bool:
        return span is None or (np.searchsorted(times, span[1], side="right")
                                - np.searchsorted(times, span[0], side="left")) >= min_events

    for length in lengths:
        spans = [span for span in _windows(times, length, step) if span not in seen and enough(span)]
        seen.update(spans)
        per_length.append(spans)
    sizes = np.array([len(spans) for spans in per_length])
    total = int(sizes.sum())
    if cap is None or total <= cap:
        return [span for spans in per_length for span in spans], 0
    keep = _shares(sizes, cap)
    kept = [[spans[i] for i in _evenly(len(spans), k)] for spans, k in zip(per_length, keep)]
    return [span for spans in kept for span in spans], total - int(keep.sum())


def _shares(sizes: np.ndarray, cap: int) -> np.ndarray:
    """How many of ``sizes[i]`` items each group keeps, ``cap`` in all (``cap`` <
    sizes.sum()): proportional shares, at least one per non-empty group, the seats left
    after the floors going to the largest remainders."""
    if cap < np.count_nonzero(sizes):
        raise SwarmtopoError(f"a cap of {cap} windows cannot keep one of each of {np.count_nonzero(sizes)} lengths")
    quota = cap * sizes / sizes.sum()  # each below its size, as cap < sizes.sum()
    keep = np.maximum(np.floor(quota).astype(int), sizes > 0)
    while keep.sum() > cap:  # the minimum of one pushed the floors over the cap
        keep[np.argmax(np.where(keep > 1, keep - quota, -np.inf))] -= 1
    # under the cap only if nothing was taken back: every remainder < 1, so each seat
    # goes to a different group and none passes its size
    keep[np.argsort(-(quota - keep), kind="stable")[:cap - keep.sum()]] += 1
    return keep


def _evenly(n: int, k: int) -> np.ndarray:
    """k of the indices 0 .. n-1, evenly spaced from the first to the last (k = 1: the middle one)."""
    if k == 1:
        return np.array([(n - 1) // 2])
    return np.unique(np.linspace(0, n - 1, k).round().astype(int))


def _silence_warnings(times: np.ndarray, window_length: float) -> list[str]:
    """A silence between the sorted event ``times`` longer than a window (a night in a
    multi-day trace): it stretches the mean gap the automatic h, windows and diffusion
    time come from.  When the window is the whole log (which such a silence may have
    stretched it to), one longer than the rest of the log together."""
    gaps = np.diff(times)
    if not len(gaps):
        return []
    k = int(np.argmax(gaps))
    if np.isfinite(window_length):
        limit, what = window_length, "a window"
    else:
        limit, what = float(times[-1] - times[0] - gaps[k]), "the rest of the log"
    if gaps[k] <= limit:
        return []
    return [f"the log is silent for {gaps[k]:.6g} s (t = {exact_time(times[k])} to {exact_time(times[k + 1])}), "
            f"longer than {what} ({limit:.3g} s): silences such as nights inflate the automatic per-hop "
            f"cost and windows; map each active period with --window T0:T1"]


def _region_part(graph: EncounterGraph, labels: np.ndarray, region_events: np.ndarray, log: EncounterLog,
                 config: MapConfig) -> EncounterGraph | None:
    """The largest component of ``graph`` among the region's events, if it is big enough
    to map (``min_region_events`` events, ``MIN_REGION_AGENTS`` agents); else None."""
    inside = np.isin(graph.event_index, region_events)
    if not inside.any():
        return None
    comps, sizes = np.unique(labels[graph.node_of_event[inside]], return_counts=True)
    comp = comps[np.argmax(sizes)]
    if sizes.max() < config.min_region_events:
        return None
    sub = graph.subgraph(np.flatnonzero(labels == comp))
    agents = np.unique(np.concatenate([log.a[sub.event_index], log.b[sub.event_index]]))
    return sub if len(agents) >= MIN_REGION_AGENTS and sub.n_nodes >= 2 else None


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
    nearest other nodes (see :mod:`swarmtopo.readers.paper`)."""
    k = min(k, graph.n_nodes - 1)
    distinct = replace(graph, multiplicity=np.ones_like(graph.multiplicity))
    return float(np.median(knn_distances(distinct, k).mean(axis=1)))


def _extrapolation_warnings(betti: dict[int, int | None]) -> list[str]:
    """A hole count beyond the arenas the confidence was calibrated on."""
    if (betti.get(1) or 0) > CALIBRATED_HOLES:
        return [f"beta_1 = {betti[1]} is beyond the 0-{CALIBRATED_HOLES} holes of the arenas its confidence was "
                "calibrated on (docs/accuracy.md): the confidence is extrapolated, and many holes in one arena "
                "leave narrow passages between them, where holes merge or go unseen"]
    return []


def _sampling_warnings(scales: RegionScales, n_landmarks: int, config: MapConfig) -> list[str]:
    """Why a region's answer may be unreliable (empty when it is not).

    A landmark count the user fixed is checked against the sampling guarantee; the
    automatic count's cap is the benchmarked setting (its accuracy is measured with
    the cap in force), so reaching it is not a warning.
    """
    if config.landmarks and scales.cover_radius > AUTO_COVER_FACTOR * scales.knn:
        return [f"landmarks too sparse: {n_landmarks} landmarks leave a covering radius of "
                f"{scales.cover_radius:.3g} s, over {AUTO_COVER_FACTOR:g} x the cloud's k-NN scale "
                f"{scales.knn:.3g} s, so subsampling noise can pass the threshold; use more landmarks (no beta_1 "
                "confidence is given: it was calibrated with the automatic landmark count)"]
    return []


def _subsample(graph: EncounterGraph, config: MapConfig, n_landmarks: int, rng,
               candidates: np.ndarray | None = None, cover: float | None = None) -> Landmarks:
    """Landmarks by ``config.subsample``; ``candidates`` (maxmin only, as validated) restricts
    the picks; ``cover`` stops them once they cover within it (``landmarks.maxmin``)."""
    if config.subsample == "knn":
        return knn_maxmin(graph, n_landmarks, k=config.knn_k, q=config.knn_q, rng=rng, cover=cover)
    if config.subsample == "probabilistic":
        return probabilistic_maxmin(graph, n_landmarks, k=config.knn_k, omega=config.omega, rng=rng, cover=cover)
    return maxmin(graph, n_landmarks, rng=rng, candidates=candidates, cover=cover)


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
