"""The baseline (lut_baker.offline.validation.baseline): a stock Principled BSDF fitted to the
model's images.

No bpy: the fit runs on the Principled replica (whose agreement with Cycles renders is checked in
tests/makeup_skin_addon/test_render_compare.py). A fit must find a Principled BSDF that is one
(round trip), and on the paper preset improve on its start, the PRINCIPLED tier's table-space
values.
"""

import dataclasses

import numpy as np
import pytest

from lut_baker.closures import cycles as cc
from lut_baker.closures import tiers
from lut_baker.model import presets
from lut_baker.offline.validation import baseline


@pytest.fixture(scope="module")
def paper(paper_tables, paper_fit):
    return presets.paper(), paper_tables, paper_fit  # the preset's tables (conftest.py)


class _PrincipledTables:
    """Stands in for baked tables whose model is itself a Principled BSDF."""

    def __init__(self, inputs):
        self.inputs = inputs

    def made_up_reflection(self, wi, wo, coverage, absorption):
        return cc.principled_reflection(wi, wo, self.inputs)


@pytest.mark.slow  # a fit of ~1.5 s
def test_fit_recovers_a_principled_bsdf(paper):
    skin, _, fit = paper
    start, _ = tiers.principled_inputs(fit, skin.coverage, skin.absorption)
    truth = dataclasses.replace(start, base_color=(0.55, 0.45, 0.35), roughness=0.5,
                                specular_ior_level=0.4, coat_weight=0.7, coat_roughness=0.3,
                                coat_ior=1.7)
    result = baseline.fit_baseline(skin, _PrincipledTables(truth), fit, resolution=16)
    print(result.start_error, result.error, result.evaluations)
    assert max(result.error.values()) < 2e-3 < min(result.start_error.values())
    got = result.inputs
    np.testing.assert_allclose(got.base_color, truth.base_color, atol=0.01)
    assert got.coat_weight == pytest.approx(0.7, abs=0.03)
    assert got.coat_ior == pytest.approx(1.7, abs=0.05)


def test_paper_baseline_improves_on_its_start_within_socket_ranges(paper):
    skin, tables, fit = paper
    # Six evaluations take the error (sum of squares) to 0.68 of the start's, twelve to 0.66.
    result = baseline.fit_baseline(skin, tables, fit, resolution=16, max_evaluations=6)
    print(result.start_error, result.error)
    assert sum(e * e for e in result.error.values()) < 0.9 * sum(
        e * e for e in result.start_error.values())
    values = result.socket_values()
    assert all(0.0 <= c <= 1.0 for c in values["Base Color"])
    for name in ("Roughness", "Specular IOR Level", "Coat Weight", "Coat Roughness"):
        assert 0.0 <= values[name] <= 1.0, name
    assert 1.0 <= values["Coat IOR"] <= 4.0
    assert values["Subsurface Radius"] == pytest.approx(tuple(fit.subsurface_radius_mm))
    assert result.subsurface_method == fit.subsurface_method


def test_a_black_image_is_refused_by_name(paper):
    skin, tables, fit = paper
    with pytest.raises(ValueError, match="light 180.0 degrees is black"):
        baseline.fit_baseline(skin, tables, fit, lights_deg=(45.0, 180.0), resolution=16)
