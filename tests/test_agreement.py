"""Cross-window cycle agreement: circular coordinates wind once round a circle, agreement
is free of rotation and reflection, overlaps and ranks by hand, and in the pipeline."""

import numpy as np
import pytest

from swarmtopo.readers import agreement
from swarmtopo.readers.agreement import BARS, PRIME, circular_coordinates, overlapping, pair_agreement, rank_agreement
from swarmtopo.errors import InputError
from swarmtopo.topology.persistence import rips_persistence


def circle(n=120, noise=0.03, seed=0):
    rng = np.random.default_rng(seed)
    angle = np.sort(rng.uniform(0, 2 * np.pi, n))
    points = np.c_[np.cos(angle), np.sin(angle)] + noise * rng.normal(size=(n, 2))
    return angle, np.sqrt(((points[:, None] - points[None]) ** 2).sum(-1))


def test_circular_coordinates_wind_once_round_a_circle_with_its_angle():
    angle, distances = circle()
    result = rips_persistence(distances, maxdim=1, cocycles=True, coefficients=PRIME)
    bars = result.diagram[1]
    longest = int(np.argmax(bars[:, 1] - bars[:, 0]))
    theta = circular_coordinates(distances, bars[longest], result.cocycles[1][longest])
    steps = (np.diff(np.r_[theta, theta[0]]) + 0.5) % 1 - 0.5  # in angle order, round the circle
    assert round(abs(steps.sum())) == 1 and np.abs(steps).max() < 0.1
    z, truth = np.exp(2j * np.pi * theta), np.exp(1j * angle)
    assert max(abs(np.mean(z * truth.conj())), abs(np.mean(z * truth))) > 0.9  # harmonic, not uniform in angle


def test_a_cocycle_from_the_run_stopped_at_the_bars_death_gives_the_same_coordinates():
    _, distances = circle(seed=1)
    full = rips_persistence(distances, maxdim=1, cocycles=True, coefficients=PRIME)
    i = int(np.argmax(full.diagram[1][:, 1] - full.diagram[1][:, 0]))
    stopped = rips_persistence(distances, maxdim=1, cocycles=True, coefficients=PRIME,
                               threshold=float(full.diagram[1][i, 1]))
    j = int(np.argmax(np.where(np.isfinite(stopped.diagram[1][:, 1]),
                               stopped.diagram[1][:, 1] - stopped.diagram[1][:, 0], -1)))
    np.testing.assert_array_equal(stopped.diagram[1][j], full.diagram[1][i])
    a = circular_coordinates(distances, full.diagram[1][i], full.cocycles[1][i])
    b = circular_coordinates(distances, stopped.diagram[1][j], stopped.cocycles[1][j])
    events = np.arange(len(a))
    assert pair_agreement((events, np.tile(a, (BARS, 1))), (events, np.tile(b, (BARS, 1))))[0, 0] > 0.999


def test_agreement_is_free_of_rotation_and_reflection_and_low_for_unrelated_or_flat_fields():
    rng = np.random.default_rng(1)
    events = np.arange(200)
    theta = np.tile(rng.uniform(0, 1, 200), (BARS, 1))
    turned = np.mod(-theta + 0.3, 1.0)  # the same loop, reflected and rotated
    np.testing.assert_allclose(np.diag(pair_agreement((events, theta), (events, turned))), 1.0)
    assert pair_agreement((events, theta), (events, rng.uniform(0, 1, theta.shape))).max() < 0.35
    # two nearly constant fields: centred, they do not agree (uncentred, they would, at 1)
    flat, flat_too = (np.full(theta.shape, c) + 0.01 * rng.normal(size=theta.shape) for c in (0.5, 0.2))
    assert pair_agreement((events, flat), (events, flat_too)).max() < 0.35
    # compared only on shared events, in any order of the windows' events
    shuffled = rng.permutation(200)[:150]
    order = np.argsort(shuffled)
    assert pair_agreement((events, theta), (shuffled[order], turned[:, shuffled[order]]))[2, 2] == pytest.approx(1.0)
    # fewer than MIN_SHARED shared events: no agreement at all
    assert not pair_agreement((events[:5], theta[:, :5]), (events[:5], theta[:, :5])).any()


def test_overlaps_by_hand():
    spans = [(0.0, 10.0), (5.0, 15.0), (9.0, 19.0), (30.0, 40.0), (0.0, 3.0)]
    # 0 and 1 share 5 s of 10 (>= 40 %); 0 and 2 share 1 s; 4 lies inside 0 (3 s of the shorter 3)
    assert overlapping(spans, 0) == [1, 4]
    assert overlapping(spans, 1) == [0, 2]
    assert overlapping(spans, 3) == []


def test_rank_agreement_by_hand():
    rng = np.random.default_rng(2)
    events = np.arange(100)
    loop = rng.uniform(0, 1, 100)
    # window 0: rank 1 is the loop, rank 2 noise; window 1: the loop at rank 2, rank 1 other noise;
    # window 2 overlaps nothing (its coordinates are never read)
    w0 = np.vstack([loop, rng.uniform(0, 1, (BARS - 1, 100))])
    w1 = np.vstack([rng.uniform(0, 1, 100), np.mod(loop + 0.5, 1), rng.uniform(0, 1, (BARS - 2, 100))])
    a = rank_agreement([(events, w0), (events, w1), None], [(0, 10), (5, 15), (50, 60)])
    # the loop finds its match at any rank of the other window: both windows' loops score 1
    expected_1 = (1.0 + pair_agreement((events, w1), (events, w0))[0].max()) / 2
    expected_2 = (pair_agreement((events, w0), (events, w1))[1].max() + 1.0) / 2
    assert a[0] == pytest.approx(expected_1) and a[1] == pytest.approx(expected_2)
    assert a[0] < 1 and a[1] < 1 and max(a[0], a[1]) > 0.6
    # a window with fewer bars scores 0 at the ranks it lacks
    short = w0.copy()
    short[3:] = np.nan
    assert rank_agreement([(events, short), (events, w1)], [(0, 10), (5, 15)])[3] == pytest.approx(
        pair_agreement((events, w1), (events, short))[3].max() / 2)
    assert np.isnan(rank_agreement([None, None], [(0, 1), (5, 6)])).all()


def test_a_window_without_h1_bars_has_no_coordinates():
    from swarmtopo.topology.persistence import Diagram

    class Graph:  # the one attribute of an EncounterGraph read when there is no bar
        event_index = np.arange(4)

    empty = Diagram(pairs=(np.array([[0.0, np.inf]]), np.empty((0, 2))), backend="test")
    events, theta = agreement.window_coordinates(np.zeros((1, 1)), empty, np.array([0]), Graph())
    assert len(events) == 0 and theta.shape == (BARS, 0)


def test_persistence_coefficients_must_be_a_prime():
    _, distances = circle(n=20)
    for bad in (1, 4, 2.0, True):
        with pytest.raises(InputError, match="prime"):
            rips_persistence(distances, coefficients=bad)
    # on a circle, Z/2 and Z/47 give the same bars, from every backend that takes a field
    for backend in ("gudhi", "ripser"):
        np.testing.assert_allclose(rips_persistence(distances, backend=backend, coefficients=47).diagram[1],
                                   rips_persistence(distances, backend=backend).diagram[1])
