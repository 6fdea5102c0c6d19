"""Numerical building blocks with no physics in them: quadrature rules, directions and their
geometry, one-dimensional optimisation, a least-recently-used cache.

The type the formulas of the runtime take is written here once: :data:`Real`, a float or a
float array (numpy broadcasts the two alike; arrays as ``numpy.typing.NDArray[np.float64]``,
inputs a function converts first as ``numpy.typing.ArrayLike``)."""

import numpy as np
from numpy.typing import NDArray

__all__ = ["Real"]

Real = float | NDArray[np.float64]
"""A float or a float array of any shape: what a formula over cosines, angles or layer
parameters takes, broadcasting by numpy's rules."""
