"""Benchmark of swarmtopo.sim.simulate: compiled kernels vs a per-agent Python loop.

Throughput in agent-steps per second (dt = 0.1 s, paper motion defaults, r_d = 30 mm)
for 200, 2,000 and 20,000 agents.  The arena is a 500 mm square with one 100 mm
square hole, scaled by sqrt(N / 200) so the agent density stays the paper's
(200 agents in 500 x 500 mm).  The baseline runs the *same* model with the same
neighbour search, but on the kernels' pure-Python functions (``.py_func``) driven
agent by agent -- the way an agent-based framework runs a model; it is measured in
the same run on shorter simulations (agent-steps/s is comparable).  Also: the
paper's scale (200 agents x 200 s), and the one-off JIT compile time, measured in a
fresh process with an empty numba cache, next to the time to load the cached code.

Usage: python benchmarks/bench_simulate.py [--quick]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

from shapely.geometry import Polygon, box

from swarmtopo import Arena
from swarmtopo.sim import interpreted_kernels, simulate

DT = 0.1


def arena_for(n_agents: int) -> Arena:
    side = 500.0 * math.sqrt(n_agents / 200)
    return Arena(Polygon(box(0, 0, side, side).exterior.coords,
                         [box(0.4 * side, 0.4 * side, 0.6 * side, 0.6 * side).exterior.coords]))


def time_run(n_agents: int, steps: int, repeats: int) -> float:
    """Median wall time (s) of simulate() over ``repeats`` runs of ``steps`` steps."""
    arena = arena_for(n_agents)
    times = []
    for r in range(repeats):
        t0 = time.perf_counter()
        simulate(arena, n_agents, steps * DT, dt=DT, rng=r)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def compile_times() -> tuple[float, float]:
    """(cold compile, cached load) seconds for a first tiny simulation in a fresh process."""
    code = ("import time; t0 = time.perf_counter(); "
            "from shapely.geometry import box; from swarmtopo import Arena; from swarmtopo.sim import simulate; "
            "t1 = time.perf_counter(); simulate(Arena(box(0, 0, 100, 100)), 5, 0.2, rng=0); "
            "print(time.perf_counter() - t1)")
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        runs = [float(subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True,
                                     text=True).stdout) for _ in range(2)]
    return runs[0], runs[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer steps and repeats")
    args = parser.parse_args()
    repeats = 1 if args.quick else 3
    # (agents, compiled steps, python steps)
    plan = [(200, 2000, 20), (2000, 500, 5), (20000, 100, 2)]
    if args.quick:
        plan = [(200, 500, 5), (2000, 100, 2), (20000, 20, 1)]

    cold, cached = compile_times()
    simulate(arena_for(200), 5, 1.0, rng=0)  # load the compiled kernels in this process

    print(f"swarmtopo.sim.simulate benchmark (dt = {DT} s, density 200 agents / 500^2 mm^2, "
          f"median of {repeats})")
    print(f"{'agents':>7} {'arena mm':>9} {'steps':>6} {'compiled a-steps/s':>19} "
          f"{'py steps':>8} {'python a-steps/s':>17} {'ratio':>7}")
    ratios = {}
    for n, steps, py_steps in plan:
        fast = n * (steps + 1) / time_run(n, steps, repeats)
        with interpreted_kernels():
            slow = n * (py_steps + 1) / time_run(n, py_steps, repeats)
        ratios[n] = fast / slow
        side = 500.0 * math.sqrt(n / 200)
        print(f"{n:>7} {side:>9.0f} {steps:>6} {fast:>19,.0f} {py_steps:>8} {slow:>17,.0f} {fast / slow:>6.0f}x")

    paper = time_run(200, 2000, repeats)
    print()
    print(f"paper scale, 200 agents x 200 s (2000 steps): {paper:.3f} s wall time (target well under 1 s)")
    print(f"JIT compile, first call in a fresh process, empty cache: {cold:.1f} s; with the cache: {cached:.2f} s")
    print(f"ratio at 2,000 agents: {ratios[2000]:.0f}x (target >= 50x)")


if __name__ == "__main__":
    main()
