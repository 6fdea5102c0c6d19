"""The LTC refit of EEVEE's GGX table (lut_baker.offline.eevee_ltc): its GGX is the Cycles
replica's, its fits approximate GGX and reproduce the shipped table."""

import numpy as np
import pytest

from lut_baker.closures import cycles as cc
from lut_baker.closures import eevee
from lut_baker.numerics.geometry import direction
from lut_baker.offline import eevee_ltc


def test_ggx_lobe_is_the_cycles_replica_times_the_cosine():
    rng = np.random.default_rng(5)
    light = direction(rng.uniform(0, 1.5, 40), rng.uniform(0, 2 * np.pi, 40))
    view = direction(0.7, 0.0)
    alpha = 0.4
    lobe, pdf = eevee_ltc.ggx_lobe(view, light, alpha)
    replica = cc.microfacet_reflection(light, np.broadcast_to(view, light.shape),
                                       np.sqrt(alpha)) * light[:, 2]
    np.testing.assert_allclose(lobe, replica, rtol=1e-9, atol=1e-12)
    assert np.all(pdf > 0.0)


@pytest.mark.parametrize(("roughness", "s"), [(0.65, 0.0), (0.65, 0.5), (0.4, 0.8)])
def test_a_refit_node_gives_the_shipped_lobe(roughness, s):
    """One node fitted again (from the shipped neighbour's parameters) gives the lobe the
    shipped table holds there: the same values within 1% RMS over the hemisphere."""
    size = eevee.LTC_TABLE_SIZE
    i, j = round(roughness * (size - 1)), round(s * (size - 1))
    roughness, s = i / (size - 1), j / (size - 1)
    start = None
    if j > 0:  # the neighbour's fit, as the table was built
        start, _, _ = eevee_ltc.fit_node(roughness, (j - 1) / (size - 1), None)
    params, frame, magnitude = eevee_ltc.fit_node(roughness, s, start, isotropic=j == 0)
    cos_o = 1.0 - s * s
    light = direction(*np.meshgrid(np.linspace(0.02, 1.55, 40), np.linspace(0, np.pi, 40)))
    light = light.reshape(-1, 3)
    refit = eevee_ltc._Ltc(params, frame, magnitude).value(light)
    shipped = eevee.glossy_from_cosines(light, cos_o, roughness) * light[:, 2]
    error = np.sqrt(np.mean((refit - shipped) ** 2) / np.mean(shipped**2))
    assert error < 0.01


@pytest.mark.parametrize("roughness", [0.5, 0.8])
def test_fitted_ltc_approximates_ggx(roughness):
    """The LTC holds GGX's energy and, near the mirror direction, its shape (the tails it
    drops are where EEVEE and Cycles differ)."""
    cos_o = 0.7
    _, magnitude = eevee.ltc_coefficients(roughness, cos_o)
    albedo = float(cc.microfacet_albedo(cos_o, roughness))
    assert magnitude == pytest.approx(albedo, rel=0.015)
    view = np.array([np.sqrt(1 - cos_o**2), 0.0, cos_o])
    mirror = view * np.array([-1.0, -1.0, 1.0])
    lobe, _ = eevee_ltc.ggx_lobe(view, mirror[None], roughness**2)
    assert (eevee.glossy_from_cosines(mirror, cos_o, roughness) * mirror[2]
            == pytest.approx(lobe[0], rel=0.12))
