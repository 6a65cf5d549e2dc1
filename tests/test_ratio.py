"""Ratio classifier: hand-made diagrams, mean and median pooling, scale invariance,
fitting, files."""

import json

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.special import expit
from sklearn.base import clone

from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.pipeline import MapConfig
from swarmtopo.readers.base import longest_bars, median_vote, vote
from swarmtopo.readers.ratio import (LOG_RATIO_CAP, MAX_MARGIN, RATIO_FORMAT, REGIONS_EXPONENT, RESOLUTION_CAP,
                                     SCORE_VAR_PRIOR, SPAN_FEATURES, Z_CAP, RatioClassifier, RatioThresholds,
                                     below_full_resolution, calibrated_probability, confidence_readout,
                                     pooled_scores, resolution, score_margin, score_matrix, standardised_margin,
                                     window_scores, windows_span)
from swarmtopo.readers.registry import load_classifier
from swarmtopo.topology.persistence import Diagram

TH = RatioThresholds(q=0.5, tau=2.0)


def ratio(th, **options):
    """A ratio classifier of dimension-1 thresholds ``th``."""
    return RatioClassifier.from_thresholds({1: th}, **options)


def diagram(h1):
    return Diagram(pairs=(np.array([[0.0, np.inf]]), np.array(h1, dtype=float).reshape(-1, 2)), backend="test")


def windows_of(*h1s):
    return [diagram(h1) for h1 in h1s]


def test_window_scores_hand_computed():
    # finite lengths 4, 1.5, 1: median l_q = 1.5; scores ln(4/1.5), 0 (ln 1), 0 (ln(1/1.5) clipped);
    # the infinite bar scores the cap
    d = diagram([[1, 5], [2, 3.5], [0.5, 1.5], [1, np.inf]])
    assert window_scores(d, 1, 0.5) == pytest.approx([LOG_RATIO_CAP, np.log(4 / 1.5), 0.0, 0.0])
    assert len(window_scores(diagram(np.empty((0, 2))), 1, 0.5)) == 0


def test_window_count_threshold_and_margin_hand_computed():
    # lengths 4, 1.5, 1: tau = 2 counts lengths > 2 x 1.5 = 3: only [1, 5]
    d = diagram([[1, 5], [2, 3.5], [0.5, 1.5]])
    model = ratio(TH)
    assert model.betti(d) == {1: 1}
    assert model.length_thresholds(d) == {1: pytest.approx(3.0)}
    # [1, 5] is ln(4/3) above the threshold, [2, 3.5] (score 0) ln 2 below: the margin is ln(4/3)
    assert model.margin(d, 1) == pytest.approx(np.log(4 / 3))
    assert model.margin(diagram(np.empty((0, 2))), 1) == MAX_MARGIN
    # the infinite bar always counts (tau < 1000)
    assert model.betti(diagram([[1, 5], [2, 3.5], [0.5, 1.5], [1, np.inf]])) == {1: 2}


def test_mean_pooling_hand_computed_against_the_median():
    # window 1: lengths 8, 2, 2, 1 (median 2) -> scores ln 4, 0, 0, 0; own count 1 (8 > 4)
    # window 2: lengths 3, 2, 1 (median 2)    -> scores ln 1.5, 0, 0; own count 0 (3 <= 4)
    # pooled: S_1 = (ln 4 + ln 1.5) / 2 = ln(sqrt 6) > ln 2 -> 1 hole; the lower median of (1, 0) is 0
    w = windows_of([[0, 8], [0, 2], [1, 3], [0, 1]], [[0, 3], [1, 3], [0, 1]])
    assert pooled_scores(w, 1, 0.5) == pytest.approx([np.log(np.sqrt(6)), 0, 0, 0])
    mean, median = ratio(TH), ratio(TH, pooling="median")
    assert mean.pooled_betti(w) == {1: 1} and median.pooled_betti(w) == {1: 0}
    betti, rep, counts = vote(mean, w)
    assert betti == {1: 1} and counts == {1: [1, 0]} and rep == 0  # the window that agrees
    assert vote(median, w)[:2] == ({1: 0}, 1)
    features = mean.region_features(w, 1)
    assert features["windows"] == pytest.approx(np.log(2))
    # z: rank 1 scores ln 4 and ln 1.5 (variance (ln 4 - ln 1.5)^2 / 2 with ddof 1), rank 2 scores 0 and 0
    se1 = np.sqrt(((np.log(4) - np.log(1.5)) ** 2 / 2 + SCORE_VAR_PRIOR) / 2)
    se2 = np.sqrt(SCORE_VAR_PRIOR / 2)
    assert features["z"] == pytest.approx(min((np.log(np.sqrt(6)) - np.log(2)) / se1, np.log(2) / se2))


def test_a_missing_rank_scores_zero():
    # window 1 has two long bars, window 2 one: S_2 = (ln 5 + 0) / 2 = ln sqrt 5 > ln 2
    w = windows_of([[0, 10], [0, 10], [0, 2], [0, 2], [0, 2]], [[0, 10], [0, 2], [0, 2]])
    assert ratio(TH).pooled_betti(w) == {1: 2}
    assert ratio(RatioThresholds(0.5, 2.5)).pooled_betti(w) == {1: 1}


def test_score_margin_and_longest_bars_hand_computed():
    scores = np.array([2.0, 1.0, 0.2])
    # ln tau = 0.5: two counted; the last counted is 1.0 - 0.5 above, the first uncounted 0.5 - 0.2 below
    assert score_margin(scores, np.exp(0.5)) == pytest.approx(0.3)
    # ln tau = 1.2: one counted, 2.0 - 1.2 above; 1.2 - 1.0 below
    assert score_margin(scores, np.exp(1.2)) == pytest.approx(0.2)
    assert score_margin(np.array([10.0]), 2.0) == MAX_MARGIN
    d = diagram([[1, 2], [0, 5], [1, np.inf], [2, 6]])
    assert [tuple(d[1][i]) for i in longest_bars(d, 1, 2)] == [(1.0, np.inf), (0.0, 5.0)]
    assert list(longest_bars(d, 1, 0)) == []


def test_standardised_margin_hand_computed():
    # three windows, ranks 1-3; S = (2, 0.5, 0); ln tau = 1: the vote is 1
    matrix = np.array([[2.5, 0.5, 0.0], [2.0, 1.0, 0.0], [1.5, 0.0, 0.0]])
    se = np.sqrt((np.array([0.25, 0.25, 0.0]) + SCORE_VAR_PRIOR) / 3)  # ddof-1 variances 0.25, 0.25, 0
    z_above, z_below = (2.0 - 1.0) / se[0], (1.0 - 0.5) / se[1]
    assert standardised_margin(matrix, 1, np.e) == pytest.approx(min(z_above, z_below))
    # a vote the means disagree with (a median vote can) has a negative z
    assert standardised_margin(matrix, 2, np.e) == pytest.approx((0.5 - 1.0) / se[1])
    # no rank left above (count 0) or below (count = every rank): that side counts as Z_CAP
    assert standardised_margin(np.array([[0.2], [0.4]]), 0, np.e) == pytest.approx(
        min(Z_CAP, (1.0 - 0.3) / np.sqrt((0.02 + SCORE_VAR_PRIOR) / 2)))
    assert standardised_margin(np.array([[9.0]]), 1, np.e) == pytest.approx(min(Z_CAP, 8.0 / np.sqrt(SCORE_VAR_PRIOR)))
    # one window: the prior alone is its variance
    assert standardised_margin(np.array([[1.5, 0.0]]), 1, np.e) == pytest.approx(0.5 / np.sqrt(SCORE_VAR_PRIOR))


def test_score_matrix_pads_missing_ranks_with_zero():
    w = windows_of([[0, 8], [0, 2], [1, 3], [0, 1]], [[0, 3], [1, 3], [0, 1]])
    assert score_matrix(w, 1, 0.5) == pytest.approx(np.array([[np.log(4), 0, 0, 0], [np.log(1.5), 0, 0, 0]]))
    assert score_matrix(w, 1, 0.5).mean(axis=0) == pytest.approx(pooled_scores(w, 1, 0.5))


def test_a_calibration_weighs_z_and_known_features_only():
    # the features of calibrations before z (agreement with the vote, log margin, ln #windows) are not read
    with pytest.raises(InputError, match="a calibration needs 'intercept' and 'z'"):
        ratio(TH, calibration={"1": {"intercept": -1.0, "agreement": 2.0, "margin": 1.5, "windows": 0.5}})
    with pytest.raises(InputError, match=r"unknown confidence feature\(s\) \['gap'\]"):
        ratio(TH, calibration={"1": {"intercept": 0.0, "z": 1.0, "gap": 1.0}})
    with pytest.raises(InputError, match=r"unknown confidence feature\(s\) \['windows'\]"):
        ratio(TH, calibration={"1": {"intercept": 0.0, "z": 1.0, "windows": 1.0}})
    with pytest.raises(InputError, match="a dimension the classifier does not read") as caught:
        ratio(TH, calibration={"2": {"intercept": 0.0, "z": 1.0}})
    assert caught.value.column == "calibration.2"
    with pytest.raises(SwarmtopoError, match="z alone"):
        ratio(TH).calibrate([{"z": 1.0, "windows": 0.0}] * 2, [True, False], names=("z", "windows"))


def with_landmarks(n, h1=((1.0, 5.0),)):
    """A window of n landmarks: n dim-0 bars (one infinite), and the given H1 bars."""
    dim0 = np.array([[0.0, np.inf]] + [[0.0, 1.0]] * (n - 1))
    return Diagram(pairs=(dim0, np.array(h1, dtype=float).reshape(-1, 2)), backend="test")


def test_resolution_is_the_mean_log_landmark_count_capped_at_the_automatic_cap():
    # windows of 10 and 1000 landmarks: (ln 10 + ln 400) / 2; the cap is the automatic count's
    w = [with_landmarks(10), with_landmarks(1000)]
    assert resolution(w) == pytest.approx((np.log(10) + np.log(RESOLUTION_CAP)) / 2)
    assert ratio(TH).region_features(w, 1)["resolution"] == resolution(w)
    assert RESOLUTION_CAP == MapConfig().max_landmarks
    assert resolution([with_landmarks(1)]) == 0.0
    # full resolution is the cap, whatever the floating point of exp(mean ln L)
    assert not below_full_resolution([with_landmarks(RESOLUTION_CAP)] * 7)
    assert not below_full_resolution([with_landmarks(1000), with_landmarks(RESOLUTION_CAP)])
    assert below_full_resolution([with_landmarks(RESOLUTION_CAP), with_landmarks(RESOLUTION_CAP - 1)])


def test_confidence_readout_is_the_slope_of_z_and_the_confidence_at_z_zero_per_landmark_count():
    # logit = -3 + 1.2 z + 0.5 ln L + 0.25 z ln L: at L = 1 the slope is 1.2 and P(z = 0) = expit(-3) = 0.047
    model = ratio(TH, calibration={"1": {"intercept": -3.0, "z": 1.2, "resolution": 0.5,
                                                        "z_x_resolution": 0.25, "maps": 10}})
    text = confidence_readout(model, landmarks=(1, int(round(np.exp(2)))))
    assert text == ("L = 1: z's slope 1.20, P(right | z = 0) 0.05; "
                    f"L = 7: z's slope {1.2 + 0.25 * np.log(7):.2f}, P(right | z = 0) "
                    f"{1 / (1 + np.exp(3.0 - 0.5 * np.log(7))):.2f}")
    z_alone = ratio(TH, calibration={"1": {"intercept": 0.0, "z": 2.0, "maps": 10}})
    assert confidence_readout(z_alone, landmarks=(20, 400)) == (
        "L = 20: z's slope 2.00, P(right | z = 0) 0.50; L = 400: z's slope 2.00, P(right | z = 0) 0.50")


def test_a_calibration_of_z_and_resolution_is_applied_as_fitted_and_one_of_z_alone_ignores_resolution():
    # logit = a + b z + c ln L + d z ln L, hand-computed
    calibration = {"intercept": -3.0, "z": 1.2, "resolution": 0.5, "z_x_resolution": 0.25, "maps": 10}
    model = ratio(TH, calibration={"1": calibration})
    sparse, fine = [with_landmarks(20)] * 3, [with_landmarks(300)] * 3  # same bars, same z
    z = model.region_features(sparse, 1)["z"]
    assert z == model.region_features(fine, 1)["z"] > 0
    for windows, landmarks in ((sparse, 20), (fine, 300)):
        ln_l = np.log(landmarks)
        assert model.region_features(windows, 1)["z_x_resolution"] == pytest.approx(z * ln_l)
        assert model.region_confidence(windows)[1] == pytest.approx(expit(-3.0 + 1.2 * z + 0.5 * ln_l + 0.25 * z * ln_l))
    assert "resolution" in model.describe()["confidence"]
    with pytest.raises(InputError, match="'resolution' and 'z_x_resolution' together"):
        ratio(TH, calibration={"1": {"intercept": -3.0, "z": 1.2, "resolution": 0.5}})
    z_only = ratio(TH, calibration={"1": {"intercept": -3.0, "z": 1.2}})
    assert z_only.region_confidence(sparse)[1] == z_only.region_confidence(fine)[1] == pytest.approx(
        expit(-3.0 + 1.2 * z))


def test_the_span_features_are_ln_t_and_z_ln_t_and_a_calibration_never_reads_a_missing_feature_as_zero():
    model = ratio(TH, calibration={"1": {"intercept": -3.0, "z": 1.2, "resolution": 0.5,
                                                        "z_x_resolution": 0.25, "maps": 10}})
    windows = [with_landmarks(20)] * 3
    plain = model.region_features(windows, 1)
    spanned = model.region_features(windows, 1, span=45.0)
    assert not set(SPAN_FEATURES) & set(plain)
    assert spanned["log_span"] == pytest.approx(np.log(45.0))
    assert spanned["z_x_log_span"] == pytest.approx(plain["z"] * np.log(45.0))
    assert {k: v for k, v in spanned.items() if k not in SPAN_FEATURES} == plain
    with pytest.raises(ValueError, match="weighs resolution, z_x_resolution, which the region's features lack"):
        calibrated_probability(model.calibration_["1"], {"z": plain["z"]})
    with pytest.raises(InputError, match="unknown confidence feature.*log_span"):  # no file weighs the span
        ratio(TH, calibration={"1": {"intercept": 0.0, "z": 1.0, "log_span": 0.1}})


def test_a_map_of_several_regions_raises_the_product_of_their_confidences_to_the_fitted_power():
    calibration = {"intercept": -3.0, "z": 1.2, "maps": 10}
    plain = ratio(TH, calibration={"1": calibration})
    powered = ratio(TH, calibration={"1": {**calibration, REGIONS_EXPONENT: 0.5}})
    assert plain.map_confidence([0.9, 0.8]) == pytest.approx(0.72)  # no exponent: the plain product
    assert powered.map_confidence([0.9, 0.8]) == pytest.approx(0.72 ** 0.5)
    assert powered.map_confidence([0.9, 0.8, 0.5]) == pytest.approx(0.36 ** 0.5)
    assert powered.map_confidence([0.9]) == 0.9  # one region: its own confidence, never powered
    assert powered.map_confidence([0.9, None]) is None and powered.map_confidence([]) is None
    assert powered.map_confidence([0.9, 0.8], n=2) == pytest.approx(0.72)  # fitted for beta_1 only
    assert load_classifier("paper").map_confidence([0.9, 0.8]) == pytest.approx(0.72)  # the paper's: the product
    # the exponent is not a feature: the regional confidence is the same with or without it
    windows = [with_landmarks(20)] * 3
    assert powered.region_confidence(windows)[1] == plain.region_confidence(windows)[1]
    assert "to the power 0.5" in powered.describe()["confidence"]
    restored = RatioClassifier.from_json(powered.to_json())
    assert restored.calibration_ == powered.calibration_ and restored.map_confidence([0.9, 0.8]) == pytest.approx(
        0.72 ** 0.5)
    # a refit of the regional model drops the power, and the provenance that it was fitted
    powered.provenance_["regions_calibration"] = "fitted on 96 several-region tuning maps"
    powered.calibrate([{"z": 1.0}, {"z": 2.0}, {"z": 0.5}], [True, False, True], names=("z",))
    assert REGIONS_EXPONENT not in powered.calibration_["1"] and "regions_calibration" not in powered.provenance_
    for bad in (0.0, -1.0):
        with pytest.raises(InputError, match="must be positive") as caught:
            ratio(TH, calibration={"1": {**calibration, REGIONS_EXPONENT: bad}})
        assert caught.value.column == f"calibration.1.{REGIONS_EXPONENT}"


def test_the_shipped_classifiers_power_raises_a_several_region_confidence():
    # fitted on the two-room tuning maps, where the plain product was below how often they were right
    for name in ("default", "trace"):
        a = load_classifier(name).calibration_["1"][REGIONS_EXPONENT]
        assert 0 < a < 1
        assert load_classifier(name).map_confidence([0.9, 0.9]) > 0.81


def test_windows_span_is_the_first_start_to_the_last_end():
    records = [{"t0": 5.0, "t1": 20.0, "band": 1.0}, {"t0": 0.0, "t1": 15.0, "band": 0.5},
               {"t0": 10.0, "t1": 25.0, "band": 1.0}]
    assert windows_span(records) == 25.0
    assert windows_span(records[1:2]) == 15.0


def test_median_vote_is_the_lower_median():
    assert median_vote([2]) == 2
    assert median_vote([1, 2]) == 1
    assert median_vote([0, 3, 1]) == 1
    assert median_vote([2, 2, 1, 3]) == 2


def test_vote_picks_the_agreeing_window_with_the_largest_margin():
    model = ratio(TH, pooling="median")
    w = windows_of([[0, 9], [0, 4.1], [0, 1], [0, 1], [0, 1]],  # 2 counted, the second barely (4.1 > 2)
                   [[0, 20], [0, 1], [0, 1]],                     # 1, far from the threshold
                   [[0, 2.5], [0, 1], [0, 1]])                    # 1, ratio 2.5 close to 2
    betti, rep, counts = vote(model, w)
    assert counts == {1: [2, 1, 1]} and betti == {1: 1} and rep == 1
    # the widest margin in a window of under half the events of the fullest agreeing one: not shown
    assert vote(model, w, events=[5000, 146, 4000]) == (betti, 2, counts)
    assert vote(model, w, events=[5000, 2000, 4000])[1] == 1


def test_vote_without_windows_is_an_error():
    with pytest.raises(SwarmtopoError, match="no window"):
        vote(ratio(TH), [])


bar_lists = st.lists(st.tuples(st.floats(0.1, 10), st.floats(0.01, 10)), max_size=12)


@settings(max_examples=60, deadline=None)
@given(bars=st.lists(bar_lists, min_size=1, max_size=4), c=st.floats(0.01, 100),
       tau=st.floats(1.0, 20.0), q=st.sampled_from([0.5, 0.7, 0.9]))
def test_pooled_counts_are_scale_invariant_and_between_the_windows_counts(bars, c, tau, q):
    # multiplying every distance by c multiplies births and deaths by c
    h1s = [np.array([[b, b + length] for b, length in w]).reshape(-1, 2) for w in bars]
    # a score on the threshold itself (tau = 1 and two equal bars) counts or not by rounding: not a case
    scores = np.r_[pooled_scores(windows_of(*h1s), 1, q), *(window_scores(diagram(h), 1, q) for h in h1s)]
    assume(not np.any(np.abs(scores - np.log(tau)) < 1e-9))
    model = ratio(RatioThresholds(q, tau))
    pooled = model.pooled_betti(windows_of(*h1s))[1]
    assert pooled == model.pooled_betti(windows_of(*(h * c for h in h1s)))[1]
    # every rank's mean score passes when it passes in every window, fails when it fails in every one
    own = [model.betti(diagram(h))[1] for h in h1s]
    assert min(own) <= pooled <= max(own)
    if len(h1s) == 1:  # one window: both poolings are the window's own count
        assert pooled == own[0] == ratio(RatioThresholds(q, tau), pooling="median").pooled_betti(
            windows_of(*h1s))[1]


def test_calibration_and_json_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    model = ratio(TH, provenance={"name": "test"})
    regions, correct = [], []
    for _ in range(60):
        clean = rng.random() < 0.5
        # clean: a bar 20 x the median, a margin of ln 2; unsure: one 2.05 x, ln(2.05 / 2) above tau
        bars = [[1, 21], [1, 2], [1, 2]] if clean else [[1, 3.05], [1, 2], [1, 2]]
        regions.append(windows_of(bars, bars, bars))
        correct.append(clean or rng.random() < 0.3)
    model.calibrate([model.region_features(r, 1) for r in regions], correct)
    sure = model.region_confidence(windows_of(*[[[1, 21], [1, 2], [1, 2]]] * 3))[1]
    unsure = model.region_confidence(windows_of(*[[[1, 3.05], [1, 2], [1, 2]]] * 3))[1]
    assert 0 <= unsure < sure <= 1 and sure > 0.8 and unsure < 0.6
    path = tmp_path / "c.json"
    model.save(path)
    again = load_classifier(path)
    assert isinstance(again, RatioClassifier) and again.pooling == "mean"
    assert again.to_json() == model.to_json()


def test_earlier_formats_are_refused_naming_the_file_and_the_formats():
    for n in (1, 2, 3, 4):
        old = {"format": f"swarmtopo-ratio-classifier/{n}", "pooling": "mean",
               "thresholds": {"1": {"q": 0.5, "tau": 2.0}}}
        with pytest.raises(InputError) as caught:
            RatioClassifier.from_json(old, source="old.json")
        assert (caught.value.file, caught.value.column, caught.value.value) == ("old.json", "format", old["format"])
        assert f'"{RATIO_FORMAT}"' in caught.value.reason
    # a threshold of an earlier format's gates (rho, kappa, gamma, the agreement gate) is not the current one's
    for extra in ({"agreement": 0.7}, {"rho": 1.0}):
        obj = {"format": RATIO_FORMAT, "pooling": "mean", "thresholds": {"1": {"q": 0.5, "tau": 2.0, **extra}}}
        with pytest.raises(InputError, match="exactly 'q' and 'tau'") as caught:
            RatioClassifier.from_json(obj, source="new.json")
        assert (caught.value.file, caught.value.column) == ("new.json", "thresholds.1")


def test_bad_thresholds_and_files_are_input_errors():
    with pytest.raises(InputError, match="1 <= tau < 1000"):
        ratio(RatioThresholds(0.5, 0.5))
    with pytest.raises(InputError, match="1 <= tau < 1000"):
        ratio(RatioThresholds(0.5, 1000.0))
    with pytest.raises(InputError, match="q <= 1"):
        ratio(RatioThresholds(1.5, 2.0))
    with pytest.raises(InputError, match="pooling"):
        ratio(TH, pooling="max")
    with pytest.raises(InputError, match="finite number") as caught:
        RatioClassifier.from_json({"format": RATIO_FORMAT, "pooling": "mean",
                                   "thresholds": {"1": {"q": "x", "tau": 2}}}, source="c.json")
    assert (caught.value.file, caught.value.column) == ("c.json", "thresholds.1.q")
    for pooling in ("mode", None):
        with pytest.raises(InputError, match="pooling"):
            RatioClassifier.from_json({"format": RATIO_FORMAT, "pooling": pooling,
                                       "thresholds": {"1": {"q": 0.5, "tau": 2.0}}})
    for thresholds in ({}, None, {"0": {"q": 0.5, "tau": 2.0}}, {"x": {"q": 0.5, "tau": 2.0}}):
        with pytest.raises(InputError, match="thresholds"):
            RatioClassifier.from_json({"format": RATIO_FORMAT, "pooling": "mean", "thresholds": thresholds})


def test_shipped_default_and_trace_are_calibrated_mean_pooled_ratio_classifiers_of_their_bands():
    for name, bands in (("default", (1.0, 0.5)), ("trace", (1.0,))):
        model = load_classifier(name)
        assert isinstance(model, RatioClassifier) and model.pooling == "mean"
        assert set(model.calibration_) == {"1"}  # beta_0's confidence is the pipeline's (swarmtopo.readers.beta0)
        assert model.landmark_bands == bands  # the bands its tuning maps were drawn with
        assert model.to_json()["format"] == RATIO_FORMAT


@pytest.mark.parametrize("name", ["default", "trace"])
def test_shipped_confidence_rises_with_z_and_with_the_places_resolved(name):
    # over the fitted range (50-400 landmarks per window, z >= 0 by construction): more
    # standard errors from changing the vote and more places told apart both mean more trust
    # (the trace classifier's fitted on the calibration grid read as contact traces)
    cal = load_classifier(name).calibration_["1"]
    assert {"z", "resolution", "z_x_resolution"} <= set(cal) and "calibration-grid" in load_classifier(
        name).provenance_["calibration"]
    z, ln_l = np.meshgrid(np.linspace(0, Z_CAP, 41), np.log(np.linspace(50, RESOLUTION_CAP, 36)), indexing="ij")
    logit = cal["intercept"] + cal["z"] * z + cal["resolution"] * ln_l + cal["z_x_resolution"] * z * ln_l
    assert np.all(np.diff(logit, axis=0) > 0) and np.all(np.diff(logit, axis=1) > 0)


@pytest.mark.parametrize("key, value, message", [
    ("z", "high", "must be a finite number"),
    ("intercept", float("nan"), "must be a finite number"),
    ("maps", -1, "must be a finite number"),
])
def test_a_classifier_file_with_a_bad_calibration_is_refused_naming_the_file(tmp_path, key, value, message):
    obj = json.loads(json.dumps(load_classifier("default").to_json()))
    obj["calibration"]["1"][key] = value
    path = tmp_path / "c.json"
    path.write_text(json.dumps(obj))
    with pytest.raises(InputError, match=message) as caught:
        load_classifier(path)
    assert (caught.value.file, caught.value.column) == (str(path), f"calibration.1.{key}")


def test_an_earlier_classifier_files_beta0_rate_is_refused(tmp_path):
    obj = json.loads(json.dumps(load_classifier("default").to_json()))
    obj["calibration"]["0"] = {"maps": 1248, "rate": 0.9992}
    path = tmp_path / "c.json"
    path.write_text(json.dumps(obj))
    with pytest.raises(InputError, match="a dimension the classifier does not read") as caught:
        load_classifier(path)
    assert (caught.value.file, caught.value.column) == (str(path), "calibration.0")


@pytest.mark.parametrize("model", [{}, {"z": 2.0}, {"intercept": 0.1, "margin": 1.0}, [0.1, 2.0], 0.5],
                         ids=["empty", "no-intercept", "old-features", "list", "number"])
def test_an_incomplete_calibration_is_refused_naming_the_file_and_key(tmp_path, model):
    obj = json.loads(json.dumps(load_classifier("default").to_json()))
    obj["calibration"]["1"] = model
    path = tmp_path / "c.json"
    path.write_text(json.dumps(obj))
    with pytest.raises(InputError, match="a calibration needs 'intercept' and 'z'") as caught:
        load_classifier(path)
    assert (caught.value.file, caught.value.column) == (str(path), "calibration.1")


def test_an_unknown_classifier_format_lists_the_formats_read(tmp_path):
    obj = json.loads(json.dumps(load_classifier("default").to_json()))
    obj["format"] = "swarmtopo-ratio-classifier/9"
    path = tmp_path / "c.json"
    path.write_text(json.dumps(obj))
    with pytest.raises(InputError) as caught:
        load_classifier(path)
    assert (caught.value.file, caught.value.column, caught.value.value) == (str(path), "format", obj["format"])
    for fmt in ("swarmtopo-classifier/1", RATIO_FORMAT):
        assert f'"{fmt}"' in caught.value.reason


# -- fitting ------------------------------------------------------------------------------
def one_window_map(*h1):
    """A map of one region mapped in one window with these H1 bars."""
    return [[diagram(h1)]]


# three maps, one window each; l_q is the median length 1 of each window:
# A (beta_1 = 1): lengths 4, 1, 1        -> counts 1, 1, 0, 0 at tau = 2, 3, 5, 8
# B (beta_1 = 0): lengths 2.5, 1, 1      -> counts 1, 0, 0, 0
# C (beta_1 = 2): lengths 10, 6, 1, 1, 1 -> counts 2, 2, 2, 1
HAND_X = [one_window_map([0, 4], [0, 1], [0, 1]), one_window_map([0, 2.5], [0, 1], [0, 1]),
          one_window_map([0, 10], [0, 6], [0, 1], [0, 1], [0, 1])]
HAND_Y = [1, 0, 2]
HAND_TAU = (2.0, 3.0, 5.0, 8.0)


def test_fit_recovers_the_hand_computed_threshold_inside_the_plateau():
    # right maps at tau = 2, 3, 5, 8: {A, C}, {A, B, C}, {B, C}, {B}: rates 2/3, 1, 2/3, 1/3;
    # averaged with their tau neighbours (edges repeated): 7/9, 7/9, 2/3, 4/9 -- tau = 2 and 3 tie,
    # and the rate itself breaks the tie: tau = 3, every map right
    model = RatioClassifier(q_grid=(0.5,), tau_grid=HAND_TAU).fit(HAND_X, HAND_Y)
    assert model.thresholds_ == {1: RatioThresholds(0.5, 3.0)} and model.accuracy_ == 1.0
    assert model.surface_ == pytest.approx(np.array([[2 / 3, 1, 2 / 3, 1 / 3]]))
    assert [sum(model.pooled_betti(region)[1] for region in m) for m in HAND_X] == HAND_Y
    # C's beta_0 wrong: right at tau = 2, 3, 5, 8: {A}, {A, B}, {B}, {B}; averaged 4/9, 4/9, 4/9, 1/3:
    # the first three tie and tau = 3 (2 of 3 right) has the highest rate
    model.fit(HAND_X, HAND_Y, beta0_right=[True, True, False])
    assert model.thresholds_ == {1: RatioThresholds(0.5, 3.0)} and model.accuracy_ == pytest.approx(2 / 3)
    # q picks l_q too: with q = 0 (the shortest bar, length 1 in every window) the same tau fits
    both = RatioClassifier(q_grid=(0.0, 0.5), tau_grid=HAND_TAU).fit(HAND_X, HAND_Y)
    assert both.surface_[0] == pytest.approx(both.surface_[1]) and both.thresholds_[1] == RatioThresholds(0.0, 3.0)


def test_fit_follows_scikit_learn_conventions_and_checks_its_input():
    model = RatioClassifier(pooling="median", tau_grid=HAND_TAU)
    assert model.get_params()["pooling"] == "median" and not hasattr(model, "thresholds_")  # __init__ only stores
    assert model.fit(HAND_X, HAND_Y) is model and model.pooling == "median"
    assert not hasattr(clone(model), "thresholds_") and clone(model).get_params() == model.get_params()
    with pytest.raises(SwarmtopoError, match="not fitted"):
        RatioClassifier().read(HAND_X[0][0])
    with pytest.raises(SwarmtopoError, match="one true beta_1"):
        RatioClassifier().fit(HAND_X, HAND_Y[:2])
    with pytest.raises(SwarmtopoError, match="one true beta_1"):
        RatioClassifier().fit(HAND_X, HAND_Y, beta0_right=[True])
    with pytest.raises(SwarmtopoError, match=">= 0"):
        RatioClassifier().fit(HAND_X, [1, -1, 2])
    with pytest.raises(SwarmtopoError, match="tau_grid"):
        RatioClassifier(tau_grid=(3.0, 2.0)).fit(HAND_X, HAND_Y)
    with pytest.raises(SwarmtopoError, match="q_grid"):
        RatioClassifier(q_grid=(1.5,)).fit(HAND_X, HAND_Y)
    with pytest.raises(InputError, match="pooling"):
        RatioClassifier(pooling="max").fit(HAND_X, HAND_Y)
