"""Torrance-Sparrow reflection and the film's transmission (paper eqs. 2, 4; docs/model.md §2.1,
§2.2), each term written once, over cosines.

The formulas take the cosines ``n.h``, ``v.h``, ``n.v``, ``n.l`` (any shapes that broadcast
against each other and against the layer's parameters); the vector functions :func:`ts_reflection`
and :func:`ts_transmission` compute those cosines from unit vectors ``(..., 3)`` in the local
frame (normal +z, ``wi`` toward the light, ``wo`` toward the viewer) and call them, and the bake
computes them from polar angles and relative azimuths (:func:`half_vector_cosines`) and calls the
same formulas.  Every layer parameter may be a scalar or an RGB triple; vector results have shape
``batch + channels`` where ``channels`` is ``()`` for scalar layers and ``(3,)`` for RGB ones.

Functions
---------
- :func:`fresnel_reflectance` -- unpolarised dielectric Fresnel ``F_r(c, eta)`` (eq. 2);
  :func:`fresnel_transmittance` -- ``1 - F_r``.
- :func:`distribution_term` -- ``D = exp(-(alpha n)^2)``, alpha in degrees, n in 1/degree
  (eqs. 2, 4).
- :func:`attenuation_term` -- Torrance-Sparrow ``G`` (eq. 2).
- :func:`ts_specular_from_cosines` -- eq. 2's specular term ``P_s D G F_r``.
- :func:`ts_reflection_from_cosines` -- the BRDF ``P_d + P_s D G F_r`` (eq. 2).
- :func:`ts_transmission_from_cosines` -- the film's BTDF ``P_d + P_t D(beta) F_t`` (eq. 4).
- :func:`ts_reflection`, :func:`ts_transmission` -- the same at unit vectors.
- :func:`reflection_cosines`, :func:`transmission_cosines` -- the cosines eqs. 2 and 4 take,
  at unit vectors.
- :func:`half_vector_cosines` -- ``(n.h, v.h)`` from polar angles and a relative azimuth.
- :func:`check_directions` -- unit vectors ``(..., 3)`` or ``ValueError``.

The three terms are the inner loops of the bake and the evaluator, so they take their arguments
unchecked; ``check=True`` validates them first, for values that come from outside.  The
functions at unit vectors check their directions unless told not to (``check=False``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics import Real
from ..numerics.geometry import half_vector
from .layers import ReflectionLayer, TransmissionLayer, channel_axis

__all__ = [
    "UNIT_TOLERANCE",
    "check_directions",
    "fresnel_reflectance",
    "fresnel_transmittance",
    "distribution_term",
    "attenuation_term",
    "ts_specular_from_cosines",
    "ts_reflection_from_cosines",
    "ts_transmission_from_cosines",
    "ts_reflection",
    "reflection_cosines",
    "ts_transmission",
    "transmission_cosines",
    "half_vector_cosines",
]

UNIT_TOLERANCE = 1e-6
"""How far ``|w|`` may stray from 1 (and a cosine from [0, 1]) before it is rejected."""

Fresnel = Callable[[NDArray[np.float64], Real], NDArray[np.float64]]
"""``F_r(c, eta)`` at an array of cosines: :func:`fresnel_reflectance` or an accelerator of it
(the bake's tabulation)."""


# --------------------------------------------------------------------------------------------
# Directions
# --------------------------------------------------------------------------------------------
def check_directions(name: str, w: ArrayLike) -> NDArray[np.float64]:
    """Return ``w`` as a float array of unit vectors ``(..., 3)`` or raise ``ValueError``."""
    vectors = np.asarray(w, dtype=float)
    if vectors.ndim == 0 or vectors.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3), got {vectors.shape}")
    if not np.all(np.isfinite(vectors)):
        raise ValueError(f"{name} must be finite unit vectors; it holds NaN or Inf")
    norm = np.linalg.norm(vectors, axis=-1)
    if np.any(np.abs(norm - 1.0) > UNIT_TOLERANCE):
        worst = float(np.max(np.abs(norm - 1.0)))
        raise ValueError(f"{name} must be unit vectors (|w| = 1 within 1e-6), off by {worst:.3g}")
    return vectors


def half_vector_cosines(cos_a: NDArray[np.float64], sin_a: NDArray[np.float64],
                        cos_b: NDArray[np.float64], sin_b: NDArray[np.float64],
                        cos_phi: NDArray[np.float64]
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(n.h, v.h)`` of the half vector of ``wa``, ``wb`` (eq. 2) from their polar angles'
    cosines and sines and the cosine of their relative azimuth (all broadcasting):
    ``|wa + wb|^2 = 2 + 2 wa.wb``, ``n.h = (cos_a + cos_b) / |wa + wb|``, ``v.h = |wa + wb| / 2``;
    the normal where ``wa + wb`` vanishes (as :func:`ts_reflection`).  Both in [0, 1]."""
    dot = cos_a * cos_b + sin_a * sin_b * cos_phi
    length = np.sqrt(np.maximum(2.0 + 2.0 * dot, 0.0))
    safe = length > 1e-12
    n_dot_h = np.where(safe, (cos_a + cos_b) / np.where(safe, length, 1.0), 1.0)
    v_dot_h = np.where(safe, 0.5 * length, np.broadcast_to(cos_b, length.shape))
    return np.clip(n_dot_h, 0.0, 1.0), np.clip(v_dot_h, 0.0, 1.0)


def _angle_from_normal_deg(cos_angle: Real) -> NDArray[np.float64]:
    """Angle (degrees) of a unit vector with z-component ``cos_angle`` from the normal."""
    return np.degrees(np.arccos(np.clip(cos_angle, -1.0, 1.0)))


# --------------------------------------------------------------------------------------------
# The terms of eqs. 2 and 4
# --------------------------------------------------------------------------------------------
def fresnel_reflectance(cos_theta: Real, eta: Real, *, check: bool = False
                        ) -> NDArray[np.float64]:
    """Unpolarised dielectric Fresnel reflectance ``F_r(c, eta)`` (paper eq. 2, dimensionless)
    at cosines ``c`` in [0, 1] (between the direction and the (micro)normal on the incident
    side) and relative index ``eta`` > 0, broadcasting by numpy's rules.  Total internal
    reflection gives 1; ``eta = 1`` (no interface) gives 0 at every angle, grazing included.
    ``check=True`` rejects NaN, cosines outside [0, 1] and indices <= 0 first.

    >>> round(float(fresnel_reflectance(1.0, 1.5)), 6)  # ((eta - 1) / (eta + 1))^2
    0.04
    >>> print(np.round(fresnel_reflectance(np.array([1.0, 0.5, 0.0]), 1.33), 4))
    [0.0201 0.0591 1.    ]
    >>> float(fresnel_reflectance(0.3, 1 / 1.5))  # inside glass beyond the critical angle
    1.0
    """
    c, index = _checked_fresnel_arguments(cos_theta, eta) if check else (cos_theta, eta)
    # g^2 = (eta^2 - 1) + c^2, with eta^2 - 1 = (eta - 1)(eta + 1): no cancellation near
    # eta = 1 (where g -> c and F -> 0), and no underflow of c^2 for eta >= 1 (hypot).
    excess = (index - 1.0) * (index + 1.0)
    # eta >= 1 everywhere (the usual case): no total internal reflection, g from hypot alone
    # (the same numbers as the general branch, without evaluating its other side).
    outside = bool(np.all(np.asarray(excess) >= 0.0))
    if outside:
        g = np.hypot(np.sqrt(excess), c)
        if np.ndim(g) > 0:
            return _outside_fresnel(g, c)
    else:
        g2 = excess + c * c
        g = np.where(excess >= 0.0, np.hypot(np.sqrt(np.maximum(excess, 0.0)), c),
                     np.sqrt(np.maximum(g2, 0.0)))
    gpc = g + c
    gmc = g - c
    with np.errstate(divide="ignore", invalid="ignore"):
        first = 0.5 * (gmc / gpc) ** 2
        second = 1.0 + ((c * gpc - 1.0) / (c * gmc + 1.0)) ** 2
        f = first * second
    # g2 < 0 is total internal reflection.  Otherwise g + c = 0 only at eta = 1 and grazing,
    # where the formula is 0/0: with no interface nothing is reflected.
    f = np.where(gpc > 0.0, f, 0.0)
    if not outside:
        f = np.where(g2 < 0.0, 1.0, f)
    return np.clip(f, 0.0, 1.0)


def _outside_fresnel(g: NDArray[np.float64], c: Real) -> NDArray[np.float64]:
    """:func:`fresnel_reflectance` where no total internal reflection can occur, from ``g``
    (an array of the result's shape, used up): the same operations in the same order, worked
    on in place (the closures call it on thousands of cosines per index)."""
    gpc = g + c
    silent = ~(gpc > 0.0)  # g + c = 0 (eta = 1, grazing) or NaN: nothing reflected
    gmc = np.subtract(g, c, out=g)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.divide(gmc, gpc)
        np.square(f, out=f)
        f *= 0.5  # first = 0.5 ((g - c) / (g + c))^2
        second = np.multiply(c, gpc, out=gpc)
        second -= 1.0
        below = np.multiply(c, gmc, out=gmc)
        below += 1.0
        second /= below
        np.square(second, out=second)
        second += 1.0  # 1 + ((c (g + c) - 1) / (c (g - c) + 1))^2
        f *= second
    np.copyto(f, 0.0, where=silent)
    return np.clip(f, 0.0, 1.0, out=f)


def _checked_fresnel_arguments(cos_theta: Real, eta: Real
                               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(c, eta)`` as float arrays, ``c`` clipped to [0, 1], or ``ValueError``."""
    c = np.asarray(cos_theta, dtype=float)
    index = np.asarray(eta, dtype=float)
    if np.any(np.isnan(c)) or np.any((c < -UNIT_TOLERANCE) | (c > 1.0 + UNIT_TOLERANCE)):
        raise ValueError("cos_theta must lie in [0, 1]")
    if not np.all(np.isfinite(index)) or np.any(index <= 0.0):
        raise ValueError(f"eta must lie in (0, inf), got {index!r}")
    return np.clip(c, 0.0, 1.0), index


def fresnel_transmittance(cos_theta: Real, eta: Real) -> NDArray[np.float64]:
    """Unpolarised Fresnel transmittance ``F_t = 1 - F_r`` at cosine ``cos_theta`` and relative
    index ``eta`` (unchecked, like :func:`fresnel_reflectance`).

    >>> print(np.round(fresnel_transmittance(np.array([1.0, 0.5]), 1.4), 4))
    [0.9722 0.928 ]
    """
    return 1.0 - fresnel_reflectance(cos_theta, eta)


def distribution_term(angle_deg: Real, n: Real, *, check: bool = False) -> NDArray[np.float64]:
    """Torrance-Sparrow facet distribution ``D = exp(-(angle n)^2)`` (paper eqs. 2, 4,
    dimensionless): ``angle_deg`` is alpha (or beta for transmission) in degrees, ``n`` in
    1/degree, so ``D`` falls to 1/e at ``1 / n`` degrees.  ``check=True`` rejects angles that
    are not finite and ``n`` <= 0 first.

    >>> print(np.round(distribution_term(np.array([0.0, 5.0, 10.0]), 0.1), 4))
    [1.     0.7788 0.3679]
    """
    if check:
        angle_deg, n = _checked_distribution_arguments(angle_deg, n)
    return np.exp(-np.square(angle_deg * n))


def _checked_distribution_arguments(angle_deg: Real, n: Real
                                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(angle_deg, n)`` as float arrays, or ``ValueError``."""
    angle = np.asarray(angle_deg, dtype=float)
    width = np.asarray(n, dtype=float)
    if not np.all(np.isfinite(angle)):
        raise ValueError("angle_deg must be finite angles (degrees)")
    if not np.all(np.isfinite(width)) or np.any(width <= 0.0):
        raise ValueError(f"n must lie in (0, inf) (1/degree), got {width!r}")
    return angle, width


def attenuation_term(n_dot_h: Real, n_dot_v: Real, n_dot_l: Real, v_dot_h: Real, *,
                     check: bool = False) -> NDArray[np.float64]:
    """Torrance-Sparrow shadowing/masking ``G = min(1, 2 NH NV / VH, 2 NH NL / VH)`` (paper
    eq. 2, dimensionless) of cosines in [0, 1].  Where ``VH`` is 0 (an opposite horizontal
    pair) G is 0.  ``check=True`` rejects cosines outside [0, 1] (NaN included) first.

    >>> float(attenuation_term(1.0, 0.5, 0.8, 0.9))  # 2 NH min(NV, NL) / VH = 1.11: unshadowed
    1.0
    >>> round(float(attenuation_term(0.9, 0.2, 0.8, 0.7)), 4)  # the view masked
    0.5143
    """
    cosines: tuple[Real, ...] = (n_dot_h, n_dot_v, n_dot_l, v_dot_h)
    if check:
        cosines = _checked_cosines(cosines)
    nh, nv, nl, vh = np.broadcast_arrays(*cosines)
    safe = vh > 1e-12
    ratio = 2.0 * nh * np.minimum(nv, nl) / np.where(safe, vh, 1.0)
    return np.where(safe, np.clip(ratio, 0.0, 1.0), 0.0)


def _checked_cosines(cosines: tuple[Real, ...]) -> tuple[NDArray[np.float64], ...]:
    """The cosines as float arrays broadcast together, or ``ValueError`` if any lies outside
    [0, 1]."""
    arrays = tuple(np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in cosines)))
    if any(np.any(~((x >= 0.0) & (x <= 1.0 + UNIT_TOLERANCE))) for x in arrays):
        raise ValueError("n_dot_h, n_dot_v, n_dot_l and v_dot_h must lie in [0, 1]")
    return arrays


# --------------------------------------------------------------------------------------------
# Eqs. 2 and 4 over cosines
# --------------------------------------------------------------------------------------------
Cosines = NDArray[np.float64]
"""Cosines ``n.h``, ``v.h``, ``n.v``, ``n.l`` in [0, 1] (any shapes that broadcast)."""


def ts_specular_from_cosines(n_dot_h: Cosines, v_dot_h: Cosines, n_dot_v: Cosines,
                             n_dot_l: Cosines, P_s: Real, n: Real, eta: Real,
                             fresnel: Fresnel = fresnel_reflectance) -> NDArray[np.float64]:
    """Eq. 2's specular term ``P_s D(alpha) G F_r(v.h)`` in the unit of ``P_s`` (1/sr once
    normalised), ``alpha = acos(n.h)`` in degrees, ``n`` in 1/degree.  ``fresnel(c, eta)``:
    :func:`fresnel_reflectance` or an accelerator of it (the bake's tabulation)."""
    alpha = _angle_from_normal_deg(n_dot_h)
    geometry = attenuation_term(n_dot_h, n_dot_v, n_dot_l, v_dot_h)
    return P_s * distribution_term(alpha, n) * geometry * fresnel(v_dot_h, eta)


def ts_reflection_from_cosines(n_dot_h: Cosines, v_dot_h: Cosines, n_dot_v: Cosines,
                               n_dot_l: Cosines, layer: ReflectionLayer,
                               fresnel: Fresnel = fresnel_reflectance) -> NDArray[np.float64]:
    """Torrance-Sparrow BRDF ``f_r = P_d + P_s D(alpha) G F_r(v.h)`` (paper eq. 2), without
    the cosine, in the unit of ``P_d``/``P_s`` (1/sr once normalised).  The cosines must
    broadcast against the layer's parameters (a trailing channel axis for RGB layers)."""
    return layer.P_d + ts_specular_from_cosines(n_dot_h, v_dot_h, n_dot_v, n_dot_l, layer.P_s,
                                                layer.n, layer.eta, fresnel)


def ts_transmission_from_cosines(n_dot_h: Cosines, v_dot_h: Cosines, layer: TransmissionLayer,
                                 fresnel: Fresnel = fresnel_reflectance) -> NDArray[np.float64]:
    """Thin-film BTDF ``f_t = P_d + P_t D(beta) (1 - F_r(v'.h'))`` (paper eq. 4), without the
    cosine, in the unit of ``P_d``/``P_t``: ``n_dot_h`` is ``n.h'`` (``beta = acos(n.h')`` in
    degrees), ``v_dot_h`` is ``v'.h'``, with ``v'`` the transmitted direction mirrored through
    the film plane and ``h'`` the half vector of ``wi`` and ``v'`` (docs/model.md §2.2)."""
    beta = _angle_from_normal_deg(n_dot_h)
    through = 1.0 - fresnel(v_dot_h, layer.eta)
    return layer.P_d + layer.P_t * distribution_term(beta, layer.n) * through


# --------------------------------------------------------------------------------------------
# Eqs. 2 and 4 at unit vectors
# --------------------------------------------------------------------------------------------
def ts_reflection(wi: ArrayLike, wo: ArrayLike, layer: ReflectionLayer, *,
                  check: bool = True,
                  cosines: tuple[NDArray[np.float64], ...] | None = None
                  ) -> NDArray[np.float64]:
    """:func:`ts_reflection_from_cosines` at unit vectors ``wi``, ``wo`` ``(..., 3)`` (paper
    eq. 2); where either lies below the surface (z < 0) the value is 0.  ``check=False`` skips
    the direction checks (inner loops that pass unit vectors); ``cosines``: their
    :func:`reflection_cosines`, if already computed (layers at the same directions share
    them; unchecked)."""
    if cosines is None:
        if check:
            wi = check_directions("wi", wi)
            wo = check_directions("wo", wo)
        cosines = reflection_cosines(wi, wo)
    n_dot_h, v_dot_h, n_dot_v, n_dot_l = cosines
    value = ts_reflection_from_cosines(channel_axis(n_dot_h, layer), channel_axis(v_dot_h, layer),
                                       channel_axis(n_dot_v, layer), channel_axis(n_dot_l, layer),
                                       layer)
    upper = (n_dot_l >= 0.0) & (n_dot_v >= 0.0)
    return np.where(channel_axis(upper, layer), value, 0.0)


def reflection_cosines(wi: ArrayLike, wo: ArrayLike
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                                  NDArray[np.float64]]:
    """``(n.h, v.h, n.v, n.l)``, the cosines eq. 2 takes, at unit vectors ``wi``, ``wo``
    ``(..., 3)`` (unchecked): ``h`` their half vector (the normal where they are opposite and
    horizontal), ``v.h`` clipped to [0, 1]; ``n.v``, ``n.l`` signed (< 0 below the surface)."""
    wi, wo = np.broadcast_arrays(wi, wo)
    h = half_vector(wi, wo)
    v_dot_h = np.clip(np.sum(wo * h, axis=-1), 0.0, 1.0)
    return h[..., 2], v_dot_h, wo[..., 2], wi[..., 2]


def ts_transmission(wi: ArrayLike, wt: ArrayLike, layer: TransmissionLayer, *,
                    check: bool = True) -> NDArray[np.float64]:
    """:func:`ts_transmission_from_cosines` at unit vectors ``wi`` above the film (z > 0) and
    ``wt`` below (z < 0) (paper eq. 4).  The film is symmetric, so the pair mirrored through
    the film plane gives the same value (light crossing upward); pairs on the same side
    evaluate to 0.  ``check=False`` skips the direction checks."""
    if check:
        wi = check_directions("wi", wi)
        wt = check_directions("wt", wt)
    n_dot_h, v_dot_h, crossing = transmission_cosines(wi, wt)
    value = ts_transmission_from_cosines(channel_axis(n_dot_h, layer),
                                         channel_axis(v_dot_h, layer), layer)
    return np.where(channel_axis(crossing, layer), value, 0.0)


def transmission_cosines(wi: ArrayLike, wt: ArrayLike
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                    NDArray[np.bool_]]:
    """``(n.h', v'.h', crossing)`` at unit vectors ``wi``, ``wt`` ``(..., 3)`` (unchecked): the
    cosines eq. 4 takes (:func:`ts_transmission_from_cosines`) and whether the pair lies on
    opposite sides of the film (else the BTDF is 0)."""
    wi, wt = np.broadcast_arrays(wi, wt)
    crossing = wi[..., 2] * wt[..., 2] <= 0.0
    # Upward crossing (``wi`` below, or on the horizon with ``wt`` above): mirror the pair.
    flip = np.where(wi[..., 2:3] < wt[..., 2:3], -1.0, 1.0)
    top = wi * np.concatenate([np.ones_like(flip), np.ones_like(flip), flip], axis=-1)
    mirrored = wt * np.concatenate([np.ones_like(flip), np.ones_like(flip), -flip], axis=-1)
    h = half_vector(top, mirrored)
    v_dot_h = np.clip(np.sum(mirrored * h, axis=-1), 0.0, 1.0)
    return h[..., 2], v_dot_h, crossing
