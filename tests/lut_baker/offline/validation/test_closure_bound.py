"""The lower bound of view-weighted closures (lut_baker.offline.validation.closure_bound)."""

import numpy as np
import pytest

from lut_baker.closures import tiers
from lut_baker.offline.validation import compare
from lut_baker.offline.validation.closure_bound import bound_reflection, closure_bound


@pytest.fixture(scope="module")
def bounds(paper_tables):
    w, a = paper_tables.coverage_and_absorption()
    return {name: closure_bound(paper_tables, w, a, name) for name in ("EEVEE", "CYCLES")}


def _local_error(reflection, tables, light_deg):
    w, a = tables.coverage_and_absorption()
    exact = compare.local_image(lambda wi, wo: tables.made_up_reflection(wi, wo, w, a), 32,
                                light_deg)
    return compare.relative_rms(compare.local_image(reflection, 32, light_deg), exact)


def test_weights_are_non_negative_and_fit(bounds):
    for bound in bounds.values():
        assert np.all(bound.weights >= 0.0)
        assert 0.0 < bound.error < 0.2


@pytest.mark.parametrize("light_deg", [0.0, 45.0, 75.0])
def test_no_tier_beats_its_renderers_bound(bounds, paper_tables, paper_fit, light_deg):
    """The tiers are sums of their renderer's closures weighted by the view: none comes closer
    to the exact local image than the best such sum (the paper film at full coverage)."""
    w, a = paper_tables.coverage_and_absorption()
    for renderer, tier in (("EEVEE", "EEVEE"), ("CYCLES", "LAYERED")):
        replica = tiers.TIER_REPLICAS[tier]
        tier_error = _local_error(
            lambda wi, wo, r=replica: r(paper_fit, paper_tables, w, a, directions=(wi, wo)),
            paper_tables, light_deg)
        bound_error = _local_error(bound_reflection(bounds[renderer]), paper_tables, light_deg)
        assert bound_error <= tier_error * 1.02, (renderer, bound_error, tier_error)
