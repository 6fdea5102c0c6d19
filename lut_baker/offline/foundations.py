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
- :func:`write_all` -- everything above into one folder, and the presets to the runtime's file.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..model.albedo import reflection_albedo
from ..model.thick_layer import paper_film_exchange, stack_reflectance
from .atomic_files import replacing, write_text
from .foundation_presets import derive_presets, write_presets
from .measured.inplane import InPlaneData, read_inplane
from .measured.inplane_fit import (
    CHANNELS,
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
        "(data/lanza2024/README.md). The text below the tables is written in "
        "lut_baker/offline/foundations.py's `NOTES`; rerunning the command rewrites the numbers.",
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
        "theta_o = theta_i + 2 tau (fitted within ±5° with its standard error; a nuisance "
        "parameter, not part of the presets). Every fit is refined from several starts (the "
        "full form from 9: eta 1.05, 1.5, 5 at tilts -1.5°, 0°, +1.5°, P_d and P_s by "
        "non-negative least squares on a grid of n; without the tilt from 3; with eta held "
        "from the best n in each third of the grid; P_d alone, which is linear, from its "
        "solution), and the best end is polished by Gauss-Newton steps, so that the "
        "parameters move by about 1e-9 when the data move by 1e-9. The form of eq. 2 is then "
        "reduced until the data determine every parameter (`inplane_fit.well_posed`): the "
        "tilt is left out when it runs to its bound or its standard error exceeds its size; "
        "the lobe is left out (P_d alone, no tilt) when in some channel P_s or n sits at a "
        "bound or has a standard error beyond its value; eta is held at the paper film's "
        "1.19 when it is not determined or P_s and eta correlate beyond 0.99. ± is one "
        "standard error; \"starts\" counts the starts that ended within 1e-6 (relative) of "
        "the best cost, the largest difference of their (logarithmic) parameters, and how "
        "much higher the best other end lies; \"warnings\" counts the fit's own diagnostics "
        "(ill-conditioned or degenerate parameters, bounds, residual > 20%). Albedo: the "
        "fitted layer's directional albedo (eq. 2 integrated over the hemisphere). Misses are "
        "in luminance Y, for the chosen fit; the model's peak is searched on a 0.1° grid over "
        "the measured theta_o range.",
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


NOTES: dict[str, str] = {
    "clarins_103": (
        "**Reading.** The data determine no lobe. The full fit's roughness ends at its lower "
        "bound in every channel (D = 1: no lobe), and what it fits instead, P_s G F_r with "
        "eta ≈ 1.03–1.04, is a Fresnel-shaped rise toward grazing whose P_s and eta are "
        "degenerate (|correlation| 0.9986; P_s's standard error 1.9 times its value in R); the "
        "tilt, with nothing to align, runs to its bound (-5°). The preset is therefore fitted "
        "with P_d alone: 19.4% rms, 23.1% held-out, where the undetermined full form reaches "
        "12.1% and 16.6%. **Misses.** The data rise toward grazing view (1.32× from "
        "theta_o ≈ 0 to 78° at 20–30° incidence, 1.57× at 70°), and the level near the normal "
        "rises with incidence (0.84 of P_d at 20° to 1.19 at 70°), as does the back-scatter "
        "side (0.92 at 40° to 1.24 at 70°): a retro-reflective, incidence-dependent component "
        "eq. 2 does not have (see the conclusions)."),
    "clarins_105": (
        "**Reading.** A broad lobe (n = 0.15–0.18 /deg: 1/e at 5.5–6.5° of alpha) over a "
        "diffuse base, on a sample tilted by +1.15 ± 0.07°: its mirror direction lies at "
        "theta_i + 2.3°, where the measured maxima are (3° past the nominal mirror at 20–40° "
        "incidence, 6° at 50–70°). With the tilt every parameter is determined; P_s and eta "
        "are still correlated (|correlation| up to 0.983, under the 0.99 at which they would "
        "be tied: the narrowest margin of any check that decides a form), but "
        "P_s's standard error is at most 19% of its value. The tilt takes the fit from 13.3% "
        "to 10.3% rms and the held-out error from 18.3% to 17.2%, and the peaks from "
        "measured/model 1.19, 1.16, 1.13, 1.04, 1.01, 1.16 to 1.15, 1.11, 1.07, 0.96, 0.90, "
        "1.07 (20–70°). The fitted lobe's own maximum lies 0.1–0.5° past the tilted mirror at "
        "20–30° and 1.5–5.3° at 40–70° (eq. 2's G F_r cos at a broad lobe). **Misses.** The "
        "back-scatter side is over-predicted (0.85–0.96 at 40–60°), the level near the normal "
        "too (0.85–0.88 at 30–50°), while at grazing view the data rise 1.3–1.4× (30–50° "
        "incidence) and the model stays flat (1.00–1.02×)."),
    "clarins_108": (
        "**Reading.** The data determine no lobe. Of the full fit's three starts one finds "
        "the lowest minimum (the next end lies 30% higher; the previous report's single "
        "start stopped in a higher one, with red's lobe collapsed, at 14.9% and 19.0% "
        "held-out): 12.4% rms and 10.5% held-out, with a weak wide lobe (n ≈ 0.05 /deg) whose "
        "eta runs to 9–10 with a standard error 10 times eta - 1 and whose P_s, correlated "
        "with eta at 0.9996, has a standard error 4 times its value. With the tilt the fit "
        "runs to its bound (+5°); with eta held at 1.19 the lobe vanishes (P_s → 0, n "
        "undetermined). The preset is fitted with P_d alone: 19.5% rms, 19.0% held-out. "
        "**Misses.** The data have structure a constant cannot follow: maxima at grazing view "
        "for 30–40° incidence (1.43× and 1.67× the theta_o ≈ 0 level), off-specular maxima at "
        "theta_o ≈ 50° for 60° and 70° incidence, and a level near the normal that falls with "
        "incidence (0.89 of P_d at 30° to 0.65–0.67 at 60–70°); back-scatter 0.73–0.87. The "
        "file is also the noisiest (3.5% along wavelength; an abrupt drop at 50°/75°)."),
    "clarins_112": (
        "**Reading.** Most of what eq. 2 missed on this narrow gloss was the sample's "
        "alignment. Tilted by +1.37 ± 0.04°, the sample's mirror lies at theta_i + 2.7°, where "
        "the measured maxima are (32°, 43°, 53°, 63° at 30–60° incidence); the fit goes from "
        "135.9% to 52.9% rms (held-out 167.6% to 82.5%), its peaks from 1.90–3.91× under to "
        "1.29–1.41× under at 30–50° incidence and 2.05× at 60°, and the lobe comes out higher "
        "and narrower (P_s 49–100 /sr, n = 0.47 /deg, 1/e at 2.1° of alpha; untilted 24–40 /sr "
        "and 0.34 /deg). The fitted lobe's own maximum lies only 0.1–0.5° past the tilted "
        "mirror (eq. 2's G F_r cos), while the measured maxima lie 2–3° past the nominal one: "
        "the offset is geometric, not off-specular reflection. **What remains.** Away from "
        "the lobe the data fall with incidence (near-normal measured/model 0.87 at 30° to "
        "0.56–0.59 at 60–70°) and rise toward grazing view (2.2–2.5× at 30–50° incidence) "
        "where the model stays flat (1.00×); one lobe over a constant P_d cannot hold the lobe "
        "and its surroundings, and the worst errors (274%) sit on the lobe's flanks."),
    "presets": (
        "**Reading.** The stack of the paper's film reflects at most 0.834 (no absorption): "
        "every target but 105's red lies below, and those are met to rounding. 105's red "
        "(0.897) is brighter than the paper's film can be made by stacking, so its absorption "
        "is clamped at 0 and its thick-layer limit reflects 0.834 (7% under). Absorption rises "
        "from red to blue in every product, as in the hand-picked shades; 108 and 112, the "
        "darker products, absorb 0.76–0.89 of the blue. The matte products get no gloss: "
        "their well-posed fits are P_d alone, so their target is pi P_d, the geometric mean of "
        "the measured factors over the sampled geometries. The dewy ones get one achromatic "
        "lobe: 105 broad (P_s = 42.4 /sr, n = 0.168 /deg), 112 narrow (71.5 /sr, n = 0.470 "
        "/deg; its fit still misses its peaks by 1.3–2×, so its gloss remains a lower bound in "
        "height). Against the previous fits (single start, no tilt, every parameter kept): "
        "108's green and blue absorption fell from 0.66 and 0.86 to 0.51 and 0.76 (the "
        "previous fits gave them an undetermined lobe with eta ≈ 9.5 that took reflectance "
        "from P_d; red, then without lobe, keeps 0.167), 103's from 0.08 / 0.29 / 0.48 to "
        "0.06 / 0.24 / 0.40, and 112's gloss rose from 31.6 /sr at n = 0.342 to 71.5 /sr at "
        "n = 0.470. The hand-picked shades stay beside them: deep_mocha absorbs far more red "
        "(0.38) than any product (at most 0.28), a deep brown none of the four is, though 108 "
        "and 112 absorb more green and blue."),
    "conclusion": (
        "**Reflectance factors, R = pi f_r.** The matte products' levels settle it. Near the "
        "normal 103 measures R, G, B ≈ 0.74, 0.55, 0.43 and 108 ≈ 0.48, 0.29, 0.19, the "
        "reflectances of a light and a medium beige powder; the fits read as R = pi f_r "
        "integrate to directional albedos (at normal incidence) 0.740 / 0.569 / 0.455 (103) "
        "and 0.624 / 0.395 / 0.261 (108), below 1 as they must be (105: 0.895 / 0.656 / "
        "0.496; 112: 0.544 / 0.330 / 0.195). "
        "Read as BRDF values in 1/sr instead, the same data would integrate to pi times "
        "those, 2.3 / 1.8 / 1.4 for 103 and 2.0 / 1.2 for 108's red and green: more light out "
        "than in. So the files hold reflectance relative to a white standard, i.e. pi x BRDF "
        "for an ideal Lambertian white; a real standard (reflectance about 0.98, not quite "
        "Lambertian at grazing view) leaves a scale uncertainty of a few percent.\n\n"
        "**Well-posed fits.** Every number the presets take is determined by its data: "
        "re-derived from the measurements perturbed by 1e-9 (relative), with 1 or 2 BLAS "
        "threads, or on a CPU without AVX-512, every preset value moves by about 1e-9 "
        "(tests/lut_baker/offline/test_foundation_presets.py holds it under 1e-6). The price "
        "is honesty about the matte products: P_d alone fits them to 19.4–19.5% rms where "
        "the undetermined full forms reach 12.1–12.4%; a number the data do not pin (108's "
        "red absorption was 0.167 on one CPU and 0.340 on another) is not a preset.\n\n"
        "**Alignment.** Both glossy products need a tilt of the same sign, +1.15 ± 0.07° "
        "(105) and +1.37 ± 0.04° (112), and the matte products, which have no direction to "
        "align, run to the bound either way: a setup offset more likely than the samples. "
        "These data cannot tell a tilted sample from a camera arm off by twice the angle, or "
        "from a tilt that also changes the irradiance (a white reference taken at the nominal "
        "geometry): re-fitted either way (same data, not in these tables) both fit slightly "
        "better, their costs 0.4–5% lower, with offsets within 0.06° (105) and 0.002° (112) "
        "of the tilt's. The tilt is a nuisance parameter: it never reaches the presets.\n\n"
        "**Eq. 2 against real foundations: what remains.** Aligned, eq. 2 gets the broad "
        "dewy product to 10.3% rms (35% worst) and predicts its held-out incidences at 17.2%. "
        "Three things it cannot do: (1) the narrow gloss of 112, 52.9% rms even aligned, its "
        "peaks 1.3–2× under and the lobe's surroundings off; (2) a base level that changes "
        "with incidence (103 rises from 0.84 to 1.19 of P_d between 20° and 70°; 108 falls "
        "from 0.89 to 0.67, 112 from 0.87 to 0.59), where P_d is constant; (3) a rise toward "
        "grazing view at moderate incidence (1.3–2.5× measured against 1.0× modelled). On 103 "
        "(2) is what a powder's single scattering does: a Lommel-Seeliger term "
        "1/(cos theta_i + cos theta_o) rises 1.43× from (20°, 10°) to (70°, 0°), measured "
        "1.42×, though it over-shoots (3) (1.68× from theta_o = 10° to 78° at 20° incidence, "
        "measured 1.32×); 108's level falls instead. **Why the model is not extended.** No "
        "closure of the model has such a term: (2) and (3) need a second, "
        "incidence-dependent diffuse term, which would add a closure to both tiers and a table "
        "to the bake for errors that are 10–20% of a reflectance a render shows mostly "
        "through its colour, and the presets take that colour from the measurement (the film "
        "stacked on itself reproduces each product's reflectance), not from the lobe's shape. "
        "The limits are written here with their numbers instead."),
}
"""Written observations per product and the conclusion, added below the generated tables
(they quote the tables' numbers: rewrite them if the fits change)."""


def write_all(data_dir, out_dir, products=None, presets_path=None) -> list[Path]:
    """Analyse ``products`` (default all of :data:`PRODUCTS`) and write ``<product>.csv``,
    ``<product>.png`` and ``README.md`` (with the derived presets) to ``out_dir``, and the
    presets' JSON to ``presets_path`` if given (the runtime reads
    :data:`~lut_baker.offline.foundation_presets.PRESET_FILE`); returns the paths written."""
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
    write_text(readme, report(analyses, NOTES, presets))
    paths.append(readme)
    if presets_path is not None:
        paths.append(write_presets(presets, presets_path))
    return paths
