"""The one interface of a Betti reader: how a region's windows give its Betti numbers.

The pipeline cuts a region's log into time windows and maps each to a persistence
diagram dgm^w (:mod:`swarmtopo.pipeline.map`).  A *Betti reader* (:class:`BettiReader`)
turns the W diagrams of one region into beta_hat_n, n >= 1, in one call,
:meth:`BettiReader.read`, which returns a :class:`RegionReading`.  Both shipped kinds
implement it: the default :class:`~swarmtopo.readers.ratio.RatioClassifier` and the
paper's :class:`~swarmtopo.readers.paper.BettiClassifier`; both read a region the same
way (:class:`WindowReader`):

1. each window's own count beta_hat^w_n (the reader's ``betti``) and the region's count,
   the windows pooled (its ``pooled_betti``);
2. a representative window (:func:`vote`): among the windows whose own count in the
   lowest dimension equals the region's (or, if none does, is nearest it) and that hold
   at least half the events of the fullest of them, the one whose nearest bar is
   farthest from the threshold (the reader's ``margin``; the first on ties);
3. the region's confidence P(beta_hat_n right) (the reader's ``region_confidence``), and
   of the representative window's diagram the counted bars (its beta_hat_n longest,
   :func:`longest_bars`) and the bar length a bar must exceed to count
   (``length_thresholds``), which the pictures draw.

beta_0 is the pipeline's (graph components; its confidence :mod:`swarmtopo.readers.beta0`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, Sequence, runtime_checkable

import numpy as np

from .._json import read_json, write_json
from ..errors import SwarmtopoError
from ..topology.persistence import Diagram


@dataclass(frozen=True, eq=False)
class RegionReading:
    """What a reader reads off one region's windows (data only).

    betti
        beta_hat_n of the region, n >= 1 up to the diagrams' maxdim.
    window
        Index of the representative window (module docstring, step 2).
    window_betti
        Each window's own beta_hat^w_n, in window order.
    confidence
        P(beta_hat_n right); None where the reader is not calibrated.
    counted
        Indices into the representative window's ``diagram[n]`` of its counted bars.
    thresholds
        The bar length (seconds) above which a bar of the representative window counts.
    """

    betti: dict[int, int]
    window: int
    window_betti: list[dict[int, int]]
    confidence: dict[int, float | None]
    counted: dict[int, np.ndarray]
    thresholds: dict[int, float]


@runtime_checkable
class BettiReader(Protocol):
    """What the pipeline asks of a Betti reader (module docstring)."""

    landmark_bands: tuple[float, ...]
    """The landmark bands (``MapConfig.landmark_bands``) the reader was fitted with."""

    def read(self, windows: Sequence[Diagram], events: Sequence[int] | None = None) -> RegionReading:
        """One region's reading from its windows' diagrams and events per window
        (None: every window counts as full)."""
        ...

    def map_confidence(self, confidences: Sequence[float | None], n: int = 1) -> float | None:
        """P(a map's beta_n is right) from its regions' P(right); None if a region has none."""
        ...

    def describe(self) -> dict[str, Any]:
        """What map.json says about how its Betti numbers were read."""
        ...


def median_vote(counts: Sequence[int]) -> int:
    """The lower median of the windows' counts."""
    ordered = sorted(int(c) for c in counts)
    return ordered[(len(ordered) - 1) // 2]


def longest_bars(diagram: Diagram, dim: int, count: int) -> np.ndarray:
    """Indices into ``diagram[dim]`` of its ``count`` longest bars (infinite first; ties by position)."""
    if dim > diagram.maxdim or count <= 0:
        return np.empty(0, np.int64)
    return np.argsort(-diagram.lengths(dim), kind="stable")[:count]


def product_confidence(confidences: Sequence[float | None], exponent: float = 1.0) -> float | None:
    """(prod_r p_r)^a of the regions' P(right) p_r (the one region's p, never raised, for
    one region); None if there is no region or one has no confidence."""
    if not len(confidences) or any(p is None for p in confidences):
        return None
    product = float(np.prod(confidences))
    return product if len(confidences) == 1 else product ** float(exponent)


def vote(reader, windows: Sequence[Diagram], events: Sequence[int] | None = None
         ) -> tuple[dict[int, int], int, dict[int, list[int]]]:
    """A region's (beta_hat, representative window, each dimension's counts per window)
    (module docstring, steps 1-2); ``reader`` has ``betti``, ``pooled_betti`` and ``margin``."""
    if not windows:
        raise SwarmtopoError("no window of this region has enough events to map")
    per_window = [reader.betti(d) for d in windows]
    counts = {n: [c[n] for c in per_window] for n in per_window[0]}
    betti = reader.pooled_betti(windows)
    if not counts:
        return betti, 0, counts
    key = min(counts)
    off = [abs(c - betti[key]) for c in counts[key]]
    nearest = [i for i, x in enumerate(off) if x == min(off)]
    if events is not None:
        fullest = max(events[i] for i in nearest)
        nearest = [i for i in nearest if 2 * events[i] >= fullest]
    margins = [reader.margin(windows[i], key) for i in nearest]
    return betti, nearest[int(np.argmax(margins))], counts


def fitted_bands(provenance: dict) -> tuple[float, ...]:
    """The landmark bands a reader's ``provenance`` says it was fitted with
    (``pipeline.landmark_bands``); (1,) when it names none."""
    pipeline = provenance.get("pipeline") or {}
    return tuple(float(b) for b in pipeline.get("landmark_bands", (1.0,)))


class WindowReader:
    """:meth:`read`, :attr:`landmark_bands`, :meth:`save` and :meth:`load` of a reader with ``betti(diagram)``,
    ``pooled_betti(windows)``, ``margin(diagram, n)``, ``region_confidence(windows, voted)``,
    ``length_thresholds(diagram)``, ``provenance_``, ``to_json`` and ``from_json`` (module docstring)."""

    shipped_preset: str | None = None
    """The preset name when :func:`~swarmtopo.readers.registry.load_classifier` loaded a
    shipped reader (what :mod:`~swarmtopo.readers.recalibrated`'s fits are for)."""

    def save(self, path) -> None:
        """Write the fitted reader as JSON (its ``to_json``), atomically."""
        write_json(self.to_json(), path)

    @classmethod
    def load(cls, path):
        """A reader of this class from a JSON file (its ``from_json``, errors naming the file)."""
        return cls.from_json(read_json(path), source=str(path))

    @property
    def landmark_bands(self) -> tuple[float, ...]:
        """The landmark bands the reader was fitted with (:func:`fitted_bands` of its provenance)."""
        return fitted_bands(getattr(self, "provenance_", {}))

    def read(self, windows: Sequence[Diagram], events: Sequence[int] | None = None) -> RegionReading:
        """One region's :class:`RegionReading` (module docstring)."""
        voted = vote(self, windows, events)
        betti, rep, counts = voted
        chosen = windows[rep]
        return RegionReading(
            betti=betti, window=rep,
            window_betti=[dict(zip(counts, c)) for c in zip(*counts.values())] if counts else [{} for _ in windows],
            confidence=self.region_confidence(windows, voted),
            counted={n: longest_bars(chosen, n, count) for n, count in betti.items()},
            thresholds=self.length_thresholds(chosen))
