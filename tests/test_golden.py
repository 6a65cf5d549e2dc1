"""Golden maps: the exact output of ``swarmtopo simulate`` and ``swarmtopo map`` on small
seeded cases, every option at its default.

Any change to what the simulator or the pipeline computes changes a pin here and fails
in seconds; whether the change is for the better is the accuracy benchmark's question
(``python benchmarks/bench_accuracy_slice.py``, then ``swarmtopo bench accuracy``).

Updating the pins after an intentional change: check the slice first (it must not
regress), then run ``python -m pytest tests/test_golden.py``; each failure prints the
case's new pins as the line of ``GOLDEN`` to paste.  Paste them, rerun, and say in the
commit why the maps changed.
"""

import hashlib
import json

import pytest

GOLDEN = {
    "one_hole": ({"0": 1, "1": 1}, "226902f44b0d0def82f15f905f95e96bbd92a16f3b87eaa66b01a61d563be3ac",
                 "712be6e5b93bb85a2ecf56ee7b66397a8506fa3cf83d7bd771c498aecca3afbb"),
    "two_rooms": ({"0": 2, "1": 1}, "039449b6a62d366be2702e2300906ebf25e157c290181328899dd370403df37a",
                  "4301b4ffb024b21cb4d39853068ec62b037eeba151373020b9b7b939479a483b"),
}
"""Case -> (Betti numbers, :func:`log_digest`, :func:`map_digest`); the Betti numbers are
the arenas' true ones (the one-hole arena's (1, 1); two rooms, one with a hole: (2, 1))."""

SIGNIFICANT_DIGITS = 10
"""Floats are hashed at this precision: a last-bit difference of another CPU's BLAS or
libm (the confidences go through exp and log, the MDS stress through LAPACK) is not a
change of the map; any change of the pipeline's arithmetic is."""


def rounded(value):
    """``value`` (parsed JSON) with every float at :data:`SIGNIFICANT_DIGITS` significant digits."""
    if isinstance(value, float):
        return float(f"{value:.{SIGNIFICANT_DIGITS}g}")
    if isinstance(value, list):
        return [rounded(v) for v in value]
    if isinstance(value, dict):
        return {k: rounded(v) for k, v in value.items()}
    return value


def map_digest(doc: dict) -> str:
    """SHA-256 of map.json without its timings and software versions, floats :func:`rounded`."""
    kept = {k: v for k, v in doc.items() if k not in ("timings", "software")}
    return hashlib.sha256(json.dumps(rounded(kept), sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def log_digest(folder) -> str:
    """SHA-256 of the log folder's events.csv and status.csv bytes."""
    digest = hashlib.sha256()
    for name in ("events.csv", "status.csv"):
        digest.update((folder / name).read_bytes())
    return digest.hexdigest()


@pytest.mark.parametrize("case", sorted(GOLDEN))
def test_golden_logs_and_maps_are_unchanged(case, request):
    log = request.getfixturevalue(f"{case}_log")
    run = request.getfixturevalue(f"{case}_map")
    got = (run.doc["betti"], log_digest(log.folder), map_digest(run.doc))
    assert got == GOLDEN[case], (f"the {case} case changed (log digest {'same' if got[1] == GOLDEN[case][1] else 'new'}); "
                                 f"if intended, paste into GOLDEN:\n    {case!r}: {got!r},")


def test_rounding_keeps_ten_significant_digits_and_every_other_value():
    doc = {"a": [0.1 + 0.2, 1e-300, None, "x", 3, True], "b": {"c": 123456789012.5}}
    assert rounded(doc) == {"a": [0.3, 1e-300, None, "x", 3, True], "b": {"c": 123456789000.0}}
    assert map_digest({"betti": 1, "timings": {"graph": 1.0}}) == map_digest({"betti": 1, "software": {}})
    assert map_digest({"betti": 1}) != map_digest({"betti": 2})


READINGS = {
    "paper": ({"0": 1, "1": 1}, "3f2ac6e655abfb82bb6b39c26f715bd00d295aa20bd4e8a56078989798a81b53"),
    "trace": ({"0": 1, "1": 1}, "6abc69c1f6ddc181e62d9f81f9f1a2acfc6ff068fc1bad2c841e079a9caedf6a"),
}
"""Reading -> (Betti numbers, :func:`map_digest`) of the ``one_hole`` log mapped as a
contact trace (its events.csv alone: the ``trace`` reader) and with ``--paper`` (the
paper's pipeline and its ``paper`` reader)."""


@pytest.mark.parametrize("reading", sorted(READINGS))
def test_golden_readings_of_the_one_hole_log_are_unchanged(reading, one_hole_log, tmp_path, cli):
    import shutil

    if reading == "trace":
        folder = tmp_path / "trace"
        folder.mkdir()
        shutil.copy(one_hole_log.folder / "events.csv", folder / "events.csv")
        args = ()
    else:
        folder, args = one_hole_log.folder, ("--paper",)
    proc = cli("map", folder, "--out", tmp_path / "map", "-q", *args)
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((tmp_path / "map" / "map.json").read_text(encoding="utf-8"))
    assert doc["classifier"]["classifier"] == reading
    got = (doc["betti"], map_digest(doc))
    assert got == READINGS[reading], f"the {reading} reading changed; if intended, paste into READINGS:\n    {reading!r}: {got!r},"
