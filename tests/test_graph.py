"""Encounter graph: hand-computed metrics, agreement with the literal definition, scale."""

import math
import tracemalloc

import networkx as nx
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from swarmtopo.errors import InputError
from swarmtopo.metric.graph import METRICS, EncounterGraph, build_graph, literal_distances, state_time
from swarmtopo.log import RW, S, STATES, WF, EncounterLog

INF = np.inf


def event_distances(graph: EncounterGraph) -> np.ndarray:
    """All-pairs distances between the graph's events (small graphs only)."""
    node_d = graph.distances_from(np.arange(graph.n_nodes))
    return node_d[np.ix_(graph.node_of_event, graph.node_of_event)]


# -- hand-computed logs ------------------------------------------------------------------
def stop_and_static_log(static_time=4.0, with_status=True):
    """Agents 0..3.  Events, already in (t, a, b) order:
    e0 t=1 (0,2); e1 t=2 (1,2); e2 t=5 (2,3); e3 t=7 (0,2); e4 t=8 (1,3).
    Agent 2 is stopped in [2, 6] (S at 2, RW at 6); agent 3 is static from ``static_time``.
    """
    status = ([2, 6], [2, 2], ["S", "RW"]) if with_status else None
    return EncounterLog.from_records([1, 2, 5, 7, 8], [0, 1, 2, 0, 1], [2, 2, 3, 2, 3],
                                     status=status, static=([3], [static_time]))


def test_plain_metric_hand_computed():
    # Literal edges: agent 2 joins e0..e3 (|dt|), agent 0: e0-e3 = 6, agent 1: e1-e4 = 6,
    # agent 3: e2-e4 = 3.
    # d(e0,e4) = e0-e2-e4 = 4 + 3 = 7 (= e0-e1-e4 = 1 + 6)
    # d(e3,e4) = e3-e2-e4 = 2 + 3 = 5 (e3-e1-e4 = 5 + 6 = 11; |7 - 8| = 1 is no path)
    # d(e1,e4) = min(6, e1-e2-e4 = 3 + 3) = 6
    expected = np.array([
        [0, 1, 4, 6, 7],
        [1, 0, 3, 5, 6],
        [4, 3, 0, 2, 3],
        [6, 5, 2, 0, 5],
        [7, 6, 3, 5, 0],
    ], dtype=float)
    graph = build_graph(stop_and_static_log(), "plain")
    assert graph.n_nodes == 5 and graph.n_events == 5
    np.testing.assert_array_equal(event_distances(graph), expected)


def test_contracted_metric_hand_computed():
    # e1 (t=2) and e2 (t=5) both lie in agent 2's stop [2, 6]: w_12 = 0 (e0 at t=1 and
    # e3 at t=7 do not).  So e1, e2 are one node.
    # d(e0,e2) = e0-e1-e2 = 1 + 0 = 1;   d(e0,e3) = e0-e1-e2-e3 = 1 + 0 + 2 = 3
    # d(e1,e3) = e1-e2-e3 = 0 + 2 = 2;   d(e1,e4) = e1-e2-e4 = 0 + 3 = 3
    # d(e0,e4) = 1 + 0 + 3 = 4;          d(e3,e4) = e3-e2-e4 = 2 + 3 = 5
    expected = np.array([
        [0, 1, 1, 3, 4],
        [1, 0, 0, 2, 3],
        [1, 0, 0, 2, 3],
        [3, 2, 2, 0, 5],
        [4, 3, 3, 5, 0],
    ], dtype=float)
    graph = build_graph(stop_and_static_log(), "contracted")
    assert graph.n_nodes == 4
    np.testing.assert_array_equal(graph.multiplicity, [1, 2, 1, 1])
    np.testing.assert_array_equal(graph.node_of_event, [0, 1, 1, 2, 3])
    np.testing.assert_array_equal(event_distances(graph), expected)


def test_hybrid_metric_hand_computed():
    # As contracted, plus agent 3 static from t=4: e2 (t=5) and e4 (t=8) are both
    # after 4, so w_24 = 0 and {e1, e2, e4} is one node.
    # d(e0,e4) = e0-e1 = 1;  d(e3,e4) = e3-e2 = 2;  d(e0,e3) = 1 + 0 + 2 = 3
    expected = np.array([
        [0, 1, 1, 3, 1],
        [1, 0, 0, 2, 0],
        [1, 0, 0, 2, 0],
        [3, 2, 2, 0, 2],
        [1, 0, 0, 2, 0],
    ], dtype=float)
    graph = build_graph(stop_and_static_log(), "hybrid")
    np.testing.assert_array_equal(graph.multiplicity, [1, 3, 1])
    np.testing.assert_array_equal(event_distances(graph), expected)


def test_hybrid_zeroes_a_static_agent_only_from_its_static_time():
    # Static from t=6: e2 (t=5) is before it, so w_24 = |5 - 8| = 3 stays; hybrid equals
    # contracted here.
    log = stop_and_static_log(static_time=6.0)
    np.testing.assert_array_equal(event_distances(build_graph(log, "hybrid")),
                                  event_distances(build_graph(log, "contracted")))


def test_hybrid_without_status_rows_uses_static_agents_only():
    # No stop intervals: the only zero join is e2-e4 via static agent 3 (t=5, 8 >= 4).
    # d(e1,e4) = e1-e2-e4 = 3 + 0 = 3;  d(e0,e4) = e0-e2-e4 = 4 + 0 = 4
    # d(e3,e4) = e3-e2 = 2;  d(e1,e2) = 3 (no stop of agent 2 without status rows)
    log = stop_and_static_log(with_status=False)
    expected = np.array([
        [0, 1, 4, 6, 4],
        [1, 0, 3, 5, 3],
        [4, 3, 0, 2, 0],
        [6, 5, 2, 0, 2],
        [4, 3, 0, 2, 0],
    ], dtype=float)
    np.testing.assert_array_equal(event_distances(build_graph(log, "hybrid")), expected)
    # and contracted == plain when there are no status rows
    np.testing.assert_array_equal(event_distances(build_graph(log, "contracted")),
                                  event_distances(build_graph(log, "plain")))


def test_hybrid_merges_a_stop_touching_the_static_interval():
    # Agent 1 is stopped in [2, 4] (S at 2, RW at 4) and static from 4: merged into
    # [2, inf), so its events at t=3 and t=7 are one place (hybrid 0), while the
    # contracted metric only knows [2, 4]: 7 - 3 = 4.
    log = EncounterLog.from_records([3, 7], [0, 1], [1, 2], status=([2, 4], [1, 1], ["S", "RW"]),
                                    static=([1], [4]))
    assert event_distances(build_graph(log, "hybrid"))[0, 1] == 0
    assert event_distances(build_graph(log, "contracted"))[0, 1] == 4


def test_open_stop_contracts_to_the_end():
    # Agent 0: S at 1 and no later status: stop [1, inf); events at 1 and 9 join at 0,
    # the event at 0.5 (before the stop) is 0.5 away.
    log = EncounterLog.from_records([0.5, 1, 9], [0, 0, 0], [1, 2, 3], status=([1], [0], ["S"]))
    d = event_distances(build_graph(log, "contracted"))
    np.testing.assert_array_equal(d, [[0, 0.5, 0.5], [0.5, 0, 0], [0.5, 0, 0]])


def test_pair_meeting_twice_in_a_row_keeps_the_minimum_not_the_sum():
    # e0 t=0 (0,1), e1 t=2 (0,1) are consecutive on both chains (agents 0 and 1): two
    # parallel edges of weight 2 -> 2 (summing duplicates would give 4).
    # e2 t=5 (1,2): d(e0,e2) = 2 + 3 = 5.
    log = EncounterLog.from_records([0, 2, 5], [0, 0, 1], [1, 1, 2])
    graph = build_graph(log, "plain")
    assert graph.adjacency[0, 1] == 2.0
    np.testing.assert_array_equal(event_distances(graph), [[0, 2, 5], [2, 0, 3], [5, 3, 0]])


def test_shared_agents_take_the_minimum_over_agents():
    # e0 t=1 (0,1), e1 t=4 (0,1): agent 0 is stopped in [0, 5], agent 1 is not; the
    # pair shares both agents, so w = min(0 via agent 0, 3 via agent 1) = 0.
    log = EncounterLog.from_records([1, 4], [0, 0], [1, 1], status=([0, 5], [0, 0], ["S", "RW"]))
    graph = build_graph(log, "contracted")
    assert graph.n_nodes == 1
    assert event_distances(graph)[0, 1] == 0


def test_equal_times_merge_and_disjoint_agents_are_infinitely_far():
    # Sorted events: e0 t=3 (0,1), e1 t=3 (1,2), e2 t=4 (4,5), e3 t=5 (2,3).
    # e0, e1 share agent 1 at equal times: weight 0 in every metric -> one node.
    # d(e0,e3) = e0-e1-e3 = 0 + (5 - 3) = 2; e2 shares no agent with anyone: inf.
    log = EncounterLog.from_records([3, 3, 5, 4], [0, 1, 2, 4], [1, 2, 3, 5])
    expected = np.array([[0, 0, INF, 2], [0, 0, INF, 2], [INF, INF, 0, INF], [2, 2, INF, 0]])
    for metric in METRICS:
        graph = build_graph(log, metric)
        np.testing.assert_array_equal(graph.multiplicity, [2, 1, 1])
        np.testing.assert_array_equal(event_distances(graph), expected)
        np.testing.assert_array_equal(literal_distances(log, metric), expected)
        count, labels = graph.components()
        assert count == 2 and labels[0] == labels[2] != labels[1]


# -- literal definition, independently with networkx ------------------------------------
def merged(intervals):
    """Union of closed intervals, overlapping or touching ones merged."""
    out = []
    for start, end in sorted(intervals):
        if out and start <= out[-1][1]:
            out[-1][1] = max(out[-1][1], end)
        else:
            out.append([start, end])
    return out


def intervals_in_state(log: EncounterLog, state_name: str) -> dict[int, list[tuple[float, float]]]:
    """Per agent, the intervals [row, next row of the agent) whose status row says
    ``state_name``, read literally off the status rows without log.stop_intervals():
    in time order, a row starts (or continues) the state until the agent's next row,
    or forever if it has none."""
    rows = {}
    for t, agent, state in zip(log.status_t.tolist(), log.status_agent.tolist(), log.status_state.tolist()):
        rows.setdefault(agent, []).append((t, STATES[state]))
    out = {}
    for agent, seq in rows.items():
        seq.sort()
        for (t, state), (t_next, _) in zip(seq, seq[1:] + [(INF, None)]):
            if state == state_name:
                out.setdefault(agent, []).append((t, t_next))
    return out


def networkx_distances(log: EncounterLog, metric: str, window=None) -> np.ndarray:
    """The paper's definition literally: every pair of events sharing an agent."""
    lo, hi = (-INF, INF) if window is None else window
    events = [(float(t), {int(a), int(b)}) for t, a, b in zip(log.t, log.a, log.b) if lo <= t <= hi]
    stops = intervals_in_state(log, "S") if metric != "plain" else {}
    if metric == "hybrid":
        for agent, time in zip(log.static_agent, log.static_time):
            stops.setdefault(int(agent), []).append((float(time), INF))
    stops = {k: merged(v) for k, v in stops.items()}  # consecutive S rows: one stop
    g = nx.Graph()
    g.add_nodes_from(range(len(events)))
    for i, (ti, ai) in enumerate(events):
        for j in range(i + 1, len(events)):
            tj, aj = events[j]
            weights = [0.0 if any(s <= ti <= e and s <= tj <= e for s, e in stops.get(k, [])) else abs(ti - tj)
                       for k in ai & aj]
            if weights:
                g.add_edge(i, j, weight=min(weights))
    out = np.full((len(events), len(events)), INF)
    for i, lengths in nx.all_pairs_dijkstra_path_length(g):
        for j, d in lengths.items():
            out[i, j] = d
    return out


@st.composite
def small_logs(draw):
    """Random small logs: times on a 0.25 grid (ties likely, sums of gaps exact), random
    pairs, status rows with S / RW / WF incl. open stops, random static agents."""
    n_agents = draw(st.integers(2, 6))
    time = st.integers(0, 16).map(lambda k: k * 0.25)
    agent = st.integers(0, n_agents - 1)
    events = draw(st.lists(st.tuples(time, agent, agent).filter(lambda e: e[1] != e[2]), min_size=1,
                           max_size=14, unique_by=lambda e: (e[0], min(e[1:]), max(e[1:]))))
    status = draw(st.lists(st.tuples(time, agent, st.sampled_from(STATES)), max_size=10,
                           unique_by=lambda row: row[:2]))  # one row per agent and time
    static_agents = draw(st.lists(agent, unique=True, max_size=n_agents))
    static_times = [draw(time) for _ in static_agents]
    t, a, b = zip(*events)
    return EncounterLog.from_records(
        t, a, b,
        status=tuple(zip(*status)) if status else None,
        static=(static_agents, static_times) if static_agents else None,
        meta={"agent_count": n_agents},
    )


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(log=small_logs(), data=st.data())
def test_chain_graph_equals_literal_definition(log, data):
    window = data.draw(st.one_of(st.none(), st.tuples(st.integers(0, 8), st.integers(8, 16))
                                 .map(lambda w: (w[0] * 0.25, w[1] * 0.25))))
    if window is not None and not ((log.t >= window[0]) & (log.t <= window[1])).any():
        window = None
    for metric in METRICS:
        expected = networkx_distances(log, metric, window)
        graph = build_graph(log, metric, window=window)
        np.testing.assert_allclose(event_distances(graph), expected, rtol=0, atol=1e-12)
        np.testing.assert_allclose(literal_distances(log, metric, window), expected, rtol=0, atol=1e-12)


@settings(max_examples=100, deadline=None)
@given(log=small_logs(), metric=st.sampled_from(METRICS))
def test_graph_invariants(log, metric):
    graph = build_graph(log, metric)
    adj = graph.adjacency
    assert adj.dtype == np.float64 and adj.has_sorted_indices
    assert (adj.data > 0).all()
    assert (adj != adj.T).nnz == 0
    assert adj.diagonal().sum() == 0
    assert graph.multiplicity.sum() == graph.n_events == log.n_events
    np.testing.assert_array_equal(graph.multiplicity, np.bincount(graph.node_of_event, minlength=graph.n_nodes))
    assert (graph.multiplicity > 0).all()
    # nodes are numbered by their earliest event, which is their representative
    rep = graph.representative_event()
    assert (np.diff(rep) > 0).all()
    times = graph.node_times()
    for node in range(graph.n_nodes):
        assert rep[node] == graph.event_index[graph.node_of_event == node].min()
        assert times[node] == graph.event_t[graph.node_of_event == node].min()


# -- windowing, subgraphs, searches ------------------------------------------------------
def random_log(n_events, n_agents, duration, rng, stops_per_agent=5, static_fraction=0.05):
    """Uniform random encounters; alternating S / RW status rows; a few static agents."""
    rng = np.random.default_rng(rng)
    t = np.sort(rng.uniform(0, duration, n_events))
    a = rng.integers(0, n_agents, n_events)
    b = (a + rng.integers(1, n_agents, n_events)) % n_agents
    rows = 2 * stops_per_agent
    status_t = np.sort(rng.uniform(0, duration, (n_agents, rows)), axis=1).ravel()
    static = np.sort(rng.choice(n_agents, max(1, int(static_fraction * n_agents)), replace=False))
    return EncounterLog(
        t=t, a=np.minimum(a, b), b=np.maximum(a, b), agent_ids=np.arange(n_agents),
        status_t=status_t, status_agent=np.repeat(np.arange(n_agents), rows),
        status_state=np.tile(np.array([S, RW], np.int8), n_agents * stops_per_agent),
        static_agent=static, static_time=rng.uniform(0, duration, len(static)),
    )


def test_window_keeps_exactly_the_events_in_the_closed_window():
    log = random_log(400, 15, 50.0, rng=1)
    t0, t1 = log.t[57], log.t[311]  # boundaries on events: both must be kept
    for window, keep in [((t0, t1), (log.t >= t0) & (log.t <= t1)),
                         ((None, t1), log.t <= t1),
                         ((t0, None), log.t >= t0)]:
        graph = build_graph(log, "hybrid", window=window)
        np.testing.assert_array_equal(graph.event_index, np.flatnonzero(keep))
        np.testing.assert_array_equal(graph.event_t, log.t[keep])
    graph = build_graph(log, "contracted", window=(t0, t1))
    assert graph.event_index[0] == 57 and graph.event_index[-1] == 311
    # stop intervals come from the whole log, events from the window
    whole_window = log.window(t0, t1)
    np.testing.assert_allclose(event_distances(graph), literal_distances(whole_window, "contracted"))


def test_subgraph_of_a_component_keeps_its_distances():
    # two groups of 10 agents that never meet each other: at least two components
    rng = np.random.default_rng(2)
    a = rng.integers(0, 10, 300)
    b = (a + rng.integers(1, 10, 300)) % 10
    group = 10 * rng.integers(0, 2, 300)
    log = EncounterLog.from_records(rng.uniform(0, 30, 300), a + group, b + group,
                                    static=([3, 14], [10.0, 20.0]))
    graph = build_graph(log, "hybrid")
    count, labels = graph.components()
    assert count >= 2
    nodes = np.flatnonzero(labels == labels[0])[::-1]  # a given order, reversed
    sub = graph.subgraph(nodes)
    np.testing.assert_array_equal(sub.multiplicity, graph.multiplicity[nodes])
    kept = np.isin(graph.node_of_event, nodes)
    np.testing.assert_array_equal(sub.event_index, graph.event_index[kept])
    np.testing.assert_array_equal(nodes[sub.node_of_event], graph.node_of_event[kept])
    np.testing.assert_array_equal(sub.distances_from(np.arange(len(nodes))),
                                  graph.distances_from(nodes)[:, nodes])
    assert sub.adjacency.has_sorted_indices and (sub.adjacency.data > 0).all()


def test_distances_from_is_bounded_by_limit():
    log = random_log(500, 20, 40.0, rng=3)
    graph = build_graph(log, "plain")
    full = graph.distances_from([0, 17])
    bounded = graph.distances_from([0, 17], limit=5.0)
    within = full <= 5.0
    np.testing.assert_array_equal(bounded[within], full[within])
    assert np.isinf(bounded[~within]).all()
    assert graph.distances_from(3).shape == (1, graph.n_nodes)


def test_build_is_deterministic():
    log = random_log(2000, 30, 100.0, rng=4)
    g1, g2 = build_graph(log, "hybrid"), build_graph(log, "hybrid")
    for x, y in [(g1.adjacency.data, g2.adjacency.data), (g1.adjacency.indices, g2.adjacency.indices),
                 (g1.node_of_event, g2.node_of_event)]:
        np.testing.assert_array_equal(x, y)


# -- errors --------------------------------------------------------------------------------
def test_unknown_metric_names_value_and_choices():
    log = stop_and_static_log()
    with pytest.raises(InputError, match=r"'geodesic'.*plain, contracted, hybrid"):
        build_graph(log, "geodesic")
    with pytest.raises(InputError, match="geodesic"):
        literal_distances(log, "geodesic")


def test_empty_log_and_empty_window_are_input_errors():
    empty = EncounterLog.from_records([], [], [])
    with pytest.raises(InputError, match="no events"):
        build_graph(empty)
    with pytest.raises(InputError, match="no encounter events in the window"):
        build_graph(stop_and_static_log(), window=(2.5, 4.5))
    with pytest.raises(InputError, match="pair"):
        build_graph(stop_and_static_log(), window=3.0)


def test_bad_node_indices_are_input_errors():
    graph = build_graph(stop_and_static_log(), "plain")
    with pytest.raises(InputError, match="out of range"):
        graph.distances_from([5])
    with pytest.raises(InputError, match="distinct"):
        graph.subgraph([1, 1])


# -- scale ----------------------------------------------------------------------------------
@pytest.mark.slow
def test_million_events_build_in_linear_memory():
    # 10^6 events, 2000 agents: the chain graph holds < 4 * 10^6 directed edges; a
    # sparse build needs a few hundred bytes per event (about 250 MB measured), an
    # N x N matrix would need 8 TB.
    log = random_log(10**6, 2000, 600.0, rng=5)
    for metric in ("plain", "hybrid"):
        tracemalloc.start()
        graph = build_graph(log, metric)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert graph.n_events == 10**6
        assert peak < 500 * 2**20, f"{metric}: peak {peak / 2**20:.0f} MiB"


# -- per-hop cost ----------------------------------------------------------------------------
def test_hop_cost_hand_computed_on_the_chain_graph():
    # Plain metric, h = 1: chain edges agent 0 e0-e3 7, agent 1 e1-e4 7, agent 2 e0-e1 2,
    # e1-e2 4, e2-e3 3, agent 3 e2-e4 4.  d(e0,e2) = e0-e1-e2 = 6, where the paper's
    # all-pairs graph plus h would give the direct edge 4 + 1 = 5: the two differ.
    expected = np.array([
        [0, 2, 6, 7, 9],
        [2, 0, 4, 7, 7],
        [6, 4, 0, 3, 4],
        [7, 7, 3, 0, 7],
        [9, 7, 4, 7, 0],
    ], dtype=float)
    graph = build_graph(stop_and_static_log(), "plain", hop_cost=1.0)
    np.testing.assert_array_equal(event_distances(graph), expected)


def chain_distances_with_hop_cost(log: EncounterLog, metric: str, h: float, tau: float = INF,
                                  c: float | None = None) -> np.ndarray:
    """Literal chain metric with per-hop cost: each agent's events in time order, joined
    consecutively by the paper's weight w (0 inside one stop interval of that agent, read
    off the status rows as in networkx_distances); with c, the gap's overlap f with the
    agent's wall-following intervals is split off and weighs c f; the rest is made
    diffusive, tau (sqrt(1 + 2 w / tau) - 1), unless tau is inf; plus h."""
    following = intervals_in_state(log, "WF")
    stops = intervals_in_state(log, "S") if metric != "plain" else {}
    if metric == "hybrid":
        for agent, time in zip(log.static_agent, log.static_time):
            stops.setdefault(int(agent), []).append((float(time), INF))
    stops = {k: merged(v) for k, v in stops.items()}
    g = nx.Graph()
    g.add_nodes_from(range(log.n_events))
    for k in range(log.n_agents):
        members = [i for i in range(log.n_events) if k in (log.a[i], log.b[i])]
        for i, j in zip(members, members[1:]):
            ti, tj = float(log.t[i]), float(log.t[j])
            still = any(s <= ti <= e and s <= tj <= e for s, e in stops.get(k, []))
            w = 0.0 if still else tj - ti
            f = 0.0 if c is None or still else sum(max(0.0, min(tj, e) - max(ti, s))
                                                   for s, e in following.get(k, []))
            w = (w - f if tau == INF else tau * (math.sqrt(1 + 2 * (w - f) / tau) - 1)) + (c or 0.0) * f + h
            if not g.has_edge(i, j) or g[i][j]["weight"] > w:
                g.add_edge(i, j, weight=w)
    out = np.full((log.n_events, log.n_events), INF)
    for i, lengths in nx.all_pairs_dijkstra_path_length(g):
        for j, d in lengths.items():
            out[i, j] = d
    return out


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(log=small_logs(), h=st.sampled_from([0.5, 2.0]), tau=st.sampled_from([INF, 0.7, 3.0]),
       c=st.sampled_from([None, 0.0, 2.0]), metric=st.sampled_from(METRICS))
def test_hop_cost_graph_equals_literal_chain(log, h, tau, c, metric):
    graph = build_graph(log, metric, hop_cost=h, diffusion_time=tau, wall_follow_weight=c)
    distances = event_distances(graph)
    np.testing.assert_allclose(distances, chain_distances_with_hop_cost(log, metric, h, tau, c), rtol=0, atol=1e-9)
    # D_tau(w - f) + c f <= w for c <= 1: diffusive weights never lengthen a path
    if c is None or c <= 1:
        assert (distances <= event_distances(build_graph(log, metric, hop_cost=h)) + 1e-9).all()


def test_diffusive_weights_hand_computed():
    # The log of the hop-cost test, plain metric, h = 0, tau = 4: D(w) = 4 (sqrt(1 + w / 2) - 1),
    # so agent 0's gap e0-e3 of 6 s weighs D(6) = 4 and agent 2's e0-e1, e1-e2, e2-e3 of
    # 1, 3, 2 s weigh D(1) + D(3) + D(2) = 4.88 > 4: the single long gap is now the shorter
    # way (at tau = inf both are 6 s).  d(e0, e4) = D(1) + D(6) via agent 1's 6 s gap e1-e4;
    # d(e1, e3) = D(3) + D(2) = 3.98 along agent 2's chain (e1-e0-e3: D(1) + 4 = 4.90).
    def d(w):
        return 4.0 * (math.sqrt(1.0 + w / 2.0) - 1.0)

    distances = event_distances(build_graph(stop_and_static_log(), "plain", diffusion_time=4.0))
    assert distances[0, 3] == pytest.approx(4.0)
    assert distances[1, 3] == pytest.approx(d(3) + d(2))
    assert distances[0, 4] == pytest.approx(d(1) + 4.0)
    assert event_distances(build_graph(stop_and_static_log(), "plain"))[0, 3] == 6.0


def wall_following_log() -> EncounterLog:
    """Agent 0 meets agent 1 at t = 1 and agent 2 at t = 7; its status: RW at 0, WF at
    2, RW at 5, S at 8 (agent 1 has no status rows, agent 2 is WF from t = 6 on)."""
    return EncounterLog.from_records([1, 7], [0, 0], [1, 2],
                                     status=([0, 2, 5, 8, 6], [0, 0, 0, 0, 2], ["RW", "WF", "RW", "S", "WF"]))


def test_state_time_hand_computed():
    log = wall_following_log()
    agent = np.array([0, 0, 0, 0, 0, 1, 2, 2])
    t0 = np.array([1.0, 3.0, 0.0, 5.0, 9.0, 0.0, 0.0, 6.5])
    t1 = np.array([6.0, 4.0, 10.0, 8.0, 12.0, 10.0, 10.0, 6.5])
    # agent 0 is WF in [2, 5): 3, 1, 3, 0, 0 s; agent 1 has no rows: 0; agent 2 from 6 on: 4, 0
    np.testing.assert_allclose(state_time(log, WF, agent, t0, t1), [3, 1, 3, 0, 0, 0, 4, 0])
    # stops: agent 0 is S from 8 on (the last row lasts forever)
    np.testing.assert_allclose(state_time(log, S, agent[:5], t0[:5], t1[:5]), [0, 0, 2, 0, 3])


def test_wall_following_weight_hand_computed():
    # Agent 0's gap e0 (t=1) -> e1 (t=7) is 6 s, of which 3 s wall following (in [2, 5)).
    # tau = 4, c = 2: D_4(6 - 3) + 2 x 3 = 4 (sqrt(1 + 6 / 4) - 1) + 6 = 8.325, plus h = 0.5.
    log = wall_following_log()
    d = event_distances(build_graph(log, "plain", hop_cost=0.5, diffusion_time=4.0, wall_follow_weight=2.0))
    assert d[0, 1] == pytest.approx(4.0 * (math.sqrt(2.5) - 1.0) + 6.0 + 0.5)
    # None: the whole 6 s is diffusive, D_4(6) = 4; with tau = inf and c = 1 it is the paper's 6 s
    none = event_distances(build_graph(log, "plain", diffusion_time=4.0))
    assert none[0, 1] == pytest.approx(4.0)
    assert event_distances(build_graph(log, "plain", wall_follow_weight=1.0))[0, 1] == pytest.approx(6.0)
    # a log without status rows is unaffected
    bare = EncounterLog.from_records([1, 7], [0, 0], [1, 2])
    assert event_distances(build_graph(bare, "plain", diffusion_time=4.0, wall_follow_weight=2.0))[0, 1] == \
        pytest.approx(4.0)


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf"), "two"])
def test_bad_wall_following_weight_is_an_input_error(bad):
    with pytest.raises(InputError, match="wall-following weight"):
        build_graph(wall_following_log(), "plain", wall_follow_weight=bad)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), "two"])
def test_bad_diffusion_time_is_an_input_error(bad):
    with pytest.raises(InputError, match="diffusion time"):
        build_graph(stop_and_static_log(), "plain", diffusion_time=bad)


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf"), "two"])
def test_bad_hop_cost_is_an_input_error(bad):
    with pytest.raises(InputError, match="hop cost"):
        build_graph(stop_and_static_log(), "plain", hop_cost=bad)
