"""How the default pipeline and ``swarmtopo plan`` do on swarms and arenas the accuracy suite does not hold.

The suite (``swarmtopo-accuracy/1``) varies the arena (0-3 holes of five families,
three outer walls, scale 0.75-1.25) but hardly the swarm: its agents always have the
paper's motion and sensing (v_c = 15 mm/s, r_d = 30 mm, ...), none is static, and its
three budgets raise swarm size and duration together (200 x 30 s, 300 x 40 s,
400 x 60 s).  Every default was chosen there, and ``plan`` was fitted there.  This
maps arenas drawn the same way (holes 0-3 in turn, a random family among all five, a
random outer wall) under regimes outside those ranges -- a larger arena, a sparse or a
dense swarm, a long or a short log, other detection radii, faster agents, longer wall
following, static nodes -- each from a log stripped of ground truth, as ``swarmtopo
map`` reads a deployment's folder.  The seeds come from their own
namespace (``NAMESPACE``), so no case is a suite case.

Prints per regime: exact (beta_0, beta_1) with its Wilson 95 % interval, what the
shipped plan model expects for the regime's cases (mean over them; regimes with the
paper's motion and sensing only), the wrong maps as (true -> mapped, beta_1
confidence), the mean beta_1 confidence of the right and of the wrong maps, events per
log and seconds per map; then the reliability of the beta_1 confidence over all the
regimes' maps (Brier score against a constant, and its bins).

    python lab/outside_suite.py [--per-regime 12] [--first 0] [--regimes NAME ...] [--set FIELD=VALUE ...]
                                       [--classifier NAME|FILE] [--contact-trace] [--band-scores]

``--first`` is the index of the first case of each regime (``--first 12`` the next
twelve); ``--set`` maps with ``MapConfig`` fields changed (as
``lab/levers.py``'s ``FIELD=VALUE`` variants: ``--set window_encounters=40``);
``--classifier`` reads every map with a preset (``paper``) or a classifier file instead of
the one ``map`` picks (its landmark bands too, when ``--set`` leaves them unset);
``--contact-trace`` maps each log's encounters only, as a real contact trace comes
(``experiments.sweep.contact_trace``: no status, no r_d or speeds; ``map`` then reads it
with the ``trace`` classifier; no plan figure is printed then: ``plan`` models log folders);
``--band-scores`` prints, per regime and landmark band, where the band's windows put the
true count's ranks: the mean over cases of S_beta - ln tau_1 (the last true hole, beta the
true beta_1; cases with a hole) and S_(beta+1) - ln tau_1 (the first noise rank), S_k
pooled over that band's windows of the largest region, and how many cases' first noise
rank passes ln tau_1 (the threshold of the vote that pools all bands).
"""

from __future__ import annotations

import argparse
import hashlib
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from swarmtopo.arena import HOLE_SHAPES, OUTER_SHAPES, random_arena
from swarmtopo.errors import SwarmtopoError
from swarmtopo.experiments.accuracy import ROOM_SIDE, Rate, reliability, reliability_bin_lines
from swarmtopo.experiments.sweep import cached_classifier, contact_trace, stripped_log
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.experiments.plan import load_plan
from swarmtopo.readers.ratio import RatioClassifier, pooled_scores
from swarmtopo.sim import MotionParams, SensingParams, simulate

from levers import config_override

NAMESPACE = "swarmtopo-outside-suite/1"
"""Hashed with the regime's name and the case index into each case's seed."""


@dataclass(frozen=True)
class Regime:
    """A swarm and arena size outside the suite's: ``scale`` multiplies the suite's
    500 mm arena (one value, not the suite's draw)."""

    agents: int
    duration: float
    scale: float = 1.0
    r_d: float = 30.0
    motion: dict = field(default_factory=dict)
    static_fraction: float = 0.0

    @property
    def paper_swarm(self) -> bool:
        """The suite's motion, sensing and mobile swarm: what ``plan`` models."""
        return self.r_d == 30.0 and not self.motion and self.static_fraction == 0.0


REGIMES = {
    "suite-like (control): 300 x 40 s": Regime(300, 40.0),
    "large arena, same density: x2 side, 1200 x 40 s": Regime(1200, 40.0, scale=2.0),
    "large arena, same swarm: x2 side, 300 x 160 s": Regime(300, 160.0, scale=2.0),
    "small swarm, long log: 100 x 120 s": Regime(100, 120.0),
    "dense swarm, short log: 800 x 15 s": Regime(800, 15.0),
    "small arena: x0.6 side, 110 x 40 s": Regime(110, 40.0, scale=0.6, r_d=18.0),
    "short detection radius: r_d 15 mm, 300 x 40 s": Regime(300, 40.0, r_d=15.0),
    "long detection radius: r_d 45 mm, 300 x 40 s": Regime(300, 40.0, r_d=45.0),
    "faster agents: v_c 30, v_p 20 mm/s, 300 x 40 s": Regime(300, 40.0, motion={"v_c": 30.0, "v_p": 20.0}),
    "long wall following: tau_exit 40 s, 300 x 40 s": Regime(300, 40.0, motion={"tau_exit": 40.0}),
    "static nodes: 20 % stopped from t = 0, 300 x 40 s": Regime(300, 40.0, static_fraction=0.2),
}
"""The small arena keeps the suite's ratio of r_d to the arena (30 mm to 500 mm), so its
passages (the 60 mm clearance x 0.6) stay twice r_d; its swarm keeps the suite's density."""


def case_seed(regime: str, index: int, attempt: int) -> int:
    text = f"{NAMESPACE}|{regime}|{index}|{attempt}"
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:8], "big")


def _arena(regime_name: str, regime: Regime, index: int):
    """(arena, case seed, family) of case ``index``: ``index % 4`` holes, the next draw
    when the holes cannot be placed."""
    for attempt in range(20):
        seed = case_seed(regime_name, index, attempt)
        rng = np.random.default_rng(seed)
        family = HOLE_SHAPES[int(rng.integers(len(HOLE_SHAPES)))]
        outer = OUTER_SHAPES[int(rng.integers(len(OUTER_SHAPES)))]
        try:
            arena = random_arena(index % 4, scale=regime.scale, shapes=(family,), outer=outer, rng=rng)
        except SwarmtopoError:
            continue
        return arena, seed, family, (ROOM_SIDE * regime.scale) ** 2
    raise SwarmtopoError(f"{regime_name}: no placeable arena for case {index}")


def _run(task):
    regime_name, index, options, classifier, as_trace, band_scores = task
    regime = REGIMES[regime_name]
    arena, seed, family, area = _arena(regime_name, regime, index)
    motion = MotionParams(**regime.motion)
    dt = min(0.1, regime.r_d / (4 * max(motion.v_c, motion.v_p)))
    sim = simulate(arena, regime.agents, regime.duration, dt=dt, motion=motion,
                   sensing=SensingParams(r_d=regime.r_d), static_fraction=regime.static_fraction,
                   rng=seed % 2**32)
    log = contact_trace(stripped_log(sim.log)) if as_trace else stripped_log(sim.log)
    start = time.perf_counter()
    margins = {}
    try:
        tmap = map_encounters(log, MapConfig(seed=seed % 2**32, embed_dim=0, cycles=False, **options),
                              reader=None if classifier is None else cached_classifier(classifier, classifier))
        mapped, confidence = (tmap.betti[0], tmap.betti[1]), tmap.confidence[1]
        margins = band_margins(tmap, arena.betti[1]) if band_scores else {}
    except SwarmtopoError as error:  # a log the pipeline refuses is a wrong map, with its reason
        mapped, confidence = (str(error)[:80], None), None
    return {"regime": regime_name, "family": family, "area": area, "truth": tuple(arena.betti), "mapped": mapped,
            "confidence": confidence, "events": log.n_events, "seconds": time.perf_counter() - start,
            "band_margins": margins}


def band_margins(tmap, beta1: int) -> dict[float, tuple[float | None, float]]:
    """Per landmark band: (S_beta - ln tau_1 or None without a hole, S_(beta+1) - ln tau_1),
    S pooled over the band's windows of the largest region (``--band-scores``); empty
    for a classifier that does not pool ratio scores."""
    classifier = cached_classifier(tmap.classifier["classifier"])
    if not isinstance(classifier, RatioClassifier):
        return {}
    thresholds = classifier.thresholds_[1]
    region = max(tmap.regions, key=lambda r: r.n_events)
    margins = {}
    for band in sorted({w.band for w in region.windows}, reverse=True):
        scores = pooled_scores([w.diagram for w in region.windows if w.band == band], 1, thresholds.q)
        scores = np.concatenate([scores, np.zeros(beta1 + 1)]) - np.log(thresholds.tau)  # a missing rank scores 0
        margins[band] = (float(scores[beta1 - 1]) if beta1 else None, float(scores[beta1]))
    return margins


def band_lines(rows) -> list[str]:
    """``--band-scores``' lines of one regime (module docstring)."""
    lines = []
    for band in sorted({b for r in rows for b in r["band_margins"]}, reverse=True):
        pairs = [r["band_margins"][band] for r in rows if band in r["band_margins"]]
        holes = [h for h, _ in pairs if h is not None]
        noise = [n for _, n in pairs]
        lines.append(f"    band {band:g}: last hole S - ln tau {np.mean(holes) if holes else float('nan'):+.2f}, "
                     f"first noise rank {np.mean(noise):+.2f}, passing in {sum(n > 0 for n in noise)} of {len(noise)}")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-regime", type=int, default=12)
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--regimes", nargs="*", default=list(REGIMES), help="regime names (a prefix is enough)")
    parser.add_argument("--set", nargs="*", default=[], metavar="FIELD=VALUE", help="MapConfig fields to change")
    parser.add_argument("--processes", type=int, default=2)
    parser.add_argument("--classifier", default=None, help="a classifier preset or file to read every map with")
    parser.add_argument("--contact-trace", action="store_true", help="map the encounters only (a contact trace)")
    parser.add_argument("--band-scores", action="store_true", help="per band, the pooled scores' margins (docstring)")
    args = parser.parse_args()
    options = {k: v for text in args.set for k, v in config_override(text).items()}
    names = [n for n in REGIMES if any(n.startswith(p) for p in args.regimes)]
    tasks = [(name, i, options, args.classifier, args.contact_trace, args.band_scores)
             for name in names for i in range(args.first, args.first + args.per_regime)]
    with ProcessPoolExecutor(args.processes) as pool:
        results = list(pool.map(_run, tasks))
    plan = load_plan()
    total = 0
    for name in names:
        regime = REGIMES[name]
        rows = [r for r in results if r["regime"] == name]
        right = [r for r in rows if r["truth"] == r["mapped"]]
        wrong = [r for r in rows if r["truth"] != r["mapped"]]
        total += len(right)
        low, high = Rate(len(right), len(rows)).interval
        expected = (f"plan expects {np.mean([plan.accuracy(r['area'], regime.agents, regime.duration, r['truth'][1]) for r in rows]):.2f}; "
                    if regime.paper_swarm and not args.contact_trace else "")  # plan models log folders
        conf_right = [r["confidence"] for r in right if r["confidence"] is not None]
        conf_wrong = [r["confidence"] for r in wrong if r["confidence"] is not None]
        listed = ", ".join(f"{r['family']} {r['truth'][1]}->{r['mapped'][1]} "
                           f"({'-' if r['confidence'] is None else format(r['confidence'], '.2f')})" for r in wrong)
        print(f"{name}: {len(right)}/{len(rows)} exact [{low:.2f}, {high:.2f}]; {expected}"
              f"beta_1 confidence right {np.mean(conf_right) if conf_right else float('nan'):.2f}, "
              f"wrong {np.mean(conf_wrong) if conf_wrong else float('nan'):.2f}; "
              f"{int(np.median([r['events'] for r in rows]))} events, {np.mean([r['seconds'] for r in rows]):.1f} s per map"
              + (f"\n    wrong: {listed}" if listed else ""))
        if args.band_scores:
            print("\n".join(band_lines(rows)))
    print(f"all: {total}/{len(results)} exact")
    rel = reliability([{"confidence_betti1": r["confidence"], "betti1_right": r["mapped"][1] == r["truth"][1]}
                       for r in results], 1)
    if rel["maps"]:
        print(f"beta_1 confidence over all regimes ({rel['maps']} maps): Brier {rel['brier']:.4f} against "
              f"{rel['brier_constant']:.4f} for a constant equal to the rate")
        print("\n".join(reliability_bin_lines(rel)))


if __name__ == "__main__":
    main()
