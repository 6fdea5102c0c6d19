"""Where the layer fits start (lut_baker.offline.measured.fit_starts): on exact data the linear
start at the true eta is the truth itself when its roughness lies on the grid, one start comes
per eta, tilt and part of the grid, and the dipole's starts are its grid's minima, lowest
first."""

import numpy as np
import pytest

from lut_baker.model.layers import Dipole, ReflectionLayer
from lut_baker.offline.measured import fit_solver, fit_starts
from lut_baker.offline.measured import measurements as M

TRUTH = ReflectionLayer(P_d=0.2, P_s=3.0, n=float(fit_starts.N_GRID_PER_DEG[12]), eta=1.5)
"""A film whose roughness lies on the starts' grid."""


def _reflection_problem(data, tilt=False):
    model = M.ReflectionCounts(data)
    measured = data.intensity_counts[:, None]
    free = ("P_d", "P_s", "n", "eta")
    return fit_solver.Problem(
        "reflection", ReflectionLayer, free, {},
        lambda values, nuisance: model(values, nuisance.get(fit_solver.TILT, 0.0)), measured,
        (fit_solver.parameter_bounds(free, measured[:, 0]),),
        (fit_solver.TILT,) if tilt else ())


def test_the_linear_start_at_the_true_eta_is_the_truth_on_exact_data():
    problem = _reflection_problem(M.synthesize_reflection(TRUTH))
    (start,) = fit_starts.linear_starts(problem, "P_s", 1.5, 0.0, True,
                                        fit_starts.N_GRID_PER_DEG)
    assert start.n == TRUTH.n and start.eta == 1.5
    assert start.P_d == pytest.approx(0.2, rel=1e-9)
    assert start.P_s == pytest.approx(3.0, rel=1e-9)


def test_without_lobe_the_start_is_the_solution():
    matte = ReflectionLayer(P_d=0.3, P_s=0.0, n=1.0, eta=1.5)
    problem = _reflection_problem(M.synthesize_reflection(matte))
    (start,) = fit_starts.linear_starts(problem, "P_s", 1.5, 0.0, False, np.array([1.0]))
    assert vars(start) == {"P_d": pytest.approx(0.3, rel=1e-12)}


@pytest.mark.parametrize(("eta", "tilt", "count"), [
    (None, False, len(fit_starts.ETA_STARTS)),
    (1.5, False, fit_starts.N_GRID_PARTS),
    (None, True, len(fit_starts.ETA_STARTS) * len(fit_starts.TILT_STARTS_DEG)),
])
def test_one_start_per_eta_tilt_and_part_of_the_grid(eta, tilt, count):
    problem = _reflection_problem(M.synthesize_reflection(TRUTH), tilt)
    starts = fit_starts.pair_starts(problem, "P_s", eta, True, tilt)
    assert len(starts) == count
    low, high = problem.x_bounds()
    assert all(np.all((x > low) & (x < high)) for x in starts)


def test_the_dipole_starts_are_grid_minima_lowest_first():
    truth = Dipole(sigma_s=2.0, sigma_a=0.03, g=0.0, eta=1.26)
    data = M.synthesize_profile(truth)
    free = ("sigma_s", "sigma_a")
    problem = fit_solver.Problem(
        "dipole", Dipole, free, {"g": 0.0, "eta": 1.26},
        lambda values, nuisance: M.profile_ratio(data.distance_mm, values), data.ratio[:, None],
        (fit_solver.parameter_bounds(free, data.ratio),))
    starts = fit_starts.dipole_starts(problem)
    assert 1 <= len(starts) <= fit_starts.DIPOLE_STARTS
    costs = [float(np.sum(problem.residuals(x) ** 2)) for x in starts]
    assert costs == sorted(costs)
    best = problem.layer(starts[0], 0)  # within a grid step of the truth
    for name, grid, value in (("sigma_s", fit_starts.SIGMA_S_GRID_PER_MM, 2.0),
                              ("sigma_a", fit_starts.SIGMA_A_GRID_PER_MM, 0.03)):
        step = np.log(grid[1] / grid[0])
        assert abs(np.log(float(getattr(best, name)) / value)) <= step * (1 + 1e-9), name
