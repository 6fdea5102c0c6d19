"""The skin's subsurface scattering: the dipole (paper eqs. 5, 6; docs/model.md §2.3).

Lengths in mm, coefficients in 1/mm; RGB dipoles add a trailing channel axis of 3.

Functions
---------
- :func:`fresnel_diffuse_reflectance` -- ``F_dr`` of the dipole (eq. 6).
- :func:`dipole_profile` -- radial diffuse reflectance ``R(d)``, d in mm (eq. 6).
- :func:`dipole_total_reflectance` -- closed-form ``Rd = 2 pi Int R(d) d dd`` (Jensen 2001).

References
----------
Jensen, Marschner, Levoy, Hanrahan, "A Practical Model for Subsurface Light Transport",
SIGGRAPH 2001.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics import Real
from .layers import Dipole, channel_axis

__all__ = [
    "fresnel_diffuse_reflectance",
    "dipole_profile",
    "dipole_total_reflectance",
]


def fresnel_diffuse_reflectance(eta: ArrayLike) -> NDArray[np.float64]:
    """Diffuse Fresnel reflectance ``F_dr = -1.440/eta^2 + 0.710/eta + 0.668 + 0.0636 eta``
    (paper eq. 6; Jensen 2001 eq. 5, dimensionless), for eta >= 1.

    >>> print(np.round(fresnel_diffuse_reflectance([1.0, 1.3, 1.4]), 4))
    [0.0016 0.4448 0.5295]
    """
    index = np.asarray(eta, dtype=float)
    return -1.440 / index**2 + 0.710 / index + 0.668 + 0.0636 * index


def _dipole_terms(dipole: Dipole) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                           NDArray[np.float64], NDArray[np.float64]]:
    """Derived dipole quantities of eq. 6: reduced albedo a', reduced extinction s_t' (1/mm),
    ``k = s_tr / s_t' = sqrt(3 (1 - a'))`` and A.  (z_r = 1/s_t', z_v = z_r (1 + 4A/3).)"""
    sigma_s_reduced = dipole.sigma_s * (1.0 - dipole.g)
    sigma_t_reduced = sigma_s_reduced + dipole.sigma_a
    albedo = sigma_s_reduced / sigma_t_reduced
    k = np.sqrt(3.0 * dipole.sigma_a / sigma_t_reduced)
    f_dr = fresnel_diffuse_reflectance(dipole.eta)
    a = (1.0 + f_dr) / (1.0 - f_dr)
    return albedo, sigma_t_reduced, k, a


def dipole_profile(d_mm: ArrayLike, dipole: Dipole) -> NDArray[np.float64]:
    """Dipole diffuse reflectance ``R(d)`` in 1/mm^2 at distance ``d_mm`` >= 0 (paper eq. 6).

    ``d_mm`` of any shape; RGB dipoles add a trailing channel axis.  Finite at d = 0.

    >>> medium = Dipole(sigma_s=1.0, sigma_a=0.1)  # 1/mm
    >>> print(np.round(dipole_profile([0.0, 0.5, 2.0], medium), 4))
    [0.0805 0.0532 0.0048]
    >>> d = np.linspace(0.0, 60.0, 60001)  # 2 pi Int R(d) d dd: the total reflectance
    >>> round(float(np.sum(2 * np.pi * dipole_profile(d, medium) * d) * (d[1] - d[0])), 4)
    0.3137
    """
    d = np.asarray(d_mm, dtype=float)
    if np.any(np.isnan(d)) or np.any(d < 0.0):
        raise ValueError("d_mm must be distances >= 0 (mm)")
    albedo, sigma_t_reduced, k, a = _dipole_terms(dipole)
    # Lengths in reduced mean free paths 1/s' (s' = sigma_t' in 1/mm): z_r s' = 1, z_v s' =
    # 1 + 4A/3, s_tr / s' = k, so R = a' s'^2 / (4 pi) sum z (k + 1/r) e^(-k r) / r^2 with
    # dimensionless r = hypot(d s', z): no overflow as s' -> 0 (z_r -> inf).
    x = channel_axis(d, dipole) * sigma_t_reduced
    total: Real = 0.0
    for z in (1.0, 1.0 + 4.0 * a / 3.0):
        r = np.hypot(x, z)
        with np.errstate(invalid="ignore"):  # k = 0 with r = inf: no decay
            decay = np.exp(-np.where(k > 0.0, k * r, 0.0))
        total = total + z / (r * r) * (k + 1.0 / r) * decay
    return albedo * sigma_t_reduced**2 / (4.0 * np.pi) * total


def dipole_total_reflectance(dipole: Dipole) -> NDArray[np.float64]:
    """Total diffuse reflectance ``Rd = 2 pi Int_0^inf R(d) d dd`` (dimensionless) in closed
    form (Jensen 2001 eq. 6 integrated):
    ``Rd = a'/2 (1 + exp(-4/3 A sqrt(3(1 - a')))) exp(-sqrt(3(1 - a')))``.

    >>> round(float(dipole_total_reflectance(Dipole(sigma_s=1.0, sigma_a=0.1))), 4)
    0.3137
    >>> skin = Dipole(sigma_s=[0.74, 0.88, 1.01], sigma_a=[0.032, 0.17, 0.48], eta=1.3)
    >>> print(np.round(dipole_total_reflectance(skin), 4))  # Jensen 2001's skin 1, RGB
    [0.436  0.2273 0.131 ]
    """
    albedo, _, root, a = _dipole_terms(dipole)
    return 0.5 * albedo * (1.0 + np.exp(-4.0 / 3.0 * a * root)) * np.exp(-root)
