"""Planning a deployment from the accuracy benchmark: what accuracy a swarm will get.

The model is fitted by ``swarmtopo bench accuracy`` on its reporting maps of the
default pipeline and shipped as ``swarmtopo/data/plan.json``: a logistic regression of
"(beta_0, beta_1) exactly right" on ln(agent density N / A) and ln(duration T),

    P(right | A, N, T) = sigmoid(c0 + c1 ln(N / A) + c2 ln T)

(A in mm^2 inside the outer walls, N agents, T seconds).  Arena size enters only
through the density: the suite varies the scale of every case, so maps of the same
swarm size in bigger arenas are sparser.  The inverse questions solve the same
equation for N or T.  The benchmark spans a range of densities and durations
(``PlanModel.density_range``, ``duration_range``); answers outside it are
extrapolations and say so.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Sequence

import numpy as np
from scipy.special import expit, logit
from sklearn.linear_model import LogisticRegression

from ._validate import check_format, positive
from .errors import InputError, SwarmtopoError

PLAN_FORMAT = "swarmtopo-plan/1"


@dataclass(frozen=True)
class PlanModel:
    """P(right) = sigmoid(intercept + density_coef ln(N/A) + duration_coef ln T)."""

    intercept: float
    density_coef: float
    duration_coef: float
    density_range: tuple[float, float]  # agents per mm^2 seen by the benchmark
    duration_range: tuple[float, float]  # seconds
    maps: int
    source: str

    def accuracy(self, area: float, agents: float, duration: float) -> float:
        """Expected exact-match accuracy of the default pipeline."""
        _check_positive(area=area, agents=agents, duration=duration)
        return float(expit(self.intercept + self.density_coef * np.log(agents / area)
                           + self.duration_coef * np.log(duration)))

    def agents_for(self, area: float, duration: float, target: float) -> float:
        """Agents N needed for ``target`` accuracy (inf if more agents do not help)."""
        _check_positive(area=area, duration=duration)
        if self.density_coef <= 0:
            return float("inf")
        log_density = (logit(_target(target)) - self.intercept - self.duration_coef * np.log(duration)) / self.density_coef
        return float(area * np.exp(log_density))

    def duration_for(self, area: float, agents: float, target: float) -> float:
        """Seconds T needed for ``target`` accuracy (inf if more time does not help)."""
        _check_positive(area=area, agents=agents)
        if self.duration_coef <= 0:
            return float("inf")
        log_t = (logit(_target(target)) - self.intercept - self.density_coef * np.log(agents / area)) / self.duration_coef
        return float(np.exp(log_t))

    def inside(self, area: float, agents: float, duration: float) -> bool:
        """Whether (N / A, T) lies in the range the benchmark measured."""
        density = agents / area
        return (self.density_range[0] <= density <= self.density_range[1]
                and self.duration_range[0] <= duration <= self.duration_range[1])

    def to_json(self) -> dict[str, Any]:
        return {"format": PLAN_FORMAT, "intercept": self.intercept, "density_coef": self.density_coef,
                "duration_coef": self.duration_coef, "density_range": list(self.density_range),
                "duration_range": list(self.duration_range), "maps": self.maps, "source": self.source}

    @classmethod
    def from_json(cls, obj: dict, source: str = "<json>") -> "PlanModel":
        check_format(obj, PLAN_FORMAT, "swarmtopo plan model", source)
        try:
            return cls(float(obj["intercept"]), float(obj["density_coef"]), float(obj["duration_coef"]),
                       tuple(map(float, obj["density_range"])), tuple(map(float, obj["duration_range"])),
                       int(obj["maps"]), str(obj["source"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed plan model: {exc!r}", file=source) from None


def fit_plan(records: Sequence[dict[str, Any]], source: str) -> PlanModel:
    """The plan model of the benchmark's reporting records (``area``, ``agents``,
    ``duration``, ``right``), by a lightly regularised logistic regression."""
    density = np.array([r["agents"] / r["area"] for r in records], dtype=float)
    duration = np.array([r["duration"] for r in records], dtype=float)
    right = np.array([r["right"] for r in records], dtype=bool)
    if len(np.unique(right)) < 2:
        raise SwarmtopoError("the plan needs both right and wrong maps to fit (every map had the same outcome)")
    X = np.column_stack([np.log(density), np.log(duration)])
    model = LogisticRegression(C=10.0).fit(X, right)
    return PlanModel(float(model.intercept_[0]), float(model.coef_[0, 0]), float(model.coef_[0, 1]),
                     (float(density.min()), float(density.max())), (float(duration.min()), float(duration.max())),
                     int(len(right)), source)


def load_plan(path: str | Path | None = None) -> PlanModel:
    """The shipped plan model (``swarmtopo/data/plan.json``) or one from a file."""
    if path is None:
        text = resources.files("swarmtopo.data").joinpath("plan.json").read_text("utf-8")
        return PlanModel.from_json(json.loads(text), source="swarmtopo/data/plan.json")
    from .io import read_json

    return PlanModel.from_json(read_json(path), source=str(path))


def _target(target: float) -> float:
    if not 0.0 < target < 1.0:
        raise InputError("target accuracy must be strictly between 0 and 1", column="target", value=target)
    return float(target)


def _check_positive(**values: float) -> None:
    for name, value in values.items():
        positive(name, value)
