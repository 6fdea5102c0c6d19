"""Stability where the formulas are fragile: property-based tests over the valid parameter ranges
with the edge values forced in (normal incidence, exactly 90 degrees, wi == wo, eta -> 1,
sigma_a -> 0, d = 0, n from 1e-6 to 50 per degree).  Every public function must return finite,
non-negative values; the quadrature grid must follow the lobe width."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from lut_baker.evaluate import made_up, two_layer
from lut_baker.model import albedo, made_up_skin, microfacet
from lut_baker.model.dipole import dipole_profile, dipole_total_reflectance
from lut_baker.model.layers import Dipole, ReflectionLayer, TransmissionLayer

FAST = settings(max_examples=60, deadline=None, derandomize=True)
SLOW = settings(max_examples=6, deadline=None, derandomize=True)  # quadrature: ~1-2 s a call


def _edge_or(edges, low, high):
    """One of the edge values, or a float in [low, high]."""
    return st.one_of(st.sampled_from(edges), st.floats(low, high))


# polar angles (degrees) with normal incidence and the exact horizon forced in
THETA = _edge_or([0.0, 90.0, 89.9, 1e-9, 90.0 - 1e-9], 0.0, 90.0)
PHI = _edge_or([0.0, math.pi, -math.pi / 2], -math.pi, math.pi)
N = st.one_of(st.sampled_from([1e-6, 50.0, 0.0329, 0.2]),
              st.floats(-6.0, math.log10(50.0)).map(lambda e: 10.0**e))
ETA = _edge_or([1.0, 1.0 + 1e-9, 1.0 - 1e-9, 1.19, 0.5], 0.2, 5.0)
ETA_DIPOLE = _edge_or([1.0, 1.0 + 1e-9, 1.26], 1.0, 3.0)
P = _edge_or([0.0, 1.0], 0.0, 1e6)
ALBEDO_P = _edge_or([0.0, 0.3], 0.0, 1.0)  # albedo units (1/sr)
SIGMA = _edge_or([0.0, 1e-12, 2.83], 0.0, 100.0)
SIGMA_A = _edge_or([0.0, 1e-12, 2.82e-2], 0.0, 100.0)
G_PHASE = _edge_or([0.0, 0.9, -0.9], -0.99, 0.99)
DISTANCE = _edge_or([0.0, 1e-12, 1e3], 0.0, 100.0)


def _direction(theta_deg, phi):
    """Unit vector; z is exactly 0 at 90 degrees and exactly 1 at 0."""
    if theta_deg == 90.0:
        return np.array([math.cos(phi), math.sin(phi), 0.0])
    t = math.radians(theta_deg)
    return np.array([math.sin(t) * math.cos(phi), math.sin(t) * math.sin(phi), math.cos(t)])


DIRECTION = st.builds(_direction, THETA, PHI)
REFLECTION = st.builds(ReflectionLayer, P_d=P, P_s=P, n=N, eta=ETA)
TRANSMISSION = st.builds(TransmissionLayer, P_d=P, P_t=P, n=N, eta=ETA)
FILM_T = st.builds(TransmissionLayer, P_d=ALBEDO_P, P_t=ALBEDO_P, n=N, eta=ETA)
SKIN = st.builds(ReflectionLayer, P_d=ALBEDO_P, P_s=ALBEDO_P, n=N, eta=ETA)


@st.composite
def dipoles(draw):
    sigma_s, sigma_a, g = draw(SIGMA), draw(SIGMA_A), draw(G_PHASE)
    assume(sigma_s * (1 - g) + sigma_a > 0)
    return Dipole(sigma_s=sigma_s, sigma_a=sigma_a, g=g, eta=draw(ETA_DIPOLE))


def _sane(values):
    values = np.asarray(values)
    assert np.all(np.isfinite(values)), values
    assert np.all(values >= 0.0), values


@FAST
@given(DIRECTION, DIRECTION, REFLECTION)
def test_reflection_stable(wi, wo, layer):
    for a, b in ((wi, wo), (wi, wi), (wo, wo), (wi, -wo * [1, 1, -1])):
        value = microfacet.ts_reflection(a, b, layer)
        _sane(value)
        assert value >= layer.P_d * (1 - 1e-12)  # the lobe only adds


@FAST
@given(DIRECTION, DIRECTION, TRANSMISSION)
def test_transmission_stable(wi, wt, layer):
    below = wt * np.array([1.0, 1.0, -1.0])
    for a, b in ((wi, below), (wi, -wi), (below, wi), (-wi, wi)):
        value = microfacet.ts_transmission(a, b, layer)
        _sane(value)
        assert value <= layer.P_d + layer.P_t + 1e-9 * (layer.P_d + layer.P_t)


@FAST
@given(st.floats(0.0, 1.0), ETA)
def test_fresnel_stable(c, eta):
    value = microfacet.fresnel_reflectance(c, eta, check=True)
    _sane(value)
    assert value <= 1.0


@FAST
@given(DISTANCE, dipoles())
def test_dipole_stable(d, dipole):
    profile = dipole_profile(np.array([0.0, d]), dipole)
    _sane(profile)
    total = dipole_total_reflectance(dipole)
    _sane(total)
    assert total <= 1.0 + 1e-12


@pytest.mark.slow
@settings(parent=SLOW, max_examples=4)  # each example runs the exact evaluator: 5-10 s
@given(DIRECTION, DIRECTION, FILM_T, SKIN)
def test_layered_reflection_stable(wi, wo, film, skin):
    wi_set = np.stack([wi, wo, np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])])
    wo_set = np.stack([wo, wo, np.array([0.0, 0.0, 1.0]), np.array([-1.0, 0.0, 0.0])])
    _sane(two_layer.layered_reflection(wi_set, wo_set, film, skin))


@pytest.mark.slow
@FAST
@given(DIRECTION, FILM_T, dipoles())
def test_film_factors_stable(w, film, dipole):
    factor = two_layer.transmission_factor(w, film, dipole)
    through = albedo.film_transmittance(w, film)
    _sane(factor)
    _sane(through)
    # The skin's Fresnel transmission F_t <= 1 only removes light.
    assert factor <= through * (1 + 1e-12) + 1e-300


@pytest.mark.slow
@settings(parent=SLOW, max_examples=3)  # each example integrates the exact model: 15-25 s
@given(THETA, FILM_T, SKIN, ALBEDO_P, st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_directional_albedo_stable(theta, film_t, skin, film_p_s, coverage, absorption):
    film = ReflectionLayer(P_d=film_t.P_d, P_s=film_p_s, n=film_t.n, eta=film_t.eta)
    bundle = made_up_skin.MadeUpSkin(film=film, film_transmission=film_t, skin_reflection=skin,
                                  dipole=Dipole(sigma_s=1.0, sigma_a=0.1), coverage=coverage,
                                  absorption=absorption)
    value = made_up.directional_albedo(np.array([0.0, theta, 90.0]), bundle)
    assert value.shape == (3, 3)
    _sane(value)


def test_grid_follows_the_lobe_width():
    """Narrower lobes (larger n, lobe half-width 1/n degrees) get finer azimuth and polar steps,
    up to the clamp at quadrature.NARROWEST_LOBE_DEG; never coarser as n grows."""
    from lut_baker.numerics.quadrature import NARROWEST_LOBE_DEG

    n_values = np.geomspace(1e-6, 50.0, 40)
    grids = [albedo.grid_for(TransmissionLayer(P_d=1.0, P_t=1.0, n=n, eta=1.3))
             for n in n_values]
    n_phi = np.array([g.n_phi for g in grids])
    n_theta = np.array([g.theta.size for g in grids])
    assert np.all(np.diff(n_phi) >= 0) and np.all(np.diff(n_theta) >= 0)
    assert n_phi[-1] > 4 * n_phi[0] and n_theta[-1] > n_theta[0]
    clamp = 1.0 / NARROWEST_LOBE_DEG
    below = n_values <= clamp
    # Below the clamp, at least 4 azimuth samples per lobe width at the horizon.
    widths = 1.0 / n_values[below]
    resolved = np.minimum(widths, 90.0)
    assert np.all(n_phi[below] >= 4 * 360.0 / resolved)
    # The narrowest layer sets the grid of a pair.
    wide = ReflectionLayer(P_d=1.0, P_s=1.0, n=0.01, eta=1.3)
    narrow = TransmissionLayer(P_d=1.0, P_t=1.0, n=0.15, eta=1.3)
    assert albedo.grid_for(wide, narrow).n_phi == albedo.grid_for(narrow).n_phi
    assert albedo.grid_for(wide, narrow, level=1).n_phi > albedo.grid_for(wide, narrow).n_phi
