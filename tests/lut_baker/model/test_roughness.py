"""Blender roughness for eq. 2's lobe (lut_baker.model.roughness, docs/model.md §4): the GGX
lobe's 1/e half-width, its inverse, and a layer roughened at constant gloss albedo."""

import math

import numpy as np
import pytest

from lut_baker.model import presets
from lut_baker.model import roughness as R
from lut_baker.model.albedo import bihemispherical, specular_albedo
from lut_baker.model.layers import ReflectionLayer


def _ggx_ratio(theta_deg, roughness):
    """Blender's GGX D(theta) / D(0), alpha = roughness^2, written out."""
    alpha = roughness**2
    c = math.cos(math.radians(theta_deg))
    d = alpha**2 / (math.pi * c**4 * (alpha**2 + (1 - c * c) / (c * c)) ** 2)
    return d * math.pi * alpha**2


@pytest.mark.parametrize("roughness", [0.05, 0.2, 0.4, 0.5, 0.729, 0.85])
def test_the_width_is_where_ggx_falls_to_1_over_e(roughness):
    width = float(R.lobe_width_deg(roughness))
    assert _ggx_ratio(width, roughness) == pytest.approx(math.exp(-1.0), rel=1e-10)
    # eq. 2's lobe of that width falls to 1/e there too (docs/model.md §2.1: n in 1/degree).
    assert math.exp(-(width / width) ** 2) == pytest.approx(math.exp(-1.0))


def test_the_mapping_and_its_inverse():
    widths = np.array([0.5, 1.0, 5.0, 12.0, 19.3, 25.0, 30.4, 60.0, 85.0])
    np.testing.assert_allclose(R.lobe_width_deg(R.roughness_for_width(widths)), widths,
                               rtol=1e-12)
    assert float(R.roughness_for_width(30.4)) == pytest.approx(0.7294, abs=1e-4)  # paper film
    assert float(R.roughness_for_width(12.0)) == pytest.approx(0.5, abs=1e-4)
    assert np.all(np.diff(R.lobe_width_deg(np.linspace(0.05, 0.88, 50))) > 0)
    # Beyond 0.883 the GGX lobe stays above 1/e: the widest lobe.
    assert R.ROUGHEST_WITH_EDGE == pytest.approx(0.8825, abs=1e-4)
    assert float(R.lobe_width_deg(0.95)) == R.WIDEST_DEG == float(R.lobe_width_deg(1.0))
    for bad in (0.0, -0.1):
        with pytest.raises(ValueError, match="roughness"):
            R.lobe_width_deg(bad)
    with pytest.raises(ValueError, match="width"):
        R.roughness_for_width(95.0)


def test_a_layers_roughness_is_its_lobes():
    assert R.layer_roughness(presets.paper().film) == pytest.approx(
        float(R.roughness_for_width(1 / 0.0329)), rel=1e-14)
    surface, _ = presets.skin_layers("jensen_skin1")
    assert R.layer_roughness(surface) == pytest.approx(0.616, abs=1e-3)


@pytest.mark.parametrize("roughness", [0.2, 0.5, 0.9])
def test_roughening_keeps_the_gloss_albedo(roughness):
    film = presets.paper().film
    rough = R.with_roughness(film, roughness)
    assert float(rough.n) == pytest.approx(1.0 / float(R.lobe_width_deg(roughness)), rel=1e-14)
    assert float(rough.P_d) == float(film.P_d) and float(rough.eta) == float(film.eta)

    def albedo(layer):
        return float(bihemispherical(lambda t: specular_albedo(t, layer)[..., 0]))

    assert albedo(rough) == pytest.approx(albedo(film), rel=1e-12)
    # A narrower lobe is brighter at its peak, a wider one dimmer.
    assert (float(rough.P_s) > float(film.P_s)) == (roughness < R.layer_roughness(film))


def test_a_layer_without_lobe_has_nothing_to_roughen():
    matte = presets.foundation_film("clarins_103")
    assert R.with_roughness(matte, 0.3) is matte
    rgb = ReflectionLayer(P_d=0.1, P_s=[1.0, 2.0, 3.0], n=0.05, eta=1.3)
    rough = R.with_roughness(rgb, 0.4)
    np.testing.assert_allclose(rough.P_s / rgb.P_s, rough.P_s[0] / rgb.P_s[0], rtol=1e-12)
