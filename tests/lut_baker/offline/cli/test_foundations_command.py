"""``python -m lut_baker foundations`` (lut_baker.offline.cli.foundations_command): on the
published data it writes four CSVs with the exact header and finite values, four PNGs and the
report; a data folder that is not there is one line and exit code 2."""

from pathlib import Path

import numpy as np
import pytest

from lut_baker.offline.cli.main import COMMANDS, main

DATA = Path(__file__).parents[4] / "data" / "lanza2024"
HEADER = "theta_i_deg,theta_o_deg,measured_R,measured_G,measured_B,model_R,model_G,model_B"
ROWS = {"clarins_103": 115, "clarins_105": 147, "clarins_108": 107, "clarins_112": 124}


def test_the_command_is_registered():
    assert COMMANDS["foundations"] == ".foundations_command"


@pytest.mark.slow  # four products fitted in every form tried, held out, derived, drawn (~70 s)
def test_the_command_writes_the_csvs_figures_and_report(tmp_path, capsys):
    out = tmp_path / "foundations"
    stored = tmp_path / "presets.json"
    assert main(["foundations", "--out", str(out), "--data", str(DATA),
                 "--presets", str(stored)]) == 0
    printed = capsys.readouterr().out.split()
    expected = sorted([f"{p}.csv" for p in ROWS] + [f"{p}.png" for p in ROWS] + ["README.md"])
    assert sorted(p.name for p in out.iterdir()) == expected
    assert sorted(Path(p).name for p in printed) == sorted(expected + ["presets.json"])
    # The presets written are the runtime's (docs/model.md §4).
    from lut_baker.offline import foundation_presets

    written = foundation_presets.read_presets(stored)
    assert list(written) == list(ROWS)
    for name, entry in written.items():
        np.testing.assert_allclose(entry["absorption"],
                                   foundation_presets.read_presets()[name]["absorption"],
                                   rtol=1e-6, atol=1e-9)
    for product, rows in ROWS.items():
        path = out / f"{product}.csv"
        assert path.read_text().splitlines()[0] == HEADER
        table = np.loadtxt(path, delimiter=",", skiprows=1)
        assert table.shape == (rows, 8), product
        assert np.all(np.isfinite(table)) and np.all(table[:, 2:] > 0), product
        assert (out / f"{product}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    report = (out / "README.md").read_text()
    for product in ROWS:
        assert f"## {product} (" in report
        assert f"| {product} | Clarins {product[-3:]} (" in report
    assert "## Presets for the model" in report


def test_a_missing_data_folder_exits_2_with_one_line(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(["foundations", "--out", str(tmp_path / "o"), "--data", str(tmp_path / "none")])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is not a folder" in err
    assert not (tmp_path / "o").exists()


def test_notes_asked_for_but_missing_exit_2_with_one_line(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(["foundations", "--out", str(tmp_path / "o"), "--data", str(DATA),
              "--notes", str(tmp_path / "absent.md")])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "absent.md" in err
    assert not (tmp_path / "o").exists()
