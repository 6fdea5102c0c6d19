"""The panel's settings (makeup_skin_addon.properties): coverage, absorption and the
foundation's shade are socket values of the group node, set without a re-bake."""

import pytest
from support.addon_steps import apply_pipeline, counts


def test_coverage_and_absorption_are_sockets(sphere):
    """With the paper's film the shade is a socket (the film at a thickness bakes it)."""
    material, _ = apply_pipeline(sphere, "PRINCIPLED", film_mode="PAPER")
    node = material.node_tree.nodes["Made-up Skin"]
    groups = counts()[0]
    material.makeup_skin.coverage = 0.25
    material.makeup_skin.absorption = (0.1, 0.3, 0.5)
    assert node.inputs["Coverage"].default_value == pytest.approx(0.25)
    assert tuple(node.inputs["Foundation Absorption"].default_value)[:3] == pytest.approx(
        (0.1, 0.3, 0.5))
    material.makeup_skin.foundation = "deep_mocha"  # sets the shade's absorption
    from lut_baker.model.presets import FOUNDATIONS

    assert tuple(node.inputs["Foundation Absorption"].default_value)[:3] == pytest.approx(
        FOUNDATIONS["deep_mocha"]["absorption"])
    assert counts()[0] == groups  # no re-bake for socket-level settings


def test_the_defaults_and_ranges(addon, blank_scene):
    """A first Apply that looks like makeup (docs/addon.md): coverage 0.6, the shade picked by
    its colour (the default film's, unabsorbed) and matched at the first Apply, the film's
    normal following the pores at half strength; Film and Skin Roughness as Blender roughness,
    Film Roughness the paper film's, ending where the lobe is 60 degrees wide (the white
    furnace, docs/stability.md), Skin Roughness starting where a first Apply still takes under
    a second."""
    import bpy

    from lut_baker.model import roughness, thick_layer
    from makeup_skin_addon import properties

    settings = bpy.data.materials.new("Skin").makeup_skin
    assert settings.coverage == pytest.approx(0.6)
    assert settings.absorption_mode == "COLOUR" and settings.shade_source == "DEFAULT"
    assert tuple(settings.shade_colour) == pytest.approx(
        (float(thick_layer.stack_reflectance(0.0, thick_layer.preset_film_exchange())),) * 3,
        abs=1e-6)
    assert settings.film_follows_pores and settings.film_normal_strength == pytest.approx(0.5)
    rna = type(settings).bl_rna.properties
    assert float(roughness.lobe_width_deg(rna["film_roughness"].hard_max)) == pytest.approx(
        60.0, abs=1e-3)
    assert rna["skin_roughness"].hard_min == pytest.approx(properties.SKIN_ROUGHNESS_MIN)
    assert float(roughness.lobe_width_deg(properties.SKIN_ROUGHNESS_MIN)) == pytest.approx(
        12.0, abs=0.01)
    assert settings.film_roughness == pytest.approx(0.7294, abs=1e-4)
    assert settings.skin_roughness == pytest.approx(0.6816, abs=1e-4)  # the bio-plate's
