"""Sweeps that survive bad jobs, lost workers and schedulers; the compact store read while written.

Jobs made to crash, raise and hang come from tests/sweep_faults.py, which the Dask
workers started here (conftest.local_dask) and their job processes import.
"""

import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from conftest import free_port, local_dask, result_columns, run_cli, stop_group, pythonpath_with_tests
from swarmtopo.errors import SwarmtopoError
from swarmtopo.experiments.grid import expand_grid
from swarmtopo.experiments.isolation import JobProcess
from swarmtopo.experiments.store import (
    ResultStore, decode_regions, encode_regions, group_failures, iter_jobs, message_pattern, read_jobs, store_status,
)
from swarmtopo.experiments.sweep import run_job, run_sweep
from swarmtopo.topology.persistence import Diagram

import sweep_faults  # noqa: E402  (tests/ is on sys.path)

CHEAP = {"swarm": {"agents": 100, "duration": 20.0}, "map": {"landmarks": 60}}


def cheap_jobs(name, replicates, salt=""):
    return expand_grid({"sweep": {"name": name, "replicates": replicates, "salt": salt}, **CHEAP}).jobs


@pytest.fixture
def importable_tests(monkeypatch):
    """Job processes started by this process can import tests/sweep_faults.py."""
    monkeypatch.setenv("PYTHONPATH", pythonpath_with_tests()["PYTHONPATH"])


# -- the job process --------------------------------------------------------------------
def test_a_job_process_reports_results_errors_crashes_and_timeouts_and_lives_on(importable_tests):
    process = JobProcess()
    try:
        assert process.call(sweep_faults.add_one, 41, 10) == ("ok", 42)
        kind, settings = process.call(sweep_faults.thread_settings, None, 10)  # one core per job, always
        assert kind == "ok" and set(settings.values()) == {"1"} and "NUMBA_NUM_THREADS" in settings
        assert process.call(sweep_faults.shout, 7, 10) == ("ok", 7)  # a print cannot garble the reply
        assert process.call(sweep_faults.raise_value_error, 3, 10) == ("error", "ValueError: bad value 3")
        kind, message = process.call(sweep_faults.die, None, 10)
        assert kind == "crashed" and message.startswith("its process was killed by SIGKILL")
        start = time.monotonic()
        kind, message = process.call(sweep_faults.sleep_for, 60, 1.0)
        assert kind == "timeout" and message == "ran past the job timeout of 1 s; its process was killed"
        assert time.monotonic() - start < 10
        assert process.call(sweep_faults.add_one, 1, 10) == ("ok", 2)  # a new process after each death
    finally:
        process.close()


# -- the compact store ------------------------------------------------------------------
bars = st.lists(st.tuples(st.floats(0, 1e6), st.one_of(st.floats(0, 1e6), st.just(np.inf))).map(
    lambda bl: (bl[0], bl[0] + bl[1])), max_size=20)  # (birth, birth + length)


def _diagram(pairs_per_dim):
    return Diagram(tuple(np.array(p, dtype=float).reshape(-1, 2) for p in pairs_per_dim), "test")


@given(st.lists(st.tuples(st.lists(st.lists(bars, min_size=1, max_size=3), min_size=1, max_size=4),
                          st.lists(bars, min_size=1, max_size=3)), min_size=1, max_size=3))
def test_diagrams_read_back_bit_for_bit(regions_bars):
    # each region: windows' diagrams and a diagram of its own, written after the windows as run_job does
    regions = [{"events": i, "window": 0.5 * i, "windows": [{"t0": 0.0, "diagram": _diagram(d)} for d in windows],
                "diagram": _diagram(own)} for i, (windows, own) in enumerate(regions_bars)]
    back = decode_regions(encode_regions(regions))
    assert [r["events"] for r in back] == list(range(len(regions))) and back[-1]["window"] == 0.5 * (len(regions) - 1)

    def same(got, want):
        assert len(got.pairs) == len(want.pairs)
        for g, w in zip(got.pairs, want.pairs):
            assert g.tobytes() == np.ascontiguousarray(w, dtype=float).tobytes()
    for region, original in zip(back, regions):
        same(region["diagram"], original["diagram"])
        for w, o in zip(region["windows"], original["windows"]):
            same(w["diagram"], o["diagram"])


def test_rows_keep_the_diagrams_asked_for_and_a_store_that_keeps_less_is_rerun(tmp_path):
    job = cheap_jobs("keep", 1)[0]
    rows = {keep: run_job(job, keep) for keep in ("none", "map", "windows")}
    regions = {keep: decode_regions(row["diagrams"]) for keep, row in rows.items()}
    assert "diagram" not in regions["none"][0] and "diagram" not in regions["none"][0]["windows"][0]
    assert "diagram" in regions["map"][0] and "diagram" not in regions["map"][0]["windows"][0]
    assert all("diagram" in w for w in regions["windows"][0]["windows"])
    chosen = regions["windows"][0]["windows"][regions["windows"][0]["window"]]["diagram"]
    assert [p.tobytes() for p in chosen.pairs] == [p.tobytes() for p in regions["map"][0]["diagram"].pairs]
    assert len(rows["windows"]["diagrams"]) > len(rows["map"]["diagrams"]) > len(rows["none"]["diagrams"])
    store = tmp_path / "s.duckdb"
    ResultStore(store).write([rows["map"]])
    assert run_sweep([job], store, keep="map").run == 0
    again = run_sweep([job], store, keep="windows", workers=1)
    assert again.run == 1
    (row,) = read_jobs(store)
    assert row["diagrams_kept"] == "windows" and result_columns(row) == result_columns(rows["windows"])


def test_a_reader_in_another_process_and_the_writer_take_turns(tmp_path):
    store_path = tmp_path / "s.duckdb"
    store = ResultStore(store_path)
    rows = [run_job(job) for job in cheap_jobs("turns", 3)]
    store.add_to_sweep("turns", [row["key"] for row in rows])
    assert store.write(rows[:1])
    holder = subprocess.Popen([sys.executable, "-c", "import duckdb, sys; db = duckdb.connect(sys.argv[1], "
                               "read_only=True); print('open', flush=True); sys.stdin.read()", str(store_path)],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "open\n"
        assert not store.write(rows[1:], wait=0.3)  # held: nothing written, the caller keeps the rows
        start = time.monotonic()  # readers share the file: status answers at once
        assert store_status(store_path).sweeps[0].counts == {"ok": 1} and time.monotonic() - start < 5
    finally:
        holder.communicate("", timeout=30)
    assert store.write(rows[1:2])
    # iter_jobs opens the file for each chunk: a writer gets its turn between them; rows
    # written after the reading began are not yielded
    reading = iter_jobs(store_path, chunk_rows=1)
    first = next(reading)
    assert store.write(rows[2:])
    assert [first["key"], *(r["key"] for r in reading)] == [r["key"] for r in rows[:2]]  # the order written
    assert [r["key"] for r in iter_jobs(store_path, keys=[rows[2]["key"]], columns=("key",))] == [rows[2]["key"]]


def test_a_failed_row_never_replaces_a_good_one_and_rows_go_aside_when_the_store_refuses(tmp_path):
    import pyarrow.parquet as pq

    from swarmtopo.experiments.sweep import failed_row

    job = cheap_jobs("replace", 1)[0]
    good = run_job(job)
    assert good["status"] == "ok"
    store = ResultStore(tmp_path / "s.duckdb")
    assert store.write([failed_row(job, "timeout", "ran past")]) and store.write([good])  # good replaces failed
    assert store.write([failed_row(job, "crashed", "killed")])  # ... but not the other way round
    (row,) = read_jobs(tmp_path / "s.duckdb")
    assert row["status"] == "ok" and result_columns(row) == result_columns(good)
    aside = store.save_aside([good])
    assert aside.parent == tmp_path and pq.read_table(aside).column("key").to_pylist() == [good["key"]]


def test_failures_group_by_kind_and_message_up_to_numbers():
    assert message_pattern("too little data: 31 events among 4 agents (1.5e3 s)") == \
        "too little data: # events among # agents (# s)"
    groups = group_failures([("error", "too little data: 31 events", 1), ("error", "too little data: 12 events", 2),
                             ("timeout", "ran past 5 s", 1), ("error", "ValueError: x", 1)])
    assert [(g.status, g.count, g.example, g.varied) for g in groups] == [
        ("error", 3, "too little data: 12 events", True), ("error", 1, "ValueError: x", False),
        ("timeout", 1, "ran past 5 s", False)]


# -- bad jobs on a real scheduler and workers -------------------------------------------
@pytest.mark.slow
def test_poison_jobs_are_rows_the_sweep_goes_on_and_retry_failed_reruns_them(tmp_path, dask_cluster):
    jobs = cheap_jobs("poison", 6, salt="poison")
    store = tmp_path / "s.duckdb"
    calls = []
    summary = run_sweep(jobs, store, scheduler=dask_cluster, job_timeout=5.0, runner=sweep_faults.faulty_job,
                        progress=lambda *a: calls.append(a))
    assert calls[0] == (0, 6, 0) and calls[-1][:2] == (6, 6), read_jobs(store, columns=("key", "error"))  # the total is known before the cluster is used
    assert (summary.run, summary.failed, summary.workers) == (6, {"crashed": 1, "error": 1, "timeout": 1}, 2), \
        summary.failures
    rows = {row["replicate"]: row for row in read_jobs(store)}
    assert rows[0]["status"] == "crashed" and "killed by SIGKILL" in rows[0]["error"]
    assert (rows[1]["status"], rows[1]["error"]) == ("error", "ZeroDivisionError: a bug over two lines")
    assert rows[2]["status"] == "timeout" and rows[2]["error"].startswith("ran past the job timeout of 5 s")
    for r in (0, 1, 2):
        assert rows[r]["est_betti1"] is None and rows[r]["true_betti1"] is None and rows[r]["diagrams"] is None
    reference = {job.key: result_columns(run_job(job)) for job in jobs}
    for r in (3, 4, 5):
        assert result_columns(rows[r]) == reference[rows[r]["key"]]
    # a rerun skips failed rows; --retry-failed runs them again and replaces them
    assert run_sweep(jobs, store, scheduler=dask_cluster, runner=sweep_faults.faulty_job).run == 0
    retried = run_sweep(jobs, store, scheduler=dask_cluster, retry_failed=True)
    assert (retried.run, retried.skipped, retried.failed) == (3, 3, {})
    assert {row["key"]: result_columns(row) for row in read_jobs(store)} == reference


@pytest.mark.slow
def test_a_job_that_kills_its_workers_is_a_crashed_row(tmp_path, importable_tests):
    import dask
    import distributed  # noqa: F401  (its config must exist before the setting below, or leaving it drops it)

    jobs = cheap_jobs("killer", 1)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        summary = run_sweep(jobs, tmp_path / "s.duckdb", workers=1, runner=sweep_faults.worker_killer)
    assert summary.failed == {"crashed": 1}
    (row,) = read_jobs(tmp_path / "s.duckdb")
    assert row["status"] == "crashed" and row["error"].startswith("its workers died running it alone on the cluster (KilledWorker")


def test_jobs_per_task_grow_as_jobs_prove_cheap():
    from swarmtopo.experiments.sweep import MAX_JOBS_PER_TASK, TASK_SECONDS, _jobs_per_task

    assert _jobs_per_task([]) == _jobs_per_task([0.001] * 7) == 1  # one job per task until 8 are timed
    assert _jobs_per_task([0.01] * 8) == int(TASK_SECONDS / 0.01)
    assert _jobs_per_task([1e-6] * 8) == MAX_JOBS_PER_TASK and _jobs_per_task([2.0] * 100) == 1


@pytest.mark.slow
def test_a_worker_killer_inside_a_task_of_many_jobs_is_the_only_crashed_row(tmp_path, importable_tests, monkeypatch):
    import dask
    import distributed  # noqa: F401  (its config must exist before the setting below, or leaving it drops it)

    monkeypatch.setattr("swarmtopo.experiments.sweep.IN_FLIGHT", 1)  # 4 tasks in flight: later jobs share tasks
    jobs = expand_grid({"sweep": {"name": "chunks", "replicates": 20, "salt": "chunk-kill"},
                        "swarm": {"agents": 1, "duration": 1.0}}).jobs
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        summary = run_sweep(jobs, tmp_path / "s.duckdb", workers=1, runner=sweep_faults.kills_worker_at_15)
    assert (summary.run, summary.failed) == (20, {"crashed": 1, "error": 19})  # 1 agent: "too little data"
    rows = read_jobs(tmp_path / "s.duckdb")
    (crashed,) = [row for row in rows if row["status"] == "crashed"]
    assert crashed["replicate"] == 15
    assert {row["key"]: result_columns(row) for row in rows if row is not crashed} == \
        {job.key: result_columns(run_job(job)) for job in jobs if job.replicate != 15}


def _cli_sweep(toml, store, *extra):
    return subprocess.Popen([sys.executable, "-m", "swarmtopo", "sweep", str(toml), "--store", str(store),
                             "--verbose", *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def _wait_for_rows(store, proc, n=1, timeout=120):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        if store.exists() and len(read_jobs(store, columns=("key",))) >= n:
            return
        time.sleep(0.1)
    raise AssertionError(f"no row in {store} after {timeout} s (exit code {proc.poll()})")


@pytest.mark.slow
def test_a_lost_worker_is_counted_and_a_lost_scheduler_is_one_line_with_the_resume_command(tmp_path, sweep_file):
    with local_dask(tmp_path, workers=2, nanny=False) as (address, scheduler, workers):
        jobs = cheap_jobs("slow", 6)

        def kill_a_worker(done, total, failed):
            if done == 1:
                stop_group(workers[0])
        summary = run_sweep(jobs, tmp_path / "a.duckdb", scheduler=address, runner=sweep_faults.slow_job,
                            progress=kill_a_worker)
        assert (summary.run, summary.failed, summary.workers) == (6, {}, 1)  # workers at the end
    # a loaded machine may finish the 8 jobs (their rows written in one batch) before the
    # scheduler is stopped: try up to three fresh clusters and stores, assert on the first cut short
    for attempt in range(3):
        logs = tmp_path / f"lost-{attempt}"
        logs.mkdir()
        with local_dask(logs, workers=2, nanny=False) as (address, scheduler, workers):
            store = tmp_path / f"b{attempt}.duckdb"
            proc = _cli_sweep(sweep_file, store, "--scheduler", address)
            try:
                _wait_for_rows(store, proc)
                stop_group(scheduler)
                _, stderr = proc.communicate(timeout=120)
            finally:
                stop_group(proc)
        if not (proc.returncode == 0 and len(read_jobs(store, columns=("key",))) == 8):
            break
    assert proc.returncode == 1 and "Traceback" not in stderr, stderr
    line = stderr.strip().splitlines()[-1]
    saved = len(read_jobs(store, columns=("key",)))
    assert 1 <= saved < 8
    assert line.startswith(f"error: lost the Dask scheduler at {address} (")
    assert line.endswith(f"resume with: swarmtopo sweep {sweep_file} --store {store} --scheduler {address}")
    assert store_status(store).runs[-1]["outcome"] == "scheduler lost"


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("sweep") / "tiny.toml"
    path.write_text('[sweep]\nname = "tiny"\nreplicates = 4\n[arena]\nholes = [1, 2]\n'
                    '[swarm]\nagents = 200\nduration = 60\n[map]\nlandmarks = 100\n')
    return path


def test_an_unreachable_scheduler_is_one_line_and_creates_no_store(tmp_path, sweep_file, monkeypatch):
    monkeypatch.setattr("swarmtopo.pipeline.engine.CONNECT_TIMEOUT", 2.0)  # the CLI runs in this process
    address = f"tcp://127.0.0.1:{free_port()}"
    proc = run_cli("sweep", sweep_file, "--store", tmp_path / "r.duckdb", "--scheduler", address)
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    (line,) = proc.stderr.strip().splitlines()
    assert line.startswith(f"error: cannot connect to the Dask scheduler at {address!r}")
    assert not (tmp_path / "r.duckdb").exists()


# -- the command line -------------------------------------------------------------------
@pytest.mark.slow
def test_status_reads_the_store_while_the_sweep_writes_it(tmp_path, sweep_file):
    store = tmp_path / "s.duckdb"
    proc = _cli_sweep(sweep_file, store, "--workers", "1")
    watchdog = threading.Timer(240, stop_group, [proc])
    watchdog.start()
    try:
        _wait_for_rows(store, proc)
        during = run_cli("status", store)
        proc.communicate(timeout=240)
    finally:
        watchdog.cancel()
        stop_group(proc)
    assert proc.returncode == 0 and during.returncode == 0, during.stderr
    head = during.stdout.splitlines()[0]
    assert head.startswith("sweep 'tiny': 8 jobs: ") and not head.endswith(" 0 pending")
    assert "running since" in during.stdout
    after = run_cli("status", store)
    counts = store_status(store).sweeps[0].counts
    assert after.stdout.splitlines()[0] == (f"sweep 'tiny': 8 jobs: {counts.get('ok', 0)} done, "
                                            f"{counts.get('error', 0)} failed"
                                            f"{' (%d error)' % counts['error'] if counts.get('error') else ''}, "
                                            "0 pending")
    assert "ended (finished)" in after.stdout


def test_cli_job_timeout_makes_timeout_rows_and_retry_failed_reruns_them(tmp_path):
    toml = tmp_path / "quick.toml"
    toml.write_text('[sweep]\nname = "quick"\nreplicates = 2\n[swarm]\nagents = 100\nduration = 20\n'
                    '[map]\nlandmarks = 60\n')
    store = tmp_path / "r.duckdb"
    first = run_cli("sweep", toml, "--store", store, "--workers", "1", "--job-timeout", "0.001")
    assert first.returncode == 1 and "Traceback" not in first.stderr
    assert first.stderr.strip().splitlines() == [
        f"error: sweep 'quick': all 2 jobs failed (timeout: ran past the job timeout of 0.001 s; its process "
        f"was killed); their rows are in {store}"]
    status = run_cli("status", store).stdout.splitlines()
    assert status[:2] == ["sweep 'quick': 2 jobs: 0 done, 2 failed (2 timeout), 0 pending",
                          "failed 2x (timeout): ran past the job timeout of 0.001 s; its process was killed"]
    again = run_cli("sweep", toml, "--store", store, "--workers", "1", "--retry-failed")
    assert again.returncode == 0, again.stderr
    assert "sweep 'quick': 2 jobs: 2 run (0 failed), 0 already in the store" in again.stdout
    assert [row["status"] for row in read_jobs(store, columns=("key", "status"))] == ["ok", "ok"]


def test_status_of_a_missing_or_foreign_file_is_one_line(tmp_path):
    proc = run_cli("status", tmp_path / "none.duckdb")
    assert proc.returncode == 1 and proc.stderr.strip() == f"error: {tmp_path / 'none.duckdb'}: no such result store"
    with pytest.raises(SwarmtopoError, match="no such result store"):
        store_status(tmp_path / "none.duckdb")
    (tmp_path / "text.duckdb").write_text("not a database")
    proc = run_cli("status", tmp_path / "text.duckdb")
    assert proc.returncode == 1 and len(proc.stderr.strip().splitlines()) == 1
    assert proc.stderr.startswith(f"error: {tmp_path / 'text.duckdb'}: cannot open the result store")
