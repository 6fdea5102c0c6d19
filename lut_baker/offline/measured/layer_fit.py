"""Fitting the paper's layers to measurements (paper sections 4.1, 4.2; docs/model.md §5, 6).

Each fit minimises relative residuals ``log(model) - log(measured)`` with
:func:`scipy.optimize.least_squares` (suited to multiplicative noise: 2% noise gives a residual
rms of 0.02) over conditioned parameters: ``log`` of ``P_d``, ``P_s``/``P_t``, ``n``,
``sigma_s``, ``sigma_a`` and ``log(eta - 1)``; a tilt of the sample stays in degrees.  The
forward models are :mod:`lut_baker.offline.measured.measurements`' (``I = f N.L``, paper eqs.
1-4; ``R(d)/R(0)``, eq. 6).  The Jacobian is taken by forward differences (step
``sqrt(eps)`` in the conditioned parameters) and the optimiser's tolerances are 1e-12, so that
the optimum is located to about 1e-9 of a standard error and a fit moves by about as much as
its data when they are perturbed.

Several data sets may be fitted at once (:func:`fit_reflection_sets`: the R, G, B channels of one
measurement), each with its own layer, sharing nuisance parameters: a tilt of the sample in the
plane of incidence (an offset of alpha, :func:`~lut_baker.offline.measured.protocols.tilted`) or
the profile's scale.  A nuisance parameter is fitted with its standard error and is not part of
the layer.

Starting points (multi-start).  The intensity is linear in ``P_d`` and ``P_s``/``P_t``, so for
each ``n`` on a coarse logarithmic grid they are solved by non-negative least squares at a
given eta; the best ``n`` per eta of :data:`ETA_STARTS` (and per tilt of
:data:`TILT_STARTS_DEG` when the tilt is fitted) is one start; with eta held fixed, the best
``n`` in each of :data:`N_GRID_PARTS` parts of the grid is; the caller's start, if any, is one
more.  Without lobe the problem is linear in ``log P_d``: its one start is the solution.  The
dipole's starts are the local minima of a coarse ``(sigma_s, sigma_a)`` grid (at most
:data:`DIPOLE_STARTS`).  Every start is refined; the lowest cost wins, is polished (Gauss-Newton
steps, central differences) and :class:`Starts` records how many starts reached it (within
:data:`SAME_COST` relative), how far their parameters spread and how much higher the best other
end lies.

Uncertainty: ``cov = (J^T J)^-1 s^2`` with ``J`` the Jacobian of the residuals in the conditioned
parameters at the solution and ``s^2`` the residual variance.  Since every conditioned parameter
but the tilt is a logarithm, its standard error is a *relative* one (for eta: relative to
``eta - 1``, the strength of Fresnel reflection).  A fit says so rather than return nonsense:
its ``warnings`` name every parameter whose relative standard error exceeds 10%, every pair
correlated beyond 0.99, a Jacobian condition number beyond 1e4, parameters stuck at a bound, a
residual rms beyond 20%, another minimum that fits as well within the noise (a start that ended
elsewhere with a chi-square less than 4 higher and some parameter more than one standard error
away: the covariance describes one basin only) and a failed optimisation (thresholds:
:class:`Limits`).

Functions and types
-------------------
- :class:`FitResult` -- fitted layer, standard errors, correlation, diagnostics, warnings.
- :class:`JointFit` -- several data sets fitted at once: one ``FitResult`` each, the shared
  nuisance parameters, the joint diagnostics.
- :class:`Starts` -- how the starts of a fit ended.
- :class:`Limits` -- the thresholds behind the warnings.
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

from dataclasses import dataclass, field, fields, replace
from types import SimpleNamespace

import numpy as np
from scipy.optimize import least_squares, nnls

from ...model.layers import Dipole, ReflectionLayer, TransmissionLayer
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
    "TILT",
    "TILT_LIMIT_DEG",
    "ETA_STARTS",
    "N_GRID_PARTS",
    "TILT_STARTS_DEG",
    "SAME_COST",
    "Limits",
    "Starts",
    "FitResult",
    "JointFit",
    "fit_reflection",
    "fit_reflection_sets",
    "fit_transmission",
    "fit_dipole",
    "fit_measurements",
    "poor_start",
    "relative_errors",
]

D_MIN_MM = 0.1
"""Profile samples closer than this to the lit pixel (mm) are left out of a dipole fit: there the
direct light and the scattering separate poorly (paper 4.2.2)."""

TILT = "tilt_deg"
"""Name of the nuisance parameter "tilt of the sample" (degrees; an offset of alpha)."""
TILT_LIMIT_DEG = 5.0
"""The tilt is fitted within +-this many degrees; one that ends there is not determined."""

N_GRID_PER_DEG = np.geomspace(2e-3, 0.5, 25)
"""Roughness grid (1/degree) of the starting search: lobe half-widths 500 to 2 degrees."""
ETA_STARTS = (1.05, 1.5, 5.0)
"""Eta of the linear starts (one start each): weak to strong Fresnel reflection."""
N_GRID_PARTS = 3
"""With eta held fixed, the roughness grid is cut into this many parts (wide to narrow
lobes), one start each."""
TILT_STARTS_DEG = (-1.5, 0.0, 1.5)
"""Tilts (degrees) of the starts when the tilt is fitted."""
SIGMA_S_GRID_PER_MM = np.geomspace(0.05, 200.0, 10)
"""Scattering grid (1/mm) of the dipole's starting search."""
SIGMA_A_GRID_PER_MM = np.geomspace(1e-4, 10.0, 11)
"""Absorption grid (1/mm) of the dipole's starting search."""
DIPOLE_STARTS = 4
"""At most this many local minima of the dipole's grid are refined."""
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

# Natural-unit bounds; P bounds scale with the largest measured value.
_BOUNDS = {
    "P": (1e-9, 1e6),  # times max(measured)
    "n": (1e-4, 10.0),  # 1/degree
    "eta": (1.0 + 1e-4, 10.0),
    "sigma_s": (1e-4, 1e4),  # 1/mm
    "sigma_a": (1e-7, 1e3),  # 1/mm
    "scale": (1e-6, 1e6),
    TILT: (-TILT_LIMIT_DEG, TILT_LIMIT_DEG),
}
_NO_LOBE = {"n": _BOUNDS["n"][0], "eta": 1.0}
"""``n`` and ``eta`` of a layer fitted without lobe (``P_s = 0``; unused, reported as fixed): the
widest lobe (integrals over the hemisphere need no fine grid) and no interface."""


@dataclass(frozen=True)
class Limits:
    """Thresholds beyond which a fit warns (module docstring)."""

    relative_stderr: float = 0.10
    correlation: float = 0.99
    condition_number: float = 1e4
    residual_rms: float = 0.20
    rival_chi2: float = 4.0
    """Another minimum whose chi-square ``2 cost / s^2`` exceeds the best's by less than this
    (two standard deviations), with some parameter more than one standard error away, is a
    rival: the data do not choose between the two."""


@dataclass(frozen=True)
class Starts:
    """How the starts of a fit ended (module docstring).

    ``count``: starts refined; ``reached``: how many ended within :data:`SAME_COST` (relative)
    of the best cost ``best_cost`` (half the sum of squared residuals, at the polished optimum);
    ``spread``: the largest difference of a conditioned parameter (the logarithm of a value, of
    ``eta - 1``; the tilt in degrees) between the optimum and the end of a start that reached it
    (the optimiser's tolerance); ``next_excess``: ``(cost -
    best) / best`` of the best end that did not reach it (another local minimum), ``None``
    when every start reached the best."""

    count: int
    reached: int
    best_cost: float
    spread: float
    next_excess: float | None

    def as_dict(self) -> dict:
        """Plain numbers (``next_excess`` absent when every start reached the best)."""
        out = {"count": self.count, "reached": self.reached, "best_cost": self.best_cost,
               "spread": self.spread}
        if self.next_excess is not None:
            out["next_excess"] = self.next_excess
        return out

    def summary(self) -> str:
        """One phrase: ``"9 of 12 starts reached the best cost (parameters within 2e-09; the
        next end lies 31% higher)"``."""
        text = (f"{self.reached} of {self.count} starts reached the best cost (parameters "
                f"within {self.spread:.1g}")
        if self.next_excess is not None:
            text += f"; the next end lies {_relative_text(self.next_excess)} higher"
        return text + ")"


def _relative_text(value: float) -> str:
    return f"{100 * value:.3g}%" if value >= 1e-3 else f"{value:.2g} (relative)"


@dataclass(frozen=True, eq=False)
class FitResult:
    """The outcome of a fit.

    ``params``: the fitted layer (fixed fields as given).  ``stderr``: standard error per free
    field, in its unit.  ``relative_stderr``: the same relative to the value (to ``eta - 1``
    for eta).  ``correlation``: matrix over ``free`` and then the nuisance parameters (in that
    order).  ``derived``: name -> ``(value, stderr)`` of derived quantities (the P ratio) and
    of nuisance parameters (the profile's ``scale``, the sample's ``tilt_deg``).
    ``residual_rms``: rms of ``log(model/measured)`` (~ the relative noise).
    ``condition_number``: of the Jacobian in the conditioned parameters.  ``warnings``: one
    sentence per problem; empty when the fit is trustworthy.  ``starts``: how the starts ended
    (:class:`Starts`; in a joint fit, the joint fit's).
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
    starts: Starts | None = None

    @property
    def ok(self) -> bool:
        """True when the fit raised no warning."""
        return not self.warnings

    def at_bound(self, name: str) -> bool:
        """Whether the free parameter (or nuisance) ``name`` ended at its bound."""
        return any(w.startswith(f"{name} ended at its bound") for w in self.warnings)

    def as_dict(self) -> dict:
        """Plain floats, lists and strings, for TOML/JSON output."""
        out = {
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
        if self.starts is not None:
            out["starts"] = self.starts.as_dict()
        return out


@dataclass(frozen=True, eq=False)
class JointFit:
    """Several data sets fitted at once (:func:`fit_reflection_sets`).

    ``fits``: one :class:`FitResult` per data set, in order, labelled ``labels``; each holds its
    layer, its parameters' standard errors from the joint covariance (the shared parameters'
    uncertainty included), its own residual rms and the warnings that concern it.
    ``nuisance``: name -> ``(value, stderr)`` of the shared parameters (``tilt_deg``; empty when
    none was fitted).  ``names``: the joint parameters (``"<label>.<field>"``, then the
    nuisance), over which ``correlation`` runs.  ``residual_rms``: over every sample.
    ``warnings``: every warning, each parameter named with its label.
    """

    fits: tuple[FitResult, ...]
    labels: tuple[str, ...]
    nuisance: dict[str, tuple[float, float]]
    names: tuple[str, ...]
    correlation: np.ndarray
    residual_rms: float
    condition_number: float
    samples: int
    starts: Starts
    warnings: list[str] = field(default_factory=list)

    def at_bound(self, name: str) -> bool:
        """Whether the joint parameter ``name`` (e.g. ``"tilt_deg"``, ``"R.n"``) ended at its
        bound."""
        return any(w.startswith(f"{name} ended at its bound") for w in self.warnings)


# --------------------------------------------------------------------------------------------
# Conditioned parameters: x = log(value), or log(eta - 1) for eta; the tilt as it is
# --------------------------------------------------------------------------------------------
def _offset(name: str) -> float:
    return 1.0 if name == "eta" else 0.0


def _to_x(name: str, value: float) -> float:
    if name == TILT:
        return float(value)
    return float(np.log(value - _offset(name)))


def _from_x(name: str, x: float) -> float:
    return float(_from_x_array(name, x))


def _from_x_array(name: str, x):
    if name == TILT:
        return x
    return np.exp(x) + _offset(name)


class _Values(SimpleNamespace):
    """Layer field values without the layer's checks, for the fit's inner loop (the bounds
    keep them valid): the free fields as arrays over the data sets (``channels``), so the
    forward models evaluate every set at once (a trailing axis, as for an RGB layer)."""


@dataclass(frozen=True, eq=False)
class _Problem:
    """One least-squares problem over one or more data sets sharing their geometry: the layer
    type, the fields fitted in every set (``free``; the others ``fixed``), the forward model
    ``predict(values, nuisance) -> (samples, sets)`` (values > 0), the ``measured`` values
    ``(samples, sets)``, natural-unit ``bounds`` per set, the shared ``nuisance`` parameters
    (``"scale"`` multiplies the model, ``tilt_deg`` goes to ``predict``) and the sets'
    ``labels``.

    The conditioned vector ``x`` holds the free fields of set 0, of set 1, ..., then the
    nuisance parameters; the residuals run over set 0's samples, then set 1's, ..."""

    kind: str
    layer_type: type
    free: tuple[str, ...]
    fixed: dict
    predict: object
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

    def layer(self, x: np.ndarray, s: int):
        """Set ``s``'s fitted layer (checked)."""
        values = dict(self.fixed)
        values.update({name: _from_x(name, x[i])
                       for name, i in zip(self.free, self.set_indices(s), strict=True)})
        return self.layer_type(**values)

    def values(self, x: np.ndarray) -> _Values:
        """Every set's fields at once (free ones as arrays over the sets)."""
        k = len(self.free)
        columns = x[:self.sets * k].reshape(self.sets, k)
        free = {name: _from_x_array(name, columns[:, j]) for j, name in enumerate(self.free)}
        return _Values(channels=(self.sets,), **self.fixed, **free)

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

    def x_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        pairs = [[_to_x(name, v) for v in self.bounds[s][name]]
                 for s in range(self.sets) for name in self.free]
        pairs += [[_to_x(name, v) for v in _BOUNDS[name]] for name in self.nuisance]
        return np.array(pairs).T

    def x_of(self, layers, nuisance: dict | None = None) -> np.ndarray:
        """Conditioned coordinates of one start layer (or any object with the free fields) per
        set and the nuisance values (default: scale 1, tilt 0), clipped inside the bounds."""
        nuisance = nuisance or {}
        x = [_to_x(name, float(getattr(layer, name))) for layer in layers for name in self.free]
        x += [_to_x(name, nuisance.get(name, 0.0 if name == TILT else 1.0))
              for name in self.nuisance]
        low, high = self.x_bounds()
        return np.clip(np.array(x), low + 1e-9, high - 1e-9)


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
    guess refined alongside the multi-start's (module docstring)."""
    if not isinstance(data, ReflectionData):
        raise ValueError("fit_reflection needs ReflectionData (psi_deg, alpha_deg, "
                         "intensity_counts)")
    return fit_reflection_sets([data], start, eta=eta, limits=limits).fits[0]


def fit_reflection_sets(datasets, start: ReflectionLayer | None = None, *,
                        eta: float | None = None, lobe: bool = True, tilt: bool = False,
                        labels=None, limits: Limits = Limits()) -> JointFit:
    """Fit one ``ReflectionLayer`` (eq. 2) per data set in ``datasets`` (``ReflectionData``,
    e.g. the R, G, B channels of one measurement) at once.  ``eta`` given: held fixed in every
    set.  ``lobe=False``: ``P_d`` alone (``P_s = 0``; ``n``, ``eta`` fixed and unused).
    ``tilt``: a tilt of the sample shared by every set (``tilt_deg``, an offset of alpha; within
    +-:data:`TILT_LIMIT_DEG`) is fitted with them.  The sets must share their geometry.
    ``labels``: one per set (default ``"R"``, ``"G"``, ``"B"`` for three sets, else ``"0"``,
    ``"1"``, ...; none for one set).  ``start``: one layer, refined in every set alongside the
    multi-start's."""
    datasets = list(datasets)
    if not datasets or not all(isinstance(d, ReflectionData) for d in datasets):
        raise ValueError("fit_reflection_sets needs one or more ReflectionData")
    first = datasets[0]
    if not all(np.array_equal(d.psi_deg, first.psi_deg)
               and np.array_equal(d.alpha_deg, first.alpha_deg) for d in datasets):
        raise ValueError("the data sets of a joint fit must share their geometry (psi_deg, "
                         "alpha_deg)")
    model = ReflectionCounts(first)

    def predict(values, nuisance):
        return model(values, nuisance.get(TILT, 0.0))

    return _fit_pair(datasets, ReflectionLayer, "P_s", predict, start, eta, limits,
                     lobe_free=lobe, tilt=tilt, labels=labels)


def fit_transmission(data: TransmissionData, start: TransmissionLayer | None = None, *,
                     eta: float | None = None, limits: Limits = Limits()) -> FitResult:
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
                       lambda values, nuisance: profile_ratio(d, values), ratio[:, None],
                       (_bounds(free, ratio),), ("scale",) if free_scale else ())
    _check_size(problem, data.distance_mm.size, f" at d >= {d_min_mm:g} mm")
    Dipole(sigma_s=1.0, sigma_a=0.1, g=g, eta=eta)  # validates g and eta before the search
    starts = _dipole_starts(problem)
    if start is not None:
        starts.append(problem.x_of([start]))
    return _solve(problem, starts, limits).fits[0]


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
    if problem.samples < needed:
        used = f"{problem.samples} of {total}" if where else f"{problem.samples}"
        what = (f"a {problem.kind} fit" if problem.sets == 1 else
                f"a joint {problem.kind} fit of {problem.sets} data sets")
        raise ValueError(f"{what} needs at least {needed} samples{where}, got {used}")


def _default_labels(count: int) -> tuple[str, ...]:
    if count == 1:
        return ("",)
    return ("R", "G", "B") if count == 3 else tuple(str(i) for i in range(count))


def _fit_pair(datasets, layer_type, lobe: str, predict, start, eta, limits, *,
              lobe_free: bool = True, tilt: bool = False, labels=None) -> JointFit:
    """Reflection and transmission: intensity linear in ``P_d`` and the lobe's P; one layer per
    data set, an optional shared tilt."""
    measured = np.column_stack([data.intensity_counts for data in datasets])
    if lobe_free:
        free = ("P_d", lobe, "n") + (() if eta is not None else ("eta",))
        fixed = {} if eta is None else {"eta": float(eta)}
    else:
        free, fixed = ("P_d",), {lobe: 0.0, **_NO_LOBE}
    kind = "reflection" if layer_type is ReflectionLayer else "transmission"
    labels = tuple(labels) if labels is not None else _default_labels(len(datasets))
    if len(labels) != len(datasets):
        raise ValueError(f"{len(labels)} labels for {len(datasets)} data sets")
    problem = _Problem(kind, layer_type, free, fixed, predict, measured,
                       tuple(_bounds(free + ("eta",), m) for m in measured.T),
                       (TILT,) if tilt else (), labels)
    _check_size(problem, problem.samples)
    if eta is not None:
        layer_type(P_d=1.0, **{lobe: 1.0}, n=1.0, eta=eta)  # validates a fixed eta
    etas = (eta,) if eta is not None else ETA_STARTS
    grids = np.array_split(N_GRID_PER_DEG, 1 if len(etas) > 1 else N_GRID_PARTS)
    starts = []
    for tilt_deg in (TILT_STARTS_DEG if tilt else (0.0,)):
        for eta0 in (etas if lobe_free else etas[:1]):
            for grid in (grids if lobe_free else grids[:1]):
                layers = _linear_starts(problem, lobe, eta0, tilt_deg, lobe_free, grid)
                starts.append(problem.x_of(layers, {TILT: tilt_deg}))
    if start is not None:
        starts.append(problem.x_of([start] * problem.sets))
    return _solve(problem, starts, limits)


def _linear_starts(problem: _Problem, lobe: str, eta: float, tilt_deg: float,
                   lobe_free: bool, grid) -> list[SimpleNamespace]:
    """One start per set at ``eta`` and ``tilt_deg``: for each ``n`` of ``grid``, ``P_d`` and
    the lobe's P by non-negative least squares on relative residuals; the ``n`` of lowest cost.
    A lobe the least squares drop starts at 1% of the diffuse level at its peak (from 0 the
    optimiser could not grow it).  Without lobe: ``P_d`` by least squares in log (the
    solution: the problem is linear)."""
    nuisance = {TILT: tilt_deg}
    diffuse = problem.predict(_Values(channels=(), P_d=1.0, **{lobe: 0.0}, n=1.0, eta=eta),
                              nuisance)
    bases = [problem.predict(_Values(channels=(), P_d=0.0, **{lobe: 1.0}, n=n, eta=eta),
                             nuisance) for n in grid]
    starts = []
    for s in range(problem.sets):
        measured = problem.measured[:, s]
        low, high = problem.bounds[s]["P_d"]
        if not lobe_free:
            p_d = float(np.exp(np.mean(np.log(measured / diffuse))))
            starts.append(SimpleNamespace(P_d=float(np.clip(p_d, low, high))))
            continue
        weight = 1.0 / measured
        best = None
        for n, basis in zip(grid, bases, strict=True):
            p, _ = nnls(np.stack([diffuse, basis], axis=1) * weight[:, None],
                        np.ones_like(weight))
            p = np.clip(p, low, high)
            cost = float(np.sum(np.log((p[0] * diffuse + p[1] * basis) * weight) ** 2))
            if best is None or cost < best[0]:
                floor = 0.01 * p[0] * float(np.max(diffuse) / np.max(basis))
                best = (cost, SimpleNamespace(**{"P_d": p[0], lobe: max(p[1], floor), "n": n,
                                                 "eta": eta}))
        starts.append(best[1])
    return starts


def _dipole_starts(problem: _Problem) -> list[np.ndarray]:
    """The local minima (no lower neighbour along either axis) of the cost on a logarithmic
    ``(sigma_s, sigma_a)`` grid, lowest first, at most :data:`DIPOLE_STARTS` (with the best
    log-scale when it is free)."""
    grid, costs = {}, np.empty((SIGMA_S_GRID_PER_MM.size, SIGMA_A_GRID_PER_MM.size))
    for i, sigma_s in enumerate(SIGMA_S_GRID_PER_MM):
        for j, sigma_a in enumerate(SIGMA_A_GRID_PER_MM):
            x = problem.x_of([SimpleNamespace(sigma_s=sigma_s, sigma_a=sigma_a)])
            r = problem.residuals(x)
            if problem.nuisance:
                x[-1] = -float(np.mean(r))
                r = r + x[-1]
            grid[i, j] = x
            costs[i, j] = float(np.sum(r * r))
    padded = np.pad(costs, 1, constant_values=np.inf)
    minima = ((costs <= padded[:-2, 1:-1]) & (costs <= padded[2:, 1:-1])
              & (costs <= padded[1:-1, :-2]) & (costs <= padded[1:-1, 2:]))
    order = sorted(zip(*np.nonzero(minima), strict=True), key=lambda ij: costs[ij])
    return [grid[ij] for ij in order[:DIPOLE_STARTS]]


def _solve(problem: _Problem, starts, limits: Limits) -> JointFit:
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


def _polish(problem: _Problem, x: np.ndarray, low, high) -> tuple[np.ndarray, float]:
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


def _ends(problem: _Problem, runs, best) -> tuple[Starts, list]:
    """The :class:`Starts` record and the runs that ended elsewhere (other minima)."""
    floor = _COST_FLOOR * problem.samples
    reached = [run.cost - best.cost <= SAME_COST * best.cost + floor for run in runs]
    same = [run for run, flag in zip(runs, reached, strict=True) if flag]
    others = [run for run, flag in zip(runs, reached, strict=True) if not flag]
    spread = max(float(np.max(np.abs(run.x - best.x))) for run in same)
    excess = (min(run.cost for run in others) - best.cost) / max(best.cost, floor) if others \
        else None
    return Starts(len(runs), len(same), float(best.cost), spread, excess), others


def _rival(problem: _Problem, others, result, s2: float, se_x, limits: Limits) -> str | None:
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


def _diagnose(problem: _Problem, result, low, high, limits: Limits, runs) -> JointFit:
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


def _set_result(problem: _Problem, s: int, idx: list[int], cov, nuisance, rms: float,
                starts: Starts, result, diagnosis) -> FitResult:
    """Set ``s``'s :class:`FitResult` from the joint covariance."""
    x, se_x, correlation, condition = diagnosis[:4]
    layer = problem.layer(x, s)
    own = problem.set_indices(s)
    stderr, relative = {}, {}
    for name, i in zip(problem.free, own, strict=True):
        stderr[name] = float((float(getattr(layer, name)) - _offset(name)) * se_x[i])
        relative[name] = float(se_x[i])
    derived = {}
    lobe = _lobe_name(layer)
    if lobe and {"P_d", lobe} <= set(problem.free):
        i, j = own[problem.free.index("P_d")], own[problem.free.index(lobe)]
        ratio = float(getattr(layer, lobe) / layer.P_d)
        var = cov[i, i] + cov[j, j] - 2.0 * cov[i, j]
        derived[f"{lobe}/P_d"] = (ratio, ratio * float(np.sqrt(max(var, 0.0))))
    derived.update(nuisance)
    warnings = _warnings(problem, idx, False, result, rms, diagnosis)
    return FitResult(problem.kind, layer, problem.free, dict(problem.fixed), stderr, relative,
                     correlation[np.ix_(idx, idx)], derived, rms, condition,
                     int(problem.measured.shape[0]), warnings, starts)


def _warnings(problem: _Problem, idx: list[int], labelled: bool, result, rms: float,
              diagnosis) -> list[str]:
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
