"""The tiers' replicas and their errors against the tables.

Each tier's shader (:attr:`lut_baker.closures.tier_registry.Tier.shader`, written over
:mod:`lut_baker.closures.tier_formulas`' algebra) is evaluated here by numpy
(:class:`NumpyShaders`) at a coverage, absorption and Gloss (Skin Color the fitted skin's
albedo): closures turned into BRDFs by the replicas of Blender's closures
(:mod:`lut_baker.closures.cycles`; a tier's Glossy lobes as its renderer draws them, EEVEE's
for the EEVEE tier), as the renderer shades the node group, then compared with the tables on a
view grid.

- :data:`TIERS`, :class:`TierError`.
- :class:`NumpyShaders` -- the shader algebra on numpy: closures as BRDFs at ``(wi, wo)``.
- :func:`principled_inputs` -- a Principled BSDF's inputs from a fit (its sockets in numpy).
- :func:`tier_replica` -- a tier's BRDF at a coverage, absorption and Gloss.
- :func:`tier_reflection` -- a tier's BRDF as a made-up material renders it (over the
  artist's shader: the bare skin is theirs).
- :func:`reference_reflection` -- what they are measured against (the tables' made-up skin,
  or the film as a slab at the fit's thickness); :func:`slab_bare` -- a slab fit's bare skin;
  :func:`slab_lookup_of` -- the slab's lookups they share.
- :func:`tier_errors` -- the tiers of a fit against the tables at one coverage and absorption.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.made_up_skin import combine, coverage_weights
from ..tables.slab_tables import SlabLookup, slab_lookup, slab_mixed
from ..tables.table_set import ReflectionParts, Tables
from . import cycles as cc
from .closure_fit import ClosureFit
from .lobes import LobeFit
from .tier_formulas import Closure, NumpyAlgebra, TierInputs, principled_sockets
from .tier_registry import TIERS, Tier, held
from .view_grid import ERROR_VIEWS, lobe_widths_deg, view_grid

__all__ = ["TIERS", "TierError", "NumpyShaders", "principled_inputs", "tier_replica",
           "tier_reflection", "reference_reflection", "slab_lookup_of", "slab_bare", "tier_errors"]

Directions = tuple[NDArray[np.float64], NDArray[np.float64]]
"""``(wi, wo)``: light and view directions, local unit vectors ``(..., 3)``."""


@dataclass(frozen=True)
class TierError:
    """A tier's error against the tables at one coverage and absorption: ``rms`` (relative RMS
    of ``f cos(theta_i)``) and ``albedo`` (largest relative view-albedo error)."""

    tier: str
    coverage: float
    absorption: tuple[float, ...]
    rms: float
    albedo: float


def _absorption(absorption: ArrayLike) -> NDArray[np.float64]:
    return np.broadcast_to(np.asarray(absorption, float), (3,)).copy()


def _inputs(fit: ClosureFit, coverage: float, absorption: ArrayLike,
            gloss: float) -> TierInputs:
    """The group's inputs a replica takes: the fitted skin's albedo as Skin Color."""
    return TierInputs.numpy(coverage, _absorption(absorption), fit.skin_albedo, gloss)


def _principled_inputs(sockets: dict[str, Any]) -> tuple[cc.PrincipledInputs, float]:
    """``(PrincipledInputs, subsurface_weight)`` of numpy sockets at one point."""
    def scalar(name: str) -> float:
        return float(np.ravel(sockets[name])[0])

    inputs = cc.PrincipledInputs(
        base_color=tuple(np.ravel(sockets["Base Color"]).tolist()),
        roughness=scalar("Roughness"), ior=scalar("IOR"),
        specular_ior_level=scalar("Specular IOR Level"), coat_weight=scalar("Coat Weight"),
        coat_roughness=scalar("Coat Roughness"), coat_ior=scalar("Coat IOR"))
    return inputs, scalar("Subsurface Weight")


def principled_inputs(fit: ClosureFit, coverage: float, absorption: ArrayLike,
                      gloss: float = 1.0) -> tuple[cc.PrincipledInputs, float]:
    """``(PrincipledInputs, subsurface_weight)`` of a Principled BSDF at a coverage,
    absorption and Gloss, Skin Color the fitted skin's albedo:
    :func:`lut_baker.closures.tier_formulas.principled_sockets`, which the node group
    emits as nodes."""
    return _principled_inputs(principled_sockets(
        fit, _inputs(fit, coverage, absorption, gloss), NumpyAlgebra()))


class NumpyShaders(NumpyAlgebra):
    """The shader algebra (:class:`lut_baker.closures.tier_formulas.ShaderAlgebra`) on numpy:
    a shader is its BRDF ``(..., 3)`` at ``(wi, wo)``; rows read at ``wo``'s view angles; a
    Glossy closure is its white lobe (``lobes`` by name, drawn by ``glossy(pairs, lobe)``,
    :class:`lut_baker.closures.cycles.DirectionPairs` shared by the lobes) times its colour,
    Diffuse and Subsurface closures Lambertian, a closure of colour 0 none (it is never
    allocated); a Principled BSDF Cycles' (:func:`lut_baker.closures.cycles.
    principled_reflection`).  ``read``: :class:`~lut_baker.closures.tier_formulas.
    NumpyAlgebra`'s."""

    def __init__(self, wi: NDArray[np.float64], wo: NDArray[np.float64],
                 rows: dict[str, Any], lobes: dict[str, LobeFit],
                 glossy: Callable[[cc.DirectionPairs, LobeFit], NDArray[np.float64]],
                 pairs: cc.DirectionPairs | None = None,
                 read: dict[str, Any] | None = None):
        super().__init__(rows, wo[..., 2], read)
        self.wi, self.wo, self._lobes, self._glossy = wi, wo, lobes, glossy
        self._pairs = cc.DirectionPairs(wi, wo) if pairs is None else pairs

    def closure(self, closure: Closure) -> Any:
        colour = closure.product
        if not np.any(colour):
            return 0.0
        if closure.kind == "glossy":
            return self._glossy(self._pairs, self._lobes[closure.name])[..., None] * colour
        return cc.lambert_reflection(colour)

    def principled(self, sockets: dict[str, Any]) -> Any:
        return cc.principled_reflection(self.wi, self.wo, _principled_inputs(sockets)[0],
                                        pairs=self._pairs)

    @staticmethod
    def add(*shaders: Any) -> Any:
        value: Any = 0.0
        for shader in shaders:
            value = value + shader
        return value

    @staticmethod
    def mix(coverage: Any, bare: Any, covered: Any) -> Any:
        return combine(coverage_weights(coverage, 0.0), top=covered, bare=bare)


def tier_replica(fit: ClosureFit, tables: Tables, name: str | Tier, coverage: float,
                 absorption: ArrayLike, gloss: float = 1.0,
                 directions: Directions | None = None, *,
                 pairs: cc.DirectionPairs | None = None,
                 read: dict[str, Any] | None = None) -> NDArray[np.float64]:
    """Tier ``name``'s (or a :class:`~lut_baker.closures.tier_registry.Tier`'s) BRDF
    ``(..., 3)`` at the angular nodes or at ``directions``
    ``(wi, wo)``: its shader (:attr:`~lut_baker.closures.tier_registry.Tier.shader`) at a
    coverage, absorption and Gloss evaluated by :class:`NumpyShaders`, its image's rows read
    as Blender reads them (linear between texel centres).  ``pairs``: the
    :class:`lut_baker.closures.cycles.DirectionPairs` of ``directions``, if made (their
    cosines shared by the replicas there); ``read``: this tier's rows already read at
    ``directions``, by name, filled as they are read (shared by its replicas there at other
    inputs)."""
    found = name if isinstance(name, Tier) else held(fit, name)
    wi, wo = tables.node_directions() if directions is None else directions
    image = found.image(fit)
    rows = {} if image is None else dict(zip(image.rows, image.texels, strict=True))
    ops = NumpyShaders(wi, wo, rows, found.lobes(fit), found.glossy, pairs, read)
    value = np.asarray(found.shader(fit, _inputs(fit, coverage, absorption, gloss), ops, None))
    shape = np.broadcast_shapes(wi.shape, wo.shape)[:-1] + (3,)
    return value if value.shape == shape else np.broadcast_to(value, shape).copy()


def tier_reflection(fit: ClosureFit, tables: Tables, name: str, coverage: float,
                    absorption: ArrayLike, gloss: float = 1.0,
                    directions: Directions | None = None, *, over_shader: bool = False,
                    bare: NDArray[np.float64] | None = None,
                    pairs: cc.DirectionPairs | None = None,
                    read: dict[str, Any] | None = None) -> NDArray[np.float64]:
    """Tier ``name``'s BRDF ``(..., 3)`` (:func:`tier_replica`) at the angular nodes or at
    ``directions``.  ``over_shader``: the group goes over the artist's shader, which is the
    bare skin (the tables' bare skin stands for it, with the film as a slab on the fit's skin;
    the Gloss input leaves it alone): the tier's covered skin (its replica at coverage 1) and
    that bare skin (``bare``, if already computed at these directions), mixed by coverage as
    areas.  ``pairs``, ``read``: as :func:`tier_replica`'s."""
    if not over_shader:
        return tier_replica(fit, tables, name, coverage, absorption, gloss, directions,
                            pairs=pairs, read=read)
    wi, wo = tables.node_directions() if directions is None else directions
    covered = tier_replica(fit, tables, name, 1.0, absorption, gloss, (wi, wo), pairs=pairs,
                           read=read)
    if bare is None:
        bare = (tables.made_up_reflection(wi, wo, 0.0, absorption) if fit.slab is None
                else slab_bare(fit, tables, (wi, wo)))
    return combine(coverage_weights(coverage, 0.0), top=covered, bare=bare)


def reference_reflection(fit: ClosureFit, tables: Tables, coverage: float,
                         absorption: ArrayLike, directions: Directions,
                         lookup: SlabLookup | None = None) -> NDArray[np.float64]:
    """What a fit's tiers are measured against, ``(..., 3)``: the tables' made-up skin at a
    coverage and absorption, or with the film as a slab (``fit.slab``) the slab's at the fit's
    thickness on the fit's skin (``fit.skin_albedo``, the skin the film covers; its absorption
    baked, :func:`lut_baker.tables.slab_tables.slab_reflection`; the skin under the film
    darkened by ``slab.skin_under`` where Match Skin set it).  ``lookup``: the slab's
    :func:`~lut_baker.tables.slab_tables.slab_lookup` at ``directions`` and the fit's
    thickness, if already made (:func:`slab_lookup_of`)."""
    if fit.slab is None:
        return tables.made_up_reflection(*directions, coverage, absorption)
    found = slab_lookup_of(fit, tables, directions) if lookup is None else lookup
    under = fit.slab.skin_under
    if under is None:
        return slab_mixed(tables, found, skin_albedo=fit.skin_albedo, coverage=coverage)
    covered = slab_mixed(tables, found, skin_albedo=fit.skin_albedo * np.asarray(under, float))
    return combine(coverage_weights(coverage, 0.0), top=covered,
                   bare=slab_bare(fit, tables, directions, found))


def slab_lookup_of(fit: ClosureFit, tables: Tables, directions: Directions) -> SlabLookup:
    """The slab's lookups at ``directions`` and a slab fit's thickness
    (:func:`lut_baker.tables.slab_tables.slab_lookup`): what its reference and bare skin
    share."""
    if fit.slab is None:
        raise ValueError("a fit of the paper's film has no slab")
    return slab_lookup(tables, *directions, fit.slab.thickness_um)


def slab_bare(fit: ClosureFit, tables: Tables, directions: Directions,
               lookup: SlabLookup | None = None) -> NDArray[np.float64]:
    """The bare skin of a fit of the film as a slab: the skin's gloss and the fit's skin
    (:func:`lut_baker.tables.slab_tables.slab_reflection` at coverage 0; ``lookup``: its
    lookups at ``directions``, if already made)."""
    if fit.slab is None:
        raise ValueError("a fit of the paper's film takes its bare skin from the tables")
    found = slab_lookup_of(fit, tables, directions) if lookup is None else lookup
    return slab_mixed(tables, found, skin_albedo=fit.skin_albedo, coverage=0.0)


def tier_errors(fit: ClosureFit, tables: Tables, coverage: float, absorption: ArrayLike,
                gloss: float = 1.0, *, tiers: Iterable[str] | None = None,
                over_shader: bool = False) -> dict[str, TierError]:
    """:class:`TierError` of ``tiers`` (default: every tier ``fit`` holds) against the tables
    at one coverage and absorption (``gloss``: the group's Gloss input; at 0 the error
    includes all of the gloss left out; ``over_shader``: :func:`tier_reflection`'s), on a
    :class:`lut_baker.closures.view_grid.ViewGrid` of :data:`ERROR_VIEWS` views that
    resolves the narrower of the two surfaces' gloss lobes."""
    tiers = tuple(fit.tiers if tiers is None else tiers)
    if not tiers:
        return {}
    grid = view_grid(min(lobe_widths_deg(tables).values()), ERROR_VIEWS)
    directions = grid.directions
    # The tables looked up once for both coverages, and only where they are read: a fit of
    # the film as a slab takes its reference and its bare skin from the slab on its skin.
    bare: NDArray[np.float64] | None = None
    if fit.slab is None:
        looked_up: ReflectionParts = tables.reflection_parts(*directions)
        reference = tables.mixed_reflection(looked_up, coverage, absorption)
        if over_shader:
            bare = tables.mixed_reflection(looked_up, 0.0, absorption)
    else:
        lookup = slab_lookup_of(fit, tables, directions)
        reference = reference_reflection(fit, tables, coverage, absorption, directions, lookup)
        if over_shader:
            bare = slab_bare(fit, tables, directions, lookup)
    out = {}
    pairs = cc.DirectionPairs(*directions)  # the tiers' lobes share their cosines
    for name in TIERS:
        if name not in tiers:
            continue
        f = tier_reflection(fit, tables, name, coverage, absorption, gloss, directions,
                            over_shader=over_shader, bare=bare, pairs=pairs)
        out[name] = TierError(tier=name, coverage=float(coverage),
                              absorption=tuple(_absorption(absorption).tolist()),
                              rms=grid.error(f, reference),
                              albedo=grid.albedo_error(f, reference))
    return out
