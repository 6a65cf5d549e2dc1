"""benchmarks/cycle_agreement.py: circular coordinates and their agreement (the lever's parts)."""

import importlib.util
from pathlib import Path

import numpy as np
from ripser import ripser

_spec = importlib.util.spec_from_file_location("cycle_agreement",
                                               Path(__file__).parent.parent / "benchmarks" / "cycle_agreement.py")
cycle_agreement = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cycle_agreement)


def circle(n=120, noise=0.03, seed=0):
    rng = np.random.default_rng(seed)
    angle = np.sort(rng.uniform(0, 2 * np.pi, n))
    points = np.c_[np.cos(angle), np.sin(angle)] + noise * rng.normal(size=(n, 2))
    return angle, np.sqrt(((points[:, None] - points[None]) ** 2).sum(-1))


def test_circular_coordinates_wind_once_round_a_circle_with_its_angle():
    angle, distances = circle()
    out = ripser(distances, distance_matrix=True, maxdim=1, do_cocycles=True, coeff=cycle_agreement.PRIME)
    longest = int(np.argmax(out["dgms"][1][:, 1] - out["dgms"][1][:, 0]))
    theta = cycle_agreement.circular_coordinates(distances, out["dgms"][1][longest], out["cocycles"][1][longest])
    steps = (np.diff(np.r_[theta, theta[0]]) + 0.5) % 1 - 0.5  # in angle order, round the circle
    assert round(abs(steps.sum())) == 1 and np.abs(steps).max() < 0.1
    z, truth = np.exp(2j * np.pi * theta), np.exp(1j * angle)
    assert max(abs(np.mean(z * truth.conj())), abs(np.mean(z * truth))) > 0.9  # harmonic, not uniform in angle


def test_agreement_is_free_of_rotation_and_reflection_and_low_for_unrelated_fields():
    rng = np.random.default_rng(1)
    events = np.arange(200)
    theta = np.tile(rng.uniform(0, 1, 200), (cycle_agreement.M, 1))
    turned = np.mod(-theta + 0.3, 1.0)  # the same loop, reflected and rotated
    unrelated = rng.uniform(0, 1, theta.shape)
    same = cycle_agreement.pair_agreement((events, theta), (events, turned))
    other = cycle_agreement.pair_agreement((events, theta), (events, unrelated))
    np.testing.assert_allclose(np.diag(same["centred"]), 1.0)
    assert other["centred"].max() < 0.35
    # a nearly constant field passes the raw measure, not the centred one
    flat = np.full(theta.shape, 0.5) + 0.01 * rng.normal(size=theta.shape)
    flat_too = np.full(theta.shape, 0.2) + 0.01 * rng.normal(size=theta.shape)
    both = cycle_agreement.pair_agreement((events, flat), (events, flat_too))
    assert both["raw"].min() > 0.99 and both["centred"].max() < 0.35
    # fewer than 10 shared events: no agreement
    assert not cycle_agreement.pair_agreement((events[:5], theta[:, :5]), (events[:5], theta[:, :5]))["centred"].any()
