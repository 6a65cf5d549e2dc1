"""Planning a deployment from the accuracy benchmark: what accuracy a swarm will get.

A logistic regression of "(beta_0, beta_1) exactly right" on ln(agent density N / A),
ln(duration T), the number of holes H and, from format /3, ln(swarm size N) and, from
format /4, ln N ln T (time buys more with more agents):

    P(right | A, N, T, H) = sigmoid(c0 + c1 ln(N / A) + c2 ln T + c4 ln N + c5 ln N ln T + c3 H)

(A in mm^2 inside the outer walls, N agents, T seconds).  The shipped
``swarmtopo/data/plan.json`` is the /4 model the full ``swarmtopo bench accuracy`` fits
on its reporting maps and its planning grid (``experiments.accuracy.PLANNING_CELLS``);
``plan-trace.json`` is the same form fitted on the same cases read as contact traces
(encounters only, the ``trace`` classifier: ``lab/trace_accuracy.py``).
The reporting budgets raise N and T together (200 x 30 s, 300 x 40 s, 400 x 60 s), so
alone they cannot tell what more agents buy from what more time buys; the grid varies
N, T and A each on its own.  ``--quick`` runs no grid and fits the /2 form (c4 = c5 = 0);
``lab/plan_forms.py`` compares the forms.  A team that does not know H
gets the average over the benchmark's mix of hole counts (``PlanModel.holes_mix``).
The inverse questions solve the same equation for N or T.  The fit spans a range of
densities, durations, swarm sizes and hole counts (``density_range``,
``duration_range``, ``agents_range``, ``len(holes_mix) - 1``); answers outside it are
extrapolations and say so.  Format /1 files (no hole term) are read with c3 = 0, files
before /3 with c4 = 0, before /4 with c5 = 0; files without ``agents_range`` check no
swarm size.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Sequence

import numpy as np
from scipy.optimize import brentq
from scipy.special import expit
from sklearn.linear_model import LogisticRegression

from .._validate import check_format, positive
from ..errors import InputError, SwarmtopoError

PLAN_FORMAT = "swarmtopo-plan/4"
READ_FORMATS = ("swarmtopo-plan/1", "swarmtopo-plan/2", "swarmtopo-plan/3", PLAN_FORMAT)
LOG_SPAN = 50.0
"""How far (in ln units) beyond the benchmark's range the inverse answers search."""


@dataclass(frozen=True)
class PlanModel:
    """P(right) = sigmoid(intercept + density_coef ln(N/A) + duration_coef ln T
    + agents_coef ln N + agents_duration_coef ln N ln T + holes_coef H)."""

    intercept: float
    density_coef: float
    duration_coef: float
    density_range: tuple[float, float]  # agents per mm^2 seen by the benchmark
    duration_range: tuple[float, float]  # seconds
    maps: int
    source: str
    holes_coef: float = 0.0
    holes_mix: tuple[float, ...] = (1.0,)  # fraction of the benchmark's maps with 0, 1, 2, ... holes
    agents_range: tuple[float, float] | None = None  # swarm sizes the benchmark ran (None: not recorded)
    agents_coef: float = 0.0
    agents_duration_coef: float = 0.0

    def accuracy(self, area: float, agents: float, duration: float, holes: int | None = None) -> float:
        """Expected exact-match accuracy of the default pipeline with ``holes`` holes
        (None: averaged over the benchmark's mix of hole counts)."""
        _check_positive(area=area, agents=agents, duration=duration)
        return self._accuracy(np.log(agents), np.log(area), np.log(duration), holes)

    def agents_for(self, area: float, duration: float, target: float, holes: int | None = None) -> float:
        """Agents N needed for ``target`` accuracy (inf if more agents do not help)."""
        _check_positive(area=area, duration=duration)
        log_a, log_t = np.log(area), np.log(duration)
        log_n = self._solve(lambda x: self._accuracy(x, log_a, log_t, holes),
                            self.density_coef + self.agents_coef + self.agents_duration_coef * log_t,
                            np.log(self.density_range) + log_a, target)
        return float(np.exp(log_n))

    def duration_for(self, area: float, agents: float, target: float, holes: int | None = None) -> float:
        """Seconds T needed for ``target`` accuracy (inf if more time does not help)."""
        _check_positive(area=area, agents=agents)
        log_n, log_a = np.log(agents), np.log(area)
        log_t = self._solve(lambda x: self._accuracy(log_n, log_a, x, holes),
                            self.duration_coef + self.agents_duration_coef * log_n,
                            np.log(self.duration_range), target)
        return float(np.exp(log_t))

    def inside(self, area: float, agents: float, duration: float, holes: int | None = None) -> bool:
        """Whether (N / A, N, T, H) lies in the range the benchmark measured."""
        density = agents / area
        return (self.density_range[0] <= density <= self.density_range[1]
                and (self.agents_range is None or self.agents_range[0] <= agents <= self.agents_range[1])
                and self.duration_range[0] <= duration <= self.duration_range[1]
                and (holes is None or holes < len(self.holes_mix)))

    def _accuracy(self, log_agents: float, log_area: float, log_duration: float, holes: int | None) -> float:
        base = (self.intercept + self.density_coef * (log_agents - log_area) + self.duration_coef * log_duration
                + self.agents_coef * log_agents + self.agents_duration_coef * log_agents * log_duration)
        if holes is not None:
            if holes < 0:
                raise InputError("the number of holes must be >= 0", column="holes", value=holes)
            return float(expit(base + self.holes_coef * holes))
        return float(sum(w * expit(base + self.holes_coef * h) for h, w in enumerate(self.holes_mix)))

    @staticmethod
    def _solve(accuracy_at, coef: float, log_range, target: float) -> float:
        """The ln x where ``accuracy_at(ln x)`` (increasing when ``coef`` > 0) equals ``target``."""
        target = _target(target)
        if coef <= 0:
            return float("inf")
        lo, hi = log_range[0] - LOG_SPAN, log_range[1] + LOG_SPAN
        if not accuracy_at(lo) < target < accuracy_at(hi):
            return float("inf") if accuracy_at(hi) <= target else float("-inf")
        return float(brentq(lambda x: accuracy_at(x) - target, lo, hi, xtol=1e-10))

    def to_json(self) -> dict[str, Any]:
        return {"format": PLAN_FORMAT, "intercept": self.intercept, "density_coef": self.density_coef,
                "duration_coef": self.duration_coef, "holes_coef": self.holes_coef,
                "holes_mix": list(self.holes_mix), "density_range": list(self.density_range),
                "duration_range": list(self.duration_range), "maps": self.maps, "source": self.source,
                "agents_coef": self.agents_coef, "agents_duration_coef": self.agents_duration_coef,
                **({} if self.agents_range is None else {"agents_range": list(self.agents_range)})}

    @classmethod
    def from_json(cls, obj: dict, source: str = "<json>") -> "PlanModel":
        check_format(obj, READ_FORMATS, "swarmtopo plan model", source)
        try:
            model = cls(float(obj["intercept"]), float(obj["density_coef"]), float(obj["duration_coef"]),
                        tuple(map(float, obj["density_range"])), tuple(map(float, obj["duration_range"])),
                        int(obj["maps"]), str(obj["source"]), float(obj.get("holes_coef", 0.0)),
                        tuple(map(float, obj.get("holes_mix", (1.0,)))),
                        tuple(map(float, obj["agents_range"])) if "agents_range" in obj else None,
                        float(obj.get("agents_coef", 0.0)), float(obj.get("agents_duration_coef", 0.0)))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed plan model: {exc!r}", file=source) from None
        for name in ("density_range", "duration_range", "agents_range"):
            bounds = getattr(model, name)
            if bounds is not None and not (len(bounds) == 2 and all(np.isfinite(bounds)) and 0 < bounds[0] <= bounds[1]):
                raise InputError("must be [low, high] with 0 < low <= high", file=source, column=name,
                                 value=list(bounds))
        if not model.holes_mix or abs(sum(model.holes_mix) - 1.0) > 1e-6 or min(model.holes_mix) < 0:
            raise InputError("holes_mix must be fractions summing to 1", file=source, column="holes_mix",
                             value=list(model.holes_mix))
        return model


def fit_plan(records: Sequence[dict[str, Any]], source: str, *, swarm_terms: int = 2) -> PlanModel:
    """The plan model of benchmark records (``area``, ``agents``, ``duration``,
    ``true_betti1``, ``right``), by a lightly regularised logistic regression;
    ``swarm_terms`` of the swarm-size terms ln N, ln N ln T in that order: 2 (the /4
    model), 1 (c5 = 0: the /3 model) or 0 (c4 = c5 = 0: the /2 model)."""
    agents = np.array([r["agents"] for r in records], dtype=float)
    density = agents / np.array([r["area"] for r in records], dtype=float)
    duration = np.array([r["duration"] for r in records], dtype=float)
    holes = np.array([r["true_betti1"] for r in records], dtype=int)
    right = np.array([r["right"] for r in records], dtype=bool)
    if len(np.unique(right)) < 2:
        raise SwarmtopoError("the plan needs both right and wrong maps to fit (every map had the same outcome)")
    swarm = [np.log(agents), np.log(agents) * np.log(duration)][:swarm_terms]
    X = np.column_stack([np.log(density), np.log(duration), holes] + swarm)
    model = LogisticRegression(C=10.0).fit(X, right)
    mix = np.bincount(holes) / len(holes)
    coef = np.concatenate([model.coef_[0], np.zeros(2 - swarm_terms)])  # c4, c5 = 0 where left out
    return PlanModel(float(model.intercept_[0]), float(coef[0]), float(coef[1]),
                     (float(density.min()), float(density.max())), (float(duration.min()), float(duration.max())),
                     int(len(right)), source, float(coef[2]), tuple(float(w) for w in mix),
                     (float(agents.min()), float(agents.max())), float(coef[3]), float(coef[4]))


SHIPPED_PLANS = {"log": "plan.json", "contact-trace": "plan-trace.json"}
"""The shipped plan model of each reading: log folders (``swarmtopo bench accuracy``'s
full run) and contact traces, the same cases read as encounters only
(``lab/trace_accuracy.py --planning --plan-out``)."""


def load_plan(path: str | Path | None = None, reading: str = "log") -> PlanModel:
    """The shipped plan model of ``reading`` (SHIPPED_PLANS) or one from a file."""
    if path is None:
        if reading not in SHIPPED_PLANS:
            raise InputError(f"no plan for input {reading!r}; expected one of {', '.join(SHIPPED_PLANS)}",
                             column="input", value=reading)
        name = SHIPPED_PLANS[reading]
        text = resources.files("swarmtopo.data").joinpath(name).read_text("utf-8")
        return PlanModel.from_json(json.loads(text), source=f"swarmtopo/data/{name}")
    from .._json import read_json

    return PlanModel.from_json(read_json(path), source=str(path))


def _target(target: float) -> float:
    if not 0.0 < target < 1.0:
        raise InputError("target accuracy must be strictly between 0 and 1", column="target", value=target)
    return float(target)


def _check_positive(**values: float) -> None:
    for name, value in values.items():
        positive(name, value)
