"""Draw the paper's figures from the model as PNGs.

    python -m lut_baker figures --out DIR [--only NAME ...]

Writes the model curves of the paper's figs. 5, 7, 11, 13, 14 and 15 and a white-furnace chart
(fig16, beyond the paper) to DIR as figNN_<name>.png (150 dpi, 6 x 4 in), with the paper's
parameters (docs/model.md §5).  docs/figures.md's figures are made with --out docs/figures.  Needs
matplotlib.
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["HELP", "configure", "run"]

HELP = "draw the paper's figures 5, 7, 11, 13, 14, 15 (and a white-furnace chart) as PNGs"


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the command's arguments (matplotlib and the model are imported only by :func:`run`)."""
    parser.add_argument("--out", type=Path, required=True, metavar="DIR",
                        help="folder for the PNGs (created if missing)")
    parser.add_argument("--only", action="append", metavar="NAME",
                        help="draw only this figure, e.g. fig05_film_reflection (repeatable)")


def run(args: argparse.Namespace) -> int:
    """Write the figures; print one path per line.  Bad input raises ``ValueError``."""
    try:
        import matplotlib  # noqa: F401  (checked here so a missing install is one clear line)
    except ModuleNotFoundError as error:
        raise ValueError("the figures need matplotlib: pip install matplotlib") from error
    from ..paper_figures import render_all

    if args.out.exists() and not args.out.is_dir():
        raise ValueError(f"--out {args.out} exists and is not a folder")
    for path in render_all(args.out, args.only):
        print(path)
    return 0
