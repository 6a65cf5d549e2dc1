"""Training the shipped classifier from sweep rows: which maps are examples, and the
optimizer chosen on held-out maps."""

import numpy as np
import pytest

from swarmtopo.readers.paper import detection_scores
from swarmtopo.experiments.grid import expand_grid
from swarmtopo.experiments.training import (
    DEFAULT_TRAINING, Examples, examples_from_rows, fit_and_select, heldout_sweep,
)
from swarmtopo.topology.persistence import Diagram


def row(true_b0, true_b1, est_b0, h1_lengths, error=None):
    def dgm(lengths):
        return Diagram(pairs=(np.array([[0.0, np.inf]]), np.array([[1.0, 1.0 + l] for l in lengths]).reshape(-1, 2)),
                       backend="test")
    return {"error": error, "true_betti0": true_b0, "true_betti1": true_b1, "est_betti0": est_b0,
            "diagrams": None if error else [{"events": 500, "diagram": dgm(h1_lengths)},
                                            {"events": 60, "diagram": dgm([99.0])}]}


def test_examples_use_the_largest_region_of_connected_arenas_only():
    rows = [row(1, 1, 1, [8.0, 1.0, 1.1]), row(1, 0, 2, [1.0, 1.2]), row(2, 0, 2, [1.0]),
            row(1, 2, None, [], error="too little data")]
    ex = examples_from_rows(rows)
    assert len(ex) == 2
    assert ex.truth.tolist() == [1, 0]
    # the largest region's diagram (first in the row), not the 60-event fragment's
    assert ex.diagrams[0].lengths(1).tolist() == pytest.approx([8.0, 1.1, 1.0])
    assert ex.beta0_correct.tolist() == [True, False, True]        # every mapped row
    assert ex.excluded == {"no map (too little data)": 1, "disconnected arena": 1}


def noisy_examples(m, rng, overlap):
    """beta in 0..2 signal bars `overlap`-close to a noise floor: harder as overlap -> 1."""
    rng = np.random.default_rng(rng)
    dgms, truth = [], []
    for _ in range(m):
        beta = int(rng.integers(0, 3))
        noise = rng.lognormal(0, 0.4, 30) * rng.uniform(0.5, 2)
        signal = np.median(noise) * rng.uniform(overlap, 6 * overlap, beta)
        dgms.append(Diagram(pairs=(np.array([[0.0, np.inf]]),
                                   np.array([[1.0, 1.0 + l] for l in np.concatenate([signal, noise])])), backend="t"))
        truth.append(beta)
    return Examples(dgms, np.array(truth), np.ones(m, dtype=bool))


def test_selection_is_decided_on_heldout_maps_and_calibrates_the_winner():
    train, heldout = noisy_examples(80, 0, 1.5), noisy_examples(80, 1, 1.5)
    selection = fit_and_select(train, heldout, {"name": "test"})
    f = {name: detection_scores(m.predict(heldout.diagrams), heldout.truth).mean_absolute_error
         for name, m in selection.fits.items()}
    assert f[selection.winner] == min(f.values())
    assert {r["optimizer"]: r["heldout_F"] for r in selection.table()} == pytest.approx(f)
    assert hasattr(selection.classifier, "calibration_")
    assert selection.classifier.calibration_["maps"] == 80
    assert selection.classifier.provenance_["name"] == "test"


def test_training_and_heldout_sweeps_share_the_grid_but_no_job():
    train = expand_grid(DEFAULT_TRAINING)
    heldout = expand_grid(heldout_sweep(DEFAULT_TRAINING))
    assert {j.config_json for j in train.jobs} == {j.config_json for j in heldout.jobs}
    assert not {j.key for j in train.jobs} & {j.key for j in heldout.jobs}
    assert not {j.seed for j in train.jobs} & {j.seed for j in heldout.jobs}
