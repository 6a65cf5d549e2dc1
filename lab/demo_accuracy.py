"""Accuracy of the map on the paper's Fig. "encmds" arena (the demo's), default against paper.

500 mm square with one centred hole, or none; 200 agents; 20 s (the paper's figure:
shorter than an automatic window of 20 encounters per agent, so the default's window
scales 1 and 1.25 map the log whole and scale 0.75 gives two windows) and 30 s (the demo).
Prints how many maps give the exact beta_1 over seeds 0..N-1 for swarmtopo's default
pipeline and for the paper's (``swarmtopo map --paper``: no per-hop cost, the whole
log, the paper's classifier form, the ``paper`` preset).  These
fixed arenas are in neither the tuning nor the training cases.

    python lab/demo_accuracy.py [--seeds N]
"""

import argparse

from swarmtopo.arena import default_arena, square_arena
from swarmtopo.readers.registry import load_classifier
from swarmtopo.pipeline.config import WHOLE_LOG
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.sim import simulate

PAPER_WEIGHTS = dict(hop_cost=0.0, diffusion_time=WHOLE_LOG, wall_follow_weight=None, window_length=WHOLE_LOG)
PIPELINES = {
    "default": (dict(), "default"),
    "--paper (h = 0, whole log)": (PAPER_WEIGHTS, "paper"),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    args = parser.parse_args()
    print(f"| arena | pipeline (seeds 0-{args.seeds - 1}) | 200 x 20 s: exact beta_1 | 200 x 30 s: exact beta_1 |")
    print("|---|---|---|---|")
    for name, arena, holes in (("one hole", default_arena(), 1), ("no hole", square_arena(), 0)):
        logs = {t: [simulate(arena, 200, t, rng=seed).log for seed in range(args.seeds)] for t in (20.0, 30.0)}
        for label, (options, classifier) in PIPELINES.items():
            model = load_classifier(classifier)
            right = [sum(map_encounters(log, MapConfig(seed=seed, embed_dim=0, cycles=False, **options),
                                        reader=model).betti[1] == holes
                         for seed, log in enumerate(logs[t])) for t in (20.0, 30.0)]
            print(f"| {name} | {label} | {right[0]}/{args.seeds} | {right[1]}/{args.seeds} |")


if __name__ == "__main__":
    main()
