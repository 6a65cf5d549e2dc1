"""How sure the count of regions is: beta_0's evidence and confidence.

beta_0 is the number of encounter-graph components big enough to map
(:mod:`swarmtopo.pipeline.map`).  Walls between rooms split the graph, but so does a log too
short for the agents of one room to have met: at first a swarm is many small groups
that merge as its agents meet.  Two pieces of evidence tell the cases apart
(:class:`Beta0Evidence`):

* ``settled`` (beta_0 >= 2): how long the regions have coexisted without merging, in
  mean gaps between an agent's consecutive encounters, (t_end - t_formed) / gap, where
  t_formed is the last time one of the regions grew to ``FORMED_SHARE`` of its agents
  (:func:`formation_times`).  Regions of one room merge within a few gaps of forming;
  separate rooms never do.
* ``fragments`` (beta_0 = 1): the share of the mapped events in components too small to
  be regions.  A second room seen by only a few agents hides there (the fitted model
  doubts a single region only when fragments are most of the log: a small room holding
  1 % of the events is missed at 0.999, lab/beta0_outside_suite.py).

:class:`Beta0Model` turns them into P(beta_0 right): a logistic model of
ln(1 + settled) when beta_0 >= 2 and of ``fragments`` when beta_0 = 1, fitted by
``lab/calibrate_beta0.py`` on the benchmark's tuning cases cut short
(docs/accuracy.md, "Confidence").  It is the same whichever classifier reads beta_1: it
judges the components, not the diagrams.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from functools import lru_cache
from importlib import resources

import numpy as np
from scipy.cluster.hierarchy import DisjointSet
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import minimum_spanning_tree
from scipy.special import expit

from .._validate import check_format
from ..errors import InputError

FORMED_SHARE = 0.9
"""A region counts as formed once one group of its agents holds this share of them (not
all: one straggler meeting the others late would date a settled region late)."""
BETA0_DEFINITION = ("P(beta_0 right) from a logistic model of ln(1 + settled) when beta_0 >= 2 (settled: mean gaps "
                    "between an agent's encounters since the last region formed) and of the share of events outside "
                    "every region when beta_0 = 1, fitted on the benchmark's tuning cases cut short")
"""map.json's ``beta0_evidence.definition``."""
BETA0_FORMAT = "swarmtopo-beta0-confidence/1"
SHIPPED_BETA0_MODEL = "beta0-confidence.json"


@dataclass(frozen=True)
class Beta0Evidence:
    """What beta_0's confidence is read from (module docstring)."""

    regions: int
    settled: float  # (t_end - t_formed) / mean agent gap; 0 without a gap
    fragments: float  # share of the mapped events outside every region

    def to_json(self) -> dict[str, float]:
        return asdict(self)


def formation_times(a: np.ndarray, b: np.ndarray, t: np.ndarray, region_of_agent: np.ndarray,
                    n_regions: int, share: float = FORMED_SHARE) -> np.ndarray:
    """When each region formed: the time of the encounter after which one group of its
    agents, linked by the encounters up to then, first held ``share`` of them (and at
    least two: a group forms at an encounter).

    ``a, b, t``: the mapped encounters; ``region_of_agent[i]`` is agent i's region
    (-1: none; both agents of an encounter are in the same one).  Groups grow as in
    union-find over the encounters in time order; only each pair's first encounter can
    join two groups, and of those the minimum spanning forest of the agents (weights:
    first-encounter times) joins them in the same order, so at most one merge per agent
    is replayed, and only the regions' agents are numbered.
    """
    formed = np.full(n_regions, np.nan)
    inside = region_of_agent[a] >= 0
    if not inside.any():
        return formed
    agents, ends = np.unique(np.r_[a[inside], b[inside]], return_inverse=True)
    lo, hi = np.minimum(*ends.reshape(2, -1)), np.maximum(*ends.reshape(2, -1))
    t = t[inside]
    region = region_of_agent[agents]
    target = np.maximum(np.ceil(share * np.bincount(region, minlength=n_regions) - 1e-9), 2)
    order = np.lexsort((t, lo, hi))
    pair = lo[order] * np.int64(len(agents)) + hi[order]
    first = order[np.r_[True, pair[1:] != pair[:-1]]]
    instants, rank = np.unique(t[first], return_inverse=True)
    weights = rank + 1.0  # ranks of the times: exact, and never the zero the spanning forest ignores
    forest = minimum_spanning_tree(coo_matrix((weights, (lo[first], hi[first])),
                                              shape=(len(agents), len(agents)))).tocoo()
    groups = DisjointSet(range(len(agents)))
    waiting = n_regions
    for k in np.argsort(forest.data, kind="stable"):
        u = int(forest.row[k])
        groups.merge(u, int(forest.col[k]))
        r = region[u]
        if np.isnan(formed[r]) and groups.subset_size(u) >= target[r]:
            formed[r] = instants[int(forest.data[k]) - 1]
            waiting -= 1
            if not waiting:
                break
    return formed


def beta0_evidence(a: np.ndarray, b: np.ndarray, t: np.ndarray, region_of_agent: np.ndarray, n_regions: int,
                   events_in_regions: int, gap: float | None) -> Beta0Evidence:
    """:class:`Beta0Evidence` of the mapped encounters ``a, b, t`` (module docstring);
    ``gap`` is the mean time between an agent's consecutive encounters (None: no agent
    met twice, so no region has had time to settle)."""
    settled = 0.0
    if n_regions >= 2 and gap:
        formed = formation_times(a, b, t, region_of_agent, n_regions)
        settled = max(0.0, float(t.max() - np.nanmax(formed)) / gap)
    return Beta0Evidence(regions=int(n_regions), settled=settled,
                         fragments=float(1.0 - events_in_regions / len(t)) if len(t) else 0.0)


@dataclass(frozen=True)
class Beta0Model:
    """P(beta_0 right | evidence): logistic in ln(1 + settled) for beta_0 >= 2
    (``several``) and in ``fragments`` for beta_0 = 1 (``one``); each a pair
    (intercept, slope)."""

    one: tuple[float, float]
    several: tuple[float, float]
    provenance: dict

    @staticmethod
    def feature(evidence: Beta0Evidence) -> float:
        """The one feature the model reads for this beta_0."""
        return float(np.log1p(evidence.settled)) if evidence.regions >= 2 else evidence.fragments

    def confidence(self, evidence: Beta0Evidence) -> float:
        intercept, slope = self.several if evidence.regions >= 2 else self.one
        return float(expit(intercept + slope * self.feature(evidence)))

    def to_json(self) -> dict:
        return {"format": BETA0_FORMAT,
                "one": {"intercept": self.one[0], "fragments": self.one[1]},
                "several": {"intercept": self.several[0], "log1p_settled": self.several[1]},
                "provenance": self.provenance}

    @classmethod
    def from_json(cls, obj: dict, source: str = "<json>") -> "Beta0Model":
        check_format(obj, (BETA0_FORMAT,), "swarmtopo beta_0 confidence model", source)
        pairs = {}
        for part, slope in (("one", "fragments"), ("several", "log1p_settled")):
            model = obj.get(part)
            if not isinstance(model, dict):
                raise InputError("missing or not an object", file=source, column=part, value=model)
            for key in ("intercept", slope):
                value = model.get(key)
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
                    raise InputError("must be a finite number", file=source, column=f"{part}.{key}", value=value)
            pairs[part] = (float(model["intercept"]), float(model[slope]))
        provenance = obj.get("provenance") or {}
        if not isinstance(provenance, dict):
            raise InputError("must be an object", file=source, column="provenance", value=provenance)
        return cls(pairs["one"], pairs["several"], dict(provenance))


@lru_cache(maxsize=1)
def shipped_beta0_model() -> Beta0Model:
    """The model in ``swarmtopo/data/beta0-confidence.json``."""
    text = resources.files("swarmtopo.data").joinpath(SHIPPED_BETA0_MODEL).read_text()
    return Beta0Model.from_json(json.loads(text), source=SHIPPED_BETA0_MODEL)
