"""Parameter files (lut_baker.model.params_file): the schema of the example file, and a file in
the paper's counts reproducing the paper's preset."""

from pathlib import Path

import numpy as np
import pytest

from lut_baker.model import params_file, presets

ROOT = Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "examples" / "beige_on_skin1.toml"

def test_parameter_file_schema():
    skin = params_file.load_params(EXAMPLE)
    assert skin.name == "beige_on_skin1" and skin.coverage == 0.8
    np.testing.assert_allclose(skin.absorption, [0.12, 0.26, 0.45])
    assert float(skin.film.n) == 0.036 and float(skin.film_transmission.P_t) == 0.04
    base = presets.made_up_skin("medium_beige", "jensen_skin1")
    assert float(skin.film.P_s) == float(base.film.P_s)  # not overridden
    np.testing.assert_array_equal(skin.skin_reflection.P_d, base.skin_reflection.P_d)
    again = params_file.skin_from_dict(params_file.skin_to_dict(skin))
    assert params_file.skin_to_dict(again) == params_file.skin_to_dict(skin)
    assert params_file.params_from_mapping({}).name == "paper"


def test_parameter_file_in_paper_counts_reproduces_the_paper():
    film, film_t, skin, _ = presets.paper_layers()
    mapping = {"units": "counts", "film": film.as_dict(), "film_transmission": film_t.as_dict(),
               "skin_surface": skin.as_dict()}
    made_up = params_file.params_from_mapping(mapping)
    assert made_up.K == pytest.approx(presets.paper().K)
    np.testing.assert_allclose(made_up.film.P_s, presets.paper().film.P_s)
