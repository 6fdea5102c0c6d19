"""Two-layer functions (lut_baker.evaluate.two_layer, docs/model.md §3): path 3 against an
independent brute-force 4-D quadrature, convergence when the grid is doubled (levels 0, 1,
2), reciprocity, RGB channels and path 4's angular factor against the independent reference."""

import math

import numpy as np
import pytest
from support import reference_impl as ref
from support.samples import layer_args

from lut_baker.evaluate import two_layer
from lut_baker.model import albedo, made_up_skin, presets
from lut_baker.model.layers import Dipole, ReflectionLayer, TransmissionLayer
from lut_baker.numerics.geometry import direction

CONVERGENCE_RTOL = 1e-4


def _film_and_skin(foundation, skin_name):
    skin = presets.made_up_skin(foundation, skin_name)
    return made_up_skin.film_transmission_layer(skin), skin.skin_reflection


def _random_pairs(count, seed):
    """``count`` direction pairs, uniform in projected solid angle, with grazing rows: the first
    ten incidences run 80..89 degrees and ten views sit at 89 degrees."""
    rng = np.random.default_rng(seed)
    theta_i = np.degrees(np.arccos(np.sqrt(rng.uniform(0, 1, count))))
    theta_o = np.degrees(np.arccos(np.sqrt(rng.uniform(0, 1, count))))
    theta_i[:10] = np.linspace(80.0, 89.0, 10)
    theta_o[5:15] = 89.0
    wi = direction(np.radians(theta_i), rng.uniform(0, 2 * np.pi, count))
    wo = direction(np.radians(theta_o), rng.uniform(0, 2 * np.pi, count))
    return wi, wo


# --- brute force ---------------------------------------------------------------------------
BRUTE_POINTS_DEG = [(0.0, 0.0, 0.0), (30.0, 45.0, 1.0), (60.0, 20.0, math.pi),
                    (75.0, 60.0, 2.5), (89.0, 89.0, 0.0)]


def _brute_force_check(film, skin, resolutions):
    """Model (level 0 and 1) against Richardson-extrapolated midpoint sums at three
    resolutions; returns (relative error, relative accuracy estimate of the brute force)."""
    theta_i, theta_o, phi = (np.array(v) for v in zip(*BRUTE_POINTS_DEG, strict=True))
    wi = direction(np.radians(theta_i), phi)
    wo = direction(np.radians(theta_o), 0.0)
    sums = [ref.brute_force_layered(wi, wo, film, skin, n, 2 * n) for n in resolutions]
    # Midpoint error is O(h^2): extrapolate each successive pair.
    coarse = (4 * sums[1] - sums[0]) / 3
    fine = (4 * sums[2] - sums[1]) / 3
    accuracy = np.abs(fine - coarse) / np.abs(fine)
    return wi, wo, fine, accuracy


@pytest.mark.slow
def test_layered_reflection_matches_brute_force_paper():
    film, skin = _film_and_skin("paper_natural", "paper_bioplate")
    wi, wo, brute, accuracy = _brute_force_check(layer_args(film, 0), layer_args(skin),
                                                 (10, 20, 40))
    for level in (0, 1):
        model = two_layer.layered_reflection(wi, wo, film, skin, level=level)[:, 0]
        error = np.abs(model - brute) / brute
        print(f"paper level {level}: brute-force rel. error {error.max():.2e}, "
              f"brute-force accuracy {accuracy.max():.2e}")
        # The extrapolated sum is better than the coarser extrapolation's distance to it.
        assert np.all(error <= accuracy), (error, accuracy)
        assert np.all(error < 1e-4)


def test_layered_reflection_matches_brute_force_jensen_blue():
    """An RGB case, one channel (blue: the most absorbing shade, the sharpest skin lobe)."""
    film, skin = _film_and_skin("medium_beige", "jensen_skin1")
    wi, wo, brute, accuracy = _brute_force_check(layer_args(film, 2), layer_args(skin, 2),
                                                 (8, 16, 32))
    model = two_layer.layered_reflection(wi, wo, film, skin, level=0)[:, 2]
    error = np.abs(model - brute) / brute
    print(f"jensen_skin1 blue: brute-force rel. error {error.max():.2e}, "
          f"accuracy {accuracy.max():.2e}")
    assert np.all(error <= accuracy), (error, accuracy)


# --- convergence: the test doubles the grid ------------------------------------------------
def _convergence_points(seed):
    """100 random pairs: 10 polar angles of incidence x 10 of view (each set with grazing rows
    at 80, 85 and 89 degrees), one random relative azimuth (radians) per pair."""
    rng = np.random.default_rng(seed)
    grazing = [80.0, 85.0, 89.0]
    theta_i = np.concatenate([grazing, np.degrees(np.arccos(rng.uniform(0.2, 1, 7)))])
    theta_o = np.concatenate([grazing, np.degrees(np.arccos(rng.uniform(0.2, 1, 7)))])
    phi = rng.uniform(0, 2 * np.pi, (10, 10))
    return np.radians(theta_i), np.radians(theta_o), phi


def _fourier_values(film, skin, level, theta_i, theta_o, phi):
    """``f_cs`` on the pairs (theta_i[p], theta_o[q], phi[p, q]) from the level's Fourier
    matrices: one inner table per level instead of one per point (the level-2 grid is big)."""
    grid = albedo.grid_for(film, skin, level=level)
    matrices = two_layer.layered_fourier_matrices(theta_i, theta_o, film, skin, grid)
    m = np.arange(matrices.shape[0])[:, None, None]
    return np.einsum("mpqc,mpq->pqc", matrices, np.cos(m * phi[None]))


@pytest.mark.slow
@pytest.mark.parametrize("foundation, skin_name, levels", [
    ("paper_natural", "paper_bioplate", 3),
    ("medium_beige", "jensen_skin1", 2),
    ("deep_mocha", "jensen_skin2", 2),
])
def test_levels_agree(foundation, skin_name, levels):
    """Doubling the grid (level 0 -> 1) changes nothing beyond 1e-4; for the paper's preset a
    second doubling (level 2, the slow one) shows the differences shrinking."""
    film, skin = _film_and_skin(foundation, skin_name)
    theta_i, theta_o, phi = _convergence_points(seed=11)
    values = [_fourier_values(film, skin, level, theta_i, theta_o, phi) for level in range(levels)]
    # The same numbers as the public evaluator gives at those directions.
    wi = direction(theta_i[:, None], phi)
    wo = direction(theta_o[None, :], 0.0)
    np.testing.assert_allclose(two_layer.layered_reflection(wi, wo, film, skin), values[0],
                               rtol=1e-10)
    assert values[-1].shape == (10, 10, 3) and np.all(values[-1] > 0)
    diff01 = np.max(np.abs(values[0] - values[1]) / values[1])
    print(f"{foundation}+{skin_name}: level 0-1 {diff01:.2e}")
    assert diff01 <= CONVERGENCE_RTOL
    if levels == 3:
        diff12 = np.max(np.abs(values[1] - values[2]) / values[2])
        diff02 = np.max(np.abs(values[0] - values[2]) / values[2])
        print(f"  level 1-2 {diff12:.2e}, 0-2 {diff02:.2e}")
        assert max(diff12, diff02) <= CONVERGENCE_RTOL
        # refining converges (once both differences are ~1e-8 they are at the quadrature's floor)
        assert diff12 <= max(diff01, 1e-7)


@pytest.mark.slow
def test_pure_lobes_converge_at_grazing():
    """Path 3 with no diffuse terms (P_d = 0), lobes of 10 degrees, at 80 and 89 degrees."""
    film = TransmissionLayer(P_d=0.0, P_t=0.05, n=0.1, eta=1.19)
    skin = ReflectionLayer(P_d=0.0, P_s=2.0, n=0.1, eta=1.26)
    wi = direction(np.radians([80.0, 89.0]), math.pi)
    wo = direction(np.radians([80.0, 89.0]), 0.0)
    values = [two_layer.layered_reflection(wi, wo, film, skin, level=level) for level in (0, 1)]
    change = np.abs(values[0] - values[1]) / values[1]
    print(f"pure lobes n = 0.1: level 0-1 change {change}")
    assert np.all(change <= CONVERGENCE_RTOL)


@pytest.mark.slow
def test_converged_evaluator_reports_its_change():
    film, skin = _film_and_skin("light_ivory", "paper_bioplate")
    wi, wo = _random_pairs(12, seed=12)
    values, change, level = two_layer.layered_reflection_converged(wi, wo, film, skin)
    assert change <= CONVERGENCE_RTOL and level >= 1
    # The same evaluation again, compared to rounding: its reductions (einsum, BLAS products)
    # are not promised to repeat their order to the last bit.
    np.testing.assert_allclose(values, two_layer.layered_reflection(wi, wo, film, skin,
                                                                 level=level), rtol=1e-12)


# --- structure -----------------------------------------------------------------------------
@pytest.mark.slow
def test_layered_reciprocity():
    """The Fourier structure makes f_cs(wi, wo) = f_cs(wo, wi) exact up to rounding."""
    for foundation, skin_name in (("paper_natural", "paper_bioplate"),
                                  ("deep_mocha", "jensen_skin2")):
        film, skin = _film_and_skin(foundation, skin_name)
        wi, wo = _random_pairs(100, seed=13)
        forward = two_layer.layered_reflection(wi, wo, film, skin)
        backward = two_layer.layered_reflection(wo, wi, film, skin)
        np.testing.assert_allclose(forward, backward, rtol=1e-9, atol=0)


@pytest.mark.slow
def test_layered_rgb_channels_and_shapes():
    film, skin = _film_and_skin("deep_mocha", "jensen_skin1")  # both RGB
    scalar_skin = presets.paper().skin_reflection  # scalar skin under an RGB film
    wi, wo = _random_pairs(20, seed=14)
    for this_skin in (skin, scalar_skin):
        rgb = two_layer.layered_reflection(wi.reshape(4, 5, 3), wo.reshape(4, 5, 3), film,
                                           this_skin)
        assert rgb.shape == (4, 5, 3)
        for c in range(3):
            single_skin = this_skin.channel(c) if this_skin.channels else this_skin
            one = two_layer.layered_reflection(wi, wo, film.channel(c), single_skin)
            assert one.shape == (20,)
            np.testing.assert_allclose(rgb[..., c].ravel(), one, rtol=1e-12)


def test_layered_outside_hemisphere_is_zero():
    film, skin = _film_and_skin("paper_natural", "paper_bioplate")
    wi, wo = _random_pairs(10, seed=15)
    below = wi * np.array([1.0, 1.0, -1.0])
    assert np.all(two_layer.layered_reflection(below, wo, film, skin) == 0.0)
    assert np.all(two_layer.layered_reflection(wo, below, film, skin) == 0.0)
    assert np.all(two_layer.transmission_factor(below, film, presets.paper().dipole) == 0.0)


# --- path 4's angular factor --------------------------------------------------------------
def test_transmission_factor_fresnel():
    film = made_up_skin.film_transmission_layer(presets.made_up_skin("light_ivory"))
    theta = np.linspace(0.0, 89.0, 12)
    w = direction(np.radians(theta), 0.3)
    lossless = Dipole(sigma_s=1.0, sigma_a=0.0, eta=1.0)
    # eta_s = 1: no Fresnel at the skin, the factor is the film's transmittance.
    np.testing.assert_allclose(two_layer.transmission_factor(w, film, lossless),
                               albedo.film_transmittance(w, film), rtol=1e-12)
    dipole = presets.paper().dipole
    factor = two_layer.transmission_factor(w, film, dipole)
    assert factor.shape == (12, 3)
    assert np.all(factor > 0) and np.all(factor < albedo.film_transmittance(w, film))
    # Independent: Int f_t(w, -u) (1 - F_r(cos u, eta_s)) cos(theta_u) du, blue channel.
    eta_s = float(dipole.eta)
    film_b = layer_args(film, 2)

    def kernel(wa, u):
        weight = 1.0 - ref.vector_fresnel(u[..., 2], eta_s)
        return ref.vector_transmission_down(wa, u, *film_b) * weight

    sums = [ref.brute_force_albedo(kernel, w, n, 2 * n) for n in (64, 128)]
    brute = (4 * sums[1] - sums[0]) / 3
    accuracy = np.abs(sums[1] - sums[0]) / 3 / brute
    np.testing.assert_allclose(factor[:, 2], brute, rtol=max(accuracy.max(), 1e-6))
