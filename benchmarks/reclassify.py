"""The accuracy bench's stored maps read by other classifiers: a classifier's effect apart from the maps'.

``swarmtopo bench accuracy`` stores every default-pipeline map's per-window diagrams, so
the same maps can be read again by another classifier without mapping anything.  For
each classifier given, prints exact (beta_0, beta_1) over the reporting maps, per cell
and for the held-out family, with the Brier score of its beta_1 confidence; then per
budget (the two rooms on their own) the wrong maps counting too many and too few holes
and the held-out family's exact maps, and the range of the wrong maps' beta_1
confidence.  Reading a
store made by an older swarmtopo (other grid columns) works too: only the columns the
verdict needs are read, so two rounds' maps can be compared under one classifier.

    python benchmarks/reclassify.py --store bench.duckdb [--classifier default old.json ratio:median:0.7:4.08 ...]

A classifier is a preset, a JSON file, or ``ratio:POOLING:Q:TAU``: the ratio classifier
with thresholds (q_1, tau_1) pooled by POOLING (mean or median), uncalibrated (no
Brier score).

Example: the previous round's classifier on this round's maps:

    git show HEAD~1:src/swarmtopo/data/classifier-default.json > old.json
    python benchmarks/reclassify.py --store bench.duckdb --classifier default old.json
"""

from __future__ import annotations

import argparse

from swarmtopo.classify import load_classifier
from swarmtopo.ratio import RatioClassifier, RatioThresholds
from swarmtopo.experiments.accuracy import (CELLS, PIPELINES, accuracy_table, beta1_misses, most_windows, outcomes,
                                            reliability)
from swarmtopo.experiments.store import read_jobs
from swarmtopo.experiments.sweep import map_input

COLUMNS = ("key", "config", "replicate", "diagrams", "error", "est_betti0", "confidence_betti0", "true_betti0", "true_betti1",
           "t_total")
"""The columns the verdict needs (``accuracy.outcomes``)."""


def default_rows(store: str) -> list[dict]:
    """The store's reporting rows of the default pipeline (its ``classifier`` is "default",
    reading the whole log folder; not the planning grid's), sorted by key."""
    return [row for row in read_jobs(store, columns=COLUMNS, sweep="accuracy-reporting-default")
            if row["config"]["map"].get("classifier") == PIPELINES["default"]["classifier"]
            and map_input(row["config"]["map"]) == "log"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", required=True, help="a store written by swarmtopo bench accuracy")
    parser.add_argument("--classifier", nargs="+", default=["default"],
                        help="classifier presets or JSON files (default: the shipped one)")
    args = parser.parse_args()
    rows = default_rows(args.store)
    print(f"{args.store}: {len(rows)} default-pipeline maps, at most {most_windows(rows)} windows per region")
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
        return RatioClassifier({1: RatioThresholds(float(q), float(tau))}, pooling=pooling)
    return load_classifier(name)


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
