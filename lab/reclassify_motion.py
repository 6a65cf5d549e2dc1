"""The motion benchmark's tuning maps read again by other classifiers (per model:
exact maps, too many and too few holes), to see whether a threshold of the reader
alone would fix one motion model without breaking another.

    python lab/reclassify_motion.py --store motion-tuning.duckdb --per-cell 6 --workers 2 \\
        --classifier trace ratio:mean:0.7:3.0 ratio:mean:0.6:3.74

Runs (resumably, windows' diagrams kept) the tuning cases of every model read as
contact traces, then reads each map's stored windows with each classifier (a preset,
a JSON file, or ``ratio:POOLING:Q:TAU`` as in ``lab/reclassify.py``).
"""

from __future__ import annotations

import argparse

from reclassify import _classifier
from swarmtopo.experiments.accuracy import tuning_session
from swarmtopo.experiments.motion_models import MODELS, jobs
from swarmtopo.experiments.store import read_jobs
from swarmtopo.experiments.sweep import run_sweep

COLUMNS = ("key", "config", "diagrams", "error", "est_betti0", "true_betti0", "true_betti1")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", required=True)
    parser.add_argument("--per-cell", type=int, default=6)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--classifier", nargs="+", default=["trace"])
    args = parser.parse_args()
    with tuning_session():
        todo = jobs("tuning", args.per_cell)
    run_sweep(todo, args.store, workers=args.workers, keep="windows")
    rows = read_jobs(args.store, columns=COLUMNS, keys=[job.key for job in todo])
    print("| classifier | " + " | ".join(MODELS) + " |")
    print("|---" * (len(MODELS) + 1) + "|")
    for name in args.classifier:
        reader = _classifier(name)
        tally = {m: [0, 0, 0, 0] for m in MODELS}  # exact, too many, too few, maps
        for row in rows:
            counts = tally[row["config"]["swarm"].get("motion", "cockroach")]
            counts[3] += 1
            if row["error"] is not None:
                continue
            est = sum(reader.read([w["diagram"] for w in r["windows"]]).betti.get(1, 0) for r in row["diagrams"])
            counts[0] += est == row["true_betti1"] and row["est_betti0"] == row["true_betti0"]
            counts[1] += est > row["true_betti1"]
            counts[2] += est < row["true_betti1"]
        print(f"| {name} | " + " | ".join(f"{e}/{n} (+{o}, -{u})" for e, o, u, n in tally.values()) + " |")


if __name__ == "__main__":
    main()
