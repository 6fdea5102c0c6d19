"""A foundation's shade with the film as a slab (lut_baker.model.slab_shade): the thick limit's
colour against absorption, read both ways from its table as the exact root gives it, the
measured products' colours reached, and the shipped tables as computed."""

import numpy as np
import pytest

from lut_baker.model import film_slab as FS
from lut_baker.model import presets, slab_skin
from lut_baker.model import slab_shade as SS
from lut_baker.numerics.quadrature import hemisphere_panels

GRID = hemisphere_panels(*SS.CURVE_GRID)


def exact_absorption(film, target):
    """The exact root: the absorption whose foundation slab (the paper film's body), infinitely
    thick under its own surface, has ``target`` under uniform light."""
    absorption, _ = FS.solve_thick_absorption(
        target, slab_skin.measured_film(film), presets.paper().film_transmission, GRID,
        face=FS.face_albedo(film, GRID))
    return absorption


@pytest.mark.parametrize("name", ["paper_natural", "clarins_105"])
def test_the_table_reads_as_the_exact_root(name):
    """Colours drawn over the reachable range: the table's absorption within 5e-4 of the exact
    root (linear interpolation between 121 nodes), its colour back
    within 1e-4; the colour falls with the absorption."""
    film = presets.foundation_film(name)
    curve = SS.preset_curve(name)
    assert np.all(np.diff(curve.colours, axis=0) < 0.0)
    lightest, darkest = curve.colours[0, 0], curve.colours[-1, 0]
    targets = np.random.default_rng(3).uniform(darkest + 0.01, lightest - 0.01, (6, 3))
    for target in targets:
        a, clamped = curve.absorption(target)
        assert not np.any(clamped)
        np.testing.assert_allclose(a, exact_absorption(film, target), atol=1.5e-4)
        np.testing.assert_allclose(curve.colour(a), target, atol=1e-4)


def test_the_measured_products_in_the_bottle():
    """Each measured product's colour is its slab's thick limit at the absorption the table
    gives (the lighter-than-reachable red of Clarins 105 clamped at 0), and the stored
    absorptions (derived from the stacked thick layer) are not that limit's."""
    for name, entry in presets.FOUNDATIONS.items():
        if "colour" not in entry:
            continue
        curve = SS.preset_curve(name)
        a, clamped = curve.absorption(entry["colour"])
        reached = SS.thick_limit_colours(presets.foundation_film(name),
                                         presets.paper().film_transmission, GRID, a)
        colour = np.diagonal(reached)
        np.testing.assert_allclose(np.where(clamped, 0.0, colour - entry["colour"]), 0.0,
                                   atol=1e-4, err_msg=name)
        assert not np.allclose(a, entry["absorption"], atol=1e-3), name
    assert SS.preset_curve("clarins_105").absorption(
        presets.FOUNDATIONS["clarins_105"]["colour"])[1][0]


def test_the_shipped_tables_are_the_computed_ones():
    """lut_baker/model/slab_shades.json against a fresh computation (run
    ``python tools/slab_shades.py`` after changing the film's model): the same numbers, up to
    how far the computation moves between machines (1e-9)."""
    shipped = SS.read_curves()
    fresh = SS.preset_curves()
    assert set(shipped) == set(fresh) == set(presets.FOUNDATIONS)
    for name, curve in fresh.items():
        np.testing.assert_array_equal(shipped[name].absorption_nodes, curve.absorption_nodes)
        np.testing.assert_allclose(shipped[name].colours, curve.colours, rtol=0, atol=1e-9,
                                   err_msg=name)
