"""The view-angle image of the view-weighted tiers: its rows, its texel centres and how
Blender's Image Texture samples it.

A tier's view-dependent weights are 1-D functions of ``cos(theta_o)``, one per row of a small
float image that the node group reads at ``u = cos(theta_o)``: :data:`IMAGE_ROWS` names the rows
(:data:`EEVEE_IMAGE_ROWS` the EEVEE tier's), :func:`texel_centres` gives the texel centres,
:func:`texel_pair` and :func:`read_row` read a row at ``u`` as Blender's Linear, EXTEND lookup
does, written once over an algebra (two Closest lookups at neighbouring texel centres mixed
linearly: numpy arrays in :func:`sample_row`, node sockets in the add-on's node group, where
EEVEE's Linear lookup would mix rows through mipmaps); :func:`row_reader` reads many rows at
the same ``u``, its texels found once.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["IMAGE_ROWS", "EEVEE_IMAGE_ROWS", "DEFAULT_IMAGE_SIZE", "texel_centres", "texel_pair",
           "read_row", "sample_row", "row_reader"]

IMAGE_ROWS = ("film_gloss", "path3_gloss", "skin_gloss", "film_transmittance",
            "film_gloss_diffuse")
"""Rows of the LAYERED tier's view-angle image: three Glossy weights, the film's
transmittance ``T(theta_o)`` and the film gloss's Lambertian companion
(:func:`lut_baker.closures.lobes.fit_glossy`)."""
EEVEE_IMAGE_ROWS = IMAGE_ROWS + ("film_gloss_2",)
"""Rows of the EEVEE tier's view-angle image: :data:`IMAGE_ROWS` and the weight of the film
gloss's second lobe (:func:`lut_baker.closures.lobes.fit_glossy_pair`)."""
DEFAULT_IMAGE_SIZE = 64
"""Texels per row of the view-angle image (linear filtering between texel centres)."""


def texel_centres(size: int = DEFAULT_IMAGE_SIZE) -> np.ndarray:
    """``cos(theta_o)`` at the texel centres ``(i + 0.5) / size`` of a view-angle image."""
    return (np.arange(size) + 0.5) / size


def texel_pair(u: Any, size: int, ops: Any) -> tuple[Any, Any, Any]:
    """``(u0, u1, t)`` for reading a row of ``size`` texels at ``u`` linearly between texel
    centres and held beyond them: ``x = clamp(u size, 0.5, size - 0.5) - 0.5``, the centres
    ``(i + 0.5) / size`` of texel ``i = floor(x)`` and of the next (the edge one twice beyond
    the centres), and the weight ``t = x - i`` of the second.  ``ops``: ``minimum``,
    ``maximum``, ``floor`` of the values' kind (numpy's, or the node group's)."""
    x = ops.minimum(ops.maximum(u * float(size), 0.5), size - 0.5) - 0.5
    index = ops.floor(x)
    return ((index + 0.5) / float(size), ops.minimum(index + 1.5, size - 0.5) / float(size),
            x - index)


def read_row(u: Any, size: int, texel: Callable[[Any], Any], ops: Any) -> Any:
    """A row of ``size`` texels read at ``u`` as Blender's Linear, EXTEND lookup does: the
    two texels of :func:`texel_pair` read by ``texel(u)`` (a Closest lookup) and mixed,
    ``ops.lerp(t, a, b)``."""
    u0, u1, t = texel_pair(u, size, ops)
    return ops.lerp(t, texel(u0), texel(u1))


class _Numpy:
    minimum = staticmethod(np.minimum)
    maximum = staticmethod(np.maximum)
    floor = staticmethod(np.floor)

    @staticmethod
    def lerp(t: Any, a: Any, b: Any) -> Any:
        t = np.asarray(t, float)
        t = t[..., None] if np.ndim(a) > t.ndim else t
        return a + t * (b - a)


def sample_row(row: ArrayLike, cos_view: ArrayLike) -> NDArray[np.float64]:
    """What Blender's Image Texture (Linear, EXTEND) returns for a row ``row`` ``(size[, C])``
    at ``u = cos_view``: :func:`read_row` on numpy arrays.

    >>> print(np.round(texel_centres(4), 3))  # the texel centres of a row of 4
    [0.125 0.375 0.625 0.875]
    >>> print(sample_row([0.0, 1.0, 2.0, 3.0], [0.0, 0.25, 0.5, 1.0]))  # held beyond them
    [0.  0.5 1.5 3. ]
    """
    row = np.asarray(row, float)
    return row_reader(cos_view, row.shape[0])(row)


def row_reader(cos_view: ArrayLike, size: int
               ) -> Callable[[ArrayLike], NDArray[np.float64]]:
    """:func:`sample_row` at ``u = cos_view`` for any row of ``size`` texels: the texels and
    weights of :func:`texel_pair` found once, each row then read by two lookups and a mix (the
    same operations as :func:`sample_row`: the same numbers).  ``ValueError`` for a row of
    another size."""
    def texel(u: NDArray[np.float64]) -> NDArray[np.intp]:
        return np.clip(np.floor(u * size).astype(int), 0, size - 1)

    u0, u1, t = texel_pair(np.asarray(cos_view, float), size, _Numpy)
    first, second = texel(u0), texel(u1)

    def read(row: ArrayLike) -> NDArray[np.float64]:
        row = np.asarray(row, float)
        if row.shape[0] != size:
            raise ValueError(f"a row of {row.shape[0]} texels read as one of {size}")
        return np.asarray(_Numpy.lerp(t, np.take(row, first, axis=0),
                                      np.take(row, second, axis=0)), float)

    return read
