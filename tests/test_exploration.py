"""Beacon-led exploration: the leader's track, the leash, and the global map stitched from local maps."""

import json

import numpy as np
import pytest

from swarmtopo.arena import hall_arena, square_arena
from swarmtopo.beacon import BeaconTrack, long_axis_track, track_along
from swarmtopo.errors import InputError
from swarmtopo.experiments.exploration import CELLS, case_config, records, table
from swarmtopo.io import read_log, strip_ground_truth, write_log
from swarmtopo.io.beacons import read_beacon_path
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.pipeline.exploration import leader_speed, stitch
from swarmtopo.pipeline.result import TimelineWindow
from swarmtopo.sim import simulate
from swarmtopo.sim.leash import HEADING_ERROR
from swarmtopo.viz.summary import map_json


# -- the leader's track ----------------------------------------------------------------
def test_a_track_is_linear_between_rows_and_held_outside_them():
    track = BeaconTrack.from_columns([10.0, 20.0, 40.0], [0.0, 100.0, 100.0], [0.0, 0.0, 200.0])
    x, y = track.position([0.0, 15.0, 30.0, 99.0])
    assert x.tolist() == [0.0, 50.0, 100.0, 100.0] and y.tolist() == [0.0, 0.0, 100.0, 200.0]
    assert track.distance_travelled(15.0, 30.0) == pytest.approx(50.0 + 100.0)
    cut = track.between(15.0, 30.0)
    assert cut.t.tolist() == [15.0, 20.0, 30.0] and cut.x.tolist() == [50.0, 100.0, 100.0]
    assert cut.y.tolist() == [0.0, 0.0, 100.0] and track.between(0.0, 5.0).x.tolist() == [0.0, 0.0]


@pytest.mark.parametrize("t, x, column, row", [
    ([0.0, 5.0, 5.0], [0, 1, 2], "t", 3),  # not increasing
    ([0.0, -1.0], [0, 1], "t", 2),
    ([0.0, 1.0], [0, float("nan")], "x", 2),
])
def test_a_bad_track_is_refused_naming_its_row_and_column(t, x, column, row):
    with pytest.raises(InputError) as info:
        BeaconTrack.from_columns(t, x, [0.0] * len(t), source="beacon.csv")
    assert (info.value.file, info.value.row, info.value.column) == ("beacon.csv", row, column)


def test_track_along_a_path_waits_walks_and_dwells():
    track = track_along([(0, 0), (30, 40), (30, 40), (30, 140)], speed=5.0, start=2.0, dwell=3.0)
    # wait 2 s at the start, 50 mm in 10 s, dwell 3 s, 100 mm in 20 s, dwell 3 s
    assert track.t.tolist() == [0.0, 2.0, 12.0, 15.0, 35.0, 38.0]
    assert leader_speed(track) == pytest.approx(5.0)


def test_long_axis_track_sweeps_the_middle_of_the_long_side_once():
    track = long_axis_track((0.0, 0.0, 3000.0, 600.0), 300.0, 2.0, start=30.0)
    assert track.x.tolist() == [300.0, 300.0, 2700.0] and set(track.y.tolist()) == {300.0}
    assert track.t[-1] == pytest.approx(30.0 + 2400.0 / 2.0)
    along_y = long_axis_track((0.0, 0.0, 400.0, 900.0), 300.0, start=0.0)
    assert along_y.y.tolist() == [300.0, 600.0] and set(along_y.x.tolist()) == {200.0}
    short = long_axis_track((0.0, 0.0, 400.0, 500.0), 300.0)  # shorter than 2 R: it waits in the middle
    assert short.y.tolist() == [250.0, 250.0] and short.x.tolist() == [200.0, 200.0]


def test_a_geojson_path_and_a_table_give_the_track(tmp_path):
    path = tmp_path / "path.geojson"
    path.write_text(json.dumps({"type": "Feature", "properties": {"speed": 0.5, "units": "cm", "start": 4},
                                "geometry": {"type": "LineString", "coordinates": [[0, 0], [10, 0]]}}))
    track = read_beacon_path(path)
    assert track.t.tolist() == [0.0, 4.0, 24.0] and track.x.tolist() == [0.0, 0.0, 100.0]
    table = tmp_path / "track.csv"
    table.write_text("t,x,y\n0,0,0\n10,5,oops\n")
    with pytest.raises(InputError) as info:
        read_beacon_path(table)
    assert (info.value.row, info.value.column, info.value.value) == (2, "y", "oops")
    path.write_text(json.dumps({"type": "LineString", "coordinates": [[0, 0], [1, 0]]}))
    with pytest.raises(InputError, match="'speed'"):
        read_beacon_path(path)


# -- the leash -----------------------------------------------------------------------------
def _distances_beyond(sim, leash):
    tj, track = sim.trajectories, sim.log.beacon
    bx, by = track.position(tj["t"])
    return np.hypot(tj["x"] - bx, tj["y"] - by) - leash


def test_agents_stay_within_the_leash_plus_a_step_in_an_open_hall():
    arena = hall_arena(0, length=1500.0, width=600.0)
    track = long_axis_track(arena.bounds, 250.0, 2.0)
    sim = simulate(arena, 150, float(np.ceil(track.t[-1] + 10)), rng=5, trajectory_every=1.0, beacon=track,
                   leash=250.0)
    beyond = _distances_beyond(sim, 250.0)
    step = sim.log.meta["v_c"] * sim.log.meta["dt"]
    assert np.percentile(beyond, 99.9) <= 2 * step and beyond.max() <= 10.0
    assert 0 < sim.log.meta["simulation"]["leash"]["stimulated_share"] < 0.5


def test_agents_get_round_obstacles_back_to_the_leader():
    arena = hall_arena(2, length=1500.0, width=600.0, rng=3)
    track = long_axis_track(arena.bounds, 250.0, 2.0)
    sim = simulate(arena, 150, float(np.ceil(track.t[-1] + 10)), rng=5, trajectory_every=1.0, beacon=track,
                   leash=250.0)
    beyond = _distances_beyond(sim, 250.0)
    assert np.percentile(beyond, 99) <= 20.0 and beyond.max() <= 250.0  # a few lag round a hole, none is lost


def test_stimulated_walkers_head_for_the_beacon_and_stops_end():
    from swarmtopo.log import RW, S
    from swarmtopo.sim import motion, walls
    from swarmtopo.sim.leash import steer
    from swarmtopo.sim.params import MotionParams

    arena = square_arena(4000.0)
    model = motion.make_model(MotionParams(), 30.0, 0.1)
    grid = walls.build_wall_grid(arena.boundary_segments, arena.bounds, cell=30.0, reach=35.0)
    agents = motion.new_swarm(np.full((2000, 2), 500.0), model, np.random.default_rng(0))
    agents["state"][:1000] = S  # half of them stopped, to resume walking
    agents["resume_state"][:] = RW
    agents["stop_left"][:1000] = 50
    stimulus = np.zeros(2000, np.bool_)
    n = steer(agents, stimulus, 2000.0, 2000.0, 1000.0, model, grid, np.random.default_rng(1))
    assert n == 2000 and stimulus.all()
    error = agents["heading"] - np.pi / 4  # the bearing to (2000, 2000)
    assert abs(error.mean()) < 0.05 and error.std() == pytest.approx(HEADING_ERROR, rel=0.1)
    assert (agents["stop_left"][:1000] == 1).all()
    agents["x"][:], agents["y"][:] = 1700.0, 1700.0  # within R / 2: no longer stimulated
    assert steer(agents, stimulus, 2000.0, 2000.0, 1000.0, model, grid, np.random.default_rng(1)) == 0


def test_a_leader_run_is_reproducible_and_the_interpreted_kernels_agree():
    from swarmtopo.sim.simulate import interpreted_kernels

    arena = hall_arena(1, length=800.0, width=400.0, rng=1)
    track = long_axis_track(arena.bounds, 150.0, 3.0, start=2.0)
    runs = [simulate(arena, 30, 20.0, rng=7, beacon=track, leash=150.0) for _ in range(2)]
    with interpreted_kernels():
        runs.append(simulate(arena, 30, 20.0, rng=7, beacon=track, leash=150.0))
    for other in runs[1:]:
        for name in ("t", "a", "b", "status_t", "status_agent", "status_state"):
            assert np.array_equal(getattr(runs[0].log, name), getattr(other.log, name)), name
    assert runs[0].log.n_events > 0 and runs[0].log.meta["simulation"]["leash"]["stimulated_share"] > 0


def test_a_leader_needs_both_its_track_and_its_leash():
    with pytest.raises(InputError, match="both"):
        simulate(square_arena(), 5, 1.0, leash=100.0)


# -- the log folder ------------------------------------------------------------------------
def test_beacon_csv_round_trips_and_survives_stripping_ground_truth(tmp_path):
    arena = hall_arena(0, length=800.0, width=400.0)
    track = long_axis_track(arena.bounds, 150.0, 3.0, start=2.0)
    sim = simulate(arena, 20, 10.0, rng=1, beacon=track, leash=150.0)
    write_log(sim.log, tmp_path / "log", arena=arena)
    assert (tmp_path / "log" / "beacon.csv").read_text().splitlines()[0].replace('"', "") == "t,x,y"
    strip_ground_truth(tmp_path / "log", tmp_path / "stripped")
    log = read_log(tmp_path / "stripped")
    assert np.array_equal(log.beacon.t, sim.log.beacon.t) and np.array_equal(log.beacon.x, sim.log.beacon.x)
    assert log.meta["leash"] == 150.0 and "simulation" not in log.meta
    assert log.beacon.t[-1] == 10.0  # clipped to the log
    (tmp_path / "stripped" / "beacon.csv").write_text("t,x,y\n0,1,1\n0,2,2\n")
    with pytest.raises(InputError) as info:
        read_log(tmp_path / "stripped")
    assert info.value.row == 2 and info.value.column == "t" and info.value.file.endswith("beacon.csv")


# -- stitching local maps ------------------------------------------------------------------
def _windows(counts, length=20.0):
    step = length / 2
    return [TimelineWindow(t0=k * step, t1=k * step + length, n_events=500, betti={0: 1, 1: c},
                           confidence={0: 0.99, 1: 0.9}) for k, c in enumerate(counts)]


SPAN = (0.0, 1000.0)


def _straight(speed=2.0, end=1000.0):
    return BeaconTrack.from_columns([0.0, end], [0.0, speed * end], [0.0, 0.0])


def test_a_hole_is_placed_a_leash_behind_where_the_leader_was_when_it_left_the_view():
    counts = [0] * 10 + [1] * 12 + [0] * 10
    found = stitch(_windows(counts), _straight(), 200.0, 20.0, 10.0, 1, {}, SPAN)
    (hole,) = found.holes
    # the count rises between window 9 ([90, 110]) and window 10 ([100, 120]): t = (90 + 120) / 2 = 105 s,
    # and falls between window 21 ([210, 230]) and window 22 ([220, 240]): t = (210 + 240) / 2 = 225 s
    assert (hole.t_in, hole.t_out) == (105.0, 225.0)
    assert hole.x == pytest.approx(2.0 * 225.0 - 200.0) and hole.y == 0.0
    assert hole.radius == pytest.approx(100.0 + 2.0 * 10.0) and not hole.open and hole.windows == 12
    assert found.betti == {0: 1, 1: 1} and len(found.windows) == 32


def test_a_count_that_stays_one_for_two_holes_travels_is_two_holes_handed_over():
    counts = [0] * 10 + [1] * 26 + [0] * 10  # in view from 105 to 365 s: 520 mm, twice 1.3 x 200 mm
    first, second = stitch(_windows(counts), _straight(), 200.0, 20.0, 10.0, 1, {}, SPAN).holes
    assert (first.t_in, first.t_out, second.t_in, second.t_out) == (105.0, 235.0, 235.0, 365.0)
    assert first.x == pytest.approx(2.0 * 235.0 - 200.0) and second.x == pytest.approx(2.0 * 365.0 - 200.0)
    assert len(stitch(_windows(counts), _straight(), 200.0, 20.0, 10.0, 1, {}, SPAN, handover=2.0).holes) == 1
    fast = stitch(_windows([0] * 10 + [1] * 6 + [0] * 10), _straight(speed=50.0), 200.0, 20.0, 10.0, 1, {}, SPAN)
    assert len(fast.holes) == 6  # 50 mm/s over 6 windows is 11 hand-over travels: no more holes than windows


def test_holes_in_view_together_leave_first_in_first_out():
    counts = [0] * 8 + [1] * 8 + [2] * 8 + [1] * 8 + [0] * 8
    found = stitch(_windows(counts), _straight(), 100.0, 20.0, 10.0, 1, {}, SPAN)
    first, second = found.holes
    assert first.t_in < second.t_in and first.t_out < second.t_out
    assert first.x < second.x


def test_a_misread_window_is_not_a_hole_and_a_revisit_is_one_hole():
    assert stitch(_windows([0] * 10 + [1] + [0] * 10), _straight(), 100.0, 20.0, 10.0, 1, {}, SPAN).holes == []
    there_and_back = BeaconTrack.from_columns([0.0, 250.0, 500.0], [0.0, 500.0, 0.0], [0.0, 0.0, 0.0])
    counts = [0] * 8 + [1] * 8 + [0] * 18 + [1] * 8 + [0] * 7  # out past it and back past it
    found = stitch(_windows(counts), there_and_back, 400.0, 20.0, 10.0, 1, {}, (0.0, 500.0))
    assert len(found.holes) == 1 and found.holes[0].windows >= 16
    pieces = stitch(_windows(counts), there_and_back, 400.0, 20.0, 10.0, 1, {}, (0.0, 500.0), handover=0.1)
    assert [h.windows for h in pieces.holes] == [16]  # one window per hand-over, at most, all merged back


def test_warnings_name_a_fast_leader_and_a_stretch_without_local_maps():
    windows = _windows([0] * 10) + [TimelineWindow(t0=400.0, t1=420.0, n_events=500, betti={0: 1, 1: 0},
                                                   confidence={0: 0.99, 1: 0.9})]
    found = stitch(windows, _straight(speed=10.0, end=500.0), 100.0, 20.0, 10.0, 1, {"v_c": 15.0}, (0.0, 420.0))
    assert any("faster than" in w for w in found.warnings)
    assert any(w.startswith("no local map from 110 to 400 s") for w in found.warnings)
    late = stitch(_windows([0] * 10), BeaconTrack.from_columns([200.0, 300.0], [0.0, 100.0], [0.0, 0.0]), 100.0,
                  20.0, 10.0, 1, {}, (0.0, 110.0))
    assert late.leader_speed == 0.0 and late.warnings[0].startswith("the leader's track (beacon.csv) runs from 200")
    short = stitch(_windows([0] * 10), _straight(), 100.0, 20.0, 10.0, 1, {"r_d": 30.0}, SPAN)
    assert any(w.startswith("the leash R = 100 mm is less than 5 x r_d = 150 mm") for w in short.warnings)
    assert not any(w.startswith("the leash") for w in stitch(_windows([0] * 10), _straight(), 150.0, 20.0, 10.0, 1,
                                                             {"r_d": 30.0}, SPAN).warnings)
    few = stitch(_windows([1] * 5), _straight(), 100.0, 20.0, 10.0, 1, {}, SPAN)
    assert few.betti[1] is None and few.holes == [] and "no global count" in few.warnings[0]


# -- the whole map ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def explored(tmp_path_factory):
    arena = hall_arena(1, length=1400.0, width=500.0, rng=2)
    track = long_axis_track(arena.bounds, 250.0, 2.0)
    sim = simulate(arena, 200, float(np.ceil(track.t[-1] + 20)), rng=3, truth=True, beacon=track, leash=250.0)
    folder = tmp_path_factory.mktemp("explored")
    write_log(sim.log, folder / "log", truth=sim.truth, arena=arena)
    return arena, folder, map_encounters(read_log(folder / "log"), MapConfig(embed_dim=0, cycles=False))


def test_a_beacon_log_gets_a_global_map_whose_count_is_the_answer(explored):
    arena, _, tmap = explored
    found = tmap.exploration
    assert found is not None and tmap.betti[1] == found.betti[1] and tmap.confidence[1] is None
    assert found.betti[1] == arena.betti[1] == 1
    (hole,) = found.holes
    (true,) = [np.asarray(ring.centroid.coords[0]) for ring in arena.regions[0].interiors]
    assert np.hypot(hole.x - true[0], hole.y - true[1]) <= hole.radius
    doc = map_json(tmap)["exploration"]
    assert doc["betti"] == {"0": 1, "1": 1} and len(doc["windows"]) == len(found.windows)


def test_a_log_without_a_leader_has_no_exploration():
    sim = simulate(square_arena(), 60, 20.0, rng=0)
    assert map_encounters(sim.log, MapConfig(embed_dim=0, cycles=False)).exploration is None


def test_a_leader_that_never_moves_keeps_the_pooled_answer():
    """One local map (the paper's whole-log window) is no global map: the pooled count stays, with its reason."""
    from dataclasses import replace

    from swarmtopo.pipeline import config_from_options
    from swarmtopo.pipeline.config import PAPER_OPTIONS

    sim = simulate(square_arena(), 150, 30.0, rng=1, beacon=BeaconTrack.from_columns([0.0], [250.0], [250.0]),
                   leash=300.0)
    config = replace(config_from_options(PAPER_OPTIONS), embed_dim=0, cycles=False)
    without = {k: v for k, v in sim.log.meta.items() if k != "leash"}
    pooled = map_encounters(replace(sim.log, beacon=None, meta=without), config)
    tmap = map_encounters(sim.log, config)
    assert tmap.exploration.betti[1] is None and tmap.betti == pooled.betti and tmap.confidence == pooled.confidence
    assert any("no global count" in w for w in tmap.warnings)
    assert map_json(tmap)["exploration"]["length"] is None
    half = map_encounters(replace(sim.log, beacon=None), MapConfig(embed_dim=0, cycles=False))
    assert any("a 'leash' in meta.json but no beacon.csv" in w for w in half.warnings)


def test_simulate_and_map_from_the_command_line(explored, tmp_path):
    from conftest import run_cli

    arena, folder, _ = explored
    done = run_cli("simulate", "--arena", str(folder / "log" / "arena.geojson"), "--beacon", "sweep", "--leash", "250",
                   "--agents", "200", "--duration", "400", "--seed", "3", "--out", str(tmp_path / "log"))
    assert done.returncode == 0, done.stderr
    assert "a leader moved 740 mm" in done.stdout and (tmp_path / "log" / "beacon.csv").exists()  # 2 mm/s from 30 s to 400 s
    assert "the leader's track runs to" in done.stderr  # 30 + 900 / 2 s > 400 s
    done = run_cli("map", str(tmp_path / "log"), "--out", str(tmp_path / "map"))
    assert done.returncode == 0, done.stderr
    assert "global map along the leader's path" in done.stdout.splitlines()[0]
    page = (tmp_path / "map" / "report.html").read_text()
    assert '<section id="exploration">' in page and 'data-target="plot-exploration"' in page
    bad = run_cli("simulate", "--beacon", "sweep", "--out", str(tmp_path / "x"))
    assert bad.returncode == 2 and "--leash" in bad.stderr
    bad = run_cli("simulate", "--beacon", str(tmp_path / "log" / "beacon.csv"), "--leash", "250", "--leader-speed", "3",
                  "--out", str(tmp_path / "x"))
    assert bad.returncode == 2 and "--leader-speed" in bad.stderr


# -- the benchmark ---------------------------------------------------------------------------
def test_benchmark_cases_are_seeded_and_within_their_ranges():
    for cell in CELLS:
        config = case_config(cell, "reporting", 0)
        assert config == case_config(cell, "reporting", 0) != case_config(cell, "tuning", 0)
        assert 2400 <= config["arena"]["length"] <= 3600 and 250 <= config["swarm"]["leash"] <= 400
        assert config["arena"]["holes"] == cell.holes and 200 <= config["swarm"]["agents"] <= 400


def test_benchmark_scoring_by_hand():
    def row(holes, est, found, status="ok"):
        return {"config": {"arena": {"holes": holes, "length": 3000.0, "width": 600.0},
                           "swarm": {"agents": 300, "leash": 300.0}},
                "status": status, "error": None, "replicate": 0, "est_betti1": est, "t_total": 1.0,
                "exploration": found}
    true = [[500.0, 300.0], [1500.0, 300.0]]
    recs = records([
        row(2, 2, {"true_holes": true, "holes": [{"x": 530.0, "y": 340.0, "radius": 100.0},
                                                 {"x": 1500.0, "y": 100.0, "radius": 150.0}]}),
        row(2, 1, {"true_holes": true, "holes": [{"x": 1000.0, "y": 300.0, "radius": 200.0}]}),
        row(2, None, None, status="timeout"),
    ])
    assert [r["exact"] for r in recs] == [True, False, False]
    assert recs[0]["position_errors"] == [50.0, 200.0] and recs[0]["held"] == 1
    cell = table(recs)["cells"]["2 holes"]
    assert cell["exact"]["right"] == 1 and cell["under"] == 1 and cell["error_median"] == pytest.approx(200.0)


def test_a_sweep_job_with_a_leader_maps_a_hall_and_stores_its_global_map():
    from swarmtopo.experiments.grid import expand_grid
    from swarmtopo.experiments.sweep import run_job

    sweep = expand_grid({"arena": {"generator": "hall", "holes": 1, "length": 900.0, "width": 400.0},
                         "swarm": {"agents": 120, "duration": 150.0, "leash": 150.0, "leader_speed": 5.0},
                         "map": {"window_scales": [1.0]}})
    (job,) = sweep.jobs
    assert job.config["swarm"]["leash"] == 150.0 and job.config["arena"]["length"] == 900.0
    row = run_job(job)
    assert row["status"] == "ok", row["error"]
    found = row["exploration"]
    assert len(found["true_holes"]) == row["true_betti1"] == 1
    assert row["est_betti1"] == found["betti"]["1"] and "windows" not in found
    with pytest.raises(InputError, match="leader_speed.*not used: leash is 0"):
        expand_grid({"swarm": {"leader_speed": 3.0}})
    assert "leash" not in expand_grid({"swarm": {"leash": 0.0}}).jobs[0].config["swarm"]  # no leader: jobs as before


def test_the_sweep_record_of_a_changing_arena_gives_its_holes_at_the_start():
    from swarmtopo.changing import changing_arena
    from swarmtopo.experiments.sweep import exploration_record

    arena = changing_arena("appear", 1, 60.0, rng=0)
    found = stitch(_windows([0] * 8), _straight(), 100.0, 20.0, 10.0, 1, {}, SPAN)
    record = exploration_record(found, arena, "map")
    assert record["true_holes"] == arena.at(0.0).hole_centroids().tolist() and len(record["true_holes"]) == 1
    assert "windows" not in record and "windows" in exploration_record(found, arena, "windows")


@pytest.mark.parametrize("bad, message", [
    ({"type": "FeatureCollection", "features": 5}, "must be a list"),
    ({"type": "Feature", "properties": {"speed": 1, "units": ["m"]},
      "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 0]]}}, "units"),
    ({"type": "Feature", "properties": {"speed": -0.5, "units": "cm"},
      "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 0]]}}, "speed"),
])
def test_a_bad_path_file_is_one_line_naming_it(tmp_path, bad, message):
    path = tmp_path / "path.geojson"
    path.write_text(json.dumps(bad))
    with pytest.raises(InputError, match=message) as info:
        read_beacon_path(path)
    assert info.value.file == str(path) and "\n" not in str(info.value)


def test_a_leader_out_of_reach_of_the_arena_is_refused():
    with pytest.raises(InputError, match="not within the leash"):
        simulate(square_arena(), 5, 1.0, beacon=BeaconTrack.from_columns([0.0], [5000.0], [5000.0]), leash=100.0)
