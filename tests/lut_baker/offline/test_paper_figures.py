"""The paper's figures (lut_baker.offline.paper_figures): the plotted numbers are the model's
(tests read the drawn lines back by their ``gid``, not pixels)."""

import numpy as np
import pytest

from lut_baker.model.dipole import dipole_profile, dipole_total_reflectance
from lut_baker.model.microfacet import ts_reflection, ts_transmission
from lut_baker.model.presets import (
    PAPER_FILM_REFLECTION,
    PAPER_FILM_TRANSMISSION,
    PAPER_SKIN_DIPOLE,
    PAPER_SKIN_REFLECTION,
)
from lut_baker.offline import paper_figures
from lut_baker.offline.measured.protocols import reflection_sweep, transmission_sweep


def lines(figure) -> dict:
    """The drawn data lines of a one-axes figure: {gid: (x, y)}."""
    (axes,) = figure.axes
    return {line.get_gid(): (np.asarray(line.get_xdata()), np.asarray(line.get_ydata()))
            for line in axes.lines if line.get_gid()}


@pytest.mark.slow
def test_every_figure_has_title_axis_labels_and_legend(drawn):
    for name, figure in drawn.items():
        (axes,) = figure.axes
        number = int(name[3:5])
        expected = f"Fig. {number}:" if number <= 15 else "Beyond the paper"
        assert axes.get_title().startswith(expected), name
        assert "(" in axes.get_xlabel() and "(" in axes.get_ylabel(), name  # units in brackets
        assert axes.get_legend() is not None, name
        assert lines(figure), name


@pytest.mark.slow
@pytest.mark.parametrize("name, curves, key", [
    ("fig05_film_reflection",
     lambda: paper_figures.reflection_curves(PAPER_FILM_REFLECTION), "psi"),
    ("fig11_skin_reflection",
     lambda: paper_figures.reflection_curves(PAPER_SKIN_REFLECTION), "psi"),
    ("fig07_film_transmission", paper_figures.transmission_curves, "theta_i"),
])
def test_drawn_angle_curves_are_the_data(drawn, name, curves, key):
    drawn_lines = lines(drawn[name])
    data = curves()
    assert set(drawn_lines) == {f"{key}={angle:g}" for angle in data}
    for angle, curve in data.items():
        x, y = drawn_lines[f"{key}={angle:g}"]
        np.testing.assert_array_equal(y, curve["intensity"])
        assert x.size == y.size > 100


@pytest.mark.parametrize("layer", [PAPER_FILM_REFLECTION, PAPER_SKIN_REFLECTION])
def test_reflection_curves_follow_the_protocol_and_peak_at_the_mirror(layer):
    curves = paper_figures.reflection_curves(layer)
    assert sorted(curves) == [30.0, 60.0, 90.0, 120.0]
    for psi, curve in curves.items():
        theta_r, brdf, intensity = curve["theta_r_deg"], curve["brdf"], curve["intensity"]
        # Light and camera psi apart; every sample of the paper's protocol is on the curve, with
        # the value the protocol's own directions give.
        np.testing.assert_allclose(curve["theta_i_deg"] - theta_r, psi)
        sweep = reflection_sweep(psi)
        at = np.isin(theta_r, sweep.theta_r_deg)
        assert at.sum() == sweep.theta_r_deg.size
        expected = ts_reflection(sweep.wi, sweep.wo, layer) * sweep.wi[:, 2]
        np.testing.assert_allclose(intensity[at], expected, rtol=1e-12)
        # The BRDF peaks in the mirror direction theta_r = -psi/2 (alpha = 0)...
        assert abs(theta_r[np.argmax(brdf)] + psi / 2) <= paper_figures.CURVE_STEP_DEG
        # ...but the camera sees f (N.L): the cosine pulls the peak toward the light's normal
        # incidence, i.e. theta_r below the mirror, by more than the sampling step.
        peak = theta_r[np.argmax(intensity)]
        assert peak < -psi / 2 - 1.0
        assert np.all(intensity > 0)


def test_the_film_is_glossier_than_the_skin():
    """Paper 4.2.1 (fig. 12's text): the skin's specular reflection is weaker than the film's."""
    film = paper_figures.reflection_curves(PAPER_FILM_REFLECTION)
    skin = paper_figures.reflection_curves(PAPER_SKIN_REFLECTION)
    for psi in film:
        def specular(curve, layer):
            return curve["intensity"] - layer.P_d * np.cos(np.radians(curve["theta_i_deg"]))

        assert (specular(film[psi], PAPER_FILM_REFLECTION).max()
                > 2.0 * specular(skin[psi], PAPER_SKIN_REFLECTION).max())


def test_transmission_curves_peak_straight_through_and_fall_with_incidence():
    curves = paper_figures.transmission_curves()
    peaks = []
    for incidence, curve in curves.items():
        theta_t, intensity = curve["theta_t_deg"], curve["intensity"]
        sweep = transmission_sweep(incidence)
        at = np.isin(theta_t, sweep.theta_t_deg)
        assert at.sum() == sweep.theta_t_deg.size
        expected = ts_transmission(sweep.wi, sweep.wt, PAPER_FILM_TRANSMISSION) * sweep.wi[:, 2]
        np.testing.assert_allclose(intensity[at], expected, rtol=1e-12)
        # The lobe is around the straight-through direction (Fresnel pulls it slightly inward).
        assert abs(theta_t[np.argmax(intensity)] - incidence) <= 3.0
        peaks.append(intensity.max())
    # Normal incidence is symmetric about theta_t = 0.
    normal = curves[0.0]
    mirrored = np.interp(-normal["theta_t_deg"], normal["theta_t_deg"], normal["intensity"])
    inside = np.abs(normal["theta_t_deg"]) <= 80
    np.testing.assert_allclose(mirrored[inside], normal["intensity"][inside], rtol=1e-9)
    # Paper 4.1.2: the larger the incidence, the darker the transmitted light.
    assert peaks == sorted(peaks, reverse=True) and peaks[-1] < 0.6 * peaks[0]


def test_profile_is_the_ratio_to_the_lit_pixel():
    curve = paper_figures.profile_curve()
    assert curve["d_mm"][0] == 0.0 and curve["d_mm"][-1] == pytest.approx(3.0)
    assert curve["ratio"][0] == 1.0
    assert np.all(np.diff(curve["ratio"]) < 0) and np.all(curve["ratio"] > 0)
    # Times R(0), the ratio integrates over the plane to the dipole's closed-form Rd (Jensen).
    far = paper_figures.profile_curve(max_mm=80.0, step_mm=0.002)
    integral = 2 * np.pi * np.trapz(far["ratio"] * far["d_mm"], far["d_mm"])
    rd = float(dipole_total_reflectance(PAPER_SKIN_DIPOLE))
    assert integral * float(dipole_profile(0.0, PAPER_SKIN_DIPOLE)) == pytest.approx(rd, rel=1e-4)


@pytest.mark.slow
def test_made_up_sum_is_path1_plus_path3(drawn):
    drawn_lines = lines(drawn["fig14_made_up_reflection"])
    assert set(drawn_lines) == {"bare", "path1", "path3", "sum w=1", "sum w=0.5"}
    (theta, path1), (_, path3) = drawn_lines["path1"], drawn_lines["path3"]
    total, half, bare = (drawn_lines[key][1] for key in ("sum w=1", "sum w=0.5", "bare"))
    # made_up_reflection at coverage 1 is paper eq. 9, computed independently of the two paths.
    np.testing.assert_allclose(total, path1 + path3, rtol=1e-12, atol=0)
    np.testing.assert_allclose(half, 0.5 * bare + 0.5 * total, rtol=1e-12, atol=0)
    assert np.all(path3 > 0) and np.all(path1 > path3)
    # The relative angle is 60 degrees: the film's gloss peaks near its mirror theta_r = -30.
    assert -45.0 < theta[np.argmax(path1)] < -30.0


@pytest.mark.slow
def test_film_attenuates_the_subsurface_profile(drawn):
    drawn_lines = lines(drawn["fig15_made_up_profile"])
    (d, bare), (_, made_up) = drawn_lines["bare"], drawn_lines["made_up"]
    assert d[0] == 0.0 and bare[0] == pytest.approx(1.0)
    assert np.all(made_up < bare) and np.all(made_up > 0)
    data = paper_figures.made_up_profile_curves()
    np.testing.assert_array_equal(made_up, data["made_up"])
    # Path 4 factorises (docs/model.md §3): the film scales the whole profile by (t / F_t)^2.
    np.testing.assert_allclose(made_up / bare, (data["t"] / data["F_t"]) ** 2, rtol=1e-12)
    assert 0.0 < data["t"] < data["F_t"] < 1.0


@pytest.mark.slow
def test_white_furnace_chart_stays_below_one(drawn):
    drawn_lines = lines(drawn["fig16_directional_albedo"])
    expected = {f"{name} {c}" for name in paper_figures.FOUNDATIONS for c in "RGB"} | {"bare"}
    assert set(drawn_lines) == expected
    for gid, (theta, albedo) in drawn_lines.items():
        assert theta[0] == 0.0 and theta[-1] == 89.0, gid
        assert np.all(albedo > 0.0) and np.all(albedo <= 1.0), gid
    # Pigment absorbs: the deepest shade is darker than the paper's film in every channel.
    for channel in "RGB":
        deep = drawn_lines[f"deep_mocha {channel}"][1]
        natural = drawn_lines[f"paper_natural {channel}"][1]
        assert np.all(deep < natural)
