"""Arenas that change over time, and the simulator in them."""

import json
import math

import numpy as np
import pytest
import shapely

from swarmtopo.arena import Arena, default_arena
from swarmtopo.changing import (ChangingArena, TimedObstacle, arena_from_geojson, betti_timeline_of, changing_arena,
                                changing_demo_arena, timeline_text)
from swarmtopo.errors import ArenaError
from swarmtopo.io import read_arena, write_arena
from swarmtopo.sim import simulate
from swarmtopo.sim.changes import arena_changed


def _collection(*obstacles, units="mm"):
    free = {"type": "Feature", "properties": {},
            "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [500, 0], [500, 500], [0, 500], [0, 0]]]}}
    feats = [free]
    for coords, props in obstacles:
        feats.append({"type": "Feature", "properties": {"units": units, **props},
                      "geometry": {"type": "Polygon", "coordinates": [coords]}})
    return {"type": "FeatureCollection", "features": feats}


SQUARE_HOLE = [[200, 200], [300, 200], [300, 300], [200, 300], [200, 200]]
WALL = [[240, -10], [260, -10], [260, 510], [240, 510], [240, -10]]  # spans the arena: splits it in two


def test_timed_obstacles_give_the_hand_computed_betti_timeline():
    arena = arena_from_geojson(_collection((SQUARE_HOLE, {"role": "obstacle", "from": 10, "until": 30}),
                                           (WALL, {"role": "wall", "from": 20})))
    assert isinstance(arena, ChangingArena)
    assert arena.change_times() == [10.0, 20.0, 30.0]
    # 0-10: empty square; 10-20: one hole; 20-30: the wall cuts through the hole: two rooms,
    # each holding half of the hole as a notch of its wall; 30-: two rooms
    assert betti_timeline_of(arena, 40.0) == [
        {"from": 0.0, "until": 10.0, "beta_0": 1, "beta_1": 0},
        {"from": 10.0, "until": 20.0, "beta_0": 1, "beta_1": 1},
        {"from": 20.0, "until": 40.0, "beta_0": 2, "beta_1": 0}]
    assert arena.at(15.0).area == pytest.approx(500 ** 2 - 100 ** 2)
    assert arena.at(35.0).area == pytest.approx(500 ** 2 - 20 * 500)
    assert arena.betti == (1, 0)  # at t = 0
    assert timeline_text(betti_timeline_of(arena, 40.0)) == \
        "beta_0 = 1 until 20 s, then 2, beta_1 = 0 until 10 s, then 1 until 20 s, then 0"


def test_static_files_stay_static_and_a_permanent_obstacle_is_a_hole(tmp_path):
    plain = arena_from_geojson(_collection())
    assert isinstance(plain, Arena) and plain.betti == (1, 0)
    holed = arena_from_geojson(_collection((SQUARE_HOLE, {"role": "obstacle"})))
    assert isinstance(holed, Arena) and holed.betti == (1, 1)
    assert betti_timeline_of(holed, 5.0) == [{"from": 0.0, "until": 5.0, "beta_0": 1, "beta_1": 1}]


@pytest.mark.parametrize("kind", ["appear", "disappear", "door"])
def test_changing_arenas_round_trip_through_geojson_files(tmp_path, kind):
    arena = changing_arena(kind, 1, 50.0, rng=4, scale=0.9)
    path = write_arena(arena, tmp_path / "arena.geojson")
    again = read_arena(path)
    assert again.betti_timeline(100.0) == arena.betti_timeline(100.0)
    for t in (0.0, 60.0):
        assert again.at(t).geometry.equals_exact(arena.at(t).geometry, 1e-9)


def test_each_generated_change_changes_the_right_number():
    before_after = {kind: [(i["beta_0"], i["beta_1"]) for i in changing_arena(kind, 2, 40.0, rng=1).betti_timeline(99)]
                    for kind in ("appear", "disappear", "door")}
    assert before_after == {"appear": [(1, 2), (1, 3)], "disappear": [(1, 3), (1, 2)], "door": [(1, 2), (2, 2)]}
    assert isinstance(changing_arena("none", 1, 40.0, rng=1), Arena)


@pytest.mark.parametrize("obstacle, message", [
    ((SQUARE_HOLE, {"role": "door"}), "feature 1: role 'door' is not one of obstacle, wall"),
    ((SQUARE_HOLE, {"role": "obstacle", "from": 30, "until": 10}), "obstacle 0: 'from' 30 must be >= 0 and before"),
    ((SQUARE_HOLE, {"role": "obstacle", "from": "soon"}), "feature 1: properties.from 'soon' is not a time"),
    (([[600, 600], [700, 600], [700, 700], [600, 600]], {"role": "obstacle", "from": 1}),
     "obstacle 0 lies outside the free space"),
])
def test_bad_timed_obstacles_are_refused_naming_the_feature(obstacle, message):
    with pytest.raises(ArenaError, match=message.replace("(", r"\(")):
        arena_from_geojson(_collection(obstacle), source="a.geojson")


def test_an_epoch_that_is_no_valid_arena_is_refused_naming_the_obstacles():
    touching = [[100, 100], [200, 100], [200, 200], [100, 200], [100, 100]]
    with pytest.raises(ArenaError, match=r"with obstacle\(s\) 0, 1 present the free space is not a valid arena"):
        arena_from_geojson(_collection((touching, {"role": "obstacle", "from": 1}),
                                       (SQUARE_HOLE, {"role": "obstacle", "from": 2})))


def test_an_appearing_obstacle_moves_the_agents_inside_it_out_and_counts_them():
    arena = changing_demo_arena()
    sim = simulate(arena, 300, 80.0, rng=3, trajectory_every=0.1)
    relocated = sim.log.meta["simulation"]["relocated"]
    assert [r["t"] for r in relocated] == [60.0] and relocated[0]["agents"] > 0
    assert sim.log.meta["simulation"]["betti_timeline"] == [
        {"from": 0.0, "until": 60.0, "beta_0": 1, "beta_1": 1}, {"from": 60.0, "until": 80.0, "beta_0": 1, "beta_1": 2}]
    tr = sim.trajectories
    assert np.isfinite(tr["x"]).all() and np.isfinite(tr["y"]).all()
    for t in np.unique(tr["t"]):  # at every step: inside the free space of that time, never in a present obstacle
        at = tr["t"] == t
        assert arena.at(t).contains(tr["x"][at], tr["y"][at]).all(), t


def test_arena_changed_moves_exactly_the_agents_inside_to_the_nearest_free_point():
    from swarmtopo.sim.motion import AGENT_DTYPE, make_model
    from swarmtopo.sim.params import MotionParams
    from swarmtopo.sim.walls import build_wall_grid

    arena = ChangingArena(default_arena(), [TimedObstacle(shapely.box(50, 50, 100, 100), 5.0)])
    free = arena.at(5.0)
    agents = np.zeros(3, AGENT_DTYPE)
    agents["x"], agents["y"] = [60.0, 99.0, 300.0], [75.0, 75.0, 450.0]
    walls = build_wall_grid(free.boundary_segments, free.bounds, 30.0, 40.0)
    assert arena_changed(agents, free, walls, make_model(MotionParams(), 30.0, 0.1)) == 2
    # nearest wall of the box: x = 50 for the first, x = 100 for the second; 1 mm past it
    np.testing.assert_allclose(agents["x"][:2], [49.0, 101.0])
    np.testing.assert_allclose(agents["y"], [75.0, 75.0, 450.0])


def test_no_encounter_crosses_a_closed_door_and_the_log_is_reproducible():
    arena = changing_arena("door", 0, 30.0, rng=2)
    sim = simulate(arena, 200, 60.0, rng=5, truth=True)
    truth = sim.truth
    door = arena.obstacles[0].polygon
    x_mid = (door.bounds[0] + door.bounds[2]) / 2
    after = truth["t"] >= 30.0
    left_a, left_b = truth["xa"] < x_mid, truth["xb"] < x_mid
    assert after.sum() > 1000
    assert not np.any(after & (left_a != left_b))  # no pair across the door once it is shut
    assert np.any(~after & (left_a != left_b))  # while open, agents met through the doorway
    again = simulate(arena, 200, 60.0, rng=5)
    np.testing.assert_array_equal(again.log.t, sim.log.t)
    np.testing.assert_array_equal(again.log.a, sim.log.a)
    assert again.log.meta == sim.log.meta


def test_a_wall_follower_whose_wall_vanishes_walks_on():
    from swarmtopo.log import STATES

    arena = changing_arena("disappear", 0, 20.0, rng=7)
    sim = simulate(arena, 300, 40.0, rng=1, trajectory_every=0.1)
    tr = sim.trajectories
    assert np.isfinite(tr["x"]).all()
    for t in np.unique(tr["t"]):
        at = tr["t"] == t
        assert arena.at(t).contains(tr["x"][at], tr["y"][at]).all(), t
    assert sim.log.meta["simulation"]["relocated"] == [{"t": 20.0, "agents": 0}]
    # the agents following the hole's wall just before it goes walk on at 20 s (WF -> RW)
    hole = arena.obstacles[0].polygon
    before, after = tr["t"] == 19.9, tr["t"] == 20.0
    near = shapely.distance(shapely.points(tr["x"][before], tr["y"][before]), hole.exterior) < 30.0
    following = near & (tr["state"][before] == STATES.index("WF"))
    assert following.sum() >= 3
    assert not np.any(tr["state"][after][following] == STATES.index("WF"))


def test_a_change_time_just_after_a_step_is_applied_at_that_step():
    obstacle = TimedObstacle(shapely.box(200, 200, 300, 300), 10.00000000004)
    arena = ChangingArena(Arena(shapely.box(0, 0, 500, 500)), [obstacle])
    sim = simulate(arena, 300, 12.0, rng=2, trajectory_every=0.1)
    tr = sim.trajectories
    after = tr["t"] >= 10.0
    assert not shapely.contains_xy(obstacle.polygon, tr["x"][after], tr["y"][after]).any()
    assert sim.log.meta["simulation"]["relocated"][0]["agents"] > 0


def test_the_demo_changes_once_and_its_geojson_is_a_feature_collection(tmp_path):
    arena = changing_demo_arena()
    doc = json.loads(write_arena(arena, tmp_path / "a.geojson").read_text())
    assert doc["type"] == "FeatureCollection"
    assert [f["properties"].get("role") for f in doc["features"]] == [None, "obstacle"]
    assert doc["features"][1]["properties"]["from"] == 60.0 and "until" not in doc["features"][1]["properties"]
    assert arena.obstacles[0].end == math.inf


def test_simulate_and_demo_say_what_changed(tmp_path):
    from conftest import run_cli

    arena = tmp_path / "arena.geojson"
    write_arena(changing_demo_arena(), arena)
    done = run_cli("simulate", "--arena", str(arena), "--agents", "300", "--duration", "70", "--out",
                   str(tmp_path / "log"))
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].endswith("s in an arena that changes (beta_0 = 1, beta_1 = 1 until 60 s, then 2)")
    assert lines[1].startswith("at t = 60 s the arena changed: ") and "moved to the nearest free point" in lines[1]
    meta = json.loads((tmp_path / "log" / "meta.json").read_text())
    assert meta["simulation"]["betti_timeline"][1] == {"from": 60.0, "until": 70.0, "beta_0": 1, "beta_1": 2}
    assert isinstance(read_arena(tmp_path / "log" / "arena.geojson"), ChangingArena)


def test_demo_changing_finds_the_hole_that_appears_and_draws_the_timeline(tmp_path):
    from conftest import run_cli

    done = run_cli("demo", "--changing", "--out", str(tmp_path / "demo"))
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("recovered: the arena changed: beta_1 = 1 until about ") and lines[0].endswith(", then 2")
    assert lines[1].startswith("change:    beta_1 from 1 to 2 at about ")
    assert lines[2].startswith("pooled:    beta_0 = 1") and lines[3] == "true:      beta_0 = 1, beta_1 = 1 until 60 s, then 2"
    doc = json.loads((tmp_path / "demo" / "map.json").read_text())
    (change,) = doc["timeline"]["changes"]
    assert change["interval"][0] <= 60.0 <= change["interval"][1]
    page = (tmp_path / "demo" / "report.html").read_text()
    assert '<section id="timeline">' in page and 'data-target="plot-timeline"' in page
    assert "true (from the arena): beta_0 = 1, beta_1 = 1 until 60 s, then 2" in page
