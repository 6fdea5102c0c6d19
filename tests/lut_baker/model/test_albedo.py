"""Single-layer integrals (lut_baker.model.albedo): the film's transmittance and a reflecting
layer's albedo against the independent brute-force reference (tests/support/reference_impl.py)."""

import math

import numpy as np
import pytest
from support import reference_impl as ref
from support.samples import layer_args

from lut_baker.model import albedo, presets
from lut_baker.model.layers import TransmissionLayer
from lut_baker.numerics.geometry import direction


def _film_kernel(film):
    def kernel(w, u):
        return ref.vector_transmission_down(w, u, *film)

    return kernel


def test_film_transmittance_matches_brute_force():
    film = presets.paper().film_transmission
    theta = np.array([0.0, 30.0, 60.0, 80.0, 89.0])
    w = direction(np.radians(theta), 0.0)
    got = albedo.film_transmittance(w, film)
    sums = [ref.brute_force_albedo(_film_kernel(layer_args(film)), w, n, 2 * n) for n in (64, 128)]
    brute = (4 * sums[1] - sums[0]) / 3
    accuracy = np.abs(sums[1] - sums[0]) / 3 / brute
    np.testing.assert_allclose(got, brute, rtol=max(accuracy.max(), 1e-6))
    np.testing.assert_allclose(albedo.transmission_albedo(theta, film), got, rtol=1e-12)


def test_film_transmittance_of_a_diffuse_film_is_pi_p_d():
    """A purely diffuse film (P_t = 0) transmits pi P_d at every incidence."""
    film = TransmissionLayer(P_d=0.2, P_t=0.0, n=0.05, eta=1.3)
    w = direction(np.radians(np.array([0.0, 45.0, 89.0, 90.0])), 1.0)
    np.testing.assert_allclose(albedo.film_transmittance(w, film), math.pi * 0.2, rtol=1e-12)


def test_bare_skin_albedo_against_brute_force():
    """The skins' own albedos (coverage 0) are <= 1; checked with the independent reference."""
    theta = np.array([0.0, 45.0, 75.0, 89.0])
    w = direction(np.radians(theta), 0.0)
    for name in presets.SKINS:
        surface, _ = presets.skin_layers(name)
        got = np.reshape(albedo.reflection_albedo(theta, surface), (4, -1))
        for c in range(got.shape[1]):
            args = [float(np.broadcast_to(v, (3,))[c]) for v in surface.as_dict().values()]
            brute = ref.brute_force_albedo(lambda a, u, args=args: ref.vector_reflection(
                a, u, *args), w, 128, 256)
            assert np.all(brute <= 1.0)
            # Level 0 of the model's grid is coarse at grazing incidence (the G kink).
            np.testing.assert_allclose(got[:, c], brute, rtol=3e-3)


@pytest.mark.parametrize("width_deg", [9.0, 5.0, 2.0])
def test_narrow_lobes_integrate_through_the_half_vector(width_deg):
    """Below MIRROR_BELOW_DEG a layer's albedo is pi P_d plus its specular albedo through the
    half vector; at 5 degrees and beyond, where the Fourier grid still resolves the lobe, the
    two agree within 0.05% up to 80 degrees; the half-vector rule converges by itself at any
    width (a level finer moves it by under 0.02% up to 85 degrees)."""
    layer = presets.paper().film.scaled(n=30.4 / width_deg)
    theta = np.array([0.0, 30.0, 60.0, 80.0, 85.0])
    value = albedo.reflection_albedo(theta, layer)
    np.testing.assert_allclose(value, np.pi * layer.P_d
                               + albedo.specular_albedo(theta, layer)[..., 0], rtol=1e-12)
    np.testing.assert_allclose(albedo.specular_albedo(theta, layer, level=1),
                               albedo.specular_albedo(theta, layer), rtol=2e-4)
    if width_deg >= 5.0:
        grid = albedo.grid_for(layer)
        fourier = albedo.order0_integral(albedo.fourier_kernel(
            albedo.reflection_kernel(layer), np.radians(theta), grid.theta, grid.n_phi)[0],
            grid)[:, 0]
        np.testing.assert_allclose(value[:4], fourier[:4], rtol=5e-4)
