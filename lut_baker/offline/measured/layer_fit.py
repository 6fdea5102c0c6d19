"""Fitting the paper's layers to measurements (paper sections 4.1, 4.2; docs/model.md §5, 6).

Each fit minimises relative residuals ``log(model) - log(measured)`` with
:func:`scipy.optimize.least_squares` (suited to multiplicative noise: 2% noise gives a residual
rms of 0.02) over conditioned parameters: ``log`` of ``P_d``, ``P_s``/``P_t``, ``n``,
``sigma_s``, ``sigma_a`` and ``log(eta - 1)``.  The forward models are
:mod:`lut_baker.offline.measured.measurements`' (``I = f N.L``, paper eqs. 1-4; ``R(d)/R(0)``, eq.
6).

Starting point: the intensity is linear in ``P_d`` and ``P_s``/``P_t``, so for each ``n`` on a
coarse logarithmic grid (and at the caller's start, if any) they are solved by non-negative
least squares at the start's eta; the candidate of lowest cost, the caller's start as given
included, is refined.  The dipole's candidates are a coarse grid over ``(sigma_s, sigma_a)``.

Uncertainty: ``cov = (J^T J)^-1 s^2`` with ``J`` the Jacobian of the residuals in the conditioned
parameters at the solution and ``s^2`` the residual variance.  Since every conditioned parameter
is a logarithm, its standard error is a *relative* one (for eta: relative to ``eta - 1``, the
strength of Fresnel reflection).  A fit says so rather than return nonsense: its ``warnings``
name every parameter whose relative standard error exceeds 10%, every pair correlated beyond
0.99, a Jacobian condition number beyond 1e4, parameters stuck at a bound, a residual rms beyond
20% and a failed optimisation (thresholds: :class:`Limits`).

Functions and types
-------------------
- :class:`FitResult` -- fitted layer, standard errors, correlation, diagnostics, warnings.
- :class:`Limits` -- the thresholds behind the warnings.
- :func:`fit_reflection` -- a Torrance-Sparrow layer (eq. 2) to reflection samples.
- :func:`fit_transmission` -- a thin-film layer (eq. 4) to transmission samples.
- :func:`fit_dipole` -- a dipole's ``sigma_s``, ``sigma_a`` (eq. 6) to a profile.
- :func:`fit_measurements` -- whichever of the three fits the data set's type.
- :func:`poor_start` -- a deliberately poor start (parameters x3 or /3, eta 1.5).
- :func:`relative_errors` -- fitted against true parameters, including the P ratio.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from types import SimpleNamespace

import numpy as np
from scipy.optimize import least_squares, nnls

from ...model.layers import Dipole, ReflectionLayer, TransmissionLayer
from .measurements import (
    ProfileData,
    ReflectionData,
    TransmissionData,
    profile_ratio,
    reflection_counts,
    transmission_counts,
)

__all__ = [
    "D_MIN_MM",
    "Limits",
    "FitResult",
    "fit_reflection",
    "fit_transmission",
    "fit_dipole",
    "fit_measurements",
    "poor_start",
    "relative_errors",
]

D_MIN_MM = 0.1
"""Profile samples closer than this to the lit pixel (mm) are left out of a dipole fit: there the
direct light and the scattering separate poorly (paper 4.2.2)."""

N_GRID_PER_DEG = np.geomspace(2e-3, 0.5, 25)
"""Roughness grid (1/degree) of the starting search: lobe half-widths 500 to 2 degrees."""
SIGMA_S_GRID_PER_MM = np.geomspace(0.05, 200.0, 10)
"""Scattering grid (1/mm) of the dipole's starting search."""
SIGMA_A_GRID_PER_MM = np.geomspace(1e-4, 10.0, 11)
"""Absorption grid (1/mm) of the dipole's starting search."""

# Natural-unit bounds; P bounds scale with the largest measured value.
_BOUNDS = {
    "P": (1e-9, 1e6),  # times max(measured)
    "n": (1e-4, 10.0),  # 1/degree
    "eta": (1.0 + 1e-4, 10.0),
    "sigma_s": (1e-4, 1e4),  # 1/mm
    "sigma_a": (1e-7, 1e3),  # 1/mm
    "scale": (1e-6, 1e6),
}


@dataclass(frozen=True)
class Limits:
    """Thresholds beyond which a fit warns (module docstring)."""

    relative_stderr: float = 0.10
    correlation: float = 0.99
    condition_number: float = 1e4
    residual_rms: float = 0.20


@dataclass(frozen=True, eq=False)
class FitResult:
    """The outcome of a fit.

    ``params``: the fitted layer (fixed fields as given).  ``stderr``: standard error per free
    field, in its unit.  ``relative_stderr``: the same relative to the value (to ``eta - 1``
    for eta).  ``correlation``: matrix over ``free`` (in that order).  ``derived``: name ->
    ``(value, stderr)`` of derived quantities (the P ratio; the profile's scale if fitted).
    ``residual_rms``: rms of ``log(model/measured)`` (~ the relative noise).
    ``condition_number``: of the Jacobian in the conditioned parameters.  ``warnings``: one
    sentence per problem; empty when the fit is trustworthy.
    """

    kind: str
    params: ReflectionLayer | TransmissionLayer | Dipole
    free: tuple[str, ...]
    fixed: dict[str, float]
    stderr: dict[str, float]
    relative_stderr: dict[str, float]
    correlation: np.ndarray
    derived: dict[str, tuple[float, float]]
    residual_rms: float
    condition_number: float
    samples: int
    warnings: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when the fit raised no warning."""
        return not self.warnings

    def as_dict(self) -> dict:
        """Plain floats, lists and strings, for TOML/JSON output."""
        return {
            "kind": self.kind,
            "params": {k: float(v) for k, v in self.params.as_dict().items()},
            "free": list(self.free),
            "fixed": dict(self.fixed),
            "stderr": dict(self.stderr),
            "relative_stderr": dict(self.relative_stderr),
            "correlation": np.round(self.correlation, 6).tolist(),
            "derived": {k: list(v) for k, v in self.derived.items()},
            "residual_rms": self.residual_rms,
            "condition_number": self.condition_number,
            "samples": self.samples,
            "warnings": list(self.warnings),
        }


# --------------------------------------------------------------------------------------------
# Conditioned parameters: x = log(value), or log(eta - 1) for eta
# --------------------------------------------------------------------------------------------
def _offset(name: str) -> float:
    return 1.0 if name == "eta" else 0.0


def _to_x(name: str, value: float) -> float:
    return float(np.log(value - _offset(name)))


def _from_x(name: str, x: float) -> float:
    return float(np.exp(x) + _offset(name))


@dataclass(frozen=True)
class _Problem:
    """One least-squares problem: the layer type, which fields are free, the forward model
    ``predict(layer) -> values > 0`` and the measured values it is compared with."""

    kind: str
    layer_type: type
    free: tuple[str, ...]
    fixed: dict
    predict: object
    measured: np.ndarray
    bounds: dict
    scale_free: bool = False  # an extra free log-scale multiplies the model (profile only)

    def layer(self, x: np.ndarray):
        values = dict(self.fixed)
        values.update({name: _from_x(name, xi) for name, xi in zip(self.free, x, strict=False)})
        return self.layer_type(**values)

    def residuals(self, x: np.ndarray) -> np.ndarray:
        model = np.maximum(self.predict(self.layer(x)), 1e-300)
        scale = x[-1] if self.scale_free else 0.0
        return np.log(model) + scale - np.log(self.measured)

    def names(self) -> tuple[str, ...]:
        return self.free + (("scale",) if self.scale_free else ())

    def x_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        pairs = [[_to_x(name, v) for v in self.bounds[name]] for name in self.names()]
        return np.array(pairs).T


def _bounds(names, measured: np.ndarray) -> dict:
    """Natural-unit bounds per parameter (P bounds relative to the largest measured value)."""
    top = float(np.max(measured))
    out = {}
    for name in names:
        if name.startswith("P_"):
            low, high = _BOUNDS["P"]
            out[name] = (low * top, high * top)
        else:
            out[name] = _BOUNDS[name]
    return out


# --------------------------------------------------------------------------------------------
# Public fits
# --------------------------------------------------------------------------------------------
def fit_reflection(data: ReflectionData, start: ReflectionLayer | None = None, *,
                   eta: float | None = None, limits: Limits = Limits()) -> FitResult:
    """Fit ``ReflectionLayer(P_d, P_s, n, eta)`` (paper eq. 2) to reflection samples, with
    ``I = f_r N.L`` in the data's unit.  ``eta`` given: held fixed.  ``start``: an initial
    guess refined alongside the grid search's best (module docstring)."""
    if not isinstance(data, ReflectionData):
        raise ValueError("fit_reflection needs ReflectionData (psi_deg, alpha_deg, "
                         "intensity_counts)")
    return _fit_linear_pair(data, ReflectionLayer, "P_s", reflection_counts, start, eta, limits)


def fit_transmission(data: TransmissionData, start: TransmissionLayer | None = None, *,
                     eta: float | None = None, limits: Limits = Limits()) -> FitResult:
    """Fit ``TransmissionLayer(P_d, P_t, n, eta)`` (paper eq. 4) to transmission samples, with
    ``I = f_t N.L``.  Eta enters only through ``F_t = 1 - F_r``, a percent-level effect at the
    paper's incidences, so it is usually flagged; hold it fixed (``eta=``, e.g. the same film's
    reflection fit) to fit the rest."""
    if not isinstance(data, TransmissionData):
        raise ValueError("fit_transmission needs TransmissionData (incidence_deg, theta_t_deg, "
                         "intensity_counts)")
    return _fit_linear_pair(data, TransmissionLayer, "P_t", transmission_counts, start, eta,
                            limits)


def fit_dipole(data: ProfileData, start: Dipole | None = None, *, g: float = 0.0,
               eta: float = 1.26, d_min_mm: float = D_MIN_MM, free_scale: bool = False,
               limits: Limits = Limits()) -> FitResult:
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
    problem = _Problem("dipole", Dipole, free, {"g": float(g), "eta": float(eta)},
                       lambda dipole: profile_ratio(d, dipole), ratio,
                       {**_bounds(free, ratio), "scale": _BOUNDS["scale"]}, free_scale)
    _check_size(problem, data.distance_mm.size, f" at d >= {d_min_mm:g} mm")
    Dipole(sigma_s=1.0, sigma_a=0.1, g=g, eta=eta)  # validates g and eta before the search
    candidates = _dipole_starts(problem)
    if start is not None:
        candidates.append(_scored(problem, _x_of(problem, start)))
    return _solve(problem, candidates, limits)


def fit_measurements(data, start=None, **options) -> FitResult:
    """The fit matching the data set's type
    (:class:`~lut_baker.offline.measured.measurements.ReflectionData`, ``TransmissionData`` or
    ``ProfileData``); ``options`` go to that fit."""
    fits = {ReflectionData: fit_reflection, TransmissionData: fit_transmission,
            ProfileData: fit_dipole}
    if type(data) not in fits:
        raise ValueError(f"no fit for data of type {type(data).__name__}")
    return fits[type(data)](data, start, **options)


def poor_start(layer, factor: float = 3.0, eta: float = 1.5):
    """A deliberately poor start for round-trip checks: the free fields multiplied by
    ``factor`` and ``1/factor`` in turn, eta set to ``eta`` (a dipole's g and eta untouched)."""
    names = [f.name for f in fields(layer) if f.name not in ("eta", "g")]
    scaled = layer.scaled(**{n: factor ** (-1) ** i for i, n in enumerate(names)})
    return scaled if isinstance(layer, Dipole) else replace(scaled, eta=eta)


def relative_errors(params, truth) -> dict[str, float]:
    """``fitted / true - 1`` per field (eta and g: also relative to the value), plus the P
    ratio ``P_s/P_d`` or ``P_t/P_d`` where the layer has one."""
    out = {f.name: float(getattr(params, f.name) / getattr(truth, f.name) - 1.0)
           for f in fields(truth) if getattr(truth, f.name) != 0}
    lobe = _lobe_name(truth)
    if lobe:
        ratio = (getattr(params, lobe) / params.P_d) / (getattr(truth, lobe) / truth.P_d)
        out[f"{lobe}/P_d"] = float(ratio - 1.0)
    return out


# --------------------------------------------------------------------------------------------
# Internals
# --------------------------------------------------------------------------------------------
def _lobe_name(layer) -> str | None:
    return {ReflectionLayer: "P_s", TransmissionLayer: "P_t"}.get(type(layer))


def _check_size(problem: _Problem, total: int, where: str = "") -> None:
    needed = len(problem.names()) + 1
    if problem.measured.size < needed:
        used = f"{problem.measured.size} of {total}" if where else f"{problem.measured.size}"
        raise ValueError(f"a {problem.kind} fit needs at least {needed} samples{where}, "
                         f"got {used}")


def _x_of(problem: _Problem, layer) -> np.ndarray:
    """Conditioned coordinates of a start layer, clipped inside the bounds."""
    x = [_to_x(name, float(getattr(layer, name))) for name in problem.free]
    if problem.scale_free:
        x.append(0.0)
    low, high = problem.x_bounds()
    return np.clip(np.array(x), low + 1e-9, high - 1e-9)


def _fit_linear_pair(data, layer_type, lobe: str, forward, start, eta, limits) -> FitResult:
    """Reflection and transmission: intensity linear in ``P_d`` and the lobe's P."""
    measured = data.intensity_counts
    free = ("P_d", lobe, "n") + (() if eta is not None else ("eta",))
    fixed = {} if eta is None else {"eta": float(eta)}
    kind = "reflection" if layer_type is ReflectionLayer else "transmission"
    problem = _Problem(kind, layer_type, free, fixed, lambda layer: forward(data, layer),
                       measured, _bounds(free + ("eta",), measured))
    _check_size(problem, measured.size)
    if eta is not None:
        layer_type(P_d=1.0, **{lobe: 1.0}, n=1.0, eta=eta)  # validates a fixed eta
    eta0 = eta if eta is not None else (float(start.eta) if start is not None else 1.3)
    eta0 = min(max(eta0, 1.01), 5.0)
    grid = list(N_GRID_PER_DEG) + ([float(start.n)] if start is not None else [])
    candidates = _linear_starts(problem, lobe, grid, eta0)
    if start is not None:
        candidates.append(_scored(problem, _x_of(problem, start)))
    return _solve(problem, candidates, limits)


def _linear_starts(problem: _Problem, lobe: str, n_grid, eta: float) -> list[tuple]:
    """``(x, cost)`` per roughness ``n`` in ``n_grid`` (eta held at ``eta``), with ``P_d`` and
    the lobe's P by non-negative least squares on relative residuals."""
    weight = 1.0 / problem.measured
    low, high = problem.bounds["P_d"]
    diffuse = problem.predict(problem.layer_type(P_d=1.0, **{lobe: 0.0}, n=1.0, eta=eta))
    starts = []
    for n in n_grid:
        lobe_basis = problem.predict(problem.layer_type(P_d=0.0, **{lobe: 1.0}, n=n, eta=eta))
        p, _ = nnls(np.stack([diffuse, lobe_basis], axis=1) * weight[:, None],
                    np.ones_like(weight))
        p = np.clip(p, low, high)
        cost = float(np.sum(np.log((p[0] * diffuse + p[1] * lobe_basis) * weight) ** 2))
        values = SimpleNamespace(**{"P_d": p[0], lobe: p[1], "n": n, "eta": eta})
        starts.append((_x_of(problem, values), cost))
    return starts


def _dipole_starts(problem: _Problem) -> list[tuple]:
    """``(x, cost)`` per point of a logarithmic ``(sigma_s, sigma_a)`` grid (with the best
    log-scale when it is free)."""
    starts = []
    for sigma_s in SIGMA_S_GRID_PER_MM:
        for sigma_a in SIGMA_A_GRID_PER_MM:
            x = _x_of(problem, SimpleNamespace(sigma_s=sigma_s, sigma_a=sigma_a))
            r = problem.residuals(x)
            if problem.scale_free:
                x[-1] = -float(np.mean(r))
                r = r + x[-1]
            starts.append((x, float(np.sum(r * r))))
    return starts


def _scored(problem: _Problem, x: np.ndarray) -> tuple[np.ndarray, float]:
    """A start with its cost (sum of squared residuals)."""
    return x, float(np.sum(problem.residuals(x) ** 2))


def _solve(problem: _Problem, candidates, limits: Limits) -> FitResult:
    """Refine the ``(x, cost)`` candidate of lowest cost with ``least_squares`` and diagnose
    the result."""
    low, high = problem.x_bounds()
    x0 = min(candidates, key=lambda pair: pair[1])[0]
    result = least_squares(problem.residuals, x0, bounds=(low, high), method="trf",
                           x_scale=1.0, ftol=1e-10, xtol=1e-10, gtol=1e-10,
                           max_nfev=200 * len(x0))
    return _diagnose(problem, result, low, high, limits)


def _diagnose(problem: _Problem, result, low, high, limits: Limits) -> FitResult:
    """Covariance ``(J^T J)^-1 s^2`` and the warnings of :class:`Limits`."""
    names = problem.names()
    m, p = problem.measured.size, len(names)
    jac = np.asarray(result.jac, dtype=float)
    s2 = 2.0 * result.cost / max(m - p, 1)
    _, s, vt = np.linalg.svd(jac, full_matrices=False)
    condition = float(s[0] / s[-1]) if s[-1] > 0 else np.inf
    s = np.maximum(s, s[0] * 1e-15) if s[0] > 0 else np.full_like(s, 1e-300)
    cov = (vt.T / s**2) @ vt * s2
    se_x = np.sqrt(np.maximum(np.diag(cov), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = cov / np.outer(se_x, se_x)
    correlation = np.where(np.isfinite(correlation), correlation, 0.0)
    np.fill_diagonal(correlation, 1.0)

    layer = problem.layer(result.x)
    stderr, relative = {}, {}
    for i, name in enumerate(problem.free):
        value = float(getattr(layer, name))
        stderr[name] = float((value - _offset(name)) * se_x[i])
        relative[name] = float(se_x[i])
    derived = {}
    lobe = _lobe_name(layer)
    if lobe and {"P_d", lobe} <= set(problem.free):
        i, j = problem.free.index("P_d"), problem.free.index(lobe)
        ratio = float(getattr(layer, lobe) / layer.P_d)
        var = cov[i, i] + cov[j, j] - 2.0 * cov[i, j]
        derived[f"{lobe}/P_d"] = (ratio, ratio * float(np.sqrt(max(var, 0.0))))
    if problem.scale_free:
        derived["scale"] = (float(np.exp(result.x[-1])), float(np.exp(result.x[-1]) * se_x[-1]))

    rms = float(np.sqrt(2.0 * result.cost / m))
    warnings = _warnings(names, result, se_x, correlation, condition, rms, low, high, limits)
    return FitResult(problem.kind, layer, problem.free, dict(problem.fixed), stderr, relative,
                     correlation, derived, rms, condition, m, warnings)


def _warnings(names, result, se_x, correlation, condition, rms, low, high,
              limits: Limits) -> list[str]:
    """One sentence per problem the covariance and the optimiser reveal."""
    out = []
    if not result.success:
        out.append(f"the optimiser did not converge: {result.message}")
    for i, name in enumerate(names):
        if result.x[i] <= low[i] + 1e-6 or result.x[i] >= high[i] - 1e-6:
            out.append(f"{name} ended at its bound ({_from_x(name, result.x[i]):.4g}): "
                       "the data do not determine it")
        elif se_x[i] > limits.relative_stderr:
            what = "eta - 1" if name == "eta" else name
            hint = "; hold it fixed if it is known (eta=, --eta)" if name == "eta" else ""
            out.append(f"{name} is ill-conditioned: its standard error is {100 * se_x[i]:.3g}% "
                       f"of {what} (limit {100 * limits.relative_stderr:.3g}%); the other "
                       f"values and their errors hold for this {name} only{hint}")
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            if abs(correlation[i, j]) > limits.correlation:
                out.append(f"{names[i]} and {names[j]} are degenerate (correlation "
                           f"{correlation[i, j]:+.4f}): only a combination of them is determined")
    if condition > limits.condition_number:
        out.append(f"the Jacobian's condition number {condition:.3g} exceeds "
                   f"{limits.condition_number:.3g}: the problem is ill-conditioned")
    if rms > limits.residual_rms:
        out.append(f"the residual rms {100 * rms:.3g}% exceeds {100 * limits.residual_rms:.3g}%: "
                   "the model does not describe these data")
    return out
