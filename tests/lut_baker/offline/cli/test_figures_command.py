"""``python -m lut_baker figures`` (lut_baker.offline.cli.figures_command): the command writes
every figure as a PNG and refuses unknown figures and a file as its folder."""

import struct

import pytest

from lut_baker.offline import paper_figures
from lut_baker.offline.cli.main import main

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_command_writes_every_figure_as_png(tmp_path, capsys, monkeypatch, drawn):
    # The figures the fixture drew with their defaults are what the command draws: reuse them
    # (drawing twice would double this file's run time) and test the command's writing.
    for name, figure in drawn.items():
        monkeypatch.setitem(paper_figures.FIGURES, name, lambda figure=figure: figure)
    out = tmp_path / "new" / "figs"
    assert main(["figures", "--out", str(out)]) == 0
    written = sorted(p.name for p in out.iterdir())
    assert written == sorted(f"{name}.png" for name in paper_figures.FIGURES)
    assert capsys.readouterr().out.split() == [str(out / f"{name}.png")
                                               for name in paper_figures.FIGURES]
    for path in out.iterdir():
        data = path.read_bytes()
        assert data[:8] == PNG_SIGNATURE, path.name
        assert data[12:16] == b"IHDR", path.name
        width, height = struct.unpack(">II", data[16:24])
        assert (width, height) == (900, 600), path.name  # 6 x 4 in at 150 dpi
        assert len(data) > 20_000, path.name  # curves and text, not a blank canvas


@pytest.mark.parametrize("argv, message", [
    (["--only", "fig99_nothing"], "unknown figure"),
    (["--only", "fig13_skin_profile", "--only", "fig5"], "unknown figure"),
])
def test_command_rejects_unknown_figures(tmp_path, capsys, argv, message):
    out = tmp_path / "figs"
    with pytest.raises(SystemExit) as exit_info:
        main(["figures", "--out", str(out), *argv])
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_command_rejects_a_file_as_out(tmp_path, capsys):
    target = tmp_path / "taken"
    target.write_text("not a folder")
    with pytest.raises(SystemExit) as exit_info:
        main(["figures", "--out", str(target), "--only", "fig13_skin_profile"])
    assert exit_info.value.code == 2
    assert "not a folder" in capsys.readouterr().err
