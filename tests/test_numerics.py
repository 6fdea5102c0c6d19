"""lut_baker.numerics: the quadrature rules, the geometry of directions and of the reference
sphere, and the LRU cache."""

import numpy as np
import pytest

from lut_baker.numerics import geometry, quadrature
from lut_baker.numerics.cache import LRUCache


@pytest.mark.parametrize("panels", [1, 3, 7])
def test_gauss_legendre_integrates_polynomials_exactly(panels):
    nodes, weights = quadrature.gauss_legendre(5, -1.0, 2.0, panels)
    assert nodes.size == weights.size == 5 * panels
    assert np.all(np.diff(nodes) > 0) and np.all((nodes > -1.0) & (nodes < 2.0))
    exact = (2.0**10 - 1.0) / 10.0  # Int_{-1}^{2} x^9 dx
    assert np.sum(weights * nodes**9) == pytest.approx(exact, rel=1e-13)
    with pytest.raises(ValueError):
        nodes[0] = 0.0  # cached: every caller shares the arrays


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


def test_directions_and_angles():
    wi = geometry.direction(np.radians(30.0), np.radians(200.0))
    wo = geometry.direction(np.radians(60.0), np.radians(20.0))
    assert geometry.polar_angle_deg(wi) == pytest.approx(30.0)
    assert geometry.folded_azimuth_deg(wi, wo) == pytest.approx(180.0)
    h = geometry.half_vector(wi, wo)
    assert np.linalg.norm(h) == pytest.approx(1.0)
    assert np.dot(h, wi) == pytest.approx(np.dot(h, wo))


def test_sphere_framing():
    """The reference sphere's lit pixels: local directions at the pixel normals, the view along
    each normal's polar angle, the light's cosine the normal's dot the light."""
    lit, wi, wo = geometry.sphere_directions(16, 45.0)
    normals, mask = geometry.sphere_normals(16)
    assert lit.shape == mask.shape == (16, 16) and np.all(mask[lit])
    assert wi.shape == wo.shape == (int(lit.sum()), 3)
    np.testing.assert_allclose(wo[:, 2], normals[lit][:, 2], rtol=1e-12)
    np.testing.assert_allclose(wi[:, 2], normals[lit] @ geometry.light_direction(45.0),
                               rtol=1e-12)
    assert np.all(wi[:, 2] > 0.0) and np.all(wo[:, 2] > 0.0)


def test_lru_cache_drops_the_least_recently_used():
    cache = LRUCache(2)
    cache.put("a", 1)
    cache.put("b", 2)
    assert cache.get("a") == 1  # "b" is now the least recently used
    cache.put("c", 3)
    assert "b" not in cache and len(cache) == 2
    calls = []
    assert cache.get_or_compute("d", lambda: calls.append(1) or 4) == 4
    assert cache.get_or_compute("d", lambda: calls.append(1) or 5) == 4 and calls == [1]
    assert cache.get("zzz", "none") == "none"
    cache.clear()
    assert len(cache) == 0
    unbounded = LRUCache(None)
    for i in range(100):
        unbounded.put(i, i)
    assert len(unbounded) == 100
    with pytest.raises(ValueError):
        LRUCache(0)
