"""Everything a map decides from the data, decided once, before any graph is built.

:func:`resolve` turns a :class:`~.config.MapConfig` (where None means "from the data")
and the log into :class:`Settings`: the per-hop cost h, the diffusion time tau, the
window length W and every window's span, and the landmark bands, each with where it
came from.  Nothing downstream reads the config's "auto" fields again, and nothing
rewrites the config.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, SwarmtopoError
from ..log import EncounterLog
from ..metric.graph import agent_gaps, event_slice
from ..readers.base import BettiReader
from .config import MAX_HOP_COST, WHOLE_LOG, MapConfig
from .windows import scaled_windows, window_length

HOP_GAP_FACTOR = 2.0
"""Without r_d and v_c in meta.json, the per-hop cost h is this many times the mean time
between an agent's consecutive encounters."""
DIFFUSION_GAP_FACTOR = 0.5
"""The automatic diffusion time tau is this many times the mean time between an agent's
consecutive encounters."""


@dataclass(frozen=True)
class Settings:
    """What a map uses, each data-dependent value with where it came from.

    ``spans`` are the windows to map, in order (None: the whole log, for a scale whose
    windows would not be shorter than it); ``tried`` the window lengths shorter than the
    log (for the fallback's message); ``windows_left_out`` how many the cap dropped.
    """

    hop_cost: tuple[float, str]
    diffusion_time: tuple[float, str]
    window_length: tuple[float, str]
    spans: list[tuple[float, float] | None]
    tried: list[float]
    windows_left_out: int
    landmark_bands: tuple[float, ...]
    agent_gap: float | None
    times: np.ndarray  # the mapped events' times, sorted


def resolve(log: EncounterLog, config: MapConfig, reader: BettiReader) -> Settings:
    """The :class:`Settings` of mapping ``log`` with ``config`` and ``reader``.

    Raises
    ------
    SwarmtopoError
        If the log has fewer than 2 events, or ``config.window`` none.
    InputError
        If meta.json's r_d / v_c give a per-hop cost beyond ``MAX_HOP_COST``.
    """
    if log.n_events < 2:
        raise SwarmtopoError(f"the log has {log.n_events} event(s); at least 2 encounters are needed to build a map")
    event_slice(log, config.window)  # raises if the window holds no event
    mapped = log if config.window is None else log.window(*config.window)
    gap = mean_agent_gap(mapped)
    times = np.sort(mapped.t)
    span = float(times[-1] - times[0])
    length = window_length(gap, config.window_length, config.window_encounters, span)
    lengths = [window_length(gap, None if config.window_length is None else scale * config.window_length,
                             scale * config.window_encounters, span)[0] for scale in config.window_scales]
    spans, left_out = scaled_windows(times, lengths, config.window_step, config.max_windows, config.min_region_events)
    bands = config.landmark_bands
    if bands is None:
        bands = reader.landmark_bands if config.subsample == "maxmin" else (1.0,)
    return Settings(hop_cost=hop_cost(mapped, config.hop_cost, gap),
                    diffusion_time=diffusion_time(gap, config.diffusion_time),
                    window_length=length, spans=spans, tried=sorted(x for x in lengths if x < span),
                    windows_left_out=left_out, landmark_bands=tuple(bands), agent_gap=gap, times=times)


def hop_cost(log: EncounterLog, given: float | None, gap: float | None = None) -> tuple[float, str]:
    """(h, where it came from): the given value, else r_d / v_c from the log's meta.json,
    else ``HOP_GAP_FACTOR`` x ``gap``, the mean time between an agent's consecutive
    encounters (:func:`mean_agent_gap` of ``log`` when not given)."""
    if given is not None:
        return float(given), "given"
    r_d, v_c = log.meta.get("r_d"), log.meta.get("v_c")
    if all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) and x > 0 for x in (r_d, v_c)):
        h = float(r_d) / float(v_c)
        if not h <= MAX_HOP_COST:  # inf too; no file named: the caller knows the log's folder
            raise InputError(f"meta.json: r_d = {r_d:g} and v_c = {v_c:g} give a per-hop cost r_d / v_c of {h:.3g} s, "
                             f"more than {MAX_HOP_COST:g} s (the bound of --hop-cost): r_d must be in mm, v_c in mm/s")
        return h, "r_d / v_c from meta.json"
    gap = mean_agent_gap(log) if gap is None else gap
    if gap is None:
        return 0.0, "no agent met twice at different times: 0"
    return HOP_GAP_FACTOR * gap, f"{HOP_GAP_FACTOR:g} x mean time between an agent's encounters"


def diffusion_time(gap: float | None, given: float | None) -> tuple[float, str]:
    """(tau used, where it came from): the given value, else ``DIFFUSION_GAP_FACTOR`` x
    ``gap``; inf (the paper's weights) when no agent met twice at different times."""
    if given is not None:
        return float(given), "given"
    if gap is None:
        return WHOLE_LOG, "no agent met twice at different times: none"
    return DIFFUSION_GAP_FACTOR * gap, f"{DIFFUSION_GAP_FACTOR:g} x mean time between an agent's encounters"


def mean_agent_gap(log: EncounterLog) -> float | None:
    """Mean time between an agent's consecutive encounters at different times (None: none)."""
    gaps = agent_gaps(log)
    gaps = gaps[gaps > 0]
    return float(gaps.mean()) if len(gaps) else None
