"""Measurements (lut_baker.offline.measured.measurements): the model's counts in the paper's
geometries, the synthesised protocols, and measurement files (CSV)."""

import numpy as np
import pytest

from lut_baker.model.microfacet import fresnel_reflectance
from lut_baker.model.presets import paper_layers
from lut_baker.offline.measured import measurements as M

NOISE = 0.02
FILM, FILM_T, SKIN, DIPOLE = paper_layers()


def test_reflection_counts_at_the_mirror_configuration():
    """alpha = 0 at psi = 60: D = 1, G = 1, V.H = cos 30 deg, N.L = cos 30 deg (eq. 2)."""
    data = M.ReflectionData([60.0], [0.0], [1.0])
    c = np.cos(np.radians(30.0))
    expected = (float(FILM.P_d) + float(FILM.P_s) * fresnel_reflectance(c, 1.19)) * c
    assert M.reflection_counts(data, FILM)[0] == pytest.approx(expected, rel=1e-9)


def test_transmission_counts_straight_through():
    """theta_t = incidence: beta = 0, c = cos(incidence), I = (P_d + P_t F_t) N.L (eq. 4)."""
    data = M.TransmissionData([30.0], [30.0], [1.0])
    c = np.cos(np.radians(30.0))
    expected = (float(FILM_T.P_d) + float(FILM_T.P_t) * (1 - fresnel_reflectance(c, 1.19))) * c
    assert M.transmission_counts(data, FILM_T)[0] == pytest.approx(expected, rel=1e-9)


def test_profile_ratio_is_one_at_the_lit_pixel_and_falls():
    ratio = M.profile_ratio(np.linspace(0.0, 3.0, 31), DIPOLE)
    assert ratio[0] == 1.0 and np.all(np.diff(ratio) < 0.0)


def test_synthesis_follows_the_paper_protocols():
    data = M.paper_protocols(NOISE, 0)
    assert sorted(set(data["film_reflection"].psi_deg)) == [30.0, 60.0, 90.0, 120.0]
    assert sorted(set(data["film_transmission"].incidence_deg)) == [0.0, 30.0, 60.0]
    exact = M.synthesize_reflection(FILM)
    noise = data["film_reflection"].intensity_counts / exact.intensity_counts - 1.0
    assert abs(np.std(noise) - NOISE) < 0.003 and abs(np.mean(noise)) < 0.003
    again = M.paper_protocols(NOISE, 0)["skin_profile"].ratio
    assert np.array_equal(again, data["skin_profile"].ratio)


def test_csv_round_trip(tmp_path):
    data = M.paper_protocols(NOISE, 1)
    for name, dataset in data.items():
        path = M.write_measurements(tmp_path / f"{name}.csv", dataset, ("a comment",))
        back = M.read_measurements(path)
        assert type(back) is type(dataset)
        for column in dataset.COLUMNS:
            np.testing.assert_allclose(getattr(back, column), getattr(dataset, column),
                                       rtol=1e-6)


def test_csv_accepts_theta_r_instead_of_alpha(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("intensity_counts,theta_r_deg,psi_deg,note\n100,-25,60,x\n90,-40,90,y\n")
    data = M.read_measurements(path)
    np.testing.assert_allclose(data.alpha_deg, [5.0, 5.0])
    np.testing.assert_allclose(data.wo[:, 0], np.sin(np.radians([-25.0, -40.0])))


@pytest.mark.parametrize(("text", "message"), [
    ("", "empty file"),
    ("psi_deg,intensity_counts\n30,1\n", "missing column alpha_deg"),
    ("psi_deg,alpha_deg,intensity_counts\n30,0,abc\n", "row 2, column intensity_counts"),
    ("psi_deg,alpha_deg,intensity_counts\n", "no data rows"),
    ("foo,bar\n1,2\n", "unknown columns"),
    ("distance_mm,ratio\n0,1\n0.1,-0.5\n", "ratio must be > 0"),
    ("psi_deg,alpha_deg,intensity_counts\n30,80,5\n", "below the sample"),
    ("incidence_deg,theta_t_deg,intensity_counts\n95,0,5\n", "incidence_deg must lie in"),
])
def test_csv_problems_raise_one_line(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as info:
        M.read_measurements(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)


def test_a_tilted_sample_reflects_f_r_at_the_offset_alpha_with_the_nominal_cosine():
    data = M.synthesize_reflection(FILM, noise=0.0)
    tilt = 1.7
    shifted = M.ReflectionData(data.psi_deg, data.alpha_deg + tilt, data.intensity_counts)
    expected = M.reflection_counts(shifted, FILM) * data.wi[:, 2] / shifted.wi[:, 2]
    np.testing.assert_allclose(M.reflection_counts(data, FILM, tilt), expected, rtol=1e-12)
    # One model for many layers and tilts gives what the one-off function gives.
    model = M.ReflectionCounts(data)
    for value in (0.0, tilt, -0.5, tilt):
        np.testing.assert_array_equal(model(FILM, value), M.reflection_counts(data, FILM, value))
    transmission = M.synthesize_transmission(FILM_T, noise=0.0)
    np.testing.assert_array_equal(M.TransmissionCounts(transmission)(FILM_T),
                                  M.transmission_counts(transmission, FILM_T))
