"""The shade, the film and the skin settings (makeup_skin_addon.shade): the colour seen picked
and solved, the roughness settings in the model."""

import numpy as np
import pytest
from support.addon_steps import apply_pipeline, group_node

from lut_baker.model import presets, thick_layer

PRODUCTS = ("clarins_103", "clarins_105", "clarins_108", "clarins_112")


def _settings(obj):
    settings = obj.active_material.makeup_skin
    settings.live_update = False
    return settings


@pytest.mark.parametrize("name", PRODUCTS)
def test_picking_a_products_colour_gives_its_preset(sphere, name):
    """The measured product's own colour (its bottle) picked in Colour mode, the paper's film:
    the preset's absorption, and the group node has it at once."""
    material, _ = apply_pipeline(sphere, "PRINCIPLED", film_mode="PAPER")
    settings = material.makeup_skin
    settings.absorption_mode = "COLOUR"
    settings.shade_colour = presets.FOUNDATIONS[name]["colour"]
    expected = presets.FOUNDATIONS[name]["absorption"]
    # The panel stores float32: the colour moved by ~3e-8, the absorption by about as much.
    assert tuple(settings.absorption) == pytest.approx(expected, abs=1e-6)
    assert tuple(group_node(material).inputs["Foundation Absorption"].default_value)[:3] == \
        pytest.approx(expected, abs=1e-6)
    assert settings.shade_source == "USER"
    assert (settings.shade_note != "") == (name == "clarins_105")  # 105's red is beyond reach


def test_a_picked_colour_is_the_thick_layer_of_the_solved_film(addon, blank_scene):
    """The paper's film: reachable colours come back from the solved film's thick layer to
    1e-6; a colour too light in red is clamped and the note says so in words; choosing a
    foundation shows its colour."""
    import bpy

    settings = bpy.data.materials.new("Skin").makeup_skin
    settings.film_mode = "PAPER"
    rng = np.random.default_rng(3)
    exchange = thick_layer.preset_film_exchange()
    for colour in rng.uniform(exchange.r_gloss + 0.01, 0.8, size=(5, 3)):
        settings.shade_colour = colour
        stored = np.asarray(settings.shade_colour, float)
        np.testing.assert_allclose(thick_layer.stack_reflectance(
            np.asarray(settings.absorption, float), exchange), stored, atol=1e-6)
        assert settings.shade_note == ""
    settings.shade_colour = (0.95, 0.5, 0.3)
    assert settings.absorption[0] == 0.0
    assert settings.shade_note.startswith("Red 0.950 is lighter than the film can be (0.834)")
    assert settings.shade_note.endswith("clamped")
    settings.foundation = "medium_beige"
    np.testing.assert_allclose(settings.shade_colour, thick_layer.stack_reflectance(
        np.asarray(presets.FOUNDATIONS["medium_beige"]["absorption"]), exchange), atol=1e-6)
    assert settings.shade_note == "" and settings.shade_source == "PRESET"
    settings.absorption = (0.2, 0.4, 0.6)  # by hand: the colour follows
    np.testing.assert_allclose(settings.shade_colour, thick_layer.stack_reflectance(
        np.array([0.2, 0.4, 0.6]), exchange), atol=1e-6)


def test_with_the_film_at_a_thickness_the_bottle_is_the_slabs_thick_limit(addon, blank_scene):
    """Film at a Thickness: a preset's absorption is the one whose slab, infinitely thick, has
    the product's colour (within the table's 1e-4 of the exact limit); a picked colour the
    same; switching Film keeps the bottle's colour and moves the absorption (a preset back to
    its own), and an absorption typed by hand keeps its value."""
    import bpy

    from lut_baker.model import slab_shade
    from lut_baker.numerics.quadrature import hemisphere_panels

    settings = bpy.data.materials.new("Skin").makeup_skin
    settings.live_update = False
    settings.film_mode = "SLAB"
    settings.foundation = "clarins_108"
    colour = np.asarray(presets.FOUNDATIONS["clarins_108"]["colour"])
    absorption = np.asarray(settings.absorption, float)
    reached = np.diagonal(slab_shade.thick_limit_colours(
        presets.foundation_film("clarins_108"), presets.paper().film_transmission,
        hemisphere_panels(*slab_shade.CURVE_GRID), absorption))
    np.testing.assert_allclose(reached, colour, atol=1e-4)
    assert np.all(absorption < np.asarray(presets.FOUNDATIONS["clarins_108"]["absorption"]))
    np.testing.assert_allclose(settings.shade_colour, colour, atol=1e-6)
    settings.film_mode = "PAPER"  # the preset's own absorption, the same bottle
    np.testing.assert_allclose(settings.absorption,
                               presets.FOUNDATIONS["clarins_108"]["absorption"], atol=1e-6)
    np.testing.assert_allclose(settings.shade_colour, colour, atol=1e-6)
    settings.absorption_mode = "COLOUR"
    settings.shade_colour = (0.6, 0.45, 0.35)  # picked on the paper's film
    paper_absorption = np.asarray(settings.absorption, float)
    settings.film_mode = "SLAB"  # the same colour, the slab's absorption
    np.testing.assert_allclose(settings.shade_colour, (0.6, 0.45, 0.35), atol=1e-6)
    np.testing.assert_allclose(
        slab_shade.preset_curve("clarins_108").colour(settings.absorption), (0.6, 0.45, 0.35),
        atol=1e-5)
    assert not np.allclose(settings.absorption, paper_absorption, atol=1e-3)
    settings.shade_colour = (0.95, 0.5, 0.3)  # lighter than the slab can be in red
    assert settings.absorption[0] == 0.0 and settings.shade_note.startswith("Red 0.950 is "
                                                                            "lighter")
    settings.absorption_mode = "ABSORPTION"
    settings.absorption = (0.2, 0.4, 0.6)  # by hand: kept across Film, its colour the film's
    settings.film_mode = "PAPER"
    np.testing.assert_allclose(settings.absorption, (0.2, 0.4, 0.6), atol=1e-6)
    np.testing.assert_allclose(settings.shade_colour, thick_layer.stack_reflectance(
        np.array([0.2, 0.4, 0.6]), thick_layer.preset_film_exchange()), atol=1e-6)
