"""What ``swarmtopo map`` and ``swarmtopo demo`` write: map.json, report.html and PNG figures.

Ground truth (true positions, the arena) only colours pictures here; it never
reaches :func:`swarmtopo.pipeline.map.map_encounters`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._json import write_json
from ..io.logs import make_folder
from ..log import EncounterLog
from ..pipeline.result import TopologicalMap
from .summary import map_json
from .report_html import write_report

MAP_FILES = ("map.json", "report.html", "diagram.png", "cloud.png")
"""Every file :func:`write_map` may write: a map's output folder holds these."""


def write_map(tmap: TopologicalMap, out_dir: Path, *, log: EncounterLog,
                      truth: dict[str, np.ndarray] | None = None, arena=None,
                      trajectories: dict[str, np.ndarray] | None = None) -> list[Path]:
    """Write map.json, report.html, diagram.png and (with an MDS picture) cloud.png; return the paths.

    ``trajectories`` (``io.read_trajectories``) adds the swarm animation to the report.
    A :class:`~swarmtopo.changing.ChangingArena` is drawn as it is at the log's last
    event, and the report's timeline shows its true Betti numbers over time.
    """
    from ..changing import ChangingArena, betti_timeline_of

    true_timeline = None
    if isinstance(arena, ChangingArena):  # pictures draw the arena at the log's end; the verdict its timeline
        true_timeline = betti_timeline_of(arena, float(log.t.max()) if log.n_events else 0.0)
        arena = arena.at(float(log.t.max()) if log.n_events else 0.0)
    out_dir = Path(out_dir)
    make_folder(out_dir)
    written = [out_dir / "map.json", out_dir / "report.html", out_dir / "diagram.png"]
    doc = map_json(tmap)  # one document for map.json and the report: they cannot disagree
    write_json(doc, written[0])
    write_report(tmap, written[1], log=log, truth=truth, arena=arena, trajectories=trajectories, doc=doc,
                 true_timeline=true_timeline)
    _diagram_figure(tmap).savefig(written[2], dpi=110)
    if any(r.embedding is not None for r in tmap.regions):
        written.append(out_dir / "cloud.png")
        _cloud_figure(tmap, log, truth, arena).savefig(written[-1], dpi=110)
    return written


def _diagram_figure(tmap: TopologicalMap):
    from .plots import new_figure, plot_barcode, plot_diagram

    rows = len(tmap.regions)
    fig = new_figure(10, 4.5 * rows)
    axes = fig.subplots(rows, 2, squeeze=False)
    for (ax_d, ax_b), region in zip(axes, tmap.regions):
        lengths = region.thresholds
        name = f"region {region.component}: " if rows > 1 else ""
        betti = ", ".join(f"beta_{n}={b}" for n, b in sorted(region.betti.items()))
        plot_diagram(region.diagram, ax_d, thresholds=lengths, title=f"{name}persistence diagram ({betti})")
        plot_barcode(region.diagram, ax_b, thresholds=lengths, title=f"{name}barcode")
    return fig


def _cloud_figure(tmap: TopologicalMap, log: EncounterLog, truth, arena):
    from ..topology.cycles import event_positions
    from .plots import new_figure, plot_cycles, plot_point_cloud, position_colors

    with_truth = truth is not None
    rows = len(tmap.regions)
    cols = 3 if with_truth and arena is not None else (2 if with_truth else 1)
    fig = new_figure(5.2 * cols, 4.8 * rows)
    dim = tmap.config.embed_dim
    for r, region in enumerate(tmap.regions):
        if region.embedding is None:
            continue
        coords = region.embedding.coords
        events = region.landmark_events
        ax = fig.add_subplot(rows, cols, r * cols + 1, projection="3d" if dim == 3 else None)
        plot_point_cloud(coords, log.t[events], ax, label="event time (s)",
                         title=f"landmarks in encounter space (stress {region.embedding.stress:.2f})")
        if not with_truth:
            continue
        xy = event_positions(truth, events)
        bounds = arena.bounds if arena is not None else (*xy.min(axis=0), *xy.max(axis=0))
        colors = position_colors(xy, bounds)
        ax = fig.add_subplot(rows, cols, r * cols + 2, projection="3d" if dim == 3 else None)
        plot_point_cloud(coords, colors, ax, title="coloured by true position")
        if arena is not None:
            plot_cycles(arena, [event_positions(truth, c.events) for c in region.cycles],
                        fig.add_subplot(rows, cols, r * cols + 3), points=xy, color=colors,
                        title="landmark events at true positions" + (", holes' loops" if region.cycles else ""))
    return fig
