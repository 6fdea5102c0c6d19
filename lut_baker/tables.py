"""Baked lookup tables of one made-up skin: the contract between the bake and the shader side.

Everything is per RGB channel (trailing axis of length 3) and in albedo units (1/sr), at
absorption 0 and split into parts so that coverage ``w`` and absorption ``A`` can be applied
afterwards (by a shader socket or by :meth:`Tables.made_up_reflection`)::

    f = w [film_gloss + (1 - A) film_diffuse + (1 - A)^2 (path3_gloss + skin_diffuse T(wi) T(wo))]
        + (1 - w) [skin_gloss + skin_diffuse]

``T`` is the film's directional transmittance (light crosses the film twice on path 3, so
its pigment absorbs twice).  The skin's diffuse part of path 3 is the part that spreads under
the surface with the dipole's normalised profile ``profile = R(d) / Rd`` (SPEC 4).

Angular tables are indexed ``[theta_i, theta_o, phi]`` on the grids ``theta_deg`` (degrees
from the normal) and ``phi_deg`` (relative azimuth, degrees, 0..180 by symmetry); radial ones by
``radius_mm``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

__all__ = ["FORMAT_VERSION", "Tables", "ANGULAR", "DIRECTIONAL", "CONSTANT", "RADIAL"]

FORMAT_VERSION = 1

ANGULAR = ("film_gloss", "path3_gloss", "skin_gloss")
"""Tables of shape ``(n_theta, n_theta, n_phi, 3)``, 1/sr."""
DIRECTIONAL = (
    "film_transmittance",
    "transmission_factor",
    "film_gloss_albedo",
    "path3_gloss_albedo",
    "skin_gloss_albedo",
)
"""Tables of shape ``(n_theta, 3)``, dimensionless (transmittances and albedos)."""
CONSTANT = ("film_diffuse", "skin_diffuse", "total_reflectance")
"""Per-channel constants of shape ``(3,)``: the two P_d (1/sr) and the dipole's Rd."""
RADIAL = ("profile",)
"""Tables of shape ``(n_radius, 3)``: ``R(d) / Rd`` in 1/mm^2."""


@dataclass(frozen=True, eq=False)
class Tables:
    """Baked tables of one made-up skin (see the module docstring for the formula).

    Grids: ``theta_deg`` (n_theta,), ``phi_deg`` (n_phi,), ``radius_mm`` (n_radius,).
    ``parameters``: the MadeUpSkin as plain data (``MadeUpSkin`` fields via ``as_dict``),
    including ``K``, ``coverage`` and ``absorption`` it was baked for.  ``inter_reflection``:
    optional angular table, the full adding-equation sum minus path 3 (1/sr), or None.
    """

    theta_deg: np.ndarray
    phi_deg: np.ndarray
    radius_mm: np.ndarray
    film_gloss: np.ndarray
    path3_gloss: np.ndarray
    skin_gloss: np.ndarray
    film_transmittance: np.ndarray
    transmission_factor: np.ndarray
    film_gloss_albedo: np.ndarray
    path3_gloss_albedo: np.ndarray
    skin_gloss_albedo: np.ndarray
    film_diffuse: np.ndarray
    skin_diffuse: np.ndarray
    total_reflectance: np.ndarray
    profile: np.ndarray
    parameters: dict = field(default_factory=dict)
    inter_reflection: np.ndarray | None = None

    def __post_init__(self):
        n_theta, n_phi, n_radius = self.theta_deg.size, self.phi_deg.size, self.radius_mm.size
        expected = {name: (n_theta, n_theta, n_phi, 3) for name in ANGULAR}
        expected.update({name: (n_theta, 3) for name in DIRECTIONAL})
        expected.update({name: (3,) for name in CONSTANT})
        expected.update({name: (n_radius, 3) for name in RADIAL})
        if self.inter_reflection is not None:
            expected["inter_reflection"] = (n_theta, n_theta, n_phi, 3)
        for name, shape in expected.items():
            value = np.asarray(getattr(self, name))
            if value.shape != shape:
                raise ValueError(f"table {name!r} must have shape {shape}, got {value.shape}")
            if not np.all(np.isfinite(value)):
                raise ValueError(f"table {name!r} holds NaN or Inf")

    @property
    def arrays(self) -> dict[str, np.ndarray]:
        """Every array field by name (grids and tables), for writing to disk."""
        return {
            f.name: getattr(self, f.name)
            for f in fields(self)
            if f.name != "parameters" and getattr(self, f.name) is not None
        }
