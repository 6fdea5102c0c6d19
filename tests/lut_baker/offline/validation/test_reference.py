"""The exact reference image of a made-up sphere (lut_baker.offline.validation.reference)."""

import numpy as np
import pytest

from lut_baker.evaluate.made_up import made_up_reflection
from lut_baker.model import presets
from lut_baker.model.layers import Dipole
from lut_baker.numerics import geometry
from lut_baker.offline.validation import reference as ref


@pytest.fixture(scope="module")
def skin():
    return presets.paper()


def _relative_rms(a, b, mask):
    return np.sqrt(np.mean((a - b)[mask] ** 2)) / np.sqrt(np.mean(b[mask] ** 2))


def test_local_image_is_the_brdf_times_cosine(skin):
    image = ref.sphere_image(skin, resolution=8, radius_mm=5.0, light_angle_deg=45.0)
    _, normals, mask = ref.sphere_points(8, 5.0)
    row, col = 2, 5
    assert mask[row, col]
    light = geometry.light_direction(45.0)
    n = normals[row, col][None]
    wi = geometry.local_directions(light[None], n)
    wo = geometry.local_directions(geometry.VIEW[None], n)
    expected = made_up_reflection(wi, wo, skin)[0] * wi[0, 2]
    np.testing.assert_allclose(image[row, col], expected, rtol=1e-12)
    assert np.all(image[~mask] == 0.0)


def test_image_is_finite_non_negative_and_lit_side_brighter(skin):
    image = ref.sphere_image(skin, resolution=16, radius_mm=5.0, light_angle_deg=75.0)
    assert np.all(np.isfinite(image)) and np.all(image >= 0.0)
    # light from +x: the right half outshines the left half
    assert image[:, 8:].sum() > 2.0 * image[:, :8].sum()


@pytest.mark.slow
def test_spread_with_a_vanishing_profile_equals_the_local_image(skin):
    narrow = skin.replace(dipole=Dipole(sigma_s=60.0, sigma_a=1.0, g=0.0, eta=1.26))
    local = ref.sphere_image(narrow, resolution=16, radius_mm=1.5)
    spread = ref.sphere_image(narrow, resolution=16, radius_mm=1.5, spread=True)
    mask = local.sum(-1) > 0
    assert _relative_rms(spread, local, mask) < 1e-3


@pytest.mark.slow
def test_spread_blurs_the_terminator(skin):
    # light at 90 degrees from the view: half the visible disk is unlit; subsurface light
    # crosses the terminator into the dark half (docs/model.md §4: the diffuse part spreads).
    local = ref.sphere_image(skin, resolution=16, radius_mm=2.0, light_angle_deg=90.0)
    spread = ref.sphere_image(skin, resolution=16, radius_mm=2.0, light_angle_deg=90.0,
                              spread=True, samples=20000)
    dark = (local.sum(-1) == 0) & (ref.sphere_points(16, 2.0)[2])
    assert np.all(spread[dark] >= 0.0) and spread[dark].sum() > 0.0


@pytest.mark.slow
def test_spread_converges_when_samples_double(skin):
    assert ref.spread_convergence(skin, resolution=8, radius_mm=3.0, samples=20000) < 1e-2


def test_profile_cutoff_holds_the_energy(skin):
    from scipy.integrate import quad

    from lut_baker.model.dipole import dipole_profile, dipole_total_reflectance

    cutoff = ref.profile_cutoff_mm(skin, lost_fraction=1e-3)
    inside = 2 * np.pi * quad(lambda d: dipole_profile(d, skin.dipole) * d, 0, cutoff,
                              limit=200)[0]
    assert inside == pytest.approx(0.999 * dipole_total_reflectance(skin.dipole), rel=2e-3)


def test_bad_scene_arguments_raise():
    with pytest.raises(ValueError, match="radius_mm"):
        ref.sphere_points(8, -1.0)
