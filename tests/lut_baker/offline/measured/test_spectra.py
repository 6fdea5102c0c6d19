"""Spectra to linear Rec.709 RGB (lut_baker.offline.measured.spectra): the white reflector maps
to exactly (1, 1, 1), a flat spectrum to its grey, and a product's rows match colour-science
computed directly (CIE 1931 2-degree observer, D65, sRGB primaries)."""

from pathlib import Path

import numpy as np
import pytest

from lut_baker.offline.measured import spectra as S  # noqa: E402
from lut_baker.offline.measured.inplane import read_inplane  # noqa: E402

DATA = Path(__file__).parents[4] / "data" / "lanza2024"


def test_the_grid_is_380_to_780_nm_in_5_nm_steps():
    assert S.WAVELENGTHS_NM.size == 81
    assert S.WAVELENGTHS_NM[0] == 380.0 and S.WAVELENGTHS_NM[-1] == 780.0
    assert np.all(np.diff(S.WAVELENGTHS_NM) == 5.0)


def test_the_perfect_white_reflector_is_exactly_white():
    assert np.array_equal(S.spectra_to_rgb(np.ones(81)), np.ones(3))
    assert S.luminance(S.spectra_to_rgb(np.ones(81))) == pytest.approx(1.0, abs=1e-15)


def test_a_flat_half_spectrum_is_half_grey():
    np.testing.assert_allclose(S.spectra_to_rgb(np.full((2, 81), 0.5)), 0.5, rtol=0, atol=1e-15)


def test_the_wrong_number_of_samples_is_one_clear_error():
    with pytest.raises(ValueError, match="81 samples"):
        S.spectra_to_rgb(np.ones(80))


def _direct(spectrum: np.ndarray) -> np.ndarray:
    import colour  # here, not at the top: its import (~0.8 s) would slow every collection

    shape = colour.SpectralShape(380.0, 780.0, 5.0)  # the data's grid: no interpolation
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    illuminant = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    sd = colour.SpectralDistribution(dict(zip(S.WAVELENGTHS_NM, spectrum, strict=True)))
    xyz = colour.sd_to_XYZ(sd, cmfs, illuminant, method="Integration") / 100.0
    return colour.XYZ_to_RGB(xyz, "sRGB")


def test_a_products_rows_match_colour_science_directly():
    # colour-science's own route differs only by the white balance to exactly (1, 1, 1),
    # a few parts in 10^4 per channel (the module docstring).
    data = read_inplane(DATA / "Clarinsfoundation103N_norm_thick_layer_tab.txt")
    rows = data.values[::7]
    ours = S.spectra_to_rgb(rows)
    direct = np.array([_direct(row) for row in rows])
    white = _direct(np.ones(81))
    np.testing.assert_allclose(white, 1.0, atol=5e-4)
    np.testing.assert_allclose(ours, direct / white, rtol=1e-9)
    np.testing.assert_allclose(ours, direct, rtol=5e-4)
