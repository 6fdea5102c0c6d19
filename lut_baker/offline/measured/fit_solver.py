"""The layer fits' solver (:mod:`lut_baker.offline.measured.layer_fit`): one least-squares
problem over one or more data sets in conditioned parameters, refined from every start,
polished to the optimum and diagnosed (paper sections 4.1, 4.2; docs/fitting.md).

Each fit minimises relative residuals ``log(model) - log(measured)`` with
:func:`scipy.optimize.least_squares` (suited to multiplicative noise: 2% noise gives a residual
rms of 0.02) over conditioned parameters: ``log`` of ``P_d``, ``P_s``/``P_t``, ``n``,
``sigma_s``, ``sigma_a`` and ``log(eta - 1)``; a tilt of the sample stays in degrees.  The
Jacobian is taken by forward differences (step ``sqrt(eps)`` in the conditioned parameters)
and the optimiser's tolerances are 1e-12, so that the optimum is located to about 1e-9 of a
standard error and a fit moves by about as much as its data when they are perturbed.  Every
start is refined; the lowest cost wins, is polished (Gauss-Newton steps, central differences)
and :class:`~lut_baker.offline.measured.fit_results.Starts` records how many starts reached it
(within :data:`SAME_COST` relative), how far their parameters spread and how much higher the
best other end lies.

Uncertainty: ``cov = (J^T J)^-1 s^2`` with ``J`` the Jacobian of the residuals in the conditioned
parameters at the solution and ``s^2`` the residual variance.  Since every conditioned parameter
but the tilt is a logarithm, its standard error is a *relative* one (for eta: relative to
``eta - 1``, the strength of Fresnel reflection).  A fit says so rather than return nonsense:
its ``warnings`` name every parameter whose relative standard error exceeds 10%, every pair
correlated beyond 0.99, a Jacobian condition number beyond 1e4, parameters stuck at a bound, a
residual rms beyond 20%, another minimum that fits as well within the noise (a start that ended
elsewhere with a chi-square less than 4 higher and some parameter more than one standard error
away: the covariance describes one basin only) and a failed optimisation (thresholds:
:class:`~lut_baker.offline.measured.fit_results.Limits`).

Functions and types
-------------------
- :class:`Problem` -- the least-squares problem: layer type, free and fixed fields, forward
  model, measured values, bounds, shared nuisance parameters; its residuals and Jacobian.
- :class:`LayerValues` -- a layer's fields without the layer's checks (the inner loop).
- :func:`parameter_bounds` -- natural-unit bounds per parameter.
- :func:`check_size` -- enough samples for the parameters, or ``ValueError``.
- :func:`lobe_name` -- a layer's lobe field (``P_s``, ``P_t``), if any.
- :func:`solve` -- every start refined, the best polished and diagnosed: a
  :class:`~lut_baker.offline.measured.fit_results.JointFit`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any, Generic

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import OptimizeResult, least_squares

from ...model.layers import Dipole, Layer, ReflectionLayer, TransmissionLayer
from ...numerics import Real
from .fit_results import FitResult, FittedLayer, JointFit, Limits, Starts

__all__ = ["TILT", "TILT_LIMIT_DEG", "SAME_COST", "POLISH_STEPS", "BOUNDS", "Problem",
           "LayerValues", "Predict", "parameter_bounds", "check_size", "lobe_name", "solve"]

TILT = "tilt_deg"
"""Name of the nuisance parameter "tilt of the sample" (degrees; an offset of alpha)."""
TILT_LIMIT_DEG = 5.0
"""The tilt is fitted within +-this many degrees; one that ends there is not determined."""
SAME_COST = 1e-6
"""A start reached the best when its final cost is within this (relative) of the best's."""
_COST_FLOOR = 1e-18
"""Per sample: costs below ``_COST_FLOOR * samples`` count as zero (exact data)."""
_TOLERANCE = 1e-12
"""``ftol``, ``xtol`` and ``gtol`` of ``least_squares``."""
_STEP = np.finfo(float).eps ** 0.5
"""Forward-difference step in the conditioned parameters (the optimiser's Jacobian)."""
_CENTRAL_STEP = np.finfo(float).eps ** (1.0 / 3.0)
"""Central-difference step (the polish's and the covariance's Jacobian)."""
_EVALUATIONS = 40
"""``least_squares`` stops after this many evaluations per parameter (a start that has not
converged by then crawls along a valley of undetermined parameters)."""
POLISH_STEPS = 30
"""At most this many Gauss-Newton steps polish the optimiser's best end."""

BOUNDS = {
    "P": (1e-9, 1e6),  # times max(measured)
    "n": (1e-4, 10.0),  # 1/degree
    "eta": (1.0 + 1e-4, 10.0),
    "sigma_s": (1e-4, 1e4),  # 1/mm
    "sigma_a": (1e-7, 1e3),  # 1/mm
    "scale": (1e-6, 1e6),
    TILT: (-TILT_LIMIT_DEG, TILT_LIMIT_DEG),
}
"""Natural-unit bounds of the parameters; the P bounds scale with the largest measured value
(:func:`parameter_bounds`)."""


# Conditioned parameters: x = log(value), or log(eta - 1) for eta; the tilt as it is.
def _offset(name: str) -> float:
    return 1.0 if name == "eta" else 0.0


def _to_x(name: str, value: float) -> float:
    if name == TILT:
        return float(value)
    return float(np.log(value - _offset(name)))


def _from_x(name: str, x: float) -> float:
    return float(_from_x_array(name, x))


def _from_x_array(name: str, x: Real) -> Real:
    if name == TILT:
        return x
    return np.exp(x) + _offset(name)


class LayerValues(SimpleNamespace):
    """Layer field values without the layer's checks, for the fit's inner loop (the bounds
    keep them valid): the free fields as arrays over the data sets (``channels``), so the
    forward models evaluate every set at once (a trailing axis, as for an RGB layer)."""


Predict = Callable[[Any, dict[str, float]], NDArray[np.float64]]
"""``predict(values, nuisance) -> (samples, sets)``: a forward model at a layer's field values
(:class:`LayerValues`, or a start's) and the nuisance parameters by name."""


@dataclass(frozen=True, eq=False)
class Problem(Generic[FittedLayer]):
    """One least-squares problem over one or more data sets sharing their geometry: the layer
    type, the fields fitted in every set (``free``; the others ``fixed``), the forward model
    ``predict(values, nuisance) -> (samples, sets)`` (values > 0), the ``measured`` values
    ``(samples, sets)``, natural-unit ``bounds`` per set, the shared ``nuisance`` parameters
    (``"scale"`` multiplies the model, ``tilt_deg`` goes to ``predict``) and the sets'
    ``labels``.

    The conditioned vector ``x`` holds the free fields of set 0, of set 1, ..., then the
    nuisance parameters; the residuals run over set 0's samples, then set 1's, ..."""

    kind: str
    layer_type: type[FittedLayer]
    free: tuple[str, ...]
    fixed: dict
    predict: Predict
    measured: np.ndarray
    bounds: tuple[dict, ...]
    nuisance: tuple[str, ...] = ()
    labels: tuple[str, ...] = ("",)

    @property
    def sets(self) -> int:
        return self.measured.shape[1]

    @property
    def samples(self) -> int:
        return int(self.measured.size)

    def set_indices(self, s: int) -> list[int]:
        """Indices in ``x`` of set ``s``'s free fields."""
        k = len(self.free)
        return list(range(s * k, (s + 1) * k))

    def nuisance_indices(self) -> list[int]:
        start = self.sets * len(self.free)
        return list(range(start, start + len(self.nuisance)))

    def set_rows(self, s: int) -> slice:
        """Set ``s``'s rows of the residuals."""
        m = self.measured.shape[0]
        return slice(s * m, (s + 1) * m)

    def names(self, labelled: bool = True) -> tuple[str, ...]:
        """Parameter names in ``x`` order (``"<label>.<field>"`` when labelled and the set has
        a label)."""
        out = []
        for label in self.labels:
            prefix = f"{label}." if (labelled and label) else ""
            out += [prefix + name for name in self.free]
        return tuple(out) + self.nuisance

    def parameter(self, i: int) -> str:
        """The unlabelled name of parameter ``i``."""
        k = len(self.free)
        return self.free[i % k] if i < self.sets * k else self.nuisance[i - self.sets * k]

    def layer(self, x: np.ndarray, s: int) -> FittedLayer:
        """Set ``s``'s fitted layer (checked)."""
        values = dict(self.fixed)
        values.update({name: _from_x(name, x[i])
                       for name, i in zip(self.free, self.set_indices(s), strict=True)})
        return self.layer_type(**values)

    def values(self, x: np.ndarray) -> LayerValues:
        """Every set's fields at once (free ones as arrays over the sets)."""
        k = len(self.free)
        columns = x[:self.sets * k].reshape(self.sets, k)
        free = {name: _from_x_array(name, columns[:, j]) for j, name in enumerate(self.free)}
        return LayerValues(channels=(self.sets,), **self.fixed, **free)

    def nuisance_values(self, x: np.ndarray) -> dict[str, float]:
        return {name: _from_x(name, x[i])
                for name, i in zip(self.nuisance, self.nuisance_indices(), strict=True)}

    def residuals(self, x: np.ndarray) -> np.ndarray:
        nuisance = self.nuisance_values(x)
        model = np.maximum(self.predict(self.values(x), nuisance), 1e-300)
        scale = np.log(nuisance["scale"]) if "scale" in nuisance else 0.0
        return (np.log(model) + scale - np.log(self.measured)).T.ravel()

    def jacobian(self, x: np.ndarray, central: bool = False) -> np.ndarray:
        """Forward differences (step ``sqrt(eps) max(1, |x|)``), or ``central`` ones (step
        ``eps^(1/3) max(1, |x|)``: truncation and rounding errors near 1e-11 instead of 1e-8); a
        field is moved in every set at once (a set's own fields move only its residuals)."""
        base = None if central else self.residuals(x)
        k = len(self.free)
        groups = [[s * k + j for s in range(self.sets)] for j in range(k)]
        groups += [[i] for i in self.nuisance_indices()]
        jac = np.zeros((self.samples, x.size))
        for group in groups:
            size = (_CENTRAL_STEP if central else _STEP) * np.maximum(1.0, np.abs(x[group]))
            up, down = x.copy(), x.copy()
            up[group] += size
            if central:
                down[group] -= size
            change = self.residuals(up) - (self.residuals(down) if central else base)
            for i in group:
                step = up[i] - down[i]  # the step as represented
                rows = slice(None) if i >= self.sets * k else self.set_rows(i // k)
                jac[rows, i] = change[rows] / step
        return jac

    def x_bounds(self) -> NDArray[np.float64]:
        """``(2, parameters)``: the lower and the upper bound of each parameter in ``x``."""
        pairs = [[_to_x(name, v) for v in self.bounds[s][name]]
                 for s in range(self.sets) for name in self.free]
        pairs += [[_to_x(name, v) for v in BOUNDS[name]] for name in self.nuisance]
        return np.array(pairs).T

    def x_of(self, layers: Sequence[Any], nuisance: dict | None = None) -> np.ndarray:
        """Conditioned coordinates of one start layer (or any object with the free fields) per
        set and the nuisance values (default: scale 1, tilt 0), clipped inside the bounds."""
        nuisance = nuisance or {}
        x = [_to_x(name, float(getattr(layer, name))) for layer in layers for name in self.free]
        x += [_to_x(name, nuisance.get(name, 0.0 if name == TILT else 1.0))
              for name in self.nuisance]
        low, high = self.x_bounds()
        return np.clip(np.array(x), low + 1e-9, high - 1e-9)


def parameter_bounds(names: Sequence[str], measured: np.ndarray) -> dict:
    """Natural-unit bounds per parameter (P bounds relative to the largest measured value)."""
    top = float(np.max(measured))
    out = {}
    for name in names:
        if name.startswith("P_"):
            low, high = BOUNDS["P"]
            out[name] = (low * top, high * top)
        else:
            out[name] = BOUNDS[name]
    return out


def lobe_name(layer: Layer) -> str | None:
    """The field of a layer's lobe: ``P_s`` of eq. 2, ``P_t`` of eq. 4, None for a dipole."""
    return {ReflectionLayer: "P_s", TransmissionLayer: "P_t"}.get(type(layer))


def check_size(problem: Problem, total: int, where: str = "") -> None:
    """``ValueError`` unless the problem has a sample more than it has parameters."""
    needed = len(problem.names()) + 1
    if problem.samples < needed:
        used = f"{problem.samples} of {total}" if where else f"{problem.samples}"
        what = (f"a {problem.kind} fit" if problem.sets == 1 else
                f"a joint {problem.kind} fit of {problem.sets} data sets")
        raise ValueError(f"{what} needs at least {needed} samples{where}, got {used}")


def solve(problem: Problem[FittedLayer], starts: Sequence[NDArray[np.float64]],
          limits: Limits) -> JointFit[FittedLayer]:
    """Refine every start with ``least_squares``; polish the lowest cost's end (:func:`_polish`)
    and diagnose it."""
    low, high = problem.x_bounds()
    runs = []
    for x0 in starts:
        x0 = np.clip(np.asarray(x0, dtype=float), low + 1e-9, high - 1e-9)
        runs.append(least_squares(problem.residuals, x0, jac=problem.jacobian,
                                  bounds=(low, high), method="trf", x_scale=1.0,
                                  ftol=_TOLERANCE, xtol=_TOLERANCE, gtol=_TOLERANCE,
                                  max_nfev=_EVALUATIONS * x0.size))
    best = min(runs, key=lambda run: run.cost)
    x, cost = _polish(problem, best.x, low, high)
    end = SimpleNamespace(x=x, cost=cost, success=best.success, message=best.message)
    return _diagnose(problem, end, low, high, limits, runs)


def _polish(problem: Problem, x: np.ndarray, low: NDArray[np.float64],
            high: NDArray[np.float64]) -> tuple[np.ndarray, float]:
    """Gauss-Newton steps with a central-difference Jacobian over the parameters off their
    bounds, from the optimiser's end (which its tolerances leave about 1e-7 away from the
    optimum in poorly determined directions) to the optimum within about 1e-9; a step that
    would leave the bounds or raise the cost ends the polish (``(x, cost)``)."""
    r = problem.residuals(x)
    cost = 0.5 * float(r @ r)
    inside = (x > low + 1e-6) & (x < high - 1e-6)
    previous = np.inf
    for _ in range(POLISH_STEPS if np.any(inside) else 0):
        jac = problem.jacobian(x, central=True)[:, inside]
        step = np.linalg.lstsq(jac, r, rcond=None)[0]
        trial = x.copy()
        trial[inside] -= step
        if np.any(trial <= low) or np.any(trial >= high):
            break
        trial_r = problem.residuals(trial)
        trial_cost = 0.5 * float(trial_r @ trial_r)
        if trial_cost > cost * (1.0 + 1e-12):
            break
        x, r, cost = trial, trial_r, trial_cost
        size = float(np.max(np.abs(step)))
        if size < 1e-12 or (size < 1e-8 and size > 0.5 * previous):
            break  # converged, or down to rounding
        previous = size
    return x, cost


def _ends(problem: Problem, runs: list[OptimizeResult],
          best: SimpleNamespace) -> tuple[Starts, list[OptimizeResult]]:
    """The :class:`Starts` record and the runs that ended elsewhere (other minima)."""
    floor = _COST_FLOOR * problem.samples
    reached = [run.cost - best.cost <= SAME_COST * best.cost + floor for run in runs]
    same = [run for run, flag in zip(runs, reached, strict=True) if flag]
    others = [run for run, flag in zip(runs, reached, strict=True) if not flag]
    spread = max(float(np.max(np.abs(run.x - best.x))) for run in same)
    excess = (min(run.cost for run in others) - best.cost) / max(best.cost, floor) if others \
        else None
    return Starts(len(runs), len(same), float(best.cost), spread, excess), others


def _rival(problem: Problem, others: list[OptimizeResult], result: SimpleNamespace, s2: float,
           se_x: NDArray[np.float64], limits: Limits) -> str | None:
    """A warning when another minimum fits as well within the noise (:attr:`Limits.rival_chi2`)
    with some parameter more than one standard error away."""
    names = problem.names()
    for run in sorted(others, key=lambda r: r.cost):
        chi2 = 2.0 * (run.cost - result.cost) / max(s2, 1e-300)
        if chi2 >= limits.rival_chi2:
            return None
        with np.errstate(divide="ignore", invalid="ignore"):
            distance = np.abs(run.x - result.x) / se_x
        distance = np.where(np.isfinite(distance), distance, 0.0)
        i = int(np.argmax(distance))
        if distance[i] > 1.0:
            return (f"another minimum fits as well within the noise: its chi-square is higher "
                    f"by {chi2:.2g} (limit {limits.rival_chi2:g}), with {names[i]} = "
                    f"{_from_x(problem.parameter(i), run.x[i]):.4g}, {distance[i]:.3g} standard "
                    "errors away; the data do not choose between the two")
    return None


def _diagnose(problem: Problem[FittedLayer], result: SimpleNamespace,
              low: NDArray[np.float64], high: NDArray[np.float64], limits: Limits,
              runs: list[OptimizeResult]) -> JointFit[FittedLayer]:
    """Covariance ``(J^T J)^-1 s^2`` over every parameter, one :class:`FitResult` per set and
    the warnings of :class:`Limits`."""
    names = problem.names()
    x = result.x
    starts, others = _ends(problem, runs, result)
    m, p = problem.samples, len(names)
    jac = problem.jacobian(x, central=True)
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

    nuisance_idx = problem.nuisance_indices()
    nuisance = {}
    for i in nuisance_idx:
        name = problem.parameter(i)
        value = _from_x(name, x[i])
        nuisance[name] = (value, float(se_x[i] if name == TILT else value * se_x[i]))
    residuals = problem.residuals(x)
    rival = _rival(problem, others, result, s2, se_x, limits)
    diagnosis = (x, se_x, correlation, condition, low, high, limits, rival)
    fits = []
    for s_index in range(problem.sets):
        idx = problem.set_indices(s_index) + nuisance_idx
        own = residuals[problem.set_rows(s_index)]
        rms = float(np.sqrt(np.mean(own * own)))
        fits.append(_set_result(problem, s_index, idx, cov, nuisance, rms, starts, result,
                                diagnosis))
    rms = float(np.sqrt(2.0 * result.cost / m))
    warnings = _warnings(problem, list(range(p)), True, result, rms, diagnosis)
    return JointFit(tuple(fits), problem.labels, nuisance, names, correlation, rms, condition,
                    m, starts, warnings)


def _set_result(problem: Problem[FittedLayer], s: int, idx: list[int],
                cov: NDArray[np.float64], nuisance: dict[str, tuple[float, float]], rms: float,
                starts: Starts, result: SimpleNamespace,
                diagnosis: tuple) -> FitResult[FittedLayer]:
    """Set ``s``'s :class:`FitResult` from the joint covariance."""
    x, se_x, correlation, condition = diagnosis[:4]
    layer = problem.layer(x, s)
    own = problem.set_indices(s)
    stderr, relative = {}, {}
    for name, i in zip(problem.free, own, strict=True):
        stderr[name] = float((float(getattr(layer, name)) - _offset(name)) * se_x[i])
        relative[name] = float(se_x[i])
    derived = {}
    lobe = lobe_name(layer)
    if lobe and {"P_d", lobe} <= set(problem.free) and not isinstance(layer, Dipole):
        i, j = own[problem.free.index("P_d")], own[problem.free.index(lobe)]
        ratio = float(getattr(layer, lobe) / layer.P_d)
        var = cov[i, i] + cov[j, j] - 2.0 * cov[i, j]
        derived[f"{lobe}/P_d"] = (ratio, ratio * float(np.sqrt(max(var, 0.0))))
    derived.update(nuisance)
    warnings = _warnings(problem, idx, False, result, rms, diagnosis)
    return FitResult(problem.kind, layer, problem.free, dict(problem.fixed), stderr, relative,
                     correlation[np.ix_(idx, idx)], derived, rms, condition,
                     int(problem.measured.shape[0]), warnings, starts)


def _warnings(problem: Problem, idx: list[int], labelled: bool, result: SimpleNamespace,
              rms: float, diagnosis: tuple) -> list[str]:
    """One sentence per problem the covariance and the optimiser reveal, over the parameters
    ``idx`` (named with their set's label when ``labelled``)."""
    x, se_x, correlation, condition, low, high, limits, rival = diagnosis
    names = problem.names(labelled)
    out = []
    if not result.success:
        out.append(f"the optimiser did not converge: {result.message}")
    for i in idx:
        name, parameter = names[i], problem.parameter(i)
        if x[i] <= low[i] + 1e-6 or x[i] >= high[i] - 1e-6:
            out.append(f"{name} ended at its bound ({_from_x(parameter, x[i]):.4g}): "
                       "the data do not determine it")
        elif parameter != TILT and se_x[i] > limits.relative_stderr:
            what = name.replace("eta", "eta - 1") if parameter == "eta" else name
            hint = "; hold it fixed if it is known (eta=, --eta)" if parameter == "eta" else ""
            out.append(f"{name} is ill-conditioned: its standard error is {100 * se_x[i]:.3g}% "
                       f"of {what} (limit {100 * limits.relative_stderr:.3g}%); the other "
                       f"values and their errors hold for this {name} only{hint}")
    for a, i in enumerate(idx):
        for j in idx[a + 1:]:
            if abs(correlation[i, j]) > limits.correlation:
                out.append(f"{names[i]} and {names[j]} are degenerate (correlation "
                           f"{correlation[i, j]:+.4f}): only a combination of them is determined")
    if condition > limits.condition_number:
        out.append(f"the Jacobian's condition number {condition:.3g} exceeds "
                   f"{limits.condition_number:.3g}: the problem is ill-conditioned")
    if rms > limits.residual_rms:
        out.append(f"the residual rms {100 * rms:.3g}% exceeds {100 * limits.residual_rms:.3g}%: "
                   "the model does not describe these data")
    if rival:
        out.append(rival)
    return out
