"""lut_baker.numerics.geometry: directions and angles, and the reference sphere's framing."""

import numpy as np
import pytest

from lut_baker.numerics import geometry


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


def test_sphere_frames_shared_by_lights():
    """Every light at one resolution shares the sphere's frames (made once): the directions
    are those of local_directions at the lit normals (the same operations: equal to the last
    bit), and a caller's arrays are its own (writing them leaves the next call alone)."""
    normals, mask = geometry.sphere_normals(20)
    for light_deg in (0.0, 45.0, 89.0, 120.0):
        lit, wi, wo = geometry.sphere_directions(20, light_deg)
        points = normals[lit]
        light = np.broadcast_to(geometry.light_direction(light_deg), points.shape)
        # bit for bit: the same numpy operations on the same inputs
        np.testing.assert_array_equal(wi, geometry.local_directions(light, points))
        np.testing.assert_array_equal(
            wo, geometry.local_directions(np.broadcast_to(geometry.VIEW, points.shape), points))
        lit[...], wi[...], wo[...] = False, 0.0, 0.0
        again = geometry.sphere_directions(20, light_deg)
        assert np.any(again[0]) and np.all(again[2][:, 2] > 0.0)
