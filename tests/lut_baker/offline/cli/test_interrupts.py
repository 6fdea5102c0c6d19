"""SIGINT/SIGTERM as an exception (lut_baker.offline.cli.interrupts): raised where the program
is, held while a module is being imported (where Python would swallow it or turn it into
another exception) and raised once the import is over; handlers and timer put back after."""

import os
import signal
import sys
import textwrap

import pytest

from lut_baker.offline.cli import interrupts

SIGNALS_AND_TIMER = (signal.SIGINT, signal.SIGTERM, signal.SIGALRM)


def handlers():
    return {signum: signal.getsignal(signum) for signum in SIGNALS_AND_TIMER}


@pytest.fixture
def module_named(tmp_path, monkeypatch):
    """Write a module (its source given) into a folder on sys.path; returns its name."""
    monkeypatch.syspath_prepend(str(tmp_path))

    def write(name, source):
        (tmp_path / f"{name}.py").write_text(textwrap.dedent(source))
        monkeypatch.delitem(sys.modules, name, raising=False)
        return name

    return write


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_raises_where_the_program_is_and_later_ones_are_ignored(signum):
    before = handlers()
    reached = []
    with pytest.raises(interrupts.Interrupted) as raised:
        with interrupts.signals_interrupt():
            try:
                os.kill(os.getpid(), signum)
                reached.append("after the kill")  # never: raised at once
            finally:
                assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN  # clean-up runs on
                os.kill(os.getpid(), signal.SIGINT)  # ignored
    assert raised.value.signum == signum and reached == []
    assert handlers() == before


SIGNAL_WHILE_IMPORTED = """
import os, signal
os.kill(os.getpid(), signal.SIGINT)   # the signal arrives while this module is imported


class Named:
    def __set_name__(self, owner, name):   # an exception here would become a RuntimeError
        self.name = name


class Owner:
    attribute = Named()


total = sum(range(100_000))            # long enough for the retry timer to fire inside
done = True
"""


def test_a_signal_during_an_import_is_raised_once_the_import_is_over(module_named):
    name = module_named("imported_while_signalled", SIGNAL_WHILE_IMPORTED)
    before = handlers()
    with pytest.raises(interrupts.Interrupted) as raised:
        with interrupts.signals_interrupt():
            __import__(name)
            for _ in range(10**8):  # the timer's retry raises it here, within milliseconds
                pass
    assert raised.value.signum == signal.SIGINT
    assert sys.modules[name].done  # the module was imported whole
    assert type(raised.value.__context__) is not RuntimeError
    assert handlers() == before and signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_a_signal_held_at_the_end_of_the_block_is_raised_then(module_named):
    """Without the timer (SIGALRM in use by someone else) the end of the block raises it."""
    name = module_named("imported_while_signalled_2", SIGNAL_WHILE_IMPORTED)
    signal.signal(signal.SIGALRM, lambda *args: None)
    try:
        with pytest.raises(interrupts.Interrupted):
            with interrupts.signals_interrupt():
                __import__(name)
                assert sys.modules[name].done  # still held: the block has not ended
    finally:
        signal.signal(signal.SIGALRM, signal.SIG_DFL)


def test_an_enclosing_block_keeps_the_handling():
    with interrupts.signals_interrupt():
        outer = handlers()
        with interrupts.signals_interrupt():
            assert handlers() == outer
        assert handlers() == outer
        with pytest.raises(interrupts.Interrupted):
            with interrupts.signals_interrupt():
                os.kill(os.getpid(), signal.SIGTERM)
        assert signal.getsignal(signal.SIGTERM) == signal.SIG_IGN  # the enclosing: ignoring


def test_report_is_one_line_and_128_plus_the_signal(capsys):
    assert interrupts.report(interrupts.Interrupted(signal.SIGTERM)) == 128 + signal.SIGTERM
    assert interrupts.report(KeyboardInterrupt()) == 128 + signal.SIGINT
    assert capsys.readouterr().err == "interrupted\ninterrupted\n"
