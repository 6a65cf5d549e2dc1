"""Time windows: where a region's log is cut into the overlapping windows it is mapped in.

A window of length W holds about K encounters per agent when W = K x the mean time
between an agent's consecutive encounters (:func:`window_length`).  Windows of every
scale s x W start at most half their length apart, evenly spaced from the first event
to the last (:func:`window_spans`); a cap keeps an evenly spaced share of each length's
windows (:func:`scaled_windows`).  Each window is mapped once per landmark band, its
landmarks drawn from the middle share B of its span (:func:`in_band`).
"""

from __future__ import annotations

import numpy as np

from ..errors import SwarmtopoError
from ..log import exact_time
from ..metric.graph import EncounterGraph
from ..metric.landmarks import MIN_LANDMARKS
from .config import WHOLE_LOG

MAX_WINDOWS_LISTED = 100_000
"""Most windows of one length a log may be cut into before the cap picks its share."""


def window_length(gap: float | None, length: float | None, encounters: float, span: float) -> tuple[float, str]:
    """(window length W used, where it came from): the given ``length``, else W = K x
    ``gap``, the mean time between an agent's consecutive encounters in the mapped
    events (K = ``encounters``), so a window holds about K encounters per agent;
    ``WHOLE_LOG`` when W is not shorter than ``span``, the seconds the mapped events
    cover, or when no agent met twice at different times (``gap`` None)."""
    if length is not None:
        return (float(length) if length < span else WHOLE_LOG), "given"
    if gap is None:
        return WHOLE_LOG, "no agent met twice at different times: the whole log"
    length = encounters * gap
    source = f"{encounters:g} x mean time between an agent's encounters"
    return (length, source) if length < span else (WHOLE_LOG, source + " (longer than the log: the whole log)")


def window_spans(event_t: np.ndarray, length: float, step: float | None = None) -> list[tuple[float, float] | None]:
    """Time windows of ``length`` s over [t_first, t_last], starts at most ``step`` apart
    (default length / 2): 1 + ceil((span - length) / step) of them, evenly spaced from
    the first event to the last; [None] (the whole log) when the span is not longer
    than one window."""
    t_first, t_last = float(event_t.min()), float(event_t.max())
    if t_last - t_first <= length:
        return [None]
    step = length / 2 if step is None else step
    count = 1 + np.ceil((t_last - t_first - length) / step - 1e-9)  # a float: inf for a length of 1e-320 s
    if count > MAX_WINDOWS_LISTED:
        raise SwarmtopoError(f"windows of {length:.3g} s every {step:.3g} s over the log's {t_last - t_first:.6g} s "
                             f"would be {f'{int(count):,}' if count < 1e12 else f'{count:.3g}'}, "
                             f"more than {MAX_WINDOWS_LISTED:,}: use longer windows")
    n = int(count)
    return [(float(s), float(s) + length) for s in np.linspace(t_first, t_last - length, n)]


def scaled_windows(times: np.ndarray, lengths, step: float | None = None, cap: int | None = None,
                   min_events: int = 0) -> tuple[list[tuple[float, float] | None], int]:
    """The distinct windows of every length in ``lengths`` (:func:`window_spans`) over
    the sorted event ``times`` that hold at least ``min_events`` events (a gap in a real
    trace is skipped), in order: by length as given, then by start; and how many the
    cap left out.

    With more than ``cap`` distinct windows, each length keeps a share of its windows
    in proportion to their number, at least one (largest remainders, so the shares sum
    to ``cap``), evenly spaced from its first window to its last (one window: the
    middle one)."""
    seen: set = set()
    per_length = []

    def enough(span) -> bool:
        return span is None or events_in(times, span) >= min_events

    for length in lengths:
        spans = [span for span in window_spans(times, length, step) if span not in seen and enough(span)]
        seen.update(spans)
        per_length.append(spans)
    sizes = np.array([len(spans) for spans in per_length])
    total = int(sizes.sum())
    if cap is None or total <= cap:
        return [span for spans in per_length for span in spans], 0
    keep = shares(sizes, cap)
    kept = [[spans[i] for i in evenly(len(spans), k)] for spans, k in zip(per_length, keep)]
    return [span for spans in kept for span in spans], total - int(keep.sum())


def events_in(times: np.ndarray, span: tuple[float, float]) -> int:
    """How many of the sorted event ``times`` lie in ``span`` = (t0, t1), ends included."""
    return int(np.searchsorted(times, span[1], side="right") - np.searchsorted(times, span[0], side="left"))


def shares(sizes: np.ndarray, cap: int) -> np.ndarray:
    """How many of ``sizes[i]`` items each group keeps, ``cap`` in all (``cap`` <
    sizes.sum()): proportional shares, at least one per non-empty group, the seats left
    after the floors going to the largest remainders."""
    if cap < np.count_nonzero(sizes):
        raise SwarmtopoError(f"a cap of {cap} windows cannot keep one of each of {np.count_nonzero(sizes)} lengths")
    quota = cap * sizes / sizes.sum()  # each below its size, as cap < sizes.sum()
    keep = np.maximum(np.floor(quota).astype(int), sizes > 0)
    while keep.sum() > cap:  # the minimum of one pushed the floors over the cap
        keep[np.argmax(np.where(keep > 1, keep - quota, -np.inf))] -= 1
    # under the cap only if nothing was taken back: every remainder < 1, so each seat
    # goes to a different group and none passes its size
    keep[np.argsort(-(quota - keep), kind="stable")[:cap - keep.sum()]] += 1
    return keep


def evenly(n: int, k: int) -> np.ndarray:
    """k of the indices 0 .. n-1, evenly spaced from the first to the last (k = 1: the middle one)."""
    if k == 1:
        return np.array([(n - 1) // 2])
    return np.unique(np.linspace(0, n - 1, k).round().astype(int))


def in_band(times: np.ndarray, span: tuple[float, float], band: float) -> np.ndarray:
    """Whether each time lies in the middle ``band`` share of ``span`` = (t0, t1), ends included."""
    t0, t1 = span
    margin = (1 - band) / 2 * (t1 - t0)
    return (times >= t0 + margin) & (times <= t1 - margin)


def usable_bands(sub: EncounterGraph, span: tuple[float, float] | None, bands: tuple[float, ...]) -> list[float]:
    """The landmark ``bands`` a window can be mapped with: those whose middle share of the
    window's span (None: its events' first to last time) holds at least ``MIN_LANDMARKS``
    nodes -- a quiet stretch of the log can leave it (nearly) empty; whole-window
    landmarks (band 1) if none does."""
    t_lo, t_hi = (float(sub.event_t.min()), float(sub.event_t.max())) if span is None else span
    times = sub.node_times()
    usable = [band for band in bands
              if band == 1 or np.count_nonzero(in_band(times, (t_lo, t_hi), band)) >= MIN_LANDMARKS]
    return usable or [1.0]


def silence_warnings(times: np.ndarray, length: float) -> list[str]:
    """A silence between the sorted event ``times`` longer than a window (a night in a
    multi-day trace): it stretches the mean gap the automatic h, windows and diffusion
    time come from.  When the window is the whole log (which such a silence may have
    stretched it to), one longer than the rest of the log together."""
    gaps = np.diff(times)
    if not len(gaps):
        return []
    k = int(np.argmax(gaps))
    if np.isfinite(length):
        limit, what = length, "a window"
    else:
        limit, what = float(times[-1] - times[0] - gaps[k]), "the rest of the log"
    if gaps[k] <= limit:
        return []
    return [f"the log is silent for {gaps[k]:.6g} s (t = {exact_time(times[k])} to {exact_time(times[k + 1])}), "
            f"longer than {what} ({limit:.3g} s): silences such as nights inflate the automatic per-hop "
            f"cost and windows; map each active period with --window T0:T1"]
