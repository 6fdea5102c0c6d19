"""Fitting Blender closures to baked tables: the fit that ties the lobes, the profiles and the
tiers together.

A Cycles shader sees the view direction but not the light's, so the add-on's tiers are
closures (replicated in :mod:`lut_baker.closures.cycles`) whose parameters are fitted to the
tables of :mod:`lut_baker.tables.table_set`, with weights that may depend on the view angle
through 1-D lookup images.  Everything is numpy only (it runs inside Blender, which ships no
scipy).

Tiers
-----
``PRINCIPLED``: one Principled BSDF.  Coat = the film's gloss (Coat Weight = coverage; none
for a film without gloss, or one no coat follows; Coat Roughness and Coat IOR fitted);
specular = the skin's gloss, bare or through the film (Roughness and Specular IOR Level
fitted per case, mixed by coverage); base colour = the diffuse albedo (film diffuse + skin seen
through the film, or bare skin), divided by the mean attenuation of the layers above it;
Subsurface Weight = the skin's share of it.
``LAYERED``: closures added with view-dependent weights: film gloss, path-3 gloss and skin gloss
(Glossy, roughness fitted, weight = table albedo / closure albedo read from a 1-D image by
``cos(theta_o)``; the film gloss shares its albedo with a Lambertian companion, its own row),
film diffuse plus that companion (one Diffuse), the skin through the film and bare
(Subsurface), mixed by coverage.
``EEVEE``: the LAYERED tier's closures and mix, made for EEVEE: every Glossy lobe is GGX (EEVEE
renders no other distribution) fitted to the tables as EEVEE renders it under a lamp, a
linearly transformed cosine (:mod:`lut_baker.closures.eevee`), the film's gloss as two such
lobes and the companion (:func:`~lut_baker.closures.lobes.fit_glossy_pair`), with its own
view-angle rows; subsurface Christensen-Burley (EEVEE's screen-space method).
The formulas of all three: :mod:`lut_baker.closures.tier_formulas`.

Where each part lives: the lobes :mod:`~lut_baker.closures.lobes`, the subsurface radii
:mod:`~lut_baker.closures.profiles`, the tiers' replicas and errors
:mod:`~lut_baker.closures.tiers`, the grids :mod:`~lut_baker.closures.view_grid`, the view-angle
image :mod:`~lut_baker.closures.view_image`.

- :func:`fit_closures` -- every fit of one set of tables, and the tiers' errors.
- :func:`subsurface_ior` -- the Subsurface IOR from the tables' parameters.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..numerics.quadrature import trapezoid_weights
from ..tables.table_set import Tables
from . import cycles as cc
from .closure_fit import ClosureFit
from .lobes import EEVEE_GLOSSY, fit_coat, fit_glossy, fit_glossy_pair, fit_specular
from .profiles import REPLICA_EDGE_ERROR, fit_profiles
from .tier_formulas import SPECULAR_IOR
from .tiers import tier_errors
from .view_grid import FIT_VIEWS, lobe_widths_deg, view_grid
from .view_image import DEFAULT_LUT_SIZE, EEVEE_LUT_ROWS, LUT_ROWS, lut_nodes

__all__ = ["fit_closures", "subsurface_ior"]



def _cosine_mean(values: np.ndarray, theta_deg: np.ndarray) -> np.ndarray:
    """``2 Int v(mu) mu dmu`` of a directional table ``(n_theta[, C])`` (its hemispherical
    cosine-weighted mean), trapezoid in ``mu``, held at its last value beyond ``theta_max``."""
    mu = np.cos(np.radians(np.asarray(theta_deg, float)))[::-1]
    values = np.asarray(values, float)[::-1]
    mu = np.concatenate([[0.0], mu])
    values = np.concatenate([values[:1], values])
    w = trapezoid_weights(mu)
    return 2.0 * np.tensordot(w * mu, values, axes=(0, 0))


def _view_mean(albedo_of) -> float:
    """``2 Int a(mu) mu dmu``: the cosine-weighted mean over view angles of ``albedo_of(mu)``
    (trapezoid on 33 view cosines)."""
    mu = np.linspace(0.0, 1.0, 33)
    return float(2.0 * np.sum(trapezoid_weights(mu) * mu * albedo_of(mu)))


def _coat_layering_mean(roughness: float, ior: float) -> float:
    """:func:`_view_mean` of the coat's layering albedo
    (:func:`lut_baker.closures.cycles.coat_view_terms`)."""
    return _view_mean(lambda mu: cc.coat_view_terms(mu, roughness, ior)[1])


def _layering_mean(roughness: float, ior: float, f0=None) -> float:
    """:func:`_view_mean` of :func:`lut_baker.closures.cycles.layering_albedo` (its largest
    channel)."""
    return _view_mean(lambda mu: np.max(
        np.atleast_2d(cc.layering_albedo(mu, roughness, ior, f0).T).T, axis=-1))


def subsurface_ior(parameters: dict) -> float:
    """The skin dipole's relative index (the Subsurface IOR) from tables' ``parameters``;
    1.4 (Blender's default) if they do not say.  Clamped to Cycles' [1.01, 3.8]."""
    dipole = parameters.get("dipole", {}) if isinstance(parameters, dict) else {}
    eta = float(np.mean(dipole.get("eta", 1.4)))
    return float(np.clip(eta, 1.01, 3.8))


def fit_closures(tables: Tables, *, lut_size: int = DEFAULT_LUT_SIZE,
                 subsurface_method: str | None = None, errors_at=None,
                 progress=None) -> ClosureFit:
    """Fit both tiers to ``tables`` and measure their errors at ``errors_at`` = ``(coverage,
    absorption)`` (default: those the tables were baked for).  ``subsurface_method``: force
    one (default: the method whose edge response, fitted error and replica error combined,
    is closest to the tables'; all three are fitted and reported).  ``progress(fraction,
    message)``: called as the fit advances (fraction 0..1).

    The film's gloss is fitted on a grid sized by its own lobe, the skin's gloss and path 3 on
    one sized by the skin's (:func:`lobe_widths_deg`, :func:`lut_baker.closures.view_grid.
    view_grid`), so the cost does not depend on how narrow either lobe is."""
    report = progress or (lambda fraction, message="": None)
    report(0.0, "fitting the Principled tier")
    widths = lobe_widths_deg(tables)
    film_grid = view_grid(widths["film_gloss"], FIT_VIEWS)
    skin_grid = view_grid(widths["skin_gloss"], FIT_VIEWS)
    film_gloss = tables.surface_gloss("film_gloss", *film_grid.directions)
    skin_gloss = tables.surface_gloss("skin_gloss", *skin_grid.directions)
    path3 = tables.angular("path3_gloss", *skin_grid.directions)

    coat = fit_coat(film_grid, film_gloss)
    e_coat = cc.coat_view_terms(skin_grid.cos_view, coat.roughness, coat.ior)[1]
    specular_bare = fit_specular(skin_grid, skin_gloss)
    specular_film = fit_specular(skin_grid, path3, attenuation=1.0 - e_coat)
    # The node group mixes the two roughnesses by coverage: a dropped lobe (level 0) takes the
    # other's, so that mixing never sharpens the remaining lobe.
    if specular_film.level == 0.0:
        specular_film = replace(specular_film, roughness=specular_bare.roughness)
    elif specular_bare.level == 0.0:
        specular_bare = replace(specular_bare, roughness=specular_film.roughness)

    theta_deg = np.asarray(tables.theta_deg, float)
    transmittance = np.asarray(tables.film_transmittance, float)
    mu = lut_nodes(lut_size)
    t_rows = np.stack([np.interp(np.degrees(np.arccos(mu)), theta_deg, transmittance[:, c])
                       for c in range(3)], -1)

    targets = {"film_gloss": (film_grid, film_gloss), "path3_gloss": (skin_grid, path3),
               "skin_gloss": (skin_grid, skin_gloss)}

    def lobe(name, closures):
        grid, table = targets[name]
        return fit_glossy(grid, table, np.asarray(getattr(tables, name + "_albedo")),
                          theta_deg, lut_size, companion=name == "film_gloss",
                          closures=closures)

    def image(lobes, rows):
        """The view-angle image of ``lobes``, rows named ``rows``."""
        found = {**{name: lobes[name].lut for name in lobes}, "film_transmittance": t_rows,
                 "film_gloss_diffuse": lobes["film_gloss"].diffuse_lut}
        if any(found.get(name) is None for name in rows):
            raise AssertionError("the lobes give every view-angle row")
        return np.stack([found[name] for name in rows])

    report(0.3, "fitting the Layered tier's gloss lobes")
    glossy = {name: lobe(name, cc.GLOSSY_DISTRIBUTIONS) for name in targets}
    lut = image(glossy, LUT_ROWS)
    report(0.45, "fitting the EEVEE tier's gloss lobes")
    # EEVEE draws GGX alone: the film's gloss takes two lobes and the companion.
    first, second = fit_glossy_pair(film_grid, film_gloss,
                                    np.asarray(tables.film_gloss_albedo), theta_deg, lut_size)
    eevee_glossy = {"film_gloss": first, "film_gloss_2": second,
                    **{name: lobe(name, (EEVEE_GLOSSY,)) for name in ("path3_gloss",
                                                                       "skin_gloss")}}
    eevee_lut = image(eevee_glossy, EEVEE_LUT_ROWS)
    coat_ior = coat.ior
    if coat_ior is None:
        raise AssertionError("fit_coat gives an IOR")

    report(0.6, "fitting the subsurface profile")
    ior = subsurface_ior(tables.parameters)
    profiles = fit_profiles(tables)
    if subsurface_method is None:
        subsurface_method = min(cc.SUBSURFACE_METHODS, key=lambda m: np.hypot(
            profiles[m].worst_error, REPLICA_EDGE_ERROR[m]))
    elif subsurface_method not in cc.SUBSURFACE_METHODS:
        raise ValueError(f"subsurface_method must be one of {cc.SUBSURFACE_METHODS}, "
                         f"got {subsurface_method!r}")

    def specular_mean(lobe):
        if lobe.level == 0.0:
            return 0.0
        f0 = float(cc.f0_from_ior(SPECULAR_IOR)) * 2.0 * lobe.level
        return _layering_mean(lobe.roughness, float(cc.ior_from_f0(f0)), f0)

    fit = ClosureFit(
        coat=coat,
        specular_bare=specular_bare,
        specular_film=specular_film,
        coat_albedo_mean=_coat_layering_mean(coat.roughness, coat_ior),
        specular_albedo_mean=(specular_mean(specular_bare), specular_mean(specular_film)),
        gloss_to_diffuse=(_cosine_mean(np.asarray(tables.path3_gloss_albedo), theta_deg)
                          if specular_film.level == 0.0 else np.zeros(3)),
        glossy=glossy,
        transmittance_mean=_cosine_mean(transmittance, theta_deg),
        film_albedo=np.pi * np.asarray(tables.film_diffuse, float),
        skin_albedo=np.pi * np.asarray(tables.skin_diffuse, float),
        profiles=profiles,
        subsurface_method=subsurface_method,
        subsurface_ior=ior,
        lut=lut,
        eevee_glossy=eevee_glossy,
        eevee_lut=eevee_lut,
    )
    if errors_at is None:
        errors_at = (float(tables.parameters.get("coverage", 1.0)),
                     tables.parameters.get("absorption", 0.0))
    report(0.8, "measuring the tiers' errors")
    fit = replace(fit, errors=tier_errors(fit, tables, *errors_at))
    report(1.0, "fitted")
    return fit
