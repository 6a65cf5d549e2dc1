"""Command line: thin wrappers that parse, call the package, and write files.

Every user error (bad file, bad option value) is printed as one line on stderr with
exit code 1; usage errors exit 2 (Typer); only bugs produce a traceback.
"""

from __future__ import annotations

import math
import re
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Optional

import numpy as np
import typer
from typer.exceptions import TyperException
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

from .errors import SwarmtopoError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_show_locals=False,
    help="Topological maps of unknown arenas from the encounters of a localization-free swarm.",
)
out = Console()
err = Console(stderr=True)
MAX_LANDMARKS_OPTION = 2000
"""Most landmarks --landmarks may ask for per window (800 took about 1 GB and 80 s per window on a trace)."""
DEMO_AGENTS, DEMO_SECONDS = 200, 30.0
"""The demo's swarm: the accuracy benchmark's smallest budget."""
DEMO_WRITER = "swarmtopo demo"
"""``written_by`` in the meta.json of the demo's log: the only log demo may replace."""
MAX_SCALE = 1000.0
"""Largest --scale: a 500 m square random arena, beyond what the wall grid accepts at r_d = 30 mm."""
MIN_WINDOW_SCALE = 0.05
"""Least --window-scales multiplier: windows of one encounter per agent at the automatic length."""
VERBOSE_HELP = "Also report each stage's details and timings on stderr (in pipes too)."


OVERWRITE_HELP = "Replace the log already in --out (its log files are replaced or removed)."


def _write_log_folder(log, out_dir: Path, quiet: bool, overwrite: bool, protect=(), **options) -> list[Path]:
    """``io.write_log`` into a folder without a log, or over one with ``overwrite``,
    saying which outdated log files of the folder it removed; never over a file of
    ``protect`` (the trace an ingest reads)."""
    from .io.logs import log_files, refuse_protected, write_log

    refuse_protected(out_dir, protect)  # before --overwrite could be suggested
    before = set(log_files(out_dir))
    if before and not overwrite:
        names = ", ".join(sorted(p.name for p in before))
        raise SwarmtopoError(f"{out_dir}: already holds a log ({names}); pass --overwrite to replace it, "
                             f"or choose another --out")
    written = write_log(log, out_dir, **options)
    if not quiet:
        for path in sorted(before - set(written)):
            out.print(f"removed the outdated {path}", markup=False, highlight=False, soft_wrap=True)
    return written


def _check_verbosity(quiet: bool, verbose: bool) -> None:
    if quiet and verbose:
        raise typer.BadParameter("--quiet and --verbose exclude each other")


def _detail(message: str) -> None:
    """One --verbose line on stderr."""
    err.print(message, markup=False, highlight=False, soft_wrap=True)


def _positive_option(value: float | None) -> float | None:
    """A finite number > 0 (None passes: the option was not given)."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise typer.BadParameter(f"{value:g} is not a finite number > 0")
    return value


def _finite_option(value: float | None) -> float | None:
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"{value:g} is not a finite number")
    return value


def _agents_option(value: int | None) -> int | None:
    """A swarm size of at most ``sim.MAX_AGENTS`` (None passes)."""
    from decimal import Decimal

    from .sim import MAX_AGENTS

    if value is not None and value > MAX_AGENTS:
        shown = f"{value:,}" if value < 10**15 else f"{Decimal(value):.3g}"
        raise typer.BadParameter(f"{shown} is more than {MAX_AGENTS:,} agents")
    return value


def _check_option(hint: str, check, *args) -> None:
    """Run a simulator check; its InputError becomes a usage error naming ``hint``."""
    from .errors import InputError

    try:
        check(*args)
    except InputError as exc:
        got = "" if exc.value is None else f" (got {exc.value:g})"
        raise typer.BadParameter(exc.reason + got, param_hint=hint) from None


def _accuracy_option(value: float | None) -> float | None:
    """A probability strictly between 0 and 1 (None passes)."""
    if value is not None and not 0 < value < 1:
        raise typer.BadParameter(f"{value:g} is not strictly between 0 and 1")
    return value


def _fmt_option(value: str) -> str:
    if value not in ("csv", "parquet"):
        raise typer.BadParameter(f"{value!r} is not one of 'csv', 'parquet'")
    return value


@contextmanager
def _progress(description: str, quiet: bool):
    """A Rich progress bar on a terminal; nothing in pipes, CI or with --quiet."""
    if quiet or not err.is_terminal:
        yield lambda fraction: None
        return
    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                  TimeElapsedColumn(), TimeRemainingColumn(), console=err, transient=True) as bar:
        task = bar.add_task(description, total=1.0)
        yield lambda fraction: bar.update(task, completed=fraction)


@app.command(epilog="Example: swarmtopo simulate --holes 2 --agents 200 --duration 30 --seed 1 --out runs/two-holes --truth")
def simulate(
    out_dir: Path = typer.Option(..., "--out", help="Folder to write the log into (created)."),
    arena: Optional[Path] = typer.Option(None, "--arena", help="Arena as GeoJSON Polygon/MultiPolygon in mm."),
    holes: Optional[int] = typer.Option(None, "--holes", min=0,
                                        help="Square holes of a random square arena (default 1; not with --arena)."),
    scale: float = typer.Option(1.0, "--scale", min=0.05, max=MAX_SCALE, callback=_finite_option,
                                help="Scale factor of every length of the arena (random or --arena)."),
    agents: int = typer.Option(200, "--agents", min=1, callback=_agents_option,
                               help="Swarm size N (at most 100,000; agents x duration / dt at most 1e10)."),
    duration: float = typer.Option(20.0, "--duration", min=0.0, callback=_finite_option, help="Seconds of data."),
    seed: int = typer.Option(0, "--seed", min=0, help="Random seed (same seed, same bytes)."),
    static_fraction: float = typer.Option(0.0, "--static-fraction", min=0.0, max=1.0,
                                          help="Hybrid network: fraction of agents stopped for good."),
    static_time: float = typer.Option(0.0, "--static-time", min=0.0, callback=_finite_option,
                                      help="When the static agents stop (s)."),
    dt: float = typer.Option(0.1, "--dt", callback=_positive_option, help="Time step (s); v_c*dt must stay <= r_d/4."),
    rd: float = typer.Option(30.0, "--rd", callback=_positive_option, help="Detection radius r_d (mm)."),
    truth: bool = typer.Option(False, "--truth", help="Also write truth.<fmt>: true positions per event."),
    trajectories: Optional[float] = typer.Option(None, "--trajectories", callback=_positive_option,
                                                 help="Also write positions every EVERY s."),
    fmt: str = typer.Option("csv", "--format", callback=_fmt_option, help="csv or parquet."),
    overwrite: bool = typer.Option(False, "--overwrite", help=OVERWRITE_HELP),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar, no summary."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Simulate a swarm in an arena and write its encounter log folder."""
    import time

    from .arena import random_arena
    from .io.logs import read_arena
    from .sim import (MotionParams, SensingParams, check_run_size, check_static_time, check_time_step,
                      simulate as run)

    _check_verbosity(quiet, verbose)
    if arena is not None and holes is not None:
        raise typer.BadParameter("an --arena file has its own holes; drop --holes or --arena", param_hint="--holes")
    if static_time > 0 and static_fraction == 0:
        raise typer.BadParameter("the static agents' stop time needs --static-fraction > 0", param_hint="--static-time")
    _check_option("--dt", check_time_step, dt, MotionParams(), SensingParams(r_d=rd))  # the motion simulate runs with
    _check_option("--agents, --duration, --dt", check_run_size, agents, duration, dt)
    _check_option("--static-time", check_static_time, static_fraction, static_time, duration, dt)

    if arena:  # scaled like a sweep's file arena
        world = read_arena(arena) if scale == 1.0 else read_arena(arena).scaled(scale)
    else:  # the arena draws from its own stream, spawned from the seed; the swarm uses the seed
        world = random_arena(1 if holes is None else holes, scale=scale,
                             rng=np.random.SeedSequence(seed).spawn(1)[0])
    for passage in world.narrow_passages(rd):
        _warn(f"{passage}, less than r_d = {rd:g} mm: the swarm may not tell them apart, and the map may miss "
              f"that hole", quiet)
    if verbose:
        _detail(f"arena: {world.betti[0]} region(s), {world.betti[1]} hole(s), area {world.area:.0f} mm^2; "
                f"{agents} agents, {duration:g} s, dt {dt:g} s, r_d {rd:g} mm, seed {seed}")
    start = time.perf_counter()
    with _progress("simulating", quiet) as tick:
        sim = run(world, agents, duration, dt=dt, sensing=SensingParams(r_d=rd), rng=seed,
                  static_fraction=static_fraction, static_time=static_time, truth=truth,
                  trajectory_every=trajectories, progress=tick)
    if verbose:
        _detail(f"simulated in {time.perf_counter() - start:.2f} s: {sim.log.n_events} encounters, "
                f"{len(sim.log.status_t)} status changes")
    written = _write_log_folder(sim.log, out_dir, quiet, overwrite, fmt=fmt, truth=sim.truth,
                                trajectories=sim.trajectories, arena=world)
    if not quiet:
        b0, b1 = world.betti
        out.print(f"{sim.log.n_events} encounters of {agents} agents over {sim.log.meta['duration']:g} s "
                  f"in an arena with {b0} region(s) and {b1} hole(s)")
        out.print(f"wrote {', '.join(str(p) for p in written)}")


@app.command(epilog="Example: swarmtopo ingest primaryschool.csv --format sociopatterns --out runs/school "
                    "&& swarmtopo map runs/school")
def ingest(
    trace: Path = typer.Argument(..., help="Proximity trace file."),
    fmt: str = typer.Option(..., "--format",
                            help="csv | parquet | sociopatterns (t i j Ci Cj) | one (ONE CONN events)."),
    out_dir: Path = typer.Option(..., "--out", help="Log folder to write (created); swarmtopo map reads it."),
    skip_bad: bool = typer.Option(False, "--skip-bad",
                                  help="Skip malformed lines and count them (default: stop at the first)."),
    time_column: Optional[str] = typer.Option(None, "--time-column",
                                              help="csv/parquet: column of encounter times (s) (default t)."),
    a_column: Optional[str] = typer.Option(None, "--a-column", help="csv/parquet: column of the first agent ID "
                                                                   "(default a)."),
    b_column: Optional[str] = typer.Option(None, "--b-column", help="csv/parquet: column of the second agent ID "
                                                                   "(default b)."),
    window: Optional[float] = typer.Option(None, "--contact-window", callback=_positive_option,
                                           help="sociopatterns: seconds of one contact window (a line at t covers "
                                                "(t-w, t]; default 20)."),
    log_fmt: str = typer.Option("csv", "--log-format", callback=_fmt_option, help="Log folder tables: csv or parquet."),
    overwrite: bool = typer.Option(False, "--overwrite", help=OVERWRITE_HELP),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Convert a proximity trace into an encounter log folder (see docs/real-data.md)."""
    from .io.traces import FORMATS, SOCIOPATTERNS_WINDOW, ingest as read_trace
    from .log import exact_time

    _check_verbosity(quiet, verbose)
    if fmt not in FORMATS:
        raise typer.BadParameter(f"{fmt!r} is not one of {', '.join(FORMATS)}", param_hint="--format")
    given = {"--time-column": time_column, "--a-column": a_column, "--b-column": b_column, "--contact-window": window}
    for option, value in given.items():
        formats = ("sociopatterns",) if option == "--contact-window" else ("csv", "parquet")
        if value is not None and fmt not in formats:
            raise typer.BadParameter(f"applies to --format {' or '.join(formats)} only", param_hint=option)
    columns = {"time_column": time_column or "t", "a_column": a_column or "a", "b_column": b_column or "b"}
    if len(set(columns.values())) < 3:
        raise typer.BadParameter(f"name three different columns, not {', '.join(map(repr, columns.values()))}",
                                 param_hint="--time-column, --a-column, --b-column")
    log, report = read_trace(trace, fmt, skip_bad=skip_bad, **columns,
                             window=SOCIOPATTERNS_WINDOW if window is None else window)
    written = _write_log_folder(log, out_dir, quiet, overwrite, fmt=log_fmt, protect=(trace,))
    if verbose:
        _detail(f"ingest report: {report.as_meta()}")
    if not quiet:
        out.print(f"{report.lines} lines of {trace}: {log.n_events} encounters of {log.n_agents} agents "
                  f"from t = {exact_time(log.t[0])} to {exact_time(log.t[-1])} s", markup=False, highlight=False)
        if skip_bad:
            out.print(f"skipped {report.skipped} malformed line(s)", markup=False, highlight=False)
            for message in report.examples:
                out.print(f"  {message}", markup=False, highlight=False, soft_wrap=True)
        notes = ", ".join(f"{k.replace('_', ' ')}: {v}" for k, v in report.counts.items() if v)
        if notes:
            out.print(notes, markup=False, highlight=False)
        out.print(f"wrote {', '.join(str(p) for p in written)}", markup=False, highlight=False)


def _parse_window(text: Optional[str]):
    if text is None:
        return None
    parts = text.split(":")
    if len(parts) != 2:
        raise typer.BadParameter(f"{text!r} is not T0:T1 (either side may be empty)")
    try:
        ends = [float(p) if p.strip() else None for p in parts]
    except ValueError:
        raise typer.BadParameter(f"{text!r} is not T0:T1 with numbers in seconds") from None
    if any(e is not None and math.isnan(e) for e in ends):
        raise typer.BadParameter(f"{text!r}: a window end cannot be NaN")
    if ends[0] == math.inf or ends[1] == -math.inf:
        raise typer.BadParameter(f"{text!r}: a window cannot start at +inf or end at -inf (it would hold nothing)")
    return tuple(None if e is None or math.isinf(e) else e for e in ends)


def _hop_cost_option(value: Optional[float]) -> Optional[float]:
    """A --hop-cost value: seconds in [0, MAX_HOP_COST]."""
    from .pipeline.map import MAX_HOP_COST

    if value is not None and not (math.isfinite(value) and value <= MAX_HOP_COST):
        raise typer.BadParameter(f"{value:g} is not a number of seconds in [0, {MAX_HOP_COST:g}]")
    return value


def _parse_wall_follow_weight(text: Optional[str]):
    """A --wall-follow-weight value: 'none' or a number >= 0."""
    if text is None or text == "none":
        return text
    try:
        value = float(text)
    except ValueError:
        raise typer.BadParameter(f"{text!r} is not a number or 'none'") from None
    from .pipeline.map import MAX_WALL_FOLLOW_WEIGHT

    if not (math.isfinite(value) and 0 <= value <= MAX_WALL_FOLLOW_WEIGHT):
        raise typer.BadParameter(f"{text!r} must be a number in [0, {MAX_WALL_FOLLOW_WEIGHT:g}]")
    return text


def _parse_seconds(text: Optional[str]):
    """A --window-length or --diffusion-time value: 'auto', 'none' or seconds > 0."""
    if text is None or text in ("auto", "none"):
        return text
    try:
        value = float(text)
    except ValueError:
        raise typer.BadParameter(f"{text!r} is not a number of seconds, 'auto' or 'none'") from None
    if not (math.isfinite(value) and value > 0):
        raise typer.BadParameter(f"{text!r} must be a positive number of seconds")
    return text


def _distinct_numbers(text: str, example: str) -> tuple[float, ...]:
    """Comma-separated distinct numbers (a usage error otherwise)."""
    try:
        numbers = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise typer.BadParameter(f"{text!r} is not a comma-separated list of numbers (e.g. {example})") from None
    if len(set(numbers)) < len(numbers):
        raise typer.BadParameter(f"{text!r}: the numbers must be distinct")
    return numbers


def _parse_scales(text: Optional[str]):
    """A --window-scales value: comma-separated distinct positive numbers."""
    if text is None:
        return None
    scales = _distinct_numbers(text, "0.75,1,1.25")
    if not all(math.isfinite(x) and x >= MIN_WINDOW_SCALE for x in scales):
        raise typer.BadParameter(f"{text!r}: the scales must be distinct positive numbers, each at least "
                                 f"{MIN_WINDOW_SCALE:g}")
    return scales


def _parse_bands(text: Optional[str]):
    """A --landmark-bands value: comma-separated distinct numbers in (0, 1]."""
    if text is None:
        return None
    bands = _distinct_numbers(text, "1,0.5")
    if not all(0 < x <= 1 for x in bands):
        raise typer.BadParameter(f"{text!r}: the bands must be distinct numbers in (0, 1]")
    return bands


MAP_CONFIG_OPTIONS = ("--hop-cost", "--diffusion-time", "--wall-follow-weight", "--window-length",
                      "--window-scales", "--landmark-bands", "--max-windows")
"""map's options whose MapConfig field (``--max-windows``: ``max_windows``) a validation message may name."""


def in_option_terms(message: str) -> str:
    """A MapConfig validation message in map's terms: fields named as their options
    (MAP_CONFIG_OPTIONS), Python's None as the options' 'none'."""
    for option in MAP_CONFIG_OPTIONS:
        message = re.sub(rf"\b{option[2:].replace('-', '_')}\b", option, message)
    return re.sub(r"\bNone\b", "'none'", message)


def _parse_max_windows(text: Optional[str]):
    """A --max-windows value: 'none' (every window) or a whole number >= 1."""
    if text is None or text.strip().lower() == "none":
        return None if text is None else "none"
    try:
        whole = int(text) >= 1
    except ValueError:
        whole = False
    if not whole:
        raise typer.BadParameter(f"{text!r} is not a whole number >= 1 or 'none'")
    return text


@app.command("map", epilog="Example: swarmtopo map runs/two-holes --out runs/two-holes/map --metric hybrid --landmarks 300")
def map_command(
    log_dir: Path = typer.Argument(..., help="Log folder: events.csv|parquet, optional status, meta.json."),
    out_dir: Optional[Path] = typer.Option(None, "--out", help="Output folder (default: LOG_DIR/map)."),
    metric: str = typer.Option("hybrid", "--metric", help="plain | contracted | hybrid (paper's metrics)."),
    subsample: str = typer.Option("maxmin", "--subsample", help="maxmin | knn | probabilistic."),
    landmarks: Optional[int] = typer.Option(
        None, "--landmarks", min=3, max=MAX_LANDMARKS_OPTION,
        help="Number of landmarks L per region and window (default: the fewest that meet the sampling "
             f"guarantee, at most 400; at most {MAX_LANDMARKS_OPTION}: persistence time grows about as L^3)."),
    window: Optional[str] = typer.Option(None, "--window", callback=_parse_window,
                                         help="Time window T0:T1 in seconds (either end may be empty)."),
    maxdim: int = typer.Option(1, "--maxdim", min=1, max=2, help="Highest homology dimension (1 or 2)."),
    seed: int = typer.Option(0, "--seed", min=0, help="Seed of landmark start and MDS."),
    hop_cost: Optional[float] = typer.Option(
        None, "--hop-cost", min=0.0, callback=_hop_cost_option,
        help="Per-hop cost h in seconds on the encounter graph; 0 = the paper's metric "
             "(default: r_d / v_c from meta.json, else from the data)."),
    diffusion_time: Optional[str] = typer.Option(
        None, "--diffusion-time", callback=_parse_seconds,
        help="tau in seconds: a gap of w s between an agent's encounters weighs tau (sqrt(1 + 2 w / tau) - 1), "
             "about a random walk's displacement; 'none' = the paper's weight w; 'auto' (default) = half the mean "
             "time between an agent's encounters."),
    wall_follow_weight: Optional[str] = typer.Option(
        None, "--wall-follow-weight", callback=_parse_wall_follow_weight,
        help="Seconds charged per second an agent spent wall following (status WF) within a gap, outside the "
             "diffusive weights: along a wall an agent walks, it does not diffuse (default 2); 'none' = like any "
             "other time (the paper)."),
    window_length: Optional[str] = typer.Option(
        None, "--window-length", callback=_parse_seconds,
        help="Seconds of the time windows whose maps are pooled; 'none' maps the whole log at once; 'auto' "
             "(default) holds about 20 encounters per agent (20 x the mean time between an agent's encounters)."),
    window_scales: Optional[str] = typer.Option(
        None, "--window-scales", callback=_parse_scales,
        help="Comma-separated multipliers of the window length, each at least 0.05: the windows of every such "
             "length are pooled together (default: 0.75,1,1.25; 1 maps one length, about three times faster: "
             "docs/accuracy.md)."),
    landmark_bands: Optional[str] = typer.Option(
        None, "--landmark-bands", callback=_parse_bands,
        help="Comma-separated shares of each window's length: every window is mapped once per share B, its "
             "landmarks drawn from the window's middle B x its length, and all are pooled (1: the whole window "
             "once; unset: the bands the classifier reading the map was fitted with, 1,0.5 for the default "
             "classifier and 1 for the others: docs/accuracy.md)."),
    max_windows: Optional[str] = typer.Option(
        None, "--max-windows", callback=_parse_max_windows,
        help="Cap of the time windows mapped, all lengths together, at least one per length (default 48, more "
             "than any benchmark map pools): a longer log maps an evenly spaced share of each length's windows, so "
             "its time stops growing with its length; 'none' maps every window."),
    agreement: str = typer.Option(
        "auto", "--agreement",
        help="When to compute each region's cross-window cycle agreement A_1..A_5 (map.json regions[].agreement: "
             "is each of the longest loops the same loop in overlapping windows?): auto (default) where a gated "
             "classifier (--classifier gated) needs it, always for every region, to inspect."),
    classifier: Optional[str] = typer.Option(
        None, "--classifier",
        help="Betti classifier: default (tuned on the accuracy benchmark), trace (the same tuned on its logs read "
             "as contact traces), gated (whole-window landmarks, a score threshold gated by cross-window cycle "
             "agreement: better than the default where agents follow walls for tens of seconds, docs/accuracy.md), "
             "paper-form (the paper's form trained our way), paper (the paper's Theta*), or a JSON file. Unset: "
             "default for a log with status changes, trace for one without."),
    paper: bool = typer.Option(
        False, "--paper",
        help="Run exactly the paper's pipeline: no per-hop cost, no diffusive weights, wall following like any "
             "time, the whole log, the paper's Theta*."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Map an encounter log folder: Betti numbers with confidence, diagrams and pictures."""
    from .readers.paper import load_classifier
    from .io.logs import read_log
    from .log import exact_time
    from .pipeline.map import MapConfig, max_windows_option, seconds_option, wall_follow_option

    _check_verbosity(quiet, verbose)
    if paper:
        given = [name for name, value in (("--hop-cost", hop_cost), ("--diffusion-time", diffusion_time),
                                          ("--wall-follow-weight", wall_follow_weight),
                                          ("--window-length", window_length), ("--window-scales", window_scales),
                                          ("--landmark-bands", landmark_bands),
                                          ("--max-windows", max_windows), ("--classifier", classifier))
                 if value is not None]
        if given:
            raise typer.BadParameter(f"--paper fixes {', '.join(given)}; drop one or the other")
        hop_cost, diffusion_time, wall_follow_weight, window_length, classifier = 0.0, "none", "none", "none", "paper"
        window_scales, landmark_bands = (1.0,), (1.0,)
    out_dir = out_dir or log_dir / "map"
    if out_dir.exists() and not out_dir.is_dir():
        raise SwarmtopoError(f"{out_dir}: --out is a file; give a folder for the map's outputs")
    try:
        config = MapConfig(metric=metric, subsample=subsample, landmarks=landmarks, window=window, maxdim=maxdim,
                           seed=seed, hop_cost=hop_cost, diffusion_time=seconds_option(diffusion_time),
                           wall_follow_weight=wall_follow_option(wall_follow_weight),
                           window_length=seconds_option(window_length),
                           window_scales=window_scales or MapConfig.window_scales,
                           landmark_bands=landmark_bands or MapConfig.landmark_bands,
                           max_windows=max_windows_option(max_windows), agreement=agreement).validate()
    except SwarmtopoError as exc:  # options that do not go together: a usage error
        raise typer.BadParameter(in_option_terms(str(exc))) from None
    model = load_classifier(classifier) if classifier else None  # None: the shipped one for the log
    log = read_log(log_dir)
    if verbose:
        _detail(f"log {log_dir}: {log.n_events} encounters of {log.n_agents} agents from t = {exact_time(log.t[0])} "
                f"to {exact_time(log.t[-1])} s")
    tmap, written = _run_map(log, config, log_dir, out_dir, quiet, verbose, classifier=model)
    if not quiet:
        _print_verdict(tmap, truth=None)
        out.print(f"wrote {', '.join(str(p) for p in written)}")


@app.command(epilog="Example: swarmtopo demo --out swarmtopo-demo")
def demo(
    out_dir: Path = typer.Option(Path("swarmtopo-demo"), "--out",
                                 help="Output folder (a log already in its log/ is replaced only if demo wrote it)."),
    seed: int = typer.Option(0, "--seed", min=0, help="Random seed."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Simulate the paper's Fig. "encmds" arena and map it.

    A 500 mm square with one hole, 200 agents, 30 s of data (the accuracy benchmark's
    smallest budget; the paper's figure has 20 s): prints the recovered
    Betti numbers beside the true ones and where the figures were written.
    """
    from .arena import default_arena
    from .io.logs import log_files, write_log
    from .pipeline.map import MapConfig
    from .sim import simulate as run

    _check_verbosity(quiet, verbose)
    log_dir = out_dir / "log"
    foreign = [] if _demo_wrote(log_dir) else log_files(log_dir)
    if foreign:
        raise SwarmtopoError(f"{log_dir}: already holds a log that swarmtopo demo did not write "
                             f"({', '.join(p.name for p in foreign)}); choose another --out")
    world = default_arena()
    with _progress("simulating", quiet) as tick:
        sim = run(world, DEMO_AGENTS, DEMO_SECONDS, rng=seed, truth=True, trajectory_every=0.5, progress=tick)
    sim.log.meta["written_by"] = DEMO_WRITER
    write_log(sim.log, log_dir, truth=sim.truth, trajectories=sim.trajectories, arena=world)
    if verbose:
        _detail(f"simulated: {sim.log.n_events} encounters of {DEMO_AGENTS} agents over {DEMO_SECONDS:g} s; "
                f"log: {log_dir}")
    tmap, written = _run_map(sim.log, MapConfig(seed=seed), log_dir, out_dir, quiet, verbose,
                             ground_truth=(world, sim.truth, sim.trajectories))
    if not quiet:
        _print_verdict(tmap, truth=world.betti)
        out.print(f"log: {log_dir}")
        out.print(f"wrote {', '.join(str(p) for p in written)}")


def _demo_wrote(log_dir: Path) -> bool:
    """Whether ``log_dir``'s meta.json says ``swarmtopo demo`` wrote the log (so it may replace it)."""
    from .io.logs import read_json

    meta = log_dir / "meta.json"
    try:
        doc = read_json(meta) if meta.is_file() else None
    except SwarmtopoError:  # unreadable: not provably the demo's
        return False
    return isinstance(doc, dict) and doc.get("written_by") == DEMO_WRITER


@app.command(epilog="Example: swarmtopo sweep examples/sweep-small.toml --store results.duckdb --workers 2  "
                    "(run it again after a crash or Ctrl-C: finished jobs are skipped)")
def sweep(
    config: Path = typer.Argument(..., help="Sweep grid: a TOML file with sweep, arena, swarm and map tables."),
    store: Path = typer.Option(..., "--store", help="DuckDB result store (created; one row per job in table jobs)."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler",
                                            help="Address of an existing Dask scheduler, e.g. tcp://10.0.0.5:8786."),
    workers: Optional[int] = typer.Option(None, "--workers", min=1,
                                          help="Worker processes of the local cluster (default: all cores)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Run every simulate-and-map job of a grid on Dask and store one row per job.

    Jobs already in the store are skipped, so a sweep can be resumed or grown.  A job
    that cannot be mapped (too little data) is a stored row with its error; if every job
    of the grid is, the sweep exits 1.
    """
    from .experiments.grid import read_sweep
    from .experiments.sweep import run_sweep

    _check_verbosity(quiet, verbose)
    grid = read_sweep(config)
    if verbose:
        _detail(f"sweep {grid.name!r} from {config}: {len(grid.jobs)} jobs ({grid.replicates} replicate(s), "
                f"salt {grid.salt!r})")
    try:
        with _sweep_progress(quiet, verbose) as tick:
            summary = run_sweep(grid.jobs, store, scheduler=scheduler, workers=workers, progress=tick)
    except KeyboardInterrupt:
        if not quiet:
            err.print(f"interrupted: finished jobs are saved in {store}; run the same command again to run the rest",
                      markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(130) from None
    # every job failed (the grid, not the data, is likely wrong): only then read the rows run before
    errors = _stored_errors(store, grid.jobs) if summary.failed == summary.run else {}
    if summary.total and sum(errors.values()) == summary.total:
        message = max(errors.items(), key=lambda item: item[1])[0]
        err.print(f"error: sweep {grid.name!r}: all {summary.total} jobs failed ({message}); their rows are in "
                  f"{store}", markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(1)
    if quiet:
        return
    if summary.run == 0:
        out.print(f"sweep {grid.name!r}: all {summary.total} jobs already in {store}; nothing to run",
                  markup=False, highlight=False)
        return
    out.print(f"sweep {grid.name!r}: {summary.total} jobs: {summary.run} run ({summary.failed} failed), "
              f"{summary.skipped} already in the store", markup=False, highlight=False)
    out.print(f"{summary.run} jobs in {summary.seconds:.1f} s on {summary.workers} worker(s): "
              f"{summary.jobs_per_minute:.1f} jobs/minute", markup=False, highlight=False)
    for message, count in sorted(summary.errors.items(), key=lambda item: -item[1])[:3]:
        out.print(f"failed {count}x: {message}", markup=False, highlight=False, soft_wrap=True)
    out.print(f"results: {store} (table jobs)", markup=False, highlight=False)


def _stored_errors(store: Path, jobs) -> dict[str, int]:
    """Error message -> number of ``jobs`` stored with it (those run now and those run before)."""
    from collections import Counter

    from .experiments.store import read_jobs

    keys = {job.key for job in jobs}
    return dict(Counter(row["error"] for row in read_jobs(store, columns=("key", "error"))
                        if row["key"] in keys and row["error"] is not None))


@app.command(epilog="Example: swarmtopo reproduce encmds --out reproduction/encmds --runs 5  "
                    "(clust runs its sweeps on Dask: --workers N or --scheduler ADDRESS)")
def reproduce(
    name: str = typer.Argument(..., help="Experiment: enc | encmds | encimpr | land2 | clust."),
    out_dir: Optional[Path] = typer.Option(None, "--out", help="Output folder (default: reproduction/NAME)."),
    runs: Optional[int] = typer.Option(None, "--runs", min=1,
                                       help="Environments or repetitions, scaled down for a quick look "
                                            "(default: the documented full size)."),
    workers: Optional[int] = typer.Option(None, "--workers", min=1, help="clust: local Dask worker processes."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="clust: address of an existing Dask scheduler."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Reproduce one of the paper's experiments: PNG figures, NAME.csv (one row per run),
    NAME.md (summary table) and NAME.json (summary and settings) in the output folder."""
    from .experiments.reproduce import REPRODUCTIONS, reproduce as run

    _check_verbosity(quiet, verbose)
    if name not in REPRODUCTIONS:
        raise typer.BadParameter(f"{name!r} is not one of {', '.join(REPRODUCTIONS)}", param_hint="NAME")
    if name != "clust" and (workers is not None or scheduler is not None):
        raise typer.BadParameter("--workers and --scheduler apply to clust only (the others run in this process)")
    out_dir = out_dir or Path("reproduction") / name
    options = {"workers": workers, "scheduler": scheduler} if name == "clust" else {}
    with _sweep_progress(quiet, verbose, label=name) as tick:
        result = run(name, out_dir, runs=runs, progress=tick, **options)
    if not quiet:
        out.print(result.table_markdown, markup=False, highlight=False)
        written = [*result.figures, result.table, out_dir / f"{name}.md", out_dir / f"{name}.json"]
        out.print(f"wrote {', '.join(str(p) for p in written)}", markup=False, highlight=False)


@contextmanager
def _sweep_progress(quiet: bool, verbose: bool = False, label: str = "sweep"):
    """progress(done, total, failed): a Rich bar on a terminal; with --verbose a line per
    finished job instead (in pipes too); nothing otherwise."""
    if quiet or (not verbose and not err.is_terminal):
        yield lambda done, total, failed: None
        return
    if verbose:
        def line(done, total, failed):
            if done:
                err.print(f"{done}/{total} jobs done ({failed} failed)", markup=False, highlight=False)
        yield line
        return
    with Progress(TextColumn(label), BarColumn(), TextColumn("{task.completed}/{task.total} jobs"),
                  TextColumn("{task.fields[failed]} failed"), TimeElapsedColumn(), TimeRemainingColumn(),
                  console=err, transient=True) as bar:
        task = bar.add_task(label, total=None, failed=0)
        yield lambda done, total, failed: bar.update(task, completed=done, total=total, failed=failed)


bench_app = typer.Typer(no_args_is_help=True, help="Benchmarks that measure swarmtopo's answers.")
app.add_typer(bench_app, name="bench")


@bench_app.command("accuracy", epilog="Example: swarmtopo bench accuracy --quick --store accuracy.duckdb --workers 2  "
                                      "(run it again after Ctrl-C: finished maps are kept)")
def bench_accuracy(
    quick: bool = typer.Option(False, "--quick", help="10 reporting cases per cell instead of 30, no planning grid (minutes, not an hour)."),
    store: Path = typer.Option(Path("accuracy.duckdb"), "--store", help="DuckDB result store (resumable)."),
    out_dir: Path = typer.Option(Path("accuracy"), "--out", help="Folder for accuracy.md, accuracy.json, plan.json."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Address of an existing Dask scheduler."),
    workers: Optional[int] = typer.Option(None, "--workers", min=1,
                                          help="Worker processes of the local cluster (default: all cores)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Exact-match accuracy of (beta_0, beta_1) on the frozen suite of simulated arenas.

    Maps every reporting case (0-3 holes x three swarm budgets, and two rooms) with the
    default pipeline and the paper's, from log folders stripped of ground truth, on
    Dask; prints the table with Wilson 95 % intervals and the confidence's reliability.
    The full run also maps the planning grid (agents and duration varied apart) and fits
    plan.json on both; --quick fits it on its reporting maps without the swarm-size terms.
    """
    import shlex
    import time

    from .experiments.accuracy import PLANNING_PER_CELL, markdown, run_benchmark
    from .io.logs import make_folder, write_json
    from .experiments.plan import fit_plan

    _check_verbosity(quiet, verbose)
    make_folder(out_dir)  # before the hour of maps, not after
    command = "swarmtopo " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    start = time.perf_counter()
    try:
        with _sweep_progress(quiet, verbose, label="accuracy") as tick:
            summary = run_benchmark(store, quick=quick, scheduler=scheduler, workers=workers, progress=tick,
                                    planning_per_cell=0 if quick else PLANNING_PER_CELL)
    except KeyboardInterrupt:
        if not quiet:
            err.print(f"interrupted: finished maps are saved in {store}; run the same command again to run the rest",
                      markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(130) from None
    summary["wall_seconds"] = time.perf_counter() - start
    text = markdown(summary, command)
    written = [write_json({k: v for k, v in summary.items()}, out_dir / "accuracy.json")]
    (out_dir / "accuracy.md").write_text(text, encoding="utf-8")
    written.append(out_dir / "accuracy.md")
    try:
        # ln N and ln N ln T are only told apart from ln T by the planning grid (the suite's budgets raise N and T together)
        written.append(write_json(fit_plan(summary["records"] + summary["planning"], source=command,
                                           swarm_terms=2 if summary["planning"] else 0).to_json(), out_dir / "plan.json"))
    except SwarmtopoError as exc:
        _warn(f"no plan.json: {exc}", quiet)
    if not quiet:
        out.print(text, markup=False, highlight=False, soft_wrap=True)
        out.print(f"wrote {', '.join(str(p) for p in written)}", markup=False, highlight=False, soft_wrap=True)


def _plan_input_option(value: str) -> str:
    from .experiments.plan import SHIPPED_PLANS

    if value not in SHIPPED_PLANS:
        raise typer.BadParameter(f"{value!r} is not one of {', '.join(map(repr, SHIPPED_PLANS))}")
    return value


@app.command(epilog="Examples: swarmtopo plan --area 250000 --agents 200 --duration 30;  "
                    "swarmtopo plan --area 250000 --agents 200 --target 0.95 --holes 3;  "
                    "swarmtopo plan --input contact-trace --area 250000 --agents 200 --duration 60")
def plan(
    area: float = typer.Option(..., "--area", callback=_positive_option, help="Area inside the outer walls, mm^2."),
    agents: Optional[int] = typer.Option(None, "--agents", min=1, callback=_agents_option,
                                         help="Swarm size N (at most 100,000)."),
    duration: Optional[float] = typer.Option(None, "--duration", callback=_positive_option, help="Seconds of data T."),
    target: Optional[float] = typer.Option(None, "--target", callback=_accuracy_option,
                                           help="Wanted exact-match accuracy, e.g. 0.95."),
    holes: Optional[int] = typer.Option(None, "--holes", min=0, help="Holes the arena is expected to have "
                                        "(default: averaged over the benchmark's mix of 0-3 holes)."),
    reading: str = typer.Option("log", "--input", callback=_plan_input_option,
                                help="What will be mapped: 'log' (encounters and status changes, as the simulator "
                                     "writes them) or 'contact-trace' (encounters only, as 'swarmtopo ingest' "
                                     "writes a proximity trace)."),
    model_file: Optional[Path] = typer.Option(None, "--model", help="plan.json of a benchmark run "
                                                                    "(default: the shipped one for --input)."),
) -> None:
    """What accuracy a deployment will get, or the agents / time it needs for a target.

    Give --agents and --duration for the expected accuracy; or one of them and --target
    for the other; --holes if you know how many holes to expect; --input contact-trace
    if the swarm will record encounters only.  Answers come from the accuracy benchmark
    (docs/accuracy.md).
    """
    from .pipeline.map import MIN_REGION_AGENTS
    from .experiments.plan import load_plan

    if agents is not None and agents < MIN_REGION_AGENTS:
        raise typer.BadParameter(f"a map needs encounters among {MIN_REGION_AGENTS} agents or more", param_hint="--agents")
    given = {"agents": agents is not None, "duration": duration is not None, "target": target is not None}
    if sum(given.values()) != 2:
        raise typer.BadParameter("give two of --agents, --duration and --target (the third is computed)")
    if model_file is not None and reading != "log":
        raise typer.BadParameter("--model names its own plan; drop --input or --model", param_hint="--input")
    model = load_plan(model_file, reading)
    qualifier = "" if holes is None else f" with {holes} hole{'' if holes == 1 else 's'}"
    if reading == "contact-trace":
        qualifier += ", as a contact trace"
    if target is None:
        p = model.accuracy(area, agents, duration, holes)
        out.print(f"expected exact (beta_0, beta_1) accuracy: {100 * p:.0f}% "
                  f"({agents} agents x {duration:g} s in {area:g} mm^2{qualifier})", markup=False, highlight=False)
        n, t = agents, duration
    elif agents is None:
        n = max(model.agents_for(area, duration, target, holes), MIN_REGION_AGENTS)  # fewer cannot be mapped
        t = duration
        out.print(_plan_answer("agents", n, f"for {100 * target:.10g}% in {duration:g} s over {area:g} mm^2{qualifier}"),
                  markup=False, highlight=False)
    else:
        t = model.duration_for(area, agents, target, holes)
        n = agents
        out.print(_plan_answer("seconds of data", t,
                               f"for {100 * target:.10g}% with {agents} agents over {area:g} mm^2{qualifier}"),
                  markup=False, highlight=False)
    if np.isfinite(n) and np.isfinite(t) and not model.inside(area, n, t, holes):
        lo, hi = model.density_range
        t_lo, t_hi = model.duration_range
        swarms = "" if model.agents_range is None else f"{model.agents_range[0]:g}-{model.agents_range[1]:g} agents, "
        out.print(f"note: outside the benchmark's range ({swarms}{lo * 1e6:.0f}-{hi * 1e6:.0f} agents per m^2, "
                  f"{t_lo:g}-{t_hi:g} s, 0-{len(model.holes_mix) - 1} holes): an extrapolation",
                  markup=False, highlight=False)


def _plan_answer(what: str, value: float, condition: str) -> str:
    if not np.isfinite(value):
        return f"no number of {what} reaches that {condition} in the benchmark's model"
    return f"needed: {math.ceil(value)} {what} {condition}"


def _run_map(log, config, log_dir: Path, out_dir: Path, quiet: bool, verbose: bool = False, classifier=None,
             ground_truth=None):
    """Map, write map.json and figures; ground truth beside the log only colours pictures,
    and a broken ground-truth file costs a warning, never the map.  ``ground_truth``
    (arena, truth, trajectories): the caller's, instead of reading them beside the log."""
    from .pipeline.map import STAGES, map_encounters
    from .viz.report import write_map_outputs

    with _progress("mapping", quiet) as tick:
        try:
            tmap = map_encounters(log, config, classifier=classifier,
                                  progress=lambda stage: tick(STAGES.index(stage) / len(STAGES)))
        except SwarmtopoError as exc:
            if getattr(exc, "file", None):  # already names its file
                raise
            raise SwarmtopoError(f"{log_dir}: {exc}") from None
        tick(1.0)
    if verbose:
        _map_details(tmap)
    arena, truth, trajectories = ground_truth or _ground_truth(log, log_dir, quiet)
    return tmap, write_map_outputs(tmap, out_dir, log=log, truth=truth, arena=arena, trajectories=trajectories)


def _map_details(tmap) -> None:
    """--verbose: each stage's time and each region's landmarks, scales, bars and loops."""
    _detail("stages: " + ", ".join(f"{stage} {seconds:.2f} s" for stage, seconds in tmap.timings.items()))
    for r in tmap.regions:
        longest = ", ".join(f"{x:.3g}" for x in r.diagram.lengths(1)[:4]) if r.diagram.maxdim >= 1 else "-"
        _detail(f"region {r.component}: {r.n_events} events, {r.n_agents} agents, "
                f"{len(r.landmarks.nodes)} landmarks (covering radius {r.scales.cover_radius:.3g} s, "
                f"k-NN scale {r.scales.knn:.3g} s); longest H1 bars {longest} s; "
                f"threshold {', '.join(f'{v:.3g} s' for v in r.thresholds.values())}; "
                f"{len(r.cycles)} loop(s) found")
        if len(r.windows) > 1:
            scales = ", ".join(f"{x:g}" for x in tmap.config.window_scales)
            bands = ("" if tmap.config.landmark_bands == (1.0,) else
                     f", each at landmark bands {', '.join(f'{x:g}' for x in tmap.config.landmark_bands)}")
            _detail(f"region {r.component}: {len(r.windows)} windows of {scales} x {tmap.window_length[0]:.3g} s{bands} counted "
                    f"{[w.betti.get(1) for w in r.windows]} holes each; pooled {r.betti.get(1)}, shown: window "
                    f"{r.window} [{r.windows[r.window].t0:.1f}, {r.windows[r.window].t1:.1f}] s")
    _detail(f"per-hop cost h = {tmap.hop_cost[0]:.3g} s ({tmap.hop_cost[1]}); diffusion time "
            f"{tmap.diffusion_time[0]:.3g} s ({tmap.diffusion_time[1]}); wall following "
            f"{'like any time' if tmap.config.wall_follow_weight is None else f'x {tmap.config.wall_follow_weight:g}'}; window "
            f"{tmap.window_length[0]:.3g} s ({tmap.window_length[1]})")


def _ground_truth(log, log_dir: Path, quiet: bool):
    """(arena, truth, trajectories) beside the log, each None when absent or broken
    (a broken file costs a warning: ground truth only draws pictures)."""
    from .io.logs import read_arena, read_trajectories, read_truth

    arena = truth = trajectories = None
    try:
        if (log_dir / "arena.geojson").exists():
            arena = read_arena(log_dir / "arena.geojson")
        truth = read_truth(log_dir)
    except SwarmtopoError as exc:
        _warn(f"ground truth ignored for pictures: {exc}", quiet)
        return arena, None, None
    if truth is not None and not _aligned(truth, log):
        _warn(f"ground truth ignored for pictures: {log_dir / 'truth'}.* rows do not match the events "
              "one for one (same order, same t, a, b)", quiet)
        truth = None
    try:
        trajectories = read_trajectories(log_dir)
    except SwarmtopoError as exc:
        _warn(f"trajectories ignored (no swarm animation in the report): {exc}", quiet)
    return arena, truth, trajectories


def _aligned(truth, log) -> bool:
    if len(truth["t"]) != log.n_events or not np.array_equal(np.asarray(truth["t"], float), log.t):
        return False
    ids = [np.asarray(truth[c]).astype(str) for c in ("a", "b")]
    a, b = log.ids_of(log.a).astype(str), log.ids_of(log.b).astype(str)
    return bool(np.all(((ids[0] == a) & (ids[1] == b)) | ((ids[0] == b) & (ids[1] == a))))


def _warn(message: str, quiet: bool) -> None:
    if not quiet:
        err.print(f"warning: {message}", markup=False, highlight=False, soft_wrap=True)


def _print_verdict(tmap, truth) -> None:
    def confidence(n):
        p = tmap.confidence.get(n)
        return "" if p is None else f" ({100 * p:.0f}% confidence)"

    est = ", ".join(f"beta_{n} = {b}{confidence(n)}" if b is not None else
                    f"beta_{n} not estimated (the classifier has no threshold for it)"
                    for n, b in sorted(tmap.betti.items()))
    out.print(f"recovered: {est}")
    if truth is not None:
        out.print(f"true:      beta_0 = {truth[0]}, beta_1 = {truth[1]}")
    for warning in tmap.warnings:
        out.print(f"warning: {warning}", markup=False)
    for line in tmap.advice():
        out.print(f"advice: {line}", markup=False, highlight=False, soft_wrap=True)
    for small in tmap.too_little_data:
        out.print(f"note: {small['events']} encounter(s) of {small['agents']} agent(s) never linked to the "
                  "rest: too little data, not counted as a region")


def main() -> None:
    """Entry point: one-line errors; exit 1 for bad input, 2 for bad usage."""
    try:
        code = app(standalone_mode=False)
    except typer.Abort:
        err.print("aborted", markup=False)
        sys.exit(130)
    except TyperException as exc:  # usage errors: bad option value, unknown option, missing argument
        message = exc.format_message()
        if message:  # empty when the help was shown for a bare command
            ctx = getattr(exc, "ctx", None)
            where = f"{ctx.command_path}: " if ctx is not None else ""
            err.print(f"error: {where}{message}", markup=False, highlight=False, soft_wrap=True)
        sys.exit(getattr(exc, "exit_code", 2))
    except SwarmtopoError as exc:
        err.print(f"error: {exc}", markup=False, highlight=False, soft_wrap=True)
        sys.exit(1)
    except OSError as exc:
        err.print(f"error: {exc.filename or ''}: {exc.strerror or exc}", markup=False, highlight=False,
                  soft_wrap=True)
        sys.exit(1)
    sys.exit(code if isinstance(code, int) else 0)


if __name__ == "__main__":
    main()
