"""Planning model: recovery of a known logistic law, inverse answers, the CLI."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from swarmtopo.cli import app
from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.plan import PlanModel, fit_plan, load_plan

runner = CliRunner()


def synthetic_records(n, rng, c=(-2.0, 1.5, 2.0)):
    """Maps drawn from P(right) = sigmoid(c0 + c1 ln(N/A) + c2 ln T) with A around 1 m^2."""
    records = []
    for _ in range(n):
        area = rng.uniform(0.5e6, 1.5e6)
        agents = rng.integers(100, 500)
        duration = rng.uniform(20, 80)
        z = c[0] + c[1] * np.log(agents / area * 1e4) + c[2] * np.log(duration / 30)
        records.append({"area": area, "agents": int(agents), "duration": duration,
                        "right": bool(rng.random() < 1 / (1 + np.exp(-z)))})
    return records


def test_fit_recovers_the_law_it_was_drawn_from():
    rng = np.random.default_rng(1)
    model = fit_plan(synthetic_records(4000, rng), source="test")
    # slope standard errors at n = 4000 are about 0.1; 0.3 is three of them
    assert model.density_coef == pytest.approx(1.5, abs=0.3)
    assert model.duration_coef == pytest.approx(2.0, abs=0.3)
    p = model.accuracy(1e6, 300, 40)
    truth = 1 / (1 + np.exp(-(-2.0 + 1.5 * np.log(300 / 1e6 * 1e4) + 2.0 * np.log(40 / 30))))
    assert p == pytest.approx(truth, abs=0.04)


def test_inverse_answers_invert_the_forward_one():
    model = PlanModel(-3.0, 1.2, 1.8, (1e-4, 1e-3), (30, 60), 100, "test")
    n = model.agents_for(250_000, 40, 0.9)
    assert model.accuracy(250_000, n, 40) == pytest.approx(0.9)
    t = model.duration_for(250_000, 300, 0.95)
    assert model.accuracy(250_000, 300, t) == pytest.approx(0.95)
    flat = PlanModel(0.0, 0.0, -1.0, (1e-4, 1e-3), (30, 60), 100, "test")
    assert flat.agents_for(1, 1, 0.9) == np.inf and flat.duration_for(1, 1, 0.9) == np.inf


def test_bad_plan_inputs():
    model = PlanModel(-3.0, 1.2, 1.8, (1e-4, 1e-3), (30, 60), 100, "test")
    with pytest.raises(InputError, match="target"):
        model.agents_for(1e5, 30, 1.0)
    with pytest.raises(InputError, match="area"):
        model.accuracy(-1, 200, 30)
    with pytest.raises(SwarmtopoError, match="both right and wrong"):
        fit_plan([{"area": 1.0, "agents": 1, "duration": 1.0, "right": True}] * 3, source="x")


def test_plan_cli_forward_and_inverse(tmp_path):
    path = tmp_path / "plan.json"
    model = PlanModel(-3.0, 1.2, 1.8, (5e-4, 2e-3), (30, 60), 100, "test")
    path.write_text(json.dumps(model.to_json()))
    res = runner.invoke(app, ["plan", "--area", "250000", "--agents", "200", "--duration", "30", "--model", str(path)])
    assert res.exit_code == 0, res.output
    assert f"{100 * model.accuracy(250000, 200, 30):.0f}%" in res.output
    res = runner.invoke(app, ["plan", "--area", "250000", "--duration", "30", "--target", "0.95", "--model", str(path)])
    assert res.exit_code == 0 and f"needed: {int(np.ceil(model.agents_for(250000, 30, 0.95)))} agents" in res.output
    res = runner.invoke(app, ["plan", "--area", "250000", "--agents", "200", "--model", str(path)])
    assert res.exit_code != 0 and "two of --agents, --duration and --target" in res.output


def test_shipped_plan_was_fitted_on_the_full_benchmark():
    from swarmtopo.experiments.accuracy import BUDGETS, CELLS, REPORTING_PER_CELL, SCALE_RANGE
    model = load_plan()
    assert model.maps == len(CELLS) * REPORTING_PER_CELL
    # its ranges are the suite's: 200-400 agents in (500 s)^2 rooms of scale 0.75-1.25
    lo = min(n for n, _ in BUDGETS) / (2 * (500 * SCALE_RANGE[1]) ** 2)  # two rooms share their swarm
    hi = max(n for n, _ in BUDGETS) / (500 * SCALE_RANGE[0]) ** 2
    assert lo * 0.99 <= model.density_range[0] and model.density_range[1] <= hi * 1.01
    assert model.duration_range == (min(t for _, t in BUDGETS), max(t for _, t in BUDGETS))
