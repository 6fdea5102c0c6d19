"""The paper's eq. 2 fitted to in-plane reflectance factors, and where it misses
(docs/model.md §2.1, §4, §6).

Geometry.  An in-plane row has the light at ``theta_i`` and the camera at signed ``theta_o``,
on opposite sides of the normal for ``theta_o > 0``.  In the paper's reflection protocol
(:func:`~lut_baker.offline.measured.protocols.reflection_geometry`: ``theta_i = alpha + psi/2``,
``theta_r = alpha - psi/2``, signed in one frame) the camera's signed angle is
``theta_r = -theta_o``, so::

    psi = theta_i + theta_o,    alpha = (theta_i - theta_o) / 2

(``alpha = 0``: the mirror direction ``theta_o = theta_i``).  ``psi`` must be > 0, which the
published files satisfy (``theta_i + theta_o >= 30``).

Units.  A reflectance factor is the BRDF relative to an ideal Lambertian white,
``R = pi f_r`` (no cosine), so the paper's camera signal (eq. 1) is
``I = f_r cos(theta_i) = R cos(theta_i) / pi``; fitted on that signal the layer's ``P_d`` and
``P_s`` come out in 1/sr, the unit docs/model.md §4 gives them (a white Lambertian film has
``P_d = 1/pi``).  The fit itself is
:func:`~lut_baker.offline.measured.layer_fit.fit_reflection` (relative residuals), one channel
at a time.

Functions and types
-------------------
- :func:`reflection_data` -- rows (angles, reflectance factor) as the fit's ``ReflectionData``.
- :func:`model_factor` -- a layer's reflectance factor ``pi f_r`` at in-plane geometries.
- :class:`ChannelFits` -- one fit per RGB channel, the model at the rows, its errors.
- :func:`fit_channels` -- eq. 2 per channel to the rows at chosen incidences.
- :func:`relative_error` -- rms and worst of ``model / measured - 1``.
- :func:`alternate_incidences` -- the held-out split: 20/40/60 (or 30/50/70) against the rest.
- :func:`misses` -- where eq. 2 misses, in numbers: lobe peaks, back-scatter, grazing view.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model.layers import ReflectionLayer
from ...model.microfacet import ts_reflection
from .layer_fit import FitResult, fit_reflection
from .measurements import ReflectionData
from .protocols import in_plane_direction
from .spectra import luminance

__all__ = [
    "reflection_data",
    "model_factor",
    "ChannelFits",
    "fit_channels",
    "relative_error",
    "alternate_incidences",
    "misses",
]

CHANNELS = ("R", "G", "B")
CURVE_STEP_DEG = 0.1
"""Step (degrees) of the dense theta_o grid on which the model's peak is found."""


def reflection_data(theta_i_deg, theta_o_deg, factor) -> ReflectionData:
    """Rows ``(theta_i, theta_o, R)`` as the paper's reflection samples: ``psi = theta_i +
    theta_o``, ``alpha = (theta_i - theta_o)/2``, signal ``R cos(theta_i) / pi`` (module
    docstring)."""
    theta_i = np.asarray(theta_i_deg, dtype=float)
    theta_o = np.asarray(theta_o_deg, dtype=float)
    psi = theta_i + theta_o
    if np.any(psi <= 0.0):
        row = int(np.argmax(psi <= 0.0))
        raise ValueError(f"theta_i + theta_o must be > 0 degrees (row {row + 1}: theta_i = "
                         f"{theta_i[row]:g}, theta_o = {theta_o[row]:g}); eq. 2's fit needs the "
                         f"light and the camera apart")
    signal = np.asarray(factor, dtype=float) * np.cos(np.radians(theta_i)) / np.pi
    return ReflectionData(psi_deg=psi, alpha_deg=(theta_i - theta_o) / 2.0,
                          intensity_counts=signal)


def model_factor(layer: ReflectionLayer, theta_i_deg, theta_o_deg) -> np.ndarray:
    """``pi f_r(wi, wo)`` (eq. 2, no cosine) with the light at ``theta_i`` and the camera at
    signed ``theta_o`` (positive: opposite side of the normal)."""
    wi = in_plane_direction(np.asarray(theta_i_deg, dtype=float))
    wo = in_plane_direction(-np.asarray(theta_o_deg, dtype=float))
    wi, wo = np.broadcast_arrays(wi, wo)
    return np.pi * ts_reflection(wi, wo, layer)


def relative_error(model, measured) -> tuple[float, float]:
    """``(rms, worst |.|)`` of ``model / measured - 1`` over all entries."""
    ratio = np.asarray(model, dtype=float) / np.asarray(measured, dtype=float) - 1.0
    return float(np.sqrt(np.mean(ratio**2))), float(np.max(np.abs(ratio)))


@dataclass(frozen=True, eq=False)
class ChannelFits:
    """Eq. 2 fitted per RGB channel: ``fits`` (R, G, B :class:`FitResult`), the incidences fitted
    (``fitted_deg``) and the rows' ``model`` factors ``(N, 3)``."""

    fits: tuple[FitResult, FitResult, FitResult]
    fitted_deg: tuple[float, ...]
    theta_i_deg: np.ndarray
    theta_o_deg: np.ndarray
    measured: np.ndarray
    model: np.ndarray

    @property
    def layers(self) -> tuple[ReflectionLayer, ...]:
        """The fitted layer per channel (``P_d``, ``P_s`` in 1/sr; ``n`` in 1/degree)."""
        return tuple(fit.params for fit in self.fits)

    def predict(self, theta_i_deg, theta_o_deg) -> np.ndarray:
        """The model's RGB factors ``(..., 3)`` at in-plane geometries."""
        return np.stack([model_factor(layer, theta_i_deg, theta_o_deg)
                         for layer in self.layers], axis=-1)

    def error(self, incidences_deg=None) -> tuple[float, float]:
        """:func:`relative_error` over all channels of the rows at ``incidences_deg`` (default
        all rows)."""
        rows = _rows(self.theta_i_deg, incidences_deg)
        return relative_error(self.model[rows], self.measured[rows])

    def channel_error(self, channel: int, incidences_deg=None) -> tuple[float, float]:
        """:func:`relative_error` of one channel over the rows at ``incidences_deg``."""
        rows = _rows(self.theta_i_deg, incidences_deg)
        return relative_error(self.model[rows, channel], self.measured[rows, channel])


def _rows(theta_i_deg: np.ndarray, incidences_deg) -> np.ndarray:
    if incidences_deg is None:
        return np.ones(theta_i_deg.shape, dtype=bool)
    return np.isin(theta_i_deg, np.asarray(incidences_deg, dtype=float))


def fit_channels(theta_i_deg, theta_o_deg, rgb, incidences_deg=None) -> ChannelFits:
    """Fit ``ReflectionLayer(P_d, P_s, n, eta)`` (eq. 2) per channel of ``rgb`` ``(N, 3)``
    (reflectance factors) to the rows at ``incidences_deg`` (default all), and evaluate the fits
    at every row."""
    theta_i = np.asarray(theta_i_deg, dtype=float)
    theta_o = np.asarray(theta_o_deg, dtype=float)
    rgb = np.asarray(rgb, dtype=float)
    rows = _rows(theta_i, incidences_deg)
    if not np.any(rows):
        raise ValueError(f"no rows at incidences {list(incidences_deg)}")
    fits = tuple(fit_reflection(reflection_data(theta_i[rows], theta_o[rows], rgb[rows, c]))
                 for c in range(3))
    fitted = tuple(float(v) for v in np.unique(theta_i[rows]))
    model = np.stack([model_factor(fit.params, theta_i, theta_o) for fit in fits], axis=-1)
    return ChannelFits(fits, fitted, theta_i, theta_o, rgb, model)


def alternate_incidences(incidences_deg) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``(fit, held out)``: every other incidence from the lowest, i.e. 20/40/60 where 20 was
    measured, else 30/50/70; the rest is held out."""
    ordered = sorted(float(v) for v in incidences_deg)
    return tuple(ordered[0::2]), tuple(ordered[1::2])


def misses(fits: ChannelFits) -> dict:
    """Where the all-incidence fit misses, in luminance (Rec.709 ``Y``) per incidence.

    - ``peak_deg``: ``(measured, model)`` theta_o of the maximum; the model's on a
      :data:`CURVE_STEP_DEG` grid over the measured theta_o range.
    - ``peak_ratio``: measured maximum over the model's maximum.
    - ``mirror_deg``: the mirror direction ``theta_o = theta_i``, for reference.
    - ``back_ratio``: mean and min/max of measured/model over the rows with ``theta_o < 0``
      (absent where none was measured).
    - ``grazing``: at the largest theta_o, ``(theta_o, measured/model)``, and the measured and
      model rises from the row nearest ``theta_o = 0`` (``from_deg``) to it, and measured/model
      at that row (``near_normal_ratio``: the diffuse level's change with incidence).
    """
    y_meas = luminance(fits.measured)
    y_model = luminance(fits.model)
    out = {}
    for incidence in np.unique(fits.theta_i_deg):
        rows = np.flatnonzero(fits.theta_i_deg == incidence)
        theta_o = fits.theta_o_deg[rows]
        dense = np.arange(theta_o.min(), theta_o.max() + 0.5 * CURVE_STEP_DEG, CURVE_STEP_DEG)
        curve = luminance(fits.predict(np.full_like(dense, incidence), dense))
        top = rows[np.argmax(y_meas[rows])]
        entry = {
            "mirror_deg": float(incidence),
            "peak_deg": (float(fits.theta_o_deg[top]), float(dense[np.argmax(curve)])),
            "peak_ratio": float(y_meas[top] / curve.max()),
        }
        back = rows[theta_o < 0.0]
        if back.size:
            ratio = y_meas[back] / y_model[back]
            entry["back_ratio"] = (float(ratio.mean()), float(ratio.min()), float(ratio.max()))
        last = rows[np.argmax(theta_o)]
        near0 = rows[np.argmin(np.abs(theta_o))]
        entry["grazing"] = {
            "theta_o_deg": float(fits.theta_o_deg[last]),
            "ratio": float(y_meas[last] / y_model[last]),
            "measured_rise": float(y_meas[last] / y_meas[near0]),
            "model_rise": float(y_model[last] / y_model[near0]),
            "from_deg": float(fits.theta_o_deg[near0]),
            "near_normal_ratio": float(y_meas[near0] / y_model[near0]),
        }
        out[float(incidence)] = entry
    return out
