"""SIGINT and SIGTERM as an exception, :class:`Interrupted` (a ``KeyboardInterrupt``), raised
where the program is, like Ctrl-C -- but never inside Python's import machinery or a finaliser.

An exception raised while a module is being imported can be lost or changed on its way out: in
a module lock's weakref callback Python prints it as "Exception ignored" and carries on; in a
class statement's ``__set_name__`` it becomes a ``RuntimeError``.  So a signal that arrives
there is held and raised once the import is over: a SIGALRM timer retries every
:data:`RETRY_S` (when no one else uses the timer), and the next signal, the end of the protected
block or :func:`raise_held` raise it at the latest.  The first signal raised makes later SIGINT and
SIGTERM ignored, so that clean-up is not cut short.

Standard library only (signal, threading, contextlib): the command line imports it before
anything heavy.

- :func:`signals_interrupt` -- a block inside which the signals raise :class:`Interrupted`;
- :func:`take_signals` -- the same for the rest of the process (``python -m lut_baker``);
- :func:`release_signals`, :func:`ignore_signals`, :func:`raise_held` -- the process's start
  (signals the entry point held back get through), end (its outcome known) and safe points;
- :func:`report` -- the line ``interrupted`` and the exit code, 128 + the signal number.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from typing import Any

__all__ = ["Interrupted", "SIGNALS", "RETRY_S", "signals_interrupt", "take_signals",
           "release_signals", "ignore_signals", "raise_held", "report"]

SIGNALS = (signal.SIGINT, signal.SIGTERM)
RETRY_S = 0.005
"""Seconds between two tries to raise a signal held during an import."""

_TIMER = hasattr(signal, "setitimer")
_held: list[int] = []
"""The signal waiting for the import in progress to end (at most one)."""


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM arrived (``signum``): raised where the program is, like Ctrl-C."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _unsafe(frame) -> bool:
    """Whether ``frame`` runs inside Python's import machinery or a ``__del__``, where an
    exception may be swallowed or turned into another."""
    while frame is not None:
        if (frame.f_globals.get("__name__", "").startswith("importlib._bootstrap")
                or frame.f_code.co_name == "__del__"):
            return True
        frame = frame.f_back
    return False


def _stop(signum: int):
    """Raise :class:`Interrupted`; from now on SIGINT and SIGTERM are ignored."""
    _held.clear()
    for other in SIGNALS:
        if signal.getsignal(other) is _deliver:
            signal.signal(other, signal.SIG_IGN)
    raise Interrupted(signum)


def _deliver(signum, frame):
    """The SIGINT and SIGTERM handler: raise, or hold the signal while it is unsafe (then the
    retry timer, the end of the block or the next signal raises it)."""
    if _unsafe(frame):
        if not _held:
            _held.append(signum)
        if _TIMER and signal.getsignal(signal.SIGALRM) is _retry:
            signal.setitimer(signal.ITIMER_REAL, RETRY_S)
        return
    _stop(_held[0] if _held else signum)


def _retry(alarm, frame):
    """The SIGALRM handler: try again to raise the held signal."""
    if _held:
        _deliver(_held[0], frame)


def raise_held() -> None:
    """Raise :class:`Interrupted` if a signal is held (a safe point)."""
    if _held:
        _stop(_held[0])


def _take(replaced: dict) -> None:
    """Install the handlers, recording in ``replaced`` the handler each signal had.  A signal
    the process was started to ignore stays ignored, one already taken (by an enclosing block)
    is left to it, and the retry timer is used only when no one else uses SIGALRM; outside the
    main thread nothing changes."""
    if threading.current_thread() is not threading.main_thread():
        return
    for signum in SIGNALS:
        handler = signal.getsignal(signum)
        if handler not in (signal.SIG_IGN, None, _deliver):
            replaced[signum] = handler
            signal.signal(signum, _deliver)
    if (_TIMER and signal.getsignal(signal.SIGALRM) == signal.SIG_DFL
            and signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)):
        replaced[signal.SIGALRM] = signal.SIG_DFL
        signal.signal(signal.SIGALRM, _retry)


def _restore(replaced: dict) -> None:
    """Put back the handlers :func:`_take` replaced (the retry timer stopped first)."""
    if _TIMER and signal.SIGALRM in replaced:  # (Windows has neither)
        signal.setitimer(signal.ITIMER_REAL, 0)
        _held.clear()
    for signum, handler in replaced.items():
        signal.signal(signum, handler)


@contextlib.contextmanager
def signals_interrupt():
    """While inside, SIGINT and SIGTERM raise :class:`Interrupted` (held while unsafe, see the
    module's docstring; one still held when the block ends is raised then); later ones are
    ignored until the block is left, so that clean-up is not cut short.  Signals the process
    was started to ignore stay ignored; outside the main thread nothing changes; inside an
    enclosing block (or after :func:`take_signals`) the enclosing handling goes on."""
    replaced: dict[int, Any] = {}  # signal number -> the handler it had
    try:
        _take(replaced)
        yield
    finally:
        try:
            raise_held()
        finally:
            _restore(replaced)


def take_signals() -> None:
    """Install the handlers of :func:`signals_interrupt` for the rest of the process."""
    _take({})


def release_signals() -> None:
    """Let SIGINT and SIGTERM through where they were held back with ``pthread_sigmask`` (one
    that came meanwhile arrives now)."""
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)


def ignore_signals() -> None:
    """SIGINT and SIGTERM ignored, the retry timer stopped (the process's outcome is known: it
    only has to exit)."""
    if threading.current_thread() is threading.main_thread():
        for signum in SIGNALS:
            signal.signal(signum, signal.SIG_IGN)
        if _TIMER and signal.getsignal(signal.SIGALRM) is _retry:
            signal.setitimer(signal.ITIMER_REAL, 0)
    _held.clear()


def report(error: KeyboardInterrupt) -> int:
    """Say ``interrupted`` (one line on stderr); the exit code, 128 + the signal number."""
    print("interrupted", file=sys.stderr)
    return 128 + int(getattr(error, "signum", signal.SIGINT))
