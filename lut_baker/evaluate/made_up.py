"""The exact made-up skin: paths 1 + 3 summed and mixed by coverage (paper eq. 9; docs/model.md
§4), evaluated with the two-layer evaluator of :mod:`lut_baker.evaluate.two_layer`.

Functions
---------
- :func:`made_up_reflection` -- the made-up skin's BRDF, paths 1 + 3 with coverage, 1/sr.
- :func:`directional_albedo` -- paths 1 + 3 integrated over the view hemisphere.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.albedo import grid_for, reflection_albedo
from ..model.layers import Layer
from ..model.made_up_skin import (
    MadeUpSkin,
    combine,
    coverage_weights,
    film_reflection_layer,
    film_transmission_layer,
)
from ..model.microfacet import check_directions, ts_reflection
from .two_layer import layered_fourier_matrices, layered_reflection

__all__ = [
    "made_up_reflection",
    "directional_albedo",
]


def _rgb(values: np.ndarray, *layers: Layer) -> np.ndarray:
    """Broadcast a result of ``layers`` to RGB: ``(...)`` for scalar layers -> ``(..., 3)``."""
    values = np.asarray(values)
    rgb = any(layer.channels for layer in layers)
    return values if rgb else np.repeat(values[..., None], 3, axis=-1)


def made_up_reflection(wi: ArrayLike, wo: ArrayLike, skin: MadeUpSkin, *,
                       level: int = 0) -> NDArray[np.float64]:
    """Made-up skin BRDF, paths 1 + 3 (paper eq. 9) mixed with bare skin by coverage
    (docs/model.md §4): ``(1 - w) f_r,s + w (f_r,c + f_cs)`` with the film's absorption in its
    layers (:func:`~lut_baker.model.made_up_skin.coverage_weights`), in 1/sr, RGB: shape
    ``(..., 3)``.  ``wi``, ``wo``: unit vectors ``(..., 3)``; ``level`` refines the quadrature
    of path 3."""
    wi = check_directions("wi", wi)
    wo = check_directions("wo", wo)
    film = film_reflection_layer(skin)
    film_transmission = film_transmission_layer(skin)
    bare = _rgb(ts_reflection(wi, wo, skin.skin_reflection, check=False), skin.skin_reflection)
    top = _rgb(ts_reflection(wi, wo, film, check=False), film)
    path3 = _rgb(layered_reflection(wi, wo, film_transmission, skin.skin_reflection, level=level),
                 film_transmission, skin.skin_reflection)
    # The layers hold the absorption already: everything the film covers is "top".
    return combine(coverage_weights(skin.coverage, skin.absorption), top=top + path3,
                   bare=bare)


def directional_albedo(theta_i_deg: ArrayLike, skin: MadeUpSkin, *,
                       level: int = 0) -> NDArray[np.float64]:
    """Paths 1 + 3 (with coverage) integrated over the view hemisphere, per RGB channel:
    ``Int f(wi, wo) cos(theta_o) dwo`` (dimensionless) at incidence ``theta_i_deg`` (degrees).
    A white furnace test asserts it is <= 1.  Shape ``theta_i_deg.shape + (3,)``."""
    theta = np.radians(np.atleast_1d(np.asarray(theta_i_deg, float)))
    film_transmission = film_transmission_layer(skin)
    grid = grid_for(film_transmission, skin.skin_reflection,
                    level=level)  # path 3's layers (the film's top: below)
    path3 = layered_fourier_matrices(theta, grid.theta, film_transmission, skin.skin_reflection,
                                     grid,
                                     orders=1)[0]  # (P, N, C)
    path3 = 2.0 * np.pi * np.einsum("pnc,n->pc", path3, grid.weight)
    path3 = path3 if (film_transmission.channels or skin.skin_reflection.channels) else path3[...,
                                                                                              0]
    film = film_reflection_layer(skin)
    top = reflection_albedo(np.degrees(theta), film, level=level)
    bare = reflection_albedo(np.degrees(theta), skin.skin_reflection, level=level)
    total = combine(coverage_weights(skin.coverage, skin.absorption),
                    top=_rgb(top, film) + _rgb(path3, film_transmission, skin.skin_reflection),
                    bare=_rgb(bare, skin.skin_reflection))
    return total.reshape(np.shape(theta_i_deg) + (3,))
