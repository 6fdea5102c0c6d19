"""`python -m lut_baker bake` (lut_baker.cli_bake) and parameter files (lut_baker.params_file)."""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lut_baker import bake, cli, cli_bake, io, params_file, presets

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "beige_on_skin1.toml"


def run_cli(*args, cwd=ROOT, **kwargs):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "lut_baker", "bake", *map(str, args)],
                          cwd=cwd, env=env, capture_output=True, text=True, timeout=120,
                          **kwargs)


def parse(*args):
    return cli.build_parser().parse_args(["bake", *map(str, args)])


def test_cli_bake_writes_the_same_tables_as_the_function(tmp_path):
    result = run_cli("--preset", "paper", "--resolution", "preview", "--out", tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("\n") == 1 and "paper.exr" in result.stdout
    assert "[###" not in result.stderr  # no progress bar when stderr is not a terminal
    meta = json.loads((tmp_path / "paper.json").read_text())
    assert meta["sha256"] == io.content_hash(bake.bake(presets.paper(), "preview"))
    assert io.content_hash(io.load_tables(tmp_path / "paper.exr")) == meta["sha256"]


def test_cli_options_override_in_order(tmp_path):
    result = run_cli("--params", EXAMPLE, "--coverage", "0.25", "--absorption", "0", "0.5", "1",
                     "--resolution", "preview", "--inter-reflection", "--out", tmp_path,
                     "--name", "mine")
    assert result.returncode == 0, result.stderr
    meta = json.loads((tmp_path / "mine.json").read_text())
    assert meta["parameters"]["coverage"] == 0.25
    assert meta["parameters"]["absorption"] == [0.0, 0.5, 1.0]
    assert meta["parameters"]["film"]["n"] == 0.036  # from the file
    assert "inter_reflection" in meta["layout"]
    skin = cli_bake.skin_from_args(parse("--params", EXAMPLE, "--coverage", "0.25",
                                         "--absorption", "0", "0.5", "1"))
    expected = bake.bake(skin, "preview", inter_reflection=True)
    assert meta["sha256"] == io.content_hash(expected)


@pytest.mark.bpy
def test_bake_inside_blenders_python_gives_the_same_tables():
    """The same bake after `import bpy` (Blender's Python as a module) hashes the same."""
    pytest.importorskip("bpy")
    code = ("import bpy, lut_baker.bake as b, lut_baker.io as i, lut_baker.presets as p;"
            "print(i.content_hash(b.bake(p.paper(), 'preview')))")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == io.content_hash(
        bake.bake(presets.paper(), "preview"))


def main_exit(capsys, *args):
    """Run ``python -m lut_baker bake ARGS`` in-process: (exit code, stderr)."""
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["bake", *map(str, args)])
    return exit_info.value.code, capsys.readouterr().err


def test_bad_argument_exits_2_with_one_line_from_the_shell(tmp_path):
    result = run_cli("--coverage", "1.5", "--out", tmp_path)
    assert result.returncode == 2
    assert result.stderr.strip() == ("python -m lut_baker bake: error: argument --coverage: "
                                     "coverage must lie in [0, 1], got 1.5")
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("args, named", [
    (["--coverage", "abc"], "--coverage"),
    (["--coverage", "-0.1"], "--coverage"),
    (["--absorption", "0.1", "0.2"], "--absorption"),
    (["--absorption", "0.1", "0.2", "1.2"], "--absorption"),
    (["--resolution", "ultra"], "--resolution"),
    (["--foundation", "purple"], "--foundation"),
    (["--skin", "green"], "--skin"),
    (["--params", "missing.toml"], "--params"),
])
def test_bad_arguments_exit_2_with_one_line(capsys, args, named, tmp_path):
    code, err = main_exit(capsys, *args, "--out", tmp_path)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and named in lines[0] and "error" in lines[0], err
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("text, message", [
    ("coverage = [", "not valid TOML"),
    ("colour = 1", "unknown key"),
    ("skin = 3", "skin must be one of"),
    ("[film]\nroughness = 2", r"\[film\] has unknown field"),
    ("[film]\nn = -1", r"\[film\] n must lie in"),
    ("[skin_surface]\neta = 0", r"\[skin_surface\] eta must lie in"),
    ('units = "counts"\n[film]\nn = 0.03', r"\[film\] is missing field"),
    ("coverage = 2", "coverage must lie in"),
])
def test_invalid_parameter_files_exit_2_naming_params(capsys, text, message, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    code, err = main_exit(capsys, "--params", bad, "--out", tmp_path / "out")
    assert code == 2
    line = err.strip()
    assert "\n" not in line and "--params" in line
    assert re.search(message, line), line
    assert not (tmp_path / "out").exists()


def test_missing_openimageio_is_one_clear_line(capsys, monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "OpenImageIO", None)  # import fails
    assert cli.main(["bake", "--resolution", "preview", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "needs OpenImageIO" in err and "pip install" in err
    assert not any(tmp_path.iterdir())


def test_help_explains_every_option_with_units():
    result = run_cli("--help")
    assert result.returncode == 0
    text = " ".join(result.stdout.split())
    for option in ("--preset", "--foundation", "--skin", "--params", "--coverage",
                   "--absorption", "--resolution", "--inter-reflection", "--out", "--name"):
        assert option in text
    for unit in ("[0, 1]", "1/sr", "per RGB channel", "docs/baking.md"):
        assert unit in text


def test_progress_bar_only_on_a_terminal():
    class Stream:
        def __init__(self, tty):
            self.tty, self.text = tty, ""

        def isatty(self):
            return self.tty

        def write(self, text):
            self.text += text

        def flush(self):
            pass

    for tty in (True, False):
        stream = Stream(tty)
        progress = cli_bake._Progress(stream)
        progress(0.5, "path 3")
        progress.close()
        assert ("[###############" in stream.text and "50%" in stream.text) is tty
        assert (stream.text == "") is (not tty)


def test_parameter_file_schema():
    skin = params_file.load_params(EXAMPLE)
    assert skin.name == "beige_on_skin1" and skin.coverage == 0.8
    np.testing.assert_allclose(skin.absorption, [0.12, 0.26, 0.45])
    assert float(skin.film.n) == 0.036 and float(skin.film_transmission.P_t) == 0.04
    base = presets.made_up_skin("medium_beige", "jensen_skin1")
    assert float(skin.film.P_s) == float(base.film.P_s)  # not overridden
    np.testing.assert_array_equal(skin.skin.P_d, base.skin.P_d)
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
