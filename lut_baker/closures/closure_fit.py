"""What a closure fit gives the node group: :class:`ClosureFit`, the fitted lobes, profiles,
view-angle image and constants of one set of tables for some of the tiers (:data:`TIERS`),
made by :func:`lut_baker.closures.fitting.fit_closures`."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .lobes import LobeFit
from .profiles import ProfileFit
from .tier_registry import TIERS, tier

__all__ = ["TIERS", "ClosureFit", "SlabFit"]


@dataclass(frozen=True, eq=False)
class SlabFit:
    """What a fit to tables with the film as a slab adds (docs/model.md "The tiers at a
    thickness"): ``thickness_um`` (the thickness it was fitted at) and ``below`` (RGB, ``c``:
    the film's reflectance seen from the skin, the skin's diffuse light ``a t t / (1 - a c)``).
    The fit's ``transmittance_mean`` is then the slab's ``t`` averaged over uniform light and
    its ``film_albedo`` the film body's albedo under uniform light (its share of the gloss
    included: the Principled tier's base colour holds it).  ``skin_under`` (RGB, or
    None for 1): the skin's albedo under the film relative to Skin Color, where Match Skin
    darkens it (a sheer film whose gloss alone adds more than full absorption takes away,
    docs/model.md "Made-up skin at a thickness")."""

    thickness_um: float
    below: NDArray[np.float64]
    skin_under: NDArray[np.float64] | None = None


@dataclass(frozen=True, eq=False)
class ClosureFit:
    """Everything the node group needs from one set of tables (absorption 0), for the tiers it
    was fitted for (:attr:`tiers`; a tier's parts are None when it was not).

    All tiers: ``transmittance_mean`` (RGB, the cosine-weighted mean of T), ``film_albedo``
    and ``skin_albedo`` (RGB, ``pi P_d``), ``profiles`` (by method) and ``subsurface_method``
    (the best-fitting one, or the one forced), ``subsurface_ior`` (the dipole's index, for the
    random walk and the profile fits), ``errors`` of the fitted tiers at one coverage and
    absorption.  PRINCIPLED: ``coat`` (film gloss), ``specular_bare`` (skin gloss),
    ``specular_film`` (path-3 gloss under the coat), ``coat_albedo_mean``,
    ``specular_albedo_mean`` (bare, film): the cosine-weighted mean layering albedos;
    ``gloss_to_diffuse`` (RGB): the path-3 gloss albedo the base colour carries when no
    specular lobe fits it (else 0; with the film as a slab, what holds the covered skin's
    colour); ``bare_to_diffuse`` (RGB): what the base colour carries on bare skin so that its
    colour under uniform light is the tables' (None over the artist's shader, whose bare skin
    is theirs).  LAYERED: ``glossy`` (film_gloss, path3_gloss, skin_gloss:
    Glossy lobes with their weight rows) and ``view_rows`` (``(len(IMAGE_ROWS), size, 3)``: the
    view-angle image).  EEVEE: ``eevee_glossy`` (the same lobes, GGX as EEVEE renders it, the
    film gloss in two: ``film_gloss`` and ``film_gloss_2``) and ``eevee_view_rows`` (their
    view-angle image, rows :data:`lut_baker.closures.view_image.EEVEE_IMAGE_ROWS`); its
    subsurface is Burley's.  ``extra``: the parts of tiers registered beyond these, by tier
    (:mod:`lut_baker.closures.tier_registry`).  ``slab``: a :class:`SlabFit` when the tables
    hold the film as a slab (the tiers then shade it at the fit's thickness, absorption baked
    in), else None (the paper's film).

    A fit for a group over the artist's own shader (``fit_closures(..., over_shader=True)``),
    whose bare skin is that shader, leaves out the bare skin's gloss lobes (``specular_bare``
    of level 0, the ``skin_gloss`` lobes of error 1 and rows 0) and, with a forced method, the
    subsurface profiles (the radius is the artist's: ``profiles`` empty); its errors take the
    bare skin from the tables (:func:`lut_baker.closures.tiers.tier_reflection`).
    """

    transmittance_mean: NDArray[np.float64]
    film_albedo: NDArray[np.float64]
    skin_albedo: NDArray[np.float64]
    profiles: dict[str, ProfileFit]
    subsurface_method: str
    subsurface_ior: float
    coat: LobeFit | None = None
    specular_bare: LobeFit | None = None
    specular_film: LobeFit | None = None
    coat_albedo_mean: float | None = None
    specular_albedo_mean: tuple[float, float] | None = None
    gloss_to_diffuse: NDArray[np.float64] | None = None
    bare_to_diffuse: NDArray[np.float64] | None = None
    glossy: dict[str, LobeFit] | None = None
    view_rows: NDArray[np.float64] | None = None
    eevee_glossy: dict[str, LobeFit] | None = None
    eevee_view_rows: NDArray[np.float64] | None = None
    errors: dict[str, Any] = field(default_factory=dict)  # TierError by tier
    extra: dict[str, Any] = field(default_factory=dict)
    slab: SlabFit | None = None

    @property
    def tiers(self) -> tuple[str, ...]:
        """The tiers this fit holds the parts of, in :data:`TIERS` order."""
        return tuple(name for name in TIERS if tier(name).holds(self))

    @property
    def subsurface_radius_mm(self) -> NDArray[np.float64]:
        """The chosen method's Subsurface Radius x Scale per channel, mm."""
        return self.profiles[self.subsurface_method].radius_mm

    def summary(self) -> dict[str, Any]:
        """Plain data (floats and lists) for metadata, the panel and the docs: the fitted
        tiers' parts only."""
        out: dict[str, Any] = {}
        if self.coat is not None:
            out["coat"] = {"roughness": self.coat.roughness, "ior": self.coat.ior,
                           "level": self.coat.level, "error": self.coat.error}
            for name in ("specular_bare", "specular_film"):
                lobe = getattr(self, name)
                out[name] = {"roughness": lobe.roughness, "level": lobe.level,
                             "error": lobe.error}
        if self.glossy is not None:
            out["glossy"] = {name: {"roughness": lobe.roughness, "error": lobe.error,
                                    "distribution": lobe.distribution}
                             for name, lobe in self.glossy.items()}
        if self.eevee_glossy is not None:
            out["eevee_glossy"] = {name: {"roughness": lobe.roughness, "error": lobe.error}
                                   for name, lobe in self.eevee_glossy.items()}
        return {
            **out,
            "subsurface_method": self.subsurface_method,
            "subsurface_ior": self.subsurface_ior,
            "profiles": {name: {"radius_mm": p.radius_mm.tolist(), "error": p.error.tolist(),
                                "max_error": p.max_error.tolist()}
                         for name, p in self.profiles.items()},
            "errors": {name: asdict(e) for name, e in self.errors.items()},
            "tiers": list(self.tiers),
            **({"film_thickness_um": self.slab.thickness_um} if self.slab is not None else {}),
        }
