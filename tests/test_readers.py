"""The one reader interface (readers.base) and the registry of presets (readers.registry):
every preset reads a region of real windows exactly as the step-by-step calls do."""

import dataclasses
import json
import subprocess
import sys

import numpy as np
import pytest

from swarmtopo.arena import default_arena, two_rooms_arena
from swarmtopo.errors import InputError
from swarmtopo.experiments.sweep import contact_trace
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.readers.base import BettiReader, RegionReading, product_confidence
from swarmtopo.readers.paper import BettiClassifier
from swarmtopo.readers.base import longest_bars, vote
from swarmtopo.readers.ratio import RatioClassifier
from swarmtopo.readers.registry import PRESETS, load_classifier, shipped_reader_for
from swarmtopo.sim import simulate


@pytest.fixture(scope="module")
def regions():
    """(windows' diagrams, events per window) of every region of three real maps: a one-hole
    square, two rooms, and the square's log read as a contact trace."""
    square = simulate(default_arena(), 200, 30.0, rng=3).log
    logs = [square, simulate(two_rooms_arena(), 200, 30.0, rng=7).log, contact_trace(square)]
    out = []
    for log in logs:
        for region in map_encounters(log, MapConfig(max_landmarks=80, embed_dim=0)).regions:
            out.append(([w.diagram for w in region.windows], [w.n_events for w in region.windows]))
    return out


def literal_reading(reader, windows, events):
    """The region's reading by the calls the pipeline made one by one before ``read``."""
    voted = vote(reader, windows, events)
    betti, rep, counts = voted
    return {"betti": betti, "window": rep,
            "window_betti": [{n: counts[n][w] for n in counts} for w in range(len(windows))],
            "confidence": reader.region_confidence(windows, voted),
            "counted": {n: longest_bars(windows[rep], n, k) for n, k in betti.items()},
            "thresholds": reader.length_thresholds(windows[rep])}


@pytest.mark.parametrize("name", PRESETS)
def test_every_preset_reads_a_region_of_real_windows_as_the_step_by_step_calls(regions, name):
    reader = load_classifier(name)
    assert isinstance(reader, BettiReader)
    assert len(regions) >= 4 and any(len(windows) > 2 for windows, _ in regions)
    for windows, events in regions:
        for weights in (events, None):
            got = reader.read(windows, weights)
            want = literal_reading(reader, windows, weights)
            assert {k: v for k, v in dataclasses.asdict(got).items() if k != "counted"} == {
                k: v for k, v in want.items() if k != "counted"}
            assert got.counted.keys() == want["counted"].keys()
            for n in got.counted:
                np.testing.assert_array_equal(got.counted[n], want["counted"][n])
                # the counted bars are the representative window's longest, as many as the region's count
                lengths = windows[got.window].lengths(n)
                assert len(got.counted[n]) == min(got.betti[n], len(lengths))
                assert np.all(lengths[got.counted[n]][:, None] >= np.delete(lengths, got.counted[n])[None, :])
    confidences = [reader.read(windows, events).confidence.get(1) for windows, events in regions[1:3]]
    exponent = (reader.calibration_ or {}).get("1", {}).get("regions_exponent", 1.0) \
        if isinstance(reader, RatioClassifier) else 1.0
    assert reader.map_confidence(confidences, 1) == pytest.approx(product_confidence(confidences, exponent))


def test_a_reading_is_frozen_data():
    reading = RegionReading(betti={1: 0}, window=0, window_betti=[{1: 0}], confidence={1: None}, counted={},
                            thresholds={1: 1.0})
    with pytest.raises(dataclasses.FrozenInstanceError):
        reading.window = 1


def test_a_maps_confidence_is_the_product_of_its_regions_raised_only_by_a_fitted_power():
    assert product_confidence([0.9, 0.8]) == pytest.approx(0.72)
    assert product_confidence([0.9, 0.8], 0.5) == pytest.approx(0.72 ** 0.5)
    assert product_confidence([0.9], 0.5) == 0.9
    assert product_confidence([0.9, None]) is None and product_confidence([]) is None
    paper = load_classifier("paper")
    assert paper.map_confidence([0.9, 0.8]) == pytest.approx(0.72)  # fitted with no power


def test_the_presets_are_one_definition_each_and_map_picks_by_the_logs_status():
    assert PRESETS == ("default", "trace", "paper")
    kinds = {name: type(load_classifier(name)) for name in PRESETS}
    assert kinds == {"default": RatioClassifier, "trace": RatioClassifier, "paper": BettiClassifier}
    assert {name: load_classifier(name).landmark_bands for name in PRESETS} == {
        "default": (1.0, 0.5), "trace": (1.0,), "paper": (1.0,)}
    log = simulate(default_arena(), 30, 2.0, rng=0).log
    assert len(log.status_t) and shipped_reader_for(log) == "default"
    assert shipped_reader_for(contact_trace(log)) == "trace"
    for retired in ("gated", "paper-form"):
        with pytest.raises(InputError, match="no such classifier: expected one of default, trace, paper"):
            load_classifier(retired)


def test_a_file_of_an_earlier_format_is_refused_naming_it_and_the_formats_read(tmp_path):
    obj = load_classifier("default").to_json()
    obj["format"] = "swarmtopo-ratio-classifier/4"
    path = tmp_path / "old.json"
    path.write_text(json.dumps(obj))
    with pytest.raises(InputError) as caught:
        load_classifier(path)
    assert (caught.value.file, caught.value.value) == (str(path), "swarmtopo-ratio-classifier/4")
    assert '"swarmtopo-ratio-classifier/5"' in caught.value.reason and '"swarmtopo-classifier/1"' in caught.value.reason
    path.write_text("[1, 2")
    with pytest.raises(InputError, match="old.json"):
        load_classifier(path)


@pytest.mark.parametrize("first", ["swarmtopo.readers.registry", "swarmtopo.readers.paper",
                                   "swarmtopo.readers.ratio"])
def test_the_readers_import_in_any_order(first):
    code = (f"import {first}; from swarmtopo.readers.registry import load_classifier; "
            "print(type(load_classifier('paper')).__name__)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "BettiClassifier"
