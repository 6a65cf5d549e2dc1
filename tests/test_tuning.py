"""Tuning the ratio classifier: the grid fit finds a separating threshold; cross-fitted calibration."""

import numpy as np

from swarmtopo.experiments.tuning import TuningMap, calibrated_classifier, exact, fit_thresholds
from swarmtopo.persistence import Diagram
from swarmtopo.ratio import RatioThresholds, WindowBars


def window(holes, rng):
    """Ten noise bars of length ~1 (born at 1-2) and ``holes`` bars 8-12 times longer."""
    noise = [[b, b + rng.uniform(0.5, 1.5)] for b in rng.uniform(1, 2, 10)]
    signal = [[b, b + rng.uniform(8, 12)] for b in rng.uniform(1, 2, holes)]
    pairs = np.array(noise + signal, dtype=float).reshape(-1, 2)
    return WindowBars(Diagram(pairs=(np.array([[0.0, np.inf]]), pairs), backend="test"), 1.0)


def synthetic_maps(n, rng):
    maps = []
    for i in range(n):
        holes = int(rng.integers(0, 4))
        windows = tuple(window(holes, rng) for _ in range(3))
        maps.append(TuningMap(regions=(windows,), est_betti0=1, true_betti0=1, true_betti1=holes, cell="c"))
    return maps


def test_fit_finds_a_threshold_between_noise_and_holes():
    maps = synthetic_maps(40, np.random.default_rng(0))
    fit = fit_thresholds(maps)
    assert fit.accuracy == 1.0 and exact(maps, fit.thresholds).all()
    # the median length is ~1 (noise dominates), holes are >= 8: tau must sit in between
    assert 1.5 < fit.thresholds.tau < 8.0
    # a threshold outside that gap is wrong on the maps with holes (or without)
    assert not exact(maps, RatioThresholds(fit.thresholds.q, 20.0)).all()
    assert not exact(maps, RatioThresholds(fit.thresholds.q, 1.01)).all()


def test_cross_fitted_calibration_is_confident_on_clean_maps():
    maps = synthetic_maps(30, np.random.default_rng(1))
    model = calibrated_classifier(maps, fit_thresholds(maps), provenance={"name": "t"}, folds=3)
    assert model.provenance_["calibration"] == "3-fold cross-fitted"
    # every out-of-fold outcome is right: the smoothed rate (30 + 1) / (30 + 2)
    confidence = model.region_confidence(maps[0].regions[0])[1]
    assert np.isclose(confidence, 31 / 32)
    assert np.isclose(model.beta0_confidence(), 31 / 32)
