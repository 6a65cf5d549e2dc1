"""Reading Betti numbers off persistence diagrams.

Interim rule, until the trained classifier of the paper's "Robust Classification of
Persistence Intervals" replaces it: :class:`CoverRadiusRule`.

A landmark set with covering radius r_cover is an r_cover-dense sample of the event
cloud, so the bottleneck distance between the Rips diagram of the landmarks and that
of all events is at most 2 r_cover.  A landmark bar longer than 4 r_cover therefore
cannot be matched to the diagonal: it is certainly a feature of the whole encounter
cloud, not an artefact of subsampling.  The rule counts those bars::

    beta_hat_n = #{ i : l_i > tau * r_cover },   tau = 4,   n >= 1

It is scale-free (r_cover is in the metric's own unit, seconds) and answers 0 when no
bar stands out.  beta_0 is not read from H0: it is the number of encounter-graph
components with enough events (see :mod:`swarmtopo.pipeline`).

Measured limits (tuning seeds 1000-1007, 500 mm square, 200 agents, 20 s, hybrid
metric): at L = 300 landmarks the one-hole bar lay at 4.3-7.0 r_cover and the longest
no-hole noise bar at 2.7-3.7 r_cover; at L = 500 noise bars reached 6.7 r_cover,
because the event cloud carries metric noise of its own that a denser sample resolves.
The guarantee is about subsampling, not about noise in the encounter metric.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from .persistence import Diagram


class BettiRule(Protocol):
    """How Betti numbers n >= 1 are read off one region's diagram."""

    def betti(self, diagram: Diagram, cover_radius: float) -> dict[int, int]: ...

    def thresholds(self, diagram: Diagram, cover_radius: float) -> dict[int, float]: ...

    def describe(self) -> dict: ...


@dataclass(frozen=True)
class CoverRadiusRule:
    """Count bars longer than ``tau`` covering radii (see module docstring)."""

    tau: float = 4.0

    def thresholds(self, diagram: Diagram, cover_radius: float) -> dict[int, float]:
        """Bar-length threshold per dimension n >= 1, in the metric's unit."""
        return {n: self.tau * float(cover_radius) for n in range(1, diagram.maxdim + 1)}

    def betti(self, diagram: Diagram, cover_radius: float) -> dict[int, int]:
        """beta_hat_n for n = 1 .. maxdim."""
        return {n: int(np.count_nonzero(diagram.lengths(n) > thr))
                for n, thr in self.thresholds(diagram, cover_radius).items()}

    def describe(self) -> dict:
        return {"rule": "cover-radius", "tau": self.tau,
                "definition": "beta_n = #{bars of dim n with length > tau * cover_radius}"}


def default_rule() -> BettiRule:
    """The rule ``swarmtopo map`` uses."""
    return CoverRadiusRule()
