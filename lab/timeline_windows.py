"""Which of the map's windows the timeline should read: all, or only those at least W long.

On the timeline benchmark's tuning maps (a store written by ``lab/tune_timeline.py``, every
timeline window's counts kept), re-cuts each map's windows, all of them or only those at
least the map's window length W (scales 1 and 1.25; the 0.75 scale's windows hold 15
encounters per agent and misread more), with each penalty, and prints: true changes found,
found within 15 s (a beta_0 change counts as on time: it is dated by the encounters, not
by the windows), false change points on the changing logs, static logs with a false alarm.

    python lab/timeline_windows.py [--store lab-timeline.duckdb]
"""

from __future__ import annotations

import argparse

import numpy as np

from swarmtopo.experiments.store import iter_jobs
from swarmtopo.experiments.timeline import WITHIN, true_changes
from swarmtopo.pipeline.timeline import segment

PENALTIES = (2.0, 3.0, 4.0, 5.0, 6.0)


def changes(windows: list[dict], penalty: float) -> list[tuple[int, int, int, float]]:
    """(dimension, from, to, t) of the change points of the windows' counts."""
    found = []
    for n in ("0", "1"):
        mine = [w for w in windows if n in w["betti"]]
        cuts = segment([w["betti"][n] for w in mine], penalty)
        for (_, j, a), (_, _, b) in zip(cuts[:-1], cuts[1:]):
            found.append((int(n), a, b, (mine[j - 1]["t0"] + mine[j]["t1"]) / 2))
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--store", default="lab-timeline.duckdb")
    args = parser.parse_args()
    rows = [r for r in iter_jobs(args.store) if r["status"] == "ok" and r["timeline"].get("windows")]
    print(f"{len(rows)} tuning maps")
    print("windows | penalty | found | within 15 s | false changes | static false alarms")
    for which in ("all", "at least W"):
        for penalty in PENALTIES:
            found = within = expected = false = alarms = static = 0
            for row in rows:
                timeline = row["timeline"]
                windows = timeline["windows"]
                if which != "all":
                    lengths = np.array([w["t1"] - w["t0"] for w in windows])
                    windows = [w for w, length in zip(windows, lengths) if length >= timeline["length"] * (1 - 1e-9)]
                got = changes(windows, penalty)
                wanted = true_changes(timeline["truth"])
                for true in wanted:
                    same = [g for g in got if g[:3] == (true["dimension"], true["from"], true["to"])]
                    if same:
                        best = min(same, key=lambda g: abs(g[3] - true["t"]))
                        got.remove(best)
                        found += 1
                        within += true["dimension"] == 0 or abs(best[3] - true["t"]) <= WITHIN
                if wanted:
                    expected += len(wanted)
                    false += len(got)
                else:
                    static += 1
                    alarms += bool(got)
            print(f"{which} | {penalty:g} | {found}/{expected} | {within}/{expected} | {false} | {alarms}/{static}")


if __name__ == "__main__":
    main()
