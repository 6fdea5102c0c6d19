"""The Auto tier (lut_baker.auto_tier), without Blender.

The model's parts against independent computations (the pinhole footprint, the exact
reference's subsurface spread, the tables' gloss share) and its decisions (close-up against
distant, EEVEE, the gloss rule, the tolerance); it runs without scipy, as inside Blender.
tests/makeup_skin_addon/test_scene_fit.py renders its choices and runs Fit to Scene.
"""

import math
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from lut_baker import auto_tier
from lut_baker.auto_tier import SceneDescription
from lut_baker.model import presets
from lut_baker.numerics import geometry
from lut_baker.offline.validation import compare, reference

ROOT = Path(__file__).resolve().parents[2]



# --------------------------------------------------------------------------------------------
# The model's parts
# --------------------------------------------------------------------------------------------
def test_footprint_orthographic_and_pinhole():
    assert auto_tier.pixel_footprint_mm("ORTHO", 500, ortho_scale_mm=250.0) == 0.5
    # A 36 mm sensor behind a 50 mm lens sees 720 mm at 1 m; over 1000 px that is 0.72 mm.
    value = auto_tier.pixel_footprint_mm("PERSP", 1000, distance_mm=1000.0, sensor_mm=36.0,
                                           focal_mm=50.0)
    assert value == pytest.approx(0.72)
    with pytest.raises(ValueError):
        auto_tier.pixel_footprint_mm("ORTHO", 500)
    with pytest.raises(ValueError):
        auto_tier.pixel_footprint_mm("PANORAMA", 500, distance_mm=1.0)


def test_mean_radius_of_a_burley_profile():
    """Cycles' Burley profile (shape length d, cut at a = 16 d, renormalised) has the mean
    distance ``[I(d) + I(3d)] / (4 d cdf)`` with ``I(s) = s^2 (1 - e^(-a/s) (1 + a/s))``
    (2.44 d; 2.5 d uncut)."""
    from lut_baker.closures.cycles import BURLEY_MFP_SCALE, burley_profile

    radius = 6.0
    s = radius * BURLEY_MFP_SCALE
    a = 16.0 * s

    def moment(length):
        return length**2 * (1.0 - math.exp(-a / length) * (1.0 + a / length))

    cdf = 1.0 - 0.25 * math.exp(-16.0) - 0.75 * math.exp(-16.0 / 3.0)
    expected = (moment(s) + moment(3.0 * s)) / (4.0 * s * cdf)
    d = np.concatenate([[0.0], np.geomspace(1e-6, a * (1 - 1e-9), 20000)])
    mean = auto_tier.profile_mean_radius_mm(d, burley_profile(d, radius))
    assert mean == pytest.approx(expected, rel=1e-3)


def test_blur_kernel_is_normalised_and_tends_to_a_point(paper_tables):
    wide = auto_tier.blur_kernel(0.25, paper_tables.radius_mm, paper_tables.profile)
    assert np.allclose(wide.sum(axis=(0, 1)), 1.0) and wide.min() >= 0.0
    h = wide.shape[0] // 2
    assert wide[h, h, 0] < 0.5  # the spread leaves the centre cell
    point = auto_tier.blur_kernel(100.0, paper_tables.radius_mm, paper_tables.profile)
    assert point[point.shape[0] // 2, point.shape[1] // 2, 0] > 0.99


@pytest.mark.slow
def test_omission_error_follows_the_exact_reference(paper_tables):
    """The pixel-footprint blur model against lut_baker.offline.validation.reference's own spread
    (spread minus local skin light, over the sphere's total): within a factor 2 on a 6 mm sphere at
    24 px (measured 0.0157 against 0.0184), and it falls as the pixels grow."""
    skin = presets.made_up_skin("paper_natural", "paper_bioplate")
    radius, size = 3.0, 24
    _, normals, mask = reference.sphere_points(size, radius)
    points = normals[mask]
    light = geometry.light_direction(45.0)
    local = reference.local_diffuse(points, light, skin)
    spread = reference.spread_diffuse(points, light, skin, radius_mm=radius,
                                      samples=reference.default_samples(skin, radius))
    total = compare.reference_image(skin, tables=paper_tables, resolution=size,
                                    radius_mm=radius, spread=False)[mask]
    exact = np.sqrt(np.mean((spread - local) ** 2)) / np.sqrt(np.mean(total**2))
    _, share = auto_tier.gloss_and_skin_shares(paper_tables, 45.0)
    predicted = auto_tier.subsurface_omission_error(2 * radius / size, 2 * radius, 45.0,
                                                      paper_tables.radius_mm,
                                                      paper_tables.profile, share)
    assert 0.5 * exact < predicted < 2.0 * exact
    coarse = [auto_tier.subsurface_omission_error(footprint, 400.0, 45.0,
                                                    paper_tables.radius_mm,
                                                    paper_tables.profile, share)
              for footprint in (0.5, 4.0, 40.0)]
    assert coarse[0] > coarse[1] > coarse[2] >= 0.0


def test_shares_add_up(paper_tables):
    """Gloss and skin light are parts of the image: each share is in (0, 1); bare skin is
    nearly all skin light, full film mostly not (the film hides the skin)."""
    gloss, skin = auto_tier.gloss_and_skin_shares(paper_tables, 45.0, 1.0, 0.0)
    bare_gloss, bare_skin = auto_tier.gloss_and_skin_shares(paper_tables, 45.0, 0.0, 0.0)
    assert 0.0 < gloss < 1.0 and 0.0 < skin < 0.5 and bare_skin > 0.9 > bare_gloss
    _, absorbed = auto_tier.gloss_and_skin_shares(paper_tables, 45.0, 1.0, 1.0)
    assert absorbed == 0.0


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


def test_close_up_and_distant_get_different_tiers():
    close, far = auto_tier.choose(CLOSE_UP), auto_tier.choose(DISTANT)
    assert close.candidate != far.candidate
    assert close.candidate.subsurface and not far.candidate.subsurface
    assert far.chosen.cost < close.chosen.cost
    assert far.chosen.error <= far.best_error + far.tolerance
    traits = auto_tier.paper_traits()
    assert auto_tier.needs_subsurface(CLOSE_UP, traits)
    assert not auto_tier.needs_subsurface(DISTANT, traits)


def test_half_a_pixel_is_the_threshold():
    traits = auto_tier.paper_traits()
    radius = traits.mean_radius_mm
    for ratio, needed in ((0.45, False), (0.55, True)):
        scene = SceneDescription(object_size_mm=100.0, footprint_mm=radius / ratio)
        assert auto_tier.needs_subsurface(scene, traits) == needed
        assert auto_tier.choose(scene).candidate.subsurface == needed
    # The artist's Subsurface Scale widens the spread: 4x makes the distant scene need it.
    assert auto_tier.needs_subsurface(DISTANT, traits.scaled(40.0))
    assert not auto_tier.choose(CLOSE_UP, traits.scaled(0.0)).candidate.subsurface


def test_each_engine_gets_the_tier_made_for_it():
    """EEVEE: the EEVEE tier only (whatever its predicted error against the others'); Cycles:
    never the EEVEE tier."""
    for scene in (CLOSE_UP, DISTANT):
        eevee = SceneDescription(**{**scene.__dict__, "engine": "EEVEE"})
        choice = auto_tier.choose(eevee)
        assert auto_tier.ENGINE_TIERS["EEVEE"] == ("EEVEE",)
        assert {p.candidate.tier for p in choice.predictions} == {"EEVEE"}
        assert choice.chosen.noise == 0.0
        assert "EEVEE" in choice.reasons[-1]
        cycles = auto_tier.choose(scene)
        assert "EEVEE" not in {p.candidate.tier for p in cycles.predictions}
    assert {c.tier for c in auto_tier.EEVEE_CANDIDATES} == {"EEVEE"}
    assert len(set(auto_tier.EEVEE_CANDIDATES)) == 4


def _traits(gloss_share):
    paper = auto_tier.paper_traits()
    return auto_tier.MaterialTraits(
        tier_errors=dict(paper.tier_errors), radius_mm=paper.radius_mm, profile=paper.profile,
        profile_mismatch=paper.profile_mismatch, skin_share=dict(paper.skin_share),
        gloss_share={angle: gloss_share for angle in paper.gloss_share})


def test_gloss_below_the_noise_needs_no_gloss_lobe():
    """A gloss of 1% of the image, under the noise of the fullest tier (6% at 16 samples, 3%
    at 64), is left out far away and close up (subsurface kept); the paper's 19% never is.
    An artist's Gloss of 0 leaves no candidate with gloss; one of 0.5 counts half of it as
    missing."""
    far = SceneDescription(object_size_mm=200.0, footprint_mm=6.25, samples=16)
    close = SceneDescription(object_size_mm=60.0, footprint_mm=0.1, samples=64)
    for scene in (far, close):
        faint = auto_tier.choose(scene, _traits(0.01))
        assert not faint.candidate.gloss
        assert faint.candidate.subsurface == (scene is close)
        assert faint.chosen.cost < auto_tier.choose(
            scene, _traits(0.01), candidates=[c for c in auto_tier.CANDIDATES
                                              if c.gloss]).chosen.cost
        strong = auto_tier.choose(scene)
        assert strong.candidate.gloss and "kept" in strong.reasons[2]
        assert all(p.gloss > 0.15 for p in strong.predictions if not p.candidate.gloss)
    assert "left out" in auto_tier.choose(far, _traits(0.01)).reasons[2]
    matte = auto_tier.choose(far, auto_tier.paper_traits().scaled(1.0, 0.0))
    assert all(not p.candidate.gloss for p in matte.predictions)
    half = auto_tier.predict(auto_tier.FULLEST, far, auto_tier.paper_traits().scaled(
        1.0, 0.5))
    assert half.gloss == pytest.approx(0.5 * auto_tier.PAPER_GLOSS_OMISSION["LAYERED"][45.0])


def test_gloss_omission_is_the_tiers_gloss(paper_tables, paper_fit, matte):
    """What Gloss 0 changes in a sphere's image, from the tiers' replicas: for the paper's
    film within 15% of the tables' gloss share (the fits reproduce the gloss lobes) and the
    stored constants; for a film of index 1.01 under 1.5% at every light angle."""
    from lut_baker.closures import tiers

    omissions = auto_tier.gloss_omissions(paper_tables, paper_fit, lights_deg=(0.0, 45.0))
    for tier, by_light in omissions.items():
        for light, value in by_light.items():
            share, _ = auto_tier.gloss_and_skin_shares(paper_tables, light)
            assert value == pytest.approx(share, rel=0.15), (tier, light)
            assert value == pytest.approx(auto_tier.PAPER_GLOSS_OMISSION[tier][light],
                                          rel=0.05), (tier, light)  # default against preview
    _, tables, fit = matte
    traits = auto_tier.traits_from_tables(tables, fit)
    for tier in tiers.TIERS:
        assert max(traits.gloss_omission[tier].values()) < 0.015, tier
        assert traits.gloss_error(tier, 45.0) == traits.gloss_omission[tier][45.0]


def test_tolerance_trades_error_for_cost():
    strict = auto_tier.choose(CLOSE_UP, tolerance=0.0)
    loose = auto_tier.choose(CLOSE_UP, tolerance=1.0)
    assert strict.chosen.error == strict.best_error
    assert loose.chosen.cost == min(p.cost for p in loose.predictions)
    assert loose.chosen.cost < strict.chosen.cost
    with pytest.raises(ValueError):
        auto_tier.choose(CLOSE_UP, tolerance=-0.1)


@pytest.mark.slow  # a fresh Python bakes and fits (~1.3 s)
def test_runs_without_scipy():
    """Fit to Scene runs inside Blender, which has no scipy."""
    script = textwrap.dedent("""
        import sys
        sys.modules["scipy"] = None
        from lut_baker import bake
        from lut_baker.closures import fitting
        from lut_baker.model import presets
        from lut_baker import auto_tier
        tables = bake.bake(presets.made_up_skin(), "preview")
        traits = auto_tier.traits_from_tables(tables, fitting.fit_closures(tables))
        scene = auto_tier.SceneDescription(object_size_mm=60.0, footprint_mm=0.1)
        print("ok", auto_tier.choose(scene, traits).candidate.name)
    """)
    done = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("ok")
