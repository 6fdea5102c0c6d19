"""Single-layer functions of lut_baker.model.microfacet (docs/model.md §2.1, §2.2): known values,
broadcasting, RGB channels, agreement with the independent reference
(tests/support/reference_impl.py) in the paper's raw units, reciprocity, input validation and
hemisphere masking; the dipole's broadcasting and argument checks run alongside."""

import math

import numpy as np
import pytest
from support import reference_impl as ref
from support.samples import (
    DIPOLES,
    RAW_REFLECTION,
    RAW_TRANSMISSION,
    grazing_pairs,
    layer_args,
    random_upper,
    unit,
)

from lut_baker.model import microfacet, presets
from lut_baker.model.dipole import dipole_profile, dipole_total_reflectance
from lut_baker.model.layers import TransmissionLayer

RTOL = 1e-10


# --- known values --------------------------------------------------------------------------
@pytest.mark.parametrize("eta", [0.5, 1.0, 1.0001, 1.19, 1.26, 1.33, 1.5, 2.42, 10.0])
def test_fresnel_normal_incidence(eta):
    assert microfacet.fresnel_reflectance(1.0, eta, check=True) == pytest.approx(
        ((eta - 1) / (eta + 1)) ** 2, rel=1e-12, abs=1e-15)


def test_fresnel_normal_incidence_rgb():
    eta = np.array([1.19, 1.33, 1.5])
    np.testing.assert_allclose(microfacet.fresnel_reflectance(1.0, eta, check=True),
                               ((eta - 1) / (eta + 1)) ** 2, rtol=1e-12)


@pytest.mark.parametrize("eta", [0.6, 1.0001, 1.19, 1.5, 3.0])
def test_fresnel_grazing_is_one(eta):
    """Any interface reflects everything at grazing incidence (without one, see below)."""
    assert microfacet.fresnel_reflectance(0.0, eta, check=True) == pytest.approx(1.0, abs=1e-12)


def test_fresnel_mixed_indices_per_channel_match_each_index_alone():
    """Indices below 1 (total internal reflection) beside indices above it, and above it
    alone (where the formula skips the total-internal-reflection branch): each channel is
    what its index gives on its own."""
    c = np.linspace(0.0, 1.0, 41)[:, None]
    for eta in (np.array([0.7, 1.0, 1.5]), np.array([1.0, 1.19, 2.4]), np.array([0.5, 0.9, 0.95])):
        together = microfacet.fresnel_reflectance(c, eta)
        alone = np.stack([microfacet.fresnel_reflectance(c[:, 0], float(e)) for e in eta], -1)
        np.testing.assert_allclose(together, alone, rtol=1e-15, atol=1e-300)
    assert microfacet.fresnel_reflectance(np.array([np.nan]), 1.5)[0] == 0.0  # as for eta < 1
    assert microfacet.fresnel_reflectance(np.array([np.nan]), 0.7)[0] == 0.0


def test_fresnel_arrays_agree_with_single_cosines_and_keep_their_input():
    """An array of cosines (worked on in place where no total internal reflection can occur)
    gives what each cosine gives alone (the formula on scalars), NaN and index-matched
    grazing included, and leaves the caller's array as it was."""
    c = np.array([0.0, 5e-324, 1e-8, 0.2, 0.5, 0.99, 1.0, np.nan])
    kept = c.copy()
    for eta in (1.0, 1.0 + 1e-12, 1.19, 1.5, 2.42, np.float64(1.33), np.array(1.45)):
        together = microfacet.fresnel_reflectance(c, eta)
        alone = [float(microfacet.fresnel_reflectance(float(value), eta)) for value in c]
        np.testing.assert_allclose(together, alone, rtol=1e-15, atol=1e-300)
        assert together[-1] == 0.0 and together.shape == c.shape
        np.testing.assert_array_equal(c, kept)
    assert microfacet.fresnel_reflectance(c[:1], 1.0)[0] == 0.0  # no interface, grazing


def test_fresnel_index_matched_is_zero():
    """eta = 1: no interface, no reflection at any incidence, grazing included, and the
    values next to eta = 1 approach it continuously."""
    c = np.array([0.0, 5e-324, 1e-300, 1e-200, 1e-12, 1e-8, 1e-4, 0.3, 1.0])
    np.testing.assert_array_equal(microfacet.fresnel_reflectance(c, 1.0, check=True), 0.0)
    # Beyond the grazing zone cos < sqrt(2 |eta - 1|) ~ 1.4e-6 the values are near 0.
    near = microfacet.fresnel_reflectance(c[6:], np.array([[1.0 - 1e-12], [1.0 + 1e-12]]),
                                          check=True)
    assert np.all(near < 1e-8)


def test_fresnel_index_matched_is_zero_at_grazing_per_channel():
    """An RGB eta with one channel at 1: that channel is 0 at grazing, the others 1; the
    inner loops' unchecked form agrees."""
    eta = np.array([1.19, 1.0, 1.5])
    np.testing.assert_array_equal(microfacet.fresnel_reflectance(0.0, eta, check=True),
                                  [1.0, 0.0, 1.0])
    np.testing.assert_array_equal(microfacet.fresnel_reflectance(np.zeros((4, 1)), eta),
                                  [[1.0, 0.0, 1.0]] * 4)
    assert microfacet.fresnel_reflectance(0, 1, check=True) == 0.0


def test_fresnel_total_internal_reflection():
    eta = 1.0 / 1.5
    cos_critical = math.sqrt(1.0 - eta**2)
    c = np.linspace(0.0, cos_critical * (1 - 1e-9), 50)
    np.testing.assert_array_equal(microfacet.fresnel_reflectance(c, eta, check=True), 1.0)
    beyond = microfacet.fresnel_reflectance(np.linspace(cos_critical * 1.01, 1.0, 50), eta,
                                            check=True)
    assert np.all(beyond < 1.0) and np.all(np.diff(beyond) < 0)


def test_fresnel_matches_reference():
    """Everywhere but (c = 0, eta = 1), where the reference keeps the limit 1 of the formula
    and the model the physical 0 (no interface; see test_fresnel_index_matched_is_zero)."""
    c = np.linspace(0.0, 1.0, 101)
    for eta in (0.7, 1.0, 1.19, 2.0):
        x = c[1:] if eta == 1.0 else c
        expected = [ref.fresnel(value, eta) for value in x]
        np.testing.assert_allclose(microfacet.fresnel_reflectance(x, eta, check=True), expected,
                                   rtol=RTOL)


@pytest.mark.parametrize("n", [1e-6, 3.29e-2, 0.04, 1.0, 50.0])
def test_distribution_half_width(n):
    """The lobe's 1/e half-width is 1/n degrees (docs/model.md §2.1)."""
    assert microfacet.distribution_term(1.0 / n, n, check=True) == pytest.approx(
        math.exp(-1.0), rel=1e-12)
    assert microfacet.distribution_term(0.0, n, check=True) == 1.0


@pytest.mark.parametrize("nh, nv, nl, vh, expected", [
    (1.0, 1.0, 1.0, 1.0, 1.0),  # mirror at normal incidence: unshadowed
    (0.9, 0.3, 0.8, 0.7, 2 * 0.9 * 0.3 / 0.7),  # masking of the view
    (0.9, 0.8, 0.2, 0.7, 2 * 0.9 * 0.2 / 0.7),  # shadowing of the light
    (0.8, 0.0, 0.9, 0.5, 0.0),  # grazing view
    (1.0, 0.0, 0.0, 0.0, 0.0),  # opposite horizontal pair: VH = 0
])
def test_attenuation_term_cases(nh, nv, nl, vh, expected):
    assert microfacet.attenuation_term(nh, nv, nl, vh, check=True) == pytest.approx(expected,
                                                                                 rel=1e-12)


def test_reflection_at_normal_mirror_known_value():
    layer = presets.PAPER_SKIN_REFLECTION
    z = np.array([0.0, 0.0, 1.0])
    expected = 2.00e4 + 2.05e5 * 1.0 * 1.0 * ((1.26 - 1) / (1.26 + 1)) ** 2
    assert microfacet.ts_reflection(z, z, layer) == pytest.approx(expected, rel=1e-12)


# --- broadcasting and channels -------------------------------------------------------------
BATCHED = {"rtol": 1e-12, "atol": 1e-300}
"""A batch against the same pairs one at a time: numpy may take other (SIMD or scalar) loops
for other shapes, so the two agree to rounding, not bit for bit."""


def test_nd_directions_broadcast():
    rng = np.random.default_rng(1)
    wi = random_upper(rng, 20).reshape(4, 5, 3)
    wo = random_upper(rng, 20).reshape(4, 5, 3)
    wt = -random_upper(rng, 20).reshape(4, 5, 3)
    for func, a, b, layer in [
        (microfacet.ts_reflection, wi, wo, RAW_REFLECTION["film"]),
        (microfacet.ts_transmission, wi, wt, RAW_TRANSMISSION["film"]),
        (microfacet.ts_reflection, wi, wo, RAW_REFLECTION["rgb"]),
    ]:
        whole = func(a, b, layer)
        assert whole.shape == (4, 5) + layer.channels
        flat = np.array([func(x, y, layer) for x, y in zip(a.reshape(-1, 3), b.reshape(-1, 3),
                                                            strict=True)])
        np.testing.assert_allclose(whole.reshape(flat.shape), flat, **BATCHED)
    one = microfacet.ts_reflection(wi[0, 0], wo, RAW_REFLECTION["film"])  # (3,) with (4, 5, 3)
    np.testing.assert_allclose(one, microfacet.ts_reflection(
        np.broadcast_to(wi[0, 0], wo.shape), wo, RAW_REFLECTION["film"]), **BATCHED)
    d = np.linspace(0, 3, 20).reshape(4, 5)
    profile = dipole_profile(d, DIPOLES["jensen_skin1"])
    assert profile.shape == (4, 5, 3)
    np.testing.assert_allclose(profile[1, 2], dipole_profile(d[1, 2], DIPOLES["jensen_skin1"]),
                               **BATCHED)


def test_rgb_layer_equals_scalar_layer_per_channel():
    rng = np.random.default_rng(2)
    wi, wo = random_upper(rng, 50), random_upper(rng, 50)
    d = np.linspace(0.0, 5.0, 30)
    cases = [
        (microfacet.ts_reflection, (wi, wo), RAW_REFLECTION["rgb"]),
        (microfacet.ts_transmission, (wi, -wo), RAW_TRANSMISSION["rgb"]),
        (dipole_profile, (d,), DIPOLES["jensen_skin2"]),
        (dipole_total_reflectance, (), DIPOLES["jensen_skin2"]),
    ]
    for func, args, layer in cases:
        rgb = func(*args, layer)
        assert rgb.shape[-1] == 3
        for c in range(3):
            scalar = func(*args, layer.channel(c))
            assert np.shape(scalar) == rgb.shape[:-1]
            np.testing.assert_allclose(rgb[..., c], scalar, rtol=1e-14)


# --- agreement with the independent reference ----------------------------------------------
def _assert_matches_reference(function, reference, pairs, layer):
    """``function(wi, wo, layer)`` on all pairs at once == the scalar reference, per channel."""
    got = function(np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs]), layer)
    for c in range(3) if layer.channels else [None]:
        args = layer_args(layer, c)
        expected = np.array([reference(a, b, *args) for a, b in pairs])
        np.testing.assert_allclose(got if c is None else got[:, c], expected, rtol=RTOL)


@pytest.mark.parametrize("name", sorted(RAW_REFLECTION))
def test_reflection_matches_reference(name):
    layer = RAW_REFLECTION[name]
    rng = np.random.default_rng(3)
    pairs = list(zip(random_upper(rng, 200), random_upper(rng, 200), strict=True))
    pairs += grazing_pairs()
    _assert_matches_reference(microfacet.ts_reflection, ref.ts_reflection, pairs, layer)


@pytest.mark.parametrize("name", sorted(RAW_TRANSMISSION))
def test_transmission_matches_reference(name):
    layer = RAW_TRANSMISSION[name]
    rng = np.random.default_rng(4)
    pairs = list(zip(random_upper(rng, 200), -random_upper(rng, 200), strict=True))
    # Grazing pairs with the second direction moved below, and light crossing upward.
    pairs += [(a, b * np.array([1, 1, -1])) for a, b in grazing_pairs()]
    pairs += [(b * np.array([1, 1, -1]), a) for a, b in grazing_pairs()]
    _assert_matches_reference(microfacet.ts_transmission, ref.ts_transmission, pairs, layer)


# --- reciprocity and the transmission lobe -------------------------------------------------
def test_reflection_reciprocity():
    rng = np.random.default_rng(5)
    wi, wo = random_upper(rng, 500), random_upper(rng, 500)
    for layer in RAW_REFLECTION.values():
        np.testing.assert_allclose(microfacet.ts_reflection(wi, wo, layer),
                                   microfacet.ts_reflection(wo, wi, layer), rtol=1e-12)


def test_transmission_reciprocity_and_mirror_symmetry():
    rng = np.random.default_rng(6)
    wi = random_upper(rng, 500)
    wt = -random_upper(rng, 500)
    pairs = grazing_pairs()
    wi = np.concatenate([wi, [a for a, _ in pairs]])
    wt = np.concatenate([wt, [b * np.array([1, 1, -1]) for _, b in pairs]])
    mirror = np.array([1.0, 1.0, -1.0])
    for layer in RAW_TRANSMISSION.values():
        forward = microfacet.ts_transmission(wi, wt, layer)
        np.testing.assert_allclose(microfacet.ts_transmission(-wt, -wi, layer), forward, rtol=RTOL)
        np.testing.assert_allclose(microfacet.ts_transmission(wi * mirror, wt * mirror, layer),
                                   forward, rtol=RTOL)


def test_transmission_lobe_peaks_straight_through():
    """D(beta) peaks at wt = -wi (docs/model.md §2.2): exactly so when F_t is flat (eta = 1), and at
    normal incidence for any eta.  (With eta > 1 the factor F_t pulls the peak toward the
    normal at oblique incidence; see the report.)"""
    for eta, angles in ((1.0, (0.0, 30.0, 60.0, 85.0)), (1.19, (0.0,))):
        layer = TransmissionLayer(P_d=10.0, P_t=100.0, n=0.0346, eta=eta)
        for theta in angles:
            wi = np.array([math.sin(math.radians(theta)), 0.0, math.cos(math.radians(theta))])
            straight = microfacet.ts_transmission(wi, -wi, layer)
            assert straight == pytest.approx(10.0 + 100.0 * (1 - ref.fresnel(wi[2], eta)))
            rng = np.random.default_rng(7)
            around = -unit(wi + 0.3 * rng.normal(size=(400, 3)))
            around = around[around[:, 2] < 0]
            assert np.all(microfacet.ts_transmission(wi, around, layer) < straight)


# --- validation ----------------------------------------------------------------------------
@pytest.mark.parametrize("bad, message", [
    (np.array([0.0, 0.0]), r"wi must have shape \(\.\.\., 3\)"),
    (np.array(1.0), r"wi must have shape \(\.\.\., 3\)"),
    (np.array([0.0, 0.0, 1.1]), r"wi must be unit vectors \(\|w\| = 1 within 1e-6\)"),
    (np.array([0.0, 0.0, 0.0]), r"wi must be unit vectors"),
    (np.array([np.nan, 0.0, 1.0]), r"wi must be finite unit vectors"),
])
def test_direction_validation(bad, message):
    z = np.array([0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match=message):
        microfacet.ts_reflection(bad, z, RAW_REFLECTION["film"])
    with pytest.raises(ValueError, match=message):
        microfacet.ts_transmission(bad, -z, RAW_TRANSMISSION["film"])
    with pytest.raises(ValueError, match=message.replace("wi must", "wo must")):
        microfacet.ts_reflection(z, bad, RAW_REFLECTION["film"])
    with pytest.raises(ValueError, match=message.replace("wi must", "wt must")):
        microfacet.ts_transmission(z, bad, RAW_TRANSMISSION["film"])


def test_function_argument_validation():
    with pytest.raises(ValueError, match=r"eta must lie in \(0, inf\)"):
        microfacet.fresnel_reflectance(0.5, 0.0, check=True)
    with pytest.raises(ValueError, match=r"eta must lie in \(0, inf\)"):
        microfacet.fresnel_reflectance(0.5, float("nan"), check=True)
    with pytest.raises(ValueError, match=r"cos_theta must lie in \[0, 1\]"):
        microfacet.fresnel_reflectance(float("nan"), 1.3, check=True)
    with pytest.raises(ValueError, match=r"cos_theta must lie in \[0, 1\]"):
        microfacet.fresnel_reflectance(1.5, 1.3, check=True)
    with pytest.raises(ValueError, match=r"d_mm must be distances >= 0 \(mm\)"):
        dipole_profile(-0.1, DIPOLES["paper"])
    with pytest.raises(ValueError, match=r"d_mm must be distances >= 0 \(mm\)"):
        dipole_profile([0.1, float("nan")], DIPOLES["paper"])
    with pytest.raises(ValueError, match=r"n must lie in \(0, inf\)"):
        microfacet.distribution_term(1.0, 0.0, check=True)
    with pytest.raises(ValueError, match=r"angle_deg must be finite"):
        microfacet.distribution_term(float("nan"), 0.04, check=True)
    with pytest.raises(ValueError, match=r"must lie in \[0, 1\]"):
        microfacet.attenuation_term(float("nan"), 0.5, 0.5, 0.5, check=True)


# --- hemispheres ---------------------------------------------------------------------------
def test_outside_hemisphere_is_zero():
    rng = np.random.default_rng(8)
    up, up2 = random_upper(rng, 100), random_upper(rng, 100)
    up[:, 2] += 1e-3  # strictly above the horizon
    up, up2 = unit(up), unit(up2 + [0, 0, 1e-3])
    for layer in RAW_REFLECTION.values():
        assert np.all(microfacet.ts_reflection(-up, up2, layer) == 0.0)
        assert np.all(microfacet.ts_reflection(up, -up2, layer) == 0.0)
    for layer in RAW_TRANSMISSION.values():
        assert np.all(microfacet.ts_transmission(up, up2, layer) == 0.0)
        assert np.all(microfacet.ts_transmission(-up, -up2, layer) == 0.0)
    # The same pairs inside the hemispheres are not 0 (the masks above are not vacuous).
    assert np.all(microfacet.ts_reflection(up, up2, RAW_REFLECTION["film"]) > 0.0)
    assert np.all(microfacet.ts_transmission(up, -up2, RAW_TRANSMISSION["film"]) > 0.0)
    assert np.all(microfacet.ts_transmission(-up, up2, RAW_TRANSMISSION["film"]) > 0.0)


# --- one formula, two geometries -------------------------------------------------------------
def test_polar_angle_cosines_give_the_vector_values():
    """The bake evaluates eqs. 2 and 4 from polar angles and a relative azimuth
    (half_vector_cosines), the exact evaluator from unit vectors: the same formulas over the
    same cosines, so the two agree to rounding."""
    rng = np.random.default_rng(9)
    wa, wb = random_upper(rng, 200), random_upper(rng, 200)
    cos_a, cos_b = wa[:, 2], wb[:, 2]
    sin_a, sin_b = np.hypot(wa[:, 0], wa[:, 1]), np.hypot(wb[:, 0], wb[:, 1])
    cos_phi = (wa[:, 0] * wb[:, 0] + wa[:, 1] * wb[:, 1]) / (sin_a * sin_b)
    n_dot_h, v_dot_h = microfacet.half_vector_cosines(cos_a, sin_a, cos_b, sin_b, cos_phi)
    cosines = [x[:, None] for x in (n_dot_h, v_dot_h, cos_b, cos_a)]
    for layer in RAW_REFLECTION.values():
        np.testing.assert_allclose(microfacet.ts_reflection_from_cosines(*cosines, layer),
                                   np.reshape(microfacet.ts_reflection(wa, wb, layer), (200, -1)),
                                   rtol=1e-11)
    # f_t(wa, -wb): the lobe is the mirror image, at azimuth phi + pi
    n_dot_h, v_dot_h = microfacet.half_vector_cosines(cos_a, sin_a, cos_b, sin_b, -cos_phi)
    for layer in RAW_TRANSMISSION.values():
        np.testing.assert_allclose(
            microfacet.ts_transmission_from_cosines(n_dot_h[:, None], v_dot_h[:, None], layer),
            np.reshape(microfacet.ts_transmission(wa, -wb, layer), (200, -1)), rtol=1e-11)
