"""The live preview (makeup_skin_addon.live): a setting that changes the tables re-bakes at
preview resolution, and no timer is left behind."""

import json

import pytest
from support.addon_steps import apply_pipeline

from lut_baker.model import presets


def test_live_update_rebakes_at_preview_resolution(sphere):
    import bpy

    from makeup_skin_addon import live

    material, _ = apply_pipeline(sphere, "PRINCIPLED", resolution="preview")
    node = material.node_tree.nodes["Made-up Skin"]
    before = node.node_tree["makeup_skin_fit"]
    material.makeup_skin.skin = "jensen_skin2"  # changes the tables
    assert material.name in live.pending()
    assert live.flush(bpy.context) == []
    assert not live.pending()
    after = node.node_tree["makeup_skin_fit"]
    assert json.loads(after)["key"] != json.loads(before)["key"]
    assert not bpy.app.timers.is_registered(live.rebake_timer)


def test_choosing_a_foundation_updates_its_gloss_live(sphere):
    """The Foundation dropdown sets everything the product is: its absorption at once, its
    gloss (the film's lobe: roughness, index) by the debounced preview re-fit."""
    from makeup_skin_addon import live, nodes
    from makeup_skin_addon import material as made_up

    material, _ = apply_pipeline(sphere, "LAYERED", foundation="clarins_103")
    matte = nodes.read_meta(made_up.group_of(material).node_tree)
    material.makeup_skin.foundation = "clarins_112"
    assert material.name in live.pending()
    assert list(material.makeup_skin.absorption) == pytest.approx(
        presets.FOUNDATIONS["clarins_112"]["absorption"])
    live.flush()
    dewy = nodes.read_meta(made_up.group_of(material).node_tree)
    assert dewy["parameters"]["film"] != matte["parameters"]["film"]
    assert dewy["parameters"]["film"]["P_s"] > 0.0 == matte["parameters"]["film"]["P_s"]
    assert dewy["glossy"]["film_gloss"] != matte["glossy"]["film_gloss"]


def test_roughness_moves_the_gloss_live_and_a_picked_colour_at_once(sphere):
    """Film and Skin Roughness re-fit the preview (the film's and the skin's lobe in the bake);
    a colour picked sets the group's absorption at once, with no re-bake."""
    from support.addon_steps import counts

    from makeup_skin_addon import live, nodes
    from makeup_skin_addon import material as made_up

    material, _ = apply_pipeline(sphere, "LAYERED", resolution="preview")
    settings = material.makeup_skin
    before = nodes.read_meta(made_up.group_of(material).node_tree)["parameters"]
    settings.film_roughness = 0.4
    settings.skin_roughness = 0.55
    assert material.name in live.pending()
    live.flush()
    after = nodes.read_meta(made_up.group_of(material).node_tree)["parameters"]
    assert after["film"]["n"] > before["film"]["n"] and after["skin"]["n"] > before["skin"]["n"]
    groups = counts()[0]
    settings.absorption_mode = "COLOUR"
    settings.shade_colour = presets.FOUNDATIONS["clarins_108"]["colour"]
    node = made_up.group_of(material)
    assert tuple(node.inputs["Foundation Absorption"].default_value)[:3] == pytest.approx(
        presets.FOUNDATIONS["clarins_108"]["absorption"], abs=1e-6)
    assert not live.pending() and counts()[0] == groups
