"""The panel's settings (makeup_skin_addon.properties): coverage, absorption and the
foundation's shade are socket values of the group node, set without a re-bake."""

import pytest
from support.addon_steps import apply_pipeline, counts


def test_coverage_and_absorption_are_sockets(sphere):
    material, _ = apply_pipeline(sphere, "PRINCIPLED")
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
