"""Bake a made-up skin into lookup tables (:class:`lut_baker.tables.table_set.Tables`), fast.

Path 3 is a product of matrices per azimuthal Fourier order (docs/model.md §3): the bake evaluates
:func:`lut_baker.evaluate.two_layer.layered_fourier_matrices` with the table's polar grid as the
outer angles and sums the cosine series on the table's azimuth grid.  What makes it fast:

- the layers' kernels are evaluated from cosines alone (no direction vectors), at the
  ``n_phi // 2 + 1`` distinct azimuths of an even kernel, once per unordered pair of polar
  angles (both kernels are symmetric), and turned into cosine coefficients by one BLAS product
  (:func:`fourier_coefficients`, equal to :func:`lut_baker.model.albedo.layer_fourier_kernel`
  within 1e-8), the Fresnel term interpolated from a checked tabulation
  (:func:`fresnel_interpolated`);
- every kernel table is computed once per bake (:class:`KernelCache`);
- the bake's quadrature (:func:`lut_baker.numerics.quadrature.hemisphere_panels`) is coarser
  than the exact evaluator's, as coarse as the convergence study (``bench/bake.py --study``,
  docs/baking.md) allows;
- the surfaces' own gloss (paths 1 and the bare skin's, eq. 2's specular term) is a closed form
  and is not tabulated (:data:`lut_baker.tables.table_set.SURFACE_GLOSS`); only its directional
  albedo is, integrated through the half vector (:func:`gloss_albedos`), which costs the same
  for a lobe of any width.  The grids are sized by what path 3 goes through, the film's
  transmission and the skin's gloss (:meth:`Resolution.for_lobe`), never by the film's gloss.

Functions and types
-------------------
- :func:`bake` -- the tables of one :class:`~lut_baker.model.made_up_skin.MadeUpSkin`.
- :class:`Resolution`, :data:`RESOLUTIONS`, :func:`resolution` -- grid sizes per name;
  :func:`lobe_scale`, :func:`scaled_count` -- how narrow lobes scale them.
- :func:`fourier_coefficients` -- cosine coefficients of a layer's kernel, fast.
- :class:`KernelCache` -- memoises :func:`fourier_coefficients` within one bake.
- :func:`gloss_layer` -- a layer's Torrance-Sparrow specular part alone.
- :func:`gloss_albedos` -- the directional albedos of Torrance-Sparrow specular parts (eq. 2),
  through the half vector (any lobe width).
- :func:`path3_width_deg` -- the narrowest lobe path 3 goes through (degrees).
- :func:`inter_reflection_albedo` -- what the inter-reflections add to the albedo.
- :data:`PAPER_FILM`, :data:`SLAB_RESOLUTION` -- the bake's film modes and the slab tables' grids.
- :func:`bake_slab` -- the film as a slab at every thickness of the axis, or at one
  (:class:`lut_baker.tables.slab_tables.SlabTables`).
- :func:`profile_radius` -- where the dipole's R(d) falls to a fraction of its peak (mm).
- :func:`rgb_view` -- a channel axis of 1 or 3 as 3, without a copy.

How close the tables come to the exact evaluator is measured offline, by
:mod:`lut_baker.offline.validation.table_accuracy`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .evaluate.two_layer import inter_reflection_fourier_matrices, layered_fourier_matrices
from .model.albedo import specular_albedo
from .model.dipole import dipole_profile, dipole_total_reflectance
from .model.film_slab import face_albedo, relative_thickness, skin_star, surface_share
from .model.layers import Dipole, ReflectionLayer, TransmissionLayer
from .model.made_up_skin import MadeUpSkin, film_reflection_layer, film_transmission_layer
from .model.microfacet import (
    fresnel_reflectance,
    fresnel_transmittance,
    half_vector_cosines,
    ts_specular_from_cosines,
    ts_transmission_from_cosines,
)
from .model.params_file import skin_to_dict
from .model.slab_skin import body_gloss_weight, foundation_slab, slab_skin_parts
from .numerics import Real
from .numerics.adding_doubling import from_star, star_albedo, star_scale
from .numerics.cache import LRUCache
from .numerics.quadrature import (
    hemisphere_panels,
    order0_integral,
    panel_interpolation,
    uniform_azimuths,
)
from .tables.slab_tables import SlabTables, at_support, thickness_nodes, thickness_support
from .tables.table_set import THETA_OFFSET, Tables, node_cos_azimuths, radius_nodes, theta_nodes

__all__ = [
    "Resolution",
    "RESOLUTIONS",
    "resolution",
    "bake",
    "fourier_coefficients",
    "KernelCache",
    "fresnel_tabulation",
    "fresnel_interpolated",
    "gloss_layer",
    "gloss_albedos",
    "path3_width_deg",
    "profile_radius",
    "inter_reflection_albedo",
    "rgb_view",
    "PROFILE_FLOOR",
    "RADIUS_PRECISION",
    "COUNT_SLACK",
    "lobe_scale",
    "scaled_count",
    "REFERENCE_LOBE_DEG",
    "PAPER_FILM",
    "SLAB_RESOLUTION",
    "bake_slab",
]

PROFILE_FLOOR = 1e-4
"""The radial table ends where R(d) falls below this fraction of R(0) (in every channel)."""
RADIUS_PRECISION = 1e-13
"""Relative width of the bracket :func:`profile_radius` bisects the table's end down to."""
REFERENCE_LOBE_DEG = 19.3
"""The narrowest lobe path 3 goes through (1/e half-width, 1/n degrees) among the presets the
resolutions were chosen for (the Jensen skins' gloss).  Narrower lobes in path 3 (a film
transmission or a skin gloss of the user's) scale the angular grids up
(:meth:`Resolution.for_lobe`), up to 4x; the film's own gloss never does."""
COUNT_SLACK = 0.1
"""A scaled grid count is rounded up unless it exceeds a whole count by less than this
(nodes, panels): the Jensen skins' lobe is the reference's, 19.3 degrees, to its last bit, and
a lobe narrower by 1e-9 must not add a node to every grid (:func:`scaled_count`)."""


@dataclass(frozen=True)
class Resolution:
    """Grid sizes of one bake.

    Table grids: ``n_theta`` polar nodes (theta_i and theta_o) on [0, ``theta_max_deg``] with
    ``theta_spacing``, ``n_phi`` azimuth coordinates on [0, 180] degrees with ``phi_spacing``,
    ``n_radius`` distances with ``radius_spacing`` (closed forms in
    :mod:`lut_baker.tables.table_set`). Quadrature of the path-3 integrals: ``quad_panels``
    Gauss-Legendre panels of ``quad_points`` nodes in polar angle, ``quad_phi`` (odd) azimuth
    samples.  The gloss albedos (:func:`gloss_albedos`) need no grid of their own: their
    half-vector quadrature is at ``gloss_level`` (:func:`lut_baker.model.albedo.
    specular_albedo`'s ``level``; a preview's -1, half the nodes each way).
    """

    name: str
    n_theta: int
    n_phi: int
    n_radius: int
    quad_panels: int
    quad_points: int
    quad_phi: int
    theta_spacing: str = "grazing"
    theta_offset: float = THETA_OFFSET
    phi_spacing: str = "half_vector"
    radius_spacing: str = "quadratic"
    theta_max_deg: float = 89.0
    gloss_level: int = 0

    def for_lobe(self, width_deg: float) -> Resolution:
        """This resolution scaled for a lobe of 1/e half-width ``width_deg`` (degrees):
        intervals, panels and azimuth pairs times ``REFERENCE_LOBE_DEG / width_deg`` (1 to 4),
        by :func:`scaled_count`."""
        scale = lobe_scale(width_deg)
        if scale == 1.0:
            return self
        return replace(
            self,
            n_theta=scaled_count(self.n_theta - 1, scale) + 1,
            n_phi=scaled_count(self.n_phi - 1, scale) + 1,
            quad_panels=scaled_count(self.quad_panels, scale),
            quad_phi=2 * scaled_count(self.quad_phi // 2, scale) + 1,
        )

    def scaled_counts(self) -> dict:
        """The counts :meth:`for_lobe` scales, by name (intervals, panels, azimuth pairs)."""
        return {"n_theta": self.n_theta - 1, "n_phi": self.n_phi - 1,
                "quad_panels": self.quad_panels, "quad_phi": self.quad_phi // 2}


def lobe_scale(width_deg: float) -> float:
    """How much finer than the named resolutions a lobe of 1/e half-width ``width_deg``
    (degrees) needs the grids: ``REFERENCE_LOBE_DEG / width_deg`` held to [1, 4]."""
    return float(np.clip(REFERENCE_LOBE_DEG / width_deg, 1.0, 4.0))


def scaled_count(count: int, scale: float) -> int:
    """``count x scale`` rounded up, less :data:`COUNT_SLACK`: a whole count stays as it is
    under a last-bit change of ``scale``."""
    return int(np.ceil(count * scale - COUNT_SLACK))


RESOLUTIONS = {
    "preview": Resolution("preview", n_theta=48, n_phi=33, n_radius=128,
                          quad_panels=2, quad_points=6, quad_phi=17, gloss_level=-1),
    "default": Resolution("default", n_theta=96, n_phi=65, n_radius=320,
                          quad_panels=3, quad_points=10, quad_phi=33),
    "high": Resolution("high", n_theta=112, n_phi=97, n_radius=512,
                       quad_panels=4, quad_points=10, quad_phi=65),
}
"""Named resolutions, chosen by the convergence study in docs/baking.md."""


def resolution(name_or_resolution: str | Resolution) -> Resolution:
    """A :class:`Resolution` from its name (``preview``, ``default``, ``high``) or itself."""
    if isinstance(name_or_resolution, Resolution):
        return name_or_resolution
    if name_or_resolution not in RESOLUTIONS:
        raise ValueError(f"resolution must be one of {list(RESOLUTIONS)}, "
                         f"got {name_or_resolution!r}")
    return RESOLUTIONS[name_or_resolution]


# --------------------------------------------------------------------------------------------
# Kernels from cosines
# --------------------------------------------------------------------------------------------
FRESNEL_NODES = 1 << 16
"""Intervals of the tabulated Fresnel term on cos in [0, 1] (:func:`fresnel_interpolated`)."""
FRESNEL_TOLERANCE = 1e-8
"""Largest relative error of the tabulation, checked at every midpoint when it is built."""


@lru_cache(maxsize=16)
def fresnel_tabulation(eta: float) -> np.ndarray | None:
    """``F_r`` (eq. 2) at ``FRESNEL_NODES + 1`` uniform cosines, or None when linear
    interpolation of it errs by more than ``FRESNEL_TOLERANCE`` (eta near 1, or below 1 where
    total internal reflection puts a kink in F)."""
    nodes = fresnel_reflectance(np.linspace(0.0, 1.0, FRESNEL_NODES + 1), eta)
    mid = fresnel_reflectance((np.arange(FRESNEL_NODES) + 0.5) / FRESNEL_NODES, eta)
    error = np.abs(0.5 * (nodes[1:] + nodes[:-1]) - mid) / np.maximum(mid, 1e-300)
    return nodes if error.max() <= FRESNEL_TOLERANCE else None


@lru_cache(maxsize=16)
def _fresnel_steps(eta: float) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`fresnel_tabulation` and its differences between neighbouring nodes (what
    :func:`fresnel_interpolated` gathers: one look-up per value, not two)."""
    table = fresnel_tabulation(eta)
    return None if table is None else (table, table[1:] - table[:-1])


def fresnel_interpolated(cosine: NDArray[np.float64], eta: Real) -> NDArray[np.float64]:
    """:func:`lut_baker.model.microfacet.fresnel_reflectance` of cosines in [0, 1] with a
    trailing channel axis of 1, interpolated from :func:`fresnel_tabulation` (5x faster,
    within 1e-8 relative) when eta is one number; the formula itself otherwise."""
    steps = _fresnel_steps(float(eta)) if np.ndim(eta) == 0 else None
    if steps is None:
        return fresnel_reflectance(cosine, eta)
    table, step = steps
    x = cosine * FRESNEL_NODES
    low = np.minimum(x.astype(np.intp), FRESNEL_NODES - 1)
    return np.take(table, low) + (x - low) * np.take(step, low)


def _reflection_values(layer: ReflectionLayer, cos_a: NDArray[np.float64],
                       cos_b: NDArray[np.float64], n_dot_h: NDArray[np.float64],
                       v_dot_h: NDArray[np.float64]) -> NDArray[np.float64]:
    """``P_d + P_s (D G F_r)`` (eq. 2) of ``wa``, ``wb`` with polar cosines ``cos_a``,
    ``cos_b`` and half-vector cosines ``n_dot_h``, ``v_dot_h``, with a trailing channel axis
    (1 or 3): :func:`~lut_baker.model.microfacet.ts_specular_from_cosines` of the unit lobe,
    its Fresnel term from :func:`fresnel_interpolated`."""
    # P_s times the unit lobe, P_s (D G F_r), rather than ts_reflection_from_cosines's
    # (P_s D) G F_r: the two groupings differ in the last bits only.
    lobe = ts_specular_from_cosines(n_dot_h[..., None], v_dot_h[..., None], cos_b[..., None],
                                    cos_a[..., None], 1.0, layer.n, layer.eta, fresnel_interpolated)
    return layer.P_d + layer.P_s * lobe


def _kernel_values(layer: ReflectionLayer | TransmissionLayer, theta_a: NDArray[np.float64],
                   theta_b: NDArray[np.float64],
                   cos_phi: NDArray[np.float64]) -> NDArray[np.float64]:
    """The layer's kernel at polar angles ``theta_a``, ``theta_b`` (radians, broadcasting)
    and relative azimuths with cosine ``cos_phi``: ``f_r(wa, wb)`` for a reflecting layer,
    ``f_t(wa, -wb)`` for the film (whose lobe is the mirror image: azimuth ``phi + pi``)."""
    cos_a, sin_a, cos_b, sin_b = np.cos(theta_a), np.sin(theta_a), np.cos(theta_b), np.sin(theta_b)
    if isinstance(layer, ReflectionLayer):
        n_dot_h, v_dot_h = half_vector_cosines(cos_a, sin_a, cos_b, sin_b, cos_phi)
        return _reflection_values(layer, cos_a, cos_b, n_dot_h, v_dot_h)
    n_dot_h, v_dot_h = half_vector_cosines(cos_a, sin_a, cos_b, sin_b, -cos_phi)
    return ts_transmission_from_cosines(n_dot_h[..., None], v_dot_h[..., None], layer,
                                        fresnel_interpolated)


@lru_cache(maxsize=16)
def _cosine_matrix(n_phi: int) -> np.ndarray:
    """``(orders, n_phi // 2 + 1)``: cosine coefficients from the distinct samples of an even
    sequence on ``n_phi`` uniform azimuths (the real FFT of :func:`quadrature.fourier_kernel`)."""
    k = np.arange(n_phi // 2 + 1)
    m = k[:, None]
    multiplicity = np.where((k == 0) | (2 * k == n_phi), 1.0, 2.0)
    matrix = multiplicity * np.cos(2.0 * np.pi * m * k / n_phi) / n_phi
    matrix[1:] *= 2.0
    return matrix


def fourier_coefficients(layer: ReflectionLayer | TransmissionLayer, theta_a: ArrayLike,
                         theta_b: ArrayLike, n_phi: int) -> NDArray[np.float64]:
    """Cosine coefficients ``(orders, A, B, C)`` of a layer's kernel (the signature and result
    of :func:`lut_baker.model.albedo.layer_fourier_kernel`, within 1e-8 relative: the
    tabulated Fresnel term), evaluated at the distinct azimuths only, and once per unordered pair
    when ``theta_a`` equals ``theta_b``."""
    angles_a = np.atleast_1d(np.asarray(theta_a, float))
    angles_b = np.atleast_1d(np.asarray(theta_b, float))
    matrix = _cosine_matrix(n_phi)
    cos_phi = np.cos(uniform_azimuths(n_phi)[:matrix.shape[1]])
    if angles_a.shape == angles_b.shape and np.array_equal(angles_a, angles_b):
        upper = np.triu_indices(angles_a.size)
        values = _kernel_values(layer, angles_a[upper[0], None], angles_b[upper[1], None],
                                cos_phi)
        pairs = np.tensordot(matrix, values, axes=([1], [1]))  # (M, pairs, C)
        out = np.empty((matrix.shape[0], angles_a.size, angles_a.size, pairs.shape[-1]))
        out[:, upper[0], upper[1]] = pairs
        out[:, upper[1], upper[0]] = pairs
        return out
    values = _kernel_values(layer, angles_a[:, None, None], angles_b[None, :, None], cos_phi)
    return np.tensordot(matrix, values, axes=([1], [2]))


class KernelCache:
    """:func:`fourier_coefficients` memoised by (layer, grids): pass as ``fourier=`` to the
    matrix functions of :mod:`lut_baker.evaluate.two_layer` so that one bake evaluates each
    kernel once."""

    def __init__(self) -> None:
        self._store = LRUCache(None)

    def __call__(self, layer: ReflectionLayer | TransmissionLayer, theta_a: ArrayLike,
                 theta_b: ArrayLike, n_phi: int) -> NDArray[np.float64]:
        angles_a = np.atleast_1d(np.asarray(theta_a, float))
        angles_b = np.atleast_1d(np.asarray(theta_b, float))
        key = (id(layer), angles_a.tobytes(), angles_b.tobytes(), n_phi)
        # The layer is stored too, so that it stays alive and its id unique.
        return self._store.get_or_compute(key, lambda: (layer, fourier_coefficients(
            layer, angles_a, angles_b, n_phi)))[1]


# --------------------------------------------------------------------------------------------
# Tables
# --------------------------------------------------------------------------------------------
def gloss_layer(layer: ReflectionLayer) -> ReflectionLayer:
    """The Torrance-Sparrow specular part of a layer (``P_d`` = 0)."""
    if not np.any(layer.P_d):
        return layer
    return ReflectionLayer(P_d=0.0, P_s=layer.P_s, n=layer.n, eta=layer.eta)


def rgb_view(values: np.ndarray) -> np.ndarray:
    """A trailing channel axis of 1 or 3 as 3 (a read-only broadcast view, no copy)."""
    return np.broadcast_to(values, values.shape[:-1] + (3,))


CHUNK_ELEMENTS = 1 << 15
"""Node values computed together (temporaries of a few hundred kB stay in the CPU cache)."""


class _NodePairs:
    """The angular nodes with ``theta_i <= theta_o`` (tables are symmetric under the swap):
    ``upper`` indices into ``(n_theta, n_theta)``, their cosines and the cosine of each node's
    relative azimuth ``cos_phi`` ``(P, n_phi)``; :meth:`tables` evaluates functions on them in
    cache-sized chunks and fills the symmetric tables."""

    def __init__(self, theta_deg: NDArray[np.float64], phi_deg: NDArray[np.float64],
                 phi_spacing: str) -> None:
        theta_deg = np.asarray(theta_deg, float)
        self.n, self.n_phi = theta_deg.size, np.size(phi_deg)
        self.upper = np.triu_indices(self.n)
        a, b = np.radians(theta_deg[self.upper[0]]), np.radians(theta_deg[self.upper[1]])
        self.cos_a, self.sin_a = np.cos(a)[:, None], np.sin(a)[:, None]
        self.cos_b, self.sin_b = np.cos(b)[:, None], np.sin(b)[:, None]
        self.chunks = self.chunked(1)
        self.cos_phi = np.empty((a.size, self.n_phi))
        for chunk in self.chunks:
            self.cos_phi[chunk] = node_cos_azimuths(theta_deg[self.upper[0][chunk]],
                                                    theta_deg[self.upper[1][chunk]],
                                                    phi_deg, phi_spacing)

    def chunked(self, channels: int) -> list[slice]:
        """Slices of the pairs holding about :data:`CHUNK_ELEMENTS` values of ``channels``
        channels each."""
        step = max(1, CHUNK_ELEMENTS // (self.n_phi * channels))
        return [slice(start, start + step) for start in range(0, self.upper[0].size, step)]

    def tables(self, function: Callable[[slice], list[NDArray[np.float64]]],
               channels: Sequence[int]) -> list[np.ndarray]:
        """``function(chunk)`` -> a list of ``(len(chunk), n_phi, C_k)`` arrays for slices of
        the pairs; returns the full ``(n_theta, n_theta, n_phi, C_k)`` tables.  ``channels``:
        the ``C_k``."""
        out = [np.empty((self.n, self.n, self.n_phi, c)) for c in channels]
        for chunk in self.chunked(max(channels)):
            i, j = self.upper[0][chunk], self.upper[1][chunk]
            for table, values in zip(out, function(chunk), strict=True):
                table[i, j] = values
                table[j, i] = values
        return out


def gloss_albedos(layers: Sequence[ReflectionLayer], theta_deg: ArrayLike, *,
                  level: int = 0) -> list[np.ndarray]:
    """Directional albedos ``Int P_s D G F_r cos(theta_o) dwo`` (eq. 2's specular part
    integrated) of each reflecting layer at incidences ``theta_deg``: ``(n_theta, 3)`` each.

    The integral runs over the half vector (:func:`lut_baker.model.albedo.specular_albedo`),
    in panels sized by the layer's own lobe (1/n degrees), so that a lobe of any width is
    resolved at the same cost; the Fresnel term from :func:`fresnel_interpolated`.
    ``level``: the quadrature's (:func:`lut_baker.model.albedo.specular_albedo`)."""
    return [rgb_view(specular_albedo(np.asarray(theta_deg, float), layer, level=level,
                                     fresnel=fresnel_interpolated)) for layer in layers]


def path3_width_deg(skin: MadeUpSkin) -> float:
    """The narrowest lobe path 3 goes through (1/e half-width, degrees): the film's
    transmission (eq. 4) and the skin's gloss (eq. 2), whose product path 3 integrates; the
    film's own gloss (path 1) is not among them."""
    return min(1.0 / float(np.max(layer.n)) for layer in (skin.film_transmission,
                                                          skin.skin_reflection))


def _cosine_series(matrices: np.ndarray, pairs: _NodePairs) -> np.ndarray:
    """``sum_m F_m(theta_i, theta_o) cos(m phi)`` at the nodes: ``(M, I, I, C)`` ->
    ``(I, I, P, 3)`` (C = 1 or 3), clipped at 0 (:func:`_series_table`)."""
    return rgb_view(_series_table(matrices, pairs))


def _series_table(matrices: np.ndarray, pairs: _NodePairs) -> np.ndarray:
    """``sum_m F_m(theta_i, theta_o) cos(m phi)`` at the nodes: ``(M, I, I, C)`` ->
    ``(I, I, P, C)`` for any number of channels ``C`` (several tables at once share the
    recurrence), clipped at 0 (cos(m phi) by Chebyshev's recurrence)."""
    f = matrices[:, pairs.upper[0], pairs.upper[1], None, :]  # (M, P, 1, C)

    def values(chunk: slice) -> list[NDArray[np.float64]]:
        x = pairs.cos_phi[chunk][..., None]  # (p, n_phi, 1)
        previous, current = np.ones_like(x), x
        series = f[0, chunk] + f[1, chunk] * x
        for m in range(2, f.shape[0]):
            previous, current = current, 2.0 * x * current - previous
            series += f[m, chunk] * current
        return [np.maximum(series, 0.0)]

    return pairs.tables(values, [matrices.shape[-1]])[0]


def profile_radius(dipole: Dipole, floor: float = PROFILE_FLOOR) -> float:
    """Distance (mm) beyond which the dipole's ``R(d)`` stays below ``floor`` times ``R(0)`` in
    every channel (R decreases with d): bracketed on a geometric grid, refined once, then
    bisected in ``log d`` to :data:`RADIUS_PRECISION` (the value returned is the last bracket's
    far end).  A continuous function of the dipole: a grid's far end would jump a grid step
    (2e-4) when the crossing moves past a node."""
    def above(d: NDArray[np.float64]) -> NDArray[np.bool_]:  # (K,): R(d) > floor R(0) anywhere
        values = np.reshape(dipole_profile(d, dipole), (np.size(d), -1))
        return np.any(values > limit, axis=1)

    limit = floor * np.reshape(dipole_profile(0.0, dipole), (1, -1))
    high = 1.0
    while above(np.array([high]))[0]:
        high *= 4.0
    low = 1e-6 * high
    for _ in range(2):
        grid = np.geomspace(low, high, 256)
        last = int(np.max(np.nonzero(above(grid))[0], initial=0))
        low, high = grid[last], grid[min(last + 1, grid.size - 1)]
    while high > low * (1.0 + RADIUS_PRECISION):
        low, high = _bisected(low, high, above)
    return float(high)


BISECTION_DEPTH = 6
"""Steps of :func:`profile_radius`'s bisection whose midpoints are evaluated together."""


def _bisected(low: float, high: float,
              above: Callable[[NDArray[np.float64]], NDArray[np.bool_]]) -> tuple[float, float]:
    """Up to :data:`BISECTION_DEPTH` steps of the bisection in ``log d`` of ``[low, high]``
    (``above`` true at the low end), stopping at :data:`RADIUS_PRECISION` as one step at a
    time would: the midpoints every path could reach, ``sqrt(low high)`` as each step takes it,
    are evaluated in one call of ``above`` (the same points, the same bracket)."""
    tree: list[float] = []  # midpoints in breadth-first order: node k's halves are 2k+1, 2k+2
    brackets = [(low, high)]
    for _ in range(BISECTION_DEPTH):
        halves = []
        for a, b in brackets:
            middle = np.sqrt(a * b)
            tree.append(middle)
            halves += [(a, middle), (middle, b)]
        brackets = halves
    known = above(np.array(tree))
    node = 0
    while node < len(tree) and high > low * (1.0 + RADIUS_PRECISION):
        if known[node]:
            low, node = tree[node], 2 * node + 2
        else:
            high, node = tree[node], 2 * node + 1
    return low, high


Progress = Callable[[float, str], object]
"""``progress(fraction, message)``: told as a bake advances (fraction 0..1)."""


def _stage(progress: Progress | None, fraction: float, message: str) -> None:
    if progress is not None:
        progress(fraction, message)


def bake(skin: MadeUpSkin, resolution_name: str | Resolution = "default", *,
         inter_reflection: bool = False, progress: Progress | None = None,
         film: str | float = "paper", one_thickness: bool = False) -> Tables:
    """Bake the tables of one made-up skin (see :mod:`lut_baker.tables.table_set` for their
    meaning).

    ``resolution_name``: ``"preview"``, ``"default"``, ``"high"`` or a :class:`Resolution`;
    it is scaled up when path 3 goes through lobes narrower than the presets'
    (:func:`path3_width_deg`, :meth:`Resolution.for_lobe`).
    ``inter_reflection``: also bake the film-skin inter-reflections beyond path 3 (the adding
    equation, film underside reflecting like its top, at the skin's absorption).
    ``progress(fraction, message)``: called as the bake advances (fraction 0..1).
    ``film``: :data:`PAPER_FILM` (``"paper"``, the default), the paper's model as published
    (paths 1 + 3, its 150 um free film; the tables as they always were), or a thickness in
    micrometres: the tables also hold the film as a slab at every thickness of the axis, every
    inter-reflection in (``tables.slab``, :func:`bake_slab`), and ``parameters`` record the
    thickness (``film_thickness_um``) as the lookups' default.
    ``one_thickness``: with a thickness, the slab's tables at that thickness only (equal to the
    axis's there, :func:`bake_slab`'s ``only_um``): a preview's, which a Thickness move cannot
    read (it needs the axis's).
    """
    thickness_um = _film_thickness(film)
    if not isinstance(skin, MadeUpSkin):
        raise ValueError(f"skin must be a MadeUpSkin, got {type(skin).__name__}")
    res = resolution(resolution_name).for_lobe(path3_width_deg(skin))
    _stage(progress, 0.0, f"grids ({res.name})")
    theta_deg = theta_nodes(res.n_theta, res.theta_spacing, res.theta_max_deg, res.theta_offset)
    phi_deg = np.linspace(0.0, 180.0, res.n_phi)
    pairs = _NodePairs(theta_deg, phi_deg, res.phi_spacing)
    theta = np.radians(theta_deg)
    grid = hemisphere_panels(res.quad_panels, res.quad_points, res.quad_phi)
    kernels = KernelCache()
    film_transmission = skin.film_transmission  # absorption 0: the tables apply it afterwards
    skin_gloss = gloss_layer(skin.skin_reflection)

    _stage(progress, 0.05, "path 3 (Fourier matrices)")
    outer = np.concatenate([theta, grid.theta])
    path3_m = layered_fourier_matrices(theta, outer, film_transmission, skin_gloss, grid,
                                       fourier=kernels)
    path3 = _cosine_series(path3_m[:, :, :theta.size], pairs)
    path3_albedo = order0_integral(path3_m[0, :, theta.size:], grid)

    _stage(progress, 0.45, "transmittances and albedos")
    rows0 = kernels(film_transmission, theta, grid.theta, grid.n_phi)[0]
    fresnel_t = fresnel_transmittance(np.cos(grid.theta)[:, None],
                                      np.atleast_1d(skin.dipole.eta))
    inner_t = order0_integral(kernels(film_transmission, grid.theta, grid.theta, grid.n_phi)[0],
                              grid)
    albedos = gloss_albedos((skin.film, skin.skin_reflection), theta_deg,
                            level=res.gloss_level)

    extra = None
    if inter_reflection:
        _stage(progress, 0.7, "inter-reflections (adding equation)")
        film_t_a = film_transmission_layer(skin)
        full = inter_reflection_fourier_matrices(
            theta, theta, film_t_a, skin.skin_reflection, grid,
            film_below=film_reflection_layer(skin), fourier=kernels)
        first = layered_fourier_matrices(theta, theta, film_t_a, skin.skin_reflection, grid,
                                         fourier=kernels)
        extra = _cosine_series(full - first, pairs)

    slab = None
    if thickness_um is not None:
        _stage(progress, 0.8, "the film as a slab at its thickness" if one_thickness
               else "the film as a slab at every thickness")
        slab = bake_slab(skin, res, only_um=thickness_um if one_thickness else None)

    _stage(progress, 0.9, "radial profile")
    radius_mm = radius_nodes(res.n_radius, res.radius_spacing, profile_radius(skin.dipole))
    total = np.atleast_1d(dipole_total_reflectance(skin.dipole))
    profile = np.atleast_2d(dipole_profile(radius_mm, skin.dipole).T).T / total

    tables = Tables(
        theta_deg=theta_deg,
        phi_deg=phi_deg,
        radius_mm=radius_mm,
        path3_gloss=path3,
        film_transmittance=rgb_view(order0_integral(rows0, grid)),
        transmission_factor=rgb_view(order0_integral(rows0, grid, fresnel_t)),
        film_gloss_albedo=albedos[0],
        path3_gloss_albedo=rgb_view(path3_albedo),
        skin_gloss_albedo=albedos[1],
        film_diffuse=rgb_view(np.atleast_1d(skin.film.P_d)),
        skin_diffuse=rgb_view(np.atleast_1d(skin.skin_reflection.P_d)),
        total_reflectance=rgb_view(total),
        film_transmittance_integral=rgb_view(order0_integral(inner_t[None], grid)[0]),
        profile=rgb_view(profile),
        parameters=(skin_to_dict(skin) if thickness_um is None
                    else {**skin_to_dict(skin), "film_thickness_um": thickness_um}),
        inter_reflection=extra,
        slab=slab,
        theta_spacing=res.theta_spacing,
        theta_offset=res.theta_offset,
        phi_spacing=res.phi_spacing,
        radius_spacing=res.radius_spacing,
    )
    _stage(progress, 1.0, "done")
    return tables


def inter_reflection_albedo(skin: MadeUpSkin, theta_deg: ArrayLike,
                            resolution_name: str | Resolution = "default") -> NDArray[np.float64]:
    """Directional albedo ``Int f_extra(wi, wo) cos(theta_o) dwo`` of the inter-reflections
    beyond path 3 (the adding equation's further terms, as in :func:`bake`'s
    ``inter_reflection`` table), at the skin's absorption, before coverage: ``(n, 3)``."""
    res = resolution(resolution_name)
    grid = hemisphere_panels(res.quad_panels, res.quad_points, res.quad_phi)
    theta = np.radians(np.atleast_1d(np.asarray(theta_deg, float)))
    film_transmission = film_transmission_layer(skin)
    kernels = KernelCache()
    full = inter_reflection_fourier_matrices(theta, grid.theta, film_transmission,
                                             skin.skin_reflection, grid,
                                             film_below=film_reflection_layer(skin),
                                             fourier=kernels)
    first = layered_fourier_matrices(theta, grid.theta, film_transmission, skin.skin_reflection,
                                     grid, fourier=kernels)
    return rgb_view(order0_integral(full[0] - first[0], grid))


PAPER_FILM = "paper"
"""The bake's film mode of the paper's model as published (:func:`bake`'s ``film``)."""
SLAB_RESOLUTION = {"preview": (32, 17), "default": (48, 33), "high": (64, 49)}
"""The slab tables' angular grid per resolution, ``(n_theta, n_phi)``: coarser than path 3's
table, because the slab is known on the quadrature's polar nodes (30 at default) and
interpolated from them, and it is held at every thickness (docs/baking.md)."""


def _film_thickness(film: str | float) -> float | None:
    """None for :data:`PAPER_FILM`, else the thickness in micrometres (checked)."""
    if isinstance(film, str):
        if film != PAPER_FILM:
            raise ValueError(f"film must be {PAPER_FILM!r} or a thickness in micrometres, "
                             f"got {film!r}")
        return None
    relative_thickness(film)  # raises on a negative thickness
    return float(film)


def bake_slab(skin: MadeUpSkin, resolution_name: str | Resolution = "default", *,
              thicknesses_um: ArrayLike | None = None,
              only_um: float | None = None) -> SlabTables:
    """The film as a slab over the skin at every thickness of the axis
    (:func:`lut_baker.tables.slab_tables.thickness_nodes`, or ``thicknesses_um``), at the
    skin's absorption: per thickness, the parts of :func:`lut_baker.model.slab_skin.
    slab_skin_parts` computed on the bake's quadrature (Gauss-Legendre panels), interpolated
    to the tables' polar nodes panel by panel (:func:`~lut_baker.numerics.quadrature.
    panel_interpolation`) and summed as cosine series at the tables' azimuths.

    ``only_um``: the tables at that thickness only (one entry, what a preview needs): the
    axis's nodes either side of it baked (:func:`~lut_baker.tables.slab_tables.
    thickness_support`) and interpolated there as the axis's lookups are
    (:func:`~lut_baker.tables.slab_tables.at_support`), so that they equal the whole axis's
    tables at that thickness, for a fifth of its cost."""
    res = resolution(resolution_name)
    grid = hemisphere_panels(res.quad_panels, res.quad_points, res.quad_phi)
    n_theta, n_phi = SLAB_RESOLUTION.get(res.name, SLAB_RESOLUTION["default"])
    theta_deg = theta_nodes(n_theta, res.theta_spacing, res.theta_max_deg, res.theta_offset)
    phi_deg = np.linspace(0.0, 180.0, n_phi)
    pairs = _NodePairs(theta_deg, phi_deg, res.phi_spacing)
    lagrange = panel_interpolation(np.radians(theta_deg), res.quad_points, 0.0, np.pi / 2,
                                   res.quad_panels)
    axis = (thickness_nodes() if thicknesses_um is None
            else np.asarray(thicknesses_um, float))
    support: tuple[NDArray[np.intp], float] | None = None
    if only_um is not None:
        relative_thickness(only_um)  # raises on a negative thickness
        support = thickness_support(float(only_um), axis.size, float(axis[0]),
                                    float(axis[-2]))
    absorption = np.broadcast_to(np.asarray(skin.absorption, float), (3,))
    film = foundation_slab(skin.film, skin.film_transmission, grid, absorption)
    share = np.broadcast_to(surface_share(skin.film), (3,))  # k: the surface's share of the gloss
    face = np.broadcast_to(face_albedo(skin.film, grid), (3, grid.theta.size))  # a_g
    scale = star_scale(grid)
    lobe = skin_star(gloss_layer(skin.film), grid)  # eq. 2's gloss, star form, every order
    on_table, top_albedo, through, through_mean, below, film_albedo, body_gloss = (
        [] for _ in range(7))
    for h in (axis if support is None else axis[support[0]]):
        x = np.inf if np.isinf(h) else relative_thickness(h)
        parts = slab_skin_parts(film, x, skin.skin_reflection, face)
        body_gloss.append(np.broadcast_to(
            body_gloss_weight(film, x, face, lobe, film_top=parts.film_top), (3,)))
        kernel = from_star(parts.top, scale)  # (C, M, N, N) 1/sr
        on_table.append(lagrange @ kernel @ lagrange.T)  # (C, M, I, I)
        top_albedo.append(rgb_view(lagrange @ star_albedo(parts.top[:, 0], scale[0]).T))
        through.append(rgb_view(lagrange @ parts.through.T))
        through_mean.append(np.broadcast_to(parts.through @ (2.0 * grid.weight), (3,)))
        below.append(np.broadcast_to(parts.below, (3,)))
        film_albedo.append(rgb_view(lagrange @ np.asarray(parts.film).T))
    rows = {"top": _thickness_series(np.stack(on_table), pairs),
            "top_albedo": np.stack(top_albedo), "through": np.stack(through),
            "through_mean": np.stack(through_mean), "below": np.stack(below),
            "film_albedo": np.stack(film_albedo), "body_gloss": np.stack(body_gloss)}
    if support is not None and only_um is not None:
        rows = {name: at_support(table, support[1]) for name, table in rows.items()}
        axis = np.array([float(only_um)])
    return SlabTables(thickness_um=axis, theta_deg=theta_deg, phi_deg=phi_deg, **rows,
                      absorption=absorption.copy(), surface_share=share.copy(),
                      theta_spacing=res.theta_spacing, theta_offset=res.theta_offset,
                      phi_spacing=res.phi_spacing)


def _thickness_series(on_table: NDArray[np.float64], pairs: _NodePairs) -> NDArray[np.float64]:
    """The slab's ``top`` at the tables' nodes, ``(H, I, I, P, 3)``, from its cosine
    coefficients at every thickness ``(H, C, M, I, I)`` (C = 1 or 3): one
    :func:`_series_table` for all thicknesses, the channels and thicknesses side by side."""
    h, c, m, i = on_table.shape[:4]
    stacked = np.moveaxis(on_table, 2, 0).reshape(m, h * c, i, i)  # (M, H C, I, I)
    table = _series_table(np.moveaxis(stacked, 1, -1), pairs)  # (I, I, P, H C)
    per_thickness = np.moveaxis(table.reshape(table.shape[:3] + (h, c)), 3, 0)
    return np.array(np.broadcast_to(per_thickness, per_thickness.shape[:-1] + (3,)))
