"""One-dimensional minimisation in plain numpy, so the run-time path inside Blender needs no
scipy (Blender's Python ships numpy only).

Functions
---------
- :func:`golden_minimum` -- coarse scan, then golden-section search.
- :func:`brent_minimum` -- coarse scan, then Brent's method (parabolic steps, golden-section
  fallback) to a tight tolerance: the minimum of a smooth function, converged so far that the
  result is a continuous function of the data (a change of ``1e-9`` in the function moves it
  by about as much, not by the tolerance of a loose search).
- :func:`least_squares` -- bounded Levenberg-Marquardt on a small parameter vector, from a
  start, to a tight tolerance (a smooth fit converges in a few steps where nested 1-D searches
  take hundreds of evaluations).
"""

from __future__ import annotations

import numpy as np

__all__ = ["golden_minimum", "brent_minimum", "BRENT_XTOL", "least_squares"]

BRENT_XTOL = 1e-9
"""Default absolute tolerance of :func:`brent_minimum`, in the units of ``x``."""


def golden_minimum(function, low: float, high: float, *, tol: float = 1e-4,
                   coarse: int = 9) -> tuple[float, float]:
    """``(x, f(x))`` minimising a 1-D ``function`` on ``[low, high]``: the best of ``coarse``
    evenly spaced samples, then golden-section search in the bracket around it."""
    xs = np.linspace(low, high, coarse)
    values = [function(x) for x in xs]
    k = int(np.argmin(values))
    a, b = xs[max(k - 1, 0)], xs[min(k + 1, coarse - 1)]
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = function(c), function(d)
    while b - a > tol * max(1.0, abs(a) + abs(b)):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - ratio * (b - a)
            fc = function(c)
        else:
            a, c, fc = c, d, fd
            d = a + ratio * (b - a)
            fd = function(d)
    best = min([(values[k], xs[k]), (fc, c), (fd, d)])
    return float(best[1]), float(best[0])


def brent_minimum(function, low: float, high: float, *, xtol: float = BRENT_XTOL,
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


def least_squares(residuals, start, lower, upper, *, xtol: float = 1e-9,
                  max_steps: int = 100, step: float = 1e-6) -> tuple[np.ndarray, float]:
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
            trial = np.clip(x + delta, lower, upper)
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
