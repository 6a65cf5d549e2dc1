"""lab/learned_classifier.py: its count rule by hand and its features without a unit."""

import importlib.util
import sys
from pathlib import Path

import numpy as np

from swarmtopo.topology.persistence import Diagram

_root = Path(__file__).parent.parent
sys.path.insert(0, str(_root))  # the script imports calibration.py beside it
_spec = importlib.util.spec_from_file_location("learned_classifier", _root / "learned_classifier.py")
learned = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(learned)


def test_joint_count_by_hand():
    # c = 0: 0.1 * 0.4 * 0.9 = 0.036; c = 1: 0.9 * 0.4 * 0.9 = 0.324; c = 2: 0.9 * 0.6 * 0.9 = 0.486;
    # c = 3: 0.9 * 0.6 * 0.1 = 0.054
    assert learned.joint_count(np.array([0.9, 0.6, 0.1])) == 2
    assert learned.joint_count(np.array([0.2, 0.1])) == 0
    assert learned.joint_count(np.array([0.99, 0.98, 0.97])) == 3


def _window(rng, scale):
    births = rng.uniform(1.0, 2.0, 30)
    bars = np.column_stack([births, births + rng.exponential(0.5, 30)])
    bars[0, 1] = bars[0, 0] + 9.0  # one long bar
    zero = np.column_stack([np.zeros(10), np.r_[rng.uniform(0.5, 1.5, 9), np.inf]])
    return Diagram((zero * scale, bars * scale), "ripser")


def test_rank_features_have_no_unit():
    rng = np.random.default_rng(0)
    windows = [_window(rng, 1.0) for _ in range(4)]
    features = learned.rank_features(windows)
    assert features.shape == (learned.RANKS, 10)
    scaled = learned.rank_features([Diagram(tuple(np.asarray(d[n]) * 7.5 for n in (0, 1)), "ripser") for d in windows])
    np.testing.assert_allclose(scaled, features, atol=1e-12)
    # the long bar ranks first in every window: its pooled score is the window's ln(l / l_0.5) averaged
    assert features[0, 0] > features[1, 0] + 1.0
