"""What the sparse cells' misses owe to the encounter metric: the same windows read with the truth.

For tuning cases of the accuracy suite (inside ``tuning_session``), each log is mapped
by the default pipeline (stripped of ground truth), and every window of every region is
read again with distances taken from the simulation's truth instead of the encounter
metric.  Readings (each an H1 diagram per window, pooled as the shipped classifier pools):

* ``default`` -- the encounter metric on the map's landmarks (what ``map`` reads);
* ``truth`` -- the true geodesic distance g (mm) between the same landmark events'
  positions (the midpoint of the two agents; shortest paths in the free space,
  ``metric_vs_truth.geodesic_distances``): a perfect metric on the same events;
* ``truth-landmarks`` -- landmarks drawn by maxmin (gudhi's farthest points, Euclidean)
  on the true positions of the window's events, as many as the default drew, and g
  between them: a perfect metric and a perfect draw, the same events (one-region maps;
  others keep ``truth``);
* ``metric-truth-landmarks`` -- the encounter metric on landmarks drawn in that order
  (maxmin on the true positions of the window's graph nodes), as many as the pipeline's
  covering rule keeps (covering radius in the encounter metric <= 1.5 x the k-NN scale,
  at most 400): the metric as it is, with a draw that covers the arena evenly;
* ``truth+time-C`` -- g + C x dt (mm, dt the two events' time separation in s): the
  metric's systematic drift with time alone (``metric_vs_truth.py`` fits
  d = 11.8 s + 0.125 s/mm g + 0.35 dt, i.e. C = 2.8 mm/s);
* ``truth+noise-S`` -- g plus independent Gaussian noise of sd S mm per landmark pair
  (symmetric, clipped at 0; seeded by the case): how much noise the holes survive
  (the fit above leaves a residual sd of 8.6 s, 69 mm).

Each reading gets thresholds fitted on its own maps (``experiments.tuning.fit_thresholds``,
mean pooling) and is printed fitted / 4-fold cross-validated, per cell and per hole
family, so a reading is compared at its best.  ``truth-landmarks`` is what a perfect
metric on these events reaches; ``truth`` and ``metric-truth-landmarks`` split the gap
into the distances and the draw; the time and noise rows say which kind of error costs
how much.  Defaults: the two cells that miss the per-cell target, 12 cases each.

    python lab/metric_ceiling.py --per-cell 96 [--readings metric-truth-landmarks]
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from gudhi.subsampling import choose_n_farthest_points
from scipy.spatial import cKDTree

from metric_vs_truth import geodesic_distances
from swarmtopo.metric import landmarks as L
from swarmtopo.pipeline import tasks as P
from swarmtopo.metric import _kernels
from swarmtopo.topology.cycles import event_positions
from swarmtopo.experiments.accuracy import CELLS, tuning_arena
from swarmtopo.experiments.sweep import stripped_log
from tuning import TuningMap, cross_validated, exact, fit_thresholds
from swarmtopo.topology.persistence import rips_persistence
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.sim import simulate

TIME_DRIFT_MM_PER_S = (2.8,)
NOISE_MM = (25.0, 50.0, 75.0)
READINGS = (("default", "truth", "truth-landmarks", "metric-truth-landmarks")
            + tuple(f"truth+time-{c:g}" for c in TIME_DRIFT_MM_PER_S)
            + tuple(f"truth+noise-{s:g}" for s in NOISE_MM))


def _h1(distances: np.ndarray):
    return rips_persistence(distances, maxdim=1).diagram


def _farthest_points(positions: np.ndarray, count: int, start: int) -> np.ndarray:
    """Indices of ``count`` of ``positions`` in maxmin (farthest-point, Euclidean) order from ``start``."""
    chosen = np.asarray(choose_n_farthest_points(points=positions, nb_points=count, starting_point=start))
    return np.asarray(cKDTree(positions).query(chosen)[1], np.int64)


def _truth_maxmin(truth):
    """A stand-in for the pipeline's subsampler: landmarks in maxmin order on the true
    positions of the graph's nodes (their representative events), covering radii in the
    encounter metric (as maxmin's, so the pipeline's covering rule, ``cover``, applies unchanged)."""
    def subsample(graph, config, n_landmarks, start, candidates=None, cover=None):
        arrays = L._GraphArrays.of(graph)
        positions = event_positions(truth, graph.representative_event())
        start = int(start) % len(positions)  # a rank drawn among the band's nodes: a node of the graph
        nodes = _farthest_points(positions, n_landmarks, start)
        search = _kernels.Searcher(arrays.indptr, arrays.indices, arrays.weights)
        to_set, radii = np.full(arrays.n, np.inf), np.empty(len(nodes))
        for i, node in enumerate(nodes):
            search.add_landmark(int(node), to_set)
            radii[i] = to_set.max()
        land = L._result(arrays, nodes, radii, "truth-maxmin", {"start": start}, L._quiet)
        return land if cover is None else L.covering_prefix(land, cover)
    return subsample


def _window_readings(arena, log, truth, window, region_count: int, rng: np.random.Generator,
                     readings: tuple[str, ...]) -> dict:
    """The diagrams of one window under ``readings`` (module docstring), all but
    ``metric-truth-landmarks``, which maps the log again (:func:`_run`)."""
    events = window.landmark_events
    times = log.t[events]
    needs_truth = any(name != "default" for name in readings)
    g = geodesic_distances(arena, event_positions(truth, events)) if needs_truth else None
    out = {"default": window.diagram}
    for name in readings:
        if name == "truth":
            out[name] = _h1(g)
        elif name.startswith("truth+time-"):
            c = float(name.rsplit("-", 1)[1])
            out[name] = _h1(g + c * np.abs(times[:, None] - times[None, :]))
        elif name.startswith("truth+noise-"):
            noise = np.triu(rng.normal(0.0, float(name.rsplit("-", 1)[1]), g.shape), 1)
            out[name] = _h1(np.clip(g + noise + noise.T, 0.0, None) * (1 - np.eye(len(g))))
        elif name == "truth-landmarks" and region_count == 1:
            inside = np.flatnonzero((log.t >= window.t0) & (log.t <= window.t1))
            positions = event_positions(truth, inside)
            out[name] = _h1(geodesic_distances(arena, positions[_farthest_points(positions, len(events), 0)]))
        elif name == "truth-landmarks":
            out[name] = _h1(g)
    return out


def _windows(log, seed, subsample=None):
    """The default map of ``log`` (every window), with ``subsample`` in place of the
    pipeline's subsampler if given."""
    original = P.subsample
    P.subsample = subsample or original
    try:
        return map_encounters(log, MapConfig(seed=seed, embed_dim=0, cycles=False, max_windows=None))
    finally:
        P.subsample = original


def _run(task):
    cell_index, index, readings = task
    cell = CELLS[cell_index]
    arena_table, seed, arena, stream = tuning_arena(cell, index)
    sim = simulate(arena, cell.agents, cell.duration, rng=stream, truth=True)
    log = stripped_log(sim.log)
    family = arena_table["shapes"][0] if arena_table["holes"] else "no hole"
    start = time.perf_counter()
    seed = seed % 2**32
    tmap = _windows(log, seed)
    rng = np.random.default_rng(seed)
    regions = {name: [] for name in readings}
    for region in tmap.regions:
        per_window = [_window_readings(arena, log, sim.truth, w, len(tmap.regions), rng,
                                       tuple(r for r in readings if r != "metric-truth-landmarks"))
                      for w in region.windows]
        for name in readings:
            if name != "metric-truth-landmarks":
                regions[name].append(tuple(r[name] for r in per_window))
    if "metric-truth-landmarks" in readings:
        regions["metric-truth-landmarks"] = [tuple(w.diagram for w in r.windows)
                                             for r in _windows(log, seed, _truth_maxmin(sim.truth)).regions]
    truth = arena.betti
    maps = {name: TuningMap(tuple(regions[name]), tmap.betti[0], truth[0], truth[1], cell.name) for name in readings}
    return maps, family, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=12)
    parser.add_argument("--cells", nargs="+", metavar="TEXT", default=["2 holes, 200 x 30", "3 holes, 200 x 30"],
                        help="the cells whose name contains one of these")
    parser.add_argument("--readings", nargs="+", choices=READINGS, default=list(READINGS),
                        help="default: all (the default pipeline's reading is always printed)")
    parser.add_argument("--processes", type=int, default=2)
    args = parser.parse_args()
    readings = tuple(dict.fromkeys(["default", *args.readings]))
    cells = [i for i, c in enumerate(CELLS) if any(text in c.name for text in args.cells)]
    if args.per_cell * len(cells) < 4:
        parser.error(f"{args.per_cell * len(cells)} map(s): the 4-fold cross-validation needs at least 4")
    tasks = [(c, i, readings) for i in range(args.per_cell) for c in cells]
    print(f"tuning cases of {len(cells)} cells x {args.per_cell}: " + ", ".join(CELLS[c].name for c in cells))
    start = time.perf_counter()
    with ProcessPoolExecutor(args.processes) as pool:
        results = list(pool.map(_run, tasks))
    print(f"{len(tasks)} maps in {(time.perf_counter() - start) / 60:.1f} min "
          f"({np.mean([s for _, _, s in results]):.1f} s per map for all readings)")
    families = [f for _, f, _ in results]
    for name in readings:
        maps = [m[name] for m, _, _ in results]
        fit = fit_thresholds(maps)
        right = exact(maps, fit.thresholds)
        per_cell = [int(sum(ok for m, ok in zip(maps, right) if m.cell == CELLS[c].name)) for c in cells]
        per_family = ", ".join(f"{f} {sum(ok for g, ok in zip(families, right) if g == f)}/{families.count(f)}"
                               for f in sorted(set(families)))
        print(f"{name}: {int(right.sum())}/{len(maps)} exact (q {fit.thresholds.q:g}, tau {fit.thresholds.tau:g}); "
              f"4-fold CV {cross_validated(maps)}/{len(maps)}; per cell {per_cell}; per hole family {per_family}",
              flush=True)


if __name__ == "__main__":
    main()
