"""``python -m lut_baker fit``: fit the paper's layers to measurements, or synthesise some.

    python -m lut_baker fit reflection FILE.csv [--eta ETA]
    python -m lut_baker fit transmission FILE.csv [--eta ETA]
    python -m lut_baker fit dipole FILE.csv [--g 0 --eta 1.26 --d-min 0.1 --free-scale]
    python -m lut_baker fit synthesize --preset paper --out DIR [--noise 0.02 --seed 0]
    python -m lut_baker fit inplane FILE [--name NAME] [--finish auto|matte|dewy]
                                         [--out params.toml] [--strict]

Fits print a TOML (or ``--format json``) block on stdout, or write it to ``--out FILE``: the
fitted layer under its kind (``[reflection]``, ``[transmission]``, ``[dipole]``: pass it to the
layer type as keywords), then ``[stderr]``, ``[relative_stderr]`` (eta: relative to eta - 1),
``[derived]`` (the P ratio as [value, stderr]) and ``[fit]`` (samples, residual rms, Jacobian
condition number, correlation matrix over ``free``, how the starts ended, warnings).  Warnings
(ill-conditioned or degenerate parameters, poor fit) also go to stderr, one per line.

CSV columns (units in the names; ``#`` lines are comments; see
lut_baker.offline.measured.measurements):
  reflection    psi_deg, alpha_deg (or theta_r_deg), intensity_counts
  transmission  incidence_deg, theta_t_deg, intensity_counts
  dipole        distance_mm, ratio   (ratio to the lit pixel, modelled as R(d)/R(0))

Exit codes: 0 done; 2 bad input (one line naming the problem); 3 the fit warned and --strict
was given.  ``synthesize`` writes the paper's protocols (docs/model.md §6) from its parameters
(docs/model.md §5) as CSV files plus ``truth.toml``, to try the round trip.

``inplane`` turns in-plane measurements of a foundation's thick layer into a parameter file
that ``python -m lut_baker bake --params FILE`` bakes (docs/model.md §4, "Presets from measured
thick layers"; :mod:`lut_baker.offline.own_foundation`); see ``fit inplane --help``.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ...model.layers import Dipole, ReflectionLayer
from ...model.presets import paper_layers
from ..atomic_files import write_text
from ..measured.fit_results import FitResult
from ..measured.layer_fit import D_MIN_MM, fit_dipole, fit_reflection, fit_transmission
from ..measured.measurements import (
    MAX_NOISE,
    PAPER_INCIDENCES_DEG,
    PAPER_RELATIVE_ANGLES_DEG,
    ProfileData,
    ReflectionData,
    TransmissionData,
    paper_protocols,
    read_measurements,
    write_measurements,
)

__all__ = ["HELP", "STRICT_EXIT", "configure", "run", "result_document", "to_toml"]

HELP = ("fit reflection/transmission/dipole layers to CSV measurements, synthesise them, or "
        "make a foundation's parameter file from in-plane measurements")
STRICT_EXIT = 3
"""Exit code of a fit that warned when ``--strict`` is given."""

_FITS: dict[str, tuple[type[ReflectionData] | type[TransmissionData] | type[ProfileData],
                       Callable[..., FitResult]]] = {
    "reflection": (ReflectionData, fit_reflection),
    "transmission": (TransmissionData, fit_transmission),
    "dipole": (ProfileData, fit_dipole),
}


def configure(parser) -> None:
    """Add the ``fit`` sub-commands and their arguments."""
    sub = parser.add_subparsers(dest="fit_kind", required=True, metavar="KIND")
    helps = {
        "reflection": "Torrance-Sparrow layer (eq. 2): P_d, P_s, n, eta",
        "transmission": "thin-film layer (eq. 4): P_d, P_t, n, eta",
        "dipole": "dipole (eq. 6): sigma_s, sigma_a with g and eta given",
    }
    for kind, text in helps.items():
        command = sub.add_parser(kind, help=text, description=f"Fit a {text}.")
        command.add_argument("csv", type=Path, help="measurements (CSV, see fit --help)")
        if kind == "dipole":
            command.add_argument("--g", type=float, default=0.0,
                                 help="phase asymmetry, held fixed (default 0, docs/model.md §2.3)")
            command.add_argument("--eta", type=float, default=1.26,
                                 help="relative index, held fixed (default 1.26, the paper's "
                                      "skin)")
            command.add_argument("--d-min", type=float, default=D_MIN_MM, metavar="MM",
                                 help=f"leave out samples closer than MM to the lit pixel "
                                      f"(default {D_MIN_MM:g} mm)")
            command.add_argument("--free-scale", action="store_true",
                                 help="fit k R(d)/R(0) with a free k (lit pixel holding direct "
                                      "light)")
        else:
            command.add_argument("--eta", type=float, default=None,
                                 help="hold eta fixed at this value (default: fitted)")
        command.add_argument("--out", type=Path, help="write the block here, not to stdout")
        command.add_argument("--format", choices=("toml", "json"), default=None,
                             help="output format (default: from --out's suffix, else toml)")
        command.add_argument("--strict", action="store_true",
                             help=f"exit {STRICT_EXIT} when the fit warns")
    synth = sub.add_parser("synthesize", help="write the paper's protocols as CSV files",
                           description="Synthesise the paper's experiments (docs/model.md §6) "
                                       "from its parameters (docs/model.md §5) with "
                                       "multiplicative noise.")
    synth.add_argument("--preset", choices=("paper",), default="paper")
    synth.add_argument("--out", type=Path, required=True, help="output folder")
    synth.add_argument("--noise", type=float, default=0.02,
                       help=f"relative noise per sample, 0 to {MAX_NOISE:g} (default 0.02)")
    synth.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    _configure_inplane(sub)


INPLANE_DESCRIPTION = """\
Make a foundation's parameter file from in-plane measurements of a thick layer of it
(docs/fitting.md, "Your own foundation: in-plane measurements"; docs/model.md §4).

The file: plain text, tab-separated, no header, one geometry per row; blank lines and lines
starting with # are skipped. Columns:
  theta_i   incidence, degrees from the normal, 0 <= theta_i < 90
  theta_o   signed viewing angle, degrees, |theta_o| < 90; > 0 on the specular side
            (theta_o = theta_i is the mirror direction), < 0 on the light's side;
            theta_i + theta_o > 0 on every row
  then either 81 spectral reflectance factors at 380, 385, ..., 780 nm (5 nm steps;
  converted to linear Rec.709 with CIE 1931 2 deg and D65, needs colour-science)
  or 3 linear RGB reflectance factors R, G, B.
Reflectance factors are dimensionless, relative to a white standard: R = pi f_r (pi times
the BRDF in 1/sr; an ideal white Lambertian reads 1). At least 5 rows.

Eq. 2 is fitted to every row, the three channels at once with one tilt of the sample (a
nuisance, not in the film), in the form whose every parameter the data determine (the tilt,
the lobe or eta left out or held where they are not determined; a matte product keeps P_d
alone); the film is derived as the measured presets are:
the paper's film (foundation = "paper_natural") with the product's gloss ([film] P_s, n, eta)
and per-channel absorption whose endless stack reflects what the thick layer reflects. The
TOML file holds name, foundation, absorption, [film], and comments with the fit's parameters
and errors, target against stack per channel, clamping and warnings. Fit warnings and clamping
also go to stderr.

Exit codes: 0 done; 2 bad input (one line naming the file and the problem); 3 --strict given
and the fit warned or an absorption was clamped.
"""


def _configure_inplane(sub) -> None:
    import argparse

    command = sub.add_parser("inplane", help="a foundation's parameter file from in-plane "
                                             "measurements (theta_i, theta_o, spectra or RGB)",
                             description=INPLANE_DESCRIPTION,
                             formatter_class=argparse.RawDescriptionHelpFormatter)
    command.add_argument("file", type=Path, help="in-plane measurements (tab-separated: "
                                                 "theta_i, theta_o in degrees, then 81 "
                                                 "spectral or 3 RGB reflectance factors)")
    command.add_argument("--name", default=None,
                         help="the parameter set's name (default: the file's stem)")
    command.add_argument("--finish", choices=("auto", "matte", "dewy"), default="auto",
                         help="matte: no gloss (P_s = 0); dewy: one lobe, the "
                              "luminance-weighted mean of the channels' fits; auto (default): "
                              "dewy when every channel's fit determined its lobe (roughness n "
                              "not at its bound, standard error at most 10%% of n), else matte")
    command.add_argument("--out", type=Path, metavar="FILE.toml",
                         help="write the parameter file here, not to stdout")
    command.add_argument("--strict", action="store_true",
                         help=f"exit {STRICT_EXIT} when the fit warns or an absorption is "
                              f"clamped")


def run(args) -> int:
    """Run ``fit KIND``; returns the exit code."""
    if args.fit_kind == "synthesize":
        return _synthesize(args)
    if args.fit_kind == "inplane":
        return _inplane(args)
    data_type, fit = _FITS[args.fit_kind]
    options = {"eta": args.eta}
    if args.fit_kind == "dipole":
        options.update(g=args.g, d_min_mm=args.d_min, free_scale=args.free_scale)
    _check_options(options)
    data = read_measurements(args.csv)
    if not isinstance(data, data_type):
        raise ValueError(f"{args.csv}: holds {data.KIND} columns ({','.join(data.COLUMNS)}), "
                         f"not {data_type.KIND} ones ({','.join(data_type.COLUMNS)})")
    try:
        result = fit(data, **options)
    except ValueError as error:
        raise ValueError(f"{args.csv}: {error}") from None
    document = result_document(result)
    form = args.format or ("json" if args.out and args.out.suffix == ".json" else "toml")
    header = (f"python -m lut_baker fit {args.fit_kind} {args.csv}",
              f"{result.samples} samples, residual rms {100 * result.residual_rms:.3g}% "
              f"(relative), Jacobian condition number {result.condition_number:.3g}")
    text = json.dumps(document, indent=2) + "\n" if form == "json" else to_toml(document, header)
    return _emit(text, args.out, result.warnings, args.strict)


def _emit(text: str, out, warnings, strict: bool) -> int:
    """Write ``text`` to ``out`` (or stdout), the warnings to stderr; the exit code."""
    if out:
        write_text(out, text)
        print(f"wrote {out}")
    else:
        sys.stdout.write(text)
    for warning in warnings:
        print(f"warning: {warning}", file=sys.stderr)
    return STRICT_EXIT if (strict and warnings) else 0


def _inplane(args) -> int:
    """``fit inplane``: the parameter file on stdout or to ``--out``; warnings on stderr."""
    from ..own_foundation import fit_own_foundation, params_text

    if args.out is not None and args.out.is_dir():
        raise ValueError(f"--out {args.out} is a folder; give a file name such as params.toml")
    try:
        result = fit_own_foundation(args.file, name=args.name, finish=args.finish)
    except ModuleNotFoundError as error:
        raise ValueError(f"{args.file}: {error}") from None
    command = f"python -m lut_baker fit inplane {args.file} --finish {args.finish}"
    if args.name is not None:
        command += f" --name {json.dumps(args.name)}"
    return _emit(params_text(result, command), args.out, result.warnings, args.strict)


def _check_options(options: dict) -> None:
    """Reject invalid fixed parameters before reading any file."""
    try:
        if "g" in options:
            Dipole(sigma_s=1.0, sigma_a=0.1, g=options["g"], eta=options["eta"])
        elif options["eta"] is not None:
            ReflectionLayer(P_d=1.0, P_s=1.0, n=1.0, eta=options["eta"])
    except ValueError as error:
        raise ValueError(f"--{str(error).split()[0]}: {error}") from None
    if options.get("d_min_mm", 0.0) < 0.0:
        raise ValueError(f"--d-min must be >= 0 mm, got {options['d_min_mm']:g}")


def result_document(result) -> dict:
    """The output block of a :class:`~lut_baker.offline.measured.fit_results.FitResult` as
    nested plain data."""
    data = result.as_dict()
    return {
        result.kind: data["params"],
        "stderr": data["stderr"],
        "relative_stderr": data["relative_stderr"],
        "derived": data["derived"],
        "fit": {key: data[key] for key in ("samples", "residual_rms", "condition_number",
                                           "free", "fixed", "correlation", "starts",
                                           "warnings") if key in data},
    }


def _toml_value(value) -> str:
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        value = float(value)
        return repr(value) if np.isfinite(value) else ("nan" if np.isnan(value) else
                                                        ("inf" if value > 0 else "-inf"))
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}"
                               for k, v in value.items()) + "}"
    return "[" + ", ".join(_toml_value(v) for v in value) + "]"


def _toml_key(key: str) -> str:
    return key if key.replace("_", "").isalnum() else json.dumps(key)


def to_toml(document: dict, comments=()) -> str:
    """A two-level document (tables of scalars, lists, inline tables) as TOML text."""
    lines = [f"# {comment}" for comment in comments]
    for table, entries in document.items():
        lines.append(f"\n[{_toml_key(table)}]")
        lines += [f"{_toml_key(k)} = {_toml_value(v)}" for k, v in entries.items()]
    return "\n".join(lines).lstrip("\n") + "\n"


def _synthesize(args) -> int:
    """Write the paper's four protocols and their true parameters to ``args.out``."""
    out = args.out
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out} exists and is not a folder")
    datasets = paper_protocols(args.noise, args.seed)
    out.mkdir(parents=True, exist_ok=True)
    film, film_transmission, skin, dipole = paper_layers()
    truth = {"film_reflection": film, "film_transmission": film_transmission,
             "skin_reflection": skin, "skin_profile": dipole}
    origin = (f"python -m lut_baker fit synthesize --preset {args.preset} "
              f"--noise {args.noise:g} --seed {args.seed}")
    notes = {
        "film_reflection": f"paper 4.1.1: film reflection, counts at 3 s, psi "
                           f"{', '.join(f'{a:g}' for a in PAPER_RELATIVE_ANGLES_DEG)} deg",
        "film_transmission": f"paper 4.1.2: film transmission, counts at 10 s, incidence "
                             f"{', '.join(f'{a:g}' for a in PAPER_INCIDENCES_DEG)} deg",
        "skin_reflection": "paper 4.2.1: skin substitute reflection, counts at 3 s",
        "skin_profile": "paper 4.2.2: skin substitute profile, ratio R(d)/R(0)",
    }
    commands = {"film_reflection": "reflection", "film_transmission": "transmission",
                "skin_reflection": "reflection", "skin_profile": "dipole"}
    for name, data in datasets.items():
        path = write_measurements(out / f"{name}.csv", data,
                                  (origin, notes[name], f"truth: {truth[name].as_dict()}"))
        print(f"wrote {path}  (python -m lut_baker fit {commands[name]} {path})")
    truth_path = out / "truth.toml"
    write_text(truth_path, to_toml({name: {k: float(v) for k, v in layer.as_dict().items()}
                                    for name, layer in truth.items()},
                                   (origin, "the parameters the CSV files were made from")))
    print(f"wrote {truth_path}")
    return 0
