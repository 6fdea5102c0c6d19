"""What the Auto tier needs of a material (lut_baker.auto_tier.material): the profile's mean
radius, the shares of a sphere's image, the gloss each tier leaves out."""

import math
from pathlib import Path

import numpy as np
import pytest

from lut_baker import auto_tier

ROOT = Path(__file__).resolve().parents[3]


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


def test_shares_add_up(paper_tables):
    """Gloss and skin light are parts of the image: each share is in (0, 1); bare skin is
    nearly all skin light, full film mostly not (the film hides the skin)."""
    gloss, skin = auto_tier.gloss_and_skin_shares(paper_tables, 45.0, 1.0, 0.0)
    bare_gloss, bare_skin = auto_tier.gloss_and_skin_shares(paper_tables, 45.0, 0.0, 0.0)
    assert 0.0 < gloss < 1.0 and 0.0 < skin < 0.5 and bare_skin > 0.9 > bare_gloss
    _, absorbed = auto_tier.gloss_and_skin_shares(paper_tables, 45.0, 1.0, 1.0)
    assert absorbed == 0.0


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


def test_traits_measure_each_sphere_once(paper_tables, paper_fit):
    """The traits' gloss omissions, measured with the shares on each sphere in one pass, are
    gloss_omissions' (the same spheres and replicas: the same numbers, bit for bit)."""
    traits = auto_tier.traits_from_tables(paper_tables, paper_fit, 0.6, 0.2)
    assert traits.gloss_omission == auto_tier.gloss_omissions(paper_tables, paper_fit, 0.6, 0.2)
    assert list(traits.gloss_omission) == list(paper_fit.tiers)
    assert all(list(by_light) == list(auto_tier.SHARE_LIGHTS_DEG)
               for by_light in traits.gloss_omission.values())


def test_traits_of_a_fit_of_some_tiers(paper_tables, paper_fit):
    """The traits hold the tiers the fit holds (the Auto tier asks only for the engine's),
    those tiers' values as a full fit gives them; over the artist's shader the subsurface
    closure under the film is theirs, radius and method: no profile mismatch."""
    from lut_baker.closures import fitting

    cycles = fitting.fit_closures(paper_tables, tiers=("PRINCIPLED", "LAYERED"))
    traits = auto_tier.traits_from_tables(paper_tables, cycles, 0.6, 0.2)
    full = auto_tier.traits_from_tables(paper_tables, paper_fit, 0.6, 0.2)
    assert set(traits.tier_errors) == set(traits.gloss_omission) == {"PRINCIPLED", "LAYERED"}
    for tier in traits.tier_errors:
        assert traits.tier_errors[tier] == pytest.approx(full.tier_errors[tier], rel=1e-9)
        assert traits.gloss_omission[tier] == pytest.approx(full.gloss_omission[tier],
                                                            rel=1e-9)
    assert traits.profile_mismatch == full.profile_mismatch > 0.0
    over = fitting.fit_closures(paper_tables, tiers=("LAYERED",), over_shader=True,
                                subsurface_method="BURLEY")
    traits = auto_tier.traits_from_tables(paper_tables, over, 0.6, 0.2, over_shader=True)
    assert traits.profile_mismatch == 0.0 and set(traits.tier_errors) == {"LAYERED"}
    # Gloss 0 leaves the artist's bare skin as it is: what it changes is the covered part's.
    assert 0.0 < traits.gloss_error("LAYERED", 45.0) < full.gloss_error("LAYERED", 45.0)


def test_a_slab_materials_traits_follow_its_thickness():
    """With the film as a slab the traits are the slab's at the fit's thickness: the skin's
    spreading light a large share of the image through a sheer film (2 um: 0.49-0.62) and a
    small one through a thick film (150 um: 0.08-0.09, about the paper film's 0.05-0.06 with
    every inter-reflection added), every share and gloss omission between 0 and 1."""
    import dataclasses

    from lut_baker import bake
    from lut_baker.closures import fitting
    from lut_baker.model import presets

    tables = bake.bake(presets.made_up_skin("paper_natural", "jensen_skin1"), "preview",
                       film=9.6)
    skin_share = {}
    for thickness in (2.0, 150.0):
        at = dataclasses.replace(tables, parameters={**tables.parameters,
                                                     "film_thickness_um": thickness})
        traits = auto_tier.traits_from_tables(at, fitting.fit_closures(at), 1.0, 0.0)
        skin_share[thickness] = min(traits.skin_share.values())
        for values in (traits.skin_share, traits.gloss_share,
                       *traits.gloss_omission.values()):
            assert all(0.0 < v < 1.0 for v in values.values())
    assert skin_share[2.0] > 0.4 and skin_share[150.0] < 0.12
