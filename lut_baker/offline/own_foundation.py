"""A user's own foundation: in-plane measurements of a thick layer into a parameter file
(docs/model.md §4, "Presets from measured thick layers"; §2.1; docs/fitting.md).

The steps are those that made the measured presets (:mod:`~lut_baker.offline.foundations`),
applied to one file of the published layout (:mod:`~lut_baker.offline.measured.inplane`:
``theta_i``, ``theta_o``, then 81 spectral or 3 linear RGB reflectance factors):

1. read the file; spectra become linear Rec.709 RGB (:mod:`~lut_baker.offline.measured.spectra`);
2. fit eq. 2 to the three channels at once, in the form the data determine
   (:func:`~lut_baker.offline.measured.inplane_fit.well_posed`: the full eq. 2 with the
   sample's tilt, reduced where a parameter is not determined; a matte product keeps ``P_d``
   alone);
3. decide the finish: given, or ``"auto"``, dewy when every channel's fit determined its lobe
   (:func:`~lut_baker.offline.foundation_presets.auto_finish`), else matte;
4. derive the thin film (:func:`~lut_baker.offline.foundation_presets.derive_preset`): the
   paper's film with the product's gloss and the per-channel absorption whose endless stack
   reflects what the thick layer reflects;
5. write a parameter file (:mod:`lut_baker.model.params_file`): ``name``,
   ``foundation = "paper_natural"`` (the paper's film as the base), ``absorption`` and
   ``[film]`` (``P_s``, ``n``, ``eta``: the gloss; ``P_d`` stays the paper film's), with the
   fit's errors, target against stack per channel and every warning as comments.

The written file therefore gives the same film and absorption as a measured preset derived
from the same data (``foundation = "clarins_105"`` and the file made from 105's measurements
load alike).

Functions and types
-------------------
- :data:`BASE_FOUNDATION` -- the preset the parameter file starts from.
- :class:`OwnFoundation` -- one file's fit, finish, derived preset and warnings.
- :func:`fit_own_foundation` -- read, fit and derive from one file.
- :func:`params_mapping` -- the parameter file's content as plain data.
- :func:`params_text` -- the parameter file as TOML, with its comments.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from ..model.thick_layer import paper_film_exchange, stack_reflectance
from .foundation_presets import auto_finish, derive_preset
from .measured.inplane import SPECTRAL_SAMPLES, InPlaneData, read_inplane
from .measured.inplane_fit import CHANNELS, ChannelFits, ModelChoice, well_posed

__all__ = ["BASE_FOUNDATION", "FINISHES", "OwnFoundation", "fit_own_foundation",
           "params_mapping", "params_text"]

BASE_FOUNDATION = "paper_natural"
"""The preset a user's foundation starts from: the paper's film (docs/model.md §4)."""

FINISHES = ("auto", "matte", "dewy")
"""Accepted finishes; ``auto`` decides from the fit (:func:`fit_own_foundation`)."""


@dataclass(frozen=True, eq=False)
class OwnFoundation:
    """One measurement file turned into a foundation: ``data`` as read, ``choice`` (the forms
    of eq. 2 tried and the well-posed one), ``fits`` (the chosen fit), the ``finish`` used and
    ``finish_reason`` (why), and ``preset`` (the entry of
    :func:`~lut_baker.offline.foundation_presets.derive_preset`: ``absorption``, ``film``,
    ``target``, ``stack``, ``clamped``)."""

    path: Path
    name: str
    data: InPlaneData
    choice: ModelChoice
    finish: str
    finish_reason: str
    preset: dict

    @property
    def fits(self) -> ChannelFits:
        """The well-posed fit the film is derived from."""
        return self.choice.fit

    @property
    def fit_warnings(self) -> list[str]:
        """The per-channel fits' warnings, each prefixed with its channel (``"G: ..."``)."""
        return [f"{channel}: {warning}"
                for channel, fit in zip(CHANNELS, self.fits.fits, strict=True)
                for warning in fit.warnings]

    @property
    def clamp_warnings(self) -> list[str]:
        """One sentence per channel whose absorption was clamped (target out of the stack's
        reach)."""
        out = []
        for c, channel in enumerate(CHANNELS):
            if self.preset["clamped"][c]:
                target, stack = self.preset["target"][c], self.preset["stack"][c]
                side = "above the most" if target > stack else "below the least"
                out.append(f"{channel}: absorption clamped at {self.preset['absorption'][c]:g}: "
                           f"the thick layer reflects {target:.4f}, {side} the paper's film "
                           f"reflects stacked ({stack:.4f})")
        return out

    @property
    def finish_warnings(self) -> list[str]:
        """A dewy finish given for a fit without lobe: the film gets no gloss."""
        if self.finish == "dewy" and not self.fits.fit_model.lobe:
            return ["finish: dewy was given, but the data determine no lobe "
                    f"({self.choice.summary()}): the film's P_s is 0"]
        return []

    @property
    def warnings(self) -> list[str]:
        """:attr:`fit_warnings`, :attr:`clamp_warnings`, then :attr:`finish_warnings`."""
        return self.fit_warnings + self.clamp_warnings + self.finish_warnings


def fit_own_foundation(path, name: str | None = None, finish: str = "auto") -> OwnFoundation:
    """Read ``path``, fit eq. 2 to every row in its well-posed form and derive the film
    (module docstring).  ``name`` defaults to the file's stem.  ``finish``: ``"matte"`` (no
    gloss), ``"dewy"`` (the luminance-weighted mean lobe) or ``"auto"``: dewy when every
    channel's roughness ``n`` is determined (fitted, not at its bound, standard error at most
    10% of ``n``), else matte.  Every problem is one ``ValueError`` line naming the file."""
    path = Path(path)
    if finish not in FINISHES:
        raise ValueError(f"finish must be one of {', '.join(FINISHES)}, got {finish!r}")
    data = read_inplane(path)
    try:
        rgb = data.rgb
        choice = well_posed(data.theta_i_deg, data.theta_o_deg, rgb)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    if finish == "auto":
        used, determined = auto_finish(choice.fit.fits)
        reason = (f"auto: {determined}" if choice.model.lobe else
                  f"auto: the data determine no lobe; {choice.summary()}")
    else:
        used, reason = finish, "given"
    name = path.stem if name is None else name
    preset = derive_preset(name, used, choice.fit.layers, label=name)
    return OwnFoundation(path, name, data, choice, used, reason, preset)


def params_mapping(result: OwnFoundation) -> dict:
    """The parameter file's entries (:mod:`lut_baker.model.params_file`): ``name``,
    ``foundation``, ``absorption`` and ``film`` (``P_s``, ``n``, ``eta``)."""
    return {
        "name": result.name,
        "foundation": BASE_FOUNDATION,
        "absorption": [float(a) for a in result.preset["absorption"]],
        "film": {key: float(result.preset["film"][key]) for key in ("P_s", "n", "eta")},
    }


def _triple(values, digits: int = 4) -> str:
    return " / ".join(f"{float(v):.{digits}f}" for v in values)


def _fit_lines(result: OwnFoundation) -> list[str]:
    fits = result.fits
    out = ["eq. 2 fitted to every row, the three channels at once, in the form the data "
           "determine (forms tried: "
           + "; ".join(f"{step.fit_model.describe()}, error rms {100 * step.error()[0]:.3g}%"
                       for step, _ in result.choice.steps) + ")"]
    tilt = fits.tilt
    out.append(f"chosen: {fits.fit_model.describe()}"
               + (f"; the sample's tilt {tilt[0]:+.3f} +- {tilt[1]:.3f} degrees (not in the "
                  "film)" if tilt else "")
               + f"; {fits.joint.starts.summary()}")
    out.append("per channel (reflectance factors R = pi f_r; P_d, P_s in 1/sr, n in 1/degree; "
               "+- relative standard error, eta's relative to eta - 1; error = model / "
               "measured - 1):")
    for c, (channel, fit) in enumerate(zip(CHANNELS, fits.fits, strict=True)):
        se = fit.relative_stderr
        keys = ("P_d", "P_s", "n", "eta") if fits.fit_model.lobe else ("P_d",)
        parts = [f"{key} = {float(getattr(fit.params, key)):.4g} (+-{100 * se[key]:.3g}%)"
                 if key in se else f"{key} = {float(getattr(fit.params, key)):.4g} (held)"
                 for key in keys]
        if not fits.fit_model.lobe:
            parts.append("no lobe (P_s = 0)")
        rms, worst = fits.channel_error(c)
        out.append(f"  {channel}: {', '.join(parts)}; error rms {100 * rms:.3g}%, worst "
                   f"{100 * worst:.3g}%")
    rms, worst = fits.error()
    out.append(f"  all channels: error rms {100 * rms:.3g}%, worst {100 * worst:.3g}%")
    return out


def _header(result: OwnFoundation, command: str | None) -> list[str]:
    data = result.data
    layout = (f"{SPECTRAL_SAMPLES} spectral values (380-780 nm) per row, to linear Rec.709 "
              f"(CIE 1931 2 deg, D65)" if data.layout == "spectral"
              else "3 linear RGB values per row")
    incidences = ", ".join(f"{v:g}" for v in data.incidences_deg)
    preset = result.preset
    exchange = paper_film_exchange()
    top = float(stack_reflectance(0.0, exchange))
    lines = [command] if command else []
    lines += [
        "A foundation from in-plane measurements of a thick layer (docs/fitting.md): the paper's",
        "film with the product's gloss and absorption (docs/model.md §4, \"Presets from "
        "measured thick layers\").",
        f"file: {result.path}; {layout}; {len(data.theta_i_deg)} rows; "
        f"incidences {incidences} degrees",
        f"finish: {result.finish} ({result.finish_reason})",
        "",
        *_fit_lines(result),
        "",
        "thick layer against the film stacked without end (bihemispherical reflectance, "
        f"R / G / B; the paper's film stacked reflects {exchange.r_gloss:.4f} to {top:.4f}):",
        f"  target {_triple(preset['target'])}",
        f"  stack  {_triple(preset['stack'])}",
        f"  absorption {_triple(preset['absorption'])}; clamped: "
        f"{', '.join(c for c, f in zip(CHANNELS, preset['clamped'], strict=True) if f) or 'none'}",
        "",
    ]
    warnings = result.warnings
    lines += ["warnings:"] + [f"  {w}" for w in warnings] if warnings else ["warnings: none"]
    return lines


def params_text(result: OwnFoundation, command: str | None = None) -> str:
    """The parameter file as TOML: comments (``command`` first if given, the file, the finish
    and why, the fit's parameters and errors per channel, target against stack, warnings), then
    :func:`params_mapping`'s entries.  ``python -m lut_baker bake --params FILE`` bakes it."""
    mapping = params_mapping(result)
    lines = [f"# {line}".rstrip() for line in _header(result, command)]
    film = mapping["film"]
    lines += [
        "",
        f"name = {json.dumps(mapping['name'])}",
        f"foundation = {json.dumps(mapping['foundation'])}   # the paper's film as the base",
        f"absorption = [{', '.join(repr(a) for a in mapping['absorption'])}]   # R, G, B in "
        f"[0, 1]",
        "# skin = \"jensen_skin1\"   # and coverage = 0.8: add as needed (docs/baking.md)",
        "",
        f"[film]   # the gloss (eq. 2, albedo units: P_s in 1/sr, n in 1/degree); P_d and the "
        f"transmission stay the paper film's{'; matte: no lobe' if film['P_s'] == 0 else ''}",
        *(f"{key} = {value!r}" for key, value in film.items()),
    ]
    return "\n".join(lines) + "\n"
