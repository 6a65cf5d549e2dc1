"""End-to-end mapping: log -> TopologicalMap, checked against known topology."""

import json
import re
from dataclasses import replace

import numpy as np
import pytest

from swarmtopo.arena import default_arena, square_arena, two_rooms_arena
from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.log import EncounterLog
from swarmtopo.pipeline import MapConfig, map_encounters, settings
from swarmtopo.pipeline.config import WHOLE_LOG, ConfigError, config_from_options
from swarmtopo.pipeline.map import share_landmarks
from swarmtopo.pipeline.settings import DIFFUSION_GAP_FACTOR, HOP_GAP_FACTOR, mean_agent_gap
from swarmtopo.pipeline.windows import scaled_windows, window_length, window_spans
from swarmtopo.readers.registry import load_classifier, shipped_reader_for
from swarmtopo.viz.summary import advice, map_json, window_json
from swarmtopo.sim import simulate

FAST = dict(embed_dim=0, landmark_bands=(1.0,))
"""No picture, whole-window landmarks: the window mechanics tested here; the bands have tests of their own."""


def ring_log(n_agents=120, jitter=0.05, rng=0):
    """Agents 0..n-1 on a ring; agent i meets i+1 at time (i mod 2) + noise.

    Events E_i = [t_i, i, i+1] and E_{i+1} share agent i+1, so under the plain metric
    the event graph is a cycle of n events with edge weights ~1: a noisy circle of
    circumference ~n seconds.
    """
    rng = np.random.default_rng(rng)
    i = np.arange(n_agents)
    t = (i % 2) + 5.0 + rng.uniform(-jitter, jitter, n_agents)
    return EncounterLog.from_records(t, i, (i + 1) % n_agents)


def test_noisy_circle_of_events_gives_one_dominant_h1_bar():
    tmap = map_encounters(ring_log(), MapConfig(metric="plain", landmarks=60, min_region_events=10, **FAST))
    lengths = tmap.diagram.lengths(1)
    assert tmap.betti[0] == 1
    # A cycle of circumference C ~ 120 s sampled every ~2 s: the hole bar lives from
    # ~2 s to ~C/3 = 40 s; every other bar is subsampling noise of a few seconds.
    assert lengths[0] > 30 and (len(lengths) == 1 or lengths[0] > 5 * lengths[1])


def test_two_disjoint_rooms_give_two_regions():
    sim = simulate(two_rooms_arena(), 200, 20.0, rng=7)
    tmap = map_encounters(sim.log, MapConfig(**FAST))
    # beta_1 of sparse rooms is the benchmark's business (docs/accuracy.md, two rooms cell)
    assert tmap.betti[0] == 2
    assert len(tmap.regions) == 2
    # one infinite H0 bar per region in the union diagram
    assert np.isinf(tmap.diagram[0][:, 1]).sum() == 2
    assert sum(r.n_events for r in tmap.regions) + sum(s["events"] for s in tmap.too_little_data) == sim.log.n_events
    # beta_1's confidence: the regions' product to the default classifier's fitted power
    a = load_classifier("default").calibration_["1"]["regions_exponent"]
    assert tmap.confidence[1] == pytest.approx(np.prod([r.confidence[1] for r in tmap.regions]) ** a)


@pytest.mark.slow
@pytest.mark.parametrize("arena, holes, recorded", [(default_arena(), 1, 7), (square_arena(), 0, 8)],
                         ids=["one-hole", "no-hole"])
def test_simulated_arenas_map_to_their_hole_count(arena, holes, recorded):
    """The paper's Fig. "encmds" set-up (200 agents, 20 s), default map options, seeds 0-9.

    A regression guard at the level recorded with the shipped classifier: one-hole
    7/10, no-hole 8/10 (17/20 and 16/20 over seeds 0-19 in
    ``lab/demo_accuracy.py``; one-hole 8/10 and 18/20 before the landmark bands).  20 s is shorter than an automatic window of
    scale 1 (scales 1 and 1.25 map the log whole, 0.75 in two windows), and below the
    accuracy benchmark's smallest budget (docs/accuracy.md).
    beta_0 must always be 1.  The seeds are fixed, so the test is deterministic.
    """
    right = 0
    for seed in range(10):
        sim = simulate(arena, 200, 20.0, rng=seed)
        tmap = map_encounters(sim.log, MapConfig(seed=seed, embed_dim=0))
        assert tmap.betti[0] == 1
        right += tmap.betti[1] == holes
    assert right >= recorded


def test_same_seed_same_map_and_seed_matters():
    log = simulate(default_arena(), 120, 10.0, rng=3).log
    docs = [map_json(map_encounters(log, MapConfig(seed=s, landmarks=60, embed_dim=3))) for s in (5, 5, 6)]
    for d in docs:
        d.pop("timings")
    assert json.dumps(docs[0]) == json.dumps(docs[1])
    assert docs[0]["diagrams"] != docs[2]["diagrams"]


def test_small_component_is_reported_not_counted():
    big = ring_log(80)
    t = np.r_[big.t, 1.0, 2.0]
    a = np.r_[big.a, 500, 500]
    b = np.r_[big.b, 501, 502]
    log = EncounterLog.from_records(t, a, b)
    tmap = map_encounters(log, MapConfig(metric="plain", landmarks=40, min_region_events=10, **FAST))
    assert tmap.betti[0] == 1
    assert tmap.too_little_data == [{"component": tmap.too_little_data[0]["component"], "events": 2, "agents": 3}]


def test_one_event_gets_a_clear_message():
    log = EncounterLog.from_records([1.0], [1], [2])
    with pytest.raises(SwarmtopoError, match="at least 2 encounters"):
        map_encounters(log)


def test_no_shared_agents_gets_a_clear_message():
    n = 60
    log = EncounterLog.from_records(np.arange(n, dtype=float), 2 * np.arange(n), 2 * np.arange(n) + 1)
    with pytest.raises(SwarmtopoError, match="too short or the agents too few"):
        map_encounters(log)


def test_encounters_all_at_one_time_get_a_clear_message():
    pairs = [(a, b) for a in range(30) for b in range(a + 1, 30)]
    log = EncounterLog.from_records([1.4e9] * len(pairs), *zip(*pairs))
    with pytest.raises(SwarmtopoError, match="all 435 encounters are at one time \\(t = 1400000000 s\\)"):
        map_encounters(log)


def test_empty_windows_do_not_take_seats_under_the_cap():
    # bursts in [30, 40] and [60, 70] of a log from 0 to 110 s: of the 21 windows of 10 s every 5 s, only
    # the two over a burst hold 40 events; an even share of all 21 would be the empty first and last ones
    t = np.r_[0.0, np.linspace(30.0, 40.0, 50), np.linspace(60.0, 70.0, 50), 110.0]
    assert scaled_windows(t, [10.0], cap=2)[0] == [(0.0, 10.0), (100.0, 110.0)]
    spans, left_out = scaled_windows(t, [10.0], cap=None, min_events=40)
    assert spans == [(30.0, 40.0), (60.0, 70.0)] and left_out == 0
    assert scaled_windows(t, [10.0], cap=2, min_events=40) == (spans, 0)


def test_windows_too_short_to_list_are_refused_and_too_short_to_hold_a_region_say_so():
    with pytest.raises(SwarmtopoError, match="would be 799,999, more than 100,000: use longer windows"):
        window_spans(np.array([0.0, 40.0]), 1e-4)  # 1 + (40 - 1e-4) / 5e-5 windows
    for length, count in ((1e-300, "8e+301"), (1e-320, "inf")):  # said in short, never an OverflowError
        with pytest.raises(SwarmtopoError, match=f"would be {re.escape(count)}, more than 100,000"):
            window_spans(np.array([0.0, 40.0]), length)
    log = simulate(default_arena(), 100, 10.0, rng=3).log
    tmap = map_encounters(log, MapConfig(window_length=0.01, window_scales=(1.0, 2.0), **FAST))
    assert tmap.regions[0].warnings[0] == ("no window (0.01-0.02 s long) holds 50 encounters of this region "
                                           "among 3 agents: its whole log was mapped instead")
    assert [(w.t0, w.t1) for w in tmap.regions[0].windows] == [(float(log.t.min()), float(log.t.max()))]


def test_a_window_of_a_trace_takes_the_hop_cost_of_its_own_pace():
    # agents meet every 1 s in [0, 100) and every 10 s in [100, 1100): h from the data follows the window
    rng = np.random.default_rng(0)
    t = np.r_[np.arange(0.0, 100.0, 0.05), np.arange(100.0, 1100.0, 0.5)]
    a = rng.integers(0, 20, len(t))
    b = (a + rng.integers(1, 20, len(t))) % 20
    log = EncounterLog.from_records(t, a, b)
    early = map_encounters(log, MapConfig(window=(0.0, 99.9), recontacts="keep", **FAST))
    h, _ = settings.hop_cost(log.window(0.0, 99.9), None)
    assert map_json(early)["params"]["hop_cost_used"] == pytest.approx(h)
    assert h < 0.5 * settings.hop_cost(log, None)[0]


def test_window_restricts_events():
    log = simulate(default_arena(), 200, 15.0, rng=1).log
    tmap = map_encounters(log, MapConfig(window=(2.0, 12.0), **FAST))
    inside = int(np.count_nonzero((log.t >= 2.0) & (log.t <= 12.0)))
    assert 0 < inside < log.n_events
    assert tmap.n_events == inside


@pytest.mark.parametrize("bad, match", [
    (dict(metric="euclid"), "unknown metric"),
    (dict(subsample="random"), "unknown subsampler"),
    (dict(landmarks=2), r"landmarks: must be a whole number in 3\.\.2000"),
    (dict(landmarks=10.5), r"landmarks: must be a whole number"),
    (dict(seed=-3), "seed: must be a whole number >= 0"),
    (dict(seed=1.5), "seed: must be a whole number >= 0"),
    (dict(window_scales=(0.01,)), "window_scales: must be one or more numbers >= 0.05"),
    (dict(landmarks=2001), r"landmarks: must be a whole number in 3\.\.2000"),
    (dict(max_landmarks=2001), r"max_landmarks: must be a whole number in 3\.\.2000"),
    (dict(maxdim=3), "maxdim"),
    (dict(window=(5.0, 1.0)), "before its start"),
    (dict(hop_cost=-1.0), "hop_cost"),
    (dict(diffusion_time=0.0), "diffusion_time"),
    (dict(wall_follow_weight=-0.5), "wall_follow_weight"),
    (dict(wall_follow_weight=float("inf")), "wall_follow_weight"),
    (dict(window_length=0.0), "window_length"),
    (dict(window_step=float("nan")), "window_step"),
    (dict(max_windows=0), "max_windows"),
    (dict(max_windows=2), "at least the number of window scales"),
    (dict(max_windows=2.5), "max_windows"),
    (dict(max_windows=True), "max_windows"),
    (dict(max_windows="48"), "max_windows"),
])
def test_bad_config_is_refused(bad, match):
    with pytest.raises(SwarmtopoError, match=match):
        map_encounters(ring_log(), MapConfig(**bad))


@pytest.mark.parametrize("options, field, value", [
    ({"window_length": "12.5"}, "window_length", 12.5),
    ({"window_length": "none"}, "window_length", WHOLE_LOG),
    ({"window_length": "AUTO"}, "window_length", None),
    ({"diffusion_time": 3}, "diffusion_time", 3.0),
    ({"wall_follow_weight": "none"}, "wall_follow_weight", None),
    ({"max_windows": "none"}, "max_windows", None),
    ({"max_windows": "7"}, "max_windows", 7),
    ({"window_scales": "1,0.75"}, "window_scales", (1.0, 0.75)),
    ({"window_scales": [1.25, 1]}, "window_scales", (1.25, 1.0)),
    ({"landmark_bands": "auto"}, "landmark_bands", None),
    ({"landmarks": 300}, "landmarks", 300),
    ({"hop_cost": None}, "hop_cost", None),
])
def test_option_values_as_users_write_them(options, field, value):
    """One parser for command-line text and sweep TOML values: words, numbers, lists."""
    assert getattr(config_from_options(options), field) == value


@pytest.mark.parametrize("options, field, words", [
    ({"window_length": "soon"}, "window_length", "'soon' is not a finite number > 0 or 'auto' or 'none'"),
    ({"hop_cost": -1}, "hop_cost", "-1 is not a finite number >= 0 and <= 1e+09 or 'auto'"),
    ({"max_windows": "2.5"}, "max_windows", "is not a whole number >= 1 or 'none'"),
    ({"window_scales": "1,1"}, "window_scales", "distinct"),
    ({"window_scales": "0.01"}, "window_scales", ">= 0.05"),
    ({"landmark_bands": "1,0.5"}, "landmark_bands", None),  # valid alone: refused with knn below
    ({"metric": "euclid"}, "metric", "one of plain, contracted, hybrid"),
    ({"windows": 3}, "windows", "is not an option"),
])
def test_bad_option_values_name_their_field(options, field, words):
    if words is None:
        with pytest.raises(ConfigError) as caught:
            config_from_options({**options, "subsample": "knn"})
    else:
        with pytest.raises(ConfigError) as caught:
            config_from_options(options)
        assert words in caught.value.reason
    assert caught.value.field == field


def test_landmark_shares_follow_events_with_a_minimum_of_three():
    assert share_landmarks(300, np.array([1000, 500, 500])).tolist() == [150, 75, 75]
    # largest remainder: 100 * (2/3, 1/3) = 66.67, 33.33 -> 67, 33
    assert share_landmarks(100, np.array([200, 100])).tolist() == [67, 33]
    # a tiny region still gets 3 (raw share 0.12), so the total may exceed the budget
    assert share_landmarks(300, np.array([10000, 4])).tolist() == [300, 3]


@pytest.mark.parametrize("metric", ["plain", "hybrid"])
@pytest.mark.parametrize("n_landmarks", [15, 40, 90])
def test_landmark_diagram_within_twice_the_cover_radius_of_the_full_cloud(metric, n_landmarks):
    """Theorem: landmarks that are r-dense in the cloud give a Rips diagram within
    bottleneck distance 2r of the whole cloud's (Chazal, de Silva, Oudot 2014)."""
    from swarmtopo.metric.graph import build_graph
    from swarmtopo.metric.landmarks import maxmin
    from swarmtopo.topology.persistence import bottleneck, rips_persistence

    log = simulate(default_arena(), 150, 8.0, rng=11, static_fraction=0.1).log
    graph = build_graph(log, metric)
    n, labels = graph.components()
    sub = graph.subgraph(np.flatnonzero(labels == np.argmax(np.bincount(labels))))
    assert 150 < sub.n_nodes < 1500
    full = rips_persistence(sub.distances_from(np.arange(sub.n_nodes)), maxdim=1).diagram
    land = maxmin(sub, n_landmarks, rng=0)
    sample = rips_persistence(land.distances, maxdim=1).diagram
    for dim in (0, 1):
        assert bottleneck(full, sample, dim) <= 2 * land.cover_radius + 1e-9


def test_automatic_landmarks_are_the_shortest_prefix_meeting_the_guarantee():
    from swarmtopo.pipeline.map import AUTO_COVER_FACTOR

    log = simulate(default_arena(), 200, 20.0, rng=5).log
    auto = map_encounters(log, MapConfig(seed=1, **FAST)).regions[0]
    limit = AUTO_COVER_FACTOR * auto.scales.knn
    n = len(auto.landmarks.nodes)
    assert auto.landmarks.cover_radius <= limit and auto.warnings == []
    assert auto.landmarks.cover_radii[n - 2] > limit  # one fewer would not do
    # greedy selection: the same first n landmarks as an explicit run with L = n
    fixed = map_encounters(log, MapConfig(seed=1, landmarks=n, **FAST)).regions[0]
    assert np.array_equal(fixed.landmarks.nodes, auto.landmarks.nodes)
    assert np.array_equal(fixed.landmarks.distances, auto.landmarks.distances)
    assert fixed.betti == auto.betti


def test_windows_hand_computed():
    t = np.array([0.0, 7.0, 30.0])
    # span 30, length 20, step 10: 1 + ceil(10 / 10) = 2 windows, [0, 20] and [10, 30]
    assert window_spans(t, 20.0) == [(0.0, 20.0), (10.0, 30.0)]
    # span 30, length 12, step 6: 1 + ceil(18 / 6) = 4 windows evenly spaced over [0, 18]
    assert window_spans(t, 12.0) == [(0.0, 12.0), (6.0, 18.0), (12.0, 24.0), (18.0, 30.0)]
    # step 12: 1 + ceil(18 / 12) = 3 windows, starts 0, 9, 18
    assert window_spans(t, 12.0, 12.0) == [(0.0, 12.0), (9.0, 21.0), (18.0, 30.0)]
    assert window_spans(t, 30.0) == [None] and window_spans(t, WHOLE_LOG) == [None]


def test_scaled_windows_are_the_distinct_windows_of_every_length():
    t = np.array([0.0, 7.0, 30.0])
    # 20 s: [0, 20], [10, 30]; 15 s (step 7.5): [0, 15], [7.5, 22.5], [15, 30]; 30 s: the whole log
    assert scaled_windows(t, [20.0, 15.0, 30.0]) == ([(0.0, 20.0), (10.0, 30.0), (0.0, 15.0), (7.5, 22.5),
                                                        (15.0, 30.0), None], 0)
    assert scaled_windows(t, [20.0, 20.0]) == (window_spans(t, 20.0), 0)  # a window is pooled once
    assert scaled_windows(t, [30.0, WHOLE_LOG]) == ([None], 0)
    assert scaled_windows(t, [30.0, WHOLE_LOG], cap=1) == ([None], 0)  # counted once, so not over the cap


def test_capped_windows_keep_an_even_share_of_every_length():
    t = np.array([0.0, 100.0])
    # 10 s: 19 windows every 5 s; 20 s: 9 every 10 s; 28 windows in all
    every, left_out = scaled_windows(t, [10.0, 20.0])
    assert len(every) == 28 and left_out == 0 and scaled_windows(t, [10.0, 20.0], cap=28) == (every, 0)
    # quotas 7 x 19 / 28 = 4.75 and 7 x 9 / 28 = 2.25: floors 4 and 2, the seat left to the larger remainder
    capped, left_out = scaled_windows(t, [10.0, 20.0], cap=7)
    assert left_out == 21
    # 5 of the 19 10 s windows, indices 0, 4.5, 9, 13.5, 18 rounded half to even; 2 of the 9 20 s ones
    assert capped == [(0.0, 10.0), (20.0, 30.0), (45.0, 55.0), (70.0, 80.0), (90.0, 100.0),
                      (0.0, 20.0), (80.0, 100.0)]
    # one per length at the least, the middle window when only one is kept
    assert scaled_windows(t, [10.0, 20.0], cap=2) == ([(45.0, 55.0), (40.0, 60.0)], 26)
    with pytest.raises(SwarmtopoError, match="one of each"):
        scaled_windows(t, [10.0, 20.0, 50.0], cap=2)


def test_window_shares_sum_to_the_cap_and_keep_one_per_length():
    from swarmtopo.pipeline.windows import shares as _shares

    # 48 x (399, 3, 2) / 404 = (47.41, 0.36, 0.24): the floors (47, 0, 0) raised to one each exceed
    # the cap, so the largest share gives one back
    assert _shares(np.array([399, 3, 2]), 48).tolist() == [46, 1, 1]
    # the 10^6-event log: 48 x (126, 95, 76) / 297 = (20.36, 15.35, 12.28), the seat left to the first
    assert _shares(np.array([126, 95, 76]), 48).tolist() == [21, 15, 12]
    for sizes in ([5, 5, 5], [100, 1, 1], [60, 0, 3], [7, 9, 11, 13]):
        for cap in range(4, sum(sizes)):
            keep = _shares(np.array(sizes), cap)
            assert keep.sum() == cap and (keep <= sizes).all() and (keep >= np.minimum(sizes, 1)).all()


def test_a_long_log_maps_at_most_max_windows():
    import dataclasses

    from swarmtopo.viz.summary import ADVICE_BELOW

    log = simulate(default_arena(), 150, 30.0, rng=2).log
    base = dict(window_length=6.0, window_scales=(1.0, 1.5), **FAST)
    every = map_encounters(log, MapConfig(max_windows=None, **base)).regions[0].windows
    capped = map_encounters(log, MapConfig(max_windows=6, **base))
    assert len(every) > 6 == len(capped.regions[0].windows)
    kept = [(w.t0, w.t1) for w in capped.regions[0].windows]
    assert set(kept) <= {(w.t0, w.t1) for w in every} and len({round(b - a, 9) for a, b in kept}) == 2
    params = map_json(capped)["params"]
    assert params["max_windows"] == 6 and params["windows_left_out"] == len(every) - 6
    assert map_encounters(log, MapConfig(max_windows=None, **base)).windows_left_out == 0
    unsure = dataclasses.replace(capped, confidence={0: 0.99, 1: ADVICE_BELOW - 0.2})
    assert advice(unsure)[-1].startswith("to raise it: use more agents")  # a longer log adds no window


def test_window_scales_pool_the_windows_of_every_scale():
    log = simulate(default_arena(), 150, 30.0, rng=2).log
    base = dict(window_encounters=8.0, **FAST)
    mixed = map_encounters(log, MapConfig(window_scales=(0.75, 1.0, 1.5), **base))
    single = [map_encounters(log, MapConfig(window_scales=(1.0,), **{**base, "window_encounters": 8.0 * s}))
              for s in (0.75, 1.0, 1.5)]
    spans = [(w.t0, w.t1) for w in mixed.regions[0].windows]
    assert spans == [(w.t0, w.t1) for m in single for w in m.regions[0].windows]  # every scale's windows, once
    assert len({round(t1 - t0, 9) for t0, t1 in spans}) == 3
    bars = [w.diagram for w in mixed.regions[0].windows]
    assert mixed.betti[1] == load_classifier("default").pooled_betti(bars)[1]  # one pooling over them all
    assert mixed.window_length == single[1].window_length  # the scale-1 length is the one reported
    assert map_json(mixed)["params"]["window_scales"] == [0.75, 1.0, 1.5]


def test_landmark_bands_map_each_window_once_per_band_from_its_middle():
    log = simulate(default_arena(), 150, 30.0, rng=2).log
    base = dict(window_encounters=8.0, window_scales=(1.0,), seed=4, embed_dim=0)
    whole = map_encounters(log, MapConfig(landmark_bands=(1.0,), **base)).regions[0].windows
    banded = map_encounters(log, MapConfig(landmark_bands=(1.0, 0.5), **base)).regions[0]
    windows = banded.windows
    assert len(whole) > 1 and len(windows) == 2 * len(whole)
    assert [(w.t0, w.t1, w.band) for w in windows] == [(w.t0, w.t1, b) for w in whole for b in (1.0, 0.5)]
    for w in windows[1::2]:  # band 0.5: every landmark from the middle half of its window
        quarter = (w.t1 - w.t0) / 4
        times = log.t[w.landmark_events]
        assert (times >= w.t0 + quarter - 1e-9).all() and (times <= w.t1 - quarter + 1e-9).all()
    assert any(log.t[w.landmark_events].min() < w.t0 + (w.t1 - w.t0) / 4 for w in windows[::2])
    assert banded.betti[1] == load_classifier("default").pooled_betti([w.diagram for w in windows])[1]
    assert window_json(windows[1])["band"] == 0.5


def test_a_band_with_an_empty_middle_is_left_out_and_said():
    # the ring's encounters come at t ~ 5 s and ~ 6 s only: the middle half of the log is empty
    log = ring_log()
    config = MapConfig(metric="plain", landmarks=60, min_region_events=10, embed_dim=0, window_length=np.inf,
                       landmark_bands=(1.0, 0.5))
    region = map_encounters(log, config).regions[0]
    assert [w.band for w in region.windows] == [1.0]
    assert any("a landmark band draws from" in w and ": 1;" in w for w in region.warnings)
    whole = map_encounters(log, replace(config, landmark_bands=(1.0,))).regions[0]
    assert np.array_equal(region.diagram[1], whole.diagram[1]) and not whole.warnings
    # with no band that can be drawn from, the window keeps whole-window landmarks
    middle_only = map_encounters(log, replace(config, landmark_bands=(0.5,))).regions[0]
    assert [w.band for w in middle_only.windows] == [1.0]
    assert np.array_equal(middle_only.diagram[1], whole.diagram[1])


def test_unset_landmark_bands_are_the_classifiers_own():
    log = simulate(default_arena(), 150, 30.0, rng=2).log
    base = dict(window_encounters=8.0, window_scales=(1.0,), seed=4, embed_dim=0)
    fitted = load_classifier("default")
    fitted.provenance_ = {**fitted.provenance_, "pipeline": {"landmark_bands": [1.0, 0.5]}}
    unnamed = load_classifier("default")
    unnamed.provenance_ = {k: v for k, v in unnamed.provenance_.items() if k != "pipeline"}
    assert fitted.landmark_bands == (1.0, 0.5) and unnamed.landmark_bands == (1.0,)
    explicit = map_encounters(log, MapConfig(landmark_bands=(1.0, 0.5), **base), reader=fitted)
    resolved = map_encounters(log, MapConfig(**base), reader=fitted)
    assert resolved.config.landmark_bands == (1.0, 0.5) and map_json(resolved)["params"]["landmark_bands"] == [1.0, 0.5]
    assert [w.diagram.lengths(1).tolist() for w in resolved.regions[0].windows] == \
        [w.diagram.lengths(1).tolist() for w in explicit.regions[0].windows]
    assert map_encounters(log, MapConfig(**base), reader=unnamed).config.landmark_bands == (1.0,)
    knn = map_encounters(log, MapConfig(subsample="knn", **base), reader=fitted)
    assert knn.config.landmark_bands == (1.0,)  # bands need maxmin: another subsampler maps whole windows
    assert {w.band for w in knn.regions[0].windows} == {1.0}


@pytest.mark.parametrize("bands, subsample, message", [((), "maxmin", "distinct numbers in"),
                                                       ((1.0, 0.0), "maxmin", "distinct numbers in"),
                                                       ((1.5,), "maxmin", "distinct numbers in"),
                                                       ((0.5, 0.5), "maxmin", "distinct numbers in"),
                                                       ((1.0, 0.5), "knn", "use maxmin")])
def test_bad_landmark_bands_are_refused(bands, subsample, message):
    with pytest.raises(SwarmtopoError, match=message):
        MapConfig(landmark_bands=bands, subsample=subsample).validate()


@pytest.mark.parametrize("scales, message", [((), "one or more numbers >= 0.05"), ((1.0, 0.0), "one or more numbers >= 0.05"),
                                             ((1.0, float("nan")), "one or more numbers >= 0.05"),
                                             ((1.0, 1.0), "distinct")])
def test_bad_window_scales_are_refused(scales, message):
    with pytest.raises(SwarmtopoError, match=message):
        MapConfig(window_scales=scales).validate()


def test_hop_cost_comes_from_meta_then_from_the_data():
    log = EncounterLog.from_records([0.0, 1.0, 3.0, 4.0], [1, 1, 2, 1], [2, 3, 3, 2], meta={"r_d": 30.0, "v_c": 15.0})
    assert settings.hop_cost(log, 0.5) == (0.5, "given")
    assert settings.hop_cost(log, None) == (2.0, "r_d / v_c from meta.json")
    bare = EncounterLog.from_records(log.t, log.a, log.b)
    # consecutive events per agent: 1: 0,1,4 -> gaps 1, 3; 2: 0,3,4 -> 3, 1; 3: 1,3 -> 2: mean 2
    h, source = settings.hop_cost(bare, None)
    assert h == pytest.approx(HOP_GAP_FACTOR * 2.0) and "mean time" in source


def test_diffusion_time_comes_from_the_data():
    log = EncounterLog.from_records([0.0, 1.0, 3.0, 4.0], [1, 1, 2, 1], [2, 3, 3, 2], meta={"r_d": 30.0, "v_c": 15.0})
    # mean gap between an agent's consecutive encounters 2 s (see the hop-cost test), whatever meta.json says
    gap = mean_agent_gap(log)
    assert gap == pytest.approx(2.0)
    assert settings.diffusion_time(gap, 0.3) == (0.3, "given")
    tau, source = settings.diffusion_time(gap, None)
    assert tau == pytest.approx(DIFFUSION_GAP_FACTOR * 2.0) and "mean time" in source
    lonely = EncounterLog.from_records([0.0, 0.0], [1, 3], [2, 4])
    assert mean_agent_gap(lonely) is None and settings.diffusion_time(None, None)[0] == WHOLE_LOG


def test_window_length_comes_from_the_data():
    log = EncounterLog.from_records([0.0, 1.0, 3.0, 4.0], [1, 1, 2, 1], [2, 3, 3, 2])
    # mean gap between an agent's consecutive encounters 2 s (see the hop-cost test): W = K x 2 s
    gap = mean_agent_gap(log)
    assert window_length(gap, None, 1.5, span=4.0) == (3.0, "1.5 x mean time between an agent's encounters")
    length, source = window_length(gap, None, 25.0, span=4.0)
    assert length == WHOLE_LOG and "whole log" in source  # 50 s > the log's 4 s
    assert window_length(gap, 2.5, 25.0, span=4.0) == (2.5, "given")
    assert window_length(gap, 9.0, 25.0, span=4.0) == (WHOLE_LOG, "given")
    assert window_length(None, None, 25.0, span=0.0)[0] == WHOLE_LOG  # no agent met twice


def test_automatic_windows_hold_about_k_encounters_per_agent():
    log = simulate(default_arena(), 150, 30.0, rng=2).log
    tmap = map_encounters(log, MapConfig(window_encounters=8.0, window_scales=(1.0,), **FAST))
    length, source = tmap.window_length
    windows = tmap.regions[0].windows
    assert 1 < len(windows) and all(w.t1 - w.t0 == pytest.approx(length) for w in windows)
    per_agent = [2 * w.n_events / len(np.unique(np.r_[log.a, log.b])) for w in windows]
    assert 0.6 * 8 < np.mean(per_agent) < 1.4 * 8  # about K encounters per agent and window
    doc = map_json(tmap)["params"]
    assert doc["window_length_used"] == pytest.approx(length) and "8 x mean time" in doc["window_source"]


def test_windowed_map_pools_and_records_its_windows():
    log = simulate(default_arena(), 150, 30.0, rng=2).log
    tmap = map_encounters(log, MapConfig(window_length=12.0, window_scales=(1.0,), **FAST))
    region = tmap.regions[0]
    assert len(region.windows) == 4  # span ~30 s, 12 s windows every <= 6 s
    bars = [w.diagram for w in region.windows]
    classifier = load_classifier("default")
    assert region.betti[1] == classifier.pooled_betti(bars)[1]  # the classifier's pooling of the windows
    assert [w.betti[1] for w in region.windows] == [classifier.betti(w.diagram)[1] for w in region.windows]
    counts = [w.betti[1] for w in region.windows]
    rep = region.windows[region.window].betti[1]  # the representative window agrees with the vote if any does
    assert rep == region.betti[1] or region.betti[1] not in counts
    assert list(region.counted[1]) == list(classifier.read(bars, [w.n_events for w in region.windows]).counted[1])
    lengths = region.diagram.lengths(1)  # the counted bars are the region's beta_1 longest
    assert sorted(lengths[region.counted[1]]) == sorted(lengths)[len(lengths) - region.betti[1]:]
    assert region.diagram is region.windows[region.window].diagram
    doc = map_json(tmap)
    assert [w["betti"]["1"] for w in doc["regions"][0]["windows"]] == [w.betti[1] for w in region.windows]
    assert doc["params"]["hop_cost_used"] == 2.0 and doc["params"]["hop_cost_source"] == "r_d / v_c from meta.json"
    assert doc["params"]["diffusion_time_used"] == pytest.approx(tmap.diffusion_time[0])
    assert "mean time between an agent's encounters" in doc["params"]["diffusion_time_source"]



def test_loops_are_drawn_from_the_chosen_window_run_again_with_cocycles():
    log = simulate(default_arena(), 150, 30.0, rng=2).log
    config = dict(window_length=12.0, window_scales=(1.0,), seed=3, **FAST)
    with_loops = map_encounters(log, MapConfig(**config)).regions[0]
    without = map_encounters(log, MapConfig(cycles=False, **config)).regions[0]
    assert [w.diagram.backend for w in without.windows] == ["gudhi"] * 4
    backends = [w.diagram.backend for w in with_loops.windows]
    assert backends[with_loops.window] == "ripser" and backends.count("gudhi") == 3
    for a, b in zip(with_loops.windows, without.windows):  # the same diagrams whichever backend ran
        for n in (0, 1):
            np.testing.assert_array_equal(a.diagram[n], b.diagram[n])
    assert with_loops.betti == without.betti and with_loops.window == without.window
    assert len(with_loops.cycles) == with_loops.betti[1] and without.cycles == []

def test_a_log_without_status_changes_is_read_by_the_trace_classifier():
    from swarmtopo.experiments.sweep import contact_trace

    log = simulate(default_arena(), 150, 30.0, rng=2).log
    trace = contact_trace(log)
    assert shipped_reader_for(log) == "default" and shipped_reader_for(trace) == "trace"
    for source, name in ((log, "default"), (trace, "trace")):
        tmap = map_encounters(source, MapConfig(seed=1, cycles=False, **FAST))
        assert tmap.classifier["classifier"] == name
        assert tmap.classifier["theta"] == load_classifier(name).describe()["theta"]
    given = map_encounters(trace, MapConfig(seed=1, cycles=False, **FAST), reader=load_classifier("default"))
    assert given.classifier["classifier"] == "default"  # an explicit reader is kept


def test_advice_comes_below_the_threshold_and_names_what_would_raise_it():
    import dataclasses

    from swarmtopo.viz.summary import ADVICE_BELOW
    from swarmtopo.readers.ratio import RESOLUTION_CAP, resolution

    log = simulate(default_arena(), 150, 30.0, rng=2).log
    tmap = map_encounters(log, MapConfig(window_length=12.0, window_scales=(1.0,), **FAST))
    sure = dataclasses.replace(tmap, confidence={0: 0.99, 1: ADVICE_BELOW})
    assert advice(sure) == [] and map_json(sure)["advice"] == []
    unsure = dataclasses.replace(tmap, confidence={0: 0.99, 1: ADVICE_BELOW - 0.2})
    lines = advice(unsure)
    assert lines[0] == f"beta_1 = {tmap.betti[1]} is uncertain (70.0% confidence)"  # as the CLI and report say it
    assert lines[-1].startswith("to raise it: record longer") and "more agents than 150" in lines[-1]
    assert "swarmtopo plan" in lines[-1] and map_json(unsure)["advice"] == lines
    # the windows' resolution, the confidence's second feature, is named when beta_1 is in doubt
    places = np.exp(resolution([w.diagram for w in tmap.regions[0].windows]))
    assert places < RESOLUTION_CAP
    assert sum(f"tell about {places:.0f} places apart" in line for line in lines) == 1
    only_beta0 = dataclasses.replace(tmap, confidence={0: ADVICE_BELOW - 0.2, 1: 0.99})
    assert not any("places apart" in line for line in advice(only_beta0))


def test_paper_pipeline_is_the_whole_log_without_hop_cost():
    log = simulate(default_arena(), 150, 30.0, rng=2).log
    tmap = map_encounters(log, MapConfig(hop_cost=0.0, diffusion_time=WHOLE_LOG, wall_follow_weight=None,
                                         window_length=WHOLE_LOG, **FAST))
    assert len(tmap.regions[0].windows) == 1 and tmap.hop_cost == (0.0, "given")
    assert tmap.diffusion_time == (WHOLE_LOG, "given") and map_json(tmap)["params"]["diffusion_time_used"] is None
    assert tmap.regions[0].windows[0].n_events == log.n_events


def test_windows_in_a_gap_of_the_trace_are_skipped():
    # two bursts of the same ring of encounters, 200 s apart: 20 s windows between them
    # hold no event (a gap in a real trace) and are skipped, not an error
    first = ring_log(80)
    log = EncounterLog.from_records(np.r_[first.t, first.t + 200.0], np.r_[first.a, first.a], np.r_[first.b, first.b])
    tmap = map_encounters(log, MapConfig(metric="plain", window_length=20.0, min_region_events=10, **FAST))
    spans = [(w.t0, w.t1) for w in tmap.regions[0].windows]
    assert spans and all(np.any((log.t >= t0) & (log.t <= t1)) for t0, t1 in spans)
    assert len(spans) < len(window_spans(log.t, 20.0))


def test_the_whole_log_fallback_is_said_even_when_no_window_holds_enough_events():
    # 60 agents meeting at a steady pace for 100 s: 1 s windows never hold 50 encounters
    rng = np.random.default_rng(4)
    t = np.sort(rng.uniform(0.0, 100.0, 3000))
    a = rng.integers(0, 60, len(t))
    b = (a + rng.integers(1, 60, len(t))) % 60
    log = EncounterLog.from_records(t, a, b)
    tmap = map_encounters(log, MapConfig(window_length=0.5, window_scales=(1.0, 2.0), **FAST))
    assert tmap.regions[0].warnings[0].startswith("no window (0.5-1 s long) holds 50 encounters")


def test_a_silence_longer_than_a_window_is_a_warning_and_a_day_mapped_alone_has_none():
    # two "days" of steady meetings, 100 s each, 10^4 s apart
    rng = np.random.default_rng(5)
    t = np.sort(np.r_[rng.uniform(0.0, 100.0, 3000), rng.uniform(10_100.0, 10_200.0, 3000)])
    a = rng.integers(0, 60, len(t))
    b = (a + rng.integers(1, 60, len(t))) % 60
    log = EncounterLog.from_records(t, a, b)
    whole = map_encounters(log, MapConfig(**FAST))
    gap = float(np.diff(t).max())
    assert whole.warnings[0].startswith(f"the log is silent for {gap:.6g} s") and "--window T0:T1" in whole.warnings[0]
    assert map_json(whole)["warnings"][0] == whole.warnings[0]
    day = map_encounters(log, MapConfig(window=(0.0, 100.0), **FAST))
    assert not any("silent" in w for w in day.warnings)


def test_landmarks_below_the_sampling_guarantee_warn_and_give_no_beta1_confidence():
    log = simulate(default_arena(), 200, 20.0, rng=3).log
    sparse = map_encounters(log, MapConfig(landmarks=3, **FAST))
    assert any(w.startswith("landmarks too sparse: 3 landmarks") for w in sparse.warnings)
    # the confidence was calibrated with the automatic count: no number rather than a wrong one
    assert sparse.confidence[1] is None and sparse.regions[0].confidence[1] is None
    assert 0 < sparse.confidence[0] <= 1
    automatic = map_encounters(log, MapConfig(**FAST))
    assert not any("too sparse" in w for w in automatic.warnings) and automatic.confidence[1] is not None


def test_a_hole_count_beyond_the_calibrated_arenas_is_flagged():
    from swarmtopo.experiments.accuracy import CELLS
    from swarmtopo.pipeline.map import CALIBRATED_HOLES, _extrapolation_warnings

    assert CALIBRATED_HOLES == max(c.holes for c in CELLS if c.holes is not None)
    assert _extrapolation_warnings({0: 1, 1: CALIBRATED_HOLES}) == []
    assert _extrapolation_warnings({0: 1, 1: None}) == []
    (line,) = _extrapolation_warnings({0: 1, 1: CALIBRATED_HOLES + 5})
    assert line.startswith(f"beta_1 = {CALIBRATED_HOLES + 5} is beyond the 0-{CALIBRATED_HOLES} holes")


def test_a_silence_that_stretches_the_window_to_the_whole_log_is_still_a_warning():
    # 10 s of meetings, then the same 10 s shifted by 10^6 s: the silence inflates the mean
    # gap so much that the automatic window is the whole log, and it was not compared
    rng = np.random.default_rng(6)
    t = np.sort(rng.uniform(0.0, 10.0, 200))
    a = rng.integers(0, 60, len(t))
    b = (a + rng.integers(1, 60, len(t))) % 60
    log = EncounterLog.from_records(np.r_[t, t + 1e6], np.r_[a, a], np.r_[b, b])
    tmap = map_encounters(log, MapConfig(**FAST))
    assert tmap.window_length[0] == WHOLE_LOG
    gap, rest = 1e6 + t[0] - t[-1], 2 * (t[-1] - t[0])
    assert tmap.warnings[0].startswith(f"the log is silent for {gap:.6g} s (t = ")
    assert f"longer than the rest of the log ({rest:.3g} s)" in tmap.warnings[0]
    # the same meetings without the silence, mapped whole: no warning
    quiet = map_encounters(EncounterLog.from_records(t, a, b), MapConfig(window_length=WHOLE_LOG, **FAST))
    assert not any("silent" in w for w in quiet.warnings)


@pytest.mark.parametrize("r_d, v_c", [(1e200, 15.0), (30.0, 1e-300), (1e308, 1e-300)])
def test_a_per_hop_cost_from_meta_beyond_the_bound_is_refused(r_d, v_c):
    log = EncounterLog.from_records([0.0, 1.0, 3.0, 4.0], [1, 1, 2, 1], [2, 3, 3, 2], meta={"r_d": r_d, "v_c": v_c})
    with pytest.raises(InputError, match=r"^meta.json: r_d = .* per-hop cost r_d / v_c of .*, more than 1e\+09 s"):
        settings.hop_cost(log, None)
    assert settings.hop_cost(log, 2.0) == (2.0, "given")  # not read when the cost is given


def test_a_swarm_static_from_the_start_says_there_is_nothing_to_map():
    rng = np.random.default_rng(7)
    t = np.sort(rng.uniform(0.0, 20.0, 300))
    a = rng.integers(0, 40, len(t))
    b = (a + rng.integers(1, 40, len(t))) % 40
    static = (np.arange(40), np.zeros(40))
    log = EncounterLog.from_records(t, a, b, static=static)
    with pytest.raises(SwarmtopoError, match=r"^the largest connected group of encounters \(300 events among 40 "
                                             r"agents\) is a single point of the encounter metric"):
        map_encounters(log, MapConfig(hop_cost=0.0, diffusion_time=WHOLE_LOG, window_length=WHOLE_LOG, **FAST))
