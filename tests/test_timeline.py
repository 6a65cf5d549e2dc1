"""The map's timeline: sliding windows, segments and change points."""

import json

import numpy as np
import pytest
from hypothesis import given, strategies as st

from swarmtopo.changing import changing_arena
from swarmtopo.experiments.timeline import score, table, true_changes
from swarmtopo.log import EncounterLog
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.pipeline.timeline import TimelineWindow, build_timeline, date_split, segment
from swarmtopo.sim import simulate
from swarmtopo.viz.summary import map_json, timeline_json


def _cost(values, cuts, penalty):
    return sum(sum(v != u for v in values[i:j]) for i, j, u in cuts) + penalty * (len(cuts) - 1)


def _brute_force(values, penalty):
    """The least cost over every cut of ``values`` into segments, each at its best value."""
    k = len(values)
    best = np.inf
    for mask in range(2 ** (k - 1)):
        bounds = [0] + [i + 1 for i in range(k - 1) if mask >> i & 1] + [k]
        cuts = [(i, j, max(set(values[i:j]), key=lambda u: (values[i:j].count(u), -u)))
                for i, j in zip(bounds[:-1], bounds[1:])]
        best = min(best, _cost(values, cuts, penalty))
    return best


@given(st.lists(st.integers(0, 3), min_size=1, max_size=10), st.sampled_from([0.5, 1.5, 2.5, 4.0]))
def test_segment_is_optimal_against_every_cut(values, penalty):
    cuts = segment(values, penalty)
    assert cuts[0][0] == 0 and cuts[-1][1] == len(values)
    assert all(a[1] == b[0] for a, b in zip(cuts[:-1], cuts[1:]))
    assert _cost(values, cuts, penalty) == pytest.approx(_brute_force(values, penalty))


@pytest.mark.parametrize("values, expected", [
    ([1, 1, 1, 1, 2, 2, 2, 2], [(0, 4, 1), (4, 8, 2)]),
    ([1, 1, 2, 1, 1, 1, 2, 1], [(0, 8, 1)]),  # isolated misreads: no change
    ([1, 1, 1, 1, 1, 2, 2], [(0, 7, 1)]),  # two windows at the end are not enough at 2.5
    ([1, 1, 1, 1, 1, 2, 2, 2], [(0, 5, 1), (5, 8, 2)]),  # three are
    ([2, 2, 2, 1, 1, 1, 1, 2, 2, 2], [(0, 10, 2)]),  # a run of 4 inside costs less than two changes
    ([2, 2, 2, 1, 1, 1, 1, 1, 1, 2, 2, 2], [(0, 3, 2), (3, 9, 1), (9, 12, 2)]),
])
def test_segment_hand_cases(values, expected):
    assert segment(values, 2.5) == expected


def _window(t0, t1, b0, b1, p=0.9, agents=None):
    return TimelineWindow(t0=t0, t1=t1, n_events=100, betti={0: b0, 1: b1}, confidence={0: 0.99, 1: p},
                          region_agents=agents or [])


def test_a_change_point_lies_between_the_last_old_window_and_the_first_new_one():
    windows = [_window(10.0 * k, 10.0 * k + 20, 1, 1 if k < 6 else 2, p=0.8 + 0.01 * k) for k in range(12)]
    tl = build_timeline(windows, 20.0, 10.0, {0: 1, 1: 2}, {0: 0.95, 1: 0.7})
    (change,) = tl.changes
    # last window reading 1 is [50, 70], first reading 2 is [60, 80]: interval [50, 80]
    assert (change.dim, change.before, change.after, change.lo, change.hi, change.t) == (1, 1, 2, 50.0, 80.0, 65.0)
    first, second = tl.segments[1]
    assert (first.value, first.t_from, first.t_until, first.windows) == (1, 0.0, 65.0, 6)
    assert (second.value, second.t_from, second.t_until, second.windows) == (2, 65.0, 130.0, 6)
    assert first.confidence == pytest.approx(np.median([0.8, 0.81, 0.82, 0.83, 0.84, 0.85]))
    assert change.confidence == pytest.approx(first.confidence * second.confidence)
    assert tl.segments[0][0].value == 1 and tl.segments[0][0].confidence == 0.95  # no change: the map's own
    assert tl.summary() == "beta_1 = 1 until about 65 s, then 2"
    assert list(tl.table()) == ["t0", "t1", "t", "n_events", "beta_0", "confidence_0", "beta_1", "confidence_1"]
    assert tl.table()["beta_1"].tolist() == [1] * 6 + [2] * 6
    # three windows on each side do not pay for a change point at the default penalty (3 windows)
    assert build_timeline(windows[3:-3], 20.0, 10.0, {0: 1, 1: 2}, {0: 0.95, 1: 0.7}).changes == []


def test_a_log_that_did_not_change_has_one_segment_per_dimension_and_no_change():
    windows = [_window(5.0 * k, 5.0 * k + 10, 1, [1, 2, 1, 1, 1, 1][k]) for k in range(6)]
    tl = build_timeline(windows, 10.0, 5.0, {0: 1, 1: 1}, {0: 0.9, 1: 0.8})
    assert tl.changes == [] and [len(s) for s in tl.segments.values()] == [1, 1]
    assert tl.summary() == "no change of the Betti numbers over 0-35 s (6 time windows)"
    assert json.loads(json.dumps(timeline_json(tl)))["changes"] == []


def test_a_split_is_dated_by_the_last_encounter_between_the_new_regions():
    # agents 0-2 left, 3-5 right; the last encounter across is at t = 33
    t = np.array([1.0, 5.0, 20.0, 33.0, 40.0, 41.0, 50.0])
    a = np.array([0, 0, 1, 2, 0, 3, 1])
    b = np.array([3, 1, 4, 5, 2, 4, 2])
    log = EncounterLog.from_records(t, a, b)
    last = _window(10.0, 40.0, 1, 0)
    first = _window(30.0, 60.0, 2, 0, agents=[np.array([0, 1, 2]), np.array([3, 4, 5])])
    assert date_split(log, last, first, split=True) == (33.0, 33.0, 60.0)
    # the same log read backwards in time is a merge: the first encounter across after 'last' starts
    merged = _window(10.0, 30.0, 2, 0, agents=[np.array([0, 1, 2]), np.array([3, 4, 5])])
    assert date_split(log, merged, _window(20.0, 50.0, 1, 0), split=False) == (20.0, 10.0, 20.0)


def test_scoring_against_the_true_timeline():
    truth = [{"from": 0.0, "until": 70.0, "beta_0": 1, "beta_1": 1},
             {"from": 70.0, "until": 150.0, "beta_0": 1, "beta_1": 2}]
    assert true_changes(truth) == [{"dimension": 1, "t": 70.0, "from": 1, "to": 2}]
    on_time = {"dimension": 1, "t": 80.0, "from": 1, "to": 2, "interval": [60.0, 90.0], "confidence": 0.8}
    late = {**on_time, "t": 90.0, "interval": [86.0, 95.0]}
    wrong_way = {**on_time, "from": 2, "to": 1}
    assert score(truth, [on_time]) == {"expected": 1, "found": 1, "within": 1, "errors": [10.0], "covered": 1,
                                       "false": 0}
    assert score(truth, [late, wrong_way]) == {"expected": 1, "found": 1, "within": 0, "errors": [20.0],
                                               "covered": 0, "false": 1}
    static = [{"from": 0.0, "until": 150.0, "beta_0": 1, "beta_1": 1}]
    records = [{"kind": "none", "cell": "static control, 300 agents", "agents": 300, "pooled_right": True,
                **score(static, [wrong_way])},
               {"kind": "none", "cell": "static control, 300 agents", "agents": 300, "pooled_right": False,
                **score(static, [])},
               {"kind": "appear", "cell": "hole appears, 300 agents", "agents": 300, "pooled_right": False,
                **score(truth, [late])}]
    overall = table(records)["overall"]
    assert overall["false_alarms"]["rate"] == 0.5 and overall["found_within"]["rate"] == 0.0
    assert overall["found"]["rate"] == 1.0 and overall["error_median"] == 20.0


@pytest.fixture(scope="module")
def appearing_log():
    arena = changing_arena("appear", 1, 50.0, rng=11)
    return simulate(arena, 300, 110.0, rng=2).log


def test_the_timeline_finds_a_hole_that_appears_and_leaves_the_rest_of_the_map_unchanged(appearing_log):
    config = MapConfig(embed_dim=3, cycles=True)
    with_timeline = map_encounters(appearing_log, config)
    (change,) = with_timeline.timeline.changes
    assert (change.dim, change.before, change.after) == (1, 1, 2)
    assert abs(change.t - 50.0) <= 15 and change.lo <= 50.0 <= change.hi
    assert any("the Betti numbers changed during the log" in w for w in with_timeline.warnings)
    without = map_encounters(appearing_log, MapConfig(embed_dim=3, cycles=True, timeline_length=float("inf")))
    assert without.timeline.windows == [] and without.timeline.changes == []
    assert "no timeline" in without.timeline.note
    a, b = map_json(with_timeline), map_json(without)
    for key in ("betti", "confidence", "diagrams", "regions", "beta0_evidence"):
        assert a[key] == b[key], key  # the timeline draws after everything else: the map is the same
    doc = json.loads(json.dumps(a))
    assert doc["timeline"]["changes"][0]["dimension"] == 1 and len(doc["timeline"]["windows"]) >= 10


def test_a_static_log_has_no_change_point():
    arena = changing_arena("none", 2, 0.0, rng=3)
    log = simulate(arena, 300, 100.0, rng=4).log
    tmap = map_encounters(log, MapConfig(embed_dim=0, cycles=False))
    assert tmap.timeline.changes == [] and len(tmap.timeline.windows) >= 10


def test_a_grid_of_changing_arenas_runs_and_stores_the_true_and_found_timelines(tmp_path):
    from swarmtopo.errors import InputError
    from swarmtopo.experiments.grid import expand_grid
    from swarmtopo.experiments.store import ResultStore, read_jobs
    from swarmtopo.experiments.sweep import run_job

    document = {"arena": {"generator": "changing", "change": ["appear", "none"], "holes": 0, "change_time": 20.0},
                "swarm": {"agents": 150, "duration": 40.0}, "map": {"landmarks": 60}}
    jobs = expand_grid(document).jobs
    assert [job.config["arena"].get("change_time") for job in jobs] == [20.0, None]  # unused by "none": dropped
    with pytest.raises(InputError, match=r"change_time = 50.0.*before the end of the log \(duration = 40\)"):
        expand_grid({**document, "arena": {**document["arena"], "change_time": 50.0}})
    rows = [run_job(job, keep="windows") for job in jobs]
    assert [r["status"] for r in rows] == ["ok", "ok"]
    appear, static = (r["timeline"] for r in rows)
    assert appear["truth"] == [{"from": 0.0, "until": 20.0, "beta_0": 1, "beta_1": 0},
                               {"from": 20.0, "until": 40.0, "beta_0": 1, "beta_1": 1}]
    assert static["truth"] == [{"from": 0.0, "until": 40.0, "beta_0": 1, "beta_1": 0}]
    assert all({"changes", "segments", "windows"} <= set(t) for t in (appear, static))
    ResultStore(tmp_path / "s.duckdb").write(rows)
    stored = {r["key"]: r for r in read_jobs(tmp_path / "s.duckdb")}
    assert [stored[r["key"]]["timeline"] for r in rows] == [appear, static]
    assert [stored[r["key"]]["change"] for r in rows] == ["appear", "none"]


def test_a_store_from_before_the_timeline_gets_its_columns_and_keeps_its_rows(tmp_path):
    import duckdb

    from swarmtopo.experiments.store import NEW_COLUMNS, ResultStore, read_jobs

    path = tmp_path / "old.duckdb"
    ResultStore(path)
    with duckdb.connect(str(path)) as db:
        for name in NEW_COLUMNS:
            db.execute(f'ALTER TABLE jobs DROP COLUMN "{name}"')
        db.execute("INSERT INTO jobs (key, sweep, replicate, salt, seed, config, status) "
                   "VALUES ('k', 's', 0, '', 1, '{}', 'ok')")
    with pytest.raises(Exception, match="another swarmtopo version"):
        read_jobs(path)  # read-only: not changed, said
    ResultStore(path)  # a sweep opening it adds them
    [row] = read_jobs(path)
    assert row["key"] == "k" and row["timeline"] is None and row["change"] is None


def test_a_confidence_the_map_withholds_the_timeline_withholds_too():
    windows = [_window(10.0 * k, 10.0 * k + 20, 1, 1 if k < 6 else 2) for k in range(12)]
    tl = build_timeline(windows, 20.0, 10.0, {0: 1, 1: 2}, {0: 0.95, 1: None})  # e.g. a fixed --landmarks L
    assert all(w.confidence[1] is None for w in tl.windows) and all(w.confidence[0] == 0.99 for w in tl.windows)
    (change,) = tl.changes
    assert change.confidence is None and all(s.confidence is None for s in tl.segments[1])


def test_bench_timeline_writes_and_prints_its_report(tmp_path, monkeypatch):
    from conftest import run_cli

    import swarmtopo.experiments.timeline as bench

    truth = [{"from": 0.0, "until": 70.0, "beta_0": 1, "beta_1": 1},
             {"from": 70.0, "until": 150.0, "beta_0": 1, "beta_1": 2}]
    found = {"dimension": 1, "t": 75.0, "from": 1, "to": 2, "interval": [60.0, 90.0], "confidence": 0.8}
    record = {"kind": "appear", "cell": "hole appears, 300 agents", "agents": 300, "pooled_right": False,
              "status": "ok", **score(truth, [found])}

    def run_benchmark(store, *, quick, scheduler, workers, progress):
        progress(1, 1, 0)
        return {"suite": bench.SUITE, "split": "reporting", "cases_per_cell": 1, "within_seconds": bench.WITHIN,
                "seconds": 1.0, "jobs_run": 1, "workers": 1, "table": table([record]), "records": [record]}

    monkeypatch.setattr(bench, "run_benchmark", run_benchmark)
    done = run_cli("bench", "timeline", "--store", str(tmp_path / "t.duckdb"), "--out", str(tmp_path / "out"))
    assert done.returncode == 0, done.stderr
    assert "| hole appears, 300 agents | 1 | 100 % (1/1) | 100 % (1/1) | 5.0 s |" in done.stdout
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["timeline.json", "timeline.md"]
    doc = json.loads((tmp_path / "out" / "timeline.json").read_text())
    assert doc["table"]["overall"]["found_within"]["rate"] == 1.0 and doc["wall_seconds"] >= 0
