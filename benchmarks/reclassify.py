"""The accuracy bench's stored maps read by other classifiers: a classifier's effect apart from the maps'.

``swarmtopo bench accuracy`` stores every default-pipeline map's per-window diagrams, so
the same maps can be read again by another classifier without mapping anything.  For
each classifier given, prints exact (beta_0, beta_1) over the reporting maps, per cell
and for the held-out family, with the Brier score of its beta_1 confidence.  Reading a
store made by an older swarmtopo (other grid columns) works too: only the columns the
verdict needs are read, so two rounds' maps can be compared under one classifier.

    python benchmarks/reclassify.py --store bench.duckdb [--classifier default old.json ...]

Example: the previous round's classifier on this round's maps:

    git show HEAD~1:src/swarmtopo/data/classifier-default.json > old.json
    python benchmarks/reclassify.py --store bench.duckdb --classifier default old.json
"""

from __future__ import annotations

import argparse
import json

import duckdb

from swarmtopo.classify import load_classifier
from swarmtopo.experiments.accuracy import CELLS, PIPELINES, accuracy_table, outcomes, reliability

COLUMNS = ("key", "config", "replicate", "diagrams", "error", "est_betti0", "true_betti0", "true_betti1", "t_total")


def default_rows(store: str) -> list[dict]:
    """The store's rows of the default pipeline (its ``classifier`` is "default"), sorted by key."""
    db = duckdb.connect(store, read_only=True)
    try:
        rows = db.execute(f"SELECT {', '.join(COLUMNS)} FROM jobs ORDER BY key").fetchall()
    finally:
        db.close()
    parsed = []
    for values in rows:
        row = dict(zip(COLUMNS, values))
        row["config"] = json.loads(row["config"])
        row["diagrams"] = json.loads(row["diagrams"]) if row["diagrams"] else None
        if row["config"]["map"].get("classifier") == PIPELINES["default"]["classifier"]:
            parsed.append(row)
    return parsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", required=True, help="a store written by swarmtopo bench accuracy")
    parser.add_argument("--classifier", nargs="+", default=["default"],
                        help="classifier presets or JSON files (default: the shipped one)")
    args = parser.parse_args()
    rows = default_rows(args.store)
    print(f"{args.store}: {len(rows)} default-pipeline maps")
    for name in args.classifier:
        records = outcomes(rows, load_classifier(name))
        table, rel = accuracy_table(records), reliability(records, 1)
        cells = ", ".join(f"{table['cells'][c.name].right}" for c in CELLS)
        print(f"{name}: {table['overall'].right}/{table['overall'].total} exact; per cell [{cells}]; "
              f"held-out family {table['held_out'].right}/{table['held_out'].total}; "
              f"Brier {rel['brier']:.4f} (constant {rel['brier_constant']:.4f})")


if __name__ == "__main__":
    main()
