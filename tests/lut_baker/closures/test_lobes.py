"""The lobe fits (lut_baker.closures.lobes), by round trips: tables synthesised from a known
closure must give that closure's parameters back."""


import numpy as np
import pytest

from lut_baker.closures import cycles as cc
from lut_baker.closures import lobes, view_image
from lut_baker.closures.view_grid import view_grid


@pytest.mark.slow  # a fit of ~0.5 s
def test_fit_glossy_companion_recovers_a_lobe_plus_lambert(paper_tables):
    """A target that is 0.7 of a Beckmann lobe plus a Lambertian 0.2: the companion fit finds
    the lobe and splits the albedo between the two, and the weights' albedos add up to the
    table's at every texel (so the white furnace is kept)."""
    grid = view_grid(20.0)
    lobe = grid.lobe(0.5, "BECKMANN")
    theta = np.asarray(paper_tables.theta_deg)
    e = cc.microfacet_albedo(np.cos(np.radians(theta)), 0.5, distribution="BECKMANN")
    albedo = (0.7 * e + 0.2)[:, None] * np.ones(3)
    target = (0.7 * lobe + 0.2 / np.pi)[..., None] * np.ones(3)
    plain = lobes.fit_glossy(grid, target, albedo, theta)
    fit = lobes.fit_glossy(grid, target, albedo, theta, companion=True)
    assert plain.diffuse_weights is None and fit.error < 0.25 * plain.error
    assert fit.distribution == "BECKMANN" and fit.roughness == pytest.approx(0.5, abs=0.02)
    inner = slice(4, -4)  # texels away from the ends, where interpolation holds them
    np.testing.assert_allclose(fit.weights[inner], 0.7, atol=0.03)
    np.testing.assert_allclose(fit.diffuse_weights[inner], 0.2, atol=0.02)
    mu = view_image.texel_centres(view_image.DEFAULT_IMAGE_SIZE)
    texel_e = cc.microfacet_albedo(mu, fit.roughness, distribution=fit.distribution)
    texel_table = np.interp(np.degrees(np.arccos(mu)), theta, albedo[:, 0])
    np.testing.assert_allclose(fit.weights[:, 0] * texel_e + fit.diffuse_weights[:, 0], texel_table,
                               rtol=2e-3)

@pytest.mark.parametrize("roughness, ior", [(0.45, 1.8), (0.12, 1.4)])
def test_fit_coat_recovers_a_known_coat(roughness, ior):
    """A coat of any width comes back: the grid resolves the lobe it is given (0.12 is a lobe
    about 0.6 degrees wide)."""
    width = float(np.degrees(np.arctan(0.8 * roughness**2)))
    grid = view_grid(width)
    synthetic = cc.microfacet_reflection(*grid.directions, roughness,
                                         lambda c: cc.dielectric_fresnel(c, ior))
    # The coat's energy compensation (a view factor the fit models) is part of the target.
    scale = cc.ggx_energy_compensation(grid.cos_view, roughness,
                                       float(cc.dielectric_fss(ior)))[0]
    fit = lobes.fit_coat(grid, (synthetic * scale[:, None, None])[..., None] * np.ones(3))
    assert fit.roughness == pytest.approx(roughness, rel=0.02)
    assert fit.ior == pytest.approx(ior, abs=0.02)
    assert fit.error < 0.02

def test_fit_glossy_recovers_distribution_and_roughness(paper_tables):
    grid = view_grid(20.0)
    lobe = grid.lobe(0.5, "BECKMANN")
    mu = np.cos(np.radians(paper_tables.theta_deg))
    albedo = cc.microfacet_albedo(mu, 0.5, distribution="BECKMANN")[:, None] * np.ones(3)
    fit = lobes.fit_glossy(grid, lobe[..., None] * np.ones(3), albedo,
                             np.asarray(paper_tables.theta_deg))
    assert fit.distribution == "BECKMANN"
    assert fit.roughness == pytest.approx(0.5, abs=0.01)
    assert fit.error < 0.02
    # The weight row is table albedo / closure albedo: 1 for the lobe itself.
    np.testing.assert_allclose(fit.weights, 1.0, atol=0.02)

def test_fit_glossy_keeps_ggx_in_a_near_tie(paper_tables, monkeypatch):
    """Another distribution replaces GGX only when it errs DISTRIBUTION_MARGIN less: with a
    margin no gain can reach, even a Beckmann target fits as GGX."""
    grid = view_grid(20.0)
    mu = np.cos(np.radians(paper_tables.theta_deg))
    albedo = cc.microfacet_albedo(mu, 0.5, distribution="BECKMANN")[:, None] * np.ones(3)
    target = grid.lobe(0.5, "BECKMANN")[..., None] * np.ones(3)
    monkeypatch.setattr(lobes, "DISTRIBUTION_MARGIN", 1.0)
    fit = lobes.fit_glossy(grid, target, albedo, np.asarray(paper_tables.theta_deg))
    assert fit.distribution == "GGX"


def _eevee_target(grid, theta, parts):
    """A target made of EEVEE lobes ``(weight, roughness)`` (roughness None: Lambert) on the
    grid, and its albedo table on ``theta``."""
    cos_theta = np.cos(np.radians(theta))
    target, albedo = 0.0, 0.0
    for weight, roughness in parts:
        if roughness is None:
            target, albedo = target + weight / np.pi, albedo + weight
        else:
            target = target + weight * lobes.glossy_lobe(grid, roughness, lobes.EEVEE_GLOSSY)
            albedo = albedo + weight * lobes.glossy_albedo(cos_theta, roughness,
                                                           lobes.EEVEE_GLOSSY)
    return target[..., None] * np.ones(3), np.asarray(albedo)[:, None] * np.ones(3)


def _closure_albedo(first, second):
    """The closures' albedo per texel: both lobes' rows times their albedos, and the
    companion's row."""
    mu = view_image.texel_centres(view_image.DEFAULT_IMAGE_SIZE)
    return (first.weights[:, 0] * lobes.glossy_albedo(mu, first.roughness, lobes.EEVEE_GLOSSY)
            + second.weights[:, 0] * lobes.glossy_albedo(mu, second.roughness, lobes.EEVEE_GLOSSY)
            + first.diffuse_weights[:, 0])


def test_fit_glossy_pair_recovers_two_lobes(paper_tables):
    """Two EEVEE lobes at the pair's ratio and a Lambertian term: the pair comes back, both
    rows carry their weights, and the closures' albedo stays within the slack of the
    table's."""
    grid = view_grid(10.0)
    theta = np.asarray(paper_tables.theta_deg)
    r = 0.45
    low, high = r / np.sqrt(lobes.PAIR_RATIO), r * np.sqrt(lobes.PAIR_RATIO)
    target, albedo = _eevee_target(grid, theta, [(0.5, low), (0.4, high), (0.05, None)])
    first, second = lobes.fit_glossy_pair(grid, target, albedo, theta)
    assert first.searched[lobes.PAIR] < 0.25 * first.searched["GGX"]
    assert first.roughness == pytest.approx(low, rel=0.02)
    assert second.roughness == pytest.approx(high, rel=0.02)
    assert first.error < 0.02
    inner = slice(4, -4)
    np.testing.assert_allclose(first.weights[inner, 0], 0.5, atol=0.05)
    np.testing.assert_allclose(second.weights[inner, 0], 0.4, atol=0.05)
    mu = view_image.texel_centres(view_image.DEFAULT_IMAGE_SIZE)
    table = np.interp(np.degrees(np.arccos(mu)), theta, albedo[:, 0])
    ratio = _closure_albedo(first, second) / table
    assert np.all(np.abs(ratio - 1.0) <= lobes.PAIR_ALBEDO_SLACK + 1e-3)


def test_fit_glossy_pair_keeps_one_lobe_where_one_fits(paper_tables):
    """One EEVEE lobe: the pair gains nothing, so the second lobe has weight 0 and the
    first's roughness, and the one lobe comes back."""
    grid = view_grid(10.0)
    theta = np.asarray(paper_tables.theta_deg)
    target, albedo = _eevee_target(grid, theta, [(0.6, 0.3)])
    first, second = lobes.fit_glossy_pair(grid, target, albedo, theta)
    assert not np.any(second.weights) and second.roughness == first.roughness
    assert first.roughness == pytest.approx(0.3, rel=0.01) and first.error < 0.01
    assert first.searched[lobes.PAIR] >= (1.0 - lobes.DISTRIBUTION_MARGIN) * first.searched["GGX"]


def test_fit_glossy_pair_stays_in_blenders_range(paper_tables):
    """Two lobes of the narrowest: the pair's roughnesses stay within ROUGHNESS_RANGE (the
    Glossy BSDF's socket), the narrower one at its floor."""
    grid = view_grid(2.0)
    theta = np.asarray(paper_tables.theta_deg)
    low, high = lobes.ROUGHNESS_RANGE[0], lobes.ROUGHNESS_RANGE[0] * lobes.PAIR_RATIO
    target, albedo = _eevee_target(grid, theta, [(0.3, low), (0.3, high), (0.1, None)])
    first, second = lobes.fit_glossy_pair(grid, target, albedo, theta)
    for lobe in (first, second):
        assert lobes.ROUGHNESS_RANGE[0] <= lobe.roughness <= lobes.ROUGHNESS_RANGE[1]
    assert first.roughness == pytest.approx(low, rel=0.02)


def test_fit_glossy_pair_of_no_gloss_is_empty():
    grid = view_grid(10.0)
    theta = np.linspace(0.0, 90.0, 10)
    first, second = lobes.fit_glossy_pair(grid, np.zeros(grid.cos_i.shape), np.zeros((10, 3)),
                                          theta)
    assert not np.any(first.weights) and not np.any(first.diffuse_weights)
    assert not np.any(second.weights)


def test_the_share_problem_meets_its_optimality_conditions():
    """The non-negative shares minimising ``f G f - 2 r f`` per view, free or with their sum
    held, meet the Karush-Kuhn-Tucker conditions: the gradient ``2 (G f - r)`` vanishes (or,
    with the sum held, equals one multiplier) on every share above 0 and is no lower on the
    shares at 0; on random problems of two and three shares with every kind of active set."""
    rng = np.random.default_rng(7)
    for count in (2, 3):
        basis = rng.normal(size=(400, count, count + 2))
        gram = np.einsum("vka,vja->vkj", basis, basis) + 1e-3 * np.eye(count)
        right = rng.normal(size=(400, count))
        for total in (None, rng.uniform(0.5, 1.5, 400)):
            shares = lobes._face_minimum(gram, right, total)
            gradient = 2.0 * (np.einsum("vkj,vj->vk", gram, shares) - right)
            active = shares > 0.0
            if total is None:
                multiplier = np.zeros(400)
            else:
                np.testing.assert_allclose(shares.sum(axis=1), total, rtol=1e-12)
                multiplier = np.nanmean(np.where(active, gradient, np.nan), axis=1)
            # the gradient less the multiplier, relative to the gradient's size
            excess = (gradient - multiplier[:, None]) / (1.0 + np.abs(gradient).max(
                axis=1, keepdims=True))
            assert np.all(shares >= 0.0)
            assert np.all(np.abs(excess[active]) < 1e-9)
            assert np.all(excess[~active] > -1e-9)
            assert len({tuple(row) for row in active}) >= count + 1  # several active sets
