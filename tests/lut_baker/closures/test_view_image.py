"""The view-angle image (lut_baker.closures.view_image): texel centres and Blender's sampling."""

import numpy as np

from lut_baker.closures import view_image


def test_texel_centres_are_half_a_texel_in():
    np.testing.assert_allclose(view_image.texel_centres(4), [0.125, 0.375, 0.625, 0.875])
    assert len(view_image.texel_centres()) == view_image.DEFAULT_IMAGE_SIZE


def test_a_row_is_read_linearly_between_centres_and_held_beyond_them():
    row = np.array([1.0, 3.0, 2.0, 6.0])
    u = np.array([0.0, 0.125, 0.25, 0.5, 0.875, 1.0])
    np.testing.assert_allclose(view_image.sample_row(row, u), [1.0, 1.0, 2.0, 2.5, 6.0, 6.0])


def test_an_rgb_row_is_read_per_channel_in_any_shape():
    rng = np.random.default_rng(3)
    row = rng.uniform(size=(8, 3))
    u = rng.uniform(size=(2, 5))
    value = view_image.sample_row(row, u)
    assert value.shape == (2, 5, 3)
    for c in range(3):
        np.testing.assert_allclose(value[..., c], view_image.sample_row(row[:, c], u))
