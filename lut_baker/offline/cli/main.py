"""The command line: ``python -m lut_baker <command> ...``.

Each command lives in its own module exposing ``HELP`` (one line), ``configure(parser)`` (adds
its arguments) and ``run(args) -> int`` (the exit code).  Modules are imported only when their
command runs, so ``--help`` stays fast.  Bad input exits with code 2 and one line naming the
argument (argparse's convention); a ``ValueError`` raised by the model is reported the same way.
SIGINT and SIGTERM unwind the command like Ctrl-C (``finally`` blocks remove temporaries) and
exit with 128 + the signal number after one line, ``interrupted``.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import signal
import sys
import threading

__all__ = ["COMMANDS", "main", "build_parser", "Interrupted", "signals_interrupt"]

COMMANDS = {
    "bake": ".bake_command",
    "fit": ".fit_command",
    "figures": ".figures_command",
    "foundations": ".foundations_command",
}
"""Command name -> module (relative to this package) implementing it."""


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM arrived (``signum``): raised where the program is, like Ctrl-C."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def signals_interrupt():
    """While inside, SIGINT and SIGTERM raise :class:`Interrupted`; later ones are ignored
    until the block is left, so that clean-up is not cut short.  Signals the process was
    started to ignore stay ignored; outside the main thread nothing changes."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {signum: signal.getsignal(signum) for signum in SIGNALS}
    handled = [signum for signum, handler in previous.items()
               if handler not in (signal.SIG_IGN, None)]

    def interrupt(signum, frame):
        for other in handled:
            signal.signal(other, signal.SIG_IGN)
        raise Interrupted(signum)

    for signum in handled:
        signal.signal(signum, interrupt)
    try:
        yield
    finally:
        for signum in handled:
            signal.signal(signum, previous[signum])


def _module(name: str):
    return importlib.import_module(COMMANDS[name], __package__)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m lut_baker",
        description="Made-up skin model (Baba, Mukaigawa, Yagi): fit, bake, draw.",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        try:
            module = _module(name)
        except ModuleNotFoundError as error:  # a command not built yet must say so, not vanish
            sub.add_parser(name, help=f"(unavailable: {error})")
            continue
        command = sub.add_parser(name, help=module.HELP, description=module.__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
        module.configure(command)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with signals_interrupt():
            return int(_module(args.command).run(args) or 0)
    except ValueError as error:
        parser.exit(2, f"{parser.prog} {args.command}: error: {error}\n")
    except KeyboardInterrupt as error:
        print("interrupted", file=sys.stderr)
        return 128 + int(getattr(error, "signum", signal.SIGINT))
