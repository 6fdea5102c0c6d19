"""Bake a made-up skin's lookup tables to a float32 OpenEXR atlas and its JSON sidecar.

Parameters come from a preset (the paper's film on the paper's skin substitute unless
--foundation/--skin name others), then a TOML parameter file (--params, schema in
docs/baking.md), then --coverage/--absorption, each overriding the one before; --thickness
bakes the film as a slab of that thickness too (the tables then hold it at every thickness of
their axis, docs/baking.md "The film as a slab in the tables").  Writes
OUT/NAME.exr and OUT/NAME.json (atomically) and prints one line with the result.  If they
cannot be written (OUT is a file or read-only, the disk is full, the bake is interrupted) it
says why in one line, exits non-zero and leaves no partial or temporary file; an earlier
OUT/NAME pair stays as it was.

examples:
  python -m lut_baker bake --preset paper --out out
  python -m lut_baker bake --foundation medium_beige --skin jensen_skin1 --coverage 0.8
  python -m lut_baker bake --params examples/beige_on_skin1.toml --resolution high
  python -m lut_baker bake --foundation clarins_103 --thickness 9.6 --name sheer

"""

from __future__ import annotations

import argparse
import re
import sys
import time
import types
from pathlib import Path, PurePosixPath, PureWindowsPath

__all__ = ["HELP", "configure", "run", "skin_from_args", "stem_problem", "Progress"]

HELP = "bake a made-up skin's lookup tables to an OpenEXR atlas + JSON sidecar"
PROG = "python -m lut_baker bake"
PRESETS = ("paper",)
BAR_WIDTH = 30
ADDED_SUFFIXES = (".exr", ".json")


def _fraction(name: str):
    """argparse type: a float in [0, 1] (the message names the range and the value)."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number in [0, 1], "
                                             f"got {text!r}") from None
        if not 0.0 <= value <= 1.0:
            raise argparse.ArgumentTypeError(f"{name} must lie in [0, 1], got {text}")
        return value

    parse.__name__ = name
    return parse


def _thickness(text: str) -> float:
    """argparse type of --thickness: micrometres, a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"thickness must be a number of micrometres, "
                                         f"got {text!r}") from None
    if not 0.0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"thickness must be > 0 micrometres and finite, "
                                         f"got {text}")
    return value


def stem_problem(stem: str) -> str | None:
    """Why ``stem`` cannot name OUT/STEM.exr and OUT/STEM.json, or None."""
    if not stem.strip():
        return "the file name is empty"
    if any(kind(stem).name != stem for kind in (PurePosixPath, PureWindowsPath)):
        return f"{stem!r} is a path"
    if stem.startswith("."):
        return f"{stem!r} starts with a dot"
    if any(ord(char) < 32 for char in stem):
        return f"{stem!r} holds a control character"
    suffix = Path(stem).suffix.lower()
    if suffix in ADDED_SUFFIXES:
        return f"{stem!r} ends in {suffix}"
    return None


def _stem(text: str) -> str:
    """argparse type of --name: a file stem."""
    problem = stem_problem(text)
    if problem is not None:
        raise argparse.ArgumentTypeError(
            f"{problem}; give a plain file name such as 'mine' (--out names the folder, "
            ".exr and .json are added)")
    return text


def _default_stem(name: str) -> str:
    """The file stem of a parameter set's name (characters other than letters, digits and
    ``._+-`` become ``_``); ``ValueError`` if that is no file name."""
    stem = re.sub(r"[^A-Za-z0-9._+-]", "_", name)
    problem = stem_problem(stem)
    if problem is not None:
        raise ValueError(f"argument --name: the parameter set's name {name!r} makes no file "
                         f"name ({problem}); give one with --name")
    return stem


def _one_line_error(parser, message: str):
    """argparse's error without the usage block: one line, exit code 2."""
    parser.exit(2, f"{parser.prog}: error: {message}\n")


def configure(parser: argparse.ArgumentParser) -> None:
    from ...bake import RESOLUTIONS
    from ...model.presets import FOUNDATIONS, SKINS

    parser.error = types.MethodType(_one_line_error, parser)  # type: ignore[method-assign]
    parser.add_argument("--preset", choices=PRESETS, default="paper",
                        help="base parameters: the paper's film ('natural' liquid foundation) "
                             "on its skin substitute, in albedo units (1/sr) normalised by K "
                             "(default: %(default)s)")
    parser.add_argument("--foundation", choices=sorted(FOUNDATIONS), metavar="NAME",
                        help="foundation preset (the paper's film with a shade's per-channel "
                             "absorption, or with a measured product's gloss and absorption, "
                             f"docs/model.md §4): {', '.join(sorted(FOUNDATIONS))}")
    parser.add_argument("--skin", choices=sorted(SKINS), metavar="NAME",
                        help=f"skin preset (surface gloss and dipole): {', '.join(sorted(SKINS))}")
    parser.add_argument("--params", type=Path, metavar="FILE.toml",
                        help="TOML parameter file overriding the preset (schema: docs/baking.md, "
                             "example: examples/beige_on_skin1.toml)")
    parser.add_argument("--coverage", type=_fraction("coverage"), metavar="W",
                        help="film coverage, dimensionless in [0, 1]: 0 bare skin, 1 the full "
                             "two-layer model, an areal mix between (default: 1, or the file's)")
    parser.add_argument("--absorption", type=_fraction("absorption"), nargs=3,
                        metavar=("R", "G", "B"),
                        help="fraction of the light crossing the film's pigment that it absorbs, "
                             "per RGB channel, each in [0, 1] (default: the foundation's)")
    parser.add_argument("--resolution", choices=list(RESOLUTIONS), default="default",
                        help="table grids: preview (fast, error < 1%%, for live sliders), "
                             "default (error ~1e-3, docs/baking.md), high (default: %(default)s)")
    parser.add_argument("--thickness", type=_thickness, metavar="UM",
                        help="the film as a slab of this thickness in micrometres, every "
                             "inter-reflection with the skin in, with the tables at every "
                             "thickness of their axis (1-300 um and the thick limit; a typical "
                             "application on a face is 9.6 um); default: the paper's 150 um "
                             "free film as published (paths 1 + 3)")
    parser.add_argument("--inter-reflection", action="store_true",
                        help="also bake the inter-reflections between the film's underside and "
                             "the skin beyond the paper's path 3 (the adding equation)")
    parser.add_argument("--out", type=Path, default=Path("out"), metavar="DIR",
                        help="output folder, created if missing (default: %(default)s)")
    parser.add_argument("--name", type=_stem, metavar="STEM",
                        help="file name stem of OUT/STEM.exr and OUT/STEM.json, without a "
                             "folder or an extension (default: the parameter set's name, "
                             "e.g. 'paper')")


def skin_from_args(args):
    """The :class:`~lut_baker.model.made_up_skin.MadeUpSkin` the options describe (``ValueError``
    naming the option on bad input)."""
    from ...model.params_file import params_from_mapping, read_mapping

    mapping = {}
    if args.params is not None:
        try:
            mapping = read_mapping(args.params)
        except ValueError as error:
            raise ValueError(f"argument --params: {error}") from None
    for key in ("foundation", "skin", "coverage"):
        if getattr(args, key) is not None:
            mapping[key] = getattr(args, key)
    if args.absorption is not None:
        mapping["absorption"] = list(args.absorption)
    try:
        return params_from_mapping(mapping)
    except ValueError as error:
        where = f"--params {str(args.params)!r}" if args.params is not None else "parameters"
        raise ValueError(f"argument {where}: {error}") from None


class Progress:
    """A progress bar on a terminal (stderr), nothing otherwise."""

    def __init__(self, stream=sys.stderr):
        self.stream = stream
        self.enabled = stream.isatty()

    def __call__(self, fraction: float, message: str) -> None:
        if self.enabled:
            filled = int(round(BAR_WIDTH * fraction))
            bar = "#" * filled + "." * (BAR_WIDTH - filled)
            self.stream.write(f"\r[{bar}] {100 * fraction:3.0f}% {message:<40}")
            self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()


def _failed(error: Exception) -> int:
    """Report what stopped the bake in one line; the exit code 1."""
    print(f"{PROG}: error: {' '.join(str(error).split())}", file=sys.stderr)
    return 1


def run(args) -> int:
    from ...bake import bake
    from ...tables.codec import content_hash
    from ..exr_files import check_target, require_oiio, save_tables

    skin = skin_from_args(args)
    stem = args.name or _default_stem(skin.name)
    try:  # before the bake: fail in a moment, not after it
        require_oiio()
        target = check_target(args.out / f"{stem}.exr")
    except (ImportError, OSError) as error:
        return _failed(error)
    progress = Progress()
    start = time.perf_counter()
    try:
        tables = bake(skin, args.resolution, inter_reflection=args.inter_reflection,
                      progress=progress,
                      film="paper" if args.thickness is None else args.thickness)
    finally:
        progress.close()
    seconds = time.perf_counter() - start
    try:
        path = save_tables(tables, target)
    except OSError as error:
        return _failed(error)
    shape = "x".join(str(n) for n in tables.path3_gloss.shape[:3])
    film = "" if args.thickness is None else f", film {args.thickness:g} um as a slab"
    print(f"baked {skin.name} ({args.resolution}, angular {shape}{film}) in {seconds:.2f} s -> "
          f"{path} + {path.with_suffix('.json').name}, sha256 {content_hash(tables)[:16]}")
    return 0
