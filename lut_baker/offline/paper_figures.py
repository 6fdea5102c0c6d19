"""The paper's figures, reproduced from the model (figs. 5, 7, 11, 13, 14, 15), plus a white-furnace
chart beyond the paper.

Each figure has a data function (numpy only: the curves, as plain arrays) and a drawing function
(matplotlib, imported lazily on first use, drawn on an Agg canvas without pyplot) that returns the
:class:`matplotlib.figure.Figure`.  Every drawn line carries a ``gid`` naming its entry in the data,
so tests can read the plotted numbers back.  Intensities are what the camera sees, ``f (N.L)``
(paper eqs. 1-4), with ``N.L`` the cosine of the incidence angle.

Data functions
--------------
- :func:`reflection_curves` -- paper eq. 2 along the reflection protocol (figs. 5, 11).
- :func:`transmission_curves` -- paper eq. 4 along the transmission protocol (fig. 7).
- :func:`profile_curve` -- dipole ``R(d) / R(0)`` (paper eq. 6, fig. 13).
- :func:`made_up_reflection_curves` -- paths 1, 3, their sum with coverage (eq. 9, fig. 14).
- :func:`made_up_profile_curves` -- bare (eq. 5) and made-up (eq. 8, docs/model.md §3) profiles
  (fig. 15).
- :func:`directional_albedo_curves` -- paths 1 + 3 integrated, per foundation (docs/model.md §4).

Drawing functions
-----------------
- :func:`fig05_film_reflection`, :func:`fig07_film_transmission`, :func:`fig11_skin_reflection`,
  :func:`fig13_skin_profile`, :func:`fig14_made_up_reflection`, :func:`fig15_made_up_profile`,
  :func:`fig16_directional_albedo`; :data:`FIGURES` maps file stems to them.
- :func:`render_all` -- write them all as ``figNN_<name>.png`` (150 dpi, 6 x 4 in).
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..evaluate.made_up import directional_albedo, made_up_reflection
from ..evaluate.two_layer import layered_reflection, transmission_factor
from ..model.dipole import dipole_profile
from ..model.layers import Dipole, ReflectionLayer, TransmissionLayer
from ..model.made_up_skin import MadeUpSkin, film_reflection_layer, film_transmission_layer
from ..model.microfacet import fresnel_reflectance, ts_reflection, ts_transmission
from ..model.presets import (
    FOUNDATIONS,
    PAPER_FILM_REFLECTION,
    PAPER_FILM_TRANSMISSION,
    PAPER_SKIN_DIPOLE,
    PAPER_SKIN_REFLECTION,
    made_up_skin,
    paper,
)
from .atomic_files import replacing
from .measured.protocols import (
    ReflectionSweep,
    in_plane_direction,
    profile_distances,
    reflection_geometry,
    reflection_sweep,
    transmission_geometry,
    transmission_sweep,
)

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType

__all__ = [
    "DPI",
    "GREY",
    "styled_figure",
    "sequence_colours",
    "FIGSIZE_IN",
    "RELATIVE_ANGLES_DEG",
    "INCIDENCES_DEG",
    "reflection_curves",
    "transmission_curves",
    "profile_curve",
    "made_up_reflection_curves",
    "made_up_profile_curves",
    "directional_albedo_curves",
    "fig05_film_reflection",
    "fig07_film_transmission",
    "fig11_skin_reflection",
    "fig13_skin_profile",
    "fig14_made_up_reflection",
    "fig15_made_up_profile",
    "fig16_directional_albedo",
    "FIGURES",
    "render_all",
]

DPI = 150
"""Resolution of the written PNGs (dots per inch)."""
FIGSIZE_IN = (6.0, 4.0)
"""Figure size (inches)."""
RELATIVE_ANGLES_DEG = (30.0, 60.0, 90.0, 120.0)
"""Light-camera relative angles of the reflection experiments (4.1.1, 4.2.1), degrees."""
INCIDENCES_DEG = (0.0, 30.0, 60.0)
"""Incidence angles of the transmission experiment (4.1.2), degrees."""
CHANNEL = 0
"""The channel drawn where a layer is RGB: red, the only one the paper measured (docs/model.md
§1)."""
ALBEDO_ANGLES_DEG = np.append(np.arange(0.0, 89.0, 2.0), 89.0)
"""Incidence angles (degrees) of the white-furnace chart: every 2 degrees, and 89."""
CURVE_STEP_DEG = 0.25
"""Angular step (degrees) of the model curves between the protocol's samples."""
MADE_UP_STEP_DEG = 1.0
"""The same for fig. 14, whose path 3 costs a quadrature per point (and is smooth)."""

_STYLE: dict[RcKeyType, Any] = {
    "font.size": 9,
    "axes.titlesize": 9.5,
    "axes.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.6,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.fontsize": 8,
    "legend.frameon": False,
    "lines.linewidth": 1.6,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
}
# Paper colours for figs. 14 and 15 (5.1, 5.2): film surface green, through the film blue,
# their sum (the proposed model) light blue; the skin-only model of fig. 15 green.
_GREEN, _BLUE, _LIGHT_BLUE, GREY = "#2ca02c", "#1f5fbf", "#17b3e6", "#7f7f7f"


# --------------------------------------------------------------------------------------------
# Data
# --------------------------------------------------------------------------------------------
def _red(values) -> np.ndarray:
    """One channel of a per-sample result: ``(P, 3)`` -> ``(P,)``; ``(P,)`` stays."""
    values = np.asarray(values, dtype=float)
    return values[..., CHANNEL] if values.ndim == 2 else values


def _densified(samples_deg: np.ndarray, step_deg: float = CURVE_STEP_DEG) -> np.ndarray:
    """The protocol's sample angles plus a ``step_deg`` grid over their range, so the model
    curves are smooth and still pass through every sample the paper measured at."""
    grid = np.arange(samples_deg.min(), samples_deg.max(), step_deg)
    return np.union1d(samples_deg, grid)


def _dense_reflection(relative_angle_deg: float,
                      step_deg: float = CURVE_STEP_DEG) -> ReflectionSweep:
    """The reflection protocol at relative angle psi with its samples of alpha densified."""
    alpha = _densified(reflection_sweep(relative_angle_deg).alpha_deg, step_deg)
    return reflection_geometry(relative_angle_deg, alpha)


def reflection_curves(layer: ReflectionLayer = PAPER_FILM_REFLECTION,
                      relative_angles_deg=RELATIVE_ANGLES_DEG) -> dict:
    """Paper eq. 2 in the reflection protocol (docs/model.md §6): per relative angle psi (degrees) a
    dict of ``theta_r_deg``, ``theta_i_deg = theta_r_deg + psi`` (signed, degrees), ``brdf`` ``f_r``
    and ``intensity`` ``f_r cos(theta_i)`` (units of ``layer``: counts per 3 s for the paper),
    at the protocol's samples (:func:`~lut_baker.offline.measured.protocols.reflection_sweep`)
    densified."""
    curves = {}
    for psi in relative_angles_deg:
        sweep = _dense_reflection(psi)
        brdf = _red(ts_reflection(sweep.wi, sweep.wo, layer))
        curves[float(psi)] = {
            "theta_r_deg": sweep.theta_r_deg,
            "theta_i_deg": sweep.theta_i_deg,
            "brdf": brdf,
            "intensity": brdf * sweep.wi[..., 2],
        }
    return curves


def transmission_curves(layer: TransmissionLayer = PAPER_FILM_TRANSMISSION,
                        incidences_deg=INCIDENCES_DEG) -> dict:
    """Paper eq. 4 in the transmission protocol (docs/model.md §6): per incidence (degrees) a dict
    of ``theta_t_deg`` (signed, from -z; straight through at theta_t = incidence), ``btdf``
    ``f_t`` and ``intensity`` ``f_t cos(theta_i)`` (counts per 10 s for the paper), at the
    protocol's samples (:func:`~lut_baker.offline.measured.protocols.transmission_sweep`)
    densified."""
    curves = {}
    for incidence in incidences_deg:
        theta_t = _densified(transmission_sweep(incidence).theta_t_deg)
        sweep = transmission_geometry(incidence, theta_t)
        btdf = _red(ts_transmission(sweep.wi, sweep.wt, layer))
        curves[float(incidence)] = {
            "theta_t_deg": theta_t,
            "btdf": btdf,
            "intensity": btdf * sweep.wi[..., 2],
        }
    return curves


def profile_curve(dipole: Dipole = PAPER_SKIN_DIPOLE, max_mm: float = 3.0,
                  step_mm: float = 0.01) -> dict:
    """The dipole profile as the paper plots it (eq. 6, 4.2.2): ``ratio = R(d) / R(0)``, the
    scattered intensity relative to the lit pixel, against ``d_mm`` (mm)."""
    d = profile_distances(max_mm, step_mm)
    return {"d_mm": d, "ratio": _red(dipole_profile(d, dipole)) / _red(dipole_profile(0.0, dipole))}


def made_up_reflection_curves(skin: MadeUpSkin | None = None, relative_angle_deg: float = 60.0,
                              coverages=(1.0, 0.5)) -> dict:
    """Made-up skin in the reflection protocol at one relative angle (paper 5.1, eq. 9), as
    intensities ``f cos(theta_i)`` in albedo units (1/sr, docs/model.md §4): ``path1`` (film
    surface), ``path3`` (through the film, off the skin surface, back through), ``bare`` (the skin
    alone) and ``sum`` {coverage: :func:`~lut_baker.evaluate.made_up.made_up_reflection` at that
    coverage}."""
    skin = paper() if skin is None else skin
    sweep = _dense_reflection(relative_angle_deg, MADE_UP_STEP_DEG)
    wi, wo, cosine = sweep.wi, sweep.wo, sweep.wi[..., 2]
    path1 = _red(ts_reflection(wi, wo, film_reflection_layer(skin)))
    path3 = _red(layered_reflection(wi, wo, film_transmission_layer(skin), skin.skin_reflection))
    bare = _red(ts_reflection(wi, wo, skin.skin_reflection))
    total = {float(w): _red(made_up_reflection(wi, wo, skin.replace(coverage=w)))
             for w in coverages}
    return {
        "relative_angle_deg": float(relative_angle_deg),
        "theta_r_deg": sweep.theta_r_deg,
        "path1": path1 * cosine,
        "path3": path3 * cosine,
        "bare": bare * cosine,
        "sum": {w: value * cosine for w, value in total.items()},
    }


def made_up_profile_curves(skin: MadeUpSkin | None = None, angle_deg: float = 30.0,
                           max_mm: float = 3.0, step_mm: float = 0.01) -> dict:
    """Path 4 at incidence = view = ``angle_deg`` in the specular geometry (paper 5.2):
    ``bare = (1/pi) F_t(wo) R(d) F_t(wi)`` (eq. 5) and ``made_up = R(d)/pi t(wi) t(wo)``
    (eq. 8, docs/model.md §3, ``t`` = :func:`~lut_baker.evaluate.two_layer.transmission_factor` of
    the absorbing film), both divided by ``bare`` at d = 0.  Also returns ``t`` and ``F_t`` at that
    angle."""
    skin = paper() if skin is None else skin
    wi = in_plane_direction(angle_deg)
    wo = in_plane_direction(-angle_deg)
    d = profile_distances(max_mm, step_mm)
    profile = _red(dipole_profile(d, skin.dipole)) / np.pi
    cosines = np.array([[wi[2]], [wo[2]]])  # (2, 1): broadcasts against a scalar or RGB eta
    fresnel_t = 1.0 - _red(fresnel_reflectance(cosines, skin.dipole.eta, check=True))
    t = _red(transmission_factor(np.stack([wi, wo]), film_transmission_layer(skin), skin.dipole))
    bare = profile * fresnel_t[0] * fresnel_t[1]
    made_up = profile * t[0] * t[1]
    scale = _red(dipole_profile(0.0, skin.dipole)) / np.pi * fresnel_t[0] * fresnel_t[1]
    return {
        "angle_deg": float(angle_deg),
        "d_mm": d,
        "bare": bare / scale,
        "made_up": made_up / scale,
        "t": float(t[0]),
        "F_t": float(fresnel_t[0]),
    }


def directional_albedo_curves(foundations=None, skin: str = "paper_bioplate",
                              theta_deg=None) -> dict:
    """Directional albedo of paths 1 + 3 (docs/model.md §4) against incidence ``theta_deg``
    (degrees) per foundation preset on ``skin``, RGB ``(P, 3)``; ``"bare"`` is the skin alone
    (coverage 0)."""
    names = tuple(FOUNDATIONS) if foundations is None else tuple(foundations)
    theta = ALBEDO_ANGLES_DEG if theta_deg is None else np.asarray(theta_deg, float)
    curves = {"theta_deg": theta}
    for name in names:
        curves[name] = directional_albedo(theta, made_up_skin(name, skin))
    curves["bare"] = directional_albedo(theta, made_up_skin(names[0], skin, coverage=0.0))
    return curves


# --------------------------------------------------------------------------------------------
# Drawing
# --------------------------------------------------------------------------------------------
_SYMBOLS = {"P_d": "$P_d$", "P_s": "$P_s$", "P_t": "$P_t$", "n": "$n$", "eta": r"$\eta$",
            "sigma_s": r"$\sigma_s$", "sigma_a": r"$\sigma_a$", "g": "$g$"}
_UNITS = {"n": "/deg", "sigma_s": "/mm", "sigma_a": "/mm"}


def _number(x: float) -> str:
    """``x`` to 3 significant digits, as ``a x 10^b`` (mathtext) outside [0.01, 1000)."""
    if x == 0 or 0.01 <= abs(x) < 1000:
        return f"{x:.3g}"
    exponent = int(np.floor(np.log10(abs(x))))
    return rf"${x / 10.0**exponent:.3g}\times10^{{{exponent}}}$"


def _parameter_text(layer) -> str:
    """The layer's fields (red channel) as one line, e.g. for a title or legend."""
    parts = []
    for name, value in layer.as_dict().items():
        value = value[CHANNEL] if isinstance(value, list) else value
        parts.append(f"{_SYMBOLS[name]} = {_number(value)}{_UNITS.get(name, '')}")
    return ", ".join(parts)


@contextmanager
def styled_figure(title: str, xlabel: str, ylabel: str):
    """A styled 6 x 4 in figure on an Agg canvas with one axes, built inside the style."""
    try:
        import matplotlib
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ModuleNotFoundError as error:
        raise ModuleNotFoundError(
            "lut_baker.offline.paper_figures needs matplotlib to draw (pip install matplotlib)"
        ) from error
    with matplotlib.rc_context(_STYLE):
        figure = Figure(figsize=FIGSIZE_IN, dpi=DPI, layout="constrained")
        FigureCanvasAgg(figure)
        axes = figure.add_subplot()
        axes.set_title(title)
        axes.set_xlabel(xlabel)
        axes.set_ylabel(ylabel)
        yield figure, axes


def sequence_colours(count: int):
    """``count`` colours along viridis, avoiding its pale yellow end."""
    from matplotlib import colormaps

    return colormaps["viridis"](np.linspace(0.05, 0.8, count))


def _reflection_figure(curves: dict, title: str) -> object:
    with styled_figure(title, r"reflection angle $\theta_r$ (degrees)",
                 r"intensity $f_r\,(N\cdot L)$ (counts, 3 s exposure)") as (figure, axes):
        for colour, (psi, curve) in zip(sequence_colours(len(curves)), curves.items(),
                                        strict=True):
            axes.plot(curve["theta_r_deg"], curve["intensity"], color=colour,
                      label=rf"$\psi$ = {psi:g}°", gid=f"psi={psi:g}")
            axes.axvline(-psi / 2.0, color=colour, linestyle=":", linewidth=0.9)
        axes.plot([], [], color=GREY, linestyle=":", linewidth=0.9,
                  label=r"mirror direction $\theta_r = -\psi/2$")
        axes.set_xlim(-90.0, 60.0)
        axes.set_ylim(bottom=0.0)
        axes.legend(title=r"light-camera angle $\psi$", loc="upper right")
    return figure


def fig05_film_reflection(layer: ReflectionLayer = PAPER_FILM_REFLECTION,
                          relative_angles_deg=RELATIVE_ANGLES_DEG):
    """Paper fig. 5: the foundation film's reflection (eq. 2, 4.1.1) against theta_r."""
    return _reflection_figure(reflection_curves(layer, relative_angles_deg),
                              "Fig. 5: foundation film, reflection (Torrance-Sparrow, eq. 2)\n"
                              + _parameter_text(layer))


def fig11_skin_reflection(layer: ReflectionLayer = PAPER_SKIN_REFLECTION,
                          relative_angles_deg=RELATIVE_ANGLES_DEG):
    """Paper fig. 11: the skin substitute's (bio-plate) reflection (eq. 2, 4.2.1)."""
    return _reflection_figure(reflection_curves(layer, relative_angles_deg),
                              "Fig. 11: skin (bio-plate), reflection (Torrance-Sparrow, eq. 2)\n"
                              + _parameter_text(layer))


def fig07_film_transmission(layer: TransmissionLayer = PAPER_FILM_TRANSMISSION,
                            incidences_deg=INCIDENCES_DEG):
    """Paper fig. 7: the film's transmission (eq. 4, 4.1.2) against theta_t."""
    curves = transmission_curves(layer, incidences_deg)
    with styled_figure("Fig. 7: foundation film, transmission (eq. 4)\n" + _parameter_text(layer),
                 r"transmission angle $\theta_t$ (degrees from $-N$)",
                 r"intensity $f_t\,(N\cdot L)$ (counts, 10 s exposure)") as (figure, axes):
        for colour, (incidence, curve) in zip(sequence_colours(len(curves)), curves.items(),
                                              strict=True):
            axes.plot(curve["theta_t_deg"], curve["intensity"], color=colour,
                      label=rf"$\theta_i$ = {incidence:g}°", gid=f"theta_i={incidence:g}")
            axes.axvline(incidence, color=colour, linestyle=":", linewidth=0.9)
        axes.plot([], [], color=GREY, linestyle=":", linewidth=0.9,
                  label=r"straight through $\theta_t = \theta_i$")
        axes.set_xlim(-90.0, 90.0)
        axes.set_ylim(bottom=0.0)
        axes.legend(title="incidence", loc="lower center", ncols=2)
    return figure


def fig13_skin_profile(dipole: Dipole = PAPER_SKIN_DIPOLE, max_mm: float = 3.0):
    """Paper fig. 13: the bio-plate's subsurface profile, ``R(d)/R(0)`` (eq. 6, 4.2.2)."""
    curve = profile_curve(dipole, max_mm)
    label = "dipole: " + _parameter_text(dipole)
    with styled_figure("Fig. 13: skin (bio-plate), subsurface scattering profile (dipole, eq. 6)",
                 "distance from the lit point $d$ (mm)",
                 r"$R(d)/R(0)$ (ratio to the lit pixel)") as (figure, axes):
        axes.plot(curve["d_mm"], curve["ratio"], color=_GREEN, label=label, gid="ratio")
        axes.set_xlim(0.0, max_mm)
        axes.set_ylim(0.0, 1.05)
        axes.legend(loc="upper right")
    return figure


def fig14_made_up_reflection(skin: MadeUpSkin | None = None, relative_angle_deg: float = 60.0,
                             coverages=(1.0, 0.5)):
    """Paper fig. 14: made-up skin at relative angle 60 degrees, paths 1, 3 and their sum
    (eq. 9, 5.1), with the coverage weight and the bare skin for reference."""
    curves = made_up_reflection_curves(skin, relative_angle_deg, coverages)
    theta = curves["theta_r_deg"]
    title = (f"Fig. 14: made-up skin, reflection at $\\psi$ = {relative_angle_deg:g}° (eq. 9)\n"
             "the paper weighted paths 1 and 3 by hand; here coverage $w$ mixes with bare skin")
    with styled_figure(title, r"reflection angle $\theta_r$ (degrees)",
                 r"intensity $f\,(N\cdot L)$ (albedo units, 1/sr)") as (figure, axes):
        axes.plot(theta, curves["bare"], color=GREY, linestyle=":",
                  label="bare skin (w = 0)", gid="bare")
        axes.plot(theta, curves["path1"], color=_GREEN, label="path 1: film surface",
                  gid="path1")
        axes.plot(theta, curves["path3"], color=_BLUE,
                  label="path 3: through film, skin surface, back", gid="path3")
        for style, (w, total) in zip(("-", "--", "-.", (0, (1, 1))), curves["sum"].items(),
                                     strict=False):
            axes.plot(theta, total, color=_LIGHT_BLUE, linestyle=style,
                      linewidth=2.2 if w == 1.0 else 1.6,
                      label=f"made-up skin, coverage w = {w:g}", gid=f"sum w={w:g}")
        axes.set_xlim(-90.0, 30.0)
        axes.set_ylim(bottom=0.0)
        axes.legend(loc="lower left", bbox_to_anchor=(0.0, 0.12))
    return figure


def fig15_made_up_profile(skin: MadeUpSkin | None = None, angle_deg: float = 30.0,
                          max_mm: float = 3.0):
    """Paper fig. 15: made-up versus bare skin subsurface profile at incidence = view =
    ``angle_deg`` (specular geometry, 5.2), both divided by the bare skin's value at d = 0."""
    curves = made_up_profile_curves(skin, angle_deg, max_mm)
    with styled_figure(f"Fig. 15: made-up vs bare skin, subsurface profile "
                 f"($\\theta_i = \\theta_r$ = {angle_deg:g}°)",
                 "distance from the lit point $d$ (mm)",
                 r"$S(d)\,/\,S_{\mathrm{bare}}(0)$ (log scale)") as (figure, axes):
        axes.semilogy(curves["d_mm"], curves["bare"], color=_GREEN,
                      label=r"bare skin: $\frac{1}{\pi}F_t(\omega_o)R(d)F_t(\omega_i)$ (eq. 5)",
                      gid="bare")
        axes.semilogy(curves["d_mm"], curves["made_up"], color=_LIGHT_BLUE,
                      label=r"made-up: $\frac{1}{\pi}R(d)\,t(\omega_i)\,t(\omega_o)$ (eq. 8)",
                      gid="made_up")
        ratio = (curves["t"] / curves["F_t"]) ** 2
        axes.text(0.97, 0.62, f"film: t({angle_deg:g}°) = {curves['t']:.3f},  "
                  f"$F_t$({angle_deg:g}°) = {curves['F_t']:.3f}\n"
                  f"made-up / bare = $(t/F_t)^2$ = {ratio:.3f} at every d",
                  transform=axes.transAxes, ha="right", va="top", fontsize=8)
        axes.set_xlim(0.0, max_mm)
        axes.legend(loc="upper right")
    return figure


def fig16_directional_albedo(foundations=None, skin: str = "paper_bioplate"):
    """Beyond the paper: the directional albedo of paths 1 + 3 (docs/model.md §4) per foundation
    preset on ``skin``, against incidence; a white furnace check (every curve <= 1)."""
    curves = directional_albedo_curves(foundations, skin)
    theta = curves["theta_deg"]
    names = [name for name in curves if name not in ("theta_deg", "bare")]
    channel_styles = (("R", "-"), ("G", "--"), ("B", ":"))
    with styled_figure("Beyond the paper: white furnace, directional albedo of paths 1 + 3",
                 r"incidence $\theta_i$ (degrees)",
                 r"directional albedo $\int f\,\cos\theta_o\,d\omega_o$ (1 = lossless)"
                 ) as (figure, axes):
        axes.axhline(1.0, color="black", linewidth=0.8)
        axes.plot(theta, curves["bare"][:, CHANNEL], color=GREY, linewidth=1.2,
                  label="bare bio-plate (w = 0)", gid="bare")
        for colour, name in zip(sequence_colours(len(names)), names, strict=True):
            for index, (channel, style) in enumerate(channel_styles):
                axes.plot(theta, curves[name][:, index], color=colour, linestyle=style,
                          label=FOUNDATIONS[name]["label"] if index == 0 else None,
                          gid=f"{name} {channel}")
        for channel, style in channel_styles:
            axes.plot([], [], color="black", linestyle=style, linewidth=1.0,
                      label=f"{channel} channel")
        axes.set_xlim(0.0, 90.0)
        axes.set_ylim(0.0, 1.1)
        axes.legend(loc="lower left", ncols=2)
    return figure


FIGURES: dict[str, Callable[[], Any]] = {
    "fig05_film_reflection": fig05_film_reflection,
    "fig07_film_transmission": fig07_film_transmission,
    "fig11_skin_reflection": fig11_skin_reflection,
    "fig13_skin_profile": fig13_skin_profile,
    "fig14_made_up_reflection": fig14_made_up_reflection,
    "fig15_made_up_profile": fig15_made_up_profile,
    "fig16_directional_albedo": fig16_directional_albedo,
}
"""File stem -> drawing function (called with its defaults: the paper's parameters)."""


def render_all(out_dir, names=None) -> list[Path]:
    """Draw the figures ``names`` (default all of :data:`FIGURES`) with their defaults and write
    them to ``out_dir`` as ``<name>.png`` (150 dpi); returns the paths written."""
    names = list(FIGURES) if names is None else list(names)
    unknown = [name for name in names if name not in FIGURES]
    if unknown:
        raise ValueError(f"unknown figure(s) {unknown}; choose from {list(FIGURES)}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name in names:
        path = out / f"{name}.png"
        # No software/version stamp: the committed PNGs change only when the pictures do.
        with replacing(path) as temporary:
            FIGURES[name]().savefig(temporary, dpi=DPI, metadata={"Software": None})
        paths.append(path)
    return paths
