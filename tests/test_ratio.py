"""Ratio classifier: hand-made diagrams, the median vote, scale invariance, files."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from swarmtopo.classify import load_classifier
from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.persistence import Diagram
from swarmtopo.ratio import (MAX_MARGIN, RatioClassifier, RatioThresholds, WindowBars, counted_bars, median_vote,
                             vote, window_margin)

TH = RatioThresholds(q=0.5, tau=1e-9, rho=2.0, kappa=1.0)  # quantile test off in effect (tau ~ 0)


def diagram(h1):
    return Diagram(pairs=(np.array([[0.0, np.inf]]), np.array(h1, dtype=float).reshape(-1, 2)), backend="test")


def test_counted_bars_hand_computed():
    # bars sorted by decreasing length: [1, 5] (ratio 5, length 4), [2, 3.5] (1.75, 1.5),
    # [0.5, 1.5] (3, 1), [1, inf]
    d = diagram([[1, 5], [2, 3.5], [0.5, 1.5], [1, np.inf]])
    pairs = d[1]
    counted = counted_bars(d, 1, cover_radius=0.9, th=TH)
    # ratio > 2 and length > 0.9: [1, 5] and [0.5, 1.5]; the infinite bar always counts
    got = {tuple(pairs[i]) for i in counted}
    assert got == {(1.0, 5.0), (0.5, 1.5), (1.0, np.inf)}
    # a covering radius of 1.2 puts [0.5, 1.5] (length 1) under kappa r_cover
    assert {tuple(pairs[i]) for i in counted_bars(d, 1, 1.2, TH)} == {(1.0, 5.0), (1.0, np.inf)}


def test_quantile_test_hand_computed():
    # lengths 4, 1.5, 1 (finite): median l_q = 1.5; tau = 2 counts lengths > 3: only [1, 5]
    d = diagram([[1, 5], [2, 3.5], [0.5, 1.5]])
    th = RatioThresholds(q=0.5, tau=2.0)
    assert [tuple(d[1][i]) for i in counted_bars(d, 1, 1.0, th)] == [(1.0, 5.0)]
    model = RatioClassifier({1: th})
    assert model.length_thresholds(d, 1.0) == {1: pytest.approx(3.0)}
    # the margin: [1, 5] is ln(4/3) above, [2, 3.5] ln(2) below -> ln(4/3)
    assert window_margin(d, 1, 1.0, th) == pytest.approx(np.log(4 / 3))


def test_gap_rule_hand_computed():
    # lengths 10, 9, 3, 2.8, 1, 1, 1 and an infinite bar; tau ~ 0: every bar a candidate.
    # Gaps ln(10/9), ln 3, ln(3/2.8), ln 2.8, 0, 0, 0 (none after the last): the largest,
    # ln 3 after the 2nd bar, cuts -> the two longest and the infinite bar count.
    d = diagram([[1, 11], [1, 10], [1, 4], [1, 3.8], [1, 2], [2, 3], [3, 4], [1, np.inf]])
    th = RatioThresholds(q=0.5, tau=1e-9, gamma=1.5)
    assert {tuple(d[1][i]) for i in counted_bars(d, 1, 1.0, th)} == {(1.0, 11.0), (1.0, 10.0), (1.0, np.inf)}
    # margin: the largest gap ln 3 over the next largest ln 2.8 and over ln 1.5
    assert window_margin(d, 1, 1.0, th) == pytest.approx(min(np.log(3 / 2.8), np.log(3 / 1.5)))
    # gamma above every gap: only the infinite bar
    assert [tuple(d[1][i]) for i in counted_bars(d, 1, 1.0, RatioThresholds(0.5, 1e-9, gamma=3.5))] == [(1.0, np.inf)]
    # a floor: l_q = median(10, 9, 3, 2.8, 1, 1, 1) = 2.8, tau 1.1 -> candidates are the
    # lengths > 3.08, 10 and 9; the largest gap among them, after 9, cuts: 2 (+ inf)
    assert len(counted_bars(d, 1, 1.0, RatioThresholds(0.5, 1.1, gamma=1.0))) == 3
    # without the gap rule every candidate counts: with tau ~ 0, all 7 (+ inf)
    assert len(counted_bars(d, 1, 1.0, RatioThresholds(0.5, 1e-9))) == 8


def test_version_1_files_read_with_the_gap_rule_off():
    old = {"format": "swarmtopo-ratio-classifier/1",
           "thresholds": {"1": {"q": 0.5, "tau": 2.0, "rho": 1.0, "kappa": 0.0}}}
    model = RatioClassifier.from_json(old)
    assert model.thresholds_[1].gamma == 0.0
    assert model.to_json()["format"] == "swarmtopo-ratio-classifier/2"


def test_bar_born_at_zero_has_infinite_ratio():
    d = diagram([[0.0, 2.0]])
    assert len(counted_bars(d, 1, 1.0, TH)) == 1
    assert len(counted_bars(d, 1, 3.0, TH)) == 0  # but still needs the length


def test_margin_hand_computed():
    # one counted bar [1, 5]: ratio 5 vs rho 2 -> ln 2.5; length 4 vs kappa r = 1 -> ln 4:
    # it flips when the nearer test fails, ln 2.5.  One uncounted bar [2, 3] (ratio 1.5,
    # length 1 vs 0.5): it needs both tests, so its distance is max(ln(2/1.5), -ln 2) = ln(4/3).
    d = diagram([[1, 5], [2, 3]])
    m = window_margin(d, 1, cover_radius=0.5, th=RatioThresholds(q=0.5, tau=0.01, rho=2.0, kappa=1.0))
    assert m == pytest.approx(min(np.log(2.5), np.log(4 / 3)))
    assert window_margin(diagram(np.empty((0, 2))), 1, 1.0, TH) == MAX_MARGIN


def test_median_vote_is_the_lower_median():
    assert median_vote([2]) == 2
    assert median_vote([1, 2]) == 1
    assert median_vote([0, 3, 1]) == 1
    assert median_vote([2, 2, 1, 3]) == 2


def test_vote_picks_an_agreeing_window_with_the_largest_margin():
    model = RatioClassifier({1: TH})
    windows = [WindowBars(diagram([[1, 5], [1, 2.1]]), 0.5),   # 2 bars counted, nearest barely
               WindowBars(diagram([[1, 8]]), 0.5),             # 1 bar, far from both thresholds
               WindowBars(diagram([[1, 2.5]]), 0.5)]           # 1 bar, ratio 2.5 close to 2
    betti, rep, counts = vote(model, windows)
    assert counts == {1: [2, 1, 1]} and betti == {1: 1} and rep == 1


def test_vote_without_windows_is_an_error():
    with pytest.raises(SwarmtopoError, match="no window"):
        vote(RatioClassifier({1: TH}), [])


@settings(max_examples=60, deadline=None)
@given(bars=st.lists(st.tuples(st.floats(0.1, 10), st.floats(0.01, 10)), max_size=12),
       cover=st.floats(0.05, 5), c=st.floats(0.01, 100))
def test_counts_are_scale_invariant(bars, cover, c):
    # multiplying every distance by c multiplies births, deaths and r_cover by c
    h1 = [[b, b + length] for b, length in bars]
    for th in (RatioThresholds(0.5, 2.0, 2.0, 1.5), RatioThresholds(0.5, 1.5, gamma=1.2)):
        model = RatioClassifier({1: th})
        assert model.betti(diagram(h1), cover) == model.betti(diagram(np.array(h1).reshape(-1, 2) * c), cover * c)


def test_calibration_and_json_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    model = RatioClassifier({1: TH}, provenance={"name": "test"})
    regions, correct = [], []
    for _ in range(60):
        clean = rng.random() < 0.5
        bars = [[1, 6]] if clean else [[1, 2.05], [1, 1.95]]
        regions.append([WindowBars(diagram(bars), 0.5)] * 3)
        correct.append(clean or rng.random() < 0.3)
    model.calibrate(np.array([model.region_features(r, 1) for r in regions]), correct,
                    beta0_correct=[True] * 59 + [False])
    sure = model.region_confidence([WindowBars(diagram([[1, 6]]), 0.5)] * 3)[1]
    unsure = model.region_confidence([WindowBars(diagram([[1, 2.05], [1, 1.95]]), 0.5)] * 3)[1]
    assert 0 <= unsure < sure <= 1 and sure > 0.8 and unsure < 0.6
    assert model.beta0_confidence() == pytest.approx(60 / 62)
    path = tmp_path / "c.json"
    from swarmtopo.io import write_json
    write_json(model.to_json(), path)
    again = load_classifier(path)
    assert isinstance(again, RatioClassifier)
    assert again.to_json() == model.to_json()


def test_bad_thresholds_and_files_are_input_errors(tmp_path):
    with pytest.raises(InputError, match="rho >= 1"):
        RatioClassifier({1: RatioThresholds(0.5, 2.0, rho=0.5)})
    with pytest.raises(InputError, match="q <= 1"):
        RatioClassifier({1: RatioThresholds(1.5, 2.0)})
    with pytest.raises(InputError, match="gamma 0 or >= 1"):
        RatioClassifier({1: RatioThresholds(0.5, 2.0, gamma=0.5)})
    with pytest.raises(InputError, match="malformed"):
        RatioClassifier.from_json({"format": "swarmtopo-ratio-classifier/1", "thresholds": {"1": {"rho": "x"}}})


def test_shipped_default_is_a_calibrated_ratio_classifier():
    model = load_classifier("default")
    assert isinstance(model, RatioClassifier)
    assert model.calibration_.get("1") and model.beta0_confidence() is not None
