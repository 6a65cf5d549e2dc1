"""The paper's "clust" experiment at a tiny size: sweeps, fits and the table agree."""

import csv
import json

import numpy as np
import pytest

from swarmtopo.readers.paper import PAPER_THETA, betti_function
from swarmtopo.experiments.clust import DEFAULT_COLUMN, HOLES, SCALES, clust_sweeps, default_jobs
from swarmtopo.experiments.reproduce import reproduce
from swarmtopo.experiments.store import read_jobs


def test_sweeps_share_the_two_hole_scale_one_test_set_and_not_the_training_set():
    sweeps = clust_sweeps(runs=3)
    keys = {name: {j.key for j in s.jobs} for name, s in sweeps.items()}
    assert len(keys["train"]) == 3 and len(keys["scale"]) == 3 * len(SCALES) and len(keys["holes"]) == 3 * len(HOLES)
    assert len(keys["scale"] & keys["holes"]) == 3          # holes = 2 at scale 1, same salt
    assert not keys["train"] & (keys["scale"] | keys["holes"])
    # the default pipeline maps the same arenas and swarms: its jobs' arena and simulation streams are the paper's
    for paper, default in zip(sweeps["holes"].jobs, default_jobs(sweeps["holes"].jobs)):
        assert default.config["arena"] == paper.config["arena"] and default.config["map"]["classifier"] == "default"
        own, shared = paper.stream_seeds(), default.stream_seeds()
        assert (own["arena"], own["simulation"]) == (shared["arena"], shared["simulation"]) and default.key != paper.key


@pytest.mark.slow
def test_tiny_clust_table_matches_its_store(tmp_path):
    result = reproduce("clust", tmp_path, runs=2, workers=1)
    rows = list(csv.DictReader(open(result.table, encoding="utf-8")))
    assert len(rows) == 4 * (len(SCALES) + len(HOLES))      # grid, sigmoid, paper, default pipeline x test sets
    store = read_jobs(tmp_path / "clust.duckdb")
    assert len(store) == 2 + 2 * (2 * len(SCALES) + 2 * len(HOLES) - 2)
    assert (tmp_path / "clust.png").stat().st_size > 20_000
    summary = json.loads((tmp_path / "clust.json").read_text())["summary"]
    assert summary["winner"] in ("grid", "sigmoid")
    # the paper's row is its published Theta*, scored on the stored diagrams
    paper = {r["test_set"]: r for r in rows if r["classifier"] == "paper"}
    q, delta, tau = PAPER_THETA[1]
    for holes in HOLES:
        maps = [r for r in store if r["holes"] == holes and r["scale"] == 1.0 and r["salt"] == "clust-test"
                and r["error"] is None and not r["sweep"].endswith("-default")]
        estimates = [betti_function(r["diagrams"][0]["diagram"].lengths(1), q, delta, tau)
                     for r in maps]
        row = paper[f"holes={holes}"]
        assert int(row["maps"]) == len(maps)
        assert float(row["F"]) == pytest.approx(np.mean(np.abs(np.array(estimates) - holes)))
    # the default pipeline's row is its own maps' counts
    default = {r["test_set"]: r for r in rows if r["classifier"] == DEFAULT_COLUMN}
    for holes in HOLES:
        mine = [r for r in store if r["holes"] == holes and r["scale"] == 1.0 and r["sweep"].endswith("-default")
                and r["status"] == "ok"]
        assert int(default[f"holes={holes}"]["maps"]) == len(mine) > 0
        assert float(default[f"holes={holes}"]["F"]) == pytest.approx(np.mean([abs(r["est_betti1"] - holes)
                                                                               for r in mine]))
