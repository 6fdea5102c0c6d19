"""The layer fits' solver (lut_baker.offline.measured.fit_solver): the conditioned parameters
map a layer to itself, the two Jacobians agree, exact data solved from anywhere near give the
truth with nothing to warn about, and a problem with fewer samples than parameters is refused."""

import numpy as np
import pytest

from lut_baker.model.layers import ReflectionLayer
from lut_baker.offline.measured import fit_results, fit_solver
from lut_baker.offline.measured import measurements as M

TRUTH = ReflectionLayer(P_d=0.2, P_s=3.0, n=0.05, eta=1.4)


def _problem(data):
    model = M.ReflectionCounts(data)
    measured = data.intensity_counts[:, None]
    free = ("P_d", "P_s", "n", "eta")
    return fit_solver.Problem("reflection", ReflectionLayer, free, {},
                              lambda values, nuisance: model(values), measured,
                              (fit_solver.parameter_bounds(free, measured[:, 0]),))


def test_conditioned_parameters_map_a_layer_to_itself():
    problem = _problem(M.synthesize_reflection(TRUTH))
    x = problem.x_of([TRUTH])
    assert x[3] == pytest.approx(np.log(0.4))  # log(eta - 1)
    layer = problem.layer(x, 0)
    for name in problem.free:
        assert float(getattr(layer, name)) == pytest.approx(float(getattr(TRUTH, name)),
                                                            rel=1e-12)
    np.testing.assert_allclose(problem.residuals(x), 0.0, atol=1e-12)


def test_forward_and_central_jacobians_agree():
    problem = _problem(M.synthesize_reflection(TRUTH, noise=0.02, rng=1))
    x = problem.x_of([TRUTH.scaled(P_d=1.3, n=0.8)])
    forward, central = problem.jacobian(x), problem.jacobian(x, central=True)
    scale = np.max(np.abs(central))
    np.testing.assert_allclose(forward, central, atol=1e-6 * scale)


def test_exact_data_solve_to_the_truth_without_warnings():
    problem = _problem(M.synthesize_reflection(TRUTH))
    start = problem.x_of([TRUTH.scaled(P_d=1.5, P_s=0.7, n=1.2)])
    joint = fit_solver.solve(problem, [start], fit_results.Limits())
    (fit,) = joint.fits
    assert isinstance(fit.params, ReflectionLayer) and fit.ok and joint.warnings == []
    for name in problem.free:
        assert float(getattr(fit.params, name)) == pytest.approx(float(getattr(TRUTH, name)),
                                                                 rel=1e-6)
    assert fit.starts.count == fit.starts.reached == 1


def test_too_few_samples_are_refused():
    data = M.synthesize_reflection(TRUTH)
    few = M.ReflectionData(data.psi_deg[:4], data.alpha_deg[:4], data.intensity_counts[:4])
    with pytest.raises(ValueError, match="at least 5 samples, got 4"):
        fit_solver.check_size(_problem(few), 4)
    assert fit_solver.lobe_name(TRUTH) == "P_s"
