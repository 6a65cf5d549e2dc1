"""The accuracy bench's stored maps read by other classifiers: a classifier's effect apart from the maps'.

``swarmtopo bench accuracy`` stores every default-pipeline map's per-window diagrams, so
the same maps can be read again by another classifier without mapping anything.  For
each classifier given, prints exact (beta_0, beta_1) over the reporting maps, per cell
and for the held-out family, with the Brier score of its beta_1 confidence; then per
budget (the two rooms on their own) the wrong maps counting too many and too few holes
and the held-out family's exact maps, and the range of the wrong maps' beta_1
confidence.  With ``--planning`` it reads the planning grid's maps instead (the full
run's swarms and logs beyond the suite's budgets) and prints, per classifier, the
reliability of the beta_1 confidence there, the mean confidence against the fraction
right per swarm size, and the wrong maps said at 0.95 or more.  ``--reading
contact-trace`` reads the maps of the same cases read as contact traces instead
(``lab/trace_accuracy.py``'s store, with ``--planning`` for the grid).  Reading a
store made by an older swarmtopo (other grid columns) works too: only the columns the
verdict needs are read, so two rounds' maps can be compared under one classifier.

    python lab/reclassify.py --store bench.duckdb [--classifier default old.json ratio:median:0.7:4.08 ...]
                                    [--planning] [--reading contact-trace]

A classifier is a preset, a JSON file, or ``ratio:POOLING:Q:TAU``: the ratio classifier
with thresholds (q_1, tau_1) pooled by POOLING (mean or median), uncalibrated (no
Brier score).

Example: the previous round's classifier on this round's maps:

    git show HEAD~1:src/swarmtopo/data/classifier-default.json > old.json
    python lab/reclassify.py --store bench.duckdb --classifier default old.json
"""

from __future__ import annotations

import argparse

from swarmtopo.readers.registry import load_classifier
from swarmtopo.readers.ratio import RatioClassifier, RatioThresholds
from swarmtopo.experiments.accuracy import (CELLS, PIPELINES, PLANNING_CELLS, accuracy_table, beta1_misses,
                                            most_windows, outcomes, reading_name, reliability,
                                            reliability_bin_lines)
from swarmtopo.experiments.store import read_jobs
from swarmtopo.experiments.sweep import INPUTS, map_input

COLUMNS = ("key", "config", "replicate", "diagrams", "error", "est_betti0", "confidence_betti0", "true_betti0", "true_betti1",
           "t_total")
"""The columns the verdict needs (``accuracy.outcomes``)."""


def default_rows(store: str, reading: str = "log") -> list[dict]:
    """The store's reporting rows of the default pipeline (its ``classifier`` is "default",
    reading the whole log folder, or only its encounters with ``reading="contact-trace"``;
    not the planning grid's), sorted by key."""
    return [row for row in read_jobs(store, columns=COLUMNS, sweep=f"accuracy-reporting-{reading_name(reading)}")
            if row["config"]["map"].get("classifier") == PIPELINES["default"]["classifier"]
            and map_input(row["config"]["map"]) == reading]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", required=True, help="a store written by swarmtopo bench accuracy")
    parser.add_argument("--classifier", nargs="+", default=["default"],
                        help="classifier presets or JSON files (default: the shipped one)")
    parser.add_argument("--planning", action="store_true", help="read the planning grid's maps (the full run's)")
    parser.add_argument("--reading", choices=INPUTS, default="log",
                        help="the maps of the cases read as log folders (the bench's) or as contact traces "
                             "(encounters only: lab/trace_accuracy.py's store)")
    args = parser.parse_args()
    if args.planning:
        rows = read_jobs(args.store, columns=COLUMNS, sweep=f"accuracy-planning-{reading_name(args.reading)}")
        print(f"{args.store}: {len(rows)} planning-grid maps ({args.reading})")
        for name in args.classifier:
            print(planning_summary(name, outcomes(rows, _classifier(name), cells=PLANNING_CELLS)))
        return
    rows = default_rows(args.store, args.reading)
    print(f"{args.store}: {len(rows)} default-pipeline maps ({args.reading}), at most {most_windows(rows)} windows per region")
    for name in args.classifier:
        records = outcomes(rows, _classifier(name))
        table, rel = accuracy_table(records), reliability(records, 1)
        cells = ", ".join(f"{table['cells'][c.name].right}" for c in CELLS)
        print(f"{name}: {table['overall'].right}/{table['overall'].total} exact; per cell [{cells}]; "
              f"held-out family {table['held_out'].right}/{table['held_out'].total}; "
              + (f"Brier {rel['brier']:.4f} (constant {rel['brier_constant']:.4f})" if rel["maps"] else "uncalibrated"))
        print("  " + _misses(records))


def _classifier(name: str):
    """A preset or JSON file (``load_classifier``), or ``ratio:POOLING:Q:TAU``."""
    if name.startswith("ratio:"):
        _, pooling, q, tau = name.split(":")
        return RatioClassifier.from_thresholds({1: RatioThresholds(float(q), float(tau))}, pooling=pooling)
    return load_classifier(name)


def planning_summary(name: str, records: list[dict]) -> str:
    """The beta_1 confidence on the planning grid: reliability, per swarm size, confident misses."""
    rel = reliability(records, 1)
    if not rel["maps"]:
        return f"{name}: uncalibrated"
    lines = [f"{name}: {sum(r['right'] for r in records)}/{len(records)} exact; beta_1 confidence on {rel['maps']} "
             f"maps: Brier {rel['brier']:.4f} (constant {rel['brier_constant']:.4f})"]
    lines += reliability_bin_lines(rel)
    rated = [r for r in records if r["confidence_betti1"] is not None]
    for agents in sorted({r["agents"] for r in rated}):
        mine = [r for r in rated if r["agents"] == agents]
        wrong = [r["confidence_betti1"] for r in mine if not r["betti1_right"]]
        lines.append(f"  {agents} agents: {len(mine)} maps, said {sum(r['confidence_betti1'] for r in mine) / len(mine):.2f}, "
                     f"right {sum(r['betti1_right'] for r in mine) / len(mine):.2f}"
                     + (f", wrong maps said {sum(wrong) / len(wrong):.2f}" if wrong else ""))
    sure = [r for r in rated if not r["betti1_right"] and r["confidence_betti1"] >= 0.95]
    lines.append("  wrong at 0.95 or more: " + (", ".join(
        f"{r['agents']} x {r['duration']:g} s {r['true_betti1']}->{r['est_betti1']} ({r['confidence_betti1']:.3f})"
        for r in sure) or "none"))
    return "\n".join(lines)


def _group(record: dict) -> str:
    """A record's budget ("200 x 30 s"), or "two rooms"."""
    cell = record["cell"]
    return "two rooms" if cell.startswith("two rooms") else cell.split(", ", 1)[1]


def _misses(records: list[dict]) -> str:
    """Per group: wrong maps with beta_1 too high / too low, held-out family right / all;
    then the wrong maps' beta_1 confidence range."""
    parts = []
    for group in dict.fromkeys(_group({"cell": cell.name}) for cell in CELLS):
        mine = [r for r in records if _group(r) == group]
        too_many, too_few = beta1_misses(mine)
        held = [r for r in mine if r["held_out"]]
        parts.append(f"{group}: {too_many} too many / {too_few} too few holes, held-out "
                     f"{sum(r['right'] for r in held)}/{len(held)}")
    confidences = sorted(r["confidence_betti1"] for r in records
                         if not r["right"] and r["confidence_betti1"] is not None)
    if confidences:
        parts.append(f"wrong maps' beta_1 confidence {confidences[0]:.2f}-{confidences[-1]:.2f}, "
                     f"{sum(c >= 0.8 for c in confidences)} of {len(confidences)} at 0.8 or more")
    return "; ".join(parts)


if __name__ == "__main__":
    main()
