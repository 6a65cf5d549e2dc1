"""Regions: the components of the encounter graph that hold enough data to map.

Encounters never cross walls between regions, so separate regions give separate graph
components; too little data can also split one region.  A component with at least
``min_region_events`` events among at least ``MIN_REGION_AGENTS`` agents counts as a
region and is mapped on its own; a smaller one is reported as too little data.  The
diagram of the whole map is the union of the regions' diagrams -- exactly the Rips
diagram of the disjoint union (points in different regions are infinitely far apart),
so H0 has one infinite bar per region.  No inf or NaN ever reaches a persistence backend.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SwarmtopoError
from ..log import EncounterLog, exact_time
from ..metric.graph import EncounterGraph
from ..readers.beta0 import Beta0Evidence, beta0_evidence

MIN_REGION_AGENTS = 3
"""Distinct agents a component needs to count as a region (two agents alone that keep
meeting say nothing about the arena)."""


@dataclass(frozen=True)
class RegionSplit:
    """The mapped log's encounter graph cut into components, and which are regions:
    what a map maps and what beta_0 counts."""

    labels: np.ndarray  # component of each graph node
    event_comp: np.ndarray  # component of each mapped event
    events_per_comp: np.ndarray
    agents_per_comp: np.ndarray
    regions: list[int]  # the components that count as regions, most events first
    beta0: Beta0Evidence

    def too_little_data(self) -> list[dict[str, int]]:
        """The components that are not regions: their events and agents."""
        others = np.setdiff1d(np.arange(len(self.events_per_comp)), self.regions)
        return [{"component": int(c), "events": int(self.events_per_comp[c]), "agents": int(self.agents_per_comp[c])}
                for c in others]


def split_regions(log: EncounterLog, graph: EncounterGraph, min_region_events: int,
                  agent_gap: float | None) -> RegionSplit:
    """The components of ``graph`` (the mapped events of ``log``) and which are regions.

    Raises
    ------
    SwarmtopoError
        If the events are all at one instant, or no component is big enough to count
        as a region.
    """
    n_comp, labels = graph.components()
    event_comp = labels[graph.node_of_event]
    events_per_comp = np.bincount(event_comp, minlength=n_comp)
    agents_per_comp = agents_per_component(log, graph.event_index, event_comp, n_comp)
    times = graph.event_t
    if graph.n_events >= 2 and times.min() == times.max():
        raise SwarmtopoError(f"all {graph.n_events} encounters are at one time (t = {exact_time(times[0])} s); "
                             f"a map needs encounters spread over time")
    is_region = ((events_per_comp >= min_region_events) & (agents_per_comp >= MIN_REGION_AGENTS)
                 & (np.bincount(labels, minlength=n_comp) >= 2))  # one node: its encounters all at one instant
    regions = [int(c) for c in np.argsort(-events_per_comp, kind="stable") if is_region[c]]
    if not regions:
        largest = int(np.argmax(events_per_comp))
        if np.count_nonzero(labels == largest) == 1 and agents_per_comp[largest] >= MIN_REGION_AGENTS:
            raise SwarmtopoError(
                f"the largest connected group of encounters ({int(events_per_comp[largest])} events among "
                f"{int(agents_per_comp[largest])} agents) is a single point of the encounter metric: its agents never "
                f"moved between their encounters (static from the start, as meta.json 'static' says, or stopped), so "
                f"there is nothing to map")
        raise SwarmtopoError(
            f"no connected group of encounters has {min_region_events} events or more among "
            f"{MIN_REGION_AGENTS} agents or more (largest: {int(events_per_comp[largest])} events among "
            f"{int(agents_per_comp[largest])} agents, of {graph.n_events} events in {n_comp} groups); "
            f"the log is too short or the agents too few to map: collect more data")
    a, b = log.a[graph.event_index], log.b[graph.event_index]
    region_of_comp = np.full(n_comp, -1)
    region_of_comp[regions] = np.arange(len(regions))
    region_of_agent = np.full(log.n_agents, -1)
    region_of_agent[a] = region_of_agent[b] = region_of_comp[event_comp]  # an agent's events share a component
    evidence = beta0_evidence(a, b, graph.event_t, region_of_agent, len(regions),
                              int(events_per_comp[regions].sum()), agent_gap)
    return RegionSplit(labels, event_comp, events_per_comp, agents_per_comp, regions, evidence)


def region_part(graph: EncounterGraph, labels: np.ndarray, region_events: np.ndarray, log: EncounterLog,
                min_region_events: int) -> EncounterGraph | None:
    """The largest component of a window's ``graph`` among the region's events, if it is
    big enough to map (``min_region_events`` events, ``MIN_REGION_AGENTS`` agents); else None."""
    inside = np.isin(graph.event_index, region_events)
    if not inside.any():
        return None
    comps, sizes = np.unique(labels[graph.node_of_event[inside]], return_counts=True)
    comp = comps[np.argmax(sizes)]
    if sizes.max() < min_region_events:
        return None
    sub = graph.subgraph(np.flatnonzero(labels == comp))
    agents = np.unique(np.concatenate([log.a[sub.event_index], log.b[sub.event_index]]))
    return sub if len(agents) >= MIN_REGION_AGENTS and sub.n_nodes >= 2 else None


def agents_per_component(log: EncounterLog, event_index: np.ndarray, event_comp: np.ndarray,
                         n_comp: int) -> np.ndarray:
    """Distinct agents among each component's events."""
    comp = np.concatenate([event_comp, event_comp])
    agent = np.concatenate([log.a[event_index], log.b[event_index]])
    pairs = np.unique(comp * np.int64(log.n_agents) + agent)
    return np.bincount(pairs // log.n_agents, minlength=n_comp)
