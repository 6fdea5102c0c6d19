"""Where the layer fits start (:mod:`lut_baker.offline.measured.layer_fit`): a multi-start, so
that a fit finds the best of the minima its data allow and reports the others
(:class:`~lut_baker.offline.measured.fit_results.Starts`).

The intensity is linear in ``P_d`` and ``P_s``/``P_t``, so for each ``n`` on a coarse
logarithmic grid they are solved by non-negative least squares at a given eta; the best ``n``
per eta of :data:`ETA_STARTS` (and per tilt of :data:`TILT_STARTS_DEG` when the tilt is fitted)
is one start; with eta held fixed, the best ``n`` in each of :data:`N_GRID_PARTS` parts of the
grid is; the caller's start, if any, is one more.  Without lobe the problem is linear in
``log P_d``: its one start is the solution.  The dipole's starts are the local minima of a
coarse ``(sigma_s, sigma_a)`` grid (at most :data:`DIPOLE_STARTS`).

Functions
---------
- :func:`pair_starts` -- the starts of a reflection or transmission fit (eqs. 2, 4), in the
  problem's conditioned parameters.
- :func:`linear_starts` -- one start per data set at one eta and tilt, from a roughness grid.
- :func:`dipole_starts` -- the starts of a dipole fit (eq. 6).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import nnls

from .fit_solver import TILT, LayerValues, Problem

__all__ = ["N_GRID_PER_DEG", "ETA_STARTS", "N_GRID_PARTS", "TILT_STARTS_DEG",
           "SIGMA_S_GRID_PER_MM", "SIGMA_A_GRID_PER_MM", "DIPOLE_STARTS", "pair_starts",
           "linear_starts", "dipole_starts"]

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


def pair_starts(problem: Problem, lobe: str, eta: float | None, lobe_free: bool,
                tilt: bool) -> list[NDArray[np.float64]]:
    """The starts (conditioned ``x``) of a reflection or transmission fit: per tilt of
    :data:`TILT_STARTS_DEG` (0 alone when the tilt is not fitted), per eta of
    :data:`ETA_STARTS` (``eta`` alone when it is held) and per part of the roughness grid
    (the whole grid when eta is free), :func:`linear_starts`; without lobe one start."""
    etas = (eta,) if eta is not None else ETA_STARTS
    grids = np.array_split(N_GRID_PER_DEG, 1 if len(etas) > 1 else N_GRID_PARTS)
    starts = []
    for tilt_deg in (TILT_STARTS_DEG if tilt else (0.0,)):
        for eta0 in (etas if lobe_free else etas[:1]):
            for grid in (grids if lobe_free else grids[:1]):
                layers = linear_starts(problem, lobe, eta0, tilt_deg, lobe_free, grid)
                starts.append(problem.x_of(layers, {TILT: tilt_deg}))
    return starts


def linear_starts(problem: Problem, lobe: str, eta: float, tilt_deg: float,
                  lobe_free: bool, grid: NDArray[np.float64]) -> list[SimpleNamespace]:
    """One start per set at ``eta`` and ``tilt_deg``: for each ``n`` of ``grid``, ``P_d`` and
    the lobe's P by non-negative least squares on relative residuals; the ``n`` of lowest cost.
    A lobe the least squares drop starts at 1% of the diffuse level at its peak (from 0 the
    optimiser could not grow it).  Without lobe: ``P_d`` by least squares in log (the
    solution: the problem is linear)."""
    nuisance = {TILT: tilt_deg}
    diffuse = problem.predict(LayerValues(channels=(), P_d=1.0, **{lobe: 0.0}, n=1.0, eta=eta),
                              nuisance)
    bases = [problem.predict(LayerValues(channels=(), P_d=0.0, **{lobe: 1.0}, n=n, eta=eta),
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
        best: tuple[float, SimpleNamespace] | None = None
        for n, basis in zip(grid, bases, strict=True):
            p, _ = nnls(np.stack([diffuse, basis], axis=1) * weight[:, None],
                        np.ones_like(weight))
            p = np.clip(p, low, high)
            cost = float(np.sum(np.log((p[0] * diffuse + p[1] * basis) * weight) ** 2))
            if best is None or cost < best[0]:
                floor = 0.01 * p[0] * float(np.max(diffuse) / np.max(basis))
                best = (cost, SimpleNamespace(**{"P_d": p[0], lobe: max(p[1], floor), "n": n,
                                                 "eta": eta}))
        if best is None:
            raise ValueError("the roughness grid of the starts is empty")
        starts.append(best[1])
    return starts


def dipole_starts(problem: Problem) -> list[np.ndarray]:
    """The local minima (no lower neighbour along either axis) of the cost on a logarithmic
    ``(sigma_s, sigma_a)`` grid, lowest first, at most :data:`DIPOLE_STARTS` (with the best
    log-scale when it is free)."""
    grid: dict[tuple[int, int], NDArray[np.float64]] = {}
    costs = np.empty((SIGMA_S_GRID_PER_MM.size, SIGMA_A_GRID_PER_MM.size))
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
