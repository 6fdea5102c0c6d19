"""The pixel-footprint blur argument (lut_baker.auto_tier.blur) against the exact reference's
subsurface spread."""

from pathlib import Path

import numpy as np
import pytest

from lut_baker import auto_tier
from lut_baker.model import presets
from lut_baker.numerics import geometry
from lut_baker.offline.validation import compare, reference

ROOT = Path(__file__).resolve().parents[3]


def test_blur_kernel_is_normalised_and_tends_to_a_point(paper_tables):
    wide = auto_tier.blur_kernel(0.25, paper_tables.radius_mm, paper_tables.profile)
    assert np.allclose(wide.sum(axis=(0, 1)), 1.0) and wide.min() >= 0.0
    h = wide.shape[0] // 2
    assert wide[h, h, 0] < 0.5  # the spread leaves the centre cell
    point = auto_tier.blur_kernel(100.0, paper_tables.radius_mm, paper_tables.profile)
    assert point[point.shape[0] // 2, point.shape[1] // 2, 0] > 0.99


@pytest.mark.slow
def test_omission_error_follows_the_exact_reference(paper_tables):
    """The pixel-footprint blur model against lut_baker.offline.validation.reference's own spread
    (spread minus local skin light, over the sphere's total): within a factor 2 on a 6 mm sphere at
    24 px (measured 0.0157 against 0.0184), and it falls as the pixels grow."""
    skin = presets.made_up_skin("paper_natural", "paper_bioplate")
    radius, size = 3.0, 24
    _, normals, mask = reference.sphere_points(size, radius)
    points = normals[mask]
    light = geometry.light_direction(45.0)
    local = reference.local_diffuse(points, light, skin)
    spread = reference.spread_diffuse(points, light, skin, radius_mm=radius,
                                      samples=reference.default_samples(skin, radius))
    total = compare.reference_image(skin, tables=paper_tables, resolution=size,
                                    radius_mm=radius, spread=False)[mask]
    exact = np.sqrt(np.mean((spread - local) ** 2)) / np.sqrt(np.mean(total**2))
    _, share = auto_tier.gloss_and_skin_shares(paper_tables, 45.0)
    predicted = auto_tier.subsurface_omission_error(2 * radius / size, 2 * radius, 45.0,
                                                      paper_tables.radius_mm,
                                                      paper_tables.profile, share)
    assert 0.5 * exact < predicted < 2.0 * exact
    coarse = [auto_tier.subsurface_omission_error(footprint, 400.0, 45.0,
                                                    paper_tables.radius_mm,
                                                    paper_tables.profile, share)
              for footprint in (0.5, 4.0, 40.0)]
    assert coarse[0] > coarse[1] > coarse[2] >= 0.0
