"""Subsurface radii fitted to the skin's radial profile, per Blender subsurface method.

The tables hold the dipole's profile ``R(d) / Rd``; a Subsurface closure of radius ``r`` per
channel spreads light with its method's own profile (replicated in
:mod:`lut_baker.closures.cycles`).  The fit matches the two through their response to a
straight shadow edge, which is what a render shows of subsurface scattering (docs/addon.md,
"Subsurface: which Blender method fits the skin").

- :class:`ProfileFit` -- a method's radius and its error.
- :func:`edge_response` -- a radial profile's response to a straight shadow edge;
  :func:`edge_kernel` -- its integral as a matrix, for many profiles on the same radii.
- :func:`fit_profile`, :func:`fit_profiles` -- one method's radius, or every method's (cached).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.cache import LRUCache
from ..numerics.optimise import brent_minimum
from ..numerics.quadrature import trapezoid_weights
from ..tables.table_set import Tables
from . import cycles as cc
from .lobes import FIT_XTOL

__all__ = ["ProfileFit", "edge_response", "edge_kernel", "profile_grid", "fit_profile",
           "fit_profiles", "REPLICA_EDGE_ERROR"]

REPLICA_EDGE_ERROR = {"BURLEY": 0.0035, "RANDOM_WALK": 0.0068, "RANDOM_WALK_SKIN": 0.0067}
"""RMS difference (fraction of the lit level) between a rendered edge response and the
replica's at albedo 0.8 (tools/calibrate_subsurface.py, Cycles 5.0.1 and 4.5.15, 256 samples):
Burley's is the Monte Carlo noise; the random walks add the mismatch of their Burley-shaped
replica (0.6-1.3% over albedos 0.2-0.95)."""


@dataclass(frozen=True)
class ProfileFit:
    """Subsurface Radius (x Scale, in mm, per channel) of one Blender subsurface method fitted
    to the tables' normalised profile ``R(d)/Rd``.  ``error`` and ``max_error`` per channel: RMS
    and largest difference of the edge response (:func:`edge_response`, a fraction of the lit
    level) over distances up to the tables' last radius; ``albedo``: the colour assumed (the
    random walks' spread depends on it)."""

    method: str
    radius_mm: np.ndarray
    error: np.ndarray
    max_error: np.ndarray
    albedo: np.ndarray | None = None

    @property
    def worst_error(self) -> float:
        return float(np.max(self.error))


def edge_response(r_mm: ArrayLike, profile: ArrayLike, s_mm: ArrayLike) -> NDArray[np.float64]:
    """The light a point ``s_mm`` inside a straight shadow edge receives from the lit
    half-plane, as a fraction of the lit level, for a radial profile ``profile`` (unit area,
    1/mm^2) sampled at ``r_mm``: ``ESF(s) = Int_s^inf P(r) 2 r arccos(s / r) dr`` (0.5 at the
    edge).  What a subsurface profile looks like in a render: the blur of a shadow edge.
    ``profile``: ``(n_r)`` or ``(n_r, C)``; the result ``(n_s)`` or ``(n_s, C)``."""
    return edge_kernel(r_mm, s_mm) @ np.asarray(profile, float)


def edge_kernel(r_mm: ArrayLike, s_mm: ArrayLike) -> NDArray[np.float64]:
    """:func:`edge_response`'s integral as a matrix ``(n_s, n_r)``: ``2 r arccos(s / r)`` times
    the trapezoid weights in ``r`` (0 where ``r <= s``), so that a fit trying many profiles on
    the same radii builds it once."""
    r = np.asarray(r_mm, float)
    s = np.asarray(s_mm, float)[:, None]
    arc = np.where(r > s, 2.0 * np.arccos(np.clip(s / np.maximum(r, 1e-300), -1.0, 1.0)), 0.0)
    return arc * (r * trapezoid_weights(r))


PROFILE_RADII = 600
"""Radii of :func:`profile_grid` (1200 moves the fitted radii by under 0.2%)."""


def profile_grid(r_max: float) -> np.ndarray:
    """Integration radii (mm) for :func:`edge_response`: geometric, to 40 x the table's end."""
    return np.concatenate([[0.0], np.geomspace(1e-5 * r_max, 40.0 * r_max, PROFILE_RADII)])


def fit_profile(tables: Tables, method: str, *, albedo: ArrayLike | None = None) -> ProfileFit:
    """Fit the Subsurface Radius (mm, per channel) of ``method`` (``BURLEY``, ``RANDOM_WALK``,
    ``RANDOM_WALK_SKIN``) so that its edge response matches the tables' profile's (RMS over
    distances up to the tables' last radius).  ``albedo`` (per channel): the colour the random
    walk sees, default the skin's diffuse albedo ``pi skin_diffuse``."""
    if method not in cc.SUBSURFACE_METHODS:
        raise ValueError(f"method must be one of {cc.SUBSURFACE_METHODS}, got {method!r}")
    colour = np.clip(np.pi * np.asarray(tables.skin_diffuse, float) if albedo is None
                     else np.broadcast_to(np.asarray(albedo, float), (3,)), 0.0, 1.0)
    r_max = float(tables.radius_mm[-1])
    r = profile_grid(r_max)
    s = np.linspace(0.0, r_max, 48)
    kernel = edge_kernel(r, s)
    reference = kernel @ np.asarray(tables.radial(r), float)  # (48, 3): edge_response
    radii: list[float] = []
    errors: list[float] = []
    worst: list[float] = []
    done: dict[tuple, int] = {}
    for c in range(3):
        key = (reference[:, c].tobytes(), float(colour[c]))
        if key in done:
            for values in (radii, errors, worst):
                values.append(values[done[key]])
            continue
        done[key] = c

        def difference(log_radius: float, c: int = c) -> NDArray[np.float64]:
            model = cc.subsurface_profile(r, float(np.exp(log_radius)), colour[c], method)
            return kernel @ np.asarray(model, float) - reference[:, c]

        def rms(log_radius: float) -> float:
            return float(np.sqrt(np.mean(np.square(difference(log_radius)))))

        # Half the reference's mean spread (mm) centres the search window (log radius).
        centre = np.log(max(float(np.mean(reference[:, c]) * r_max), 1e-6))
        log_radius, error = brent_minimum(rms, centre - 3.0, centre + 5.0, coarse=17,
                                          xtol=FIT_XTOL)
        radii.append(float(np.exp(log_radius)))
        errors.append(error)
        worst.append(float(np.max(np.abs(difference(log_radius)))))
    return ProfileFit(method=method, radius_mm=np.array(radii), error=np.array(errors),
                      max_error=np.array(worst), albedo=None if method == "BURLEY" else colour)


PROFILE_FIT_CACHE_SIZE = 16
"""Profile fits kept in this process: they depend on the skin alone (its profile and diffuse
albedo), so every foundation on one skin shares them."""
_PROFILE_FITS = LRUCache(PROFILE_FIT_CACHE_SIZE)


def fit_profiles(tables: Tables, **options: ArrayLike) -> dict[str, ProfileFit]:
    """:func:`fit_profile` for every Blender subsurface method, by method name; remembered by
    the tables' radial grid, profile, skin albedo and ``options`` (the fits read nothing
    else)."""
    key = (np.asarray(tables.radius_mm, float).tobytes(),
           np.asarray(tables.profile, float).tobytes(),
           np.asarray(tables.skin_diffuse, float).tobytes(),
           repr(sorted((name, np.asarray(value).tolist()) for name, value in options.items())))
    return _PROFILE_FITS.get_or_compute(key, lambda: {
        method: fit_profile(tables, method, **options) for method in cc.SUBSURFACE_METHODS})
