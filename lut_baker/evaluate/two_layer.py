"""The two-layer functions of made-up skin (paper section 3, docs/model.md §3).

Path 3, light through the film, reflected by the skin's surface, back through the film::

    f_cs(wi, wo) = Int Int f_t(wi, -u) f_r,s(u, v) f_t(wo, -v) cos(theta_u) cos(theta_v) du dv

and the angular factor of path 4 (the film seen from above, the skin's Fresnel below)::

    t(w) = Int f_t(w, -u) F_t(eta_s, u) cos(theta_u) du

are evaluated by quadrature over the hemisphere with an azimuthal Fourier expansion: per order
m the double integral is a product of matrices.  The grid is sized from the lobe widths (1/n
degrees) and refined by ``level``; :func:`layered_reflection_converged` doubles it until two
levels agree, which makes it the project's exact evaluator.

Functions
---------
- :func:`layered_reflection` -- ``f_cs`` (paper eq. 7, docs/model.md §3) at given directions.
- :func:`layered_reflection_converged` -- the same, refined until two levels agree.
- :func:`transmission_factor` -- path 4's angular factor (paper eq. 8, docs/model.md §3).
- :func:`layered_fourier_matrices` -- the per-order matrices of ``f_cs`` between two polar grids
  (the layers' kernels from :func:`lut_baker.model.albedo.layer_fourier_kernel` by default; a
  faster one with the same signature may be passed as ``fourier``).
- :func:`inter_reflection_fourier_matrices` -- the adding equation's terms beyond path 3.
- :func:`inner_matrices` -- the skin bounce of those matrices (the film's crossings are
  :func:`lut_baker.model.albedo.transmission_rows`).

The single layer's integrals (its albedo, the film's transmittance) are in
:mod:`lut_baker.model.albedo`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.albedo import (
    LayerFourier,
    drop_channel_axis,
    grid_for,
    hemisphere_factor,
    layer_fourier_kernel,
    transmission_rows,
)
from ..model.layers import Dipole, ReflectionLayer, TransmissionLayer
from ..model.microfacet import check_directions, fresnel_transmittance
from ..numerics.geometry import relative_azimuth
from ..numerics.quadrature import HemisphereGrid, azimuth_convolution_factor

__all__ = [
    "layered_reflection",
    "layered_reflection_converged",
    "transmission_factor",
    "layered_fourier_matrices",
    "inter_reflection_fourier_matrices",
    "inner_matrices",
]

POINT_CHUNK = 64
"""Evaluation points processed together (bounds memory at a few tens of MB)."""


def inner_matrices(grid: HemisphereGrid, film_transmission: TransmissionLayer,
                   skin_reflection: ReflectionLayer,
                   fourier: LayerFourier = layer_fourier_kernel) -> NDArray[np.float64]:
    """``c_m^2 W B_m W`` on the grid's polar nodes: shape ``(orders, N, N, C)``."""
    b = fourier(skin_reflection, grid.theta, grid.theta, grid.n_phi)
    w = grid.weight
    factor = azimuth_convolution_factor(grid.orders) ** 2
    return factor[:, None, None, None] * w[None, :, None, None] * b * w[None, None, :, None]


def _batched_matmul(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``sum_u left[m, p, u, c] right[m, u, q, c]`` with BLAS, channel by channel."""
    left_c = np.moveaxis(left, -1, 1)  # (M, C, P, U)
    right_c = np.moveaxis(right, -1, 1)  # (M, C, U, Q)
    return np.moveaxis(left_c @ right_c, 1, -1)  # (M, P, Q, C)


def layered_fourier_matrices(theta_i: ArrayLike, theta_o: ArrayLike,
                             film_transmission: TransmissionLayer,
                             skin_reflection: ReflectionLayer, grid: HemisphereGrid, *,
                             fourier: LayerFourier = layer_fourier_kernel,
                             orders: int | None = None) -> NDArray[np.float64]:
    """Fourier matrices ``F_m(theta_i, theta_o)`` of path 3: ``f_cs = sum_m F_m cos(m phi)``.

    ``theta_i``, ``theta_o``: polar angles (radians) of the outer directions; returns shape
    ``(orders, len(theta_i), len(theta_o), C)``.  Cost: one kernel table per layer and two
    batched matrix products per order (docs/model.md §3).  ``fourier``: the function giving each
    layer's kernel coefficients (signature of :func:`layer_fourier_kernel`, e.g. a faster or cached
    one). ``orders``: keep only the first orders (1 for azimuth-integrated quantities such as
    albedos: the kernels are still sampled at every azimuth, but the products run once).
    """
    keep = slice(None, orders)
    inner = inner_matrices(grid, film_transmission, skin_reflection, fourier)[keep]
    rows = transmission_rows(theta_i, grid, film_transmission, fourier)[keep]
    cols = transmission_rows(theta_o, grid, film_transmission, fourier)[keep]
    return _batched_matmul(_batched_matmul(rows, inner), np.swapaxes(cols, 1, 2))


def inter_reflection_fourier_matrices(theta_i: ArrayLike, theta_o: ArrayLike,
                                      film_transmission: TransmissionLayer,
                                      skin_reflection: ReflectionLayer, grid: HemisphereGrid,
                                      *, film_below: ReflectionLayer | None = None,
                                      fourier: LayerFourier = layer_fourier_kernel
                                      ) -> NDArray[np.float64]:
    """Fourier matrices of all inter-reflections between film and skin (the adding equation).

    Path 3 is the first term of ``T (I - R_s R_f)^-1 R_s T``, where ``R_f`` is the film's
    underside reflecting like its top (``film_below``, a :class:`ReflectionLayer`; omit it for
    path 3 alone).  Shapes and ``fourier`` as :func:`layered_fourier_matrices`.
    """
    if film_below is None:
        return layered_fourier_matrices(theta_i, theta_o, film_transmission, skin_reflection,
                                        grid, fourier=fourier)
    # S = c_m^2 W B_m W carries the two azimuth integrals around a skin bounce; each further
    # bounce off the film's underside adds R_f S, so the sum is S (I - R_f S)^-1 = (I - S R_f)^-1 S.
    skin_m = inner_matrices(grid, film_transmission, skin_reflection, fourier)
    film_m = fourier(film_below, grid.theta, grid.theta, grid.n_phi)
    channels = max(film_m.shape[-1], skin_m.shape[-1])
    skin_m = np.broadcast_to(skin_m, skin_m.shape[:3] + (channels,))
    film_m = np.broadcast_to(film_m, skin_m.shape)
    eye = np.eye(grid.theta.size)
    adding = np.empty(skin_m.shape)
    for m in range(skin_m.shape[0]):
        for c in range(channels):
            s_m = skin_m[m, :, :, c]
            adding[m, :, :, c] = np.linalg.solve(eye - s_m @ film_m[m, :, :, c], s_m)
    rows = transmission_rows(theta_i, grid, film_transmission, fourier)
    cols = transmission_rows(theta_o, grid, film_transmission, fourier)
    return _batched_matmul(_batched_matmul(rows, adding), np.swapaxes(cols, 1, 2))


def _fourier_sum(matrices_diag: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """``sum_m F_m(p) cos(m phi_p)`` for per-point coefficients ``(orders, P, C)``."""
    m = np.arange(matrices_diag.shape[0])
    cosines = np.cos(m[:, None] * phi[None, :])  # (orders, P)
    return np.einsum("mpc,mp->pc", matrices_diag, cosines)


def layered_reflection(wi: ArrayLike, wo: ArrayLike, film_transmission: TransmissionLayer,
                       skin_reflection: ReflectionLayer, *,
                       level: int = 0, grid: HemisphereGrid | None = None
                       ) -> NDArray[np.float64]:
    """Path 3 of made-up skin, ``f_cs(wi, wo)`` (paper eq. 7, docs/model.md §3), without the cosine.

    ``wi``, ``wo``: unit vectors ``(..., 3)``; 0 where either is below the surface.  Units:
    film_transmission units squared times skin units (albedo units in, albedo units out).
    """
    wi = check_directions("wi", wi)
    wo = check_directions("wo", wo)
    wi, wo = np.broadcast_arrays(wi, wo)
    batch = wi.shape[:-1]
    wi = wi.reshape(-1, 3)
    wo = wo.reshape(-1, 3)
    grid = grid or grid_for(film_transmission, skin_reflection, level=level)
    inner = inner_matrices(grid, film_transmission, skin_reflection)
    theta_i = np.arccos(np.clip(wi[:, 2], 0.0, 1.0))
    theta_o = np.arccos(np.clip(wo[:, 2], 0.0, 1.0))
    phi = relative_azimuth(wi, wo)
    out = np.empty((wi.shape[0],
                    3 if (film_transmission.channels or skin_reflection.channels) else 1))
    for start in range(0, wi.shape[0], POINT_CHUNK):
        s = slice(start, start + POINT_CHUNK)
        rows = transmission_rows(theta_i[s], grid, film_transmission)  # (M, P, N, C)
        cols = transmission_rows(theta_o[s], grid, film_transmission)  # (M, P, N, C)
        through = _batched_matmul(rows, inner)  # (M, P, N, C)
        diag = np.einsum("mpnc,mpnc->mpc", through, cols)
        out[s] = _fourier_sum(diag, phi[s])
    upper = (wi[:, 2] >= 0.0) & (wo[:, 2] >= 0.0)
    out = np.where(upper[:, None], np.maximum(out, 0.0), 0.0)
    return drop_channel_axis(out.reshape(batch + (out.shape[-1],)), film_transmission,
                             skin_reflection)


def layered_reflection_converged(wi: ArrayLike, wo: ArrayLike,
                                 film_transmission: TransmissionLayer,
                                 skin_reflection: ReflectionLayer, *, rtol: float = 1e-4,
                                 max_level: int = 3) -> tuple[NDArray[np.float64], float, int]:
    """The exact evaluator of path 3: :func:`layered_reflection` at increasing ``level`` until
    two successive levels agree within ``rtol`` relative (of the larger of the value and 1e-3
    of the batch's peak).  Returns ``(values, achieved_relative_change, level)``; raises
    ``RuntimeError`` if ``max_level`` is reached without convergence."""
    previous = layered_reflection(wi, wo, film_transmission, skin_reflection, level=0)
    for level in range(1, max_level + 1):
        current = layered_reflection(wi, wo, film_transmission, skin_reflection, level=level)
        scale = np.maximum(np.abs(current), 1e-3 * np.max(np.abs(current)))
        change = float(np.max(np.abs(current - previous) / np.where(scale > 0, scale, 1.0)))
        if change <= rtol:
            return current, change, level
        previous = current
    raise RuntimeError(
        f"layered_reflection did not converge to rtol={rtol:g} by level {max_level} "
        f"(last relative change {change:.3g})"
    )


def transmission_factor(w: ArrayLike, film_transmission: TransmissionLayer, dipole: Dipole, *,
                        level: int = 0) -> NDArray[np.float64]:
    """Path 4's angular factor ``t(w) = Int f_t(w, -u) F_t(eta_s, u) cos(theta_u) du``
    (paper eq. 8, docs/model.md §3): light through the film into the skin (or out of it, by
    reciprocity).  ``w``: unit vectors ``(..., 3)``, 0 below the surface."""
    directions = check_directions("w", w)
    grid = grid_for(film_transmission, level=level)
    # (N, C): the dipole may be RGB through its coefficients with a scalar eta.
    fresnel_t = fresnel_transmittance(np.cos(grid.theta)[:, None], np.atleast_1d(dipole.eta))
    fresnel_t = np.broadcast_to(fresnel_t, (grid.theta.size, 3 if dipole.channels else 1))
    return hemisphere_factor(directions, grid, film_transmission, fresnel_t, dipole)

