"""The dipole of lut_baker.model.dipole (docs/model.md §2.3): agreement with the independent
reference (tests/support/reference_impl.py), the closed form of its integral, its value at
zero distance and the lossless limit."""

import math

import numpy as np
import pytest
from support import reference_impl as ref
from support.samples import DIPOLES, layer_args

from lut_baker.model.dipole import dipole_profile, dipole_total_reflectance
from lut_baker.model.layers import Dipole

RTOL = 1e-10


@pytest.mark.parametrize("name", sorted(DIPOLES))
def test_dipole_profile_matches_reference(name):
    dipole = DIPOLES[name]
    d = np.concatenate([[0.0, 1e-9], np.geomspace(1e-4, 50.0, 60)])
    got = dipole_profile(d, dipole)
    for c in range(3) if dipole.channels else [None]:
        expected = [ref.dipole_profile(x, *layer_args(dipole, c)) for x in d]
        np.testing.assert_allclose(got if c is None else got[:, c], expected, rtol=RTOL)


# --- dipole --------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(DIPOLES))
def test_dipole_integral_equals_closed_form(name):
    from scipy.integrate import quad  # here: importing scipy.integrate slows collection ~0.3 s

    dipole = DIPOLES[name]
    closed = np.atleast_1d(dipole_total_reflectance(dipole))
    for c in range(closed.size):
        channel = dipole.channel(c) if dipole.channels else dipole

        def integrand(d, channel=channel):
            return 2.0 * math.pi * float(dipole_profile(d, channel)) * d

        # Split at a few mean free paths: the profile is sharp near d = 0, slow in its tail.
        z = 1.0 / float(channel.sigma_s * (1 - channel.g) + channel.sigma_a)
        near, _ = quad(integrand, 0.0, 10 * z, limit=200, epsabs=1e-12, epsrel=1e-10)
        far, _ = quad(integrand, 10 * z, np.inf, limit=200, epsabs=1e-12, epsrel=1e-10)
        assert near + far == pytest.approx(closed[c], rel=1e-4)


def test_dipole_finite_at_zero_distance():
    for dipole in DIPOLES.values():
        at_zero = np.atleast_1d(dipole_profile(0.0, dipole))
        assert np.all(np.isfinite(at_zero)) and np.all(at_zero > 0)
        np.testing.assert_allclose(at_zero, np.atleast_1d(dipole_profile(1e-9, dipole)),
                                   rtol=1e-9)


def test_dipole_lossless_reflects_everything():
    """sigma_a = 0: nothing is absorbed, Rd = 1 (the closed form's limit)."""
    assert dipole_total_reflectance(Dipole(sigma_s=1.0, sigma_a=0.0)) == pytest.approx(1.0)
