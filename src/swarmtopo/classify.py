"""Reading Betti numbers off persistence diagrams.

Interim rule, until the trained classifier of the paper's "Robust Classification of
Persistence Intervals" replaces it: :class:`LocalScaleRule`.

The encounter metric is noisy at a scale of its own: neighbouring events are a few
seconds apart, and Rips noise bars live at a few times that scale.  The rule measures
that scale on the event cloud itself and counts the bars far above it::

    s        = median over events x of  d_bar_k(x)   (mean distance to the k nearest
               other distinct events -- the paper's KNN-filter statistic, k = 10)
    beta_n   = #{ i : l_i > tau * s },   tau = 6,   n >= 1

s is a property of the cloud, not of the landmarks, so the answer does not drift with
the number of landmarks L; it is in the metric's unit, so it transfers across arena
size and time units; and it answers 0 when no bar stands out.  beta_0 is not read from
H0: it is the number of encounter-graph components with enough events (see
:mod:`swarmtopo.pipeline`).  Distinct events = graph nodes: events merged at distance
0 (a static agent's stop) count once, else s could collapse to 0.

The landmarks' diagram is within bottleneck 2 r_cover of the whole cloud's, so the
rule is only trustworthy when 4 r_cover <= tau * s (:meth:`LocalScaleRule.max_cover_radius`):
the pipeline's automatic landmark count picks landmarks until it holds, and
:meth:`LocalScaleRule.warnings` says when it does not (too few landmarks).

tau was chosen on tuning seeds 1000-1011 (500 mm square, one centred hole or none,
200 agents, 20 s, hybrid metric, maxmin, L in {300, 600, all events}, 0 and 5 % static
agents): the longest bar over s was 5.3-11.8 with the hole (4.9-8.9 with 5 % static)
and 3.4-7.0 without.  The classes overlap: expect about one map in ten wrong there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from .persistence import Diagram


@dataclass(frozen=True)
class RegionScales:
    """Scales of one region's event cloud, in the metric's unit (seconds).

    knn
        s: median over distinct events of the mean distance to their k nearest others.
    cover_radius
        r_cover of the landmark set.
    """

    knn: float
    cover_radius: float


class BettiRule(Protocol):
    """How Betti numbers n >= 1 are read off one region's diagram."""

    knn_k: int

    def betti(self, diagram: Diagram, scales: RegionScales) -> dict[int, int]: ...

    def thresholds(self, diagram: Diagram, scales: RegionScales) -> dict[int, float]: ...

    def warnings(self, scales: RegionScales) -> list[str]: ...

    def max_cover_radius(self, knn_scale: float) -> float: ...

    def describe(self) -> dict: ...


@dataclass(frozen=True)
class LocalScaleRule:
    """Count bars longer than ``tau`` times the cloud's k-NN scale (module docstring)."""

    tau: float = 6.0
    knn_k: int = 10

    def thresholds(self, diagram: Diagram, scales: RegionScales) -> dict[int, float]:
        """Bar-length threshold per dimension n >= 1, in the metric's unit."""
        return {n: self.tau * scales.knn for n in range(1, diagram.maxdim + 1)}

    def betti(self, diagram: Diagram, scales: RegionScales) -> dict[int, int]:
        """beta_hat_n for n = 1 .. maxdim."""
        return {n: int(np.count_nonzero(diagram.lengths(n) > limit))
                for n, limit in self.thresholds(diagram, scales).items()}

    def max_cover_radius(self, knn_scale: float) -> float:
        """Largest covering radius for which the sampling guarantee holds: tau s / 4."""
        return self.tau * knn_scale / 4

    def warnings(self, scales: RegionScales) -> list[str]:
        """Why the answer may be unreliable (empty when it is not)."""
        if scales.cover_radius > self.max_cover_radius(scales.knn):
            return [f"landmarks too sparse: covering radius {scales.cover_radius:.3g} s exceeds "
                    f"{self.tau / 4:g} x the cloud's k-NN scale {scales.knn:.3g} s, so subsampling noise "
                    "can pass the threshold; use more landmarks"]
        return []

    def describe(self) -> dict:
        return {"rule": "local-scale", "tau": self.tau, "k": self.knn_k,
                "definition": "beta_n = #{bars of dim n with length > tau * s}, s = median over distinct "
                              "events of the mean distance to their k nearest others"}


def default_rule() -> BettiRule:
    """The rule ``swarmtopo map`` uses."""
    return LocalScaleRule()
