"""Published foundations against the paper's eq. 2: CSVs, figures and a report
(docs/model.md §2.1, §4; data/lanza2024/README.md).

For each of the four products of Lanza et al. 2024 (doi:10.1111/cgf.15148), the spectral rows
are converted to linear Rec.709 reflectance factors
(:mod:`~lut_baker.offline.measured.spectra`), and eq. 2 is fitted to the three channels at once
in the well-posed form the data determine (:func:`~lut_baker.offline.measured.inplane_fit.
well_posed`: the full eq. 2 with the sample's tilt, reduced where a parameter is not
determined) to every incidence and, for the held-out test, each form tried to alternate
incidences (:mod:`~lut_baker.offline.measured.inplane_fit`); the outputs are, per product,
``<product>.csv`` (measured and model factors of the chosen fit at the measured geometries),
``<product>.png`` (luminance: measured points, model curves per incidence, in the style of
:mod:`~lut_baker.offline.paper_figures`' fig. 5) and one ``README.md`` with the numbers.

Functions and types
-------------------
- :data:`PRODUCTS` -- product name -> file and finish.
- :class:`ProductAnalysis` -- one product's data, fits (the forms tried and the chosen one)
  and misses.
- :func:`analyse` -- read, convert and fit one product.
- :func:`write_csv` -- the measured/model table of one product.
- :func:`product_figure` -- the luminance figure of one product.
- :func:`report` -- the Markdown report over the products.
- :func:`derived_presets` -- the thin-film presets the products imply
  (:mod:`~lut_baker.offline.foundation_presets`, docs/model.md §4).
- :func:`read_notes` -- the written notes placed below the tables (docs/foundations/notes.md).
- :func:`write_all` -- everything above into one folder, and the presets to the runtime's file.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..model.albedo import reflection_albedo
from ..model.presets import paper
from ..model.thick_layer import paper_film_exchange, stack_reflectance
from .atomic_files import replacing, write_text
from .foundation_presets import derive_presets, write_presets
from .measured import inplane_fit
from .measured.fit_results import DEFAULT_LIMITS
from .measured.fit_solver import SAME_COST, TILT_LIMIT_DEG
from .measured.fit_starts import ETA_STARTS, N_GRID_PARTS, TILT_STARTS_DEG
from .measured.inplane import InPlaneData, read_inplane
from .measured.inplane_fit import (
    CHANNELS,
    DEGENERATE_CORRELATION,
    ChannelFits,
    FitModel,
    ModelChoice,
    alternate_incidences,
    fit_channels,
    misses,
    well_posed,
)
from .measured.spectra import luminance
from .paper_figures import GREY, sequence_colours, styled_figure

__all__ = [
    "PRODUCTS",
    "CSV_COLUMNS",
    "ProductAnalysis",
    "analyse",
    "write_csv",
    "product_figure",
    "report",
    "derived_presets",
    "NOTE_SECTIONS",
    "read_notes",
    "write_all",
]

PRODUCTS = {
    "clarins_103": ("Clarinsfoundation103N_norm_thick_layer_tab.txt", "matte"),
    "clarins_105": ("Clarins_105_Nude_coll_norm.txt", "dewy"),
    "clarins_108": ("Clarinsfoundation108_5W_norm_thick_layer_tab.txt", "matte"),
    "clarins_112": ("Clarins112_5W_thick_layer_tab.txt", "dewy"),
}
"""Product name -> (file in data/lanza2024/, finish)."""

CSV_COLUMNS = ("theta_i_deg", "theta_o_deg", "measured_R", "measured_G", "measured_B",
               "model_R", "model_G", "model_B")
"""The header of each product's CSV, in order."""

CURVE_STEP_DEG = 0.25
"""Step (degrees) of the figures' model curves."""


@dataclass(frozen=True, eq=False)
class ProductAnalysis:
    """One product: ``data`` as read, ``choice`` (the forms of eq. 2 tried on every incidence
    and the well-posed one, :func:`~lut_baker.offline.measured.inplane_fit.well_posed`),
    ``held_out_steps`` (each form fitted on ``split[0]``, to be judged on ``split[1]``) and
    ``misses`` of the chosen fit (:func:`~lut_baker.offline.measured.inplane_fit.misses`);
    where the chosen form has the tilt, ``untilted`` holds the same form without it, fitted on
    every incidence and on ``split[0]``, for comparison."""

    name: str
    finish: str
    data: InPlaneData
    choice: ModelChoice
    held_out_steps: tuple[ChannelFits, ...]
    split: tuple[tuple[float, ...], tuple[float, ...]]
    misses: dict
    untilted: tuple[ChannelFits, ChannelFits] | None = None

    @property
    def fit(self) -> ChannelFits:
        """The chosen (well-posed) fit on every incidence: the one the preset is derived
        from."""
        return self.choice.fit

    @property
    def held_out(self) -> ChannelFits:
        """The chosen form fitted on ``split[0]``."""
        return self.held_out_steps[-1]


def analyse(name: str, data_dir) -> ProductAnalysis:
    """Read product ``name`` (:data:`PRODUCTS`) from ``data_dir``, convert it to RGB and fit."""
    if name not in PRODUCTS:
        raise ValueError(f"unknown product {name!r}; choose from {list(PRODUCTS)}")
    filename, finish = PRODUCTS[name]
    path = Path(data_dir) / filename
    if not path.is_file():
        raise ValueError(f"{path}: no such file (the data folder needs {filename})")
    data = read_inplane(path)
    rgb = data.rgb
    choice = well_posed(data.theta_i_deg, data.theta_o_deg, rgb)
    split = alternate_incidences(data.incidences_deg)
    held_out = tuple(fit_channels(data.theta_i_deg, data.theta_o_deg, rgb, split[0],
                                  fits.fit_model) for fits, _ in choice.steps)
    untilted: tuple[ChannelFits, ChannelFits] | None = None
    if choice.model.tilt:
        model = replace(choice.model, tilt=False)
        untilted = (fit_channels(data.theta_i_deg, data.theta_o_deg, rgb, None, model),
                    fit_channels(data.theta_i_deg, data.theta_o_deg, rgb, split[0], model))
    return ProductAnalysis(name, finish, data, choice, held_out, split, misses(choice.fit),
                           untilted)


def write_csv(analysis: ProductAnalysis, path) -> Path:
    """``path`` with :data:`CSV_COLUMNS`: one row per measured geometry, reflectance factors
    (model: the all-incidence fit)."""
    fit = analysis.fit
    table = np.column_stack([fit.theta_i_deg, fit.theta_o_deg, fit.measured, fit.model])
    lines = [",".join(CSV_COLUMNS)]
    lines += [",".join([f"{row[0]:g}", f"{row[1]:g}"] + [f"{v:.6g}" for v in row[2:]])
              for row in table]
    return write_text(path, "\n".join(lines) + "\n")


def product_figure(analysis: ProductAnalysis):
    """Luminance (Rec.709 ``Y``) of the reflectance factor against theta_o: measured points and
    the chosen fit's curve per incidence (the tilt included), mirror directions dotted, log
    scale; where the chosen form is a reduced one, the full eq. 2 without tilt dashed (or the
    form before the chosen one: a fit whose parameters the data do not determine)."""
    fit = analysis.fit
    tried = [fits for fits, _ in analysis.choice.steps[:-1]]
    before = next((fits for fits in tried if fits.fit_model == FitModel(tilt=False)),
                  tried[-1] if tried else None)
    incidences = np.unique(fit.theta_i_deg)
    y_measured = luminance(fit.measured)
    title = (f"{analysis.name} ({analysis.finish}), Lanza et al. 2024: "
             f"{fit.fit_model.describe(short=True)}")
    with styled_figure(title, r"viewing angle $\theta_o$ (degrees; > 0: specular side)",
                 r"reflectance factor $\pi f_r$ (luminance $Y$)") as (figure, axes):
        for colour, incidence in zip(sequence_colours(incidences.size), incidences,
                                     strict=True):
            rows = fit.theta_i_deg == incidence
            theta_o = fit.theta_o_deg[rows]
            dense = np.arange(theta_o.min(), theta_o.max() + 0.5 * CURVE_STEP_DEG,
                              CURVE_STEP_DEG)
            curve = luminance(fit.predict(np.full_like(dense, incidence), dense))
            axes.plot(dense, curve, color=colour, gid=f"model theta_i={incidence:g}",
                      label=rf"$\theta_i$ = {incidence:g}°")
            if before is not None:
                axes.plot(dense, luminance(before.predict(np.full_like(dense, incidence),
                                                          dense)),
                          color=colour, linestyle="--", linewidth=0.8,
                          gid=f"not determined theta_i={incidence:g}")
            axes.plot(theta_o, y_measured[rows], linestyle="none", marker="o", markersize=2.5,
                      color=colour, gid=f"measured theta_i={incidence:g}")
            axes.axvline(incidence, color=colour, linestyle=":", linewidth=0.9)
        axes.plot([], [], linestyle="none", marker="o", markersize=2.5, color=GREY,
                  label="measured")
        axes.plot([], [], color=GREY, label=f"{fit.fit_model.describe(short=True)} (chosen)")
        if before is not None:
            axes.plot([], [], color=GREY, linestyle="--", linewidth=0.8,
                      label=f"{before.fit_model.describe(short=True)}: not determined")
        axes.plot([], [], color=GREY, linestyle=":", linewidth=0.9,
                  label=r"mirror $\theta_o = \theta_i$")
        axes.set_yscale("log")
        axes.set_xlim(-45.0, 85.0)
        axes.legend(loc="upper left", ncols=2)
    return figure


# --------------------------------------------------------------------------------------------
# Report
# --------------------------------------------------------------------------------------------
def _pct(value: float) -> str:
    return f"{100.0 * value:.1f}%"


def _param(fit, name: str) -> str:
    value = float(getattr(fit.params, name))
    if name not in fit.free:
        if name == "P_s" and value == 0.0:
            return "0 (no lobe)"
        return "–" if float(fit.params.P_s) == 0.0 else f"{value:.3g} (held)"
    stderr = fit.stderr[name]
    text = f"{value:.3g} ± {stderr:.2g}"
    return text + (" (at bound)" if fit.at_bound(name) else "")


def _parameter_table(analysis: ProductAnalysis) -> list[str]:
    lines = ["| channel | P_d (1/sr) | P_s (1/sr) | n (1/deg) | eta | fit rms / worst | "
             "held-out rms / worst | albedo at 0° / 60° | warnings |",
             "|---|---|---|---|---|---|---|---|---|"]
    held = analysis.split[1]
    for c, channel in enumerate(CHANNELS):
        fit = analysis.fit.fits[c]
        rms, worst = analysis.fit.channel_error(c)
        h_rms, h_worst = analysis.held_out.channel_error(c, held)
        albedo = [float(reflection_albedo(t, fit.params)) for t in (0.0, 60.0)]
        lines.append(f"| {channel} | {_param(fit, 'P_d')} | {_param(fit, 'P_s')} | "
                     f"{_param(fit, 'n')} | {_param(fit, 'eta')} | {_pct(rms)} / "
                     f"{_pct(worst)} | {_pct(h_rms)} / {_pct(h_worst)} | "
                     f"{albedo[0]:.3f} / {albedo[1]:.3f} | {len(fit.warnings)} |")
    return lines


def _tilt_text(fits: ChannelFits) -> str:
    if fits.tilt is None:
        return "–"
    value, stderr = fits.tilt
    bound = " (at bound)" if fits.joint.at_bound("tilt_deg") else ""
    return f"{value:+.3f} ± {stderr:.3f}{bound}"


def _starts_text(fits: ChannelFits) -> str:
    starts = fits.joint.starts
    text = f"{starts.reached} of {starts.count}, within {starts.spread:.1g}"
    if starts.next_excess is not None:
        text += f"; next end +{_pct(starts.next_excess)}"
    return text


def _checks_text(decisions) -> str:
    if not decisions:
        return "– (linear in log P_d)"
    return "; ".join(("passed" if d.passed else "**failed**") + f": {d.why}"
                     for d in decisions)


def _model_table(analysis: ProductAnalysis) -> list[str]:
    """The forms of eq. 2 tried (:func:`~lut_baker.offline.measured.inplane_fit.well_posed`),
    each with its errors, tilt, starts and checks."""
    lines = ["| form of eq. 2 | fit rms / worst | held-out rms / worst | tilt (degrees) | "
             "starts reaching the best (parameter spread; next end) | checks | |",
             "|---|---|---|---|---|---|---|"]
    held = analysis.split[1]
    steps = analysis.choice.steps
    for index, ((fits, decisions), held_out) in enumerate(zip(steps, analysis.held_out_steps,
                                                              strict=True)):
        rms, worst = fits.error()
        h_rms, h_worst = held_out.error(held)
        verdict = "**chosen**" if index == len(steps) - 1 else "reduced"
        lines.append(f"| {fits.fit_model.describe()} | {_pct(rms)} / {_pct(worst)} | "
                     f"{_pct(h_rms)} / {_pct(h_worst)} | {_tilt_text(fits)} | "
                     f"{_starts_text(fits)} | {_checks_text(decisions)} | {verdict} |")
    if analysis.untilted:
        fits, held_out = analysis.untilted
        rms, worst = fits.error()
        h_rms, h_worst = held_out.error(held)
        lines.append(f"| {fits.fit_model.describe()} | {_pct(rms)} / {_pct(worst)} | "
                     f"{_pct(h_rms)} / {_pct(h_worst)} | – | {_starts_text(fits)} | – | "
                     "without the tilt, for comparison |")
    return lines


def _untilted_peaks(analysis: ProductAnalysis) -> list[str]:
    """One line: the peaks of the same form without the tilt."""
    if not analysis.untilted:
        return []
    found = misses(analysis.untilted[0])
    ratios = ", ".join(f"{m['peak_ratio']:.2f}" for m in found.values())
    offsets = [m["peak_deg"][1] - m["mirror_deg"] for m in found.values()]
    first, last = min(found), max(found)
    return [f"Without the tilt, peak Y measured / model {ratios} ({first:g}–{last:g}°), the "
            f"model's peaks {min(offsets):.1f}–{max(offsets):.1f}° past the mirror theta_i.",
            ""]


def _miss_table(analysis: ProductAnalysis) -> list[str]:
    tilted = analysis.fit.tilt is not None
    lines = ["| theta_i | peak theta_o measured / model"
             + (" (sample's mirror theta_i + 2 tilt)" if tilted else "")
             + " | peak Y measured / model | "
             "back-scatter measured / model (mean, range) | at theta_o ≈ 0: measured / model | "
             "at largest theta_o: measured / model | rise from theta_o ≈ 0 to there: "
             "measured, model |",
             "|---|---|---|---|---|---|---|"]
    for incidence, m in analysis.misses.items():
        back = m.get("back_ratio")
        back_text = (f"{back[0]:.2f} ({back[1]:.2f}–{back[2]:.2f})" if back else "not measured")
        g = m["grazing"]
        mirror = f" ({m['tilted_mirror_deg']:.1f}°)" if tilted else ""
        model_peak = "flat" if m["peak_deg"][1] is None else f"{m['peak_deg'][1]:.1f}°"
        lines.append(f"| {incidence:g}° | {m['peak_deg'][0]:g}° / {model_peak}"
                     f"{mirror} | {m['peak_ratio']:.2f} | {back_text} | "
                     f"{g['near_normal_ratio']:.2f} (at {g['from_deg']:g}°) | {g['ratio']:.2f} "
                     f"(at {g['theta_o_deg']:g}°) | {g['measured_rise']:.2f}, "
                     f"{g['model_rise']:.2f} |")
    return lines


def _summary(analysis: ProductAnalysis) -> str:
    rms, worst = analysis.fit.error()
    h_rms, h_worst = analysis.held_out.error(analysis.split[1])
    fitted = "/".join(f"{v:g}" for v in analysis.split[0])
    judged = "/".join(f"{v:g}" for v in analysis.split[1])
    tilt = analysis.fit.tilt
    tilt_text = (f"; the sample's tilt {tilt[0]:+.3f} ± {tilt[1]:.3f}° (a nuisance parameter: "
                 "not in the preset)" if tilt else "")
    return (f"Chosen form: {analysis.fit.fit_model.describe()}{tilt_text}. All channels: fit on "
            f"every incidence {_pct(rms)} rms, {_pct(worst)} worst; "
            f"fitted on {fitted}° and predicting {judged}°: {_pct(h_rms)} rms, "
            f"{_pct(h_worst)} worst (relative errors `model/measured - 1` over the measured "
            f"geometries).")


def derived_presets(analyses: list[ProductAnalysis]) -> dict:
    """The presets' entries (:func:`~lut_baker.offline.foundation_presets.derive_presets`) from
    the all-incidence fits."""
    return derive_presets({a.name: (a.finish, a.fit.layers) for a in analyses})


def _triple(values, digits: int = 3) -> str:
    return " / ".join(f"{float(v):.{digits}f}" for v in values)


def _preset_section(presets: dict) -> list[str]:
    exchange = paper_film_exchange()
    out = ["## Presets for the model: the thin film each thick layer implies", "",
           "Written to lut_baker/model/measured_foundations.json, which the presets read "
           "(docs/model.md §4, \"Presets from measured thick layers\"). The film keeps the "
           "paper film's P_d and transmission (eq. 4); its absorption A (R / G / B) is solved "
           "so that the film stacked on itself without end (adding equation, uniform light) "
           "reflects the target, the eq. 2 fit's bihemispherical reflectance (its directional "
           "albedo averaged over uniform incident light); gloss: dewy, the luminance-weighted "
           "mean of the fit's P_s, n, eta; matte, none (P_s = 0). The paper film's exchange: "
           f"gloss {exchange.r_gloss:.4f}, diffuse {exchange.r_diffuse:.4f} (pi P_d), "
           f"transmittance {exchange.t_0:.4f}; stacked, it reflects at most "
           f"{_stack_max(exchange):.4f} (A = 0) and at least {exchange.r_gloss:.4f} (A = 1).",
           "",
           "| preset | label | target R / G / B | stack R / G / B | absorption A R / G / B | "
           "gloss P_s (1/sr), n (1/deg), eta | clamped |",
           "|---|---|---|---|---|---|---|"]
    for name, entry in presets.items():
        film = entry["film"]
        clamped = ", ".join(c for c, flag in zip("RGB", entry["clamped"], strict=True) if flag)
        out.append(f"| {name} | {entry['label']} | {_triple(entry['target'])} | "
                   f"{_triple(entry['stack'])} | {_triple(entry['absorption'], 4)} | "
                   f"{film['P_s']:.3g}, {film['n']:.3g}, {film['eta']:.3g} | "
                   f"{clamped or 'no'} |")
    out.append("")
    return out


def _stack_max(exchange) -> float:
    return float(stack_reflectance(0.0, exchange))


def _listed(values, unit: str = "", signed: bool = False) -> str:
    """``1.05, 1.5, 5`` (``-1.5°, 0°, +1.5°`` signed, with a unit)."""
    return ", ".join((f"{v:+g}" if signed and v else f"{v:g}") + unit for v in values)


def _part(count: int) -> str:
    """``third`` for 3: the part of a grid cut into ``count``."""
    return {2: "half", 3: "third", 4: "quarter"}.get(count, f"1/{count} part")


def _power(value: float) -> str:
    """``1e-6``, not ``1e-06``."""
    mantissa, exponent = f"{value:.0e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def report(analyses: list[ProductAnalysis], notes: dict | None = None,
           presets: dict | None = None) -> str:
    """The Markdown report: method, per product the parameters, errors and misses, the
    derived ``presets`` (:func:`derived_presets`) if given, and the written ``notes`` (product
    name -> paragraph; key ``"presets"`` below the presets' table, ``"conclusion"`` for the
    end)."""
    notes = notes or {}
    out = [
        "# Published foundations against the paper's eq. 2",
        "",
        "Generated by `python -m lut_baker foundations` (lut_baker/offline/foundations.py) "
        "from the in-plane measurements of Lanza et al., \"Practical Appearance Model for "
        "Foundation Cosmetics\", Computer Graphics Forum 43(4), 2024, doi:10.1111/cgf.15148 "
        "(data/lanza2024/README.md). The text below the tables is written by hand in "
        "[notes.md](notes.md), which quotes their numbers; rerunning the command rewrites the "
        "tables and copies the notes.",
        "",
        "**Method.** Spectra (380–780 nm) to linear Rec.709 RGB (CIE 1931 2°, D65, white "
        "reflector -> 1, 1, 1). Each row is light at theta_i, camera at signed theta_o "
        "(> 0: specular side), so the paper's reflection geometry (docs/model.md §6) has "
        "psi = theta_i + theta_o and alpha = (theta_i - theta_o)/2. The values are read as "
        "reflectance factors R = pi f_r, so the paper's signal (eq. 1) is "
        "I = R cos(theta_i)/pi and the fitted P_d, P_s are in 1/sr (docs/model.md §4). "
        "`ReflectionLayer(P_d, P_s, n, eta)` (eq. 2, n in 1/degree, docs/model.md §2.1) is "
        "fitted to the three channels at once (`fit_reflection_sets`, relative residuals), one "
        "layer per channel and, shared by the channels and every incidence, the tilt of the "
        "sample in the plane of incidence: a sample tilted by tau sees the light at "
        "theta_i + tau and the camera at theta_o - tau, so its mirror direction lies at "
        f"theta_o = theta_i + 2 tau (fitted within ±{TILT_LIMIT_DEG:g}° with its standard "
        "error; a nuisance "
        f"parameter, not part of the presets). Every fit is refined from several starts (the "
        f"full form from {len(ETA_STARTS) * len(TILT_STARTS_DEG)}: eta {_listed(ETA_STARTS)} "
        f"at tilts {_listed(TILT_STARTS_DEG, '°', signed=True)}, P_d and P_s by "
        f"non-negative least squares on a grid of n; without the tilt from {len(ETA_STARTS)}; "
        f"with eta held from the best n in each {_part(N_GRID_PARTS)} of the grid; P_d alone, "
        "which is linear, from its "
        "solution), and the best end is polished by Gauss-Newton steps, so that the "
        "parameters move by about 1e-9 when the data move by 1e-9. The form of eq. 2 is then "
        "reduced until the data determine every parameter (`inplane_fit.well_posed`): the "
        "tilt is left out when it runs to its bound or its standard error exceeds its size; "
        "the lobe is left out (P_d alone, no tilt) when in some channel P_s or n sits at a "
        "bound or has a standard error beyond its value; eta is held at the paper film's "
        f"{float(paper().film.eta):g} when it is not determined or P_s and eta correlate "
        f"beyond {DEGENERATE_CORRELATION:g}. ± is one "
        f"standard error; \"starts\" counts the starts that ended within {_power(SAME_COST)} "
        "(relative) of "
        "the best cost, the largest difference of their (logarithmic) parameters, and how "
        "much higher the best other end lies; \"warnings\" counts the fit's own diagnostics "
        "(ill-conditioned or degenerate parameters, bounds, residual > "
        f"{100 * DEFAULT_LIMITS.residual_rms:g}%). Albedo: the "
        "fitted layer's directional albedo (eq. 2 integrated over the hemisphere). Misses are "
        "in luminance Y, for the chosen fit; the model's peak is searched on a "
        f"{inplane_fit.CURVE_STEP_DEG:g}° grid over the measured theta_o range.",
        "",
    ]
    for analysis in analyses:
        out += [f"## {analysis.name} ({analysis.finish})", "",
                f"![{analysis.name}]({analysis.name}.png) — data and model at the measured "
                f"geometries: [{analysis.name}.csv]({analysis.name}.csv)", "",
                _summary(analysis), ""]
        out += ["The forms of eq. 2 tried, from the full one down (each fitted to every "
                "incidence, and to alternate incidences for the held-out column):", ""]
        out += _model_table(analysis) + [""]
        out += ["The chosen fit per channel:", ""]
        out += _parameter_table(analysis) + [""]
        out += ["Where the chosen fit misses (luminance; mirror direction theta_o = theta_i):",
                ""]
        out += _miss_table(analysis) + [""]
        out += _untilted_peaks(analysis)
        if analysis.name in notes:
            out += [notes[analysis.name], ""]
    if presets:
        out += _preset_section(presets)
        if "presets" in notes:
            out += [notes["presets"], ""]
    if "conclusion" in notes:
        out += ["## Conclusions", "", notes["conclusion"], ""]
    return "\n".join(out)


NOTE_SECTIONS = ("presets", "conclusion")
"""The notes' sections beside the products': below the presets' table, and the end."""


def read_notes(path) -> dict[str, str]:
    """The written notes of a Markdown file (``docs/foundations/notes.md``): section name ->
    text, a section being a level-2 heading naming a product of :data:`PRODUCTS` or one of
    :data:`NOTE_SECTIONS`, its text running to the next heading (a paragraph's lines joined
    with single spaces, paragraphs by a blank line).  The notes quote the report's numbers, so
    they are prose in the docs, not code.  ``ValueError`` for a missing file or a heading that
    names no section."""
    try:
        lines = Path(path).read_text(encoding="utf-8").splitlines()
    except OSError as error:
        raise ValueError(f"notes {str(path)!r}: {error.strerror or error}") from None
    sections: dict[str, list[str]] = {}
    current: list[str] | None = None
    for line in lines:
        if line.startswith("## "):
            name = line[3:].strip()
            if name not in PRODUCTS and name not in NOTE_SECTIONS:
                raise ValueError(f"notes {str(path)!r}: section {name!r} is neither a product "
                                 f"({', '.join(PRODUCTS)}) nor one of {', '.join(NOTE_SECTIONS)}")
            current = sections.setdefault(name, [])
        elif current is not None:
            current.append(line)
    return {name: _paragraphs(body) for name, body in sections.items()}


def _paragraphs(lines: list[str]) -> str:
    """Markdown lines as paragraphs of one line each, separated by a blank line."""
    paragraphs, words = [], []
    for line in [*lines, ""]:
        if line.strip():
            words.append(line.strip())
        elif words:
            paragraphs.append(" ".join(words))
            words = []
    return "\n\n".join(paragraphs)


def write_all(data_dir, out_dir, products=None, presets_path=None,
              notes: dict[str, str] | None = None) -> list[Path]:
    """Analyse ``products`` (default all of :data:`PRODUCTS`) and write ``<product>.csv``,
    ``<product>.png`` and ``README.md`` (with the derived presets and the written ``notes``,
    :func:`read_notes`) to ``out_dir``, and the presets' JSON to ``presets_path`` if given (the
    runtime reads :data:`~lut_baker.offline.foundation_presets.PRESET_FILE`); returns the paths
    written."""
    from .paper_figures import DPI

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ValueError(f"{out} exists and is not a folder")
    analyses = [analyse(name, data_dir) for name in (products or PRODUCTS)]
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for analysis in analyses:
        paths.append(write_csv(analysis, out / f"{analysis.name}.csv"))
        figure_path = out / f"{analysis.name}.png"
        with replacing(figure_path) as temporary:
            product_figure(analysis).savefig(temporary, dpi=DPI, metadata={"Software": None})
        paths.append(figure_path)
    presets = derived_presets(analyses)
    readme = out / "README.md"
    write_text(readme, report(analyses, notes, presets))
    paths.append(readme)
    if presets_path is not None:
        paths.append(write_presets(presets, presets_path))
    return paths
