"""The session's tables and closure fits, and what a fit measured, by bake key (no bpy).

A bake is named by its key (:func:`.storage.bake_key`: the made-up skin's parameters and the
resolution, hashed), which the same settings give on every machine and in every session; an
Apply that repeats a bake finds its group by that name and bakes, fits and hashes nothing.
What a fit measured at a coverage and absorption (the tiers' errors, what Gloss 0 would change,
the Auto tier's traits) is plain data that the group's record keeps (:mod:`.nodes`), so a
reopened file knows it too.

A fit holds the tiers it was asked for (Apply asks for those of the scene's engine,
:data:`lut_baker.auto_tier.ENGINE_TIERS`, and the settings' tier if it is fixed to another);
a tier asked for later is fitted then, onto the same fit.  A fit for a group over the artist's
shader is another fit (it leaves out the bare skin's lobes:
:func:`lut_baker.closures.fitting.fit_closures`).  The caches may be read and filled from a
worker thread (:mod:`.live`): nothing here touches bpy.

- :func:`baked` -- ``(tables, fit)`` of a bake record, baked and fitted once per session.
- :func:`cached` -- the same if this session has them, else None (never fits).
- :func:`measure` -- what a fit measures at a coverage and absorption, as plain data.
- :func:`measured_at` -- a stored measurement if it was taken at this coverage and absorption,
  of the tiers asked for.
- :func:`traits` -- the Auto tier's :class:`lut_baker.auto_tier.MaterialTraits` of one.
- :func:`clear` -- forget the session's bakes and fits.
"""

from __future__ import annotations

import math

from .core import auto_tier, cache, closure_fit, fitting, table_set, tiers
from .storage import rebake

__all__ = ["FIT_CACHE_SIZE", "baked", "cached", "measure", "measured_at", "traits", "clear"]

FIT_CACHE_SIZE = 8
"""Closure fits kept in this session, by bake key (with their tables, :mod:`.storage`)."""
_FITS = cache.LRUCache(FIT_CACHE_SIZE)
TOLERANCE = 1e-6
"""How close a coverage or an absorption must be to count as the same (the panel's sliders
store floats)."""


def _fit_key(record: dict, method, over_shader: bool) -> tuple:
    return (record["key"], method, bool(over_shader))


def cached(record: dict, method=None, *, tiers=closure_fit.TIERS, over_shader: bool = False
           ) -> tuple[table_set.Tables, closure_fit.ClosureFit] | None:
    """``(tables, fit)`` of ``record`` if this session baked and fitted them (``tiers`` among
    the fit's), else None."""
    fit = _FITS.get(_fit_key(record, method, over_shader))
    if fit is None or not set(tiers) <= set(fit.tiers):
        return None
    return rebake(record), fit


def baked(record: dict, *, method=None, tiers=closure_fit.TIERS, over_shader: bool = False,
          errors_at=None, bake_progress=None, fit_progress=None
          ) -> tuple[table_set.Tables, closure_fit.ClosureFit]:
    """``(tables, fit)`` of a bake record (:func:`.storage.bake_record`): re-baked (cached by
    :func:`.storage.rebake`) and fitted (cached here) once per session.  ``method``: a
    subsurface method forced by the user, else None; ``tiers``: those the fit must hold (a
    cached fit without some gets them fitted onto it); ``over_shader``: a fit for a group over
    the artist's shader; ``errors_at``: ``(coverage, absorption)`` at which a new fit measures
    the tiers (default: the bake's).

    Raises
    ------
    StorageError
        If the record cannot be baked (:func:`.storage.rebake`).
    """
    tables = rebake(record, progress=bake_progress)
    key = _fit_key(record, method, over_shader)
    fit = _FITS.get(key)
    if fit is None or not set(tiers) <= set(fit.tiers):
        fit = fitting.fit_closures(
            tables, tiers=tiers, over_shader=over_shader, onto=fit, subsurface_method=method,
            errors_at=errors_at, progress=fit_progress)
        _FITS.put(key, fit)
    return tables, fit


def _same(a, b) -> bool:
    a, b = list(a), list(b)
    return len(a) == len(b) and all(math.isclose(x, y, abs_tol=TOLERANCE)
                                    for x, y in zip(a, b, strict=True))


def measure(tables, fit, coverage: float, absorption, method=None, *,
            with_traits: bool = True, over_shader: bool = False) -> dict:
    """What ``fit`` measures at ``coverage`` and ``absorption`` (per channel), of the tiers it
    holds, as plain data: ``{"coverage", "absorption", "method", "errors": {tier: {"rms",
    "albedo"}}, "traits": MaterialTraits.as_dict() or None}`` (the traits, which hold the
    gloss omissions too, only ``with_traits``: the Auto tier's, about 10 ms a tier more).
    ``over_shader``: ``fit`` is for a group over the artist's shader.  The fit's own errors
    are reused when it was measured there."""
    coverage = float(coverage)
    absorption = [float(a) for a in absorption]
    errors = fit.errors
    first = next(iter(errors.values()), None)
    if first is None or not (_same([first.coverage], [coverage])
                             and _same(first.absorption, absorption)):
        errors = tiers.tier_errors(fit, tables, coverage, absorption, over_shader=over_shader)
    traits = auto_tier.traits_from_tables(tables, fit, coverage, absorption, method=method,
                                          errors=errors, over_shader=over_shader) \
        if with_traits else None
    return {"coverage": coverage, "absorption": absorption, "method": method,
            "errors": {tier: {"rms": float(e.rms), "albedo": float(e.albedo)}
                       for tier, e in errors.items()},
            "traits": None if traits is None else traits.as_dict()}


def measured_at(meta: dict, coverage: float, absorption, *, with_traits: bool = False,
                tiers=closure_fit.TIERS) -> dict | None:
    """The measurement a group's record keeps (``meta["measured"]``) if it was taken at this
    coverage and absorption (and holds the Auto tier's traits, ``with_traits``), else None.
    A measurement without the errors of every tier of ``tiers`` (default all: an older
    add-on's, before the EEVEE tier; one of another engine's tiers) is None too: it is
    measured again."""
    measured = meta.get("measured") if isinstance(meta, dict) else None
    if not isinstance(measured, dict) or (with_traits and not measured.get("traits")):
        return None
    if not set(tiers) <= set(measured.get("errors") or ()):
        return None
    if with_traits and not set(tiers) <= set(
            (measured["traits"] or {}).get("tier_errors") or ()):
        return None
    try:
        if _same([measured["coverage"]], [coverage]) and _same(measured["absorption"],
                                                              absorption):
            return measured
    except (KeyError, TypeError):
        return None
    return None


def traits(measured: dict):
    """The :class:`lut_baker.auto_tier.MaterialTraits` a measurement keeps, or None if they
    cannot be read."""
    try:
        return auto_tier.MaterialTraits.from_dict(measured["traits"])
    except (KeyError, TypeError, ValueError):
        return None


def clear() -> None:
    """Forget the session's fits (the add-on's unregister calls it with
    :func:`.storage.clear_cache`)."""
    _FITS.clear()
