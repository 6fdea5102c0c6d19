"""One-dimensional minimisation (lut_baker.numerics.optimise)."""

import math

import numpy as np
import pytest

from lut_baker.numerics.optimise import REFINE_PRECISION, golden_minimum, stencil_minimum


def _skewed(centre, wobble=0.0):
    """A valley at ``centre`` that is not a parabola (so a parabola's vertex is not exact),
    plus ``wobble`` times a smooth ripple (a perturbation of the data)."""
    return lambda t: (t - centre) ** 2 * (1.0 + 0.3 * (t - centre)) + 0.1 + wobble * np.sin(
        37.0 * t)


@pytest.mark.parametrize("centre", [0.137, 2.5, 9.9])
def test_finds_the_minimum_of_a_parabola_within_the_tolerance(centre):
    x, value = golden_minimum(lambda t: (t - centre) ** 2 + 1.0, 0.0, 10.0, tol=1e-6)
    assert x == pytest.approx(centre, abs=1e-5)
    assert value == pytest.approx(1.0, abs=1e-9)


def test_the_coarse_pass_finds_the_lower_of_two_valleys():
    """Two minima: golden-section search alone can settle in the wrong one; the coarse samples
    bracket the lower."""
    def two_valleys(t):
        return min((t - 2.0) ** 2 + 0.5, (t - 8.0) ** 2)

    x, value = golden_minimum(two_valleys, 0.0, 10.0, tol=1e-6)
    assert x == pytest.approx(8.0, abs=1e-5) and value == pytest.approx(0.0, abs=1e-9)


def test_a_minimum_at_the_end_of_the_interval():
    x, value = golden_minimum(math.exp, -1.0, 3.0, tol=1e-6)
    assert x == -1.0 and value == math.exp(-1.0)
    x, _ = golden_minimum(lambda t: -t, -1.0, 3.0, tol=1e-3)
    assert x == pytest.approx(3.0, abs=1e-2)  # no curvature: the search's own point


def test_the_minimiser_follows_the_minimum_continuously():
    """As the valley moves by 1e-5 steps, the minimiser moves by the same steps.  A search
    that returns one of the points it compared stays put and then jumps by its bracket (up to
    1e-3 here) when a comparison flips."""
    centres = 0.5 + 1e-5 * np.arange(200)
    xs = np.array([golden_minimum(_skewed(c), 0.2, 1.0, tol=2e-3, coarse=7)[0]
                   for c in centres])
    np.testing.assert_allclose(np.diff(xs), 1e-5, rtol=1e-3)
    np.testing.assert_allclose(xs, centres, atol=2e-6)  # the stencil's bias, h^2 f'''/f''


def test_a_near_tie_between_two_coarse_samples_does_not_move_the_result():
    """The valley midway between two coarse samples: a 1e-9 ripple decides which of them the
    coarse pass takes, and the bracket differs; the result moves only as the valley does
    (the ripple's slope 4e-8 over the curvature 2: 2e-8), not by a bracket (~1e-3)."""
    low, high, coarse = 0.2, 1.0, 7
    samples = np.linspace(low, high, coarse)
    centre = 0.5 * (samples[3] + samples[4])
    chosen, results = set(), []
    for wobble in (-1e-9, 1e-9):
        def f(t, wobble=wobble):  # even about the centre: the two samples tie but for wobble
            return (t - centre) ** 2 + 3.0 * (t - centre) ** 4 + 0.1 + wobble * np.sin(37.0 * t)

        chosen.add(int(np.argmin([f(x) for x in samples])))
        results.append(golden_minimum(f, low, high, tol=2e-3, coarse=coarse)[0])
    assert chosen == {3, 4}  # the perturbation flipped the coarse choice
    assert max(abs(x - centre) for x in results) < 3e-8


@pytest.mark.parametrize("start", [0.42, 0.47, 0.5, 0.53, 0.6])
def test_the_refinement_ends_where_it_would_from_any_start(start):
    """:func:`stencil_minimum` has one fixed point: from starts across the valley it ends
    within ~1e-12 of the interval of the same point, where ``f(x - h) = f(x + h)``."""
    f, h = _skewed(0.5), 1.6e-3
    x, value = stencil_minimum(f, start, 0.2, 1.0, h)
    reference, _ = stencil_minimum(f, 0.5, 0.2, 1.0, h)
    assert abs(x - reference) < 1e-12
    assert abs(f(x - h) - f(x + h)) < 1e-12 and value == pytest.approx(f(x), abs=1e-12)


def test_the_refinement_is_continuous_where_its_stencil_meets_the_end():
    """A valley moving through the end's zone (within one step of the end, where the stencil
    is held inside the interval): the result moves with it, and clips to the end."""
    h = 0.01
    centres = np.linspace(-0.01, 0.03, 401)
    xs = np.array([stencil_minimum(_skewed(c), 0.1, 0.0, 1.0, h)[0] for c in centres])
    assert xs[0] == 0.0 and np.all(np.diff(xs) >= 0.0)
    assert np.max(np.diff(xs)) < 2.0 * (centres[1] - centres[0])
    np.testing.assert_allclose(xs[centres > 0.002], centres[centres > 0.002], atol=2e-5)


def test_the_refinement_stops_where_there_is_no_valley():
    assert stencil_minimum(lambda t: -((t - 0.5) ** 2), 0.5, 0.0, 1.0, 0.01) is None
    with pytest.raises(ValueError):
        stencil_minimum(math.exp, 0.5, 0.0, 1.0, 0.6)
    assert REFINE_PRECISION < 1e-5
