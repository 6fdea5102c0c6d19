"""What the Auto tier needs of a scene (lut_baker.auto_tier.scene): the pixel footprint against
the pinhole camera."""

from pathlib import Path

import pytest

from lut_baker import auto_tier

ROOT = Path(__file__).resolve().parents[3]


def test_footprint_orthographic_and_pinhole():
    assert auto_tier.pixel_footprint_mm("ORTHO", 500, ortho_scale_mm=250.0) == 0.5
    # A 36 mm sensor behind a 50 mm lens sees 720 mm at 1 m; over 1000 px that is 0.72 mm.
    value = auto_tier.pixel_footprint_mm("PERSP", 1000, distance_mm=1000.0, sensor_mm=36.0,
                                           focal_mm=50.0)
    assert value == pytest.approx(0.72)
    with pytest.raises(ValueError):
        auto_tier.pixel_footprint_mm("ORTHO", 500)
    with pytest.raises(ValueError):
        auto_tier.pixel_footprint_mm("PANORAMA", 500, distance_mm=1.0)
