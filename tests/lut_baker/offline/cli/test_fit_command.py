"""``python -m lut_baker fit`` (lut_baker.offline.cli.fit_command): synthesised protocols
written, fitted back from their files, warnings and ``--strict``, and bad input."""

import json
import tomllib

import numpy as np
import pytest

from lut_baker.model.layers import Dipole, ReflectionLayer
from lut_baker.model.presets import paper_layers
from lut_baker.offline.cli.fit_command import STRICT_EXIT
from lut_baker.offline.cli.main import main
from lut_baker.offline.measured import layer_fit as F

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
