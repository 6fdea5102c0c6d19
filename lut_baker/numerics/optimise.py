"""One-dimensional minimisation in plain numpy, so the run-time path inside Blender needs no
scipy (Blender's Python ships numpy only).

Functions
---------
- :func:`golden_minimum` -- coarse scan, then golden-section search.
"""

from __future__ import annotations

import numpy as np

__all__ = ["golden_minimum"]


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
