"""The paper's experiments reproduced with the package's own pipeline (``swarmtopo reproduce``).

``enc``
    Agents on a thin ring: their encounter point cloud is a cylinder S^1 x time
    (paper, Fig. "enc").  Checked with numbers, not only looked at: beta_1; in the
    metric, distance grows with the time gap at one place and with the way round the
    ring at one time (:func:`cylinder_checks`); in the MDS picture, the loop goes round
    as the true ring does (:func:`ring_concordance`).
``encmds``
    One-hole square, 200 agents, 20 s, the plain encounter metric: MDS picture coloured
    by time and diagram (Fig. "encmds"); over many seeds, how often beta_1 = 1.
``encimpr``
    The same over 200 s: plain vs contracted vs hybrid metric (5 % static agents)
    (Fig. "encImpr"); also over the first 20 s of the same runs.
``land2``
    Maxmin vs KNN-filtered maxmin vs probabilistic maxmin, 150 landmarks, q = 0.9,
    k = 10, on one cloud (the encmds scenario, contracted metric): SNR of dgm_1 over
    independent subsamplings (Fig. "land2").

Each experiment writes into ``out``: PNG figures, ``NAME.csv`` (one row per run),
``NAME.md`` (the summary table) and ``NAME.json`` (summary, settings, software).

Settings the paper leaves open are fixed here once for all four experiments (module
constants; docs/reproduction.md says why): the 500 mm square with one centred 150 mm
square hole (:func:`swarmtopo.arena.default_arena`), 200 agents in it (the same density
of agents per mm^2 of free space elsewhere), the paper's motion parameters, r_d = 30 mm,
dt = 0.1 s, the paper's pipeline (no per-hop cost, the whole log at once, the paper's
classifier form trained our way: the ``paper`` preset) and the pipeline's
defaults for everything else (maxmin, the automatic landmark count capped at 400,
landmark and MDS seed 0).

Seeds: run i of experiment NAME simulates with :func:`run_seed` (NAME, i), so a run
with ``runs=n`` is the first n runs of the full experiment, and every CSV row names
its seed (``simulate(arena, agents, duration, rng=seed)`` reruns it).
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any, Callable

import numpy as np
from scipy.stats import spearmanr

from .._validate import positive_int
from ..arena import Arena, annulus_arena, default_arena
from ..readers.registry import load_classifier
from ..topology.cycles import event_positions
from ..topology.embed import mds
from ..errors import InputError, SwarmtopoError
from ..metric.graph import build_graph
from ..metric.landmarks import knn_maxmin, maxmin, probabilistic_maxmin
from ..topology.persistence import Diagram, rips_persistence, snr
from ..pipeline import MapConfig, TopologicalMap, map_encounters
from ..pipeline.config import WHOLE_LOG
from ..pipeline.result import software_versions
from ..sim import simulate
from .clust import reproduce_clust
from .reproduction import Reproduction, output_folder, write_reproduction

PAPER_CLASSIFIER = "paper"
"""The reproductions read Betti numbers with the paper's classifier form, trained our way."""

Progress = Callable[[int, int, int], None]
"""Called as ``progress(done, total, failed)`` after every unit of work (as sweeps do)."""

AGENTS = 200
"""Swarm size in the one-hole square (paper: 200)."""
DURATION = 20.0
"""Seconds of data of enc, encmds and land2 (paper: 20 s for encmds)."""
LONG_DURATION = 200.0
"""Seconds of data of encimpr (paper: 200 s)."""
STATIC_FRACTION = 0.05
"""Share of static agents of the hybrid network (paper: 5 %)."""
STATIC_TIME = 0.0
"""When the static agents stop, s.  Agents start uniformly spread over the arena, so
they are "dispersed enough" (paper) from the start."""
RING_RADII = (200.0, 140.0)
"""Outer and inner radius of enc's ring, mm: 60 mm = 2 r_d wide, 200 mm outer radius
(the scale of the 500 mm square)."""
TRUE_BETA1 = 1
"""Holes of every arena here (the ring and the one-hole square)."""
LAND2_LANDMARKS = 150
KNN_K = 10
KNN_Q = 0.9
OMEGA = 1.0
"""land2's subsampler parameters (paper: 150 landmarks, k = 10, q = 0.9; omega is the
project's unit-free weight, :func:`swarmtopo.metric.landmarks.probabilistic_maxmin`)."""
DEFAULT_RUNS = {"enc": 50, "encmds": 50, "encimpr": 10, "land2": 100}
"""Runs (seeds, or subsamplings for land2) of the full experiments (land2: paper's 100)."""
SAME_PLACE_MM = 30.0
LONG_GAP_S = 10.0
FAR_MM = 200.0
SAME_TIME_S = 5.0
"""Pair classes of the ground-truth checks: same place = true positions at most
SAME_PLACE_MM apart, far = at least FAR_MM apart, same time = at most SAME_TIME_S apart,
long gap = at least LONG_GAP_S apart (:func:`cylinder_checks`, :func:`metric_diagnostics`)."""


def run_seed(name: str, index: int) -> int:
    """Seed of run ``index`` of experiment ``name``: the first 32-bit word of
    ``numpy.random.SeedSequence([crc32(name), index])``."""
    sequence = np.random.SeedSequence([zlib.crc32(name.encode()), int(index)])
    return int(sequence.generate_state(1, np.uint32)[0])


def reproduce(name: str, out: Path, *, runs: int | None = None, progress: Progress | None = None,
              **options) -> Reproduction:
    """Run experiment ``name`` and write its figures and tables into ``out``.

    Parameters
    ----------
    name
        A key of :data:`REPRODUCTIONS`.
    out
        Output folder (created).
    runs
        Number of runs (seeds or subsamplings), for a quick look; None = the full
        experiment (:data:`DEFAULT_RUNS`).
    progress
        Called as ``progress(done, total, failed)``.
    options
        Experiment-specific options (clust: ``workers``, ``scheduler``, ``store``).
    """
    if name not in REPRODUCTIONS:
        raise InputError(f"unknown experiment; expected one of {', '.join(REPRODUCTIONS)}", value=name)
    return REPRODUCTIONS[name](Path(out), runs=runs, progress=progress, **options)


# -- measures ---------------------------------------------------------------------------
def h1_bars(diagram: Diagram, power=None) -> dict[str, float]:
    """Longest and second-longest dgm_1 bar (0 if missing), their ratio (inf with
    one bar, NaN with none) and the paper's SNR given the true beta_1 = 1 (``power``:
    that ``snr`` when the caller has it)."""
    lengths = diagram.lengths(1)
    longest = float(lengths[0]) if len(lengths) else 0.0
    second = float(lengths[1]) if len(lengths) > 1 else 0.0
    if second > 0:
        ratio = longest / second
    else:
        ratio = float("inf") if longest > 0 else float("nan")
    power = power or snr(diagram, 1, TRUE_BETA1)
    return {"longest_h1": longest, "second_h1": second, "ratio": ratio, "snr": power.ratio}


@dataclass(frozen=True)
class CylinderChecks:
    """Whether the encounter cloud of agents on a ring is the cylinder ring x time.

    rho_time
        Spearman correlation of d_ij with |t_i - t_j| over landmark pairs at the same
        place (true positions at most ``SAME_PLACE_MM`` apart): near 1 when time is
        one direction of the cloud.
    rho_angle
        Spearman correlation of d_ij with the angle between the two events seen from
        the ring's centre (in [0, pi]), over pairs at most ``SAME_TIME_S`` apart in
        time: near 1 when the other direction is the way round the ring.
    NaN when fewer than three pairs are in the class.
    """

    rho_time: float
    rho_angle: float


def cylinder_checks(distances: np.ndarray, t: np.ndarray, xy: np.ndarray, centre) -> CylinderChecks:
    """:class:`CylinderChecks` of landmark distances ``distances`` (L, L), event times
    ``t`` and true event positions ``xy`` (L, 2) on a ring around ``centre``."""
    i, j = np.triu_indices(len(t), k=1)
    d = distances[i, j]
    gap = np.abs(t[i] - t[j])
    angle = ring_angle(xy, centre)
    turn = np.abs(np.angle(np.exp(1j * (angle[i] - angle[j]))))
    same_place = np.linalg.norm(xy[i] - xy[j], axis=1) <= SAME_PLACE_MM
    same_time = gap <= SAME_TIME_S
    return CylinderChecks(rho_time=_spearman(d[same_place], gap[same_place]),
                          rho_angle=_spearman(d[same_time], turn[same_time]))


def ring_angle(xy: np.ndarray, centre) -> np.ndarray:
    """Angle (radians) of each position around ``centre``."""
    return np.arctan2(xy[:, 1] - centre[1], xy[:, 0] - centre[0])


def ring_concordance(coords: np.ndarray, angle: np.ndarray) -> float:
    """Whether a 3-D picture goes round its ring as the events go round the true ring.

    For each of the three planes spanned by two principal axes of ``coords``, phi is
    the angle of the points around their centroid in that plane; the result is the
    largest |mean exp(i (phi - s angle))| over the planes and s = +1, -1 (mirror
    images).  1 when the picture is a rotated or mirrored copy of the ring in one of
    those planes (a tube drawn along an axis, or a flat annulus), about 1/sqrt(n) for
    unrelated angles.
    """
    centred = np.asarray(coords, dtype=float) - np.mean(coords, axis=0)
    axes = np.linalg.svd(centred, full_matrices=False)[2]
    best = 0.0
    for left_out in range(axes.shape[0]):
        flat = centred @ np.delete(axes, left_out, axis=0).T
        phi = np.arctan2(flat[:, 1], flat[:, 0])
        for sign in (1, -1):
            best = max(best, float(abs(np.mean(np.exp(1j * (phi - sign * angle))))))
    return best


def _spearman(x: np.ndarray, y: np.ndarray) -> float:
    if len(x) < 3:
        return float("nan")
    return float(spearmanr(x, y)[0])


def metric_diagnostics(distances: np.ndarray, t: np.ndarray, xy: np.ndarray) -> dict[str, float]:
    """Ground-truth check of an encounter metric on landmark events.

    time_stretch
        Median of d_ij / |t_i - t_j| over pairs at the same place (true positions at
        most ``SAME_PLACE_MM`` apart) and at least ``LONG_GAP_S`` apart in time.  The
        plain metric gives >= 1 (every path spends at least |t_i - t_j| s); contraction
        aims at 0 (the same place is the same point whenever it was visited).
    far_speed
        Median of |p_i - p_j| / d_ij (mm/s) over pairs at least ``FAR_MM`` apart and
        at most ``SAME_TIME_S`` apart in time: the apparent speed at which the metric
        crosses the arena.  A single agent walks at most v_c = 15 mm/s; more means
        paths relay through encounters or jump through static agents.
    NaN when no pair is in the class.
    """
    i, j = np.triu_indices(len(t), k=1)
    gap = np.abs(t[i] - t[j])
    apart = np.linalg.norm(xy[i] - xy[j], axis=1)
    d = distances[i, j]
    same_place = (apart <= SAME_PLACE_MM) & (gap >= LONG_GAP_S)
    far = (apart >= FAR_MM) & (gap <= SAME_TIME_S) & (d > 0)
    return {
        "time_stretch": float(np.median(d[same_place] / gap[same_place])) if same_place.any() else float("nan"),
        "far_speed": float(np.median(apart[far] / d[far])) if far.any() else float("nan"),
    }


# -- experiments ------------------------------------------------------------------------
def reproduce_enc(out: Path, *, runs: int | None = None, progress: Progress | None = None) -> Reproduction:
    """Fig. "enc": the encounter cloud of agents on a thin ring is a cylinder over it."""
    name, out = "enc", output_folder(out)
    runs = _runs(name, runs)
    arena, agents = ring_arena(), ring_agents()
    centre = _centre(arena)
    tick = _Ticker(runs, progress)
    rows, picture = [], None
    for i in range(runs):
        seed = run_seed(name, i)
        sim = simulate(arena, agents, DURATION, rng=seed, truth=True)
        tmap, error = _map(sim.log, _config("plain", picture=True))
        row = {"run": i, "seed": seed, **_map_row(tmap, error)}
        if tmap is not None:
            region = tmap.regions[0]
            xy = event_positions(sim.truth, region.landmark_events)
            checks = cylinder_checks(region.landmarks.distances, sim.log.t[region.landmark_events], xy, centre)
            angle = ring_angle(xy, centre)
            concordance = ring_concordance(region.embedding.coords, angle)
            row.update(rho_time=checks.rho_time, rho_angle=checks.rho_angle, angle_concordance=concordance,
                       mds_stress=region.embedding.stress)
            if picture is None:
                picture = (sim, tmap, xy, angle, concordance, seed)
        rows.append(row)
        tick(failed=tmap is None)

    figures = []
    if picture is not None:
        figures.append(_enc_figure(out / "enc.png", arena, *picture))
    summary = {**_aggregate(rows),
               "median_rho_time": _median(rows, "rho_time"), "median_rho_angle": _median(rows, "rho_angle"),
               "median_angle_concordance": _median(rows, "angle_concordance"),
               "picture": _picked(picture, rows) if picture else None}
    headers = ["runs", "beta_1 = 1", "median longest / second H1", "median rho_time", "median rho_angle",
               "median angle concordance (MDS)"]
    cells = [[runs, _rate(summary), _fmt(summary["median_ratio"]), _fmt(summary["median_rho_time"]),
              _fmt(summary["median_rho_angle"]), _fmt(summary["median_angle_concordance"])]]
    settings = {**_common_settings(), "arena": f"annulus r_outer = {RING_RADII[0]:g} mm, r_inner = {RING_RADII[1]:g} mm",
                "agents": agents, "duration": DURATION, "metric": "plain", "runs": runs}
    return write_reproduction(name, out, rows, headers, cells, figures, summary, settings)


def reproduce_encmds(out: Path, *, runs: int | None = None, progress: Progress | None = None) -> Reproduction:
    """Fig. "encmds": one-hole square, 200 agents, 20 s, plain encounter metric."""
    name, out = "encmds", output_folder(out)
    runs = _runs(name, runs)
    arena = default_arena()
    tick = _Ticker(runs, progress)
    rows, picture = [], None
    for i in range(runs):
        seed = run_seed(name, i)
        sim = simulate(arena, AGENTS, DURATION, rng=seed, truth=True)
        tmap, error = _map(sim.log, _config("plain", picture=picture is None))
        rows.append({"run": i, "seed": seed, **_map_row(tmap, error)})
        if tmap is not None and picture is None:
            picture = (sim, tmap)
        tick(failed=tmap is None)

    figures = [_separation_figure(out / "encmds-runs.png", rows, [None], ["20 s, plain"])]
    if picture is not None:
        figures.insert(0, _encmds_figure(out / "encmds.png", arena, *picture))
    summary = _aggregate(rows)
    headers = ["runs", "beta_1 = 1", "median longest H1 (s)", "median second H1 (s)", "median longest / second",
               "SNR mean", "SNR median"]
    cells = [[runs, _rate(summary), _fmt(summary["median_longest_h1"]), _fmt(summary["median_second_h1"]),
              _fmt(summary["median_ratio"]), _fmt(summary["mean_snr"]), _fmt(summary["median_snr"])]]
    settings = {**_common_settings(), "arena": "default_arena()", "agents": AGENTS, "duration": DURATION,
                "metric": "plain", "runs": runs}
    return write_reproduction(name, out, rows, headers, cells, figures, summary, settings)


ENCIMPR_CONDITIONS = (("plain", 0.0), ("contracted", 0.0), ("hybrid", STATIC_FRACTION))
"""(metric, static fraction of the log) compared by encimpr: the paper's mobile network
with its encounter metric, the contracted metric on the same log (natural stops only),
and the contracted metric of the hybrid network (5 % static agents), which is what
``hybrid`` computes (see :mod:`swarmtopo.metric.graph`)."""


def reproduce_encimpr(out: Path, *, runs: int | None = None, progress: Progress | None = None) -> Reproduction:
    """Fig. "encImpr": plain vs contracted vs hybrid metric over 200 s (and the first 20 s)."""
    name, out = "encimpr", output_folder(out)
    runs = _runs(name, runs)
    arena = default_arena()
    durations = (DURATION, LONG_DURATION)
    tick = _Ticker(runs * len(durations) * len(ENCIMPR_CONDITIONS), progress)
    rows, pictures = [], {}
    for i in range(runs):
        seed = run_seed(name, i)
        sims = {fraction: simulate(arena, AGENTS, LONG_DURATION, rng=seed, truth=True,
                                   static_fraction=fraction, static_time=STATIC_TIME)
                for fraction in sorted({f for _, f in ENCIMPR_CONDITIONS})}
        for duration in durations:
            window = None if duration == LONG_DURATION else (None, duration)
            for metric, fraction in ENCIMPR_CONDITIONS:
                sim = sims[fraction]
                draw = i == 0 and duration == LONG_DURATION
                tmap, error = _map(sim.log, _config(metric, picture=draw, window=window))
                row = {"run": i, "seed": seed, "duration": duration, "metric": metric,
                       "static_fraction": fraction, **_map_row(tmap, error)}
                if tmap is not None:
                    region = tmap.regions[0]
                    events = region.landmark_events
                    row.update(metric_diagnostics(region.landmarks.distances, sim.log.t[events],
                                                  event_positions(sim.truth, events)))
                    if draw:
                        pictures[metric] = (sim, tmap)
                rows.append(row)
                tick(failed=tmap is None)

    figures = []
    if pictures:
        figures.append(_encimpr_figure(out / "encimpr.png", pictures))
    figures.append(_separation_figure(out / "encimpr-runs.png", rows, list(durations),
                                      [f"{d:g} s" for d in durations], by_metric=True))
    summary: dict[str, Any] = {"runs": runs, "conditions": {}}
    headers = ["duration", "metric", "static agents", "beta_1 = 1", "median longest H1 (s)",
               "median second H1 (s)", "median longest / second", "SNR median", "SNR mean",
               "time stretch", "far-pair speed (mm/s)"]
    cells = []
    for duration in durations:
        for metric, fraction in ENCIMPR_CONDITIONS:
            subset = [r for r in rows if r["duration"] == duration and r["metric"] == metric]
            agg = {**_aggregate(subset), "median_time_stretch": _median(subset, "time_stretch"),
                   "median_far_speed": _median(subset, "far_speed")}
            summary["conditions"][f"{metric}@{duration:g}s"] = agg
            cells.append([f"{duration:g} s", metric, f"{fraction:.0%}", _rate(agg),
                          _fmt(agg["median_longest_h1"]), _fmt(agg["median_second_h1"]), _fmt(agg["median_ratio"]),
                          _fmt(agg["median_snr"]), _fmt(agg["mean_snr"]), _fmt(agg["median_time_stretch"]),
                          _fmt(agg["median_far_speed"])])
    settings = {**_common_settings(), "arena": "default_arena()", "agents": AGENTS, "duration": LONG_DURATION,
                "short_window": [0.0, DURATION], "static_fraction": STATIC_FRACTION, "static_time": STATIC_TIME,
                "conditions": [list(c) for c in ENCIMPR_CONDITIONS], "runs": runs,
                "diagnostics": {"same_place_mm": SAME_PLACE_MM, "long_gap_s": LONG_GAP_S, "far_mm": FAR_MM,
                                "same_time_s": SAME_TIME_S}}
    return write_reproduction(name, out, rows, headers, cells, figures, summary, settings)


LAND2_METHODS: dict[str, Callable] = {
    "maxmin": maxmin,
    "knn": partial(knn_maxmin, k=KNN_K, q=KNN_Q),
    "probabilistic": partial(probabilistic_maxmin, k=KNN_K, omega=OMEGA),
}
"""land2's subsamplers: standard, KNN-filtered and probabilistic maxmin."""


def reproduce_land2(out: Path, *, runs: int | None = None, progress: Progress | None = None) -> Reproduction:
    """Fig. "land2": three subsamplers on one contracted encounter cloud, SNR over ``runs``
    independent subsamplings (landmark seeds :func:`run_seed` ("land2", r))."""
    name, out = "land2", output_folder(out)
    runs = _runs(name, runs)
    cloud_seed = run_seed("encmds", 0)
    sim = simulate(default_arena(), AGENTS, DURATION, rng=cloud_seed)
    graph = land2_graph(sim.log)
    classifier = load_classifier(PAPER_CLASSIFIER)
    tick = _Ticker(runs * len(LAND2_METHODS), progress)
    rows, first = [], {}
    for r in range(runs):
        landmark_seed = run_seed(name, r)
        for method, subsample in LAND2_METHODS.items():
            land = subsample(graph, LAND2_LANDMARKS, rng=landmark_seed)
            diagram = rips_persistence(land.distances, maxdim=1).diagram
            power = snr(diagram, 1, TRUE_BETA1)
            rows.append({"run": r, "landmark_seed": landmark_seed, "method": method, "landmarks": len(land.nodes),
                         "cover_radius": land.cover_radius, "beta_1": classifier.betti(diagram)[1],
                         **h1_bars(diagram, power), "signal_power": power.signal_power, "noise_power": power.noise_power})
            if r == 0:
                first[method] = (land, diagram)
            tick(failed=False)

    by_method = {m: np.array([row["snr"] for row in rows if row["method"] == m]) for m in LAND2_METHODS}
    summary: dict[str, Any] = {"runs": runs, "cloud_seed": cloud_seed, "events": graph.n_events,
                               "nodes": graph.n_nodes, "methods": {}}
    headers = ["method", "SNR mean", "SNR std", "SNR median", "SNR IQR", "runs with SNR > maxmin's",
               "beta_1 = 1"]
    cells = []
    for method, values in by_method.items():
        subset = [row for row in rows if row["method"] == method]
        agg = {"mean_snr": float(np.mean(values)), "std_snr": float(np.std(values, ddof=1)) if runs > 1 else 0.0,
               "median_snr": float(np.median(values)), "q25_snr": float(np.quantile(values, 0.25)),
               "q75_snr": float(np.quantile(values, 0.75)),
               "beta1_is_1": sum(row["beta_1"] == TRUE_BETA1 for row in subset),
               "better_than_maxmin": float(np.mean(values > by_method["maxmin"])) if method != "maxmin" else None}
        agg["beta1_rate"] = agg["beta1_is_1"] / runs
        summary["methods"][method] = agg
        cells.append([method, _fmt(agg["mean_snr"]), _fmt(agg["std_snr"]), _fmt(agg["median_snr"]),
                      f"{_fmt(agg['q25_snr'])} - {_fmt(agg['q75_snr'])}",
                      "-" if agg["better_than_maxmin"] is None else f"{agg['better_than_maxmin']:.0%}",
                      f"{agg['beta1_is_1']}/{runs}"])
    times = graph.node_times()
    figures = [_land2_figure(out / "land2.png", first, times, by_method)]
    settings = {**_common_settings(), "arena": "default_arena()", "agents": AGENTS, "duration": DURATION,
                "metric": "contracted", "cloud_seed": cloud_seed, "landmarks": LAND2_LANDMARKS, "k": KNN_K,
                "q": KNN_Q, "omega": OMEGA, "runs": runs}
    return write_reproduction(name, out, rows, headers, cells, figures, summary, settings)


def land2_graph(log):
    """land2's point cloud: the contracted encounter graph of ``log``, its largest
    connected component if it has several."""
    graph = build_graph(log, "contracted")
    count, labels = graph.components()
    if count == 1:
        return graph
    return graph.subgraph(np.flatnonzero(labels == np.argmax(np.bincount(labels))))


def ring_arena() -> Arena:
    """enc's thin ring (:data:`RING_RADII`)."""
    return annulus_arena(*RING_RADII)


def ring_agents() -> int:
    """Agents on the ring at the density of :data:`AGENTS` in the one-hole square."""
    return int(round(AGENTS * ring_arena().area / default_arena().area))


REPRODUCTIONS: dict[str, Callable[..., Reproduction]] = {
    "enc": reproduce_enc,
    "encmds": reproduce_encmds,
    "encimpr": reproduce_encimpr,
    "land2": reproduce_land2,
    "clust": reproduce_clust,
}
"""Experiment name -> function(out, *, runs=None, progress=None, **options) -> Reproduction
(clust's options: ``workers``, ``scheduler``, ``store``; see :mod:`.clust`)."""


def output_names(name: str) -> tuple[str, ...]:
    """Every file experiment ``name`` may write into its folder: NAME.csv, .md, .json and
    its figures NAME.png and NAME-runs.png (clust's store, clust.duckdb, is not an output)."""
    return tuple(f"{name}{suffix}" for suffix in (".csv", ".md", ".json", ".png", "-runs.png"))


# -- helpers ----------------------------------------------------------------------------
class _Ticker:
    """Counts finished units and calls ``progress(done, total, failed)``."""

    def __init__(self, total: int, progress: Progress | None):
        self.total, self.progress = total, progress
        self.done = self.failed = 0

    def __call__(self, *, failed: bool) -> None:
        self.done += 1
        self.failed += int(failed)
        if self.progress is not None:
            self.progress(self.done, self.total, self.failed)


def _runs(name: str, runs: int | None) -> int:
    return DEFAULT_RUNS[name] if runs is None else positive_int("runs", runs)


def _config(metric: str, *, picture: bool, window=None) -> MapConfig:
    """The paper's pipeline with one of its metrics."""
    return MapConfig(metric=metric, hop_cost=0.0, diffusion_time=WHOLE_LOG, wall_follow_weight=None,
                     window_length=WHOLE_LOG, landmark_bands=(1.0,), embed_dim=3 if picture else 0, window=window,
                     cycles=False)


def _map(log, config: MapConfig) -> tuple[TopologicalMap | None, str]:
    """The map, or None and the reason when there is too little data to map."""
    try:
        return map_encounters(log, config, reader=load_classifier(PAPER_CLASSIFIER)), ""
    except SwarmtopoError as exc:
        return None, str(exc)


def _map_row(tmap: TopologicalMap | None, error: str) -> dict[str, Any]:
    if tmap is None:
        return {"error": error}
    return {"events": tmap.n_events, "regions": tmap.betti[0],
            "landmarks": sum(len(r.landmarks.nodes) for r in tmap.regions),
            "beta_1": tmap.betti[1], "confidence_1": tmap.confidence.get(1),
            **h1_bars(tmap.diagram), "error": ""}


def _centre(arena: Arena) -> tuple[float, float]:
    xmin, ymin, xmax, ymax = arena.bounds
    return (xmin + xmax) / 2, (ymin + ymax) / 2


def _values(rows, key) -> np.ndarray:
    return np.array([r[key] for r in rows if r.get(key) is not None and not r.get("error")], dtype=float)


def _median(rows, key) -> float:
    values = _values(rows, key)
    values = values[~np.isnan(values)]
    return float(np.median(values)) if len(values) else float("nan")


def _aggregate(rows) -> dict[str, Any]:
    """Rate of beta_1 = 1 (failed runs count as misses), medians of the H1 bars, SNR."""
    snrs = _values(rows, "snr")
    hits = sum(r.get("beta_1") == TRUE_BETA1 for r in rows)
    return {"runs": len(rows), "failed": sum(bool(r.get("error")) for r in rows),
            "beta1_is_1": hits, "beta1_rate": hits / len(rows) if rows else float("nan"),
            "median_longest_h1": _median(rows, "longest_h1"), "median_second_h1": _median(rows, "second_h1"),
            "median_ratio": _median(rows, "ratio"),
            "mean_snr": float(np.mean(snrs)) if len(snrs) else float("nan"),
            "median_snr": float(np.median(snrs)) if len(snrs) else float("nan")}


def _picked(picture: tuple, rows) -> dict[str, Any]:
    """Headline numbers of the run drawn in enc's figure."""
    tmap, seed = picture[1], picture[-1]
    row = next(r for r in rows if r["seed"] == seed)
    return {"seed": seed, "beta_1": tmap.betti[1], "longest_h1_bars": [float(v) for v in tmap.diagram.lengths(1)[:5]],
            **{k: row[k] for k in ("rho_time", "rho_angle", "angle_concordance")}}


def _common_settings() -> dict[str, Any]:
    return {"motion": "MotionParams() (paper defaults)", "r_d": 30.0, "dt": 0.1,
            "map_config": "MapConfig(metric=..., hop_cost=0, diffusion_time=WHOLE_LOG, wall_follow_weight=None, "
                          "window_length=WHOLE_LOG, landmark_bands=(1,), embed_dim=3 for pictures else 0), "
                          "other fields default",
            "seeds": "run_seed(NAME, i) = SeedSequence([crc32(NAME), i]).generate_state(1)[0]",
            "classifier": load_classifier(PAPER_CLASSIFIER).describe(), "software": software_versions()}


def _fmt(value) -> str:
    if value is None or (isinstance(value, float) and np.isnan(value)):
        return "-"
    if isinstance(value, float):
        return "inf" if np.isinf(value) else f"{value:.3g}"
    return str(value)


def _rate(agg: dict[str, Any]) -> str:
    return f"{agg['beta1_is_1']}/{agg['runs']}"


# -- figures ----------------------------------------------------------------------------
DPI = 100


def _enc_figure(path: Path, arena: Arena, sim, tmap: TopologicalMap, xy, angle, concordance: float, seed: int) -> Path:
    from ..viz.plots import cyclic_colors, new_figure, plot_arena, plot_diagram, plot_point_cloud

    region = tmap.regions[0]
    coords, times, colours = region.embedding.coords, sim.log.t[region.landmark_events], cyclic_colors(angle)
    fig = new_figure(10, 9)
    plot_arena(arena, fig.add_subplot(2, 2, 1), points=xy, color=colours,
               title=f"(a) landmark events on the ring ({sim.log.n_agents} agents, {DURATION:g} s)")
    plot_point_cloud(coords, times, fig.add_subplot(2, 2, 2, projection="3d"), label="event time (s)",
                     title=f"(b) encounter cloud (MDS), seed {seed}")
    plot_point_cloud(coords, colours, fig.add_subplot(2, 2, 3, projection="3d"),
                     title=f"(c) coloured by angle on the ring, concordance {concordance:.2f}")
    plot_diagram(tmap.diagram, fig.add_subplot(2, 2, 4), thresholds=region.thresholds,
                 title=f"(d) diagram, plain metric (beta_1 = {tmap.betti[1]})")
    fig.savefig(path, dpi=DPI)
    return path


def _encmds_figure(path: Path, arena: Arena, sim, tmap: TopologicalMap) -> Path:
    from ..viz.plots import new_figure, plot_arena, plot_diagram, plot_point_cloud

    region = tmap.regions[0]
    events = region.landmark_events
    times = sim.log.t[events]
    fig = new_figure(16, 5)
    plot_arena(arena, fig.add_subplot(1, 3, 1), points=event_positions(sim.truth, events), color=times,
               title="(a) one-hole arena, landmark events by time")
    plot_point_cloud(region.embedding.coords, times, fig.add_subplot(1, 3, 2, projection="3d"),
                     label="event time (s)", title=f"(b) encounter cloud over {DURATION:g} s (MDS)")
    plot_diagram(tmap.diagram, fig.add_subplot(1, 3, 3), thresholds=region.thresholds,
                 title=f"(c) diagram, plain metric (beta_1 = {tmap.betti[1]})")
    fig.savefig(path, dpi=DPI)
    return path


def _encimpr_figure(path: Path, pictures: dict[str, tuple]) -> Path:
    from ..viz.plots import new_figure, plot_diagram, plot_point_cloud

    fig = new_figure(4.8 * len(pictures), 8.8)
    for col, (metric, (sim, tmap)) in enumerate(pictures.items(), start=1):
        region = tmap.regions[0]
        fraction = sim.log.meta["simulation"]["static_fraction"]
        network = f"{fraction:.0%} static" if fraction else "mobile"
        plot_point_cloud(region.embedding.coords, sim.log.t[region.landmark_events],
                         fig.add_subplot(2, len(pictures), col, projection="3d"), label="event time (s)",
                         title=f"{metric} metric, {network} network, {LONG_DURATION:g} s")
        plot_diagram(tmap.diagram, fig.add_subplot(2, len(pictures), len(pictures) + col),
                     thresholds=region.thresholds, title=f"{metric}: beta_1 = {tmap.betti[1]}")
    fig.savefig(path, dpi=DPI)
    return path


def _separation_figure(path: Path, rows, durations: list, titles: list[str], *, by_metric: bool = False) -> Path:
    from ..viz.plots import new_figure, plot_bar_separation

    fig = new_figure(5.2 * len(durations), 4.8)
    for col, (duration, title) in enumerate(zip(durations, titles), start=1):
        subset = [r for r in rows if not r["error"] and (duration is None or r["duration"] == duration)]
        plot_bar_separation([r["longest_h1"] for r in subset], [r["second_h1"] for r in subset],
                            fig.add_subplot(1, len(durations), col),
                            groups=[r["metric"] for r in subset] if by_metric else None,
                            title=f"H1 bars per run, {title}")
    fig.savefig(path, dpi=DPI)
    return path


def _land2_figure(path: Path, first: dict[str, tuple], node_times: np.ndarray, snrs: dict[str, np.ndarray]) -> Path:
    from ..viz.plots import new_figure, plot_diagram, plot_distributions, plot_point_cloud

    fig = new_figure(16, 8)
    grid = fig.add_gridspec(2, len(first) + 1, width_ratios=[1] * len(first) + [0.8])
    letters = "abc"
    for col, (method, (land, diagram)) in enumerate(first.items()):
        picture = mds(land.distances, 3, rng=0)
        plot_point_cloud(picture.coords, node_times[land.nodes], fig.add_subplot(grid[0, col], projection="3d"),
                         label="event time (s)", title=f"({letters[col]}) {method}: {len(land.nodes)} landmarks")
        plot_diagram(diagram, fig.add_subplot(grid[1, col]),
                     title=f"{method}: SNR = {snr(diagram, 1, TRUE_BETA1).ratio:.3g}")
    plot_distributions(snrs, fig.add_subplot(grid[:, len(first)]), ylabel="SNR of dgm_1 (beta_1 = 1)",
                       title=f"(d) SNR, {len(next(iter(snrs.values())))} subsamplings")
    fig.savefig(path, dpi=DPI)
    return path
