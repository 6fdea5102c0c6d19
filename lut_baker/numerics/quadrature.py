"""Hemisphere quadrature and azimuthal Fourier expansion of isotropic kernels.

An isotropic kernel ``K(theta_a, theta_b, dphi)`` (even in ``dphi``) is expanded as
``K = sum_m K_m(theta_a, theta_b) cos(m dphi)``; chaining kernels over the hemisphere then
becomes a product of matrices per Fourier order (SPEC section 3).

Functions
---------
- :func:`hemisphere_grid` -- Gauss-Legendre panels in polar angle, uniform odd azimuth count,
  sized from the narrowest lobe (degrees) so sharp lobes are resolved.
- :func:`direction` -- unit vectors from polar and azimuth angles (radians).
- :func:`fourier_kernel` -- cosine coefficients ``K_m`` of an isotropic kernel on grids.
- :func:`azimuth_convolution_factor` -- ``2 pi`` for m = 0, ``pi`` otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "HemisphereGrid",
    "hemisphere_grid",
    "direction",
    "fourier_kernel",
    "azimuth_convolution_factor",
    "relative_azimuth",
    "grazing_azimuth_width_deg",
]

GAUSS_POINTS_PER_PANEL = 8
WIDEST_PANEL_DEG = 22.5
"""Panels are never wider than this, so the G kink of broad lobes still converges."""
GRAZING_DEG = 89.0
"""The most grazing direction the evaluator promises to resolve (issue 2: to 89 degrees)."""
NARROWEST_LOBE_DEG = 5.0
"""Lobes narrower than this (n > 0.2 / degree) are not resolved further: the grid would cost
O(width^-4).  The exact evaluator reports them as not converged rather than guess."""


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
    x, w = np.polynomial.legendre.leggauss(GAUSS_POINTS_PER_PANEL)
    edges = np.linspace(0.0, np.pi / 2, panels + 1)
    half = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[1:] + edges[:-1])
    theta = (mid[:, None] + half[:, None] * x[None, :]).ravel()
    dtheta = (half[:, None] * w[None, :]).ravel()
    weight = np.cos(theta) * np.sin(theta) * dtheta
    samples_per_turn = max(64, int(np.ceil(4 * 360.0 / width)),
                           int(np.ceil(360.0 / grazing_azimuth_width_deg(width))))
    samples_per_turn += samples_per_turn % 2  # even, so n_phi is odd (no Nyquist order)
    n_phi = samples_per_turn * 2**level + 1
    return HemisphereGrid(theta=theta, weight=weight, n_phi=n_phi)


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


def direction(theta, phi) -> np.ndarray:
    """Unit vectors ``(..., 3)`` for polar angle ``theta`` and azimuth ``phi`` (radians)."""
    theta, phi = np.broadcast_arrays(np.asarray(theta, float), np.asarray(phi, float))
    s = np.sin(theta)
    return np.stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)], axis=-1)


def relative_azimuth(wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """Azimuth of ``wi`` minus that of ``wo`` (radians); 0 where either is the normal."""
    return np.arctan2(wi[..., 1], wi[..., 0]) - np.arctan2(wo[..., 1], wo[..., 0])


def azimuth_convolution_factor(orders: int) -> np.ndarray:
    """``Int_0^{2pi} cos(m(a - x)) cos(m(x - b)) dx / cos(m(a - b))``: 2 pi at m = 0, else pi."""
    factor = np.full(orders, np.pi)
    factor[0] = 2.0 * np.pi
    return factor


def fourier_kernel(kernel, theta_a, theta_b, n_phi: int) -> np.ndarray:
    """Cosine coefficients of an isotropic kernel.

    ``kernel(wa, wb)`` takes direction arrays ``(A, B, n_phi, 3)`` with ``wa`` at azimuth 0 and
    ``wb`` at azimuth ``2 pi k / n_phi`` and returns ``(A, B, n_phi, C)``.  Returns ``K_m`` of
    shape ``(n_phi // 2 + 1, A, B, C)`` with ``K(dphi) = sum_m K_m cos(m dphi)``.
    """
    theta_a = np.atleast_1d(np.asarray(theta_a, float))
    theta_b = np.atleast_1d(np.asarray(theta_b, float))
    phi = 2.0 * np.pi * np.arange(n_phi) / n_phi
    wa = direction(theta_a[:, None, None], np.zeros((1, 1, 1)))
    wb = direction(theta_b[None, :, None], phi[None, None, :])
    wa = np.broadcast_to(wa, (theta_a.size, theta_b.size, n_phi, 3))
    values = kernel(wa, wb)
    spectrum = np.fft.rfft(values, axis=2).real / n_phi
    spectrum[:, :, 1:] *= 2.0
    return np.moveaxis(spectrum, 2, 0)
