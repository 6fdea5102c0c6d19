"""One-dimensional minimisation in plain numpy, so the run-time path inside Blender needs no
scipy (Blender's Python ships numpy only).

Functions
---------
- :func:`golden_minimum` -- coarse scan, golden-section search, then a refinement that makes
  the result a continuous function of the data (:func:`stencil_minimum`).
- :func:`stencil_minimum` -- the point where a function takes equal values a fixed step
  either side: the vertex of the parabola through three points, iterated to its fixed point.
"""

from __future__ import annotations

import numpy as np

__all__ = ["golden_minimum", "stencil_minimum", "REFINE_STEPS", "REFINE_PRECISION"]

REFINE_STEPS = 12
"""Most parabola steps of :func:`stencil_minimum` (it needs 2-4 from a golden-section
bracket)."""
REFINE_PRECISION = 1e-6
""":func:`stencil_minimum` stops when a step is below this fraction of the interval.  Near
its fixed point a step leaves about the square of the distance (times ``f''' / f''``), or a
fraction ``h^2 f'''' / (12 f'')`` of it where that is more (about 1e-7 at the fits' steps):
the point after such a step is within ~1e-12 of the interval of the fixed point, from any
start."""


def stencil_minimum(function, x: float, low: float, high: float, step: float):
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

    def held(point):  # the stencil's middle for a point: inside [low + step, high - step]
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


def golden_minimum(function, low: float, high: float, *, tol: float = 1e-4,
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
    known = {}

    def function_once(x):  # the refinement's first middle point is the search's best
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
