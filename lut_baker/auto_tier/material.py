"""What the Auto tier needs to know of a made-up material.

- :class:`MaterialTraits` -- the tiers' angular errors, the skin's profile, the shares of gloss
  and of spreading skin light, the gloss each tier leaves out at Gloss 0.
- :func:`traits_from_tables` -- a material's traits from its tables and closure fit (with the
  film as a slab, the slab's made-up skin and parts at the fit's thickness);
  :func:`paper_traits` -- the paper preset's (measured, :mod:`.measured`), assumed before a
  material has tables.
- :func:`profile_mean_radius_mm`, :func:`gloss_and_skin_shares`, :func:`gloss_omission_error`,
  :func:`gloss_omissions`, :func:`profile_mismatch` -- the traits' parts.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property, lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..bake import RESOLUTIONS, profile_radius
from ..closures.closure_fit import ClosureFit
from ..closures.cycles import DirectionPairs
from ..closures.profiles import edge_response, profile_grid
from ..closures.tier_parts import FitTargets
from ..closures.tiers import (
    TierError,
    reference_reflection,
    slab_bare,
    slab_lookup_of,
    tier_errors,
    tier_reflection,
)
from ..model.dipole import dipole_profile, dipole_total_reflectance
from ..model.made_up_skin import combine, coverage_weights, mix_slots
from ..model.presets import made_up_skin
from ..numerics.geometry import sphere_directions
from ..numerics.quadrature import trapezoid_weights
from ..tables.slab_tables import SlabLookup
from ..tables.table_set import ReflectionParts, Tables, radius_nodes
from .measured import by_number, load

__all__ = ["MaterialTraits", "traits_from_tables", "paper_traits", "profile_mean_radius_mm",
           "gloss_and_skin_shares", "gloss_omission_error", "gloss_omissions",
           "profile_mismatch", "SHARE_LIGHTS_DEG", "TRAITS_COMMAND", "PAPER_TIER_ERRORS",
           "PAPER_MISMATCH", "PAPER_SKIN_SHARE", "PAPER_GLOSS_SHARE", "PAPER_GLOSS_OMISSION",
           "SPHERE_PX"]


@dataclass(frozen=True, eq=False)
class MaterialTraits:
    """What the Auto tier needs of a made-up material at its coverage and absorption.

    ``tier_errors``: angular relative RMS per tier (:func:`lut_baker.closures.tiers.tier_errors`);
    ``radius_mm``, ``profile``: the normalised radial profile ``R(d)/Rd`` (1/mm^2, ``(n, 3)``)
    on distances (mm), the tables' ``radius_mm`` and ``profile``; ``profile_mismatch``: the
    fitted closure's relative edge-response error (:func:`profile_mismatch`);
    ``skin_share``, ``gloss_share``: per light angle (degrees), the share of the image that
    spreads under the skin and that the gloss lobes make (:func:`gloss_and_skin_shares`);
    ``subsurface_scale``, ``gloss_scale``: the artist's Subsurface Scale and Gloss (the
    group's inputs); ``gloss_omission``: per tier, per light angle, what Gloss 0 changes in
    a sphere's image (:func:`gloss_omissions`; None: ``gloss_share`` stands in for it).
    """

    tier_errors: dict[str, float]
    radius_mm: NDArray[np.float64]
    profile: NDArray[np.float64]
    profile_mismatch: float
    skin_share: dict[float, float]
    gloss_share: dict[float, float]
    subsurface_scale: float = 1.0
    gloss_omission: dict[str, dict[float, float]] | None = None
    gloss_scale: float = 1.0

    def share(self, name: str, light_deg: float) -> float:
        """``skin_share`` or ``gloss_share`` at a light angle (linear between the stored
        angles, held beyond them)."""
        return _at_angle(getattr(self, name), light_deg)

    def gloss_error(self, tier: str, light_deg: float) -> float:
        """What leaving out the gloss lobes changes in a sphere's image lit ``light_deg`` from
        the view: ``gloss_omission`` of ``tier`` if known, else ``gloss_share``."""
        if self.gloss_omission and tier in self.gloss_omission:
            return _at_angle(self.gloss_omission[tier], light_deg)
        return self.share("gloss_share", light_deg)

    def scaled(self, subsurface_scale: float, gloss_scale: float | None = None
               ) -> MaterialTraits:
        """The same material with the artist's Subsurface Scale (distances multiplied) and
        Gloss (default: unchanged)."""
        return replace(self, subsurface_scale=float(subsurface_scale),
                       gloss_scale=self.gloss_scale if gloss_scale is None
                       else float(gloss_scale))

    @property
    def mean_radius_mm(self) -> float:
        """:func:`profile_mean_radius_mm` with the Subsurface Scale applied."""
        return self.subsurface_scale * profile_mean_radius_mm(self.radius_mm, self.profile)

    def as_dict(self) -> dict[str, Any]:
        """Plain data (floats, lists, string keys), for a file; :meth:`from_dict` reads it."""
        def by_angle(table: Mapping[float, float]) -> dict[str, float]:
            return {repr(float(angle)): float(value) for angle, value in table.items()}

        return {
            "tier_errors": {tier: float(e) for tier, e in self.tier_errors.items()},
            "radius_mm": np.asarray(self.radius_mm, float).tolist(),
            "profile": np.asarray(self.profile, float).tolist(),
            "profile_mismatch": float(self.profile_mismatch),
            "skin_share": by_angle(self.skin_share),
            "gloss_share": by_angle(self.gloss_share),
            "subsurface_scale": float(self.subsurface_scale),
            "gloss_omission": None if self.gloss_omission is None else {
                tier: by_angle(table) for tier, table in self.gloss_omission.items()},
            "gloss_scale": float(self.gloss_scale),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> MaterialTraits:
        """The traits :meth:`as_dict` wrote (``KeyError``, ``TypeError`` or ``ValueError``
        when an entry is missing or malformed)."""
        def by_angle(table: Mapping[str, Any]) -> dict[float, float]:
            return {float(angle): float(value) for angle, value in table.items()}

        omission = data["gloss_omission"]
        return cls(
            tier_errors={str(tier): float(e) for tier, e in data["tier_errors"].items()},
            radius_mm=np.asarray(data["radius_mm"], float),
            profile=np.asarray(data["profile"], float),
            profile_mismatch=float(data["profile_mismatch"]),
            skin_share=by_angle(data["skin_share"]),
            gloss_share=by_angle(data["gloss_share"]),
            subsurface_scale=float(data["subsurface_scale"]),
            gloss_omission=None if omission is None else {
                str(tier): by_angle(table) for tier, table in omission.items()},
            gloss_scale=float(data["gloss_scale"]),
        )


def _at_angle(table: Mapping[float, float], light_deg: float) -> float:
    """A per-light-angle table at ``light_deg`` (linear between its angles, held beyond)."""
    angles = sorted(table)
    return float(np.interp(light_deg, angles, [table[a] for a in angles]))


def profile_mean_radius_mm(radius_mm: ArrayLike, profile: ArrayLike) -> float:
    """Mean distance (mm) between where light enters and leaves: ``Int d P(d) 2 pi d dd`` of
    the normalised profile ``P = R/Rd`` (largest over channels)."""
    d = np.asarray(radius_mm, float)
    p = np.reshape(np.asarray(profile, float), (d.size, -1))
    w = trapezoid_weights(d)
    mass = w @ (p * (2.0 * np.pi * d)[:, None])
    mean = w @ (p * (2.0 * np.pi * d * d)[:, None])
    return float(np.max(mean / np.maximum(mass, 1e-300)))


@dataclass
class _Sphere:
    """A sphere's lit pixels under one distant light (orthographic, the reference's
    framing): their directions, ``cos(theta_i)`` ``(N, 1)``, the tables' lookups there (made
    once for the total, the bare skin and the shares: with the film as a slab the slab's,
    ``lookup``, :func:`lut_baker.closures.tiers.slab_lookup_of`, and the paper's tables',
    :meth:`lut_baker.tables.table_set.Tables.reflection_parts`, only when asked for) and the
    tables' radiance ``f cos(theta_i)`` at a coverage and absorption, with its RMS ``norm``;
    each tier's image rows read at the pixels (:meth:`rows_read`) are shared by its replicas
    there."""

    wi: NDArray[np.float64]
    wo: NDArray[np.float64]
    cos_i: NDArray[np.float64]
    total: NDArray[np.float64]
    norm: float
    lookup: SlabLookup | None = None
    _parts: ReflectionParts | None = None
    _bare: NDArray[np.float64] | None = None
    _rows: dict[str, dict[str, NDArray[np.float64]]] = field(default_factory=dict)

    @cached_property
    def pairs(self) -> DirectionPairs:
        """The pixels' :class:`lut_baker.closures.cycles.DirectionPairs` (the replicas' lobes
        share their cosines)."""
        return DirectionPairs(self.wi, self.wo)

    def rows_read(self, tier: str) -> dict[str, NDArray[np.float64]]:
        """Tier ``tier``'s image rows read at the pixels, by name (filled by its replicas:
        :func:`lut_baker.closures.tiers.tier_replica`'s ``read``)."""
        return self._rows.setdefault(tier, {})

    def parts(self, tables: Tables) -> ReflectionParts:
        """The tables' lookups at the pixels (made once)."""
        if self._parts is None:
            self._parts = tables.reflection_parts(self.wi, self.wo)
        return self._parts

    def bare(self, tables: Tables, absorption: ArrayLike,
             fit: ClosureFit | None = None) -> NDArray[np.float64]:
        """The bare skin's BRDF at the pixels (computed once): with the film as a slab the
        slab fit's (:func:`lut_baker.closures.tiers.slab_bare`, from the sphere's lookups),
        else the tables'."""
        if self._bare is None:
            if self.lookup is not None and fit is not None and fit.slab is not None:
                self._bare = slab_bare(fit, tables, (self.wi, self.wo), self.lookup)
            else:
                self._bare = tables.mixed_reflection(self.parts(tables), 0.0, absorption)
        return self._bare


def _sphere(tables: Tables, light_deg: float, w: float, a: ArrayLike, resolution: int,
            fit: ClosureFit | None = None) -> _Sphere:
    """A sphere's pixels under one light (the tables' lookups kept for the shares); with a
    slab ``fit`` its made-up skin is the slab's at the fit's thickness
    (:func:`lut_baker.closures.tiers.reference_reflection`)."""
    _, wi, wo = sphere_directions(resolution, light_deg)
    cos_i = wi[:, 2:3]
    if fit is None or fit.slab is None:
        sphere = _Sphere(wi, wo, cos_i, np.zeros(0), 0.0)
        reflection = tables.mixed_reflection(sphere.parts(tables), w, a)
    else:
        sphere = _Sphere(wi, wo, cos_i, np.zeros(0), 0.0,
                         lookup=slab_lookup_of(fit, tables, (wi, wo)))
        reflection = reference_reflection(fit, tables, w, a, (wi, wo), sphere.lookup)
    sphere.total = reflection * cos_i
    sphere.norm = float(np.sqrt(np.mean(sphere.total**2)))
    return sphere


def _shares(tables: Tables, sphere: _Sphere, w: float, a: ArrayLike) -> tuple[float, float]:
    """:func:`gloss_and_skin_shares` on a sphere's pixels (its lookups reused)."""
    cos_i, parts = sphere.cos_i, sphere.parts(tables)
    looked_up = parts.angular
    weights = coverage_weights(w, a)
    gloss = combine(weights, **mix_slots(film_gloss=looked_up["film_gloss"],
                                         path3_gloss=looked_up["path3_gloss"],
                                         skin_gloss=looked_up["skin_gloss"])) * cos_i
    t_i, t_o = parts.t_i, parts.t_o
    skin = combine(weights, **mix_slots(through_film=tables.skin_diffuse * t_i * t_o,
                                        skin=tables.skin_diffuse)) * cos_i
    norm = sphere.norm
    if not norm > 0:
        return 0.0, 0.0
    return float(np.sqrt(np.mean(gloss**2)) / norm), float(np.sqrt(np.mean(skin**2)) / norm)


def _slab_shares(tables: Tables, fit: ClosureFit, sphere: _Sphere, w: float,
                 targets: FitTargets | None = None) -> tuple[float, float]:
    """:func:`_shares` with the film as a slab at the fit's thickness (docs/model.md, "The
    tiers at a thickness"): the gloss is the film's (its surface's and its body's share of
    eq. 2's lobe), the skin's gloss through the film (``top`` less the film's body) and the bare
    skin's; what spreads is the skin's
    diffuse light ``a t t / (pi (1 - a c))`` and the bare skin's.  The sphere's slab lookups
    are reused; ``targets``: the slab's :class:`FitTargets` at the fit's thickness, if
    made (shared by the spheres)."""
    wi, wo, cos_i = sphere.wi, sphere.wo, sphere.cos_i
    slab = fit.slab
    if slab is None:
        raise ValueError("the fit holds no slab: use the paper film's shares")
    h = slab.thickness_um
    targets = FitTargets(tables, 2, h) if targets is None else targets
    found = sphere.lookup if sphere.lookup is not None else \
        slab_lookup_of(fit, tables, (wi, wo))
    weights = coverage_weights(w, 0.0)
    through_gloss = found.top - targets.film_body(wi, wo, found.film_gloss)
    film_gloss = targets.gloss_weight() * found.film_gloss
    gloss = combine(weights, **mix_slots(film_gloss=film_gloss,
                                         path3_gloss=through_gloss,
                                         skin_gloss=found.skin_gloss)
                    ) * cos_i
    albedo = np.asarray(fit.skin_albedo, float)
    under = albedo * (1.0 if slab.skin_under is None else np.asarray(slab.skin_under, float))
    skin = combine(weights, **mix_slots(
        through_film=under * found.through_i * found.through_o
        / (np.pi * (1.0 - under * slab.below)),
        skin=albedo / np.pi)) * cos_i
    norm = sphere.norm
    if not norm > 0:
        return 0.0, 0.0
    return float(np.sqrt(np.mean(gloss**2)) / norm), float(np.sqrt(np.mean(skin**2)) / norm)


SPHERE_PX = 48
"""Pixels across the spheres the shares and gloss omissions are measured on by default."""


def gloss_and_skin_shares(tables: Tables, light_deg: float, coverage: float | None = None,
                          absorption: ArrayLike | None = None, *,
                          resolution: int = SPHERE_PX) -> tuple[float, float]:
    """``(gloss share, skin share)`` of a sphere's image under one distant light
    ``light_deg`` from the view (orthographic, the reference's framing): relative RMS over
    the lit pixels of the gloss lobes' radiance (film, path-3 and skin gloss at the coverage
    and absorption) and of the skin's diffuse part (what spreads), against the total radiance
    ``f cos(theta_i)`` from the tables."""
    w, a = tables.coverage_and_absorption(coverage, absorption)
    return _shares(tables, _sphere(tables, light_deg, w, a, resolution), w, a)


def _omission(tables: Tables, fit: ClosureFit, tier: str, sphere: _Sphere, w: float,
              a: ArrayLike, over_shader: bool) -> float:
    """:func:`gloss_omission_error` on a sphere's pixels."""
    norm = sphere.norm
    if not norm > 0:
        return 0.0
    bare = sphere.bare(tables, a, fit) if over_shader else None
    kept, left_out = (tier_reflection(fit, tables, tier, w, a, gloss, (sphere.wi, sphere.wo),
                                      over_shader=over_shader, bare=bare, pairs=sphere.pairs,
                                      read=sphere.rows_read(tier))
                      for gloss in (1.0, 0.0))
    return float(np.sqrt(np.mean(((kept - left_out) * sphere.cos_i) ** 2)) / norm)


def gloss_omission_error(tables: Tables, fit: ClosureFit, tier: str, light_deg: float,
                         coverage: float | None = None, absorption: ArrayLike | None = None,
                         *, resolution: int = SPHERE_PX,
                         over_shader: bool = False) -> float:
    """Relative RMS change of a sphere's image (orthographic, one distant light ``light_deg``
    from the view, the lit pixels) when ``tier``'s Gloss input goes from 1 to 0: the tier's
    replica (:func:`lut_baker.closures.tiers.tier_reflection` with the closure fit ``fit``;
    ``over_shader``: the bare skin the artist's, which Gloss leaves alone) with and without
    its gloss lobes, over the RMS of the tables' radiance ``f cos(theta_i)``, at the coverage
    and absorption (default: the tables')."""
    w, a = tables.coverage_and_absorption(coverage, absorption)
    return _omission(tables, fit, tier, _sphere(tables, light_deg, w, a, resolution), w, a,
                     over_shader)


def gloss_omissions(tables: Tables, fit: ClosureFit, coverage: float | None = None,
                    absorption: ArrayLike | None = None, *,
                    lights_deg: Iterable[float] | None = None,
                    tiers: Iterable[str] | None = None,
                    over_shader: bool = False) -> dict[str, dict[float, float]]:
    """:func:`gloss_omission_error` of ``tiers`` (default: every tier ``fit`` holds) at
    ``lights_deg`` (default :data:`SHARE_LIGHTS_DEG`): ``{tier: {light angle: error}}``."""
    lights = SHARE_LIGHTS_DEG if lights_deg is None else lights_deg
    w, a = tables.coverage_and_absorption(coverage, absorption)
    tiers = tuple(fit.tiers if tiers is None else tiers)
    out: dict[str, dict[float, float]] = {tier: {} for tier in tiers}
    for light in lights:
        sphere = _sphere(tables, light, w, a, SPHERE_PX)
        for tier in tiers:
            out[tier][float(light)] = _omission(tables, fit, tier, sphere, w, a, over_shader)
    return out


def profile_mismatch(tables: Tables, fit_error: ArrayLike) -> float:
    """Relative error of a fitted subsurface closure's blur: ``fit_error`` (per channel, the
    RMS difference of its edge response and the tables', a fraction of the lit level:
    :class:`lut_baker.closures.profiles.ProfileFit` ``error``) over the RMS of the tables' edge
    response's departure from a sharp edge, largest over channels."""
    r_max = float(tables.radius_mm[-1])
    r = profile_grid(r_max)
    s = np.linspace(0.0, r_max, 48)
    reference = edge_response(r, tables.radial(r), s)
    departure = np.sqrt(np.mean(reference**2, axis=0))  # the sharp edge is 0 inside
    return float(np.max(np.asarray(fit_error, float) / np.maximum(departure, 1e-12)))


SHARE_LIGHTS_DEG = (0.0, 45.0, 75.0, 89.0)
"""Light angles (degrees from the view) at which :func:`traits_from_tables` measures the
shares."""


def traits_from_tables(tables: Tables, fit: ClosureFit, coverage: float | None = None,
                       absorption: ArrayLike | None = None, *,
                       lights_deg: Iterable[float] = SHARE_LIGHTS_DEG,
                       method: str | None = None,
                       errors: Mapping[str, TierError] | None = None,
                       over_shader: bool = False, sphere_px: int = SPHERE_PX
                       ) -> MaterialTraits:
    """:class:`MaterialTraits` of baked ``tables`` and their
    :class:`lut_baker.closures.closure_fit.ClosureFit` ``fit`` at a coverage and absorption
    (default: the tables'), for the tiers ``fit`` holds; ``errors``: the fit's
    :func:`lut_baker.closures.tiers.tier_errors` there, if already measured.
    ``over_shader``: a fit for a group over the artist's shader (``fit_closures(...,
    over_shader=True)``): the bare skin is the artist's (the tiers' errors and gloss
    omissions leave it as it is) and so is the subsurface closure under the film, radius and
    method, which spreads light as the artist's skin does: no profile mismatch.
    ``sphere_px``: pixels across the spheres the shares and omissions are measured on."""
    w, a = tables.coverage_and_absorption(coverage, absorption)
    errors = tier_errors(fit, tables, w, a, over_shader=over_shader) if errors is None \
        else errors
    targets = None if fit.slab is None else FitTargets(tables, 2, fit.slab.thickness_um)
    shares: dict[float, tuple[float, float]] = {}
    omissions: dict[str, dict[float, float]] = {tier: {} for tier in fit.tiers}
    for light in lights_deg:  # each sphere's lookups, rows and bare skin made once
        angle = float(light)
        if fit.slab is not None:  # the film as a slab: its own made-up skin and parts
            sphere = _sphere(tables, angle, w, a, sphere_px, fit)
            shares[angle] = _slab_shares(tables, fit, sphere, w, targets)
        else:
            sphere = _sphere(tables, angle, w, a, sphere_px)
            shares[angle] = _shares(tables, sphere, w, a)
        for tier in fit.tiers:
            omissions[tier][angle] = _omission(tables, fit, tier, sphere, w, a, over_shader)
    mismatch = 0.0 if over_shader else profile_mismatch(
        tables, fit.profiles[method or fit.subsurface_method].error)
    return MaterialTraits(
        tier_errors={tier: float(e.rms) for tier, e in errors.items()},
        radius_mm=np.asarray(tables.radius_mm, float),
        profile=np.asarray(tables.profile, float),
        profile_mismatch=mismatch,
        skin_share={angle: value[1] for angle, value in shares.items()},
        gloss_share={angle: value[0] for angle, value in shares.items()},
        gloss_omission=omissions,
    )


_PAPER = load()["paper_traits"]
TRAITS_COMMAND = _PAPER["command"]
PAPER_TIER_ERRORS = {tier: float(error) for tier, error in _PAPER["tier_errors"].items()}
PAPER_MISMATCH = float(_PAPER["profile_mismatch"])
PAPER_SKIN_SHARE = by_number(_PAPER["skin_share"])
PAPER_GLOSS_SHARE = by_number(_PAPER["gloss_share"])
PAPER_GLOSS_OMISSION = {tier: by_number(by_light)
                        for tier, by_light in _PAPER["gloss_omission"].items()}
"""The paper preset's traits (foundation paper_natural on paper_bioplate, coverage 1,
absorption 0, default bake, closure fit with Burley) as :data:`TRAITS_COMMAND` measures them
into ``measured.json``: what the Auto tier assumes of a material it has no tables for yet."""


def _paper_traits() -> MaterialTraits:
    """The constants above with the paper dipole's profile on the bake's
    radial grid (exact and cheap to recompute)."""
    dipole = made_up_skin("paper_natural", "paper_bioplate").dipole
    res = RESOLUTIONS["default"]
    radius = radius_nodes(res.n_radius, res.radius_spacing, profile_radius(dipole))
    profile = np.reshape(dipole_profile(radius, dipole), (radius.size, -1))
    profile = profile / np.atleast_1d(dipole_total_reflectance(dipole)) * np.ones(3)
    return MaterialTraits(tier_errors=dict(PAPER_TIER_ERRORS), radius_mm=radius,
                          profile=profile, profile_mismatch=PAPER_MISMATCH,
                          skin_share=dict(PAPER_SKIN_SHARE), gloss_share=dict(PAPER_GLOSS_SHARE),
                          gloss_omission={tier: dict(by_light) for tier, by_light
                                          in PAPER_GLOSS_OMISSION.items()})


@lru_cache(maxsize=1)
def paper_traits() -> MaterialTraits:
    """The paper preset's :class:`MaterialTraits` (the constants above; built once)."""
    return _paper_traits()
