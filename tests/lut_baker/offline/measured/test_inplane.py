"""In-plane reflectance files (lut_baker.offline.measured.inplane): the published spectral
files and RGB files read; every bad file is one ValueError line naming the file and the
problem."""

from pathlib import Path

import numpy as np
import pytest

from lut_baker.offline.measured.inplane import read_inplane, write_inplane

DATA = Path(__file__).parents[4] / "data" / "lanza2024"


def test_a_published_spectral_file_reads():
    data = read_inplane(DATA / "Clarins112_5W_thick_layer_tab.txt")
    assert data.layout == "spectral"
    assert data.values.shape == (124, 81)
    assert list(data.incidences_deg) == [30.0, 40.0, 50.0, 60.0, 70.0]
    assert data.theta_i_deg[0] == 30.0 and data.theta_o_deg[0] == 0.0
    assert data.values[0, 0] == pytest.approx(0.130456079742286, rel=1e-15)
    assert data.rgb.shape == (124, 3)


def test_an_rgb_file_round_trips(tmp_path):
    rgb = np.array([[0.5, 0.4, 0.3], [1.5, 1.2, 0.9]])
    path = write_inplane(tmp_path / "mine.txt", [30.0, 30.0], [0.0, 30.0], rgb)
    text = path.read_text()
    path.write_text("# my sample\n\n" + text)  # comments and blank lines are skipped
    data = read_inplane(path)
    assert data.layout == "rgb"
    assert np.array_equal(data.rgb, rgb)
    assert np.array_equal(data.theta_o_deg, [0.0, 30.0])


ROW = "30\t10\t" + "\t".join(["0.5"] * 81)
BAD = {
    "wrong column count": ("30\t10\t0.5\t0.5\n", r"line 1: 4 tab-separated columns; expected 83"),
    "column count changes": (ROW + "\n30\t10\t0.5\t0.5\t0.5\n",
                             r"line 2: 5 tab-separated columns, but the first row has 83"),
    "not a number": (ROW.replace("\t0.5", "\tabc", 1) + "\n",
                     r"line 1, column 3: not a number: 'abc'"),
    "not finite": (ROW.replace("\t0.5", "\tnan", 1) + "\n", r"line 1, column 3: not a finite"),
    "theta_i out of range": ("95" + ROW[2:] + "\n", r"line 1: theta_i = 95 degrees is out of"),
    "theta_o out of range": ("30\t-90" + ROW[5:] + "\n", r"line 1: theta_o = -90 degrees is out"),
    "negative value": (ROW.replace("\t0.5", "\t-0.1", 1) + "\n", r"line 1: negative reflectance"),
    "empty": ("# only a comment\n\n", r"no data rows"),
}


@pytest.mark.parametrize("case", BAD)
def test_a_bad_file_is_one_clear_line(tmp_path, case):
    text, message = BAD[case]
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as caught:
        read_inplane(path)
    assert str(caught.value).startswith(f"{path}: ")
    assert "\n" not in str(caught.value)


def test_a_missing_file_is_one_clear_line(tmp_path):
    with pytest.raises(ValueError, match="cannot read"):
        read_inplane(tmp_path / "absent.txt")
