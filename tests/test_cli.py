"""The command line as a user meets it: exit codes, stdout/stderr.

Most runs are in-process (``conftest.run_cli``: the CLI's start-up is most of a short
run); what only a real process shows -- an exit code as the shell sees it, nothing
written to the file descriptors by C code, the version as installed -- runs
``python -m swarmtopo`` (:func:`run_process`)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import run_cli as run

from swarmtopo.readers.registry import load_classifier
from swarmtopo.io import read_log, strip_ground_truth
from swarmtopo.pipeline import MapConfig
from swarmtopo.viz.text import format_confidence


def run_process(*args, cwd=None, env=None):
    """``python -m swarmtopo ARGS`` in a new process."""
    return subprocess.run([sys.executable, "-m", "swarmtopo", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=300)


def run_all(*commands):
    """:func:`run` of each command (a tuple of arguments), one after the other."""
    return [run(*args) for args in commands]


def assert_one_line_error(proc, *fragments, code=1):
    assert proc.returncode == code, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, proc.stderr
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def assert_one_line_errors(*cases):
    """:func:`assert_one_line_error` of each (arguments, fragments, exit code), the runs
    made by :func:`run_all`."""
    for (args, fragments, code), proc in zip(cases, run_all(*(case[0] for case in cases)), strict=True):
        assert proc.returncode == code, (args, proc.stderr)
        assert_one_line_error(proc, *fragments, code=code)


@pytest.fixture(scope="module")
def simulated(one_hole_log):
    """``swarmtopo simulate --holes 1 --agents 200 --duration 20 --seed 4 --truth
    --trajectories 1`` (conftest): (folder, run)."""
    return one_hole_log


def test_simulate_writes_the_log_folder(simulated):
    out, proc = simulated
    names = sorted(p.name for p in out.iterdir())
    assert names == ["arena.geojson", "events.csv", "meta.json", "status.csv", "trajectories.csv", "truth.csv"]
    log = read_log(out)
    assert log.n_agents == 200 and log.n_events > 500
    assert f"{log.n_events} encounters" in proc.stdout


def test_simulate_parquet_has_the_same_events_as_csv(tmp_path, simulated):
    proc = run("simulate", "--holes", 1, "--agents", 200, "--duration", 20, "--seed", 4, "--format", "parquet",
               "--out", tmp_path / "pq", "--quiet")
    assert proc.returncode == 0 and proc.stdout == ""
    a, b = read_log(simulated[0]), read_log(tmp_path / "pq")
    assert np.array_equal(a.t, b.t) and np.array_equal(a.a, b.a) and np.array_equal(a.b, b.b)


def test_map_writes_map_json_and_figures(tmp_path, simulated):
    proc = run("map", simulated[0], "--out", tmp_path / "m", "--landmarks", 200)
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((tmp_path / "m" / "map.json").read_text())
    assert set(doc) >= {"betti", "confidence", "diagrams", "params", "timings", "classifier", "software"}
    assert doc["classifier"]["classifier"] == "default"
    assert doc["betti"]["0"] == 1
    assert doc["params"]["landmarks"] == 200
    # one loop of landmark events round each counted hole, with valid event indices
    region = doc["regions"][0]
    assert len(region["cycles"]) == region["betti"]["1"]
    n_events = read_log(simulated[0]).n_events
    assert all(0 <= e < n_events for c in region["cycles"] for e in c["events"])
    assert f"beta_1 = {doc['betti']['1']}" in proc.stdout
    # infinite bars are written as null, one per region
    assert [d for _, d in doc["diagrams"]["0"]].count(None) == doc["betti"]["0"]
    assert (tmp_path / "m" / "diagram.png").stat().st_size > 10_000
    assert (tmp_path / "m" / "cloud.png").stat().st_size > 10_000


def test_map_never_reads_ground_truth(tmp_path, simulated):
    stripped = tmp_path / "stripped"
    strip_ground_truth(simulated[0], stripped)
    docs = []
    # keep only what a real deployment's meta.json may declare: no r_d, speeds, dt, seed
    meta = json.loads((stripped / "meta.json").read_text())
    (stripped / "meta.json").write_text(json.dumps({k: meta[k] for k in ("agent_count", "static", "units")}))
    # r_d and v_c set the default per-hop cost, so the comparison fixes it
    for src, out in ((simulated[0], tmp_path / "full"), (stripped, tmp_path / "bare")):
        assert run("map", src, "--out", out, "--quiet", "--hop-cost", "2").returncode == 0
        doc = json.loads((out / "map.json").read_text())
        doc.pop("timings")
        docs.append(doc)
    assert docs[0] == docs[1]
    # without them the cost comes from the data, and map.json says so
    assert run("map", stripped, "--out", tmp_path / "auto", "--quiet").returncode == 0
    params = json.loads((tmp_path / "auto" / "map.json").read_text())["params"]
    assert params["hop_cost"] is None and "mean time between an agent's encounters" in params["hop_cost_source"]


def test_demo_prints_recovered_and_true_betti_numbers(tmp_path):
    # a log an earlier demo wrote is replaced, its outdated files removed (running demo twice works)
    earlier = tmp_path / "demo" / "log"
    assert run("simulate", "--agents", 20, "--duration", 1, "--format", "parquet", "--out", earlier, "-q").returncode == 0
    meta = json.loads((earlier / "meta.json").read_text())
    (earlier / "meta.json").write_text(json.dumps({**meta, "written_by": "swarmtopo demo"}))
    proc = run("demo", "--out", tmp_path / "demo")
    assert proc.returncode == 0, proc.stderr
    assert not (earlier / "events.parquet").exists() and read_log(earlier).n_agents == 200
    assert json.loads((earlier / "meta.json").read_text())["written_by"] == "swarmtopo demo"
    doc = json.loads((tmp_path / "demo" / "map.json").read_text())
    # the verdict is map.json's, with each Betti number's confidence in percent as report.html shows it
    b1, c0, c1 = doc["betti"]["1"], doc["confidence"]["0"], doc["confidence"]["1"]
    assert (f"recovered: beta_0 = 1 ({format_confidence(c0)} confidence), beta_1 = {b1} "
            f"({format_confidence(c1)} confidence)") in proc.stdout
    html = (tmp_path / "demo" / "report.html").read_text(encoding="utf-8")
    assert f">{format_confidence(c0)}</span> confidence" in html
    assert "true:      beta_0 = 1, beta_1 = 1" in proc.stdout
    assert (tmp_path / "demo" / "map.json").exists() and (tmp_path / "demo" / "log" / "events.csv").exists()
    # the report carries the swarm animation from the demo's sampled trajectories
    assert "The swarm" in html and '"frames"' in html


def test_demo_never_replaces_a_log_it_did_not_write(tmp_path):
    folder = tmp_path / "d"
    log = folder / "log"
    assert run("simulate", "--agents", 20, "--duration", 1, "--format", "parquet", "--truth", "--out", log,
               "-q").returncode == 0
    before = {p.name: p.read_bytes() for p in log.iterdir()}
    assert_one_line_error(run("demo", "--out", folder), f"{log}: already holds a log that swarmtopo demo did not write",
                          "events.parquet", "choose another --out")
    assert {p.name: p.read_bytes() for p in log.iterdir()} == before
    assert sorted(p.name for p in folder.iterdir()) == ["log"]
    # nor a map beside no log of its own
    other = tmp_path / "other"
    other.mkdir()
    (other / "map.json").write_text("{}")
    assert_one_line_error(run("demo", "--out", other), f"{other}: already holds a map that swarmtopo demo did not "
                          "write (map.json); choose another --out")
    assert sorted(p.name for p in other.iterdir()) == ["map.json"]


def test_bad_events_file_is_one_line_naming_file_row_column_value(tmp_path):
    folder = tmp_path / "bad"
    folder.mkdir()
    (folder / "events.csv").write_text("t,a,b\n1.0,1,2\n2.0,2,3\nsoon,3,4\n")
    assert_one_line_error(run("map", folder), "events.csv", "row 3", "'t'", "soon")


def test_non_finite_window_is_refused_or_open(simulated, tmp_path):
    proc = run("map", simulated[0], "--window", "nan:5", "--out", tmp_path / "n")
    assert proc.returncode == 2 and "NaN" in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    proc = run("map", simulated[0], "--window", "0:inf", "--out", tmp_path / "i", "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert json.loads((tmp_path / "i" / "map.json").read_text())["params"]["window"] == [0.0, None]


def test_broken_ground_truth_costs_a_warning_not_the_map(simulated, tmp_path):
    import shutil

    folder = tmp_path / "log"
    shutil.copytree(simulated[0], folder)
    (folder / "arena.geojson").write_text("{}")
    truth = (folder / "truth.csv").read_text().splitlines()
    (folder / "truth.csv").write_text("\n".join(truth[:-5]) + "\n")
    proc = run("map", folder, "--out", tmp_path / "m")
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.startswith("warning: ground truth ignored") and "Traceback" not in proc.stderr
    assert (tmp_path / "m" / "map.json").exists() and (tmp_path / "m" / "cloud.png").exists()


def test_out_that_is_a_file_is_one_line(simulated, tmp_path):
    target = tmp_path / "file"
    target.write_text("x")
    assert_one_line_error(run("map", simulated[0], "--out", target), str(target))


def test_missing_folder_is_one_line(tmp_path):
    assert_one_line_error(run_process("map", tmp_path / "nowhere"), f"{tmp_path / 'nowhere'}: log folder not found")
    assert list(tmp_path.iterdir()) == []  # not made by the map's default --out nowhere/map


def test_overlapping_holes_arena_is_one_line(tmp_path):
    arena = {"type": "Polygon", "coordinates": [
        [[0, 0], [500, 0], [500, 500], [0, 500], [0, 0]],
        [[100, 100], [200, 100], [200, 200], [100, 200], [100, 100]],
        [[150, 150], [250, 150], [250, 250], [150, 250], [150, 150]]]}
    path = tmp_path / "arena.geojson"
    path.write_text(json.dumps(arena))
    assert_one_line_error(run("simulate", "--arena", path, "--out", tmp_path / "o"), "arena.geojson", "overlap")


def test_bad_option_values(simulated, tmp_path):
    log = simulated[0]
    assert_one_line_errors(
        (("map", log, "--out", tmp_path / "x", "--metric", "euclid"), ("'euclid' is not one of plain, contracted, hybrid",), 2),
        (("map", log, "--max-windows", 2), ("at least the number of window scales",), 2),
        (("map", log, "--landmarks", 2001), ("'--landmarks'",), 2),
        *((("map", log, "--window", window), ("that can hold something",), 2) for window in ("inf:", ":-inf")),
        (("map", log, "--window", "1e9:2e9"),
         ("no encounter events in the window [1000000000, 2000000000] s; the log's events run from",), 1),
        (("map", log, "--window", "abc"), ("T0:T1",), 2),
        (("simulate", "--format", "xml", "--out", tmp_path / "y"), ("xml",), 2),
        *(((*command, "--seed", -1), ("--seed",), 2)
          for command in (("map", log), ("simulate", "--out", tmp_path / "z"), ("demo", "--out", tmp_path / "w"))),
        (("simulate", "--out", tmp_path / "z", "--static-time", 3), ("--static-fraction",), 2),
        *((("simulate", "--out", tmp_path / "z", option, value), (f"'{option}'",), 2)
          for option, value in (("--dt", 0), ("--rd", -1), ("--duration", "inf"), ("--trajectories", 0))),
        (("plan", "--area", 0, "--agents", 200, "--duration", 30), ("'--area'",), 2),
        *((("map", log, option, value), (f"'{option}'",), 2)
          for option, value in (("--hop-cost", 1e10), ("--wall-follow-weight", 1e7))))
    assert not (tmp_path / "z").exists()


def test_option_values_that_do_not_fit_name_the_option(tmp_path):
    trace = tmp_path / "trace.csv"
    trace.write_text("id1,id2,t\n1,2,0\n1,3,1\n")
    out = tmp_path / "out"
    assert_one_line_error(run("plan", "--area", 250000, "--agents", 200, "--target", 1), "--target",
                          "1 is not strictly between 0 and 1", code=2)
    assert_one_line_error(run("simulate", "--out", out, "--dt", 10), "--dt", "time step too coarse", code=2)
    assert_one_line_error(run("ingest", trace, "--format", "sociopatterns", "--contact-window", 0, "--out", out),
                          "--contact-window", "0 is not a finite number > 0", code=2)
    assert_one_line_error(run("ingest", trace, "--format", "csv", "--contact-window", 10, "--out", out),
                          "--contact-window", "applies to --format sociopatterns only", code=2)
    assert_one_line_error(run("ingest", trace, "--format", "one", "--a-column", "id1", "--out", out),
                          "--a-column", "applies to --format csv or parquet only", code=2)
    assert_one_line_error(run("ingest", trace, "--format", "csv", "--time-column", "id1", "--a-column", "id1",
                              "--b-column", "id2", "--out", out), "three different columns", code=2)
    assert not out.exists()
    proc = run("ingest", trace, "--format", "csv", "--time-column", "t", "--a-column", "id1", "--b-column", "id2",
               "--out", out)
    assert proc.returncode == 0 and read_log(out).n_events == 2


def test_runs_too_big_are_refused_naming_the_options(tmp_path):
    out = tmp_path / "big"
    for command in (["plan", "--area", 250000, "--duration", 30], ["simulate", "--duration", 1, "--out", out]):
        for agents in (99999999999999999999999, 100001):
            assert_one_line_error(run(*command, "--agents", agents), "'--agents'",
                                  f"{'1.00e+23' if agents > 10**6 else '100,001'} is more than 100,000 agents",
                                  code=2)
    for option, value, steps in (("--duration", 1e300, "2e+303"), ("--dt", 1e-9, "4e+12")):
        assert_one_line_error(run("simulate", option, value, "--out", out), "--agents, --duration, --dt",
                              f"= {steps} agent-steps, more than the 1e+10 a run may take", code=2)
    assert not out.exists()


def test_the_limits_the_cli_states_without_importing_them_are_the_librarys():
    """The CLI keeps its start-up light by stating these limits in its own code and help."""
    from swarmtopo import cli
    from swarmtopo.pipeline.config import MAX_LANDMARKS
    from swarmtopo.sim.simulate import MAX_AGENT_STEPS, MAX_AGENTS

    assert f"3..{MAX_LANDMARKS}" in Path(cli.__file__).read_text()
    source = Path(cli.__file__).read_text()
    assert f"at most {MAX_AGENTS:,}; agents x duration / dt at most {MAX_AGENT_STEPS:.0e}".replace("e+", "e") in source


def test_simulate_scales_a_file_arena_and_refuses_holes_with_it(tmp_path):
    from swarmtopo.io import read_arena

    path = tmp_path / "arena.geojson"
    path.write_text(json.dumps({"type": "Polygon", "coordinates": [
        [[0, 0], [300, 0], [300, 200], [0, 200], [0, 0]], [[100, 50], [200, 50], [200, 150], [100, 150], [100, 50]]]}))
    assert_one_line_error(run("simulate", "--arena", path, "--holes", 3, "--out", tmp_path / "h"), "--holes",
                          "has its own holes", code=2)
    assert not (tmp_path / "h").exists()
    proc = run("simulate", "--arena", path, "--scale", 2, "--agents", 20, "--duration", 1, "--out", tmp_path / "s")
    assert proc.returncode == 0, proc.stderr
    arena = read_arena(tmp_path / "s" / "arena.geojson")
    assert arena.bounds == (0, 0, 600, 400) and arena.area == 4 * (300 * 200 - 100 * 100) and arena.betti == (1, 1)


def test_simulate_summary_says_the_time_simulated(tmp_path):
    for duration, dt in ((9.9, 0.3), (0.1, 0.1)):
        out = tmp_path / f"d{duration}"
        proc = run("simulate", "--agents", 10, "--duration", duration, "--dt", dt, "--out", out)
        assert proc.returncode == 0, proc.stderr
        assert json.loads((out / "meta.json").read_text())["duration"] == duration
        assert f" agents over {duration:g} s in an arena" in proc.stdout


def test_a_duration_that_is_not_whole_time_steps_is_a_usage_error(tmp_path):
    out = tmp_path / "o"
    assert_one_line_errors(
        (("simulate", "--duration", 0.1, "--dt", 0.5, "--out", out),
         ("--duration, --dt", "duration 0.1 s is not a whole number of time steps dt = 0.5 s (0.2 steps); use 0.5 s"),
         2),
        (("simulate", "--duration", 1, "--dt", 0.3, "--out", out),
         ("--duration, --dt", "duration 1 s is not a whole number of time steps dt = 0.3 s (3.33333 steps); use 0.9 s "
          "or 1.2 s"), 2),
        (("simulate", "--duration", 0, "--out", out), ("'--duration'", "0 is not a finite number > 0"), 2))
    assert not out.exists()


def test_option_values_out_of_range_name_the_option_in_short(tmp_path):
    out = tmp_path / "o"
    for value in ("inf", "1e300", "nan"):
        assert_one_line_error(run("simulate", "--scale", value, "--out", out), "'--scale'", code=2)
    assert_one_line_error(run("simulate", "--static-time", 10.04, "--static-fraction", 0.5, "--duration", 10,
                              "--out", out), "--static-time", "after the run ends at t = 10 s", "(got 10.04)", code=2)
    assert_one_line_error(run("simulate", "--static-time", "inf", "--static-fraction", 0.5, "--out", out),
                          "'--static-time'", "inf is not a finite number", code=2)
    assert not out.exists()
    proc = run("map", tmp_path, "--window-scales", "1,1e-300")
    assert_one_line_error(proc, "'--window-scales'", "each a finite number >= 0.05", code=2)
    assert len(proc.stderr) < 200


def test_simulate_replaces_a_log_only_with_overwrite(tmp_path):
    folder = tmp_path / "deployment"
    folder.mkdir()
    (folder / "events.csv").write_text("t,a,b\n1,x,y\n")
    (folder / "notes.txt").write_text("mine")
    assert_one_line_error(run("simulate", "--agents", 20, "--duration", 1, "--out", folder, "--format", "parquet"),
                          f"{folder}: already holds a log (events.csv); pass --overwrite")
    assert (folder / "events.csv").read_text() == "t,a,b\n1,x,y\n"
    proc = run("simulate", "--agents", 20, "--duration", 1, "--out", folder, "--format", "parquet", "--overwrite")
    assert proc.returncode == 0 and f"removed the outdated {folder / 'events.csv'}" in proc.stdout
    assert sorted(p.name for p in folder.iterdir()) == ["arena.geojson", "events.parquet", "meta.json", "notes.txt",
                                                         "status.parquet"]


def test_too_little_data_names_the_log_folder(tmp_path):
    folder = tmp_path / "tiny"
    assert run("simulate", "--agents", 4, "--duration", 1, "--out", folder, "-q").returncode == 0
    assert_one_line_error(run("map", folder, "--out", tmp_path / "m"), f"{folder}: the log has 1 event(s)")


def test_simulate_warns_of_passages_narrower_than_r_d(tmp_path):
    arena = tmp_path / "gap.geojson"
    arena.write_text(json.dumps({"type": "Polygon", "coordinates": [
        [[0, 0], [500, 0], [500, 500], [0, 500], [0, 0]], [[5, 200], [105, 200], [105, 300], [5, 300], [5, 200]]]}))
    proc = run("simulate", "--arena", arena, "--agents", 20, "--duration", 1, "--out", tmp_path / "log")
    assert proc.returncode == 0 and proc.stderr.strip() == (
        "warning: region 0: hole 0 is 5 mm from the outer wall, less than r_d = 30 mm: the swarm may not tell them "
        "apart, and the map may miss that hole")


@pytest.mark.parametrize("command", ["simulate", "perturb", "ingest", "map", "demo", "sweep", "reproduce"])
def test_help_shows_an_example(command):
    proc = run(command, "--help")
    assert proc.returncode == 0 and "Example: swarmtopo" in proc.stdout


def test_quiet_verbose_and_pipes(tmp_path, simulated):
    # in a pipe a normal run prints its verdict and no progress; --quiet prints nothing
    normal = run("map", simulated[0], "--out", tmp_path / "n", "--landmarks", 100)
    assert normal.returncode == 0 and "recovered:" in normal.stdout and normal.stderr == ""
    quiet = run_process("map", simulated[0], "--out", tmp_path / "q", "--landmarks", 100, "--quiet")
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == ""
    # --verbose adds each stage's time and each region's details on stderr, same result
    verbose = run("map", simulated[0], "--out", tmp_path / "v", "--landmarks", 100, "--verbose")
    assert verbose.returncode == 0 and verbose.stdout == normal.stdout.replace(str(tmp_path / "n"), str(tmp_path / "v"))
    assert "stages: graph" in verbose.stderr and "region 0:" in verbose.stderr
    assert_one_line_error(run_process("map", simulated[0], "-q", "-v"), "--quiet and --verbose exclude each other",
                          code=2)


def test_map_paper_and_pipeline_options(simulated, tmp_path):
    log = simulated[0]
    paper, default, auto, capped, inspected, every = run_all(
        ("map", log, "--out", tmp_path / "p", "--paper"),
        ("map", log, "--out", tmp_path / "d", "--hop-cost", "1.5", "--window-length", "8", "--diffusion-time", "0.4",
         "--wall-follow-weight", "1.5"),
        ("map", log, "--out", tmp_path / "a", "-q", "--window-length", "auto"),
        ("map", log, "--out", tmp_path / "c", "-q", "--window-length", "4", "--max-windows", "3"),
        ("map", log, "--out", tmp_path / "i", "-q", "--window-length", "4", "--window-scales", "0.5,1"),
        ("map", log, "--out", tmp_path / "e", "-q", "--window-length", "4", "--max-windows", "none",
         "--landmark-bands", "1,0.5"))
    assert paper.returncode == 0, paper.stderr
    doc = json.loads((tmp_path / "p" / "map.json").read_text())
    assert doc["params"]["hop_cost"] == 0.0 and doc["params"]["window_length"] == "inf"
    assert doc["params"]["diffusion_time"] == "inf" and doc["params"]["diffusion_time_used"] is None
    assert doc["params"]["window_length_used"] is None and doc["params"]["wall_follow_weight"] is None
    assert doc["classifier"]["classifier"] == "paper" and len(doc["regions"][0]["windows"]) == 1
    assert doc["params"]["landmark_bands"] == [1.0]
    assert default.returncode == 0, default.stderr
    doc = json.loads((tmp_path / "d" / "map.json").read_text())
    assert doc["params"]["wall_follow_weight"] == 1.5
    assert doc["params"]["hop_cost_used"] == 1.5 and doc["params"]["window_length"] == 8.0
    assert doc["params"]["diffusion_time_used"] == 0.4 and doc["params"]["diffusion_time_source"] == "given"
    assert len(doc["regions"][0]["windows"]) > 1
    assert auto.returncode == 0, auto.stderr
    doc = json.loads((tmp_path / "a" / "map.json").read_text())
    assert doc["params"]["window_length"] is None and "encounters" in doc["params"]["window_source"]
    assert doc["params"]["wall_follow_weight"] == MapConfig.wall_follow_weight
    assert doc["params"]["window_scales"] == list(MapConfig.window_scales)
    assert doc["params"]["landmark_bands"] == list(load_classifier("default").landmark_bands)  # unset: its own
    assert doc["params"]["max_windows"] == MapConfig.max_windows
    assert capped.returncode == 0, capped.stderr
    doc = json.loads((tmp_path / "c" / "map.json").read_text())
    spans = {(w["t0"], w["t1"]) for w in doc["regions"][0]["windows"]}
    assert doc["params"]["max_windows"] == 3 and len(spans) == 3  # one per length, each mapped once per band
    assert len(doc["regions"][0]["windows"]) == 3 * len(doc["params"]["landmark_bands"])
    assert inspected.returncode == 0, inspected.stderr
    doc = json.loads((tmp_path / "i" / "map.json").read_text())
    assert doc["params"]["window_scales"] == [0.5, 1.0]
    assert every.returncode == 0, every.stderr
    doc = json.loads((tmp_path / "e" / "map.json").read_text())
    assert doc["params"]["max_windows"] is None and len(doc["regions"][0]["windows"]) > 3
    assert doc["params"]["landmark_bands"] == [1.0, 0.5]
    assert [w["band"] for w in doc["regions"][0]["windows"]][:2] == [1.0, 0.5]
    assert_one_line_errors(
        *((("map", log, "--max-windows", bad), ("whole number >= 1",), 2) for bad in ("0", "-1", "2.5", "abc")),
        (("map", log, "--max-windows", "2"), ("'--max-windows': must be a whole number, at least the number of "
                                               "window scales (3: one window per length), or 'none'; got 2",), 2),
        (("map", log, "--paper", "--max-windows", "5"), ("--paper fixes --max-windows",), 2),
        (("map", log, "--paper", "--window-step", "3"), ("--paper fixes --window-step",), 2),
        (("map", log, "--paper", "--window-encounters", "5"), ("--paper fixes --window-encounters",), 2),
        (("map", log, "--landmark-bands", "1,1.5"), ("each a finite number > 0 and <= 1",), 2),
        (("map", log, "--landmark-bands", "0.5,x"), ("a list of distinct numbers, each",), 2),
        (("map", log, "--landmark-bands", "0.5,0.5"), ("list of distinct numbers",), 2),
        (("map", log, "--landmark-bands", "0.5", "--subsample", "knn"), ("use maxmin",), 2),
        (("map", log, "--paper", "--landmark-bands", "1,0.5"), ("--paper fixes --landmark-bands",), 2),
        (("map", log, "--window-scales", "1,0"), ("each a finite number >= 0.05",), 2),
        (("map", log, "--window-scales", "1,x"), ("a list of distinct numbers, each",), 2),
        (("map", log, "--paper", "--window-scales", "1,2"), ("--paper fixes --window-scales",), 2),
        (("map", log, "--paper", "--hop-cost", "1"), ("--paper fixes --hop-cost",), 2),
        (("map", log, "--paper", "--diffusion-time", "1"), ("--paper fixes --diffusion-time",), 2),
        (("map", log, "--window-length", "-3"), ("not a finite number > 0",), 2),
        (("map", log, "--diffusion-time", "0"), ("not a finite number > 0",), 2),
        (("map", log, "--paper", "--wall-follow-weight", "1"), ("--paper fixes --wall-follow-weight",), 2),
        (("map", log, "--wall-follow-weight", "-1"), ("not a finite number >= 0 and <= 1e+06",), 2),
        (("map", log, "--hop-cost", "-1"), ("--hop-cost",), 2))


def test_bench_and_plan_help_show_examples():
    for args in (("bench", "accuracy", "--help"), ("plan", "--help")):
        proc = run(*args)
        assert proc.returncode == 0 and "Example" in proc.stdout


def test_version():
    from importlib.metadata import version

    proc = run_process("--version")
    assert proc.returncode == 0 and proc.stdout == f"swarmtopo {version('swarmtopo')}\n" and proc.stderr == ""


@pytest.mark.parametrize("command", [(), ("simulate",), ("perturb",), ("ingest",), ("map",), ("demo",), ("sweep",),
                                     ("reproduce",), ("plan",), ("bench",), ("bench", "accuracy"), ("bench", "faults")])
def test_help_sends_nobody_to_files_they_do_not_have(command):
    """A pip install has no docs/ folder: a pointer to one says it is in the source repository."""
    import re

    proc = run(*command, "--help", env={**os.environ, "COLUMNS": "100"})
    assert proc.returncode == 0, proc.stderr
    text = re.sub(r"[\s│]+", " ", proc.stdout)  # the help as one line, without Rich's box
    assert "Usage:" in text
    for m in re.finditer(r"docs/", text):
        assert re.match(r"docs/[\w.-]+\.md in the source repository", text[m.start():]), text[m.start() - 80:][:200]


def test_map_replaces_a_map_only_with_overwrite(simulated, tmp_path):
    out = tmp_path / "m"
    out.mkdir()
    (out / "map.json").write_text("{}")
    (out / "notes.txt").write_text("mine")
    assert_one_line_error(run("map", simulated[0], "--out", out),
                          f"{out}: already holds a map (map.json); pass --overwrite to replace it, or choose another "
                          "--out")
    assert (out / "map.json").read_text() == "{}"
    proc = run("map", simulated[0], "--out", out, "--overwrite", "--landmarks", 100, "-q")
    assert proc.returncode == 0, proc.stderr
    assert json.loads((out / "map.json").read_text())["params"]["landmarks"] == 100
    assert sorted(p.name for p in out.iterdir()) == ["cloud.png", "diagram.png", "map.json", "notes.txt",
                                                     "report.html"]


def test_reproduce_replaces_its_own_outputs_only(tmp_path):
    out = tmp_path / "r"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    (out / "land2-runs.png").write_text("an earlier run's figure")  # land2 no longer draws it: removed
    proc = run("reproduce", "land2", "--runs", 1, "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in out.iterdir()) == ["land2.csv", "land2.json", "land2.md", "land2.png", "notes.txt"]
    assert f"wrote {out / 'land2.png'}, {out / 'land2.csv'}, {out / 'land2.md'}, {out / 'land2.json'}" in proc.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["r"]
