"""Where the holes are: precision and recall of representative cycles on random arenas.

Random 500 mm square arenas with 1-3 holes (squares and discs), 200 agents, 25 s,
default map options (no MDS picture).  For every region, the H1 bars the shipped
classifier counts (length > tau_1 (l_q + Delta_1)) get a representative cycle
(:mod:`swarmtopo.topology.cycles`), taken in the Rips graph at eps = b + position (d - b) for
several positions; the default (0.5) is compared with the bar's birth (0.0) as the
baseline.  Precision = detected cycles whose loop of true event positions encircles
exactly one obstacle; recall = obstacles encircled by some detected cycle.  Wilson
95 % intervals.  Writes docs/figures/cycles.png (first maps, default position).

    python lab/cycle_localization.py [--quick]
"""

import argparse
import time
from pathlib import Path

import numpy as np

from swarmtopo.arena import random_arena
from swarmtopo.topology.cycles import (DEFAULT_POSITION, encircled_obstacles, event_positions, localization_scores,
                              representative_cycles, wilson_interval)
from swarmtopo.topology.persistence import rips_persistence
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.viz.plots import new_figure, plot_cycles
from swarmtopo.sim import simulate

POSITIONS = (0.0, DEFAULT_POSITION, 0.9)
FIGURE = Path(__file__).resolve().parents[1] / "docs" / "figures" / "cycles.png"


def one_map(n_holes: int, seed: int, duration: float):
    """(arena, estimated beta_1, {position: list of (cycle, loop_xy, encircled)}, map seconds,
    cycle seconds per position)."""
    arena = random_arena(n_holes, rng=seed, shapes=("square", "disc"))
    sim = simulate(arena, 200, duration, rng=seed, truth=True)
    t0 = time.perf_counter()
    tmap = map_encounters(sim.log, MapConfig(seed=seed, embed_dim=0, cycles=False))
    t1 = time.perf_counter()
    found = {p: [] for p in POSITIONS}
    for region in tmap.regions:
        distances = region.landmarks.distances
        result = rips_persistence(distances, maxdim=1, cocycles=True)
        for position in POSITIONS:
            for cycle in representative_cycles(distances, result, region.counted[1], position=position):
                xy = event_positions(sim.truth, region.landmark_events[cycle.landmarks])
                found[position].append((cycle, xy, encircled_obstacles(xy, arena)))
    t2 = time.perf_counter()
    return arena, tmap.betti[1], found, t1 - t0, (t2 - t1) / len(POSITIONS)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="4 arenas per hole count instead of 25")
    args = parser.parse_args()
    per_count = 4 if args.quick else 25
    duration = 25.0
    maps, map_seconds, cycle_seconds = [], [], []
    for n_holes in (1, 2, 3):
        for seed in range(per_count):
            arena, beta1, found, t_map, t_cyc = one_map(n_holes, 1000 * n_holes + seed, duration)
            maps.append((n_holes, arena, beta1, found))
            map_seconds.append(t_map)
            cycle_seconds.append(t_cyc)

    print(f"{len(maps)} maps: random 500 mm arenas, 1-3 square/disc holes ({per_count} each), "
          f"200 agents, {duration:g} s, default MapConfig, shipped classifier")
    exact = sum(beta1 == n for n, _, beta1, _ in maps)
    print(f"classifier beta_1 exact on {exact}/{len(maps)} maps")
    print()
    print("| position in bar | eps | cycles | precision (95% CI) | obstacles | recall (95% CI) "
          "| precision / baseline |")
    print("|---|---|---|---|---|---|---|")
    baseline = None
    for position in POSITIONS:
        scores = localization_scores(([e for _, _, e in found[position]], n) for n, _, _, found in maps)
        if baseline is None:
            baseline = scores.precision
        plo, phi = wilson_interval(scores.correct, scores.detected)
        rlo, rhi = wilson_interval(scores.found, scores.obstacles)
        name = ("birth (baseline)" if position == 0.0
                else f"{position:g}" + (" (default)" if position == DEFAULT_POSITION else ""))
        print(f"| {name} | b + {position:g} (d - b) | {scores.detected} | {scores.correct}/{scores.detected} = "
              f"{scores.precision:.2f} [{plo:.2f}, {phi:.2f}] | {scores.obstacles} | "
              f"{scores.found}/{scores.obstacles} = "
              f"{scores.recall:.2f} [{rlo:.2f}, {rhi:.2f}] | {scores.precision / baseline:.2f} |")
    print()
    for n_holes in (1, 2, 3):
        sub = [m for m in maps if m[0] == n_holes]
        s = localization_scores(([e for _, _, e in m[3][DEFAULT_POSITION]], n_holes) for m in sub)
        print(f"default position, {n_holes} hole(s): precision {s.correct}/{s.detected}, "
              f"recall {s.found}/{s.obstacles}")
    wrong = [e for _, _, _, found in maps for _, _, e in found[DEFAULT_POSITION] if len(e) != 1]
    ceiling = sum(min(len(found[DEFAULT_POSITION]), n) for n, _, _, found in maps)
    print(f"default position, wrong cycles: {sum(len(e) == 0 for e in wrong)} encircle no obstacle, "
          f"{sum(len(e) >= 2 for e in wrong)} encircle two or more")
    print(f"obstacles reachable at one obstacle per cycle (sum over maps of min(cycles, holes)): "
          f"{ceiling}/{sum(n for n, _, _, _ in maps)}")
    print(f"median seconds per map: map_encounters {np.median(map_seconds):.3f}, "
          f"cycles (ripser with cocycles + loops) {np.median(cycle_seconds):.3f}, "
          f"ratio {np.median(cycle_seconds) / np.median(map_seconds):.2f}")

    fig = new_figure(10, 10)
    shown = [maps[i * per_count] for i in range(3)] + [maps[per_count + 1]]
    for k, (n_holes, arena, beta1, found) in enumerate(shown):
        ax = fig.add_subplot(2, 2, k + 1)
        loops = [xy for _, xy, _ in found[DEFAULT_POSITION]]
        plot_cycles(arena, loops, ax, correct=[len(e) == 1 for _, _, e in found[DEFAULT_POSITION]],
                    title=f"{n_holes} hole(s), beta_1 estimated {beta1}: {len(loops)} cycle(s)")
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=90)
    print(f"figure: {FIGURE.relative_to(FIGURE.parents[2])}")


if __name__ == "__main__":
    main()
