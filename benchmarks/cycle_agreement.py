"""Cross-window cycle agreement, a lever measured on the benchmark's tuning cases.

The idea: a true hole's loop is the same loop in every window (windows overlap by half,
so consecutive windows share events), a noise loop is not.  For each window of a
region, the ``M`` longest H1 bars get circular coordinates (de Silva, Morozov and
Vejdemo-Johansson 2011: the Z/p cocycle from ripser.py lifted to the integers and
smoothed by least squares on the Rips 1-skeleton at the middle of the bar) on the
landmarks; every event of the window takes its nearest landmark's.  Two windows that
overlap by at least 40 % of the shorter agree on a pair of bars by the correlation of
their coordinates on the events they share, rotation and reflection free:
``max(|<za, zb>|, |<za, conj zb>|) / (|za| |zb|)`` with z = exp(2 pi i theta) centred
(``centred``), or not centred (``raw``, which two nearly constant fields pass).  A bar's
agreement is its best over the other window's bars, averaged over the overlapping
windows; A_k, the region's, is the mean over its windows of their k-th bars'.

Printed: the ROC AUC with which S_k (the shipped pooled score) and A_k tell the true
bars (rank <= true beta_1) from the noise among ranks 1..M, over all bars and near the
threshold; then exact (beta_0, beta_1) of the shipped rule (S_k > ln tau_1), of S_k > a
and of S_k > a and A_k > b, (a, b) fitted by grid search, in-sample and 4-fold
cross-validated (folds: case index mod 4); with ``--rule A B`` that fixed rule is read
instead (for cells not used to choose it).  One-room cells only (the truth is per
arena, a rank's per region).  Seconds per map with and without the agreement.

Usage::

    python benchmarks/cycle_agreement.py --per-cell 96 --cells "0 holes, 200" "2 holes, 200" "3 holes, 200"
    python benchmarks/cycle_agreement.py --per-cell 48 --cells "1 holes, 200" "0 holes, 300" "3 holes, 300" --rule 1.84 0.64
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager

import numpy as np
from ripser import ripser
from scipy import sparse
from scipy.sparse.csgraph import dijkstra
from scipy.sparse.linalg import lsqr
from sklearn.metrics import roc_auc_score

from swarmtopo import pipeline
from swarmtopo.classify import load_classifier
from swarmtopo.errors import SwarmtopoError
from swarmtopo.experiments.accuracy import CELLS, tuning_arena
from swarmtopo.experiments.sweep import stripped_log
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.ratio import pooled_scores
from swarmtopo.sim import simulate

M = 5  # bars per window given coordinates
PRIME = 47  # coefficients of the cocycles (Z/2 cocycles cannot be lifted to the integers)
OVERLAP = 0.4  # windows overlapping by this share of the shorter are compared
SHIPPED = load_classifier("default").thresholds_[1]
A_GRID = [round(float(a), 2) for a in np.arange(1.60, 2.201, 0.02)]
B_GRID = [round(float(b), 2) for b in np.arange(0.0, 0.961, 0.02)]


def circular_coordinates(distances: np.ndarray, bar, cocycle) -> np.ndarray:
    """theta in [0, 1) of each landmark for one H1 bar (module docstring)."""
    birth, death = bar
    radius = birth + 0.5 * ((death if np.isfinite(death) else distances.max()) - birth)
    iu, ju = np.triu_indices(len(distances), 1)
    keep = distances[iu, ju] <= radius
    iu, ju = iu[keep], ju[keep]
    rows = np.asarray(cocycle, dtype=np.int64).reshape(-1, 3)
    values = rows[:, 2].astype(float)
    values[values > (PRIME - 1) / 2] -= PRIME  # the integer lift
    lifted = np.zeros(distances.shape)
    lifted[rows[:, 0], rows[:, 1]] = values
    lifted[rows[:, 1], rows[:, 0]] = -values
    edges = np.arange(len(iu))
    coboundary = sparse.csr_matrix((np.r_[-np.ones(len(iu)), np.ones(len(iu))], (np.r_[edges, edges], np.r_[iu, ju])),
                                   shape=(len(iu), len(distances)))
    return np.mod(lsqr(coboundary, lifted[iu, ju], atol=1e-10, btol=1e-10, iter_lim=5000)[0], 1.0)


def window_coordinates(window, graph) -> tuple[np.ndarray, np.ndarray]:
    """(events of the window, sorted; (M, events) coordinates, NaN rows for missing bars)."""
    distances = window.landmarks.distances
    out = ripser(distances, distance_matrix=True, maxdim=1, do_cocycles=True, coeff=PRIME)
    diagram, cocycles = out["dgms"][1], out["cocycles"][1]
    order = np.argsort(-(diagram[:, 1] - diagram[:, 0]), kind="stable")[:M]
    theta = np.full((M, len(distances)), np.nan)
    for k, i in enumerate(order):
        theta[k] = circular_coordinates(distances, diagram[i], cocycles[i])
    nodes = window.landmarks.nodes
    _, _, source = dijkstra(graph.adjacency, indices=nodes, min_only=True, return_predecessors=True)
    landmark_of_node = np.full(graph.n_nodes, -1)
    landmark_of_node[nodes] = np.arange(len(nodes))
    nearest = landmark_of_node[source[graph.node_of_event]]
    reached = nearest >= 0
    events = graph.event_index[reached]
    order = np.argsort(events)
    return events[order], theta[:, nearest[reached]][:, order]


def pair_agreement(a, b) -> dict[str, np.ndarray]:
    """(M, M) raw and centred agreements of window a's bars with window b's."""
    _, ia, ib = np.intersect1d(a[0], b[0], return_indices=True)
    if len(ia) < 10:
        return {"raw": np.zeros((M, M)), "centred": np.zeros((M, M))}
    za, zb = np.exp(2j * np.pi * a[1][:, ia]), np.exp(2j * np.pi * b[1][:, ib])
    raw = np.maximum(np.abs(za @ zb.conj().T), np.abs(za @ zb.T)) / len(ia)
    ca, cb = za - za.mean(axis=1, keepdims=True), zb - zb.mean(axis=1, keepdims=True)
    norms = np.outer(np.linalg.norm(ca, axis=1), np.linalg.norm(cb, axis=1)) + 1e-12
    centred = np.maximum(np.abs(ca @ cb.conj().T), np.abs(ca @ cb.T)) / norms
    return {"raw": np.nan_to_num(raw), "centred": np.nan_to_num(centred)}


def region_agreement(windows, graphs) -> dict[str, np.ndarray]:
    """A_k (k = 1..M) of a region, raw and centred (module docstring)."""
    coords = [window_coordinates(w, g) for w, g in zip(windows, graphs)]
    spans = [(w.t0, w.t1) for w in windows]
    per_window = {"raw": [], "centred": []}
    for i, (lo, hi) in enumerate(spans):
        near = [j for j, (lo2, hi2) in enumerate(spans)
                if j != i and min(hi, hi2) - max(lo, lo2) >= OVERLAP * min(hi - lo, hi2 - lo2)]
        present = ~np.isnan(coords[i][1][:, 0])
        for kind in per_window:
            if not near:
                continue
            best = np.mean([pair_agreement(coords[i], coords[j])[kind].max(axis=1) for j in near], axis=0)
            per_window[kind].append(np.where(present, best, 0.0))
    return {kind: np.mean(rows, axis=0) if rows else np.full(M, np.nan) for kind, rows in per_window.items()}


@contextmanager
def window_graphs(store: list):
    """Record the graph each window of ``map_encounters`` was mapped on."""
    original = pipeline._map_window

    def recording(span, sub, *args, **kwargs):
        store.append(sub)
        return original(span, sub, *args, **kwargs)

    pipeline._map_window = recording
    try:
        yield
    finally:
        pipeline._map_window = original


def run(task):
    cell_index, index = task
    cell = CELLS[cell_index]
    table, seed, arena, stream = tuning_arena(cell, index)
    log = stripped_log(simulate(arena, cell.agents, cell.duration, rng=stream).log)
    graphs = []
    start = time.perf_counter()
    try:
        with window_graphs(graphs):
            tmap = map_encounters(log, MapConfig(seed=seed % 2**32, embed_dim=0, cycles=False))
    except SwarmtopoError:
        return None
    seconds_map = time.perf_counter() - start
    region = max(tmap.regions, key=lambda r: r.n_events)
    windows = region.windows
    first = sum(len(r.windows) for r in tmap.regions[:tmap.regions.index(region)])
    start = time.perf_counter()
    agreement = region_agreement(windows, graphs[first:first + len(windows)])
    scores = np.r_[pooled_scores([w.diagram for w in windows], 1, SHIPPED.q), np.zeros(M)][:M]
    return {"cell": cell.name, "index": index, "right_b0": tmap.betti[0] == arena.betti[0],
            "true_b1": arena.betti[1], "S": scores, **agreement,
            "seconds": (seconds_map, time.perf_counter() - start)}


def exact(maps, a, b=None, kind="centred") -> np.ndarray:
    """Whether each map's (beta_0, beta_1) is right when rank k counts iff S_k > a (and A_k > b)."""
    out = []
    for m in maps:
        counted = m["S"] > a
        if b is not None:
            counted &= np.nan_to_num(m[kind], nan=1.0) > b  # a region of one window has no agreement
        out.append(m["right_b0"] and int(counted.sum()) == m["true_b1"])
    return np.array(out)


def best(maps, with_agreement: bool):
    grid = [(a, b) for a in A_GRID for b in (B_GRID if with_agreement else [None])]
    counts = [exact(maps, a, b).sum() for a, b in grid]
    return grid[int(np.argmax(counts))]


def cross_validated(maps, with_agreement: bool) -> tuple[np.ndarray, list]:
    right, chosen = np.zeros(len(maps), bool), []
    for fold in range(4):
        held = np.array([m["index"] % 4 == fold for m in maps])
        rule = best([m for m, h in zip(maps, held) if not h], with_agreement)
        chosen.append(rule)
        right[held] = exact([m for m, h in zip(maps, held) if h], *rule)
    return right, chosen


def per_cell(maps, right) -> str:
    cells = sorted({m["cell"] for m in maps})
    return ", ".join(f"{c}: {sum(r for m, r in zip(maps, right) if m['cell'] == c)}/"
                     f"{sum(m['cell'] == c for m in maps)}" for c in cells)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=24)
    parser.add_argument("--cells", nargs="+", default=["0 holes, 200", "2 holes, 200", "3 holes, 200"])
    parser.add_argument("--rule", nargs=2, type=float, metavar=("A", "B"),
                        help="read this fixed rule (S_k > A and A_k > B) instead of fitting one")
    parser.add_argument("--processes", type=int, default=2)
    args = parser.parse_args()
    cells = [i for i, c in enumerate(CELLS) if any(text in c.name for text in args.cells)]
    if any(CELLS[c].generator != "random" for c in cells):
        parser.error("one-room cells only: the truth is per arena, a rank's per region")
    started = time.perf_counter()
    with ProcessPoolExecutor(args.processes) as pool:
        results = list(pool.map(run, [(c, i) for i in range(args.per_cell) for c in cells]))
    maps = [m for m in results if m is not None]
    print(f"{len(maps)} maps ({len(results) - len(maps)} refused) of {', '.join(CELLS[c].name for c in cells)}; "
          f"{(time.perf_counter() - started) / 60:.1f} min")
    seconds = np.array([m["seconds"] for m in maps])
    print(f"seconds per map: {np.median(seconds[:, 0]):.2f} to map, {np.median(seconds[:, 1]):.2f} more for the "
          "agreement (medians)")
    ln_tau = float(np.log(SHIPPED.tau))
    bars = [(m["S"][k], m["raw"][k], m["centred"][k], k < m["true_b1"]) for m in maps for k in range(M)
            if not np.isnan(m["centred"][k])]
    s, raw, centred, true = (np.array(column) for column in zip(*bars))
    for name, zone in (("all bars", np.ones(len(s), bool)), ("|S - ln tau_1| <= 0.3", np.abs(s - ln_tau) <= 0.3)):
        print(f"AUC, {name} ({zone.sum()} bars, {true[zone].sum()} true): S {roc_auc_score(true[zone], s[zone]):.3f}, "
              f"A raw {roc_auc_score(true[zone], raw[zone]):.3f}, A centred {roc_auc_score(true[zone], centred[zone]):.3f}")
    shipped = exact(maps, ln_tau)
    print(f"shipped (S > {ln_tau:.3f}): {shipped.sum()}/{len(maps)}; {per_cell(maps, shipped)}")
    if args.rule:
        a, b = args.rule
        for label, right in ((f"S > {a:g}", exact(maps, a)), (f"S > {a:g} and A > {b:g}", exact(maps, a, b))):
            print(f"{label}: {right.sum()}/{len(maps)}; {per_cell(maps, right)}; "
                  f"against shipped {np.sum(right & ~shipped)} fixed, {np.sum(~right & shipped)} broken")
        return
    for with_agreement in (False, True):
        rule = best(maps, with_agreement)
        right, chosen = cross_validated(maps, with_agreement)
        label = "S > a and A > b" if with_agreement else "S > a"
        print(f"{label}: in-sample {exact(maps, *rule).sum()}/{len(maps)} at {rule}; 4-fold CV {right.sum()}/"
              f"{len(maps)} (folds chose {chosen}); {per_cell(maps, right)}; against shipped "
              f"{np.sum(right & ~shipped)} fixed, {np.sum(~right & shipped)} broken")


if __name__ == "__main__":
    main()
