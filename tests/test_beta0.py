"""beta_0's evidence and confidence (swarmtopo.readers.beta0)."""

import json

import numpy as np
import pytest

from swarmtopo.arena import square_arena, two_rooms_arena
from swarmtopo.readers.beta0 import FORMED_SHARE, Beta0Evidence, Beta0Model, beta0_evidence, formation_times, shipped_beta0_model
from swarmtopo.readers.registry import load_classifier
from swarmtopo.errors import InputError
from swarmtopo.experiments.sweep import contact_trace
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.sim import simulate
from swarmtopo.viz.summary import advice, map_json

FAST = {"max_landmarks": 80, "window_scales": (1.0,)}


def literal_formation_times(a, b, t, region_of_agent, n_regions, share=FORMED_SHARE):
    """Union-find over every encounter in time order, region sizes checked after each."""
    parent = list(range(len(region_of_agent)))

    def root(x):
        while parent[x] != x:
            x = parent[x]
        return x

    size = np.bincount(region_of_agent[region_of_agent >= 0], minlength=n_regions)
    formed = [None] * n_regions
    for k in np.argsort(t, kind="stable"):
        ra, rb = root(a[k]), root(b[k])
        if ra != rb:
            parent[ra] = rb
        region = region_of_agent[a[k]]
        group = sum(root(x) == root(a[k]) for x in range(len(parent)))
        if region >= 0 and formed[region] is None and group >= max(np.ceil(share * size[region] - 1e-9), 2):
            formed[region] = t[k]
    return np.array([np.nan if f is None else f for f in formed], dtype=float)


def test_formation_hand_case():
    # region 0: agents 0, 1, 2 (joined at t = 1 and 2); region 1: agents 3, 4, 5 (t = 3 and 8)
    a, b, t = np.array([0, 1, 3, 4, 0]), np.array([1, 2, 4, 5, 2]), np.array([1.0, 2.0, 3.0, 8.0, 9.0])
    region_of_agent = np.array([0, 0, 0, 1, 1, 1])
    # 90 % of 3 agents is all 3
    assert formation_times(a, b, t, region_of_agent, 2).tolist() == [2.0, 8.0]
    # half of them: the first encounter of each region already joins 2 of 3
    assert formation_times(a, b, t, region_of_agent, 2, share=0.5).tolist() == [1.0, 3.0]
    # settled: the log ends at 9, the last region formed at 8; one gap of 0.5 s -> 2 gaps
    evidence = beta0_evidence(a, b, t, region_of_agent, 2, events_in_regions=4, gap=0.5)
    assert (evidence.regions, evidence.settled, evidence.fragments) == (2, 2.0, pytest.approx(0.2))
    # no gap (no agent met twice): nothing has settled
    assert beta0_evidence(a, b, t, region_of_agent, 2, 5, None).settled == 0.0


@pytest.mark.parametrize("seed", range(6))
def test_formation_agrees_with_a_literal_union_find(seed):
    rng = np.random.default_rng(seed)
    n_agents, n_events = 12, 40
    a = rng.integers(0, n_agents, n_events)
    b = (a + rng.integers(1, n_agents, n_events)) % n_agents
    t = np.round(rng.uniform(0, 10, n_events), 1)  # ties in time on purpose
    # the regions are the final groups with 3 agents or more
    parent = list(range(n_agents))

    def root(x):
        while parent[x] != x:
            x = parent[x]
        return x

    for x, y in zip(a, b):
        parent[root(x)] = root(y)
    roots = np.array([root(x) for x in range(n_agents)])
    big = [r for r in np.unique(roots) if (roots == r).sum() >= 3]
    region_of_agent = np.array([big.index(r) if r in big else -1 for r in roots])
    for share in (0.5, FORMED_SHARE, 1.0):
        expected = literal_formation_times(a, b, t, region_of_agent, len(big), share)
        np.testing.assert_array_equal(formation_times(a, b, t, region_of_agent, len(big), share), expected)


def test_model_reads_one_feature_each_and_round_trips():
    model = Beta0Model(one=(5.0, -3.0), several=(-2.0, 2.0), provenance={"name": "t"})
    settled = [model.confidence(Beta0Evidence(2, s, 0.0)) for s in (0.0, 1.0, 5.0, 50.0)]
    assert settled == sorted(settled) and settled[0] < 0.2 and settled[-1] > 0.99
    fragmented = [model.confidence(Beta0Evidence(1, 100.0, f)) for f in (0.0, 0.5, 0.9)]
    assert fragmented == sorted(fragmented, reverse=True)
    assert model.confidence(Beta0Evidence(1, 0.0, 0.0)) == pytest.approx(1 / (1 + np.exp(-5.0)))
    assert Beta0Model.from_json(json.loads(json.dumps(model.to_json()))) == model


@pytest.mark.parametrize("part, key, value", [("several", "log1p_settled", "x"), ("one", "intercept", None),
                                              ("one", "fragments", float("nan"))])
def test_a_bad_model_file_is_refused_naming_the_field(part, key, value):
    obj = shipped_beta0_model().to_json()
    obj[part] = {**obj[part], key: value}
    with pytest.raises(InputError, match="finite number") as caught:
        Beta0Model.from_json(obj, source="m.json")
    assert (caught.value.file, caught.value.column) == ("m.json", f"{part}.{key}")
    with pytest.raises(InputError, match="must be an object") as caught:
        Beta0Model.from_json({**shipped_beta0_model().to_json(), "provenance": "fitted"}, source="m.json")
    assert caught.value.column == "provenance"
    with pytest.raises(InputError, match="beta_0 confidence model"):
        Beta0Model.from_json({"format": "swarmtopo-ratio-classifier/3"}, source="m.json")


def test_shipped_model_is_fitted_so_that_more_evidence_means_more_confidence():
    model = shipped_beta0_model()
    assert model.provenance["script"] == "lab/calibrate_beta0.py"
    assert model.several[1] > 0 and model.one[1] < 0


def test_a_room_cut_before_its_agents_met_is_not_reported_as_several_rooms_with_certainty():
    # a dense start in one room: in its first second the swarm is still separate groups
    log = simulate(square_arena(), 300, 1.0, rng=1).log
    tmap = map_encounters(log, MapConfig(**FAST))
    assert tmap.beta0_evidence.regions >= 2 and tmap.beta0_evidence.settled < 2
    assert tmap.betti[0] >= 2 and tmap.confidence[0] < 0.5
    assert any("only a longer log tells one room from several" in line for line in advice(tmap))
    assert map_json(tmap)["beta0_evidence"]["regions"] == tmap.betti[0]
    assert any("swarmtopo plan --area" in line for line in advice(tmap))
    # the same encounters as a contact trace: plan's model of contact traces is offered
    trace = map_encounters(contact_trace(log), MapConfig(**FAST))
    assert trace.classifier["classifier"] == "trace" and trace.confidence[0] == tmap.confidence[0]
    assert not any("swarmtopo plan --area" in line for line in advice(trace))
    assert any("swarmtopo plan --input contact-trace --area" in line for line in advice(trace))
    # it is the log that is a trace, whichever classifier reads it
    read_as_paper = map_encounters(contact_trace(log), MapConfig(**FAST), reader=load_classifier("paper"))
    assert any("swarmtopo plan --input contact-trace --area" in line for line in advice(read_as_paper))
    # the same room recorded for 20 s: one region, and sure of it
    whole = map_encounters(simulate(square_arena(), 300, 20.0, rng=1).log, MapConfig(**FAST))
    assert whole.betti[0] == 1 and whole.confidence[0] > 0.95


def test_two_rooms_recorded_long_enough_are_two_rooms_with_confidence():
    model = shipped_beta0_model()
    short, long = (map_encounters(simulate(two_rooms_arena(), 200, duration, rng=7).log,
                                  MapConfig(**FAST)).beta0_evidence for duration in (20.0, 40.0))
    assert short.regions == long.regions == 2 and short.settled < long.settled
    # the longer the rooms stay apart, the surer the count
    assert model.confidence(short) < model.confidence(long) and model.confidence(long) > 0.9
