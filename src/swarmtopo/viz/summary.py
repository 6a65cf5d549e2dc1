"""A map for people and files: its map.json document and its advice.

:func:`map_json` is the map.json document (deaths of infinite bars as null);
:func:`advice` says what would raise a confidence below ``ADVICE_BELOW``.
"""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import Any

import numpy as np

from .._json import jsonable
from ..pipeline.faults import FaultScreen
from ..pipeline.motion import MotionEstimate
from ..pipeline.result import Exploration, RegionMap, Timeline, TopologicalMap, WindowMap
from ..readers.beta0 import BETA0_DEFINITION
from ..readers.ratio import RESOLUTION_CAP, below_full_resolution, resolution
from .text import format_confidence

ADVICE_BELOW = 0.9
"""A Betti number reported with less confidence than this comes with advice."""


def advice(tmap: TopologicalMap) -> list[str]:
    """What would raise a confidence below ``ADVICE_BELOW`` (empty otherwise)."""
    low = [n for n, p in sorted(tmap.confidence.items()) if p is not None and p < ADVICE_BELOW]
    if not low:
        return []
    lines = [f"beta_{n} = {tmap.betti[n]} is uncertain ({format_confidence(tmap.confidence[n])} confidence)"
             for n in low]
    evidence = tmap.beta0_evidence
    if 0 in low and evidence is not None:
        apart = (f"have stayed apart for only {evidence.settled:.3g} mean gaps between an agent's encounters since "
                 "they formed" if evidence.settled else "formed at the log's end (or no agent met twice)")
        lines.append(
            f"the {evidence.regions} regions {apart}; groups in one room merge when their agents meet, so only a "
            "longer log tells one room from several" if evidence.regions >= 2 else
            f"{100 * evidence.fragments:.0f}% of the events are in groups too small to map (too_little_data); "
            "a room only a few agents saw would hide there")
    for r in tmap.regions:
        counts = [w.betti.get(1) for w in r.windows]
        if len(set(counts)) > 1:
            lines.append(f"region {r.component}: its {len(counts)} time windows counted {counts} holes each")
        if 1 in low and below_full_resolution(diagrams := [w.diagram for w in r.windows]):
            places = f"{np.exp(resolution(diagrams)):.0f} places apart (landmarks; {RESOLUTION_CAP} at full resolution)"
            lines.append(f"region {r.component}: its windows tell about {places}: with few places a hole can go "
                         "unseen in every window alike, so agreeing windows are no proof" if len(diagrams) > 1 else
                         f"region {r.component}: its one window tells about {places}: with few places a hole can go "
                         "unseen")
    length = tmap.window_length[0]
    more_time = ("" if tmap.windows_left_out else
                 f"record longer (each extra {tmap.config.window_step or length / 2:.3g} s adds a window to "
                 "the pooling), " if np.isfinite(length) else "record longer, ")
    how_much = ("'swarmtopo plan " + ("--input contact-trace " if tmap.contact_trace else "")
                + "--area A --agents N --target 0.95' tells how much")
    lines.append(f"to raise it: {more_time}use more agents than {tmap.n_agents} (denser windows); {how_much}")
    return lines


def map_json(tmap: TopologicalMap) -> dict[str, Any]:
    """The map.json document (deaths of infinite bars as null)."""
    return {
        "betti": {str(k): v for k, v in sorted(tmap.betti.items())},
        "confidence": {str(k): v for k, v in sorted(tmap.confidence.items())},
        "diagrams": tmap.diagram.to_json(),
        "classifier": tmap.classifier,
        "warnings": tmap.warnings,
        "advice": advice(tmap),
        "regions": [_region_json(r) for r in tmap.regions],
        "too_little_data": tmap.too_little_data,
        "timeline": None if tmap.timeline is None else timeline_json(tmap.timeline),
        "exploration": None if tmap.exploration is None else exploration_json(tmap.exploration),
        "motion": None if tmap.motion is None else motion_json(tmap.motion),
        "sensing": None if tmap.sensing is None else sensing_json(tmap.sensing),
        "beta0_evidence": None if tmap.beta0_evidence is None else {**tmap.beta0_evidence.to_json(),
                                                                      "definition": BETA0_DEFINITION},
        "params": {**jsonable(asdict(tmap.config)), "hop_cost_used": tmap.hop_cost[0],
                   "hop_cost_source": tmap.hop_cost[1],
                   "diffusion_time_used": tmap.diffusion_time[0] if np.isfinite(tmap.diffusion_time[0]) else None,
                   "diffusion_time_source": tmap.diffusion_time[1],
                   "window_length_used": tmap.window_length[0] if np.isfinite(tmap.window_length[0]) else None,
                   "window_source": tmap.window_length[1], "windows_left_out": tmap.windows_left_out},
        "log": {"events": tmap.n_events, "agents": tmap.n_agents, "contact_trace": tmap.contact_trace},
        "timings": {k: round(v, 6) for k, v in tmap.timings.items()},
        "software": {**tmap.software, "persistence_backend": tmap.diagram.backend},
    }


def motion_json(motion: MotionEstimate) -> dict[str, Any]:
    """map.json's ``motion``: what the encounters say about the agents' motion."""
    return {"regime": motion.regime, "summary": motion.describe(), "recontact_share": motion.recontact_share,
            "median_gap": motion.median_gap, "encounter_rate": motion.encounter_rate,
            "partners_per_agent": motion.partners_per_agent, "merged": motion.merged}


def sensing_json(screen: FaultScreen) -> dict[str, Any]:
    """map.json's ``sensing``: what the encounters say about faulty sensing."""
    return {"summary": screen.describe(), "uncorroborated_share": screen.uncorroborated_share,
            "far_share": screen.far_share, "duplicate_share": screen.duplicate_share, "suspected": screen.suspected,
            "dropped": screen.dropped, "merged": screen.merged}


def timeline_json(timeline: Timeline) -> dict[str, Any]:
    """map.json's ``timeline`` (an unknown or infinite number as null)."""
    def number(p):
        return None if p is None or not math.isfinite(p) else float(p)
    return {
        "length": number(timeline.length), "step": number(timeline.step), "note": timeline.note,
        "summary": timeline.summary(),
        "windows": [{"t0": w.t0, "t1": w.t1, "events": w.n_events,
                     "betti": {str(n): b for n, b in sorted(w.betti.items())},
                     "confidence": {str(n): number(p) for n, p in sorted(w.confidence.items())},
                     "h1_scaled_lengths": [float(x) for x in w.h1_scaled]} for w in timeline.windows],
        "segments": {str(n): [{"value": s.value, "from": number(s.t_from), "until": number(s.t_until),
                               "confidence": number(s.confidence), "windows": s.windows} for s in segs]
                     for n, segs in sorted(timeline.segments.items())},
        "changes": [{"dimension": c.dim, "t": c.t, "from": c.before, "to": c.after, "interval": [c.lo, c.hi],
                     "confidence": number(c.confidence)} for c in timeline.changes],
    }


def exploration_json(exploration: Exploration) -> dict[str, Any]:
    """map.json's ``exploration``: the global map of a beacon-led log."""
    def number(x):
        return float(x) if math.isfinite(x) else None
    return {
        "summary": exploration.summary(), "leash": exploration.leash, "leader_speed": exploration.leader_speed,
        "length": number(exploration.length), "step": number(exploration.step), "coverage_mm2": exploration.coverage,
        "betti": {str(n): b for n, b in sorted(exploration.betti.items())},
        "holes": [{"x": h.x, "y": h.y, "radius": h.radius, "in_view": [h.t_in, h.t_out], "windows": h.windows,
                   "open": h.open} for h in exploration.holes],
        "windows": [{"t0": w.t0, "t1": w.t1, "beta_1": w.betti[1], "leader": [float(x), float(y)]}
                    for w, (x, y) in zip(exploration.windows, exploration.leader_xy)],
        "warnings": exploration.warnings,
    }


def _region_json(r: RegionMap) -> dict[str, Any]:
    return {
        "component": r.component,
        "events": r.n_events,
        "agents": r.n_agents,
        "landmarks": int(len(r.landmarks.nodes)),
        "cover_radius": float(r.scales.cover_radius),
        "knn_scale": float(r.scales.knn),
        "thresholds": {str(n): float(v) for n, v in r.thresholds.items()},
        "betti": {str(k): int(v) for k, v in sorted(r.betti.items())},
        "confidence": {str(k): v for k, v in sorted(r.confidence.items())},
        "cycles": [c.to_json() for c in r.cycles],
        "windows": [window_json(w) for w in r.windows],
        "window": r.window,
        "diagrams": r.diagram.to_json(),
        "mds_stress": None if r.embedding is None else float(r.embedding.stress),
        "warnings": r.warnings,
    }


def window_json(w: WindowMap) -> dict[str, Any]:
    return {"t0": w.t0, "t1": w.t1, "band": w.band, "events": w.n_events, "landmarks": int(len(w.landmarks.nodes)),
            "cover_radius": float(w.scales.cover_radius), "knn_scale": float(w.scales.knn),
            "betti": {str(n): int(v) for n, v in w.betti.items()}}
