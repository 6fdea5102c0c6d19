"""Cycles closure replicas (lut_baker.closures.cycles), checked against independent quadratures
and closed forms."""

import dataclasses

import numpy as np
import pytest

from lut_baker.closures import cycles as cc
from lut_baker.numerics.geometry import direction


# ---------------------------------------------------------------------------------------------
# Replicas
# ---------------------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("distribution", cc.GLOSSY_DISTRIBUTIONS)
@pytest.mark.parametrize("roughness", [0.3, 0.6, 0.95])
def test_lobe_albedo_matches_brute_quadrature(distribution, roughness):
    mu = np.array([1.0, 0.7, 0.3, 0.1])
    fast = cc.microfacet_albedo(mu, roughness, distribution=distribution)
    brute = cc.directional_albedo(
        lambda w, v: cc.microfacet_reflection(w, v, roughness, distribution=distribution), mu,
        lobe_width_deg=5.0, level=1)
    np.testing.assert_allclose(fast, brute, rtol=5e-3, atol=2e-3)
    assert np.all(fast <= 1.0 + 1e-9)


def test_albedo_nodes_are_shared_and_left_alone(monkeypatch):
    """The albedo's quadrature nodes are made once per resolution and read-only, so every
    call, chunk and roughness reads the same nodes: a view's albedo is the same to the last bit
    alone, among others, in chunks of any size, and before and after other roughnesses
    (numpy's reductions over a view's own nodes: the same operations)."""
    first = cc._albedo_nodes(48, 32)
    assert first is cc._albedo_nodes(48, 32)
    assert not any(array.flags.writeable for array in first[1:])
    mu = np.linspace(0.05, 1.0, 20)
    alone = np.array([cc.microfacet_albedo(m, 0.3) for m in mu])
    together = cc.microfacet_albedo(mu, 0.3)
    cc.microfacet_albedo(mu, 0.7, lambda c: cc.dielectric_fresnel(c, 1.4))
    monkeypatch.setattr(cc, "ALBEDO_CHUNK", 3 * 48 * 32)
    np.testing.assert_array_equal(cc.microfacet_albedo(mu, 0.3), together)
    np.testing.assert_array_equal(alone, together)


def test_ggx_distribution_is_normalised():
    # Int D(h) cos(theta_h) dw_h = 1 for any alpha.
    theta = np.linspace(0.0, np.pi / 2, 200001)
    for alpha in (0.05, 0.3, 1.0):
        integrand = cc.ggx_distribution(np.cos(theta), alpha) * np.cos(theta) * np.sin(theta)
        assert np.trapz(integrand, theta) * 2 * np.pi == pytest.approx(1.0, rel=1e-3)


def test_schlick_ior_fresnel_is_the_real_curve_at_its_own_f0():
    c = np.linspace(0.0, 1.0, 11)
    eta = 1.45
    np.testing.assert_allclose(cc.schlick_ior_fresnel(c, eta, cc.f0_from_ior(eta)),
                               cc.dielectric_fresnel(c, eta), atol=1e-12)
    assert float(cc.dielectric_fresnel(1.0, 1.5)) == pytest.approx(0.04)


def test_principled_without_coat_and_specular_is_lambert():
    inputs = cc.PrincipledInputs(base_color=(0.2, 0.5, 0.8), specular_ior_level=0.0)
    wi = direction(np.radians([10.0, 40.0]), 1.0)
    wo = direction(np.radians([60.0, 5.0]), 0.0)
    np.testing.assert_allclose(cc.principled_reflection(wi, wo, inputs),
                               np.broadcast_to(np.array([0.2, 0.5, 0.8]) / np.pi, (2, 3)),
                               rtol=1e-12)


def test_coat_attenuates_the_base_by_its_albedo():
    wi = direction(np.radians(30.0), 2.0)
    wo = direction(np.radians(50.0), 0.0)
    plain = cc.PrincipledInputs(base_color=(0.5, 0.5, 0.5), specular_ior_level=0.0)
    coated = dataclasses.replace(plain, coat_weight=1.0, coat_roughness=0.5, coat_ior=1.8)
    coat_only = cc.microfacet_reflection(wi, wo, 0.5, lambda c: cc.dielectric_fresnel(c, 1.8))
    scale, e_coat = cc.coat_view_terms(np.cos(np.radians(50.0)), 0.5, 1.8)
    expected = scale * coat_only + (1.0 - e_coat) * 0.5 / np.pi
    np.testing.assert_allclose(cc.principled_reflection(wi, wo, coated), [expected] * 3,
                               rtol=2e-3)
    assert 0.0 < e_coat < cc.layering_albedo(np.cos(np.radians(50.0)), 0.5, 1.8) < 1.0
    assert 1.0 < scale < 1.1


@pytest.mark.parametrize("roughness", [0.2, 0.5, 0.9])
def test_coat_energy_compensation(roughness):
    """Cycles' multiple-scattering compensation: with a white Fresnel (F_ss = 1) the lobe's
    albedo becomes exactly 1 (the white furnace), the darkening 1; with a dielectric one the
    lobe gains less than the missing energy and the darkening is below 1; a smooth lobe
    (nothing missing) keeps its value."""
    mu = np.array([1.0, 0.6, 0.2])
    e = cc.microfacet_albedo(mu, roughness)
    scale, darkening = cc.ggx_energy_compensation(mu, roughness, 1.0)
    np.testing.assert_allclose(e * scale, 1.0, rtol=1e-9)
    np.testing.assert_allclose(darkening, 1.0, rtol=1e-9)
    fss = float(cc.dielectric_fss(1.5))
    assert fss == pytest.approx(0.0918, rel=0.03)  # 2 Int F mu dmu = 0.0918 at eta 1.5 (a fit)
    scale, darkening = cc.ggx_energy_compensation(mu, roughness, fss)
    assert np.all((scale > 1.0) & (scale < 1.0 / e)) and np.all(darkening < 1.0)
    smooth, _ = cc.ggx_energy_compensation(mu[:2], 0.05, fss)
    np.testing.assert_allclose(smooth, 1.0, atol=1e-3)


def _radial_integral(profile, r):
    return float(np.trapz(2 * np.pi * r * profile, r))


@pytest.mark.parametrize("method", cc.SUBSURFACE_METHODS)
def test_subsurface_profiles_have_unit_area(method):
    r = np.geomspace(1e-7, 400.0, 400000)
    value = cc.subsurface_profile(r, 5.0, 0.7, method)
    assert _radial_integral(value, r) == pytest.approx(1.0, rel=2e-3)


def test_burley_length_is_radius_over_four_pi():
    # Cycles: d = radius / (4 pi), cut at T = 16 d and renormalised.  The mean distance is
    # [d^2 g(T/d) + 9 d^2 g(T/3d)] / (4 d cdf), with Int_0^T r exp(-r/a) dr = a^2 g(T/a) and
    # g(x) = 1 - exp(-x) (1 + x).
    d = 8.0 / (4 * np.pi)

    def g(x):
        return 1 - np.exp(-x) * (1 + x)

    cdf = 1 - 0.25 * np.exp(-16) - 0.75 * np.exp(-16 / 3)
    expected = (d * d * g(16) + 9 * d * d * g(16 / 3)) / (4 * d * cdf)
    r = np.geomspace(1e-7, 400.0, 400000)
    mean = np.trapz(2 * np.pi * r * r * cc.burley_profile(r, 8.0), r)
    assert mean == pytest.approx(expected, rel=1e-3)


@pytest.mark.parametrize("method", cc.SUBSURFACE_METHODS)
def test_subsurface_radius_scales_the_profile(method):
    # P(r; k radius) = P(r / k; radius) / k^2 at a fixed colour: Subsurface Scale is a length.
    r = np.linspace(0.1, 10.0, 41)
    k = 2.5
    scaled = cc.subsurface_profile(r, 2.0 * k, 0.6, method)
    base = cc.subsurface_profile(r / k, 2.0, 0.6, method)
    np.testing.assert_allclose(scaled, base / k**2, rtol=1e-9)


def test_random_walk_scale_interpolates_the_measurements():
    table = dict(cc.RANDOM_WALK_BURLEY_SCALE["RANDOM_WALK"])
    assert cc.random_walk_scale(0.5, "RANDOM_WALK") == pytest.approx(table[0.5])
    assert cc.random_walk_scale(0.65, "RANDOM_WALK") == pytest.approx(
        0.5 * (table[0.5] + table[0.8]))
    assert cc.random_walk_scale(0.0, "RANDOM_WALK") == pytest.approx(table[0.2])  # held
    with pytest.raises(ValueError, match="method"):
        cc.random_walk_scale(0.5, "BURLEY")
