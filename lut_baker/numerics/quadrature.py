"""Quadrature rules, and the azimuthal Fourier expansion of isotropic kernels.

Every integration rule of ``lut_baker`` is written here once.  An isotropic kernel
``K(theta_a, theta_b, dphi)`` (even in ``dphi``) is expanded as
``K = sum_m K_m(theta_a, theta_b) cos(m dphi)``; chaining kernels over the hemisphere then
becomes a product of matrices per Fourier order (docs/model.md §3).

Functions
---------
- :func:`gauss_legendre` -- composite Gauss-Legendre nodes and weights on an interval;
  :func:`legendre_rules_data`, the rules on [-1, 1] it reads from
  :data:`LEGENDRE_RULES_FILE` (numpy's, stored at :data:`STORED_LEGENDRE_POINTS`).
- :func:`panel_interpolation` -- values at those nodes interpolated to other points, panel by
  panel (Lagrange).
- :func:`midpoint_nodes` -- the midpoint rule's nodes on an interval.
- :func:`trapezoid_weights` -- trapezoid-rule weights on any monotonic grid.
- :func:`cumulative_trapezoid` -- the running trapezoid integral.
- :func:`uniform_azimuths` -- equally spaced azimuths on a full turn.
- :func:`mirror_weighted_azimuths` -- an azimuth rule dense at the mirror azimuth.
- :func:`hemisphere_panels` -- Gauss-Legendre panels in polar angle, odd azimuth count.
- :func:`hemisphere_grid` -- the same sized from the narrowest lobe (degrees), so sharp lobes
  are resolved.
- :class:`MirrorQuadrature`, :func:`mirror_quadrature` -- direction pairs through their half
  vector, for lobes of any width around the mirror direction; :func:`mirror_alpha_edges`, its
  panels.
- :func:`order0_integral` -- an order-0 kernel integrated over the hemisphere.
- :func:`fourier_kernel` -- cosine coefficients ``K_m`` of an isotropic kernel on grids.
- :func:`azimuth_convolution_factor` -- ``2 pi`` for m = 0, ``pi`` otherwise.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .geometry import direction

__all__ = [
    "gauss_legendre",
    "LEGENDRE_RULES_FILE",
    "STORED_LEGENDRE_POINTS",
    "legendre_rules_data",
    "panel_interpolation",
    "midpoint_nodes",
    "trapezoid_weights",
    "cumulative_trapezoid",
    "uniform_azimuths",
    "mirror_weighted_azimuths",
    "HemisphereGrid",
    "hemisphere_panels",
    "hemisphere_grid",
    "MirrorQuadrature",
    "mirror_alpha_edges",
    "mirror_quadrature",
    "order0_integral",
    "fourier_kernel",
    "azimuth_convolution_factor",
    "grazing_azimuth_width_deg",
]

GAUSS_POINTS_PER_PANEL = 8
WIDEST_PANEL_DEG = 22.5
"""Panels are never wider than this, so the G kink of broad lobes still converges."""
GRAZING_DEG = 89.0
"""The most grazing direction (degrees) the evaluator resolves."""
NARROWEST_LOBE_DEG = 5.0
"""Lobes narrower than this (n > 0.2 / degree) are not resolved further: the grid would cost
O(width^-4).  The exact evaluator reports them as not converged rather than guess."""


def _read_only(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """The arrays, made read-only (cached rules hand the same arrays to every caller)."""
    for array in arrays:
        array.setflags(write=False)
    return arrays


LEGENDRE_RULES_FILE = Path(__file__).with_name("legendre_rules.json")
"""numpy's ``leggauss`` at the point counts the runtime uses (:data:`STORED_LEGENDRE_POINTS`),
its nodes and weights as exact hexadecimal floats (written by tools/legendre_rules.py)."""
STORED_LEGENDRE_POINTS = (5, 6, 10, 12, 16, 24, 32, 48, 96)
"""The counts stored: the bake's panels (6, 10), the half-vector rules (5, 12, 24; 12, 48,
96), the view and albedo rules (16, 32, 48)."""


def legendre_rules_data(points: tuple[int, ...] = STORED_LEGENDRE_POINTS) -> dict:
    """numpy's ``leggauss`` at each count, as :data:`LEGENDRE_RULES_FILE` stores it."""
    rules = {}
    for count in points:
        x, w = np.polynomial.legendre.leggauss(count)
        rules[str(count)] = {"nodes": [float(v).hex() for v in x],
                             "weights": [float(v).hex() for v in w]}
    return {"source": "numpy.polynomial.legendre.leggauss", "rules": rules}


@lru_cache(maxsize=1)
def _stored_legendre_rules() -> dict[int, tuple[np.ndarray, np.ndarray]]:
    data = json.loads(LEGENDRE_RULES_FILE.read_text())
    return {int(count): (np.array([float.fromhex(v) for v in rule["nodes"]]),
                         np.array([float.fromhex(v) for v in rule["weights"]]))
            for count, rule in data["rules"].items()}


@lru_cache(maxsize=16)
def _legendre_rule(points: int) -> tuple[np.ndarray, np.ndarray]:
    """numpy's ``leggauss(points)`` on [-1, 1] (read-only arrays), once per process and
    count, read from :data:`LEGENDRE_RULES_FILE` when stored: it costs 0.2 ms at 5 nodes to
    3 ms at 96 in every new process, and every interval and panel count of
    :func:`gauss_legendre` shares it."""
    stored = _stored_legendre_rules().get(points)
    x, w = np.polynomial.legendre.leggauss(points) if stored is None else stored
    _read_only(x, w)
    return x, w


@lru_cache(maxsize=32)
def gauss_legendre(points: int, start: float = 0.0, stop: float = 1.0,
                   panels: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """``(nodes, weights)`` of the composite Gauss-Legendre rule: ``panels`` equal panels of
    ``points`` nodes on [``start``, ``stop``], ``Int f dx ~ sum_k weights_k f(nodes_k)``
    (read-only arrays, in the units of ``start`` and ``stop``)."""
    x, w = _legendre_rule(points)
    half = (stop - start) / 2.0 / panels
    mid = start + half * (2.0 * np.arange(panels) + 1.0)
    nodes = (mid[:, None] + half * x[None, :]).ravel()
    weights = np.tile(half * w, panels)
    _read_only(nodes, weights)
    return nodes, weights


def panel_interpolation(x: ArrayLike, points: int, start: float = 0.0, stop: float = 1.0,
                        panels: int = 1) -> np.ndarray:
    """The matrix ``(len(x), panels * points)`` that interpolates values at the nodes of
    :func:`gauss_legendre` (same arguments) to the points ``x``: within each panel the
    polynomial through its ``points`` nodes (barycentric Lagrange weights), ``x`` outside
    [``start``, ``stop``] taken by the first or last panel.

    >>> nodes, _ = gauss_legendre(4, 0.0, 1.0, 2)
    >>> x = np.array([0.0, 0.3, 0.75, 1.0])
    >>> bool(np.allclose(panel_interpolation(x, 4, 0.0, 1.0, 2) @ nodes**3, x**3))
    True
    """
    targets = np.atleast_1d(np.asarray(x, float))
    nodes, _ = gauss_legendre(points, start, stop, panels)
    local = nodes[:points] - nodes[0]
    bary = 1.0 / np.prod(local[:, None] - local[None, :] + np.eye(points), axis=1)
    width = (stop - start) / panels
    panel = np.clip(np.floor((targets - start) / width).astype(np.intp), 0, panels - 1)
    matrix = np.zeros((targets.size, nodes.size))
    for row, (value, k) in enumerate(zip(targets, panel, strict=True)):
        own = nodes[k * points:(k + 1) * points]
        offset = value - own
        hit = np.isclose(offset, 0.0, rtol=0.0, atol=1e-14)
        if np.any(hit):
            weights = hit.astype(float)
        else:
            weights = bary / offset
            weights = weights / weights.sum()
        matrix[row, k * points:(k + 1) * points] = weights
    return matrix


def midpoint_nodes(count: int, start: float, stop: float) -> np.ndarray:
    """The midpoint rule's ``count`` nodes on [``start``, ``stop``] (each weighs
    ``(stop - start) / count``)."""
    return start + (np.arange(count) + 0.5) * (stop - start) / count


def trapezoid_weights(x: np.ndarray, axis: int = -1) -> np.ndarray:
    """Trapezoid-rule weights of nodes ``x`` along ``axis`` (any monotonic spacing, in the
    units of ``x``): ``Int f dx ~ sum_k weights_k f(x_k)``."""
    x = np.moveaxis(np.asarray(x, float), axis, -1)
    dx = np.diff(x, axis=-1)
    w = np.zeros_like(x)
    w[..., :-1] += 0.5 * dx
    w[..., 1:] += 0.5 * dx
    return np.moveaxis(w, -1, axis)


def cumulative_trapezoid(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``Int_{x_0}^{x_k} y dx`` for ``k = 1..K-1`` by the trapezoid rule along the first axis
    of ``y`` ``(K, ...)``: shape ``(K - 1, ...)``, units of ``y`` times those of ``x``."""
    y = np.asarray(y, float)
    dx = np.diff(np.asarray(x, float)).reshape((-1,) + (1,) * (y.ndim - 1))
    return np.cumsum(0.5 * (y[1:] + y[:-1]) * dx, axis=0)


def uniform_azimuths(n_phi: int) -> np.ndarray:
    """``2 pi k / n_phi`` for ``k = 0..n_phi-1`` (radians): the periodic trapezoid rule's
    nodes on a full turn (each weighs ``2 pi / n_phi``)."""
    return 2.0 * np.pi * np.arange(n_phi) / n_phi


@lru_cache(maxsize=8)
def mirror_weighted_azimuths(count: int, power: int) -> tuple[np.ndarray, np.ndarray]:
    """``(cos(phi_k), w_k)`` with ``Int_0^{2 pi} f(phi) dphi ~ sum_k w_k f(phi_k)`` for even
    ``f`` (radians): Gauss-Legendre in ``s`` after ``phi = pi (1 - s^power)``, dense at the
    mirror azimuth ``pi`` (read-only arrays)."""
    s, w = gauss_legendre(count)
    weight = 2.0 * np.pi * power * s ** (power - 1) * w
    cos_phi = np.cos(np.pi * (1.0 - s**power))
    _read_only(cos_phi, weight)
    return cos_phi, weight


@dataclass(frozen=True)
class HemisphereGrid:
    """Quadrature over the upper hemisphere with the projected-solid-angle measure.

    ``theta``: polar nodes (radians); ``weight``: ``cos(theta) sin(theta) dtheta`` weights, so
    ``Int f cos(theta) dw ~ sum_j sum_k f(theta_j, phi_k) weight_j (2 pi / n_phi)``;
    ``n_phi``: odd number of uniform azimuth samples, orders ``0..n_phi // 2``.
    """

    theta: np.ndarray
    weight: np.ndarray
    n_phi: int

    @property
    def orders(self) -> int:
        """Number of Fourier orders represented exactly by ``n_phi`` samples."""
        return self.n_phi // 2 + 1

    @property
    def size(self) -> tuple[int, int]:
        return (self.theta.size, self.n_phi)

    @property
    def phi(self) -> np.ndarray:
        """The ``n_phi`` azimuths (radians, :func:`uniform_azimuths`)."""
        return uniform_azimuths(self.n_phi)

    @property
    def phi_weight(self) -> float:
        """The weight of each azimuth, ``2 pi / n_phi`` (radians)."""
        return 2.0 * np.pi / self.n_phi


@lru_cache(maxsize=16)
def hemisphere_panels(panels: int, points: int, n_phi: int) -> HemisphereGrid:
    """Quadrature over the upper hemisphere (projected solid angle): ``panels`` equal
    Gauss-Legendre panels of ``points`` nodes over [0, 90] degrees, ``n_phi`` (odd) azimuths."""
    if panels < 1 or points < 1 or n_phi < 3 or n_phi % 2 == 0:
        raise ValueError(f"need panels, points >= 1 and odd n_phi >= 3, got "
                         f"{panels}, {points}, {n_phi}")
    theta, dtheta = gauss_legendre(points, 0.0, np.pi / 2, panels)
    (weight,) = _read_only(np.cos(theta) * np.sin(theta) * dtheta)
    return HemisphereGrid(theta=theta, weight=weight, n_phi=n_phi)


def hemisphere_grid(lobe_width_deg: float = 90.0, level: int = 0) -> HemisphereGrid:
    """A grid that resolves a lobe of 1/e half-width ``lobe_width_deg`` (degrees).

    Polar angle: ``[0, 90]`` degrees cut into panels no wider than 1.5 lobe widths (and
    22.5 degrees), each with 8 Gauss-Legendre nodes; azimuth: at least 4 samples per lobe width
    and at least one per the lobe's azimuthal width at 89 degrees
    (:func:`grazing_azimuth_width_deg`), where two grazing directions make a lobe narrowest
    in azimuth.  Each ``level`` doubles both.  Widths
    below ``NARROWEST_LOBE_DEG`` are clamped to it.
    """
    if not np.isfinite(lobe_width_deg) or lobe_width_deg <= 0:
        raise ValueError(f"lobe_width_deg must be > 0, got {lobe_width_deg!r}")
    if level < 0:
        raise ValueError(f"level must be >= 0, got {level!r}")
    width = min(max(float(lobe_width_deg), NARROWEST_LOBE_DEG), 90.0)
    panels = int(np.ceil(90.0 / min(1.5 * width, WIDEST_PANEL_DEG))) * 2**level
    samples_per_turn = max(64, int(np.ceil(4 * 360.0 / width)),
                           int(np.ceil(360.0 / grazing_azimuth_width_deg(width))))
    samples_per_turn += samples_per_turn % 2  # even, so n_phi is odd (no Nyquist order)
    n_phi = samples_per_turn * 2**level + 1
    return hemisphere_panels(panels, GAUSS_POINTS_PER_PANEL, n_phi)


def grazing_azimuth_width_deg(lobe_width_deg: float, theta_deg: float = GRAZING_DEG) -> float:
    """Azimuthal width (degrees) of a lobe of half-vector width ``lobe_width_deg`` around the
    mirror (or straight-through) direction when both directions lie at ``theta_deg``.

    Both near the horizon, ``h ~ (sin t * dphi, 2 cos t)`` so the lobe spans only
    ``dphi ~ 2 cos(t) tan(width)``: far narrower than ``width`` itself (0.35 degrees for a
    10 degree lobe at 89 degrees).  Widths beyond 45 degrees are taken as 45 (such lobes cover
    the hemisphere anyway).
    """
    width = np.radians(min(float(lobe_width_deg), 45.0))
    return float(np.degrees(2.0 * np.cos(np.radians(theta_deg)) * np.tan(width)))


MIRROR_ALPHA_POINTS = 6
"""Gauss-Legendre nodes per half-vector panel of :func:`mirror_quadrature`."""
MIRROR_PHI_POINTS = 16
"""Gauss-Legendre half-vector azimuths on [0, 180] degrees of :func:`mirror_quadrature`."""
MIRROR_NARROWEST_DEG = 0.01
"""Lobe widths below this (degrees) are resolved as this one."""


@dataclass(frozen=True, eq=False)
class MirrorQuadrature:
    """Direction pairs for integrals of a lobe around the mirror direction, at any width.

    For each fixed direction ``d`` (``fixed``, ``(N, 3)``, at polar angles ``theta`` and
    azimuth 0) the other direction ``e = 2 (d.h) h - d`` (``other``, ``(N, A, P, 3)``) runs
    over the upper hemisphere through its half vector ``h = normalize(d + e)``, at polar
    angles ``alpha`` from the normal and azimuths ``phi`` in [0, 180] degrees (the other half
    by symmetry):  ``Int g(d, e) dw_e ~ sum weight * g`` with ``dw_e = 4 (d.h) dw_h``.
    ``cos_h`` is ``n.h``, ``cos_dh`` is ``d.h = e.h`` and ``cos_other`` is ``n.e``, each
    ``(N, A, P)``; ``sin_h`` and ``phi`` (``(P,)``) the half vector's polar sine and azimuth,
    from which ``other`` is built when asked (an integral over ``n.e`` alone, such as
    :func:`lut_baker.model.albedo.specular_albedo`, never needs it).
    """

    theta: np.ndarray
    fixed: np.ndarray
    weight: np.ndarray
    cos_h: np.ndarray
    cos_dh: np.ndarray
    cos_other: np.ndarray
    sin_h: np.ndarray
    phi: np.ndarray

    @property
    def cos_fixed(self) -> np.ndarray:
        """``n.d`` broadcast to the nodes, ``(N, A, P)``."""
        return np.broadcast_to(np.cos(self.theta)[:, None, None], self.weight.shape)

    @cached_property
    def other(self) -> np.ndarray:
        """``e = 2 (d.h) h - d``, ``(N, A, P, 3)`` (its z-component is ``cos_other``)."""
        twice = 2.0 * self.cos_dh
        out = np.empty(self.weight.shape + (3,))
        np.subtract(twice * (self.sin_h * np.cos(self.phi)), self.fixed[:, 0, None, None],
                    out=out[..., 0])
        np.subtract(twice * (self.sin_h * np.sin(self.phi)), 0.0, out=out[..., 1])
        out[..., 2] = self.cos_other
        return out


def mirror_alpha_edges(width_deg: float) -> np.ndarray:
    """Panel edges (radians) in the half vector's polar angle for a lobe of 1/e half-width
    ``width_deg`` (degrees): 0, w, 2w, 4w, ... doubling up to 90 degrees, so that panels are
    narrow where the lobe is and wide where it is flat."""
    width = max(float(width_deg), MIRROR_NARROWEST_DEG)
    edges = [0.0, min(width, 90.0)]
    while edges[-1] < 90.0:
        edges.append(min(2.0 * edges[-1], 90.0))
    return np.radians(np.array(edges))


def mirror_quadrature(theta: ArrayLike, width_deg: float, *,
                      alpha_points: int = MIRROR_ALPHA_POINTS,
                      phi_points: int = MIRROR_PHI_POINTS) -> MirrorQuadrature:
    """:class:`MirrorQuadrature` for fixed directions at polar angles ``theta`` (radians) and
    lobes no narrower than ``width_deg`` (degrees, the 1/e half-width in the half vector's
    polar angle, 1/n for eq. 2's D).

    The half vector's polar angle is split at :func:`mirror_alpha_edges`; for each azimuth
    the panels stop where ``e`` meets the horizon, ``alpha_max = psi / 2 + 45 degrees`` with
    ``tan(psi) = tan(theta) cos(phi)``, so every panel integrates a smooth function (a
    Lambertian integrates to 1 within 1e-8 at 6 x 16 nodes per panel, up to 89 degrees).
    Panels beyond ``alpha_max`` have zero length and zero weight."""
    angles = np.atleast_1d(np.asarray(theta, float))
    edges = mirror_alpha_edges(width_deg)
    x, wx = gauss_legendre(alpha_points)
    phi, wphi = gauss_legendre(phi_points, 0.0, np.pi)
    sin_t, cos_t = np.sin(angles)[:, None], np.cos(angles)[:, None]
    alpha_max = 0.5 * np.arctan2(sin_t * np.cos(phi), cos_t) + 0.25 * np.pi  # (N, P)
    low = np.minimum(edges[None, :-1, None], alpha_max[:, None, :])  # (N, K, P)
    length = np.minimum(edges[None, 1:, None], alpha_max[:, None, :]) - low
    # The nodes' arrays (N, K * A, P) are the cost: each is worked on in place, in the same
    # operations and order as written in the comments (products and sums commute exactly).
    alpha = length[:, :, None] * x[None, None, :, None]
    alpha += low[:, :, None]  # low + length x
    alpha = alpha.reshape(angles.size, -1, phi.size)
    d_alpha = (length[:, :, None] * wx[None, None, :, None]).reshape(alpha.shape)
    sin_a = np.sin(alpha)
    cos_a = np.cos(alpha, out=alpha)
    fixed = np.stack([sin_t[:, 0], np.zeros_like(angles), cos_t[:, 0]], axis=-1)
    sin_d, cos_d = sin_t[:, :, None], cos_t[:, :, None]
    # d.h with h = (sin_a cos(phi), hy, cos_a) and d = (sin_t, 0, cos_t); hy only for
    # ``other``, when asked
    cos_dh = sin_a * np.cos(phi)
    cos_dh *= sin_d
    scratch = np.multiply(cos_d, cos_a)
    cos_dh += scratch
    np.clip(cos_dh, 0.0, 1.0, out=cos_dh)
    # n.e of e = 2 (d.h) h - d, held at 0 against rounding at the horizon
    cos_other = np.multiply(2.0, cos_dh, out=scratch)
    cos_other *= cos_a
    cos_other -= cos_d
    np.maximum(cos_other, 0.0, out=cos_other)
    weight = 8.0 * cos_dh  # 2 (the other half) 4 (d.h) sin_a d_alpha wphi
    weight *= sin_a
    weight *= d_alpha
    weight *= wphi
    return MirrorQuadrature(theta=angles, fixed=fixed, weight=weight, cos_h=cos_a,
                            cos_dh=cos_dh, cos_other=cos_other, sin_h=sin_a, phi=phi)


def order0_integral(matrix0: np.ndarray, grid: HemisphereGrid,
                    weight: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """``2 pi sum_u K_0(theta, theta_u) weight_u W_u``: an order-0 kernel ``matrix0``
    ``(P, N, C)`` (cosine coefficients on ``grid``'s polar nodes) integrated over the hemisphere
    (projected solid angle), ``weight`` ``(N, C)`` or None a factor per node: ``(P, C)``."""
    w = grid.weight[:, None] if weight is None else grid.weight[:, None] * weight
    return 2.0 * np.pi * np.sum(matrix0 * w[None], axis=1)


def azimuth_convolution_factor(orders: int) -> np.ndarray:
    """``Int_0^{2pi} cos(m(a - x)) cos(m(x - b)) dx / cos(m(a - b))``: 2 pi at m = 0, else pi."""
    factor = np.full(orders, np.pi)
    factor[0] = 2.0 * np.pi
    return factor


Kernel = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]
"""An isotropic kernel ``kernel(wa, wb)`` of unit vectors ``(..., 3)``: ``(..., C)``."""


def fourier_kernel(kernel: Kernel, theta_a: ArrayLike, theta_b: ArrayLike,
                   n_phi: int) -> NDArray[np.float64]:
    """Cosine coefficients of an isotropic kernel.

    ``kernel(wa, wb)`` takes direction arrays ``(A, B, n_phi, 3)`` with ``wa`` at azimuth 0 and
    ``wb`` at azimuth ``2 pi k / n_phi`` and returns ``(A, B, n_phi, C)``.  Returns ``K_m`` of
    shape ``(n_phi // 2 + 1, A, B, C)`` with ``K(dphi) = sum_m K_m cos(m dphi)``.
    """
    angles_a = np.atleast_1d(np.asarray(theta_a, float))
    angles_b = np.atleast_1d(np.asarray(theta_b, float))
    phi = uniform_azimuths(n_phi)
    wa = direction(angles_a[:, None, None], np.zeros((1, 1, 1)))
    wb = direction(angles_b[None, :, None], phi[None, None, :])
    wa = np.broadcast_to(wa, (angles_a.size, angles_b.size, n_phi, 3))
    values = kernel(wa, wb)
    spectrum = np.fft.rfft(values, axis=2).real / n_phi
    spectrum[:, :, 1:] *= 2.0
    return np.moveaxis(spectrum, 2, 0)
