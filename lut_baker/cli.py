"""The command line: ``python -m lut_baker <command> ...``.

Each command lives in its own module exposing ``HELP`` (one line), ``configure(parser)`` (adds
its arguments) and ``run(args) -> int`` (the exit code).  Modules are imported only when their
command runs, so ``--help`` stays fast.  Bad input exits with code 2 and one line naming the
argument (argparse's convention); a ``ValueError`` raised by the model is reported the same way.
"""

from __future__ import annotations

import argparse
import importlib
import sys

__all__ = ["COMMANDS", "main", "build_parser"]

COMMANDS = {
    "bake": ".cli_bake",
    "fit": ".cli_fit",
    "figures": ".cli_figures",
}
"""Command name -> module (relative to this package) implementing it."""


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
        return int(_module(args.command).run(args) or 0)
    except ValueError as error:
        parser.exit(2, f"{parser.prog} {args.command}: error: {error}\n")
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
