"""Choose the timeline's change penalty on the timeline benchmark's tuning cases.

Runs the tuning split of ``swarmtopo bench timeline`` (seeds of their own: never a
reported case) with every timeline window's counts kept, re-cuts each map's windows
with every penalty of ``PENALTIES`` (:func:`swarmtopo.pipeline.timeline.segment`), and
prints per penalty: true changes found (right dimension and direction, any time), false
change points on the changing logs, and static controls with a false alarm.  The
shipped ``CHANGE_PENALTY`` is the least penalty whose false alarms on the static
controls are at most 5 % with the most changes found (docs/timeline.md, "How the
penalty was chosen").

    python lab/tune_timeline.py [--store lab-timeline.duckdb] [--per-cell 16] [--workers 2]
"""

from __future__ import annotations

import argparse

from swarmtopo.experiments.store import iter_jobs
from swarmtopo.experiments.timeline import TUNING_PER_CELL, jobs, true_changes
from swarmtopo.experiments.sweep import run_sweep
from swarmtopo.pipeline.timeline import CHANGE_PENALTY, segment

PENALTIES = (1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0)


def cut_changes(windows: list[dict], penalty: float) -> list[tuple[int, int, int]]:
    """(dimension, from, to) of every change point of the windows' counts cut with ``penalty``."""
    found = []
    for n in ("0", "1"):
        values = [w["betti"][n] for w in windows if n in w["betti"]]
        cuts = segment(values, penalty)
        found += [(int(n), a[2], b[2]) for a, b in zip(cuts[:-1], cuts[1:])]
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--store", default="lab-timeline.duckdb")
    parser.add_argument("--per-cell", type=int, default=2 * TUNING_PER_CELL)
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args()
    todo = jobs("tuning", args.per_cell)
    run_sweep(todo, args.store, workers=args.workers, keep="windows")
    rows = [r for r in iter_jobs(args.store, keys=[j.key for j in todo]) if r["status"] == "ok"]
    print(f"{len(rows)} tuning maps of {len(todo)}; shipped penalty {CHANGE_PENALTY:g}")
    print("penalty | changes found | false changes (changing logs) | static logs with a false alarm")
    for penalty in PENALTIES:
        found = expected = false = alarms = static = 0
        for row in rows:
            timeline = row["timeline"]
            wanted = [(c["dimension"], c["from"], c["to"]) for c in true_changes(timeline["truth"])]
            got = cut_changes(timeline["windows"], penalty)
            hits = sum(1 for w in wanted if w in got)
            extra = len(got) - hits
            if wanted:
                expected += len(wanted)
                found += hits
                false += extra
            else:
                static += 1
                alarms += extra > 0
        print(f"{penalty:7g} | {found}/{expected} | {false} | {alarms}/{static}")


if __name__ == "__main__":
    main()
