"""The direction pairs closures are fitted and judged on (lut_baker.closures.view_grid): the
measure's known values, the view albedo of a Lambertian and of lobes of any width."""

import numpy as np
import pytest

from lut_baker.closures import cycles as cc
from lut_baker.closures.view_grid import view_grid


def test_error_is_zero_against_itself_and_scales():
    grid = view_grid(20.0)
    f = grid.lobe(0.5) + 0.1
    assert grid.error(f, f) == 0.0
    assert grid.error(1.1 * f, f) == pytest.approx(0.1, rel=1e-12)
    assert grid.albedo_error(1.1 * f, f) == pytest.approx(0.1, rel=1e-12)
    rgb = np.stack([f, 2 * f, 3 * f], axis=-1)
    assert grid.error(1.1 * rgb, rgb) == pytest.approx(0.1, rel=1e-12)


@pytest.mark.parametrize("width_deg", [30.0, 5.0, 0.5])
def test_a_lambertian_reflects_its_albedo_at_every_view(width_deg):
    """The lights' weights integrate a Lambertian exactly at every view, whatever the panels
    (they stop where the light meets the horizon, so nothing is cut)."""
    grid = view_grid(width_deg)
    albedo = grid.view_albedo(np.full(grid.cos_i.shape, 0.8 / np.pi))
    np.testing.assert_allclose(albedo, 0.8, rtol=1e-7)


@pytest.mark.parametrize("roughness", [0.9, 0.4, 0.12])
def test_glossy_albedo_of_any_width_matches_the_closure_albedo(roughness):
    """A GGX lobe 0.6 to 40 degrees wide integrates on a grid sized for it to Cycles' own
    albedo (the replica's quadrature over microfacet normals at 384 x 256 nodes) within 0.3%
    at every view but the most grazing (cos = 1/24, 88 degrees), where both rules converge
    slowly for the roughest lobe: 0.6% there."""
    width = float(np.degrees(np.arctan(0.8 * roughness**2)))
    grid = view_grid(width)
    albedo = grid.view_albedo(grid.lobe(roughness))
    reference = cc.microfacet_albedo(grid.cos_view, roughness, n_u=384, n_phi=256)
    np.testing.assert_allclose(albedo[1:], reference[1:], rtol=3e-3)
    np.testing.assert_allclose(albedo[0], reference[0], rtol=6e-3)


def test_pairs_are_unit_directions_above_the_surface_with_their_cosines():
    grid = view_grid(3.0)
    wi, wo = grid.directions
    used = grid.light_weight > 0.0
    np.testing.assert_allclose(np.linalg.norm(wi[used], axis=-1), 1.0, rtol=1e-12)
    assert np.all(wi[..., 2][used] >= 0.0) and np.all(wo[..., 2] > 0.0)
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    np.testing.assert_allclose(h[..., 2][used], grid.cos_h[used], atol=1e-12)
    np.testing.assert_allclose(np.sum(h * wi, axis=-1)[used], grid.cos_hi[used], atol=1e-12)
    np.testing.assert_array_equal(grid.cos_o[:, 0, 0], grid.cos_view)
    with pytest.raises(ValueError):  # cached, so read-only
        grid.weight[0, 0, 0] = 1.0
