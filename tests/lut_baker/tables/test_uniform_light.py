"""The made-up skin under uniform light from the tables (lut_baker.tables.uniform_light): the
parts against the tables' own albedo, the mix against the evaluator's, and the shade that
matches a colour (Match Skin)."""

import numpy as np
import pytest

from lut_baker.bake import bake
from lut_baker.evaluate import made_up
from lut_baker.model import presets
from lut_baker.model.albedo import bihemispherical
from lut_baker.tables import uniform_light as U


@pytest.fixture(scope="module")
def light(paper_tables):
    return U.uniform_light(paper_tables)


def test_the_parts_average_the_tables_albedo(paper_tables, light):
    """At the preset's skin albedo, the mix is the tables' directional albedo averaged over
    incidence, at any coverage and absorption."""
    skin = np.pi * np.asarray(paper_tables.skin_diffuse, float)
    for coverage, absorption in ((1.0, [0.0, 0.0, 0.0]), (0.6, [0.1, 0.3, 0.5]),
                                 (0.0, [0.5, 0.5, 0.5]), (0.3, [1.0, 0.2, 0.0])):
        expected = bihemispherical(lambda t, c=coverage, a=absorption:
                                   paper_tables.directional_albedo(t, c, a))
        np.testing.assert_allclose(U.made_up_colour(light, coverage, absorption, skin),
                                   expected, rtol=1e-12)


def test_the_mix_follows_the_exact_evaluator():
    """The tables' uniform-light colour against the exact made-up skin's albedo averaged over
    incidence (evaluate.made_up.directional_albedo): within the tables' albedo error."""
    skin = presets.made_up_skin("clarins_103", "jensen_skin1", coverage=1.0, absorption=0.0)
    light = U.uniform_light(bake(skin, "preview"))
    absorption = np.array([0.1, 0.4, 0.6])
    exact = bihemispherical(lambda t: made_up.directional_albedo(
        t, skin.replace(coverage=0.7, absorption=absorption)))
    colour = U.made_up_colour(light, 0.7, absorption, np.pi * skin.skin_reflection.P_d)
    np.testing.assert_allclose(colour, exact, rtol=3e-3)


def test_skin_colour_and_gloss_enter_linearly(light):
    a, b = np.array([0.2, 0.1, 0.05]), np.array([0.6, 0.4, 0.3])
    for coverage in (0.0, 0.5, 1.0):
        mid = U.made_up_colour(light, coverage, [0.2, 0.3, 0.4], 0.5 * (a + b), gloss=0.5)
        ends = [U.made_up_colour(light, coverage, [0.2, 0.3, 0.4], x, gloss=0.5) for x in (a, b)]
        np.testing.assert_allclose(mid, 0.5 * (ends[0] + ends[1]), rtol=1e-13)
    no_gloss = U.bare_colour(light, a, gloss=0.0)
    np.testing.assert_allclose(no_gloss, a, rtol=1e-15)
    np.testing.assert_allclose(U.bare_colour(light, a) - no_gloss, light.skin_gloss, rtol=1e-12)


@pytest.mark.parametrize("skin", [[0.436, 0.227, 0.131], [0.3, 0.25, 0.2]])
def test_matching_gives_the_skins_colour_at_every_coverage(light, skin):
    bare = U.bare_colour(light, skin)
    absorption, clamped = U.matching_absorption(light, bare, skin)
    assert not np.any(clamped) and np.all((absorption >= 0) & (absorption <= 1))
    for coverage in (0.0, 0.3, 0.6, 1.0):
        np.testing.assert_allclose(U.made_up_colour(light, coverage, absorption, skin), bare,
                                   rtol=1e-12)


def test_matching_clamps_what_the_film_cannot_reach(light):
    """A skin lighter in red than the film over it can be, and darker in blue than the film's
    own gloss: A = 0 and 1 there, said so, and the solved channel still matches."""
    skin = np.array([0.9, 0.3, 0.02])
    bare = U.bare_colour(light, skin)
    absorption, clamped = U.matching_absorption(light, bare, skin)
    assert list(clamped) == [True, False, True]
    assert absorption[0] == 0.0 and absorption[2] == 1.0
    covered = U.covered_colour(light, absorption, skin)
    assert covered[0] < bare[0] and covered[2] > bare[2]
    assert covered[1] == pytest.approx(bare[1], rel=1e-12)
    # Both ends of the covered colour's range, and monotone between.
    x = np.linspace(0.0, 1.0, 21)
    colours = np.array([U.covered_colour(light, [a] * 3, skin) for a in x])
    assert np.all(np.diff(colours, axis=0) < 0)
