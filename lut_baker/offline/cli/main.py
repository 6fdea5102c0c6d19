"""The command line: ``python -m lut_baker <command> ...``.

Each command lives in its own module exposing ``HELP`` (one line), ``configure(parser)`` (adds
its arguments) and ``run(args) -> int`` (the exit code).  Modules are imported by :func:`main`,
inside its handling of signals.  Bad input exits with code 2 and one line naming the argument
(argparse's convention); a ``ValueError`` raised by the model is reported the same way.
SIGINT and SIGTERM unwind the command like Ctrl-C (``finally`` blocks remove temporaries) and
exit with 128 + the signal number after one line, ``interrupted``.

This module and :mod:`.interrupts` (the signal handling) import little of the standard library
(argparse only when the parser is built): ``lut_baker.__main__`` imports them first and
:func:`command_line` installs the handlers before anything heavy (numpy, scipy, OpenImageIO) is
imported, so that a signal at any moment of ``python -m lut_baker`` ends the same way.
"""

from __future__ import annotations

import importlib

from . import interrupts
from .interrupts import Interrupted, signals_interrupt

TYPE_CHECKING = False  # (typing itself takes milliseconds to import)
if TYPE_CHECKING:
    import argparse

__all__ = ["COMMANDS", "main", "command_line", "build_parser", "Interrupted", "signals_interrupt"]

COMMANDS = {
    "bake": ".bake_command",
    "fit": ".fit_command",
    "figures": ".figures_command",
    "foundations": ".foundations_command",
}
"""Command name -> module (relative to this package) implementing it."""


def _module(name: str):
    return importlib.import_module(COMMANDS[name], __package__)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of every command (which imports each command's module), or, given the
    ``command`` being run, of that one alone: the others are named but their modules (and
    what they import: scipy for ``fit``, OpenImageIO for ``bake``, matplotlib) are not
    imported, so a command costs only its own imports."""
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m lut_baker",
        description="Made-up skin model (Baba, Mukaigawa, Yagi): fit, bake, draw.",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        if command is not None and name != command:
            sub.add_parser(name, add_help=False)
            continue
        try:
            module = _module(name)
        except ModuleNotFoundError as error:  # a command not built yet must say so, not vanish
            sub.add_parser(name, help=f"(unavailable: {error})")
            continue
        command_parser = sub.add_parser(name, help=module.HELP, description=module.__doc__,
                                        formatter_class=argparse.RawDescriptionHelpFormatter)
        module.configure(command_parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Parse ``argv`` (default ``sys.argv[1:]``) and run its command; the exit code.  A signal
    while the parser is built (the command modules imported), while arguments are parsed or
    while the command runs is reported as ``interrupted``."""
    import sys

    argv = sys.argv[1:] if argv is None else list(argv)
    named = next((item for item in argv if not item.startswith("-")), None)
    try:
        with signals_interrupt():
            parser = build_parser(named if named in COMMANDS else None)
            interrupts.raise_held()  # one that came during the imports: stop before parsing
            args = parser.parse_args(argv)
            try:
                return int(_module(args.command).run(args) or 0)
            except ValueError as error:
                parser.exit(2, f"{parser.prog} {args.command}: error: {error}\n")
    except KeyboardInterrupt as error:
        return interrupts.report(error)


def command_line() -> int:
    """:func:`main` as the whole process (``python -m lut_baker``): SIGINT and SIGTERM are
    handled from its first line (before any command module is imported; one held back by the
    entry point until then arrives here) and, once the exit code is known, ignored, so that
    none lands in the interpreter's shutdown."""
    try:
        interrupts.take_signals()
        interrupts.release_signals()
        code = main()
        interrupts.ignore_signals()
        return code
    except KeyboardInterrupt as error:  # one arriving between main's handling and the ignoring
        interrupts.ignore_signals()
        return interrupts.report(error)
