"""Adding and doubling per Fourier order (lut_baker.numerics.adding_doubling): the star form,
the adding equations, doubling, a homogeneous slab at any thickness from its matrices at one
(the doubling relation inverted), its thin and thick limits, energy and passivity.  The slabs
tested are media built here from an isotropic phase function, whose physics is known."""

import numpy as np
import pytest

from lut_baker.model.thick_layer import FilmExchange, stack_reflectance
from lut_baker.numerics import adding_doubling as AD
from lut_baker.numerics.quadrature import hemisphere_panels

GRID = hemisphere_panels(2, 8, 9)


@pytest.fixture(scope="module")
def scale():
    return AD.star_scale(GRID)


def medium(albedo: float, scale):
    """The transport matrices per unit optical depth of an isotropically scattering medium
    (single-scattering ``albedo``), as :func:`AD.generator_from_matrices` takes them: per
    unit of full thickness they are half those of the half slab's Riccati equations."""
    mu = np.cos(GRID.theta)
    orders = GRID.orders
    loss = np.broadcast_to(np.diag(1.0 / mu), (orders, mu.size, mu.size)).copy()
    scatter = np.zeros_like(loss)
    s0 = scale[0]
    # Isotropic phase function 1/(4 pi): order 0 only, the same forward and back.
    scatter[0] = albedo * (s0[:, None] * s0[None, :]) / (4.0 * np.pi * np.outer(mu, mu))
    alpha = loss - scatter
    beta = scatter
    return 0.5 * (alpha + beta), 0.5 * (alpha - beta)


def medium_slab(albedo, scale):
    return AD.generator_from_matrices(*medium(albedo, scale))


def albedos(r, t, scale):
    return AD.star_albedo(r[0], scale[0]), AD.star_albedo(t[0], scale[0])


def test_the_star_form_turns_integrals_into_products(scale):
    kernel = np.zeros((GRID.orders, GRID.theta.size, GRID.theta.size))
    kernel[0] = 0.2  # a Lambertian of albedo 0.2 pi
    star = AD.to_star(kernel, scale)
    assert np.allclose(AD.star_albedo(star[0], scale[0]), 0.2 * np.pi, rtol=1e-12)
    assert np.allclose(AD.from_star(star, scale), kernel, rtol=1e-14)
    # Light reflected twice by Lambertians: albedo times albedo.
    assert np.allclose(AD.star_albedo(star[0] @ star[0], scale[0]), (0.2 * np.pi) ** 2, rtol=1e-12)
    mirror = AD.mirror(np.full(GRID.theta.size, 0.3), GRID.orders)
    assert np.allclose(AD.star_albedo(mirror[0], scale[0]), 0.3, rtol=1e-14)
    assert np.allclose(mirror[1], -mirror[0])  # the mirror direction is the azimuth pi


def test_a_pure_absorber_transmits_straight_by_beer_lambert(scale):
    gen = medium_slab(0.0, scale)
    mu = np.cos(GRID.theta)
    for tau in (0.1, 1.0, 3.0):
        r, t = AD.slab(gen, tau)
        assert np.abs(r).max() < 1e-12
        for m in range(GRID.orders):
            assert np.allclose(t[m], np.diag(np.exp(-tau / mu)), atol=1e-12)


def test_adding_a_clear_layer_changes_nothing_and_doubling_is_adding(scale):
    gen = medium_slab(0.8, scale)
    r, t = AD.slab(gen, 0.7)
    layer = AD.Layer(top=r, bottom=r, down=t)
    eye = np.broadcast_to(np.eye(r.shape[-1]), r.shape)
    clear = AD.Layer(top=np.zeros_like(r), bottom=np.zeros_like(r), down=eye)
    for stack in (AD.add_layers(clear, layer), AD.add_layers(layer, clear)):
        assert np.allclose(stack.top, r, atol=1e-14) and np.allclose(stack.down, t, atol=1e-14)
    both = AD.add_layers(layer, layer)
    r2, t2 = AD.double_slab(r, t)
    assert np.allclose(both.top, r2, atol=1e-14) and np.allclose(both.down, t2, atol=1e-14)
    assert np.allclose(both.bottom, r2, atol=1e-14)


def test_symmetric_layers_solve_both_systems_as_one(scale):
    """``symmetric=True`` (a mirror over a slab, each reflection symmetric) gives what the
    general adding equations give, with layers of different leading shapes broadcast; the
    general form still handles a non-symmetric pair (where the flag would not apply)."""
    gen = medium_slab(0.8, scale)
    r, t = AD.slab(gen, 0.7)
    surface = AD.Layer(top=np.zeros((3,) + r.shape), bottom=AD.mirror(
        np.array([[0.1], [0.3], [0.5]]) * np.ones(r.shape[-1]), GRID.orders),
        down=np.broadcast_to(0.8 * np.eye(r.shape[-1]), (3,) + r.shape))
    body = AD.Layer(top=r, bottom=r, down=t)
    per_channel = AD.Layer(*(np.broadcast_to(part, (3,) + r.shape) for part in body))
    for upper, lower in ((surface, body), (body, body), (per_channel, surface)):
        general = AD.add_layers(upper, lower)
        together = AD.add_layers(upper, lower, symmetric=True)
        for got, expected in zip(together, general, strict=True):
            assert got.shape == expected.shape
            np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-15)
    skewed = AD.Layer(top=r, bottom=r + 0.01 * np.triu(np.ones_like(r)), down=t)
    general = AD.add_layers(skewed, body)
    assert not np.allclose(AD.add_layers(skewed, body, symmetric=True).top, general.top,
                           rtol=1e-6)  # the flag is a promise the caller must keep
    r2, t2 = AD.double_slab(r, t)
    np.testing.assert_allclose(AD.add_layers(body, body).top, r2, atol=1e-14)


def test_the_slab_doubles_into_itself_at_every_thickness(scale):
    gen = medium_slab(0.9, scale)
    for x in (0.01, 0.3, 1.0, 4.0):
        r, t = AD.slab(gen, x)
        r2, t2 = AD.double_slab(r, t)
        r_twice, t_twice = AD.slab(gen, 2.0 * x)
        assert np.allclose(r2, r_twice, atol=1e-12) and np.allclose(t2, t_twice, atol=1e-12)


def test_the_inverted_doubling_relation_recovers_the_medium(scale):
    """From a slab of the medium at one thickness, the slab at every other thickness (the
    reference is thin enough for the straight light at the most grazing node, exp(-0.2/0.016),
    to be far above rounding: a mode the reference extinguishes entirely cannot be recovered,
    which is what ``max_rate`` is for)."""
    gen = medium_slab(0.95, scale)
    reference = 0.2
    r, t = AD.slab(gen, reference)
    recovered = AD.slab_generator(r, t)
    for x in (0.05, 0.5, 1.0, 3.0):
        want_r, want_t = AD.slab(gen, x * reference)
        got_r, got_t = AD.slab(recovered, x)
        assert np.allclose(got_r, want_r, atol=1e-9) and np.allclose(got_t, want_t, atol=1e-9)
    # A mode extinguished below rounding at the reference gets the rate given for it.
    thick_r, thick_t = AD.slab(gen, 40.0)
    capped = AD.slab_generator(thick_r, thick_t, max_rate=3.0)
    assert capped.rates.max() == pytest.approx(3.0, rel=1e-12)
    # The half slab doubled gives the slab back.
    half_r, half_t = AD.slab(recovered, 0.5)
    r2, t2 = AD.double_slab(half_r, half_t)
    assert np.allclose(r2, r, atol=1e-12) and np.allclose(t2, t, atol=1e-12)


def test_a_mode_extinguished_beyond_its_rate_stays_pure_loss(scale):
    """A slab measured too thick to resolve (a pure absorber, and the medium 40 times over)
    capped at ``max_rate`` stays as absorbing as it was scattering: no back-scattering is
    created in the capped modes (P = Q there), which would reflect a delta at the
    retro-reflection direction (the identity of the star form), weighted by 1 / (c_m w) and
    so a spike near the normal in every order."""
    n = GRID.theta.size
    eye = np.broadcast_to(np.eye(n), (GRID.orders, n, n))
    gen = AD.slab_generator(np.zeros_like(eye), 1e-30 * eye, max_rate=3.0)
    p, q = AD.generator_matrices(gen)
    assert np.allclose(p, q, atol=1e-12)
    for x in (0.01, 0.1, 1.0):
        r, t = AD.slab(gen, x)
        assert np.abs(r).max() < 1e-12
        assert np.allclose(t, np.exp(-6.0 * x) * eye, atol=1e-12)
    # A scattering medium: the capped modes add no back-scattering at small thickness either
    # (the thin slab reflects what the medium's first order reflects, not a retro delta).
    thick_r, thick_t = AD.slab(medium_slab(0.95, scale), 40.0)
    capped = AD.slab_generator(thick_r, thick_t, max_rate=3.0)
    r, _ = AD.slab(capped, 1e-3)
    assert np.abs(r[1:]).max() < 1e-9  # isotropic scattering: order 0 only


def test_thin_and_thick_limits(scale):
    gen = medium_slab(0.7, scale)
    r, t = AD.slab(gen, 0.0)
    assert np.array_equal(r, np.zeros_like(r))
    assert np.array_equal(t, np.broadcast_to(np.eye(r.shape[-1]), t.shape))
    r_far, t_far = AD.slab(gen, 200.0)
    assert np.abs(t_far).max() < 1e-12
    assert np.allclose(r_far, AD.thick_slab(gen), atol=1e-12)
    with pytest.raises(ValueError):
        AD.slab(gen, -1.0)


def test_a_lambertian_slab_stacks_to_the_adding_equations_fixed_point(scale):
    """With Lambertian reflection and transmission the matrices act on one vector, so the thick
    slab is the scalar fixed point of lut_baker.model.thick_layer."""
    s0 = scale[0]
    u = s0 / np.linalg.norm(s0)  # the cosine-weighted Lambertian, normalised
    r_albedo, t_albedo = 0.45, 0.38
    rank1 = np.zeros((1, s0.size, s0.size))
    r = rank1 + r_albedo * np.outer(u, u)
    t = rank1 + t_albedo * np.outer(u, u)
    assert np.allclose(AD.star_albedo(r[0], s0), r_albedo)
    gen = AD.slab_generator(r, t, max_rate=20.0)
    expected = stack_reflectance(0.0, FilmExchange(r_gloss=0.0, r_diffuse=r_albedo,
                                                   t_0=t_albedo))
    assert np.allclose(AD.star_albedo(AD.thick_slab(gen)[0], s0), expected, rtol=1e-10)


def test_energy_reciprocity_and_conservation(scale):
    for albedo in (1.0, 0.9, 0.3):
        gen = medium_slab(albedo, scale)
        for x in (0.05, 0.5, 2.0, 8.0):
            r, t = AD.slab(gen, x)
            assert np.allclose(r, np.swapaxes(r, -1, -2), atol=1e-12)
            assert np.allclose(t, np.swapaxes(t, -1, -2), atol=1e-12)
            ra, ta = albedos(r, t, scale)
            if albedo == 1.0:  # conservative scattering loses nothing
                assert np.allclose(ra + ta, 1.0, atol=1e-9)
            else:
                assert np.all(ra + ta < 1.0)
        a = AD.absorption_per_direction(AD.SlabGenerator(gen.basis[0], gen.rates[0]), scale[0])
        assert np.all(a >= -1e-9) if albedo == 1.0 else np.all(a > 0.0)


def test_a_slab_that_creates_light_is_made_passive(scale):
    gen = medium_slab(1.1, scale)  # single-scattering albedo above 1: gain
    order0 = AD.SlabGenerator(gen.basis[0], gen.rates[0])
    assert np.any(AD.absorption_per_direction(order0, scale[0]) < 0.0)
    ra, ta = albedos(*AD.slab(gen, 0.5), scale)
    assert np.max(ra + ta) > 1.0
    fixed = AD.passive_generator(gen, scale[0])
    order0 = AD.SlabGenerator(fixed.basis[0], fixed.rates[0])
    assert np.all(AD.absorption_per_direction(order0, scale[0]) >= -1e-9)
    for x in (0.01, 0.5, 3.0, 30.0):
        ra, ta = albedos(*AD.slab(fixed, x), scale)
        assert np.max(ra + ta) <= 1.0 + 1e-9
    # A passive slab is left as it is.
    passive = medium_slab(0.5, scale)
    assert AD.passive_generator(passive, scale[0]) is passive


def test_a_half_response_outside_a_slab_is_refused(scale):
    r = np.zeros((1, GRID.theta.size, GRID.theta.size))
    t = 1.5 * np.eye(GRID.theta.size)[None]  # transmits more than it receives
    with pytest.raises(ValueError, match="not those of a slab"):
        AD.slab_generator(r, t)
