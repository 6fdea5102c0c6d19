"""The view-angle image (lut_baker.closures.view_image): texel centres and Blender's sampling."""

import numpy as np
import pytest

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


def test_a_row_reader_reads_every_row_as_read_row_does():
    """row_reader finds the texels once and reads any row of its size at them: the numbers of
    read_row with numpy's Closest lookup (the same operations, so bit for bit), and of
    sample_row; a row of another size is refused."""
    rng = np.random.default_rng(5)
    u = np.concatenate([rng.uniform(size=40), [0.0, 1.0, 1.0 / 16, 0.999999]])
    reader = view_image.row_reader(u, 16)

    class Ops:
        minimum, maximum, floor = np.minimum, np.maximum, np.floor

        @staticmethod
        def lerp(t, a, b):
            return a + (t[..., None] if np.ndim(a) > np.ndim(t) else t) * (b - a)

    for row in (rng.uniform(size=16), rng.uniform(size=(16, 3))):
        def texel(at, row=row):
            return row[np.clip(np.floor(at * 16).astype(int), 0, 15)]

        np.testing.assert_array_equal(reader(row), view_image.read_row(u, 16, texel, Ops))
        np.testing.assert_array_equal(reader(row), view_image.sample_row(row, u))
    with pytest.raises(ValueError, match="8 texels"):
        reader(np.zeros(8))
