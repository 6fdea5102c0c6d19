"""The session's bakes: a bake's key and record, its tables and closure fits in one cache, what
a fit measured, and :class:`Bake`, which makes them when first asked for (no bpy).

A bake is identified by its record (:func:`bake_record`): the made-up skin's parameters, the
resolution name and their key (:func:`bake_key`, a hash of those two and of the tables' format:
the same settings give the same key on any machine, without baking).  Baking is deterministic
and takes a fraction of a second, so the tables are re-baked from the record when Check Tables
or a re-fit needs them (:func:`rebake`) instead of travelling in every saved file; an Apply
that repeats a bake finds its group by the key (:mod:`.groups`) and bakes, fits and hashes
nothing.

One cache holds, per bake key, the tables and their closure fits (one per forced subsurface
method and kind of group: a fit for a group over the artist's shader leaves out the bare
skin's lobes, :func:`lut_baker.closures.fitting.fit_closures`).  A fit holds the tiers it was
asked for (Apply asks for those of the scene's engine, :data:`lut_baker.auto_tier.ENGINE_TIERS`,
and the settings' tier if it is fixed to another); a tier asked for later is fitted then, onto
the same fit.  What a fit measured at a coverage and absorption (the tiers' errors, what Gloss
0 would change, the Auto tier's traits) is plain data that the group's record keeps
(:mod:`.nodes`), so a reopened file knows it too.  The cache may be read and filled from a
worker thread (:mod:`.live`): nothing here touches bpy.

- :func:`bake_key`, :func:`bake_record`, :func:`record_key` -- a bake's key and record (the
  film as a slab: its thickness in the record; the slab's tables, baked at every thickness,
  shared by the records of every thickness, and a fit at a new thickness moved from the last
  one, :func:`lut_baker.closures.fitting.at_thickness`).
- :func:`rebake` -- the tables of a record, baked once per session (a preview's with the film
  as a slab at its thickness only, if asked, kept apart); :func:`remember` -- tables a caller
  baked itself, kept as the record's.
- :func:`baked` -- ``(tables, fit)`` of a record, baked and fitted once per session;
  :func:`cached` -- the same if this session has them, else None (never fits).
- :func:`measure` -- what a fit measures at a coverage and absorption, as plain data;
  :func:`measured_at` -- a stored measurement if it was taken there, of the tiers asked for;
  :func:`traits` -- the Auto tier's :class:`lut_baker.auto_tier.MaterialTraits` of one.
- :class:`Bake` -- one record's tables, fit and measurement, made when first asked for.
- :func:`clear` -- forget the session's bakes and fits.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from .core import auto_tier, bake, cache, closure_fit, fitting, params_file, table_set, tiers
from .progress import Report, Stages, stage

__all__ = ["BakeRecordError", "KEY_LENGTH", "CACHE_SIZE", "TOLERANCE", "BAKE_SHARE",
           "MEASURE_SHARE", "SLAB_TABLES", "RECORD_FIELDS", "bake_key", "bake_record",
           "record_key", "remember", "rebake", "baked", "cached",
           "measure", "measured_at", "traits", "Bake", "clear"]

KEY_LENGTH = 16
"""Hex digits of a bake key (64 bits: no two bakes of one file collide)."""
CACHE_SIZE = 8
"""Bakes (their tables and fits) kept in this session, by bake key."""
TOLERANCE = 1e-6
"""How close a coverage or an absorption must be to count as the same (the panel's sliders
store floats)."""
BAKE_SHARE = 0.15
"""Share of Apply's progress bar the bake takes (the closure fit and its measurement take the
rest)."""
MEASURE_SHARE = 0.85
"""Where on Apply's progress bar the fit ends and its measurement begins."""
SLAB_TABLES = "slab"
""":func:`bake_key`'s thickness for the slab's tables, shared by every thickness."""
RECORD_FIELDS = ("key", "parameters", "resolution", "film_thickness_um", "skin_under",
                 "skin_albedo")
"""A bake record's fields (the thickness, the skin under the film and the skin the fit is made
at only with the film as a slab)."""


class BakeRecordError(ValueError):
    """A bake record cannot be re-baked; the message says why, as a sentence's end."""


class _Entry:
    """One bake in the cache: its tables (None until baked), with the film as a slab its tables
    at the record's thickness only (``one``: a preview's, :func:`rebake`'s ``one_thickness``;
    kept apart: never handed out for the tables of the axis) and its fits by ``(forced
    method, over the artist's shader)`` (the same from either: the tables at one thickness
    equal the axis's there, :func:`lut_baker.bake.bake_slab`)."""

    def __init__(self) -> None:
        self.tables: table_set.Tables | None = None
        self.one: table_set.Tables | None = None
        self.fits: dict[tuple, closure_fit.ClosureFit] = {}

    def any_tables(self) -> table_set.Tables | None:
        """The tables of the axis if baked, else those at one thickness, else None."""
        return self.tables if self.tables is not None else self.one


_BAKES = cache.LRUCache(CACHE_SIZE)
_SLABS = cache.LRUCache(CACHE_SIZE)
"""The slab's tables by the key they share over thicknesses (:func:`_tables_key`)."""
_SLAB_FITS = cache.LRUCache(4 * CACHE_SIZE)
"""The last fit of the slab's tables per ``(shared key, skin albedo, forced method, over the
artist's shader)``: a fit at another thickness on the same skin moves from it
(:func:`lut_baker.closures.fitting.at_thickness`) instead of fitting again."""


def _entry(key: str) -> _Entry:
    """The cache's entry of bake ``key``, made empty if there is none."""
    entry = _BAKES.get(key)
    if entry is None:
        entry = _Entry()
        _BAKES.put(key, entry)
    return entry


def bake_key(parameters: dict, resolution: str, thickness_um: Any = None,
             skin_under: Any = None, skin_albedo: Any = None) -> str:
    """The key of a bake: SHA-256 (first :data:`KEY_LENGTH` hex digits) of the made-up skin's
    ``parameters`` (:func:`lut_baker.model.params_file.skin_to_dict`), the resolution name,
    the film's thickness (micrometres; None: the paper's film, whose keys are those of every
    earlier version; ``"slab"``: the slab's tables, whatever the thickness), the skin's albedo
    under the film relative to Skin Color where Match Skin darkened it (``skin_under``, RGB, or
    None), the skin the film covers where the fit is made at it (``skin_albedo``, RGB, or None:
    the skin preset's) and the tables' format version, as canonical JSON (floats by ``repr``:
    the same on every machine)."""
    version = table_set.FORMAT_VERSION
    data: dict[str, Any] = {"parameters": parameters, "resolution": str(resolution),
                            "format": version}
    if thickness_um is not None:
        data["film_thickness_um"] = (thickness_um if thickness_um == SLAB_TABLES
                                     else float(thickness_um))
    if skin_under is not None:
        data["skin_under"] = [float(u) for u in skin_under]
    if skin_albedo is not None:
        data["skin_albedo"] = [float(a) for a in skin_albedo]
    text = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:KEY_LENGTH]


def bake_record(skin: Any, resolution: str, film: Any = "paper",
                skin_under: Any = None, skin_albedo: Any = None) -> dict:
    """What identifies a bake: ``{"key", "parameters", "resolution"}`` and, for the film as a
    slab (``film`` a thickness in micrometres, :func:`.skin_model.film_of`),
    ``"film_thickness_um"``, where Match Skin darkened the skin under it ``"skin_under"``
    (:func:`.skin_model.skin_under_of`) and, where the skin the film covers is known (the
    artist's, :func:`.skin_model.skin_albedo_of`), ``"skin_albedo"``: the fit is made and
    judged there (plain data, no bake needed).  A slab's skin carries its absorption (the slab
    is baked at it)."""
    parameters = params_file.skin_to_dict(skin)
    thickness = None if film == "paper" else float(film)
    under = None if thickness is None or skin_under is None else [float(u)
                                                                  for u in skin_under]
    albedo = None if thickness is None or skin_albedo is None else [float(a)
                                                                    for a in skin_albedo]
    record: dict[str, Any] = {"key": bake_key(parameters, resolution, thickness, under,
                                              albedo),
                              "parameters": parameters, "resolution": str(resolution)}
    if thickness is not None:
        record["film_thickness_um"] = thickness
    if under is not None:
        record["skin_under"] = under
    if albedo is not None:
        record["skin_albedo"] = albedo
    return record


def record_key(record: dict) -> str:
    """The key a record's parameters, resolution, thickness, skin under the film and skin
    albedo give (:func:`bake_key`)."""
    return bake_key(record["parameters"], record["resolution"],
                    record.get("film_thickness_um"), record.get("skin_under"),
                    record.get("skin_albedo"))


def _tables_key(record: dict) -> str | None:
    """The key of the slab tables a slab record's bake shares with every other thickness
    (None for the paper's film)."""
    if record.get("film_thickness_um") is None:
        return None
    return bake_key(record["parameters"], record["resolution"], SLAB_TABLES)


def remember(record: dict, tables: table_set.Tables) -> None:
    """Keep ``tables`` as this session's bake of ``record`` (for a caller that baked them
    itself: tests and tools)."""
    _entry(record["key"]).tables = tables


def rebake(record: dict, *, progress: Report | None = None,
           one_thickness: bool = False) -> table_set.Tables:
    """The tables of a :func:`bake_record`, baked once per session (cached by key);
    ``progress(fraction, message)``: the bake's, when it runs.  ``one_thickness``: with the
    film as a slab, tables at the record's thickness will do (a preview Apply's: the slab baked
    there only, :func:`lut_baker.bake.bake`'s ``one_thickness``, unless the axis's are here
    already); they are kept apart from the axis's, which a Thickness move reads.

    Raises
    ------
    BakeRecordError
        If the record has no readable parameters or resolution, or its key is not theirs.
    """
    try:
        key = record_key(record)
    except (KeyError, TypeError, ValueError):
        raise BakeRecordError("its bake record cannot be read (a parameter or the resolution "
                              "is missing)") from None
    if key != record.get("key"):
        raise BakeRecordError("its bake record does not match its key (it was edited, or "
                              "written by another version)")
    entry = _entry(key)
    if entry.tables is not None:
        return entry.tables
    thickness = record.get("film_thickness_um")
    shared = _tables_key(record)
    slab = None if shared is None else _SLABS.get(shared)
    if slab is not None and thickness is not None:  # another thickness: the same bake
        entry.tables = dataclasses.replace(
            slab, parameters={**slab.parameters, "film_thickness_um": float(thickness)})
        return entry.tables
    one = one_thickness and thickness is not None
    if one and entry.one is not None:
        return entry.one
    try:
        skin = params_file.skin_from_dict(record["parameters"])
        tables = bake.bake(skin, record["resolution"], progress=progress,
                           film="paper" if thickness is None else float(thickness),
                           one_thickness=one)
    except (KeyError, TypeError, ValueError):
        raise BakeRecordError("its bake record cannot be re-baked (a parameter is missing or "
                              "unreadable)") from None
    if one:
        entry.one = tables
        return tables
    entry.tables = tables
    if shared is not None:
        _SLABS.put(shared, tables)
    return tables


def cached(record: dict, method: str | None = None, *,
           tiers: Iterable[str] = closure_fit.TIERS, over_shader: bool = False
           ) -> tuple[table_set.Tables, closure_fit.ClosureFit] | None:
    """``(tables, fit)`` of ``record`` if this session baked and fitted them (``tiers`` among
    the fit's), else None."""
    entry = _BAKES.get(record["key"])
    fit = None if entry is None else entry.fits.get((method, bool(over_shader)))
    if fit is None or not set(tiers) <= set(fit.tiers):
        return None
    tables = entry.any_tables()  # at the fit's thickness either will do
    return (rebake(record) if tables is None else tables), fit


def baked(record: dict, *, method: str | None = None,
          tiers: Iterable[str] = closure_fit.TIERS, over_shader: bool = False,
          errors_at: tuple[float, Sequence[float]] | None = None,
          bake_progress: Report | None = None, fit_progress: Report | None = None,
          one_thickness: bool = False) -> tuple[table_set.Tables, closure_fit.ClosureFit]:
    """``(tables, fit)`` of a bake record (:func:`bake_record`): re-baked (:func:`rebake`) and
    fitted once per session.  ``method``: a subsurface method forced by the user, else None;
    ``tiers``: those the fit must hold (a cached fit without some gets them fitted onto it);
    ``over_shader``: a fit for a group over the artist's shader; ``errors_at``: ``(coverage,
    absorption)`` at which a new fit measures the tiers (default: the bake's);
    ``one_thickness``: the tables at the record's thickness will do (:func:`rebake`).  A
    preview's tables are fitted as a preview (:func:`lut_baker.closures.fitting.
    fit_closures`'s ``preview``: the refine replaces the fit).

    Raises
    ------
    BakeRecordError
        If the record cannot be baked (:func:`rebake`).
    """
    fits = _entry(record["key"]).fits
    which = (method, bool(over_shader))
    fit = fits.get(which)
    tiers = tuple(tiers)
    shared = _tables_key(record)
    skin = record.get("skin_albedo")
    skin_key = None if skin is None else tuple(float(a) for a in skin)
    if fit is None and shared is not None:
        other = _SLAB_FITS.get((shared, skin_key, *which))
        if other is not None and set(tiers) <= set(other.tiers):
            tables = rebake(record, progress=bake_progress)  # the axis's: the fit moves on it
            fit = _under(fitting.at_thickness(other, tables,
                                              float(record["film_thickness_um"])), record)
            fits[which] = fit
            return tables, fit
    tables = rebake(record, progress=bake_progress, one_thickness=one_thickness)
    if fit is None or not set(tiers) <= set(fit.tiers):
        fit = _under(fitting.fit_closures(
            tables, tiers=tiers, over_shader=over_shader, onto=fit, subsurface_method=method,
            errors_at=errors_at, skin_albedo=skin, preview=record["resolution"] == "preview",
            progress=fit_progress), record)
        fits[which] = fit
        if shared is not None:
            _SLAB_FITS.put((shared, skin_key, *which), fit)
    return tables, fit


def _under(fit: closure_fit.ClosureFit, record: dict) -> closure_fit.ClosureFit:
    """A slab fit with the record's skin under the film (its errors then measured again:
    dropped)."""
    under = record.get("skin_under")
    if under is None or fit.slab is None:
        return fit
    return dataclasses.replace(fit, errors={}, slab=dataclasses.replace(
        fit.slab, skin_under=np.asarray(under, float)))


def _same(a: Iterable[float], b: Iterable[float]) -> bool:
    a, b = list(a), list(b)
    return len(a) == len(b) and all(math.isclose(x, y, abs_tol=TOLERANCE)
                                    for x, y in zip(a, b, strict=True))


PREVIEW_SPHERE_PX = 32
"""Pixels across the Auto tier's spheres (:func:`lut_baker.auto_tier.traits_from_tables`)
when the tables are at preview resolution (the settings' resolution: its default, 48)."""


def measure(tables: table_set.Tables, fit: closure_fit.ClosureFit, coverage: float,
            absorption: Iterable[float], method: str | None = None, *,
            with_traits: bool = True, over_shader: bool = False,
            resolution: str | None = None) -> dict:
    """What ``fit`` measures at ``coverage`` and ``absorption`` (per channel), of the tiers it
    holds, as plain data: ``{"coverage", "absorption", "method", "errors": {tier: {"rms",
    "albedo"}}, "traits": MaterialTraits.as_dict() or None}`` (the traits, which hold the
    gloss omissions too, only ``with_traits``: the Auto tier's, about 10 ms a tier more).
    ``over_shader``: ``fit`` is for a group over the artist's shader; ``resolution``: the
    tables' (at ``"preview"`` the traits' spheres are :data:`PREVIEW_SPHERE_PX` across).  The
    fit's own errors are reused when it was measured there."""
    coverage = float(coverage)
    absorption = [float(a) for a in absorption]
    errors = fit.errors
    first = next(iter(errors.values()), None)
    if first is None or not (_same([first.coverage], [coverage])
                             and _same(first.absorption, absorption)):
        errors = tiers.tier_errors(fit, tables, coverage, absorption, over_shader=over_shader)
    sphere_px = PREVIEW_SPHERE_PX if resolution == "preview" else auto_tier.SPHERE_PX
    traits = auto_tier.traits_from_tables(tables, fit, coverage, absorption, method=method,
                                          errors=errors, over_shader=over_shader,
                                          sphere_px=sphere_px) if with_traits else None
    return {"coverage": coverage, "absorption": absorption, "method": method,
            "errors": {tier: {"rms": float(e.rms), "albedo": float(e.albedo)}
                       for tier, e in errors.items()},
            "traits": None if traits is None else traits.as_dict()}


def measured_at(meta: dict, coverage: float, absorption: Iterable[float], *,
                with_traits: bool = False, tiers: Iterable[str] = closure_fit.TIERS
                ) -> dict | None:
    """The measurement a group's record keeps (``meta["measured"]``) if it was taken at this
    coverage and absorption (and holds the Auto tier's traits, ``with_traits``), else None.
    A measurement without the errors of every tier of ``tiers`` (default all: an older
    add-on's, before the EEVEE tier; one of another engine's tiers) is None too: it is
    measured again."""
    measured = meta.get("measured") if isinstance(meta, dict) else None
    if not isinstance(measured, dict) or (with_traits and not measured.get("traits")):
        return None
    tiers = set(tiers)
    if not tiers <= set(measured.get("errors") or ()):
        return None
    if with_traits and not tiers <= set((measured["traits"] or {}).get("tier_errors") or ()):
        return None
    try:
        if _same([measured["coverage"]], [coverage]) and _same(measured["absorption"],
                                                              absorption):
            return measured
    except (KeyError, TypeError):
        return None
    return None


def traits(measured: dict) -> auto_tier.MaterialTraits | None:
    """The :class:`lut_baker.auto_tier.MaterialTraits` a measurement keeps, or None if they
    cannot be read."""
    try:
        return auto_tier.MaterialTraits.from_dict(measured["traits"])
    except (KeyError, TypeError, ValueError):
        return None


class Bake:
    """One bake record's tables, fit and measurement, made when first asked for (a group that
    can be reused needs none of them): the fit of ``tiers`` for the forced subsurface
    ``method`` (None: the fit's choice), measured at ``coverage`` and ``absorption``, for a
    group over the artist's shader if ``over``.  ``progress``: Apply's (:class:`.progress.
    Stages`).  ``one_thickness``: with the film as a slab, tables at the record's thickness
    will do (a preview that a refinement follows: :func:`rebake`).  Nothing here touches bpy:
    a worker thread may make them (:mod:`.live`), and the group is built from them on the
    main thread (:mod:`.groups`)."""

    def __init__(self, record: dict, method: str | None, coverage: float,
                 absorption: Iterable[float], progress: Stages | None = None, *,
                 tiers: Iterable[str] = tiers.TIERS, over: bool = False,
                 one_thickness: bool = False):
        self.record, self.method = record, method
        self.one_thickness = bool(one_thickness)
        self.coverage, self.absorption = float(coverage), [float(a) for a in absorption]
        self.progress = progress
        self.tiers, self.over = tuple(tiers), bool(over)
        self._measured: dict | None = None
        self._fitted: tuple[table_set.Tables, closure_fit.ClosureFit] | None = None

    @property
    def key(self) -> str:
        """The bake's key."""
        return self.record["key"]

    def fitted(self, tier: str | None = None
               ) -> tuple[table_set.Tables, closure_fit.ClosureFit]:
        """``(tables, fit)`` (:func:`baked`), the fit holding :attr:`tiers` (and ``tier``,
        added to them if need be)."""
        if tier is not None and tier not in self.tiers:
            self.tiers = tuple(t for t in tiers.TIERS if t in {*self.tiers, tier})
        if self._fitted is None or not set(self.tiers) <= set(self._fitted[1].tiers):
            self._fitted = baked(
                self.record, method=self.method, tiers=self.tiers, over_shader=self.over,
                errors_at=(self.coverage, self.absorption),
                bake_progress=stage(self.progress, 0.0, BAKE_SHARE),
                fit_progress=stage(self.progress, BAKE_SHARE, MEASURE_SHARE),
                one_thickness=self.one_thickness)
        return self._fitted

    def adopt(self, measured: dict | None) -> None:
        """Take a measurement a group's record kept at this coverage and absorption."""
        if measured is not None:
            self._measured = measured

    def measured(self, *, with_traits: bool = False) -> dict:
        """What the fit measures at the coverage and absorption (baking and fitting if need
        be), the Auto tier's traits too if ``with_traits``."""
        if self._measured is None or (with_traits and not self._measured["traits"]):
            tables, fit = self.fitted()
            measured = measure(tables, fit, self.coverage, self.absorption,
                               self.method or fit.subsurface_method,
                               with_traits=with_traits, over_shader=self.over,
                               resolution=self.record.get("resolution"))
            self._measured = measured
            report = stage(self.progress, MEASURE_SHARE, 1.0)
            if report is not None:
                report(1.0, "measured")
            return measured
        return self._measured


def clear() -> None:
    """Forget the session's bakes and fits (the add-on's unregister calls it)."""
    _BAKES.clear()
    _SLABS.clear()
    _SLAB_FITS.clear()
