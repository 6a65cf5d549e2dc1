"""Sweeps: grid expansion, job identity, the result store, and runs on real Dask clusters.

The cluster tests compare every stored row with a reference computed in this process
by calling ``run_job`` serially: a sweep must give the same rows (run columns aside)
whatever the cluster, the number of workers, or how often it was interrupted.
"""

import hashlib
import json
import os
import signal
import subprocess
import sys
import threading
import time
from itertools import product
from pathlib import Path

import numba
import numpy as np
import pytest

from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.experiments.grid import PARAMS, STORE_INT_MAX, expand_grid, read_sweep
from swarmtopo.experiments.store import ResultStore, decode_regions, read_jobs
from swarmtopo.experiments.sweep import job_map_config, run_job, run_sweep
from swarmtopo.pipeline import MapConfig

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "sweep-small.toml"

# 8 jobs, about 0.5 s each for 200 agents; 20 agents mostly give "too little data" rows.
SWEEP_TOML = """\
[sweep]
name = "tiny"
replicates = 2
salt = "test"
[arena]
holes = [1, 2]
[swarm]
agents = [20, 200]
duration = 60
[map]
landmarks = 100
"""


from conftest import result_columns, stop_group, run_cli  # noqa: E402  (the CLI in-process)


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("sweep") / "tiny.toml"
    path.write_text(SWEEP_TOML)
    return path


@pytest.fixture(scope="module")
def reference(sweep_file):
    """key -> result columns of every job's row, computed here by run_job (JSON-normalised like the store's)."""
    rows = [run_job(job) for job in read_sweep(sweep_file).jobs]
    return {row["key"]: result_columns(row) for row in rows}


def assert_store_matches(store, reference):
    rows = read_jobs(store, sweep="tiny")
    assert [r["key"] for r in rows] == sorted(reference)  # exactly one row per job
    for row in rows:
        assert result_columns(row) == reference[row["key"]]


# -- grid ------------------------------------------------------------------------------
def test_grid_is_the_product_of_lists_times_replicates_with_defaults():
    sweep = expand_grid({"sweep": {"replicates": 2}, "arena": {"holes": [1, 2, 3]},
                         "swarm": {"agents": [100, 200]}, "map": {"landmarks": [150, "auto"]}})
    assert len(sweep.jobs) == 3 * 2 * 2 * 2
    points = {(j.config["arena"]["holes"], j.config["swarm"]["agents"], j.config["map"]["landmarks"], j.replicate)
              for j in sweep.jobs}
    assert points == set(product([1, 2, 3], [100, 200], [150, "auto"], [0, 1]))
    job = next(j for j in sweep.jobs if j.config["map"]["landmarks"] == "auto")
    assert job.config == {
        "arena": {"generator": "random", "holes": job.config["arena"]["holes"], "shapes": ["square"],
                  "outer": "square", "scale": 1.0},
        "swarm": {"agents": job.config["swarm"]["agents"], "duration": 20.0, "static_fraction": 0.0},
        "map": {"metric": "hybrid", "hop_cost": "auto", "diffusion_time": "auto", "wall_follow_weight": 2.0,
                "window_length": "auto", "window_encounters": 20.0, "window_scales": list(MapConfig.window_scales),
                "window_step": "auto", "subsample": "maxmin", "landmarks": "auto", "max_landmarks": 400, "maxdim": 1, "classifier": "default"},
    }
    # max_landmarks only caps "auto": a fixed L drops it
    assert "max_landmarks" not in next(j for j in sweep.jobs if j.config["map"]["landmarks"] == 150).config["map"]
    assert sweep.name == "sweep" and sweep.salt == "" and sweep.replicates == 2


def test_job_map_config_reads_words_and_numbers():
    paper = expand_grid({"map": {"hop_cost": 0, "diffusion_time": "none", "wall_follow_weight": "none",
                                 "window_length": "none"}}).jobs[0].config["map"]
    config = job_map_config(paper, seed=3)
    assert (config.hop_cost, config.diffusion_time, config.wall_follow_weight, config.window_length) == \
        (0.0, float("inf"), None, float("inf"))
    assert config.seed == 3 and config.embed_dim == 0 and not config.cycles
    default = job_map_config(expand_grid({"map": {"wall_follow_weight": 1.5}}).jobs[0].config["map"])
    assert (default.hop_cost, default.diffusion_time, default.wall_follow_weight, default.window_length) == \
        (None, None, 1.5, None)
    assert default.window_scales == MapConfig.window_scales and config.window_scales == MapConfig.window_scales
    scaled = job_map_config(expand_grid({"map": {"window_scales": [1.25, 0.75, 1]}}).jobs[0].config["map"])
    assert scaled.window_scales == (0.75, 1.0, 1.25)
    # landmark bands: absent or "auto" are the classifier's own (resolved by map_encounters), else as given
    mapping = expand_grid({}).jobs[0].config["map"]
    assert "landmark_bands" not in mapping and job_map_config(mapping).landmark_bands is None
    assert job_map_config({**mapping, "landmark_bands": "auto"}).landmark_bands is None
    assert job_map_config({**mapping, "landmark_bands": [1.0, 0.5]}).landmark_bands == (1.0, 0.5)


def test_window_scales_flat_list_is_one_set_and_list_of_lists_a_grid():
    one = expand_grid({"map": {"window_scales": [1.25, 1, 0.75, 1]}})
    assert [j.config["map"]["window_scales"] for j in one.jobs] == [[0.75, 1.0, 1.25]]  # canonical: sorted, distinct
    assert one.jobs[0].key == expand_grid({"map": {"window_scales": [0.75, 1.25, 1.0]}}).jobs[0].key
    grid = expand_grid({"map": {"window_scales": [[1], [0.75, 1]]}})
    assert [j.config["map"]["window_scales"] for j in grid.jobs] == [[1.0], [0.75, 1.0]]
    assert expand_grid({"map": {"window_scales": 1.5}}).jobs[0].config["map"]["window_scales"] == [1.5]
    whole = expand_grid({"map": {"window_length": "none"}}).jobs[0].config["map"]
    assert "window_scales" not in whole  # one window: no scales to vote


def test_shapes_flat_list_is_one_set_and_list_of_lists_a_grid():
    one = expand_grid({"arena": {"shapes": ["square", "disc"]}})
    assert [j.config["arena"]["shapes"] for j in one.jobs] == [["disc", "square"]]
    grid = expand_grid({"arena": {"shapes": [["square"], ["disc", "square"], ["square", "disc"]]}})
    assert [j.config["arena"]["shapes"] for j in grid.jobs] == [["square"], ["disc", "square"]]  # sets: 2 points
    assert expand_grid({"arena": {"shapes": "L"}}).jobs[0].config["arena"]["shapes"] == ["L"]


def test_keys_a_generator_does_not_use_are_dropped_and_points_merged():
    sweep = expand_grid({"arena": {"generator": ["random", "default"], "holes": [1, 2]},
                         "swarm": {"static_fraction": [0.0, 0.1], "static_time": 5.0}})
    arenas = [j.config["arena"] for j in sweep.jobs]
    # random x {1, 2} holes + default once; x static_fraction {0, 0.1}
    assert len(sweep.jobs) == 3 * 2
    assert {"generator": "default", "scale": 1.0} in arenas
    swarms = [j.config["swarm"] for j in sweep.jobs]
    assert all(("static_time" in s) == (s["static_fraction"] > 0) for s in swarms)


def test_key_and_seed_are_the_hash_of_config_replicate_and_salt():
    job = expand_grid({"sweep": {"replicates": 2, "salt": "s"}}).jobs[1]
    text = json.dumps({"config": job.config, "replicate": 1, "salt": "s"}, sort_keys=True, separators=(",", ":"))
    digest = hashlib.sha256(text.encode()).hexdigest()
    assert job.key == digest
    assert job.seed == int(digest[:16], 16)
    children = np.random.SeedSequence(job.seed).spawn(4)
    assert job.stream_seeds() == {name: int(c.generate_state(1, np.uint64)[0])
                                  for name, c in zip(("arena", "simulation", "map", "faults"), children)}


def test_growing_the_grid_keeps_every_finished_job():
    small = expand_grid({"sweep": {"replicates": 2}, "arena": {"holes": [1, 2]}, "swarm": {"agents": 100}})
    grown = expand_grid({"sweep": {"replicates": 3, "name": "renamed"}, "arena": {"holes": [0, 1, 2, 3]},
                         "swarm": {"agents": [100, 300]}})
    identity = {(j.key, j.seed) for j in grown.jobs}
    assert {(j.key, j.seed) for j in small.jobs} <= identity
    assert len(identity) == len(grown.jobs) == 4 * 2 * 3
    salted = expand_grid({"sweep": {"replicates": 2, "salt": "test"}, "arena": {"holes": [1, 2]},
                          "swarm": {"agents": 100}})
    assert not {j.key for j in salted.jobs} & {j.key for j in small.jobs}
    assert not {j.seed for j in salted.jobs} & {j.seed for j in small.jobs}


def test_keys_are_the_same_in_another_process():
    code = ("from swarmtopo.experiments.grid import read_sweep; import sys; "
            "print(' '.join(f'{j.key}:{j.seed}' for j in read_sweep(sys.argv[1]).jobs))")
    proc = subprocess.run([sys.executable, "-c", code, str(EXAMPLE)], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONHASHSEED": "12345"})
    assert proc.returncode == 0, proc.stderr
    here = [f"{j.key}:{j.seed}" for j in read_sweep(EXAMPLE).jobs]
    assert proc.stdout.split() == here and len(here) == 8


@pytest.mark.parametrize("body, fragments", [
    ("[map]\nmetrc = 'plain'", ["[map] metrc: unknown key"]),
    ("[mapp]\nmetric = 'plain'", ["[mapp]: unknown table"]),
    ("[swarm]\nagents = 'many'", ['[swarm] agents = "many"', "integer >= 1"]),
    ("[swarm]\nagents = [200, 0]", ["[swarm] agents = 0", "integer >= 1"]),
    ("[swarm]\nduration = true", ["[swarm] duration = true", "finite number > 0"]),
    ("[swarm]\nstatic_fraction = 1.5", ["[swarm] static_fraction = 1.5", "<= 1"]),
    ("[swarm]\nstatic_fraction = 0.1\nstatic_time = 30",
     ["[swarm] static_fraction = 0.1, static_time = 30.0: static_time is after the run ends at t = 20 s"]),
    # the simulator's own checks: the run ends at t = 10 s; 10.04 s is no whole number of 0.1 s steps
    ("[swarm]\nduration = 10\nstatic_fraction = 0.3\nstatic_time = 10.04",
     ["[swarm] duration = 10.0, static_fraction = 0.3, static_time = 10.04: static_time is after the run "
      "ends at t = 10 s"]),
    ("[swarm]\nduration = 10.04", ["[swarm] duration = 10.04: duration 10.04 s is not a whole number of time steps "
                                   "dt = 0.1 s (100.4 steps); use 10 s or 10.1 s"]),
    ("[swarm]\nduration = [30, 10]\nstatic_fraction = 0.5\nstatic_time = 20",
     ["[swarm] duration = 10.0, static_fraction = 0.5, static_time = 20.0", "run ends at t = 10 s"]),
    # integers must fit the store's 32-bit columns
    ("[arena]\nholes = 99999999999999999", ["[arena] holes = 99999999999999999", "at most 2147483647"]),
    ("[swarm]\nagents = [100, 2147483648]", ["[swarm] agents = 2147483648", "at most 2147483647"]),
    ("[sweep]\nreplicates = 2147483648", ["[sweep] replicates = 2147483648", "at most 2147483647"]),
    ("[sweep]\nreplicates = 500001\n[swarm]\nagents = [100, 200]",
     ["[sweep] replicates = 500001", "2 grid points x 500,001 replicates = 1,000,002 jobs, more than the 1,000,000"]),
    # the map's own option parser (pipeline.config.OPTIONS), as `swarmtopo map`'s
    ("[map]\nhop_cost = 1e15", ["[map] hop_cost = 1000000000000000.0: expected a finite number >= 0 and <= 1e+09"]),
    ("[map]\nhop_cost = [0, 2e9]", ["[map] hop_cost = 2000000000.0: expected a finite number >= 0 and <= 1e+09"]),
    ("[map]\nwall_follow_weight = 1e300", ["[map] wall_follow_weight = 1e+300: expected a finite number >= 0 "
                                           "and <= 1e+06"]),
    ("[map]\nlandmarks = 100000", ["[map] landmarks = 100000: expected a whole number >= 3 and <= 2000"]),
    ("[map]\nmax_landmarks = 2001", ["[map] max_landmarks = 2001: expected a whole number >= 3 and <= 2000"]),
    (f"[map]\nwindow_scales = {list(range(1, 50))}", ["[map] window_scales = [1.0, 2.0,", "max_windows: must be"]),
    ("[swarm]\nstatic_time = 3", ["[swarm] static_time", "static_fraction is 0"]),
    ("[map]\nlandmarks = 2", ["[map] landmarks = 2", '"auto"']),
    ("[map]\nmaxdim = 3", ["[map] maxdim = 3", ">= 1 and <= 2"]),
    ("[map]\nmetric = 'hybird'", ['[map] metric = "hybird"', "plain, contracted, hybrid"]),
    ("[map]\nlandmarks = 100\nmax_landmarks = 500", ["[map] max_landmarks", "landmarks is a number"]),
    ("[map]\nhop_cost = -2", ["[map] hop_cost = -2", '>= 0 and <= 1e+09 or "auto"']),
    ("[map]\ndiffusion_time = 0", ["[map] diffusion_time = 0", '> 0 or "auto" or "none"']),
    ("[map]\nwall_follow_weight = -1", ["[map] wall_follow_weight = -1", '>= 0 and <= 1e+06 or "none"']),
    ("[map]\nwindow_length = 'all'", ['[map] window_length = "all"', '> 0 or "auto" or "none"']),
    ("[map]\nwindow_length = 20\nwindow_encounters = 30", ["[map] window_encounters", 'window_length is not "auto"']),
    ("[map]\nwindow_encounters = 0", ["[map] window_encounters = 0", "> 0"]),
    ("[map]\nwindow_length = 'none'\nwindow_step = 5", ["[map] window_step", 'window_length is "none"']),
    ("[map]\nwindow_length = 'none'\nwindow_scales = [1, 2]", ["[map] window_scales", 'window_length is "none"']),
    ("[map]\nwindow_scales = [1, 0]", ["[map] window_scales = [1, 0]", "each a finite number >= 0.05"]),
    ("[map]\nwindow_scales = []", ["[map] window_scales = []", "positive number"]),
    ("[map]\nclassifier = 'nope.json'", ['[map] classifier = "nope.json"', "cannot read"]),
    ("[arena]\nholes = []", ["[arena] holes = []", "empty list"]),
    ("[arena]\nshapes = ['hexagon']", ['[arena] shapes = ["hexagon"]', "square"]),
    ("[arena]\npath = 'a.geojson'", ["[arena] path", "not used by generator 'random'"]),
    ("[arena]\ngenerator = 'file'", ["[arena] path", "missing"]),
    ("[arena]\ngenerator = 'annulus'\nr_inner = 300", ["[arena] r_inner = 300.0", "smaller than r_outer"]),
    ("[sweep]\nreplicates = 0", ["[sweep] replicates = 0"]),
    ("[sweep]\nseed = 3", ["[sweep] seed: unknown key"]),
    ("map = 3", ["[map]: expected a table"]),
    ("[map\nmetric = 1", ["invalid TOML", "line 1"]),
    *((body, ["no key in [arena], [swarm], [map] or [faults]: nothing to sweep"])
      for body in ("", "# a comment", "[sweep]\nreplicates = 3\n[swarm]\n[map]")),
])
def test_malformed_file_is_one_error_naming_file_key_and_value(tmp_path, body, fragments):
    path = tmp_path / "bad.toml"
    path.write_text(body + "\n")
    with pytest.raises(InputError) as info:
        read_sweep(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    for fragment in fragments:
        assert fragment in message


def test_every_integer_key_is_bounded_by_its_store_column(tmp_path):
    integers = [p for p in PARAMS if p.sql == "INTEGER"]
    assert {p.name for p in integers} == {"holes", "agents", "landmarks", "max_landmarks", "maxdim"}
    for p in integers:
        with pytest.raises(InputError, match=rf"^<grid>: \[{p.table}\] {p.name} = {STORE_INT_MAX + 1}: "):
            expand_grid({p.table: {p.name: STORE_INT_MAX + 1}})
    # the bound itself is stored (the job's row: holes that do not fit)
    row = run_job(expand_grid({"arena": {"holes": STORE_INT_MAX}}).jobs[0])
    assert row["error"].startswith(f"cannot place {STORE_INT_MAX} holes")
    assert ResultStore(tmp_path / "s.duckdb").write([row])
    assert [r["holes"] for r in read_jobs(tmp_path / "s.duckdb")] == [STORE_INT_MAX]


@pytest.mark.parametrize("body, where", [
    ("[arena]\nholes = 99999999999999999", "[arena] holes = 99999999999999999: "),
    ("[map]\nhop_cost = 1e15", "[map] hop_cost = 1000000000000000.0: "),
    ("[map]\nwall_follow_weight = 1e300", "[map] wall_follow_weight = 1e+300: "),
    ("[map]\nlandmarks = 100000", "[map] landmarks = 100000: "),
    ("[swarm]\nduration = 10.04\nstatic_fraction = 0.3\nstatic_time = 10.04",
     "[swarm] duration = 10.04, static_fraction = 0.3, static_time = 10.04: "),
])
def test_cli_refuses_a_job_its_checks_would_fail_before_touching_the_store(tmp_path, body, where):
    path = tmp_path / "bad.toml"
    path.write_text(body + "\n")
    proc = run_cli("sweep", path, "--store", tmp_path / "r.duckdb", "--workers", "1")
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    (line,) = proc.stderr.strip().splitlines()
    assert line.startswith(f"error: {path}: {where}")
    assert not (tmp_path / "r.duckdb").exists()


def test_cli_bad_config_is_one_line_exit_1(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[map]\nmetrc = 'plain'\n")
    proc = run_cli("sweep", path, "--store", tmp_path / "r.duckdb")
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert proc.stderr.strip().splitlines() == [f"error: {path}: [map] metrc: unknown key; expected one of "
                                                "metric, hop_cost, diffusion_time, wall_follow_weight, window_length, "
                                                "window_encounters, window_scales, "
                                                "window_step, "
                                                "subsample, landmarks, "
                                                "max_landmarks, maxdim, classifier"]
    assert not (tmp_path / "r.duckdb").exists()


def test_input_files_enter_the_key_by_content_and_reach_the_job(tmp_path):
    import shapely

    from swarmtopo.arena import square_arena
    from swarmtopo.readers.paper import BettiClassifier
    from swarmtopo.io import write_arena

    write_arena(square_arena(400.0, [shapely.box(150, 150, 250, 250)]), tmp_path / "room.geojson")
    BettiClassifier.from_theta({1: (0.5, 0.0, 1e9)}, {"name": "blind"}).save(tmp_path / "theta.json")  # no hole
    doc = {"arena": {"generator": "file", "path": "room.geojson"},
           "swarm": {"duration": 10.0}, "map": {"classifier": "theta.json", "landmarks": 100}}
    first = expand_grid(doc, base_dir=tmp_path).jobs[0]
    assert first.file("arena.path") == str(tmp_path / "room.geojson")
    assert first.file("map.classifier") == str(tmp_path / "theta.json")
    assert first.config["arena"]["path_sha256"] == hashlib.sha256((tmp_path / "room.geojson").read_bytes()).hexdigest()
    row = run_job(first)
    assert (row["true_betti0"], row["true_betti1"], row["error"], row["est_betti1"]) == (1, 1, None, 0)
    assert row["versions"]["classifier"] == "blind" and row["versions"]["theta"]["1"]["tau"] == 1e9
    write_arena(square_arena(300.0), tmp_path / "room.geojson")
    assert expand_grid(doc, base_dir=tmp_path).jobs[0].key != first.key


# -- jobs and the store ----------------------------------------------------------------
def test_run_job_row_is_deterministic_and_consistent():
    job = expand_grid({"arena": {"holes": 2}, "swarm": {"agents": 200, "duration": 40},
                       "map": {"landmarks": 200}}).jobs[0]
    row, again = run_job(job), run_job(job)
    assert result_columns(row) == result_columns(again)
    assert (row["true_betti0"], row["true_betti1"], row["error"]) == (1, 2, None)
    assert row["n_agents"] == 200 and row["n_regions"] == 1 and row["n_landmarks"] == 200
    # the union diagram's H1 lengths, decreasing, are the regions' H1 bars
    lengths = np.array(row["lengths_h1"])
    bars = np.concatenate([r["diagram"].lengths(1) for r in decode_regions(row["diagrams"])])
    assert np.array_equal(lengths, np.sort(bars)[::-1])
    # paper's SNR with beta_1 = 2: mean square of the 2 longest over mean square of the rest
    assert row["snr_h1"] == pytest.approx(np.mean(lengths[:2] ** 2) / np.mean(lengths[2:] ** 2), rel=1e-12)
    assert row["noise_power_h1"] == pytest.approx(np.mean(lengths[2:] ** 2), rel=1e-12)
    assert row["holes"] == 2 and row["landmarks"] == 200 and row["max_landmarks"] is None
    # the window tasks' seconds are summed over the threads they ran on side by side
    assert row["t_total"] >= row["t_simulate"] + row["t_graph"]
    assert row["t_landmarks"] + row["t_persistence"] <= numba.get_num_threads() * row["t_total"]


def test_user_errors_are_rows_with_null_estimates(tmp_path):
    job = expand_grid({"swarm": {"agents": 1, "duration": 5}}).jobs[0]  # one agent never meets anyone
    row = run_job(job)
    assert row["error"] == "the log has 0 event(s); at least 2 encounters are needed to build a map"
    assert row["est_betti0"] is None and row["lengths_h1"] is None and row["snr_h1"] is None
    assert row["true_betti1"] == 1 and row["n_events"] == 0 and row["t_simulate"] > 0
    store = ResultStore(tmp_path / "s.duckdb")
    assert store.write([row]) and store.write([row])  # a key is stored once: the second write replaces it
    (stored,) = read_jobs(tmp_path / "s.duckdb")
    assert stored["status"] == "error" and result_columns(stored) == result_columns(row)


def test_a_job_shared_by_two_sweeps_is_stored_once_and_read_by_both(tmp_path):
    base = {"arena": {"holes": 1}, "swarm": {"agents": 5, "duration": 5}}
    a = expand_grid({**base, "sweep": {"name": "a", "replicates": 2}}).jobs
    b = expand_grid({**base, "sweep": {"name": "b", "replicates": 3}}).jobs  # replicates 0, 1 are a's jobs
    store = tmp_path / "s.duckdb"
    ResultStore(store).write([run_job(job) for job in {job.key: job for job in a + b}.values()])
    # everything is stored already: no cluster is started, every job is skipped
    summary = run_sweep(a + b, store)
    assert (summary.total, summary.skipped, summary.run, summary.workers) == (3, 3, 0, 0)
    assert [r["key"] for r in read_jobs(store, sweep="a")] == sorted(j.key for j in a)
    assert [r["key"] for r in read_jobs(store, sweep="b")] == sorted(j.key for j in b)
    assert len(read_jobs(store)) == 3 and read_jobs(store, sweep="c") == []


def test_foreign_files_are_refused_as_stores(tmp_path):
    import duckdb

    with duckdb.connect(str(tmp_path / "other.duckdb")) as db:
        db.execute("CREATE TABLE jobs (key TEXT, answer INTEGER)")
    for open_store in (ResultStore, read_jobs):
        with pytest.raises(SwarmtopoError, match="lacks the jobs and sweep_jobs tables"):
            open_store(tmp_path / "other.duckdb")
    with duckdb.connect(str(tmp_path / "other.duckdb")) as db:
        db.execute("CREATE TABLE sweep_jobs (sweep TEXT, key TEXT)")
    for open_store in (ResultStore, read_jobs):
        with pytest.raises(SwarmtopoError, match="a result store of an earlier swarmtopo version"):
            open_store(tmp_path / "other.duckdb")
    # a store of another version is read for the columns asked, if it has them
    with duckdb.connect(str(tmp_path / "other.duckdb")) as db:
        db.execute("INSERT INTO jobs VALUES ('k2', 2), ('k1', 1)")
    assert read_jobs(tmp_path / "other.duckdb", columns=("key", "answer")) == [{"key": "k1", "answer": 1},
                                                                              {"key": "k2", "answer": 2}]
    with pytest.raises(SwarmtopoError, match="lacks the columns config"):
        read_jobs(tmp_path / "other.duckdb", columns=("key", "config"))


# -- sweeps on real clusters -----------------------------------------------------------
@pytest.mark.slow
def test_one_local_worker_and_two_scheduler_workers_give_identical_tables(tmp_path, sweep_file, reference,
                                                                         dask_cluster):
    jobs = read_sweep(sweep_file).jobs
    one = run_sweep(jobs, tmp_path / "one.duckdb", workers=1)
    two = run_sweep(jobs, tmp_path / "two.duckdb", scheduler=dask_cluster)
    assert (one.workers, two.workers) == (1, 2)
    failed = sum(r["error"] is not None for r in reference.values())
    assert 0 < failed < 8  # error rows are results too: stored, compared, never rerun
    assert (one.run, one.skipped, one.failed) == (8, 0, {"error": failed})
    assert_store_matches(tmp_path / "one.duckdb", reference)
    assert_store_matches(tmp_path / "two.duckdb", reference)
    again = run_sweep(jobs, tmp_path / "two.duckdb", scheduler=dask_cluster)
    assert (again.run, again.skipped) == (0, 8)
    with pytest.raises(SwarmtopoError, match="drop --workers"):
        run_sweep(jobs, tmp_path / "two.duckdb", scheduler=dask_cluster, workers=2)


def _interrupt_after_first_row(sweep_file, store, sig, *extra):
    """Run `swarmtopo sweep`, send ``sig`` once the first row is in the store (read by this
    process while the sweep writes to it); (process, rest of stderr)."""
    proc = subprocess.Popen([sys.executable, "-m", "swarmtopo", "sweep", str(sweep_file), "--store", str(store),
                             "--verbose", *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    watchdog = threading.Timer(240, stop_group, [proc])  # the suite must never hang
    watchdog.start()
    try:
        for line in proc.stderr:  # --verbose: one line per finished job
            if line.startswith("1/8 jobs done"):
                break
        while not store.exists() or not read_jobs(store, columns=("key",)):  # written within FLUSH_SECONDS
            time.sleep(0.1)
        os.kill(proc.pid, sig)
        _, rest = proc.communicate(timeout=60)
    except BaseException:
        stop_group(proc)
        raise
    finally:
        watchdog.cancel()
    return proc, rest


def _group_gone(pgid: int, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.2)
    return False


@pytest.mark.slow
def test_ctrl_c_stops_the_local_cluster_and_a_rerun_finishes_exactly_the_rest(tmp_path, sweep_file, reference,
                                                                              dask_cluster):
    for attempt in range(3):  # on a loaded machine the sweep may finish before the first row is seen: again
        store = tmp_path / f"s{attempt}.duckdb"
        proc, stderr = _interrupt_after_first_row(sweep_file, store, signal.SIGINT, "--workers", "1")
        if proc.returncode != 0:
            break
    try:
        assert proc.returncode == 130 and "Traceback" not in stderr, stderr
        assert stderr.strip().endswith("run the same command again to run the rest")
        assert _group_gone(proc.pid, timeout=10)  # the local cluster's worker processes are gone
    finally:
        stop_group(proc)
    done = len(read_jobs(store))
    assert 1 <= done < 8
    rerun = run_sweep(read_sweep(sweep_file).jobs, store, scheduler=dask_cluster)
    assert (rerun.skipped, rerun.run) == (done, 8 - done)
    assert_store_matches(store, reference)


@pytest.mark.slow
def test_sigkill_loses_no_written_row_and_a_rerun_finishes_exactly_the_rest(tmp_path, sweep_file, reference,
                                                                            dask_cluster):
    store = tmp_path / "s.duckdb"
    proc, _ = _interrupt_after_first_row(sweep_file, store, signal.SIGKILL, "--scheduler", dask_cluster)
    assert proc.returncode == -signal.SIGKILL
    done = read_jobs(store)
    assert 1 <= len(done) <= 8  # on a loaded machine the last rows may be written before the kill lands
    for row in done:  # rows written before the kill are whole
        assert result_columns(row) == reference[row["key"]]
    rerun = run_cli("sweep", sweep_file, "--store", store, "--scheduler", dask_cluster)
    assert rerun.returncode == 0, rerun.stderr
    if len(done) < 8:
        assert f"8 jobs: {8 - len(done)} run" in rerun.stdout and f"{len(done)} already in the store" in rerun.stdout
        assert "2 worker(s) at the end" in rerun.stdout
    else:
        assert "all 8 jobs already in" in rerun.stdout
    assert_store_matches(store, reference)


def test_sweep_help_shows_an_example():
    proc = run_cli("sweep", "--help")
    assert proc.returncode == 0 and "Example: swarmtopo sweep examples/sweep-small.toml" in proc.stdout


def test_a_sweep_whose_every_job_fails_exits_1_with_its_rows_stored(tmp_path):
    path = tmp_path / "lonely.toml"
    path.write_text('[sweep]\nname = "lonely"\nreplicates = 2\n[swarm]\nagents = 1\nduration = 1\n')
    proc = run_cli("sweep", path, "--store", tmp_path / "r.duckdb", "--workers", "1")
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    line = (f"error: sweep 'lonely': all 2 jobs failed (error: the log has 0 event(s); at least 2 encounters are needed "
            f"to build a map); their rows are in {tmp_path / 'r.duckdb'}")
    assert proc.stderr.strip().splitlines() == [line]
    assert [row["error"] is not None for row in read_jobs(tmp_path / "r.duckdb")] == [True, True]
    # run again: nothing to run, and it still says so
    again = run_cli("sweep", path, "--store", tmp_path / "r.duckdb", "--workers", "1")
    assert again.returncode == 1 and again.stderr.strip().splitlines() == [line]
