"""The thick medium under a rough surface (lut_baker/offline/matte_slab.py): its formulas'
properties (normalisation, the smooth and no-surface limits, reciprocity, energy)."""

import numpy as np
import pytest

from lut_baker.model.microfacet import fresnel_reflectance
from lut_baker.numerics import adding_doubling as AD
from lut_baker.numerics.quadrature import hemisphere_panels
from lut_baker.offline.matte_slab import (
    MatteSlab,
    cone_distribution,
    flake_extinction,
    flake_orders,
    ggx_albedo,
    ggx_distribution,
    ggx_reflection,
    kernel_orders,
    matte_slab_kernel,
    medium_generator,
    medium_reflection,
    phase_orders,
    projected_area,
    refracted_grid,
)

GRID = hemisphere_panels(3, 8, 33)
MU = np.cos(GRID.theta)


def _scattered(forward, back):
    """Each node's kernel integrated over the sphere (order 0), 1/sr * sr."""
    return ((forward[0] + back[0]) * 2.0 * np.pi * GRID.weight / MU).sum(axis=1)


def test_smooth_surface_reflects_fresnel():
    # GGX of vanishing roughness is the smooth interface: its albedo is Fresnel's.
    np.testing.assert_allclose(ggx_albedo(MU, 1e-4, 1.5), fresnel_reflectance(MU, 1.5),
                               atol=2e-3)


@pytest.mark.parametrize("alpha", [0.1, 0.5, 1.0])
def test_surface_is_reciprocal_and_passive(alpha):
    a = ggx_reflection(0.3, 0.8, -0.4, alpha, 1.5)
    b = ggx_reflection(0.8, 0.3, -0.4, alpha, 1.5)
    assert a == pytest.approx(b, rel=1e-12)
    albedo = ggx_albedo(MU, alpha, 1.5)
    assert np.all((albedo > 0.0) & (albedo < 1.0))


def test_refracted_grid_covers_the_hemisphere():
    inside = refracted_grid(GRID, 1.4, 8)
    # Int cos sin dtheta over [0, 90] degrees = 1/2, split at the critical angle.
    assert inside.weight.sum() == pytest.approx(0.5, rel=1e-9)
    assert np.degrees(inside.theta[:MU.size]).max() < np.degrees(np.arcsin(1 / 1.4))


@pytest.mark.parametrize("alpha", [0.5, 0.8, 1.0])
def test_flakes_scatter_what_they_intercept(alpha):
    # sigma(w) p(w -> w') integrates to the projected area sigma(w); isotropic normals
    # (GGX alpha = 1) project the same area every way.
    np.testing.assert_allclose(_scattered(*flake_orders(GRID, alpha)),
                               flake_extinction(MU, alpha), rtol=1e-2)
    if alpha == 1.0:
        np.testing.assert_allclose(flake_extinction(MU, alpha), 1.0, rtol=1e-12)


@pytest.mark.parametrize("alpha", [0.2, 0.6, 1.0])
def test_projected_area_of_ggx_is_smiths(alpha):
    # The azimuth in closed form and the polar angle by quadrature give Smith's mu (1 + 2 Lambda).
    np.testing.assert_allclose(projected_area(MU, lambda c: ggx_distribution(c, alpha)),
                               flake_extinction(MU, alpha), rtol=1e-5)


CONES = [(52.0, 20.0), (2.0, 31.0), (30.0, 12.0), (85.0, 25.0)]


@pytest.mark.parametrize(("cone", "spread"), CONES)
def test_cone_is_normalised_and_its_flakes_scatter_what_they_intercept(cone, spread):
    def dist(c):
        return cone_distribution(c, cone, spread)

    # Brute force over the hemisphere of normals (midpoints in the polar angle and azimuth):
    # Int D cos dm = 1, and the projected area along a tilted direction is projected_area's.
    theta = (np.arange(2000) + 0.5) * (0.5 * np.pi / 2000)
    phi = (np.arange(720) + 0.5) * (2.0 * np.pi / 720)
    cell = np.broadcast_to((0.5 * np.pi / 2000) * (2.0 * np.pi / 720) * np.sin(theta)[:, None],
                           (theta.size, phi.size))
    density = dist(np.cos(theta))[:, None]
    assert np.sum(density * np.cos(theta)[:, None] * cell) == pytest.approx(1.0, rel=1e-4)
    w = np.radians(63.0)
    dot = (np.cos(w) * np.cos(theta)[:, None]
           + np.sin(w) * np.sin(theta)[:, None] * np.cos(phi)[None, :])
    assert np.sum(density * np.abs(dot) * cell) == pytest.approx(
        float(projected_area(np.cos(w), dist)), rel=1e-4)
    # Seen from straight above the flakes project 1 (the flakes' share keeps its meaning), and
    # D(h) / 4 over the sphere gives back the area intercepted.
    assert float(projected_area(1.0, dist)) == pytest.approx(1.0, rel=1e-9)
    np.testing.assert_allclose(_scattered(*kernel_orders(GRID, dist)),
                               projected_area(MU, dist), rtol=2e-2)


@pytest.mark.parametrize(("cone", "spread"), CONES)
def test_white_furnace_with_flakes_on_a_cone(cone, spread):
    # A conservative slab of spheres and cone flakes (over nothing) reflects and transmits
    # all it receives and no more, to the grid's quadrature of the kernel (0.2% on this grid);
    # absorbing, less. (The thick limit of albedo 1 is singular: a finite slab instead.)
    scale0 = AD.star_scale(GRID)[0]
    totals = []
    for albedo in (1.0, 0.9):
        model = MatteSlab(albedo=np.array([albedo]), g1=-0.2, flakes=0.7, cone_deg=cone,
                          cone_spread_deg=spread)
        for thickness in (1.0, 4.0):
            r, t = AD.slab(medium_generator(GRID, model), thickness)
            totals.append(AD.star_albedo(r[:, 0], scale0) + AD.star_albedo(t[:, 0], scale0))
    conservative = np.concatenate(totals[:2])
    assert np.all(conservative <= 1.0 + 2e-3)
    np.testing.assert_allclose(conservative, 1.0, atol=2e-2)
    assert np.all(np.concatenate(totals[2:]) < 0.9)


def test_white_furnace_with_flat_and_tilted_flakes():
    # Flakes on a cone with a share lying flat: a conservative finite slab still returns what
    # it receives (the mixture of two normalised distributions is normalised).
    scale0 = AD.star_scale(GRID)[0]
    model = MatteSlab(albedo=np.array([1.0]), g1=0.3, flakes=0.8, cone_deg=45.0,
                      cone_spread_deg=15.0, flat=0.4, flat_spread_deg=20.0)
    for thickness in (1.0, 4.0):
        r, t = AD.slab(medium_generator(GRID, model), thickness)
        total = AD.star_albedo(r[:, 0], scale0) + AD.star_albedo(t[:, 0], scale0)
        assert np.all(total <= 1.0 + 2e-3)
        np.testing.assert_allclose(total, 1.0, atol=2e-2)


def test_phase_function_is_normalised():
    np.testing.assert_allclose(_scattered(*phase_orders(GRID, 0.6, -0.3, 0.7)), 1.0, rtol=2e-3)


MODELS = [
    MatteSlab(albedo=np.array([0.999, 0.95, 0.6]), g1=0.4),
    MatteSlab(albedo=np.array([0.999, 0.95, 0.6]), g1=-0.3, eta=1.5, alpha=0.4),
    MatteSlab(albedo=np.array([0.98, 0.9, 0.6]), g1=0.2, flakes=0.5, flake_alpha=0.6,
              eta=1.3, alpha=0.8),
    MatteSlab(albedo=np.array([0.98, 0.9, 0.6]), g1=-0.2, flakes=0.7, cone_deg=52.0,
              cone_spread_deg=20.0, flake_albedo=np.array([0.95, 0.85, 0.7])),
    MatteSlab(albedo=np.array([0.98, 0.9, 0.6]), g1=0.1, flakes=0.4, cone_deg=30.0,
              cone_spread_deg=15.0, eta=1.4, alpha=0.5),
    MatteSlab(albedo=np.array([0.98, 0.9, 0.6]), g1=0.3, flakes=0.4, cone_deg=40.0,
              cone_spread_deg=20.0, eta=1.5, alpha=0.3, coverage=0.3),
    MatteSlab(albedo=np.array([0.98, 0.9, 0.6]), g1=0.3, flakes=0.4, cone_deg=40.0,
              cone_spread_deg=20.0, eta=1.5, alpha=0.1, coverage=0.2, alpha2=0.7,
              coverage2=0.6),
]


@pytest.mark.parametrize("model", MODELS)
def test_reciprocal_and_energy_at_most_one(model):
    kernel, a_g = matte_slab_kernel(GRID, model)
    scale = AD.star_scale(GRID)
    star = AD.to_star(kernel, scale)
    np.testing.assert_allclose(star, np.swapaxes(star, -1, -2), atol=1e-12)
    total = AD.star_albedo(star[:, 0], scale[0]) + a_g
    assert np.all(total <= 1.0 + 1e-9)
    # Darker single scattering reflects less.
    assert np.all(np.diff(total, axis=0) < 0.0)


def test_no_surface_is_the_limit_of_a_vanishing_one():
    bare = MatteSlab(albedo=np.array([0.9]), g1=0.3)
    faint = MatteSlab(albedo=np.array([0.9]), g1=0.3, eta=1.0 + 1e-7, alpha=0.3)
    k_bare, _ = matte_slab_kernel(GRID, bare)
    k_faint, a_g = matte_slab_kernel(GRID, faint)
    assert np.max(a_g) < 1e-6
    np.testing.assert_allclose(k_faint, k_bare, atol=1e-2 * np.max(np.abs(k_bare)))


def test_partial_surface_is_its_patches_by_area():
    # Surface over 30% of the area, bare medium elsewhere: each patch's light by its area, the
    # ends of the range the bare medium and the whole surface.
    medium = {"albedo": np.array([0.95, 0.7]), "g1": 0.5, "flakes": 0.3, "cone_deg": 40.0,
              "cone_spread_deg": 20.0}
    k_bare, _ = matte_slab_kernel(GRID, MatteSlab(**medium))
    k_full, a_full = matte_slab_kernel(GRID, MatteSlab(**medium, eta=1.5, alpha=0.3))
    k_part, a_part = matte_slab_kernel(GRID, MatteSlab(**medium, eta=1.5, alpha=0.3,
                                                       coverage=0.3))
    np.testing.assert_allclose(k_part, 0.3 * k_full + 0.7 * k_bare, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(a_part, 0.3 * a_full, rtol=1e-12)
    k_none, a_none = matte_slab_kernel(GRID, MatteSlab(**medium, eta=1.5, alpha=0.3,
                                                       coverage=0.0))
    np.testing.assert_allclose(k_none, k_bare, rtol=1e-10, atol=1e-14)
    assert np.all(a_none == 0.0)
    # Two kinds of patch (roughness 0.3 over 30%, 0.8 over 50%), bare medium over 20%.
    k_rough, a_rough = matte_slab_kernel(GRID, MatteSlab(**medium, eta=1.5, alpha=0.8))
    k_two, a_two = matte_slab_kernel(GRID, MatteSlab(**medium, eta=1.5, alpha=0.3,
                                                     coverage=0.3, alpha2=0.8, coverage2=0.5))
    np.testing.assert_allclose(k_two, 0.3 * k_full + 0.5 * k_rough + 0.2 * k_bare, rtol=1e-10,
                               atol=1e-14)
    np.testing.assert_allclose(a_two, 0.3 * a_full + 0.5 * a_rough, rtol=1e-12)


def test_top_layer_of_the_medium():
    # A top layer absorbing as the medium does is the medium; a very thick one is its own thick
    # medium; a less absorbing one reflects more.
    medium = {"albedo": np.array([0.98, 0.9]), "g1": 0.5, "flakes": 0.4, "cone_deg": 40.0,
              "cone_spread_deg": 20.0}
    plain = medium_reflection(GRID, MatteSlab(**medium))
    same = medium_reflection(GRID, MatteSlab(**medium, top_thickness=3.0, top_absorption=1.0))
    np.testing.assert_allclose(same, plain, atol=1e-12)
    deep = medium_reflection(GRID, MatteSlab(**medium, top_thickness=200.0, top_absorption=0.3))
    whiter = medium_reflection(GRID, MatteSlab(**{**medium, "albedo": 1.0 - 0.3 * (
        1.0 - medium["albedo"])}))
    np.testing.assert_allclose(deep, whiter, atol=1e-12)
    scale0 = AD.star_scale(GRID)[0]
    thin = medium_reflection(GRID, MatteSlab(**medium, top_thickness=2.0, top_absorption=0.3))
    assert np.all(AD.star_albedo(thin[:, 0], scale0) > AD.star_albedo(plain[:, 0], scale0))


def test_the_medium_over_a_black_base():
    # Very thick, it is the thick medium; thinner, it reflects less at every incidence, and
    # less the more nearly normal the light (its path to the black base is shorter); with no
    # thickness there is nothing to reflect.
    medium = {"albedo": np.array([0.98, 0.9]), "g1": 0.5, "flakes": 0.4, "cone_deg": 40.0,
              "cone_spread_deg": 20.0}
    plain = medium_reflection(GRID, MatteSlab(**medium))
    deep = medium_reflection(GRID, MatteSlab(**medium, thickness=400.0))
    np.testing.assert_allclose(deep, plain, atol=1e-9)
    scale0 = AD.star_scale(GRID)[0]
    thick_albedo = AD.star_albedo(plain[:, 0], scale0)
    thin_albedo = AD.star_albedo(
        medium_reflection(GRID, MatteSlab(**medium, thickness=2.0))[:, 0], scale0)
    assert np.all(thin_albedo < thick_albedo)
    lost = 1.0 - thin_albedo / thick_albedo  # the share the black base takes, by incidence
    mu = np.cos(GRID.theta)
    assert np.all(lost[..., np.argmax(mu)] > lost[..., np.argmin(mu)])


def test_a_top_layer_over_the_finite_medium():
    # A top layer absorbing as the medium does, over the medium at a finite thickness, is the
    # medium as thick as both over the black base.
    medium = {"albedo": np.array([0.98, 0.9]), "g1": 0.5, "flakes": 0.4, "cone_deg": 40.0,
              "cone_spread_deg": 20.0}
    layered = medium_reflection(GRID, MatteSlab(**medium, thickness=2.0, top_thickness=1.5,
                                                top_absorption=1.0))
    whole = medium_reflection(GRID, MatteSlab(**medium, thickness=3.5))
    np.testing.assert_allclose(layered, whole, atol=1e-10)
