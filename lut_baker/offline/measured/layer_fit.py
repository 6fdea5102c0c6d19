"""Fitting the paper's layers to measurements (paper sections 4.1, 4.2; docs/model.md §5, 6;
docs/fitting.md).

Each fit minimises the relative residuals ``log(model) - log(measured)`` of a forward model of
:mod:`lut_baker.offline.measured.measurements` (``I = f N.L``, paper eqs. 1-4; ``R(d)/R(0)``,
eq. 6) from several starts (:mod:`~lut_baker.offline.measured.fit_starts`), solved, polished
and diagnosed by :mod:`~lut_baker.offline.measured.fit_solver`; the outcome, with standard
errors and warnings, is a :class:`~lut_baker.offline.measured.fit_results.FitResult`.

Several data sets may be fitted at once (:func:`fit_reflection_sets`: the R, G, B channels of one
measurement), each with its own layer, sharing nuisance parameters: a tilt of the sample in the
plane of incidence (an offset of alpha, :func:`~lut_baker.offline.measured.protocols.tilted`) or
the profile's scale.  A nuisance parameter is fitted with its standard error and is not part of
the layer.

Functions
---------
- :func:`fit_reflection` -- a Torrance-Sparrow layer (eq. 2) to reflection samples.
- :func:`fit_reflection_sets` -- one eq. 2 layer per data set, optionally without lobe, with a
  shared tilt of the sample.
- :func:`fit_transmission` -- a thin-film layer (eq. 4) to transmission samples.
- :func:`fit_dipole` -- a dipole's ``sigma_s``, ``sigma_a`` (eq. 6) to a profile.
- :func:`fit_measurements` -- whichever of the three fits the data set's type.
- :func:`poor_start` -- a deliberately poor start (parameters x3 or /3, eta 1.5).
- :func:`relative_errors` -- fitted against true parameters, including the P ratio.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import fields, replace
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

from ...model.layers import Dipole, Layer, ReflectionLayer, TransmissionLayer
from .fit_results import DEFAULT_LIMITS, FitResult, JointFit, Limits
from .fit_solver import (
    BOUNDS,
    TILT,
    Predict,
    Problem,
    check_size,
    lobe_name,
    parameter_bounds,
    solve,
)
from .fit_starts import dipole_starts, pair_starts
from .measurements import (
    ProfileData,
    ReflectionCounts,
    ReflectionData,
    TransmissionCounts,
    TransmissionData,
    profile_ratio,
)

__all__ = [
    "D_MIN_MM",
    "fit_reflection",
    "fit_reflection_sets",
    "fit_transmission",
    "fit_dipole",
    "fit_measurements",
    "poor_start",
    "relative_errors",
]

_Start = TypeVar("_Start", ReflectionLayer, TransmissionLayer, Dipole)
_Pair = TypeVar("_Pair", ReflectionLayer, TransmissionLayer)

D_MIN_MM = 0.1
"""Profile samples closer than this to the lit pixel (mm) are left out of a dipole fit: there the
direct light and the scattering separate poorly (paper 4.2.2)."""
_NO_LOBE = {"n": BOUNDS["n"][0], "eta": 1.0}
"""``n`` and ``eta`` of a layer fitted without lobe (``P_s = 0``; unused, reported as fixed): the
widest lobe (integrals over the hemisphere need no fine grid) and no interface."""


def fit_reflection(data: ReflectionData, start: ReflectionLayer | None = None, *,
                   eta: float | None = None,
                   limits: Limits = DEFAULT_LIMITS) -> FitResult[ReflectionLayer]:
    """Fit ``ReflectionLayer(P_d, P_s, n, eta)`` (paper eq. 2) to reflection samples, with
    ``I = f_r N.L`` in the data's unit.  ``eta`` given: held fixed.  ``start``: an initial
    guess refined alongside the multi-start's (:mod:`~lut_baker.offline.measured.fit_starts`)."""
    if not isinstance(data, ReflectionData):
        raise ValueError("fit_reflection needs ReflectionData (psi_deg, alpha_deg, "
                         "intensity_counts)")
    return fit_reflection_sets([data], start, eta=eta, limits=limits).fits[0]


def fit_reflection_sets(datasets: Iterable[ReflectionData],
                        start: ReflectionLayer | None = None, *, eta: float | None = None,
                        lobe: bool = True, tilt: bool = False,
                        labels: Sequence[str] | None = None,
                        limits: Limits = DEFAULT_LIMITS) -> JointFit[ReflectionLayer]:
    """Fit one ``ReflectionLayer`` (eq. 2) per data set in ``datasets`` (``ReflectionData``,
    e.g. the R, G, B channels of one measurement) at once.  ``eta`` given: held fixed in every
    set.  ``lobe=False``: ``P_d`` alone (``P_s = 0``; ``n``, ``eta`` fixed and unused).
    ``tilt``: a tilt of the sample shared by every set (``tilt_deg``, an offset of alpha; within
    +-:data:`~lut_baker.offline.measured.fit_solver.TILT_LIMIT_DEG`) is fitted with them.  The
    sets must share their geometry.
    ``labels``: one per set (default ``"R"``, ``"G"``, ``"B"`` for three sets, else ``"0"``,
    ``"1"``, ...; none for one set).  ``start``: one layer, refined in every set alongside the
    multi-start's."""
    sets = list(datasets)
    if not sets or not all(isinstance(d, ReflectionData) for d in sets):
        raise ValueError("fit_reflection_sets needs one or more ReflectionData")
    first = sets[0]
    if not all(np.array_equal(d.psi_deg, first.psi_deg)
               and np.array_equal(d.alpha_deg, first.alpha_deg) for d in sets):
        raise ValueError("the data sets of a joint fit must share their geometry (psi_deg, "
                         "alpha_deg)")
    model = ReflectionCounts(first)

    def predict(values: Any, nuisance: dict[str, float]) -> NDArray[np.float64]:
        return model(values, nuisance.get(TILT, 0.0))

    return _fit_pair(sets, ReflectionLayer, "P_s", predict, start, eta, limits,
                     lobe_free=lobe, tilt=tilt, labels=labels)


def fit_transmission(data: TransmissionData, start: TransmissionLayer | None = None, *,
                     eta: float | None = None,
                     limits: Limits = DEFAULT_LIMITS) -> FitResult[TransmissionLayer]:
    """Fit ``TransmissionLayer(P_d, P_t, n, eta)`` (paper eq. 4) to transmission samples, with
    ``I = f_t N.L``.  Eta enters only through ``F_t = 1 - F_r``, a percent-level effect at the
    paper's incidences, so it is usually flagged; hold it fixed (``eta=``, e.g. the same film's
    reflection fit) to fit the rest."""
    if not isinstance(data, TransmissionData):
        raise ValueError("fit_transmission needs TransmissionData (incidence_deg, theta_t_deg, "
                         "intensity_counts)")
    model = TransmissionCounts(data)
    return _fit_pair([data], TransmissionLayer, "P_t", lambda values, nuisance: model(values),
                     start, eta, limits).fits[0]


def fit_dipole(data: ProfileData, start: Dipole | None = None, *, g: float = 0.0,
               eta: float = 1.26, d_min_mm: float = D_MIN_MM, free_scale: bool = False,
               limits: Limits = DEFAULT_LIMITS) -> FitResult[Dipole]:
    """Fit a dipole's ``sigma_s``, ``sigma_a`` (1/mm; paper eq. 6) to a profile measured
    relative to the lit pixel, modelled as ``R(d)/R(0)``; ``g`` and ``eta`` are given (the
    paper's skin: 0 and 1.26).  Samples with ``d < d_min_mm`` are left out.  ``free_scale``:
    fit ``k R(d)/R(0)`` with a free ``k`` instead, for a lit pixel that also holds direct
    reflection (the shape alone then has to carry both coefficients)."""
    if not isinstance(data, ProfileData):
        raise ValueError("fit_dipole needs ProfileData (distance_mm, ratio)")
    keep = data.distance_mm >= d_min_mm
    d, ratio = data.distance_mm[keep], data.ratio[keep]
    free = ("sigma_s", "sigma_a")
    problem = Problem("dipole", Dipole, free, {"g": float(g), "eta": float(eta)},
                      lambda values, nuisance: profile_ratio(d, values), ratio[:, None],
                      (parameter_bounds(free, ratio),), ("scale",) if free_scale else ())
    check_size(problem, data.distance_mm.size, f" at d >= {d_min_mm:g} mm")
    Dipole(sigma_s=1.0, sigma_a=0.1, g=g, eta=eta)  # validates g and eta before the search
    starts = dipole_starts(problem)
    if start is not None:
        starts.append(problem.x_of([start]))
    return solve(problem, starts, limits).fits[0]


def fit_measurements(data: ReflectionData | TransmissionData | ProfileData,
                     start: Layer | None = None, **options: Any) -> FitResult[Any]:
    """The fit matching the data set's type
    (:class:`~lut_baker.offline.measured.measurements.ReflectionData`, ``TransmissionData`` or
    ``ProfileData``); ``options`` go to that fit."""
    fits: dict[type, Any] = {ReflectionData: fit_reflection, TransmissionData: fit_transmission,
                             ProfileData: fit_dipole}
    if type(data) not in fits:
        raise ValueError(f"no fit for data of type {type(data).__name__}")
    return fits[type(data)](data, start, **options)


def poor_start(layer: _Start, factor: float = 3.0, eta: float = 1.5) -> _Start:
    """A deliberately poor start for round-trip checks: the free fields multiplied by
    ``factor`` and ``1/factor`` in turn, eta set to ``eta`` (a dipole's g and eta untouched)."""
    names = [f.name for f in fields(layer) if f.name not in ("eta", "g")]
    scaled = layer.scaled(**{n: factor ** (-1) ** i for i, n in enumerate(names)})
    return scaled if isinstance(layer, Dipole) else replace(scaled, eta=eta)


def relative_errors(params: _Start, truth: _Start) -> dict[str, float]:
    """``fitted / true - 1`` per field (eta and g: also relative to the value), plus the P
    ratio ``P_s/P_d`` or ``P_t/P_d`` where the layer has one."""
    out = {f.name: float(getattr(params, f.name) / getattr(truth, f.name) - 1.0)
           for f in fields(truth) if getattr(truth, f.name) != 0}
    lobe = lobe_name(truth)
    if lobe and not isinstance(truth, Dipole):  # (a dipole has no lobe)
        ratio = (getattr(params, lobe) / params.P_d) / (getattr(truth, lobe) / truth.P_d)
        out[f"{lobe}/P_d"] = float(ratio - 1.0)
    return out


# --------------------------------------------------------------------------------------------
# Internals
# --------------------------------------------------------------------------------------------
def _default_labels(count: int) -> tuple[str, ...]:
    if count == 1:
        return ("",)
    return ("R", "G", "B") if count == 3 else tuple(str(i) for i in range(count))


def _fit_pair(datasets: Sequence[ReflectionData] | Sequence[TransmissionData],
              layer_type: type[_Pair], lobe: str, predict: Predict, start: Layer | None,
              eta: float | None, limits: Limits, *, lobe_free: bool = True, tilt: bool = False,
              labels: Sequence[str] | None = None) -> JointFit[_Pair]:
    """Reflection and transmission: intensity linear in ``P_d`` and the lobe's P; one layer per
    data set, an optional shared tilt."""
    measured = np.column_stack([data.intensity_counts for data in datasets])
    if lobe_free:
        free = ("P_d", lobe, "n") + (() if eta is not None else ("eta",))
        fixed = {} if eta is None else {"eta": float(eta)}
    else:
        free, fixed = ("P_d",), {lobe: 0.0, **_NO_LOBE}
    kind = "reflection" if layer_type is ReflectionLayer else "transmission"
    names = tuple(labels) if labels is not None else _default_labels(len(datasets))
    if len(names) != len(datasets):
        raise ValueError(f"{len(names)} labels for {len(datasets)} data sets")
    problem = Problem(kind, layer_type, free, fixed, predict, measured,
                      tuple(parameter_bounds(free + ("eta",), m) for m in measured.T),
                      (TILT,) if tilt else (), names)
    check_size(problem, problem.samples)
    if eta is not None:
        layer_type(P_d=1.0, **{lobe: 1.0}, n=1.0, eta=eta)  # validates a fixed eta
    starts = pair_starts(problem, lobe, eta, lobe_free, tilt)
    if start is not None:
        starts.append(problem.x_of([start] * problem.sets))
    return solve(problem, starts, limits)
