"""An independent, straightforward re-implementation of the model for cross-checks.

Written from docs/model.md's formulas only: nothing here imports ``lut_baker``. Layer parameters are
plain floats (one channel at a time); tests loop over RGB channels themselves.

Scalar functions (``math`` module, one direction pair at a time):

- :func:`fresnel` -- ``F_r(c, eta)`` (paper eq. 2), 1 under total internal reflection.
- :func:`ts_reflection` -- ``P_d + P_s D G F_r`` (eq. 2).
- :func:`ts_transmission` -- ``P_d + P_t D(beta) F_t`` (eq. 4), either crossing direction.
- :func:`dipole_profile` -- ``R(d)`` (eq. 6), d in mm, coefficients in 1/mm.

Brute-force integrals (vectorised numpy, midpoint rule in ``(cos theta, phi)`` per hemisphere,
so ``cos(theta) dw = mu dmu dphi``):

- :func:`midpoint_hemisphere` -- nodes (unit vectors) and projected-solid-angle weights.
- :func:`brute_force_layered` -- ``f_cs(wi, wo)`` of docs/model.md §3 as a 4-D sum.
- :func:`brute_force_albedo` -- ``Int f(wi, w) cos(theta) dw`` of a single layer.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "fresnel",
    "ts_reflection",
    "ts_transmission",
    "dipole_profile",
    "vector_fresnel",
    "vector_reflection",
    "vector_transmission_down",
    "midpoint_hemisphere",
    "brute_force_layered",
    "brute_force_albedo",
]


# ------------------------------------------------------------------------------------------
# Scalar reference (math module)
# ------------------------------------------------------------------------------------------
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _normalised_sum(a, b):
    """``normalize(a + b)``; the normal when ``a + b`` is the zero vector."""
    s = (a[0] + b[0], a[1] + b[1], a[2] + b[2])
    length = math.sqrt(_dot(s, s))
    if length == 0.0:
        return (0.0, 0.0, 1.0)
    return (s[0] / length, s[1] / length, s[2] / length)


def _angle_deg(cos_value):
    return math.degrees(math.acos(max(-1.0, min(1.0, cos_value))))


def fresnel(c, eta):
    """Unpolarised Fresnel reflectance, docs/model.md §2.1: ``g = sqrt(eta^2 + c^2 - 1)``, with
    ``eta^2 - 1`` written ``(eta - 1)(eta + 1)`` so that eta = 1 gives g = c exactly."""
    g2 = (eta - 1.0) * (eta + 1.0) + c * c
    if g2 < 0.0:
        return 1.0  # total internal reflection
    g = math.sqrt(g2)
    if g + c == 0.0:
        return 1.0  # eta = 1 at grazing incidence: the limit is 1
    first = 0.5 * (g - c) ** 2 / (g + c) ** 2
    second = 1.0 + (c * (g + c) - 1.0) ** 2 / (c * (g - c) + 1.0) ** 2
    return first * second


def ts_reflection(wi, wo, P_d, P_s, n, eta):
    """Torrance-Sparrow BRDF of docs/model.md §2.1, 0 when either direction is below the surface."""
    if wi[2] < 0.0 or wo[2] < 0.0:
        return 0.0
    h = _normalised_sum(wi, wo)
    alpha = _angle_deg(h[2])
    d = math.exp(-((alpha * n) ** 2))
    vh = _dot(wo, h)
    if vh <= 0.0:
        g_term = 0.0
    else:
        g_term = min(1.0, 2.0 * h[2] * wo[2] / vh, 2.0 * h[2] * wi[2] / vh)
    return P_d + P_s * d * g_term * fresnel(max(0.0, min(1.0, vh)), eta)


def ts_transmission(wi, wt, P_d, P_t, n, eta):
    """Thin-film BTDF of docs/model.md §2.2 for a pair on opposite sides (0 otherwise).

    Downward crossing (``wi`` above, ``wt`` below) as written in docs/model.md; an upward crossing
    is the same configuration mirrored through the film plane (the film is symmetric).
    """
    if wi[2] >= 0.0 and wt[2] <= 0.0:
        top, bottom = wi, wt
    elif wi[2] <= 0.0 and wt[2] >= 0.0:
        top, bottom = (wi[0], wi[1], -wi[2]), (wt[0], wt[1], -wt[2])
    else:
        return 0.0
    mirrored = (bottom[0], bottom[1], -bottom[2])
    h = _normalised_sum(top, mirrored)
    beta = _angle_deg(h[2])
    d = math.exp(-((beta * n) ** 2))
    c = max(0.0, min(1.0, _dot(mirrored, h)))
    return P_d + P_t * d * (1.0 - fresnel(c, eta))


def dipole_profile(d, sigma_s, sigma_a, g, eta):
    """Dipole ``R(d)`` of docs/model.md §2.3 (Jensen 2001), 1/mm^2 for d in mm."""
    sigma_s_red = sigma_s * (1.0 - g)
    sigma_t_red = sigma_s_red + sigma_a
    albedo = sigma_s_red / sigma_t_red
    sigma_tr = math.sqrt(3.0 * sigma_a * sigma_t_red)
    f_dr = -1.440 / eta**2 + 0.710 / eta + 0.668 + 0.0636 * eta
    a = (1.0 + f_dr) / (1.0 - f_dr)
    z_r = 1.0 / sigma_t_red
    z_v = z_r * (1.0 + 4.0 * a / 3.0)
    total = 0.0
    for z in (z_r, z_v):
        dist = math.sqrt(d * d + z * z)
        total += z * (sigma_tr + 1.0 / dist) * math.exp(-sigma_tr * dist) / dist**2
    return albedo / (4.0 * math.pi) * total


# ------------------------------------------------------------------------------------------
# Vectorised versions of the same formulas (for the brute-force integrals)
# ------------------------------------------------------------------------------------------
def vector_fresnel(c, eta):
    """:func:`fresnel` on arrays (``c`` in [0, 1])."""
    g2 = (eta - 1.0) * (eta + 1.0) + c * c
    g = np.sqrt(np.maximum(g2, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        value = 0.5 * (g - c) ** 2 / (g + c) ** 2 * (
            1.0 + (c * (g + c) - 1.0) ** 2 / (c * (g - c) + 1.0) ** 2
        )
    return np.where((g2 < 0.0) | (g + c == 0.0), 1.0, value)


def _vector_half(a, b):
    s = a + b
    length = np.sqrt(np.sum(s * s, axis=-1, keepdims=True))
    zero = length == 0.0
    return np.where(zero, np.array([0.0, 0.0, 1.0]), s / np.where(zero, 1.0, length))


def vector_reflection(wi, wo, P_d, P_s, n, eta):
    """:func:`ts_reflection` on broadcastable arrays of upper-hemisphere directions."""
    wi, wo = np.broadcast_arrays(wi, wo)
    h = _vector_half(wi, wo)
    alpha = np.degrees(np.arccos(np.clip(h[..., 2], -1.0, 1.0)))
    vh = np.sum(wo * h, axis=-1)
    safe = np.where(vh > 0.0, vh, 1.0)
    g_term = np.minimum(1.0, 2.0 * h[..., 2] * np.minimum(wo[..., 2], wi[..., 2]) / safe)
    g_term = np.where(vh > 0.0, g_term, 0.0)
    f = vector_fresnel(np.clip(vh, 0.0, 1.0), eta)
    value = P_d + P_s * np.exp(-((alpha * n) ** 2)) * g_term * f
    return np.where((wi[..., 2] >= 0.0) & (wo[..., 2] >= 0.0), value, 0.0)


def vector_transmission_down(w_top, u, P_d, P_t, n, eta):
    """``f_t(w_top, -u)``: light from ``w_top`` (upper) crossing down along ``-u`` (u upper)."""
    w_top, u = np.broadcast_arrays(w_top, u)
    mirrored = u * np.array([-1.0, -1.0, 1.0])  # -u mirrored through the film plane
    h = _vector_half(w_top, mirrored)
    beta = np.degrees(np.arccos(np.clip(h[..., 2], -1.0, 1.0)))
    c = np.clip(np.sum(mirrored * h, axis=-1), 0.0, 1.0)
    return P_d + P_t * np.exp(-((beta * n) ** 2)) * (1.0 - vector_fresnel(c, eta))


# ------------------------------------------------------------------------------------------
# Brute-force integrals
# ------------------------------------------------------------------------------------------
def midpoint_hemisphere(n_mu: int, n_phi: int):
    """Midpoint nodes in ``mu = cos(theta)`` and ``phi``: ``(directions (N, 3), weights (N,))``
    with ``sum weights * f ~ Int f cos(theta) dw``."""
    mu = (np.arange(n_mu) + 0.5) / n_mu
    phi = (np.arange(n_phi) + 0.5) * 2.0 * np.pi / n_phi
    mu, phi = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1.0 - mu * mu)
    dirs = np.stack([s * np.cos(phi), s * np.sin(phi), mu], axis=-1).reshape(-1, 3)
    weights = (mu * (1.0 / n_mu) * (2.0 * np.pi / n_phi)).ravel()
    return dirs, weights


def brute_force_layered(wi, wo, film, skin, n_mu: int, n_phi: int, chunk: int = 256):
    """``f_cs(wi_p, wo_p)`` (docs/model.md §3) for point pairs ``wi``, ``wo`` of shape ``(P, 3)``.

    ``film = (P_d, P_t, n, eta)`` (transmission), ``skin = (P_d, P_s, n, eta)`` (reflection),
    scalars.  ``sum_u sum_v a_p(u) f_r(u, v) b_p(v)`` with ``a_p(u) = f_t(wi_p, -u) W_u``.
    """
    wi = np.asarray(wi, float).reshape(-1, 3)
    wo = np.asarray(wo, float).reshape(-1, 3)
    nodes, weights = midpoint_hemisphere(n_mu, n_phi)
    a = vector_transmission_down(wi[:, None, :], nodes[None, :, :], *film) * weights  # (P, N)
    b = vector_transmission_down(wo[:, None, :], nodes[None, :, :], *film) * weights  # (P, N)
    total = np.zeros(wi.shape[0])
    for start in range(0, nodes.shape[0], chunk):
        u = nodes[start:start + chunk]
        block = vector_reflection(u[:, None, :], nodes[None, :, :], *skin)  # (chunk, N)
        total += np.sum(a[:, start:start + chunk] * (b @ block.T), axis=1)
    return total


def brute_force_albedo(kernel, w, n_mu: int, n_phi: int):
    """``Int kernel(w, u) cos(theta_u) du`` over the upper hemisphere for each ``w`` (P, 3)."""
    w = np.asarray(w, float).reshape(-1, 3)
    nodes, weights = midpoint_hemisphere(n_mu, n_phi)
    return kernel(w[:, None, :], nodes[None, :, :]) @ weights
