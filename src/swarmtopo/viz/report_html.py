"""The self-contained HTML report (``report.html`` beside ``map.json``).

One file that opens offline: plotly.js is bundled inline (``<script id="plotly-js">``)
and nothing else is loaded -- no remote script, style, font or image.  Sections, in
order: the verdict (Betti numbers with their confidence, the true ones when the
arena is known), the persistence diagram and barcode with the classifier's threshold,
the 3-D MDS encounter point cloud (coloured by event time and, with ground truth, by
true position), the cycles at true positions on the arena (ground truth), an
animation of the swarm (simulations with trajectories), then parameters and timings.

Every number shown comes from ``viz.summary.map_json(tmap)`` -- the map.json document -- so the
report and map.json cannot disagree.

Untrusted input.  Agent IDs and ``meta.json`` come from whoever wrote the log.  In
HTML they pass through :func:`html.escape`; in plotly hover text (which plotly reads
as its own small HTML dialect) they are escaped too, so plotly shows them as text;
and every figure travels as JSON in a ``<script type="application/json">`` block
written by :func:`script_json`, which escapes ``<``, ``>``, ``&``, ``/`` and U+2028/9,
so no string can close the block.
"""

from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np

from ..changing import timeline_text
from ..topology.cycles import encircled_obstacles, event_positions
from ..log import STATES, EncounterLog
from ..pipeline.exploration import reach
from ..pipeline.result import TopologicalMap
from .summary import map_json
from .plots import position_colors
from .text import format_confidence

MAX_ANIMATION_AGENTS = 120
"""Agents drawn in the swarm animation (evenly spaced among the sampled agents)."""
MAX_ANIMATION_FRAMES = 60
"""Frames of the swarm animation (evenly spaced among the sampled times)."""
MAX_BARS = 60
"""Longest bars per dimension drawn in the barcode."""

_DIM_COLORS = {0: "#1f77b4", 1: "#d62728", 2: "#2ca02c"}
_STATE_COLORS = {"RW": "#1f77b4", "WF": "#ff7f0e", "S": "#7f7f7f"}
_LOOP_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf")
_SCRIPT_ESCAPES = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "/": "\\/",
                   "\u2028": "\\u2028", "\u2029": "\\u2029"}

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:0 auto;max-width:1200px;
padding:1em 2em;color:#222;line-height:1.4}
h1{margin-bottom:.2em}h2{border-bottom:1px solid #ddd;padding-bottom:.2em;margin-top:1.6em}
#verdict .betti-line{font-size:1.6em;margin:.3em 0}
.truth{color:#555}.ok{color:#1a7f37;font-weight:600}.bad{color:#c62828;font-weight:600}
.warning{color:#b35c00}
table{border-collapse:collapse;margin:.5em 0 1em}td,th{border:1px solid #ddd;padding:.25em .6em;text-align:left;
vertical-align:top}th{background:#f5f5f5}td.num{text-align:right;font-variant-numeric:tabular-nums}
.plot{width:100%;min-height:420px}.note{color:#555;font-size:.92em}
code{background:#f5f5f5;padding:0 .2em}
"""


def write_report(tmap: TopologicalMap, path, *, log: EncounterLog, truth: dict | None = None, arena=None,
                 trajectories: dict | None = None, doc: dict | None = None, true_timeline: list | None = None) -> Path:
    """Write :func:`report_html` to ``path`` (UTF-8) and return the path."""
    path = Path(path)
    path.write_text(report_html(tmap, log=log, truth=truth, arena=arena, trajectories=trajectories, doc=doc,
                                true_timeline=true_timeline), encoding="utf-8")
    return path


def report_html(tmap: TopologicalMap, *, log: EncounterLog, truth: dict | None = None, arena=None,
                trajectories: dict | None = None, doc: dict | None = None, true_timeline: list | None = None) -> str:
    """The report as one HTML document (see the module docstring).

    Parameters
    ----------
    tmap
        The map; its numbers are taken from ``viz.summary.map_json(tmap)``.
    log
        The mapped log (event times and agent IDs for hover text, ``meta``).
    truth
        Ground truth per event (``io.read_truth``), aligned with ``log``: true
        positions of the landmark events and cycles.  Pictures only.
    arena
        The true arena: true Betti numbers in the verdict, arena in the pictures.
    trajectories
        Sampled true positions (``io.read_trajectories``): the swarm animation.
    doc
        ``viz.summary.map_json(tmap)`` when the caller already has it (the map.json it writes).
    true_timeline
        The true Betti numbers over time of an arena that changed
        (:func:`swarmtopo.changing.betti_timeline_of`): drawn on the timeline, and the
        verdict gives them instead of comparing the pooled answer with one arena.
    """
    from plotly.offline import get_plotlyjs

    doc = doc or map_json(tmap)
    figures: dict[str, dict] = {}
    sections = [
        _verdict_section(doc, None if true_timeline else arena, true_timeline),
        _exploration_section(doc, figures, arena),
        _timeline_section(doc, figures, true_timeline),
        _persistence_section(tmap, doc, figures),
        _cloud_section(tmap, log, truth, arena, figures),
    ]
    if truth is not None:
        sections.append(_arena_section(tmap, truth, arena, figures))
    if trajectories is not None and len(trajectories["t"]):
        sections.append(_animation_section(trajectories, arena, figures))
    sections.append(_parameters_section(doc, log))
    figure_blocks = "\n".join(
        f'<script type="application/json" class="figure" data-target="{html.escape(key)}">'
        f"{script_json(fig)}</script>" for key, fig in figures.items())
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>swarmtopo map report</title>
<style>{_CSS}</style>
<script id="plotly-js">{get_plotlyjs()}</script>
</head>
<body>
<h1>swarmtopo map</h1>
<p class="note">{doc["log"]["events"]} encounter events of {doc["log"]["agents"]} agents;
swarmtopo {html.escape(str(doc["software"].get("swarmtopo", "")))}.
Pictures are interactive: drag to rotate or pan, scroll to zoom, hover for details.</p>
{"".join(sections)}
{figure_blocks}
<script>
(function () {{
  var pending = [];
  document.querySelectorAll('script.figure').forEach(function (block) {{
    var fig = JSON.parse(block.textContent);
    pending.push(Plotly.newPlot(block.dataset.target, fig));
  }});
  Promise.all(pending).then(function () {{ document.body.dataset.plotsReady = 'true'; }},
    function (error) {{ console.error('a figure failed to draw:', error); }});
}})();
</script>
</body>
</html>
"""


def script_json(obj) -> str:
    """JSON text that is safe inside a ``<script>`` element.

    ``<``, ``>``, ``&``, ``/`` and the line separators U+2028/9 are written as
    escapes, so ``</script>`` or ``<!--`` in any string cannot end the element;
    ``json.loads`` (and ``JSON.parse``) give back exactly ``obj``.
    """
    text = json.dumps(obj, allow_nan=False, separators=(",", ":"), ensure_ascii=False)
    for char, escape in _SCRIPT_ESCAPES.items():  # no escape contains a char escaped here: order is free
        text = text.replace(char, escape)
    return text


# -- sections ------------------------------------------------------------------------------
def _verdict_section(doc: dict, arena, true_timeline: list | None = None) -> str:
    true_betti = dict(enumerate(arena.betti)) if arena is not None else {}
    items = []
    timeline = doc.get("timeline") or {}
    for key, value in doc["betti"].items():
        n = int(key)
        conf = doc["confidence"].get(key)
        conf_html = ("no calibrated confidence" if conf is None else
                     f'<span class="confidence" data-dim="{n}" data-value="{conf!r}">{format_confidence(conf)}</span>'
                     " confidence")
        shown = "unknown" if value is None else str(value)
        items.append(f'<span class="betti" data-dim="{n}" data-value="{shown}">&beta;<sub>{n}</sub> = {shown}</span>'
                     f" ({conf_html})")
    lines = [f'<p class="betti-line">{" &nbsp;&middot;&nbsp; ".join(items)}</p>']
    if doc.get("exploration"):
        lines.insert(0, f'<p class="explored">{html.escape(doc["exploration"]["summary"])} '
                        '(<a href="#exploration">exploration</a>):</p>')
    elif timeline.get("changes"):
        lines.insert(0, f'<p class="changed">the arena changed: {html.escape(timeline["summary"])} '
                        '(<a href="#timeline">timeline</a>); pooled over the whole log:</p>')
    if true_timeline:
        lines.append(f'<p class="truth">true (from the arena): {html.escape(timeline_text(true_timeline))}</p>')
    if true_betti:
        agree = all(doc["betti"].get(str(n)) == b for n, b in true_betti.items())
        truth_items = ", ".join(f'<span class="true-betti" data-dim="{n}" data-value="{b}">&beta;<sub>{n}</sub> = {b}'
                                "</span>" for n, b in true_betti.items())
        verdict = '<span class="ok">the map is right</span>' if agree else '<span class="bad">the map is wrong</span>'
        lines.append(f'<p class="truth">true (from the arena): {truth_items} &mdash; {verdict}</p>')
    holes = ("loops of the contact graph (groups linked in a cycle with no shortcut across it: not physical holes; "
             "see the project's documentation, docs/real-data.md in the source repository)"
             if doc["log"].get("contact_trace") else "holes (obstacles)")
    lines.append(f'<p class="note">&beta;<sub>0</sub> counts connected regions, &beta;<sub>1</sub> {holes}; '
                 "a confidence is the calibrated probability that the number is right.</p>")
    if doc.get("motion"):
        lines.append(f'<p class="motion" data-regime="{doc["motion"]["regime"]}">'
                     f'{html.escape(doc["motion"]["summary"])}</p>')
    if doc.get("sensing"):
        lines.append(f'<p class="sensing" data-suspected="{str(doc["sensing"]["suspected"]).lower()}">'
                     f'{html.escape(doc["sensing"]["summary"])}</p>')
    for warning in doc["warnings"]:
        lines.append(f'<p class="warning">warning: {html.escape(warning)}</p>')
    for small in doc["too_little_data"]:
        lines.append(f'<p class="note">{small["events"]} encounter(s) of {small["agents"]} agent(s) never linked '
                     "to the rest: too little data, not counted as a region.</p>")
    if len(doc["regions"]) > 1:
        lines.append(_regions_table(doc))
    return f'<section id="verdict"><h2>Verdict</h2>\n{"".join(lines)}</section>\n'


def _exploration_section(doc: dict, figures: dict, arena) -> str:
    """A beacon-led log's global map: the leader's path, the area within its leash, the
    local maps' counts where the leader was, and each hole's estimated position."""
    found = doc.get("exploration")
    if not found:
        return ""
    figures["plot-exploration"] = _exploration_figure(found, arena)
    rows = "".join(f'<tr><td>{i}</td><td class="num">({h["x"]:.0f}, {h["y"]:.0f}) mm</td>'
                   f'<td class="num">{h["radius"]:.0f} mm</td><td class="num">{h["in_view"][0]:.0f}-'
                   f'{h["in_view"][1]:.0f} s</td><td class="num">{h["windows"]}</td>'
                   f'<td>{"at an end of the path" if h["open"] else ""}</td></tr>'
                   for i, h in enumerate(found["holes"], 1))
    table = ("<table><tr><th>hole</th><th>estimated position</th><th>within</th><th>in view</th><th>local maps</th>"
             f"<th></th></tr>{rows}</table>") if rows else '<p class="note">No hole was seen along the path.</p>'
    return ('<section id="exploration"><h2>Exploration: the global map</h2>\n'
            f'<p class="note">A leader moved at {found["leader_speed"]:.3g} mm/s with the swarm on a leash of '
            f'R = {found["leash"]:g} mm; {len(found["windows"])} local maps of {found["length"]:.3g} s each (every '
            f'{found["step"]:.3g} s) counted the holes in the swarm\'s view. A hole is counted once, from when it came '
            "into view to when it left, and placed on the leader's path R behind where the leader was when it left "
            "the swarm's view (the leash is the swarm's trailing edge; a hole still in view at the end: halfway "
            "along its time in view; docs/exploration.md in the source repository). "
            f'Shaded: within R of the leader at its local maps (within R of its whole path: '
            f'{found["coverage_mm2"] / 1e6:.2f} m&sup2;), what the swarm can have seen'
            f'{"; grey: the true arena" if arena is not None else ""}.</p>{table}'
            '<div id="plot-exploration" class="plot" style="height:520px"></div></section>\n')


def _exploration_figure(found: dict, arena) -> dict:
    data = _arena_traces(arena) if arena is not None else []
    path = np.asarray([w["leader"] for w in found["windows"]], dtype=float).reshape(-1, 2)
    if len(path):
        for poly in getattr(area := reach(path, found["leash"]), "geoms", [area]):
            x, y = poly.exterior.xy
            data.append({"type": "scatter", "x": _floats(x, 1), "y": _floats(y, 1), "fill": "toself", "mode": "lines",
                         "fillcolor": "rgba(31,119,180,0.12)", "line": {"color": "rgba(31,119,180,0.4)", "width": 1},
                         "name": "within the leash of the path", "hoverinfo": "skip"})
        data.append({"type": "scatter", "mode": "lines+markers", "x": _floats(path[:, 0], 1),
                     "y": _floats(path[:, 1], 1), "name": "leader at each local map",
                     "line": {"color": "#1f77b4", "width": 2},
                     "marker": {"color": [w["beta_1"] for w in found["windows"]], "colorscale": "Viridis", "size": 7,
                                "colorbar": {"title": {"text": "holes in view"}, "len": 0.6}},
                     "text": [f'{w["t0"]:.0f}-{w["t1"]:.0f} s: {w["beta_1"]} hole(s) in view' for w in found["windows"]],
                     "hovertemplate": "%{text}<extra></extra>"})
    theta = np.linspace(0, 2 * np.pi, 65)
    for i, h in enumerate(found["holes"], 1):
        color = _LOOP_COLORS[(i - 1) % len(_LOOP_COLORS)]
        data.append({"type": "scatter", "mode": "lines", "x": _floats(h["x"] + h["radius"] * np.cos(theta), 1),
                     "y": _floats(h["y"] + h["radius"] * np.sin(theta), 1), "line": {"color": color, "dash": "dot"},
                     "name": f"hole {i}: within {h['radius']:.0f} mm", "hoverinfo": "skip"})
        data.append({"type": "scatter", "mode": "markers", "x": [h["x"]], "y": [h["y"]], "name": f"hole {i}",
                     "marker": {"color": color, "size": 14, "symbol": "x", "line": {"color": "black", "width": 1}},
                     "hovertemplate": f"hole {i} at (%{{x:.0f}}, %{{y:.0f}}) mm<extra></extra>"})
    return {"data": data, "layout": _plane_layout(arena, 520), "config": {"displaylogo": False, "responsive": True}}


def _timeline_section(doc: dict, figures: dict, true_timeline: list | None) -> str:
    timeline = doc.get("timeline")
    if not timeline or not timeline["windows"]:
        note = (timeline or {}).get("note") or "no timeline"
        return f'<section id="timeline"><h2>Timeline</h2><p class="note">{html.escape(note)}</p></section>\n'
    figures["plot-timeline"] = _timeline_figure(timeline, true_timeline)
    rows = "".join(
        f'<tr class="change" data-dim="{c["dimension"]}" data-t="{c["t"]!r}"><td>&beta;<sub>{c["dimension"]}</sub></td>'
        f'<td class="num">{c["from"]} &rarr; {c["to"]}</td><td class="num">{c["t"]:.0f} s</td>'
        f'<td class="num">{c["interval"][0]:.0f}&ndash;{c["interval"][1]:.0f} s</td>'
        f'<td class="num">{"&ndash;" if c["confidence"] is None else format_confidence(c["confidence"])}</td></tr>'
        for c in timeline["changes"])
    table = ("<table><tr><th>dimension</th><th>change</th><th>at about</th><th>within</th><th>confidence</th></tr>"
             f"{rows}</table>" if rows else "")
    return ('<section id="timeline"><h2>Timeline</h2>\n'
            f'<p class="timeline-summary">{html.escape(timeline["summary"])}</p>{table}'
            f'<p class="note">Top: the Betti numbers of each time window ({_lengths(timeline["windows"])} long) at its '
            "middle; the band around each is 1 &minus; its confidence wide on either "
            "side (thin: sure); thick lines are the segments, shaded bars the change points' intervals"
            f'{", dashed lines the true numbers" if true_timeline else ""}. Bottom (a CROCKER plot): for each window, '
            "how many H1 bars are longer than a multiple of the window's median H1 bar (its typical noise loop): "
            "the holes are the bands that run high along time; a hole that appears starts a new band.</p>"
            '<div id="plot-timeline" class="plot" style="height:640px"></div></section>\n')


def _lengths(windows: list[dict]) -> str:
    """The range of the windows' lengths, e.g. "12.6-21 s"."""
    lengths = [w["t1"] - w["t0"] for w in windows]
    lo, hi = min(lengths), max(lengths)
    return f"{lo:.3g} s" if f"{lo:.3g}" == f"{hi:.3g}" else f"{lo:.3g}-{hi:.3g} s"


def _timeline_figure(timeline: dict, true_timeline: list | None) -> dict:
    """Betti numbers per window with their confidence band, segments and change points
    (top); the windows' H1 bar counts over scale-free lengths, a CROCKER plot (bottom)."""
    windows = timeline["windows"]
    t = _floats([(w["t0"] + w["t1"]) / 2 for w in windows], 4)
    colors = {"0": "#1f77b4", "1": "#d62728", "2": "#2ca02c"}
    traces, shapes = [], []
    for n in sorted({n for w in windows for n in w["betti"]}):
        windows_n = [w for w in windows if n in w["betti"]]
        t_n = _floats([(w["t0"] + w["t1"]) / 2 for w in windows_n], 4)
        values = [w["betti"][n] for w in windows_n]
        width = [1 - (w["confidence"].get(n) if w["confidence"].get(n) is not None else 0.5) for w in windows_n]
        upper = [v + d for v, d in zip(values, width)]
        lower = [v - d for v, d in zip(values, width)]
        color = colors.get(n, "#555555")
        traces.append({"type": "scatter", "x": t_n + t_n[::-1], "y": _floats(upper + lower[::-1], 4), "fill": "toself",
                       "fillcolor": color, "opacity": 0.18, "line": {"width": 0}, "hoverinfo": "skip",
                       "showlegend": False, "xaxis": "x", "yaxis": "y"})
        traces.append({"type": "scatter", "mode": "markers", "x": t_n, "y": values, "name": f"beta_{n} per window",
                       "marker": {"color": color, "size": 7},
                       "text": [f"{w['t0']:.1f}-{w['t1']:.1f} s, confidence "
                                f"{'none' if w['confidence'].get(n) is None else format_confidence(w['confidence'][n])}"
                                for w in windows_n], "xaxis": "x", "yaxis": "y"})
        for seg in timeline["segments"].get(n, []):
            traces.append({"type": "scatter", "mode": "lines", "x": _floats([seg["from"], seg["until"]], 4),
                           "y": [seg["value"], seg["value"]], "line": {"color": color, "width": 4},
                           "name": f"beta_{n} segment", "showlegend": False, "xaxis": "x", "yaxis": "y",
                           "hoverinfo": "skip"})
        if true_timeline and all(f"beta_{n}" in interval for interval in true_timeline):
            xs, ys = [], []
            for interval in true_timeline:
                xs += [interval["from"], interval["until"]]
                ys += [interval[f"beta_{n}"]] * 2
            traces.append({"type": "scatter", "mode": "lines", "x": _floats(xs, 4), "y": ys,
                           "line": {"color": color, "dash": "dash", "width": 1.5}, "name": f"true beta_{n}",
                           "xaxis": "x", "yaxis": "y"})
    for c in timeline["changes"]:
        shapes.append({"type": "rect", "xref": "x", "yref": "paper", "x0": c["interval"][0], "x1": c["interval"][1],
                       "y0": 0.5, "y1": 1, "fillcolor": "#ffbf00", "opacity": 0.2, "line": {"width": 0}})
        shapes.append({"type": "line", "xref": "x", "yref": "paper", "x0": c["t"], "x1": c["t"], "y0": 0, "y1": 1,
                       "line": {"color": "#b07800", "width": 2}})
    longest = max([max(w["h1_scaled_lengths"], default=0) for w in windows] + [1.0])
    levels = np.geomspace(1.0, max(longest, 1.01), 60)
    z = [[int(np.sum(np.asarray(w["h1_scaled_lengths"]) > level)) for w in windows] for level in levels]
    top = max(max(row) for row in z)
    # a contour plot (as CROCKER plots are drawn): filled SVG bands, one per whole number of bars
    # (a heatmap would be drawn through an image the page would load from a data: URL)
    traces.append({"type": "contour", "x": t, "y": _floats(levels, 4), "z": z, "colorscale": "Viridis",
                   "contours": {"coloring": "fill", "start": 0.5, "end": top + 0.5, "size": 1, "showlines": False},
                   "line": {"smoothing": 0}, "zmin": 0, "zmax": max(top, 1),
                   "colorbar": {"title": {"text": "H1 bars"}, "len": 0.4, "y": 0.2}, "xaxis": "x2", "yaxis": "y2",
                   "hovertemplate": "t %{x:.1f} s, length / median > %{y:.3g}: %{z} bars<extra></extra>"})
    return {"data": traces, "layout": {
        "height": 640, "margin": {"t": 20, "l": 60, "r": 20, "b": 50}, "shapes": shapes,
        "legend": {"orientation": "h", "y": 1.08},
        "xaxis": {"anchor": "y", "domain": [0, 1], "matches": "x2", "showticklabels": False},
        "yaxis": {"domain": [0.5, 1], "title": {"text": "Betti number"}, "dtick": 1, "rangemode": "tozero"},
        "xaxis2": {"anchor": "y2", "domain": [0, 1], "title": {"text": "time (s)"}},
        "yaxis2": {"domain": [0, 0.42], "type": "log", "title": {"text": "H1 bar length / median"}}}}


def _regions_table(doc: dict) -> str:
    rows = []
    for r in doc["regions"]:
        betti = ", ".join(f"&beta;<sub>{k}</sub> = {v}" for k, v in r["betti"].items())
        conf = ", ".join("&ndash;" if v is None else format_confidence(v) for v in r["confidence"].values())
        rows.append(f'<tr><td>{r["component"]}</td><td class="num">{r["events"]}</td><td class="num">{r["agents"]}'
                    f'</td><td class="num">{r["landmarks"]}</td><td>{betti}</td><td>{conf}</td></tr>')
    return ("<table><tr><th>region</th><th>events</th><th>agents</th><th>landmarks</th><th>Betti numbers</th>"
            f'<th>confidence</th></tr>{"".join(rows)}</table>')


def _persistence_section(tmap: TopologicalMap, doc: dict, figures: dict) -> str:
    parts = []
    for k, (region, region_doc) in enumerate(zip(tmap.regions, doc["regions"])):
        key = f"plot-persistence-{k}"
        figures[key] = _persistence_figure(region.diagram, {int(n): v for n, v in region_doc["thresholds"].items()})
        rows = "".join(
            f'<tr><td>H{n}</td><td class="num threshold" data-region="{k}" data-dim="{n}" data-value="{v!r}">'
            f"{v:.4g} s</td></tr>" for n, v in region_doc["thresholds"].items())
        title = f"<h3>region {region_doc['component']}</h3>" if len(tmap.regions) > 1 else ""
        parts.append(f'{title}<div id="{key}" class="plot"></div>'
                     "<table><tr><th>dimension</th><th>threshold: a bar counts when longer than</th></tr>"
                     f"{rows}</table>")
    return ('<section id="persistence"><h2>Persistence diagram and barcode</h2>\n'
            '<p class="note">Each point (bar) is a feature of the Vietoris-Rips filtration of the landmarks in the '
            "encounter metric, born at one scale and dead at a larger one (seconds). The dotted line (left) and "
            f"the dashed segment (right) mark the classifier's threshold {_threshold_html(tmap.classifier)} "
            "(l<sub>q</sub>: the q-quantile of the bar lengths of the window shown): bars longer than it count "
            "as holes; shorter ones are drawn faded.</p>"
            f'{"".join(parts)}</section>\n')


def _threshold_html(classifier: dict) -> str:
    """The classifier's length threshold (``describe()["threshold"]``, e.g. "tau_n l_q") in HTML."""
    text = html.escape(classifier["threshold"])
    for plain, marked in (("tau_n", "&tau;<sub>n</sub>"), ("Delta_n", "&Delta;<sub>n</sub>"), ("l_q", "l<sub>q</sub>")):
        text = text.replace(plain, marked)
    return text


def _cloud_section(tmap: TopologicalMap, log: EncounterLog, truth, arena, figures: dict) -> str:
    parts = []
    for k, region in enumerate(tmap.regions):
        if region.embedding is None:
            continue
        key = f"plot-cloud-{k}"
        figures[key] = _cloud_figure(region, log, truth, arena)
        title = f"<h3>region {region.component}</h3>" if len(tmap.regions) > 1 else ""
        parts.append(f'{title}<div id="{key}" class="plot cloud" style="height:520px"></div>'
                     f'<p class="note">MDS stress {region.embedding.stress:.3f} (0 = distances kept exactly).</p>')
    if not parts:
        return ""
    colouring = " and (right) by true position" if truth is not None else ""
    loop = "A loop of the contact graph" if tmap.contact_trace else "A hole in the arena"
    return ('<section id="cloud"><h2>Encounter point cloud</h2>\n'
            f'<p class="note">The landmarks in the encounter metric, embedded by MDS, coloured by event time'
            f"{colouring}. {loop} shows as a loop in this cloud.</p>"
            f'{"".join(parts)}</section>\n')


def _arena_section(tmap: TopologicalMap, truth: dict, arena, figures: dict) -> str:
    parts = []
    for k, region in enumerate(tmap.regions):
        key = f"plot-arena-{k}"
        loops = [event_positions(truth, cycle.events) for cycle in region.cycles]
        figures[key] = _arena_figure(region, loops, truth, arena)
        rows = []
        for c, (cycle, loop) in enumerate(zip(region.cycles, loops)):
            b, d = cycle.bar
            where = ""
            if arena is not None:
                found = encircled_obstacles(loop, arena)
                where = ("encircles no obstacle" if not found else
                         "encircles obstacle" + ("s " if len(found) > 1 else " ") + ", ".join(map(str, found)))
            death = f"{d:.4g}" if np.isfinite(d) else "&infin;"
            rows.append(f'<tr><td>{c}</td><td class="num">[{b:.4g}, {death}) s</td>'
                        f'<td class="num">{len(cycle.landmarks)}</td><td class="num">{cycle.length:.4g} s</td>'
                        f"<td>{where}</td></tr>")
        table = ("<table><tr><th>loop</th><th>bar</th><th>landmarks</th><th>length</th><th>at true positions</th>"
                 f'</tr>{"".join(rows)}</table>') if rows else '<p class="note">No hole found, so no loop.</p>'
        title = f"<h3>region {region.component}</h3>" if len(tmap.regions) > 1 else ""
        parts.append(f'{title}<div id="{key}" class="plot" style="height:560px"></div>{table}')
    return ('<section id="arena"><h2>Where the holes are</h2>\n'
            '<p class="note">Ground truth, used only for this picture: the landmark events at their true positions '
            "(the midpoint of the two agents), coloured by position, and for each hole found a loop of landmarks "
            "round it (the shortest loop that crosses the bar's cocycle an odd number of times). A right answer "
            "encircles a real obstacle.</p>"
            f'{"".join(parts)}</section>\n')


def _animation_section(trajectories: dict, arena, figures: dict) -> str:
    figures["plot-animation"], (agents, swarm), (frames, samples) = _animation_figure(trajectories, arena)
    shown = [f"{agents} agents" if agents == swarm else f"{agents} of the {swarm} agents",
             f"{frames} sampled times" if frames == samples else f"{frames} of the {samples} sampled times"]
    spacing = " (evenly spaced)" if (agents, frames) != (swarm, samples) else ""
    return ('<section id="animation"><h2>The swarm (simulation)</h2>\n'
            f'<p class="note">{shown[0]} at {shown[1]}{spacing}, coloured by state '
            "(random walk, wall following, stopped). Press play.</p>"
            '<div id="plot-animation" class="plot" style="height:620px"></div></section>\n')


def _parameters_section(doc: dict, log: EncounterLog) -> str:
    params = "".join(f"<tr><td>{html.escape(k)}</td><td>{_value(v)}</td></tr>" for k, v in doc["params"].items())
    timing_rows = "".join(
        f'<tr><td>{html.escape(k)}</td><td class="num timing" data-stage="{html.escape(k)}" data-value="{v!r}">'
        f"{v:.3f} s</td></tr>" for k, v in doc["timings"].items())
    total = sum(doc["timings"].values())
    classifier = "".join(f"<tr><td>{html.escape(str(k))}</td><td>{_value(v)}</td></tr>"
                         for k, v in doc["classifier"].items())
    software = "".join(f"<tr><td>{html.escape(str(k))}</td><td>{html.escape(str(v))}</td></tr>"
                       for k, v in doc["software"].items())
    meta = "".join(f"<tr><td>{html.escape(str(k))}</td><td>{_value(v)}</td></tr>" for k, v in log.meta.items())
    meta_table = f"<h3>Log metadata (meta.json)</h3><table>{meta}</table>" if meta else ""
    return ('<section id="parameters"><h2>Parameters and timings</h2>\n'
            f"<h3>Mapping parameters</h3><table><tr><th>parameter</th><th>value</th></tr>{params}</table>"
            f"<h3>Timings</h3><table><tr><th>stage</th><th>time</th></tr>{timing_rows}"
            f'<tr><th>total</th><th class="num">{total:.3f} s</th></tr></table>'
            f"<h3>Classifier</h3><table>{classifier}</table>"
            f"<h3>Software</h3><table>{software}</table>{meta_table}</section>\n")


def _value(v) -> str:
    """A parameter or metadata value as escaped text (JSON for lists and mappings)."""
    if isinstance(v, (dict, list)):
        return f"<code>{html.escape(json.dumps(v, ensure_ascii=False, default=str))}</code>"
    return html.escape("null" if v is None else str(v))


# -- figures (plain plotly.js figure dicts) ---------------------------------------------------
def _floats(values, digits: int = 6) -> list:
    """A list of floats for JSON, rounded (NaN/inf -> None, which plotly skips)."""
    arr = np.asarray(values, dtype=float)
    out = np.round(arr, digits).astype(object)
    out[~np.isfinite(arr)] = None
    return out.tolist()


def _persistence_figure(diagram, thresholds: dict[int, float]) -> dict:
    finite = np.concatenate([diagram[n][np.isfinite(diagram[n][:, 1])].ravel() for n in range(diagram.maxdim + 1)]
                            + [diagram[0][:, 0]])
    top = float(finite.max()) * 1.1 if finite.size and finite.max() > 0 else 1.0
    data = [{"type": "scatter", "x": [0, top], "y": [0, top], "mode": "lines", "line": {"color": "#999", "width": 1},
             "name": "birth = death", "hoverinfo": "skip", "xaxis": "x", "yaxis": "y"},
            {"type": "scatter", "x": [0, top], "y": [top, top], "mode": "lines", "name": "infinite death",
             "line": {"color": "#bbb", "dash": "dash", "width": 1}, "hoverinfo": "skip", "xaxis": "x", "yaxis": "y"}]
    for n in range(diagram.maxdim + 1):
        pts = diagram[n]
        inf = ~np.isfinite(pts[:, 1])
        color = _DIM_COLORS.get(n, "#000")
        data.append({"type": "scatter", "mode": "markers", "name": f"H{n} ({len(pts)} bars)", "legendgroup": f"H{n}",
                     "x": _floats(pts[~inf, 0]), "y": _floats(pts[~inf, 1]), "xaxis": "x", "yaxis": "y",
                     "marker": {"color": color, "size": 6, "opacity": 0.8},
                     "hovertemplate": f"H{n}: born %{{x:.4g}} s, dies %{{y:.4g}} s<extra></extra>"})
        if inf.any():
            data.append({"type": "scatter", "mode": "markers", "showlegend": False, "legendgroup": f"H{n}",
                         "x": _floats(pts[inf, 0]), "y": [top] * int(inf.sum()), "xaxis": "x", "yaxis": "y",
                         "marker": {"color": color, "size": 10, "symbol": "triangle-up"},
                         "hovertemplate": f"H{n}: born %{{x:.4g}} s, never dies<extra></extra>"})
        if n in thresholds:
            tau = thresholds[n]
            data.append({"type": "scatter", "mode": "lines", "x": [0, top], "y": [tau, top + tau],
                         "name": f"H{n} threshold {tau:.4g} s", "legendgroup": f"H{n}-threshold",
                         "line": {"color": color, "dash": "dot", "width": 2}, "xaxis": "x", "yaxis": "y",
                         "hovertemplate": f"H{n} threshold: death = birth + {tau:.4g} s<extra></extra>"})
    data.extend(_barcode_traces(diagram, thresholds, top))
    layout = {
        "grid": {"rows": 1, "columns": 2, "pattern": "independent"},
        "xaxis": {"title": {"text": "birth (s)"}, "range": [-0.02 * top, 1.02 * top], "domain": [0, 0.45]},
        "yaxis": {"title": {"text": "death (s)"}, "range": [-0.02 * top, 1.05 * top]},
        "xaxis2": {"title": {"text": "filtration scale (s)"}, "range": [0, 1.02 * top], "domain": [0.55, 1]},
        "yaxis2": {"showticklabels": False, "zeroline": False, "showgrid": False},
        "annotations": [
            {"text": "persistence diagram", "showarrow": False, "xref": "x domain", "yref": "paper",
             "x": 0.5, "y": 1.08, "font": {"size": 14}},
            {"text": "barcode (longest bars on top)", "showarrow": False, "xref": "x2 domain", "yref": "paper",
             "x": 0.5, "y": 1.08, "font": {"size": 14}}],
        "legend": {"orientation": "h", "y": -0.2},
        "margin": {"t": 50, "l": 60, "r": 20, "b": 40},
        "height": 480,
    }
    return {"data": data, "layout": layout, "config": {"displaylogo": False, "responsive": True}}


def _barcode_traces(diagram, thresholds: dict[int, float], top: float) -> list[dict]:
    """Bars as line segments, longest on top; bars longer than the threshold solid,
    the others faded; the threshold itself as a dashed segment [0, tau] above each
    dimension's bars (a bar counts when it is longer than that segment)."""
    traces = []
    y = 0.0
    for n in range(diagram.maxdim + 1):
        pts = diagram[n]
        lengths = pts[:, 1] - pts[:, 0]
        order = np.argsort(-lengths, kind="stable")[:MAX_BARS]
        tau = thresholds.get(n)
        color = _DIM_COLORS.get(n, "#000")
        groups = {True: ([], []), False: ([], [])}
        for i in order[::-1]:
            birth, death = pts[i]
            solid = tau is None or lengths[i] > tau
            xs, ys = groups[solid]
            xs += [float(birth), float(death) if np.isfinite(death) else top * 1.02, None]
            ys += [y, y, None]
            y += 1
        for solid, (xs, ys) in groups.items():
            if xs:
                traces.append({"type": "scatter", "mode": "lines", "x": xs, "y": ys, "xaxis": "x2", "yaxis": "y2",
                               "line": {"color": color, "width": 3}, "opacity": 1.0 if solid else 0.3,
                               "legendgroup": f"H{n}", "showlegend": False, "hoverinfo": "x",
                               "name": f"H{n} bars" + ("" if solid else " (below threshold)")})
        if tau is not None:
            traces.append({"type": "scatter", "mode": "lines+markers", "x": [0, tau], "y": [y + 0.5, y + 0.5],
                           "xaxis": "x2", "yaxis": "y2", "legendgroup": f"H{n}-threshold", "showlegend": False,
                           "line": {"color": color, "dash": "dash", "width": 2}, "marker": {"symbol": "line-ns-open"},
                           "hovertemplate": f"H{n} threshold length {tau:.4g} s<extra></extra>"})
            traces.append({"type": "scatter", "mode": "text", "x": [tau], "y": [y + 0.5], "xaxis": "x2",
                           "yaxis": "y2", "text": [f"  H{n} threshold {tau:.3g} s"], "textposition": "middle right",
                           "showlegend": False, "hoverinfo": "skip", "textfont": {"color": color}})
        y += 3
    return traces


def _event_hover(log: EncounterLog, events: np.ndarray) -> list[str]:
    """Hover text of events; the agent IDs (untrusted) HTML-escaped, so plotly shows them as text."""
    a = log.ids_of(log.a[events])
    b = log.ids_of(log.b[events])
    return [f"event {int(e)}<br>t = {t:.2f} s<br>agents {html.escape(str(x))} &amp; {html.escape(str(y))}"
            for e, t, x, y in zip(events, log.t[events], a, b)]


def _rgb(colors: np.ndarray) -> list[str]:
    return [f"rgb({int(r)},{int(g)},{int(b)})" for r, g, b in np.round(255 * np.clip(colors, 0, 1))]


def _cloud_figure(region, log: EncounterLog, truth, arena) -> dict:
    coords = region.embedding.coords
    events = np.asarray(region.landmark_events)
    hover = _event_hover(log, events)
    dim = coords.shape[1]
    xyz = [_floats(coords[:, i]) for i in range(dim)]

    def points(color, scene, **marker):
        trace = {"x": xyz[0], "y": xyz[1], "mode": "markers", "text": hover, "hoverinfo": "text",
                 "showlegend": False, "marker": {"color": color, "size": 3 if dim == 3 else 6, **marker}}
        if dim == 3:
            trace.update(type="scatter3d", z=xyz[2], scene=scene)
        else:
            trace.update(type="scatter", xaxis="x" if scene == "scene" else "x2",
                         yaxis="y" if scene == "scene" else "y2")
        return trace

    by_time = points(_floats(log.t[events], 3), "scene", colorscale="Viridis",
                     colorbar={"title": {"text": "time (s)"}, "x": 0.46 if truth is not None else 1.0, "len": 0.8})
    data = [by_time]
    axis = {"showticklabels": False, "title": {"text": ""}}
    if dim == 3:
        layout = {"scene": {"domain": {"x": [0, 0.48] if truth is not None else [0, 1]},
                            "xaxis": axis, "yaxis": axis, "zaxis": axis, "aspectmode": "data"}}
    else:
        layout = {"xaxis": {"domain": [0, 0.45] if truth is not None else [0, 1], **axis},
                  "yaxis": {"scaleanchor": "x", **axis}}
    titles = [{"text": "coloured by event time", "showarrow": False, "xref": "paper", "yref": "paper",
               "x": 0.22 if truth is not None else 0.5, "y": 1.0, "font": {"size": 14}}]
    if truth is not None:
        data.append(points(_true_position_colors(event_positions(truth, events), arena), "scene2"))
        if dim == 3:
            layout["scene2"] = {"domain": {"x": [0.52, 1]}, "xaxis": axis, "yaxis": axis, "zaxis": axis,
                                "aspectmode": "data"}
        else:
            layout["xaxis2"] = {"domain": [0.55, 1], **axis}
            layout["yaxis2"] = {"scaleanchor": "x2", **axis}
        titles.append({"text": "coloured by true position (see the arena below)", "showarrow": False,
                       "xref": "paper", "yref": "paper", "x": 0.78, "y": 1.0, "font": {"size": 14}})
    layout.update(annotations=titles, margin={"t": 30, "l": 0, "r": 0, "b": 0}, height=520)
    return {"data": data, "layout": layout, "config": {"displaylogo": False, "responsive": True}}


def _arena_traces(arena) -> list[dict]:
    """Free space light grey, obstacles dark grey, walls black."""
    traces = []
    for region in arena.regions:
        x, y = region.exterior.xy
        traces.append({"type": "scatter", "x": _floats(x, 2), "y": _floats(y, 2), "fill": "toself",
                       "fillcolor": "#eeeeee", "mode": "lines", "line": {"color": "black", "width": 2},
                       "hoverinfo": "skip", "showlegend": False})
        for ring in region.interiors:
            x, y = ring.xy
            traces.append({"type": "scatter", "x": _floats(x, 2), "y": _floats(y, 2), "fill": "toself",
                           "fillcolor": "#777777", "mode": "lines", "line": {"color": "black", "width": 2},
                           "hoverinfo": "skip", "showlegend": False})
    return traces


def _plane_layout(arena, height: int) -> dict:
    layout = {"xaxis": {"title": {"text": "x (mm)"}, "constrain": "domain"},
              "yaxis": {"title": {"text": "y (mm)"}, "scaleanchor": "x"},
              "margin": {"t": 20, "l": 60, "r": 20, "b": 50}, "height": height,
              "legend": {"orientation": "h", "y": -0.12}}
    if arena is not None:
        xmin, ymin, xmax, ymax = arena.bounds
        pad = 0.03 * max(xmax - xmin, ymax - ymin)
        layout["xaxis"]["range"] = [xmin - pad, xmax + pad]
        layout["yaxis"]["range"] = [ymin - pad, ymax + pad]
    return layout


def _true_position_colors(xy: np.ndarray, arena) -> list[str]:
    """Colours of true positions over the arena's bounds (the points' own without an arena)."""
    bounds = arena.bounds if arena is not None else (*xy.min(axis=0), *xy.max(axis=0))
    return _rgb(position_colors(xy, bounds))


def _arena_figure(region, loops: list[np.ndarray], truth: dict, arena) -> dict:
    """Landmark events at their true positions and each cycle's ``loops`` entry (true positions)."""
    xy = event_positions(truth, np.asarray(region.landmark_events))
    data = _arena_traces(arena) if arena is not None else []
    data.append({"type": "scatter", "mode": "markers", "x": _floats(xy[:, 0], 2), "y": _floats(xy[:, 1], 2),
                 "marker": {"color": _true_position_colors(xy, arena), "size": 5}, "name": "landmark events",
                 "hovertemplate": "landmark event at (%{x:.0f}, %{y:.0f}) mm<extra></extra>"})
    for c, (cycle, loop) in enumerate(zip(region.cycles, loops)):
        closed = np.vstack([loop, loop[:1]])
        color = _LOOP_COLORS[c % len(_LOOP_COLORS)]
        data.append({"type": "scatter", "mode": "lines+markers", "x": _floats(closed[:, 0], 2),
                     "y": _floats(closed[:, 1], 2), "name": f"loop {c} (H1 bar {cycle.bar_index})",
                     "line": {"color": color, "width": 3},
                     "marker": {"color": color, "size": 8, "line": {"color": "black", "width": 1}},
                     "hovertemplate": f"loop {c}: (%{{x:.0f}}, %{{y:.0f}}) mm<extra></extra>"})
    return {"data": data, "layout": _plane_layout(arena, 560), "config": {"displaylogo": False, "responsive": True}}


def _evenly(n: int, k: int) -> np.ndarray:
    """k indices evenly spread over range(n), first and last included (all if n <= k)."""
    return np.arange(n) if n <= k else np.unique(np.round(np.linspace(0, n - 1, k)).astype(np.int64))


def _animation_figure(trajectories: dict, arena) -> tuple[dict, tuple[int, int], tuple[int, int]]:
    """A plotly animation of sampled trajectories: at most MAX_ANIMATION_AGENTS agents
    at MAX_ANIMATION_FRAMES times.  Agents absent at a time are left out of that frame.
    Returns the figure, (agents shown, agents sampled) and (times shown, times sampled)."""
    t = np.asarray(trajectories["t"], dtype=float)
    agent = np.asarray(trajectories["agent"])
    all_times, all_agents = np.unique(t), np.unique(agent)
    times = all_times[_evenly(len(all_times), MAX_ANIMATION_FRAMES)]
    agents = all_agents[_evenly(len(all_agents), MAX_ANIMATION_AGENTS)]
    keep = np.isin(t, times) & np.isin(agent, agents)
    row = np.searchsorted(times, t[keep])
    col = np.searchsorted(agents, agent[keep])
    x = np.full((len(times), len(agents)), np.nan)
    y = np.full_like(x, np.nan)
    x[row, col], y[row, col] = trajectories["x"][keep], trajectories["y"][keep]
    state = None
    if "state" in trajectories:
        state = np.full(x.shape, -1, dtype=np.int64)
        state[row, col] = trajectories["state"][keep]
    hover = [f"agent {html.escape(str(a))}" for a in agents]
    labels = np.array([_STATE_COLORS[s] for s in STATES] + ["#000000"])

    def frame_trace(i):
        trace = {"x": _floats(x[i], 1), "y": _floats(y[i], 1)}
        if state is not None:
            trace["marker"] = {"color": labels[state[i]].tolist(), "size": 7}
        return trace

    base = _arena_traces(arena) if arena is not None else []
    swarm = {"type": "scatter", "mode": "markers", "text": hover, "hoverinfo": "text", "showlegend": False,
             "marker": {"color": "#1f77b4", "size": 7}, **frame_trace(0)}
    legend = [{"type": "scatter", "mode": "markers", "x": [None], "y": [None], "name": name,
               "marker": {"color": _STATE_COLORS[name], "size": 7}} for name in STATES] if state is not None else []
    data = base + [swarm] + legend
    swarm_index = len(base)
    frames = [{"name": str(i), "data": [frame_trace(i)], "traces": [swarm_index]} for i in range(len(times))]
    play = {"frame": {"duration": 150, "redraw": False}, "transition": {"duration": 0}, "fromcurrent": True}
    layout = _plane_layout(arena, 620)
    layout["updatemenus"] = [{"type": "buttons", "direction": "left", "x": 0, "y": 1.08, "xanchor": "left",
                              "buttons": [{"label": "play", "method": "animate", "args": [None, play]},
                                          {"label": "pause", "method": "animate",
                                           "args": [[None], {"mode": "immediate", "frame": {"duration": 0},
                                                             "transition": {"duration": 0}}]}]}]
    layout["sliders"] = [{"currentvalue": {"prefix": "t = ", "suffix": " s"}, "pad": {"t": 40},
                          "steps": [{"label": f"{tt:.1f}", "method": "animate",
                                     "args": [[str(i)], {"mode": "immediate", "frame": {"duration": 0,
                                                                                           "redraw": False}}]}
                                    for i, tt in enumerate(times)]}]
    layout["margin"]["t"] = 50
    layout["legend"] = {"orientation": "h", "x": 1, "xanchor": "right", "y": 1.08}
    figure = {"data": data, "layout": layout, "frames": frames,
              "config": {"displaylogo": False, "responsive": True}}
    return figure, (len(agents), len(all_agents)), (len(times), len(all_times))
