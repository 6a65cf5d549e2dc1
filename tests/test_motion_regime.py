"""The motion read from the log (swarmtopo.pipeline.motion), the map's re-contact
option, sweeps of other motion models and the motion benchmark's cases."""

import json

import numpy as np
import pytest

import swarmtopo as st
from swarmtopo.errors import SwarmtopoError
from swarmtopo.experiments import motion_models
from swarmtopo.experiments.accuracy import tuning_session
from swarmtopo.experiments.grid import expand_grid, job_simulation_args
from swarmtopo.experiments.sweep import contact_trace
from swarmtopo.io.logs import write_log
from swarmtopo.log import EncounterLog
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.pipeline.config import ConfigError
from swarmtopo.pipeline.motion import MIN_AGENTS, estimate_motion, median_agent_gap, recontact_gaps
from swarmtopo.sim.params import Billiard, Brownian, RunAndTumble
from swarmtopo.viz.summary import map_json

FAST = dict(embed_dim=0, landmark_bands=(1.0,))


def test_recontact_gaps_and_the_median_gap_of_a_hand_made_log():
    # pair (0, 1) meets at 0, 1 and 10 s (logged either way round); (2, 3) at 1.5 s
    log = EncounterLog.from_records(np.array([0.0, 1.0, 1.5, 10.0]), np.array([0, 1, 2, 0]), np.array([1, 0, 3, 1]))
    np.testing.assert_array_equal(recontact_gaps(log), [np.inf, 1.0, np.inf, 9.0])
    # agent gaps: agent 0 and agent 1 each 1 and 9 s; agents 2, 3 none -> median of [1, 9, 1, 9] = 5
    assert median_agent_gap(log) == 5.0
    estimate, mapped = estimate_motion(log, "merge")
    assert estimate.recontact_share == pytest.approx(0.5)  # 1 s and 9 s are within 7 x 5 s
    assert estimate.regime == "unread"  # 4 agents: too few to tell motion from re-meeting
    assert estimate.merged == 2  # merging forced
    np.testing.assert_array_equal(mapped.t, [0.0, 1.5])
    assert estimate.partners_per_agent == pytest.approx(1.0) and estimate.encounter_rate == pytest.approx(0.2)
    kept = estimate_motion(log, "keep")[1]
    assert kept is log


def _random_meetings(n_agents, n_events, span, seed, burst=0):
    """Agents meeting uniformly at random; with ``burst`` each meeting is logged again
    ``burst`` times 0.05 s apart (a flickering contact)."""
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, span, n_events))
    a = rng.integers(0, n_agents, n_events)
    b = (a + rng.integers(1, n_agents, n_events)) % n_agents
    if burst:
        t = (t[:, None] + 0.05 * np.arange(burst + 1)).ravel()
        a, b = np.repeat(a, burst + 1), np.repeat(b, burst + 1)
    return EncounterLog.from_records(t, a, b)


def test_flickering_contacts_are_merged_into_their_first_start_and_persistent_logs_are_kept():
    steady = _random_meetings(300, 6000, 40.0, 1)
    estimate, mapped = estimate_motion(steady)
    assert estimate.regime == "persistent" and estimate.recontact_share < 0.05 and mapped is steady
    flicker = _random_meetings(300, 6000, 40.0, 1, burst=3)
    estimate, mapped = estimate_motion(flicker)
    assert estimate.regime == "flickering" and estimate.recontact_share > 0.7
    # the repeats (3 per meeting, 0.05 s apart: g = 0.05 s) go; of the first starts, only a pair's meeting
    # within 7 g of its previous one (a handful of 44,850 pairs) would
    assert estimate.median_gap == pytest.approx(0.05)
    assert 18000 <= estimate.merged <= 18000 + 10 and set(mapped.t) <= set(flicker.t)
    assert mapped.n_events == flicker.n_events - estimate.merged


def test_small_swarms_are_not_read_and_map_as_logged():
    # 40 cockroaches over 200 s meet the same few again and again: rho is as high as a Brownian swarm's
    log = st.simulate(st.default_arena(), 40, 200.0, rng=1).log
    estimate, mapped = estimate_motion(log)
    assert estimate.recontact_share > 0.25 and estimate.regime == "unread" and mapped is log
    assert log.n_agents < MIN_AGENTS
    tmap = map_encounters(log, MapConfig(**FAST))
    assert tmap.n_events == log.n_events and not any("flicker" in w for w in tmap.warnings)


def test_a_pair_met_just_before_the_window_keeps_its_first_contact_inside_it():
    flicker = _random_meetings(300, 3000, 40.0, 4, burst=3)
    t = np.r_[49.9, 50.0, flicker.t + 60.0]
    log = EncounterLog.from_records(t, np.r_[0, 0, flicker.a], np.r_[1, 1, flicker.b])
    estimate, merged = estimate_motion(log, window=(50.0, None))
    assert estimate.regime == "flickering"
    assert 50.0 in merged.t and 49.9 in merged.t  # outside the window nothing is merged


def test_a_persistent_log_maps_exactly_as_without_the_estimate():
    log = st.simulate(st.default_arena(), 150, 20.0, rng=2).log
    auto = map_encounters(log, MapConfig(**FAST))
    keep = map_encounters(log, MapConfig(recontacts="keep", **FAST))
    assert auto.motion.regime == "persistent" and auto.motion.merged == 0
    assert auto.betti == keep.betti and auto.confidence == keep.confidence
    for n in range(2):
        np.testing.assert_array_equal(auto.diagram[n], keep.diagram[n])
    assert not any("flicker" in w for w in auto.warnings)


def test_brownian_contacts_flicker_and_the_map_says_so():
    sim = st.simulate(st.random_arena(1, rng=2), 200, 20.0, motion=Brownian(diffusion=300.0), rng=1)
    tmap = map_encounters(contact_trace(sim.log), MapConfig(**FAST))
    assert tmap.motion.regime == "flickering" and tmap.motion.merged > 0.3 * sim.log.n_events
    assert tmap.n_events == sim.log.n_events - tmap.motion.merged
    assert any(w.startswith("the agents' contacts flicker") for w in tmap.warnings)
    doc = map_json(tmap)
    assert doc["motion"]["regime"] == "flickering" and doc["params"]["recontacts"] == "auto"
    billiard = st.simulate(st.random_arena(1, rng=2), 200, 20.0, motion=Billiard(), rng=1).log
    assert estimate_motion(billiard)[0].regime == "persistent"


def test_the_estimate_reads_the_mapped_window_only():
    quiet = _random_meetings(300, 3000, 40.0, 3)
    noisy = _random_meetings(300, 3000, 40.0, 4, burst=3)
    log = EncounterLog.from_records(np.r_[quiet.t, noisy.t + 100.0], np.r_[quiet.a, noisy.a],
                                    np.r_[quiet.b, noisy.b])
    assert estimate_motion(log, window=(0.0, 50.0))[0].regime == "persistent"
    assert estimate_motion(log, window=(100.0, None))[0].regime == "flickering"


def test_recontacts_option_is_checked_and_the_paper_keeps_every_event(tmp_path, cli):
    with pytest.raises(ConfigError, match="recontacts"):
        MapConfig(recontacts="sometimes").validate()
    sim = st.simulate(st.random_arena(1, rng=2), 200, 20.0, motion=Brownian(), rng=1)
    write_log(sim.log, tmp_path / "log")
    proc = cli("map", tmp_path / "log", "--out", tmp_path / "bad", "--recontacts", "often")
    assert proc.returncode == 2 and "recontacts" in proc.stderr and "Traceback" not in proc.stderr
    proc = cli("map", tmp_path / "log", "--out", tmp_path / "paper", "--paper", "-q")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((tmp_path / "paper" / "map.json").read_text())
    assert doc["motion"]["regime"] == "flickering" and doc["motion"]["merged"] == 0
    assert doc["log"]["events"] == sim.log.n_events
    proc = cli("map", tmp_path / "log", "--out", tmp_path / "map", "-q")
    html = (tmp_path / "map" / "report.html").read_text()
    assert 'class="motion" data-regime="flickering"' in html


def test_simulate_cli_runs_other_models_and_refuses_their_wrong_options(tmp_path, cli):
    proc = cli("simulate", "--motion", "run-and-tumble", "--tumble-rate", "2", "--agents", "50", "--duration", "5",
               "--out", tmp_path / "rt", "-q")
    assert proc.returncode == 0, proc.stderr
    meta = json.loads((tmp_path / "rt" / "meta.json").read_text())
    assert meta["simulation"]["motion_model"] == "run-and-tumble"
    assert meta["simulation"]["motion"] == {"speed": 15.0, "tumble_rate": 2.0}
    proc = cli("simulate", "--motion", "billiard", "--noise", "1", "--out", tmp_path / "b")
    assert proc.returncode == 2 and "noise is not an option of billiard motion" in proc.stderr
    proc = cli("simulate", "--motion", "brownian", "--beacon", "sweep", "--leash", "200", "--out", tmp_path / "c")
    assert proc.returncode == 2 and "cockroach model only" in proc.stderr


def test_sweeps_take_a_motion_model_and_keep_cockroach_jobs_as_they_were():
    plain = expand_grid({"swarm": {"agents": 50}}).jobs[0]
    assert "motion" not in plain.config["swarm"]
    walk = expand_grid({"swarm": {"motion": "run-and-tumble", "tumble_rate": [0.5, 2.0], "agents": 50}}).jobs
    assert [j.config["swarm"]["tumble_rate"] for j in walk] == [0.5, 2.0]
    assert job_simulation_args(walk[1].config["swarm"])["motion"] == RunAndTumble(tumble_rate=2.0)
    with pytest.raises(SwarmtopoError, match="tumble_rate.*not used by this motion model"):
        expand_grid({"swarm": {"motion": "billiard", "tumble_rate": 1.0}})
    with pytest.raises(SwarmtopoError, match="diffusion"):
        expand_grid({"swarm": {"motion": "brownian", "diffusion": 5000.0}})  # the simulator's time step rule


def test_motion_benchmark_cases_are_fixed_split_and_drawn_in_their_ranges():
    with tuning_session():
        tuning = motion_models.jobs("tuning", 2)
    reporting = motion_models.jobs("reporting", 2)
    assert len(reporting) == len(motion_models.CELLS) * 2 == 48
    assert not {j.key for j in tuning} & {j.key for j in reporting}
    assert [j.key for j in reporting] == [j.key for j in motion_models.jobs("reporting", 2)]
    for job in reporting:
        swarm = job.config["swarm"]
        model = swarm.get("motion", "cockroach")
        for name, (lo, hi) in motion_models.PARAMETER_RANGES[model].items():
            assert lo <= swarm[name] <= hi
        assert job.config["map"]["input"] == "contact-trace"
    assert all(motion_models.HELD_OUT_FAMILY not in j.config["arena"]["shapes"] for j in tuning)


def test_platt_recalibration_of_a_reader_by_hand():
    from swarmtopo.readers.recalibrated import Recalibrated

    reader = st.load_classifier("trace")
    same = Recalibrated(reader, 0.0, 1.0, {})
    assert same.scaled(0.73) == pytest.approx(0.73) and same.scaled(None) is None and same.scaled(1.0) == 1.0
    shrunk = Recalibrated(reader, -1.0, 0.5, {})
    assert shrunk.scaled(0.9) == pytest.approx(1 / (1 + np.exp(1.0 - 0.5 * np.log(9.0))))  # 0.5246
    log = st.simulate(st.random_arena(1, rng=2), 150, 15.0, rng=1).log
    tmap = map_encounters(contact_trace(log), MapConfig(**FAST), reader=reader)
    diagrams = [w.diagram for w in tmap.regions[0].windows]
    raw, scaled = reader.read(diagrams), shrunk.read(diagrams)
    assert scaled.betti == raw.betti and scaled.confidence[1] == pytest.approx(shrunk.scaled(raw.confidence[1]))
    assert shrunk.describe()["flicker_recalibration"]["slope"] == 0.5


def test_a_flickering_log_read_by_a_shipped_reader_gets_the_recalibrated_confidence():
    from swarmtopo.readers.recalibrated import recalibration

    sim = st.simulate(st.random_arena(1, rng=2), 200, 20.0, motion=Brownian(diffusion=300.0), rng=1)
    trace = contact_trace(sim.log)
    shipped = map_encounters(trace, MapConfig(**FAST))
    raw = map_encounters(trace, MapConfig(**FAST), reader=_unshipped("trace"))
    fit = recalibration("flicker", "trace", st.load_classifier("trace"))
    assert fit is not None and "flicker_recalibration" in shipped.classifier
    assert shipped.betti == raw.betti
    assert shipped.confidence[1] == pytest.approx(fit.scaled(raw.confidence[1]))
    assert "recalibrated on flickering logs" in shipped.warnings[0]
    assert "flicker_recalibration" not in raw.classifier  # a reader of one's own is left as it is


def _unshipped(name):
    reader = st.load_classifier(name)
    reader.shipped_preset = None
    return reader


def test_a_sweep_refuses_a_leader_for_another_motion_model():
    with pytest.raises(SwarmtopoError, match="leader .* steers the cockroach model only"):
        expand_grid({"swarm": {"motion": "brownian", "leash": 200.0}})
