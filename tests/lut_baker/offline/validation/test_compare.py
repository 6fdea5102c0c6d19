"""The comparison of images (lut_baker.offline.validation.compare): relative RMS error, noise
floor and bias, Blender's pixel order, the Pareto front, the Lambert sphere, and the fast
reference from tables against the exact one."""

import math

import numpy as np
import pytest

from lut_baker import bake
from lut_baker.model import presets
from lut_baker.offline.validation import compare, reference

RADIUS_MM = 10.0


def test_relative_rms_and_noise_floor_of_known_images():
    mask = compare.sphere_mask(32)
    ref = np.where(mask[..., None], 2.0, 0.0) * np.ones(3)
    assert compare.relative_rms(ref * 1.1, ref) == pytest.approx(0.1)
    rng = np.random.default_rng(0)
    a = ref + rng.normal(0.0, 0.2, ref.shape)
    b = ref + rng.normal(0.0, 0.2, ref.shape)
    # Noise of sigma 0.2 on a level of 2: 10% per image, whatever is outside the disk.
    assert compare.noise_floor(a, b, ref) == pytest.approx(0.1, rel=0.05)
    assert compare.relative_rms(a, ref) == pytest.approx(0.1, rel=0.05)
    assert compare.bias(0.05, 0.03) == pytest.approx(0.04)
    assert compare.bias(0.02, 0.03) == 0.0
    with pytest.raises(ValueError):
        compare.relative_rms(ref, np.zeros_like(ref))


def test_from_blender_pixels_flips_rows():
    image = np.arange(4 * 4 * 3, dtype=float).reshape(4, 4, 3)
    rgba = np.concatenate([image, np.ones((4, 4, 1))], axis=-1)
    flat = rgba[::-1].ravel()  # Blender's order: bottom row first
    assert np.array_equal(compare.from_blender_pixels(flat, 4), image)
    with pytest.raises(ValueError):
        compare.from_blender_pixels(flat[:-4], 4)


def test_pareto_front():
    cost = [1.0, 2.0, 3.0, 2.0, 4.0, np.nan]
    error = [0.5, 0.2, 0.1, 0.3, 0.1, 0.0]
    front = compare.pareto_front(cost, error)
    assert front.tolist() == [True, True, True, False, False, False]


def test_lambert_image_is_the_cosine_law():
    image = compare.lambert_image(16, 0.0, albedo=0.5, irradiance=math.pi)
    _, normals, mask = reference.sphere_points(16, 1.0)
    assert np.allclose(image[mask][:, 1], 0.5 * normals[mask][:, 2])
    assert np.all(image[~mask] == 0.0)
    side = compare.lambert_image(16, 90.0)
    assert np.all(side[:, :8] == 0.0) and np.all(side[compare.sphere_mask(16)][:, 0] >= 0.0)


def test_reference_from_tables_matches_the_exact_reference():
    """The fast reference (paths 1 + 3 from "default" tables) against the exact one: measured
    5.4e-5 relative at 12 px (the tables err <= 1e-3 of the peak, docs/baking.md)."""
    skin = presets.paper()
    tables = bake.bake(skin, "default")
    options = {"resolution": 12, "radius_mm": RADIUS_MM, "light_angle_deg": 60.0,
               "irradiance": math.pi, "spread": False}
    exact = compare.reference_image(skin, **options)
    fast = compare.reference_image(skin, tables=tables, **options)
    assert compare.relative_rms(fast, exact) < 3e-4
    assert compare.relative_rms(fast, 1.01 * exact) > 5e-3  # the check can fail
