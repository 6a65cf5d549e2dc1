"""Faulty sensing: the faults perturb injects (swarmtopo.sim.faults), the fault screen
that finds the encounters the rest of the log contradicts (swarmtopo.pipeline.faults),
``swarmtopo perturb`` and the fault benchmark's cases."""

import json

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

import swarmtopo as st
from swarmtopo.errors import InputError
from swarmtopo.experiments import faults as bench
from swarmtopo.experiments.grid import expand_grid
from swarmtopo.log import EncounterLog
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.pipeline.faults import CLEAN_FAR_SHARE, detours, fault_warnings, screen_faults
from swarmtopo.sim.faults import Faults, _false_reports, perturb
from swarmtopo.viz.summary import map_json

from conftest import run_cli

FAST = dict(embed_dim=0, landmark_bands=(1.0,))


def once_per_pair(n_agents=400, n_events=20000, seed=0, t0=100.0, span=1000.0) -> EncounterLog:
    """A log in which every pair meets at most once (so each report is known by its pair)."""
    rng = np.random.default_rng(seed)
    pairs = rng.choice(n_agents * (n_agents - 1) // 2, n_events, replace=False)
    a, b = np.triu_indices(n_agents, 1)
    return EncounterLog.from_records(np.sort(rng.uniform(t0, t0 + span, n_events)), a[pairs], b[pairs],
                                     meta={"agent_count": n_agents})


def by_pair(log: EncounterLog) -> dict[tuple[int, int], float]:
    return {(int(x), int(y)): float(t) for t, x, y in zip(log.t, log.a, log.b)}


@pytest.fixture(scope="module")
def clean():
    return once_per_pair()


def test_no_fault_returns_the_same_events_and_records_it(clean):
    out, record = perturb(clean, Faults(), 3)
    np.testing.assert_array_equal(out.t, clean.t)
    np.testing.assert_array_equal(out.a, clean.a)
    np.testing.assert_array_equal(out.b, clean.b)
    assert record["counts"]["delivered"] == clean.n_events and out.meta["faults"] == [record]


def test_each_rate_is_the_one_asked_for(clean):
    m = clean.n_events
    for name, p in (("lost", 0.3), ("false_encounters", 0.05), ("duplicated", 0.2)):
        record = perturb(clean, Faults(**{name: p}), 1)[1]["counts"]
        count = {"lost": "lost", "false_encounters": "false", "duplicated": "duplicated"}[name]
        assert abs(record[count] - p * m) < 4 * np.sqrt(m * p * (1 - p)), name  # binomial, 4 sigma
    # dying: exactly round(share x agents) die, and none of their events follows its death
    out, record = perturb(clean, Faults(dying=0.25), 1)
    assert record["counts"]["died"] == 100
    assert record["counts"]["delivered"] == out.n_events == m - record["counts"]["after_death"]
    # an event is lost if either agent is dead; each agent is dead a quarter x half of the log on average
    assert abs(record["counts"]["after_death"] / m - (1 - (1 - 0.25 / 2) ** 2)) < 0.03
    # outages: each radio down burst_lost of the time, so about that share of reports lost
    record = perturb(clean, Faults(burst_lost=0.3, burst_length=5.0), 1)[1]["counts"]
    assert abs(record["lost_in_outages"] / m - 0.3) < 0.03


def test_false_encounters_join_pairs_that_never_met_inside_the_log_span(clean):
    out, record = perturb(clean, Faults(false_encounters=0.05), 2)
    old = set(by_pair(clean))
    new = [k for k, pair in enumerate(by_pair_all(out)) if pair not in old]
    assert len(new) == record["counts"]["false"] > 0  # every added pair is a pair that never met
    assert out.t[new].min() >= clean.t[0] and out.t[new].max() <= clean.t[-1]


def test_duplicates_repeat_a_delivered_report_a_little_later(clean):
    out, record = perturb(clean, Faults(duplicated=0.1, duplicate_delay=0.5), 4)
    first = by_pair(clean)
    pairs, counts = np.unique(np.stack([out.a, out.b]), axis=1, return_counts=True)
    assert int((counts == 2).sum()) == record["counts"]["duplicated"] and counts.max() == 2
    for x, y in pairs[:, counts == 2].T[:50]:
        times = out.t[(out.a == x) & (out.b == y)]
        assert times[0] == first[(x, y)] and 0 <= times[1] - times[0] <= 0.5


def test_jitter_is_gaussian_of_the_given_spread(clean):
    out, record = perturb(clean, Faults(jitter=0.5), 5)
    assert record["shift"] == 0.0  # the log starts at 100 s: no stamp before 0
    first = by_pair(clean)
    diff = np.array([t - first[pair] for pair, t in by_pair(out).items()])
    assert abs(diff.mean()) < 4 * 0.5 / np.sqrt(len(diff)) and abs(diff.std() / 0.5 - 1) < 0.03


def test_clock_offsets_stamp_each_report_with_one_of_its_agents_clocks(clean):
    out, _ = perturb(clean, Faults(clock_offset=3.0), 6)
    first = by_pair(clean)
    diff = {pair: t - first[pair] for pair, t in by_pair(out).items()}
    assert max(abs(d) for d in diff.values()) <= 3.0
    # each agent's clock: the diff its reports share; every report carries one of its two agents' diffs
    values = np.round(np.array(list(diff.values())), 9)
    assert len(np.unique(values)) <= clean.n_agents
    offset = {}
    for (x, y), d in diff.items():
        offset.setdefault(x, []).append(round(d, 9))
        offset.setdefault(y, []).append(round(d, 9))
    mode = {k: max(set(v), key=v.count) for k, v in offset.items()}
    agree = np.mean([round(d, 9) in (mode[x], mode[y]) for (x, y), d in diff.items()])
    assert agree > 0.95


def test_a_stamp_before_zero_shifts_every_time_and_the_seed_reproduces_the_bytes():
    log = once_per_pair(n_agents=100, n_events=2000, t0=0.0, span=50.0)
    out, record = perturb(log, Faults(jitter=1.0, lost=0.2, false_encounters=0.02), 9)
    assert record["shift"] > 0 and out.t.min() == 0.0
    again = perturb(log, Faults(jitter=1.0, lost=0.2, false_encounters=0.02), 9)[0]
    np.testing.assert_array_equal(out.t, again.t)
    np.testing.assert_array_equal(out.a, again.a)
    other = perturb(log, Faults(jitter=1.0, lost=0.2, false_encounters=0.02), 10)[0]
    assert out.n_events != other.n_events or not np.array_equal(out.t, other.t)


def test_each_fault_draws_from_its_own_stream(clean):
    # the same reports are lost whatever the jitter
    lost = perturb(clean, Faults(lost=0.3), 1)[0]
    both = perturb(clean, Faults(lost=0.3, jitter=0.2), 1)[0]
    assert set(by_pair(lost)) == set(by_pair(both))


@pytest.mark.parametrize("fields, message", [
    ({"lost": 1.5}, "faults.lost must be in [0, 1]"),
    ({"burst_lost": 1.0}, "below 1"),
    ({"jitter": -1.0}, "faults.jitter must be a finite number >= 0"),
    ({"clock_drift": 1.0}, "below 1 s per s"),
])
def test_bad_fault_levels_are_refused(fields, message):
    with pytest.raises(InputError, match=message.replace("[", r"\[").replace("]", r"\]")):
        Faults(**fields)


def slow_detours(log: EncounterLog, hop: float) -> np.ndarray:
    """The detour of each event by the definition: scipy's Dijkstra on the chain graph with
    the event's node removed, from a virtual node 'a at t' to a virtual node 'b at t'."""
    m = log.n_events
    edges = {}  # a pair that met twice in a row is joined on both chains: one edge
    for k in range(log.n_agents):
        events = np.flatnonzero((log.a == k) | (log.b == k))
        for i, j in zip(events[:-1], events[1:]):
            edges[int(i), int(j)] = abs(log.t[j] - log.t[i]) + hop
    out = np.full(m, np.inf)
    for e in range(m):
        kept = [(i, j, w) for (i, j), w in edges.items() if e not in (i, j)]
        r, c, w = [k[0] for k in kept], [k[1] for k in kept], [k[2] for k in kept]
        source, target = m, m + 1
        for agent, end in ((log.a[e], source), (log.b[e], target)):
            events = np.flatnonzero((log.a == agent) | (log.b == agent))
            at = int(np.flatnonzero(events == e)[0])
            for n in (at - 1, at + 1):
                if 0 <= n < len(events):
                    r.append(end), c.append(events[n]), w.append(abs(log.t[events[n]] - log.t[e]) + hop)
        graph = sp.coo_matrix((w, (r, c)), shape=(m + 2, m + 2)).tocsr()
        out[e] = dijkstra(graph, directed=False, indices=source)[target]
    return out


def test_detours_of_a_hand_made_log():
    # a meets b at 0, a meets c at 1, b meets c at 1.5: a@0 -> (1, a, c) -> (1.5, b, c) -> b@0
    log = EncounterLog.from_records([0.0, 1.0, 1.5], [0, 0, 1], [1, 2, 2])
    h = 2.0
    # (1, a, c): a@1 -> (0, a, b) -> (1.5, b, c) -> c@1; (1.5, b, c): b@1.5 -> (0, a, b) -> (1, a, c) -> c@1.5
    np.testing.assert_allclose(detours(log, h, 100.0), [1 + h + 0.5 + h + 1.5 + h, 1 + h + 1.5 + h + 0.5 + h,
                                                        1.5 + h + 1 + h + 0.5 + h])
    assert np.isinf(detours(log, h, 8.5)[0])  # beyond the radius


def test_detours_agree_with_the_definition():
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0, 30, 120))
    a = rng.integers(0, 12, 120)
    b = (a + rng.integers(1, 12, 120)) % 12
    log = EncounterLog.from_records(t, a, b)
    slow = slow_detours(log, 1.5)
    fast = detours(log, 1.5, np.inf)
    np.testing.assert_allclose(fast[np.isfinite(slow)], slow[np.isfinite(slow)])
    assert np.array_equal(np.isfinite(fast), np.isfinite(slow))
    bounded = detours(log, 1.5, 8.0)
    np.testing.assert_allclose(bounded, np.where(slow <= 8.0, slow, np.inf))


@pytest.fixture(scope="module")
def swarm_log():
    arena = st.random_arena(1, rng=np.random.SeedSequence(4).spawn(1)[0])
    return st.simulate(arena, 300, 30.0, rng=4).log


def test_the_screen_leaves_a_clean_log_alone_and_drops_most_false_encounters(swarm_log):
    screen, mapped = screen_faults(swarm_log)
    assert mapped is swarm_log and not screen.suspected and screen.far_share <= CLEAN_FAR_SHARE
    faulty, _ = perturb(swarm_log, Faults(false_encounters=0.03), 1)
    screen, mapped = screen_faults(faulty)
    assert screen.suspected and screen.dropped == faulty.n_events - mapped.n_events
    old = set(by_pair_all(swarm_log))
    false_before = sum(pair not in old for pair in by_pair_all(faulty))
    false_after = sum(pair not in old for pair in by_pair_all(mapped))
    assert false_after < 0.2 * false_before  # at least 80 % of the false encounters dropped
    assert mapped.n_events > 0.95 * (faulty.n_events - false_before)  # and at most 5 % of the true ones
    assert screen_faults(faulty, "keep")[1] is faulty
    small = swarm_log.window(0.0, 30.0)
    inside = (small.a < 50) & (small.b < 50)
    few = EncounterLog.from_records(small.t[inside], small.a[inside], small.b[inside])
    assert screen_faults(few)[0].uncorroborated_share is None  # fewer than MIN_AGENTS: not read


def test_the_screen_merges_duplicated_reports(swarm_log):
    screen, mapped = screen_faults(swarm_log)
    assert not screen.duplicated and screen.merged == 0
    faulty, record = perturb(swarm_log, Faults(duplicated=0.2), 3)
    screen, mapped = screen_faults(faulty)
    duplicates = record["counts"]["duplicated"]
    assert screen.duplicated and not screen.suspected  # duplicates alone: merged, no recalibration
    assert 0.9 * duplicates <= screen.merged <= 1.1 * duplicates
    assert mapped.n_events == faulty.n_events - screen.merged
    assert abs(mapped.n_events - swarm_log.n_events) < 0.02 * swarm_log.n_events
    warnings = fault_warnings(screen, False)
    assert len(warnings) == 1 and "duplicated reports are suspected" in warnings[0]


def by_pair_all(log):
    return list(zip(log.a.tolist(), log.b.tolist()))


def test_the_map_warns_and_says_what_the_screen_did(swarm_log):
    faulty, _ = perturb(swarm_log, Faults(false_encounters=0.03), 1)
    tmap = map_encounters(faulty, MapConfig(**FAST))
    doc = map_json(tmap)
    assert doc["sensing"]["suspected"] and doc["sensing"]["dropped"] > 0
    assert any("false encounters" in w and "left out of the map" in w for w in doc["warnings"])
    assert tmap.n_events == faulty.n_events - doc["sensing"]["dropped"]
    # read by the shipped reader: its beta_1 confidence through the faulty logs' Platt scaling
    fit = doc["classifier"]["fault_recalibration"]
    raw = st.load_classifier("default")
    region = raw.read([w.diagram for w in tmap.regions[0].windows])
    z = fit["intercept"] + fit["slope"] * np.log(region.confidence[1] / (1 - region.confidence[1]))
    assert tmap.regions[0].confidence[1] == pytest.approx(1 / (1 + np.exp(-z)))
    kept = map_json(map_encounters(faulty, MapConfig(uncorroborated="keep", **FAST)))
    assert kept["sensing"]["uncorroborated_share"] is None and kept["log"]["events"] == faulty.n_events
    clean = map_json(map_encounters(swarm_log, MapConfig(**FAST)))
    assert not clean["sensing"]["suspected"] and not any("false encounters" in w for w in clean["warnings"])


def test_perturb_command_writes_a_faulty_log_with_its_record(tmp_path):
    log_dir = tmp_path / "clean"
    assert run_cli("simulate", "--holes", "1", "--agents", "60", "--duration", "10", "--seed", "2",
                   "--out", log_dir, "-q").returncode == 0
    result = run_cli("perturb", log_dir, "--out", tmp_path / "faulty", "--lost", "0.3", "--jitter", "0.2",
                     "--false-encounters", "0.2", "--seed", "5")
    assert result.returncode == 0, result.stderr
    assert "faults: " in result.stdout and "false encounters added" in result.stdout
    meta = json.loads((tmp_path / "faulty" / "meta.json").read_text())
    assert meta["faults"][0]["seed"] == 5 and meta["faults"][0]["faults"]["lost"] == 0.3
    assert (tmp_path / "faulty" / "arena.geojson").is_file()
    again = run_cli("perturb", log_dir, "--out", tmp_path / "again", "--lost", "0.3", "--jitter", "0.2",
                    "--false-encounters", "0.2", "--seed", "5", "-q")
    assert again.returncode == 0
    assert (tmp_path / "faulty" / "events.csv").read_bytes() == (tmp_path / "again" / "events.csv").read_bytes()
    none = run_cli("perturb", log_dir, "--out", tmp_path / "none")
    assert none.returncode != 0 and "no fault given" in none.stderr
    bad = run_cli("perturb", log_dir, "--out", tmp_path / "bad", "--lost", "1.5")
    assert bad.returncode != 0 and "--lost" in bad.stderr
    same = run_cli("perturb", log_dir, "--out", log_dir, "--lost", "0.1", "--overwrite")
    assert same.returncode != 0 and "Traceback" not in same.stderr


def test_simulate_with_faults_records_them_and_refuses_truth(tmp_path):
    result = run_cli("simulate", "--holes", "1", "--agents", "60", "--duration", "10", "--seed", "2",
                     "--out", tmp_path / "log", "--dying", "0.2")
    assert result.returncode == 0 and "dead agents' batteries" in result.stdout
    meta = json.loads((tmp_path / "log" / "meta.json").read_text())
    assert meta["faults"][0]["counts"]["died"] == 12
    refused = run_cli("simulate", "--agents", "60", "--duration", "10", "--out", tmp_path / "t", "--truth",
                      "--lost", "0.1")
    assert refused.returncode != 0 and "drop --truth" in refused.stderr


def test_a_sweep_with_faults(tmp_path):
    sweep = expand_grid({"swarm": {"agents": 100}, "faults": {"lost": [0.0, 0.3], "burst_lost": 0.1}})
    configs = [job.config for job in sweep.jobs]
    assert [c["faults"] for c in configs] == [{"burst_lost": 0.1, "burst_length": 2.0},
                                              {"lost": 0.3, "burst_lost": 0.1, "burst_length": 2.0}]
    plain = expand_grid({"swarm": {"agents": 100}, "faults": {"lost": 0.0}})
    assert "faults" not in plain.jobs[0].config
    assert plain.jobs[0].key == expand_grid({"swarm": {"agents": 100}}).jobs[0].key  # no fault: the key of before
    with pytest.raises(InputError, match="burst_length.*burst_lost is 0"):
        expand_grid({"swarm": {"agents": 100}, "faults": {"burst_length": 3.0}})
    with pytest.raises(InputError, match=r"\[faults\] lost"):
        expand_grid({"swarm": {"agents": 100}, "faults": {"lost": 2.0}})


def test_the_fault_benchmark_maps_one_case_at_every_level():
    assert bench.LEVELS[0].name == "none" and bench.TARGET in {level.name for level in bench.LEVELS}
    for level in bench.LEVELS:
        config, seed = bench.case(bench.Cell(level, 2), "tuning", 0)
        assert bench.level_of(config) == level
        base, base_seed = bench.case(bench.Cell(bench.LEVELS[0], 2), "tuning", 0)
        assert seed == base_seed and config["arena"] == base["arena"]  # the same case, other faults
    reporting, _ = bench.case(bench.Cell(bench.LEVELS[0], 2), "reporting", 0)
    assert reporting["arena"] != bench.case(bench.Cell(bench.LEVELS[0], 2), "tuning", 0)[0]["arena"]
    jobs = bench.jobs("reporting", quick=True)
    assert len(jobs) == len(bench.LEVELS) * len(bench.HOLES) and len({j.key for j in jobs}) == len(jobs)
    full = bench.jobs("reporting")
    assert len(full) == sum(bench.per_cell(level, False) for level in bench.LEVELS) * len(bench.HOLES)


@pytest.mark.slow
def test_the_fault_benchmark_runs_resumes_and_reports(tmp_path):
    target = next(level for level in bench.LEVELS if level.name == bench.TARGET)
    cells = [bench.Cell(bench.LEVELS[0], 1), bench.Cell(target, 1)]
    summary = bench.run_benchmark(tmp_path / "faults.duckdb", per_cell=1, cells=cells, workers=1)
    assert summary["jobs_run"] == 2 and [r["level"] for r in summary["records"]] != []
    levels = summary["table"]["levels"]
    assert set(levels) == {"none", bench.TARGET} and all(t["logs"] == 1 for t in levels.values())
    faulty = next(r for r in summary["records"] if r["level"] == bench.TARGET)
    assert faulty["suspected"] and faulty["dropped"] > 0  # 3 % false encounters: read and screened
    again = bench.run_benchmark(tmp_path / "faults.duckdb", per_cell=1, cells=cells, workers=1)
    assert again["jobs_run"] == 0 and again["table"] == summary["table"]  # resumed: nothing run again
    text = bench.markdown(summary, "swarmtopo bench faults")
    assert f"Target ({bench.TARGET})" in text and "| none | 1 |" in text
    bench.plot(summary, tmp_path / "faults.png")
    assert (tmp_path / "faults.png").stat().st_size > 10_000


def test_edge_cases_of_the_faults_and_the_screen():
    # outages start in their stationary state: a radio is down at the log's start a share F of the time
    log = once_per_pair(n_agents=400, n_events=4000, t0=0.0, span=1.0)
    record = perturb(log, Faults(burst_lost=0.5, burst_length=10.0), 2)[1]["counts"]
    assert abs(record["lost_in_outages"] / log.n_events - 0.5) < 0.05
    with pytest.raises(InputError, match="burst_length must be at least"):
        Faults(burst_lost=0.1, burst_length=1e-4)
    # false encounters join living agents only: after t = 5 only agents 0-2 live, after t = 8 none
    small = once_per_pair(n_agents=20, n_events=50)
    death = np.where(np.arange(20) < 3, 8.0, 5.0)
    t, a, b = _false_reports(np.random.default_rng(1), 400, 0.0, 10.0, death, small)
    assert len(t) < 400 and t.max() < 8.0  # none drawn where fewer than two are alive
    late = t > 5.0
    assert late.any() and np.all(np.maximum(a[late], b[late]) < 3)
    # a log of repeats only: merged, then nothing left to read, and no crash
    t = np.repeat(np.arange(60) * 10.0, 2) + np.tile([0.0, 0.001], 60)
    pairs = np.repeat(np.arange(60), 2)
    repeats = EncounterLog.from_records(t, 2 * pairs, 2 * pairs + 1)
    screen, mapped = screen_faults(repeats, "drop")
    assert screen.merged == 60 and screen.uncorroborated_share is None and mapped.n_events == 60
