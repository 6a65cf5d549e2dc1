r"""Encounter graph: the paper's three encounter metrics as sparse shortest-path graphs.

Definitions (paper, "Encounter Metric" to "A Hybrid Network")
-------------------------------------------------------------
Events E_i = [t_i, I_i^1, I_i^2] with ID sets I_i.  For an agent k let 𝒯_k be a
set of closed *stop intervals* of k.  The weight of two events i != j through a
shared agent k is

    w^k_ij = 0            if t_i, t_j in T for some T in 𝒯_k,
    w^k_ij = |t_i - t_j|  otherwise,

and the literal encounter graph G joins every pair of events sharing an agent with
``w_ij = min over k in I_i ∩ I_j of w^k_ij`` (a pair that met twice shares both
agents).  The metric is the shortest-path distance d_G.  The variants differ only
in 𝒯_k:

``plain``
    𝒯_k empty: w_ij = |t_i - t_j| (the encounter metric).
``contracted``
    𝒯_k = the stop intervals of k from its status changes
    (:meth:`EncounterLog.stop_intervals`, an open stop ends at +inf), as they are.
``hybrid``
    The contracted metric of a hybrid network: a static agent k, stopped for good at
    its static time s_k, adds the unbounded interval [s_k, inf), and overlapping or
    touching intervals of one agent are merged (it never moved again).  The paper
    writes w_ij = 0 whenever the shared agent is static; we zero only events at or
    after s_k, since before it the agent was still walking.  Needs no status rows.

Events at equal times on one agent are at distance 0 in every variant.

Sparse construction: consecutive events per agent
-------------------------------------------------
For each agent k sort its events by time (ties by event index), e_1, ..., e_m, and
join only consecutive ones, (e_p, e_{p+1}) with weight w^k_{e_p e_{p+1}}; parallel
edges keep the minimum.  Call this the chain graph C; it has fewer than 2N edges
instead of O(N^2).

**Claim.** d_C = d_G for all three variants (zero weights included).

*d_C >= d_G.*  Every chain edge joins two distinct events sharing agent k, so it is
an edge of G, and its chain weight is a minimum of w^k over the agents on whose
chains the two are consecutive, a subset of I_i ∩ I_j; hence it is >= w_ij.  Every
path of C is a path of G of no smaller weight.

*d_C <= d_G.*  Take an edge (i, j) of G and an agent k in I_i ∩ I_j with
w_ij = w^k_ij.  On k's chain, i = e_p and j = e_q with p < q (say), and the chain
path e_p, e_{p+1}, ..., e_q has weight at most sum_{r=p}^{q-1} w^k_{e_r e_{r+1}}.
If some T in 𝒯_k holds t_i and t_j, then every t_{e_r} lies in [t_i, t_j], which
is inside T because intervals are convex, so every term is 0 = w^k_ij.  Otherwise
each term is at most t_{e_{r+1}} - t_{e_r} >= 0 and the sum telescopes to
t_j - t_i = w^k_ij.  Replacing each edge of a shortest G-path by its chain path
gives a C-path of no larger weight.  ∎

Per-hop cost (swarmtopo's variant, not the paper's)
---------------------------------------------------
With ``hop_cost`` h > 0 every chain edge weighs w^k_{e_p e_{p+1}} + h, zero-weight
ones included (one stop interval, equal times), so nothing is merged: events at one
instant are up to r_d apart, and agents in contact at one instant can form chains
across the arena (at the start of a run a dense swarm percolates), which at zero cost
would be wormholes.  Consecutive
events of one agent are at most v_c |t_i - t_j| + r_d apart in the arena (each event
is within r_d/2 of the agent), so h ~ r_d / v_c makes the path length track distance
walked; at h = 0 a path changes agent at every encounter for free and, in a dense
swarm, distances shrink into noisy hop counts.  This metric lives on the chain graph
C: it is *not* the paper's all-pairs graph G with h added to every edge (there a path
pays one h for skipping many events).

Diffusive gaps (swarmtopo's variant, not the paper's)
-----------------------------------------------------
With ``diffusion_time`` tau < inf every chain edge's weight w = w^k_{e_p e_{p+1}} is
replaced by

    D_tau(w) = tau (sqrt(1 + 2 w / tau) - 1)      (w for w << tau, sqrt(2 tau w) for w >> tau)

before h is added.  D_tau is increasing, concave, D_tau(0) = 0 and D_tau -> w as tau ->
inf (the paper's weight).  A long gap between two encounters of one agent is the
least informative part of a path -- a walker that met no one for w seconds is
somewhere within reach of v_c w, and on average much closer: a random walk's
displacement grows like sqrt(w) -- so D_tau charges it about its typical
displacement, not its duration.  D_tau is subadditive, so it applies to the chain's
consecutive gaps: the claim above does not carry over, and this metric, like the
per-hop cost, lives on the chain graph C.

Wall-following time (swarmtopo's variant, not the paper's)
----------------------------------------------------------
With ``wall_follow_weight`` c (a number >= 0), the part w_WF of a chain gap that the
agent spent wall following (status WF, from its status changes; a state lasts until
the agent's next change, and before its first change counts as not WF) is taken out
of the diffusive compression and charged linearly::

    w -> D_tau(w - w_WF) + c w_WF        (then + h)

A wall-following agent walks along a wall, not at random, so its displacement grows
with the time itself, not with its square root; compressing it as a random walk's
would shorten exactly the paths that go round an obstacle.  c = None (default here)
charges w_WF like any other time (the paper's weight for tau = inf); a log without
status changes has w_WF = 0.  Each gap is charged on its own, so this metric too
lives on the chain graph C.

Zero weights and merged nodes
-----------------------------
Zero-weight chain edges (stop intervals, static agents, equal times) are contracted
first: their connected components (union-find, ``scipy.sparse.csgraph``) become the
*nodes* of the graph.  Quotienting by zero-weight edges keeps shortest-path
distances: a path maps to a path of equal weight with its zero edges gone, and a
path between nodes lifts by walking inside components at zero cost.  Between nodes
only strictly positive weights remain, so no sparse operation can drop a zero edge;
duplicate edges keep their minimum (never the sum that COO-to-CSR conversion
computes) and self-loops are dropped (they never shorten a path).  Nodes are
numbered by their earliest event.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.sparse.csgraph import connected_components, csgraph_from_dense, dijkstra

from .._validate import non_negative, positive
from ..errors import InputError
from ..log import WF, EncounterLog, exact_time

METRICS: tuple[str, ...] = ("plain", "contracted", "hybrid")
"""Encounter metrics: paper's plain encounter metric, contracted, hybrid network."""


@dataclass(frozen=True, eq=False)
class EncounterGraph:
    """Sparse encounter graph whose shortest paths are an encounter metric.

    Attributes
    ----------
    adjacency
        ``(n_nodes, n_nodes)`` symmetric float64 CSR matrix, sorted indices, every
        stored weight > 0 (zero-weight joins are merged into nodes).
    node_of_event
        ``(n_events,)`` int64: the node of each graph event.
    multiplicity
        ``(n_nodes,)`` int64: number of events merged into each node.
    event_t
        ``(n_events,)`` event times t_i, non-decreasing.
    event_index
        ``(n_events,)`` int64 index of each graph event in the original log (differs
        from ``arange`` after windowing or :meth:`subgraph`).
    metric
        One of :data:`METRICS`.
    """

    adjacency: sp.csr_matrix
    node_of_event: np.ndarray
    multiplicity: np.ndarray
    event_t: np.ndarray
    event_index: np.ndarray
    metric: str

    @property
    def n_nodes(self) -> int:
        return int(self.adjacency.shape[0])

    @property
    def n_events(self) -> int:
        return int(len(self.node_of_event))

    def representative_event(self) -> np.ndarray:
        """Original-log index of the earliest event of each node, shape ``(n_nodes,)``."""
        return self.event_index[self._first_events]

    def node_times(self) -> np.ndarray:
        """Time of each node: its earliest event's (``event_t`` is non-decreasing), shape ``(n_nodes,)``."""
        return self.event_t[self._first_events]

    @cached_property
    def _first_events(self) -> np.ndarray:
        """Index (into the graph's events) of each node's earliest event, found once per graph."""
        _, first = np.unique(self.node_of_event, return_index=True)
        return first

    def components(self) -> tuple[int, np.ndarray]:
        """Connected components: ``(count, label of each node)``."""
        count, labels = connected_components(self.adjacency, directed=False)
        return int(count), labels

    def subgraph(self, nodes) -> "EncounterGraph":
        """Induced subgraph on ``nodes`` (new node ``i`` is ``nodes[i]``), with their events.

        Distances in it are shortest paths that stay inside ``nodes``; on a union of
        connected components they equal the distances of the whole graph.
        """
        nodes = self._node_array(nodes, "nodes")
        if len(np.unique(nodes)) != len(nodes):
            raise InputError("subgraph nodes must be distinct", column="nodes")
        new_of_old = np.full(self.n_nodes, -1, np.int64)
        new_of_old[nodes] = np.arange(len(nodes))
        keep = np.flatnonzero(new_of_old[self.node_of_event] >= 0)
        adjacency = self.adjacency[nodes][:, nodes].tocsr()
        adjacency.sort_indices()
        return EncounterGraph(
            adjacency=adjacency,
            node_of_event=new_of_old[self.node_of_event[keep]],
            multiplicity=self.multiplicity[nodes],
            event_t=self.event_t[keep],
            event_index=self.event_index[keep],
            metric=self.metric,
        )

    def distances_from(self, sources, limit: float = np.inf) -> np.ndarray:
        """Shortest-path distances from source nodes to every node (Dijkstra).

        Parameters
        ----------
        sources
            Node indices (an int or a 1-D array).
        limit
            Search radius: nodes farther than ``limit`` get +inf (bounded searches
            for maxmin and k-NN; never an N x N matrix).

        Returns
        -------
        ndarray, shape ``(len(sources), n_nodes)``
        """
        sources = self._node_array(sources, "sources")
        if len(sources) == 0:
            return np.empty((0, self.n_nodes))
        # The matrix is symmetric, so the directed search is the undirected one without
        # scipy symmetrising a copy first.
        return dijkstra(self.adjacency, directed=True, indices=sources, limit=limit)

    def _node_array(self, values, name: str) -> np.ndarray:
        arr = np.atleast_1d(np.asarray(values))
        if arr.ndim != 1 or (len(arr) and arr.dtype.kind not in "iu"):
            raise InputError(f"{name} must be a 1-D array of node indices", column=name)
        arr = arr.astype(np.int64)
        bad = (arr < 0) | (arr >= self.n_nodes)
        if bad.any():
            raise InputError(f"node index out of range 0..{self.n_nodes - 1}", column=name,
                             value=int(arr[np.argmax(bad)]))
        return arr


def build_graph(log: EncounterLog, metric: str = "plain", *,
                window: tuple[float | None, float | None] | None = None,
                hop_cost: float = 0.0, diffusion_time: float = np.inf,
                wall_follow_weight: float | None = None) -> EncounterGraph:
    """Sparse chain graph of the events of ``log`` under an encounter metric.

    Parameters
    ----------
    log
        The encounter log (status changes and static agents define stop intervals).
    metric
        ``"plain"`` (w_ij = |t_i - t_j|), ``"contracted"`` (0 inside one stop interval
        of the shared agent) or ``"hybrid"`` (also 0 on a static agent from its static
        time on); see the module docstring.
    window
        ``(t0, t1)``: keep only events with t0 <= t_i <= t1 (None = unbounded), as
        :meth:`EncounterLog.window`.  Stop intervals always come from the whole log.
    hop_cost
        h >= 0, seconds, added to every chain edge (see "Per-hop cost" in the module
        docstring); 0 (default) is the paper's metric.
    diffusion_time
        tau > 0, seconds: chain gaps w weigh D_tau(w) (see "Diffusive gaps" in the module
        docstring); inf (default) is the paper's weight w.
    wall_follow_weight
        c >= 0: the wall-following part of each gap weighs c per second, outside D_tau
        (see "Wall-following time" in the module docstring); None (default) does not
        separate it, the paper's weight.

    Returns
    -------
    EncounterGraph
        Shortest paths between its nodes are exactly the paper's metric between the
        events merged into them; O(N) memory, O(N log N) time.

    Raises
    ------
    InputError
        Unknown metric, no events (in the window), a negative hop cost, a diffusion
        time that is not > 0 or a negative wall-following weight.
    """
    return weighted_chains(log, metric, window=window, hop_cost=hop_cost, diffusion_time=diffusion_time,
                           wall_follow_weight=wall_follow_weight).graph()


@dataclass(frozen=True)
class WeightedChains:
    """The chain graph's edges with their final weights (metric, D_tau, wall following,
    h), before zero-weight joins are merged: what a graph of any time window is cut from.

    ``first < second`` index the (windowed) events, which are sorted by time, so the
    events of a window [t0, t1] are one slice of them, and its chain edges are exactly
    the edges with both ends in that slice: an agent's consecutive events inside a
    window are consecutive in the whole log.  Each edge's weight depends on its two
    events and the whole log's status only, so :meth:`graph` of a window is the graph
    ``build_graph(log, window=...)`` builds, bit for bit.
    """

    first: np.ndarray
    second: np.ndarray
    weight: np.ndarray
    t: np.ndarray
    event_index: np.ndarray
    metric: str

    def graph(self, span: tuple[float, float] | None = None) -> EncounterGraph:
        """The encounter graph of the events with t0 <= t <= t1 (``span``; None: all)."""
        if span is None:
            return _contract(self.t, self.first, self.second, self.weight, self.event_index, self.metric)
        lo = int(np.searchsorted(self.t, span[0], side="left"))
        hi = int(np.searchsorted(self.t, span[1], side="right"))
        if hi <= lo:
            raise InputError(f"no encounter events in the window [{exact_time(span[0])}, {exact_time(span[1])}] s")
        inside = (self.first >= lo) & (self.second < hi)
        return _contract(self.t[lo:hi], self.first[inside] - lo, self.second[inside] - lo, self.weight[inside],
                         self.event_index[lo:hi], self.metric)


def weighted_chains(log: EncounterLog, metric: str = "plain", *,
                    window: tuple[float | None, float | None] | None = None,
                    hop_cost: float = 0.0, diffusion_time: float = np.inf,
                    wall_follow_weight: float | None = None) -> WeightedChains:
    """The chain edges of ``log`` (``window`` applied) weighted as :func:`build_graph`
    describes, ready to be cut into the graphs of time windows; raises as it does."""
    chains = chain_edges(log, metric, window)
    hop_cost = non_negative("hop cost", hop_cost)
    if wall_follow_weight is None:
        weight = diffusive_weight(chains.weight, diffusion_time)
    else:
        c = non_negative("wall-following weight", wall_follow_weight)
        following = np.minimum(state_time(log, WF, chains.agent, chains.t[chains.first], chains.t[chains.second]),
                               chains.weight)
        weight = diffusive_weight(chains.weight - following, diffusion_time) + c * following
    weight = weight + hop_cost
    return WeightedChains(chains.first, chains.second, weight, chains.t, chains.event_index, metric)


def diffusive_weight(weight: np.ndarray, diffusion_time: float) -> np.ndarray:
    """D_tau(w) = tau (sqrt(1 + 2 w / tau) - 1) of chain gaps w (module docstring);
    ``weight`` itself for tau = inf."""
    tau = positive("diffusion time", diffusion_time, allow_inf=True)
    if np.isinf(tau):
        return weight
    return tau * (np.sqrt(1.0 + 2.0 * weight / tau) - 1.0)


@dataclass(frozen=True)
class ChainEdges:
    """The chain graph's edges before contraction: consecutive events ``first`` ->
    ``second`` (indices into the windowed events) of ``agent``, with the metric's weight
    w^k (0 inside one stop interval), and the windowed events' times and log indices."""

    agent: np.ndarray
    first: np.ndarray
    second: np.ndarray
    weight: np.ndarray
    t: np.ndarray
    event_index: np.ndarray


def chain_edges(log: EncounterLog, metric: str = "plain",
                window: tuple[float | None, float | None] | None = None) -> ChainEdges:
    """Consecutive events of each agent in the (windowed) log and their weights under
    ``metric`` (no hop cost), grouped by agent in time order; raises as :func:`build_graph`."""
    _check_metric(metric)
    start, stop = event_slice(log, window)
    t, a, b = log.t[start:stop], log.a[start:stop], log.b[start:stop]
    pair_agent, first, second = _agent_chains(a, b)
    weight = t[second] - t[first]
    intervals = _stop_intervals(log, metric)
    if intervals is not None and len(intervals[0]):
        weight[_within_one_interval(pair_agent, t[first], t[second], intervals, log.n_agents)] = 0.0
    return ChainEdges(pair_agent, first, second, weight, t, np.arange(start, stop, dtype=np.int64))


def state_time(log: EncounterLog, state: int, agent: np.ndarray, t0: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """Seconds each ``agent[i]`` spent in status ``state`` (a code into
    :data:`~swarmtopo.log.STATES`) between ``t0[i] <= t1[i]``, from its status changes: a
    state lasts until the agent's next change (the last one for ever); before the
    agent's first change it counts as no state."""
    rows_agent, rows_t = log.status_agent, log.status_t  # sorted by (agent, t)
    offsets = _group_offsets(rows_agent, log.n_agents)
    same_next = np.r_[rows_agent[1:] == rows_agent[:-1], False]
    in_state = (log.status_state == state).astype(np.float64)
    spent = np.where(same_next, np.r_[rows_t[1:], 0.0] - rows_t, 0.0) * in_state
    # time in the state before each row: the agent's running sum of the rows before it
    running = np.cumsum(spent) - spent
    before = running - running[offsets[rows_agent]]
    out = np.empty(len(agent))
    _state_time(np.asarray(agent, np.int64), np.asarray(t0, np.float64), np.asarray(t1, np.float64),
                offsets, rows_t, before, in_state, out)
    return out


@njit(cache=True)
def _state_time(agent, t0, t1, offsets, rows_t, before, in_state, out):
    for p in range(len(agent)):
        out[p] = (_time_in_state_by(t1[p], offsets[agent[p]], offsets[agent[p] + 1], rows_t, before, in_state)
                  - _time_in_state_by(t0[p], offsets[agent[p]], offsets[agent[p] + 1], rows_t, before, in_state))


@njit(cache=True)
def _time_in_state_by(t, lo, hi, rows_t, before, in_state):
    """Time in the state from the agent's first status row (rows lo..hi-1) up to t."""
    j = lo + np.searchsorted(rows_t[lo:hi], t, side="right") - 1
    return before[j] + in_state[j] * (t - rows_t[j]) if j >= lo else 0.0


def agent_gaps(log: EncounterLog) -> np.ndarray:
    """|t_i - t_j| of every pair of consecutive events of one agent (the chain edges)."""
    _, first, second = _agent_chains(log.a, log.b)
    return log.t[second] - log.t[first]


def literal_distances(log: EncounterLog, metric: str,
                      window: tuple[float | None, float | None] | None = None) -> np.ndarray:
    """The metric by the paper's literal definition, all event pairs: O(N^2) memory.

    Joins *every* pair of events sharing an agent (weight min over shared agents) in
    a dense matrix and runs Dijkstra from every event: O(N^2) memory, up to O(N^3)
    time.  For tests and as the dense baseline of benchmarks only; use
    :func:`build_graph` for real data.

    Returns
    -------
    ndarray, shape ``(n_events, n_events)``
        Distances between the (windowed) events, +inf between disconnected ones.
    """
    _check_metric(metric)
    start, stop = event_slice(log, window)
    t, a, b = log.t[start:stop], log.a[start:stop], log.b[start:stop]
    n = len(t)
    weights = np.full((n, n), np.inf)
    intervals = _stop_intervals(log, metric)
    for k in np.unique(np.concatenate([a, b])):
        members = np.flatnonzero((a == k) | (b == k))
        tk = t[members]
        w = np.abs(tk[:, None] - tk[None, :])
        if intervals is not None:
            own = intervals[0] == k
            inside = ((tk[:, None] >= intervals[1][own]) & (tk[:, None] <= intervals[2][own])).astype(np.int64)
            w[(inside @ inside.T) > 0] = 0.0
        block = np.ix_(members, members)
        weights[block] = np.minimum(weights[block], w)
    np.fill_diagonal(weights, np.inf)
    return dijkstra(csgraph_from_dense(weights, null_value=np.inf), directed=False)


# -- construction steps ----------------------------------------------------------------
def _check_metric(metric) -> None:
    if metric not in METRICS:
        raise InputError(f"unknown encounter metric; expected one of {', '.join(METRICS)}",
                         column="metric", value=metric)


def event_slice(log: EncounterLog, window) -> tuple[int, int]:
    """Events t0 <= t <= t1 as a slice of the time-sorted log; raises if none."""
    try:
        t0, t1 = (None, None) if window is None else window
    except (TypeError, ValueError):
        raise InputError("window must be a pair (t0, t1); None leaves a side open", column="window",
                         value=window) from None
    lo = -np.inf if t0 is None else float(t0)
    hi = np.inf if t1 is None else float(t1)
    start = int(np.searchsorted(log.t, lo, side="left"))
    stop = int(np.searchsorted(log.t, hi, side="right"))
    if stop <= start:
        if log.n_events == 0:
            raise InputError("the encounter log has no events")
        raise InputError(f"no encounter events in the window [{exact_time(lo)}, {exact_time(hi)}] s; the log's "
                         f"events run from {exact_time(log.t[0])} to {exact_time(log.t[-1])} s")
    return start, stop


def _agent_chains(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Consecutive events of each agent: (agent, earlier event, later event).

    Events are sorted by time, so a stable sort of the incidences by agent lists each
    agent's events in time order.
    """
    incidence_agent = np.empty(2 * len(a), dtype=np.int64)
    incidence_agent[0::2], incidence_agent[1::2] = a, b
    order = np.argsort(incidence_agent, kind="stable")
    agent = incidence_agent[order]
    event = order // 2
    consecutive = agent[1:] == agent[:-1]
    return agent[:-1][consecutive], event[:-1][consecutive], event[1:][consecutive]


def _stop_intervals(log: EncounterLog, metric: str):
    """(agent, start, end) closed intervals 𝒯_k of the metric, sorted by (agent, start); None for plain."""
    if metric == "plain":
        return None
    agent, start, end = log.stop_intervals()
    if metric == "contracted":
        return agent, start, end
    agent = np.concatenate([agent, log.static_agent])
    start = np.concatenate([start, log.static_time])
    end = np.concatenate([end, np.full(len(log.static_agent), np.inf)])
    if len(agent) == 0:
        return agent, start, end
    order = np.lexsort((start, agent))
    agent, start, end = agent[order], start[order], end[order]
    reach = _running_max_per_group(_group_offsets(agent, log.n_agents), end)
    # a new merged interval starts at a new agent or past the reach of the previous ones
    head = np.ones(len(agent), dtype=bool)
    head[1:] = (agent[1:] != agent[:-1]) | (start[1:] > reach[:-1])
    heads = np.flatnonzero(head)
    tails = np.r_[heads[1:] - 1, len(agent) - 1]
    return agent[heads], start[heads], reach[tails]


def _group_offsets(sorted_group: np.ndarray, n_groups: int) -> np.ndarray:
    return np.r_[0, np.cumsum(np.bincount(sorted_group, minlength=n_groups))].astype(np.int64)


def _within_one_interval(pair_agent, t_first, t_second, intervals, n_agents) -> np.ndarray:
    """Whether [t_first, t_second] lies inside one interval of the pair's agent."""
    agent, start, end = intervals
    offsets = _group_offsets(agent, n_agents)
    # reach[j]: latest end among the agent's intervals starting at or before start[j];
    # some interval holds [t1, t2] iff the reach at the last start <= t1 is >= t2.
    reach = _running_max_per_group(offsets, end)
    return _covered(pair_agent, t_first, t_second, offsets, start, reach)


@njit(cache=True)
def _running_max_per_group(offsets, values):
    out = values.copy()
    for g in range(len(offsets) - 1):
        for j in range(offsets[g] + 1, offsets[g + 1]):
            if out[j - 1] > out[j]:
                out[j] = out[j - 1]
    return out


@njit(cache=True)
def _covered(pair_agent, t_first, t_second, offsets, start, reach):
    out = np.zeros(len(pair_agent), dtype=np.bool_)
    for p in range(len(pair_agent)):
        lo, hi = offsets[pair_agent[p]], offsets[pair_agent[p] + 1]
        j = lo + np.searchsorted(start[lo:hi], t_first[p], side="right") - 1
        out[p] = j >= lo and reach[j] >= t_second[p]
    return out


def _contract(t, first, second, weight, event_index, metric) -> EncounterGraph:
    """Merge zero-weight joins into nodes; CSR of the rest, min over duplicate edges."""
    n_events = len(t)
    zero = weight == 0.0
    if zero.any():
        joins = sp.coo_matrix((np.ones(int(zero.sum()), dtype=np.int8), (first[zero], second[zero])),
                              shape=(n_events, n_events)).tocsr()
        n_nodes, label = connected_components(joins, directed=False)
        # number nodes by their earliest event (events are sorted by time)
        _, earliest = np.unique(label, return_index=True)
        rank = np.empty(n_nodes, dtype=np.int64)
        rank[np.argsort(earliest)] = np.arange(n_nodes)
        node_of_event = rank[label]
    else:
        n_nodes, node_of_event = n_events, np.arange(n_events, dtype=np.int64)

    positive = ~zero
    u, v, w = node_of_event[first[positive]], node_of_event[second[positive]], weight[positive]
    loop = u == v
    if loop.any():
        u, v, w = u[~loop], v[~loop], w[~loop]
    # both directions of each edge, keyed row * n_nodes + column (CSR order)
    key = np.concatenate([u * n_nodes + v, v * n_nodes + u])
    del u, v
    order = np.argsort(key)
    key, w = key[order], np.concatenate([w, w])[order]
    del order
    head = np.flatnonzero(np.r_[True, key[1:] != key[:-1]]) if len(key) else np.empty(0, np.int64)
    data = np.minimum.reduceat(w, head) if len(head) else np.empty(0)
    key = key[head]
    index_dtype = np.int32 if n_nodes < np.iinfo(np.int32).max else np.int64
    indptr = np.r_[0, np.cumsum(np.bincount(key // n_nodes, minlength=n_nodes))].astype(index_dtype)
    adjacency = sp.csr_matrix((data, (key % n_nodes).astype(index_dtype), indptr), shape=(n_nodes, n_nodes))
    adjacency.has_sorted_indices = True
    return EncounterGraph(
        adjacency=adjacency,
        node_of_event=node_of_event.astype(np.int64),
        multiplicity=np.bincount(node_of_event, minlength=n_nodes).astype(np.int64),
        event_t=np.array(t, dtype=np.float64),
        event_index=event_index,
        metric=metric,
    )
