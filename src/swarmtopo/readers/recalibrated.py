"""A shipped reader's beta_1 confidence recalibrated for logs whose contacts flicker,
or whose sensing was faulty.

The shipped readers' confidences were calibrated on cockroach logs.  On logs whose
contacts flicker (:mod:`swarmtopo.pipeline.motion`: Brownian and flocking swarms) they
are far too sure: on the motion benchmark's 90 one-region flickering tuning maps the
``trace`` reader's Brier score is 0.274, worse than a constant's 0.244, and 11 wrong
maps are said at 0.9 or more (``lab/calibrate_flicker.py``).  :class:`Recalibrated` passes
each region's beta_1 confidence p through Platt scaling,

    p' = sigmoid(a + b logit p),

with (a, b) fitted per preset by ``lab/calibrate_flicker.py`` on the flickering tuning
maps of the motion benchmark (``swarmtopo/data/flicker-confidence.json``); the counts
are the reader's own.  A map's confidence is then the reader's combination of the
recalibrated regions' (``map_confidence``), and its timeline's windows are read the
same way.

Logs with faulty sensing (:mod:`swarmtopo.pipeline.faults`) are recalibrated the same
way, with (a, b) fitted per preset by ``lab/calibrate_faults.py`` on the one-region maps
of the fault benchmark's tuning cases that the screen reads as faulty
(``swarmtopo/data/fault-confidence.json``).  The screen's shares as more terms of the
fit did not lower its cross-validated Brier score (``lab/calibrate_faults.py
--features``), so the fit is Platt scaling too.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from functools import lru_cache
from importlib import resources
from typing import Any, Sequence

from ..topology.persistence import Diagram
from .base import BettiReader, RegionReading

FLICKER_FORMAT = "swarmtopo-flicker-confidence/1"
FAULT_FORMAT = "swarmtopo-fault-confidence/1"
RECALIBRATIONS = {"flicker": ("flicker-confidence.json", FLICKER_FORMAT),
                  "fault": ("fault-confidence.json", FAULT_FORMAT)}
"""Per kind of log, the file of its fits (package data) and the file's format."""


@dataclass(frozen=True)
class Recalibrated:
    """``reader`` with its beta_1 confidences p mapped to sigmoid(a + b logit p)."""

    reader: BettiReader
    intercept: float
    slope: float
    provenance: dict[str, Any]
    kind: str = "flicker"

    @property
    def landmark_bands(self) -> tuple[float, ...]:
        return self.reader.landmark_bands

    def scaled(self, p: float | None) -> float | None:
        """p' = sigmoid(a + b logit p); None stays None, 0 and 1 stay put."""
        if p is None or p <= 0.0 or p >= 1.0:
            return p
        z = self.intercept + self.slope * math.log(p / (1.0 - p))
        return 1.0 / (1.0 + math.exp(-z)) if z > -700 else 0.0

    def read(self, windows: Sequence[Diagram], events: Sequence[int] | None = None) -> RegionReading:
        reading = self.reader.read(windows, events)
        return replace(reading, confidence={n: self.scaled(p) if n == 1 else p for n, p in reading.confidence.items()})

    def map_confidence(self, confidences: Sequence[float | None], n: int = 1) -> float | None:
        return self.reader.map_confidence(confidences, n)

    def describe(self) -> dict[str, Any]:
        return {**self.reader.describe(), f"{self.kind}_recalibration": {"intercept": self.intercept,
                                                                         "slope": self.slope, **self.provenance}}


def recalibration(kind: str, preset: str, reader: BettiReader) -> Recalibrated | None:
    """The shipped preset ``preset``'s ``reader`` recalibrated for ``kind`` of log
    (``RECALIBRATIONS``: ``flicker`` or ``fault``); None: no fit shipped for that preset."""
    name, form = RECALIBRATIONS[kind]
    fits = _fits(name, form)
    if preset not in fits["presets"]:
        return None
    fit = fits["presets"][preset]
    return Recalibrated(reader, fit["intercept"], fit["slope"],
                        {"maps": fit["maps"], "script": fits["script"], "fitted_on": fits["fitted_on"]}, kind=kind)


@lru_cache(maxsize=2)
def _fits(name: str, form: str) -> dict[str, Any]:
    text = resources.files("swarmtopo.data").joinpath(name).read_text("utf-8")
    fits = json.loads(text)
    assert fits["format"] == form, fits["format"]
    return fits
