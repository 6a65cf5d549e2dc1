"""Accuracy of the interim Betti rule on the paper's Fig. "encmds" set-up.

500 mm square with one centred hole, or none; 200 agents; 20 s; default map options
(hybrid metric, maxmin, automatic landmark count) plus fixed L = 300 and 600.  Prints
how many maps give the exact beta_1 over seeds 0-19 (never used to choose tau;
tau was chosen on seeds 1000-1011).

    python benchmarks/interim_rule_accuracy.py [--seeds N]
"""

import argparse

from swarmtopo.arena import default_arena, square_arena
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.sim import simulate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    args = parser.parse_args()
    print(f"| arena | landmarks | exact beta_1 (seeds 0-{args.seeds - 1}) |")
    print("|---|---|---|")
    for name, arena, holes in (("one hole", default_arena(), 1), ("no hole", square_arena(), 0)):
        logs = [simulate(arena, 200, 20.0, rng=seed).log for seed in range(args.seeds)]
        for landmarks in (None, 300, 600):
            right = sum(map_encounters(log, MapConfig(seed=seed, landmarks=landmarks, embed_dim=0)).betti[1] == holes
                        for seed, log in enumerate(logs))
            print(f"| {name} | {landmarks or 'auto'} | {right}/{args.seeds} |")


if __name__ == "__main__":
    main()
