"""Cycles' subsurface blur against the replicas of lut_baker.closures.cycles that the radius fit
relies on (one render each, 256 x 8 px at 64 samples, the shadow-edge scene of
tests/support/subsurface_edge.py, which tools/calibrate_subsurface.py measures with)."""

import numpy as np
import pytest
from support import subsurface_edge as calibration

pytestmark = pytest.mark.slow  # Cycles renders


@pytest.mark.parametrize(("method", "albedo", "bound"), [
    ("BURLEY", 0.5, 0.009),  # exact replica: Monte Carlo noise only (0.5% at 64 samples)
    ("RANDOM_WALK_SKIN", 0.8, 0.011),  # measured Burley-shaped replica (0.7%)
])
def test_rendered_edge_matches_the_replica(bpy_factory, tmp_path, method, albedo, bound):
    x, measured = calibration.render_edge(method, albedo, samples=64, folder=tmp_path)
    near = np.abs(x) < 3 * calibration.RADIUS_M * 1e3
    assert np.all(np.isfinite(measured))

    def rms(scale):
        replica = calibration.replica_edge(x, method, albedo, scale)
        return float(np.sqrt(np.mean((measured - replica)[near] ** 2)))

    assert rms(1.0) < bound
    # The check can fail: a radius off by a factor 2 either way errs 2.3-3.6%.
    assert rms(2.0) > 2 * bound and rms(0.5) > 2 * bound
