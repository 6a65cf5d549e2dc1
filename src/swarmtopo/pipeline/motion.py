"""What the encounters say about how the agents move, read before the map is built.

From the events alone (no speeds, no r_d, no model named), for the mapped log:

* g, the median time between an agent's consecutive encounters at different times
  (the median, not the mean: a long silence in the log does not stretch it);
* the encounter rate, 2 n_events / (N T): encounters per agent per second;
* the partners per agent: distinct agents each agent met, on average;
* rho, the re-contact share: the share of events whose pair had an event less than
  ``RECONTACT_GAPS`` x g before.  A walker that keeps its heading (the cockroach,
  billiard, run-and-tumble, Lévy walks) seldom meets the same agent again so soon in a
  swarm of a few hundred: rho is 0.02-0.20 on the accuracy benchmark's cockroach logs.
  Where contacts *flicker* -- Brownian agents hovering about r_d apart, flockmates
  travelling together -- one pair logs the start of contact again and again: rho is
  0.36-0.54 on the motion benchmark's Brownian logs and up to 0.53 on its flocks.

The regime is ``flickering`` when rho > ``FLICKER_SHARE``, else ``persistent``, and
``unread`` for a swarm of fewer than ``MIN_AGENTS``: a few agents meet the same few
again and again whatever their motion (cockroach swarms of 20-60 agents on 120-600 s
logs have rho 0.25-0.45, as high as Brownian swarms; ``lab/motion_regimes.py``), so
rho tells nothing there.  A flickering log is mapped with every pair's events closer
than ``RECONTACT_GAPS`` x g to that pair's previous event (in the mapped window)
merged into the first (one contact, however long it flickers): repeated starts of one
contact carry no new place, but their tiny gaps set g, and with it the per-hop cost
(unless meta.json gives r_d and v_c), the diffusion time and the windows, to the
flicker's time scale instead of the swarm's.  A persistent or unread log is mapped as
it is, so every log the confidence was calibrated on maps exactly as before.  A
flickering log read by a shipped reader gets that reader's confidence recalibrated on
flickering logs (:mod:`swarmtopo.readers.recalibrated`).

Speed and persistence length are not identifiable from [t, a, b] alone: the rate
of encounters is density x 2 r_d x the mean relative speed, and neither the density
(the arena's area) nor r_d is in a contact trace.  The estimate therefore reports
time scales and shares, not millimetres per second.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..log import EncounterLog
from ..metric.graph import agent_gaps, event_slice

RECONTACT_GAPS = 7.0
"""A pair's event closer than this many median agent gaps g to the pair's previous
event is a re-contact (and, in a flickering log, merged into it)."""
FLICKER_SHARE = 0.3
"""Largest re-contact share rho of a ``persistent`` log: the accuracy benchmark's
cockroach logs have rho <= 0.20 (520 logs, ``lab/motion_regimes.py``; the highest in
its two small rooms), its Brownian logs 0.36 and more (module docstring)."""
MIN_AGENTS = 100
"""Fewest agents whose log's regime is read (module docstring)."""


@dataclass(frozen=True)
class MotionEstimate:
    """What the encounters say about the agents' motion (module docstring).

    ``merged`` is how many events were merged into an earlier contact of their pair
    (0 unless the map merged them).
    """

    regime: str
    recontact_share: float
    median_gap: float | None
    encounter_rate: float
    partners_per_agent: float
    merged: int

    def describe(self) -> str:
        """One line for the printed verdict and the report."""
        what = {"flickering": "contacts flicker (diffusive or flocking agents)",
                "persistent": "persistent walkers (like the cockroach, billiard, run-and-tumble or Lévy walks)",
                "unread": f"not read (fewer than {MIN_AGENTS} agents meet the same few again whatever their motion)"
                }[self.regime]
        text = (f"motion: {what}; re-contact share {self.recontact_share:.2f}, "
                f"{self.encounter_rate:.2g} encounters per agent per s, {self.partners_per_agent:.0f} partners per agent")
        if self.merged:
            text += f"; {self.merged} repeated contact starts merged"
        return text


def recontact_gaps(log: EncounterLog) -> np.ndarray:
    """Per event, the time since the same pair's previous event (inf for a pair's first)."""
    lo, hi = np.minimum(log.a, log.b).astype(np.int64), np.maximum(log.a, log.b).astype(np.int64)
    order = np.lexsort((np.arange(log.n_events), log.t, hi, lo))
    same = (lo[order][1:] == lo[order][:-1]) & (hi[order][1:] == hi[order][:-1])
    gaps = np.full(log.n_events, np.inf)
    gaps[order[1:][same]] = np.diff(log.t[order])[same]
    return gaps


def estimate_motion(log: EncounterLog, recontacts: str = "auto",
                    window: tuple[float | None, float | None] | None = None) -> tuple[MotionEstimate, EncounterLog]:
    """The motion estimate of ``log``'s events in ``window`` (None: all) and the log to
    map (re-contacts inside the window merged when ``recontacts`` is ``merge``, or
    ``auto`` and the log flickers)."""
    inside = slice(0, log.n_events) if window is None else slice(*event_slice(log, window))
    mapped = replace(log, t=log.t[inside], a=log.a[inside], b=log.b[inside])
    gap = median_agent_gap(mapped)
    recontact = np.zeros(log.n_events, bool)
    if gap is not None:
        recontact[inside] = recontact_gaps(mapped) < RECONTACT_GAPS * gap
    share = float(recontact[inside].mean()) if mapped.n_events else 0.0
    if log.n_agents < MIN_AGENTS:
        regime = "unread"
    else:
        regime = "flickering" if share > FLICKER_SHARE else "persistent"
    merge = recontacts == "merge" or (recontacts == "auto" and regime == "flickering")
    merged = int(recontact.sum()) if merge else 0
    span = float(mapped.t.max() - mapped.t.min()) if mapped.n_events else 0.0
    pairs = np.unique(np.stack([np.minimum(mapped.a, mapped.b), np.maximum(mapped.a, mapped.b)]), axis=1)
    n = max(log.n_agents, 1)
    estimate = MotionEstimate(regime=regime, recontact_share=share, median_gap=gap,
                              encounter_rate=2 * mapped.n_events / (n * span) if span > 0 else 0.0,
                              partners_per_agent=2 * pairs.shape[1] / n, merged=merged)
    keep = ~recontact
    return estimate, (replace(log, t=log.t[keep], a=log.a[keep], b=log.b[keep]) if merged else log)


def median_agent_gap(log: EncounterLog) -> float | None:
    """Median time between an agent's consecutive encounters at different times (None: none)."""
    gaps = agent_gaps(log)
    gaps = gaps[gaps > 0]
    return float(np.median(gaps)) if len(gaps) else None


def motion_warnings(motion: MotionEstimate, recalibrated: bool) -> list[str]:
    """The map's warning about a log whose contacts flicker, outside the re-contact shares
    of the cockroach logs the readers were fitted on; ``recalibrated``: its beta_1
    confidence went through the flickering logs' recalibration
    (:mod:`swarmtopo.readers.recalibrated`)."""
    if motion.regime != "flickering":
        return []
    done = (f"{motion.merged} repeated contact starts were merged into their first before mapping"
            if motion.merged else "its repeated contact starts were kept (recontacts = keep)")
    trust = ("its beta_1 confidence is recalibrated on flickering logs (Brownian and flocking swarms), which are "
             "mapped right less often than the cockroach logs the reader was fitted on" if recalibrated else
             "the confidence was calibrated on persistent walkers only")
    return [f"the agents' contacts flicker ({100 * motion.recontact_share:.0f} % of the encounters repeat a pair's "
            f"contact within {RECONTACT_GAPS:g} median gaps; persistent walkers stay under {100 * FLICKER_SHARE:.0f} "
            f"% in swarms of a few hundred): diffusive or flocking agents; {done}, and {trust} "
            "(docs/model.md, 'Motion read from the log')"]
