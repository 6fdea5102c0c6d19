"""What a closure fit gives the node group: :class:`ClosureFit`, the fitted lobes, profiles,
view-angle image and constants of one set of tables (made by
:func:`lut_baker.closures.fitting.fit_closures`)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from .lobes import LobeFit

__all__ = ["ClosureFit"]


@dataclass(frozen=True, eq=False)
class ClosureFit:
    """Everything the node group needs from one set of tables (absorption 0).

    PRINCIPLED: ``coat`` (film gloss), ``specular_bare`` (skin gloss), ``specular_film`` (path-3
    gloss under the coat), ``coat_albedo_mean``, ``specular_albedo_mean`` (bare, film): the
    cosine-weighted mean layering albedos; ``gloss_to_diffuse`` (RGB): the path-3 gloss albedo
    the base colour carries when no specular lobe fits it (else 0).  LAYERED: ``glossy``
    (film_gloss, path3_gloss, skin_gloss: Glossy lobes with their weight rows).  Both:
    ``transmittance_mean`` (RGB, the cosine-weighted mean of T), ``film_albedo`` and
    ``skin_albedo`` (RGB, ``pi P_d``), ``profiles`` (by method) and ``subsurface_method``
    (the best-fitting one), ``subsurface_ior`` (the dipole's index, for the random walk and
    the profile fits), ``lut`` (``(len(LUT_ROWS), size, 3)``: the view-angle image),
    ``errors`` at the coverage and absorption the tables were baked for.  EEVEE:
    ``eevee_glossy`` (the same lobes, GGX as EEVEE renders it, the film gloss in two:
    ``film_gloss`` and ``film_gloss_2``) and ``eevee_lut`` (their view-angle image, rows
    :data:`lut_baker.closures.view_image.EEVEE_LUT_ROWS`); its subsurface is
    Burley's (:data:`lut_baker.closures.tiers.EEVEE_SUBSURFACE_METHOD`).
    """

    coat: LobeFit
    specular_bare: LobeFit
    specular_film: LobeFit
    coat_albedo_mean: float
    specular_albedo_mean: tuple
    gloss_to_diffuse: np.ndarray
    glossy: dict
    transmittance_mean: np.ndarray
    film_albedo: np.ndarray
    skin_albedo: np.ndarray
    profiles: dict
    subsurface_method: str
    subsurface_ior: float
    lut: np.ndarray
    eevee_glossy: dict
    eevee_lut: np.ndarray
    errors: dict = field(default_factory=dict)

    @property
    def subsurface_radius_mm(self) -> np.ndarray:
        """The chosen method's Subsurface Radius x Scale per channel, mm."""
        return self.profiles[self.subsurface_method].radius_mm

    def summary(self) -> dict:
        """Plain data (floats and lists) for metadata, the panel and the docs."""
        return {
            "coat": {"roughness": self.coat.roughness, "ior": self.coat.ior,
                     "level": self.coat.level, "error": self.coat.error},
            "specular_bare": {"roughness": self.specular_bare.roughness,
                              "level": self.specular_bare.level,
                              "error": self.specular_bare.error},
            "specular_film": {"roughness": self.specular_film.roughness,
                              "level": self.specular_film.level,
                              "error": self.specular_film.error},
            "glossy": {name: {"roughness": lobe.roughness, "error": lobe.error,
                              "distribution": lobe.distribution}
                       for name, lobe in self.glossy.items()},
            "eevee_glossy": {name: {"roughness": lobe.roughness, "error": lobe.error}
                             for name, lobe in self.eevee_glossy.items()},
            "subsurface_method": self.subsurface_method,
            "subsurface_ior": self.subsurface_ior,
            "profiles": {name: {"radius_mm": p.radius_mm.tolist(), "error": p.error.tolist(),
                                "max_error": p.max_error.tolist()}
                         for name, p in self.profiles.items()},
            "errors": {name: asdict(e) for name, e in self.errors.items()},
        }
