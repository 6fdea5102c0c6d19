"""The candidates' measured costs and noise (lut_baker.auto_tier.candidates)."""

from pathlib import Path

from lut_baker import auto_tier
from lut_baker.auto_tier import SceneDescription

ROOT = Path(__file__).resolve().parents[3]


def test_costs_and_noise_cover_every_candidate():
    for table in (auto_tier.RELATIVE_COST, auto_tier.NOISE_K):
        assert set(table) == set(auto_tier.COST_SKIN_SHARE)
        for by_candidate in table.values():
            assert set(by_candidate) == set(auto_tier.CANDIDATES)
    for coverage, costs in auto_tier.RELATIVE_COST.items():
        assert costs[auto_tier.FULLEST] == 1.0 == max(costs.values()), coverage
        for candidate in auto_tier.CANDIDATES:  # the subsurface is the noisy part
            k = auto_tier.NOISE_K[coverage][candidate]
            assert (k > 0.03) if candidate.subsurface else (k < 0.01), (coverage, candidate)
    # Interpolated by the skin share, held beyond the measured ones.
    dropped = auto_tier.Candidate("LAYERED", subsurface=False)
    film, bare = (auto_tier.relative_cost(dropped, auto_tier.COST_SKIN_SHARE[c])
                  for c in (1.0, 0.0))
    assert bare < auto_tier.relative_cost(dropped, 0.5) < film
    assert auto_tier.relative_cost(dropped, 2.0) == bare


# --------------------------------------------------------------------------------------------
# The decisions
# --------------------------------------------------------------------------------------------
CLOSE_UP = SceneDescription(object_size_mm=60.0, footprint_mm=0.1, samples=128)
DISTANT = SceneDescription(object_size_mm=200.0, footprint_mm=6.25, samples=128)
