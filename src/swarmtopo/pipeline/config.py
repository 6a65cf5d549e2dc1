"""The mapping pipeline's options: :class:`MapConfig`, and the one parser of the values
users write for them (``swarmtopo map`` options, a sweep's ``[map]`` table).

A user writes a value as text on the command line (``--window-length 12.5``, ``auto``,
``none``) or as a TOML value in a sweep (``window_length = 12.5``, ``"auto"``).  Both go
through :data:`OPTIONS`: :meth:`Option.canonical` checks the value and gives its
canonical form (a word, a number, a tuple of numbers), :meth:`Option.field` turns that
into the :class:`MapConfig` field ("auto" -> None, from the data; "none" -> inf or
None), and :func:`config_from_options` builds and validates the whole config.  An error
is a :class:`ConfigError` naming the field, so the CLI can name its option.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, Callable, Mapping

import numpy as np

from ..errors import SwarmtopoError
from ..metric.graph import METRICS
from ..metric.landmarks import SUBSAMPLERS

RECONTACTS = ("auto", "merge", "keep")
"""``MapConfig.recontacts``: merge a flickering log's repeated contact starts (``auto``), always, or never."""
UNCORROBORATED = ("auto", "drop", "keep")
"""``MapConfig.uncorroborated``: drop the encounters the rest of the log does not back when the log shows
faulty sensing (``auto``), always, or never."""

MAX_HOP_COST, MAX_WALL_FOLLOW_WEIGHT = 1e9, 1e6
"""Bounds of the per-hop cost (s, about 30 years) and of the wall-following charge (s/s):
far beyond any log, and far below where squared distances overflow in MDS."""
MAX_LANDMARKS = 2000
"""Bound of ``MapConfig.landmarks`` and ``max_landmarks``: persistence time grows about as L^3."""
MIN_WINDOW_SCALE = 0.05
"""Least window-scale multiplier: windows of one encounter per agent at the automatic length."""
WALL_FOLLOW_WEIGHT = 2.0
"""Default ``MapConfig.wall_follow_weight``: seconds charged per second of wall following
inside a chain gap, outside the diffusive compression (docs/accuracy.md)."""
WINDOW_SCALES = (0.75, 1.0, 1.25)
"""Default ``MapConfig.window_scales``: multipliers of the window length whose windows
are all pooled (windows of 15, 20 and 25 encounters per agent)."""
MAX_WINDOWS = 48
"""Default ``MapConfig.max_windows``: more than any map of the accuracy benchmark pools
(at most 44), so its measured accuracy holds; a longer log maps an evenly spaced subset."""
WHOLE_LOG = float("inf")
"""``MapConfig.window_length`` that maps the whole log at once (the paper)."""


class ConfigError(SwarmtopoError):
    """A config value out of its domain; ``field`` names the :class:`MapConfig` field."""

    def __init__(self, field: str, reason: str, expected: str | None = None):
        super().__init__(f"{field}: {reason}")
        self.field, self.reason, self.expected = field, reason, expected


@dataclass(frozen=True)
class MapConfig:
    """Options of the mapping pipeline.

    Attributes
    ----------
    metric
        Encounter metric: ``plain``, ``contracted`` or ``hybrid`` (paper definitions;
        hybrid = contracted + static agents as unbounded stops; it falls back to
        contracted without static agents and to plain without status).
    hop_cost
        Per-hop cost h (seconds) added to every chain edge of the graph
        (:mod:`swarmtopo.metric.graph`); 0 is the paper's metric; None (default) takes
        r_d / v_c from the log's meta.json, or, for a trace without them,
        ``HOP_GAP_FACTOR`` x the mean time between an agent's encounters.
    diffusion_time
        tau (seconds) of the diffusive chain weights D_tau(w) = tau (sqrt(1 + 2 w / tau)
        - 1): a long gap between an agent's encounters costs about a random walk's
        displacement, not its duration.  inf is the paper's weight; None (default) is
        ``DIFFUSION_GAP_FACTOR`` x the mean time between an agent's consecutive encounters.
    wall_follow_weight
        c: the part of a chain gap an agent spent wall following (status WF) weighs c
        per second, outside D_tau.  Default ``WALL_FOLLOW_WEIGHT``; None charges it like
        any other time (the paper).
    window_length
        Length W (s) of the time windows each region is mapped in; the region's Betti
        numbers pool them.  None (default): ``window_encounters`` times the mean time
        between an agent's consecutive encounters.  ``WHOLE_LOG`` (inf), or any length
        not shorter than the log, maps the whole log at once (the paper).
    window_encounters
        K, the encounters per agent an automatic window holds (default 20).
    window_scales
        Multipliers s of the window length: the windows of every length s x W are
        pooled, each distinct window once.  Default ``WINDOW_SCALES``.
    window_step
        Seconds between the starts of consecutive windows; None (default) = half the
        window length.
    max_windows
        Cap of the windows mapped, all lengths together (default ``MAX_WINDOWS``, at
        least one per scale): a longer log keeps an evenly spaced share of each
        length's windows.  None maps every window.
    subsample
        Landmark subsampler: ``maxmin``, ``knn`` (KNN-filtered maxmin) or
        ``probabilistic`` (probabilistic maxmin).
    landmark_bands
        Shares B of each window's length: every window is mapped once per band, its
        landmarks drawn (maxmin) among the nodes of the window's middle B x its
        length, and all are pooled.  None (default): with maxmin, the bands the reader
        was fitted with; with another subsampler, (1,).
    landmarks
        Number of landmarks L (3 .. ``MAX_LANDMARKS``) for the whole map, shared between
        regions in proportion to their events.  None (default): per region and window,
        the fewest whose covering radius is at most ``AUTO_COVER_FACTOR`` times the
        window's k-NN scale s, at most ``max_landmarks``.
    max_landmarks
        Cap of the automatic landmark count per region and window (default 400).
    window
        Optional time window (t0, t1) on the events, seconds; None = whole log.
    maxdim
        Highest homology dimension (1, or 2 on request).
    seed
        Seed of the landmark start and the MDS.
    knn_k, knn_q, omega
        Subsampler parameters (paper: k = 10, q = 0.9).
    min_region_events
        Events a graph component needs to count as a region (default 50).
    embed_dim
        Dimension of the MDS picture: 3, 2, or 0 for no picture (sweeps).
    cycles
        Find a representative loop of landmarks for each counted H1 bar.
    timeline_length
        Length (s) of the windows of the map's timeline (:mod:`.timeline`): None
        (default) = the map's own windows, read one by one (or, with ``timeline_step``
        set, windows of the window length W); ``WHOLE_LOG`` (inf) = no timeline.
    timeline_step
        Seconds between the starts of the timeline's own windows; None (default) = half
        their length.
    recontacts
        What to do with a pair's repeated contact starts (:mod:`.motion`): ``auto``
        (default) merges them when the log's contacts flicker (diffusive or flocking
        agents), ``merge`` always, ``keep`` never (the paper).
    uncorroborated
        What to do with the encounters the rest of the log does not back (:mod:`.faults`):
        ``auto`` (default) drops them when their share says the sensing was faulty,
        ``drop`` always, ``keep`` never (the paper).
    """

    metric: str = "hybrid"
    hop_cost: float | None = None
    diffusion_time: float | None = None
    wall_follow_weight: float | None = WALL_FOLLOW_WEIGHT
    window_length: float | None = None
    window_encounters: float = 20.0
    window_scales: tuple[float, ...] = WINDOW_SCALES
    window_step: float | None = None
    max_windows: int | None = MAX_WINDOWS
    subsample: str = "maxmin"
    landmark_bands: tuple[float, ...] | None = None
    landmarks: int | None = None
    max_landmarks: int = 400
    window: tuple[float | None, float | None] | None = None
    maxdim: int = 1
    seed: int | None = 0
    knn_k: int = 10
    knn_q: float = 0.9
    omega: float = 1.0
    min_region_events: int = 50
    embed_dim: int = 3
    cycles: bool = True
    timeline_length: float | None = None
    timeline_step: float | None = None
    recontacts: str = "auto"
    uncorroborated: str = "auto"

    def __post_init__(self):
        for name in ("window_scales", "landmark_bands"):
            value = getattr(self, name)
            if value is not None and not isinstance(value, tuple):
                object.__setattr__(self, name, tuple(value) if isinstance(value, (list, np.ndarray)) else (value,))

    def validate(self) -> "MapConfig":
        """Check every field; raise :class:`ConfigError` naming the first bad one."""
        def bad(name, reason):
            raise ConfigError(name, reason)

        if self.metric not in METRICS:
            bad("metric", f"unknown metric {self.metric!r}; expected one of {', '.join(METRICS)}")
        if self.subsample not in SUBSAMPLERS:
            bad("subsample", f"unknown subsampler {self.subsample!r}; expected one of {', '.join(SUBSAMPLERS)}")
        for name in ("landmarks", "max_landmarks"):
            count = getattr(self, name)
            if count is not None and not (_is_whole(count) and 3 <= count <= MAX_LANDMARKS):
                bad(name, f"must be a whole number in 3..{MAX_LANDMARKS} (persistence time grows about as L^3), "
                          f"got {count}")
        if self.seed is not None and not (_is_whole(self.seed) and self.seed >= 0):
            bad("seed", f"must be a whole number >= 0 or None, got {self.seed}")
        if self.hop_cost is not None and not (np.isfinite(self.hop_cost) and 0 <= self.hop_cost <= MAX_HOP_COST):
            bad("hop_cost", f"must be a number of seconds in [0, {MAX_HOP_COST:g}], got {self.hop_cost}")
        if self.diffusion_time is not None and not self.diffusion_time > 0:
            bad("diffusion_time", f"must be a positive number of seconds or inf, got {self.diffusion_time}")
        if self.wall_follow_weight is not None and not (np.isfinite(self.wall_follow_weight)
                                                        and 0 <= self.wall_follow_weight <= MAX_WALL_FOLLOW_WEIGHT):
            bad("wall_follow_weight", f"must be a number in [0, {MAX_WALL_FOLLOW_WEIGHT:g}] or None, "
                                      f"got {self.wall_follow_weight}")
        if self.window_length is not None and not self.window_length > 0:
            bad("window_length", f"must be a positive number of seconds, got {self.window_length}")
        if not (np.isfinite(self.window_encounters) and self.window_encounters > 0):
            bad("window_encounters", f"must be a positive number, got {self.window_encounters}")
        scales = self.window_scales
        if not scales or not all(_is_number(x) and np.isfinite(x) and x >= MIN_WINDOW_SCALE for x in scales):
            bad("window_scales", f"must be one or more numbers >= {MIN_WINDOW_SCALE:g}, got {list(scales)}")
        if len(set(scales)) < len(scales):
            bad("window_scales", f"must be distinct, got {list(scales)}")
        bands = (1.0,) if self.landmark_bands is None else self.landmark_bands
        if not bands or not all(_is_number(x) and 0 < x <= 1 for x in bands) or len(set(bands)) < len(bands):
            bad("landmark_bands", f"must be one or more distinct numbers in (0, 1], got {list(bands)}")
        if any(x < 1 for x in bands) and self.subsample != "maxmin":
            bad("landmark_bands", f"bands below 1 draw maxmin landmarks from the middle of each window; "
                                  f"subsample {self.subsample!r} cannot, use maxmin")
        if self.window_step is not None and not (np.isfinite(self.window_step) and self.window_step > 0):
            bad("window_step", f"must be a positive number of seconds, got {self.window_step}")
        if self.timeline_length is not None and not self.timeline_length > 0:
            bad("timeline_length", f"must be a positive number of seconds, got {self.timeline_length}")
        if self.timeline_step is not None and not (np.isfinite(self.timeline_step) and self.timeline_step > 0):
            bad("timeline_step", f"must be a positive number of seconds, got {self.timeline_step}")
        if self.max_windows is not None and (isinstance(self.max_windows, bool) or
                                             not isinstance(self.max_windows, (int, np.integer)) or
                                             self.max_windows < len(scales)):
            bad("max_windows", f"must be a whole number, at least the number of window scales ({len(scales)}: one "
                               f"window per length), or None; got {self.max_windows}")
        if self.recontacts not in RECONTACTS:
            bad("recontacts", f"must be one of {', '.join(RECONTACTS)}, got {self.recontacts!r}")
        if self.uncorroborated not in UNCORROBORATED:
            bad("uncorroborated", f"must be one of {', '.join(UNCORROBORATED)}, got {self.uncorroborated!r}")
        if self.maxdim not in (1, 2):
            bad("maxdim", f"must be 1 or 2, got {self.maxdim}")
        if self.embed_dim not in (0, 2, 3):
            bad("embed_dim", f"must be 0, 2 or 3, got {self.embed_dim}")
        if self.window is not None:
            t0, t1 = self.window
            for end in (t0, t1):
                if end is not None and not np.isfinite(end):
                    bad("window", f"window ends must be finite numbers or None, got {end}")
            if t0 is not None and t1 is not None and t1 < t0:
                bad("window", f"window end {t1} is before its start {t0}")
        return self


PAPER_OPTIONS = {"hop_cost": 0.0, "diffusion_time": "none", "wall_follow_weight": "none", "window_length": "none",
                 "window_scales": (1.0,), "landmark_bands": (1.0,), "recontacts": "keep",
                 "uncorroborated": "keep"}
"""The options of the paper's pipeline (no per-hop cost, no diffusive weights, wall
following like any time, the whole log at once, whole-window landmarks), read with the
``paper`` reader (``swarmtopo map --paper``)."""
PAPER_EXCLUDES = (*PAPER_OPTIONS, "window_encounters", "window_step", "max_windows")
"""Options that ``--paper`` fixes, or that mean nothing when the whole log is one window:
giving one with it is refused."""


# -- the one parser of option values ----------------------------------------------------
@dataclass(frozen=True)
class Option:
    """How users write one :class:`MapConfig` field.

    ``words`` maps each word the option accepts ("auto", "none") to the field's value;
    ``parse`` checks any other value (a number, text of a number, a list) and returns its
    canonical form, raising ``ValueError`` with what was expected.
    """

    name: str
    parse: Callable[[Any], Any]
    words: Mapping[str, Any] = None  # type: ignore[assignment]

    def canonical(self, value: Any) -> Any:
        """The checked value as written canonically: a word, a number or a tuple."""
        words = self.words or {}
        if isinstance(value, str) and value.strip().lower() in words:
            return value.strip().lower()
        try:
            return self.parse(value)
        except ValueError as exc:
            expected = f"{exc}" + "".join(f" or '{w}'" for w in words)
            raise ConfigError(self.name, f"{_shown(value)} is not {expected}", expected) from None

    def field(self, canonical: Any) -> Any:
        """The MapConfig field value of a canonical value."""
        words = self.words or {}
        return words[canonical] if isinstance(canonical, str) and canonical in words else canonical


def _is_whole(x) -> bool:
    return isinstance(x, (int, np.integer)) and not isinstance(x, bool)


def _is_number(x) -> bool:
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, bool)


def _shown(value) -> str:
    return repr(value) if isinstance(value, str) else str(value)


def _as_float(value) -> float:
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            raise ValueError("a number") from None
    if not _is_number(value):
        raise ValueError("a number")
    return float(value)


def _number(lo: float, *, strict: bool, hi: float | None = None) -> Callable[[Any], float]:
    bound = f"{'>' if strict else '>='} {lo:g}" + ("" if hi is None else f" and <= {hi:g}")

    def parse(value) -> float:
        try:
            x = _as_float(value)
        except ValueError:
            raise ValueError(f"a finite number {bound}") from None
        if not (math.isfinite(x) and (x > lo if strict else x >= lo) and (hi is None or x <= hi)):
            raise ValueError(f"a finite number {bound}")
        return x
    return parse


def _integer(lo: int, hi: int | None = None) -> Callable[[Any], int]:
    expected = f"a whole number >= {lo}" + ("" if hi is None else f" and <= {hi}")

    def parse(value) -> int:
        if isinstance(value, str):
            try:
                value = int(value.strip())
            except ValueError:
                raise ValueError(expected) from None
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < lo or \
                (hi is not None and value > hi):
            raise ValueError(expected)
        return int(value)
    return parse


def _numbers(item: Callable[[Any], float], example: str) -> Callable[[Any], tuple[float, ...]]:
    """Distinct numbers: a comma-separated text, a list, or one number."""
    def parse(value) -> tuple[float, ...]:
        items = value.split(",") if isinstance(value, str) else value if isinstance(value, (list, tuple)) else [value]
        try:
            numbers = tuple(item(x) for x in items)
        except ValueError as exc:
            raise ValueError(f"a list of distinct numbers, each {exc} (e.g. {example})") from None
        if not numbers or len(set(numbers)) < len(numbers):
            raise ValueError(f"a list of distinct numbers (e.g. {example})")
        return numbers
    return parse


def _span(value) -> tuple[float | None, float | None]:
    """A time window: text ``T0:T1`` (either side may be empty) or a pair; an infinite
    end is an open one."""
    expected = "a time window T0:T1 in seconds (either side may be empty)"
    if isinstance(value, str):
        parts = value.split(":")
        if len(parts) != 2:
            raise ValueError(expected)
        try:
            ends = [float(p) if p.strip() else None for p in parts]
        except ValueError:
            raise ValueError(expected) from None
    elif isinstance(value, (list, tuple)) and len(value) == 2 and all(e is None or _is_number(e) for e in value):
        ends = [None if e is None else float(e) for e in value]
    else:
        raise ValueError(expected)
    if any(e is not None and math.isnan(e) for e in ends):
        raise ValueError(expected + ", not NaN")
    if ends[0] == math.inf or ends[1] == -math.inf:
        raise ValueError(expected + " that can hold something (it starts at +inf or ends at -inf)")
    return tuple(None if e is None or math.isinf(e) else e for e in ends)


def _choice(options) -> Callable[[Any], str]:
    def parse(value) -> str:
        value = value.strip().lower() if isinstance(value, str) else value
        if value not in options:
            raise ValueError(f"one of {', '.join(options)}")
        return value
    return parse


_SECONDS = {"auto": None, "none": WHOLE_LOG}
OPTIONS: dict[str, Option] = {option.name: option for option in (
    Option("metric", _choice(METRICS)),
    Option("subsample", _choice(SUBSAMPLERS)),
    Option("hop_cost", _number(0.0, strict=False, hi=MAX_HOP_COST), {"auto": None}),
    Option("diffusion_time", _number(0.0, strict=True), _SECONDS),
    Option("wall_follow_weight", _number(0.0, strict=False, hi=MAX_WALL_FOLLOW_WEIGHT), {"none": None}),
    Option("window_length", _number(0.0, strict=True), _SECONDS),
    Option("window_encounters", _number(0.0, strict=True)),
    Option("window_scales", _numbers(_number(MIN_WINDOW_SCALE, strict=False), "0.75,1,1.25")),
    Option("window_step", _number(0.0, strict=True), {"auto": None}),
    Option("max_windows", _integer(1), {"none": None}),
    Option("landmark_bands", _numbers(_number(0.0, strict=True, hi=1.0), "1,0.5"), {"auto": None}),
    Option("landmarks", _integer(3, MAX_LANDMARKS), {"auto": None}),
    Option("max_landmarks", _integer(3, MAX_LANDMARKS)),
    Option("maxdim", _integer(1, 2)),
    Option("window", _span),
    Option("timeline_length", _number(0.0, strict=True), _SECONDS),
    Option("timeline_step", _number(0.0, strict=True), {"auto": None}),
    Option("seed", _integer(0)),
    Option("recontacts", _choice(RECONTACTS)),
    Option("uncorroborated", _choice(UNCORROBORATED)),
)}
"""Every option users may set by name, with its parser."""


def config_from_options(options: Mapping[str, Any], **fixed: Any) -> MapConfig:
    """A validated :class:`MapConfig` from option values as users write them.

    Parameters
    ----------
    options
        Field name -> value (text or TOML value) for fields in :data:`OPTIONS`; a value
        of None leaves the field at its default.
    **fixed
        Fields given as :class:`MapConfig` values already (``seed``, ``window``,
        ``embed_dim``, ``cycles``, ...).

    Raises
    ------
    ConfigError
        Naming the first field whose value is out of its domain.
    """
    known = {f.name for f in fields(MapConfig)}
    values = dict(fixed)
    for name, value in options.items():
        if name not in OPTIONS:
            raise ConfigError(name, f"is not an option of the map (known: {', '.join(OPTIONS)})"
                              if name not in known else "cannot be written as an option")
        if value is not None:
            option = OPTIONS[name]
            values[name] = option.field(option.canonical(value))
    return MapConfig(**values).validate()
