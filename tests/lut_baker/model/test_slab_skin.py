"""Made-up skin at a thickness in closed form (lut_baker.model.slab_skin; docs/model.md, "Made-up
skin at a thickness"): the split into an albedo-free part and a rank-one diffuse part is the
adding equation exactly, the white furnace holds at every thickness and incidence, and Match
Skin matches the docs' three skins at sheer, default and full thickness."""

import numpy as np
import pytest

from lut_baker.model import film_slab as FS
from lut_baker.model import presets
from lut_baker.model import slab_skin as SS
from lut_baker.model.albedo import bihemispherical, reflection_albedo
from lut_baker.model.layers import ReflectionLayer
from lut_baker.numerics import adding_doubling as AD
from lut_baker.numerics.quadrature import hemisphere_panels

GRID = hemisphere_panels(3, 10, 33)  # the bake's default quadrature
THICKNESSES_UM = (0.5, 2.0, FS.DEFAULT_THICKNESS_UM, 50.0, 150.0, 1500.0)
SHEER_UM, FULL_UM = 2.0, 50.0

# The skins of docs/addon.md, "Match Skin": the artist's render under uniform light, and the
# foundation each was matched with.
SKINS = {
    "medium": ((0.661, 0.346, 0.243), "paper_natural"),
    "darker": ((0.299, 0.151, 0.103), "clarins_103"),
    "lighter": ((0.791, 0.478, 0.369), "paper_natural"),
}


@pytest.fixture(scope="module")
def paper():
    return presets.paper()


def bare_gloss(skin: ReflectionLayer) -> float:
    """The skin's gloss albedo under uniform light (the bare skin is it plus its albedo)."""
    return float(bihemispherical(lambda t: reflection_albedo(t, skin.scaled(P_d=0.0))))


@pytest.mark.parametrize("um", THICKNESSES_UM + (np.inf,))
def test_the_closed_form_is_the_adding_equation(paper, um):
    """top + a / (1 - a c) v v^T against film_slab.made_up_matrices (surface, body, skin with
    gloss and diffuse part, every inter-reflection): equal to rounding, every order."""
    film = SS.foundation_slab(paper.film, paper.film_transmission, GRID, [0.1, 0.3, 0.6])
    skin = presets.skin_layers("jensen_skin1")[0]
    face = FS.face_albedo(paper.film, GRID)
    x = np.inf if np.isinf(um) else FS.relative_thickness(um)
    parts = SS.slab_skin_parts(film, x, skin, face)
    albedo = np.pi * np.asarray(skin.P_d)
    exact = FS.made_up_matrices(film, FS.relative_thickness(1e9) if np.isinf(um) else x, skin,
                                face)
    assert np.allclose(SS.parts_matrices(parts, albedo, GRID), exact, rtol=0.0, atol=1e-14)
    assert np.allclose(SS.parts_albedo(parts, albedo, GRID),
                       FS.made_up_albedo(film, FS.relative_thickness(1e9) if np.isinf(um)
                                         else x, skin, face), rtol=1e-12, atol=1e-14)


def test_without_skin_gloss_the_parts_are_the_films_transmittance_and_reflectance(paper):
    """A Lambertian skin under any layer: t is the film's directional transmittance, c its
    hemispherical reflectance from below."""
    film = SS.foundation_slab(paper.film, paper.film_transmission, GRID)
    matte = ReflectionLayer(P_d=0.2, P_s=0.0, n=0.05, eta=1.3)
    x = FS.relative_thickness(FS.DEFAULT_THICKNESS_UM)
    parts = SS.slab_skin_parts(film, x, matte)
    layer = SS._film_layer(film, x, film.measured_face)
    scale0 = AD.star_scale(GRID)[0]
    transmittance = AD.star_albedo(layer.down[:, 0], scale0)
    assert np.allclose(parts.through, transmittance, rtol=1e-12)
    below = FS.bihemispherical_on_grid(AD.star_albedo(layer.bottom[:, 0], scale0), GRID)
    assert np.allclose(parts.below, below, rtol=1e-12)


@pytest.mark.parametrize("um", THICKNESSES_UM + (np.inf,))
def test_white_furnace_at_every_thickness_and_incidence(paper, um):
    """No absorption, over a white skin (albedo 1), every inter-reflection in: at most 1 at
    every incidence, and no more than the light the film's gloss and body keep back lost."""
    film = SS.foundation_slab(paper.film, paper.film_transmission, GRID)
    white = ReflectionLayer(P_d=1.0 / np.pi, P_s=0.0, n=0.05, eta=1.3)
    parts = SS.slab_skin_parts(film, np.inf if np.isinf(um) else FS.relative_thickness(um),
                               white)
    albedo = SS.parts_albedo(parts, 1.0, GRID)
    assert np.max(albedo) <= 1.0 + 1e-9
    assert np.min(albedo) > 0.7


def test_a_matte_film_the_skins_colour_looks_the_same_at_every_thickness():
    """Kubelka-Munk's fact, which the slab keeps: a film without surface gloss whose thick
    limit has the skin's colour leaves it unchanged at every thickness (the darker skin's
    shade under the matte Clarins 103 is the same from 2 to 50 um)."""
    target, foundation = SKINS["darker"]
    film = presets.foundation_film(foundation)
    paper = presets.paper()
    skin = paper.skin_reflection
    albedo = np.array(target) - bare_gloss(skin)
    shades = [SS.matching_absorption(target, film, paper.film_transmission, skin, albedo, um,
                                     GRID)[0] for um in (SHEER_UM, FULL_UM)]
    assert np.allclose(shades[0], shades[1], atol=0.01)


@pytest.mark.parametrize("name", list(SKINS))
def test_match_skin_at_sheer_default_and_full(name, paper):
    """Every skin of the docs' set within 3% per channel under uniform light at 2, 9.6 and
    50 um (exact evaluation; the skin under the film: the paper's skin gloss and the albedo
    that gives the bare skin the target).  The shade is the foundation's absorption; only
    where a sheer glossy film stays too light at full absorption is the skin under it darkened
    (the medium skin's blue at 2 um, by 3%: its surface reflects the interface's share of the
    gloss only; with all of it, the green and blue by 5% and 38%)."""
    target, foundation = SKINS[name]
    film = presets.foundation_film(foundation)
    skin = paper.skin_reflection
    albedo = np.array(target) - bare_gloss(skin)
    for um in (SHEER_UM, FS.DEFAULT_THICKNESS_UM, FULL_UM):
        absorption, under, clamped, _ = SS.matching_shade(target, film,
                                                          paper.film_transmission, skin,
                                                          albedo, um, GRID)
        colour = SS.slab_colour(film, paper.film_transmission, skin, under, um, GRID,
                                absorption)
        assert np.all(np.abs(colour / np.array(target) - 1.0) < 0.03), (name, um, colour)
        assert not clamped.any()
        if um > SHEER_UM or name != "medium":
            assert np.array_equal(under, albedo)  # the absorption alone matches
        assert np.all(under <= albedo) and np.all(under >= 0.95 * albedo)


def test_matching_skin_albedo_round_trips(paper):
    film = SS.foundation_slab(paper.film, paper.film_transmission, GRID, [0.2, 0.4, 0.6],
                              orders=1)
    parts = SS.slab_skin_parts(film, FS.relative_thickness(20.0), paper.skin_reflection)
    albedo = np.array([0.7, 0.4, 0.2])
    colour = SS.parts_colour(parts, albedo, GRID)
    solved, clamped = SS.matching_skin_albedo(parts, colour, GRID)
    assert np.allclose(solved, albedo, rtol=1e-12) and not clamped.any()
    solved, clamped = SS.matching_skin_albedo(parts, [0.0, 2.0, colour[2]], GRID)
    assert list(solved[:2]) == [0.0, 1.0] and list(clamped) == [True, True, False]


def test_a_sheer_films_surface_reflects_the_interfaces_share(paper):
    """The film's surface reflects what an interface of its vehicle reflects under uniform
    light (k of eq. 2's gloss): a film of no thickness over a black skin is its surface alone,
    and that is F_u(1.40) = 0.077, not the measured film's 0.141."""
    black = ReflectionLayer(P_d=0.0, P_s=0.0, n=0.05, eta=1.3)
    colour = SS.slab_colour(paper.film, paper.film_transmission, black, 0.0, 0.0, GRID)
    assert colour[0] == pytest.approx(FS.interface_albedo(FS.VEHICLE_INDEX), rel=2e-3)
    measured = bihemispherical(lambda t: reflection_albedo(t, paper.film.scaled(P_d=0.0)))
    assert colour[0] < 0.6 * float(measured)


def test_the_bodys_share_of_the_gloss_fades_with_the_film(paper):
    """The weight of eq. 2's gloss lobe in the film's own reflection: 1 - k of it at the
    paper's thickness (the body returns what the surface does not), times 1 - A with
    absorption, falling toward 0 as the film thins."""
    lobe = FS.skin_star(paper.film.scaled(P_d=0.0), GRID)
    face = FS.face_albedo(paper.film, GRID)
    rest = 1.0 - float(FS.surface_share(paper.film))
    for a in (0.0, 0.5):
        film = SS.foundation_slab(paper.film, paper.film_transmission, GRID, a)
        weights = [float(SS.body_gloss_weight(film, FS.relative_thickness(um), face, lobe)[0])
                   for um in (1.0, 2.0, FS.DEFAULT_THICKNESS_UM, 50.0, 150.0)]
        assert weights[-1] == pytest.approx((1.0 - a) * rest, rel=0.01)
        assert np.all(np.diff(weights) > 0.0) and weights[0] < 0.1 * weights[-1]


@pytest.mark.parametrize("um", (FS.DEFAULT_THICKNESS_UM, 150.0))
def test_nothing_in_made_up_skin_retro_reflects(paper, um):
    """Eq. 2 (film and skin) and eq. 4 peak at the mirror and straight-through directions; the
    slab reflects no more back along the light (``wi = wo``, relative azimuth 0) than at the
    mirror direction, at every polar node up to 80 degrees (the paper preset at 9.56 um held a
    retro spike of 9.2 1/sr at 0.4 degrees, where the mirror has 0.32), and a film 1e-3 of the
    paper's thick is the film of thickness 0 (the skin's gloss under the surface) at both."""
    film = SS.foundation_slab(paper.film, paper.film_transmission, GRID)
    scale = AD.star_scale(GRID)
    sign = (-1.0) ** np.arange(GRID.orders)

    def retro_mirror(star):
        diag = np.einsum("cmjj->cmj", AD.from_star(star, scale))[0]
        return diag.sum(axis=0), sign @ diag  # 1/sr at relative azimuth 0 and pi

    keep = np.degrees(GRID.theta) < 80.0
    retro, mirror = retro_mirror(SS.slab_skin_parts(film, FS.relative_thickness(um),
                                                    paper.skin_reflection).top)
    assert np.all(retro[keep] <= 1.01 * mirror[keep])
    thin = retro_mirror(SS.slab_skin_parts(film, 1e-3, paper.skin_reflection).top)
    bare = retro_mirror(SS.slab_skin_parts(film, 0.0, paper.skin_reflection).top)
    for got, want in zip(thin, bare, strict=True):
        assert np.allclose(got[keep], want[keep], rtol=0.05, atol=2e-3)


def test_match_skin_out_of_reach_in_some_channels(paper):
    """A target lighter than the film without pigment in one channel and darker than full
    absorption in another (the medium skin times (1.2, 1, 0.4) at 1 um): those channels end
    at A = 0 and 1, clamped, the one between matched."""
    target = np.array(SKINS["medium"][0]) * [1.2, 1.0, 0.4]
    skin = paper.skin_reflection
    albedo = np.array(SKINS["medium"][0]) - bare_gloss(skin)
    absorption, under, clamped, _ = SS.matching_shade(target, paper.film,
                                                      paper.film_transmission, skin, albedo,
                                                      1.0, GRID)
    assert absorption[0] == 0.0 and absorption[2] == 1.0
    assert list(clamped) == [True, False, True]
    colour = SS.slab_colour(paper.film, paper.film_transmission, skin, under, 1.0, GRID,
                            absorption)
    assert abs(colour[1] / target[1] - 1.0) < 1e-9


@pytest.mark.parametrize("um", (1.0, 2.0, FS.DEFAULT_THICKNESS_UM, 50.0))
@pytest.mark.parametrize("name", list(SKINS))
def test_the_matched_colour_is_the_slab_colour_at_the_match(name, paper, um):
    """Match Skin's colour (its search's own evaluations, the skin under the film darkened
    where it is) is :func:`slab_colour` at the absorption and skin albedo it returns, and the
    target where nothing is clamped.  The search runs in ``s`` (``A = 1 - (1 - s)^3``), 0 and 1
    at the ends exactly."""
    target, foundation = SKINS[name]
    film = presets.foundation_film(foundation)
    skin = paper.skin_reflection
    albedo = np.array(target) - bare_gloss(skin)
    absorption, under, clamped, colour = SS.matching_shade(target, film,
                                                           paper.film_transmission, skin,
                                                           albedo, um, GRID)
    exact = SS.slab_colour(film, paper.film_transmission, skin, under, um, GRID, absorption)
    assert np.allclose(colour, exact, rtol=1e-12, atol=0.0)
    assert np.allclose(colour[~clamped], np.array(target)[~clamped], rtol=1e-9, atol=0.0)
    assert SS.absorption_along(0.0) == 0.0 and SS.absorption_along(1.0) == 1.0


def test_colours_are_kept_channel_by_channel(paper, monkeypatch):
    """:func:`channel_colours` keeps each channel under its own inputs: a channel kept from
    one evaluation is what a fresh evaluation with other channels beside it gives (to
    rounding), and a search asked again evaluates nothing (Lighter then Darker retrace the
    search of the shade they return to)."""
    film = presets.foundation_film("paper_natural")
    args = (film, paper.film_transmission, paper.skin_reflection, (0.5, 0.3, 0.2),
            FS.DEFAULT_THICKNESS_UM, GRID)
    SS._COLOURS.clear()
    SS.channel_colours(*args, (0.1, 0.4, 0.7))
    SS.channel_colours(*args, (0.2, 0.5, 0.8))
    evaluated = []
    exact = SS.slab_colour
    monkeypatch.setattr(SS, "slab_colour",
                        lambda *a, **k: evaluated.append(a) or exact(*a, **k))
    mixed = SS.channel_colours(*args, (0.1, 0.5, 0.7))
    assert evaluated == []
    np.testing.assert_allclose(mixed, exact(*args, (0.1, 0.5, 0.7)), rtol=1e-14, atol=0.0)
    # Red at A = 0 (a film absorbing nothing: its passivity is solved for, the slow case),
    # then kept: the next evaluation takes green and blue alone.
    SS.channel_colours(*args, (0.0, 0.6, 0.9))
    part = SS.channel_colours(*args, (0.0, 0.61, 0.91))
    assert len(evaluated) == 2 and np.all(np.asarray(evaluated[1][6]) > 0.0)
    np.testing.assert_allclose(part, exact(*args, (0.0, 0.61, 0.91)), rtol=1e-14, atol=0.0)
    target = (0.45, 0.25, 0.15)
    del evaluated[:]
    first = SS.matching_absorption(target, *args)
    searched = len(evaluated)
    again = SS.matching_absorption(target, *args)
    assert searched > 0 and len(evaluated) == searched
    for one, other in zip(first, again, strict=True):
        np.testing.assert_allclose(one, other, rtol=1e-14, atol=0.0)
