"""The film as a slab (lut_baker.model.film_slab; docs/model.md, "The film as a slab"): the
measured film given back at its thickness, the doubling identity, the thin and thick limits,
reciprocity and energy at every thickness (white furnace), absorption and the thick-limit
solve."""

import numpy as np
import pytest

from lut_baker.model import film_slab as FS
from lut_baker.model import presets
from lut_baker.model import thick_layer as TL
from lut_baker.model.albedo import layer_fourier_kernel, reflection_albedo, specular_albedo
from lut_baker.model.layers import ReflectionLayer, TransmissionLayer
from lut_baker.numerics import adding_doubling as AD
from lut_baker.numerics.quadrature import hemisphere_panels

GRID = hemisphere_panels(3, 10, 33)  # the bake's default quadrature
SCALE0 = AD.star_scale(GRID)[0]
WHITE_SKIN = ReflectionLayer(P_d=1.0 / np.pi, P_s=0.0, n=0.05, eta=1.3)
THICKNESSES_UM = (0.0, 0.5, 2.0, FS.DEFAULT_THICKNESS_UM, 20.0, 45.0, 150.0, 1500.0, 1e5)


@pytest.fixture(scope="module")
def paper():
    return presets.paper()


@pytest.fixture(scope="module")
def exact(paper):
    return FS.film_slab(paper.film, paper.film_transmission, GRID, passive=False)


@pytest.fixture(scope="module")
def passive(paper):
    return FS.film_slab(paper.film, paper.film_transmission, GRID)


def albedo(star):
    return AD.star_albedo(star[:, 0], SCALE0)


def errors(paper, film):
    """Relative error per node of the free film of the paper's thickness against the measured
    film (its diffuse reflection P_d and its transmission, eq. 4)."""
    r_meas, t_meas = FS.measured_body_matrices(paper.film, paper.film_transmission, GRID)
    r, t = FS.free_film_matrices(film, 1.0)
    return albedo(r)[0] / albedo(r_meas)[0] - 1.0, albedo(t)[0] / albedo(t_meas)[0] - 1.0


def test_the_default_thickness_is_the_published_amount():
    assert FS.thickness_from_mass(1.0, 1.0) == pytest.approx(10.0, rel=1e-15)
    assert FS.APPLIED_MASS_MG_PER_CM2 == pytest.approx(0.956, abs=1e-3)
    assert 9.0 < FS.DEFAULT_THICKNESS_UM < 10.0
    assert FS.relative_thickness(FS.PAPER_FILM_THICKNESS_UM) == 1.0
    assert FS.PAPER_FILM_OPTICAL_THICKNESS == pytest.approx(0.5 * 150.0 / FS.DEFAULT_THICKNESS_UM)
    with pytest.raises(ValueError):
        FS.relative_thickness(-1.0)


def test_the_surface_is_the_share_of_the_films_gloss_an_interface_reflects(paper):
    """The surface reflects eq. 2's gloss times k = F / a_g (under uniform light: what an
    interface of the vehicle reflects); a gloss already below F is kept whole (k = 1).  The
    half vector's albedo (the face's) against the Fourier grid's: within 5e-4 up to 85
    degrees, 1e-4 absolute everywhere."""
    gloss = paper.film.scaled(P_d=0.0)
    theta = np.degrees(GRID.theta)
    closed = reflection_albedo(theta, gloss)
    k = FS.surface_share(paper.film)
    interface = FS.interface_albedo(FS.VEHICLE_INDEX)
    assert interface == pytest.approx(0.0768, abs=1e-4)
    assert float(k) == pytest.approx(interface / 0.14106, rel=1e-3)
    face = FS.face_albedo(paper.film, GRID)
    assert np.allclose(face[0], k * specular_albedo(theta, gloss)[:, 0], rtol=1e-14)
    assert np.max(np.abs(face[0] / (k * closed) - 1.0)[theta <= 85.0]) < 5e-4
    assert np.max(np.abs(face[0] - k * closed)) < 1e-4
    assert FS.bihemispherical_on_grid(face[0], GRID) == pytest.approx(interface, rel=1e-3)
    faint = paper.film.scaled(P_s=0.05)  # a_g 0.007, below the interface's
    assert float(FS.surface_share(faint)) == 1.0
    assert np.allclose(FS.face_albedo(faint, GRID)[0],
                       specular_albedo(theta, faint.scaled(P_d=0.0))[:, 0], rtol=1e-14)
    for name in ("clarins_105", "clarins_112"):  # the dewy products' narrow gloss: whole
        assert float(FS.surface_share(presets.foundation_film(name))) == 1.0
    matte = ReflectionLayer(P_d=0.15, P_s=0.0, n=0.0329, eta=1.19)
    assert float(FS.surface_share(matte)) == 1.0
    assert np.array_equal(FS.face_albedo(matte, GRID), np.zeros((1, GRID.theta.size)))


def test_the_gloss_lobe_is_resolved_on_the_bakes_grid(paper):
    """The measured film's 30-degree lobe in the star form (30 polar nodes, 17 orders, the
    body's share of it) against its closed-form albedo: under uniform light within 1e-3,
    directional within 0.2% up to 80 degrees, beyond within 0.006 (2-15% of the little the
    lobe reflects at 85-90 degrees)."""
    lobe = paper.film.scaled(P_d=0.0)
    star = AD.to_star(np.moveaxis(layer_fourier_kernel(lobe, GRID.theta, GRID.theta,
                                                       GRID.n_phi), -1, 0),
                      AD.star_scale(GRID))
    closed = reflection_albedo(np.degrees(GRID.theta), lobe)
    on_grid = albedo(star)[0]
    theta = np.degrees(GRID.theta)
    assert np.max(np.abs(on_grid / closed - 1.0)[theta <= 80.0]) < 2e-3
    assert np.max(np.abs(on_grid - closed)) < 0.006
    assert (FS.bihemispherical_on_grid(on_grid, GRID)
            == pytest.approx(FS.bihemispherical_on_grid(closed, GRID), rel=1e-3))


def test_the_measured_film_is_surface_and_body(paper):
    """What the surface does not reflect of the measured gloss is the body's: the surface's
    albedo plus the free film's reflection below it is eq. 2 whole, P_d and gloss."""
    r, _ = FS.measured_body_matrices(paper.film, paper.film_transmission, GRID)
    face = FS.face_albedo(paper.film, GRID)
    whole = reflection_albedo(np.degrees(GRID.theta), paper.film)
    theta = np.degrees(GRID.theta)
    assert np.max(np.abs((face[0] + albedo(r)[0]) / whole - 1.0)[theta <= 80.0]) < 2e-3
    assert np.allclose(r, np.swapaxes(r, -1, -2), atol=1e-15)


def test_taking_the_faces_off_and_putting_them_back_is_exact(paper):
    r, t = FS.measured_body_matrices(paper.film, paper.film_transmission, GRID)
    face = FS.face_albedo(paper.film, GRID)
    body_r, body_t = FS.remove_faces(r, t, face)
    upper = FS.face_layer(face, GRID.orders)
    lower = AD.Layer(top=upper.bottom, bottom=upper.top, down=upper.down)
    stack = AD.add_layers(AD.add_layers(upper, AD.Layer(body_r, body_r, body_t)), lower)
    assert np.allclose(stack.top, r, atol=1e-12) and np.allclose(stack.down, t, atol=1e-12)
    assert np.allclose(body_t, np.swapaxes(body_t, -1, -2), atol=1e-14)


def test_the_exact_slab_is_the_measured_film_at_its_thickness(paper, exact):
    """Directional albedos within 1% at every incidence (they agree to 2e-4: what eq. 4's
    light the film extinguishes entirely gets back, exp(-7.8), and rounding)."""
    err_r, err_t = errors(paper, exact)
    assert np.max(np.abs(err_r)) < 1e-3 and np.max(np.abs(err_t)) < 1e-3


def test_the_passive_slab_is_the_measured_film_within_its_cost(paper, exact, passive):
    """Passive, the film gives up 2.4% of its reflection and 3.5% of its transmission at
    normal incidence (docs/model.md, "The film as a slab"), keeps its absorption under uniform
    light, and matches within 1% (reflection) and 1.3% (transmission) from 25 to 80 degrees."""
    err_r, err_t = errors(paper, passive)
    theta = np.degrees(GRID.theta)
    upto85 = theta <= 85.0
    assert np.max(np.abs(err_r[upto85])) < 0.025 and np.max(np.abs(err_t[upto85])) < 0.036
    middle = (theta >= 25.0) & (theta <= 80.0)
    assert np.max(np.abs(err_r[middle])) < 0.01 and np.max(np.abs(err_t[middle])) < 0.013
    r_meas, t_meas = FS.measured_body_matrices(paper.film, paper.film_transmission, GRID)
    r, t = FS.free_film_matrices(passive, 1.0)
    kept = FS.bihemispherical_on_grid(albedo(r) + albedo(t), GRID)
    measured = FS.bihemispherical_on_grid(albedo(r_meas) + albedo(t_meas), GRID)
    assert kept == pytest.approx(measured, rel=1e-9)


@pytest.mark.parametrize("x", [0.01, 0.5, 2.0])
def test_doubling_the_half_film_gives_the_film(passive, x):
    r, t = FS.body(passive, x)
    r2, t2 = AD.double_slab(r, t)
    r_twice, t_twice = FS.body(passive, 2.0 * x)
    assert np.allclose(r2, r_twice, atol=1e-12) and np.allclose(t2, t_twice, atol=1e-12)


def test_no_thickness_no_body(passive, paper):
    r, t = FS.body(passive, 0.0)
    assert np.array_equal(r, np.zeros_like(r))
    assert np.array_equal(t, np.broadcast_to(np.eye(GRID.theta.size), t.shape))
    # On skin: the surface alone over the skin.
    skin = paper.skin_reflection
    made_up = FS.made_up_albedo(passive, 0.0, skin)
    face = passive.measured_face
    skin_albedo = reflection_albedo(np.degrees(GRID.theta), skin)
    # Through the surface (1 - a_g) and back, the skin between, inter-reflections aside.
    assert np.all(made_up[0] > face[0])
    assert np.all(made_up[0] < face[0] + (1.0 - face[0]) * skin_albedo + 0.05)


@pytest.mark.parametrize("um", THICKNESSES_UM)
def test_reciprocity_and_energy_at_every_thickness(passive, um):
    x = FS.relative_thickness(um)
    r, t = FS.body(passive, x)
    assert np.allclose(r, np.swapaxes(r, -1, -2), atol=1e-12)
    assert np.allclose(t, np.swapaxes(t, -1, -2), atol=1e-12)
    assert np.max(albedo(r) + albedo(t)) <= 1.0 + 1e-9
    fr, ft = FS.free_film_matrices(passive, x)
    assert np.max(passive.measured_face + albedo(fr) + albedo(ft)) <= 1.0 + 1e-9


@pytest.mark.parametrize("um", THICKNESSES_UM)
def test_white_furnace(passive, um):
    """No absorption, a white skin: gloss + film + skin with every inter-reflection <= 1."""
    made_up = FS.made_up_albedo(passive, FS.relative_thickness(um), WHITE_SKIN)
    assert np.max(made_up) <= 1.0 + 1e-9
    assert np.min(made_up) > 0.7  # what the thick film loses, at most


def test_the_exact_slab_would_create_light(exact):
    """Why the passive one is the default: the measured film, lossless at normal incidence
    (docs/model.md §4, K), is no passive slab under a lossless surface; thinner than it the
    exact slab sends out more than it receives."""
    r, t = FS.free_film_matrices(exact, FS.relative_thickness(45.0))
    assert np.max(exact.measured_face + albedo(r) + albedo(t)) > 1.01


def test_the_thick_limit(passive):
    far = FS.relative_thickness(1e6)
    r, t = FS.body(passive, far)
    assert np.abs(t).max() < 1e-12
    assert np.allclose(r, AD.thick_slab(passive.generator), atol=1e-12)
    skin_limit = FS.made_up_albedo(passive, far, WHITE_SKIN)
    assert np.allclose(skin_limit, FS.thick_limit_albedo(passive), atol=1e-12)


def test_a_lambertian_film_thickens_to_the_stacked_film():
    """Where the slab and lut_baker.model.thick_layer must agree: a film without gloss whose
    reflection and transmission are Lambertian exchanges light through three numbers, so its
    thick limit is the adding equation's fixed point."""
    r_albedo, t_albedo = 0.5, 0.3
    film = ReflectionLayer(P_d=r_albedo / np.pi, P_s=0.0, n=0.0329, eta=1.19)
    transmission = TransmissionLayer(P_d=t_albedo / np.pi, P_t=0.0, n=0.0346, eta=1.19)
    slab = FS.film_slab(film, transmission, GRID, passive=False)
    limit = FS.bihemispherical_on_grid(FS.thick_limit_albedo(slab), GRID)
    expected = TL.stack_reflectance(0.0, TL.FilmExchange(r_gloss=0.0, r_diffuse=r_albedo,
                                                         t_0=t_albedo))
    assert limit[0] == pytest.approx(expected, rel=1e-9)


def test_the_paper_films_thick_limit_is_near_the_stacked_film(passive):
    """The paper's film stacked on itself (every film with its two faces, three numbers) and
    its body thickened under one surface reflect alike, not the same: 0.823 against 0.834."""
    limit = FS.bihemispherical_on_grid(FS.thick_limit_albedo(passive), GRID)[0]
    stacked = TL.stack_reflectance(0.0, TL.paper_film_exchange())
    assert limit == pytest.approx(stacked, abs=0.02)
    assert limit < stacked


def test_absorption_keeps_its_meaning_at_the_papers_thickness(paper):
    a = np.array([0.1, 0.3, 0.6])
    film = FS.film_slab(paper.film, paper.film_transmission, GRID, absorption=a, passive=False)
    base = FS.film_slab(paper.film, paper.film_transmission, GRID, passive=False)
    r, t = FS.free_film_matrices(film, 1.0)
    r0, t0 = FS.free_film_matrices(base, 1.0)
    assert np.allclose(albedo(r), (1.0 - a)[:, None] * albedo(r0), rtol=1e-3)
    assert np.allclose(albedo(t), (1.0 - a)[:, None] * albedo(t0), rtol=1e-3)
    # A thinner film absorbs less: its transmission falls as the thickness grows.
    thin = albedo(FS.body(film, 0.05)[1])[:, 0]
    thick = albedo(FS.body(film, 1.0)[1])[:, 0]
    assert np.all(thin > thick)


def test_the_thick_limit_solve_round_trips(paper):
    a = np.array([0.05, 0.3, 0.7])
    film = FS.film_slab(paper.film, paper.film_transmission, GRID, absorption=a, orders=1)
    colour = FS.bihemispherical_on_grid(FS.thick_limit_albedo(film), GRID)
    solved, clamped = FS.solve_thick_absorption(colour, paper.film, paper.film_transmission,
                                                GRID)
    assert np.allclose(solved, a, atol=1e-9) and not clamped.any()
    solved, clamped = FS.solve_thick_absorption([0.99, 0.5, 0.0], paper.film,
                                                paper.film_transmission, GRID)
    assert solved[0] == 0.0 and solved[2] == 1.0 and list(clamped) == [True, False, True]


def test_the_measured_presets_as_the_slabs_thick_limit(paper):
    """Re-derived as the slab's thick limit under the paper film's surface, the shipped
    absorptions fall by up to 0.10 (docs/model.md, "The film as a slab": the stack reflected
    the whole gloss unabsorbed at every film, the slab's body absorbs its share of it); 105's
    red stays out of reach."""
    stored = presets.read_measured_foundations(presets.MEASURED_FOUNDATIONS_FILE)
    for name in ("clarins_103", "clarins_105", "clarins_108", "clarins_112"):
        solved, clamped = FS.solve_thick_absorption(stored[name]["colour"], paper.film,
                                                    paper.film_transmission, GRID)
        moved = np.array(stored[name]["absorption"]) - solved
        assert np.all(moved >= -1e-9) and np.max(moved) < 0.11
        assert list(clamped) == [name == "clarins_105", False, False]


@pytest.mark.parametrize("absorption", [[0.0, 1.0, 1.0], [1.0, 0.0, 0.5], [0.0, 0.0, 1.0]])
def test_each_channel_is_the_film_at_its_own_absorption(paper, absorption):
    """The channels are independent films, the ends 0 (no pigment absorbs) and 1 (nothing
    comes back from the body but what crosses it unscattered) included, mixed or not."""
    mixed = FS.film_slab(paper.film, paper.film_transmission, GRID, absorption=absorption,
                         orders=1)
    for c, a in enumerate(absorption):
        alone = FS.film_slab(paper.film, paper.film_transmission, GRID, absorption=a,
                             orders=1)
        for x in (0.01, 1.0 / 15.0, 1.0):
            for got, want in zip(FS.body(mixed, x), FS.body(alone, x), strict=True):
                assert np.allclose(got[c], want[0], rtol=0.0, atol=1e-12)
