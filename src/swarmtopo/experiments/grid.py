"""Sweep grids: a TOML file -> the simulate-and-map jobs it stands for.

Format (``examples/sweep-small.toml`` is a commented example)::

    [sweep]
    name = "two-holes"        # label of the sweep (default: the file name without .toml)
    replicates = 5            # jobs (seeds) per grid point (default 1)
    salt = "train"            # text mixed into every job's seed and key (default "")
    job_timeout = 3600        # seconds a job may run before it is killed: a "timeout" row (default 3600)
    diagrams = "map"          # diagrams each row keeps: none | map | windows (default "map")

    [arena]
    generator = "random"      # random | default | square | annulus | two_rooms | file | changing | hall
    holes = [1, 2, 3]         # random, two_rooms: number of holes (default 1)
    shapes = "square"         # random, two_rooms: hole families (default "square")
    outer = "square"          # random: outer wall square | rectangle | polygon
    scale = [0.75, 1.0]       # all: scale factor of every length (default 1.0)
    r_outer = 250.0           # annulus: outer radius, mm (default 250)
    r_inner = 150.0           # annulus: inner radius, mm (default 150)
    path = "arena.geojson"    # file: GeoJSON arena (a changing one too), relative to the TOML file
    change = "appear"         # changing: none | appear (a hole appears) | disappear | door (a door
                              # closes between two rooms): swarmtopo.changing.changing_arena
    change_time = 60.0        # changing: when, s (before the swarm's duration)
    length = 3000.0           # hall: length of a long hall, mm (swarmtopo.arena.hall_arena)
    width = 600.0             # hall: its width, mm

    [swarm]
    agents = 200              # swarm size N (default 200)
    duration = 20.0           # seconds of data (default 20)
    static_fraction = 0.0     # fraction of agents stopped for good (default 0)
    static_time = 0.0         # when they stop, s (default 0; only with static_fraction > 0)
    leash = 0.0               # R, mm: a leader sweeps the arena's long axis once and agents are kept
                              # within R of it (swarmtopo.beacon.long_axis_track); 0 (default): no leader
    leader_speed = 2.0        # the leader's speed, mm/s (only with leash > 0)
    motion = "cockroach"      # cockroach (the paper's, default) | billiard | run-and-tumble | brownian |
                              # levy | flocking (swarmtopo.sim.params); their options (default: the model's):
    speed = 15.0              # billiard, run-and-tumble, levy, flocking: mm/s
    tumble_rate = 0.5         # run-and-tumble: tumbles per s
    diffusion = 225.0         # brownian: D, mm^2/s
    levy_exponent = 2.0       # levy: mu in (1, 3]
    levy_min_step = 10.0      # levy: l_0, mm
    align_radius = 30.0       # flocking: mm
    noise = 1.0               # flocking: eta, rad

    [map]
    metric = "hybrid"         # plain | contracted | hybrid (default hybrid)
    hop_cost = "auto"         # per-hop cost h, s: a number >= 0 (0 = the paper) or "auto" (default)
    diffusion_time = "auto"   # tau of the diffusive chain weights, s: a number > 0, "auto" (default:
                              # half the mean time between an agent's encounters) or "none" (the paper)
    wall_follow_weight = 2.0  # s charged per s of wall following in a gap, outside the diffusive
                              # weights: a number >= 0 (default 2) or "none" (like any time, the paper)
    window_length = "auto"    # windows pooled, s: a number > 0, "auto" (default: window_encounters
                              # encounters per agent) or "none" (whole log, the paper)
    window_encounters = 20.0  # K of automatic windows (only with window_length = "auto")
    window_scales = [0.75, 1.0, 1.25]  # multipliers of the window length whose windows are all pooled
    window_step = "auto"      # s between window starts: a number > 0 or "auto" (half the length)
    subsample = "maxmin"      # maxmin | knn | probabilistic (default maxmin)
    landmarks = "auto"        # an integer L in 3..2000, or "auto" (default)
    max_landmarks = 400       # cap of the automatic count (only with landmarks = "auto")
    maxdim = 1                # highest homology dimension, 1 or 2 (default 1)
    classifier = "default"    # "default", "paper", or a classifier JSON file

    [faults]                  # the simulated log through a faulty radio (swarmtopo.sim.faults;
                              # every level 0 by default: no fault, and the job's config has no [faults])
    lost = 0.0                # share of reports lost independently
    burst_lost = 0.0          # share of each radio's time down (its reports lost)
    burst_length = 2.0        # mean outage, s (only with burst_lost > 0)
    false_encounters = 0.0    # false reports of pairs that never met, per report
    jitter = 0.0              # s, standard deviation of each report's time noise
    clock_offset = 0.0        # s, each agent's clock off by up to this (uniform)
    clock_drift = 0.0         # s per s, each agent's clock drifting by up to this
    dying = 0.0               # share of agents whose battery dies at a random time
    duplicated = 0.0          # share of reports delivered twice
    duplicate_delay = 0.5     # s, a duplicate's delay at most (only with duplicated > 0)

Every value of ``[arena]``, ``[swarm]``, ``[map]`` and ``[faults]`` may be a scalar or a list; lists
expand into the Cartesian product of all lists, times ``replicates``.  ``shapes`` is a
set of hole families, each hole drawing its family uniformly from the set: a string
or a list of strings is one set (``["square", "disc"]``: every arena mixes squares and
discs); a list of lists is a grid over sets (``[["square"], ["square", "disc"]]``: two
grid points).  A set is canonical sorted, so ``["disc", "square"]`` is the same job.
``window_scales`` is a set the same way: ``[0.75, 1, 1.25]`` is one set of three
scales, ``[[1], [0.75, 1, 1.25]]`` two grid points.

Canonical configuration.  Each grid point becomes a nested dict ``{"arena": ...,
"swarm": ..., "map": ...}`` with defaults filled in and only the keys its generator
and options use (``holes`` is dropped for ``generator = "default"``, ``static_time``
when ``static_fraction = 0``, ``max_landmarks`` when ``landmarks`` is a number);
points that become equal are one job.  A key given in the file that no grid point
uses is an error, and so is a point the job's own checks refuse (the simulator's,
``MapConfig.validate``): every job is checked before any runs.  Integers must fit the
store's 32-bit columns.  Input files (``path``, a classifier path) enter the
configuration as written plus the SHA-256 of their bytes, so a job is tied to the
file's content; workers read them at their absolute path (on a cluster of several
machines, keep them on a shared file system).

Job identity.  ``job.key`` is the SHA-256 (hex) of the canonical JSON of (config,
replicate, salt); ``job.seed`` is the first 64 bits of the same hash.  Neither depends
on the job's position in the grid, so growing a grid never changes finished jobs.
The job's randomness comes from ``np.random.SeedSequence(job.seed)``, spawned into
independent streams (arena, simulation, map, faults): see :meth:`Job.stream_seeds`.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..arena import HOLE_SHAPES, OUTER_SHAPES
from ..beacon import LEADER_SPEED
from ..changing import CHANGES
from ..readers.registry import PRESETS, load_classifier
from ..errors import InputError, SwarmtopoError
from ..io import read_arena
from ..pipeline.config import OPTIONS, ConfigError, MapConfig, config_from_options
from ..sim.faults import FAULT_LEVELS, FAULT_SHARES, Faults
from ..sim.params import MOTION_MODELS, MOTION_OPTIONS, make_motion
from ..sim.simulate import check_parameters

GENERATORS: dict[str, tuple[str, ...]] = {
    "random": ("holes", "shapes", "outer", "scale"),
    "default": ("scale",),
    "square": ("scale",),
    "annulus": ("r_outer", "r_inner", "scale"),
    "two_rooms": ("holes", "shapes", "scale"),
    "file": ("path", "scale"),
    "changing": ("holes", "shapes", "outer", "scale", "change", "change_time"),
    "hall": ("holes", "shapes", "length", "width"),
}
"""Arena generators and the ``[arena]`` keys each one uses (besides ``generator``)."""
STREAMS = ("arena", "simulation", "map", "faults")
"""The independent random streams of a job, in :meth:`Job.stream_seeds` order."""
STORE_INT_MAX = int(np.iinfo(np.int32).max)
"""Bound of every integer key: the store's INTEGER columns are 32-bit."""


class _Bad(Exception):
    """A value outside its key's domain (message: what was expected)."""


# -- value checks: each returns the canonical value or raises _Bad --------------------------
def _integer(lo: int, hi: int = STORE_INT_MAX) -> Callable[[Any], int]:
    expected = (f"expected an integer in {lo}..{hi}" if hi < STORE_INT_MAX
                else f"expected an integer >= {lo} (at most {hi}: a 32-bit store column)")

    def check(value):
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise _Bad(expected)
        return int(value)
    return check


def _number(lo: float, *, strict: bool, hi: float | None = None) -> Callable[[Any], float]:
    def check(value):
        ok = (not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)
              and (value > lo if strict else value >= lo) and (hi is None or value <= hi))
        if not ok:
            bound = f"{'>' if strict else '>='} {lo:g}" + ("" if hi is None else f" and <= {hi:g}")
            raise _Bad(f"expected a finite number {bound}")
        return float(value)
    return check


def _choice(options) -> Callable[[Any], str]:
    def check(value):
        if value not in options:
            raise _Bad(f"expected one of {', '.join(options)}")
        return value
    return check


def _text(value) -> str:
    if not isinstance(value, str) or not value:
        raise _Bad("expected a non-empty string")
    return value


def _shape_set(value) -> tuple[str, ...]:
    shapes = [value] if isinstance(value, str) else value
    if not isinstance(shapes, list) or not shapes or any(s not in HOLE_SHAPES for s in shapes):
        raise _Bad(f"expected hole shapes among {', '.join(HOLE_SHAPES)}")
    return tuple(sorted(set(shapes)))


def _scale_set(value) -> tuple[float, ...]:
    """A set of window scales: a number or a list of them, canonical sorted and distinct,
    each checked by the map's own option parser."""
    scales = value if isinstance(value, list) else [value]
    if not scales or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in scales):
        raise _Bad("expected a positive number or a list of them")
    return tuple(sorted(_option("window_scales")(sorted(set(scales)))))


def _option(name: str) -> Callable[[Any], Any]:
    """A ``[map]`` key checked by the map's own option parser (``pipeline.config.OPTIONS``)."""
    def check(value):
        try:
            return OPTIONS[name].canonical(value)
        except ConfigError as exc:
            raise _Bad(f"expected {exc.expected}".replace("'", '"')) from None  # TOML's quotes
    return check


@dataclass(frozen=True)
class Param:
    """One grid key: its table, default, check, SQL type of its store column, and whether
    its value is a set (a value or a flat list is one set; a list of lists, a grid)."""

    table: str
    name: str
    default: Any
    check: Callable[[Any], Any]
    sql: str
    set_valued: bool = False


PARAMS: tuple[Param, ...] = (
    Param("arena", "generator", "random", _choice(tuple(GENERATORS)), "TEXT"),
    Param("arena", "holes", 1, _integer(0), "INTEGER"),
    Param("arena", "shapes", ("square",), _shape_set, "TEXT[]", set_valued=True),
    Param("arena", "outer", "square", _choice(OUTER_SHAPES), "TEXT"),
    Param("arena", "scale", 1.0, _number(0.0, strict=True), "DOUBLE"),
    Param("arena", "r_outer", 250.0, _number(0.0, strict=True), "DOUBLE"),
    Param("arena", "r_inner", 150.0, _number(0.0, strict=True), "DOUBLE"),
    Param("arena", "path", None, _text, "TEXT"),
    Param("arena", "change", "appear", _choice(CHANGES), "TEXT"),
    Param("arena", "change_time", 60.0, _number(0.0, strict=True), "DOUBLE"),
    Param("arena", "length", 3000.0, _number(0.0, strict=True), "DOUBLE"),
    Param("arena", "width", 600.0, _number(0.0, strict=True), "DOUBLE"),
    Param("swarm", "agents", 200, _integer(1), "INTEGER"),
    Param("swarm", "duration", 20.0, _number(0.0, strict=True), "DOUBLE"),
    Param("swarm", "static_fraction", 0.0, _number(0.0, strict=False, hi=1.0), "DOUBLE"),
    Param("swarm", "static_time", 0.0, _number(0.0, strict=False), "DOUBLE"),
    Param("swarm", "leash", 0.0, _number(0.0, strict=False), "DOUBLE"),
    Param("swarm", "leader_speed", LEADER_SPEED, _number(0.0, strict=True), "DOUBLE"),
    Param("swarm", "motion", "cockroach", _choice(tuple(MOTION_MODELS)), "TEXT"),
    *(Param("swarm", name, None, _number(0.0, strict=name != "noise"), "DOUBLE") for name in MOTION_OPTIONS),
    *(Param("map", name, default, _option(name), sql) for name, default, sql in (
        ("metric", "hybrid", "TEXT"), ("hop_cost", "auto", "DOUBLE"), ("diffusion_time", "auto", "DOUBLE"),
        ("wall_follow_weight", MapConfig().wall_follow_weight, "DOUBLE"), ("window_length", "auto", "DOUBLE"),
        ("window_encounters", MapConfig().window_encounters, "DOUBLE"))),
    Param("map", "window_scales", tuple(sorted(MapConfig().window_scales)), _scale_set, "DOUBLE[]",
          set_valued=True),
    *(Param("map", name, default, _option(name), sql) for name, default, sql in (
        ("window_step", "auto", "DOUBLE"), ("subsample", "maxmin", "TEXT"), ("landmarks", "auto", "INTEGER"),
        ("max_landmarks", MapConfig().max_landmarks, "INTEGER"), ("maxdim", 1, "INTEGER"))),
    Param("map", "classifier", "default", _text, "TEXT"),
    *(Param("faults", name, getattr(Faults(), name), _number(0.0, strict=False, hi=1.0 if name in FAULT_SHARES else None),
            "DOUBLE") for name in Faults.__dataclass_fields__),
)
"""Every grid key, in expansion order (the last key varies fastest)."""
GRID_TABLES = ("arena", "swarm", "map", "faults")
SWEEP_KEYS = ("name", "replicates", "salt", "job_timeout", "diagrams")
DEFAULT_JOB_TIMEOUT = 3600.0
"""Seconds a job may run before it is killed and stored as a "timeout" row (``[sweep]
job_timeout``): generous, the benchmark's largest maps take about a minute on one core."""
KEEP_LEVELS = ("none", "map", "windows")
"""What a row's ``diagrams`` keeps (``[sweep] diagrams``), least to most: each region's
and window's metadata always; ``map`` adds each region's own diagram (its representative
window's); ``windows`` every window's diagram (what re-reading the windows with another
classifier needs)."""
MAX_JOBS = 1_000_000
"""Most jobs a sweep may expand to (grid points x replicates): months of maps on one
machine, and their Job objects still fit in memory."""


@dataclass(frozen=True)
class Job:
    """One simulate-and-map job: a canonical configuration and a replicate index.

    Attributes
    ----------
    sweep
        Name of the sweep that asked for it (a label: not part of the key).
    config_json
        Canonical JSON of the configuration (sorted keys, defaults filled in).
    replicate
        Replicate index r = 0 .. replicates - 1.
    salt
        The sweep's salt (part of the key and seed).
    files
        ``(key, absolute path)`` of the job's input files (``arena.path``,
        ``map.classifier``); not part of the key, whose config holds their SHA-256.
    case_seed
        Seed of the arena, simulation and faults streams shared by jobs that map the same
        simulated case in different ways (the accuracy benchmark's pipelines); None:
        every stream comes from the job's own seed.  Part of the key when set.
    """

    sweep: str
    config_json: str
    replicate: int
    salt: str = ""
    files: tuple[tuple[str, str], ...] = ()
    case_seed: int | None = None

    @property
    def config(self) -> dict[str, Any]:
        """The canonical configuration as a fresh dict."""
        return json.loads(self.config_json)

    @property
    def key(self) -> str:
        """Hex SHA-256 of the canonical JSON of (config, replicate, salt): the job's identity."""
        return self._digest.hex()

    @property
    def seed(self) -> int:
        """64-bit seed: the first 8 bytes of the key's hash, as an unsigned integer."""
        return int.from_bytes(self._digest[:8], "big")

    def stream_seeds(self) -> dict[str, int]:
        """Independent seeds of the job's streams (``STREAMS``), spawned from
        ``SeedSequence(seed)``: one 64-bit integer each.  With ``case_seed`` the arena,
        simulation and faults streams are spawned from it instead (:func:`case_streams`)."""
        children = np.random.SeedSequence(self.seed).spawn(len(STREAMS))
        seeds = {name: int(child.generate_state(1, np.uint64)[0]) for name, child in zip(STREAMS, children)}
        if self.case_seed is not None:
            seeds.update(case_streams(self.case_seed))
        return seeds

    def file(self, key: str) -> str | None:
        """Absolute path of the input file of ``key`` (``"arena.path"`` or
        ``"map.classifier"``); None if the job has none."""
        return dict(self.files).get(key)

    @cached_property
    def _digest(self) -> bytes:
        """SHA-256 of the canonical JSON of (config, replicate, salt), computed once per job."""
        identity = {"config": json.loads(self.config_json), "replicate": self.replicate, "salt": self.salt}
        if self.case_seed is not None:
            identity["case_seed"] = self.case_seed
        return hashlib.sha256(canonical_json(identity).encode()).digest()


def suite_case_seed(suite: str, cell: str, split: str, index: int, attempt: int = 0) -> int:
    """64-bit seed of case ``index`` of a benchmark suite's cell in one split (tuning,
    reporting, ...), from the SHA-256 of (suite, cell, split, index, attempt): splits never
    share a seed and adding cases never changes old ones."""
    identity = {"suite": suite, "cell": cell, "split": split, "index": index}
    text = canonical_json(identity if attempt == 0 else {**identity, "attempt": attempt})
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:8], "big")


def case_streams(case_seed: int) -> dict[str, int]:
    """The arena, simulation and faults seeds of a shared case (``Job.case_seed``): one
    case perturbed at several fault levels draws its faults from one stream."""
    children = np.random.SeedSequence(case_seed).spawn(3)
    return {name: int(child.generate_state(1, np.uint64)[0])
            for name, child in zip(("arena", "simulation", "faults"), children)}


@dataclass(frozen=True)
class Sweep:
    """A parsed sweep file: its name, salt, replicates and the jobs of its grid."""

    name: str
    salt: str
    replicates: int
    jobs: tuple[Job, ...]
    source: str
    job_timeout: float = DEFAULT_JOB_TIMEOUT
    diagrams: str = "map"


def canonical_json(obj) -> str:
    """Compact JSON with sorted keys: the byte-stable form hashed into job keys."""
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False)


def read_sweep(path) -> Sweep:
    """Parse a sweep TOML file and expand its grid.

    Raises
    ------
    InputError
        On a syntax error, an unknown table or key, a wrong type or an out-of-range
        value: one line naming the file, the key and the value; or when no table of
        the grid has a key (an empty file would run one job of the defaults).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError("file not found", file=str(path)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read file ({exc})", file=str(path)) from None
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"invalid TOML: {exc}", file=str(path)) from None
    sweep = expand_grid(document, source=str(path), base_dir=path.parent, default_name=path.stem)
    if not any(document.get(table) for table in GRID_TABLES):  # a typo'd table was refused above
        tables = [f"[{table}]" for table in GRID_TABLES]
        raise InputError(f"no key in {', '.join(tables[:-1])} or {tables[-1]}: nothing to sweep (give at least one "
                         "value, e.g. [swarm] agents = 200)", file=str(path))
    return sweep


def expand_grid(document: dict, *, source: str = "<grid>", base_dir=None,
                default_name: str = "sweep") -> Sweep:
    """Expand a parsed sweep document (the TOML as a dict) into its jobs.

    Parameters
    ----------
    document
        ``{"sweep": {...}, "arena": {...}, "swarm": {...}, "map": {...}}``, every table
        optional (see the module docstring).
    source
        Name used in error messages (the file).
    base_dir
        Folder that relative input paths are relative to (default: the working folder).
    default_name
        Sweep name when ``[sweep] name`` is absent.
    """
    def fail(where: str, message: str):
        raise InputError(f"{where}: {message}", file=source)

    base_dir = Path(base_dir) if base_dir is not None else Path.cwd()
    for table, body in document.items():
        if table not in ("sweep", *GRID_TABLES):
            fail(f"[{table}]", f"unknown table; expected sweep, {', '.join(GRID_TABLES)}")
        if not isinstance(body, dict):
            fail(f"[{table}]", f"expected a table, got {_toml(body)}")

    head = document.get("sweep", {})
    for key in head:
        if key not in SWEEP_KEYS:
            fail(f"[sweep] {key}", f"unknown key; expected one of {', '.join(SWEEP_KEYS)}")
    name = _scalar(head, "name", default_name, _text, fail)
    salt = head.get("salt", "")
    if not isinstance(salt, str):
        fail(f"[sweep] salt = {_toml(salt)}", "expected a string")
    replicates = _scalar(head, "replicates", 1, _integer(1), fail)
    job_timeout = _scalar(head, "job_timeout", DEFAULT_JOB_TIMEOUT, _number(0.0, strict=True), fail)
    diagrams = _scalar(head, "diagrams", "map", _choice(KEEP_LEVELS), fail)

    known = {(p.table, p.name) for p in PARAMS}
    for table in GRID_TABLES:
        for key in document.get(table, {}):
            if (table, key) not in known:
                names = ", ".join(p.name for p in PARAMS if p.table == table)
                fail(f"[{table}] {key}", f"unknown key; expected one of {names}")
    axes = [_axis(document.get(param.table, {}), param, fail) for param in PARAMS]
    points = math.prod(len(axis) for axis in axes)
    if points * replicates > MAX_JOBS:
        fail(f"[sweep] replicates = {replicates}", f"{points:,} grid points x {replicates:,} replicates = "
             f"{points * replicates:,} jobs, more than the {MAX_JOBS:,} a sweep may hold")

    inputs = _InputFiles(base_dir, fail)
    configs: dict[str, tuple[tuple[str, str], ...]] = {}
    used: set[tuple[str, str]] = set()
    for values in itertools.product(*axes):
        point = {(p.table, p.name): v for p, v in zip(PARAMS, values)}
        config, files, keys = _canonical(point, inputs, fail)
        used |= keys
        text = canonical_json(config)
        if text not in configs:
            _check_job(config, document, fail)
            configs[text] = files
    for table in GRID_TABLES:
        for key in document.get(table, {}):
            if (table, key) not in used:
                fail(f"[{table}] {key}", _unused_reason(table, key, document))

    jobs = tuple(Job(sweep=name, config_json=config, replicate=r, salt=salt, files=files)
                 for config, files in configs.items() for r in range(replicates))
    return Sweep(name=name, salt=salt, replicates=replicates, jobs=jobs, source=source, job_timeout=job_timeout,
                 diagrams=diagrams)


def flat_columns(config: dict) -> dict[str, Any]:
    """One value per ``PARAMS`` key: None where the config does not use it and for "auto"
    (from the data), inf for "none" in a number column (``diffusion_time``,
    ``wall_follow_weight`` and ``window_length``: the paper's weights, the whole log), None
    for "none" in another column but ``change`` (where "none" is a kind of change): the
    store's flattened grid columns."""
    flat = {}
    for p in PARAMS:
        value = config.get(p.table, {}).get(p.name)
        flat[p.name] = (float("inf") if value == "none" and p.sql == "DOUBLE"
                        else None if value == "auto" or (value == "none" and p.name != "change") else value)
    return flat


def job_simulation_args(swarm: dict[str, Any]) -> dict[str, Any]:
    """The swarm arguments of :func:`~swarmtopo.sim.simulate` (besides arena and rng) of a
    job's canonical ``[swarm]`` table."""
    args = {"n_agents": swarm["agents"], "duration": swarm["duration"],
            "static_fraction": swarm["static_fraction"], "static_time": swarm.get("static_time", 0.0)}
    if "motion" in swarm:
        args["motion"] = make_motion(swarm["motion"], {k: swarm[k] for k in MOTION_OPTIONS if k in swarm})
    return args


def job_map_config(mapping: dict[str, Any], seed: int | None = None) -> MapConfig:
    """The ``MapConfig`` of a job's canonical ``[map]`` table, through the map's own option
    parser (``pipeline.config.config_from_options``), as sweeps map: no picture, no loops;
    every other option is ``swarmtopo map``'s default, the window cap ``max_windows``
    included (not a grid key: no map of the accuracy suite reaches it), and
    ``landmark_bands`` (absent or "auto": the bands the job's reader was fitted with)."""
    options = {name: mapping[name] for name in OPTIONS if name in mapping}
    return config_from_options(options, seed=seed, embed_dim=0, cycles=False)


# -- internals ----------------------------------------------------------------------------
def _scalar(table: dict, key: str, default, check, fail):
    if key not in table:
        return default
    try:
        return check(table[key])
    except _Bad as exc:
        fail(f"[sweep] {key} = {_toml(table[key])}", str(exc))


def _axis(table: dict, param: Param, fail) -> list[Any]:
    """The values of one grid key: the checked scalar, or each element of a list."""
    if param.name not in table:
        return [param.default]
    raw = table[param.name]
    if param.set_valued:  # a value or list of values is one set; a list of lists, a grid
        values = raw if isinstance(raw, list) and raw and all(isinstance(v, list) for v in raw) else [raw]
    else:
        values = raw if isinstance(raw, list) else [raw]
    if not values:
        fail(f"[{param.table}] {param.name} = []", "empty list; give at least one value")
    checked = []
    for value in values:
        try:
            checked.append(param.check(value))
        except _Bad as exc:
            fail(f"[{param.table}] {param.name} = {_toml(value)}", str(exc))
    return list(dict.fromkeys(checked))


class _InputFiles:
    """Input files of the grid: absolute path and SHA-256 of each, read and checked once."""

    def __init__(self, base_dir: Path, fail):
        self.base_dir, self.fail, self.seen = base_dir, fail, {}

    def resolve(self, where: str, written: str, load: Callable[[Path], Any]) -> tuple[str, str]:
        """(absolute path, SHA-256) of the file; ``load(path)`` must accept it (its
        SwarmtopoError becomes the message)."""
        if written not in self.seen:
            path = (self.base_dir / written).resolve()
            try:
                digest = hashlib.sha256(path.read_bytes()).hexdigest()
                load(path)
            except OSError as exc:
                self.fail(f"{where} = {_toml(written)}", f"cannot read {path} ({exc.strerror or exc})")
            except SwarmtopoError as exc:
                self.fail(f"{where} = {_toml(written)}", str(exc))
            self.seen[written] = (str(path), digest)
        return self.seen[written]


def _canonical(point: dict, inputs: _InputFiles, fail):
    """(canonical config, input files, keys used) of one grid point."""
    generator = point[("arena", "generator")]
    arena = {"generator": generator}
    for name in GENERATORS[generator]:
        arena[name] = list(point[("arena", name)]) if name == "shapes" else point[("arena", name)]
    files = []
    if generator == "file":
        if arena["path"] is None:
            fail("[arena] path", 'missing: generator = "file" needs the path of a GeoJSON arena')
        absolute, arena["path_sha256"] = inputs.resolve("[arena] path", arena["path"], read_arena)
        files.append(("arena.path", absolute))
    if generator == "changing":
        if arena["change"] == "none":
            del arena["change_time"]
        elif arena["change_time"] >= point[("swarm", "duration")]:
            fail(f"[arena] change_time = {_toml(arena['change_time'])}",
                 f"must be before the end of the log (duration = {point[('swarm', 'duration')]:g})")
    if generator == "annulus" and arena["r_inner"] >= arena["r_outer"]:
        fail(f"[arena] r_inner = {_toml(arena['r_inner'])}", f"must be smaller than r_outer = {arena['r_outer']:g}")

    swarm = {name: point[("swarm", name)] for name in ("agents", "duration", "static_fraction")}
    if swarm["static_fraction"] > 0:
        swarm["static_time"] = point[("swarm", "static_time")]
    if point[("swarm", "leash")] > 0:
        swarm["leash"] = point[("swarm", "leash")]
        swarm["leader_speed"] = point[("swarm", "leader_speed")]
    if point[("swarm", "motion")] != "cockroach":  # a cockroach job's config is as before walkers existed
        if point[("swarm", "leash")] > 0:
            fail(f"[swarm] motion = {_toml(point[('swarm', 'motion')])}", "a leader (leash > 0) steers the cockroach "
                                                                          "model only")
        swarm["motion"] = point[("swarm", "motion")]
        fields = MOTION_MODELS[swarm["motion"]].__dataclass_fields__
        swarm.update({name: point[("swarm", name)] for name, field in MOTION_OPTIONS.items()
                      if field in fields and point[("swarm", name)] is not None})

    mapping = {name: point[("map", name)]
               for name in ("metric", "hop_cost", "diffusion_time", "wall_follow_weight", "window_length",
                            "subsample", "landmarks",
                            "maxdim", "classifier")}
    if mapping["window_length"] != "none":
        mapping["window_step"] = point[("map", "window_step")]
    if mapping["window_length"] == "auto":
        mapping["window_encounters"] = point[("map", "window_encounters")]
    if mapping["window_length"] != "none":
        mapping["window_scales"] = list(point[("map", "window_scales")])
    if mapping["landmarks"] == "auto":
        mapping["max_landmarks"] = point[("map", "max_landmarks")]
    if mapping["classifier"] not in PRESETS:
        absolute, mapping["classifier_sha256"] = inputs.resolve("[map] classifier", mapping["classifier"],
                                                               load_classifier)
        files.append(("map.classifier", absolute))

    config = {"arena": arena, "swarm": swarm, "map": mapping}
    faults = faults_table({name: point[("faults", name)] for name in Faults.__dataclass_fields__})
    if faults:  # a job without faults has the config it had before faults existed
        config["faults"] = faults
    used = ({(table, key) for table, body in config.items() for key in body} | {("swarm", "leash")}  # 0: no leader
            | {("faults", name) for name in FAULT_LEVELS})  # 0: no such fault
    return config, tuple(files), used


def faults_table(values: dict[str, float]) -> dict[str, float]:
    """The canonical ``[faults]`` table of a job from ``Faults`` field values (missing:
    the defaults): its non-zero levels, with ``burst_length`` and ``duplicate_delay`` only
    when they shape outages or duplicates; empty without a fault."""
    values = {**Faults().to_json(), **values}
    table = {name: values[name] for name in FAULT_LEVELS if values[name]}
    for name, level in (("burst_length", "burst_lost"), ("duplicate_delay", "duplicated")):
        if values[level]:
            table[name] = values[name]
    return table


def _check_job(config: dict, document: dict, fail) -> None:
    """The job's own checks of its configuration, before any job runs: the simulator's
    (:func:`job_simulation_args`) and the map's (:func:`job_map_config`); a failure names
    the table's keys given in the file, with this job's values."""
    checks = {"swarm": lambda: check_parameters(**job_simulation_args(config["swarm"])),
              "map": lambda: job_map_config(config["map"]).validate(),
              "faults": lambda: Faults(**config.get("faults", {}))}
    for table, check in checks.items():
        try:
            check()
        except SwarmtopoError as exc:
            body = config[table]
            given = ", ".join(f"{key} = {_toml(body[key])}" for key in document.get(table, {}) if key in body)
            fail(f"[{table}] {given}".rstrip(), exc.reason if isinstance(exc, InputError) else str(exc))


def _unused_reason(table: str, key: str, document: dict) -> str:
    if table == "arena":
        generators = document["arena"].get("generator", "random")
        generators = generators if isinstance(generators, list) else [generators]
        users = [g for g, keys in GENERATORS.items() if key in keys]
        return (f"not used by generator {', '.join(repr(g) for g in generators)} "
                f"(only by {', '.join(repr(g) for g in users)})")
    if key == "static_time":
        return "not used: static_fraction is 0 (no agent stops for good)"
    if key == "leader_speed":
        return "not used: leash is 0 (no leader)"
    if key in MOTION_OPTIONS:
        users = [name for name, model in MOTION_MODELS.items()
                 if MOTION_OPTIONS[key] in getattr(model, "__dataclass_fields__", {}) and name != "cockroach"]
        return f"not used by this motion model (only by {', '.join(repr(u) for u in users)})"
    if key == "burst_length":
        return "not used: burst_lost is 0 (no outages)"
    if key == "duplicate_delay":
        return "not used: duplicated is 0 (no duplicated report)"
    if key in ("window_step", "window_scales"):
        return 'not used: window_length is "none" (the whole log at once)'
    if key == "window_encounters":
        return 'not used: window_length is not "auto" (a length in seconds, or "none")'
    return 'not used: landmarks is a number (max_landmarks caps landmarks = "auto")'


def _toml(value) -> str:
    """A value as it would be written in TOML (for messages)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + "}"
    return str(value)
