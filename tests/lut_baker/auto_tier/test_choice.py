"""The Auto tier's choice (lut_baker.auto_tier.choice): close-up against distant, half a
pixel, each engine's tier, the gloss rule, the tolerance; it runs without scipy, as inside
Blender.  tests/makeup_skin_addon/test_tier_choice.py renders its choices and runs Fit to Scene."""

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from lut_baker import auto_tier
from lut_baker.auto_tier import SceneDescription

ROOT = Path(__file__).resolve().parents[3]

CLOSE_UP = SceneDescription(object_size_mm=60.0, footprint_mm=0.1, samples=128)
DISTANT = SceneDescription(object_size_mm=200.0, footprint_mm=6.25, samples=128)


def _traits(gloss_share):
    paper = auto_tier.paper_traits()
    return auto_tier.MaterialTraits(
        tier_errors=dict(paper.tier_errors), radius_mm=paper.radius_mm, profile=paper.profile,
        profile_mismatch=paper.profile_mismatch, skin_share=dict(paper.skin_share),
        gloss_share={angle: gloss_share for angle in paper.gloss_share})


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
