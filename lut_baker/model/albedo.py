"""One layer integrated over the hemisphere: the albedos and transmittances of a single
reflecting or transmitting layer (paper eqs. 2 and 4 integrated; docs/model.md §2, §4).

The integrals use the azimuthal Fourier expansion of :mod:`lut_baker.numerics.quadrature`: the
order-0 coefficient of a layer's kernel, summed over polar nodes, is the azimuth-integrated
value.  The grid is sized from the layer's lobe width (1/n degrees) and refined by ``level``.

Functions
---------
- :func:`reflection_albedo` -- ``Int f_r(wi, wo) cos(theta_o) dwo`` of a reflecting layer;
  :func:`specular_albedo` -- its specular term's, through the half vector (any lobe width).
- :func:`film_transmittance`, :func:`transmission_albedo` -- ``Int f_t(w, -u) cos(theta_u) du``,
  the film's directional transmittance (by direction, by incidence angle).
- :func:`hemisphere_factor` -- the film's order-0 transmission row weighted by what lies below
  (the two-layer evaluator's path-4 factor uses it).
- :func:`reflection_kernel`, :func:`transmission_kernel`, :func:`layer_fourier_kernel` -- a
  layer's kernel and its cosine coefficients between two polar grids.
- :func:`transmission_rows` -- the film's coefficients from outer angles to the grid's nodes.
- :func:`bihemispherical` -- a directional albedo averaged over uniform (cosine-weighted)
  incident light.
- :func:`grid_for` -- the hemisphere grid that resolves the narrowest lobe of some layers.
- :func:`with_channel_axis`, :func:`drop_channel_axis` -- the channel axis of scalar layers.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.geometry import direction
from ..numerics.quadrature import (
    HemisphereGrid,
    Kernel,
    fourier_kernel,
    gauss_legendre,
    hemisphere_grid,
    mirror_quadrature,
    order0_integral,
)
from .layers import Layer, ReflectionLayer, TransmissionLayer
from .microfacet import (
    Fresnel,
    check_directions,
    fresnel_reflectance,
    ts_reflection,
    ts_specular_from_cosines,
    ts_transmission,
)

__all__ = [
    "reflection_albedo",
    "specular_albedo",
    "film_transmittance",
    "transmission_albedo",
    "hemisphere_factor",
    "reflection_kernel",
    "transmission_kernel",
    "layer_fourier_kernel",
    "transmission_rows",
    "bihemispherical",
    "BIHEMISPHERICAL_NODES",
    "grid_for",
    "with_channel_axis",
    "drop_channel_axis",
]


def with_channel_axis(values: np.ndarray, layer: Layer) -> np.ndarray:
    """Give per-layer values a trailing channel axis (length 1 for scalar layers)."""
    return values if layer.channels else values[..., None]


def drop_channel_axis(values: np.ndarray, *layers: Layer) -> np.ndarray:
    """Drop the channel axis again when every layer involved is scalar."""
    return values if any(layer.channels for layer in layers) else values[..., 0]


def grid_for(*layers: Layer, level: int = 0) -> HemisphereGrid:
    """The hemisphere grid that resolves the narrowest lobe of ``layers`` at ``level``."""
    widths = [1.0 / float(np.max(layer.n)) for layer in layers
              if isinstance(layer, ReflectionLayer | TransmissionLayer)]  # a dipole has no lobe
    return hemisphere_grid(min(widths, default=90.0), level)


def transmission_kernel(film_transmission: TransmissionLayer) -> Kernel:
    """``(w_top, u) -> f_t(w_top, -u)`` with channel axis: light from ``w_top`` leaving
    downward along ``-u`` (both arguments upper-hemisphere directions)."""

    def kernel(w_top: NDArray[np.float64], u: NDArray[np.float64]) -> NDArray[np.float64]:
        return with_channel_axis(ts_transmission(w_top, -u, film_transmission, check=False),
                                 film_transmission)

    return kernel


def reflection_kernel(layer: ReflectionLayer) -> Kernel:
    """``(wi, wo) -> f_r(wi, wo)`` with channel axis."""

    def kernel(wi: NDArray[np.float64], wo: NDArray[np.float64]) -> NDArray[np.float64]:
        return with_channel_axis(ts_reflection(wi, wo, layer, check=False), layer)

    return kernel


LayerFourier = Callable[[ReflectionLayer | TransmissionLayer, ArrayLike, ArrayLike, int],
                        NDArray[np.float64]]
"""A layer's cosine coefficients between two polar grids: :func:`layer_fourier_kernel` or an
accelerator of it (the bake's)."""


def layer_fourier_kernel(layer: ReflectionLayer | TransmissionLayer, theta_a: ArrayLike,
                         theta_b: ArrayLike, n_phi: int) -> NDArray[np.float64]:
    """Cosine coefficients ``(orders, A, B, C)`` of a layer's kernel between polar angles
    ``theta_a``, ``theta_b`` (radians): ``f_r(wa, wb)`` of a :class:`ReflectionLayer`,
    ``f_t(wa, -wb)`` of a :class:`TransmissionLayer` (see :func:`quadrature.fourier_kernel`)."""
    if isinstance(layer, ReflectionLayer):
        return fourier_kernel(reflection_kernel(layer), theta_a, theta_b, n_phi)
    return fourier_kernel(transmission_kernel(layer), theta_a, theta_b, n_phi)


def transmission_rows(theta: ArrayLike, grid: HemisphereGrid,
                      film_transmission: TransmissionLayer,
                      fourier: LayerFourier = layer_fourier_kernel) -> NDArray[np.float64]:
    """``T_m(theta, theta_u)`` for outer polar angles ``theta``: shape ``(orders, P, N, C)``."""
    return fourier(film_transmission, theta, grid.theta, grid.n_phi)


def film_transmittance(w: ArrayLike, film_transmission: TransmissionLayer, *,
                       level: int = 0) -> NDArray[np.float64]:
    """The film's directional transmittance ``Int f_t(w, -u) cos(theta_u) du`` (eq. 4
    integrated): how much of the light arriving from ``w`` crosses the film."""
    directions = check_directions("w", w)
    grid = grid_for(film_transmission, level=level)
    return hemisphere_factor(directions, grid, film_transmission,
                             np.ones((grid.theta.size, 1)), film_transmission)


def hemisphere_factor(w: NDArray[np.float64], grid: HemisphereGrid,
                      film_transmission: TransmissionLayer, below_weight: NDArray[np.float64],
                      *layers: Layer) -> NDArray[np.float64]:
    """``2 pi sum_u T_0(theta_w, theta_u) below_weight(u) W_u`` (order 0: azimuth integrated)."""
    batch = w.shape[:-1]
    theta = np.arccos(np.clip(w.reshape(-1, 3)[:, 2], 0.0, 1.0))
    t0 = transmission_rows(theta, grid, film_transmission)[0]  # (P, N, C)
    value = order0_integral(t0, grid, below_weight)
    value = np.where(w.reshape(-1, 3)[:, 2:3] >= 0.0, value, 0.0)
    return drop_channel_axis(value.reshape(batch + (value.shape[-1],)), film_transmission, *layers)


SPECULAR_POINTS = (12, 48)
"""Half-vector polar nodes per panel and azimuths of :func:`specular_albedo` at level 0 (each
level doubles both): within 0.015% of the converged albedo up to 85 degrees, 0.4% at 89, for
lobes 1 to 30 degrees wide."""
MIRROR_BELOW_DEG = 10.0
"""Lobes narrower than this (1/e half-width, degrees) are integrated through the half vector
(:func:`specular_albedo`) by :func:`reflection_albedo`: the Fourier grid, which resolves broad
lobes best at grazing, grows as the inverse square of the width and stops resolving below 5
degrees (:data:`lut_baker.numerics.quadrature.NARROWEST_LOBE_DEG`)."""


def specular_albedo(theta_i_deg: ArrayLike, layer: ReflectionLayer, *, level: int = 0,
                    fresnel: Fresnel = fresnel_reflectance) -> NDArray[np.float64]:
    """Directional albedo of eq. 2's specular term alone, ``Int P_s D G F_r cos(theta_o)
    dwo``, at incidence ``theta_i_deg`` (degrees, any shape), through the half vector
    (:func:`lut_baker.numerics.quadrature.mirror_quadrature`, panels sized by the lobe): the
    same cost for a lobe of any width.  ``fresnel``: :func:`fresnel_reflectance` or an
    accelerator of it.  Shape ``theta.shape + (C,)`` (C the layer's channels, 1 for a scalar
    layer).  ``level``: each level up doubles both node counts, level -1 halves them (a
    preview's: within 0.3% of level 0 up to 85 degrees, 1% at 89)."""
    theta = np.radians(np.asarray(theta_i_deg, float))
    scale = 2.0**int(level)
    quad = mirror_quadrature(theta.ravel(), 1.0 / float(np.max(layer.n)),
                             alpha_points=int(SPECULAR_POINTS[0] * scale),
                             phi_points=int(SPECULAR_POINTS[1] * scale))
    cos_o = quad.cos_other
    values = ts_specular_from_cosines(quad.cos_h[..., None], quad.cos_dh[..., None],
                                      cos_o[..., None], quad.cos_fixed[..., None], layer.P_s,
                                      layer.n, layer.eta, fresnel)
    value = np.einsum("napc,nap->nc", values, quad.weight * cos_o)
    return value.reshape(theta.shape + (value.shape[-1],))


def reflection_albedo(theta_i_deg: ArrayLike, layer: ReflectionLayer, *,
                      level: int = 0) -> NDArray[np.float64]:
    """Directional albedo ``Int f_r(wi, wo) cos(theta_o) dwo`` of a reflecting layer (eq. 2
    integrated) at incidence ``theta_i_deg`` (degrees, any shape): the azimuthal Fourier
    expansion's order 0, or for a lobe narrower than :data:`MIRROR_BELOW_DEG`, ``pi P_d`` plus
    :func:`specular_albedo`.

    >>> matte = ReflectionLayer(P_d=0.5 / np.pi, P_s=0.0, n=0.1, eta=1.5)  # albedo pi P_d
    >>> print(np.round(reflection_albedo([0.0, 60.0, 85.0], matte), 4))
    [0.5 0.5 0.5]
    >>> gloss = ReflectionLayer(P_d=0.0, P_s=1.0, n=0.1, eta=1.5)  # a 10-degree lobe
    >>> print(np.round(reflection_albedo([0.0, 60.0], gloss), 4))
    [0.0141 0.0077]
    """
    theta = np.radians(np.asarray(theta_i_deg, float))
    if 1.0 / float(np.max(layer.n)) < MIRROR_BELOW_DEG:
        diffuse = np.pi * with_channel_axis(np.asarray(layer.P_d, float), layer)
        value = diffuse + specular_albedo(theta_i_deg, layer, level=level)
        return drop_channel_axis(value, layer)
    grid = grid_for(layer, level=level)
    r0 = fourier_kernel(reflection_kernel(layer), theta.ravel(), grid.theta, grid.n_phi)[0]
    value = order0_integral(r0, grid)
    return drop_channel_axis(value.reshape(theta.shape + (value.shape[-1],)), layer)


def transmission_albedo(theta_i_deg: ArrayLike, film_transmission: TransmissionLayer, *,
                        level: int = 0) -> NDArray[np.float64]:
    """Directional transmittance of the film at incidence ``theta_i_deg`` (degrees).

    >>> diffuse = TransmissionLayer(P_d=0.9 / np.pi, P_t=0.0, n=0.05, eta=1.3)
    >>> print(np.round(transmission_albedo([0.0, 60.0], diffuse), 4))
    [0.9 0.9]
    """
    theta = np.radians(np.asarray(theta_i_deg, float))
    return film_transmittance(direction(theta, 0.0), film_transmission, level=level)


BIHEMISPHERICAL_NODES = 48
"""Gauss-Legendre nodes in ``cos(theta)`` of :func:`bihemispherical`."""


def bihemispherical(directional: Callable[[NDArray[np.float64]], ArrayLike],
                    nodes: int = BIHEMISPHERICAL_NODES) -> NDArray[np.float64]:
    """``2 Int_0^1 a(mu) mu dmu``: the directional albedo ``directional(theta_deg)`` (degrees
    in, ``(N,)`` or ``(N, C)`` out) averaged over uniform, cosine-weighted incident light (the
    bihemispherical albedo; by reciprocity also the mean radiance a convex object shows under a
    uniform white sky).

    >>> round(float(bihemispherical(lambda theta_deg: np.cos(np.radians(theta_deg)))), 6)
    0.666667
    """
    mu, w = gauss_legendre(nodes, 0.0, 1.0)
    values = np.asarray(directional(np.degrees(np.arccos(mu))), dtype=float)
    weight = (2.0 * w * mu).reshape((-1,) + (1,) * (values.ndim - 1))
    return np.sum(weight * values, axis=0)
