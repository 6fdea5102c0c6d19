"""The direction pairs on which closures are fitted and tiers judged, for lobes of any width.

A Blender closure sees the view direction, not the light's, so the fits and the error measures
are organised by view: ``V`` view directions ``wo`` at the midpoints of ``cos(theta_o)`` in
``[0, 1]`` (the view-angle image's own texel centres when ``V`` is its size), and for each view
the light directions ``wi`` through their half vector around the mirror direction
(:func:`lut_baker.numerics.quadrature.mirror_quadrature`), in panels sized by the narrowest lobe
to resolve.  A 1-degree gloss and a 30-degree one cost the same number of pairs.

The measure is the one the fits have always used (docs/baking.md, "Errors"): the radiance
``L = f cos(theta_i)`` under a unit-irradiance light, lights uniform over the hemisphere
(``dw_i``) and views weighted by the area a sphere's image gives them (``cos(theta_o) dw_o``):
``weight = cos(theta_o) dw_o dw_i``.

Functions and types
-------------------
- :class:`ViewGrid` -- the pairs, their cosines and weights; relative RMS (against one
  reference for many fits: ``error_to``), view albedos and Glossy lobes on them.
- :func:`view_grid` -- the grid for a lobe width (cached).
- :func:`lobe_widths_deg` -- the widths of the tables' two surface glosses, which size the
  grids.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.quadrature import mirror_quadrature
from ..tables.table_set import Tables
from . import cycles as cc

__all__ = ["ViewGrid", "view_grid", "FIT_VIEWS", "ERROR_VIEWS"]

FIT_VIEWS = 12
"""Views of the grids the closures are fitted on."""
ERROR_VIEWS = 32
"""Views of the grids the tiers' errors are measured on."""
LIGHT_POINTS = (5, 12)
"""Half-vector polar nodes per panel and azimuths per view
(:func:`lut_baker.numerics.quadrature.mirror_quadrature`)."""


@dataclass(frozen=True, eq=False)
class ViewGrid:
    """Direction pairs organised by view (module docstring).

    ``cos_view`` ``(V,)``: the views' ``cos(theta_o)``; ``wi`` ``(V, A, P, 3)`` the lights and
    ``wo`` ``(V, 1, 1, 3)`` the views (local frame, normal +z); ``cos_i``, ``cos_h`` (``n.h``),
    ``cos_hi`` (``h.wi = h.wo``) ``(V, A, P)``; ``cos_o`` ``(V, 1, 1)``; ``light_weight`` the
    solid angle of each light ``(V, A, P)`` (0 for the unused nodes past the horizon);
    ``weight`` the measure, ``cos(theta_o) dw_o dw_i``.
    """

    cos_view: np.ndarray
    wi: np.ndarray
    wo: np.ndarray
    cos_i: np.ndarray
    cos_o: np.ndarray
    cos_h: np.ndarray
    cos_hi: np.ndarray
    light_weight: np.ndarray
    weight: np.ndarray

    @property
    def directions(self) -> tuple[np.ndarray, np.ndarray]:
        """``(wi, wo)`` broadcast to ``(V, A, P, 3)``, for the replicas."""
        return self.wi, np.broadcast_to(self.wo, self.wi.shape)

    @cached_property
    def _radiance_weight(self) -> np.ndarray:
        """:meth:`error`'s weight, ``weight cos(theta_i)^2`` (once per grid: the fits'
        searches measure many lobes on one grid)."""
        return self.weight * np.square(self.cos_i)

    @cached_property
    def _albedo_weight(self) -> np.ndarray:
        """:meth:`view_albedo`'s weight, ``light_weight cos(theta_i)`` (once per grid)."""
        return self.light_weight * self.cos_i

    @cached_property
    def _cosines(self) -> cc.LobeCosines:
        """What every lobe on the pairs shares (once per grid: the fits' searches evaluate
        many lobes on one grid)."""
        return cc.LobeCosines(self.cos_h, self.cos_hi, self.cos_i, self.cos_o)

    def lobe(self, roughness: float, distribution: str = "GGX") -> np.ndarray:
        """A Glossy lobe without Fresnel (1/sr) at the pairs, ``(V, A, P)``
        (:func:`lut_baker.closures.cycles.microfacet_from_cosines`)."""
        return cc.lobe_from_cosines(self._cosines, roughness, distribution)

    def error(self, f_fit: ArrayLike, f_ref: ArrayLike) -> float:
        """Relative RMS of the radiance ``f cos(theta_i)``, channels pooled (``f``:
        ``(V, A, P)`` or ``(V, A, P, C)``)."""
        fit, ref = np.asarray(f_fit, float), np.asarray(f_ref, float)
        return self.error_to(ref, channels=fit.ndim == 4)(fit)

    def error_to(self, f_ref: ArrayLike, *,
                 channels: bool = False) -> Callable[[ArrayLike], float]:
        """:meth:`error` against one ``f_ref``, its norm computed once (a search measures
        many fits against it); ``channels``: the fits have a channel axis."""
        ref = np.asarray(f_ref, float)
        weight = self._radiance_weight
        if ref.ndim == 4 or channels:
            weight = weight[..., None]
        den = np.sum(weight * np.square(ref))

        def error(f_fit: ArrayLike) -> float:
            num = np.sum(weight * np.square(np.asarray(f_fit, float) - ref))
            return float(np.sqrt(num / den)) if den > 0 else float(np.sqrt(num))
        return error

    def view_albedo(self, f: ArrayLike) -> NDArray[np.float64]:
        """``Int f cos(theta_i) dw_i`` per view, ``(V,)`` or ``(V, C)``."""
        values = np.asarray(f, float)
        weight = self._albedo_weight
        if values.ndim == 4:
            return np.einsum("vapc,vap->vc", values, weight)
        return np.sum(values * weight, axis=(1, 2))

    def albedo_error(self, f_fit: ArrayLike, f_ref: ArrayLike) -> float:
        """Largest relative error of :meth:`view_albedo` over views and channels."""
        fit, ref = self.view_albedo(f_fit), self.view_albedo(f_ref)
        return float(np.max(np.abs(fit - ref) / np.maximum(np.abs(ref), 1e-12)))


@lru_cache(maxsize=16)
def view_grid(width_deg: float, views: int = FIT_VIEWS,
              light_points: tuple[int, int] = LIGHT_POINTS) -> ViewGrid:
    """The :class:`ViewGrid` of ``views`` views that resolves lobes down to ``width_deg``
    (degrees, 1/e half-width in the half vector's polar angle) with ``light_points`` (polar
    nodes per panel, azimuths) per view; arrays read-only (cached)."""
    cos_view = (np.arange(views) + 0.5) / views
    quad = mirror_quadrature(np.arccos(cos_view), float(width_deg),
                             alpha_points=light_points[0], phi_points=light_points[1])
    cos_o = cos_view[:, None, None]
    grid = ViewGrid(
        cos_view=cos_view,
        wi=quad.other,
        wo=quad.fixed[:, None, None, :],
        cos_i=quad.cos_other,
        cos_o=cos_o,
        cos_h=quad.cos_h,
        cos_hi=quad.cos_dh,
        light_weight=quad.weight,
        weight=quad.weight * cos_o / views,
    )
    for value in vars(grid).values():
        value.setflags(write=False)
    return grid


def lobe_widths_deg(tables: Tables) -> dict[str, float]:
    """The 1/e half-widths (degrees, 1/n of eq. 2's D) of the film's and the skin's gloss, by
    surface-gloss name; path 3 is at least as wide as the skin's (it is the skin's gloss seen
    through the film's broad transmission)."""
    return {name: 1.0 / float(np.max(tables.surface_layer(name).n))
            for name in ("film_gloss", "skin_gloss")}
