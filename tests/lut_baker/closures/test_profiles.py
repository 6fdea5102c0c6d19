"""The subsurface radius fits (lut_baker.closures.profiles): the edge response of a known
profile, and a known radius fitted back."""

import dataclasses

import numpy as np
import pytest

from lut_baker.closures import cycles as cc
from lut_baker.closures import profiles
from lut_baker.tables.table_set import radius_nodes


def test_edge_response_of_a_uniform_disc():
    # P = 1 / (pi a^2) inside r < a: ESF(s) = (a^2 acos(s/a) - s sqrt(a^2 - s^2)) / (pi a^2).
    a = 2.0
    r = np.linspace(0.0, 3.0, 300001)
    disc = np.where(r < a, 1.0 / (np.pi * a * a), 0.0)
    s = np.array([0.0, 0.5, 1.0, 1.9])
    expected = (a * a * np.arccos(s / a) - s * np.sqrt(a * a - s * s)) / (np.pi * a * a)
    np.testing.assert_allclose(profiles.edge_response(r, disc, s), expected, atol=1e-4)


# ---------------------------------------------------------------------------------------------
# Fits: round trips
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("method", cc.SUBSURFACE_METHODS)
def test_fit_profile_recovers_a_known_radius(paper_tables, method):
    # A fine quadratic radius grid: Burley's profile is singular (1/r) at 0.
    r = radius_nodes(2000, "quadratic", 20.0)
    radius = np.array([3.0, 1.5, 0.8])
    profile = np.stack([cc.subsurface_profile(np.maximum(r, r[1] / 2), radius[c], 0.6, method)
                        for c in range(3)], -1)
    tables = dataclasses.replace(paper_tables, radius_mm=r, profile=profile)
    fit = profiles.fit_profile(tables, method, albedo=0.6)
    np.testing.assert_allclose(fit.radius_mm, radius, rtol=0.02)
    assert fit.worst_error < 0.005


# ---------------------------------------------------------------------------------------------
# The tiers on the paper's tables
# ---------------------------------------------------------------------------------------------
