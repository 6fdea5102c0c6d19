"""One-dimensional minimisation in plain numpy, so the run-time path inside Blender needs no
scipy (Blender's Python ships numpy only).

Functions
---------
- :func:`golden_minimum` -- coarse scan, golden-section search, then a refinement that makes
  the result a continuous function of the data (:func:`stencil_minimum`).
- :func:`stencil_minimum` -- the point where a function takes equal values a fixed step
  either side: the vertex of the parabola through three points, iterated to its fixed point.
- :func:`brent_minimum` -- coarse scan, then Brent's method (parabolic steps, golden-section
  fallback) to a tight tolerance: the minimum of a smooth function, converged so far that the
  result is a continuous function of the data (a change of ``1e-9`` in the function moves it
  by about as much, not by the tolerance of a loose search).
- :func:`least_squares` -- bounded Levenberg-Marquardt on a small parameter vector, from a
  start, to a tight tolerance (a smooth fit converges in a few steps where nested 1-D searches
  take hundreds of evaluations); :func:`scanned_least_squares` -- the same from the best point
  of a grid of starts.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["golden_minimum", "stencil_minimum", "REFINE_STEPS", "REFINE_PRECISION",
           "brent_minimum", "BRENT_XTOL", "least_squares", "scanned_least_squares"]

BRENT_XTOL = 1e-9
"""Default absolute tolerance of :func:`brent_minimum`, in the units of ``x``."""

REFINE_STEPS = 12
"""Most parabola steps of :func:`stencil_minimum` (it needs 2-4 from a golden-section
bracket)."""
REFINE_PRECISION = 1e-6
""":func:`stencil_minimum` stops when a step is below this fraction of the interval.  Near
its fixed point a step leaves about the square of the distance (times ``f''' / f''``), or a
fraction ``h^2 f'''' / (12 f'')`` of it where that is more (about 1e-7 at the fits' steps):
the point after such a step is within ~1e-12 of the interval of the fixed point, from any
start."""


def stencil_minimum(function: Callable[[float], float], x: float, low: float, high: float,
                    step: float) -> tuple[float, float] | None:
    """``(x, f)``: the point of ``[low, high]`` where ``function(x - step) = function(x +
    step)`` (the minimum of the parabola through three points ``step`` apart, moved until it
    is the middle one), found from a start ``x`` near it; ``f``: ``function`` at the last
    middle point (within ``REFINE_PRECISION (high - low)`` of ``x``).  Where the stencil would
    leave the interval it stays inside it (``[low, low + 2 step]`` or ``[high - 2 step,
    high]``) and the vertex is clipped to the interval.

    Unlike a search that compares values, the result is a continuous function of the
    ``function``'s values: where two comparisons of nearly equal values would flip, it does
    not jump.  ``None`` when the parabola does not open upwards (no minimum near ``x``) or
    the steps do not settle within :data:`REFINE_STEPS`."""
    span = high - low
    if not 0.0 < 2.0 * step < span:
        raise ValueError(f"need 0 < 2 step < high - low, got step {step} on [{low}, {high}]")

    def held(point: float) -> float:  # the stencil's middle: inside [low + step, high - step]
        return min(max(point, low + step), high - step)

    for _ in range(REFINE_STEPS):
        centre = held(x)
        below, middle, above = (function(centre - step), function(centre),
                                function(centre + step))
        curvature = above - 2.0 * middle + below
        if not curvature > 0.0:
            return None
        vertex = min(max(centre + step * (below - above) / (2.0 * curvature), low), high)
        if centre == x and abs(vertex - x) <= REFINE_PRECISION * span:
            return vertex, middle
        if centre != x and held(vertex) == centre:
            # near an end the stencil is held there: its vertex is the fixed point
            return vertex, (middle if vertex == centre else function(vertex))
        x = vertex
    return None


def golden_minimum(function: Callable[[float], float], low: float, high: float, *,
                   tol: float = 1e-4,
                   coarse: int = 9) -> tuple[float, float]:
    """``(x, f(x))`` minimising a 1-D ``function`` on ``[low, high]``: the best of ``coarse``
    evenly spaced samples, golden-section search in the bracket around it down to a few
    times ``h = tol (high - low)``, then :func:`stencil_minimum` with step ``h``.

    The refinement makes ``x`` a continuous function of the ``function``'s values: the
    golden-section search alone returns one of the points it compared, and a perturbation
    that flips one comparison of nearly equal values (two coarse samples either side of the
    minimum; a late bracket) moves ``x`` by up to the bracket's width.  The refined ``x``
    lies within about ``h^2 f''' / f''`` of the true minimum.  Should the refinement find no
    minimum near the search's point (a parabola opening downwards), that point is returned.
    Two separated minima of nearly equal value remain a discrete choice (the lower coarse
    sample's)."""
    span = high - low
    step = tol * span
    known: dict[float, float] = {}

    def function_once(x: float) -> float:  # the refinement's first middle: the search's best
        x = float(x)
        if x not in known:
            known[x] = function(x)
        return known[x]

    xs = np.linspace(low, high, coarse)
    values = [function(x) for x in xs]
    k = int(np.argmin(values))
    a, b = xs[max(k - 1, 0)], xs[min(k + 1, coarse - 1)]
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = function(c), function(d)
    while b - a > 8.0 * step:
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - ratio * (b - a)
            fc = function(c)
        else:
            a, c, fc = c, d, fd
            d = a + ratio * (b - a)
            fd = function(d)
    best = min([(values[k], xs[k]), (fc, c), (fd, d)])
    if 2.0 * step < span:
        refined = stencil_minimum(function_once, float(best[1]), low, high, step)
        if refined is not None:
            return float(refined[0]), float(refined[1])
    return float(best[1]), float(best[0])


def brent_minimum(function: Callable[[float], float], low: float, high: float, *,
                  xtol: float = BRENT_XTOL,
                  coarse: int = 9, max_steps: int = 200) -> tuple[float, float]:
    """``(x, f(x))`` minimising a 1-D ``function`` on ``[low, high]``: the best of ``coarse``
    evenly spaced samples, then Brent's bounded minimisation (as ``fminbound``: parabolic
    interpolation, golden section where it stalls) in the bracket around it, to an absolute
    tolerance ``xtol`` in ``x``.  A minimum at an end of ``[low, high]`` is returned there."""
    xs = np.linspace(low, high, coarse)
    values = [float(function(x)) for x in xs]
    k = int(np.argmin(values))
    a, b = float(xs[max(k - 1, 0)]), float(xs[min(k + 1, coarse - 1)])
    golden = 0.5 * (3.0 - np.sqrt(5.0))
    x = w = v = float(xs[k])
    fx = fw = fv = values[k]
    d = e = 0.0
    for _ in range(max_steps):
        middle = 0.5 * (a + b)
        tol1 = xtol / 3.0 + 1e-12 * abs(x)
        tol2 = 2.0 * tol1
        if abs(x - middle) <= tol2 - 0.5 * (b - a):
            break
        parabolic = False
        if abs(e) > tol1:
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            if abs(p) < abs(0.5 * q * e) and q * (a - x) < p < q * (b - x):
                e, d = d, p / q
                u = x + d
                if u - a < tol2 or b - u < tol2:
                    d = tol1 if middle >= x else -tol1
                parabolic = True
        if not parabolic:
            e = (a - x) if x >= middle else (b - x)
            d = golden * e
        u = x + (d if abs(d) >= tol1 else (tol1 if d > 0 else -tol1))
        fu = float(function(u))
        if fu <= fx:
            if u >= x:
                a = x
            else:
                b = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
    best = min((fx, x), (values[0], float(xs[0])), (values[-1], float(xs[-1])))
    return float(best[1]), float(best[0])


Residuals = Callable[[NDArray[np.float64]], ArrayLike]
"""A least-squares problem: the residuals (1-D) at a parameter vector."""


def least_squares(residuals: Residuals, start: ArrayLike, lower: ArrayLike, upper: ArrayLike,
                  *, xtol: float = 1e-9, max_steps: int = 100,
                  step: float = 1e-6) -> tuple[NDArray[np.float64], float]:
    """``(x, sum(r^2))`` minimising ``sum(residuals(x)^2)`` over ``lower <= x <= upper``
    from ``start``: Levenberg-Marquardt with a forward-difference Jacobian (steps ``step``
    times ``max(1, |x_j|)``, taken inwards at an upper bound) and steps clipped to the box;
    it stops when a step moves no parameter by more than ``xtol`` (absolute) or the damping
    finds no lower cost."""
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    x = np.clip(np.asarray(start, float), lower, upper)
    r = np.asarray(residuals(x), float)
    cost = float(r @ r)
    damping = 1e-3
    for _ in range(max_steps):
        jacobian = np.empty((r.size, x.size))
        for j in range(x.size):
            h = step * max(1.0, abs(x[j]))
            h = -h if x[j] + h > upper[j] else h
            moved = x.copy()
            moved[j] += h
            jacobian[:, j] = (np.asarray(residuals(moved), float) - r) / h
        gradient = jacobian.T @ r
        normal = jacobian.T @ jacobian
        scale = np.maximum(np.diag(normal), 1e-300)
        while True:
            delta = np.linalg.solve(normal + damping * np.diag(scale), -gradient)
            trial: NDArray[np.float64] = np.clip(x + delta, lower, upper)
            r_trial = np.asarray(residuals(trial), float)
            cost_trial = float(r_trial @ r_trial)
            if cost_trial < cost:
                damping = max(damping / 3.0, 1e-12)
                break
            damping *= 4.0
            if damping > 1e12:
                return x, cost
        moved_by = float(np.max(np.abs(trial - x)))
        x, r, cost = trial, r_trial, cost_trial
        if moved_by <= xtol:
            break
    return x, cost


def scanned_least_squares(residuals: Residuals, axes: list[ArrayLike] | tuple[ArrayLike, ...],
                          *, xtol: float = 1e-9
                          ) -> tuple[NDArray[np.float64], float, NDArray[np.float64]]:
    """``(x, sum(r^2), scan)``: :func:`least_squares` over the box the ``axes`` span (one
    increasing array of values per parameter), started from the best point of their grid;
    ``scan`` is the cost at every grid point, shaped like the grid (what a caller checks for a
    second valley near the best one's cost)."""
    grid = [np.asarray(axis, float) for axis in axes]
    points = np.stack(np.meshgrid(*grid, indexing="ij"), axis=-1)
    scan = np.empty(points.shape[:-1])
    for index in np.ndindex(scan.shape):
        r = np.asarray(residuals(points[index]), float)
        scan[index] = float(r @ r)
    start = points[np.unravel_index(int(np.argmin(scan)), scan.shape)]
    x, cost = least_squares(residuals, start, [a[0] for a in grid], [a[-1] for a in grid],
                            xtol=xtol)
    return x, cost, scan
