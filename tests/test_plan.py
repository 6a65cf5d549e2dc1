"""Planning model: recovery of a known logistic law, inverse answers, the CLI."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from swarmtopo.cli import app
from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.experiments.plan import PlanModel, fit_plan, load_plan

runner = CliRunner()


def synthetic_records(n, rng, c=(-2.0, 1.5, 2.0, -0.8)):
    """Maps drawn from P(right) = sigmoid(c0 + c1 ln(N/A) + c2 ln T + c3 H) with A around
    1 m^2 and H uniform in 0-3."""
    records = []
    for _ in range(n):
        area = rng.uniform(0.5e6, 1.5e6)
        agents = rng.integers(100, 500)
        duration = rng.uniform(20, 80)
        holes = int(rng.integers(0, 4))
        z = c[0] + c[1] * np.log(agents / area * 1e4) + c[2] * np.log(duration / 30) + c[3] * holes
        records.append({"area": area, "agents": int(agents), "duration": duration, "true_betti1": holes,
                        "right": bool(rng.random() < 1 / (1 + np.exp(-z)))})
    return records


def sigmoid(z):
    return 1 / (1 + np.exp(-z))


def test_fit_recovers_the_law_it_was_drawn_from():
    rng = np.random.default_rng(1)
    model = fit_plan(synthetic_records(4000, rng), source="test")
    # slope standard errors at n = 4000 are about 0.1; 0.3 is three of them
    assert model.density_coef == pytest.approx(1.5, abs=0.3)
    # the law has no ln N ln T term: the fitted one is small, and time's slope at N = 300 is the law's
    assert model.agents_duration_coef == pytest.approx(0.0, abs=0.6)
    assert model.duration_coef + model.agents_duration_coef * np.log(300) == pytest.approx(2.0, abs=0.3)
    assert model.holes_coef == pytest.approx(-0.8, abs=0.3)
    assert model.holes_mix == pytest.approx((0.25,) * 4, abs=0.03)  # H uniform in 0-3
    z = -2.0 + 1.5 * np.log(300 / 1e6 * 1e4) + 2.0 * np.log(40 / 30)
    assert model.accuracy(1e6, 300, 40, holes=2) == pytest.approx(sigmoid(z - 1.6), abs=0.04)
    assert model.accuracy(1e6, 300, 40) == pytest.approx(np.mean([sigmoid(z - 0.8 * h) for h in range(4)]), abs=0.04)


def test_fit_tells_swarm_size_from_density_and_time_when_they_vary_apart():
    """Drawn from a law with a ln N term of its own and a ln N ln T term (time buys more
    with more agents) besides density and time: the fit recovers the law's answers and
    its interaction, and the /2 form (no swarm-size terms) leaves both out."""
    rng = np.random.default_rng(3)

    def law(area, agents, duration, holes):
        n, t = np.log(agents / 300), np.log(duration / 30)
        return 0.5 + 0.8 * np.log(agents / area * 1e4) + 0.6 * t + 1.0 * n + 0.5 * n * t - 0.8 * holes

    records = []
    for _ in range(6000):
        area, agents, duration = rng.uniform(0.1e6, 1.0e6), int(rng.integers(100, 800)), rng.uniform(15, 120)
        holes = int(rng.integers(0, 4))
        records.append({"area": area, "agents": agents, "duration": duration, "true_betti1": holes,
                        "right": bool(rng.random() < sigmoid(law(area, agents, duration, holes)))})
    model = fit_plan(records, source="test")
    assert model.agents_duration_coef == pytest.approx(0.5, abs=0.25)
    assert model.density_coef == pytest.approx(0.8, abs=0.3)
    for case in ((0.1e6, 100, 40, 0), (0.1e6, 100, 120, 2), (1e6, 800, 15, 1), (0.5e6, 300, 30, 3), (0.3e6, 700, 100, 0)):
        # a small swarm as dense as a big one maps worse, and time helps it less: the model says so too
        assert model.accuracy(*case) == pytest.approx(sigmoid(law(*case)), abs=0.05), case
    flat = fit_plan(records, source="test", swarm_terms=0)
    assert flat.agents_coef == 0.0 and flat.agents_duration_coef == 0.0
    # the inverse answers account for every term
    n = model.agents_for(0.5e6, 40, 0.9, holes=1)
    assert model.accuracy(0.5e6, n, 40, holes=1) == pytest.approx(0.9)
    log_t = np.log(40)
    closed = np.exp((np.log(0.9 / 0.1) - model.intercept - model.duration_coef * log_t - model.holes_coef
                     + model.density_coef * np.log(0.5e6))
                    / (model.density_coef + model.agents_coef + model.agents_duration_coef * log_t))
    assert n == pytest.approx(closed, rel=1e-6)
    t = model.duration_for(0.5e6, 300, 0.9, holes=1)
    assert model.accuracy(0.5e6, 300, t, holes=1) == pytest.approx(0.9)


def test_unknown_holes_average_over_the_mix_and_more_holes_need_more_data():
    model = PlanModel(-3.0, 1.2, 1.8, (1e-4, 1e-3), (30, 60), 100, "test", -0.5, (0.5, 0.25, 0.25))
    per_hole = [model.accuracy(250_000, 200, 30, holes=h) for h in range(3)]
    assert model.accuracy(250_000, 200, 30) == pytest.approx(0.5 * per_hole[0] + 0.25 * (per_hole[1] + per_hole[2]))
    assert per_hole[0] > per_hole[1] > per_hole[2]
    assert model.agents_for(250_000, 30, 0.9, holes=2) > model.agents_for(250_000, 30, 0.9, holes=0)
    assert model.inside(250_000, 100, 40, holes=2) and not model.inside(250_000, 100, 40, holes=3)
    with pytest.raises(InputError, match="holes"):
        model.accuracy(250_000, 200, 30, holes=-1)


def test_inverse_answers_invert_the_forward_one():
    for model in (PlanModel(-3.0, 1.2, 1.8, (1e-4, 1e-3), (30, 60), 100, "test"),
                  PlanModel(-3.0, 1.2, 1.8, (1e-4, 1e-3), (30, 60), 100, "test", -0.7, (0.25,) * 4)):
        for holes in (None, 0, 3):
            n = model.agents_for(250_000, 40, 0.9, holes)
            assert model.accuracy(250_000, n, 40, holes) == pytest.approx(0.9)
            t = model.duration_for(250_000, 300, 0.95, holes)
            assert model.accuracy(250_000, 300, t, holes) == pytest.approx(0.95)
    # without a hole term the answer has a closed form: ln(N / A) = (logit p - c0 - c2 ln T) / c1
    model = PlanModel(-3.0, 1.2, 1.8, (1e-4, 1e-3), (30, 60), 100, "test")
    closed = 250_000 * np.exp((np.log(0.9 / 0.1) + 3.0 - 1.8 * np.log(40)) / 1.2)
    assert model.agents_for(250_000, 40, 0.9) == pytest.approx(closed, rel=1e-6)
    flat = PlanModel(0.0, 0.0, -1.0, (1e-4, 1e-3), (30, 60), 100, "test")
    assert flat.agents_for(1, 1, 0.9) == np.inf and flat.duration_for(1, 1, 0.9) == np.inf


def test_format_2_files_read_without_a_swarm_size_term(tmp_path):
    model = PlanModel(-3.0, 1.2, 1.8, (1e-4, 1e-3), (30, 60), 100, "test", -0.5, (0.25,) * 4, (200.0, 400.0))
    old = {**model.to_json(), "format": "swarmtopo-plan/2"}
    del old["agents_coef"], old["agents_duration_coef"]
    path = tmp_path / "old.json"
    path.write_text(json.dumps(old))
    assert load_plan(path) == model and load_plan(path).agents_coef == 0.0


def test_format_3_files_read_without_an_interaction_term(tmp_path):
    model = PlanModel(-3.0, 1.2, 1.8, (1e-4, 1e-3), (30, 60), 100, "test", -0.5, (0.25,) * 4, (200.0, 400.0), 0.7)
    old = {**model.to_json(), "format": "swarmtopo-plan/3"}
    del old["agents_duration_coef"]
    path = tmp_path / "old.json"
    path.write_text(json.dumps(old))
    assert load_plan(path) == model and load_plan(path).agents_duration_coef == 0.0
    assert load_plan(path).accuracy(250_000, 200, 30, 1) == pytest.approx(
        sigmoid(-3.0 + 1.2 * np.log(200 / 250_000) + 1.8 * np.log(30) + 0.7 * np.log(200) - 0.5))


def test_format_1_files_read_without_a_hole_term_and_bad_mixes_are_refused(tmp_path):
    old = {"format": "swarmtopo-plan/1", "intercept": -3.0, "density_coef": 1.2, "duration_coef": 1.8,
           "density_range": [1e-4, 1e-3], "duration_range": [30, 60], "maps": 100, "source": "old"}
    path = tmp_path / "old.json"
    path.write_text(json.dumps(old))
    model = load_plan(path)
    assert model.holes_coef == 0.0 and model.accuracy(1e6, 300, 40, holes=3) == model.accuracy(1e6, 300, 40)
    bad = {**model.to_json(), "holes_mix": [0.5, 0.2]}
    path.write_text(json.dumps(bad))
    with pytest.raises(InputError, match="holes_mix"):
        load_plan(path)


def test_bad_plan_inputs():
    model = PlanModel(-3.0, 1.2, 1.8, (1e-4, 1e-3), (30, 60), 100, "test")
    with pytest.raises(InputError, match="target"):
        model.agents_for(1e5, 30, 1.0)
    with pytest.raises(InputError, match="area"):
        model.accuracy(-1, 200, 30)
    with pytest.raises(SwarmtopoError, match="both right and wrong"):
        fit_plan([{"area": 1.0, "agents": 1, "duration": 1.0, "true_betti1": 0, "right": True}] * 3, source="x")


def test_plan_cli_forward_and_inverse(tmp_path):
    path = tmp_path / "plan.json"
    model = PlanModel(-3.0, 1.2, 1.8, (5e-4, 2e-3), (30, 60), 100, "test", -0.6, (0.25,) * 4)
    path.write_text(json.dumps(model.to_json()))
    res = runner.invoke(app, ["plan", "--area", "250000", "--agents", "200", "--duration", "30", "--model", str(path)])
    assert res.exit_code == 0, res.output
    assert f"{100 * model.accuracy(250000, 200, 30):.0f}%" in res.output
    res = runner.invoke(app, ["plan", "--area", "250000", "--duration", "30", "--target", "0.95", "--model", str(path)])
    assert res.exit_code == 0 and f"needed: {int(np.ceil(model.agents_for(250000, 30, 0.95)))} agents" in res.output
    res = runner.invoke(app, ["plan", "--area", "250000", "--agents", "200", "--model", str(path)])
    assert res.exit_code != 0 and "two of --agents, --duration and --target" in res.output
    res = runner.invoke(app, ["plan", "--area", "250000", "--agents", "200", "--duration", "30", "--holes", "3",
                              "--model", str(path)])
    assert res.exit_code == 0 and f"{100 * model.accuracy(250000, 200, 30, 3):.0f}%" in res.output
    assert "with 3 holes" in res.output
    res = runner.invoke(app, ["plan", "--area", "250000", "--agents", "200", "--duration", "30", "--holes", "-1",
                              "--model", str(path)])
    assert res.exit_code != 0


@pytest.mark.parametrize("reading", ["log", "contact-trace"])
def test_shipped_plan_was_fitted_on_the_full_benchmark(reading):
    from swarmtopo.experiments.accuracy import (BUDGETS, CELLS, PLANNING_BUDGETS, PLANNING_CELLS, PLANNING_PER_CELL,
                                                PLANNING_SCALE_RANGE, REPORTING_PER_CELL, SCALE_RANGE)
    model = load_plan(reading=reading)
    assert model.maps == len(CELLS) * REPORTING_PER_CELL + len(PLANNING_CELLS) * PLANNING_PER_CELL
    assert ("trace_accuracy.py" in model.source) == (reading == "contact-trace")
    # its ranges are the suite's and the planning grid's: 100-800 agents in (500 s)^2 rooms of
    # scale 0.75-2 (two rooms of the suite share their swarm), 15-120 s
    budgets = BUDGETS + PLANNING_BUDGETS
    lo = min(n for n, _ in budgets) / (500 * PLANNING_SCALE_RANGE[1]) ** 2
    hi = max(n for n, _ in budgets) / (500 * min(SCALE_RANGE[0], PLANNING_SCALE_RANGE[0])) ** 2
    assert lo * 0.99 <= model.density_range[0] and model.density_range[1] <= hi * 1.01
    assert model.duration_range == (min(t for _, t in budgets), max(t for _, t in budgets))
    assert model.agents_range == (min(n for n, _ in budgets), max(n for n, _ in budgets))
    assert len(model.holes_mix) == 4 and model.holes_coef < 0  # 0-3 holes; more holes, harder
    # the swarm-size terms are fitted (the grid tells them from duration), and they count
    # across the fitted range: at the same density and duration a larger swarm in a larger
    # arena maps better, and time helps a small swarm less than a large one
    assert model.agents_duration_coef > 0
    for log_t in np.log(model.duration_range):
        assert model.agents_coef + model.agents_duration_coef * log_t > 0
    for log_n in np.log(model.agents_range):
        assert model.duration_coef + model.agents_duration_coef * log_n > 0
    assert model.accuracy(1e6, 800, 30, 2) > model.accuracy(0.25e6, 200, 30, 2)


def test_plan_cli_answers_for_contact_traces_from_their_own_model(tmp_path):
    log, trace = load_plan(), load_plan(reading="contact-trace")
    assert trace != log
    args = ["plan", "--area", "250000", "--agents", "200", "--duration", "60"]
    for reading, model in (("log", log), ("contact-trace", trace)):
        res = runner.invoke(app, args + ["--input", reading])
        assert res.exit_code == 0, res.output
        assert f"{100 * model.accuracy(250000, 200, 60):.0f}%" in res.output
        assert ("as a contact trace" in res.output) == (reading == "contact-trace")
    res = runner.invoke(app, args + ["--input", "trace"])
    assert res.exit_code == 2 and "'trace' is not one of 'log', 'contact-trace'" in res.output
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(log.to_json()))
    res = runner.invoke(app, args + ["--input", "contact-trace", "--model", str(path)])
    assert res.exit_code == 2 and "--model names its own plan" in res.output
    with pytest.raises(InputError, match="no plan for input 'x'"):
        load_plan(reading="x")


def test_swarms_too_small_to_map_are_refused_and_sizes_outside_the_benchmark_are_extrapolations(tmp_path):
    rng = np.random.default_rng(2)
    records = synthetic_records(400, rng)
    model = fit_plan(records, source="test")
    assert model.agents_range == (min(r["agents"] for r in records), max(r["agents"] for r in records))
    assert PlanModel.from_json(json.loads(json.dumps(model.to_json()))) == model
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(model.to_json()))
    small_room = ["plan", "--area", "20000", "--model", str(path)]  # a density inside the range, a tiny swarm
    res = runner.invoke(app, small_room + ["--agents", "2", "--duration", "30"])
    assert res.exit_code == 2 and "a map needs encounters among 3 agents or more" in res.output
    res = runner.invoke(app, small_room + ["--agents", "5", "--duration", "30"])
    assert res.exit_code == 0 and "outside the benchmark's range" in res.output
    assert model.density_range[0] <= 5 / 20000 <= model.density_range[1]
    res = runner.invoke(app, small_room + ["--duration", "80", "--target", "0.05"])
    assert res.exit_code == 0 and "needed: 3 agents" in res.output and model.agents_for(20000, 80, 0.05) < 3


@pytest.mark.parametrize("key, value", [("duration_range", [60]), ("density_range", [2e-3, 5e-4]),
                                        ("agents_range", [0, 400]), ("duration_range", [30, float("inf")])])
def test_a_plan_model_with_bad_ranges_is_refused(tmp_path, key, value):
    obj = PlanModel(-3.0, 1.2, 1.8, (5e-4, 2e-3), (30, 60), 100, "test", -0.6, (0.25,) * 4, (200, 400)).to_json()
    obj[key] = value
    with pytest.raises(InputError, match="must be \\[low, high\\]") as caught:
        PlanModel.from_json(obj, source="m.json")
    assert (caught.value.file, caught.value.column) == ("m.json", key)
