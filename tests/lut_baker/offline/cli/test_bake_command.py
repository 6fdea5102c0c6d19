"""``python -m lut_baker bake`` (lut_baker.offline.cli.bake_command): the tables it writes, its
options and parameter files, its errors (one line, nothing half-written) and signals."""

import errno
import importlib.util
import json
import os
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from lut_baker import bake
from lut_baker.model import params_file, presets
from lut_baker.offline import exr_files
from lut_baker.offline.cli import bake_command, main
from lut_baker.tables import codec

ROOT = Path(__file__).resolve().parents[4]
EXAMPLE = ROOT / "examples" / "beige_on_skin1.toml"


def run_cli(*args, cwd=ROOT, **kwargs):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "lut_baker", "bake", *map(str, args)],
                          cwd=cwd, env=env, capture_output=True, text=True, timeout=120,
                          **kwargs)


def parse(*args):
    return main.build_parser().parse_args(["bake", *map(str, args)])


def test_cli_bake_writes_the_same_tables_as_the_function(tmp_path):
    result = run_cli("--preset", "paper", "--resolution", "preview", "--out", tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("\n") == 1 and "paper.exr" in result.stdout
    assert "[###" not in result.stderr  # no progress bar when stderr is not a terminal
    meta = json.loads((tmp_path / "paper.json").read_text())
    assert meta["sha256"] == codec.content_hash(bake.bake(presets.paper(), "preview"))
    assert codec.content_hash(exr_files.load_tables(tmp_path / "paper.exr")) == meta["sha256"]


def test_cli_bakes_the_film_at_a_thickness(tmp_path):
    """--thickness: the tables hold the slab, as the function bakes them, read back from the
    file."""
    args = ("--foundation", "clarins_103", "--thickness", "9.6", "--resolution", "preview")
    assert main.main(["bake", *args, "--out", str(tmp_path), "--name", "sheer"]) == 0
    meta = json.loads((tmp_path / "sheer.json").read_text())
    assert meta["parameters"]["film_thickness_um"] == 9.6 and "slab_top" in meta["layout"]
    skin = bake_command.skin_from_args(parse(*args))
    assert meta["sha256"] == codec.content_hash(bake.bake(skin, "preview", film=9.6))
    assert exr_files.load_tables(tmp_path / "sheer.exr").slab is not None


@pytest.mark.slow  # a fresh Python bakes (~0.8 s)
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
    skin = bake_command.skin_from_args(parse("--params", EXAMPLE, "--coverage", "0.25",
                                         "--absorption", "0", "0.5", "1"))
    expected = bake.bake(skin, "preview", inter_reflection=True)
    assert meta["sha256"] == codec.content_hash(expected)


@pytest.mark.slow  # a fresh Python bakes (~0.8 s)
@pytest.mark.bpy
def test_bake_inside_blenders_python_gives_the_same_tables(tmp_path):
    """The same bake after `import bpy` (Blender's Python as a module) hashes the same.  bpy is
    imported in the subprocess only (with a temporary BLENDER_USER_RESOURCES): importing it here
    would bypass tests/conftest.py's fixture, which must set that folder first."""
    if importlib.util.find_spec("bpy") is None:
        pytest.skip("bpy is not importable; run with the venv from tools/venv.sh")
    code = ("import bpy, lut_baker.bake as b, lut_baker.tables.codec as i, "
            "lut_baker.model.presets as p;"
            "print(i.content_hash(b.bake(p.paper(), 'preview')))")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "BLENDER_USER_RESOURCES": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == codec.content_hash(
        bake.bake(presets.paper(), "preview"))


def main_exit(capsys, *args):
    """Run ``python -m lut_baker bake ARGS`` in-process: (exit code, stderr)."""
    with pytest.raises(SystemExit) as exit_info:
        main.main(["bake", *map(str, args)])
    return exit_info.value.code, capsys.readouterr().err


def params_error(capsys, path, text):
    """Write ``text`` to the parameter file ``path``, bake with it into ``out/`` beside it and
    return the error line: exit code 2, one line, and no ``out/`` made."""
    path.write_text(text)
    out = path.parent / "out"
    code, err = main_exit(capsys, "--params", path, "--out", out)
    assert code == 2
    line = err.strip()
    assert "\n" not in line, err
    assert not out.exists()
    return line


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
    (["--thickness", "0"], "--thickness"),
    (["--thickness", "thin"], "--thickness"),
    (["--thickness", "inf"], "--thickness"),
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
    line = params_error(capsys, tmp_path / "bad.toml", text)
    assert "--params" in line
    assert re.search(message, line), line


def test_missing_openimageio_is_one_clear_line(capsys, monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "OpenImageIO", None)  # import fails
    assert main.main(["bake", "--resolution", "preview", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "needs OpenImageIO" in err and "pip install" in err
    assert not any(tmp_path.iterdir())


def test_help_explains_every_option_with_units():
    result = run_cli("--help")
    assert result.returncode == 0
    text = " ".join(result.stdout.split())
    for option in ("--preset", "--foundation", "--skin", "--params", "--coverage",
                   "--absorption", "--resolution", "--thickness", "--inter-reflection", "--out",
                   "--name"):
        assert option in text
    for unit in ("[0, 1]", "1/sr", "per RGB channel", "docs/baking.md", "micrometres"):
        assert unit in text
    # Every foundation preset is listed, the measured products included.
    for name in presets.FOUNDATIONS:
        assert name in text
    assert "clarins_105" in text


def test_a_parameter_file_naming_a_measured_foundation_bakes(tmp_path):
    """``foundation = "clarins_105"`` in a parameter file bakes the product's film: its gloss
    and absorption (docs/model.md §4)."""
    path = tmp_path / "dewy.toml"
    path.write_text('foundation = "clarins_105"\nskin = "jensen_skin1"\n')
    skin = bake_command.skin_from_args(parse("--params", path))
    expected = presets.made_up_skin("clarins_105", "jensen_skin1")
    assert float(skin.film.P_s) == presets.FOUNDATIONS["clarins_105"]["film"]["P_s"]
    assert params_file.skin_to_dict(skin) == params_file.skin_to_dict(expected)
    tables = bake.bake(skin, "preview")
    assert codec.content_hash(tables) == codec.content_hash(bake.bake(expected, "preview"))
    assert codec.content_hash(tables) != codec.content_hash(
        bake.bake(presets.made_up_skin("paper_natural", "jensen_skin1"), "preview"))


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
        progress = bake_command.Progress(stream)
        progress(0.5, "path 3")
        progress.close()
        assert ("[###############" in stream.text and "50%" in stream.text) is tty
        assert (stream.text == "") is (not tty)


# --- output problems: one line, non-zero exit, nothing half-written --------------------------
def run_main(capsys, *args):
    """``python -m lut_baker bake ARGS`` in-process: (exit code, stderr), returned or raised."""
    try:
        code = main.main(["bake", *map(str, args)])
    except SystemExit as exit_info:
        code = exit_info.code
    return code, capsys.readouterr().err


def one_error_line(err: str) -> str:
    """The single stderr line of a failed bake (asserts there is exactly one)."""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("python -m lut_baker bake: error: "), err
    return lines[0]


def listing(folder: Path) -> dict:
    """Every file under ``folder`` (hidden ones included) -> its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()}


@pytest.fixture
def old_pair(tmp_path):
    """OUT/paper.exr + OUT/paper.json from an earlier good bake: (folder, listing)."""
    folder = tmp_path / "out"
    result = run_cli("--resolution", "preview", "--out", folder)
    assert result.returncode == 0, result.stderr
    return folder, listing(folder)


def test_out_naming_a_file_is_one_line(capsys, tmp_path):
    target = tmp_path / "afile"
    target.write_text("keep me")
    code, err = run_main(capsys, "--resolution", "preview", "--out", target)
    line = one_error_line(err)
    assert code != 0
    assert str(target) in line and "is a file, not a folder" in line
    assert listing(tmp_path) == {"afile": b"keep me"}


@pytest.mark.slow  # a fresh Python bakes (~0.8 s)
def test_out_under_a_file_is_one_line_from_the_shell(tmp_path):
    (tmp_path / "afile").write_text("keep me")
    result = run_cli("--resolution", "preview", "--out", tmp_path / "afile" / "sub")
    assert result.returncode != 0
    line = one_error_line(result.stderr)
    assert f"'{tmp_path / 'afile'}' is a file, not a folder" in line
    assert "Traceback" not in result.stderr
    assert listing(tmp_path) == {"afile": b"keep me"}


def test_image_name_taken_by_a_folder_is_one_line(capsys, tmp_path):
    (tmp_path / "paper.json").mkdir()
    code, err = run_main(capsys, "--resolution", "preview", "--out", tmp_path)
    line = one_error_line(err)
    assert code != 0 and f"'{tmp_path / 'paper.json'}' is a folder" in line
    assert [p.name for p in tmp_path.iterdir()] == ["paper.json"]


def _make_read_only(folder: Path):
    """Make ``folder`` unwritable for this user: chmod for a user, the immutable attribute
    for root (whom permissions do not stop); the undo function, or a skip."""
    if os.geteuid() != 0:
        folder.chmod(0o555)
        return lambda: folder.chmod(0o755)
    chattr = shutil.which("chattr")
    if chattr is None or subprocess.run([chattr, "+i", str(folder)],
                                        capture_output=True).returncode != 0:
        pytest.skip("running as root on a file system without the immutable attribute: "
                    "no way to make a folder read-only")
    return lambda: subprocess.run([chattr, "-i", str(folder)], check=True)


def test_read_only_out_folder_is_one_line(capsys, tmp_path):
    folder = tmp_path / "locked"
    folder.mkdir()
    undo = _make_read_only(folder)
    try:
        code, err = run_main(capsys, "--resolution", "preview", "--out", folder / "sub")
    finally:
        undo()
    line = one_error_line(err)
    assert code != 0 and f"no permission to write in '{folder}'" in line
    assert listing(tmp_path) == {}


@pytest.mark.slow  # a fresh Python bakes (~0.8 s)
@pytest.mark.parametrize("error, words", [
    (OSError(errno.ENOSPC, "No space left on device"), "no space left on the disk"),
    (PermissionError(errno.EACCES, "Permission denied"), "no permission to write in"),
    (OSError(errno.EIO, "Input/output error"), "Input/output error"),
])
def test_write_errors_are_one_line_and_keep_the_old_pair(capsys, monkeypatch, old_pair, error,
                                                         words):
    """The disk fills up (or another write error) while the temporaries are flushed: one
    line, exit 1, the earlier pair untouched and no temporary left."""
    folder, before = old_pair

    def fail(fd):
        raise error

    monkeypatch.setattr(exr_files.os, "fsync", fail)
    code, err = run_main(capsys, "--resolution", "preview", "--coverage", "0.5",
                         "--out", folder)
    line = one_error_line(err)
    assert code == 1 and f"cannot write '{folder / 'paper.exr'}'" in line and words in line
    assert listing(folder) == before


def test_write_error_in_a_new_folder_leaves_nothing(capsys, monkeypatch, tmp_path):
    def fail(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(exr_files.os, "fsync", fail)
    code, err = run_main(capsys, "--resolution", "preview", "--out", tmp_path / "new" / "out")
    assert code == 1 and "no space left on the disk" in one_error_line(err)
    assert list(tmp_path.iterdir()) == []


SLOW_WRITE = """
import os, signal, sys, time
signal.signal(signal.SIGINT, signal.default_int_handler)  # as when started from a terminal
from lut_baker.offline.cli import main

def slow_fsync(fd):  # both temporaries are written when they are flushed
    print("writing", flush=True)
    time.sleep(60)

os.fsync = slow_fsync
sys.exit(main.main(sys.argv[1:]))
"""

@pytest.mark.slow  # a fresh Python bakes (~0.8 s)
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
@pytest.mark.parametrize("earlier", [False, True])
def test_signal_during_the_write_cleans_up(tmp_path, signum, earlier):
    folder = tmp_path / "out"
    if earlier:
        assert run_cli("--resolution", "preview", "--out", folder).returncode == 0
    before = listing(folder) if earlier else {}
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    process = subprocess.Popen(
        [sys.executable, "-c", SLOW_WRITE, "bake", "--resolution", "preview", "--coverage",
         "0.5", "--out", str(folder)],
        cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert process.stdout.readline() == "writing\n", process.stderr.read()
        assert any(p.name.startswith(".") for p in folder.iterdir())  # temporaries exist now
        process.send_signal(signum)
        code = process.wait(timeout=10)
    finally:
        process.kill()
        process.wait()
    assert code == 128 + signum
    assert process.stderr.read().strip() == "interrupted"
    assert listing(folder) == before


@pytest.mark.slow  # a fresh Python bakes (~0.8 s)
def test_sigterm_during_the_bake_exits_cleanly(tmp_path):
    code = ("import os, signal, sys; from lut_baker import bake; "
            "from lut_baker.offline.cli import main;"
            "bake.bake = lambda *a, **k: os.kill(os.getpid(), signal.SIGTERM);"
            "sys.exit(main.main(sys.argv[1:]))")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    result = subprocess.run([sys.executable, "-c", code, "bake", "--out", str(tmp_path)],
                            cwd=ROOT, env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 128 + signal.SIGTERM
    assert result.stderr.strip() == "interrupted"
    assert list(tmp_path.iterdir()) == []


# --- --name is a file stem ------------------------------------------------------------------
@pytest.mark.parametrize("name, words", [
    ("../evil", "is a path"),
    ("a/b", "is a path"),
    ("/tmp/evil", "is a path"),
    ("a\\b", "is a path"),
    ("C:evil", "is a path"),
    ("", "is empty"),
    ("  ", "is empty"),
    ("..", "starts with a dot"),
    (".", "is a path"),
    (".hidden", "starts with a dot"),
    ("mine.exr", "ends in .exr"),
    ("mine.JSON", "ends in .json"),
    ("a\nb", "control character"),
])
def test_name_must_be_a_file_stem(capsys, tmp_path, name, words):
    out = tmp_path / "out"
    code, err = main_exit(capsys, "--resolution", "preview", "--out", out, "--name", name)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "argument --name" in lines[0] and words in lines[0], err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow  # a fresh Python bakes (~0.8 s)
def test_name_may_hold_dots_inside(tmp_path):
    assert parse("--name", "beige v1.5").name == "beige v1.5"
    result = run_cli("--resolution", "preview", "--out", tmp_path, "--name", "skin.v1.5")
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["skin.v1.5.exr", "skin.v1.5.json"]


@pytest.mark.parametrize("text, words", [
    ('name = ""', "is empty"),
    ('name = ".."', "starts with a dot"),
])
def test_name_from_the_parameter_file_must_make_a_stem(capsys, tmp_path, text, words):
    line = params_error(capsys, tmp_path / "p.toml", text)
    assert "--name" in line and words in line, line


# --- parameter file values of the wrong type ------------------------------------------------
@pytest.mark.parametrize("text, message", [
    ('[film]\nn = "abc"', r"\[film\] n: expected a number or 3 numbers .*, got 'abc'"),
    ("[film]\neta = true", r"\[film\] eta: expected a number .*, got true"),
    ("[skin_surface]\nP_d = [1, 2]", r"\[skin_surface\] P_d: expected a number or 3 numbers"),
    ('[dipole]\nsigma_s = [1, "x", 2]', r"\[dipole\] sigma_s: expected .*, got \[1, 'x', 2\]"),
    ("[film_transmission]\nP_t = {a = 1}", r"\[film_transmission\] P_t: expected a number"),
    ('coverage = "x"', r"coverage: expected a number, got 'x'"),
    ("coverage = false", r"coverage: expected a number, got false"),
    ("coverage = [0.1, 0.2, 0.3]", r"coverage: expected a number, got \[0.1, 0.2, 0.3\]"),
    ('absorption = ["a", 1, 2]', r"absorption: expected a number or 3 numbers"),
    ("absorption = [[0.1, 0.2, 0.3]]", r"absorption: expected a number or 3 numbers"),
    ("absorption = true", r"absorption: expected .*, got true"),
    ('reflection_shutter_s = "3"', r"reflection_shutter_s: expected a number .*, got '3'"),
    ("transmission_shutter_s = true", r"transmission_shutter_s: expected a number"),
    ("name = 3", r"name: expected text in quotes, got 3"),
    ('units = "counts"\n[film]\nP_d = 1\nP_s = 2\nn = 0.03\neta = "x"',
     r"\[film\] eta: expected a number"),
])
def test_parameter_values_of_the_wrong_type_name_file_and_key(capsys, tmp_path, text, message):
    bad = tmp_path / "params.toml"
    line = params_error(capsys, bad, text)
    assert f"--params '{bad}'" in line
    assert re.search(message, line), line
    with pytest.raises(ValueError, match=message) as error:
        params_file.load_params(bad)
    assert str(bad) in str(error.value)
