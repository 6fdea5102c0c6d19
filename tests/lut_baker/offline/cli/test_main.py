"""The command line's frame (lut_baker.offline.cli.main): the commands, bad input as one line
with exit 2, and SIGINT/SIGTERM turned into an exception that unwinds the command."""

import os
import signal
import types

import pytest

from lut_baker.offline.cli import main


def test_help_lists_every_command(capsys):
    with pytest.raises(SystemExit) as stop:
        main.main(["--help"])
    assert stop.value.code == 0
    out = capsys.readouterr().out
    for name in main.COMMANDS:
        assert name in out


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
