"""lut_baker.numerics.quadrature: the Gauss-Legendre, hemisphere, trapezoid and azimuth rules
and the order-0 Fourier integral."""

import numpy as np
import pytest

from lut_baker.numerics import quadrature


@pytest.mark.parametrize("panels", [1, 3, 7])
def test_gauss_legendre_integrates_polynomials_exactly(panels):
    nodes, weights = quadrature.gauss_legendre(5, -1.0, 2.0, panels)
    assert nodes.size == weights.size == 5 * panels
    assert np.all(np.diff(nodes) > 0) and np.all((nodes > -1.0) & (nodes < 2.0))
    exact = (2.0**10 - 1.0) / 10.0  # Int_{-1}^{2} x^9 dx
    assert np.sum(weights * nodes**9) == pytest.approx(exact, rel=1e-13)
    with pytest.raises(ValueError):
        nodes[0] = 0.0  # cached: every caller shares the arrays


def test_gauss_legendre_shares_numpys_rule_per_point_count():
    """The rule on [-1, 1] is computed once per point count (numpy's ``leggauss``) and every
    interval and panel count maps it; another count gets its own."""
    quadrature.gauss_legendre.cache_clear()
    quadrature._legendre_rule.cache_clear()
    x, w = np.polynomial.legendre.leggauss(7)
    nodes, weights = quadrature.gauss_legendre(7, 0.0, 2.0)
    np.testing.assert_allclose(nodes, x + 1.0, rtol=0.0, atol=1e-15)
    np.testing.assert_allclose(weights, w, rtol=1e-15)
    quadrature.gauss_legendre(7, -3.0, 5.0, 4)
    assert quadrature._legendre_rule.cache_info().misses == 1  # one rule for both intervals
    assert quadrature._legendre_rule.cache_info().hits == 1
    other, _ = quadrature.gauss_legendre(9, 0.0, 2.0)
    assert other.size == 9 and quadrature._legendre_rule.cache_info().misses == 2
    rule, _ = quadrature._legendre_rule(7)
    with pytest.raises(ValueError):
        rule[0] = 0.0  # shared: read-only


def test_stored_legendre_rules_are_numpys():
    """The rules read from the file (every stored count) are numpy's ``leggauss`` (within
    what moves between machines), and a count not stored is computed."""
    stored = quadrature._stored_legendre_rules()
    assert sorted(stored) == sorted(quadrature.STORED_LEGENDRE_POINTS)
    quadrature._legendre_rule.cache_clear()
    for count in (*quadrature.STORED_LEGENDRE_POINTS, 7):
        x, w = np.polynomial.legendre.leggauss(count)
        nodes, weights = quadrature._legendre_rule(count)
        assert (nodes is stored[count][0]) if count in stored else nodes.size == 7
        np.testing.assert_allclose(nodes, x, rtol=0.0, atol=4e-16)
        np.testing.assert_allclose(weights, w, rtol=1e-14)
        assert np.sum(weights * nodes**2) == pytest.approx(2.0 / 3.0, rel=1e-14)


def test_hemisphere_rules_integrate_the_projected_solid_angle():
    """``Int cos(theta) dw = pi`` over the hemisphere, by both grids."""
    for grid in (quadrature.hemisphere_panels(3, 10, 33), quadrature.hemisphere_grid(20.0)):
        assert np.sum(grid.weight) * grid.n_phi * grid.phi_weight == pytest.approx(np.pi,
                                                                                rel=1e-12)
        assert grid.phi.size == grid.n_phi and grid.phi[1] == pytest.approx(grid.phi_weight)
    with pytest.raises(ValueError):
        quadrature.hemisphere_panels(2, 6, 16)  # even azimuth count


def test_trapezoid_rules():
    x = np.array([0.0, 0.5, 2.0, 3.0])
    w = quadrature.trapezoid_weights(x)
    np.testing.assert_allclose(w, [0.25, 1.0, 1.25, 0.5])
    y = np.stack([2.0 * x + 1.0, x], axis=-1)  # linear: the rule is exact
    running = quadrature.cumulative_trapezoid(y, x)
    np.testing.assert_allclose(running[:, 0], x[1:] ** 2 + x[1:])
    np.testing.assert_allclose(running[-1], w @ y)


def test_azimuth_rules():
    cos_phi, weight = quadrature.mirror_weighted_azimuths(16, 3)
    assert np.sum(weight) == pytest.approx(2.0 * np.pi)
    assert np.sum(weight * cos_phi**2) == pytest.approx(np.pi)
    nodes = quadrature.midpoint_nodes(4, 0.0, np.pi)
    np.testing.assert_allclose(nodes, np.pi * np.array([1, 3, 5, 7]) / 8)


def test_order0_integral_of_a_constant_kernel():
    grid = quadrature.hemisphere_panels(2, 6, 17)
    kernel = np.full((1, grid.theta.size, 1), 1.0 / np.pi)  # a Lambertian BRDF's K_0
    assert quadrature.order0_integral(kernel, grid)[0, 0] == pytest.approx(1.0, rel=1e-12)


def test_mirror_quadrature_builds_the_other_direction_on_demand():
    """``other`` (built when asked) is the unit mirror of the fixed direction through the
    half vector: its z-component is ``cos_other``, ``e.h = d.h = cos_dh`` and ``n.h``
    of ``normalize(d + e)`` is ``cos_h``."""
    quad = quadrature.mirror_quadrature(np.radians([0.0, 30.0, 75.0, 89.0]), 12.0)
    e = quad.other
    assert e.shape == quad.weight.shape + (3,)
    np.testing.assert_array_equal(e[..., 2], quad.cos_other)
    live = quad.weight > 0.0  # panels beyond the horizon have no length
    np.testing.assert_allclose(np.linalg.norm(e, axis=-1)[live], 1.0, atol=1e-12)
    d = np.broadcast_to(quad.fixed[:, None, None, :], e.shape)
    h = d + e
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    np.testing.assert_allclose(h[..., 2][live], quad.cos_h[live], atol=1e-12)
    np.testing.assert_allclose(np.sum(e * h, axis=-1)[live], quad.cos_dh[live], atol=1e-12)
    assert quad.other is e  # built once


def test_mirror_quadrature_arrays_are_separate():
    """Built in place, the node arrays still share no memory: a caller may change one."""
    quad = quadrature.mirror_quadrature(np.radians([10.0, 60.0, 85.0]), 8.0)
    arrays = [quad.weight, quad.cos_h, quad.cos_dh, quad.cos_other, quad.sin_h]
    for i, first in enumerate(arrays):
        assert first.shape == quad.weight.shape
        assert not any(np.shares_memory(first, second) for second in arrays[i + 1:])
    lambert = np.sum(quad.weight * quad.cos_other, axis=(1, 2)) / np.pi
    np.testing.assert_allclose(lambert, 1.0, atol=1e-7)
