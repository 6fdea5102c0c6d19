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
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import replace
from typing import Any

import numpy as np

from ..tables.table_set import Tables
from . import cycles as cc
from .closure_fit import ClosureFit, SlabFit
from .profiles import REPLICA_EDGE_ERROR, fit_profiles
from .tier_parts import FitTargets
from .tier_registry import TIERS, Tier, tier
from .tiers import tier_errors
from .view_image import DEFAULT_LUT_SIZE

__all__ = ["fit_closures", "subsurface_ior"]


def subsurface_ior(parameters: dict) -> float:
    """The skin dipole's relative index (the Subsurface IOR) from tables' ``parameters``;
    1.4 (Blender's default) if they do not say.  Clamped to Cycles' [1.01, 3.8]."""
    dipole = parameters.get("dipole", {}) if isinstance(parameters, dict) else {}
    eta = float(np.mean(dipole.get("eta", 1.4)))
    return float(np.clip(eta, 1.01, 3.8))




def _subsurface(tables: Tables, method: str | None, over_shader: bool) -> dict:
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


def _film_parts(targets: FitTargets) -> dict:
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
            "film_albedo": np.asarray(targets.film_mean(), float),
            "slab": SlabFit(thickness_um=float(targets.thickness_um),
                            below=np.asarray(parts.below, float))}


def _checked_tiers(tiers: Iterable[str]) -> tuple[Tier, ...]:
    """``tiers`` in :data:`TIERS` order (``ValueError`` for a name not in it)."""
    names = tuple(tiers)
    unknown = [name for name in names if name not in TIERS]
    if unknown:
        raise ValueError(f"tiers must be among {TIERS}, got {unknown}")
    return tuple(tier(name) for name in TIERS if name in names)


def _merged(parts: dict, more: dict) -> dict:
    """``parts`` updated with a tier's ``more``; the registered tiers' ``extra`` parts merged
    by tier."""
    extra = {**parts.get("extra", {}), **more.get("extra", {})}
    return {**parts, **more, **({"extra": extra} if extra else {})}


def fit_closures(tables: Tables, *, tiers: Iterable[str] | None = None,
                 over_shader: bool = False, onto: ClosureFit | None = None,
                 lut_size: int = DEFAULT_LUT_SIZE, subsurface_method: str | None = None,
                 errors_at: tuple[float, Any] | None = None,
                 progress: Callable[..., object] | None = None) -> ClosureFit:
    """Fit the ``tiers`` (default: all of :data:`TIERS`) to ``tables`` and measure their
    errors at ``errors_at`` = ``(coverage, absorption)`` (default: those the tables were baked
    for).  ``subsurface_method``: force one (default: the method whose edge response, fitted
    error and replica error combined, is closest to the tables'; all three are fitted and
    reported).  ``over_shader``: for a group over the artist's own shader, which is the bare
    skin there: the bare skin's gloss lobes are not fitted nor, with a forced method, the
    subsurface profiles (:class:`ClosureFit`), and the errors take the bare skin from the
    tables.  ``onto``: a fit of the same tables, method and ``over_shader`` whose tiers are
    kept: only the others are fitted, and measured where its errors were.
    ``progress(fraction, message)``: called as the fit advances (fraction 0..1).

    The film's gloss is fitted on a grid sized by its own lobe, the skin's gloss and path 3 on
    one sized by the skin's (:func:`lobe_widths_deg`, :func:`lut_baker.closures.view_grid.
    view_grid`), so the cost does not depend on how narrow either lobe is."""
    report = progress or (lambda fraction, message="": None)
    asked = _checked_tiers(TIERS if tiers is None else tiers)
    wanted = asked if onto is None else tuple(t for t in asked if t.name not in onto.tiers)
    targets = FitTargets(tables, lut_size)
    parts: dict = {}
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
            skin_albedo=np.pi * np.asarray(tables.skin_diffuse, float),
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
