"""The table contract (lut_baker.tables.table_set): the grids and their inverses, the
coverage/absorption formula at the nodes, validation, and lookups."""

from dataclasses import replace

import numpy as np
import pytest
from support.samples import node_directions

from lut_baker import bake
from lut_baker.evaluate import made_up
from lut_baker.model import presets
from lut_baker.numerics.geometry import direction
from lut_baker.tables import table_set


@pytest.fixture(scope="module")
def paper():
    return presets.paper()


@pytest.fixture(scope="module")
def default_tables(paper):
    return bake.bake(paper, "default")


# --------------------------------------------------------------------------------------------
# Grids
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("spacing", table_set.THETA_SPACINGS)
def test_theta_index_inverts_theta_nodes(spacing):
    nodes = table_set.theta_nodes(37, spacing, 89.0, 0.05)
    assert nodes[0] == 0.0 and nodes[-1] == 89.0 and np.all(np.diff(nodes) > 0)
    np.testing.assert_allclose(table_set.theta_index(nodes, 37, spacing, 89.0, 0.05),
                               np.arange(37), atol=1e-9)


def test_grazing_spacing_is_denser_at_grazing_than_at_the_normal():
    nodes = table_set.theta_nodes(96, "grazing", 89.0)
    assert nodes[-1] - nodes[-2] < 0.15 < 2.0 < nodes[1] - nodes[0] < 3.0


@pytest.mark.parametrize("spacing", table_set.PHI_SPACINGS)
def test_phi_index_inverts_node_azimuths(default_tables, spacing):
    t = replace(default_tables, phi_spacing=spacing)
    wi, wo = node_directions(t)
    index = table_set.phi_index(wi, wo, t.phi_deg.size, spacing)
    inner = (t.theta_deg[:, None, None] > 0) & (t.theta_deg[None, :, None] > 0)
    expected = np.broadcast_to(np.arange(t.phi_deg.size), index.shape)
    np.testing.assert_allclose(index[np.broadcast_to(inner, index.shape)],
                               expected[np.broadcast_to(inner, index.shape)], atol=1e-5)


def test_half_vector_coordinate_ends_are_true_azimuths():
    wi = direction(np.radians(70.0), 0.0)
    for phi_deg, expected in ((0.0, 0.0), (180.0, 32.0), (-180.0, 32.0), (360.0, 0.0)):
        wo = direction(np.radians(40.0), np.radians(phi_deg))
        assert table_set.phi_index(wi, wo, 33) == pytest.approx(expected, abs=1e-9)


# --------------------------------------------------------------------------------------------
# Coverage and absorption at the nodes
# --------------------------------------------------------------------------------------------
def test_tables_apply_any_coverage_and_absorption_exactly_at_the_nodes(default_tables, paper):
    """Baked at absorption 0, the formula of lut_baker.tables.table_set reproduces the exact
    evaluator for another coverage and RGB absorption (at nodes: no interpolation error)."""
    rng = np.random.default_rng(5)
    n = default_tables.theta_deg.size
    i, j, k = rng.integers(0, n, 60), rng.integers(0, n, 60), rng.integers(0, 65, 60)
    wi, wo = (w[i, j, k] for w in node_directions(default_tables))
    other = paper.replace(coverage=0.3, absorption=(0.2, 0.5, 0.9))
    exact = made_up.made_up_reflection(wi, wo, other)
    table = default_tables.made_up_reflection(wi, wo, coverage=0.3, absorption=(0.2, 0.5, 0.9))
    np.testing.assert_allclose(table, exact, rtol=1e-4, atol=1e-6)


# --------------------------------------------------------------------------------------------
# The table contract
# --------------------------------------------------------------------------------------------
def test_tables_validate_shapes_values_and_grids(default_tables):
    with pytest.raises(ValueError, match="path3_gloss"):
        replace(default_tables, path3_gloss=default_tables.path3_gloss[:, :, :-1])
    bad = np.array(default_tables.path3_gloss)
    bad[1, 2, 3, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        replace(default_tables, path3_gloss=bad)
    with pytest.raises(ValueError, match="'film' layer"):
        replace(default_tables, parameters={k: v for k, v in default_tables.parameters.items()
                                            if k != "film"})
    with pytest.raises(ValueError, match="theta_deg"):
        replace(default_tables, theta_deg=default_tables.theta_deg * 1.001)
    with pytest.raises(ValueError, match="phi_spacing"):
        replace(default_tables, phi_spacing="log")


def test_lookups_below_the_horizon_are_zero(default_tables):
    up, down = np.array([0.0, 0.0, 1.0]), np.array([0.6, 0.0, -0.8])
    assert np.all(default_tables.made_up_reflection(down, up) == 0.0)
    assert np.all(default_tables.made_up_reflection(up, down) == 0.0)


def test_lookups_are_reciprocal(default_tables):
    rng = np.random.default_rng(8)
    wi = direction(np.radians(rng.uniform(0, 89, 50)), rng.uniform(0, 2 * np.pi, 50))
    wo = direction(np.radians(rng.uniform(0, 89, 50)), rng.uniform(0, 2 * np.pi, 50))
    np.testing.assert_allclose(default_tables.made_up_reflection(wi, wo),
                               default_tables.made_up_reflection(wo, wi), rtol=1e-12)


def test_a_surface_layer_is_made_once_per_parameter_set(default_tables):
    """The surface gloss's layer (eq. 2's specular term) is made once for a set of plain
    parameters and shared, its arrays read-only; other parameters give their own layer, and
    unreadable ones are refused each time (the tables check their layers when made)."""
    layer = default_tables.surface_layer("film_gloss")
    assert layer is default_tables.surface_layer("film_gloss") and float(layer.P_d) == 0.0
    assert not layer.P_s.flags.writeable
    film = default_tables.parameters["film"]
    other = replace(default_tables, parameters={**default_tables.parameters,
                                                "film": {**film, "n": 2.0 * film["n"]}})
    assert float(other.surface_layer("film_gloss").n) == 2.0 * film["n"]
    rgb = replace(default_tables, parameters={**default_tables.parameters,
                                              "film": {**film, "P_s": [1.0, 2.0, 3.0]}})
    assert rgb.surface_layer("film_gloss").P_s.tolist() == [1.0, 2.0, 3.0]
    for _ in range(2):  # not cached: refused each time
        with pytest.raises(ValueError, match="parameters"):
            replace(default_tables, parameters={**default_tables.parameters,
                                                "film": {**film, "colour": 1.0}})
