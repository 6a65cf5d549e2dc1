"""Tuning the ratio classifier: the grid fit finds a separating threshold and agrees with
the literal classifier at every grid point; cross-fitted calibration."""

import dataclasses

import numpy as np
import pytest

from tuning import (TuningMap, calibrated_classifier, cross_fitted_features, cross_validated, exact, features_under,
                    fit_regions_exponent, fit_thresholds, maps_from_rows, regions_exponent_scores,
                    several_region_products, training_set)
from swarmtopo.readers.ratio import (CONFIDENCE_FEATURES, Q_GRID, REGIONS_EXPONENT, TAU_GRID, RatioClassifier,
                                     RatioThresholds, grid_estimates)
from swarmtopo.topology.persistence import Diagram


def window(holes, rng):
    """Ten noise bars of length ~1 (born at 1-2) and ``holes`` bars 8-12 times longer."""
    noise = [[b, b + rng.uniform(0.5, 1.5)] for b in rng.uniform(1, 2, 10)]
    signal = [[b, b + rng.uniform(8, 12)] for b in rng.uniform(1, 2, holes)]
    pairs = np.array(noise + signal, dtype=float).reshape(-1, 2)
    return Diagram(pairs=(np.array([[0.0, np.inf]]), pairs), backend="test")


def synthetic_maps(n, rng):
    maps = []
    for i in range(n):
        holes = int(rng.integers(0, 4))
        windows = tuple(window(holes, rng) for _ in range(3))
        maps.append(TuningMap(regions=(windows,), est_betti0=1, true_betti0=1, true_betti1=holes, cell="c"))
    return maps


def test_fit_finds_a_threshold_between_noise_and_holes():
    maps = synthetic_maps(40, np.random.default_rng(0))
    for pooling in ("mean", "median"):
        fit = fit_thresholds(maps, pooling)
        assert fit.accuracy == 1.0 and exact(maps, fit.thresholds, pooling).all() and fit.pooling == pooling
        # the median length is ~1 (noise dominates), holes are >= 8: tau must sit in
        # between; a threshold outside that gap is wrong somewhere
        th = fit.thresholds
        assert 1.5 < th.tau < 8.0
        assert not exact(maps, RatioThresholds(th.q, 20.0), pooling).all()
        assert not exact(maps, RatioThresholds(th.q, 1.01), pooling).all()


def test_vectorised_grid_equals_the_literal_classifier():
    """grid_estimates at every grid point == the literal classifier's pooled count, both
    poolings, on maps with ties, infinite bars, empty diagrams and windows with no bars to cut."""
    rng = np.random.default_rng(3)
    maps = synthetic_maps(12, rng)
    tie = np.array([[1.0, 3.0], [2.0, 4.0], [0.5, 2.5], [1.0, 1.5], [1.0, np.inf]])
    odd = (Diagram(pairs=(np.array([[0.0, np.inf]]), tie), backend="test"),
           Diagram(pairs=(np.array([[0.0, np.inf]]), np.empty((0, 2))), backend="test"))
    maps.append(TuningMap(regions=(odd, maps[0].regions[0]), est_betti0=2, true_betti0=2, true_betti1=2, cell="c"))
    truth = np.array([m.true_betti1 for m in maps])
    for pooling in ("mean", "median"):
        est = grid_estimates(training_set(maps)[0], pooling)
        for i, q in enumerate(Q_GRID):
            for j in range(0, len(TAU_GRID), 7):
                literal = exact(maps, RatioThresholds(q, TAU_GRID[j]), pooling)
                assert np.array_equal(literal, est[:, i, j] == truth), (pooling, q, TAU_GRID[j])


def test_cross_fitted_calibration_is_confident_on_clean_maps():
    maps = synthetic_maps(30, np.random.default_rng(1))
    model = calibrated_classifier(maps, fit_thresholds(maps).thresholds, provenance={"name": "t"}, folds=3)
    assert model.provenance_["calibration"] == "3-fold cross-fitted"
    # every out-of-fold outcome is right: the smoothed rate (30 + 1) / (30 + 2)
    confidence = model.region_confidence(maps[0].regions[0])[1]
    assert np.isclose(confidence, 31 / 32)


def test_calibration_grid_maps_join_the_cross_fitted_ones_read_with_the_final_thresholds():
    rng = np.random.default_rng(5)
    maps, grid = synthetic_maps(30, rng), synthetic_maps(8, rng)
    grid[0] = dataclasses.replace(grid[0], true_betti1=grid[0].true_betti1 + 1)  # wrong under any thresholds
    grid[1] = dataclasses.replace(grid[1], est_betti0=2)  # beta_0 wrong: no beta_1 outcome
    th = fit_thresholds(maps).thresholds
    features, correct = features_under(grid, th)
    assert len(features) == 7 and correct == [False] + [True] * 6
    assert features[0] == RatioClassifier.from_thresholds({1: th}).region_features(grid[0].regions[0], 1)
    model = calibrated_classifier(maps, th, provenance={"name": "t"}, folds=3, beyond=grid)
    assert model.provenance_["calibration"] == "3-fold cross-fitted on 30 tuning maps and 7 calibration-grid maps"
    assert model.calibration_["1"]["maps"] == 37
    # the grid gives the resolution a range: its features are fitted only with grid maps
    assert set(model.calibration_["1"]) == {"intercept", "maps", *CONFIDENCE_FEATURES}
    assert set(calibrated_classifier(maps, th, provenance={}, folds=3).calibration_["1"]) == {"intercept", "maps", "z"}
    # 36 of 37 outcomes right, and the wrong one has the features of many right ones: below 36/37 at most
    assert model.region_confidence(grid[0].regions[0])[1] < calibrated_classifier(
        maps, th, provenance={}, folds=3).region_confidence(grid[0].regions[0])[1]


def test_the_regions_exponent_is_the_maximum_likelihood_power_and_recovers_a_known_one():
    rng = np.random.default_rng(7)
    s = np.log(rng.uniform(0.2, 1.0, 4000))  # ln of two-region products
    right = rng.random(4000) < np.exp(0.5 * s)  # P(right) = product ** 0.5
    a = fit_regions_exponent(s, right)
    assert abs(a - 0.5) < 0.05
    # the score equation of the likelihood is zero at its maximum: sum_right s = sum_wrong s p / (1 - p)
    p = np.exp(a * s)
    assert np.sum(s[right]) == pytest.approx(np.sum((s * p / (1 - p))[~right]), rel=1e-3)
    with pytest.raises(ValueError, match="both right and wrong"):
        fit_regions_exponent(s[right], right[right])


def test_regions_exponent_scores_hand_computed_constant_and_product():
    s, right = np.log(np.array([0.9, 0.5, 0.8, 0.3] * 5)), np.array([True, False, True, True] * 5)
    scores = regions_exponent_scores(s, right, folds=5)
    assert scores["constant"]["brier"] == pytest.approx(0.75 * 0.25)  # rate 3/4: mean of (3/4 - y)^2
    assert scores["product"]["brier"] == pytest.approx(np.mean((np.exp(s) - right) ** 2))
    assert 0 < scores["product to the power a (cross-fitted)"]["brier"] < 1
    # one wrong map cannot be cross-fitted: the fold that holds it trains on right maps only
    one_wrong = np.array([True] * 19 + [False])
    with pytest.raises(ValueError, match="too few maps right or wrong"):
        regions_exponent_scores(s, one_wrong, folds=5)


def two_region_maps(n, rng):
    """Maps of two rooms with 0-1 holes each; every third claims one hole more than it has."""
    maps = []
    for i in range(n):
        holes = [int(rng.integers(0, 2)) for _ in range(2)]
        regions = tuple(tuple(window(h, rng) for _ in range(3)) for h in holes)
        maps.append(TuningMap(regions=regions, est_betti0=2, true_betti0=2, true_betti1=sum(holes) + (i % 3 == 0),
                              cell="two rooms"))
    return maps


def test_several_region_products_are_the_literal_regions_product_and_join_the_calibration():
    rng = np.random.default_rng(11)
    maps = synthetic_maps(30, rng)
    rooms = two_region_maps(12, rng)
    th = fit_thresholds(maps).thresholds
    model = calibrated_classifier(maps + rooms, th, provenance={"name": "t"}, folds=3)
    log_products, right = several_region_products(maps + rooms, model)
    assert len(right) == 12 and right.tolist() == [i % 3 != 0 for i in range(12)]
    for m, s in zip(rooms, log_products):
        literal = np.prod([model.region_confidence(region)[1] for region in m.regions])
        assert np.exp(s) == pytest.approx(literal)
    a = model.calibration_["1"][REGIONS_EXPONENT]
    assert a == pytest.approx(fit_regions_exponent(log_products, right))
    assert model.provenance_["regions_calibration"] == "fitted on 12 several-region tuning maps"
    confidences = [model.region_confidence(region)[1] for region in rooms[0].regions]
    assert model.map_confidence(confidences) == pytest.approx(np.prod(confidences) ** a)
    # a one-room arena that a sparse log split in two is not a map of rooms: left out of the fit
    split = dataclasses.replace(rooms[0], true_betti0=1, true_betti1=rooms[0].true_betti1)
    assert len(several_region_products([split] + rooms, model)[1]) == 12
    # without several-region maps, or with all of them right, no exponent: the plain product
    assert REGIONS_EXPONENT not in calibrated_classifier(maps, th, provenance={}, folds=3).calibration_["1"]
    all_right = [m for m, ok in zip(rooms, right) if ok]
    assert REGIONS_EXPONENT not in calibrated_classifier(maps + all_right, th, provenance={}, folds=3).calibration_["1"]


def test_cross_validated_count_reads_every_map_once_with_out_of_fold_thresholds():
    rng = np.random.default_rng(2)
    one = TuningMap(regions=(tuple(window(2, rng) for _ in range(3)),), est_betti0=1, true_betti0=1, true_betti1=2,
                    cell="c")
    maps = [one] * 20  # every fold fits the same thresholds, and they read every map right
    for pooling in ("mean", "median"):
        assert cross_validated(maps, pooling) == 20
    wrong = maps[:5] + [dataclasses.replace(one, est_betti0=2)] + maps[6:]  # a beta_0 no threshold fixes
    assert cross_validated(wrong, "mean", folds=5) == 19
    assert cross_validated(wrong, "mean", folds=4) == 19  # counted once, whatever the folds


def test_cross_fitted_features_read_each_one_region_map_with_thresholds_fitted_without_it():
    maps = synthetic_maps(15, np.random.default_rng(4))
    maps[3] = dataclasses.replace(maps[3], true_betti1=maps[3].true_betti1 + 1)  # no threshold reads it right
    maps[7] = dataclasses.replace(maps[7], est_betti0=2)  # beta_0 wrong: its region's outcome is unknown
    features, correct = cross_fitted_features(maps, "mean", folds=3)
    single = [m for i, m in enumerate(maps) if i != 7]
    assert len(features) == len(correct) == 14
    # the literal construction: fold k holds positions k, k + 3, ... of the one-region maps
    order = [i for k in range(3) for i in range(len(single)) if i % 3 == k]
    for pos, i in enumerate(order):
        th = fit_thresholds([m for j, m in enumerate(single) if j % 3 != i % 3]).thresholds
        assert features[pos] == RatioClassifier.from_thresholds({1: th}).region_features(single[i].regions[0], 1)
        assert correct[pos] == bool(exact([single[i]], th)[0])
    assert correct[order.index(3)] is False


def test_maps_know_their_regions_spans_and_their_features_carry_the_span():
    rng = np.random.default_rng(6)
    (one,) = synthetic_maps(1, rng)
    row = {"error": None, "est_betti0": 1, "true_betti0": 1, "true_betti1": one.true_betti1, "config": {},
           "diagrams": [{"windows": [{"t0": 2.0 + 10 * k, "t1": 17.0 + 10 * k, "band": band, "diagram": w}
                                     for k, w in enumerate(one.regions[0]) for band in (1.0, 0.5)]}]}
    (read,) = maps_from_rows([row], lambda config: "c")
    assert read.spans == (35.0,) and len(read.regions) == 1 and len(read.regions[0]) == 6
    th = RatioThresholds(0.5, 3.0)
    (features,), _ = features_under([read], th)
    assert features == RatioClassifier.from_thresholds({1: th}).region_features(read.regions[0], 1, span=35.0)
    assert features["log_span"] == pytest.approx(np.log(35.0))
