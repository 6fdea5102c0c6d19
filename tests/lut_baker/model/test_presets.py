"""Presets (lut_baker.model.presets): the paper's fitted values (docs/model.md §5), the
literature skins, the foundation shades, and the named bundles built from them."""

import math
from pathlib import Path

import numpy as np
import pytest

from lut_baker.model import made_up_skin, presets
from lut_baker.model.dipole import dipole_total_reflectance

# docs/model.md §5 (the paper's table), red channel, pixel counts.
PAPER_PARAMETERS = {
    "PAPER_FILM_REFLECTION": {"P_d": 1.29e4, "P_s": 8.93e5, "n": 3.29e-2, "eta": 1.19},
    "PAPER_FILM_TRANSMISSION": {"P_d": 2.64e4, "P_t": 1.08e4, "n": 3.46e-2, "eta": 1.19},
    "PAPER_SKIN_REFLECTION": {"P_d": 2.00e4, "P_s": 2.05e5, "n": 4.00e-2, "eta": 1.26},
    "PAPER_SKIN_DIPOLE": {"sigma_s": 2.83, "sigma_a": 2.82e-2, "g": 0.0, "eta": 1.26},
}
# Jensen et al. 2001, table of measured parameters (reduced scattering, absorption, 1/mm).
JENSEN = {
    "jensen_skin1": ((0.74, 0.88, 1.01), (0.032, 0.17, 0.48)),
    "jensen_skin2": ((1.09, 1.59, 1.79), (0.013, 0.070, 0.145)),
}


@pytest.mark.parametrize("name", sorted(PAPER_PARAMETERS))
def test_paper_values_are_the_papers_table(name):
    assert getattr(presets, name).as_dict() == pytest.approx(PAPER_PARAMETERS[name], rel=1e-15)


def test_paper_layers_order():
    film, film_t, skin, dipole = presets.paper_layers()
    assert film is presets.PAPER_FILM_REFLECTION and film_t is presets.PAPER_FILM_TRANSMISSION
    assert skin is presets.PAPER_SKIN_REFLECTION and dipole is presets.PAPER_SKIN_DIPOLE


def test_paper_bundle():
    paper = presets.paper()
    assert paper is presets.paper()  # cached
    assert paper.coverage == 1.0 and np.all(paper.absorption == 0.0)
    assert paper.K == pytest.approx(27697, rel=1e-4)
    # Skin and film share K: the ratio of their diffuse terms is the counts' ratio.
    assert paper.skin_reflection.P_d / paper.film.P_d == pytest.approx(2.00e4 / 1.29e4, rel=1e-14)
    assert paper.dipole is presets.PAPER_SKIN_DIPOLE


@pytest.mark.parametrize("name", sorted(JENSEN))
def test_jensen_skins(name):
    surface, dipole = presets.skin_layers(name)
    sigma_s, sigma_a = JENSEN[name]
    np.testing.assert_array_equal(dipole.sigma_s, sigma_s)
    np.testing.assert_array_equal(dipole.sigma_a, sigma_a)
    assert float(dipole.g) == 0.0 and float(dipole.eta) == 1.3
    # The diffuse albedo pi P_d is the dipole's total diffuse reflectance (docs/model.md §4).
    np.testing.assert_allclose(math.pi * surface.P_d, dipole_total_reflectance(dipole),
                               rtol=1e-14)
    assert np.all(math.pi * surface.P_d < 1.0)
    # Red scatters most and absorbs least: skin is reddest.
    assert surface.P_d[0] > surface.P_d[1] > surface.P_d[2]
    assert float(surface.n) == pytest.approx(1 / 19.3)


def test_bioplate_skin_is_the_papers():
    surface, dipole = presets.skin_layers("paper_bioplate")
    assert surface is presets.paper().skin_reflection and dipole is presets.PAPER_SKIN_DIPOLE


def test_foundations():
    assert set(presets.FOUNDATIONS) == {"paper_natural", "light_ivory", "medium_beige",
                                        "deep_mocha", "clarins_103", "clarins_105",
                                        "clarins_108", "clarins_112"}
    for entry in presets.FOUNDATIONS.values():
        absorption = np.asarray(entry["absorption"])
        assert absorption.shape == (3,) and np.all((absorption >= 0) & (absorption <= 1))
        assert entry["label"]
    # Shades get darker in order, blue absorbed most (a warm foundation).
    shades = [np.asarray(presets.FOUNDATIONS[k]["absorption"])
              for k in ("light_ivory", "medium_beige", "deep_mocha")]
    assert all(np.all(a < b) for a, b in zip(shades, shades[1:], strict=False))
    assert all(s[0] < s[1] < s[2] for s in shades)


def test_made_up_skin():
    bundle = presets.made_up_skin("medium_beige", "jensen_skin2", coverage=0.3)
    assert bundle.name == "medium_beige+jensen_skin2" and bundle.coverage == 0.3
    np.testing.assert_array_equal(bundle.absorption, presets.FOUNDATIONS["medium_beige"][
        "absorption"])
    surface, dipole = presets.skin_layers("jensen_skin2")
    np.testing.assert_array_equal(bundle.skin_reflection.P_d, surface.P_d)
    assert bundle.dipole.as_dict() == dipole.as_dict()
    assert bundle.K == presets.paper().K
    override = presets.made_up_skin("deep_mocha", absorption=0.2)
    np.testing.assert_array_equal(override.absorption, 0.2)
    assert made_up_skin.film_transmission_layer(override).P_t == pytest.approx(
        0.8 * presets.paper().film_transmission.P_t)


@pytest.mark.parametrize("call, message", [
    (lambda: presets.made_up_skin("lipstick"), r"foundation must be one of \["),
    (lambda: presets.made_up_skin(skin="marble"), r"skin must be one of \["),
    (lambda: presets.skin_layers("marble"), r"skin must be one of \["),
    (lambda: presets.made_up_skin(coverage=-0.1), r"coverage must lie in \[0, 1\]"),
    (lambda: presets.made_up_skin(absorption=(0.1, 0.2)), r"absorption must be a float or"),
])
def test_preset_errors(call, message):
    with pytest.raises(ValueError, match=message):
        call()


MEASURED = {"clarins_103": "matte", "clarins_105": "dewy", "clarins_108": "matte",
            "clarins_112": "dewy"}


def test_measured_foundations_come_from_the_shipped_file():
    """The four measured products (docs/model.md §4, "Presets from measured thick layers"):
    labelled by product and finish, read from the file shipped with the runtime."""
    assert presets.MEASURED_FOUNDATIONS_FILE.is_file()
    assert presets.MEASURED_FOUNDATIONS_FILE.parent == Path(presets.__file__).parent
    for name, finish in MEASURED.items():
        entry = presets.FOUNDATIONS[name]
        assert entry["label"] == f"Clarins {name[-3:]} ({finish}, measured)"
        assert set(entry["film"]) == {"P_s", "n", "eta"}
        if finish == "matte":
            assert entry["film"]["P_s"] == 0.0
        else:  # a lobe 1/e at 1 to 10 degrees of alpha (105: 6.0, 112: 2.1)
            assert entry["film"]["P_s"] > 0 and 0.1 < entry["film"]["n"] < 1.0
    # The measured products' red is brighter than their blue: absorption rises to blue.
    for name in MEASURED:
        absorption = presets.FOUNDATIONS[name]["absorption"]
        assert absorption[0] < absorption[1] < absorption[2]
    # 108 and 112 are darker than 103 and 105 in every channel.
    for dark in ("clarins_108", "clarins_112"):
        for light in ("clarins_103", "clarins_105"):
            assert np.all(np.greater(presets.FOUNDATIONS[dark]["absorption"],
                                     presets.FOUNDATIONS[light]["absorption"]))
    assert presets.read_measured_foundations(Path("no such file.json")) == {}


@pytest.mark.parametrize("name", sorted(MEASURED))
def test_made_up_skin_applies_a_measured_film(name):
    bundle = presets.made_up_skin(name, "jensen_skin1", coverage=0.5)
    paper = presets.paper()
    entry = presets.FOUNDATIONS[name]
    film = presets.foundation_film(name)
    assert bundle.film.as_dict() == film.as_dict()
    assert film.as_dict() == {"P_d": float(paper.film.P_d), **entry["film"]}
    assert bundle.film_transmission is paper.film_transmission
    np.testing.assert_array_equal(bundle.absorption, entry["absorption"])
    assert bundle.coverage == 0.5 and bundle.name == f"{name}+jensen_skin1"


def test_hand_picked_shades_keep_the_papers_film():
    for name in ("paper_natural", "light_ivory", "medium_beige", "deep_mocha"):
        assert "film" not in presets.FOUNDATIONS[name]
        assert presets.made_up_skin(name).film is presets.paper().film
        assert presets.foundation_film(name) is presets.paper().film
    with pytest.raises(ValueError, match="foundation must be one of"):
        presets.foundation_film("lipstick")


def test_measured_glosses_reflect_less_than_the_papers_film():
    """The white furnace test's absorption cases use the paper film; a measured product's film
    differs only in its gloss, which reflects less at every incidence (docs/model.md §4)."""
    from lut_baker.model.albedo import reflection_albedo

    theta = np.array([0.0, 30.0, 50.0, 70.0, 80.0, 85.0, 89.0])
    paper_gloss = reflection_albedo(theta, presets.paper().film.scaled(P_d=0.0))
    for name in MEASURED:
        gloss = reflection_albedo(theta, presets.foundation_film(name).scaled(P_d=0.0))
        assert np.all(gloss <= paper_gloss), name
