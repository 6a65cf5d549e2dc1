"""One map on many workers: the same bytes on this process's threads, an embedded Dask
cluster of processes and an existing cluster (a real scheduler and workers on 127.0.0.1)."""

import json

import numba
import pytest

from conftest import run_cli
from swarmtopo.io.logs import read_log
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.viz.summary import map_json


def _map_doc(folder) -> dict:
    """map.json without what differs from run to run by design (stage timings)."""
    doc = json.loads((folder / "map.json").read_text(encoding="utf-8"))
    doc.pop("timings")
    return doc


def _api_doc(tmap) -> dict:
    doc = json.loads(json.dumps(map_json(tmap)))
    doc.pop("timings")
    return doc


@pytest.mark.slow
def test_a_local_cluster_of_two_processes_maps_the_same_bytes(one_hole_log, one_hole_map, tmp_path):
    proc = run_cli("map", one_hole_log.folder, "--out", tmp_path / "map", "--workers", "2", "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert _map_doc(tmp_path / "map") == _map_doc(one_hole_map.folder)


@pytest.mark.slow
def test_an_existing_cluster_maps_a_two_region_log_to_the_same_bytes(two_rooms_log, two_rooms_map, dask_cluster,
                                                                     tmp_path):
    proc = run_cli("map", two_rooms_log.folder, "--out", tmp_path / "map", "--scheduler", dask_cluster, "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert _map_doc(tmp_path / "map") == _map_doc(two_rooms_map.folder)
    assert len(_map_doc(tmp_path / "map")["regions"]) == 2


@pytest.mark.slow
def test_the_api_takes_a_client_and_its_workers_get_one_numba_thread(one_hole_log, dask_cluster):
    from distributed import Client

    log = read_log(one_hole_log.folder)
    config = MapConfig(landmarks=60, window_scales=(1.0,), embed_dim=0)
    alone = map_encounters(log, config)
    with Client(dask_cluster) as client:
        on_cluster = map_encounters(log, config, scheduler=client)
        threads = client.run(lambda: __import__("numba").config.NUMBA_NUM_THREADS)
    assert _api_doc(on_cluster) == _api_doc(alone)
    assert set(threads.values()) == {1}, threads


def test_one_thread_or_two_give_the_same_map(one_hole_log):
    """The thread engine runs as many threads as the caller's numba threads."""
    log = read_log(one_hole_log.folder)
    config = MapConfig(landmarks=40, window_scales=(1.0,), max_windows=4, embed_dim=0)
    before = numba.get_num_threads()
    docs = []
    try:
        for threads in (1, 2):
            numba.set_num_threads(threads)
            docs.append(_api_doc(map_encounters(log, config)))
    finally:
        numba.set_num_threads(before)
    assert docs[0] == docs[1]


def test_workers_and_scheduler_together_are_a_usage_error(one_hole_log, tmp_path):
    proc = run_cli("map", one_hole_log.folder, "--out", tmp_path / "map", "--workers", "2", "--scheduler",
                   "tcp://127.0.0.1:1")
    assert proc.returncode == 2
    assert "not both" in proc.stderr


def test_an_unreachable_scheduler_is_one_line(one_hole_log, tmp_path):
    proc = run_cli("map", one_hole_log.folder, "--out", tmp_path / "map", "--scheduler", "tcp://127.0.0.1:9")
    assert proc.returncode == 1
    assert "cannot connect to the Dask scheduler" in proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "map").exists()


def test_a_region_without_a_picture_takes_no_draw_from_the_stream(two_rooms_log):
    """The MDS draws from the map's stream only when it runs (a region's chosen window
    with more landmarks than the picture's dimension), as the map always did: with 3
    landmarks per room no picture is drawn, so the second room's landmark starts are the
    same with or without pictures; with 4, the picture's draw moves them."""
    log = read_log(two_rooms_log.folder)
    for per_room, same in ((3, True), (4, False)):
        maps = [map_encounters(log, MapConfig(landmarks=2 * per_room, window_scales=(1.0,), max_windows=3,
                                              embed_dim=dim, cycles=False)) for dim in (3, 0)]
        assert [len(r.regions) for r in maps] == [2, 2]
        starts = [[w.landmarks.params["start"] for w in tmap.regions[1].windows] for tmap in maps]
        assert (starts[0] == starts[1]) == same, starts


@pytest.mark.slow
def test_ctrl_c_during_a_map_on_a_local_cluster_is_one_line(two_rooms_log, tmp_path):
    """Ctrl-C as a terminal sends it (to the whole process group, the cluster's workers
    included) while the windows run on a local cluster: one line, exit 130, nothing written."""
    import os
    import signal
    import subprocess
    import sys
    import time

    for delay in (4.0, 6.0):
        out = tmp_path / f"map-{delay}"
        proc = subprocess.Popen([sys.executable, "-m", "swarmtopo", "map", str(two_rooms_log.folder), "--out",
                                 str(out), "--workers", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True, start_new_session=True)
        time.sleep(delay)
        os.killpg(proc.pid, signal.SIGINT)
        _, stderr = proc.communicate(timeout=120)
        if proc.returncode == 0:  # the map finished first
            continue
        assert proc.returncode == 130, stderr
        assert len(stderr.strip().splitlines()) == 1 and stderr.startswith("interrupted: no"), stderr
        assert not out.exists()
