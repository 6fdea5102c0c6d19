"""Fitting Blender closures to baked tables: the fit that ties the lobes, the profiles and the
tiers together.

Each tier of the registry (:mod:`lut_baker.closures.tier_registry`) fits its own parts
(:attr:`~lut_baker.closures.tier_registry.Tier.fit`; the built-in tiers' in
:mod:`~lut_baker.closures.tier_parts`); what every tier shares (the film's and the skin's
albedos, the mean transmittance, the subsurface profiles and method) is fitted here once, and
each tier's replica is measured against the tables (:func:`~lut_baker.closures.tiers.
tier_errors`).  Everything is numpy only (it runs inside Blender, which ships no scipy).

Where each part lives: the lobes :mod:`~lut_baker.closures.lobes`, the subsurface radii
:mod:`~lut_baker.closures.profiles`, the tiers' replicas and errors
:mod:`~lut_baker.closures.tiers`, the grids :mod:`~lut_baker.closures.view_grid`, the view-angle
image :mod:`~lut_baker.closures.view_image`.

- :func:`fit_closures` -- the fits of some tiers (default all) to one set of tables, or of
  more tiers onto a fit (over the artist's shader: without the bare skin's lobes), and their
  errors.
- :func:`subsurface_ior` -- the Subsurface IOR from the tables' parameters.
- :func:`at_thickness` -- a fit to the film as a slab moved to another thickness: its lobes
  kept, what depends on the thickness read from the slab's thickness axis (milliseconds).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..tables.table_set import Tables
from . import cycles as cc
from .closure_fit import ClosureFit, SlabFit
from .lobes import LobeFit
from .profiles import REPLICA_EDGE_ERROR, fit_profiles
from .tier_parts import FitTargets, cosine_mean, held_gloss_to_diffuse
from .tier_registry import TIERS, Tier, tier
from .tiers import tier_errors
from .view_image import DEFAULT_IMAGE_SIZE

__all__ = ["fit_closures", "subsurface_ior", "at_thickness"]


def subsurface_ior(parameters: dict[str, Any]) -> float:
    """The skin dipole's relative index (the Subsurface IOR) from tables' ``parameters``;
    1.4 (Blender's default) if they do not say.  Clamped to Cycles' [1.01, 3.8]."""
    dipole = parameters.get("dipole", {}) if isinstance(parameters, dict) else {}
    eta = float(np.mean(dipole.get("eta", 1.4)))
    return float(np.clip(eta, 1.01, 3.8))




def _subsurface(tables: Tables, method: str | None, over_shader: bool) -> dict[str, Any]:
    """The subsurface parts of a fit: the profiles and the method (``method`` forced, else the
    one whose edge response, fitted error and replica error combined, is closest to the
    tables'), the Subsurface IOR.  Over the artist's shader with a forced method no profile is
    fitted (the radius is the artist's)."""
    if method is not None and method not in cc.SUBSURFACE_METHODS:
        raise ValueError(f"subsurface_method must be one of {cc.SUBSURFACE_METHODS}, "
                         f"got {method!r}")
    ior = subsurface_ior(tables.parameters)
    profiles = {} if over_shader and method is not None else fit_profiles(tables)
    if method is None:
        method = min(cc.SUBSURFACE_METHODS, key=lambda m: np.hypot(
            profiles[m].worst_error, REPLICA_EDGE_ERROR[m]))
    return {"profiles": profiles, "subsurface_method": method, "subsurface_ior": ior}


def _film_parts(targets: FitTargets) -> dict[str, Any]:
    """What every tier shares of the film: its mean transmittance and diffuse albedo (the
    paper's film: ``T_mean`` and ``pi P_d``; the film as a slab at the fit's thickness: ``t``
    averaged over uniform light, the film body's albedo under uniform light and the
    :class:`SlabFit`)."""
    tables = targets.tables
    if targets.slab is None:
        return {"transmittance_mean": tables.film_transmittance_mean,
                "film_albedo": np.pi * np.asarray(tables.film_diffuse, float)}
    parts = targets.slab_parts(0.0)
    return {"transmittance_mean": np.asarray(parts.through_mean, float),
            "film_albedo": np.asarray(targets.base_mean(), float),
            "slab": SlabFit(thickness_um=float(targets.thickness_um),
                            below=np.asarray(parts.below, float))}


def _checked_tiers(tiers: Iterable[str]) -> tuple[Tier, ...]:
    """``tiers`` in :data:`TIERS` order (``ValueError`` for a name not in it)."""
    names = tuple(tiers)
    unknown = [name for name in names if name not in TIERS]
    if unknown:
        raise ValueError(f"tiers must be among {TIERS}, got {unknown}")
    return tuple(tier(name) for name in TIERS if name in names)


def _merged(parts: dict[str, Any], more: dict[str, Any]) -> dict[str, Any]:
    """``parts`` updated with a tier's ``more``; the registered tiers' ``extra`` parts merged
    by tier."""
    extra = {**parts.get("extra", {}), **more.get("extra", {})}
    return {**parts, **more, **({"extra": extra} if extra else {})}


def fit_closures(tables: Tables, *, tiers: Iterable[str] | None = None,
                 over_shader: bool = False, onto: ClosureFit | None = None,
                 image_size: int = DEFAULT_IMAGE_SIZE, subsurface_method: str | None = None,
                 errors_at: tuple[float, Any] | None = None,
                 skin_albedo: Any = None, preview: bool = False,
                 progress: Callable[..., object] | None = None) -> ClosureFit:
    """Fit the ``tiers`` (default: all of :data:`TIERS`) to ``tables`` and measure their
    errors at ``errors_at`` = ``(coverage, absorption)`` (default: those the tables were baked
    for).  ``subsurface_method``: force one (default: the method whose edge response, fitted
    error and replica error combined, is closest to the tables'; all three are fitted and
    reported).  ``over_shader``: for a group over the artist's own shader, which is the bare
    skin there: the bare skin's gloss lobes are not fitted nor, with a forced method, the
    subsurface profiles (:class:`ClosureFit`), and the errors take the bare skin from the
    tables.  ``onto``: a fit of the same tables, method and ``over_shader`` whose tiers are
    kept: only the others are fitted, and measured where its errors were.  ``skin_albedo``
    (RGB): the skin the film covers (the artist's mean skin under the film), at which the
    tiers are judged (the fit's Skin Color) and, with the film as a slab, the PRINCIPLED
    tier's colour held (:func:`~lut_baker.closures.tier_parts.held_gloss_to_diffuse`);
    default the tables' skin, ``pi P_d`` (a fit ``onto`` keeps its own).  ``preview``: the
    tables are a preview's, soon replaced by a refined fit: the Glossy weights' closure albedo
    by a coarser quadrature (:data:`~lut_baker.closures.lobes.PREVIEW_QUADRATURE`; every
    search to the same tolerance as at any resolution, so that the fit moves continuously with
    its data).
    ``progress(fraction, message)``: called as the fit advances (fraction 0..1).

    The film's gloss is fitted on a grid sized by its own lobe, the skin's gloss and path 3 on
    one sized by the skin's (:func:`lobe_widths_deg`, :func:`lut_baker.closures.view_grid.
    view_grid`), so the cost does not depend on how narrow either lobe is."""
    report = progress or (lambda fraction, message="": None)
    asked = _checked_tiers(TIERS if tiers is None else tiers)
    wanted = asked if onto is None else tuple(t for t in asked if t.name not in onto.tiers)
    targets = FitTargets(tables, image_size,
                         skin_albedo=onto.skin_albedo if onto is not None else skin_albedo,
                         preview=preview)
    parts: dict[str, Any] = {}
    total = sum(t.fit_share for t in wanted) or 1.0
    done = 0.0
    for each in wanted:
        report(0.8 * done / total, f"fitting the {each.label} tier")
        parts = _merged(parts, each.fit(targets, over_shader))
        done += each.fit_share
    if onto is not None:
        fit = replace(onto, **_merged({"extra": onto.extra}, parts))
        if onto.errors:
            first = next(iter(onto.errors.values()))
            errors_at = (first.coverage, first.absorption)
    else:
        report(0.75, "fitting the subsurface profile")
        fit = ClosureFit(
            **_film_parts(targets),
            skin_albedo=targets.skin_albedo,
            **_subsurface(tables, subsurface_method, over_shader), **parts)
    if errors_at is None:
        errors_at = (float(tables.parameters.get("coverage", 1.0)),
                     tables.parameters.get("absorption", 0.0))
    report(0.8, "measuring the tiers' errors")
    errors = {**(onto.errors if onto is not None else {}),
              **tier_errors(fit, tables, *errors_at, tiers=[t.name for t in wanted],
                            over_shader=over_shader)}
    fit = replace(fit, errors={name: errors[name] for name in TIERS if name in errors})
    report(1.0, "fitted")
    return fit



def _scaled_row(row: NDArray[np.float64], old: NDArray[np.float64],
                new: NDArray[np.float64]) -> NDArray[np.float64]:
    """A Glossy lobe's weight row whose target albedo goes from ``old`` to ``new`` (both at
    the texels, ``(size, 3)``): scaled texel by texel (the lobe's own albedo is unchanged);
    0 where the old albedo was."""
    return np.where(old > 0.0, row * new / np.where(old > 0.0, old, 1.0), 0.0)


def _film_gloss_scaled(lobe: LobeFit, ratio: NDArray[np.float64]) -> LobeFit:
    """The film's gloss lobe with its weight rows (and its Lambertian companion's) times
    ``ratio`` (RGB): the body's share of the gloss at another thickness."""
    return replace(lobe, weights=None if lobe.weights is None else lobe.weights * ratio,
                   diffuse_weights=(None if lobe.diffuse_weights is None
                                    else lobe.diffuse_weights * ratio))


def at_thickness(fit: ClosureFit, tables: Tables, thickness_um: float) -> ClosureFit:
    """``fit`` (of ``tables``, with the film as a slab) at another thickness, without fitting:
    the lobes' shapes (roughnesses, distributions, the film gloss's rows, the coat) kept, and
    what depends on the thickness read from the slab's axis (docs/model.md, "The tiers at a
    thickness"): the mean transmittance, ``c``, the film body's albedo and row, the
    transmittance row, the skin's gloss through the film (the Glossy rows of every tier with
    a view-angle image, :attr:`~lut_baker.closures.tier_registry.Tier.image`, and the
    Principled specular level scaled by its albedo's change; the Principled base colour's
    share held on the fit's skin, :func:`~lut_baker.closures.tier_parts.
    held_gloss_to_diffuse`), the film's gloss rows scaled by its weight's change (the body's
    share of the gloss; the Principled coat is kept).  The errors are not measured again
    (dropped).  Milliseconds: what a Thickness slider costs (``bench/slab_tiers.py``)."""
    if fit.slab is None:
        raise ValueError("a fit of the paper's film has no thickness")
    imaged = [(each, image) for each in map(tier, fit.tiers)
              if (image := each.image(fit)) is not None]
    size = imaged[0][1].texels.shape[1] if imaged else DEFAULT_IMAGE_SIZE
    old = FitTargets(tables, size, fit.slab.thickness_um, fit.skin_albedo)
    new = FitTargets(tables, size, thickness_um, fit.skin_albedo)
    theta = old.albedo_theta("path3_gloss")
    gloss_old, gloss_new = old.albedo("path3_gloss"), new.albedo("path3_gloss")
    changes: dict[str, Any] = {**_film_parts(new), "errors": {}}
    if fit.specular_film is not None and fit.coat is not None:
        specular = fit.specular_film
        if specular.level:
            ratio = (np.mean(cosine_mean(gloss_new, theta))
                     / max(float(np.mean(cosine_mean(gloss_old, theta))), 1e-300))
            specular = replace(specular, level=float(specular.level * ratio))
        changes["specular_film"] = specular
        changes["gloss_to_diffuse"] = held_gloss_to_diffuse(new, {
            "coat": fit.coat, "specular_film": specular,
            "coat_albedo_mean": fit.coat_albedo_mean,
            "specular_albedo_mean": fit.specular_albedo_mean})
    film_ratio = new.gloss_weight() / np.maximum(old.gloss_weight(), 1e-300)
    for each, image in imaged:
        if each.with_image is None:
            raise ValueError(f"the {each.label} tier's image cannot be moved to another "
                             f"thickness (it names no fields: Tier.with_image)")
        lobes = each.lobes(fit)
        path3 = lobes["path3_gloss"]
        if path3.weights is None:
            raise AssertionError("a tier's Glossy lobes with an image have their rows")
        lobes = {**lobes, "path3_gloss": replace(path3, weights=_scaled_row(
            path3.weights, old.texel_rows(theta, gloss_old), new.texel_rows(theta, gloss_new)))}
        lobes.update({name: _film_gloss_scaled(lobes[name], film_ratio)
                      for name in ("film_gloss", "film_gloss_2") if name in lobes})
        texels = np.array(image.texels)
        rows: dict[str, Any] = {"path3_gloss": lobes["path3_gloss"].weights,
                                "film_transmittance": new.transmittance_rows(),
                                "film_body": new.body_rows(),
                                **{name: lobes[name].weights
                                   for name in ("film_gloss", "film_gloss_2")
                                   if name in lobes and name in image.rows}}
        if lobes["film_gloss"].diffuse_weights is not None and "film_gloss_diffuse" in image.rows:
            rows["film_gloss_diffuse"] = lobes["film_gloss"].diffuse_weights
        for name, row in rows.items():
            texels[image.rows.index(name)] = row
        changes.update(each.with_image(lobes, texels))
    return replace(fit, **changes)
