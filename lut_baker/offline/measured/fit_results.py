"""The outcome of the layer fits (:mod:`lut_baker.offline.measured.layer_fit`): the fitted layer
with its uncertainties and warnings, several data sets fitted at once, how the starts ended, and
the thresholds behind the warnings (docs/fitting.md).

Types
-----
- :class:`FitResult` -- fitted layer, standard errors, correlation, diagnostics, warnings.
- :class:`JointFit` -- several data sets fitted at once: one ``FitResult`` each, the shared
  nuisance parameters, the joint diagnostics.
- :class:`Starts` -- how the starts of a fit ended.
- :class:`Limits` -- the thresholds behind the warnings (:data:`DEFAULT_LIMITS`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Generic, TypeVar

import numpy as np

from ...model.layers import Dipole, ReflectionLayer, TransmissionLayer

__all__ = ["Limits", "DEFAULT_LIMITS", "Starts", "FitResult", "JointFit", "FittedLayer"]

FittedLayer = TypeVar("FittedLayer", ReflectionLayer, TransmissionLayer, Dipole)
"""The layer type a fit returns: eq. 2's, eq. 4's or the dipole."""


@dataclass(frozen=True)
class Limits:
    """Thresholds beyond which a fit warns (:mod:`~lut_baker.offline.measured.fit_solver`)."""

    relative_stderr: float = 0.10
    correlation: float = 0.99
    condition_number: float = 1e4
    residual_rms: float = 0.20
    rival_chi2: float = 4.0
    """Another minimum whose chi-square ``2 cost / s^2`` exceeds the best's by less than this
    (two standard deviations), with some parameter more than one standard error away, is a
    rival: the data do not choose between the two."""


DEFAULT_LIMITS = Limits()
"""The thresholds a fit warns at unless told otherwise."""


@dataclass(frozen=True)
class Starts:
    """How the starts of a fit ended (:mod:`~lut_baker.offline.measured.fit_starts`).

    ``count``: starts refined; ``reached``: how many ended within
    :data:`~lut_baker.offline.measured.fit_solver.SAME_COST` (relative) of the best cost
    ``best_cost`` (half the sum of squared residuals, at the polished optimum); ``spread``: the
    largest difference of a conditioned parameter (the logarithm of a value, of ``eta - 1``;
    the tilt in degrees) between the optimum and the end of a start that reached it (the
    optimiser's tolerance); ``next_excess``: ``(cost - best) / best`` of the best end that did
    not reach it (another local minimum), ``None`` when every start reached the best."""

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
class FitResult(Generic[FittedLayer]):
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
    params: FittedLayer
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
class JointFit(Generic[FittedLayer]):
    """Several data sets fitted at once (:func:`fit_reflection_sets`).

    ``fits``: one :class:`FitResult` per data set, in order, labelled ``labels``; each holds its
    layer, its parameters' standard errors from the joint covariance (the shared parameters'
    uncertainty included), its own residual rms and the warnings that concern it.
    ``nuisance``: name -> ``(value, stderr)`` of the shared parameters (``tilt_deg``; empty when
    none was fitted).  ``names``: the joint parameters (``"<label>.<field>"``, then the
    nuisance), over which ``correlation`` runs.  ``residual_rms``: over every sample.
    ``warnings``: every warning, each parameter named with its label.
    """

    fits: tuple[FitResult[FittedLayer], ...]
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
