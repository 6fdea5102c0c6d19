"""Numpy replica of EEVEE's Glossy BSDF under a lamp (Blender 4.2 - 5.0, EEVEE "Next").

EEVEE renders every Glossy distribution as GGX (Beckmann and Ashikhmin-Shirley fall back to
it; only Multiscatter GGX differs, by its energy compensation), and under a lamp it does not
evaluate that GGX lobe but a linearly transformed cosine (LTC): ``radiance = E colour
magnitude D(wi)`` with

    D(w) = max((M^-1 w)_z, 0) |det M^-1| / (pi |M^-1 w|^4)

in the frame whose x axis is the view's tangent direction, ``M^-1`` and ``magnitude`` (the GGX
albedo) read bilinearly from a 64 x 64 table on ``(roughness, sqrt(1 - cos(theta_o)))``
(texel centres at the nodes ``i / 63``).  EEVEE's own table is Blender's data; the table here is
refitted by the published method (:mod:`lut_baker.offline.eevee_ltc`, file
:data:`LTC_TABLE_FILE`) and renders agree with it within about 1% RMS, where Cycles' GGX
(:func:`lut_baker.closures.cycles.microfacet_reflection`) differs by 6-19% for rough lobes:
the LTC has no tails and stops where the transformed direction leaves the hemisphere
(docs/addon.md, "Why the Layered tier breaks in EEVEE").

Lambertian (Diffuse BSDF) closures render exactly in EEVEE, as in Cycles
(:func:`lut_baker.closures.cycles.lambert_reflection`).

Functions
---------
- :func:`ltc_table` -- the table (read once).
- :func:`ltc_coefficients` -- ``M^-1`` entries and magnitude at roughness and view cosines.
- :func:`glossy_from_cosines`, :func:`glossy_reflection` -- the Glossy closure's BRDF (1/sr,
  without the cosine), as EEVEE renders it under a distant light.
- :func:`glossy_albedo` -- its albedo ``Int f cos(theta_i) dw_i`` (closed form).
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["LTC_TABLE_FILE", "LTC_TABLE_SIZE", "ltc_table", "ltc_coefficients",
           "glossy_from_cosines", "glossy_reflection", "glossy_albedo"]

LTC_TABLE_FILE = Path(__file__).with_name("eevee_ltc.json")
"""The LTC table (:func:`lut_baker.offline.eevee_ltc.write_table` writes it)."""
LTC_TABLE_SIZE = 64
"""Nodes per axis of EEVEE's LTC table (and of the refitted one)."""


@lru_cache(maxsize=1)
def ltc_table() -> tuple[np.ndarray, np.ndarray]:
    """``(inverse (N, N, 4), magnitude (N, N))`` from :data:`LTC_TABLE_FILE`: ``M^-1`` over its
    middle entry as ``[m00, m02, m20, m22]``, first axis roughness ``i / (N - 1)``, second
    ``s = sqrt(1 - cos(theta_o)) = j / (N - 1)``; read-only."""
    data = json.loads(LTC_TABLE_FILE.read_text())
    inverse = np.asarray(data["inverse"], float)
    magnitude = np.asarray(data["magnitude"], float)
    for array in (inverse, magnitude):
        array.setflags(write=False)
    return inverse, magnitude


def ltc_coefficients(roughness: float,
                     cos_view: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(inverse (..., 4), magnitude (...))`` at Blender ``roughness`` (clamped to [0, 1])
    and view cosines ``cos_view``: bilinear between the table's nodes, as EEVEE's linear
    texture filter reads them at ``(roughness, sqrt(1 - cos(theta_o)))``."""
    inverse, magnitude = ltc_table()
    size = inverse.shape[0]
    x = float(np.clip(roughness, 0.0, 1.0)) * (size - 1)
    i0 = min(int(np.floor(x)), size - 2)
    tx = x - i0
    y = np.sqrt(np.clip(1.0 - np.asarray(cos_view, float), 0.0, 1.0)) * (size - 1)
    j0 = np.minimum(np.floor(y).astype(int), size - 2)
    ty = y - j0

    def at(table: NDArray[np.float64]) -> NDArray[np.float64]:
        rows = (1.0 - tx) * table[i0] + tx * table[i0 + 1]  # (N[, 4]) along s
        low, high = rows[j0], rows[j0 + 1]
        weight = ty[..., None] if table.ndim == 3 else ty
        return (1.0 - weight) * low + weight * high

    return at(inverse), at(magnitude)


def glossy_from_cosines(wi: ArrayLike, cos_o: ArrayLike,
                        roughness: float) -> NDArray[np.float64]:
    """EEVEE's white Glossy BSDF (1/sr, without the cosine) at light directions ``wi``
    ``(..., 3)`` expressed in the frame of a view of cosine ``cos_o`` (broadcasting) that lies
    in the x-z plane towards +x; 0 where either direction is below the surface."""
    to_light = np.asarray(wi, float)
    view = np.asarray(cos_o, float)
    inverse, magnitude = ltc_coefficients(roughness, view)
    a, b, c, d = np.moveaxis(inverse, -1, 0)
    x, y, z = to_light[..., 0], to_light[..., 1], to_light[..., 2]
    lx, lz = a * x + b * z, c * x + d * z
    length2 = lx * lx + y * y + lz * lz
    value = (magnitude * np.maximum(lz, 0.0) * np.abs(a * d - b * c)
             / (np.pi * np.maximum(length2, 1e-300) ** 2))
    upper = (z > 0.0) & (view > 0.0)
    return np.where(upper, value / np.where(upper, z, 1.0), 0.0)


def glossy_reflection(wi: ArrayLike, wo: ArrayLike, roughness: float) -> NDArray[np.float64]:
    """:func:`glossy_from_cosines` at unit vectors ``wi``, ``wo`` ``(..., 3)`` in any local
    frame (normal +z): ``wi`` is turned about the normal so that ``wo`` lies towards +x."""
    to_light, to_view = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
    tangent = np.hypot(to_view[..., 0], to_view[..., 1])
    safe = tangent > 1e-12
    cos_phi = np.where(safe, to_view[..., 0] / np.where(safe, tangent, 1.0), 1.0)
    sin_phi = np.where(safe, to_view[..., 1] / np.where(safe, tangent, 1.0), 0.0)
    turned = np.stack([cos_phi * to_light[..., 0] + sin_phi * to_light[..., 1],
                       -sin_phi * to_light[..., 0] + cos_phi * to_light[..., 1],
                       to_light[..., 2]], -1)
    return glossy_from_cosines(turned, to_view[..., 2], roughness)


def glossy_albedo(cos_view: ArrayLike, roughness: float) -> NDArray[np.float64]:
    """``Int f cos(theta_i) dw_i`` of :func:`glossy_from_cosines` over the upper hemisphere at
    view cosines ``cos_view``: ``magnitude (1 + cos(beta)) / 2``, the clamped cosine's share
    that ``M`` maps above the horizon (its directions ``w_o`` with ``(M w_o)_z > 0``, a
    half-space at angle ``beta`` from its axis, whose intersection with the upper hemisphere
    holds ``(1 + cos(beta)) / 2`` of its projected solid angle)."""
    views = np.asarray(cos_view, float)
    inverse, magnitude = ltc_coefficients(roughness, views)
    a, b, c, d = np.moveaxis(inverse, -1, 0)
    det = a * d - b * c
    # Third row of M = (M^-1)^-1 (the middle entry 1 leaves it in the x-z block): (-c, 0, a)/det.
    row_x, row_z = -c / det, a / det
    cos_beta = row_z / np.hypot(row_x, row_z)
    return np.where(views > 0.0, magnitude * 0.5 * (1.0 + cos_beta), 0.0)
