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
``P_d = 1/pi``).

Tilt.  A sample that sits tilted by ``tau`` in the plane of incidence sees the light at
``theta_i + tau`` and the camera at ``theta_o - tau`` (an offset of alpha,
:func:`~lut_baker.offline.measured.protocols.tilted`), so its mirror direction lies at
``theta_o = theta_i + 2 tau``; its reflectance factor is ``pi f_r`` at those angles (a white
reference in the same mount cancels the change of irradiance).  The tilt is one number per
measurement, shared by the three channels and every incidence; it is fitted as a nuisance
parameter with its standard error and never reaches the render (the layers are the sample's
own).

The fit (:func:`fit_channels`).  The three channels are fitted at once
(:func:`~lut_baker.offline.measured.layer_fit.fit_reflection_sets`: relative residuals,
multi-start), one eq. 2 layer each, in one of the forms of :class:`FitModel`: the full eq. 2
with or without the tilt, eq. 2 with eta held at the paper film's (P_s and eta tied), or
``P_d`` alone (no lobe).

A well-posed fit (:func:`well_posed`).  A fit that produces a shipped number must be determined
by its data, so the form is chosen from the full fit's own diagnostics, in this order, refitting
after each change until none applies:

1. the tilt is left out when it runs to its bound (+-5 degrees) or its standard error exceeds
   its size;
2. the lobe is left out (``P_d`` alone, no tilt: a constant has no direction to align) when in
   some channel its roughness ``n`` sits at a bound or has a standard error beyond its value;
3. eta is held at the paper film's 1.19 (P_s then carries ``P_s F``) when in some channel eta
   sits at a bound, ``eta - 1`` has a standard error beyond its value, or P_s and eta correlate
   beyond 0.99 (only their product is determined);
4. the lobe is left out when in some channel ``P_s`` (with eta held, if it was) sits at a bound
   or has a standard error beyond its value.

(``P_s`` is judged after eta: while the two are degenerate, P_s alone is not determined even
where the lobe's height ``P_s F`` is.)

Every decision is reported with its deciding number and threshold (:class:`Decision`).

Functions and types
-------------------
- :func:`reflection_data` -- rows (angles, reflectance factor) as the fit's ``ReflectionData``.
- :func:`model_factor` -- the reflectance factor eq. 2 predicts at in-plane geometries.
- :class:`FitModel` -- which form of eq. 2 is fitted (lobe, eta, tilt).
- :class:`ChannelFits` -- the three channels' fits, the tilt, the model at the rows, errors.
- :func:`fit_channels` -- eq. 2 in one form to the rows at chosen incidences.
- :class:`Decision`, :class:`ModelChoice` -- the well-posed form and why.
- :func:`well_posed` -- the fit whose every parameter the data determine.
- :func:`relative_error` -- rms and worst of ``model / measured - 1``.
- :func:`alternate_incidences` -- the held-out split: 20/40/60 (or 30/50/70) against the rest.
- :func:`misses` -- where eq. 2 misses, in numbers: lobe peaks, back-scatter, grazing view.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...model.layers import ReflectionLayer
from ...model.presets import paper
from .fit_results import FitResult, JointFit
from .fit_solver import TILT
from .layer_fit import fit_reflection_sets
from .measurements import ReflectionData, reflection_counts
from .spectra import luminance

__all__ = [
    "CHANNELS",
    "WELL_POSED_STDERR",
    "DEGENERATE_CORRELATION",
    "reflection_data",
    "model_factor",
    "FitModel",
    "ChannelFits",
    "fit_channels",
    "Decision",
    "ModelChoice",
    "well_posed",
    "relative_error",
    "alternate_incidences",
    "misses",
]

CHANNELS = ("R", "G", "B")
CURVE_STEP_DEG = 0.1
"""Step (degrees) of the dense theta_o grid on which the model's peak is found."""
WELL_POSED_STDERR = 1.0
"""A parameter is determined when its standard error is at most this fraction of its value
(for eta: of ``eta - 1``; for the tilt: of its size)."""
DEGENERATE_CORRELATION = 0.99
"""P_s and eta correlated beyond this (in size): only their product is determined."""


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


def model_factor(layer: ReflectionLayer, theta_i_deg, theta_o_deg,
                 tilt_deg: float = 0.0) -> np.ndarray:
    """The reflectance factor ``pi f_r`` eq. 2 predicts with the light at ``theta_i`` and the
    camera at signed ``theta_o`` (positive: opposite side of the normal), the sample tilted by
    ``tilt_deg`` (module docstring): the signal ``I = f_r N.L``
    (:func:`~lut_baker.offline.measured.measurements.reflection_counts`) times
    ``pi / cos(theta_i)``."""
    theta_i, theta_o = np.broadcast_arrays(np.asarray(theta_i_deg, dtype=float),
                                           np.asarray(theta_o_deg, dtype=float))
    data = reflection_data(theta_i.ravel(), theta_o.ravel(), np.ones(theta_i.size))
    factor = reflection_counts(data, layer, tilt_deg) * np.pi / np.cos(np.radians(
        theta_i.ravel()))
    return factor.reshape(theta_i.shape)


@dataclass(frozen=True)
class FitModel:
    """Which form of eq. 2 is fitted to a measurement's three channels: ``lobe`` (``P_s``,
    ``n`` fitted; ``False``: ``P_d`` alone), ``eta`` (held at this value; ``None``: fitted per
    channel) and ``tilt`` (the sample's tilt fitted, shared by the channels)."""

    lobe: bool = True
    eta: float | None = None
    tilt: bool = True

    def describe(self, short: bool = False) -> str:
        """E.g. ``"eq. 2 (P_d, P_s, n, eta per channel) + tilt"``; ``short``: ``"eq. 2 +
        tilt"``."""
        if not self.lobe:
            text = "P_d alone" if short else "P_d alone (no lobe)"
        elif self.eta is None:
            text = "eq. 2" if short else "eq. 2 (P_d, P_s, n, eta per channel)"
        else:
            text = (f"eq. 2, eta = {self.eta:g}" if short
                    else f"eq. 2 with eta = {self.eta:g} (P_d, P_s, n per channel)")
        return text + (" + tilt" if self.tilt else "")


def relative_error(model, measured) -> tuple[float, float]:
    """``(rms, worst |.|)`` of ``model / measured - 1`` over all entries."""
    ratio = np.asarray(model, dtype=float) / np.asarray(measured, dtype=float) - 1.0
    return float(np.sqrt(np.mean(ratio**2))), float(np.max(np.abs(ratio)))


@dataclass(frozen=True, eq=False)
class ChannelFits:
    """Eq. 2 fitted to the three RGB channels at once: ``fits`` (R, G, B :class:`FitResult`),
    ``joint`` (the joint fit: the shared tilt, the starts, every warning), the form fitted
    (``fit_model``), the incidences fitted (``fitted_deg``) and the rows' ``model`` factors
    ``(N, 3)`` (the tilt included)."""

    fits: tuple[FitResult[ReflectionLayer], ...]
    fitted_deg: tuple[float, ...]
    theta_i_deg: np.ndarray
    theta_o_deg: np.ndarray
    measured: np.ndarray
    model: np.ndarray
    fit_model: FitModel
    joint: JointFit

    @property
    def layers(self) -> tuple[ReflectionLayer, ...]:
        """The fitted layer per channel (``P_d``, ``P_s`` in 1/sr; ``n`` in 1/degree); the
        sample's own, without the tilt."""
        return tuple(fit.params for fit in self.fits)

    @property
    def tilt(self) -> tuple[float, float] | None:
        """``(tilt, standard error)`` in degrees, ``None`` when the tilt was not fitted."""
        return self.joint.nuisance.get(TILT)

    @property
    def tilt_deg(self) -> float:
        """The fitted tilt in degrees (0 when not fitted)."""
        return self.tilt[0] if self.tilt else 0.0

    def predict(self, theta_i_deg, theta_o_deg) -> np.ndarray:
        """The model's RGB factors ``(..., 3)`` at in-plane geometries, the tilt included."""
        return np.stack([model_factor(layer, theta_i_deg, theta_o_deg, self.tilt_deg)
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


def fit_channels(theta_i_deg, theta_o_deg, rgb, incidences_deg=None,
                 model: FitModel = FitModel()) -> ChannelFits:
    """Fit ``model`` (default: the full eq. 2 per channel and the shared tilt) to the three
    channels of ``rgb`` ``(N, 3)`` (reflectance factors) at once, on the rows at
    ``incidences_deg`` (default all), and evaluate the fit at every row."""
    theta_i = np.asarray(theta_i_deg, dtype=float)
    theta_o = np.asarray(theta_o_deg, dtype=float)
    rgb = np.asarray(rgb, dtype=float)
    rows = _rows(theta_i, incidences_deg)
    if not np.any(rows):
        raise ValueError(f"no rows at incidences {list(incidences_deg)}")
    datasets = [reflection_data(theta_i[rows], theta_o[rows], rgb[rows, c]) for c in range(3)]
    joint = fit_reflection_sets(datasets, eta=model.eta, lobe=model.lobe, tilt=model.tilt,
                                labels=CHANNELS)
    fitted = tuple(float(v) for v in np.unique(theta_i[rows]))
    tilt = joint.nuisance.get(TILT, (0.0, 0.0))[0]
    values = np.stack([model_factor(fit.params, theta_i, theta_o, tilt) for fit in joint.fits],
                      axis=-1)
    return ChannelFits(joint.fits, fitted, theta_i, theta_o, rgb, values, model, joint)


@dataclass(frozen=True)
class Decision:
    """One check of :func:`well_posed` on a fit: ``what`` was checked (``"tilt"``, ``"lobe"``,
    ``"eta"``), whether the fit ``passed``, ``why`` (a sentence with the deciding numbers) and
    the deciding number ``value`` against its ``threshold`` (``at_bound``: a parameter sat at a
    bound, which decides by itself)."""

    what: str
    passed: bool
    why: str
    value: float
    threshold: float
    at_bound: bool = False


@dataclass(frozen=True, eq=False)
class ModelChoice:
    """The well-posed fit and how it was reached: ``steps`` of ``(fits, decisions)``, the
    last being the chosen fit with the checks it passed."""

    steps: tuple[tuple[ChannelFits, tuple[Decision, ...]], ...]

    @property
    def fit(self) -> ChannelFits:
        """The chosen (last) fit."""
        return self.steps[-1][0]

    @property
    def model(self) -> FitModel:
        return self.fit.fit_model

    def summary(self) -> str:
        """One phrase: the form chosen and why each form before it was reduced, e.g. ``"P_d
        alone (no lobe); reduced from eq. 2 (...) + tilt (the tilt ran to its bound (-5
        degrees)), eq. 2 (...) (R n sits at its bound (0.0001))"``."""
        parts = []
        for fits, decisions in self.steps[:-1]:
            failed = [d for d in decisions if not d.passed]
            parts.append(f"{fits.fit_model.describe()} ({failed[0].why})")
        return self.model.describe() + ("; reduced from " + ", ".join(parts) if parts else "")


def _worst(fits: ChannelFits, names) -> tuple[float, str, bool]:
    """The largest relative standard error among ``names`` over the channels (``(value,
    "<channel> <name>", at_bound)``; a parameter at its bound wins)."""
    worst = (-1.0, "", False)
    for channel, fit in zip(CHANNELS, fits.fits, strict=True):
        for name in names:
            if name not in fit.free:
                continue
            if fit.at_bound(name):
                return float(getattr(fit.params, name)), f"{channel} {name}", True
            if fit.relative_stderr[name] > worst[0]:
                worst = (float(fit.relative_stderr[name]), f"{channel} {name}", False)
    return worst


def _check_tilt(fits: ChannelFits) -> Decision:
    if fits.tilt is None:  # (checked only when the tilt is fitted)
        raise ValueError("the tilt was not fitted")
    value, stderr = fits.tilt
    if fits.joint.at_bound(TILT):
        return Decision("tilt", False, f"the tilt ran to its bound ({value:+.3g} degrees)",
                        value, WELL_POSED_STDERR, True)
    ratio = stderr / abs(value) if value != 0.0 else np.inf
    text = (f"tilt {value:+.3f} ± {stderr:.3f} degrees (standard error {ratio:.3g} of its "
            f"size, limit {WELL_POSED_STDERR:g})")
    return Decision("tilt", bool(ratio <= WELL_POSED_STDERR), text, ratio, WELL_POSED_STDERR)


def _check_lobe(fits: ChannelFits, name: str) -> Decision:
    """The lobe's ``n`` (its shape) or ``P_s`` (its height) in every channel."""
    value, where, bound = _worst(fits, (name,))
    if bound:
        return Decision(name, False, f"{where} sits at its bound ({value:.3g})", value,
                        WELL_POSED_STDERR, True)
    text = (f"largest relative standard error of {name}: {value:.3g} ({where}; limit "
            f"{WELL_POSED_STDERR:g})")
    return Decision(name, bool(value <= WELL_POSED_STDERR), text, value, WELL_POSED_STDERR)


def _check_eta(fits: ChannelFits) -> tuple[Decision, Decision]:
    value, where, bound = _worst(fits, ("eta",))
    if bound:
        error = Decision("eta", False, f"{where} sits at its bound ({value:.4g})", value,
                         WELL_POSED_STDERR, True)
    else:
        error = Decision("eta", bool(value <= WELL_POSED_STDERR),
                         f"largest relative standard error of eta - 1: {value:.3g} ({where}; "
                         f"limit {WELL_POSED_STDERR:g})", value, WELL_POSED_STDERR)
    correlations = [(abs(float(fit.correlation[fit.free.index("P_s"), fit.free.index("eta")])),
                     channel) for channel, fit in zip(CHANNELS, fits.fits, strict=True)]
    largest, channel = max(correlations)
    degenerate = Decision("P_s-eta", bool(largest <= DEGENERATE_CORRELATION),
                          f"largest |correlation| of P_s and eta: {largest:.4f} ({channel}; "
                          f"limit {DEGENERATE_CORRELATION:g})", largest, DEGENERATE_CORRELATION)
    return error, degenerate


def _decisions(fits: ChannelFits) -> tuple[Decision, ...]:
    """The checks of :func:`well_posed`, in the order they are acted on."""
    model = fits.fit_model
    out = []
    if model.tilt:
        out.append(_check_tilt(fits))
    if model.lobe:
        out.append(_check_lobe(fits, "n"))
        if model.eta is None:
            out += _check_eta(fits)
        out.append(_check_lobe(fits, "P_s"))
    return tuple(out)


def _reduced(model: FitModel, failed: Decision) -> FitModel:
    if failed.what == "tilt":
        return replace(model, tilt=False)
    if failed.what in ("n", "P_s"):
        return FitModel(lobe=False, eta=None, tilt=False)
    return replace(model, eta=float(paper().film.eta))


def well_posed(theta_i_deg, theta_o_deg, rgb, incidences_deg=None) -> ModelChoice:
    """The fit whose every parameter the data determine (module docstring): start from the
    full eq. 2 with the tilt, and leave out the tilt, the lobe, or tie P_s and eta, refitting,
    until every check passes."""
    model = FitModel()
    steps = []
    while True:
        fits = fit_channels(theta_i_deg, theta_o_deg, rgb, incidences_deg, model)
        decisions = _decisions(fits)
        steps.append((fits, decisions))
        failed = [d for d in decisions if not d.passed]
        if not failed:
            return ModelChoice(tuple(steps))
        model = _reduced(model, failed[0])


def alternate_incidences(incidences_deg) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``(fit, held out)``: every other incidence from the lowest, i.e. 20/40/60 where 20 was
    measured, else 30/50/70; the rest is held out."""
    ordered = sorted(float(v) for v in incidences_deg)
    return tuple(ordered[0::2]), tuple(ordered[1::2])


def misses(fits: ChannelFits) -> dict:
    """Where the all-incidence fit misses, in luminance (Rec.709 ``Y``) per incidence.

    - ``peak_deg``: ``(measured, model)`` theta_o of the maximum; the model's on a
      :data:`CURVE_STEP_DEG` grid over the measured theta_o range (the tilt included), ``None``
      where the model is flat (``P_d`` alone).
    - ``peak_ratio``: measured maximum over the model's maximum.
    - ``mirror_deg``: the mirror direction ``theta_o = theta_i``, for reference, and
      ``tilted_mirror_deg``: the tilted sample's, ``theta_i + 2 tilt``.
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
            "tilted_mirror_deg": float(incidence + 2.0 * fits.tilt_deg),
            "peak_deg": (float(fits.theta_o_deg[top]),
                         float(dense[np.argmax(curve)]) if np.ptp(curve) > 1e-12 * curve.max()
                         else None),
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
