"""The closure fits (lut_baker.closures.fitting), by round trips: tables synthesised from a
known closure must give that closure's parameters back; then the tiers on the paper's
tables."""

import dataclasses

import numpy as np
import pytest

from lut_baker import bake
from lut_baker.closures import cycles as cc
from lut_baker.closures import fitting, tier_formulas, view_image
from lut_baker.closures.view_grid import view_grid
from lut_baker.model import presets
from lut_baker.numerics.geometry import direction
from lut_baker.tables.table_set import radius_nodes


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
    plain = fitting.fit_glossy(grid, target, albedo, theta)
    fit = fitting.fit_glossy(grid, target, albedo, theta, companion=True)
    assert plain.diffuse_lut is None and fit.error < 0.25 * plain.error
    assert fit.distribution == "BECKMANN" and fit.roughness == pytest.approx(0.5, abs=0.02)
    inner = slice(4, -4)  # texels away from the ends, where interpolation holds them
    np.testing.assert_allclose(fit.lut[inner], 0.7, atol=0.03)
    np.testing.assert_allclose(fit.diffuse_lut[inner], 0.2, atol=0.02)
    mu = view_image.lut_nodes(view_image.DEFAULT_LUT_SIZE)
    texel_e = cc.microfacet_albedo(mu, fit.roughness, distribution=fit.distribution)
    texel_table = np.interp(np.degrees(np.arccos(mu)), theta, albedo[:, 0])
    np.testing.assert_allclose(fit.lut[:, 0] * texel_e + fit.diffuse_lut[:, 0], texel_table,
                               rtol=2e-3)


def test_edge_response_of_a_uniform_disc():
    # P = 1 / (pi a^2) inside r < a: ESF(s) = (a^2 acos(s/a) - s sqrt(a^2 - s^2)) / (pi a^2).
    a = 2.0
    r = np.linspace(0.0, 3.0, 300001)
    disc = np.where(r < a, 1.0 / (np.pi * a * a), 0.0)
    s = np.array([0.0, 0.5, 1.0, 1.9])
    expected = (a * a * np.arccos(s / a) - s * np.sqrt(a * a - s * s)) / (np.pi * a * a)
    np.testing.assert_allclose(fitting.edge_response(r, disc, s), expected, atol=1e-4)


# ---------------------------------------------------------------------------------------------
# Fits: round trips
# ---------------------------------------------------------------------------------------------
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
    fit = fitting.fit_coat(grid, (synthetic * scale[:, None, None])[..., None] * np.ones(3))
    assert fit.roughness == pytest.approx(roughness, rel=0.02)
    assert fit.ior == pytest.approx(ior, abs=0.02)
    assert fit.error < 0.02


def test_fit_glossy_recovers_distribution_and_roughness(paper_tables):
    grid = view_grid(20.0)
    lobe = grid.lobe(0.5, "BECKMANN")
    mu = np.cos(np.radians(paper_tables.theta_deg))
    albedo = cc.microfacet_albedo(mu, 0.5, distribution="BECKMANN")[:, None] * np.ones(3)
    fit = fitting.fit_glossy(grid, lobe[..., None] * np.ones(3), albedo,
                             np.asarray(paper_tables.theta_deg))
    assert fit.distribution == "BECKMANN"
    assert fit.roughness == pytest.approx(0.5, abs=0.01)
    assert fit.error < 0.02
    # The weight row is table albedo / closure albedo: 1 for the lobe itself.
    np.testing.assert_allclose(fit.lut, 1.0, atol=0.02)


def test_fit_glossy_keeps_ggx_in_a_near_tie(paper_tables, monkeypatch):
    """Another distribution replaces GGX only when it errs DISTRIBUTION_MARGIN less: with a
    margin no gain can reach, even a Beckmann target fits as GGX."""
    grid = view_grid(20.0)
    mu = np.cos(np.radians(paper_tables.theta_deg))
    albedo = cc.microfacet_albedo(mu, 0.5, distribution="BECKMANN")[:, None] * np.ones(3)
    target = grid.lobe(0.5, "BECKMANN")[..., None] * np.ones(3)
    monkeypatch.setattr(fitting, "DISTRIBUTION_MARGIN", 1.0)
    fit = fitting.fit_glossy(grid, target, albedo, np.asarray(paper_tables.theta_deg))
    assert fit.distribution == "GGX"


@pytest.mark.parametrize("method", cc.SUBSURFACE_METHODS)
def test_fit_profile_recovers_a_known_radius(paper_tables, method):
    # A fine quadratic radius grid: Burley's profile is singular (1/r) at 0.
    r = radius_nodes(2000, "quadratic", 20.0)
    radius = np.array([3.0, 1.5, 0.8])
    profile = np.stack([cc.subsurface_profile(np.maximum(r, r[1] / 2), radius[c], 0.6, method)
                        for c in range(3)], -1)
    tables = dataclasses.replace(paper_tables, radius_mm=r, profile=profile)
    fit = fitting.fit_profile(tables, method, albedo=0.6)
    np.testing.assert_allclose(fit.radius_mm, radius, rtol=0.02)
    assert fit.worst_error < 0.005


# ---------------------------------------------------------------------------------------------
# The tiers on the paper's tables
# ---------------------------------------------------------------------------------------------
def test_paper_fit_parameters_are_in_blender_ranges(paper_fit):
    assert fitting.ROUGHNESS_RANGE[0] <= paper_fit.coat.roughness <= 1.0
    assert 1.0 < paper_fit.coat.ior <= fitting.COAT_IOR_RANGE[1]
    for lobe in paper_fit.glossy.values():
        assert lobe.distribution in cc.GLOSSY_DISTRIBUTIONS
        assert np.all(np.isfinite(lobe.lut)) and np.all(lobe.lut >= 0.0)
    assert paper_fit.lut.shape == (len(view_image.LUT_ROWS), view_image.DEFAULT_LUT_SIZE, 3)
    assert np.all(paper_fit.subsurface_radius_mm > 0.0)
    assert paper_fit.subsurface_method in cc.SUBSURFACE_METHODS
    # Burley's edge response follows the dipole's within 1% RMS of the lit level.
    assert paper_fit.profiles["BURLEY"].worst_error < 0.01


def test_layered_tier_keeps_the_albedo(paper_tables, paper_fit):
    # Glossy weights are albedo ratios, so the tier's view albedo follows the tables'.
    for coverage in (0.0, 0.5, 1.0):
        errors = fitting.tier_errors(paper_fit, paper_tables, coverage, (0.1, 0.2, 0.4))
        assert errors["LAYERED"].albedo < 0.03
        assert errors["LAYERED"].rms < 0.12
        assert np.isfinite(errors["PRINCIPLED"].rms)


def test_layered_beats_principled_on_bare_skin(paper_tables, paper_fit):
    errors = fitting.tier_errors(paper_fit, paper_tables, 0.0, 0.0)
    assert errors["LAYERED"].rms < errors["PRINCIPLED"].rms


def test_principled_inputs_follow_coverage(paper_fit):
    bare, weight_bare = fitting.principled_inputs(paper_fit, 0.0, 0.0)
    full, weight_full = fitting.principled_inputs(paper_fit, 1.0, (0.3, 0.3, 0.3))
    assert bare.coat_weight == 0.0 and full.coat_weight == 1.0
    assert weight_bare == pytest.approx(1.0)  # bare skin: all diffuse light is the skin's
    assert 0.0 < weight_full < 1.0
    # Absorption darkens the film's diffuse light: the base colour drops.
    darker, _ = fitting.principled_inputs(paper_fit, 1.0, (0.6, 0.6, 0.6))
    assert np.all(np.array(darker.base_color) < np.array(full.base_color))


def test_summary_is_plain_data(paper_fit):
    import json

    text = json.dumps(paper_fit.summary())
    assert "PRINCIPLED" in text and "subsurface_method" in text


def test_principled_error_does_not_peak_between_coverages(paper_tables, paper_fit):
    # The node group mixes roughness and level by coverage: a half-covered surface must not
    # err much more than the worse of bare and fully covered skin.
    ends = [fitting.tier_errors(paper_fit, paper_tables, w, 0.0)["PRINCIPLED"].rms
            for w in (0.0, 1.0)]
    for coverage in (0.25, 0.5, 0.75):
        middle = fitting.tier_errors(paper_fit, paper_tables, coverage, 0.0)["PRINCIPLED"]
        assert middle.rms < 1.2 * max(ends)


def test_gloss_zero_leaves_only_the_diffuse_closures(paper_tables, paper_fit):
    """The group's Gloss input at 0: the Principled tier has coat weight 0 and specular level
    0 (eta 1: Cycles allocates neither closure) and its base colour is the diffuse albedo
    itself; the Layered tier's Glossy weights are 0 and it is linear in Gloss.  Without its
    gloss, each tier misses the tables' gloss."""
    w, a = 0.5, (0.1, 0.2, 0.4)
    inputs, weight = fitting.principled_inputs(paper_fit, w, a, gloss=0.0)
    once = 1.0 - np.array(a)  # the diffuse albedo, docs/model.md §4: film once, skin twice
    skin = (1 - w) * paper_fit.skin_albedo + w * once**2 * paper_fit.skin_albedo \
        * paper_fit.transmittance_mean**2
    total = skin + w * once * paper_fit.film_albedo
    assert inputs.coat_weight == 0.0 and inputs.specular_ior_level == 0.0
    assert inputs.specular_eta_f0()[0] == 1.0
    np.testing.assert_allclose(inputs.base_color, np.clip(total, 0.0, 1.0), rtol=1e-12)
    assert weight == pytest.approx(float(np.mean(skin / total)))
    matte = fitting.principled_tier_reflection(paper_fit, paper_tables, w, a, gloss=0.0)
    np.testing.assert_allclose(matte, np.broadcast_to(np.clip(total, 0, 1) / np.pi,
                                                      matte.shape), rtol=1e-12)
    algebra = tier_formulas.NumpyAlgebra(dict(zip(view_image.LUT_ROWS, paper_fit.lut,
                                                  strict=True)),
                                         np.linspace(0.0, 1.0, 9))
    closures = tier_formulas.view_weighted_closures(
        paper_fit, tier_formulas.TierInputs.numpy(w, a, paper_fit.skin_albedo, 0.0), algebra)
    glossy = [c for c in closures.covered + closures.bare if c.kind == "glossy"]
    assert len(glossy) == 3 and not any(np.any(c.colour) for c in glossy)
    layered = {g: fitting.layered_tier_reflection(paper_fit, paper_tables, w, a, gloss=g)
               for g in (0.0, 0.5, 1.0)}
    np.testing.assert_allclose(layered[0.5], 0.5 * (layered[0.0] + layered[1.0]), rtol=1e-9)
    kept = fitting.tier_errors(paper_fit, paper_tables, w, a)
    dropped = fitting.tier_errors(paper_fit, paper_tables, w, a, gloss=0.0)
    for tier in fitting.TIERS:
        assert dropped[tier].rms > 2.0 * kept[tier].rms


def test_replicas_take_any_directions(paper_tables, paper_fit):
    """At the tables' own nodes passed explicitly, each replica gives its default values; on
    an (n, m) batch of directions it keeps the batch's shape; a NaN light direction touches
    no other value (its own is NaN for the Principled tier; the Layered tier's Glossy lobes
    count it as below the horizon and its diffuse part does not depend on it)."""
    nodes = paper_tables.node_directions()
    wi = direction(np.radians([[10.0, 40.0, 70.0], [0.0, 85.0, 30.0]]), 1.0)
    wo = direction(np.radians([[60.0, 5.0, 20.0], [45.0, 10.0, 89.0]]), 0.0)
    wi_nan = wi.copy()
    wi_nan[0, 0] = np.nan
    for tier, replica in fitting.TIER_REPLICAS.items():
        np.testing.assert_array_equal(replica(paper_fit, paper_tables, 1.0, 0.0, 1.0, nodes),
                                      replica(paper_fit, paper_tables, 1.0, 0.0), err_msg=tier)
        batch = replica(paper_fit, paper_tables, 1.0, 0.0, 1.0, (wi, wo))
        assert batch.shape == (2, 3, 3) and np.all(np.isfinite(batch)) and batch.min() >= 0
        with np.errstate(invalid="ignore"):
            poisoned = replica(paper_fit, paper_tables, 1.0, 0.0, 1.0, (wi_nan, wo))
        assert not np.isinf(poisoned[0, 0]).any(), tier
        np.testing.assert_allclose(poisoned[1], batch[1], rtol=1e-12, err_msg=tier)
        np.testing.assert_allclose(poisoned[0, 1:], batch[0, 1:], rtol=1e-12, err_msg=tier)


def test_fit_is_linear_in_the_skin_albedo(paper_tables, paper_fit):
    """A skin of another diffuse albedo fits to the same closures and view-angle image: only
    ``skin_albedo`` changes (the node group's Skin Color), so an albedo texture scales the
    skin's closures exactly (the bake leaves the inter-reflections out)."""
    colour = np.array([0.62, 0.41, 0.33])
    skin = presets.paper()
    other = skin.replace(skin_reflection=dataclasses.replace(skin.skin_reflection,
                                                             P_d=colour / np.pi))
    fit = fitting.fit_closures(bake.bake(other, "preview"))
    np.testing.assert_allclose(fit.skin_albedo, colour, rtol=1e-12)
    np.testing.assert_array_equal(fit.lut, paper_fit.lut)
    same, reference = fit.summary(), paper_fit.summary()
    for summary in (same, reference):
        summary.pop("errors")  # measured against each skin's own tables
    profiles, reference_profiles = same.pop("profiles"), reference.pop("profiles")
    assert same == reference  # lobes, coat, specular and the subsurface method
    # Burley's radius (the method chosen) is the profile's alone; the random walks' replicas
    # depend on the albedo, so their radius is fitted at the preset's (docs/addon.md).
    burley, reference_burley = profiles["BURLEY"], reference_profiles["BURLEY"]
    assert fit.subsurface_method == "BURLEY"
    assert burley["radius_mm"] == reference_burley["radius_mm"]
    np.testing.assert_allclose(burley["error"], reference_burley["error"], rtol=1e-6)
    np.testing.assert_array_equal(fit.film_albedo, paper_fit.film_albedo)
    np.testing.assert_array_equal(fit.transmittance_mean, paper_fit.transmittance_mean)


def test_fits_of_a_narrow_gloss_cost_what_a_broad_one_does():
    """The film's gloss is fitted on a grid sized by its own lobe, never on the tables' grid:
    a 1-degree gloss gives tables of the same size as the paper's and fit grids of at most
    three times as many pairs (one more panel per halving of the width: 8 panels against 3),
    and the Layered tier follows it within 3% (its albedo within 1%)."""
    paper = presets.paper()
    narrow = paper.replace(film=dataclasses.replace(paper.film, n=1.0))  # 1 degree
    broad_tables, narrow_tables = bake.bake(paper, "preview"), bake.bake(narrow, "preview")
    assert narrow_tables.path3_gloss.shape == broad_tables.path3_gloss.shape
    widths = fitting.lobe_widths_deg(narrow_tables)
    assert widths["film_gloss"] == pytest.approx(1.0, rel=1e-6)
    sizes = [view_grid(w).weight.size for w in (1.0, 30.4)]
    assert sizes[0] <= 3 * sizes[1]
    errors = fitting.fit_closures(narrow_tables, errors_at=(1.0, 0.0)).errors["LAYERED"]
    assert errors.rms < 0.03 and errors.albedo < 0.01
