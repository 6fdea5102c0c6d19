"""The command line's frame (lut_baker.offline.cli.main): the commands, bad input as one line
with exit 2, SIGINT/SIGTERM turned into an exception that unwinds the command, and
``python -m lut_baker`` signalled at any moment (an import, the bake, each step of the write)
ending with the one line ``interrupted`` and 128 + n, or normally; never a traceback."""

import os
import shutil
import signal
import subprocess
import sys
import time
import types
from pathlib import Path

import pytest

from lut_baker.offline import exr_files
from lut_baker.offline.cli import main


def test_help_lists_every_command(capsys):
    with pytest.raises(SystemExit) as stop:
        main.main(["--help"])
    assert stop.value.code == 0
    out = capsys.readouterr().out
    for name in main.COMMANDS:
        assert name in out


def test_a_command_imports_only_its_own_module():
    """``bake`` builds its own parser only: the other commands' modules, and scipy and
    matplotlib that they need, are not imported (the whole bake process takes under a
    second)."""
    code = ("import sys\n"
            "from lut_baker.offline.cli import main\n"
            "try:\n    main.main(['bake', '--help'])\nexcept SystemExit:\n    pass\n"
            "print(sorted(m for m in ('scipy', 'matplotlib', 'lut_baker.offline.cli.fit_command',"
            " 'lut_baker.offline.cli.figures_command') if m in sys.modules))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True, cwd=Path(__file__).resolve().parents[4])
    assert result.stdout.strip().splitlines()[-1] == "[]", result.stdout


def test_an_unknown_command_exits_2(capsys):
    with pytest.raises(SystemExit) as stop:
        main.main(["nonsense"])
    assert stop.value.code == 2
    assert "nonsense" in capsys.readouterr().err


def _command(run):
    return types.SimpleNamespace(HELP="a test command", __doc__="A test command.",
                                 configure=lambda parser: None, run=run)


def test_a_value_error_of_a_command_is_one_line_and_exit_2(capsys, monkeypatch):
    def run(args):
        raise ValueError("coverage must lie in [0, 1], got 2")

    monkeypatch.setattr(main, "COMMANDS", {"try": ".try"})
    monkeypatch.setattr(main, "_module", lambda name: _command(run))
    with pytest.raises(SystemExit) as stop:
        main.main(["try"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [
        "python -m lut_baker try: error: coverage must lie in [0, 1], got 2"]


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_unwinds_the_command_and_exits_128_plus_it(capsys, monkeypatch, signum):
    cleaned = []

    def run(args):
        try:
            os.kill(os.getpid(), signum)
        finally:
            cleaned.append(True)

    monkeypatch.setattr(main, "COMMANDS", {"try": ".try"})
    monkeypatch.setattr(main, "_module", lambda name: _command(run))
    before = signal.getsignal(signum)
    assert main.main(["try"]) == 128 + signum
    assert cleaned == [True]
    assert capsys.readouterr().err.strip() == "interrupted"
    assert signal.getsignal(signum) == before  # handlers restored


# --- python -m lut_baker, interrupted for real -----------------------------------------------
# A fresh Python runs the entry point as ``-m`` does (runpy, ``lut_baker.__main__``) after a
# hook fixes when the signal comes: the child sends it to itself at a chosen moment, so that each
# moment is hit every time.  Python's own start-up (before the entry point's first line, ~15 ms
# here) is out of the project's reach and not tested.

ROOT = Path(__file__).resolve().parents[4]

AS_MAIN = """
import os, runpy, signal, sys
{hook}
runpy.run_module("lut_baker", run_name="__main__", alter_sys=True)
"""

SIGNAL_AT_IMPORT = """
def hook(event, args, sent=[]):  # the import of MODULE starts: the signal arrives inside it
    if event == "import" and args[0] == {module!r} and not sent:
        sent.append(True)
        os.kill(os.getpid(), {signum})
sys.addaudithook(hook)
"""

SIGNAL_AT_STAGE = """
import lut_baker.bake as baking
stage = baking._stage
def signal_at(progress, fraction, message):  # the bake reaches a stage: the signal arrives
    stage(progress, fraction, message)
    if fraction == {fraction}:
        os.kill(os.getpid(), signal.SIGINT)
baking._stage = signal_at
"""

SIGNAL_AFTER_CALL = """
import itertools
calls = itertools.count(1)
original = getattr(os, {name!r})
def signal_after(*args, **kwargs):  # the signal arrives as the system call returns
    result = original(*args, **kwargs)
    if next(calls) == {nth}:
        os.kill(os.getpid(), signal.SIGINT)
    return result
setattr(os, {name!r}, signal_after)
"""

SIGNAL_AT_EXIT = """
import atexit
atexit.register(os.kill, os.getpid(), signal.SIGINT)  # the interpreter is shutting down
"""

READY = """
def hook(event, args, said=[]):  # the entry point's first line is about to run
    name = getattr(args[0], "co_filename", "") if event == "exec" else ""
    if name.endswith("lut_baker/__main__.py") and not said:
        said.append(True)
        print("ready", flush=True)
sys.addaudithook(hook)
"""


def start(hook: str, *args, **kwargs) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen([sys.executable, "-c", AS_MAIN.format(hook=hook), *map(str, args)],
                            cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, **kwargs)


def finish(process: subprocess.Popen, timeout=120) -> tuple[int, str, str]:
    try:
        out, err = process.communicate(timeout=timeout)
    finally:
        process.kill()
        process.wait()
    return process.returncode, out, err


def listing(folder: Path) -> dict:
    """Every file under ``folder`` (hidden ones included) -> its bytes."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()} if folder.exists() else {}


def a_whole_pair_or_the_earlier(folder: Path, before: dict) -> bool:
    """What an interrupted bake may leave in ``folder``: the earlier files untouched, or a new
    pair that loads (the image's hash matches its sidecar); never a temporary or a half pair."""
    after = listing(folder)
    if after == before:
        return True
    if sorted(after) != ["paper.exr", "paper.json"]:
        return False
    exr_files.load_tables(folder / "paper.exr")  # raises on a mismatched or partial pair
    return True


# Another skin than the earlier pair's under the same name: other pixels, so a half-replaced pair
# cannot pass for a whole one.
BAKE = ("bake", "--resolution", "preview", "--skin", "jensen_skin1", "--name", "paper", "--out")

# (command line, the module whose import the signal interrupts): every command, while the
# parser is built (numpy, scipy), while a command starts (its lazy imports) and while the
# command line's own module loads, before its handlers are in place.
IMPORTS = [
    (BAKE, "lut_baker.offline.cli.main"),
    (BAKE, "numpy"),
    (BAKE, "OpenImageIO"),
    (("fit", "--help"), "scipy"),
    (("figures", "--only", "fig05_film_reflection", "--out"), "matplotlib"),
    (("foundations", "--data", "no_such_folder", "--presets", "{tmp}/presets.json", "--out"),
     "matplotlib"),
]


@pytest.mark.slow  # interpreters started and interrupted
def test_a_signal_during_any_import_is_one_line_and_128_plus_it(tmp_path):
    """SIGINT (and SIGTERM) while a module is being imported, at every stage of every command:
    one line, ``interrupted``, exit 128 + n, nothing written.  (The children run side by side.)"""
    cases = [(args, module, signal.SIGINT) for args, module in IMPORTS]
    cases += [(BAKE, "lut_baker.offline.cli.main", signal.SIGTERM),
              (("fit", "--help"), "scipy", signal.SIGTERM)]
    runs = []
    for n, (args, module, signum) in enumerate(cases):
        out = tmp_path / f"out{n}"
        args = [a.format(tmp=tmp_path) for a in args] + ([out] if args[-1] == "--out" else [])
        hook = SIGNAL_AT_IMPORT.format(module=module, signum=int(signum))
        runs.append((module, signum, out, start(hook, *args)))
    for module, signum, out, process in runs:
        code, _, err = finish(process)
        assert (code, err) == (128 + signum, "interrupted\n"), (module, signum, err[-2000:])
        assert listing(out) == {}
    assert sorted(p.name for p in tmp_path.iterdir()) == []


DELAYS_S = (0, 0.05, 0.1, 0.2, 0.4, 0.8)


@pytest.mark.slow  # interpreters started and interrupted
def test_sigint_at_any_moment_ends_cleanly_or_not_at_all(tmp_path):
    """SIGINT after 0 ... 0.8 s of a preview bake (imports, bake and write, whatever each delay
    meets on this machine): every child either prints ``interrupted`` alone and exits 130 leaving
    no partial file, or completes normally; never a traceback."""
    runs = []
    for delay in DELAYS_S:
        out = tmp_path / f"after{delay}"
        runs.append((delay, out, start(READY, *BAKE, out)))
    signal_at = []
    for delay, _, process in runs:  # each delay counts from its child's entry point
        assert process.stdout.readline() == "ready\n"
        signal_at.append((time.monotonic() + delay, process))
    for when, process in sorted(signal_at, key=lambda pair: pair[0]):
        time.sleep(max(0.0, when - time.monotonic()))
        process.send_signal(signal.SIGINT)
    outcomes = []
    for delay, out, process in runs:
        code, stdout, err = finish(process)
        if code == 0:
            assert err == "" and stdout.startswith("baked "), (delay, err[-2000:])
            assert sorted(listing(out)) == ["paper.exr", "paper.json"]
        else:
            assert (code, err) == (130, "interrupted\n"), (delay, code, err[-2000:])
            assert a_whole_pair_or_the_earlier(out, {})
        outcomes.append(code)
    assert 130 in outcomes, outcomes  # at least the early ones met the imports


@pytest.mark.slow  # interpreters started and interrupted
def test_sigint_during_the_shutdown_changes_nothing(tmp_path):
    """A bake that has done its work and is exiting: a signal then is ignored (exit 0, the
    pair in place, nothing on stderr)."""
    code, out, err = finish(start(SIGNAL_AT_EXIT, *BAKE, tmp_path))
    assert (code, err) == (0, ""), err[-2000:]
    assert out.startswith("baked ") and sorted(listing(tmp_path)) == ["paper.exr", "paper.json"]


@pytest.mark.slow  # four fresh Pythons bake (~6 s on 2 cores)
def test_sigint_during_the_bake_keeps_the_earlier_pair(tmp_path):
    """SIGINT as the bake reaches a stage (Fourier matrices, albedos, done):
    ``interrupted``, 130, and the earlier pair as it was."""
    folder = tmp_path / "earlier"
    code, _, err = finish(start("", "bake", "--resolution", "preview", "--out", folder))
    assert code == 0, err
    before = listing(folder)
    runs = []
    for fraction in (0.05, 0.45, 1.0):
        out = tmp_path / f"at{fraction}"
        shutil.copytree(folder, out)
        runs.append((fraction, out, start(SIGNAL_AT_STAGE.format(fraction=fraction), *BAKE, out)))
    for fraction, out, process in runs:
        code, _, err = finish(process)
        assert (code, err) == (130, "interrupted\n"), (fraction, err[-2000:])
        assert listing(out) == before


@pytest.mark.slow  # ten fresh Pythons bake (~6 s on 2 cores)
@pytest.mark.parametrize("earlier", [False, True])
def test_sigint_at_each_step_of_the_write_leaves_a_whole_pair(tmp_path, earlier):
    """SIGINT as each system call of the write returns (the temporaries flushed, the image
    renamed into place, the sidecar renamed): ``interrupted``, 130, and the folder holds the
    earlier pair (or nothing) or the whole new pair; never a temporary, never a half pair."""
    folder = tmp_path / "earlier"
    if earlier:
        code, _, err = finish(start("", "bake", "--resolution", "preview", "--out", folder))
        assert code == 0, err
    before = listing(folder)
    steps = [("fsync", 1), ("fsync", 2), ("replace", 1), ("replace", 2), ("fsync", 3)]
    runs = []
    for name, nth in steps:
        out = tmp_path / f"{name}{nth}"
        if earlier:
            shutil.copytree(folder, out)
        runs.append((name, nth, out, start(SIGNAL_AFTER_CALL.format(name=name, nth=nth),
                                           *BAKE, out)))
    for name, nth, out, process in runs:
        code, _, err = finish(process)
        assert (code, err) == (130, "interrupted\n"), (name, nth, err[-2000:])
        assert a_whole_pair_or_the_earlier(out, before), (name, nth, sorted(listing(out)))
