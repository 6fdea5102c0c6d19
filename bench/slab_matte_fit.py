"""The matte products as a thick slab (a medium under a surface) instead of eq. 2: fit and
held-out errors, and whether the data determine the parameters (docs/model.md, "The matte
products as a slab under a surface"; docs/foundations/README.md).

    python bench/slab_matte_fit.py [--products NAME ...] [--forms FORM ...]
                                   [--grid PANELS POINTS N_PHI] [--starts K] [--held-starts]

For Clarins 103 and 108 (data/lanza2024, matte; eq. 2 fits them with P_d alone at 19.4% and
19.5% rms, 23.1% and 19.0% held out) this fits, by adding (lut_baker.offline.matte_slab), an
infinitely thick medium with a single-scattering albedo per channel in one of the forms

- ``slab``: spheres with a two-lobe Henyey-Greenstein phase function, no surface (6
  parameters: albedo RGB, g1, g2, weight);
- ``surface``: spheres with one HG lobe under a rough dielectric surface (GGX, index eta,
  roughness alpha; 6 parameters);
- ``flakes_surface``: the same medium with specular flakes (GGX normals, a fraction of the
  extinction and a roughness) mixed in, under the surface (8 parameters);
- ``cone``: spheres with one HG lobe and specular flakes whose normals lie on a cone
  (lut_baker.offline.matte_slab.cone_distribution: a Gaussian in the polar angle about the
  cone angle, uniform in azimuth; Lanza et al. 2024's tilted platelets), no surface (7
  parameters: albedo RGB, g, flakes, cone, spread);
- ``cone_flakes``: flakes on a cone alone, no spheres and no surface (5 parameters: albedo
  RGB, cone, spread);
- ``cone_tinted``: ``cone`` with the flakes' own albedo RGB (10 parameters), as Lanza et al.
  give their flakes and their spheres each an albedo (the spheres' at most 0.995);
- ``cone_slab``: spheres with two HG lobes and the flakes on a cone (9 parameters);
- ``cone_surface``: ``cone`` under the rough dielectric surface (9 parameters: eta, alpha
  added); ``cone_surface_15`` the same with eta held at a binder's 1.5 (8 parameters);
- ``cone_partial_15``: ``cone_surface_15`` with the surface over a fraction of the area (the
  coverage), the bare medium elsewhere (9 parameters: a powder whose particles the binder does
  not all wet);
- ``cone_patches_15``: ``cone_partial_15`` with two kinds of surface patch, each its
  roughness and coverage (11 parameters: a heavier-tailed gloss than one GGX lobe);
- ``cone_top``: ``cone`` under a top layer of the same particles absorbing differently (9
  parameters: its thickness and its absorption relative to the medium's, 0.01-100 and
  0.02-50);
- ``cone_finite``: ``cone`` of a finite optical thickness over a black base (8 parameters: the
  thickness, 0.1-200 units of extinction; Lanza et al.'s layer over a black base, its
  thickness free);
- ``cone_flat``: ``cone`` with a share of the flakes lying flat (normals about the vertical,
  their own spread; 9 parameters: Lanza et al.'s 103 has its flakes near the vertical),

read in the plane of incidence by a bicubic spline over the grid's polar nodes (the surface's
own reflection in closed form). Physical bounds: |g| <= 0.95, 1.01 <= eta <= 2, 0.05 <= alpha
<= 1, 0.2 <= flake alpha <= 1, 0 <= cone <= 90 degrees, 5 <= spread <= 60 degrees (a narrower
cone is finer than the default grid resolves), a surface's coverage 3e-4 from 0 and 1 (logits
within 8). It prints the relative error (model/measured -
1) on every incidence and, fitted on alternate incidences, on the others (as
lut_baker/offline/foundations.py does for eq. 2; that fit starts from the optimum on every
incidence, and ``--held-starts`` also starts it from the form's own starts); then the check
that the fit is determined by its data: refitted from its optimum to the measurements moved by
1e-9 (relative, random signs), the largest change of a parameter to first order (< 1e-6 passes;
:func:`data_response`) and whether a parameter sits at its bound (then it is not determined
either). About 1-6 minutes per product and form on one core at the default grid.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.interpolate import RectBivariateSpline
from scipy.optimize import least_squares

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lut_baker.numerics.quadrature import hemisphere_panels  # noqa: E402
from lut_baker.offline.foundations import PRODUCTS  # noqa: E402
from lut_baker.offline.matte_slab import MatteSlab, ggx_reflection, matte_slab_kernel  # noqa: E402
from lut_baker.offline.measured.inplane import read_inplane  # noqa: E402
from lut_baker.offline.measured.inplane_fit import (  # noqa: E402
    alternate_incidences,
    relative_error,
)

DATA = ROOT / "data" / "lanza2024"
G_MAX = 0.95
"""|g| of a Henyey-Greenstein lobe stays below this (a sharper lobe needs more orders)."""
PERTURBATION = 1e-9
DETERMINED = 1e-6

# Per form: parameter names after the three albedos, their lower and upper bounds in the
# fitted (unbounded-style) coordinates, and the starts.
LOG_ETA = (np.log(0.01), np.log(1.0))
LOG_ALPHA = (np.log(0.05), 0.0)
LOG_FLAKE_ALPHA = (np.log(0.2), 0.0)
SPREAD_DEG = (5.0, 60.0)
"""The cone's spread (degrees): at 5 the default grid departs from one of 8 x 8 nodes and 257
azimuths by 1.8% at most on the measured geometries (flakes at 67 degrees), and more below."""
LOG_SPREAD = (np.log(SPREAD_DEG[0]), np.log(SPREAD_DEG[1]))
LOGIT = (-8.0, 8.0)
FORMS = {
    "slab": (("g1", "g2", "weight"), ((-4.0, 4.0), (-4.0, 4.0), (-8.0, 8.0)),
             ((-0.3, 1.2, 0.0), (0.5, -0.5, 0.0))),
    "surface": (("g", "eta", "alpha"), ((-4.0, 4.0), LOG_ETA, LOG_ALPHA),
                ((-0.3, np.log(0.4), np.log(0.3)), (0.5, np.log(0.2), np.log(0.6)))),
    "flakes_surface": (("g", "flakes", "flake_alpha", "eta", "alpha"),
                       ((-4.0, 4.0), (-8.0, 8.0), LOG_FLAKE_ALPHA, LOG_ETA, LOG_ALPHA),
                       ((-0.3, 0.0, np.log(0.4), np.log(0.4), np.log(0.3)),
                        (0.3, 1.0, np.log(0.25), np.log(0.2), np.log(0.6)))),
    "cone": (("g", "flakes", "cone", "spread"), ((-4.0, 4.0), LOGIT, LOGIT, LOG_SPREAD),
             ((-0.2, 1.0, 0.3, np.log(20.0)), (0.3, 0.0, -1.0, np.log(30.0)))),
    "cone_flakes": (("cone", "spread"), (LOGIT, LOG_SPREAD),
                    ((0.3, np.log(20.0)), (-1.0, np.log(30.0)))),
    "cone_tinted": (("g", "flakes", "cone", "spread", "flake_r", "flake_g", "flake_b"),
                    ((-4.0, 4.0), LOGIT, LOGIT, LOG_SPREAD) + ((-12.0, 12.0),) * 3,
                    ((-0.2, 1.0, 0.3, np.log(20.0), 3.0, 2.0, 1.0),
                     (0.3, 0.0, -1.0, np.log(30.0), 3.0, 2.0, 1.0))),
    "cone_slab": (("g1", "g2", "weight", "flakes", "cone", "spread"),
                  ((-4.0, 4.0), (-4.0, 4.0), LOGIT, LOGIT, LOGIT, LOG_SPREAD),
                  ((-0.3, 1.2, 0.0, 1.0, 0.3, np.log(20.0)),
                   (0.5, -0.5, 0.0, 0.0, -1.0, np.log(30.0)))),
    "cone_surface": (("g", "flakes", "cone", "spread", "eta", "alpha"),
                     ((-4.0, 4.0), LOGIT, LOGIT, LOG_SPREAD, LOG_ETA, LOG_ALPHA),
                     ((-0.2, 1.0, 0.3, np.log(20.0), np.log(0.4), np.log(0.3)),
                      (0.3, 0.0, -1.0, np.log(30.0), np.log(0.2), np.log(0.6)))),
    "cone_surface_15": (("g", "flakes", "cone", "spread", "alpha"),
                        ((-4.0, 4.0), LOGIT, LOGIT, LOG_SPREAD, LOG_ALPHA),
                        ((-0.2, 1.0, 0.3, np.log(20.0), np.log(0.3)),
                         (0.3, 0.0, -1.0, np.log(30.0), np.log(0.6)))),
    "cone_partial_15": (("g", "flakes", "cone", "spread", "alpha", "coverage"),
                        ((-4.0, 4.0), LOGIT, LOGIT, LOG_SPREAD, LOG_ALPHA, LOGIT),
                        ((-0.2, 1.0, 0.3, np.log(20.0), np.log(0.3), -1.0),
                         (0.3, 0.0, -1.0, np.log(30.0), np.log(0.6), 0.0))),
    "cone_patches_15": (("g", "flakes", "cone", "spread", "alpha", "coverage", "alpha2",
                         "coverage2"),
                        ((-4.0, 4.0), LOGIT, LOGIT, LOG_SPREAD, LOG_ALPHA, LOGIT, LOG_ALPHA,
                         LOGIT),
                        ((-0.2, 1.0, 0.3, np.log(20.0), np.log(0.15), -3.0, np.log(0.6), 0.0),
                         (0.3, 0.0, -1.0, np.log(30.0), np.log(0.2), -1.0, np.log(0.8), 0.0))),
    "cone_top": (("g", "flakes", "cone", "spread", "top_thickness", "top_absorption"),
                 ((-4.0, 4.0), LOGIT, LOGIT, LOG_SPREAD, (np.log(0.01), np.log(100.0)),
                  (np.log(0.02), np.log(50.0))),
                 ((-0.2, 1.0, 0.3, np.log(20.0), 0.0, np.log(0.3)),
                  (0.3, 0.0, -1.0, np.log(30.0), np.log(3.0), np.log(3.0)))),
    "cone_finite": (("g", "flakes", "cone", "spread", "thickness"),
                    ((-4.0, 4.0), LOGIT, LOGIT, LOG_SPREAD, (np.log(0.1), np.log(200.0))),
                    ((-0.2, 1.0, 0.3, np.log(20.0), np.log(3.0)),
                     (0.3, 0.0, -1.0, np.log(30.0), np.log(20.0)))),
    "cone_flat": (("g", "flakes", "cone", "spread", "flat", "flat_spread"),
                  ((-4.0, 4.0), LOGIT, LOGIT, LOG_SPREAD, LOGIT, LOG_SPREAD),
                  ((-0.2, 1.0, 0.3, np.log(20.0), -1.0, np.log(15.0)),
                   (0.3, 0.0, -1.0, np.log(30.0), 0.0, np.log(30.0)))),
}
CONE_FORMS = ("cone", "cone_flakes", "cone_tinted", "cone_slab", "cone_surface",
              "cone_surface_15", "cone_partial_15", "cone_patches_15", "cone_flat",
              "cone_top", "cone_finite")
BINDER_ETA = 1.5
"""The surface's index in ``cone_surface_15``: a binder's (oils, silicones: about 1.4-1.5)."""
ALBEDO_LOGIT_MAX = {"cone_tinted": float(np.log(0.995 / 0.005))}
"""The spheres' albedo stays below 0.995 where the flakes carry their own: the kernels gain
energy above about 0.997 (docs/model.md)."""


def _sigmoid(x):
    return 1.0 / (1.0 + np.exp(-x))


def unpack(form: str, p) -> MatteSlab:
    """The model of the fitted coordinates ``p`` (albedos as logits, g as ``0.95 tanh``,
    weights as logits, the cone angle as ``90`` times a logistic, eta - 1, roughnesses and the
    cone's spread as logarithms)."""
    kw: dict = {"albedo": _sigmoid(p[:3])}
    if form in ("slab", "cone_slab"):
        kw.update(g1=G_MAX * np.tanh(p[3]), g2=G_MAX * np.tanh(p[4]), weight=_sigmoid(p[5]))
    elif form != "cone_flakes":
        kw.update(g1=G_MAX * np.tanh(p[3]))
    if form in ("surface", "flakes_surface", "cone_surface"):
        kw.update(eta=1.0 + np.exp(p[-2]), alpha=np.exp(p[-1]))
    elif form == "cone_surface_15":
        kw.update(eta=BINDER_ETA, alpha=np.exp(p[-1]))
    elif form == "cone_partial_15":
        kw.update(eta=BINDER_ETA, alpha=np.exp(p[-2]), coverage=_sigmoid(p[-1]))
    elif form == "cone_patches_15":
        # Both kinds share the coverage _sigmoid(p[8]), split by _sigmoid(p[10]).
        total, split = _sigmoid(p[8]), _sigmoid(p[10])
        kw.update(eta=BINDER_ETA, alpha=np.exp(p[7]), coverage=total * split,
                  alpha2=np.exp(p[9]), coverage2=total * (1.0 - split))
    if form == "flakes_surface":
        kw.update(flakes=_sigmoid(p[4]), flake_alpha=np.exp(p[5]))
    if form == "cone_flakes":
        kw.update(flakes=1.0, cone_deg=90.0 * _sigmoid(p[3]), cone_spread_deg=np.exp(p[4]))
    elif form in CONE_FORMS:
        first = 6 if form == "cone_slab" else 4
        kw.update(flakes=_sigmoid(p[first]), cone_deg=90.0 * _sigmoid(p[first + 1]),
                  cone_spread_deg=np.exp(p[first + 2]))
    if form == "cone_top":
        kw.update(top_thickness=np.exp(p[7]), top_absorption=np.exp(p[8]))
    if form == "cone_finite":
        kw.update(thickness=np.exp(p[7]))
    if form == "cone_flat":
        kw.update(flat=_sigmoid(p[7]), flat_spread_deg=np.exp(p[8]))
    if form == "cone_tinted":
        kw.update(flake_albedo=_sigmoid(p[7:10]))
    return MatteSlab(**kw)


def physical(form: str, p) -> np.ndarray:
    """The fitted model's parameters as numbers (albedo RGB, then the form's own)."""
    m = unpack(form, p)
    tint = m.flake_albedo if m.flake_albedo is not None else np.full(3, np.nan)
    values = {"g1": m.g1, "g2": m.g2, "weight": m.weight, "g": m.g1, "eta": m.eta,
              "alpha": m.alpha, "flakes": m.flakes, "flake_alpha": m.flake_alpha,
              "cone": m.cone_deg, "spread": m.cone_spread_deg, "flake_r": tint[0],
              "flake_g": tint[1], "flake_b": tint[2], "coverage": m.coverage,
              "flat": m.flat, "flat_spread": m.flat_spread_deg,
              "alpha2": m.alpha2, "coverage2": m.coverage2, "top_thickness": m.top_thickness,
              "top_absorption": m.top_absorption, "thickness": m.thickness}
    return np.array([*m.albedo, *(values[k] for k in FORMS[form][0])])


def in_plane(grid, model: MatteSlab, theta_i, theta_o) -> np.ndarray:
    """Reflectance factors ``pi f_r`` at ``theta_i`` and signed ``theta_o`` (degrees; > 0 the
    mirror side), ``(rows, 3)``: the medium's light by a spline over the nodes, the surface's
    gloss in closed form."""
    kernel, _ = matte_slab_kernel(grid, model)
    deg = np.degrees(grid.theta)
    orders = np.arange(kernel.shape[1])
    out = np.empty((theta_i.size, kernel.shape[0]))
    for c in range(kernel.shape[0]):
        sides = [RectBivariateSpline(deg, deg, np.einsum("mab,m->ab", kernel[c],
                                                         np.cos(orders * phi)))
                 .ev(theta_i, np.abs(theta_o)) for phi in (np.pi, 0.0)]
        out[:, c] = np.pi * np.where(theta_o >= 0.0, sides[0], sides[1])
    if model.eta > 1.0:
        for alpha, coverage in model.surface_patches():
            out += np.pi * coverage * ggx_reflection(
                np.cos(np.radians(theta_i)), np.cos(np.radians(np.abs(theta_o))),
                np.where(theta_o >= 0.0, -1.0, 1.0), alpha, model.eta)[:, None]
    return out


def fit(grid, form, theta_i, theta_o, rgb, start, *, tight=False):
    """Least squares of the relative residuals from ``start``, within the form's bounds."""
    lower = np.array([-12.0] * 3 + [b[0] for b in FORMS[form][1]])
    upper = np.array([ALBEDO_LOGIT_MAX.get(form, 12.0)] * 3 + [b[1] for b in FORMS[form][1]])

    def residual(p):
        return (in_plane(grid, unpack(form, p), theta_i, theta_o) / rgb - 1.0).ravel()

    tol = 1e-15 if tight else 1e-8
    result = least_squares(residual, np.clip(start, lower + 1e-9, upper - 1e-9),
                           bounds=(lower, upper), diff_step=1e-7 if tight else 1e-5,
                           xtol=tol, ftol=tol, gtol=tol, max_nfev=400 if tight else 150)
    at_bound = (result.x - lower < 1e-6) | (upper - result.x < 1e-6)
    return result.x, at_bound


def data_response(grid, form, theta_i, theta_o, rgb, p, seed: int = 0):
    """``(change, condition)``: how far the fitted parameters move (largest absolute change of
    :func:`physical`) when the measurements move by ``PERTURBATION`` (relative, random signs),
    by the fit's linear response at its optimum ``p`` (the Gauss-Newton step
    ``-(J^T J)^-1 J^T dr`` with ``J`` by central differences; an exact refit moves by this to
    first order), and the condition number of ``J``."""
    def residual(q, data):
        return (in_plane(grid, unpack(form, q), theta_i, theta_o) / data - 1.0).ravel()

    step = 1e-5
    jac = np.stack([(residual(p + step * e, rgb) - residual(p - step * e, rgb)) / (2.0 * step)
                    for e in np.eye(p.size)], axis=1)
    noise = np.random.default_rng(seed).uniform(-1.0, 1.0, rgb.shape)
    moved = rgb * (1.0 + PERTURBATION * noise)
    dr = residual(p, moved) - residual(p, rgb)
    dp = np.linalg.lstsq(jac, -dr, rcond=None)[0]
    change = float(np.max(np.abs(physical(form, p + dp) - physical(form, p))))
    return change, float(np.linalg.cond(jac))


def _held_from_starts(grid, form, data, rows, starts: int) -> None:
    """Print the fit on the alternate incidences ``rows`` started from the form's own starts
    (not from the optimum on every incidence): its rms on the fitted rows and on the others."""
    ti, to, rgb = data
    for k, start in enumerate(FORMS[form][2][:starts]):
        q, _ = fit(grid, form, ti[rows], to[rows], rgb[rows], np.array([3.0, 2.0, 1.0, *start]))
        q, _ = fit(grid, form, ti[rows], to[rows], rgb[rows], q, tight=True)
        model = unpack(form, q)
        on = relative_error(in_plane(grid, model, ti[rows], to[rows]), rgb[rows])[0]
        off = relative_error(in_plane(grid, model, ti[~rows], to[~rows]), rgb[~rows])[0]
        values = ", ".join(f"{v:.4f}" for v in physical(form, q))
        print(f"  held-out fit from start {k}: {100 * on:.2f}% on the fitted incidences, "
              f"predicting {100 * off:.2f}% ({values})", flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--products", nargs="+", default=["clarins_103", "clarins_108"])
    parser.add_argument("--forms", nargs="+", default=list(FORMS), choices=list(FORMS))
    parser.add_argument("--grid", type=int, nargs=3, default=(4, 8, 65),
                        metavar=("PANELS", "POINTS", "N_PHI"))
    parser.add_argument("--starts", type=int, default=2)
    parser.add_argument("--held-starts", action="store_true",
                        help="also fit the alternate incidences from the form's own starts")
    args = parser.parse_args(argv)
    grid = hemisphere_panels(*args.grid)
    np.seterr(all="ignore")
    for name in args.products:
        data = read_inplane(DATA / PRODUCTS[name][0])
        ti, to, rgb = data.theta_i_deg, data.theta_o_deg, data.rgb
        fitted, held = alternate_incidences(data.incidences_deg)
        for form in args.forms:
            clock = time.perf_counter()
            best = None
            for start in FORMS[form][2][:args.starts]:
                p, _ = fit(grid, form, ti, to, rgb, np.array([3.0, 2.0, 1.0, *start]))
                err = relative_error(in_plane(grid, unpack(form, p), ti, to), rgb)
                if best is None or err[0] < best[0][0]:
                    best = (err, p)
            assert best is not None
            p, at_bound = fit(grid, form, ti, to, rgb, best[1], tight=True)
            rms, worst = relative_error(in_plane(grid, unpack(form, p), ti, to), rgb)
            change, condition = data_response(grid, form, ti, to, rgb, p)
            rows = np.isin(ti, fitted)
            q, _ = fit(grid, form, ti[rows], to[rows], rgb[rows], p)
            out = ~rows
            held_rms, held_worst = relative_error(
                in_plane(grid, unpack(form, q), ti[out], to[out]), rgb[out])
            names = ("albedo_r", "albedo_g", "albedo_b", *FORMS[form][0])
            bound = [n for n, b in zip(names, at_bound, strict=True) if b]
            print(f"{name} {form}: fit {100 * rms:.1f}% rms, {100 * worst:.1f}% worst; fitted on "
                  f"{fitted} predicting {held}: {100 * held_rms:.2f}% rms, "
                  f"{100 * held_worst:.1f}% worst ({time.perf_counter() - clock:.0f} s)")
            values = physical(form, p)
            print("  " + ", ".join(f"{n} {v:.4f}" for n, v in zip(names, values, strict=True)))
            if args.held_starts:
                on = relative_error(in_plane(grid, unpack(form, q), ti[rows], to[rows]),
                                    rgb[rows])[0]
                print(f"  held-out fit from the optimum on every incidence: {100 * on:.2f}% on "
                      f"the fitted incidences, predicting {100 * held_rms:.2f}%")
                _held_from_starts(grid, form, (ti, to, rgb), rows, args.starts)
            verdict = "determined" if change < DETERMINED and not bound else "NOT determined"
            print(f"  data x (1 + {PERTURBATION:g} u): parameters move by {change:.2e} (condition "
                  f"{condition:.1e}); at a bound: "
                  f"{', '.join(bound) or 'none'} -> {verdict}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
