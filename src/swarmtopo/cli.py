"""Command line: thin wrappers that parse, call the package, and write files.

Every user error (bad file, bad option value) is printed as one line on stderr with
exit code 1; usage errors exit 2 (Typer); only bugs produce a traceback.
"""

from __future__ import annotations

import math
import re
import shlex
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Optional

import numpy as np
import typer
from typer.exceptions import TyperException
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn
from typer.core import TyperGroup

from . import __version__
from .errors import SwarmtopoError
from .io import output


class _Interrupt(Exception):
    """Ctrl-C in a command, as the one line to print (Typer would turn a KeyboardInterrupt
    into a silent exit 130)."""


class _Commands(TyperGroup):
    def invoke(self, ctx):
        done = len(output.COMMITTED)
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as exc:
            written = output.COMMITTED[done:]
            message = (exc.message if isinstance(exc, output.Interrupted) else
                       f"interrupted after writing {', '.join(map(str, written))}" if written else
                       "interrupted: nothing written")
            raise _Interrupt(message) from None


app = typer.Typer(
    cls=_Commands,
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_show_locals=False,
    help="Topological maps of unknown arenas from the encounters of a localization-free swarm.",
)
out = Console()
err = Console(stderr=True)
DEMO_AGENTS, DEMO_SECONDS = 200, 30.0
"""The demo's swarm: the accuracy benchmark's smallest budget."""
CHANGING_DEMO_SWARM = (300, 120.0)
"""``demo --changing``'s swarm: agents and seconds (the second hole appears at 60 s)."""
BEACON_DEMO_SWARM = (300, 300.0)
"""``demo --beacon``'s swarm: agents and leash R (mm); the leader sweeps the hall at 2 mm/s."""
DEMO_WRITER = "swarmtopo demo"
"""``written_by`` in the meta.json of the demo's log: the only log demo may replace."""
MAX_SCALE = 1000.0
"""Largest --scale: a 500 m square random arena, beyond what the wall grid accepts at r_d = 30 mm."""
VERBOSE_HELP = "Also report each stage's details and timings on stderr (in pipes too)."


OVERWRITE_HELP = "Replace the log already in --out (its log files are replaced or removed; other files stay)."
DASK_SCHEDULER_OPTION = typer.Option(None, "--scheduler", help="Address of an existing Dask scheduler.")
LOCAL_WORKERS_OPTION = typer.Option(None, "--workers", min=1,
                                    help="Worker processes of the local cluster (default: all cores).")
"""The ``--scheduler`` and ``--workers`` options of ``sweep`` and every ``bench`` command."""


@contextmanager
def _staged_log(out_dir: Path, overwrite: bool, protect=()):
    """Stage a log folder for ``out_dir`` (``output.staged_folder``, owning the log files
    there): refused if it holds a log and not ``overwrite``, or if the new log would
    replace or delete a file of ``protect`` (the trace an ingest reads)."""
    from .io.logs import log_files, refuse_protected

    refuse_protected(out_dir, protect)  # before --overwrite could be suggested
    with output.staged_folder(out_dir, [p.name for p in log_files(out_dir)], what="log",
                              overwrite=overwrite) as stage:
        yield stage


def _say_removed(stage, quiet: bool) -> None:
    """Name the outdated files the new result removed (a parquet log over a CSV one)."""
    if not quiet:
        for path in stage.removed:
            out.print(f"removed the outdated {path}", markup=False, highlight=False, soft_wrap=True)


def _print_version(value: bool) -> None:
    if value:
        out.print(f"swarmtopo {__version__}", markup=False, highlight=False)
        raise typer.Exit()


@app.callback()
def _main_options(
    version: bool = typer.Option(False, "--version", is_eager=True, callback=_print_version,
                                 help="Print swarmtopo's version and exit."),
) -> None:
    pass


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


def _check_option(hint: str, check, *args):
    """Run a simulator check (returning what it returns); its InputError becomes a usage
    error naming ``hint``."""
    from .errors import InputError

    try:
        return check(*args)
    except InputError as exc:
        value = exc.value
        got = "" if value is None else f" (got {value:g})" if isinstance(value, (int, float)) else f" (got {value})"
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


FAULT_OPTIONS = {
    "lost": typer.Option(0.0, "--lost", min=0.0, max=1.0, help="Faults: share of reports lost independently."),
    "burst_lost": typer.Option(0.0, "--burst-lost", min=0.0, max=1.0,
                               help="Faults: share of each agent's time its radio is down (its reports lost)."),
    "burst_length": typer.Option(2.0, "--burst-length", min=0.0, callback=_finite_option,
                                 help="Faults: mean length (s) of a radio outage of --burst-lost."),
    "false_encounters": typer.Option(0.0, "--false-encounters", min=0.0, max=1.0,
                                     help="Faults: false reports of pairs that never met, per report."),
    "jitter": typer.Option(0.0, "--jitter", min=0.0, callback=_finite_option,
                           help="Faults: standard deviation (s) of the noise on each report's time."),
    "clock_offset": typer.Option(0.0, "--clock-offset", min=0.0, callback=_finite_option,
                                 help="Faults: each agent's clock is off by up to this many seconds (uniform)."),
    "clock_drift": typer.Option(0.0, "--clock-drift", min=0.0, max=0.999,
                                help="Faults: each agent's clock drifts by up to this many s per s (uniform)."),
    "dying": typer.Option(0.0, "--dying", min=0.0, max=1.0,
                          help="Faults: share of agents whose battery dies at a random time."),
    "duplicated": typer.Option(0.0, "--duplicated", min=0.0, max=1.0,
                               help="Faults: share of reports delivered twice (by the pair's other agent)."),
    "duplicate_delay": typer.Option(0.5, "--duplicate-delay", min=0.0, callback=_finite_option,
                                    help="Faults: a duplicate arrives up to this many seconds later (uniform)."),
}
"""The fault options of ``perturb`` and ``simulate`` (:class:`~swarmtopo.sim.faults.Faults`;
docs/model.md, 'Faulty sensing')."""


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
    duration: float = typer.Option(20.0, "--duration", callback=_positive_option,
                                   help="Seconds of data: a whole number of time steps --dt."),
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
    beacon: Optional[str] = typer.Option(
        None, "--beacon", metavar="PATH|sweep",
        help="A leader carrying a beacon moves along PATH (a GeoJSON LineString with a 'speed' in mm/s, or a t,x,y "
             "table) or, with 'sweep', along the middle of the arena's long axis once; agents farther than --leash "
             "from it are steered back; the log gains beacon.csv (docs/exploration.md in the source repository)."),
    leash: Optional[float] = typer.Option(None, "--leash", callback=_positive_option,
                                          help="Leash R (mm) of --beacon: agents farther are steered towards it."),
    leader_speed: Optional[float] = typer.Option(None, "--leader-speed", callback=_positive_option,
                                                 help="Speed (mm/s) of the leader of --beacon sweep (default 2)."),
    motion: str = typer.Option("cockroach", "--motion",
                               help="Motion model: cockroach (the paper's), billiard, run-and-tumble, brownian, levy or "
                                    "flocking (docs/model.md in the source repository)."),
    speed: Optional[float] = typer.Option(None, "--speed", callback=_positive_option,
                                          help="Speed v (mm/s) of billiard, run-and-tumble, levy and flocking agents "
                                               "(default 15)."),
    tumble_rate: Optional[float] = typer.Option(None, "--tumble-rate", callback=_positive_option,
                                                help="Run-and-tumble: tumbles per second (default 0.5)."),
    diffusion: Optional[float] = typer.Option(None, "--diffusion", callback=_positive_option,
                                              help="Brownian: diffusion coefficient D in mm^2/s (default 225)."),
    levy_exponent: Optional[float] = typer.Option(None, "--levy-exponent", callback=_finite_option,
                                                  help="Levy walk: step-length exponent mu in (1, 3] (default 2)."),
    levy_min_step: Optional[float] = typer.Option(None, "--levy-min-step", callback=_positive_option,
                                                  help="Levy walk: shortest step l_0 in mm (default 10)."),
    align_radius: Optional[float] = typer.Option(None, "--align-radius", callback=_positive_option,
                                                 help="Flocking: alignment radius in mm (default 30)."),
    noise: Optional[float] = typer.Option(None, "--noise", callback=_finite_option,
                                          help="Flocking: heading noise eta in [0, 2 pi] rad (default 1)."),
    lost: float = FAULT_OPTIONS["lost"],
    burst_lost: float = FAULT_OPTIONS["burst_lost"],
    burst_length: float = FAULT_OPTIONS["burst_length"],
    false_encounters: float = FAULT_OPTIONS["false_encounters"],
    jitter: float = FAULT_OPTIONS["jitter"],
    clock_offset: float = FAULT_OPTIONS["clock_offset"],
    clock_drift: float = FAULT_OPTIONS["clock_drift"],
    dying: float = FAULT_OPTIONS["dying"],
    duplicated: float = FAULT_OPTIONS["duplicated"],
    duplicate_delay: float = FAULT_OPTIONS["duplicate_delay"],
    overwrite: bool = typer.Option(False, "--overwrite", help=OVERWRITE_HELP),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar, no summary."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Simulate a swarm in an arena and write its encounter log folder."""
    import time
    from dataclasses import replace

    from .arena import random_arena
    from .changing import ChangingArena, true_betti_text
    from .io.arenas import read_arena
    from .io.logs import write_log
    from .sim import SensingParams, check_run_size, check_static_time, check_time_step, simulate as run
    from .sim.faults import perturb
    from .sim.params import make_motion
    from .sim.simulate import check_duration

    _check_verbosity(quiet, verbose)
    if arena is not None and holes is not None:
        raise typer.BadParameter("an --arena file has its own holes; drop --holes or --arena", param_hint="--holes")
    if static_time > 0 and static_fraction == 0:
        raise typer.BadParameter("the static agents' stop time needs --static-fraction > 0", param_hint="--static-time")
    walk = _check_option("--motion", make_motion, motion, {
        "speed": speed, "tumble_rate": tumble_rate, "diffusion": diffusion, "levy_exponent": levy_exponent,
        "levy_min_step": levy_min_step, "align_radius": align_radius, "noise": noise})
    _check_option("--dt", check_time_step, dt, walk, SensingParams(r_d=rd))  # the motion simulate runs with
    _check_option("--agents, --duration, --dt", check_run_size, agents, duration, dt)
    _check_option("--duration, --dt", check_duration, duration, dt)
    _check_option("--static-time", check_static_time, static_fraction, static_time, duration, dt)
    if (beacon is None) != (leash is None):
        raise typer.BadParameter("a leader needs both --beacon and --leash", param_hint="--beacon" if leash else "--leash")
    if beacon is not None and motion != "cockroach":
        raise typer.BadParameter(f"a leader steers the cockroach model only, not {motion} motion", param_hint="--beacon")
    if leader_speed is not None and beacon != "sweep":
        raise typer.BadParameter("sets the speed of --beacon sweep only (a path file gives its own speed)",
                                 param_hint="--leader-speed")
    faults = _check_option("--lost ... --duplicate-delay", _faults, locals())
    if faults.any and truth:
        raise typer.BadParameter("truth.csv gives the true positions of each true event, and a log with faults has "
                                 "other events: drop --truth (arena.geojson is written anyway)", param_hint="--truth")

    if arena:  # scaled like a sweep's file arena
        world = read_arena(arena) if scale == 1.0 else read_arena(arena).scaled(scale)
    else:  # the arena draws from its own stream, spawned from the seed; the swarm uses the seed
        world = random_arena(1 if holes is None else holes, scale=scale,
                             rng=np.random.SeedSequence(seed).spawn(1)[0])
    for passage in world.narrow_passages(rd):
        _warn(f"{passage}, less than r_d = {rd:g} mm: the swarm may not tell them apart, and the map may miss "
              f"that hole", quiet)
    leader = {} if beacon is None else {"beacon": _leader_track(beacon, world, leash, leader_speed, duration, quiet),
                                        "leash": leash}
    if verbose:
        _detail(f"arena: {world.betti[0]} region(s), {world.betti[1]} hole(s), area {world.area:.0f} mm^2; "
                f"{agents} agents, {duration:g} s, dt {dt:g} s, r_d {rd:g} mm, seed {seed}")
    start = time.perf_counter()
    with _staged_log(out_dir, overwrite) as stage:
        with _progress("simulating", quiet) as tick:
            sim = run(world, agents, duration, dt=dt, motion=walk, sensing=SensingParams(r_d=rd), rng=seed,
                      static_fraction=static_fraction, static_time=static_time, truth=truth,
                      trajectory_every=trajectories, progress=tick, **leader)
        if faults.any:  # the faults draw from a stream of their own, spawned from the seed
            fault_seed = int(np.random.SeedSequence(seed).spawn(2)[1].generate_state(1)[0])
            sim = replace(sim, log=perturb(sim.log, faults, fault_seed)[0])
        if verbose:
            _detail(f"simulated in {time.perf_counter() - start:.2f} s: {sim.log.n_events} encounters, "
                    f"{len(sim.log.status_t)} status changes")
        written = [stage.final_path(p) for p in write_log(sim.log, stage.path, fmt=fmt, truth=sim.truth,
                                                           trajectories=sim.trajectories, arena=world)]
    _say_removed(stage, quiet)
    if not quiet:
        b0, b1 = world.betti
        where = (f"in an arena that changes ({true_betti_text(world, sim.log.meta['duration'])})"
                 if isinstance(world, ChangingArena) else f"in an arena with {b0} region(s) and {b1} hole(s)")
        out.print(f"{sim.log.n_events} encounters of {agents} agents over {sim.log.meta['duration']:g} s {where}",
                  markup=False, highlight=False, soft_wrap=True)
        if faults.any:
            out.print(_fault_counts(sim.log.meta["faults"][-1]), markup=False, highlight=False, soft_wrap=True)
        for moved in sim.log.meta["simulation"].get("relocated", []):
            if moved["agents"]:
                out.print(f"at t = {moved['t']:g} s the arena changed: {moved['agents']} agent(s) stood where an "
                          "obstacle appeared and were moved to the nearest free point", markup=False, highlight=False,
                          soft_wrap=True)
        if leader:
            share = sim.log.meta["simulation"]["leash"]["stimulated_share"]
            out.print(f"a leader moved {leader['beacon'].distance_travelled(0.0, sim.log.meta['duration']):.0f} mm; "
                      f"agents were steered back towards it (having gone beyond the leash R = {leash:g} mm) "
                      f"{100 * share:.1f} % of the time", markup=False, highlight=False, soft_wrap=True)
        out.print(f"wrote {', '.join(str(p) for p in written)}", markup=False, highlight=False, soft_wrap=True)


def _faults(given: dict):
    """The :class:`~swarmtopo.sim.faults.Faults` of a command's fault options (``given``: its locals)."""
    from .sim.faults import Faults

    return Faults(**{name: given[name] for name in FAULT_OPTIONS})


def _fault_counts(record: dict) -> str:
    """One line of what :func:`~swarmtopo.sim.faults.perturb` did (its record)."""
    c = record["counts"]
    parts = [f"{c['reports']} reports: {c['delivered']} delivered"]
    for key, text in (("after_death", "lost to {} dead agents' batteries"), ("lost", "lost"),
                      ("lost_in_outages", "lost in radio outages"), ("duplicated", "duplicated"),
                      ("false", "false encounters added")):
        if c[key]:
            parts.append(f"{c[key]} " + text.format(c["died"]))
    shift = f"; times shifted by {record['shift']:.3g} s (a clock before 0 s)" if record["shift"] else ""
    return "faults: " + ", ".join(parts) + shift


def _leader_track(beacon: str, world, leash: float, speed: float, duration: float, quiet: bool):
    """The leader's track of ``simulate --beacon``: a file's, or ``sweep`` along the arena's long axis."""
    from .beacon import LEADER_SPEED, long_axis_track
    from .io.beacons import read_beacon_path

    track = (long_axis_track(world.bounds, leash, speed or LEADER_SPEED) if beacon == "sweep"
             else read_beacon_path(Path(beacon)))
    if track.t[-1] > duration:
        _warn(f"the leader's track runs to t = {track.t[-1]:g} s, after the log ends at {duration:g} s: the "
              "swarm explores only part of it (give a longer --duration)", quiet)
    return track


@app.command(epilog="Example: swarmtopo perturb runs/two-holes --out runs/two-holes-faulty --lost 0.3 --jitter 0.5 "
                    "--false-encounters 0.01 --seed 1 && swarmtopo map runs/two-holes-faulty")
def perturb(
    log_dir: Path = typer.Argument(..., help="Log folder (simulated or ingested)."),
    out_dir: Path = typer.Option(..., "--out", help="Folder to write the perturbed log into (created)."),
    lost: float = FAULT_OPTIONS["lost"],
    burst_lost: float = FAULT_OPTIONS["burst_lost"],
    burst_length: float = FAULT_OPTIONS["burst_length"],
    false_encounters: float = FAULT_OPTIONS["false_encounters"],
    jitter: float = FAULT_OPTIONS["jitter"],
    clock_offset: float = FAULT_OPTIONS["clock_offset"],
    clock_drift: float = FAULT_OPTIONS["clock_drift"],
    dying: float = FAULT_OPTIONS["dying"],
    duplicated: float = FAULT_OPTIONS["duplicated"],
    duplicate_delay: float = FAULT_OPTIONS["duplicate_delay"],
    seed: int = typer.Option(0, "--seed", min=0, help="Random seed of the faults (same seed, same bytes)."),
    fmt: str = typer.Option("csv", "--format", callback=_fmt_option, help="csv or parquet."),
    overwrite: bool = typer.Option(False, "--overwrite", help=OVERWRITE_HELP),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
) -> None:
    """Pass a log's encounters through a faulty radio: lost, false, late and duplicated reports, dying agents.

    Each encounter is one report, sent by one of its two agents and stamped by that
    agent's clock; the faults are applied in turn and recorded in the new log's
    meta.json (docs/model.md in the source repository, 'Faulty sensing').  The arena
    (arena.geojson) is copied; truth.* (true positions per true event) is not.
    """
    import shutil

    from .io.logs import log_folder, read_log, write_log
    from .sim.faults import perturb as apply_faults

    faults = _check_option("--lost ... --duplicate-delay", _faults, locals())
    if not faults.any:
        raise typer.BadParameter("no fault given: set at least one of --lost, --burst-lost, --false-encounters, "
                                 "--jitter, --clock-offset, --clock-drift, --dying, --duplicated")
    source = log_folder(log_dir)
    log = read_log(source)
    with _staged_log(out_dir, overwrite, protect=[source / name for name in ("meta.json",)]) as stage:
        faulty, record = apply_faults(log, faults, seed)
        written = [stage.final_path(p) for p in write_log(faulty, stage.path, fmt=fmt)]
        if (source / "arena.geojson").is_file():
            shutil.copyfile(source / "arena.geojson", stage.path / "arena.geojson")
            written.append(stage.final_path(stage.path / "arena.geojson"))
    _say_removed(stage, quiet)
    if not quiet:
        out.print(_fault_counts(record), markup=False, highlight=False, soft_wrap=True)
        out.print(f"wrote {', '.join(str(p) for p in written)}", markup=False, highlight=False, soft_wrap=True)


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
    """Convert a proximity trace into an encounter log folder.

    What a contact trace can and cannot tell about its space: see the project's
    documentation, docs/real-data.md in the source repository.
    """
    from .io.logs import write_log
    from .io.traces import FORMATS, SOCIOPATTERNS_WINDOW, read_trace
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
    with _staged_log(out_dir, overwrite, protect=(trace,)) as stage:
        log, report = read_trace(trace, fmt, skip_bad=skip_bad, **columns,
                                 window=SOCIOPATTERNS_WINDOW if window is None else window)
        written = [stage.final_path(p) for p in write_log(log, stage.path, fmt=log_fmt)]
    _say_removed(stage, quiet)
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
        out.print(f"wrote {', '.join(str(p) for p in written)}", markup=False, highlight=False, soft_wrap=True)


def _map_option(name: str, metavar: str, help: str):
    """A ``map`` option that is one ``MapConfig`` field, passed on as written: the config
    parses and validates it (``pipeline.config.OPTIONS``)."""
    return typer.Option(None, "--" + name.replace("_", "-"), metavar=metavar, help=help)


def _option_name(field: str) -> str:
    return "--" + field.replace("_", "-")


@app.command("map", epilog="Example: swarmtopo map runs/two-holes --out runs/two-holes/map --metric hybrid --landmarks 300")
def map_command(
    log_dir: Path = typer.Argument(..., help="Log folder: events.csv|parquet, optional status, meta.json."),
    out_dir: Optional[Path] = typer.Option(None, "--out", help="Output folder (default: LOG_DIR/map)."),
    metric: Optional[str] = _map_option("metric", "NAME", "plain | contracted | hybrid (the paper's metrics; default "
                                                          "hybrid)."),
    subsample: Optional[str] = _map_option("subsample", "NAME", "maxmin | knn | probabilistic (default maxmin)."),
    landmarks: Optional[str] = _map_option(
        "landmarks", "L", "Number of landmarks L of the map, 3..2000, shared between its regions in proportion to "
                          "their events and used in every window (default: per window, the fewest that meet the "
                          "sampling guarantee, at most --max-landmarks; persistence time grows about as L^3)."),
    window: Optional[str] = _map_option("window", "T0:T1", "Time window in seconds (either end may be empty)."),
    maxdim: Optional[str] = _map_option("maxdim", "N", "Highest homology dimension, 1 or 2 (default 1)."),
    seed: Optional[str] = _map_option("seed", "SEED", "Seed of the landmark start and the MDS (default 0)."),
    hop_cost: Optional[str] = _map_option(
        "hop_cost", "SECONDS", "Per-hop cost h in seconds on the encounter graph; 0 = the paper's metric "
                               "(default: r_d / v_c from meta.json, else from the data)."),
    diffusion_time: Optional[str] = _map_option(
        "diffusion_time", "SECONDS|auto|none",
        "tau in seconds: a gap of w s between an agent's encounters weighs tau (sqrt(1 + 2 w / tau) - 1), about a "
        "random walk's displacement; 'none' = the paper's weight w; 'auto' (default) = half the mean time between "
        "an agent's encounters."),
    wall_follow_weight: Optional[str] = _map_option(
        "wall_follow_weight", "WEIGHT|none",
        "Seconds charged per second an agent spent wall following (status WF) within a gap, outside the diffusive "
        "weights: along a wall an agent walks, it does not diffuse (default 2); 'none' = like any other time "
        "(the paper)."),
    window_length: Optional[str] = _map_option(
        "window_length", "SECONDS|auto|none",
        "Seconds of the time windows whose maps are pooled; 'none' maps the whole log at once; 'auto' (default) "
        "holds about 20 encounters per agent (20 x the mean time between an agent's encounters)."),
    window_encounters: Optional[str] = _map_option(
        "window_encounters", "K", "Encounters per agent an automatic window holds (default 20)."),
    window_scales: Optional[str] = _map_option(
        "window_scales", "S,S,...",
        "Comma-separated multipliers of the window length, each at least 0.05: the windows of every such length "
        "are pooled together (default 0.75,1,1.25; 1 maps one length, about three times faster)."),
    window_step: Optional[str] = _map_option(
        "window_step", "SECONDS|auto", "Seconds between the starts of consecutive windows (default: half a window)."),
    max_windows: Optional[str] = _map_option(
        "max_windows", "N|none",
        "Cap of the time windows mapped, all lengths together, at least one per length (default 48, more than any "
        "benchmark map pools): a longer log maps an evenly spaced share of each length's windows, so its time stops "
        "growing with its length; 'none' maps every window."),
    landmark_bands: Optional[str] = _map_option(
        "landmark_bands", "B,B,...|auto",
        "Comma-separated shares of each window's length: every window is mapped once per share B, its landmarks "
        "drawn from the window's middle B x its length, and all are pooled (1: the whole window once; 'auto' "
        "(default): the bands the reader was fitted with, 1,0.5 for the default reader and 1 for the others)."),
    max_landmarks: Optional[str] = _map_option(
        "max_landmarks", "L", "Cap of the automatic landmark count per region and window, 3..2000 (default 400)."),
    timeline_length: Optional[str] = _map_option(
        "timeline_length", "SECONDS|auto|none",
        "Seconds of the time windows of the map's timeline, which says whether and when the Betti numbers "
        "changed ('auto' (default): the map's own windows, read one by one; 'none': no timeline)."),
    timeline_step: Optional[str] = _map_option(
        "timeline_step", "SECONDS|auto", "Seconds between the starts of the timeline's windows of its own (with "
                                         "this or --timeline-length; default half one)."),
    recontacts: Optional[str] = _map_option(
        "recontacts", "auto|merge|keep",
        "A pair's repeated contact starts (contacts that flicker, as with diffusive or flocking agents): 'auto' "
        "(default) merges each into the pair's first when the log's contacts flicker, 'merge' always, 'keep' never."),
    uncorroborated: Optional[str] = _map_option(
        "uncorroborated", "auto|drop|keep",
        "Encounters no short detour through the rest of the log backs (false encounters, timing errors): 'auto' "
        "(default) leaves them out when their share says the sensing was faulty, 'drop' always, 'keep' never."),
    classifier: Optional[str] = typer.Option(
        None, "--classifier",
        help="Betti reader: default (tuned on the accuracy benchmark), trace (the same tuned on its logs read as "
             "contact traces), paper (the paper's classifier form, trained on random arenas the paper's way), or a "
             "JSON file. Unset: default for a log with status changes, trace for one without."),
    paper: bool = typer.Option(
        False, "--paper",
        help="Run the paper's pipeline: no per-hop cost, no diffusive weights, wall following like any time, the "
             "whole log, whole-window landmarks, the paper's classifier form."),
    workers: Optional[int] = typer.Option(
        None, "--workers", min=1,
        help="Map the windows on an embedded Dask cluster of N worker processes (default: this process, one thread "
             "per core). The map is the same bytes either way."),
    scheduler: Optional[str] = typer.Option(
        None, "--scheduler", help="Map the windows on an existing Dask cluster: its scheduler's address, e.g. "
                                  "tcp://10.0.0.5:8786."),
    overwrite: bool = typer.Option(False, "--overwrite",
                                   help="Replace the map already in --out (its map files; other files stay)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Map an encounter log folder: Betti numbers with confidence, diagrams and pictures."""
    from .io.logs import log_folder, read_log
    from .log import exact_time
    from .pipeline.config import PAPER_EXCLUDES, PAPER_OPTIONS, ConfigError, config_from_options
    from .readers.registry import load_classifier
    from .viz.report import MAP_FILES

    _check_verbosity(quiet, verbose)
    if workers is not None and scheduler is not None:
        raise typer.BadParameter("give --workers (a local cluster) or --scheduler (an existing one), not both")
    options = {"metric": metric, "subsample": subsample, "landmarks": landmarks, "window": window, "maxdim": maxdim,
               "seed": seed, "hop_cost": hop_cost, "diffusion_time": diffusion_time,
               "wall_follow_weight": wall_follow_weight, "window_length": window_length,
               "window_encounters": window_encounters, "window_scales": window_scales, "window_step": window_step,
               "max_windows": max_windows, "landmark_bands": landmark_bands, "max_landmarks": max_landmarks,
               "timeline_length": timeline_length, "timeline_step": timeline_step, "recontacts": recontacts,
               "uncorroborated": uncorroborated}
    if paper:
        given = [_option_name(name) for name in PAPER_EXCLUDES if options[name] is not None]
        if given or classifier is not None:
            raise typer.BadParameter(f"--paper fixes {', '.join(given + ['--classifier'] * (classifier is not None))}; "
                                     "drop one or the other")
        options, classifier = {**options, **PAPER_OPTIONS}, "paper"
    out_dir = out_dir or log_dir / "map"
    if out_dir.exists() and not out_dir.is_dir():
        raise SwarmtopoError(f"{out_dir}: --out is a file; give a folder for the map's outputs")
    try:
        config = config_from_options(options)
    except ConfigError as exc:  # a value out of its domain, or options that do not go together: a usage error
        reason = re.sub(r"\bNone\b", "'none'", exc.reason)
        raise typer.BadParameter(reason, param_hint=f"'{_option_name(exc.field)}'") from None
    model = load_classifier(classifier) if classifier else None  # None: the shipped one for the log
    log_folder(log_dir)  # a file or a missing folder is said as such, before any output is staged
    with output.staged_folder(out_dir, MAP_FILES, what="map", overwrite=overwrite) as stage:
        log = read_log(log_dir)
        if verbose:
            _detail(f"log {log_dir}: {log.n_events} encounters of {log.n_agents} agents from t = "
                    f"{exact_time(log.t[0])} to {exact_time(log.t[-1])} s")
        tmap, written = _run_map(log, config, log_dir, stage.path, quiet, verbose, reader=model,
                                 engine={"workers": workers, "scheduler": scheduler})
    if not quiet:
        _print_verdict(tmap, truth=None)
        out.print(f"wrote {', '.join(str(stage.final_path(p)) for p in written)}", markup=False, highlight=False,
                  soft_wrap=True)


@app.command(epilog="Example: swarmtopo demo --out swarmtopo-demo")
def demo(
    out_dir: Path = typer.Option(Path("swarmtopo-demo"), "--out",
                                 help="Output folder: the log in its log/, the map beside it (a log and map already "
                                      "there are replaced only if demo wrote them; other files stay)."),
    seed: int = typer.Option(0, "--seed", min=0, help="Random seed."),
    changing: bool = typer.Option(False, "--changing",
                                  help="An arena that changes: a second hole appears at t = 60 s (300 agents, 120 s); "
                                       "the map's timeline says when."),
    beacon: bool = typer.Option(False, "--beacon",
                                help="A 2.4 m hall, bigger than the swarm sees at once, explored behind a leader: 300 "
                                     "agents on a 300 mm leash, the leader sweeping the hall at 2 mm/s (about 16 "
                                     "minutes of log); the map stitches its local maps into a global one."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Simulate the paper's Fig. "encmds" arena and map it.

    A 500 mm square with one hole, 200 agents, 30 s of data (the accuracy benchmark's
    smallest budget; the paper's figure has 20 s): prints the recovered
    Betti numbers beside the true ones and where the figures were written.  With
    --changing, a second hole appears half-way through a longer log; with --beacon,
    a long hall is explored behind a moving leader.
    """
    from .arena import default_arena, hall_demo_arena
    from .beacon import long_axis_track
    from .changing import changing_demo_arena, true_betti_text
    from .io.logs import log_files, write_log
    from .pipeline import MapConfig
    from .sim import simulate as run
    from .viz.report import MAP_FILES

    _check_verbosity(quiet, verbose)
    log_dir = out_dir / "log"
    if not _demo_wrote(log_dir):  # the demo replaces only its own log and map
        for folder, what, found in ((log_dir, "log", log_files(log_dir)),
                                    (out_dir, "map", [out_dir / n for n in MAP_FILES if (out_dir / n).exists()])):
            if found:
                raise SwarmtopoError(f"{folder}: already holds a {what} that swarmtopo demo did not write "
                                     f"({', '.join(p.name for p in found)}); choose another --out")
    if changing and beacon:
        raise typer.BadParameter("choose --changing or --beacon, not both")
    world, agents, seconds = ((changing_demo_arena(), *CHANGING_DEMO_SWARM) if changing
                              else (default_arena(), DEMO_AGENTS, DEMO_SECONDS))
    leader = {}
    if beacon:
        world, (agents, leash) = hall_demo_arena(), BEACON_DEMO_SWARM
        leader = {"beacon": long_axis_track(world.bounds, leash), "leash": leash}
        seconds = float(np.ceil(leader["beacon"].t[-1] + 20.0))
    owned = {"log": [p.name for p in log_files(log_dir)], **dict.fromkeys(MAP_FILES)}  # the rest of D stays
    with output.staged_folder(out_dir, owned, what="demo", overwrite=True) as stage:
        with _progress("simulating", quiet) as tick:
            sim = run(world, agents, seconds, rng=seed, truth=True, trajectory_every=2.0 if beacon else 0.5,
                      progress=tick, **leader)
        sim.log.meta["written_by"] = DEMO_WRITER
        write_log(sim.log, stage.path / "log", truth=sim.truth, trajectories=sim.trajectories, arena=world)
        if verbose:
            _detail(f"simulated: {sim.log.n_events} encounters of {agents} agents over {seconds:g} s; "
                    f"log: {log_dir}")
        tmap, written = _run_map(sim.log, MapConfig(seed=seed), log_dir, stage.path, quiet, verbose,
                                 ground_truth=(world, sim.truth, sim.trajectories))
    if not quiet:
        _print_verdict(tmap, truth=true_betti_text(world, sim.log.meta["duration"]))
        out.print(f"log: {log_dir}", markup=False, highlight=False, soft_wrap=True)
        out.print(f"wrote {', '.join(str(stage.final_path(p)) for p in written)}", markup=False, highlight=False,
                  soft_wrap=True)


def _demo_wrote(log_dir: Path) -> bool:
    """Whether ``log_dir``'s meta.json says ``swarmtopo demo`` wrote the log (so it may replace it)."""
    from ._json import read_json

    meta = log_dir / "meta.json"
    try:
        doc = read_json(meta) if meta.is_file() else None
    except SwarmtopoError:  # unreadable: not provably the demo's
        return False
    return isinstance(doc, dict) and doc.get("written_by") == DEMO_WRITER


@app.command(epilog="Example: swarmtopo sweep examples/sweep-small.toml --store results.duckdb --workers 2  "
                    "(run it again after a crash or Ctrl-C: finished jobs are skipped; "
                    "swarmtopo status results.duckdb shows the progress from another terminal)")
def sweep(
    config: Path = typer.Argument(..., help="Sweep grid: a TOML file with sweep, arena, swarm and map tables."),
    store: Path = typer.Option(..., "--store", help="DuckDB result store (created; one row per job in table jobs)."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler",
                                            help="Address of an existing Dask scheduler, e.g. tcp://10.0.0.5:8786."),
    workers: Optional[int] = LOCAL_WORKERS_OPTION,
    job_timeout: Optional[float] = typer.Option(None, "--job-timeout", min=0.001,
                                                help="Seconds a job may run before it is killed and stored as a "
                                                     "timeout row (default: [sweep] job_timeout, else 3600)."),
    retry_failed: bool = typer.Option(False, "--retry-failed",
                                      help="Run again the jobs stored as failed (error, crashed, timeout)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """Run every simulate-and-map job of a grid on Dask and store one row per job.

    Jobs already in the store are skipped, so a sweep can be resumed or grown.  A job
    that raises, crashes its process or runs past the job timeout is a stored row with
    its failure kind and message, and the sweep goes on; a rerun skips failed rows
    unless --retry-failed.  If every job of the grid failed, the sweep exits 1.
    """
    from .experiments.grid import read_sweep
    from .experiments.store import stored_failures
    from .experiments.sweep import SchedulerLost, run_sweep

    _check_verbosity(quiet, verbose)
    grid = read_sweep(config)
    timeout = grid.job_timeout if job_timeout is None else job_timeout
    if verbose:
        _detail(f"sweep {grid.name!r} from {config}: {len(grid.jobs)} jobs ({grid.replicates} replicate(s), "
                f"salt {grid.salt!r}), job timeout {timeout:g} s, rows keep diagrams: {grid.diagrams}")
    try:
        with _sweep_progress(quiet, verbose) as tick:
            summary = run_sweep(grid.jobs, store, scheduler=scheduler, workers=workers, progress=tick,
                                job_timeout=timeout, retry_failed=retry_failed, keep=grid.diagrams)
    except KeyboardInterrupt:
        if not quiet:
            err.print(f"interrupted: finished jobs are saved in {store}; run the same command again to run the rest",
                      markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(130) from None
    except SchedulerLost as exc:
        command = ["swarmtopo", "sweep", str(config), "--store", str(store)]
        command += ["--scheduler", scheduler] if scheduler is not None else []
        command += ["--workers", str(workers)] if workers is not None else []
        command += ["--job-timeout", f"{job_timeout:g}"] if job_timeout is not None else []
        command += ["--retry-failed"] if retry_failed else []
        err.print(f"error: {exc}; once the scheduler is back, resume with: {shlex.join(command)}",
                  markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(1) from None
    # every job failed (the grid, not the data, is likely wrong): only then read the rows run before
    failures = stored_failures(store, [job.key for job in grid.jobs]) if summary.n_failed == summary.run else []
    if summary.total and sum(g.count for g in failures) == summary.total:
        first = failures[0]
        err.print(f"error: sweep {grid.name!r}: all {summary.total} jobs failed ({first.status}: {first.example}); "
                  f"their rows are in {store}", markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(1)
    if quiet:
        return
    if summary.run == 0:
        out.print(f"sweep {grid.name!r}: all {summary.total} jobs already in {store}; nothing to run",
                  markup=False, highlight=False)
        return
    kinds = _kinds(summary.failed)
    out.print(f"sweep {grid.name!r}: {summary.total} jobs: {summary.run} run ({summary.n_failed} failed"
              f"{': ' + kinds if kinds else ''}), {summary.skipped} already in the store",
              markup=False, highlight=False)
    out.print(f"{summary.run} jobs in {summary.seconds:.1f} s, {summary.workers} worker(s) at the end: "
              f"{summary.jobs_per_minute:.1f} jobs/minute", markup=False, highlight=False)
    for line in _failure_lines(summary.failures):
        out.print(line, markup=False, highlight=False, soft_wrap=True)
    out.print(f"results: {store} (table jobs)", markup=False, highlight=False)


def _kinds(counts: dict[str, int]) -> str:
    """Failure kind -> count as "2 error, 1 timeout"."""
    return ", ".join(f"{n} {kind}" for kind, n in sorted(counts.items()))


def _failure_lines(groups, most: int = 3) -> list[str]:
    """The largest failure groups, one line each (messages that differ only in numbers are one group)."""
    lines = [f"failed {g.count}x ({g.status}): {g.example}" + (" (numbers vary)" if g.varied else "")
             for g in groups[:most]]
    if len(groups) > most:
        lines.append(f"... and {sum(g.count for g in groups[most:])} more failed rows of "
                     f"{len(groups) - most} other kind(s)")
    return lines


@app.command(epilog="Example: swarmtopo status results.duckdb  (while the sweep runs, from another terminal)")
def status(
    store: Path = typer.Argument(..., help="A sweep's DuckDB result store."),
) -> None:
    """What a result store holds: per sweep, jobs done, failed (by kind) and pending; the
    most common failures; and whether a sweep is writing to it now."""
    from .experiments.store import RUN_STALE, store_status, utcnow

    found = store_status(store)
    for s in found.sweeps:
        failed = {k: n for k, n in s.counts.items() if k != "ok"}
        kinds = _kinds(failed)
        out.print(f"sweep {s.sweep!r}: {s.asked} jobs: {s.counts.get('ok', 0)} done, {sum(failed.values())} failed"
                  f"{' (' + kinds + ')' if kinds else ''}, {s.pending} pending", markup=False, highlight=False)
    for line in _failure_lines(found.failures, most=5):
        out.print(line, markup=False, highlight=False, soft_wrap=True)
    now = utcnow()
    for run in found.runs[-3:]:
        ago = (now - run["updated_at"]).total_seconds()
        where = f"{run['host']}:{run['pid']} on {run['scheduler']}, {run['workers']} worker(s)"
        if run["outcome"] is not None:
            state = f"ended ({run['outcome']}) {ago:.0f} s ago"
        elif ago < RUN_STALE:
            state = f"running since {run['started_at']:%Y-%m-%d %H:%M:%S} UTC, last write {ago:.0f} s ago"
        else:
            state = f"stopped without ending (killed?) {ago:.0f} s ago"
        out.print(f"run {where}: {state}", markup=False, highlight=False)


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
    from .experiments.reproduce import REPRODUCTIONS, output_names, reproduce as run
    from .io.logs import make_folder

    _check_verbosity(quiet, verbose)
    if name not in REPRODUCTIONS:
        raise typer.BadParameter(f"{name!r} is not one of {', '.join(REPRODUCTIONS)}", param_hint="NAME")
    if name != "clust" and (workers is not None or scheduler is not None):
        raise typer.BadParameter("--workers and --scheduler apply to clust only (the others run in this process)")
    out_dir = out_dir or Path("reproduction") / name
    options, note = {}, None
    if name == "clust":  # its resumable store lives in the folder itself, outside the staged outputs
        make_folder(out_dir)
        options = {"workers": workers, "scheduler": scheduler, "store": out_dir / "clust.duckdb"}
        note = f"finished sweep jobs are saved in {options['store']}; run the same command again to run the rest"
    with output.staged_folder(out_dir, output_names(name), what=f"{name} reproduction", overwrite=True,
                              note=note) as stage:
        with _sweep_progress(quiet, verbose, label=name) as tick:
            result = run(name, stage.path, runs=runs, progress=tick, **options)
    if not quiet:
        out.print(result.table_markdown, markup=False, highlight=False)
        written = [*result.figures, result.table, stage.path / f"{name}.md", stage.path / f"{name}.json"]
        out.print(f"wrote {', '.join(str(stage.final_path(p)) for p in written)}", markup=False, highlight=False,
                  soft_wrap=True)


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
    scheduler: Optional[str] = DASK_SCHEDULER_OPTION,
    workers: Optional[int] = LOCAL_WORKERS_OPTION,
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
    from ._json import write_json
    from .experiments.accuracy import PLANNING_PER_CELL, markdown, run_benchmark
    from .experiments.plan import fit_plan

    def plan(summary, command, folder) -> list[Path]:
        try:
            # ln N and ln N ln T are only told apart from ln T by the planning grid (the suite's budgets
            # raise N and T together)
            return [write_json(fit_plan(summary["records"] + summary["planning"], source=command,
                                        swarm_terms=2 if summary["planning"] else 0).to_json(), folder / "plan.json")]
        except SwarmtopoError as exc:
            _warn(f"no plan.json: {exc}", quiet)
            return []

    _bench_report("accuracy", out_dir, store, quiet, verbose, markdown, extra_files=("plan.json",), extra=plan,
                  run=lambda tick: run_benchmark(store, quick=quick, scheduler=scheduler, workers=workers,
                                                 progress=tick, planning_per_cell=0 if quick else PLANNING_PER_CELL))


def _bench_report(name: str, out_dir: Path, store: Path, quiet: bool, verbose: bool, markdown, run,
                  extra_files: tuple[str, ...] = (), extra=None) -> None:
    """Run a benchmark (``run(progress)`` -> its summary) into ``out_dir``: NAME.json, NAME.md
    (``markdown(summary, command)``, also printed) and what ``extra(summary, command, folder)``
    writes, the folder staged before the maps (an unwritable --out fails at once); the store
    is never staged: it resumes."""
    import shlex
    import time

    from ._json import write_json

    _check_verbosity(quiet, verbose)
    command = "swarmtopo " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    start = time.perf_counter()
    with output.staged_folder(out_dir, (f"{name}.json", f"{name}.md", *extra_files), what=f"{name} report",
                              overwrite=True, note=f"finished maps are saved in {store}; run the same command "
                                                   "again to run the rest") as stage:
        with _sweep_progress(quiet, verbose, label=name) as tick:
            summary = run(tick)
        summary["wall_seconds"] = time.perf_counter() - start
        text = markdown(summary, command)
        written = [write_json(summary, stage.path / f"{name}.json")]
        (stage.path / f"{name}.md").write_text(text, encoding="utf-8")
        written.append(stage.path / f"{name}.md")
        if extra is not None:
            written += extra(summary, command, stage.path)
    if not quiet:
        out.print(text, markup=False, highlight=False, soft_wrap=True)
        out.print(f"wrote {', '.join(str(stage.final_path(p)) for p in written)}", markup=False, highlight=False,
                  soft_wrap=True)


def _plan_input_option(value: str) -> str:
    from .experiments.plan import SHIPPED_PLANS

    if value not in SHIPPED_PLANS:
        raise typer.BadParameter(f"{value!r} is not one of {', '.join(map(repr, SHIPPED_PLANS))}")
    return value


@bench_app.command("exploration", epilog="Example: swarmtopo bench exploration --quick --store exploration.duckdb "
                                         "--workers 2  (run it again after Ctrl-C: finished maps are kept)")
def bench_exploration(
    quick: bool = typer.Option(False, "--quick", help="2 cases per cell instead of 12."),
    store: Path = typer.Option(Path("exploration.duckdb"), "--store", help="DuckDB result store (resumable)."),
    out_dir: Path = typer.Option(Path("exploration"), "--out", help="Folder for exploration.md and exploration.json."),
    scheduler: Optional[str] = DASK_SCHEDULER_OPTION,
    workers: Optional[int] = LOCAL_WORKERS_OPTION,
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """How well beacon-led exploration maps halls bigger than the swarm.

    Simulates long halls (2.4-3.6 m x 0.5-0.7 m, 1-4 holes of mixed shapes) swept once
    by a leader at 2 mm/s with 200-400 agents on a 250-400 mm leash; maps each log
    stripped of ground truth on Dask; prints the share of exact global beta_1 and the
    error of the holes' estimated positions.
    """
    from .experiments.exploration import markdown, run_benchmark

    _bench_report("exploration", out_dir, store, quiet, verbose, markdown,
                  run=lambda tick: run_benchmark(store, quick=quick, scheduler=scheduler, workers=workers,
                                                 progress=tick))


@bench_app.command("motion", epilog="Example: swarmtopo bench motion --quick --store motion.duckdb --workers 2  "
                                    "(run it again after Ctrl-C: finished maps are kept)")
def bench_motion(
    quick: bool = typer.Option(False, "--quick", help="2 cases per cell instead of 12."),
    split: str = typer.Option("reporting", "--split", help="reporting, or tuning (cases of their own seeds)."),
    store: Path = typer.Option(Path("motion.duckdb"), "--store", help="DuckDB result store (resumable)."),
    out_dir: Path = typer.Option(Path("motion"), "--out", help="Folder for motion.md and motion.json."),
    scheduler: Optional[str] = DASK_SCHEDULER_OPTION,
    workers: Optional[int] = LOCAL_WORKERS_OPTION,
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """How well swarms that are not cockroaches are mapped, from their encounters alone.

    Simulates the accuracy benchmark's arenas (0-3 holes, 300 agents x 40 s) walked by
    cockroach, billiard, run-and-tumble, Brownian, Levy-walk and flocking swarms with
    parameters drawn per case; maps each log's encounters only (no status, no speeds,
    no model named) on Dask; prints the share of exact maps per model and cell, the
    regime each log was read as, and confident false holes.
    """
    from .experiments.motion_models import markdown, run_benchmark

    if split not in ("reporting", "tuning"):
        raise typer.BadParameter("must be reporting or tuning", param_hint="--split")
    _bench_report("motion", out_dir, store, quiet, verbose, markdown,
                  run=lambda tick: run_benchmark(store, quick=quick, split=split, scheduler=scheduler,
                                                 workers=workers, progress=tick))


@bench_app.command("faults", epilog="Example: swarmtopo bench faults --quick --store faults.duckdb --workers 2  "
                                    "(run it again after Ctrl-C: finished maps are kept)")
def bench_faults(
    quick: bool = typer.Option(False, "--quick", help="1 case per hole count and level instead of 4 (10 for faults "
                                                      "together)."),
    split: str = typer.Option("reporting", "--split", help="reporting, or tuning (cases of their own seeds)."),
    store: Path = typer.Option(Path("faults.duckdb"), "--store", help="DuckDB result store (resumable)."),
    out_dir: Path = typer.Option(Path("faults"), "--out", help="Folder for faults.md, faults.json and faults.png."),
    scheduler: Optional[str] = DASK_SCHEDULER_OPTION,
    workers: Optional[int] = LOCAL_WORKERS_OPTION,
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """How the map degrades when the radio loses, invents, delays and duplicates reports.

    Simulates the accuracy benchmark's arenas (0-3 holes, 300 cockroaches x 40 s), passes
    each log through a faulty radio at every level of a grid (lost 15-60 %, outages, false
    encounters 0.5-5 %, jitter 0.25-2 s, clock offsets 1-5 s, 10-30 % of agents dying,
    duplicates, and faults together), maps the encounters only on Dask; prints per level
    the share of exact maps, the confidence's Brier score against a constant, confidently
    wrong maps and the logs read as faulty, and plots the curves (faults.png).
    """
    from .experiments.faults import markdown, plot, run_benchmark

    if split not in ("reporting", "tuning"):
        raise typer.BadParameter("must be reporting or tuning", param_hint="--split")

    def figure(summary, command, folder):
        plot(summary, folder / "faults.png")
        return [folder / "faults.png"]

    _bench_report("faults", out_dir, store, quiet, verbose, markdown, extra_files=("faults.png",), extra=figure,
                  run=lambda tick: run_benchmark(store, quick=quick, split=split, scheduler=scheduler,
                                                 workers=workers, progress=tick))


@bench_app.command("timeline", epilog="Example: swarmtopo bench timeline --quick --store timeline.duckdb --workers 2  "
                                      "(run it again after Ctrl-C: finished maps are kept)")
def bench_timeline(
    quick: bool = typer.Option(False, "--quick", help="5 cases per cell instead of 20."),
    store: Path = typer.Option(Path("timeline.duckdb"), "--store", help="DuckDB result store (resumable)."),
    out_dir: Path = typer.Option(Path("timeline"), "--out", help="Folder for timeline.md and timeline.json."),
    scheduler: Optional[str] = DASK_SCHEDULER_OPTION,
    workers: Optional[int] = LOCAL_WORKERS_OPTION,
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help=VERBOSE_HELP),
) -> None:
    """How well the map's timeline finds changes of the arena, and how rarely it invents them.

    Simulates arenas where a hole appears, a hole disappears or a door closes at a
    random time (200-400 agents, 120-300 s), and static controls; maps each log
    stripped of ground truth on Dask; prints the share of changes found (within 15 s),
    the error of the change time, and the false change points.
    """
    from .experiments.timeline import markdown, run_benchmark

    _bench_report("timeline", out_dir, store, quiet, verbose, markdown,
                  run=lambda tick: run_benchmark(store, quick=quick, scheduler=scheduler, workers=workers,
                                                 progress=tick))


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
    ('swarmtopo bench accuracy'; see the project's documentation, docs/accuracy.md in the
    source repository).
    """
    from .pipeline.regions import MIN_REGION_AGENTS
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


def _run_map(log, config, log_dir: Path, out_dir: Path, quiet: bool, verbose: bool = False, reader=None,
             ground_truth=None, engine=None):
    """Map, write map.json and figures; ground truth beside the log only colours pictures,
    and a broken ground-truth file costs a warning, never the map.  ``ground_truth``
    (arena, truth, trajectories): the caller's, instead of reading them beside the log;
    ``engine``: map_encounters' ``workers`` / ``scheduler``."""
    from .pipeline import STAGES, map_encounters
    from .viz.report import write_map

    with _progress("mapping", quiet) as tick:
        try:
            tmap = map_encounters(log, config, reader=reader, **(engine or {}),
                                  progress=lambda stage: tick(STAGES.index(stage) / len(STAGES)))
        except SwarmtopoError as exc:
            if getattr(exc, "file", None):  # already names its file
                raise
            raise SwarmtopoError(f"{log_dir}: {exc}") from None
        tick(1.0)
    if verbose:
        _map_details(tmap)
    arena, truth, trajectories = ground_truth or _ground_truth(log, log_dir, quiet)
    return tmap, write_map(tmap, out_dir, log=log, truth=truth, arena=arena, trajectories=trajectories)


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
    from .io.arenas import read_arena
    from .io.logs import read_trajectories, read_truth

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
    """The map's answer, one line per fact (never wrapped, even in a pipe)."""
    from .viz.summary import advice
    from .viz.text import format_confidence

    def say(text: str) -> None:
        out.print(text, markup=False, highlight=False, soft_wrap=True)

    def confidence(n):
        p = tmap.confidence.get(n)
        return "" if p is None else f" ({format_confidence(p)} confidence)"

    est = ", ".join(f"beta_{n} = {b}{confidence(n)}" if b is not None else
                    f"beta_{n} not estimated (the classifier has no threshold for it)"
                    for n, b in sorted(tmap.betti.items()))
    timeline = tmap.timeline
    if tmap.exploration is not None and tmap.exploration.betti[1] is not None:  # its timeline's changes are holes
        # coming into the swarm's view and leaving it
        found = tmap.exploration
        say(f"recovered: {est} (global map along the leader's path: {len(found.windows)} local maps, each hole "
            "counted once; its confidence is not calibrated)")
        for i, h in enumerate(found.holes, 1):
            say(f"hole {i}:    at ({h.x:.0f}, {h.y:.0f}) mm, within {h.radius:.0f} mm (in view {h.t_in:.0f}-"
                f"{h.t_out:.0f} s{', at an end of the path' if h.open else ''})")
        timeline = None
    elif timeline is not None and timeline.changes:
        say(f"recovered: the arena changed: {timeline.summary()}")
        for c in timeline.changes:
            sure = "" if c.confidence is None else f"; {format_confidence(c.confidence)} confidence"
            say(f"change:    beta_{c.dim} from {c.before} to {c.after} at about {c.t:.0f} s "
                f"(between {c.lo:.0f} and {c.hi:.0f} s{sure})")
        say(f"pooled:    {est}, over the whole log (mixing before and after)")
    else:
        say(f"recovered: {est}")
        if timeline is not None:
            say(f"timeline:  {timeline.note or timeline.summary()}")
    if truth is not None:
        say(f"true:      {truth}")
    for warning in tmap.warnings:
        if timeline is not None and timeline.changes and warning.startswith("the Betti numbers changed"):
            continue  # said above
        say(f"warning: {warning}")
    for line in advice(tmap):
        say(f"advice: {line}")
    for small in tmap.too_little_data:
        say(f"note: {small['events']} encounter(s) of {small['agents']} agent(s) never linked to the rest: too little "
            "data, not counted as a region")


def main() -> None:
    """Entry point: one-line errors; exit 1 for bad input, 2 for bad usage."""
    try:
        code = app(standalone_mode=False)
    except _Interrupt as exc:
        err.print(str(exc), markup=False, highlight=False, soft_wrap=True)
        sys.exit(130)
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
