"""How close any tier built from one renderer's closures can come to the model: a lower bound.

A view-weighted tier (LAYERED, EEVEE) is a sum of closures whose weights depend on the view
angle only (an image read at ``cos(theta_o)``; Shader to RGB applying view-angle weights to a
lit result is the same family), never on the light.  The best such sum is found here without
any of the tiers' restrictions: at each view, every channel, the non-negative weights of a
dictionary of Glossy lobes (many roughnesses) and a Lambertian term that fit the tables' local
reflection (paths 1 + 3, eq. 9 at the coverage and absorption) best over all lights
(non-negative least squares on :class:`lut_baker.closures.view_grid.ViewGrid`'s measure).
No tier of those closures does better on that measure; rendered into the reference sphere's
local images (no spread), the bound says how far from the exact image the closures alone keep
any tier.

Non-negative: EEVEE drops a closure of negative colour (measured: a Glossy of colour -0.5 added
to another leaves its render unchanged), so no lobe can cancel another's tail there.

- :data:`ROUGHNESSES` -- the dictionary's roughnesses.
- :func:`dictionary` -- the lobes of EEVEE or of Cycles at directions.
- :class:`Bound`, :func:`closure_bound` -- the best weights and their error on the grid.
- :func:`bound_reflection` -- the bound's BRDF at any directions (for images).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import nnls

from ...closures import cycles as cc
from ...closures import eevee
from ...closures.view_grid import ViewGrid, lobe_widths_deg, view_grid
from ...tables.table_set import Tables

__all__ = ["ROUGHNESSES", "RENDERERS", "BOUND_VIEWS", "dictionary", "Bound", "closure_bound",
           "bound_reflection"]

ROUGHNESSES = tuple(float(r) for r in np.exp(np.linspace(np.log(0.03), np.log(1.0), 28)))
"""Roughnesses (Blender's) of the dictionary's Glossy lobes: 28, evenly in ``log``."""
RENDERERS = {"EEVEE": ("EEVEE_GGX",), "CYCLES": cc.GLOSSY_DISTRIBUTIONS}
"""The Glossy lobes each renderer draws: EEVEE's GGX as a linearly transformed cosine, Cycles'
three distributions."""
BOUND_VIEWS = 48
"""Views of the fitting grid; the weights are linear in ``cos(theta_o)`` between them."""


def dictionary(wi, wo, renderer: str) -> list[np.ndarray]:
    """The dictionary's white BRDFs at ``(wi, wo)`` ``(..., 3)`` each ``(...)``: every Glossy
    lobe of ``renderer`` (:data:`RENDERERS`) at every :data:`ROUGHNESSES`, then Lambert."""
    lobes = []
    for roughness in ROUGHNESSES:
        for distribution in RENDERERS[renderer]:
            if distribution == "EEVEE_GGX":
                lobes.append(eevee.glossy_reflection(wi, wo, roughness))
            else:
                lobes.append(cc.microfacet_reflection(wi, wo, roughness,
                                                      distribution=distribution))
    lobes.append(np.full(np.shape(wi)[:-1], 1.0 / np.pi))
    return lobes


@dataclass(frozen=True)
class Bound:
    """The best view-weighted sum of a renderer's closures: ``weights`` ``(views, lobes, 3)``
    at the grid's views ``cos_view``, ``renderer``, ``error`` (relative RMS of ``f cos(theta_i)``
    on the grid, :meth:`lut_baker.closures.view_grid.ViewGrid.error`)."""

    renderer: str
    cos_view: np.ndarray
    weights: np.ndarray
    error: float


def closure_bound(tables: Tables, coverage: float, absorption, renderer: str, *,
                  views: int = BOUND_VIEWS) -> Bound:
    """The :class:`Bound` of ``renderer``'s closures for ``tables``' local reflection at
    ``coverage`` and ``absorption`` (module docstring), on a grid resolving the narrower of the
    film's and the skin's gloss."""
    grid: ViewGrid = view_grid(min(lobe_widths_deg(tables).values()), views)
    wi, wo = grid.directions
    target = np.asarray(tables.made_up_reflection(wi, wo, coverage, absorption), float)
    lobes = [np.broadcast_to(lobe, grid.cos_i.shape) for lobe in dictionary(wi, wo, renderer)]
    root = np.sqrt(grid.weight) * grid.cos_i
    weights = np.zeros((views, len(lobes), 3))
    for v in range(views):
        system = np.stack([(lobe[v] * root[v]).ravel() for lobe in lobes], -1)
        for c in range(3):
            weights[v, :, c] = nnls(system, (target[v, ..., c] * root[v]).ravel(),
                                    maxiter=50 * len(lobes))[0]
    fitted = np.einsum("kvap,vkc->vapc", np.stack(lobes), weights)
    return Bound(renderer, grid.cos_view.copy(), weights, grid.error(fitted, target))


def bound_reflection(bound: Bound):
    """The bound's BRDF ``reflection(wi, wo) -> (..., 3)``, its weights linear in
    ``cos(theta_o)`` between the grid's views (held beyond them)."""
    def reflection(wi, wo):
        cos_o = np.asarray(wo)[..., 2]
        value = 0.0
        for k, lobe in enumerate(dictionary(wi, wo, bound.renderer)):
            weight = np.stack([np.interp(cos_o, bound.cos_view, bound.weights[:, k, c])
                               for c in range(3)], -1)
            value = value + lobe[..., None] * weight
        return value

    return reflection
