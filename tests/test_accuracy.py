"""Accuracy benchmark: the frozen suite, the seed split, the table.

The regression slice (26 maps, statistical) is a benchmark script,
``benchmarks/bench_accuracy_slice.py``; the suite pins small maps exactly instead
(``tests/test_golden.py``)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from swarmtopo.readers.registry import load_classifier
from swarmtopo.errors import SwarmtopoError
from swarmtopo.experiments import accuracy as acc
from swarmtopo.experiments.grid import canonical_json
from swarmtopo.experiments.store import decode_regions
from swarmtopo.experiments.sweep import run_job

ROOT = Path(__file__).resolve().parent.parent
FROZEN_DIGEST = "6e330f11fbcbae30"
"""Digest of the reporting cases (arena, swarm, salt, replicate, case seed) of suite swarmtopo-accuracy/1."""


def test_reporting_seeds_are_closed_inside_a_tuning_session():
    with acc.tuning_session():
        acc.tuning_jobs(acc.PIPELINES, per_cell=1)
        with pytest.raises(SwarmtopoError, match="closed to tuning code"):
            acc.reporting_jobs(per_cell=1)
    assert acc.reporting_jobs(per_cell=1)  # open again outside


def test_tuning_and_reporting_never_share_a_case_and_tuning_never_sees_the_held_out_family():
    # every draw a case may take (attempt 0 and each replacement), so whichever one
    # building the arena keeps: seeds apart, and no tuning draw of the held-out family
    attempts = range(acc.MAX_ATTEMPTS)
    tuning_seeds = {acc.case_seed(c, "tuning", i, a) for c in acc.CELLS for i in range(acc.TUNING_PER_CELL)
                    for a in attempts}
    reporting_seeds = {acc.case_seed(c, "reporting", i, a) for c in acc.CELLS for i in range(acc.REPORTING_PER_CELL)
                       for a in attempts}
    assert not tuning_seeds & reporting_seeds
    assert not any(acc.has_held_out_family({"arena": acc.case_arena(c, "tuning", i, a)}) for c in acc.CELLS
                   for i in range(acc.TUNING_PER_CELL) for a in attempts)
    # the jobs are those draws (the first cases of each cell built: building is the slow part)
    tuning = acc.tuning_jobs(acc.PIPELINES, per_cell=4)
    reporting = acc.reporting_jobs()
    assert {j.case_seed for j in tuning} <= tuning_seeds and {j.case_seed for j in reporting} <= reporting_seeds
    assert not {j.key for j in tuning} & {j.key for j in reporting}
    assert not any(acc.has_held_out_family(j.config) for j in tuning)
    held_out = [j for j in reporting if acc.has_held_out_family(j.config)]
    # each case with holes draws its family from 5: about a fifth hold the held-out one
    assert 0.1 < len(held_out) / len(reporting) < 0.3


def test_suite_is_frozen():
    """Any change to the suite's cases changes this digest: make it a new SUITE instead."""
    import hashlib
    cases = [{k: j.config[k] for k in ("arena", "swarm")} | {"salt": j.salt, "replicate": j.replicate,
                                                             "case_seed": j.case_seed}
             for j in acc.reporting_jobs(pipelines={"default": acc.PIPELINES["default"]})]
    digest = hashlib.sha256(canonical_json(cases).encode()).hexdigest()[:16]
    assert digest == FROZEN_DIGEST


def test_cases_cover_the_cells_draws():
    reporting = acc.reporting_jobs(pipelines={"default": acc.PIPELINES["default"]})
    assert len(reporting) == len(acc.CELLS) * acc.REPORTING_PER_CELL
    scales = np.array([j.config["arena"]["scale"] for j in reporting])
    assert acc.SCALE_RANGE[0] <= scales.min() and scales.max() <= acc.SCALE_RANGE[1]
    outers = {j.config["arena"].get("outer") for j in reporting} - {None}
    assert outers == {"square", "rectangle", "polygon"}
    assert {acc.cell_of(j.config) for j in reporting} == {c.name for c in acc.CELLS}


def test_planning_grid_has_cases_of_its_own_and_varies_swarm_size_and_duration_apart():
    planning = acc.planning_jobs()
    assert len(planning) == len(acc.PLANNING_CELLS) * acc.PLANNING_PER_CELL
    seeds = {j.case_seed for j in planning}
    suite_seeds = {acc.case_seed(c, split, i) for c in acc.CELLS for split, n in
                   (("tuning", acc.TUNING_PER_CELL), ("reporting", acc.REPORTING_PER_CELL)) for i in range(n)}
    assert len(seeds) == len(planning) and not seeds & suite_seeds
    assert {j.config["map"]["classifier"] for j in planning} == {"default"}
    scales = np.array([j.config["arena"]["scale"] for j in planning])
    assert acc.PLANNING_SCALE_RANGE[0] <= scales.min() and scales.max() <= acc.PLANNING_SCALE_RANGE[1]
    assert scales.max() > acc.SCALE_RANGE[1]  # arenas beyond the suite's
    # every swarm size is run at every duration (the suite's budgets tie them together)
    budgets = {(j.config["swarm"]["agents"], j.config["swarm"]["duration"]) for j in planning}
    assert budgets == set(acc.PLANNING_BUDGETS) and len({n for n, _ in budgets}) * len({t for _, t in budgets}) == len(budgets)
    # a planning case of the suite's smallest budget is named by its own cell, not the suite's
    small = next(j for j in planning if (j.config["swarm"]["agents"], j.config["swarm"]["duration"]) == (200, 30.0))
    assert acc.cell_of(small.config, acc.PLANNING_CELLS).startswith("planning: ")
    assert not acc.cell_of(small.config).startswith("planning")  # the default cells are the suite's


def test_calibration_grid_is_the_planning_grid_with_seeds_of_its_own_open_to_tuning_code():
    with acc.tuning_session():
        calibration = acc.calibration_jobs()
    planning = acc.planning_jobs()
    assert len(calibration) == len(acc.PLANNING_CELLS) * acc.CALIBRATION_PER_CELL
    assert {j.sweep for j in calibration} == {"accuracy-calibration-default"}
    seeds = {j.case_seed for j in calibration}
    suite_seeds = {acc.case_seed(c, split, i) for c in acc.CELLS for split, n in
                   (("tuning", acc.TUNING_PER_CELL), ("reporting", acc.REPORTING_PER_CELL)) for i in range(n)}
    assert len(seeds) == len(calibration) and not seeds & suite_seeds and not seeds & {j.case_seed for j in planning}
    # the same cells and pipeline as the planning grid, so the grid checks the confidence where it was fitted
    assert sorted(acc.cell_of(j.config, acc.PLANNING_CELLS) for j in calibration) == sorted(
        acc.cell_of(j.config, acc.PLANNING_CELLS) for j in planning)
    assert {canonical_json(j.config["map"]) for j in calibration} == {canonical_json(j.config["map"]) for j in planning}


def test_grids_read_as_contact_traces_are_the_same_cases_with_encounters_only():
    with acc.tuning_session():
        calibration = acc.calibration_jobs()
        traces = acc.calibration_jobs(reading="contact-trace")
    for grid, read in ((calibration, traces), (acc.planning_jobs(), acc.planning_jobs(reading="contact-trace"))):
        assert [(j.case_seed, j.config["arena"], j.config["swarm"]) for j in read] == [
            (j.case_seed, j.config["arena"], j.config["swarm"]) for j in grid]
        assert {j.config["map"].get("input") for j in read} == {"contact-trace"}
        assert {j.config["map"].get("input") for j in grid} == {None}
        assert not {j.key for j in read} & {j.key for j in grid}
        assert {j.config["map"]["classifier"] for j in read} == {"default"}  # the trace classifier is chosen by map
    assert {j.sweep for j in traces} == {"accuracy-calibration-contact-trace"}
    assert [j.key for j in acc.planning_jobs(reading="log")] == [j.key for j in acc.planning_jobs()]
    with pytest.raises(SwarmtopoError, match="no reading 'whole log'"):
        acc.planning_jobs(reading="whole log")


def test_table_and_reliability_hand_computed():
    records = [{"cell": acc.CELLS[0].name, "held_out": False, "right": True, "betti1_right": True,
                "confidence_betti1": 0.9} for _ in range(3)]
    records.append({"cell": acc.CELLS[0].name, "held_out": True, "right": False, "betti1_right": False,
                    "confidence_betti1": 0.1})
    table = acc.accuracy_table(records)
    assert (table["overall"].right, table["overall"].total) == (3, 4)
    assert (table["held_out"].right, table["held_out"].total) == (0, 1)
    assert table["cells"][acc.CELLS[1].name].total == 0
    rel = acc.reliability(records, 1)
    # Brier: 3 x 0.1^2 + 0.1^2 over 4 = 0.01; constant 0.75: (3 x 0.25^2 + 0.75^2) / 4 = 0.1875
    assert rel["brier"] == pytest.approx(0.01) and rel["brier_constant"] == pytest.approx(0.1875)
    assert [(b["maps"], b["fraction_right"]) for b in rel["bins"]] == [(1, 0.0), (3, 1.0)]
    assert [(b["low"], b["high"]) for b in rel["bins"]] == [(0.0, 0.5), (0.9, 0.95)]  # narrow bins near 1
    lo, hi = rel["brier_gain95"]
    assert lo <= 0.1875 - 0.01 <= hi


def test_outcomes_read_a_two_region_map_by_the_classifiers_power_of_the_product():
    from swarmtopo.topology.persistence import Diagram
    from swarmtopo.readers.base import vote

    def region(long_bar):  # three windows, ten noise loops each, and one long loop or none
        rng = np.random.default_rng(int(long_bar))
        windows = []
        for _ in range(3):
            h1 = [[b, b + rng.uniform(0.5, 1.5)] for b in rng.uniform(1, 2, 10)] + ([[1.0, 11.0]] if long_bar else [])
            windows.append(Diagram(pairs=(np.array([[0.0, np.inf]]), np.array(h1)), backend="test"))
        return windows

    regions = [region(True), region(False)]
    row = {"config": {"arena": {"generator": "two_rooms", "holes": 1, "shapes": ["square"], "scale": 1.0},
                      "swarm": {"agents": 300, "duration": 40.0}},
           "est_betti0": 2, "true_betti0": 2, "true_betti1": 1, "error": None, "confidence_betti0": 0.99,
           "replicate": 0, "t_total": 1.0,
           "diagrams": [{"windows": [{"diagram": d} for d in windows]} for windows in regions]}
    classifier = load_classifier("default")
    [record] = acc.outcomes([row], classifier)
    confidences = [classifier.region_confidence(windows, vote(classifier, windows))[1] for windows in regions]
    a = classifier.calibration_["1"]["regions_exponent"]
    assert record["est_betti1"] == 1 and record["right"]
    assert record["confidence_betti1"] == pytest.approx(np.prod(confidences) ** a)
    assert record["confidence_betti1"] == pytest.approx(classifier.map_confidence(confidences))
    assert record["confidence_betti1"] > np.prod(confidences)  # 0 < a < 1


def test_brier_gain_interval_separates_a_sharp_confidence_from_the_constant():
    y = np.r_[np.ones(190), np.zeros(10)]
    # a confidence that knows which maps are wrong beats the constant in every resample
    lo, hi = acc.brier_gain_interval(np.where(y == 1, 0.95, 0.3), y)
    assert 0 < lo < hi
    # the constant itself: each resample's own rate is at least as good, so the gain is <= 0
    lo, hi = acc.brier_gain_interval(np.full(200, y.mean()), y)
    assert lo < 0 and hi <= 1e-15
    assert acc.brier_gain_interval(np.array([0.9]), np.array([1.0])) is None  # one map: no interval
    # per resample: the gain of a literal loop over the same resampled indices
    p = np.random.default_rng(1).uniform(0.5, 1, 200)
    rows = np.random.default_rng(2).integers(0, 200, (5, 200))
    literal = [np.mean((y[r].mean() - y[r]) ** 2) - np.mean((p[r] - y[r]) ** 2) for r in rows]
    np.testing.assert_allclose(acc.brier_gain(p[rows], y[rows]), literal)


@pytest.mark.slow
def test_benchmark_runs_both_pipelines_on_dask_and_renders_its_table(tmp_path):
    cells = (acc.CELLS[0], acc.CELLS[-1])  # 0 holes and two rooms, smallest budgets
    summary = acc.run_benchmark(tmp_path / "acc.duckdb", per_cell=1, cells=cells, workers=1)
    assert summary["maps"] == 2 * len(cells) and summary["jobs_run"] == 2 * len(cells)
    assert set(summary["pipelines"]) == {"default", "paper", "paper-theta"}
    for name, result in summary["pipelines"].items():
        table = result["table"]
        assert table["overall"]["total"] == len(cells)
        assert sum(c["total"] for c in table["cells"].values()) == len(cells)
    assert len(summary["records"]) == len(cells)
    assert {r["area"] for r in summary["records"]} == {acc.case_area(j.config) for j in
                                                       acc.reporting_jobs(1, {"d": acc.PIPELINES["default"]}, cells)}
    assert summary["planning"] == []
    text = acc.markdown(summary, "swarmtopo bench accuracy --test")
    assert "swarmtopo bench accuracy --test" in text and cells[0].name in text and "Planning grid" not in text
    # with the planning grid (one of its cells): its maps under the default pipeline only,
    # the reporting maps resumed, the grid's table rendered
    planning_cells = (acc.PLANNING_CELLS[4],)  # 0 holes, 200 x 15 s
    again = acc.run_benchmark(tmp_path / "acc.duckdb", per_cell=1, cells=cells, workers=1, planning_per_cell=1,
                              planning_cells=planning_cells)
    assert again["jobs_run"] == 1 and again["records"] == summary["records"]  # resumed: only the grid's map runs
    assert [(r["agents"], r["duration"], r["true_betti1"]) for r in again["planning"]] == [(200, 15.0, 0)]
    assert "| 200 x 15 s | " in acc.markdown(again, "swarmtopo bench accuracy --test")
    # lab/reclassify.py reads the same default-pipeline maps back from the store's
    # columns: under the shipped classifier they give the bench's own records
    spec = importlib.util.spec_from_file_location("reclassify", ROOT / "lab" / "reclassify.py")
    reclassify = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(reclassify)
    rows = reclassify.default_rows(str(tmp_path / "acc.duckdb"))
    assert len(rows) == len(cells)
    assert acc.outcomes(rows, load_classifier("default")) == summary["records"]
    assert reclassify.default_rows(str(tmp_path / "acc.duckdb"), "contact-trace") == []  # no map read as a trace
    (grid_map,) = again["planning"]
    grid_text = reclassify.planning_summary("default", again["planning"])
    assert f"default: {int(grid_map['right'])}/1 exact" in grid_text
    assert (f"  200 agents: 1 maps, said {grid_map['confidence_betti1']:.2f}, "
            f"right {float(grid_map['betti1_right']):.2f}") in grid_text


def test_contact_trace_keeps_only_the_encounters_and_maps_from_them():
    from swarmtopo.arena import default_arena
    from swarmtopo.experiments.sweep import contact_trace
    from swarmtopo.pipeline.settings import HOP_GAP_FACTOR, hop_cost
    from swarmtopo.sim import simulate

    log = simulate(default_arena(), 60, 10.0, static_fraction=0.2, rng=1).log
    trace = contact_trace(log)
    for name in ("t", "a", "b", "agent_ids"):
        assert np.array_equal(getattr(trace, name), getattr(log, name))
    assert len(log.status_t) and len(log.static_agent) and not len(trace.status_t) and not len(trace.static_agent)
    assert {"r_d", "v_c", "dt", "simulation"} <= set(log.meta) and not {"r_d", "v_c", "v_p", "dt", "simulation",
                                                                       "seed"} & set(trace.meta)
    assert hop_cost(trace, None)[1].startswith(f"{HOP_GAP_FACTOR:g} x mean time")
    trace_pipeline = acc.TRACE_PIPELINE
    (job,) = acc.reporting_jobs(1, pipelines={"trace": trace_pipeline}, cells=acc.CELLS[3:4])
    (default_job,) = acc.reporting_jobs(1, pipelines={"default": acc.PIPELINES["default"]}, cells=acc.CELLS[3:4])
    row, default_row = run_job(job), run_job(default_job)
    assert row["n_events"] == default_row["n_events"] and row["error"] is None  # the same case, simulated alike
    assert row["diagrams"] != default_row["diagrams"]  # mapped with other weights (h from the data, no wall following)
    regions, default_regions = decode_regions(row["diagrams"]), decode_regions(default_row["diagrams"])
    # classifier "default" is map's: the trace classifier for a trace, and the bands each was fitted with
    assert (row["versions"]["classifier"], default_row["versions"]["classifier"]) == ("trace", "default")
    assert {w["band"] for r in regions for w in r["windows"]} == set(load_classifier("trace").landmark_bands)
    assert {w["band"] for r in default_regions for w in r["windows"]} == set(acc.PIPELINES["default"]["landmark_bands"])
    bogus = acc.reporting_jobs(1, pipelines={"bogus": {**trace_pipeline, "input": "video"}}, cells=acc.CELLS[3:4])
    with pytest.raises(ValueError, match="map input 'video' is not one of"):
        run_job(bogus[0])


def test_benchmark_pipelines_map_as_their_classifiers_were_fitted():
    """The default pipeline's bands are the ones the shipped default classifier was fitted
    with (what ``map`` uses when none are given); contact traces keep the trace classifier's."""
    assert load_classifier("default").landmark_bands == tuple(acc.PIPELINES["default"]["landmark_bands"])
    assert load_classifier("default").provenance_["pipeline"]["landmark_bands"] == acc.PIPELINES["default"]["landmark_bands"]
    assert "landmark_bands" not in acc.TRACE_PIPELINE and load_classifier("trace").landmark_bands == (1.0,)
    assert "landmark_bands" not in acc.PIPELINES["paper"] and load_classifier("paper").landmark_bands == (1.0,)


def test_most_windows_is_the_largest_region_of_the_stored_maps():
    rows = [{"diagrams": [{"windows": [{}] * 3}, {"windows": [{}] * 5}]},
            {"diagrams": None, "error": "too little data"}, {"diagrams": [{"windows": [{}] * 4}]}]
    assert acc.most_windows(rows) == 5
    assert acc.most_windows([]) == 0 and acc.most_windows(rows[1:2]) == 0


def test_tuning_arena_is_the_tuning_case_built():
    cell = next(c for c in acc.CELLS if c.name.startswith("2 holes"))
    table, seed, arena, stream = acc.tuning_arena(cell, 3)
    with acc.tuning_session():
        assert (table, seed) == acc.case(cell, "tuning", 3)
    assert arena.betti == (1, 2) and table["holes"] == 2
    assert stream == acc.case_streams(seed)["simulation"]
