"""One-dimensional minimisation (lut_baker.numerics.optimise)."""

import math

import pytest

from lut_baker.numerics.optimise import golden_minimum


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
    x, _ = golden_minimum(math.exp, -1.0, 3.0, tol=1e-6)
    assert x == pytest.approx(-1.0, abs=1e-5)
