"""The film as a slab in the tables (lut_baker.tables.slab_tables, bake(..., film=thickness)):
the thickness axis's closed form, the tables against the exact closed form at and between the
axis's nodes, the thick limit as the product's colour, and the paper's model untouched."""

import numpy as np
import pytest

from lut_baker import bake as B
from lut_baker.model import film_slab as FS
from lut_baker.model import presets
from lut_baker.model import slab_skin as SS
from lut_baker.numerics import adding_doubling as AD
from lut_baker.numerics.geometry import direction
from lut_baker.numerics.quadrature import hemisphere_panels
from lut_baker.tables import slab_tables as ST

GRID = hemisphere_panels(3, 10, 33)  # the default resolution's quadrature
ABSORPTION = [0.1, 0.3, 0.5]


@pytest.fixture(scope="module")
def skin():
    return presets.made_up_skin("paper_natural", "jensen_skin1", absorption=ABSORPTION)


@pytest.fixture(scope="module")
def tables(skin):
    return B.bake(skin, "default", film=FS.DEFAULT_THICKNESS_UM)


def test_the_thickness_axis():
    nodes = ST.thickness_nodes()
    assert nodes[0] == ST.THICKNESS_MIN_UM and np.isinf(nodes[-1])
    assert nodes[-2] == pytest.approx(ST.THICKNESS_MAX_UM, rel=1e-12)
    assert np.allclose(ST.thickness_index(nodes), np.arange(nodes.size), atol=1e-12)
    x = ST.thickness_index(np.geomspace(0.1, 1e6, 200))
    assert np.all(np.diff(x) >= 0.0) and x[0] == 0.0
    assert ST.thickness_index(600.0) == pytest.approx(nodes.size - 1.5)


@pytest.fixture(scope="module")
def preview_axis(skin):
    return B.bake_slab(skin, "preview")


def _parts_at(slab, um, directions):
    """Every table of ``slab`` read at thickness ``um``: the 1-D parts and ``top`` at
    ``directions`` ``(wi, wo)``."""
    return [*slab.sliced(um).tables, slab.top_at(um, *directions)]


@pytest.mark.parametrize("um", [0.5, 1.0, 2.0, FS.DEFAULT_THICKNESS_UM,
                                float(ST.thickness_nodes()[3]), 300.0, 1000.0, np.inf])
def test_the_tables_at_one_thickness_are_the_axiss_there(skin, preview_axis, um):
    """``bake_slab(..., only_um=h)`` (a preview's) bakes the axis's nodes either side of h
    (one at a node, below the axis or at the thick limit) and interpolates them as the
    lookups do: every table read at h equals the axis's there (measured: to the last bit, the
    same operations; rtol 1e-12 leaves room for a BLAS that splits the products otherwise),
    and another thickness is refused."""
    one = B.bake_slab(skin, "preview", only_um=um)
    assert one.one_thickness and one.thickness_um.tolist() == [um]
    nodes, t = ST.thickness_support(um)
    at_node = um <= ST.THICKNESS_MIN_UM or np.isinf(um) or um in ST.thickness_nodes()
    assert nodes.size == (1 if at_node else 2) and 0.0 <= t < 1.0
    rng = np.random.default_rng(3)
    directions = [w / np.linalg.norm(w, axis=-1, keepdims=True) * np.sign(w[..., 2:])
                  for w in rng.normal(size=(2, 200, 3))]
    for got, expected in zip(_parts_at(one, um, directions),
                             _parts_at(preview_axis, um, directions), strict=True):
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0.0)
    with pytest.raises(ValueError, match="only"):
        one.sliced(2.0 * um if np.isfinite(um) else 300.0)


def test_one_thickness_is_checked_as_isclose_does():
    """Tables at one thickness accept a thickness as ``np.isclose`` at ONE_THICKNESS_RTOL
    decides (a single thickness checked without numpy's array machinery: the same decision,
    infinities and NaN included)."""
    rng = np.random.default_rng(4)
    for baked in (9.6, 0.7, 300.0, np.inf):
        near = baked * (1.0 + rng.uniform(-3e-12, 3e-12, 50))
        for h in [*near, baked, np.nextafter(baked, 0.0), np.inf, -np.inf, np.nan, 0.0]:
            expected = bool(np.isclose(h, baked, rtol=ST.ONE_THICKNESS_RTOL, atol=0.0))
            assert ST._all_close(np.asarray(h, float), float(baked)) == expected, (baked, h)
        assert ST._all_close(np.array([baked, baked]), float(baked))


def test_the_films_albedo_alone_is_the_slices(preview_axis):
    """SlabSlice.film_albedo_at reads the film's albedo alone as at() reads it (the same
    interpolation: the same numbers, bit for bit), on and between the grid's angles."""
    theta = np.concatenate([preview_axis.theta_deg, np.linspace(0.0, 90.0, 37), [12.5]])
    for um in (0.7, 9.6, 300.0):
        found = preview_axis.sliced(um)
        np.testing.assert_array_equal(found.film_albedo_at(theta), found.at(theta).film_albedo)
        np.testing.assert_array_equal(found.film_albedo_at(33.0), found.at(33.0).film_albedo)


def test_the_lookups_share_their_angles(tables):
    """slab_lookup computes what its lookups share once (the surfaces' cosines, the polar
    angles' indices): each the same as looked up alone (the same operations: bit for bit)."""
    rng = np.random.default_rng(2)
    wi = direction(np.radians(rng.uniform(0.0, 90.0, 50)), rng.uniform(0.0, 6.0, 50))
    wo = direction(np.radians(rng.uniform(0.0, 90.0, 50)), rng.uniform(0.0, 6.0, 50))
    slab, um = tables.slab, 20.0
    found = ST.slab_lookup(tables, wi, wo, um)
    np.testing.assert_array_equal(found.top, slab.top_at(um, wi, wo))
    np.testing.assert_array_equal(found.through_i, slab.through_at(um, wi))
    np.testing.assert_array_equal(found.through_o, slab.through_at(um, wo))
    for name in ("film_gloss", "skin_gloss"):
        np.testing.assert_array_equal(getattr(found, name),
                                      tables.surface_gloss(name, wi, wo))


def test_a_bake_at_one_thickness_is_the_bake_there(skin, tables):
    """``bake(..., one_thickness=True)``: the tables of the whole bake, the slab's at its
    thickness only (equal there, rtol 1e-12 as above), the rest as they were."""
    one = B.bake(skin, "default", film=FS.DEFAULT_THICKNESS_UM, one_thickness=True)
    assert one.slab.one_thickness and one.parameters == tables.parameters
    np.testing.assert_allclose(one.path3_gloss, tables.path3_gloss, rtol=1e-12, atol=0.0)
    rng = np.random.default_rng(4)
    directions = [w / np.linalg.norm(w, axis=-1, keepdims=True) * np.sign(w[..., 2:])
                  for w in rng.normal(size=(2, 200, 3))]
    np.testing.assert_allclose(ST.slab_reflection(one, *directions),
                               ST.slab_reflection(tables, *directions), rtol=1e-12, atol=0.0)
    for got, expected in zip(_parts_at(one.slab, FS.DEFAULT_THICKNESS_UM, directions),
                             _parts_at(tables.slab, FS.DEFAULT_THICKNESS_UM, directions),
                             strict=True):
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0.0)


def test_the_paper_mode_is_the_tables_as_they_were(skin, tables):
    """The slab is an addition: the paper's parts are the same computation (bit-identical in
    one process), and the paper mode holds no slab."""
    paper_mode = B.bake(skin, "default", film="paper")
    assert paper_mode.slab is None and "film_thickness_um" not in paper_mode.parameters
    for name, array in paper_mode.arrays.items():
        np.testing.assert_array_equal(getattr(tables, name), array)
    assert tables.parameters["film_thickness_um"] == FS.DEFAULT_THICKNESS_UM
    with pytest.raises(ValueError):
        B.bake(skin, "preview", film="thick")
    with pytest.raises(ValueError):
        B.bake(skin, "preview", film=-1.0)


@pytest.mark.parametrize("um", [1.0, 2.0, FS.DEFAULT_THICKNESS_UM, 50.0, 150.0, 300.0, np.inf])
def test_the_tables_colour_is_the_exact_one(skin, tables, um):
    """Under uniform light, at the axis's nodes and between them (interpolated in log h):
    within 0.6% of the exact closed form (measured: 0.51% at most, 50 um's blue)."""
    albedo = np.pi * np.asarray(skin.skin_reflection.P_d)
    exact = SS.slab_colour(skin.film, skin.film_transmission, skin.skin_reflection, albedo, um,
                           GRID, ABSORPTION)
    assert np.allclose(ST.slab_colour(tables, um), exact, rtol=6e-3)


def test_the_tables_directional_albedo_at_the_quadrature_nodes(skin, tables):
    """At an axis node, the directional albedo from the tables (interpolated from the
    quadrature's nodes to the tables' and back) against the exact one at the nodes."""
    albedo = np.pi * np.asarray(skin.skin_reflection.P_d)
    film = SS.foundation_slab(skin.film, skin.film_transmission, GRID, ABSORPTION)
    h = ST.thickness_nodes()[4]
    parts = SS.slab_skin_parts(film, FS.relative_thickness(h), skin.skin_reflection,
                               FS.face_albedo(skin.film, GRID))
    exact = SS.parts_albedo(parts, albedo, GRID).T
    theta = np.degrees(GRID.theta)
    inside = theta <= 85.0
    from_tables = ST.slab_directional_albedo(tables, theta, h)
    assert np.allclose(from_tables[inside], exact[inside], rtol=3e-3)


def test_the_angular_table_against_the_exact_kernel(skin, tables):
    """``top`` read back at in-plane directions of the quadrature's nodes (the tables' own
    interpolation) against the exact kernel's Fourier series there: within 2% of the peak."""
    h = ST.thickness_nodes()[2]
    film = SS.foundation_slab(skin.film, skin.film_transmission, GRID, ABSORPTION)
    parts = SS.slab_skin_parts(film, FS.relative_thickness(h), skin.skin_reflection,
                               FS.face_albedo(skin.film, GRID))
    kernel = AD.from_star(parts.top, AD.star_scale(GRID))  # (C, M, N, N)
    pick = np.arange(2, GRID.theta.size - 4, 3)
    theta = GRID.theta[pick]
    wi = np.stack([np.sin(theta), 0 * theta, np.cos(theta)], -1)[:, None]
    wo = np.stack([-np.sin(theta), 0 * theta, np.cos(theta)], -1)[None, :]  # azimuth 180
    signs = (-1.0) ** np.arange(kernel.shape[1])
    exact = np.einsum("cmij,m->ijc", kernel[:, :, pick][:, :, :, pick], signs)
    table = tables.slab.top_at(h, wi, wo)
    assert np.max(np.abs(table - exact)) < 0.02 * np.max(exact)


def test_the_thick_limit_is_the_products_colour():
    """The measured products' colours (thick layers): the absorption whose slab, infinitely
    thick under the product's own surface, has that colour, baked: the tables' thick limit
    gives the colour back (105's red, out of reach, left out)."""
    paper = presets.paper()
    stored = presets.read_measured_foundations(presets.MEASURED_FOUNDATIONS_FILE)
    for name in ("clarins_103", "clarins_112"):
        film = presets.foundation_film(name)
        absorption, clamped = FS.solve_thick_absorption(
            stored[name]["colour"], SS.measured_film(film), paper.film_transmission, GRID,
            face=FS.face_albedo(film, GRID))
        skin = presets.made_up_skin(name, "paper_bioplate", absorption=absorption)
        slab = B.bake(skin, "preview", film=50.0)
        colour = ST.slab_colour(slab, np.inf, skin_albedo=0.5)
        kept = ~clamped
        assert np.allclose(colour[kept], np.asarray(stored[name]["colour"])[kept], rtol=3e-3)


def test_the_film_surface_and_the_bodys_gloss_in_the_tables(skin, tables):
    """The film's surface in the tables is k times eq. 2's gloss (closed form); the body's
    share of the gloss (what the tiers draw as gloss) grows with the thickness to (1 - A)
    (1 - k) at the thick end."""
    share = float(FS.surface_share(skin.film))
    assert np.allclose(tables.slab.surface_share, share, rtol=1e-15)
    theta = np.array([0.0, 30.0, 60.0])
    assert np.allclose(ST.surface_gloss_albedo(tables, theta),
                       share * tables.directional("film_gloss_albedo", theta), rtol=1e-15)
    weights = tables.slab.body_gloss
    assert np.all(np.diff(weights[:-1], axis=0) > 0.0)
    assert np.allclose(weights[-1], (1.0 - np.array(ABSORPTION)) * (1.0 - share), rtol=0.02)


def test_the_diffuse_term_is_what_the_brdf_holds_beyond_its_local_part(skin, tables):
    """``slab_reflection`` = its part without the diffuse term + ``slab_diffuse``'s
    ``w covered t(theta_i) t(theta_o) + (1 - w) bare``, at another thickness, albedo and
    coverage too; the diffuse part is what a skin of albedo 0 lacks."""
    rng = np.random.default_rng(3)
    wi, wo = (v / np.linalg.norm(v, axis=-1, keepdims=True)
              for v in np.abs(rng.normal(size=(2, 50, 3))))
    for h, albedo, w in ((None, None, 1.0), (30.0, [0.3, 0.5, 0.7], 0.4)):
        full = ST.slab_reflection(tables, wi, wo, h, albedo, w)
        local = ST.slab_reflection(tables, wi, wo, h, albedo, w, diffuse=False)
        terms = ST.slab_diffuse(tables, h, albedo)
        diffuse = w * terms.covered * terms.through(wi) * terms.through(wo) + (1 - w) * terms.bare
        np.testing.assert_allclose(local + diffuse, full, rtol=1e-12, atol=1e-15)
        assert np.all(diffuse > 0.05 * full)  # the split moves a real share
        np.testing.assert_allclose(ST.slab_reflection(tables, wi, wo, h, [0.0] * 3, w), local,
                                   rtol=1e-12, atol=1e-15)
