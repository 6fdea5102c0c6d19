"""A user's own foundation (lut_baker.offline.own_foundation, docs/model.md §4): a published
product's file becomes a parameter file that loads as that product's shipped preset and
bakes; the finish decided from the fit reproduces the published finishes.  The RGB round trip
through the command line is in tests/lut_baker/offline/cli/test_fit_command.py."""

from pathlib import Path

import numpy as np
import pytest

from lut_baker import bake
from lut_baker.model import presets
from lut_baker.model.params_file import load_params
from lut_baker.offline import own_foundation as O
from lut_baker.offline.foundation_presets import auto_finish
from lut_baker.offline.foundations import PRODUCTS
from lut_baker.offline.measured.inplane import read_inplane
from lut_baker.offline.measured.inplane_fit import well_posed

DATA = Path(__file__).parents[3] / "data" / "lanza2024"


def _assert_same_film_as_preset(skin, product):
    shipped = presets.FOUNDATIONS[product]
    np.testing.assert_allclose(skin.absorption, shipped["absorption"], rtol=1e-6, atol=1e-9)
    for key, value in shipped["film"].items():
        assert float(getattr(skin.film, key)) == pytest.approx(value, rel=1e-6)
    # The whole film, P_d and transmission included, is the preset's.
    preset = presets.made_up_skin(product)
    for name in ("film", "film_transmission", "skin_reflection", "dipole"):
        for key, value in getattr(preset, name).as_dict().items():
            np.testing.assert_allclose(getattr(getattr(skin, name), key), value, rtol=1e-6)


@pytest.mark.slow  # well-posed fit, then the film derived by quadrature (~10-20 s)
@pytest.mark.parametrize(("product", "finish"), [("clarins_105", "dewy"),
                                                 ("clarins_108", "matte")])
def test_a_product_file_gives_its_shipped_preset(tmp_path, product, finish):
    """Same derivation, same numbers: the file made from a product's measurements loads with
    the absorption and gloss of the shipped preset (``auto`` picks the published finish)."""
    result = O.fit_own_foundation(DATA / PRODUCTS[product][0], name=f"mine {product}")
    assert result.finish == finish == PRODUCTS[product][1]
    path = tmp_path / "mine.toml"
    path.write_text(O.params_text(result, "python -m lut_baker fit inplane ..."))
    skin = load_params(path)
    assert skin.name == f"mine {product}"
    _assert_same_film_as_preset(skin, product)
    text = path.read_text()
    assert "clamped: R" in text if product == "clarins_105" else "clamped: none" in text
    assert "error rms" in text and "target " in text and "stack  " in text


@pytest.mark.slow  # a preview bake (~2-4 s)
def test_a_product_params_file_bakes(tmp_path):
    result = O.fit_own_foundation(DATA / PRODUCTS["clarins_105"][0])
    path = tmp_path / "mine.toml"
    path.write_text(O.params_text(result))
    skin = load_params(path)
    _assert_same_film_as_preset(skin, "clarins_105")
    tables = bake.bake(skin, "preview")
    assert np.all(np.isfinite(tables.path3_gloss)) and np.all(np.isfinite(tables.profile))
    np.testing.assert_allclose(tables.parameters["absorption"], skin.absorption)


@pytest.mark.slow  # four products fitted in their well-posed forms (~20-30 s)
def test_auto_finish_reproduces_the_published_finishes():
    """The rule ``--finish auto`` applies (foundation_presets.auto_finish, on the well-posed
    fits fit_own_foundation makes) gives each product its published finish: the matte ones
    keep no lobe, the dewy ones a lobe in every channel."""
    for name, (filename, finish) in PRODUCTS.items():
        data = read_inplane(DATA / filename)
        choice = well_posed(data.theta_i_deg, data.theta_o_deg, data.rgb)
        decided, why = auto_finish(choice.fit.fits)
        assert decided == finish, (name, why)
        assert choice.model.lobe == (finish == "dewy"), (name, choice.summary())


def test_a_bad_finish_is_refused(tmp_path):
    with pytest.raises(ValueError, match="finish must be one of auto, matte, dewy"):
        O.fit_own_foundation(tmp_path / "x.txt", finish="satin")
