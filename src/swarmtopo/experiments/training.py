"""Fitting the paper's Betti classifier on sweeps of random environments.

A training example is one map: the diagram of its largest region and the true beta_1
of its arena.  Only maps of connected arenas (true beta_0 = 1) that the pipeline could
map are examples; a map whose largest region is one of several is still an example
(its extra regions are beta_0's error, not beta_1's).

:func:`fit_and_select` fits Theta_1 with both optimizers on the training maps, scores
both on held-out maps (never on the training F), keeps the better one (lower held-out
F; the grid optimizer on a tie, being exact and deterministic) and calibrates its
confidence on the held-out maps.  ``lab/train_classifier.py`` runs it on
:data:`DEFAULT_TRAINING` to make the shipped ``classifier-paper.json``.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from ..readers.paper import BettiClassifier, DetectionScores, detection_scores
from ..topology.persistence import Diagram

DEFAULT_TRAINING: dict[str, Any] = {
    "sweep": {"name": "classifier-train", "salt": "classifier-train", "replicates": 2},
    "arena": {"generator": "random", "holes": [0, 1, 2, 3],
              "shapes": ["square", "disc", "L", "triangle", "wall"],
              "outer": ["square", "rectangle", "polygon"], "scale": [0.75, 1.0, 1.25]},
    "swarm": {"agents": [200, 400], "duration": [20.0, 60.0]},
    "map": {"hop_cost": 0.0, "diffusion_time": "none", "wall_follow_weight": "none", "window_length": "none",
            "classifier": "paper"},
}
"""The ``paper`` classifier's training sweep: random arenas with 0-3 holes of every
shape family, three outer walls, scales 0.75-1.25, 200 or 400 agents for 20 or 60 s,
mapped with the paper's pipeline (no per-hop cost, whole log), 2 replicates."""


def heldout_sweep(training: dict[str, Any], replicates: int = 1) -> dict[str, Any]:
    """The same grid under another salt: new environments, never seen in training."""
    heldout = copy.deepcopy(training)
    heldout["sweep"] = {"name": training["sweep"]["name"].replace("train", "heldout"),
                        "salt": training["sweep"]["salt"].replace("train", "heldout"),
                        "replicates": replicates}
    if heldout["sweep"]["salt"] == training["sweep"]["salt"]:
        raise ValueError("the training sweep's salt must contain 'train'")
    return heldout


@dataclass
class Examples:
    """(diagram, true beta_1) pairs from a sweep's rows, plus the beta_0 outcomes."""

    diagrams: list[Diagram]
    truth: np.ndarray
    beta0_correct: np.ndarray
    excluded: dict[str, int] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.diagrams)


def examples_from_rows(rows: Sequence[dict[str, Any]]) -> Examples:
    """Training examples from ``read_jobs`` rows (module docstring)."""
    diagrams, truth, beta0 = [], [], []
    excluded = {"no map (too little data)": 0, "disconnected arena": 0}
    for row in rows:
        if row["error"] is not None:  # a job that crashed or timed out is named apart
            reason = "too little data" if row.get("status", "error") == "error" else row["status"]
            excluded[f"no map ({reason})"] = excluded.get(f"no map ({reason})", 0) + 1
            continue
        beta0.append(row["est_betti0"] == row["true_betti0"])
        if row["true_betti0"] != 1:
            excluded["disconnected arena"] += 1
            continue
        diagrams.append(row["diagrams"][0]["diagram"])
        truth.append(row["true_betti1"])
    return Examples(diagrams, np.array(truth, dtype=np.int64), np.array(beta0, dtype=bool), excluded)


@dataclass
class Selection:
    """Both fits, their held-out scores, and the winner (calibrated)."""

    fits: dict[str, BettiClassifier]
    heldout_scores: dict[str, DetectionScores]
    winner: str

    @property
    def classifier(self) -> BettiClassifier:
        return self.fits[self.winner]

    def table(self) -> list[dict[str, Any]]:
        """One row per optimizer: Theta*, training F, held-out F / SE / false holes / exact."""
        rows = []
        for name, model in self.fits.items():
            th, scores = model.theta_[1], self.heldout_scores[name]
            rows.append({"optimizer": name, "q": th.q, "delta": th.delta, "tau": th.tau,
                         "train_F": model.train_error_[1], "heldout_F": scores.mean_absolute_error,
                         "heldout_SE": scores.sensitivity, "heldout_false_holes": scores.false_hole_rate,
                         "heldout_exact": scores.exact, "winner": name == self.winner})
        return rows


def fit_and_select(train: Examples, heldout: Examples, provenance: dict[str, Any],
                   random_state: int = 0) -> Selection:
    """Fit with both optimizers, keep the one with the lower held-out F, calibrate it."""
    fits, scores = {}, {}
    for optimizer in ("grid", "sigmoid"):
        model = BettiClassifier(optimizer=optimizer, random_state=random_state)
        fits[optimizer] = model.fit(train.diagrams, train.truth, provenance=provenance)
        scores[optimizer] = detection_scores(model.predict(heldout.diagrams), heldout.truth)
    winner = min(fits, key=lambda name: (scores[name].mean_absolute_error, name != "grid"))
    fits[winner].calibrate(heldout.diagrams, heldout.truth)
    fits[winner].provenance_["heldout_F"] = scores[winner].mean_absolute_error
    return Selection(fits=fits, heldout_scores=scores, winner=winner)
