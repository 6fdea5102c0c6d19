"""The paper's measurement geometries (docs/model.md §6), as direction arrays the model can
evaluate.

Reflection (4.1.1, 4.2.1, 5.1): light and camera fixed in one plane with the sample, at a
relative angle psi; the sample rotates, so the half vector H (fixed) makes a signed angle alpha
with the normal N.  In the sample's frame::

    theta_i = alpha + psi / 2,   theta_r = alpha - psi / 2   (signed, in the x-z plane)

so ``alpha = 0`` is the mirror configuration.  Transmission (4.1.2): the film and the light turn
together (incidence fixed); the camera below sees transmission angle ``theta_t``; the step rule
applies to beta.  Sampling is densest near the lobe (docs/model.md §6): |angle| <= 3 degrees at 0.2,
3-5 at 0.5, 5-10 at 1, 10-20 at 2, beyond at 3.

Functions
---------
- :func:`step_angles` -- the paper's signed sampling of alpha or beta (degrees).
- :func:`in_plane_direction` -- unit vector at a signed in-plane angle (degrees).
- :func:`tilted` -- directions seen from a sample tilted in the plane (an offset of alpha).
- :func:`reflection_geometry` -- directions of given samples alpha at relative angle psi.
- :func:`transmission_geometry` -- directions of given samples theta_t at incidence theta_i.
- :func:`reflection_sweep` -- geometry of a reflection experiment at relative angle psi.
- :func:`transmission_sweep` -- geometry of a transmission experiment at incidence theta_i.
- :func:`profile_distances` -- distances (mm) of a pencil-beam profile.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "STEP_RULE",
    "step_angles",
    "in_plane_direction",
    "tilted",
    "ReflectionSweep",
    "TransmissionSweep",
    "reflection_geometry",
    "transmission_geometry",
    "reflection_sweep",
    "transmission_sweep",
    "profile_distances",
]

STEP_RULE = ((3.0, 0.2), (5.0, 0.5), (10.0, 1.0), (20.0, 2.0), (np.inf, 3.0))
"""``(upper bound of |angle|, step)`` pairs in degrees, from docs/model.md §6."""


def step_angles(limit_deg: float) -> np.ndarray:
    """Signed angles (degrees) from ``-limit_deg`` to ``limit_deg`` on the paper's step rule."""
    if not limit_deg > 0:
        raise ValueError(f"limit_deg must be > 0 degrees, got {limit_deg!r}")
    positive = [0.0]
    for bound, step in STEP_RULE:
        while positive[-1] + step <= min(bound, limit_deg) + 1e-9:
            positive.append(round(positive[-1] + step, 6))
        if positive[-1] + STEP_RULE[-1][1] > limit_deg and bound >= limit_deg:
            break
    nodes = np.array(positive)
    return np.concatenate([-nodes[:0:-1], nodes])


def in_plane_direction(angle_deg) -> np.ndarray:
    """Unit vectors ``(..., 3)`` in the x-z plane at signed angle ``angle_deg`` from +z."""
    a = np.radians(np.asarray(angle_deg, float))
    return np.stack([np.sin(a), np.zeros_like(a), np.cos(a)], axis=-1)


def tilted(w, tilt_deg: float) -> np.ndarray:
    """Directions ``w`` ``(..., 3)`` in the frame of a sample tilted by ``tilt_deg`` (degrees)
    about the y axis: every signed in-plane angle grows by ``tilt_deg``.  In the reflection
    protocol this is an offset of alpha (``theta_i`` and ``theta_r`` both grow); for in-plane
    rows (light at ``theta_i``, camera at ``theta_o`` on the other side) the sample sees
    ``theta_i + tilt`` and ``theta_o - tilt``, so its mirror direction lies at
    ``theta_o = theta_i + 2 tilt``."""
    w = np.asarray(w, dtype=float)
    a = np.radians(float(tilt_deg))
    c, s = np.cos(a), np.sin(a)
    x, z = w[..., 0], w[..., 2]
    return np.stack([x * c + z * s, w[..., 1], z * c - x * s], axis=-1)


@dataclass(frozen=True)
class ReflectionSweep:
    """One reflection experiment: per sample, the signed alpha, theta_i, theta_r (degrees) and
    the directions toward the light (``wi``) and the camera (``wo``)."""

    relative_angle_deg: float
    alpha_deg: np.ndarray
    theta_i_deg: np.ndarray
    theta_r_deg: np.ndarray
    wi: np.ndarray
    wo: np.ndarray


@dataclass(frozen=True)
class TransmissionSweep:
    """One transmission experiment: incidence (degrees) and per sample beta, the signed
    transmission angle theta_t (degrees, measured from -z) and the directions."""

    incidence_deg: float
    beta_deg: np.ndarray
    theta_t_deg: np.ndarray
    wi: np.ndarray
    wt: np.ndarray


def reflection_geometry(relative_angle_deg: float, alpha_deg) -> ReflectionSweep:
    """Directions of reflection samples at signed ``alpha_deg`` (degrees) with light and camera
    ``relative_angle_deg`` apart: ``theta_i = alpha + psi/2``, ``theta_r = alpha - psi/2``."""
    alpha = np.asarray(alpha_deg, float)
    half = relative_angle_deg / 2.0
    theta_i = alpha + half
    theta_r = alpha - half
    return ReflectionSweep(relative_angle_deg, alpha, theta_i, theta_r,
                           in_plane_direction(theta_i), in_plane_direction(theta_r))


def transmission_geometry(incidence_deg: float, theta_t_deg) -> TransmissionSweep:
    """Directions of transmission samples at signed ``theta_t_deg`` (degrees, from -z) with the
    light at ``incidence_deg``; in-plane, ``beta = (theta_t - theta_i) / 2``."""
    theta_t = np.asarray(theta_t_deg, float)
    beta = (theta_t - incidence_deg) / 2.0
    wi = np.broadcast_to(in_plane_direction(incidence_deg), theta_t.shape + (3,))
    return TransmissionSweep(incidence_deg, beta, theta_t, wi, -in_plane_direction(theta_t))


def reflection_sweep(relative_angle_deg: float, max_angle_deg: float = 85.0) -> ReflectionSweep:
    """The sample rotated through alpha on the paper's steps while light and camera stay
    ``relative_angle_deg`` apart; samples where light or camera is beyond ``max_angle_deg``
    from the normal are left out."""
    if not 0.0 < relative_angle_deg < 180.0:
        raise ValueError(f"relative_angle_deg must lie in (0, 180), got {relative_angle_deg!r}")
    full = reflection_geometry(relative_angle_deg, step_angles(90.0 + relative_angle_deg / 2.0))
    keep = (np.abs(full.theta_i_deg) <= max_angle_deg) & (np.abs(full.theta_r_deg) <= max_angle_deg)
    return reflection_geometry(relative_angle_deg, full.alpha_deg[keep])


def transmission_sweep(incidence_deg: float, max_angle_deg: float = 85.0) -> TransmissionSweep:
    """Light at ``incidence_deg`` above the film, camera below at transmission angles chosen so
    that beta follows the paper's steps; beta = 0 is the straight-through direction."""
    if not 0.0 <= incidence_deg < 90.0:
        raise ValueError(f"incidence_deg must lie in [0, 90), got {incidence_deg!r}")
    # Straight through: theta_t = theta_i (wt = -wi); in-plane, beta = (theta_t - theta_i) / 2.
    theta_t = incidence_deg + 2.0 * step_angles(90.0)
    return transmission_geometry(incidence_deg, theta_t[np.abs(theta_t) <= max_angle_deg])


def profile_distances(max_mm: float = 3.0, step_mm: float = 0.05) -> np.ndarray:
    """Distances (mm) from the lit point of a pencil-beam profile, 0 to ``max_mm``."""
    if not (max_mm > 0 and step_mm > 0):
        raise ValueError("max_mm and step_mm must be > 0 (mm)")
    return np.arange(0.0, max_mm + 0.5 * step_mm, step_mm)
