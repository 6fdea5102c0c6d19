"""The made-up skin's reflection and directional albedo (lut_baker.evaluate.made_up,
docs/model.md §4): the white furnace test (paths 1 + 3 reflect at most what arrives, at
every incidence), coverage and absorption."""

import math

import numpy as np
import pytest
from support import reference_impl as ref

from lut_baker.evaluate import made_up
from lut_baker.model import albedo, microfacet, presets
from lut_baker.numerics.geometry import direction

THETA_DEG = np.arange(0.0, 90.0)  # 0, 1, ..., 89 degrees
ABSORPTIONS = {"0": 0.0, "0.5": 0.5, "1": 1.0}
COVERAGES = (0.0, 0.25, 0.5, 1.0)


# --- the white furnace test ----------------------------------------------------------------
def _albedo(foundation, skin, coverage, absorption=None):
    return made_up.directional_albedo(
        THETA_DEG, presets.made_up_skin(foundation, skin, coverage=coverage,
                                        absorption=absorption))


@pytest.mark.slow
@pytest.mark.parametrize("skin", sorted(presets.SKINS))
def test_white_furnace(skin):
    """directional_albedo <= 1 at 0..89 degrees, every channel, every foundation on ``skin``
    (the products derived from measured thick layers included, with their own gloss: docs/model.md
    §4), each foundation's own shade and absorption 0, 0.5 and 1, coverage 0, 0.25, 0.5, 1.

    The albedo is affine in coverage (checked by test_albedo_linear_in_coverage), so coverages
    0.25 and 0.5 are checked as mixes of the evaluated 0 and 1."""
    bare = _albedo("paper_natural", skin, 0.0)
    surface, _ = presets.skin_layers(skin)
    assert np.all(bare <= 1.0)
    np.testing.assert_allclose(bare, np.broadcast_to(np.reshape(
        albedo.reflection_albedo(THETA_DEG, surface), (90, -1)), bare.shape), rtol=1e-12)
    worst = {"bare": float(bare.max())}
    # Each foundation with its own shade; an explicit absorption replaces the shade, so with
    # one every hand-picked foundation is the same film: evaluated once (as paper_natural). The
    # measured products' films differ from it only in their gloss, whose directional albedo is
    # below the paper film's at every incidence (at most 0.04 against 0.15-0.17).
    cases = [(f, "own", None) for f in presets.FOUNDATIONS]
    cases += [("any", label, a) for label, a in ABSORPTIONS.items()]
    for foundation, label, absorption in cases:
        name = "paper_natural" if foundation == "any" else foundation
        full = _albedo(name, skin, 1.0, absorption)
        for coverage in COVERAGES:
            mixed = (1 - coverage) * bare + coverage * full
            assert np.all(np.isfinite(mixed)) and np.all(mixed >= 0)
            assert np.all(mixed <= 1.0), (foundation, label, coverage, mixed.max())
        worst[f"{foundation}/{label}"] = float(full.max())
    best = max(worst, key=worst.get)
    print(f"{skin}: max albedo {worst[best]:.4f} ({best}); " + ", ".join(
        f"{k} {v:.4f}" for k, v in worst.items()))


@pytest.mark.slow
def test_albedo_linear_in_coverage():
    ends = [_albedo("medium_beige", "jensen_skin1", c) for c in (0.0, 1.0)]
    for coverage in (0.25, 0.5):
        np.testing.assert_allclose(_albedo("medium_beige", "jensen_skin1", coverage),
                                   (1 - coverage) * ends[0] + coverage * ends[1], rtol=1e-12)


@pytest.mark.slow
def test_furnace_at_89_degrees_direct():
    """Coverage 0.25 and 0.5 evaluated directly at grazing incidence for the paper pair."""
    for coverage in COVERAGES:
        for absorption in ABSORPTIONS.values():
            value = made_up.directional_albedo(
                89.0, presets.made_up_skin(coverage=coverage, absorption=absorption))
            assert value.shape == (3,) and np.all(value <= 1.0) and np.all(value > 0.0)


# --- coverage and absorption in the BRDF ---------------------------------------------------
def _pairs(count, seed):
    rng = np.random.default_rng(seed)
    theta = np.radians(rng.uniform(0, 89, (2, count)))
    return (direction(theta[0], rng.uniform(0, 2 * math.pi, count)),
            direction(theta[1], rng.uniform(0, 2 * math.pi, count)))


def test_coverage_zero_is_bare_skin_exactly():
    wi, wo = _pairs(10, 1)
    for name in presets.SKINS:
        skin = presets.made_up_skin("deep_mocha", name, coverage=0.0)
        bare = np.reshape(microfacet.ts_reflection(wi, wo, skin.skin_reflection), (10, -1))
        np.testing.assert_array_equal(made_up.made_up_reflection(wi, wo, skin),
                                      np.broadcast_to(bare, (10, 3)))


@pytest.mark.slow
def test_made_up_reflection_linear_in_coverage():
    wi, wo = _pairs(30, 2)
    skin = presets.made_up_skin("light_ivory", "jensen_skin2")
    ends = [made_up.made_up_reflection(wi, wo, skin.replace(coverage=c)) for c in (0.0, 1.0)]
    for coverage in (0.1, 0.25, 0.5, 0.9):
        np.testing.assert_allclose(
            made_up.made_up_reflection(wi, wo, skin.replace(coverage=coverage)),
            (1 - coverage) * ends[0] + coverage * ends[1], rtol=1e-12)


def test_full_absorption_leaves_gloss_and_bare_skin():
    """A = 1 absorbs the film's pigment: its diffuse reflection and everything it transmits
    (path 3).  What remains is the film's gloss, plus bare skin where it is uncovered."""
    wi, wo = _pairs(10, 3)
    for coverage in (0.0, 0.4, 1.0):
        skin = presets.made_up_skin("paper_natural", "jensen_skin1", coverage=coverage,
                                    absorption=1.0)
        film = presets.paper().film
        gloss = np.array([ref.ts_reflection(a, b, 0.0, float(film.P_s),
                                                         float(film.n), float(film.eta))
                                       for a, b in zip(wi, wo, strict=True)])
        bare = microfacet.ts_reflection(wi, wo, skin.skin_reflection)
        expected = (1 - coverage) * bare + coverage * gloss[:, None]
        np.testing.assert_allclose(made_up.made_up_reflection(wi, wo, skin), expected,
                                   rtol=1e-10)
        assert np.all(gloss > 0)


def test_absorption_lowers_albedo_per_channel():
    wi, wo = _pairs(10, 4)
    shade = presets.made_up_skin("deep_mocha")  # absorption rises from red to blue
    clear = presets.made_up_skin("paper_natural")
    shaded = made_up.made_up_reflection(wi, wo, shade)
    assert np.all(shaded < made_up.made_up_reflection(wi, wo, clear))
    assert np.all(shaded[:, 0] > shaded[:, 1]) and np.all(shaded[:, 1] > shaded[:, 2])


# --- the foundations derived from measured thick layers (docs/model.md §4) ------------------
# (their white furnace test is test_white_furnace above, which takes every foundation)
@pytest.mark.parametrize("foundation", [  # the dewy 105 in the fast tier (~0.8 s each)
    "clarins_105", *(pytest.param(f, marks=pytest.mark.slow)
                     for f in ("clarins_103", "clarins_108", "clarins_112"))])
def test_measured_foundations_coverage_is_continuous(foundation):
    """Coverage 0 is bare skin exactly, a small coverage stays close to it, and the BRDF is
    linear in coverage between the ends (docs/model.md §4, "Coverage")."""
    wi, wo = _pairs(12, 5)
    skin = presets.made_up_skin(foundation, "jensen_skin1")
    bare = np.reshape(microfacet.ts_reflection(wi, wo, skin.skin_reflection), (12, -1))
    ends = [made_up.made_up_reflection(wi, wo, skin.replace(coverage=c)) for c in (0.0, 1.0)]
    np.testing.assert_array_equal(ends[0], np.broadcast_to(bare, (12, 3)))
    small = made_up.made_up_reflection(wi, wo, skin.replace(coverage=1e-6))
    np.testing.assert_allclose(small, ends[0], rtol=1e-4)
    for coverage in (1e-6, 0.3, 0.7):
        value = small if coverage == 1e-6 else made_up.made_up_reflection(
            wi, wo, skin.replace(coverage=coverage))  # each evaluation ~0.25 s: once each
        np.testing.assert_allclose(value, (1 - coverage) * ends[0] + coverage * ends[1],
                                   rtol=1e-12, atol=1e-15)


def test_a_matte_product_has_no_gloss_and_a_dewy_one_does():
    """Full absorption leaves only the film's gloss (docs/model.md §4): none for the matte
    103 (P_s = 0), the product's lobe for the dewy 105."""
    wi, wo = _pairs(8, 6)
    matte = presets.made_up_skin("clarins_103", absorption=1.0)
    np.testing.assert_array_equal(made_up.made_up_reflection(wi, wo, matte), 0.0)
    dewy = presets.made_up_skin("clarins_105", absorption=1.0)
    film = presets.foundation_film("clarins_105")
    expected = microfacet.ts_reflection(wi, wo, film.scaled(P_d=0.0))
    np.testing.assert_allclose(made_up.made_up_reflection(wi, wo, dewy),
                               np.broadcast_to(expected[:, None], (8, 3)), rtol=1e-12)
