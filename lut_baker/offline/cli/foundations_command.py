"""Fit the paper's eq. 2 to published foundation measurements and write the comparison.

    python -m lut_baker foundations [--out docs/foundations] [--data data/lanza2024]
                                    [--presets lut_baker/model/measured_foundations.json]
                                    [--notes docs/foundations/notes.md]

Reads the in-plane spectral measurements of four foundations (Lanza et al. 2024,
data/lanza2024/README.md), converts them to linear Rec.709 reflectance factors, fits
``ReflectionLayer(P_d, P_s, n, eta)`` (eq. 2, docs/model.md §2.1) to the three channels at once
with the sample's tilt, in the form whose every parameter the data determine, and writes per
product ``<product>.csv`` and ``<product>.png`` and one ``README.md`` report to the output
folder, and derives from the fits the thin-film foundation presets (docs/model.md §4, "Presets
from measured thick layers") into the runtime's preset file, which
:mod:`lut_baker.model.presets` reads.  The report's written notes come from a Markdown file
(:func:`lut_baker.offline.foundations.read_notes`; default ``notes.md`` in the output folder,
when there is one).  Needs scipy, matplotlib and colour-science.
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["HELP", "configure", "run"]

HELP = ("fit eq. 2 to four published foundations; write CSVs, figures, a report and the "
        "foundation presets derived from them")


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the command's arguments (the fits and figures are imported only by :func:`run`)."""
    parser.add_argument("--out", type=Path, default=Path("docs/foundations"), metavar="DIR",
                        help="folder for the CSVs, PNGs and README.md (default "
                             "docs/foundations; created if missing)")
    parser.add_argument("--data", type=Path, default=Path("data/lanza2024"), metavar="DIR",
                        help="folder holding the four measurement files (default "
                             "data/lanza2024)")
    parser.add_argument("--presets", type=Path, default=None, metavar="FILE",
                        help="JSON file for the derived foundation presets (default: the "
                             "runtime's, lut_baker/model/measured_foundations.json)")
    parser.add_argument("--notes", type=Path, default=None, metavar="FILE",
                        help="Markdown file of the notes written below the report's tables "
                             "(default: notes.md in the --out folder, if it is there)")


def run(args: argparse.Namespace) -> int:
    """Write the outputs; print one path per line.  Bad input raises ``ValueError``."""
    for module, package in (("matplotlib", "matplotlib"), ("colour", "colour-science"),
                            ("scipy", "scipy")):
        try:
            __import__(module)
        except ModuleNotFoundError as error:
            raise ValueError(f"the foundations command needs {package}: "
                             f"pip install {package}") from error
    from ..foundations import read_notes, write_all

    if not args.data.is_dir():
        raise ValueError(f"--data {args.data} is not a folder")
    from ..foundation_presets import PRESET_FILE

    presets = PRESET_FILE if args.presets is None else args.presets
    notes_file = args.out / "notes.md" if args.notes is None else args.notes
    notes = read_notes(notes_file) if args.notes is not None or notes_file.is_file() else None
    for path in write_all(args.data, args.out, presets_path=presets, notes=notes):
        print(path)
    return 0
