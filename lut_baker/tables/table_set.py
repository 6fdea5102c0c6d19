"""Baked lookup tables of one made-up skin: the contract between the bake and the shader side.

Everything is per RGB channel (trailing axis of length 3) and in albedo units (1/sr), at
absorption 0 and split into parts so that coverage ``w`` and absorption ``A`` can be applied
afterwards (by a shader socket or by :meth:`Tables.made_up_reflection`)::

    f = w [film_gloss + (1 - A) film_diffuse + (1 - A)^2 (path3_gloss + skin_diffuse T(wi) T(wo))]
        + (1 - w) [skin_gloss + skin_diffuse]

``T`` is the film's directional transmittance (light crosses the film twice on path 3, so
its pigment absorbs twice).  The weights ``w``, ``1 - w``, ``1 - A``, ``(1 - A)^2`` are
:func:`lut_baker.model.made_up_skin.coverage_weights`.  The skin's diffuse part of path 3 is
the part that spreads under the surface with the dipole's normalised profile
``profile = R(d) / Rd`` (docs/model.md §4).

``film_gloss`` and ``skin_gloss`` are the two surfaces' own gloss, eq. 2's specular term
``P_s D G F_r`` of the film and of the skin: closed forms of the parameters, so they are evaluated
where they are needed (:meth:`Tables.angular`) and never tabulated.  A lobe of any width then
costs the same, and the tables hold only what needs an integral: path 3's gloss
(``path3_gloss``, through the film and back, as wide as the film's transmission makes it),
transmittances, albedos and the radial profile (docs/baking.md, "What is tabulated").

Angular tables are indexed ``[theta_i, theta_o, phi]`` on the grids ``theta_deg`` (degrees
from the normal) and ``phi_deg`` (relative azimuth, degrees, 0..180 by symmetry); radial ones by
``radius_mm``.

Grids and lookup
----------------
Grids are closed-form so that a shader can find a table coordinate without searching; the
fractional index ``x`` of a value (grid node ``k`` has ``x = k``) is:

- ``theta_spacing = "grazing"`` (the default): node density proportional to
  ``1 / (cos theta + mu0)`` (``mu0 = theta_offset``), even in theta at the normal (where the
  BRDF has terms linear in theta) and geometric in ``cos theta`` towards grazing (where the
  gloss lobes depend on the ratio of the two cosines)::

      x = atanh(q tan(theta / 2)) / atanh(q tan(theta_max / 2)) (n - 1),
      q = sqrt((1 - mu0) / (1 + mu0)),   atanh(y) = ln((1 + y) / (1 - y)) / 2

  with ``theta_max = theta_deg[-1]`` (nodes: ``theta = 2 atan(tanh(s X) / q)``).
  ``"uniform_cos"``: ``x = (1 - cos theta) / (1 - cos theta_max) (n - 1)``;
  ``"uniform_theta"``: ``x = theta / theta_max (n - 1)``.
- ``phi_spacing = "half_vector"`` (the default): the azimuth axis is warped so that the
  surface gloss lobes stay smooth up to grazing.  With ``alpha`` the polar angle of the half
  vector ``normalize(wi + wo)`` and ``alpha_max = (theta_i + theta_o) / 2``,
  ``alpha_min = |theta_i - theta_o| / 2`` (its values at relative azimuth 0 and 180), the
  coordinate is ``c = 180 (alpha_max - alpha) / (alpha_max - alpha_min)`` degrees and
  ``x = c / 180 (n_phi - 1)``; ``phi_deg`` holds the nodes of ``c``.  ``c`` is 0 at azimuth 0 and
  180 at azimuth 180 and increases with the azimuth between (0 where theta_i or theta_o is 0,
  where nothing depends on azimuth).  ``"uniform"``: ``c`` is the relative azimuth itself,
  folded into [0, 180] degrees.  (At theta = 89 degrees the film's gloss lobe is about 1 degree
  wide in azimuth: a uniform azimuth grid of 361 nodes still errs by 2% there.)
- ``radius_spacing = "quadratic"``: ``x = sqrt(d / d_max) (n - 1)``; ``"uniform"``:
  ``x = d / d_max (n - 1)`` (``d_max = radius_mm[-1]``).

``x`` is clamped to ``[0, n - 1]`` (beyond the last node a table holds its edge value) and the
table is interpolated linearly in each index: trilinear for angular tables, the interpolation an
image texture with linear filtering gives.  :meth:`Tables.made_up_reflection` is that lookup; the
bake's error study measures it against the exact evaluator.

Contents
--------
- :class:`Tables` -- the arrays, with the lookups ``angular``, ``directional``, ``radial``,
  ``made_up_reflection`` (or ``reflection_parts`` looked up once, then ``mixed_reflection`` at
  each coverage and absorption) and ``directional_albedo``, and the closed-form surface gloss
  (``surface_layer``); :class:`ReflectionParts` what ``reflection_parts`` looks up.
- :func:`theta_nodes`, :func:`theta_index`, :func:`radius_nodes`, :func:`radius_index`,
  :func:`phi_index`, :func:`node_cos_azimuths` -- the closed-form grids and their inverse.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.layers import ReflectionLayer
from ..model.made_up_skin import combine, coverage_weights, mix_slots
from ..model.microfacet import ts_reflection
from ..numerics.geometry import direction, folded_azimuth_deg, half_vector, polar_angle_deg

__all__ = [
    "FORMAT_VERSION",
    "Tables",
    "ReflectionParts",
    "ANGULAR",
    "SURFACE_GLOSS",
    "DIRECTIONAL",
    "CONSTANT",
    "RADIAL",
    "THETA_SPACINGS",
    "RADIUS_SPACINGS",
    "theta_nodes",
    "theta_index",
    "phi_index",
    "node_cos_azimuths",
    "THETA_OFFSET",
    "PHI_SPACINGS",
    "radius_nodes",
    "radius_index",
]

FORMAT_VERSION = 2
"""Version 2: the surface gloss is no longer tabulated (:data:`SURFACE_GLOSS`); version 1 held
``film_gloss`` and ``skin_gloss`` tables too (:mod:`lut_baker.tables.codec` still reads it)."""

ANGULAR = ("path3_gloss",)
"""Tables of shape ``(n_theta, n_theta, n_phi, 3)``, 1/sr."""
SURFACE_GLOSS = {"film_gloss": "film", "skin_gloss": "skin"}
"""The angular parts evaluated in closed form (eq. 2's specular term, 1/sr) and the layer of
``parameters`` each comes from."""
DIRECTIONAL = (
    "film_transmittance",
    "transmission_factor",
    "film_gloss_albedo",
    "path3_gloss_albedo",
    "skin_gloss_albedo",
)
"""Tables of shape ``(n_theta, 3)``, dimensionless (transmittances and albedos)."""
CONSTANT = ("film_diffuse", "skin_diffuse", "total_reflectance", "film_transmittance_integral")
"""Per-channel constants of shape ``(3,)``: the two P_d (1/sr), the dipole's Rd, and
``Int T(w) cos(theta) dw`` over the hemisphere (sr; at most pi), which turns the skin's diffuse
part of path 3 into its albedo ``skin_diffuse T(theta_i) film_transmittance_integral``."""
RADIAL = ("profile",)
"""Tables of shape ``(n_radius, 3)``: ``R(d) / Rd`` in 1/mm^2."""

THETA_SPACINGS = ("grazing", "uniform_cos", "uniform_theta")
THETA_OFFSET = 0.03
"""Default ``mu0`` of the ``grazing`` spacing (chosen by the convergence study)."""
PHI_SPACINGS = ("half_vector", "uniform")
RADIUS_SPACINGS = ("quadratic", "uniform")
GRID_TOLERANCE_DEG = 1e-9
"""How far a stored grid node may lie from its closed form (degrees or mm)."""


# --------------------------------------------------------------------------------------------
# Closed-form grids
# --------------------------------------------------------------------------------------------
def _check_spacing(spacing: str, allowed: tuple[str, ...], name: str) -> None:
    if spacing not in allowed:
        raise ValueError(f"{name} must be one of {list(allowed)}, got {spacing!r}")


def _grazing(theta_deg: ArrayLike, offset: float) -> tuple[float, NDArray[np.float64]]:
    """``(q, atanh(q tan(theta / 2)))`` of the ``grazing`` spacing."""
    if not 0.0 < offset < 1.0:
        raise ValueError(f"theta_offset must lie in (0, 1), got {offset!r}")
    q = np.sqrt((1.0 - offset) / (1.0 + offset))
    return q, np.arctanh(q * np.tan(np.radians(theta_deg) / 2.0))


def theta_nodes(n: int, spacing: str, theta_max_deg: float,
                offset: float = THETA_OFFSET) -> np.ndarray:
    """``n`` polar nodes (degrees) from 0 to ``theta_max_deg`` with the given spacing
    (``offset``: ``mu0`` of the ``grazing`` spacing)."""
    _check_spacing(spacing, THETA_SPACINGS, "theta_spacing")
    if n < 2 or not 0.0 < theta_max_deg <= 90.0:
        raise ValueError(f"need n >= 2 and 0 < theta_max_deg <= 90, got {n}, {theta_max_deg}")
    s = np.linspace(0.0, 1.0, n)
    if spacing == "uniform_theta":
        nodes = s * theta_max_deg
    elif spacing == "uniform_cos":
        nodes = np.degrees(np.arccos(1.0 - s * (1.0 - np.cos(np.radians(theta_max_deg)))))
    else:
        q, top = _grazing(theta_max_deg, offset)
        nodes = np.degrees(2.0 * np.arctan(np.tanh(s * top) / q))
    nodes[-1] = theta_max_deg
    return nodes


def theta_index(theta_deg: ArrayLike, n: int, spacing: str, theta_max_deg: float,
                offset: float = THETA_OFFSET) -> np.ndarray:
    """Fractional index (unclamped) of polar angles ``theta_deg`` on :func:`theta_nodes`."""
    _check_spacing(spacing, THETA_SPACINGS, "theta_spacing")
    theta = np.clip(np.asarray(theta_deg, float), 0.0, 90.0)
    if spacing == "uniform_theta":
        return theta / theta_max_deg * (n - 1)
    if spacing == "uniform_cos":
        mu_max = np.cos(np.radians(theta_max_deg))
        return (1.0 - np.cos(np.radians(theta))) / (1.0 - mu_max) * (n - 1)
    _, top = _grazing(theta_max_deg, offset)
    _, x = _grazing(theta, offset)
    return x / top * (n - 1)


def phi_index(wi: ArrayLike, wo: ArrayLike, n: int,
              spacing: str = "half_vector") -> NDArray[np.float64]:
    """Fractional index of the azimuth coordinate of unit directions ``wi``, ``wo``
    ``(..., 3)`` on ``n`` nodes over [0, 180] (module docstring)."""
    _check_spacing(spacing, PHI_SPACINGS, "phi_spacing")
    to_light, to_view = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
    if spacing == "uniform":
        return folded_azimuth_deg(to_light, to_view) / 180.0 * (n - 1)
    theta_i, theta_o = polar_angle_deg(to_light), polar_angle_deg(to_view)
    alpha = polar_angle_deg(half_vector(to_light, to_view))
    span = np.minimum(theta_i, theta_o)
    fraction = (0.5 * (theta_i + theta_o) - alpha) / np.where(span > 1e-9, span, 1.0)
    share: NDArray[np.float64] = np.where(span > 1e-9, np.clip(fraction, 0.0, 1.0), 0.0)
    return share * (n - 1)


def node_cos_azimuths(theta_i_deg: ArrayLike, theta_o_deg: ArrayLike, phi_deg: ArrayLike,
                      spacing: str = "half_vector") -> NDArray[np.float64]:
    """Cosine of the relative azimuth of angular nodes at polar angles ``theta_i_deg``,
    ``theta_o_deg`` (broadcasting, e.g. ``(I, 1)`` and ``(1, O)`` or paired ``(P,)``) and
    azimuth coordinates ``phi_deg`` ``(n_phi,)``: shape ``broadcast + (n_phi,)``; the inverse
    of :func:`phi_index`."""
    _check_spacing(spacing, PHI_SPACINGS, "phi_spacing")
    a = np.radians(np.asarray(theta_i_deg, float))[..., None]
    b = np.radians(np.asarray(theta_o_deg, float))[..., None]
    c = np.asarray(phi_deg, float)
    if spacing == "uniform":
        return np.broadcast_to(np.cos(np.radians(c)), np.broadcast(a, b, c).shape).copy()
    alpha = 0.5 * (a + b) - c / 180.0 * np.minimum(a, b)
    cos_a, cos_b = np.cos(a), np.cos(b)
    dot = 0.5 * ((cos_a + cos_b) / np.cos(alpha)) ** 2 - 1.0  # |wi + wo|^2 = 2 + 2 wi.wo
    sines = np.sin(a) * np.sin(b)
    cos_phi = np.where(sines > 1e-12, (dot - cos_a * cos_b) / np.where(sines > 1e-12, sines, 1.0),
                       1.0)
    return np.clip(cos_phi, -1.0, 1.0)


def radius_nodes(n: int, spacing: str, radius_max_mm: float) -> np.ndarray:
    """``n`` radial nodes (mm) from 0 to ``radius_max_mm``."""
    _check_spacing(spacing, RADIUS_SPACINGS, "radius_spacing")
    if n < 2 or not radius_max_mm > 0.0:
        raise ValueError(f"need n >= 2 and radius_max_mm > 0, got {n}, {radius_max_mm}")
    s = np.linspace(0.0, 1.0, n)
    return radius_max_mm * (s * s if spacing == "quadratic" else s)


def radius_index(d_mm: ArrayLike, n: int, spacing: str,
                 radius_max_mm: float) -> NDArray[np.float64]:
    """Fractional index (unclamped) of distances ``d_mm`` on :func:`radius_nodes`."""
    _check_spacing(spacing, RADIUS_SPACINGS, "radius_spacing")
    s = np.asarray(d_mm, float) / radius_max_mm
    return (np.sqrt(np.maximum(s, 0.0)) if spacing == "quadratic" else s) * (n - 1)


def _corners(x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Lower node and weight of the upper node for fractional indices ``x`` (clamped)."""
    x = np.clip(x, 0.0, n - 1.0)
    low = np.minimum(np.floor(x).astype(np.intp), max(n - 2, 0))
    return low, x - low


def _linear(table: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Linear interpolation of ``table[k, ...]`` at fractional indices ``x`` (any shape)."""
    low, t = _corners(x, table.shape[0])
    t = t[..., None]
    return (1.0 - t) * table[low] + t * table[low + 1]


def _trilinear(table: np.ndarray, xi: np.ndarray, xo: np.ndarray, xp: np.ndarray) -> np.ndarray:
    """Trilinear interpolation of ``table[i, j, k, c]`` at fractional indices (same shape)."""
    i, ti = _corners(xi, table.shape[0])
    j, tj = _corners(xo, table.shape[1])
    k, tk = _corners(xp, table.shape[2])
    out = np.zeros(np.shape(ti) + table.shape[3:])
    for di, wi in ((0, 1.0 - ti), (1, ti)):
        for dj, wj in ((0, 1.0 - tj), (1, tj)):
            for dk, wk in ((0, 1.0 - tk), (1, tk)):
                out = out + (wi * wj * wk)[..., None] * table[i + di, j + dj, k + dk]
    return out


@dataclass(frozen=True, eq=False)
class ReflectionParts:
    """The lookups :meth:`Tables.made_up_reflection` mixes, at some directions: ``angular``
    (each angular part by name, ``(..., 3)``), the film's transmittance toward the light and
    the view ``t_i``, ``t_o`` ``(..., 3)``, and ``upper`` ``(...)``, where both directions are
    above the surface."""

    angular: dict
    t_i: np.ndarray
    t_o: np.ndarray
    upper: np.ndarray


@dataclass(frozen=True, eq=False)
class Tables:
    """Baked tables of one made-up skin (see the module docstring for the formula).

    Grids: ``theta_deg`` (n_theta,), ``phi_deg`` (n_phi,), ``radius_mm`` (n_radius,), laid out
    as ``theta_spacing``, ``phi_spacing`` and ``radius_spacing`` say (closed forms in the module
    docstring).  ``parameters``: the MadeUpSkin as plain data (``MadeUpSkin`` fields via
    ``as_dict``), including ``K``, ``coverage`` and ``absorption`` it was baked for; its
    ``film`` and ``skin`` layers give the closed-form surface gloss (:data:`SURFACE_GLOSS`).
    ``inter_reflection``: optional angular table, the full adding-equation sum minus path 3
    (1/sr), or None; unlike the other tables it holds the film's absorption as baked
    (``parameters["absorption"]``).  ``slab``: optional, the film as a slab at every thickness
    (:class:`lut_baker.tables.slab_tables.SlabTables`, at the baked absorption), or None (the
    paper's film only).  Arrays may be read-only (the bake broadcasts a channel
    axis of 1 to 3 without copying): copy before writing into them.
    """

    theta_deg: np.ndarray
    phi_deg: np.ndarray
    radius_mm: np.ndarray
    path3_gloss: np.ndarray
    film_transmittance: np.ndarray
    transmission_factor: np.ndarray
    film_gloss_albedo: np.ndarray
    path3_gloss_albedo: np.ndarray
    skin_gloss_albedo: np.ndarray
    film_diffuse: np.ndarray
    skin_diffuse: np.ndarray
    total_reflectance: np.ndarray
    film_transmittance_integral: np.ndarray
    profile: np.ndarray
    parameters: dict = field(default_factory=dict)
    inter_reflection: np.ndarray | None = None
    slab: Any = None
    theta_spacing: str = "grazing"
    phi_spacing: str = "half_vector"
    radius_spacing: str = "quadratic"
    theta_offset: float = THETA_OFFSET

    def __post_init__(self) -> None:
        n_theta, n_phi, n_radius = self.theta_deg.size, self.phi_deg.size, self.radius_mm.size
        expected: dict[str, tuple[int, ...]] = {name: (n_theta, n_theta, n_phi, 3)
                                                for name in ANGULAR}
        expected.update({name: (n_theta, 3) for name in DIRECTIONAL})
        expected.update({name: (3,) for name in CONSTANT})
        expected.update({name: (n_radius, 3) for name in RADIAL})
        if self.inter_reflection is not None:
            expected["inter_reflection"] = (n_theta, n_theta, n_phi, 3)
        for name, shape in expected.items():
            value = np.asarray(getattr(self, name))
            if value.shape != shape:
                raise ValueError(f"table {name!r} must have shape {shape}, got {value.shape}")
            if value.ndim and value.strides[-1] == 0:  # a broadcast over channels
                value = value[..., :1]
            if not np.isfinite(np.sum(value)) and not np.all(np.isfinite(value)):
                raise ValueError(f"table {name!r} holds NaN or Inf")
        for name in SURFACE_GLOSS:
            self.surface_layer(name)  # the parameters must give every surface's layer
        _check_spacing(self.phi_spacing, PHI_SPACINGS, "phi_spacing")
        self._check_grid("theta_deg", theta_nodes(n_theta, self.theta_spacing,
                                                  float(self.theta_deg[-1]), self.theta_offset))
        self._check_grid("phi_deg", np.linspace(0.0, 180.0, n_phi))
        self._check_grid("radius_mm", radius_nodes(n_radius, self.radius_spacing,
                                                   float(self.radius_mm[-1])))

    def _check_grid(self, name: str, nodes: np.ndarray) -> None:
        grid = np.asarray(getattr(self, name), float)
        if grid.shape != nodes.shape or np.max(np.abs(grid - nodes)) > GRID_TOLERANCE_DEG * max(
                1.0, float(np.max(np.abs(nodes)))):
            raise ValueError(f"grid {name!r} does not follow its closed form (module docstring)")

    @property
    def arrays(self) -> dict[str, np.ndarray]:
        """Every array field by name (grids and tables), for writing to disk."""
        return {
            f.name: getattr(self, f.name)
            for f in fields(self)
            if f.name != "parameters" and isinstance(getattr(self, f.name), np.ndarray)
        }

    def surface_layer(self, name: str) -> ReflectionLayer:
        """The layer of surface gloss ``name`` (:data:`SURFACE_GLOSS`) from ``parameters``, its
        diffuse part left out (``P_d = 0``): eq. 2's specular term alone."""
        layer = self.parameters.get(SURFACE_GLOSS[name]) if isinstance(self.parameters,
                                                                        dict) else None
        if not isinstance(layer, dict):
            raise ValueError(f"tables need the {SURFACE_GLOSS[name]!r} layer in their "
                             f"parameters for {name!r} (eq. 2 in closed form)")
        try:
            return _specular_layer(tuple(sorted(layer.items())))
        except TypeError as error:
            raise ValueError(f"tables' {SURFACE_GLOSS[name]!r} parameters: {error}") from None

    def surface_gloss(self, name: str, wi: NDArray[np.float64],
                      wo: NDArray[np.float64], *,
                      cosines: tuple[NDArray[np.float64], ...] | None = None
                      ) -> NDArray[np.float64]:
        """Surface gloss ``name`` (:data:`SURFACE_GLOSS`, 1/sr) at unit directions ``(..., 3)``
        in closed form (eq. 2's specular term), ``(..., 3)``; 0 below the surface.
        ``cosines``: :func:`lut_baker.model.microfacet.reflection_cosines` of the directions,
        if already computed (the surfaces share them)."""
        value = ts_reflection(wi, wo, self.surface_layer(name), check=False, cosines=cosines)
        value = value if np.ndim(value) == np.ndim(wi) else value[..., None]
        return np.broadcast_to(value, value.shape[:-1] + (3,))

    @property
    def film_transmittance_mean(self) -> NDArray[np.float64]:
        """``T_mean`` (RGB): the film's transmittance averaged over the hemisphere with weight
        ``cos(theta) / pi``, ``film_transmittance_integral / pi``; the one mean transmittance
        the uniform-light colour and the closure fits read."""
        return np.asarray(self.film_transmittance_integral, float) / np.pi

    @property
    def spacings(self) -> dict:
        """How the grids are laid out: ``theta_spacing``, ``theta_offset``, ``phi_spacing``,
        ``radius_spacing`` (module docstring)."""
        return {name: getattr(self, name)
                for name in ("theta_spacing", "theta_offset", "phi_spacing", "radius_spacing")}

    # ----------------------------------------------------------------------------------------
    # Lookups (the linear interpolation a shader does)
    # ----------------------------------------------------------------------------------------
    def theta_index(self, theta_deg: ArrayLike) -> NDArray[np.float64]:
        """Fractional table index of polar angles (degrees), unclamped."""
        return theta_index(theta_deg, self.theta_deg.size, self.theta_spacing,
                           float(self.theta_deg[-1]), self.theta_offset)

    def radius_index(self, d_mm: ArrayLike) -> NDArray[np.float64]:
        """Fractional table index of distances (mm), unclamped."""
        return radius_index(d_mm, self.radius_mm.size, self.radius_spacing,
                            float(self.radius_mm[-1]))

    def node_azimuths(self, theta_index: NDArray[np.intp] | None = None,
                      phi_index: NDArray[np.intp] | None = None) -> NDArray[np.float64]:
        """Relative azimuth (degrees) of every angular node, ``(n_theta, n_theta, n_phi)``, or
        of the sub-grid of polar nodes ``theta_index`` and azimuth nodes ``phi_index``."""
        theta = self.theta_deg if theta_index is None else self.theta_deg[theta_index]
        phi = self.phi_deg if phi_index is None else self.phi_deg[phi_index]
        return np.degrees(np.arccos(node_cos_azimuths(
            theta[:, None], theta[None, :], phi, self.phi_spacing)))

    def node_directions(self, theta_index: NDArray[np.intp] | None = None,
                        phi_index: NDArray[np.intp] | None = None
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(wi, wo)`` unit vectors ``(n_theta, n_theta, n_phi, 3)`` of the angular nodes (or
        of the sub-grid ``theta_index``, ``phi_index``): ``wo`` at azimuth 0, ``wi`` at the
        node's relative azimuth (:meth:`node_azimuths`)."""
        theta = np.radians(np.asarray(self.theta_deg, float))
        theta = theta if theta_index is None else theta[theta_index]
        phi = np.radians(self.node_azimuths(theta_index, phi_index))
        wi = direction(theta[:, None, None], phi)
        wo = direction(np.broadcast_to(theta[None, :, None], phi.shape), 0.0)
        return wi, wo

    def angular(self, name: str, wi: ArrayLike, wo: ArrayLike) -> NDArray[np.float64]:
        """Angular part ``name`` at unit directions ``(..., 3)``, shape ``(..., 3)``: a
        table interpolated trilinearly, or a surface gloss in closed form
        (:data:`SURFACE_GLOSS`)."""
        to_light, to_view = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
        if name in SURFACE_GLOSS:
            return self.surface_gloss(name, to_light, to_view)
        return _trilinear(np.asarray(getattr(self, name)),
                          self.theta_index(polar_angle_deg(to_light)),
                          self.theta_index(polar_angle_deg(to_view)),
                          phi_index(to_light, to_view, self.phi_deg.size, self.phi_spacing))

    def directional(self, name: str, theta_deg: ArrayLike) -> NDArray[np.float64]:
        """Directional table ``name`` interpolated at polar angles (degrees); ``(..., 3)``."""
        return _linear(np.asarray(getattr(self, name)), self.theta_index(theta_deg))

    def radial(self, d_mm: ArrayLike) -> NDArray[np.float64]:
        """The normalised profile ``R(d) / Rd`` (1/mm^2) at distances (mm); 0 beyond the grid."""
        d = np.asarray(d_mm, float)
        value = _linear(np.asarray(self.profile), self.radius_index(d))
        return np.where((d <= self.radius_mm[-1])[..., None], value, 0.0)

    def coverage_and_absorption(self, coverage: float | None = None,
                                absorption: ArrayLike | None = None
                                ) -> tuple[float, NDArray[np.float64]]:
        """``(coverage, absorption (3,))``: the given ones, or where None those the tables were
        baked for (``parameters``)."""
        w = self.parameters.get("coverage", 1.0) if coverage is None else coverage
        a = self.parameters.get("absorption", 0.0) if absorption is None else absorption
        return float(w), np.broadcast_to(np.asarray(a, float), (3,))

    def _combine(self, parts: dict, t_i: NDArray[np.float64], t_o: NDArray[np.float64],
                 coverage: float | None, absorption: ArrayLike | None) -> NDArray[np.float64]:
        """The module docstring's formula from angular ``parts`` (by table name) and the film
        transmittances ``t_i``, ``t_o``; the inter-reflection part, baked at one absorption,
        is scaled by ``((1 - A) / (1 - A_baked))^2``."""
        weights = coverage_weights(*self.coverage_and_absorption(coverage, absorption))
        top = parts["film_gloss"]
        if self.inter_reflection is not None:
            baked = coverage_weights(*self.coverage_and_absorption()).once
            ratio = np.where(baked > 0.0, weights.once / np.where(baked > 0.0, baked, 1.0), 0.0)
            top = top + parts["inter_reflection"] * ratio**2
        return combine(weights, **mix_slots(
            film_gloss=top, film_diffuse=self.film_diffuse, path3_gloss=parts["path3_gloss"],
            through_film=self.skin_diffuse * t_i * t_o, skin_gloss=parts["skin_gloss"],
            skin=self.skin_diffuse))

    def _angular_names(self) -> tuple[str, ...]:
        """The tabulated angular parts."""
        return ANGULAR + (("inter_reflection",) if self.inter_reflection is not None else ())

    def reflection_parts(self, wi: ArrayLike, wo: ArrayLike) -> ReflectionParts:
        """What :meth:`made_up_reflection` looks up at unit directions ``(..., 3)`` before
        coverage and absorption mix it (:class:`ReflectionParts`): one lookup serves every
        coverage and absorption at the same directions."""
        to_light, to_view = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
        return ReflectionParts(
            angular={name: self.angular(name, to_light, to_view)
                     for name in self._angular_names() + tuple(SURFACE_GLOSS)},
            t_i=self.directional("film_transmittance", polar_angle_deg(to_light)),
            t_o=self.directional("film_transmittance", polar_angle_deg(to_view)),
            upper=(to_light[..., 2] >= 0.0) & (to_view[..., 2] >= 0.0))

    def mixed_reflection(self, parts: ReflectionParts, coverage: float | None = None,
                         absorption: ArrayLike | None = None) -> NDArray[np.float64]:
        """:meth:`made_up_reflection` from its looked-up ``parts`` (:meth:`reflection_parts`)
        at a coverage and absorption (default: the baked ones)."""
        value = self._combine(parts.angular, parts.t_i, parts.t_o, coverage, absorption)
        return np.where(parts.upper[..., None], value, 0.0)

    def made_up_reflection(self, wi: ArrayLike, wo: ArrayLike, coverage: float | None = None,
                           absorption: ArrayLike | None = None) -> NDArray[np.float64]:
        """Made-up skin BRDF (1/sr, ``(..., 3)``) interpolated from the tables: the module
        docstring's formula, plus the inter-reflection table if baked (exact at the baked
        absorption only).  ``coverage``, ``absorption`` default to the baked ones; 0 where
        ``wi`` or ``wo`` is below the surface."""
        return self.mixed_reflection(self.reflection_parts(wi, wo), coverage, absorption)

    def node_values(self, coverage: float | None = None, absorption: ArrayLike | None = None,
                    theta_index: NDArray[np.intp] | None = None,
                    phi_index: NDArray[np.intp] | None = None) -> NDArray[np.float64]:
        """:meth:`made_up_reflection` at the angular nodes, ``(n_theta, n_theta, n_phi, 3)``
        (no interpolation: the directions of :meth:`node_azimuths`), or on the sub-grid
        ``theta_index``, ``phi_index`` (integer arrays)."""
        it = np.arange(self.theta_deg.size) if theta_index is None else theta_index
        ip = np.arange(self.phi_deg.size) if phi_index is None else phi_index
        whole = theta_index is None and phi_index is None
        parts = {name: np.asarray(getattr(self, name)) if whole
                 else np.asarray(getattr(self, name))[np.ix_(it, it, ip)]
                 for name in self._angular_names()}
        wi, wo = self.node_directions(theta_index, phi_index)
        parts.update({name: self.surface_gloss(name, wi, wo) for name in SURFACE_GLOSS})
        t = np.asarray(self.film_transmittance)[it]
        return self._combine(parts, t[:, None, None], t[None, :, None], coverage, absorption)

    def directional_albedo(self, theta_deg: ArrayLike, coverage: float | None = None,
                           absorption: ArrayLike | None = None) -> NDArray[np.float64]:
        """``Int f(wi, wo) cos(theta_o) dwo`` (paths 1 + 3, no inter-reflection) at incidence
        ``theta_deg`` (degrees) from the albedo tables; shape ``(..., 3)``."""
        weights = coverage_weights(*self.coverage_and_absorption(coverage, absorption))
        return combine(weights, **mix_slots(
            film_gloss=self.directional("film_gloss_albedo", theta_deg),
            film_diffuse=np.pi * self.film_diffuse,
            path3_gloss=self.directional("path3_gloss_albedo", theta_deg),
            through_film=(self.skin_diffuse * self.directional("film_transmittance", theta_deg)
                          * self.film_transmittance_integral),
            skin_gloss=self.directional("skin_gloss_albedo", theta_deg),
            skin=np.pi * self.skin_diffuse))


def _specular_layer(items: tuple[tuple[str, Any], ...]) -> ReflectionLayer:
    """A reflection layer of parameters ``items`` with ``P_d = 0`` (eq. 2's specular term);
    made once per parameter set when they are plain numbers (:func:`_cached_specular_layer`),
    checked each time otherwise."""
    try:
        hash(items)
    except TypeError:
        return ReflectionLayer(**{**dict(items), "P_d": 0.0})
    return _cached_specular_layer(items)


@lru_cache(maxsize=16)
def _cached_specular_layer(items: tuple[tuple[str, Any], ...]) -> ReflectionLayer:
    """:func:`_specular_layer` made once (its arrays read-only: shared by every lookup)."""
    layer = ReflectionLayer(**{**dict(items), "P_d": 0.0})
    for value in (layer.P_d, layer.P_s, layer.n, layer.eta):
        value.setflags(write=False)
    return layer
