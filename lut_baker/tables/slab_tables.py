"""Made-up skin at every thickness as the tables hold it: the film as a slab over the skin,
every inter-reflection in, tabulated over a small thickness axis so that a thickness (or a
painted thickness map) is a lookup, not a bake (docs/baking.md, "The film as a slab in the
tables"; docs/model.md, "Made-up skin at a thickness").

Per thickness ``h`` (micrometres) and channel, with ``a`` the skin's diffuse albedo (free: a
texture, a socket) and the film's surface gloss in closed form, ``k`` times eq. 2's gloss
``film_gloss`` (:meth:`lut_baker.tables.table_set.Tables.surface_gloss`; ``k`` the share an
interface of the film's vehicle reflects, :func:`lut_baker.model.film_slab.surface_share`, the
rest the body's)::

    f = k film_gloss + top(h) + a t_h(theta_i) t_h(theta_o) / (pi (1 - a c_h))

``top`` (angular, 1/sr): the film's body through its surface and the skin's gloss through the
film, every inter-reflection (what does not depend on ``a``); ``through`` ``t`` (directional,
dimensionless): the film's transmittance into the skin's diffuse light; ``below`` ``c``: the
film's reflectance seen from the skin (:mod:`lut_baker.model.slab_skin`); ``film_albedo``: the
film's own directional albedo from above (its body through its surface: the part of ``top``'s
albedo that is not the skin's gloss, the tiers' film Diffuse closure).  The diffuse term is what
spreads under the skin (the dipole's normalised profile).  Absorption is part of the bake
(the slab is not linear in it); coverage stays an areal mix with the bare skin.

The thickness axis: ``thickness_um`` holds ``n - 1`` log-spaced thicknesses from
:data:`THICKNESS_MIN_UM` to :data:`THICKNESS_MAX_UM`, then the thick limit (``inf``).  The
fractional index of ``h`` is::

    x = ln(h / h_min) / ln(h_max / h_min) (n - 2)            h <= h_max
    x = (n - 2) + (1 - h_max / h)                             h >  h_max (in 1 / h to the limit)

clamped to ``[0, n - 1]``, and every table is interpolated linearly in ``x`` (and, for the
angular table, trilinearly in its own angular grid, as :mod:`lut_baker.tables.table_set`).

Tables at one thickness (``thickness_um`` of one entry, what a preview bakes:
``lut_baker.bake.bake_slab(..., only_um=h)``) hold the rows a lookup at ``h`` reads from the
axis (:func:`thickness_support`: the nodes either side of ``h`` and its weight between them,
:func:`at_support`), so that they equal the axis's tables there; they are read at ``h`` only
(another thickness raises: it needs the axis).

Functions and types
-------------------
- :data:`THICKNESS_MIN_UM`, :data:`THICKNESS_MAX_UM`, :data:`THICKNESS_NODES` -- the axis;
  :data:`ONE_THICKNESS_RTOL` -- how close a thickness reads tables at one thickness.
- :func:`thickness_nodes`, :func:`thickness_index` -- its nodes and the closed-form index.
- :func:`thickness_support`, :func:`at_support` -- the nodes a lookup at one thickness reads
  and its rows from theirs (tables at one thickness).
- :class:`SlabTables` -- the tables, with ``at`` (the 1-D parts at a thickness).
- :class:`SlabParts` -- the 1-D parts at one thickness; :class:`SlabSlice` -- the 1-D tables
  at one thickness (``SlabTables.sliced``), read at any angles.
- :func:`surface_gloss`, :func:`surface_gloss_albedo` -- the film surface's gloss (``k``
  times the tables' ``film_gloss``) and its directional albedo.
- :func:`slab_reflection` -- made-up skin's BRDF at a thickness from the tables (optionally
  without its diffuse term, the part that spreads under the skin); :class:`SlabLookup`,
  :func:`slab_lookup`, :func:`slab_mixed` -- the same in two steps, its lookups once for
  every skin and coverage at the same directions.
- :class:`SlabDiffuse`, :func:`slab_diffuse` -- that diffuse term's factors at one thickness
  (what a reference image spreads by the dipole's profile).
- :func:`slab_directional_albedo`, :func:`slab_colour` -- its directional albedo and its colour
  under uniform light.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.albedo import bihemispherical
from ..model.microfacet import reflection_cosines
from ..numerics.geometry import polar_angle_deg
from .table_set import (
    THETA_OFFSET,
    Tables,
    _corners,
    _linear,
    _trilinear,
    phi_index,
    theta_index,
)

__all__ = [
    "THICKNESS_MIN_UM",
    "THICKNESS_MAX_UM",
    "THICKNESS_NODES",
    "ONE_THICKNESS_RTOL",
    "thickness_nodes",
    "thickness_index",
    "thickness_support",
    "at_support",
    "SlabTables",
    "SlabParts",
    "SlabSlice",
    "surface_gloss",
    "surface_gloss_albedo",
    "slab_reflection",
    "SlabLookup",
    "slab_lookup",
    "slab_mixed",
    "SlabDiffuse",
    "slab_diffuse",
    "slab_directional_albedo",
    "slab_colour",
]

THICKNESS_MIN_UM = 1.0
"""The thinnest tabulated film, micrometres (sheer: a few; thinner is clamped to it)."""
THICKNESS_MAX_UM = 300.0
"""The thickest finite node, micrometres (twice the paper's film); beyond, interpolation in
``1 / h`` to the thick limit."""
THICKNESS_NODES = 10
"""Nodes of the axis: 9 log-spaced (a ratio of 2.04) and the thick limit
(docs/baking.md measures the interpolation error)."""
ONE_THICKNESS_RTOL = 1e-12
"""How close a thickness must be to that of tables at one thickness to be read from them (a
float's round trip through the panel and a record)."""


def thickness_nodes(n: int = THICKNESS_NODES, h_min: float = THICKNESS_MIN_UM,
                    h_max: float = THICKNESS_MAX_UM) -> NDArray[np.float64]:
    """The axis (micrometres): ``n - 1`` log-spaced thicknesses from ``h_min`` to ``h_max``
    and ``inf``."""
    if n < 3 or not 0.0 < h_min < h_max:
        raise ValueError(f"need n >= 3 and 0 < h_min < h_max, got {n}, {h_min}, {h_max}")
    return np.append(np.geomspace(h_min, h_max, n - 1), np.inf)


def thickness_index(thickness_um: ArrayLike, n: int = THICKNESS_NODES,
                    h_min: float = THICKNESS_MIN_UM,
                    h_max: float = THICKNESS_MAX_UM) -> NDArray[np.float64]:
    """The fractional index (clamped to ``[0, n - 1]``) of thicknesses on
    :func:`thickness_nodes` (module docstring)."""
    h = np.maximum(np.asarray(thickness_um, float), h_min)
    finite = np.log(np.minimum(h, h_max) / h_min) / np.log(h_max / h_min) * (n - 2)
    beyond = (n - 2) + (1.0 - h_max / np.maximum(h, h_max))
    return np.clip(np.where(h <= h_max, finite, beyond), 0.0, n - 1.0)


def thickness_support(thickness_um: float, n: int = THICKNESS_NODES,
                      h_min: float = THICKNESS_MIN_UM,
                      h_max: float = THICKNESS_MAX_UM) -> tuple[NDArray[np.intp], float]:
    """``(nodes, t)``: the nodes of :func:`thickness_nodes` a lookup at ``thickness_um``
    reads (two, or one where its weight is all on one node: at a node, or the thick limit) and
    its fractional index among them (0 for one node): what :func:`at_support` needs of the
    rows baked at ``nodes`` to give the axis's tables at that thickness."""
    corner, weight = _corners(thickness_index(thickness_um, n, h_min, h_max), n)
    low, t = int(corner), float(weight)
    if t == 0.0:
        return np.array([low], np.intp), 0.0
    if t == 1.0:
        return np.array([low + 1], np.intp), 0.0
    return np.array([low, low + 1], np.intp), t


def _all_close(h: NDArray[np.float64], baked_um: float) -> bool:
    """Whether every thickness ``h`` is ``baked_um`` within :data:`ONE_THICKNESS_RTOL`
    (``np.isclose``'s test, a single thickness without numpy's array machinery)."""
    if h.ndim:
        return bool(np.all(np.isclose(h, baked_um, rtol=ONE_THICKNESS_RTOL, atol=0.0)))
    x = float(h)
    if math.isfinite(x) and math.isfinite(baked_um):
        return abs(x - baked_um) <= ONE_THICKNESS_RTOL * abs(baked_um)
    return x == baked_um


def at_support(rows: NDArray[np.float64], t: float) -> NDArray[np.float64]:
    """A table at one thickness from its rows at :func:`thickness_support`'s nodes
    (``(1 or 2, ...)``): the interpolation :class:`SlabTables`' lookups make (the same
    operations: equal to them to the last bit), ``(1, ...)``."""
    rows = np.asarray(rows)
    if rows.shape[0] == 1:
        return rows.copy()
    return _linear(rows, np.asarray(t))[None]


class SlabParts(NamedTuple):
    """The 1-D parts at one thickness: ``top_albedo`` ``(..., 3)`` (``top``'s directional
    albedo, at the angles asked), ``through`` ``(..., 3)`` (``t``), ``through_mean`` ``(3,)``
    (``t`` averaged over uniform light, ``2 Int t mu dmu``), ``below`` ``(3,)`` (``c``),
    ``film_albedo`` ``(..., 3)`` (the film's own directional albedo, at the angles asked),
    ``body_gloss`` ``(3,)`` (the weight of eq. 2's gloss lobe in it)."""

    top_albedo: NDArray[np.float64]
    through: NDArray[np.float64]
    through_mean: NDArray[np.float64]
    below: NDArray[np.float64]
    film_albedo: NDArray[np.float64]
    body_gloss: NDArray[np.float64]


class SlabSlice(NamedTuple):
    """The 1-D tables of ``slab`` at one thickness (:meth:`SlabTables.sliced`): ``tables``,
    :class:`SlabParts` on the slab's own angular grid; :meth:`at` reads them at polar
    angles, :meth:`film_albedo_at` the film's own albedo alone."""

    slab: SlabTables
    thickness_um: float
    tables: SlabParts

    def at(self, theta_deg: ArrayLike) -> SlabParts:
        """The 1-D parts at polar angles ``theta_deg`` (degrees)."""
        x = self.slab.theta_index(theta_deg)
        tables = self.tables
        return SlabParts(top_albedo=_linear(tables.top_albedo, x),
                         through=_linear(tables.through, x),
                         through_mean=tables.through_mean, below=tables.below,
                         film_albedo=_linear(tables.film_albedo, x),
                         body_gloss=tables.body_gloss)

    def film_albedo_at(self, theta_deg: ArrayLike) -> NDArray[np.float64]:
        """:meth:`at`'s ``film_albedo`` alone (the other parts not read), ``(..., 3)``."""
        return _linear(self.tables.film_albedo, self.slab.theta_index(theta_deg))


@dataclass(frozen=True, eq=False)
class SlabTables:
    """Made-up skin at every thickness (module docstring), at the baked ``absorption`` (3,).

    ``thickness_um`` (K,): the axis (:func:`thickness_nodes`), or one thickness (K = 1: the
    tables there only, read at it only; module docstring).  Angular grid of its own,
    ``theta_deg`` (n_theta,) and ``phi_deg`` (n_phi,), laid out as ``theta_spacing``,
    ``theta_offset`` and ``phi_spacing`` say (the closed forms of
    :mod:`lut_baker.tables.table_set`).  ``top`` (K, n_theta, n_theta, n_phi, 3) 1/sr;
    ``top_albedo``, ``through``, ``film_albedo`` (K, n_theta, 3); ``through_mean``, ``below``
    (K, 3); ``body_gloss`` (K, 3): the weight of eq. 2's gloss lobe in the film's own
    reflection (:func:`lut_baker.model.slab_skin.body_gloss_weight`, the body's share of the
    gloss, what the tiers draw as gloss).  ``surface_share`` (3,): ``k``, the share of the
    tables' ``film_gloss`` the film's surface reflects
    (:func:`lut_baker.model.film_slab.surface_share`)."""

    thickness_um: NDArray[np.float64]
    theta_deg: NDArray[np.float64]
    phi_deg: NDArray[np.float64]
    top: NDArray[np.float64]
    top_albedo: NDArray[np.float64]
    through: NDArray[np.float64]
    through_mean: NDArray[np.float64]
    below: NDArray[np.float64]
    film_albedo: NDArray[np.float64]
    body_gloss: NDArray[np.float64]
    absorption: NDArray[np.float64]
    surface_share: NDArray[np.float64]
    theta_spacing: str = "grazing"
    theta_offset: float = THETA_OFFSET
    phi_spacing: str = "half_vector"

    def __post_init__(self) -> None:
        k, n, p = self.thickness_um.size, self.theta_deg.size, self.phi_deg.size
        shapes = {"top": (k, n, n, p, 3), "top_albedo": (k, n, 3), "through": (k, n, 3),
                  "film_albedo": (k, n, 3), "through_mean": (k, 3), "below": (k, 3),
                  "body_gloss": (k, 3), "absorption": (3,), "surface_share": (3,)}
        for name, shape in shapes.items():
            if np.shape(getattr(self, name)) != shape:
                raise ValueError(f"slab table {name!r} must have shape {shape}, "
                                 f"got {np.shape(getattr(self, name))}")
        if k == 1:
            return
        expected = thickness_nodes(k, float(self.thickness_um[0]),
                                   float(self.thickness_um[-2]))
        if not np.allclose(self.thickness_um, expected, rtol=1e-12):
            raise ValueError("thickness_um does not follow its closed form (thickness_nodes)")

    @property
    def one_thickness(self) -> bool:
        """Whether these are the tables at one thickness only (module docstring)."""
        return self.thickness_um.size == 1

    def thickness_index(self, thickness_um: ArrayLike) -> NDArray[np.float64]:
        """Fractional index on the axis (clamped); 0 for tables at one thickness, which
        raise ValueError at any other."""
        if self.one_thickness:
            h = np.asarray(thickness_um, float)
            if not _all_close(h, float(self.thickness_um[0])):
                raise ValueError(f"these slab tables hold the film at "
                                 f"{float(self.thickness_um[0])} um only: another thickness "
                                 f"needs the axis's (bake_slab without only_um)")
            return np.zeros(h.shape)
        return thickness_index(thickness_um, self.thickness_um.size,
                               float(self.thickness_um[0]), float(self.thickness_um[-2]))

    def theta_index(self, theta_deg: ArrayLike) -> NDArray[np.float64]:
        """Fractional index of polar angles (degrees) on the angular grid, unclamped."""
        return theta_index(theta_deg, self.theta_deg.size, self.theta_spacing,
                           float(self.theta_deg[-1]), self.theta_offset)

    def _along(self, table: NDArray[np.float64], thickness_um: float) -> NDArray[np.float64]:
        """``table[k, ...]`` interpolated linearly at one thickness (tables at one thickness:
        their row, read-only)."""
        if self.one_thickness:
            self.thickness_index(thickness_um)  # raises at another thickness
            row = np.asarray(table)[0]
            row.setflags(write=False)
            return row
        return _linear(np.asarray(table), np.asarray(self.thickness_index(thickness_um)))

    def at(self, thickness_um: float, theta_deg: ArrayLike) -> SlabParts:
        """The 1-D parts at ``thickness_um`` and polar angles ``theta_deg`` (degrees)."""
        return self.sliced(thickness_um).at(theta_deg)

    def sliced(self, thickness_um: float) -> SlabSlice:
        """The 1-D tables at one thickness (:class:`SlabSlice`, read-only: read at many
        angles, they are interpolated along the thickness once)."""
        tables = {name: self._along(getattr(self, name), thickness_um)
                  for name in SlabParts._fields}
        for table in tables.values():
            table.setflags(write=False)
        return SlabSlice(self, float(thickness_um), SlabParts(**tables))

    def through_at(self, thickness_um: float, w: ArrayLike) -> NDArray[np.float64]:
        """``t`` (dimensionless, ``(..., 3)``) at one thickness for unit directions ``(..., 3)``
        (their polar angles; clamped to the grid)."""
        return _linear(self._along(self.through, thickness_um),
                       self.theta_index(polar_angle_deg(np.asarray(w, float))))

    def top_at(self, thickness_um: float, wi: ArrayLike, wo: ArrayLike) -> NDArray[np.float64]:
        """``top`` (1/sr, ``(..., 3)``) at one thickness and unit directions ``(..., 3)``."""
        to_light, to_view = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
        return self._top(thickness_um, to_light, to_view,
                         self.theta_index(polar_angle_deg(to_light)),
                         self.theta_index(polar_angle_deg(to_view)))

    def _top(self, thickness_um: float, to_light: NDArray[np.float64],
             to_view: NDArray[np.float64], x_light: NDArray[np.float64],
             x_view: NDArray[np.float64]) -> NDArray[np.float64]:
        """:meth:`top_at` at broadcast directions whose :meth:`theta_index` of their polar
        angles are ``x_light``, ``x_view``."""
        return _trilinear(self._along(self.top, thickness_um), x_light, x_view,
                          phi_index(to_light, to_view, self.phi_deg.size, self.phi_spacing))


def _slab(tables: Tables) -> SlabTables:
    slab = getattr(tables, "slab", None)
    if not isinstance(slab, SlabTables):
        raise ValueError("these tables hold the paper's film only: bake with a film thickness "
                         "(bake(..., film=thickness_um)) for the slab's tables")
    return slab


def _thickness(tables: Tables, thickness_um: float | None) -> float:
    if thickness_um is not None:
        return float(thickness_um)
    value = tables.parameters.get("film_thickness_um")
    if value is None:
        raise ValueError("no thickness given and none baked")
    return float(value)


def _albedo(tables: Tables, skin_albedo: ArrayLike | None) -> NDArray[np.float64]:
    if skin_albedo is None:
        return np.pi * np.asarray(tables.skin_diffuse, float)
    return np.broadcast_to(np.asarray(skin_albedo, float), (3,))


def surface_gloss(tables: Tables, wi: ArrayLike, wo: ArrayLike) -> NDArray[np.float64]:
    """The film surface's gloss (1/sr, ``(..., 3)``) at unit directions: the slab's
    ``surface_share`` times the tables' ``film_gloss`` (closed form); 0 below the surface."""
    to_light, to_view = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
    return _slab(tables).surface_share * tables.surface_gloss("film_gloss", to_light, to_view)


def surface_gloss_albedo(tables: Tables, theta_deg: ArrayLike) -> NDArray[np.float64]:
    """:func:`surface_gloss`'s directional albedo at incidences ``theta_deg``, ``(..., 3)``."""
    return _slab(tables).surface_share * tables.directional("film_gloss_albedo", theta_deg)


class SlabDiffuse(NamedTuple):
    """The diffuse term of :func:`slab_reflection` at one thickness: under the film
    ``covered t(theta_i) t(theta_o)`` with ``covered = a / (pi (1 - a c))``, on bare skin
    ``bare = a / pi`` (1/sr, ``(3,)`` each), mixed by area at the coverage; ``through(w)`` is
    ``t`` for unit directions ``(..., 3)`` (the light's way in and out of the skin)."""

    covered: NDArray[np.float64]
    bare: NDArray[np.float64]
    slab: SlabTables
    thickness_um: float

    def through(self, w: ArrayLike) -> NDArray[np.float64]:
        """``t`` at directions ``w`` (``(..., 3)``)."""
        return self.slab.through_at(self.thickness_um, w)


def slab_diffuse(tables: Tables, thickness_um: float | None = None,
                 skin_albedo: ArrayLike | None = None) -> SlabDiffuse:
    """:class:`SlabDiffuse` of the tables at ``thickness_um`` (default the baked one) on skin
    of diffuse albedo ``skin_albedo`` (default the baked skin's ``pi P_d``)."""
    slab = _slab(tables)
    h = _thickness(tables, thickness_um)
    a = _albedo(tables, skin_albedo)
    below = slab._along(slab.below, h)
    return SlabDiffuse(covered=a / (np.pi * (1.0 - a * below)), bare=a / np.pi, slab=slab,
                       thickness_um=h)


class SlabLookup(NamedTuple):
    """What :func:`slab_reflection` looks up at unit directions before the skin's albedo and
    the coverage mix it (:func:`slab_lookup`): one lookup serves every skin and coverage at the
    same directions.  ``film_gloss``: the tables' ``film_gloss`` (closed form, before the
    surface's share), ``top`` and ``skin_gloss`` (1/sr, ``(..., 3)``), ``through_i``,
    ``through_o``: ``t`` at the light's and the view's polar angles, ``upper``: both directions
    above the surface, at ``thickness_um``."""

    film_gloss: NDArray[np.float64]
    top: NDArray[np.float64]
    skin_gloss: NDArray[np.float64]
    through_i: NDArray[np.float64]
    through_o: NDArray[np.float64]
    upper: NDArray[np.bool_]
    thickness_um: float


def slab_lookup(tables: Tables, wi: ArrayLike, wo: ArrayLike,
                thickness_um: float | None = None) -> SlabLookup:
    """:class:`SlabLookup` of the tables at unit directions ``(..., 3)`` and ``thickness_um``
    (default the baked one)."""
    slab = _slab(tables)
    h = _thickness(tables, thickness_um)
    to_light, to_view = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
    # what the lookups share: the surfaces' cosines, the polar angles' indices, t at h
    cosines = reflection_cosines(to_light, to_view)
    x_light = slab.theta_index(polar_angle_deg(to_light))
    x_view = slab.theta_index(polar_angle_deg(to_view))
    through = slab._along(slab.through, h)
    return SlabLookup(film_gloss=tables.surface_gloss("film_gloss", to_light, to_view,
                                                      cosines=cosines),
                      top=slab._top(h, to_light, to_view, x_light, x_view),
                      skin_gloss=tables.surface_gloss("skin_gloss", to_light, to_view,
                                                      cosines=cosines),
                      through_i=_linear(through, x_light),
                      through_o=_linear(through, x_view),
                      upper=(to_light[..., 2] >= 0.0) & (to_view[..., 2] >= 0.0),
                      thickness_um=h)


def slab_mixed(tables: Tables, lookup: SlabLookup, skin_albedo: ArrayLike | None = None,
               coverage: float = 1.0, *, diffuse: bool = True) -> NDArray[np.float64]:
    """:func:`slab_reflection` from its looked-up ``lookup`` (:func:`slab_lookup`) on skin of
    diffuse albedo ``skin_albedo`` (default the baked skin's ``pi P_d``) at ``coverage``."""
    covered = _slab(tables).surface_share * lookup.film_gloss + lookup.top
    bare = lookup.skin_gloss
    if diffuse:
        terms = slab_diffuse(tables, lookup.thickness_um, skin_albedo)
        covered = covered + terms.covered * lookup.through_i * lookup.through_o
        bare = bare + terms.bare
    value = coverage * covered + (1.0 - coverage) * bare
    return np.where(lookup.upper[..., None], value, 0.0)


def slab_reflection(tables: Tables, wi: ArrayLike, wo: ArrayLike,
                    thickness_um: float | None = None, skin_albedo: ArrayLike | None = None,
                    coverage: float = 1.0, *, diffuse: bool = True) -> NDArray[np.float64]:
    """Made-up skin's BRDF (1/sr, ``(..., 3)``) from the tables at ``thickness_um`` (default
    the baked one) on skin of diffuse albedo ``skin_albedo`` (default the baked skin's
    ``pi P_d``), mixed by area with the bare skin at ``coverage``; 0 below the surface.
    ``diffuse=False``: without the diffuse term (:func:`slab_diffuse`), what returns where it
    entered.  (:func:`slab_mixed` of :func:`slab_lookup`.)"""
    return slab_mixed(tables, slab_lookup(tables, wi, wo, thickness_um), skin_albedo,
                      coverage, diffuse=diffuse)


def slab_directional_albedo(tables: Tables, theta_deg: ArrayLike,
                            thickness_um: float | None = None,
                            skin_albedo: ArrayLike | None = None,
                            coverage: float = 1.0) -> NDArray[np.float64]:
    """``Int f cos(theta_o) dwo`` at incidences ``theta_deg`` from the tables' 1-D parts,
    ``(..., 3)``: the film surface's gloss albedo, ``top``'s, ``a t(theta) t_mean / (1 - a c)``; the
    bare skin's by ``1 - coverage``."""
    slab = _slab(tables)
    h = _thickness(tables, thickness_um)
    a = _albedo(tables, skin_albedo)
    parts = slab.at(h, theta_deg)
    covered = (surface_gloss_albedo(tables, theta_deg) + parts.top_albedo
               + a * parts.through * parts.through_mean / (1.0 - a * parts.below))
    bare = tables.directional("skin_gloss_albedo", theta_deg) + a
    return coverage * covered + (1.0 - coverage) * bare


def slab_colour(tables: Tables, thickness_um: float | None = None,
                skin_albedo: ArrayLike | None = None,
                coverage: float = 1.0) -> NDArray[np.float64]:
    """The colour under uniform white light ``(3,)``: :func:`slab_directional_albedo`
    averaged over incidence (:func:`lut_baker.model.albedo.bihemispherical`)."""
    return bihemispherical(lambda theta: slab_directional_albedo(
        tables, theta, thickness_um, skin_albedo, coverage))
