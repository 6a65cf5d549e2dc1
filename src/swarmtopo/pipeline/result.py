"""What a map is: :class:`TopologicalMap`, its regions and their windows (data only).

Its JSON document (map.json) and its advice to the user are written at the edges
(:mod:`swarmtopo.viz.summary`).
"""

from __future__ import annotations

import platform
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import __version__
from ..metric.landmarks import Landmarks
from ..readers.beta0 import Beta0Evidence
from ..topology.cycles import Cycle
from ..topology.embed import Embedding
from ..topology.persistence import Diagram, PersistenceResult
from .config import WHOLE_LOG, MapConfig
from .faults import FaultScreen
from .motion import MotionEstimate


@dataclass(frozen=True)
class RegionScales:
    """Scales of one window's event cloud, in the metric's unit (seconds).

    knn
        s: median over distinct events of the mean distance to their k nearest others.
    cover_radius
        r_cover of the landmark set.
    """

    knn: float
    cover_radius: float


@dataclass(eq=False)
class WindowMap:
    """One region's events in one time window [t0, t1], mapped with the landmarks of one band."""

    t0: float
    t1: float
    n_events: int
    landmarks: Landmarks
    landmark_events: np.ndarray  # (L,) original log event index of each landmark
    scales: RegionScales
    persistence: PersistenceResult
    band: float = 1.0  # the middle share of the window its landmarks were drawn from
    betti: dict[int, int] = field(default_factory=dict)  # this window's own count

    @property
    def diagram(self) -> Diagram:
        return self.persistence.diagram


@dataclass(eq=False)
class RegionMap:
    """One region: a connected component of the encounter graph with enough events.

    Its landmarks, diagram, loops and picture are those of its representative window
    ``windows[window]``; ``betti`` is the reader's pooled count over all its windows.
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


@dataclass
class TimelineWindow:
    """One sliding window [t0, t1]: its Betti numbers, their confidence, and its
    longest H1 bars divided by its regions' median H1 bar length (scale-free, for the
    CROCKER picture)."""

    t0: float
    t1: float
    n_events: int
    betti: dict[int, int]
    confidence: dict[int, float | None]
    h1_scaled: np.ndarray = field(default_factory=lambda: np.empty(0))
    region_agents: list[np.ndarray] = field(default_factory=list)  # the agents of each of its regions

    @property
    def t(self) -> float:
        """The window's middle."""
        return (self.t0 + self.t1) / 2


@dataclass(frozen=True)
class Segment:
    """A stretch of time over which dimension ``dim``'s count is ``value``."""

    dim: int
    value: int
    t_from: float
    t_until: float
    confidence: float | None
    windows: int  # timeline windows in it


@dataclass(frozen=True)
class ChangePoint:
    """beta_dim changes from ``before`` to ``after`` at about ``t``, within [lo, hi]."""

    dim: int
    t: float
    before: int
    after: int
    lo: float
    hi: float
    confidence: float | None


@dataclass
class Timeline:
    """The map's Betti numbers over time (module docstring)."""

    length: float
    step: float
    windows: list[TimelineWindow]
    segments: dict[int, list[Segment]]
    changes: list[ChangePoint]
    note: str | None = None  # why there are no windows, when there are none

    def table(self) -> dict[str, np.ndarray]:
        """The windows as columns (``pandas.DataFrame(timeline.table())``): t0, t1, t,
        n_events, beta_n and confidence_n per dimension."""
        dims = sorted({n for w in self.windows for n in w.betti} | set(self.segments))
        cols: dict[str, np.ndarray] = {
            "t0": np.array([w.t0 for w in self.windows]), "t1": np.array([w.t1 for w in self.windows]),
            "t": np.array([w.t for w in self.windows]),
            "n_events": np.array([w.n_events for w in self.windows], dtype=np.int64)}
        for n in dims:
            cols[f"beta_{n}"] = np.array([w.betti.get(n, -1) for w in self.windows], dtype=np.int64)
            cols[f"confidence_{n}"] = np.array([np.nan if w.confidence.get(n) is None else w.confidence[n]
                                                for w in self.windows])
        return cols

    def summary(self) -> str:
        """One line: "no change ..." or, per changing dimension, "beta_1 = 1 until about 140 s, then 2"."""
        if not self.changes:
            span = f" over {self.windows[0].t0:.4g}-{self.windows[-1].t1:.4g} s" if self.windows else ""
            return f"no change of the Betti numbers{span} ({len(self.windows)} time windows)"
        parts = []
        for n in sorted({c.dim for c in self.changes}):
            segs = self.segments[n]
            text = f"beta_{n} = {segs[0].value}"
            for seg, change in zip(segs[1:], [c for c in self.changes if c.dim == n]):
                text += f" until about {change.t:.0f} s, then {seg.value}"
            parts.append(text)
        return "; ".join(parts)


@dataclass(frozen=True)
class ExploredHole:
    """A hole of the global map of a beacon-led log (:mod:`.exploration`): in the swarm's
    view from ``t_in`` to ``t_out`` (s); its position (mm) estimated from where the leader
    was meanwhile, within ``radius`` mm; ``open`` when it was already in view at the first
    window or still in view at the last (its position is then less sure)."""

    x: float
    y: float
    radius: float
    t_in: float
    t_out: float
    windows: int
    open: bool = False


@dataclass(eq=False)
class Exploration:
    """The global map of a log with a leader's track (:mod:`.exploration`).

    ``betti`` are the global counts: beta_0 the map's regions, beta_1 the holes seen
    along the way, each counted once (``holes``).  ``windows`` are the local maps (the
    timeline's windows) with the leader's position at their middle; ``coverage`` is the
    area (mm^2) within the leash of the leader's path, the swarm's reach.
    """

    leash: float
    leader_speed: float  # mm/s, mean while moving
    length: float  # s, each local map's window
    step: float
    betti: dict[int, int | None]  # beta_1 None: too few local maps for a global count
    holes: list[ExploredHole]
    windows: list[TimelineWindow]
    leader_xy: np.ndarray  # (K, 2) the leader at the middle of each window
    coverage: float
    warnings: list[str]

    def summary(self) -> str:
        """One line: the global counts and where the holes are."""
        if self.betti[1] is None:
            return f"no global map: {len(self.windows)} local maps along the leader's path are too few"
        where = "; ".join(f"({h.x:.0f}, {h.y:.0f}) mm +- {h.radius:.0f}" for h in self.holes)
        return (f"global map along the leader's path: beta_0 = {self.betti[0]}, beta_1 = {self.betti[1]}"
                + (f"; holes at {where}" if where else "") + f" ({len(self.windows)} local maps)")


@dataclass(eq=False)
class TopologicalMap:
    """The result of mapping an encounter log.

    ``betti[n]`` is the estimated n-th Betti number: beta_0 counts regions, beta_1
    holes (None for a dimension the reader has no threshold for).  ``confidence[n]`` is
    the probability that ``betti[n]`` is right: beta_0's from :mod:`swarmtopo.readers.beta0`
    (read from ``beta0_evidence``); for n >= 1 one region's, or for several the reader's
    combination of the regions' (:meth:`~swarmtopo.readers.base.BettiReader.map_confidence`).
    ``diagram`` is the union of the regions' diagrams.
    """

    betti: dict[int, int | None]
    confidence: dict[int, float | None]
    diagram: Diagram
    regions: list[RegionMap]
    too_little_data: list[dict[str, int]]
    classifier: dict[str, Any]
    config: MapConfig
    timings: dict[str, float]  # seconds per stage; landmarks and persistence summed over the window tasks
    n_events: int
    n_agents: int
    hop_cost: tuple[float, str] = (0.0, "given")  # (h used, where it came from)
    diffusion_time: tuple[float, str] = (WHOLE_LOG, "given")  # (tau used, where it came from)
    window_length: tuple[float, str] = (WHOLE_LOG, "given")  # (window length used, where it came from)
    windows_left_out: int = 0  # windows the cap (MapConfig.max_windows) left unmapped
    software: dict[str, str] = field(default_factory=dict)
    log_warnings: list[str] = field(default_factory=list)  # about the mapped log as a whole
    beta0_evidence: Beta0Evidence | None = None  # what beta_0's confidence was read from
    contact_trace: bool = False  # the log has no status changes: a contact trace
    timeline: Timeline | None = None  # Betti numbers over sliding windows, change points (pipeline.timeline)
    exploration: Exploration | None = None  # the global map of a beacon-led log (pipeline.exploration)
    motion: MotionEstimate | None = None  # what the encounters say about the agents' motion (pipeline.motion)
    sensing: FaultScreen | None = None  # what the encounters say about faulty sensing (pipeline.faults)

    @property
    def warnings(self) -> list[str]:
        """Reasons to doubt the map: the log's, then every region's."""
        return self.log_warnings + [w for r in self.regions for w in r.warnings]


def software_versions() -> dict[str, str]:
    """Versions of swarmtopo and the libraries whose numbers it reports."""
    import gudhi
    import ripser
    import scipy
    import sklearn

    return {
        "swarmtopo": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "gudhi": gudhi.__version__,
        "ripser": ripser.__version__,
        "scikit-learn": sklearn.__version__,
    }
