"""The thick layer (lut_baker.model.thick_layer, docs/model.md §4): a film's exchange under
uniform light for any film, the film stacked on itself (adding equation), the absorption solve
(monotone, clamped), and the round trip a user makes: a measured product's own colour picked
gives back its preset."""

import numpy as np
import pytest

from lut_baker.model import presets, roughness
from lut_baker.model import thick_layer as TL
from lut_baker.model.albedo import bihemispherical, reflection_albedo, transmission_albedo

PRODUCTS = ("clarins_103", "clarins_105", "clarins_108", "clarins_112")


@pytest.fixture(scope="module")
def exchange():
    return TL.paper_film_exchange()


def test_the_paper_films_exchange(exchange):
    film = presets.paper().film
    assert exchange.r_diffuse == pytest.approx(np.pi * float(film.P_d), rel=1e-14)
    # The lossless film (K, docs/model.md §4) reflects and transmits at most all it receives.
    assert 0.9 < exchange.r_gloss + exchange.r_diffuse + exchange.t_0 <= 1.0
    assert 0.0 < exchange.r_gloss < 0.2 and 0.2 < exchange.t_0 < 0.5
    # A Lambertian albedo averages to itself.
    assert bihemispherical(lambda t: np.full(np.shape(t), 0.3)) == pytest.approx(0.3, 1e-14)
    assert TL.paper_film_exchange() is exchange  # computed once


def test_the_stored_exchange_is_the_computed_one(exchange):
    """What the panel solves against (stored beside the presets) is what the derivation
    computes and wrote."""
    stored = TL.preset_film_exchange()
    for name in ("r_gloss", "r_diffuse", "t_0"):
        assert getattr(stored, name) == pytest.approx(getattr(exchange, name), rel=1e-15)


def test_any_films_exchange_is_its_gloss_diffuse_and_transmission():
    """The exchange of a measured product's film (its own gloss on the paper's diffuse part
    and transmission) against the albedos integrated directly; a matte film has no gloss; a
    roughened lobe keeps its gloss albedo (lut_baker.model.roughness)."""
    base = presets.paper()
    t_0 = float(bihemispherical(lambda t: transmission_albedo(t, base.film_transmission)))
    for name in ("clarins_105", "clarins_112", "clarins_103"):
        film = presets.foundation_film(name)
        exchange = TL.film_exchange(film, base.film_transmission)
        gloss = film.scaled(P_d=0.0)
        expected = (float(bihemispherical(lambda t, g=gloss: reflection_albedo(t, g)))
                    if float(film.P_s) > 0 else 0.0)
        assert exchange.r_gloss == pytest.approx(expected, rel=1e-12, abs=1e-15), name
        assert exchange.t_0 == pytest.approx(t_0, rel=1e-12), name
    assert TL.film_exchange(presets.foundation_film("clarins_103"),
                            base.film_transmission).r_gloss == 0.0
    rough = roughness.with_roughness(base.film, 0.4)
    assert TL.film_exchange(rough, base.film_transmission).r_gloss == pytest.approx(
        TL.paper_film_exchange().r_gloss, rel=2e-3)


def test_the_stack_is_the_adding_equations_fixed_point(exchange):
    absorption = np.linspace(0.0, 1.0, 11)
    stack = TL.stack_reflectance(absorption, exchange)
    r, t = exchange.r(absorption), exchange.t(absorption)
    np.testing.assert_allclose(stack, r + t**2 * stack / (1.0 - r * stack), rtol=1e-12)
    # Adding film after film converges to it from below.
    added = r.copy()
    for _ in range(400):
        added = r + t**2 * added / (1.0 - r * added)
    np.testing.assert_allclose(added, stack, rtol=1e-9)
    assert np.all(np.diff(stack) < 0)  # monotone: more absorption reflects less
    assert stack[-1] == pytest.approx(exchange.r_gloss, rel=1e-14)  # A = 1: gloss alone
    assert 0.8 < stack[0] < 1.0


def test_the_solve_inverts_the_stack_and_clamps(exchange):
    top = float(TL.stack_reflectance(0.0, exchange))
    targets = np.array([exchange.r_gloss + 1e-3, 0.3, 0.5, 0.7, top - 1e-3])
    absorption, clamped = TL.solve_absorption(targets, exchange)
    assert not np.any(clamped) and np.all(np.diff(absorption) < 0)
    np.testing.assert_allclose(TL.stack_reflectance(absorption, exchange), targets,
                               rtol=0, atol=1e-12)
    absorption, clamped = TL.solve_absorption([top + 0.05, 0.5 * exchange.r_gloss], exchange)
    np.testing.assert_array_equal(absorption, [0.0, 1.0])
    np.testing.assert_array_equal(clamped, [True, True])


def test_a_picked_colour_is_reproduced_where_reachable(exchange):
    """Any colour between the gloss alone and the pigment-free stack: its solved film's thick
    layer reflects it to 1e-6 in every channel."""
    rng = np.random.default_rng(7)
    low, high = exchange.r_gloss, float(TL.stack_reflectance(0.0, exchange))
    colours = rng.uniform(low + 1e-6, high - 1e-6, size=(200, 3))
    absorption, clamped = TL.solve_absorption(colours, exchange)
    assert not np.any(clamped)
    np.testing.assert_allclose(TL.stack_reflectance(absorption, exchange), colours, rtol=0,
                               atol=1e-6)


@pytest.mark.parametrize("name", PRODUCTS)
def test_a_products_own_colour_gives_back_its_preset(name):
    """The measured thick layer's colour (what the product looks like in the bottle) picked
    as the shade gives the preset's absorption (Clarins 105's red, beyond the stack, clamps to
    0 as the preset does)."""
    entry = presets.FOUNDATIONS[name]
    absorption, clamped = TL.solve_absorption(entry["colour"], TL.preset_film_exchange())
    np.testing.assert_allclose(absorption, entry["absorption"], rtol=0, atol=1e-12)
    assert list(clamped) == [name == "clarins_105", False, False]
