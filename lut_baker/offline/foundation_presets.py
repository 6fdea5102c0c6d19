"""Foundation presets from measured thick layers: the thin film each measured product implies
(docs/model.md §4, "Presets from measured thick layers"; paper eqs. 2 and 4).

Lanza et al. 2024 measured thick layers of four foundations (data/lanza2024/README.md), not the
thin film the model lays on skin.  Each product's preset film keeps the paper's film (its
diffuse ``P_d`` and its transmission, eq. 4) and takes from the measurement:

- **gloss** (the film's top surface, eq. 2's ``P_s``, ``n``, ``eta``, not absorbed): for a dewy
  product, one achromatic lobe, the luminance-weighted mean (Rec.709 weights) of the per-channel
  fit's ``P_s``, ``n`` and ``eta`` (the fit's tilt of the sample, a nuisance of the measurement,
  is not part of it); for a matte product, whose well-posed fit has no lobe (``P_d`` alone,
  :func:`~lut_baker.offline.measured.inplane_fit.well_posed`), ``P_s = 0`` (``n``, ``eta`` stay
  the paper film's, unused);
- **absorption** ``A_c`` per channel (docs/model.md §4): the film stacked on itself without end
  reflects what the thick layer reflects.  With the film's bihemispherical reflectance ``r(A) =
  r_gloss + (1 - A) r_diffuse`` and transmittance ``t(A) = (1 - A) t_0`` (uniform incident
  light, cosine-weighted), the adding equation ``R = r + t^2 R / (1 - r R)`` has the root
  ``R_inf(A)`` of ``r R^2 - (1 + r^2 - t^2) R + r = 0`` below 1, which falls monotonically from
  ``R_inf(0)`` to ``r_gloss`` at ``A = 1``; bisection finds ``A_c`` with ``R_inf(A_c)`` equal to
  the target, the fitted eq. 2 layer's bihemispherical reflectance in channel ``c`` (``pi P_d``
  for a layer without lobe).  A target
  outside ``[r_gloss, R_inf(0)]`` is clamped (``A = 0`` or ``1``) and reported.

The result is written to :data:`PRESET_FILE` (``lut_baker/model/measured_foundations.json``),
which :mod:`lut_baker.model.presets` reads at import; ``python -m lut_baker foundations``
rewrites it.

The thick layer itself (the film's exchange under uniform light, the stack, the solve) is the
runtime's :mod:`lut_baker.model.thick_layer`, which the add-on also uses to read a picked
colour: each formula exists once, and a measured product's own colour picked in the panel gives
back its preset.

Functions and types
-------------------
- :data:`PRESET_FILE` -- where the runtime reads the derived presets.
- :func:`preset_gloss` -- the preset's top-surface lobe from a product's fit.
- :func:`lobe_determined`, :func:`auto_finish` -- matte or dewy from the fit itself.
- :func:`derive_preset`, :func:`derive_presets` -- one or all products' preset entries.
- :func:`write_presets`, :func:`read_presets` -- the JSON file.
"""

from __future__ import annotations

import json
from functools import partial
from pathlib import Path

import numpy as np

from ..model.albedo import bihemispherical, reflection_albedo
from ..model.layers import ReflectionLayer
from ..model.presets import MEASURED_FOUNDATIONS_FILE, paper
from ..model.thick_layer import (
    FilmExchange,
    paper_film_exchange,
    solve_absorption,
    stack_reflectance,
)
from .atomic_files import write_text

__all__ = [
    "PRESET_FILE",
    "LUMINANCE_WEIGHTS",
    "preset_gloss",
    "LOBE_STDERR_LIMIT",
    "lobe_determined",
    "auto_finish",
    "derive_preset",
    "derive_presets",
    "write_presets",
    "read_presets",
]

PRESET_FILE = MEASURED_FOUNDATIONS_FILE
"""The runtime's preset file (shipped with the extension)."""

LUMINANCE_WEIGHTS = np.array([0.2126, 0.7152, 0.0722])
"""Rec.709 luminance weights: how a dewy product's per-channel lobes become one."""

LOBE_STDERR_LIMIT = 0.10
"""A channel's lobe counts as determined when the standard error of its roughness ``n`` is at
most this fraction of ``n`` (the fits' own limit, ``fit_results.Limits.relative_stderr``)."""


def preset_gloss(layers, finish: str) -> dict:
    """The preset film's top surface ``{"P_s", "n", "eta"}`` (1/sr, 1/degree, -) from a
    product's per-channel eq. 2 fit ``layers`` (R, G, B :class:`ReflectionLayer`): dewy, the
    luminance-weighted means; matte, no lobe (``P_s = 0``, the paper film's ``n`` and ``eta``)."""
    if finish == "matte":
        film = paper().film
        return {"P_s": 0.0, "n": float(film.n), "eta": float(film.eta)}
    if finish != "dewy":
        raise ValueError(f"finish must be 'matte' or 'dewy', got {finish!r}")
    return {name: float(LUMINANCE_WEIGHTS @ np.array([float(getattr(layer, name))
                                                      for layer in layers]))
            for name in ("P_s", "n", "eta")}


def lobe_determined(fit) -> tuple[bool, str]:
    """``(determined, why)`` for one channel's eq. 2 fit (a ``fit_results.FitResult``): its lobe
    is determined when the roughness ``n`` was fitted, did not end at its bound and has a
    standard error of at most :data:`LOBE_STDERR_LIMIT` of ``n`` (docs/model.md §4, "Presets
    from measured thick layers": a matte product's fit has no lobe to take)."""
    if "n" not in fit.free:
        return False, "n was not fitted"
    if any(warning.startswith("n ended at its bound") for warning in fit.warnings):
        return False, f"n ended at its bound ({float(fit.params.n):.4g} /deg)"
    error = float(fit.relative_stderr["n"])
    if not error <= LOBE_STDERR_LIMIT:
        return False, (f"n = {float(fit.params.n):.4g} /deg has a standard error of "
                       f"{100 * error:.3g}% (limit {100 * LOBE_STDERR_LIMIT:.3g}%)")
    return True, (f"n = {float(fit.params.n):.4g} /deg to {100 * error:.3g}% "
                  f"(limit {100 * LOBE_STDERR_LIMIT:.3g}%)")


def auto_finish(fits) -> tuple[str, str]:
    """``(finish, why)`` from the per-channel fits (R, G, B ``fit_results.FitResult``): ``"dewy"``
    when every channel's lobe is determined (:func:`lobe_determined`), else ``"matte"``.  On the
    four published products this gives their published finishes (103, 108 matte; 105, 112
    dewy)."""
    verdicts = [lobe_determined(fit) for fit in fits]
    finish = "dewy" if all(ok for ok, _ in verdicts) else "matte"
    why = "; ".join(f"{channel}: {text}" for channel, (_, text) in zip("RGB", verdicts,
                                                                         strict=True))
    return finish, why


def derive_preset(name: str, finish: str, layers, exchange: FilmExchange | None = None, *,
                  label: str | None = None) -> dict:
    """One product's preset entry from its per-channel fit ``layers``: ``label`` (default
    ``Clarins <number> (<finish>, measured)`` from the name's last ``_`` part),
    ``absorption``, ``film`` (:func:`preset_gloss`), and for the record ``target`` (the fitted
    layers' bihemispherical reflectance per channel), ``stack`` (``R_inf`` at the solved
    absorption) and ``clamped``."""
    _check_layers(layers)
    exchange = exchange or paper_film_exchange()
    target = np.array([float(bihemispherical(partial(reflection_albedo, layer=layer)))
                       for layer in layers])
    absorption, clamped = solve_absorption(target, exchange)
    if label is None:
        label = f"Clarins {name.split('_')[-1]} ({finish}, measured)"
    return {
        "label": label,
        "finish": finish,
        "absorption": [float(a) for a in absorption],
        "film": preset_gloss(layers, finish),
        "target": [float(v) for v in target],
        "stack": [float(v) for v in stack_reflectance(absorption, exchange)],
        "clamped": [bool(v) for v in clamped],
    }


def derive_presets(fits: dict) -> dict:
    """Preset entries for ``fits``: product name -> ``(finish, layers)``, in that order."""
    exchange = paper_film_exchange()
    return {name: derive_preset(name, finish, layers, exchange)
            for name, (finish, layers) in fits.items()}


def write_presets(presets: dict, path=PRESET_FILE) -> Path:
    """Write the entries with the film exchange they were derived with, as JSON."""
    exchange = paper_film_exchange()
    document = {
        "about": "Foundation presets derived from the measured thick layers of Lanza et al. "
                 "2024 (docs/model.md §4, 'Presets from measured thick layers'). Generated by "
                 "`python -m lut_baker foundations` (lut_baker/offline/foundation_presets.py); "
                 "do not edit.",
        "film_exchange": {"r_gloss": exchange.r_gloss, "r_diffuse": exchange.r_diffuse,
                          "t_0": exchange.t_0},
        "foundations": presets,
    }
    return write_text(path, json.dumps(document, indent=2) + "\n")


def read_presets(path=PRESET_FILE) -> dict:
    """The ``foundations`` entries of a preset file."""
    return json.loads(Path(path).read_text(encoding="utf-8"))["foundations"]


def _check_layers(layers) -> None:
    if len(layers) != 3 or not all(isinstance(layer, ReflectionLayer) for layer in layers):
        raise ValueError("layers must be three ReflectionLayer fits (R, G, B)")
