"""``python -m lut_baker fit`` (lut_baker.offline.cli.fit_command): synthesised protocols
written, fitted back from their files, warnings and ``--strict``, and bad input; ``fit
inplane``: its help, bad files, an RGB file round trip and a published product's file."""

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from lut_baker.model.layers import Dipole, ReflectionLayer
from lut_baker.model.params_file import load_params
from lut_baker.model.presets import FOUNDATIONS, paper_layers
from lut_baker.offline.cli.fit_command import STRICT_EXIT
from lut_baker.offline.cli.main import main
from lut_baker.offline.measured import layer_fit as F
from lut_baker.offline.measured.inplane import write_inplane

DATA = Path(__file__).parents[4] / "data" / "lanza2024"

FILM, FILM_T, SKIN, DIPOLE = paper_layers()


@pytest.fixture(scope="module")
def synthesized(tmp_path_factory):
    out = tmp_path_factory.mktemp("synth")
    assert main(["fit", "synthesize", "--preset", "paper", "--out", str(out),
                 "--noise", "0.02", "--seed", "3"]) == 0
    return out


def test_cli_synthesize_writes_the_protocols(synthesized):
    names = sorted(p.name for p in synthesized.iterdir())
    assert names == ["film_reflection.csv", "film_transmission.csv", "skin_profile.csv",
                     "skin_reflection.csv", "truth.toml"]
    truth = tomllib.loads((synthesized / "truth.toml").read_text())
    assert ReflectionLayer(**truth["film_reflection"]).as_dict() == FILM.as_dict()
    header = (synthesized / "film_reflection.csv").read_text().splitlines()
    assert "psi_deg,alpha_deg,intensity_counts" in header


@pytest.mark.parametrize(("kind", "file", "layer_type", "truth"), [
    ("reflection", "film_reflection.csv", ReflectionLayer, FILM),
    ("reflection", "skin_reflection.csv", ReflectionLayer, SKIN),
    ("dipole", "skin_profile.csv", Dipole, DIPOLE),
])
def test_cli_fit_round_trip_toml(synthesized, tmp_path, capsys, kind, file, layer_type, truth):
    assert main(["fit", kind, str(synthesized / file)]) == 0
    captured = capsys.readouterr()
    document = tomllib.loads(captured.out)
    fitted = layer_type(**document[kind])
    errors = F.relative_errors(fitted, truth)
    for parameter in ("n", "eta", "sigma_s", "sigma_a"):
        if parameter in document["stderr"]:
            assert abs(errors[parameter]) < 0.05
            assert document["stderr"][parameter] > 0
    assert document["fit"]["warnings"] == [] and captured.err == ""
    n = len(document["fit"]["free"])
    assert np.array(document["fit"]["correlation"]).shape == (n, n)
    starts = document["fit"]["starts"]  # every start ended in the one minimum
    assert starts["reached"] == starts["count"] >= 3 and "next_excess" not in starts


def test_cli_transmission_warns_and_strict_fails(synthesized, tmp_path, capsys):
    path = str(synthesized / "film_transmission.csv")
    assert main(["fit", "transmission", path]) == 0
    assert capsys.readouterr().err.startswith("warning: eta is ill-conditioned")
    assert main(["fit", "transmission", path, "--strict"]) == STRICT_EXIT
    out = tmp_path / "t.json"
    assert main(["fit", "transmission", path, "--eta", "1.19", "--strict", "--out",
                 str(out)]) == 0
    document = json.loads(out.read_text())
    assert document["transmission"]["eta"] == 1.19 and document["fit"]["warnings"] == []
    assert abs(document["transmission"]["n"] / float(FILM_T.n) - 1) < 0.05


@pytest.mark.parametrize(("args", "message"), [
    (["reflection", "{dir}/missing.csv"], "no such file"),
    (["reflection", "{dir}/empty.csv"], "empty file"),
    (["reflection", "{dir}/nocolumn.csv"], "missing column intensity_counts"),
    (["reflection", "{dir}/text.csv"], "not a number"),
    (["reflection", "{dir}/profile.csv"], "holds profile columns"),
    (["dipole", "{dir}/profile.csv", "--eta", "0.5"], "--eta"),
])
def test_cli_bad_input_exits_2_with_one_line(tmp_path, capsys, args, message):
    (tmp_path / "empty.csv").write_text("")
    (tmp_path / "nocolumn.csv").write_text("psi_deg,alpha_deg\n30,0\n")
    (tmp_path / "text.csv").write_text("psi_deg,alpha_deg,intensity_counts\n30,zero,1\n")
    (tmp_path / "profile.csv").write_text("distance_mm,ratio\n0,1\n0.5,0.5\n1,0.2\n")
    with pytest.raises(SystemExit) as info:
        main(["fit"] + [a.format(dir=tmp_path) for a in args])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def test_cli_inplane_help_documents_the_columns_and_units(capsys):
    with pytest.raises(SystemExit) as info:
        main(["fit", "inplane", "--help"])
    assert info.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for needed in ("theta_i incidence, degrees from the normal",
                   "theta_o signed viewing angle, degrees", "tab-separated",
                   "81 spectral reflectance factors at 380, 385, ..., 780 nm",
                   "3 linear RGB reflectance factors R, G, B", "R = pi f_r",
                   'foundation = "paper_natural"', "[film] P_s, n, eta", "--finish",
                   "--strict", "Exit codes"):
        assert needed in text, needed


_GOOD_ROWS = "".join(f"30\t{o}\t0.5\t0.4\t0.3\n" for o in (0, 10, 20, 30, 40))


@pytest.mark.parametrize(("name", "text", "message"), [
    ("missing.txt", None, "missing.txt: cannot read"),
    ("columns.txt", "30\t0\t0.5\t0.4\n", "columns.txt: line 1: 4 tab-separated columns; "
                                          "expected 83"),
    ("cell.txt", _GOOD_ROWS + "30\t50\tgrey\t0.4\t0.3\n", "cell.txt: line 6, column 3: "
                                                           "not a number"),
    ("empty.txt", "# nothing\n", "empty.txt: no data rows"),
    ("few.txt", "30\t0\t0.5\t0.4\t0.3\n", "few.txt: a joint reflection fit of 3 data sets "
                                          "needs at least 14 samples, got 3"),
    ("apart.txt", _GOOD_ROWS + "30\t-30\t0.5\t0.4\t0.3\n", "apart.txt: theta_i + theta_o "
                                                            "must be > 0"),
])
def test_cli_inplane_bad_file_exits_2_with_one_line(tmp_path, capsys, name, text, message):
    path = tmp_path / name
    if text is not None:
        path.write_text(text)
    with pytest.raises(SystemExit) as info:
        main(["fit", "inplane", str(path)])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err


def test_cli_inplane_out_must_be_a_file(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(["fit", "inplane", str(tmp_path / "x.txt"), "--out", str(tmp_path)])
    assert info.value.code == 2 and "is a folder" in capsys.readouterr().err


@pytest.mark.slow  # a fit and the film derived by quadrature, twice (~4-8 s)
def test_cli_inplane_rgb_file_round_trips(tmp_path, capsys):
    """Noise-free RGB factors of a known lobe per channel, written by the reader's own writer:
    the lobe is determined (auto: dewy), the gloss is its luminance-weighted mean and the
    absorption the one its thick layer implies; nothing warns, so --strict passes."""
    from lut_baker.offline import foundation_presets as FP
    from lut_baker.offline.measured.inplane_fit import model_factor

    truth = (ReflectionLayer(P_d=0.25, P_s=40.0, n=0.12, eta=1.10),
             ReflectionLayer(P_d=0.18, P_s=38.0, n=0.12, eta=1.10),
             ReflectionLayer(P_d=0.12, P_s=36.0, n=0.12, eta=1.10))
    theta_i = np.repeat([20.0, 40.0, 60.0], 15)
    theta_o = np.tile(np.linspace(-10.0, 75.0, 15), 3)
    rgb = np.stack([model_factor(layer, theta_i, theta_o) for layer in truth], axis=-1)
    data = write_inplane(tmp_path / "my foundation.txt", theta_i, theta_o, rgb)
    out = tmp_path / "mine.toml"
    assert main(["fit", "inplane", str(data), "--out", str(out), "--strict"]) == 0
    captured = capsys.readouterr()
    assert captured.out == f"wrote {out}\n" and captured.err == ""
    skin = load_params(out)
    expected = FP.derive_preset("mine", "dewy", truth)
    assert skin.name == "my foundation"
    np.testing.assert_allclose(skin.absorption, expected["absorption"], rtol=1e-5)
    for key, value in expected["film"].items():
        assert float(getattr(skin.film, key)) == pytest.approx(value, rel=1e-5)
    text = out.read_text()
    assert "3 linear RGB values per row" in text and "finish: dewy (auto:" in text
    assert "warnings: none" in text


@pytest.mark.slow  # a published product fitted and derived (~2-4 s)
def test_cli_inplane_product_warns_and_strict_exits_3(tmp_path, capsys):
    path = DATA / "Clarinsfoundation103N_norm_thick_layer_tab.txt"
    assert main(["fit", "inplane", str(path), "--strict"]) == STRICT_EXIT
    captured = capsys.readouterr()
    out = tmp_path / "p.toml"
    out.write_text(captured.out)
    skin = load_params(out)
    shipped = FOUNDATIONS["clarins_103"]  # matte: auto finds no lobe, so no gloss
    np.testing.assert_allclose(skin.absorption, shipped["absorption"], rtol=1e-6)
    assert float(skin.film.P_s) == shipped["film"]["P_s"] == 0.0
    assert "finish: matte (auto: the data determine no lobe; P_d alone (no lobe); reduced " \
           "from eq. 2 (P_d, P_s, n, eta per channel) + tilt (the tilt ran to its bound" \
           in captured.out
    warnings = captured.err.splitlines()
    assert warnings and all(line.startswith("warning: ") for line in warnings)
    # P_d alone describes the blue channel to 29% (log residual): beyond the 20% limit.
    assert "warning: B: the residual rms" in captured.err
    # Each warning is also a comment of the file.
    for line in warnings:
        assert f"#   {line.removeprefix('warning: ')}" in captured.out
    # A finish given is used as given.
    assert main(["fit", "inplane", str(path), "--finish", "matte", "--name", "mine"]) == 0
    given = capsys.readouterr().out
    assert "finish: matte (given)" in given
    assert tomllib.loads(given) == {**tomllib.loads(captured.out), "name": "mine"}
