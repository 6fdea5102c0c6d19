"""The bake (lut_baker.bake): its fast kernels against the exact evaluators, the tables
against the exact model, and the inter-reflection table.

The expensive part, the exact evaluator at 500 random points, is computed once per module.
"""

from dataclasses import replace

import numpy as np
import pytest
from support.samples import node_directions

from lut_baker import bake
from lut_baker.evaluate import two_layer
from lut_baker.model import albedo, dipole, layers, made_up_skin, microfacet, presets
from lut_baker.numerics import quadrature
from lut_baker.numerics.geometry import direction
from lut_baker.numerics.quadrature import hemisphere_panels
from lut_baker.offline.validation import table_accuracy


@pytest.fixture(scope="module")
def paper():
    return presets.paper()


@pytest.fixture(scope="module")
def samples(paper):
    # the exact evaluator at level 0 (within 1e-4 of level 2 for the film gloss's albedo at
    # 89 degrees); the albedo, the slow part, on 100 of the 500 points
    return table_accuracy.error_samples(paper, n_points=500, seed=0, albedo_points=100)


@pytest.fixture(scope="module")
def default_tables(paper):
    return bake.bake(paper, "default")


# --------------------------------------------------------------------------------------------
# Kernels
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("n_phi", [17, 33, 76])
def test_fast_fourier_coefficients_equal_the_exact_evaluators(n_phi):
    paper = presets.paper()
    jensen = presets.made_up_skin("deep_mocha", "jensen_skin2")
    shaded_film = made_up_skin.film_transmission_layer(jensen)  # RGB through absorption
    grid = hemisphere_panels(2, 6, 17)
    outer = np.radians([0.0, 12.0, 47.0, 80.0, 89.0])
    for layer in (paper.skin_reflection, paper.film, paper.film_transmission,
                  jensen.skin_reflection, shaded_film):
        for theta_a in (outer, grid.theta):
            fast = bake.fourier_coefficients(layer, theta_a, grid.theta, n_phi)
            reference = albedo.layer_fourier_kernel(layer, theta_a, grid.theta, n_phi)
            assert fast.shape == reference.shape
            scale = np.abs(reference).max()
            # the tabulated Fresnel term is within 1e-8 (bake.FRESNEL_TOLERANCE)
            np.testing.assert_allclose(fast, reference, rtol=0, atol=2e-8 * scale)


def test_layered_matrices_with_fast_kernels_equal_the_default(paper):
    grid = hemisphere_panels(2, 6, 17)
    theta = np.radians([0.0, 30.0, 60.0, 85.0])
    fast = two_layer.layered_fourier_matrices(theta, theta, paper.film_transmission,
                                              paper.skin_reflection,
                                           grid, fourier=bake.KernelCache())
    slow = two_layer.layered_fourier_matrices(theta, theta, paper.film_transmission,
                                              paper.skin_reflection,
                                           grid)
    np.testing.assert_allclose(fast, slow, rtol=2e-8, atol=1e-15)


def test_skin_diffuse_part_of_path3_is_pd_times_both_transmittances(paper):
    """Int Int f_t P_d f_t cos cos = P_d T(wi) T(wo): the split the tables rely on."""
    rng = np.random.default_rng(3)
    wi = direction(np.radians(rng.uniform(0, 89, 20)), rng.uniform(0, 2 * np.pi, 20))
    wo = direction(np.radians(rng.uniform(0, 89, 20)), rng.uniform(0, 2 * np.pi, 20))
    diffuse_only = paper.skin_reflection.scaled(P_s=0.0)
    path3 = two_layer.layered_reflection(wi, wo, paper.film_transmission, diffuse_only)
    t_i = albedo.film_transmittance(wi, paper.film_transmission)
    t_o = albedo.film_transmittance(wo, paper.film_transmission)
    np.testing.assert_allclose(path3, paper.skin_reflection.P_d * t_i * t_o, rtol=1e-10)
    # and the gloss part is what remains of the full path 3
    full = two_layer.layered_reflection(wi, wo, paper.film_transmission, paper.skin_reflection)
    gloss = two_layer.layered_reflection(wi, wo, paper.film_transmission,
                                      bake.gloss_layer(paper.skin_reflection))
    np.testing.assert_allclose(full, gloss + paper.skin_reflection.P_d * t_i * t_o, rtol=1e-10)


def test_surface_gloss_is_eq2_in_closed_form_at_every_node(default_tables, paper):
    """The surfaces' gloss is not tabulated: the tables evaluate eq. 2's specular term of the
    layers they were baked from, exactly."""
    wi, wo = node_directions(default_tables)
    for name, layer in (("film_gloss", paper.film), ("skin_gloss", paper.skin_reflection)):
        exact = microfacet.ts_reflection(wi, wo, bake.gloss_layer(layer))
        np.testing.assert_allclose(default_tables.angular(name, wi, wo)[..., 0], exact,
                                   rtol=1e-12, atol=1e-15)


def test_tabulated_fresnel_is_checked_and_falls_back_near_eta_1():
    assert bake.fresnel_tabulation(1.19) is not None
    assert bake.fresnel_tabulation(1.0001) is None and bake.fresnel_tabulation(0.8) is None
    c = np.random.default_rng(2).uniform(0.0, 1.0, (5000, 1))
    for eta in (1.19, 1.26, 1.0001, 0.8):
        np.testing.assert_allclose(bake.fresnel_interpolated(c, eta),
                                   microfacet.fresnel_reflectance(c, eta),
                                   rtol=bake.FRESNEL_TOLERANCE)


@pytest.mark.parametrize("width_deg", [30.4, 10.0, 5.0, 1.0])
def test_gloss_albedos_match_the_converged_evaluator(paper, width_deg):
    """Through the half vector, the gloss albedos of a lobe of any width agree with the
    converged evaluator (down to 5 degrees, where it resolves lobes) and with the same
    quadrature at twice the nodes (1 degree): within 0.03% up to 85 degrees, 1% at 89."""
    theta = np.array([0.0, 40.0, 70.0, 85.0, 89.0])
    layer = bake.gloss_layer(paper.film.scaled(n=30.4 / width_deg))
    fast = bake.gloss_albedos((layer,), theta)[0][:, 0]
    if width_deg >= 5.0:
        exact = albedo.reflection_albedo(theta, layer, level=2)
    else:
        quad = quadrature.mirror_quadrature(np.radians(theta), width_deg, alpha_points=24,
                                            phi_points=96)
        values = microfacet.ts_specular_from_cosines(quad.cos_h, quad.cos_dh, quad.cos_other,
                                                     quad.cos_fixed, layer.P_s, layer.n,
                                                     layer.eta)
        exact = np.sum(values * quad.weight * quad.cos_other, axis=(1, 2))
    np.testing.assert_allclose(fast[:4], exact[:4], rtol=3e-4)
    np.testing.assert_allclose(fast, exact, rtol=1e-2)


def test_only_a_preview_bakes_its_gloss_albedos_coarser(paper):
    """A preview's gloss albedos take half the half-vector nodes each way (the refine replaces
    them): within 0.3% of the full quadrature up to 85 degrees, 1% beyond; the other
    resolutions keep the full one."""
    assert {name: r.gloss_level for name, r in bake.RESOLUTIONS.items()} == {
        "preview": -1, "default": 0, "high": 0}
    tables = bake.bake(paper, "preview")
    full = bake.gloss_albedos((paper.film, paper.skin_reflection), tables.theta_deg)
    below_85 = tables.theta_deg <= 85.0
    for preview, exact in zip((tables.film_gloss_albedo, tables.skin_gloss_albedo), full,
                              strict=True):
        np.testing.assert_allclose(preview[below_85], exact[below_85], rtol=3e-3)
        np.testing.assert_allclose(preview, exact, rtol=1e-2)


# --------------------------------------------------------------------------------------------
# The bake against the exact evaluator
# --------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_default_tables_meet_the_error_goal(default_tables, samples):
    error = table_accuracy.table_error(default_tables, samples=samples)
    for name in ("reflection", "albedo", "transmission", "profile"):
        assert error[name] <= 1e-3, (name, error)


@pytest.mark.slow
def test_preview_tables_err_below_one_percent(paper, samples):
    error = table_accuracy.table_error(bake.bake(paper, "preview"), samples=samples)
    assert error["max"] < 1e-2, error


@pytest.mark.slow
def test_a_coarse_bake_fails_the_goal(paper, samples):
    """The error measure can fail: a 12 x 12 x 9 table misses 1e-3 by far."""
    coarse = replace(bake.RESOLUTIONS["preview"], n_theta=12, n_phi=9, n_radius=8)
    assert table_accuracy.table_error(bake.bake(paper, coarse), samples=samples)["max"] > 1e-2


@pytest.mark.slow  # exact albedos at many directions
def test_directional_tables(default_tables, paper):
    theta = np.array([0.0, 33.0, 66.0, 88.0])
    w = direction(np.radians(theta), 0.0)
    np.testing.assert_allclose(default_tables.directional("film_transmittance", theta)[:, 0],
                               albedo.film_transmittance(w, paper.film_transmission, level=1),
                               rtol=1e-4)
    np.testing.assert_allclose(default_tables.directional("transmission_factor", theta)[:, 0],
                               two_layer.transmission_factor(w, paper.film_transmission,
                                                          paper.dipole, level=1), rtol=1e-4)
    # Int T(w) cos dw over the hemisphere, by a fine 1-D quadrature of the exact T
    x, weights = np.polynomial.legendre.leggauss(64)
    t = np.pi / 4 * (x + 1)
    exact_t = albedo.film_transmittance(direction(t, 0.0), paper.film_transmission, level=1)
    integral = 2 * np.pi * np.sum(exact_t * np.cos(t) * np.sin(t) * weights * np.pi / 4)
    np.testing.assert_allclose(default_tables.film_transmittance_integral, integral, rtol=1e-4)
    assert np.all(default_tables.film_transmittance_integral <= np.pi)


def test_radial_table(default_tables, paper):
    d = default_tables.radius_mm
    assert d[0] == 0.0
    profile = np.atleast_1d(dipole.dipole_profile(d, paper.dipole))
    np.testing.assert_allclose(default_tables.profile[:, 0],
                               profile / dipole.dipole_total_reflectance(paper.dipole), rtol=1e-12)
    # ends where R falls below 1e-4 of its peak, not before
    assert profile[-1] <= 1e-4 * profile[0] * (1 + 1e-6)
    assert dipole.dipole_profile(0.99 * d[-1], paper.dipole) > 1e-4 * profile[0]
    np.testing.assert_allclose(default_tables.total_reflectance,
                               dipole.dipole_total_reflectance(paper.dipole))


@pytest.mark.slow  # exact albedos at many directions
def test_rgb_skin_bakes_per_channel():
    skin = presets.made_up_skin("medium_beige", "jensen_skin1", coverage=0.5)
    t = bake.bake(skin, "preview")
    assert t.skin_diffuse.shape == (3,) and len(set(t.skin_diffuse.tolist())) == 3
    assert len(set(t.profile[1].tolist())) == 3
    samples = table_accuracy.error_samples(skin, n_points=60, seed=2, albedo_points=10)
    error = table_accuracy.table_error(t, samples=samples)
    assert error["max"] < 1e-2, error


def test_profile_radius_moves_continuously_with_the_dipole(paper):
    """The table's end is the crossing itself, not the far end of a grid's bracket (which
    stood still, then jumped by the grid's step, 2e-4, as the crossing passed a node)."""
    scales = 1.0 + 1e-6 * np.arange(-50, 51)
    radii = np.array([bake.profile_radius(paper.dipole.scaled(sigma_a=s)) for s in scales])
    steps = np.diff(radii) / radii[:-1]
    assert np.all(steps < 0.0)  # more absorption, a shorter profile, at every step
    np.testing.assert_allclose(steps, np.mean(steps), rtol=1e-3)
    profile = np.atleast_1d(dipole.dipole_profile(np.array([0.0, radii[50]]), paper.dipole))
    assert profile[1] == pytest.approx(bake.PROFILE_FLOOR * profile[0], rel=1e-9)


def test_profile_radius_bisects_as_one_step_at_a_time(paper, monkeypatch):
    """The midpoints evaluated together (``BISECTION_DEPTH`` steps a call) end the bisection
    where one step a call ends it."""
    together = [bake.profile_radius(paper.dipole.scaled(sigma_a=s)) for s in (0.5, 1.0, 3.0)]
    monkeypatch.setattr(bake, "BISECTION_DEPTH", 1)
    alone = [bake.profile_radius(paper.dipole.scaled(sigma_a=s)) for s in (0.5, 1.0, 3.0)]
    np.testing.assert_allclose(together, alone, rtol=bake.RADIUS_PRECISION)


def test_slab_top_series_of_every_thickness_at_once_is_each_thickness_alone(monkeypatch):
    """The slab's ``top`` summed for all thicknesses at once, in chunks of any size, is each
    thickness's cosine series on its own."""
    theta_deg = np.linspace(0.0, 89.0, 9)
    pairs = bake._NodePairs(theta_deg, np.linspace(0.0, 180.0, 7), "uniform")
    coefficients = np.random.default_rng(3).normal(size=(4, 3, 5, 9, 9))  # (H, C, M, I, I)
    coefficients = coefficients + np.swapaxes(coefficients, -1, -2)
    alone = [np.asarray(bake._cosine_series(np.moveaxis(c, 0, -1), pairs)) for c in coefficients]
    for chunk in (bake.CHUNK_ELEMENTS, 40):  # one chunk, and many
        monkeypatch.setattr(bake, "CHUNK_ELEMENTS", chunk)
        together = bake._thickness_series(coefficients, pairs)
        assert together.shape == (4, 9, 9, 7, 3)
        np.testing.assert_allclose(together, np.stack(alone), rtol=1e-15, atol=1e-300)


def test_narrow_lobes_in_path3_scale_the_grids_and_the_film_gloss_does_not(paper):
    """The grids follow what path 3 goes through (the film's transmission, the skin's gloss);
    the film's own gloss is a closed form and leaves them as they are."""
    sharp_skin = paper.replace(skin_reflection=paper.skin_reflection.scaled(n=2.5))  # 10 degrees
    assert bake.path3_width_deg(sharp_skin) == pytest.approx(10.0)
    res = bake.RESOLUTIONS["preview"].for_lobe(bake.path3_width_deg(sharp_skin))
    assert res.n_theta > bake.RESOLUTIONS["preview"].n_theta
    assert bake.bake(sharp_skin, "preview").theta_deg.size == res.n_theta
    sharp_film = paper.replace(film=paper.film.scaled(n=30.0))  # about 1 degree
    assert bake.path3_width_deg(sharp_film) == bake.path3_width_deg(paper)
    assert (bake.bake(sharp_film, "preview").theta_deg.size
            == bake.RESOLUTIONS["preview"].n_theta)


@pytest.mark.parametrize("name", ["preview", "default", "high"])
def test_a_lobe_a_last_bit_narrower_than_the_reference_keeps_the_grids(name):
    """The Jensen skins' lobe is the reference width to its last bit: 1e-9 narrower must not
    add a node to every grid (it did: the counts were rounded up from 47.00000005)."""
    base = bake.RESOLUTIONS[name]
    for width in bake.REFERENCE_LOBE_DEG * (1.0 + np.array([-1e-9, -1e-12, 0.0, 1e-9])):
        assert base.for_lobe(width) == base
    assert base.for_lobe(bake.REFERENCE_LOBE_DEG / 1.01).n_theta > base.n_theta


def test_a_jensen_skin_with_a_last_bit_narrower_lobe_bakes_the_same_grids():
    skin = presets.made_up_skin("medium_beige", "jensen_skin1")
    narrower = skin.replace(skin_reflection=skin.skin_reflection.scaled(n=1.0 + 1e-9))
    tables, moved = bake.bake(skin, "preview"), bake.bake(narrower, "preview")
    for name in ("theta_deg", "phi_deg", "radius_mm"):
        np.testing.assert_array_equal(getattr(moved, name), getattr(tables, name))


def test_scaled_counts_round_up_beyond_the_slack():
    assert bake.scaled_count(47, 1.0) == 47
    assert bake.scaled_count(47, 1.0 + 1e-9) == 47
    assert bake.scaled_count(47, 1.0 + 0.2 / 47) == 48  # 47.2 nodes: one more
    assert bake.scaled_count(2, 2.9027) == 6 and bake.scaled_count(16, 2.9027) == 47
    assert bake.lobe_scale(bake.REFERENCE_LOBE_DEG * 2) == 1.0
    assert bake.lobe_scale(1.0) == 4.0


def test_progress_is_reported_in_order(paper):
    calls = []
    bake.bake(paper, "preview", inter_reflection=True,
              progress=lambda f, m: calls.append((f, m)))
    fractions = [f for f, _ in calls]
    assert fractions[0] == 0.0 and fractions[-1] == 1.0 and fractions == sorted(fractions)
    assert all(isinstance(m, str) and m for _, m in calls) and len(calls) >= 5


def test_bad_input_is_rejected(paper):
    with pytest.raises(ValueError, match="resolution"):
        bake.bake(paper, "ultra")
    with pytest.raises(ValueError, match="MadeUpSkin"):
        bake.bake(paper.film, "preview")


# --------------------------------------------------------------------------------------------
# Inter-reflection (the adding equation)
# --------------------------------------------------------------------------------------------
def test_inter_reflection_of_diffuse_layers_is_the_geometric_series():
    """All layers Lambertian: f_t = a, f_s = b, film underside albedo R_f = pi c.  Path 3 is
    a^2 b pi^2 and each further bounce multiplies by (pi b)(pi c)."""
    a, b, c = 0.08, 0.2, 0.12
    grid = hemisphere_panels(2, 6, 17)
    film_t = layers.TransmissionLayer(P_d=a, P_t=0.0, n=0.03, eta=1.2)
    skin = layers.ReflectionLayer(P_d=b, P_s=0.0, n=0.03, eta=1.3)
    below = layers.ReflectionLayer(P_d=c, P_s=0.0, n=0.03, eta=1.2)
    theta = np.radians([0.0, 45.0, 80.0])
    full = two_layer.inter_reflection_fourier_matrices(theta, theta, film_t, skin, grid,
                                                    film_below=below)
    bounce = np.pi * b * np.pi * c
    np.testing.assert_allclose(full[0, ..., 0], a * a * b * np.pi**2 / (1 - bounce), rtol=1e-12)
    np.testing.assert_allclose(full[1:], 0.0, atol=1e-15)


def test_inter_reflection_equals_its_neumann_series(paper):
    """(I - S R_f)^-1 S against S + S R_f S + ... summed term by term (glossy layers)."""
    grid = hemisphere_panels(2, 6, 17)
    theta = np.radians([10.0, 50.0, 85.0])
    film_t = made_up_skin.film_transmission_layer(paper)
    below = made_up_skin.film_reflection_layer(paper)
    full = two_layer.inter_reflection_fourier_matrices(theta, theta, film_t,
                                                       paper.skin_reflection, grid,
                                                    film_below=below)
    skin_m = two_layer.inner_matrices(grid, film_t, paper.skin_reflection)[..., 0]
    film_m = albedo.layer_fourier_kernel(below, grid.theta, grid.theta, grid.n_phi)[..., 0]
    rows = albedo.transmission_rows(theta, grid, film_t)[..., 0]
    term, total = skin_m, skin_m.copy()
    for _ in range(40):
        term = term @ film_m @ skin_m
        total += term
    series = rows @ total @ np.swapaxes(rows, 1, 2)
    np.testing.assert_allclose(full[..., 0], series, rtol=1e-10, atol=1e-14)


def test_inter_reflection_table(paper):
    t = bake.bake(paper, "preview", inter_reflection=True)
    assert t.inter_reflection.shape == t.path3_gloss.shape
    assert np.all(t.inter_reflection >= 0.0) and t.inter_reflection.max() > 0.0
    # the same numbers from the exact evaluator's (slow) kernels on the bake's quadrature
    res = bake.RESOLUTIONS["preview"]
    grid = hemisphere_panels(res.quad_panels, res.quad_points, res.quad_phi)
    theta = np.radians(t.theta_deg[[4, 30]])
    film_t = made_up_skin.film_transmission_layer(paper)
    extra = (two_layer.inter_reflection_fourier_matrices(
        theta, theta, film_t, paper.skin_reflection, grid,
        film_below=made_up_skin.film_reflection_layer(paper))
        - two_layer.layered_fourier_matrices(theta, theta, film_t, paper.skin_reflection, grid))
    cos_phi = np.cos(np.radians(t.node_azimuths()[4, 30]))
    series = sum(extra[m, 0, 1, 0] * np.cos(m * np.arccos(cos_phi)) for m in range(len(extra)))
    np.testing.assert_allclose(t.inter_reflection[4, 30, :, 0], series, rtol=1e-9, atol=1e-14)
    # made_up_reflection adds it with the coverage weight
    wi, wo = (w[3, 5, 7] for w in node_directions(t))
    with_ir = t.made_up_reflection(wi, wo, coverage=0.5)
    without = replace(t, inter_reflection=None).made_up_reflection(wi, wo, coverage=0.5)
    np.testing.assert_allclose(with_ir - without, 0.5 * t.inter_reflection[3, 5, 7], rtol=1e-9)


@pytest.mark.parametrize("foundation", ["paper_natural", "deep_mocha"])
def test_white_furnace_with_inter_reflections(foundation):
    """Paths 1 + 3 plus all inter-reflections still reflect at most what arrives."""
    skin = presets.made_up_skin(foundation)
    theta = np.array([0.0, 45.0, 75.0, 89.0])
    albedo = bake.bake(skin, "preview").directional_albedo(theta)
    extra = bake.inter_reflection_albedo(skin, theta, "preview")
    assert np.all(extra > 0.0) and np.all(albedo + extra <= 1.0), albedo + extra
