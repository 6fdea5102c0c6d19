"""Blender's roughness (0-1) for eq. 2's lobe: the panel's Film Roughness and Skin Roughness
(docs/model.md §4, "Roughness as Blender shows it").

Eq. 2's facet distribution ``D = exp(-(alpha n)^2)`` (alpha in degrees) falls to 1/e at the
half-vector angle ``1/n`` degrees.  Blender's GGX distribution with roughness ``r`` has
``alpha_g = r^2`` and ``D_GGX(theta) / D_GGX(0) = (alpha_g^2 / (alpha_g^2 cos^2 theta +
sin^2 theta))^2``, which falls to 1/e where ``sin^2 theta = alpha_g^2 (sqrt(e) - 1) / (1 -
alpha_g^2)``.  A roughness maps to the eq. 2 lobe of the same 1/e half-width; beyond
``r = (1/sqrt(e))^(1/4) = 0.883`` the GGX lobe no longer falls to 1/e above the horizon and
the width stays at its widest, 90 degrees.  The paper's film (30.4 degrees) is roughness 0.729,
its bio-plate (25.0) 0.682, the Jensen skins' (19.3) 0.616.

Moving the roughness spreads the same light: :func:`with_roughness` rescales ``P_s`` so that
the lobe's bihemispherical albedo (under uniform light) stays what it was, as a Blender
roughness slider blurs a highlight without dimming it.  A layer without a lobe (``P_s = 0``, a
matte product) has nothing to roughen and is returned as it is.

Functions
---------
- :func:`lobe_width_deg` -- the 1/e half-width (degrees) of roughness ``r``.
- :func:`roughness_for_width` -- its inverse.
- :func:`layer_roughness` -- a layer's lobe as a roughness.
- :func:`with_roughness` -- a layer with its lobe at roughness ``r``, its gloss albedo kept.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .albedo import bihemispherical, specular_albedo
from .layers import ReflectionLayer

__all__ = [
    "WIDEST_DEG",
    "ROUGHEST_WITH_EDGE",
    "lobe_width_deg",
    "roughness_for_width",
    "layer_roughness",
    "with_roughness",
]

_SQRT_E_MINUS_1 = math.sqrt(math.e) - 1.0
WIDEST_DEG = 90.0
"""The widest lobe a roughness gives (degrees): where GGX no longer falls to 1/e."""
ROUGHEST_WITH_EDGE = (1.0 / math.sqrt(math.e)) ** 0.25
"""The roughness beyond which the GGX lobe stays above 1/e over the whole hemisphere (0.883)."""


def lobe_width_deg(roughness: ArrayLike) -> NDArray[np.float64]:
    """The 1/e half-width (degrees, half-vector angle) of Blender's GGX lobe of roughness
    ``roughness`` (``alpha = roughness^2``): ``asin(sqrt(alpha^2 (sqrt(e) - 1) / (1 -
    alpha^2)))``, 90 degrees from :data:`ROUGHEST_WITH_EDGE` on.

    >>> print(np.round(lobe_width_deg([0.5, 0.729, 0.9]), 2))
    [12.   30.35 90.  ]
    """
    r = np.asarray(roughness, float)
    if np.any(r <= 0.0):
        raise ValueError(f"roughness must be > 0, got {roughness!r}")
    a2 = np.minimum(r, 1.0) ** 4  # alpha_g^2
    sine2 = np.where(a2 < 1.0, a2 * _SQRT_E_MINUS_1 / np.maximum(1.0 - a2, 1e-300), 1.0)
    return np.degrees(np.arcsin(np.sqrt(np.minimum(sine2, 1.0))))


def roughness_for_width(width_deg: ArrayLike) -> NDArray[np.float64]:
    """The roughness whose GGX lobe falls to 1/e at ``width_deg`` (degrees, in (0, 90]): the
    inverse of :func:`lobe_width_deg`.

    >>> print(np.round(roughness_for_width([19.3, 25.0, 30.4]), 3))  # skins, bio-plate, film
    [0.616 0.682 0.729]
    >>> round(float(roughness_for_width(90.0)), 4) == round(ROUGHEST_WITH_EDGE, 4)
    True
    """
    width = np.asarray(width_deg, float)
    if np.any(width <= 0.0) or np.any(width > WIDEST_DEG):
        raise ValueError(f"width_deg must lie in (0, 90], got {width_deg!r}")
    sine2 = np.sin(np.radians(width)) ** 2
    return (sine2 / (_SQRT_E_MINUS_1 + sine2)) ** 0.25


def layer_roughness(layer: ReflectionLayer) -> float:
    """The roughness of a layer's eq. 2 lobe (1/e half-width ``1/n`` degrees, capped at 90)."""
    return float(roughness_for_width(min(1.0 / float(np.max(layer.n)), WIDEST_DEG)))


def _gloss_albedo(layer: ReflectionLayer) -> np.ndarray:
    """The bihemispherical albedo of eq. 2's specular term of ``layer`` at ``P_s = 1``."""
    unit = ReflectionLayer(P_d=0.0, P_s=1.0, n=layer.n, eta=layer.eta)
    return bihemispherical(lambda t: specular_albedo(t, unit))


def with_roughness(layer: ReflectionLayer, roughness: float) -> ReflectionLayer:
    """``layer`` with its lobe at ``roughness`` (``n = 1 / lobe_width_deg``) and ``P_s``
    scaled so that the specular term's bihemispherical albedo is unchanged; a layer without a
    lobe (``P_s = 0``) is returned unchanged."""
    if not np.any(np.asarray(layer.P_s) > 0.0):
        return layer
    n = 1.0 / float(lobe_width_deg(roughness))
    moved = ReflectionLayer(P_d=layer.P_d, P_s=layer.P_s, n=n, eta=layer.eta)
    scale = _gloss_albedo(layer) / _gloss_albedo(moved)
    scale = scale[..., 0] if np.ndim(scale) and np.shape(scale)[-1] == 1 else scale
    return moved.scaled(P_s=scale)
