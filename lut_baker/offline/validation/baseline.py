"""The baseline a user would otherwise use: one stock Principled BSDF, fitted to the model.

The add-on's tiers are measured against a stock Principled BSDF with coat and subsurface,
its parameters fitted to the same model as well as it allows (docs/speed_accuracy.md).  The fit here
is the strongest such baseline this project can make without rendering: its sockets are chosen by
least squares on the images that matter, the sphere under one distant light at 0, 45 and 75 degrees
from the view, each pixel ``E f cos(theta_i)`` of the Principled BSDF's replica
(:func:`lut_baker.closures.cycles.principled_reflection`) against paths 1 + 3 read from the
baked tables (:func:`lut_baker.offline.validation.compare.local_image`, no spread on either side:
the subsurface radius is fitted separately, to the profile, as for the tiers); tables holding the
film as a slab give the slab's made-up skin instead, as they do to the tiers.

Free sockets: Base Color (RGB), Roughness, Specular IOR Level, Coat Weight, Coat Roughness and
Coat IOR, within the ranges Blender's sockets allow; IOR stays at the tiers' 1.5 (Specular IOR
Level scales its F0).  The start is the PRINCIPLED tier's own table-space fit
(:func:`lut_baker.closures.tiers.principled_inputs`), so the baseline is never worse than that
tier on this measure; Subsurface Weight, Radius, IOR and method are the tier's (its radius is
fitted to the dipole's profile, the method chosen by that fit).  The baseline differs from the
PRINCIPLED tier in what it is: constants typed into one node for one coverage and absorption,
where the tier computes them from the panel's sliders (and the painted coverage) in a group.

- :class:`Baseline` -- the fitted sockets and their errors; :meth:`Baseline.socket_values`.
- :func:`fit_baseline` -- the fit.
- :func:`principled_image` -- a Principled BSDF's local sphere image (the fit's model).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares

from ...closures import cycles as cc
from ...closures import fitting, tiers
from ...closures.closure_fit import ClosureFit
from ...model.made_up_skin import MadeUpSkin
from ...numerics.geometry import sphere_directions
from ...tables.table_set import Tables
from .compare import local_image

__all__ = ["LIGHTS_DEG", "FIT_RESOLUTION", "MAX_EVALUATIONS", "Baseline", "principled_image",
           "fit_baseline"]

LIGHTS_DEG = (0.0, 45.0, 75.0)
"""Light angles (degrees from the view) whose sphere images the fit matches: the chart's."""
FIT_RESOLUTION = 32
"""Pixels across the sphere in the fit's images (~800 lit pixels each)."""
MAX_EVALUATIONS = 100
"""Cap on the least-squares evaluations (each step adds a finite-difference Jacobian, 8 more
replica calls of ~40 ms).  The paper preset converges (ftol 1e-4) after 54 in 18 s; capped at
10 it gets within 1.6e-3 of that error in 3.4 s (measured)."""

_NAMES = ("base_r", "base_g", "base_b", "roughness", "specular_ior_level", "coat_weight",
          "coat_roughness", "coat_ior")
_LOWER = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
_UPPER = np.array([1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 4.0])
"""Blender's socket ranges (Coat IOR 1-4; the others 0-1)."""


@dataclass(frozen=True)
class Baseline:
    """A stock Principled BSDF's sockets: ``inputs`` (the BSDF part), the subsurface sockets
    (``subsurface_radius_mm`` is Radius x Scale in mm; the caller sets Scale to scene units per
    mm), and the fit's relative RMS image error per light angle (degrees) at its start (the
    PRINCIPLED tier's values) and its end."""

    inputs: cc.PrincipledInputs
    subsurface_weight: float
    subsurface_method: str
    subsurface_radius_mm: tuple
    subsurface_ior: float
    start_error: dict
    error: dict
    evaluations: int = 0

    def socket_values(self) -> dict:
        """Socket name -> value for a Principled BSDF (``Subsurface Scale`` left to the
        caller); the node's ``subsurface_method`` is :attr:`subsurface_method`."""
        p = self.inputs
        return {
            "Base Color": tuple(float(c) for c in p.base_color),
            "Roughness": float(p.roughness),
            "IOR": float(p.ior),
            "Specular IOR Level": float(p.specular_ior_level),
            "Coat Weight": float(p.coat_weight),
            "Coat Roughness": float(p.coat_roughness),
            "Coat IOR": float(p.coat_ior),
            "Subsurface Weight": float(self.subsurface_weight),
            "Subsurface Radius": tuple(float(r) for r in self.subsurface_radius_mm),
            "Subsurface IOR": float(self.subsurface_ior),
        }


def principled_image(inputs: cc.PrincipledInputs, resolution: int, light_angle_deg: float,
                     irradiance: float = 1.0) -> np.ndarray:
    """The local sphere image ``(n, n, 3)`` of a Principled BSDF with ``inputs`` (subsurface
    counted as its albedo, not spread)."""
    return local_image(lambda wi, wo: cc.principled_reflection(wi, wo, inputs), resolution,
                       light_angle_deg, irradiance)


def _vector(inputs: cc.PrincipledInputs) -> np.ndarray:
    return np.clip(np.array([*inputs.base_color, inputs.roughness, inputs.specular_ior_level,
                             inputs.coat_weight, inputs.coat_roughness, inputs.coat_ior],
                            float), _LOWER, _UPPER)


def _inputs(x: np.ndarray, start: cc.PrincipledInputs) -> cc.PrincipledInputs:
    return replace(start, base_color=tuple(x[:3]), roughness=x[3], specular_ior_level=x[4],
                   coat_weight=x[5], coat_roughness=x[6], coat_ior=x[7])


def fit_baseline(skin: MadeUpSkin, tables: Tables, fit: ClosureFit | None = None, *,
                 lights_deg=LIGHTS_DEG, resolution: int = FIT_RESOLUTION,
                 max_evaluations: int = MAX_EVALUATIONS) -> Baseline:
    """Fit a stock Principled BSDF to ``tables`` (baked from ``skin``) at the skin's coverage
    and absorption: least squares over the lit pixels of every light's image, each image's
    residual relative to its own RMS (so each light counts alike).  The images are those the
    tiers are measured against (:func:`lut_baker.closures.tiers.reference_reflection`): with
    the film as a slab, the slab's made-up skin at the fit's thickness.  ``fit``: the tables'
    :class:`~lut_baker.closures.closure_fit.ClosureFit` (fitted here if not given).  A light whose
    image is black (e.g. from behind the sphere) raises ValueError naming it."""
    fit = fit or fitting.fit_closures(tables)
    start, weight = tiers.principled_inputs(fit, skin.coverage, skin.absorption)
    views = [sphere_directions(resolution, light) for light in lights_deg]
    wi = np.concatenate([v[1] for v in views])
    wo = np.concatenate([v[2] for v in views])
    ref = wi[:, 2:3] * tiers.reference_reflection(fit, tables, skin.coverage, skin.absorption,
                                                  (wi, wo))
    # Each light's residuals divided by its RMS and the root of its count: each image counts
    # as its relative mean square error.
    bounds = np.cumsum([0] + [len(v[1]) for v in views])
    scale = np.empty(len(wi))
    for light, a, b in zip(lights_deg, bounds[:-1], bounds[1:], strict=True):
        level = np.sqrt(np.mean(ref[a:b] ** 2)) if b > a else 0.0
        if not level > 0.0:
            raise ValueError(f"the model's sphere image at light {light} degrees is black (no "
                             "lit pixel or no light reflected): nothing to fit there")
        scale[a:b] = 1.0 / (level * np.sqrt(3 * (b - a)))

    def radiance(inputs):
        return wi[:, 2:3] * cc.principled_reflection(wi, wo, inputs)

    def residuals(x):
        return ((radiance(_inputs(x, start)) - ref) * scale[:, None]).ravel()

    x0 = _vector(start)
    solution = least_squares(residuals, x0, bounds=(_LOWER, _UPPER), x_scale=_UPPER - _LOWER,
                             diff_step=1e-3, ftol=1e-4, xtol=1e-4, max_nfev=max_evaluations)
    x = solution.x if solution.cost <= 0.5 * np.sum(residuals(x0) ** 2) else x0

    def errors(inputs):
        lit = radiance(inputs)
        return {float(light): float(np.sqrt(np.mean((lit[a:b] - ref[a:b]) ** 2))
                                    / np.sqrt(np.mean(ref[a:b] ** 2)))
                for light, a, b in zip(lights_deg, bounds[:-1], bounds[1:], strict=True)}

    return Baseline(inputs=_inputs(x, start), subsurface_weight=weight,
                    subsurface_method=fit.subsurface_method,
                    subsurface_radius_mm=tuple(float(r) for r in fit.subsurface_radius_mm),
                    subsurface_ior=fit.subsurface_ior, start_error=errors(start),
                    error=errors(_inputs(x, start)), evaluations=int(solution.nfev))
