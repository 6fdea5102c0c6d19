"""Each built-in tier's parts of a closure fit, fitted to one set of tables: what the tier
registry's fits (:attr:`lut_baker.closures.tier_registry.Tier.fit`) return.

A Cycles shader sees the view direction but not the light's, so the tiers are closures
(replicated in :mod:`lut_baker.closures.cycles` and :mod:`lut_baker.closures.eevee`) whose
parameters are fitted to the tables, with weights that may depend on the view angle through
1-D lookup images (:mod:`lut_baker.closures.view_image`).

- :class:`FitTargets` -- what the lobes of one set of tables are fitted to, computed once.
- :func:`cosine_mean` -- a directional table's mean under uniform light.
- :func:`principled_parts` -- one Principled BSDF's coat and speculars.
- :func:`held_gloss_to_diffuse` -- with the film as a slab, what its base colour carries so
  that its colour under uniform light is the slab's on the skin the film covers.
- :func:`held_bare_to_diffuse` -- what its base colour carries on bare skin so that its bare
  skin's colour under uniform light is the tables' (the skin's gloss and diffuse albedo).
- :func:`layered_parts` -- Cycles' Glossy lobes and their view-angle image.
- :func:`eevee_parts` -- EEVEE's GGX lobes (the film's gloss in two) and their image.
- :func:`image_rows`, :data:`SLAB_ROWS` -- a tier's image rows, the film as a slab's included.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from dataclasses import replace
from functools import lru_cache
from typing import Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.geometry import polar_angle_deg
from ..numerics.quadrature import trapezoid_weights
from ..tables.slab_tables import SlabParts, SlabSlice, SlabTables, slab_colour
from ..tables.table_set import Tables
from . import cycles as cc
from .lobes import (
    EEVEE_GLOSSY,
    ROUGHNESS_RANGE,
    LobeFit,
    fit_coat,
    fit_glossy,
    fit_glossy_pair,
    fit_specular,
)
from .tier_formulas import SPECULAR_IOR
from .view_grid import FIT_VIEWS, ViewGrid, lobe_widths_deg, view_grid
from .view_image import EEVEE_IMAGE_ROWS, IMAGE_ROWS, texel_centres

__all__ = ["FitTargets", "cosine_mean", "principled_parts", "held_gloss_to_diffuse",
           "held_bare_to_diffuse", "layered_parts", "eevee_parts", "image_rows", "SLAB_ROWS"]

SLAB_ROWS = ("film_body",)
"""The view-angle rows a tier has beyond its own with the film as a slab: the film body's
directional albedo (its Diffuse closure's weight)."""

_T = TypeVar("_T")


def cosine_mean(values: ArrayLike, theta_deg: ArrayLike) -> NDArray[np.float64]:
    """``2 Int v(mu) mu dmu`` of a directional table ``(n_theta[, C])`` (its hemispherical
    cosine-weighted mean), trapezoid in ``mu``, held at its last value beyond ``theta_max``."""
    mu = np.cos(np.radians(np.asarray(theta_deg, float)))[::-1]
    table = np.asarray(values, float)[::-1]
    mu = np.concatenate([[0.0], mu])
    table = np.concatenate([table[:1], table])
    w = trapezoid_weights(mu)
    return 2.0 * np.tensordot(w * mu, table, axes=(0, 0))


def _view_mean(albedo_of: Callable[[NDArray[np.float64]], NDArray[np.float64]]) -> float:
    """``2 Int a(mu) mu dmu``: the cosine-weighted mean over view angles of ``albedo_of(mu)``
    (trapezoid on 33 view cosines)."""
    mu = np.linspace(0.0, 1.0, 33)
    return float(2.0 * np.sum(trapezoid_weights(mu) * mu * albedo_of(mu)))


def _coat_layering_mean(roughness: float, ior: float) -> float:
    """:func:`_view_mean` of the coat's layering albedo
    (:func:`lut_baker.closures.cycles.coat_view_terms`)."""
    return _view_mean(lambda mu: cc.coat_view_terms(mu, roughness, ior)[1])


def _layering_mean(roughness: float, ior: float, f0: ArrayLike | None = None) -> float:
    """:func:`_view_mean` of :func:`lut_baker.closures.cycles.layering_albedo` (its largest
    channel)."""
    return _view_mean(lambda mu: np.max(
        np.atleast_2d(cc.layering_albedo(mu, roughness, ior, f0).T).T, axis=-1))


class FitTargets:
    """What the lobes of one set of tables are fitted to, computed when first asked for: the
    grids sized by the film's and the skin's gloss (:func:`lobe_widths_deg`), the film's gloss,
    the skin's gloss and path 3 on them, the film's transmittance rows of the view-angle
    image.

    Tables with the film as a slab (``tables.slab``, docs/model.md "The tiers at a
    thickness") are fitted at their baked thickness (``thickness_um``): ``film_gloss`` is then
    the film surface's share of it (:func:`lut_baker.tables.slab_tables.surface_gloss`),
    ``path3_gloss`` the slab's ``top`` less the film's body (Lambertian in the Layered and EEVEE
    tiers' reading: ``alpha(theta_i) alpha(theta_o) / (pi alpha_mean)``, its directional albedo the
    film's ``alpha``), the skin's gloss through the film every order; the transmittance rows
    are the slab's ``t`` and the film's body has rows of its own (``film_body``).
    ``thickness_um``: another thickness than the baked one.  ``skin_albedo`` (RGB, diffuse
    albedo ``a``): the skin the film covers, where a fit is judged and its colour held (the
    artist's mean skin under the film; default the tables' skin, ``pi P_d``).  ``preview``:
    the tables are a preview's, which a refined fit soon replaces: the Glossy lobes' weights
    by a coarser closure albedo (the ``preview`` of :func:`~lut_baker.closures.lobes.
    fit_glossy`)."""

    def __init__(self, tables: Tables, image_size: int,
                 thickness_um: float | None = None,
                 skin_albedo: ArrayLike | None = None, *, preview: bool = False) -> None:
        self.tables, self.image_size = tables, image_size
        self.preview = bool(preview)
        self.theta_deg = np.asarray(tables.theta_deg, float)
        self.skin_albedo: NDArray[np.float64] = np.array(np.broadcast_to(np.asarray(
            np.pi * np.asarray(tables.skin_diffuse, float) if skin_albedo is None
            else skin_albedo, float), (3,)))
        self.slab: SlabTables | None = getattr(tables, "slab", None)
        if self.slab is None:
            self.thickness_um = 0.0
        else:
            self.thickness_um = float(tables.parameters["film_thickness_um"]
                                      if thickness_um is None else thickness_um)
        self._found: dict[Hashable, Any] = {}

    def _once(self, name: Hashable, compute: Callable[[], _T]) -> _T:
        if name not in self._found:
            self._found[name] = compute()
        return self._found[name]

    def grid(self, surface: str) -> ViewGrid:
        """The view grid sized by ``surface``'s gloss (``film_gloss`` or ``skin_gloss``)."""
        return self._once(("grid", surface), lambda: view_grid(
            lobe_widths_deg(self.tables)[surface], FIT_VIEWS))

    def slab_tables(self) -> SlabTables:
        """The tables' slab (``ValueError`` for the paper's film)."""
        if self.slab is None:
            raise ValueError("these tables hold the paper's film only")
        return self.slab

    def slab_slice(self) -> SlabSlice:
        """The slab's 1-D tables at the fit's thickness (made once)."""
        return self._once("slice", lambda: self.slab_tables().sliced(self.thickness_um))

    def slab_parts(self, theta_deg: ArrayLike) -> SlabParts:
        """The slab's 1-D parts at the fit's thickness and polar angles ``theta_deg``."""
        return self.slab_slice().at(theta_deg)

    def gloss_weight(self) -> NDArray[np.float64]:
        """The weight of eq. 2's gloss lobe (the tables' ``film_gloss``) the tiers draw as the
        film's gloss, RGB: the surface's share and, with the film as a slab, the body's at the
        fit's thickness (``SlabTables.body_gloss``)."""
        if self.slab is None:
            return np.ones(3)
        return self.slab.surface_share + self.slab_parts(0.0).body_gloss

    def body_albedo(self, theta_deg: ArrayLike) -> NDArray[np.float64]:
        """The film body's directional albedo without its share of the gloss (what its Diffuse
        closure draws), ``(..., 3)`` at ``theta_deg``: the film's own albedo less the body's
        gloss lobe's (slab only)."""
        found = self.slab_slice()
        lobe = self.tables.directional("film_gloss_albedo", theta_deg)
        return np.maximum(found.film_albedo_at(theta_deg) - found.tables.body_gloss * lobe,
                          0.0)

    def film_body(self, wi: NDArray[np.float64], wo: NDArray[np.float64],
                  film_gloss: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """The film's body as the tiers draw it (class docstring), 1/sr ``(..., 3)``: its
        share of the gloss (:meth:`gloss_weight`, the surface's left out) and the rest read
        Lambertian.  ``film_gloss``: the tables' ``film_gloss`` at ``(wi, wo)``, if already
        looked up."""
        def albedo(w: NDArray[np.float64]) -> NDArray[np.float64]:
            return self.body_albedo(polar_angle_deg(w))
        body_gloss = self.slab_slice().tables.body_gloss
        gloss = (self.tables.surface_gloss("film_gloss", wi, wo) if film_gloss is None
                 else film_gloss)
        return (albedo(wi) * albedo(wo) / (np.pi * np.maximum(self.film_mean(), 1e-12))
                + body_gloss * gloss)

    def film_mean(self) -> NDArray[np.float64]:
        """The film body's albedo under uniform light without its gloss (RGB): ``2 Int alpha
        mu dmu``."""
        theta = self.slab_tables().theta_deg
        return self._once("film_mean", lambda: cosine_mean(self.body_albedo(theta), theta))

    def coat_weight(self) -> NDArray[np.float64]:
        """The weight of eq. 2's gloss lobe the Principled tier's coat (achromatic) draws, RGB:
        the surface's share and, with the film as a slab, the body's share in its weakest
        channel (what absorption leaves in every channel)."""
        if self.slab is None:
            return np.ones(3)
        weight = self.slab.surface_share + np.min(self.slab_parts(0.0).body_gloss)
        return np.broadcast_to(weight, (3,))

    def base_mean(self) -> NDArray[np.float64]:
        """The film's own albedo under uniform light less what the coat draws of the body's
        gloss (RGB; slab only): what the Principled tier's base colour holds of the film."""
        theta = self.slab_tables().theta_deg
        lobe = self.tables.directional("film_gloss_albedo", theta)
        extra = (self.coat_weight() - self.slab_tables().surface_share) * lobe
        return cosine_mean(self.slab_parts(theta).film_albedo - extra, theta)

    def coat_target(self) -> tuple[ViewGrid, NDArray[np.float64]]:
        """``(grid, table)`` the Principled tier's coat is fitted to: the film's gloss at
        :meth:`coat_weight` (the rest of the body's gloss, coloured by absorption, is in the
        base colour, :meth:`base_mean`)."""
        if self.slab is None:
            return self.target("film_gloss")
        return self.grid("film_gloss"), self.coat_weight() * self.surface_on_grid("film_gloss")

    def surface_on_grid(self, name: str) -> NDArray[np.float64]:
        """The tables' surface gloss ``name`` (closed form) on :meth:`grid` of ``name``
        (once: the coat's target and the film gloss's share it)."""
        return self._once(("surface", name), lambda: self.tables.surface_gloss(
            name, *self.grid(name).directions))

    def target(self, name: str) -> tuple[ViewGrid, NDArray[np.float64]]:
        """``(grid, table)`` of a gloss part: ``film_gloss`` on the film's grid,
        ``path3_gloss`` and ``skin_gloss`` on the skin's."""
        def compute() -> tuple[ViewGrid, NDArray[np.float64]]:
            if name == "path3_gloss":
                grid = self.grid("skin_gloss")
                if self.slab is not None:
                    wi, wo = grid.directions
                    return grid, (self.slab.top_at(self.thickness_um, wi, wo)
                                  - self.film_body(wi, wo))
                return grid, self.tables.angular(name, *grid.directions)
            grid = self.grid(name)
            if name == "film_gloss" and self.slab is not None:
                return grid, self.gloss_weight() * self.surface_on_grid(name)
            return grid, self.surface_on_grid(name)
        return self._once(("target", name), compute)

    def albedo(self, name: str) -> NDArray[np.float64]:
        """A gloss part's directional albedo table ``(n_theta, 3)`` on
        :meth:`albedo_theta`."""
        if name == "path3_gloss" and self.slab is not None:
            parts = self.slab_parts(self.slab.theta_deg)
            return np.maximum(parts.top_albedo - parts.film_albedo, 0.0)
        if name == "film_gloss" and self.slab is not None:
            return self.gloss_weight() * np.asarray(self.tables.film_gloss_albedo, float)
        return np.asarray(getattr(self.tables, name + "_albedo"))

    def albedo_theta(self, name: str) -> NDArray[np.float64]:
        """The polar angles (degrees) :meth:`albedo`'s table is on."""
        if name == "path3_gloss" and self.slab is not None:
            return np.asarray(self.slab.theta_deg, float)
        return self.theta_deg

    def texel_rows(self, theta_deg: NDArray[np.float64],
                   values: NDArray[np.float64]) -> NDArray[np.float64]:
        """A directional table ``(n_theta, 3)`` on ``theta_deg`` at the image's texels."""
        mu = texel_centres(self.image_size)
        return np.stack([np.interp(np.degrees(np.arccos(mu)), theta_deg, values[:, c])
                         for c in range(3)], -1)

    def transmittance_rows(self) -> NDArray[np.float64]:
        """The film's transmittance at the view-angle image's texels, ``(size, 3)`` (the
        slab's ``t`` at its thickness)."""
        def compute() -> NDArray[np.float64]:
            if self.slab is not None:
                theta = np.asarray(self.slab.theta_deg, float)
                return self.texel_rows(theta, self.slab_parts(theta).through)
            return self.texel_rows(self.theta_deg, np.asarray(self.tables.film_transmittance,
                                                         float))
        return self._once("transmittance_rows", compute)

    def body_rows(self) -> NDArray[np.float64]:
        """The film body's directional albedo at the texels, ``(size, 3)`` (slab only)."""
        def compute() -> NDArray[np.float64]:
            theta = np.asarray(self.slab_tables().theta_deg, dtype=np.float64)
            return self.texel_rows(theta, self.body_albedo(theta))
        return self._once("body_rows", compute)


def _left_out_glossy(size: int) -> LobeFit:
    """A Glossy lobe left out (a fit over the artist's shader has no bare skin of its own):
    weights 0, error 1 (what leaving a lobe out errs)."""
    return LobeFit(roughness=ROUGHNESS_RANGE[1], error=1.0, weights=np.zeros((size, 3)))


def principled_parts(targets: FitTargets, over_shader: bool) -> dict[str, Any]:
    """The PRINCIPLED tier's parts of a :class:`ClosureFit`: the coat, the two speculars (over
    the artist's shader the bare one left out: level 0, and no ``bare_to_diffuse``), their
    mean layering albedos and what the base colour carries of the gloss the lobes miss."""
    film_grid, film_gloss = targets.coat_target()
    skin_grid, path3 = targets.target("path3_gloss")
    coat = fit_coat(film_grid, film_gloss)
    coat_ior = coat.ior
    if coat_ior is None:
        raise AssertionError("fit_coat gives an IOR")
    e_coat = cc.coat_view_terms(skin_grid.cos_view, coat.roughness, coat_ior)[1]
    specular_film = fit_specular(skin_grid, path3, attenuation=1.0 - e_coat)
    if over_shader:
        specular_bare = LobeFit(roughness=specular_film.roughness, ior=SPECULAR_IOR,
                                level=0.0, error=1.0)
    else:
        specular_bare = fit_specular(skin_grid, targets.target("skin_gloss")[1])
        # The node group mixes the two roughnesses by coverage: a dropped lobe (level 0) takes
        # the other's, so that mixing never sharpens the remaining lobe.
        if specular_film.level == 0.0:
            specular_film = replace(specular_film, roughness=specular_bare.roughness)
        elif specular_bare.level == 0.0:
            specular_bare = replace(specular_bare, roughness=specular_film.roughness)

    def specular_mean(lobe: LobeFit) -> float:
        if lobe.level == 0.0:
            return 0.0
        if lobe.level is None:
            raise AssertionError("fit_specular gives a level")
        f0 = float(cc.f0_from_ior(SPECULAR_IOR)) * 2.0 * lobe.level
        return _layering_mean(lobe.roughness, float(cc.ior_from_f0(f0)), f0)

    parts = {
        "coat": coat,
        "specular_bare": specular_bare,
        "specular_film": specular_film,
        "coat_albedo_mean": _coat_layering_mean(coat.roughness, coat_ior),
        "specular_albedo_mean": (specular_mean(specular_bare), specular_mean(specular_film)),
        "gloss_to_diffuse": (cosine_mean(targets.albedo("path3_gloss"),
                                          targets.albedo_theta("path3_gloss"))
                             if specular_film.level == 0.0 else np.zeros(3)),
    }
    if targets.slab is not None:
        parts["gloss_to_diffuse"] = held_gloss_to_diffuse(targets, parts)
    if not over_shader:
        parts["bare_to_diffuse"] = held_bare_to_diffuse(targets, parts)
    return parts


def held_gloss_to_diffuse(targets: FitTargets, parts: dict[str, Any]) -> NDArray[np.float64]:
    """With the film as a slab, the PRINCIPLED tier's ``gloss_to_diffuse`` (RGB): what its
    base colour carries so that, over the skin the film covers (``targets.skin_albedo``), its
    colour under uniform light is the slab's (docs/model.md, "The tiers at a thickness").

    Its specular and coat are white while the skin's gloss through the film is tinted by the
    film's absorption (and the coat's albedo is not quite the film gloss's): they err by a
    colour the same on any skin, so a relative error that grows as the skin darkens.  With
    ``parts``' coat and film specular (coverage 1) the Principled BSDF's colour is ``G + W
    base`` (:func:`lut_baker.closures.cycles.principled_uniform`); the base colour the node
    group makes is ``(skin + film + x) / D`` (``film`` the film's own albedo less what the coat
    draws, :meth:`FitTargets.base_mean`; ``D`` the mean attenuation it divides by,
    :func:`~lut_baker.closures.tier_formulas.principled_sockets`), so ``x = (E - G) D / W -
    skin - film``, ``E`` the slab's colour (:func:`lut_baker.tables.slab_tables.slab_colour`)."""
    coat, specular = parts["coat"], parts["specular_film"]
    gloss, passed = cc.principled_uniform(cc.PrincipledInputs(
        roughness=specular.roughness, ior=SPECULAR_IOR,
        specular_ior_level=float(specular.level), coat_weight=float(coat.level),
        coat_roughness=coat.roughness, coat_ior=float(coat.ior)))
    a = targets.skin_albedo
    exact = slab_colour(targets.tables, targets.thickness_um, skin_albedo=a)
    below = targets.slab_parts(0.0)
    skin = a * np.square(below.through_mean) / (1.0 - a * below.below)
    divided = ((1.0 - float(coat.level) * float(parts["coat_albedo_mean"]))
               * (1.0 - float(parts["specular_albedo_mean"][1])))
    return (exact - gloss) * divided / max(passed, 1e-12) - skin - targets.base_mean()


def held_bare_to_diffuse(targets: FitTargets, parts: dict[str, Any]) -> NDArray[np.float64]:
    """The PRINCIPLED tier's ``bare_to_diffuse`` (RGB): what its base colour carries on bare
    skin so that its bare skin's colour under uniform light is the tables' (the skin's gloss
    and its diffuse albedo: what Match Skin matches, docs/model.md "The tiers at a
    thickness").

    The bare specular is fitted to the skin gloss's shape (:func:`fit_specular`), not to its
    albedo: the preset skins' lobes came 0.009-0.010 above their gloss under uniform light, in
    every channel (a white lobe), whatever the skin's albedo or the film.  With ``parts``' bare
    specular the Principled BSDF's colour is ``G + W base``
    (:func:`lut_baker.closures.cycles.principled_uniform`), the base colour the node group
    makes at coverage 0 is ``(skin + x) / (1 - E)`` (``E`` the lobe's mean layering albedo,
    within 1e-4 of ``1 - W``), so ``x = (gloss - G) (1 - E) / W``: the same on any skin (the
    fit stays linear in the skin's albedo), which it leaves within ``W / (1 - E) - 1`` (2e-5)
    of its part."""
    lobe = parts["specular_bare"]
    gloss, passed = _specular_uniform(float(lobe.roughness), float(lobe.level))
    wanted = cosine_mean(targets.albedo("skin_gloss"), targets.albedo_theta("skin_gloss"))
    divided = 1.0 - float(parts["specular_albedo_mean"][0])
    return (wanted - gloss) * divided / max(passed, 1e-12)


@lru_cache(maxsize=16)
def _specular_uniform(roughness: float, level: float) -> tuple[NDArray[np.float64], float]:
    """:func:`lut_baker.closures.cycles.principled_uniform` of a specular alone (cached: a
    skin's bare lobe is the same under every foundation, some 20 ms each)."""
    gloss, passed = cc.principled_uniform(cc.PrincipledInputs(
        roughness=roughness, ior=SPECULAR_IOR, specular_ior_level=level))
    gloss.setflags(write=False)
    return gloss, passed


def image_rows(rows: tuple[str, ...], slab: bool) -> tuple[str, ...]:
    """A tier's view-angle image rows: ``rows``, and with the film as a slab the film body's
    (``film_body``)."""
    return rows + (SLAB_ROWS if slab else ())


def _image(targets: FitTargets, lobes: dict[str, LobeFit],
           rows: tuple[str, ...]) -> NDArray[np.float64]:
    """The view-angle image of ``lobes``, rows named ``rows`` (:func:`image_rows`)."""
    found = {**{name: lobes[name].weights for name in lobes},
             "film_transmittance": targets.transmittance_rows(),
             "film_gloss_diffuse": lobes["film_gloss"].diffuse_weights}
    rows = image_rows(rows, targets.slab is not None)
    if targets.slab is not None:
        found["film_body"] = targets.body_rows()
    stack = [row for name in rows if (row := found.get(name)) is not None]
    if len(stack) != len(rows):
        raise AssertionError("the lobes give every view-angle row")
    return np.stack(stack)


def _glossy(targets: FitTargets, name: str, closures: tuple[str, ...]) -> LobeFit:
    """:func:`fit_glossy` of one gloss part (the film's with its Lambertian companion)."""
    grid, table = targets.target(name)
    return fit_glossy(grid, table, targets.albedo(name), targets.albedo_theta(name),
                      targets.image_size, companion=name == "film_gloss",
                      closures=closures, preview=targets.preview)


def _view_weighted_lobes(targets: FitTargets, names: tuple[str, ...],
                         closures: tuple[str, ...], over_shader: bool) -> dict[str, LobeFit]:
    """Glossy lobes of ``names`` (over the artist's shader ``skin_gloss`` left out)."""
    return {name: (_left_out_glossy(targets.image_size) if over_shader and name == "skin_gloss"
                   else _glossy(targets, name, closures)) for name in names}


def layered_parts(targets: FitTargets, over_shader: bool) -> dict[str, Any]:
    """The LAYERED tier's parts: Cycles' Glossy lobes and their view-angle image."""
    glossy = _view_weighted_lobes(targets, ("film_gloss", "path3_gloss", "skin_gloss"),
                                  cc.GLOSSY_DISTRIBUTIONS, over_shader)
    return {"glossy": glossy, "view_rows": _image(targets, glossy, IMAGE_ROWS)}


def eevee_parts(targets: FitTargets, over_shader: bool) -> dict[str, Any]:
    """The EEVEE tier's parts: EEVEE's GGX lobes (the film's gloss two of them and the
    companion, :func:`fit_glossy_pair`) and their view-angle image."""
    film_grid, film_gloss = targets.target("film_gloss")
    first, second = fit_glossy_pair(film_grid, film_gloss, targets.albedo("film_gloss"),
                                    targets.theta_deg, targets.image_size)
    eevee_glossy = {"film_gloss": first, "film_gloss_2": second,
                    **_view_weighted_lobes(targets, ("path3_gloss", "skin_gloss"),
                                           (EEVEE_GLOSSY,), over_shader)}
    return {"eevee_glossy": eevee_glossy,
            "eevee_view_rows": _image(targets, eevee_glossy, EEVEE_IMAGE_ROWS)}
