"""The tiers' replicas and their errors against the tables.

Each tier's formulas are :mod:`lut_baker.closures.tier_formulas`; here they are evaluated by the
numpy algebra at a coverage, absorption and Gloss (Skin Color the fitted skin's albedo) and
turned into BRDFs by the replicas of Blender's closures (:mod:`lut_baker.closures.cycles`), as
Cycles renders the node group, then compared with the tables on a view grid.

- :data:`TIERS`, :class:`TierError`.
- :func:`principled_inputs`, :func:`principled_tier_reflection` -- the PRINCIPLED tier;
  :func:`layered_tier_reflection` -- the LAYERED tier; :func:`eevee_tier_reflection` -- the
  EEVEE tier as EEVEE renders it; :func:`view_weighted_reflection` -- a view-weighted tier's
  closures as a BRDF, :func:`view_weighted_tier` -- with any lobes and image;
  :data:`TIER_REPLICAS` -- each by name.
- :func:`view_weighted_parts` -- what the LAYERED and EEVEE tiers take from a fit (the replicas
  here and the node group alike).
- :func:`tier_reflection` -- a tier's BRDF as a made-up material renders it (over the
  artist's shader: the bare skin is theirs).
- :func:`tier_errors` -- the tiers of a fit against the tables at one coverage and absorption.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.made_up_skin import combine, coverage_weights
from ..tables.table_set import Tables
from . import cycles as cc
from . import eevee
from .closure_fit import TIERS, ClosureFit
from .tier_formulas import (
    NumpyAlgebra,
    TierInputs,
    ViewWeightedClosures,
    principled_sockets,
    view_weighted_closures,
)
from .view_grid import ERROR_VIEWS, lobe_widths_deg, view_grid
from .view_image import EEVEE_LUT_ROWS, LUT_ROWS

__all__ = ["TIERS", "TierError", "principled_inputs", "principled_tier_reflection",
           "view_weighted_reflection", "view_weighted_tier", "layered_tier_reflection",
           "eevee_tier_reflection", "TIER_REPLICAS", "EEVEE_SUBSURFACE_METHOD", "tier_errors",
           "ViewWeightedParts", "view_weighted_parts", "tier_reflection"]

EEVEE_SUBSURFACE_METHOD = "BURLEY"
"""The EEVEE tier's subsurface method: EEVEE's screen-space subsurface is Burley's profile
whatever the node asks for, and Cycles renders the same method when the file is rendered
there."""


@dataclass(frozen=True)
class TierError:
    """A tier's error against the tables at one coverage and absorption: ``rms`` (relative RMS
    of ``f cos(theta_i)``) and ``albedo`` (largest relative view-albedo error)."""

    tier: str
    coverage: float
    absorption: tuple
    rms: float
    albedo: float


def _absorption(absorption) -> np.ndarray:
    return np.broadcast_to(np.asarray(absorption, float), (3,)).copy()


def _inputs(fit: ClosureFit, coverage: float, absorption, gloss: float) -> TierInputs:
    """The group's inputs a replica takes: the fitted skin's albedo as Skin Color."""
    return TierInputs.numpy(coverage, _absorption(absorption), fit.skin_albedo, gloss)


def principled_inputs(fit: ClosureFit, coverage: float, absorption, gloss: float = 1.0):
    """``(PrincipledInputs, subsurface_weight)`` of the PRINCIPLED tier at a coverage,
    absorption and Gloss, Skin Color the fitted skin's albedo:
    :func:`lut_baker.closures.tier_formulas.principled_sockets`, which the node group
    emits as nodes."""
    sockets = principled_sockets(fit, _inputs(fit, coverage, absorption, gloss), NumpyAlgebra())

    def scalar(name):
        return float(np.ravel(sockets[name])[0])

    inputs = cc.PrincipledInputs(
        base_color=tuple(np.ravel(sockets["Base Color"]).tolist()),
        roughness=scalar("Roughness"), ior=scalar("IOR"),
        specular_ior_level=scalar("Specular IOR Level"), coat_weight=scalar("Coat Weight"),
        coat_roughness=scalar("Coat Roughness"), coat_ior=scalar("Coat IOR"))
    return inputs, scalar("Subsurface Weight")


def principled_tier_reflection(fit: ClosureFit, tables: Tables, coverage: float, absorption,
                               gloss: float = 1.0, directions=None):
    """The PRINCIPLED tier's BRDF, ``(..., 3)``: at the angular nodes, or at ``directions``
    ``(wi, wo)`` (local unit vectors); ``gloss``: the group's Gloss input."""
    wi, wo = tables.node_directions() if directions is None else directions
    inputs, _ = principled_inputs(fit, coverage, absorption, gloss)
    return cc.principled_reflection(wi, wo, inputs)


@dataclass(frozen=True)
class ViewWeightedParts:
    """What a view-weighted tier takes from a :class:`ClosureFit`: its Glossy ``lobes`` (by
    name), its view-angle image ``lut`` (rows named ``rows``), the lobes of the film's gloss
    (``film_lobes``), whether the skin through the film is a tinted, weighted Subsurface
    closure (``tinted_subsurface``) and whether both sides share one Subsurface closure
    (``one_subsurface``); see
    :func:`lut_baker.closures.tier_formulas.view_weighted_closures`."""

    lobes: dict
    lut: np.ndarray
    rows: tuple
    film_lobes: tuple
    tinted_subsurface: bool
    one_subsurface: bool = False

    def closures(self, fit: ClosureFit, x: TierInputs, ops,
                 subsurface_weight=None) -> ViewWeightedClosures:
        """The tier's closures at inputs ``x`` in the algebra ``ops``; ``subsurface_weight``:
        the share of the skin under the film that is subsurface (a group over the artist's
        shader: theirs; its bare side is their shader, so nothing is shared with it)."""
        return view_weighted_closures(fit, x, ops, tinted_subsurface=self.tinted_subsurface,
                                      film_lobes=self.film_lobes,
                                      one_subsurface=self.one_subsurface
                                      and subsurface_weight is None,
                                      subsurface_weight=subsurface_weight)


def view_weighted_parts(fit: ClosureFit, tier: str) -> ViewWeightedParts:
    """The LAYERED tier's parts (Cycles' lobes, the tinted subsurface its random walk needs)
    or the EEVEE tier's (lobes fitted as EEVEE renders GGX, the film's gloss in two, its own
    image, the plain colour EEVEE's subsurface takes, one Subsurface closure for both sides:
    EEVEE picks one Diffuse or Subsurface closure per sample, and fewer are less noise)."""
    if tier not in ("LAYERED", "EEVEE"):
        raise ValueError(f"{tier!r} is not a view-weighted tier (LAYERED, EEVEE)")
    lobes, lut = (fit.glossy, fit.lut) if tier == "LAYERED" else (fit.eevee_glossy,
                                                                  fit.eevee_lut)
    if lobes is None or lut is None:
        raise ValueError(f"the fit holds no {tier} tier (it has {', '.join(fit.tiers)}): fit "
                         f"it with fit_closures(..., tiers=...)")
    if tier == "LAYERED":
        return ViewWeightedParts(lobes, lut, LUT_ROWS, ("film_gloss",), tinted_subsurface=True)
    # The film gloss's second lobe is a closure only where its fit kept two.
    second = np.any(lobes["film_gloss_2"].lut)
    return ViewWeightedParts(lobes, lut, EEVEE_LUT_ROWS,
                             ("film_gloss", "film_gloss_2") if second else ("film_gloss",),
                             tinted_subsurface=False, one_subsurface=True)


def view_weighted_reflection(closures: ViewWeightedClosures, lobe_of, wi, wo) -> np.ndarray:
    """A view-weighted tier's BRDF, ``(..., 3)``, at ``(wi, wo)`` from its closures
    (:func:`lut_baker.closures.tier_formulas.view_weighted_closures`, evaluated by the numpy
    algebra at ``wo``'s view angles): each Glossy closure's white lobe ``lobe_of(name, wi,
    wo)`` ``(...)`` times its colour, Diffuse and Subsurface closures Lambertian, each side
    summed and the sides mixed by coverage."""
    def side(closures_of_side):
        value = 0.0
        for closure in closures_of_side:
            colour = closure.product
            if not np.any(colour):
                continue  # a closure of weight 0 is never allocated
            if closure.kind == "glossy":
                value = value + lobe_of(closure.name, wi, wo)[..., None] * colour
            else:
                value = value + cc.lambert_reflection(colour)
        return value

    weights = coverage_weights(closures.coverage, 0.0)
    mixed = combine(weights, top=side(closures.covered), bare=side(closures.bare))
    return mixed + side(closures.shared) if closures.shared else mixed


def view_weighted_tier(fit: ClosureFit, tables: Tables, coverage: float, absorption, gloss,
                       directions, parts: ViewWeightedParts, lobe_of):
    """A view-weighted tier's BRDF ``(..., 3)`` at the angular nodes or at ``directions``:
    the closures of its ``parts`` (:class:`ViewWeightedParts`) with the rows of their image
    read at ``wo``'s view angles, its Glossy lobes drawn by ``lobe_of(wi, wo, lobe)``."""
    wi, wo = tables.node_directions() if directions is None else directions
    algebra = NumpyAlgebra(dict(zip(parts.rows, parts.lut, strict=True)), wo[..., 2])
    closures = parts.closures(fit, _inputs(fit, coverage, absorption, gloss), algebra)
    return view_weighted_reflection(
        closures, lambda name, a, b: lobe_of(a, b, parts.lobes[name]), wi, wo)


def layered_tier_reflection(fit: ClosureFit, tables: Tables, coverage: float, absorption,
                            gloss: float = 1.0, directions=None):
    """The LAYERED tier's BRDF, ``(..., 3)``, at the angular nodes or at ``directions``
    ``(wi, wo)``: its closures (:func:`lut_baker.closures.tier_formulas.view_weighted_closures`)
    with the image rows read as Blender reads them (linear between texel centres) and Cycles'
    Glossy lobes; ``gloss``: the group's Gloss input."""
    return view_weighted_tier(
        fit, tables, coverage, absorption, gloss, directions, view_weighted_parts(fit, "LAYERED"),
        lambda wi, wo, lobe: cc.microfacet_reflection(wi, wo, lobe.roughness,
                                                      distribution=lobe.distribution))


def eevee_tier_reflection(fit: ClosureFit, tables: Tables, coverage: float, absorption,
                          gloss: float = 1.0, directions=None):
    """The EEVEE tier's BRDF as EEVEE renders it under lamps, ``(..., 3)``, at the angular
    nodes or at ``directions`` ``(wi, wo)``: the LAYERED tier's closures and areal mix with
    its own lobes (``fit.eevee_glossy``, the film's gloss in two; EEVEE's GGX:
    :func:`lut_baker.closures.eevee.glossy_reflection`) and view-angle rows
    (``fit.eevee_lut``), the skin through the film as its plain colour (EEVEE's screen-space
    subsurface takes it as it is); Diffuse and Subsurface closures Lambertian."""
    return view_weighted_tier(
        fit, tables, coverage, absorption, gloss, directions, view_weighted_parts(fit, "EEVEE"),
        lambda wi, wo, lobe: eevee.glossy_reflection(wi, wo, lobe.roughness))


TIER_REPLICAS = {"PRINCIPLED": principled_tier_reflection, "LAYERED": layered_tier_reflection,
                 "EEVEE": eevee_tier_reflection}
"""Each tier's replica, ``(fit, tables, coverage, absorption, gloss=1, directions=None)``."""


def tier_reflection(fit: ClosureFit, tables: Tables, tier: str, coverage: float, absorption,
                    gloss: float = 1.0, directions=None, *, over_shader: bool = False,
                    bare=None):
    """``tier``'s BRDF ``(..., 3)`` (:data:`TIER_REPLICAS`) at the angular nodes or at
    ``directions``.  ``over_shader``: the group goes over the artist's shader, which is the
    bare skin (the tables' bare skin stands for it, the Gloss input leaves it alone): the
    tier's covered skin (its replica at coverage 1) and the tables' bare skin (``bare``, if
    already computed at these directions: ``made_up_reflection`` at coverage 0), mixed by
    coverage as areas."""
    replica = TIER_REPLICAS[tier]
    if not over_shader:
        return replica(fit, tables, coverage, absorption, gloss, directions)
    wi, wo = tables.node_directions() if directions is None else directions
    covered = replica(fit, tables, 1.0, absorption, gloss, (wi, wo))
    if bare is None:
        bare = tables.made_up_reflection(wi, wo, 0.0, absorption)
    return combine(coverage_weights(coverage, 0.0), top=covered, bare=bare)


def tier_errors(fit: ClosureFit, tables: Tables, coverage: float, absorption,
                gloss: float = 1.0, *, tiers=None, over_shader: bool = False) -> dict:
    """:class:`TierError` of ``tiers`` (default: every tier ``fit`` holds) against the tables
    at one coverage and absorption (``gloss``: the group's Gloss input; at 0 the error
    includes all of the gloss left out; ``over_shader``: :func:`tier_reflection`'s), on a
    :class:`lut_baker.closures.view_grid.ViewGrid` of :data:`ERROR_VIEWS` views that
    resolves the narrower of the two surfaces' gloss lobes."""
    tiers = fit.tiers if tiers is None else tiers
    if not tiers:
        return {}
    grid = view_grid(min(lobe_widths_deg(tables).values()), ERROR_VIEWS)
    directions = grid.directions
    looked_up = tables.reflection_parts(*directions)  # one lookup for both coverages
    reference = tables.mixed_reflection(looked_up, coverage, absorption)
    bare = tables.mixed_reflection(looked_up, 0.0, absorption) if over_shader else None
    out = {}
    for tier in TIER_REPLICAS:
        if tier not in tiers:
            continue
        f = tier_reflection(fit, tables, tier, coverage, absorption, gloss, directions,
                            over_shader=over_shader, bare=bare)
        out[tier] = TierError(tier=tier, coverage=float(coverage),
                              absorption=tuple(_absorption(absorption).tolist()),
                              rms=grid.error(f, reference),
                              albedo=grid.albedo_error(f, reference))
    return out
