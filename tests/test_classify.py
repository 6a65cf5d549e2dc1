"""The paper's Betti classifier: hand cases, scale invariance, optimality of the fit,
scores, confidence, persistence of fitted parameters."""

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sklearn.base import clone

from swarmtopo.readers.paper import (
    PAPER_THETA, BettiClassifier, Theta, betti_function, detection_scores, mean_absolute_error,
    published_paper_classifier, _best_tau,
)
from swarmtopo.readers.registry import load_classifier
from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.topology.persistence import Diagram


def diagram(h1_lengths, birth=1.0) -> Diagram:
    h1 = np.array([[birth, birth + l] for l in h1_lengths]).reshape(-1, 2)
    return Diagram(pairs=(np.array([[0.0, np.inf]]), h1), backend="test")


def synthetic_set(m, rng, noise_scale=(0.5, 3.0), signal_ratio=(3.0, 12.0), sigma=0.25):
    """Diagrams with beta in 0..3 signal bars, signal_ratio times the median of a
    lognormal(0, sigma) noise floor whose scale differs per diagram (like arenas of
    different size).  With the defaults the classes are separable: the largest of
    <= 60 noise bars is below e^(2.6 sigma) ~ 1.9 medians with probability > 0.99."""
    rng = np.random.default_rng(rng)
    out, truth = [], []
    for _ in range(m):
        scale = rng.uniform(*noise_scale)
        beta = int(rng.integers(0, 4))
        noise = scale * rng.lognormal(0.0, sigma, size=int(rng.integers(15, 60)))
        signal = np.median(noise) * rng.uniform(*signal_ratio, size=beta)
        out.append(diagram(np.concatenate([signal, noise])))
        truth.append(beta)
    return out, np.array(truth)


# -- the Betti function --------------------------------------------------------------
def test_betti_function_hand_case():
    # lengths 10, 9 over a noise floor; median of [10, 9, 1, 1.1, 0.9, 1.2] = 1.15
    lengths = np.array([10, 9, 1, 1.1, 0.9, 1.2])
    assert betti_function(lengths, 0.5, 0.0, 3.0) == 2          # ratios 8.7, 7.8 > 3
    assert betti_function(lengths, 0.5, 0.0, 8.0) == 1          # only 8.7
    assert betti_function(lengths, 0.5, 2.0, 3.0) == 1          # 10 / 3.15 = 3.17; 9 / 3.15 = 2.86
    assert betti_function(lengths, 0.5, 2.0, 3.2) == 0
    assert betti_function(np.empty(0), 0.5, 0.7, 3.7) == 0


def test_a_lone_bar_has_no_noise_floor_to_stand_out_from():
    # the paper's form measures bars against their own q-quantile: one bar alone is its
    # own quantile, so it counts only when tau < l / (l + Delta) < 1
    assert betti_function(np.array([37.0]), 0.5, 0.0, 1.5) == 0
    assert betti_function(np.array([37.0]), 0.5, 0.0, 0.9) == 1


def test_infinite_bars_always_count_and_stay_out_of_the_quantile():
    lengths = np.array([np.inf, 5.0, 1.0, 1.0, 1.0])
    assert betti_function(lengths, 0.5, 0.0, 3.0) == 2          # inf and 5/1
    assert betti_function(lengths, 0.5, 0.0, 6.0) == 1          # inf only


def test_predict_on_hand_built_diagrams():
    model = BettiClassifier.from_theta({1: (0.5, 0.0, 4.0)}, {"name": "hand"})
    noise = [1.0, 1.2, 0.8, 1.1, 0.9, 1.0, 1.05]
    dgms = [diagram(noise), diagram([6.0] + noise), diagram([6.0, 9.0, 5.0] + noise)]
    assert model.predict(dgms).tolist() == [0, 1, 3]
    assert model.betti(dgms[1]) == {1: 1}
    # threshold = tau * median: bars above it are exactly the counted ones
    assert model.thresholds(dgms[2])[1] == pytest.approx(4.0 * np.median([6.0, 9.0, 5.0] + noise))


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(1e-3, 1e3), min_size=1, max_size=40), st.floats(1e-4, 1e4),
       st.floats(0.05, 0.95), st.floats(0.5, 20.0))
def test_scale_invariance_when_delta_is_zero(lengths, factor, q, tau):
    lengths = np.array(lengths)
    assert betti_function(lengths * factor, q, 0.0, tau) == betti_function(lengths, q, 0.0, tau)


# -- fitting -------------------------------------------------------------------------
def brute_force_min_error(lengths, truth, q, delta):
    """F minimised over tau by trying every midpoint between consecutive ratios."""
    ratios = np.unique(np.concatenate([l / (np.quantile(l, q) + delta) for l in lengths]))
    candidates = np.concatenate([[ratios[0] / 2], np.sqrt(ratios[:-1] * ratios[1:]), [ratios[-1] * 2]])
    return min(mean_absolute_error(lengths, truth, Theta(q, delta, t)) for t in candidates)


@pytest.mark.parametrize("seed", range(3))
def test_exact_tau_sweep_matches_brute_force(seed):
    dgms, truth = synthetic_set(20, seed, signal_ratio=(1.5, 6.0), sigma=0.4)  # overlapping classes: F > 0
    lengths = [d.lengths(1) for d in dgms]
    for q, delta in [(0.5, 0.0), (0.2, 0.3), (0.9, 1.0)]:
        error, _, tau = _best_tau(lengths, truth, q, delta)
        assert error == pytest.approx(brute_force_min_error(lengths, truth, q, delta))
        assert mean_absolute_error(lengths, truth, Theta(q, delta, tau)) == pytest.approx(error)


@pytest.mark.parametrize("optimizer", ["grid", "sigmoid"])
def test_fit_is_no_worse_than_the_generating_parameters(optimizer):
    # labels from known Theta0, then 10 % of them perturbed by +-1: F(Theta0) = 0.1 exactly
    rng = np.random.default_rng(7)
    dgms, _ = synthetic_set(80, rng, signal_ratio=(2.0, 8.0))
    theta0 = Theta(0.5, 0.0, 3.0)
    truth = np.array([betti_function(d.lengths(1), theta0.q, theta0.delta, theta0.tau) for d in dgms])
    flip = rng.choice(len(truth), size=8, replace=False)
    truth[flip] = np.where(truth[flip] > 0, truth[flip] - 1, 1)
    f0 = mean_absolute_error([d.lengths(1) for d in dgms], truth, theta0)
    assert f0 == pytest.approx(0.1)
    model = BettiClassifier(optimizer=optimizer, random_state=0).fit(dgms, truth)
    assert model.train_error_[1] <= f0 + 1e-12
    assert -model.score(dgms, truth) == pytest.approx(model.train_error_[1])


def test_fit_on_separable_data_generalises_to_new_diagrams():
    train, y_train = synthetic_set(100, 1)
    test, y_test = synthetic_set(200, 2)
    model = BettiClassifier().fit(train, y_train)
    assert model.train_error_[1] == 0.0
    # separable classes (synthetic_set): a margin-maximising tau is right on new data too
    assert detection_scores(model.predict(test), y_test).exact >= 0.97


def test_estimator_conventions():
    model = BettiClassifier(optimizer="sigmoid", n_starts=3)
    assert not hasattr(model, "theta_")              # __init__ only stores
    assert model.get_params()["n_starts"] == 3
    dgms, truth = synthetic_set(20, 3)
    assert model.fit(dgms, truth) is model           # fit returns self
    assert not hasattr(clone(model), "theta_")
    with pytest.raises(SwarmtopoError, match="not fitted"):
        BettiClassifier().predict(dgms)
    with pytest.raises(SwarmtopoError, match="optimizer"):
        BettiClassifier(optimizer="adam").fit(dgms, truth)
    with pytest.raises(SwarmtopoError, match="shape"):
        BettiClassifier().fit(dgms, truth[:-1])


def test_fit_is_deterministic():
    dgms, truth = synthetic_set(40, 4, signal_ratio=(1.5, 6.0))
    a = BettiClassifier(optimizer="sigmoid", random_state=5).fit(dgms, truth)
    b = BettiClassifier(optimizer="sigmoid", random_state=5).fit(dgms, truth)
    assert a.theta_ == b.theta_


# -- scores ----------------------------------------------------------------------------
def test_detection_scores_hand_case():
    scores = detection_scores([1, 2, 3, 0], [1, 1, 3, 2])
    # TP = 1 + 1 + 3 + 0 = 5; FN = 7 - 5 = 2; FP = 6 - 5 = 1
    assert (scores.true_positives, scores.false_negatives, scores.false_positives) == (5, 2, 1)
    assert scores.sensitivity == pytest.approx(5 / 7)
    assert scores.false_hole_rate == pytest.approx(1 / 6)
    assert scores.mean_absolute_error == pytest.approx((0 + 1 + 0 + 2) / 4)
    assert scores.exact == pytest.approx(0.5)


def test_over_counting_keeps_sensitivity_but_not_the_false_hole_rate():
    scores = detection_scores([5, 5], [1, 2])
    assert scores.sensitivity == 1.0
    assert scores.false_hole_rate == pytest.approx(7 / 10)


# -- confidence ------------------------------------------------------------------------
def test_confidence_grows_with_the_margin_and_stays_in_unit_interval():
    dgms, truth = synthetic_set(150, 8, signal_ratio=(1.5, 10.0))
    model = BettiClassifier().fit(dgms[:75], truth[:75])
    model.calibrate(dgms[75:], truth[75:])
    calib = model.calibration_["1"]
    assert calib["margin"] + calib["gap"] > 0        # clearer separation, more often right
    conf = np.array([model.confidence(d)[1] for d in dgms])
    assert ((conf > 0) & (conf < 1)).all()


def test_confidence_features_hand_case():
    from swarmtopo.readers.paper import MAX_MARGIN, confidence_features

    # median of [8, 2, 1, 1, 1] is 1; tau = 4: ratio 8 is counted (ln 2 above), 2 is the
    # longest uncounted (ln 2 below): margin ln 2, gap ln 4
    m, g = confidence_features(np.array([8.0, 2.0, 1.0, 1.0, 1.0]), 0.5, 0.0, 4.0)
    assert (m, g) == pytest.approx((np.log(2), np.log(4)))
    # nothing counted: the missing side is MAX_MARGIN away
    m, g = confidence_features(np.array([2.0, 1.0, 1.0]), 0.5, 0.0, 4.0)
    assert (m, g) == pytest.approx((np.log(2), np.log(2) + MAX_MARGIN))


def test_uncalibrated_classifier_reports_no_confidence():
    model = published_paper_classifier()
    assert model.confidence(diagram([5.0, 1.0, 1.0])) == {1: None}


# -- persistence -----------------------------------------------------------------------
def test_json_round_trip_keeps_predictions_and_provenance(tmp_path):
    dgms, truth = synthetic_set(60, 9, signal_ratio=(1.5, 8.0))
    model = BettiClassifier().fit(dgms[:30], truth[:30], provenance={"script": "test", "seeds": [1, 2]})
    model.calibrate(dgms[30:], truth[30:])
    model.save(tmp_path / "c.json")
    back = BettiClassifier.load(tmp_path / "c.json")
    assert back.theta_ == model.theta_
    assert back.provenance_["script"] == "test" and back.provenance_["seeds"] == [1, 2]
    assert (back.predict(dgms) == model.predict(dgms)).all()
    assert [back.confidence(d) for d in dgms] == [model.confidence(d) for d in dgms]


def test_malformed_classifier_files_name_the_file(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"format": "other"}))
    with pytest.raises(InputError, match="bad.json"):
        load_classifier(path)
    good = published_paper_classifier().to_json()
    good["theta"]["1"]["tau"] = -1
    path.write_text(json.dumps(good))
    with pytest.raises(InputError, match="out of range"):
        load_classifier(path)
    with pytest.raises(InputError, match="no such classifier"):
        load_classifier(tmp_path / "missing.json")


@pytest.mark.parametrize("key, model", [("1", {}), ("1", {"intercept": 0.1, "margin": 0.5}),
                                        ("1", {"intercept": 0.1, "margin": 0.5, "gap": "x"}), ("maps", -3),
                                        ("0", {"intercept": 0.1, "margin": 0.5, "gap": 0.2})])
def test_an_incomplete_calibration_is_refused_naming_the_file_and_key(tmp_path, key, model):
    good = load_classifier("paper").to_json()
    good["calibration"][key] = model
    path = tmp_path / "c.json"
    path.write_text(json.dumps(good))
    with pytest.raises(InputError, match="a calibration maps 'maps' to a count") as caught:
        load_classifier(path)
    assert (caught.value.file, caught.value.column) == (str(path), f"calibration.{key}")


def test_the_paper_preset_is_the_paper_form_trained_and_theta_star_the_published_one():
    trained = load_classifier("paper")
    assert isinstance(trained, BettiClassifier) and trained.provenance_["name"] == "paper"
    assert trained.provenance_["script"] == "lab/train_classifier.py" and "seeds" in trained.provenance_
    assert trained.calibration_["maps"] > 0 and trained.landmark_bands == (1.0,)
    assert trained.theta_[1] != Theta(*PAPER_THETA[1])  # trained on our environments, not the published one
    published = published_paper_classifier()
    assert published.theta_ == {1: Theta(0.5, 0.7, 3.7)} and not hasattr(published, "calibration_")
