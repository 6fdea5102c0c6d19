"""The view-angle image of the view-weighted tiers: its rows, its texel centres and how
Blender's Image Texture samples it.

A tier's view-dependent weights are 1-D functions of ``cos(theta_o)``, one per row of a small
float image that the node group reads at ``u = cos(theta_o)``: :data:`LUT_ROWS` names the rows
(:data:`EEVEE_LUT_ROWS` the EEVEE tier's),
:func:`lut_nodes` gives the texel centres, :func:`sample_lut` reads a row as Blender does
(Linear, EXTEND).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["LUT_ROWS", "EEVEE_LUT_ROWS", "DEFAULT_LUT_SIZE", "lut_nodes", "sample_lut"]

LUT_ROWS = ("film_gloss", "path3_gloss", "skin_gloss", "film_transmittance",
            "film_gloss_diffuse")
"""Rows of the LAYERED tier's view-angle image: three Glossy weights, the film's
transmittance ``T(theta_o)`` and the film gloss's Lambertian companion
(:func:`lut_baker.closures.lobes.fit_glossy`)."""
EEVEE_LUT_ROWS = LUT_ROWS + ("film_gloss_2",)
"""Rows of the EEVEE tier's view-angle image: :data:`LUT_ROWS` and the weight of the film
gloss's second lobe (:func:`lut_baker.closures.lobes.fit_glossy_pair`)."""
DEFAULT_LUT_SIZE = 64
"""Texels per row of the view-angle image (linear filtering between texel centres)."""


def lut_nodes(size: int = DEFAULT_LUT_SIZE) -> np.ndarray:
    """``cos(theta_o)`` at the texel centres ``(i + 0.5) / size`` of a view-angle image."""
    return (np.arange(size) + 0.5) / size


def sample_lut(lut: ArrayLike, cos_view: ArrayLike) -> NDArray[np.float64]:
    """What Blender's Image Texture (Linear, EXTEND) returns for a row ``lut`` ``(size[, C])``
    at ``u = cos_view``: linear between texel centres, the edge texel beyond them.

    >>> print(np.round(lut_nodes(4), 3))  # the texel centres of a row of 4
    [0.125 0.375 0.625 0.875]
    >>> print(sample_lut([0.0, 1.0, 2.0, 3.0], [0.0, 0.25, 0.5, 1.0]))  # held beyond them
    [0.  0.5 1.5 3. ]
    """
    row = np.asarray(lut, float)
    nodes = lut_nodes(row.shape[0])
    u = np.asarray(cos_view, float)
    if row.ndim == 1:
        return np.interp(u, nodes, row)
    return np.stack([np.interp(u, nodes, row[:, c]) for c in range(row.shape[1])], -1)
