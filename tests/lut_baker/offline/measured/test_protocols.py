"""The paper's measurement geometries (lut_baker.offline.measured.protocols, docs/model.md §6)."""

import numpy as np
import pytest

from lut_baker.offline.measured import protocols


def test_step_rule_is_fine_near_the_peak_and_coarse_far_from_it():
    angles = protocols.step_angles(30.0)
    assert angles[0] == -angles[-1] and 0.0 in angles
    steps = np.diff(angles[angles >= 0.0])
    positive = angles[angles > 0.0]
    for bound, step in protocols.STEP_RULE:
        inside = positive <= bound
        if np.any(inside):
            assert np.all(steps[: np.count_nonzero(inside)] <= step + 1e-9)
    assert steps[0] == pytest.approx(0.2) and steps[-1] == pytest.approx(3.0)
    assert angles[-1] <= 30.0


def test_reflection_geometry_keeps_light_and_camera_psi_apart():
    sweep = protocols.reflection_sweep(60.0)
    cos_psi = np.sum(sweep.wi * sweep.wo, axis=-1)
    np.testing.assert_allclose(cos_psi, np.cos(np.radians(60.0)), atol=1e-12)
    assert np.all(np.abs(sweep.theta_i_deg) <= 85.0) and np.all(np.abs(sweep.theta_r_deg) <= 85.0)
    np.testing.assert_allclose(sweep.theta_i_deg - sweep.theta_r_deg, 60.0)


def test_transmission_geometry_is_straight_through_at_beta_zero():
    sweep = protocols.transmission_sweep(30.0)
    zero = np.flatnonzero(sweep.beta_deg == 0.0)
    assert zero.size == 1
    np.testing.assert_allclose(sweep.wt[zero[0]], -sweep.wi[zero[0]], atol=1e-12)
    assert np.all(sweep.wt[:, 2] <= 0.0) and np.all(sweep.wi[:, 2] > 0.0)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: protocols.step_angles(0.0), "limit_deg"),
    (lambda: protocols.reflection_sweep(180.0), "relative_angle_deg"),
    (lambda: protocols.transmission_sweep(90.0), "incidence_deg"),
    (lambda: protocols.profile_distances(step_mm=0.0), "step_mm"),
])
def test_bad_geometry_is_a_clear_error(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_profile_distances_include_both_ends():
    d = protocols.profile_distances(1.0, 0.25)
    np.testing.assert_allclose(d, [0.0, 0.25, 0.5, 0.75, 1.0])


def test_a_tilt_adds_to_every_in_plane_angle_and_offsets_alpha():
    angles = np.array([-40.0, 0.0, 25.0, 80.0])
    np.testing.assert_allclose(protocols.tilted(protocols.in_plane_direction(angles), 1.5),
                               protocols.in_plane_direction(angles + 1.5), atol=1e-15)
    # In the reflection protocol a tilted sample is one rotated further: alpha + tilt.
    sweep = protocols.reflection_geometry(60.0, np.array([-10.0, 0.0, 7.0]))
    shifted = protocols.reflection_geometry(60.0, sweep.alpha_deg + 2.0)
    np.testing.assert_allclose(protocols.tilted(sweep.wi, 2.0), shifted.wi, atol=1e-15)
    np.testing.assert_allclose(protocols.tilted(sweep.wo, 2.0), shifted.wo, atol=1e-15)
