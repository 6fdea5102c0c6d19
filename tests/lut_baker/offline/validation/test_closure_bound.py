"""The lower bound of view-weighted closures (lut_baker.offline.validation.closure_bound)."""

import numpy as np
import pytest

from lut_baker.closures import tiers
from lut_baker.closures.view_grid import lobe_widths_deg, view_grid
from lut_baker.offline.validation import compare
from lut_baker.offline.validation.closure_bound import (
    BOUND_VIEWS,
    bound_reflection,
    closure_bound,
)


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


def test_no_tier_beats_its_renderers_bound(bounds, paper_tables, paper_fit):
    """The tiers are sums of their renderer's closures weighted by the view: on the measure the
    bound minimises (the grid's, over all lights) none comes closer to the model than the best
    such sum (the paper film at full coverage; 2% for roughnesses between the dictionary's)."""
    w, a = paper_tables.coverage_and_absorption()
    grid = view_grid(min(lobe_widths_deg(paper_tables).values()), BOUND_VIEWS)
    target = paper_tables.made_up_reflection(*grid.directions, w, a)
    for renderer, tier in (("EEVEE", "EEVEE"), ("CYCLES", "LAYERED")):
        replica = tiers.tier_replica(paper_fit, paper_tables, tier, w, a,
                                     directions=grid.directions)
        assert bounds[renderer].error <= 1.02 * grid.error(replica, target), renderer


def test_the_bound_renders_as_fitted(bounds, paper_tables):
    """Its BRDF, rendered into the sphere's local image, stays within the bound's grid error
    of the exact image (the grid weights every light, the image one)."""
    for bound in bounds.values():
        for light_deg in (0.0, 45.0, 75.0):
            assert _local_error(bound_reflection(bound), paper_tables, light_deg) < bound.error
