"""Accuracy of the default map on the paper's Fig. "encmds" set-up (the demo).

500 mm square with one centred hole, or none; 200 agents; 20 s; default map options
(hybrid metric, maxmin, automatic landmark count, shipped classifier) plus fixed
L = 300 and 600.  Prints how many maps give the exact beta_1 over seeds 0-19 (these
fixed arenas are not in the classifier's training sweep, whose arenas are random).

    python benchmarks/demo_accuracy.py [--seeds N] [--classifier default|paper|FILE]
"""

import argparse

from swarmtopo.arena import default_arena, square_arena
from swarmtopo.classify import load_classifier
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.sim import simulate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--classifier", default="default")
    args = parser.parse_args()
    classifier = load_classifier(args.classifier)
    print(f"| arena | landmarks | exact beta_1 (seeds 0-{args.seeds - 1}) |")
    print("|---|---|---|")
    for name, arena, holes in (("one hole", default_arena(), 1), ("no hole", square_arena(), 0)):
        logs = [simulate(arena, 200, 20.0, rng=seed).log for seed in range(args.seeds)]
        for landmarks in (None, 300, 600):
            right = sum(map_encounters(log, MapConfig(seed=seed, landmarks=landmarks, embed_dim=0, cycles=False),
                                       classifier=classifier).betti[1] == holes
                        for seed, log in enumerate(logs))
            print(f"| {name} | {landmarks or 'auto'} | {right}/{args.seeds} |")


if __name__ == "__main__":
    main()
