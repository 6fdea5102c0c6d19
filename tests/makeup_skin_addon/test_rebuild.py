"""A material's group rebuilt from its settings (makeup_skin_addon.rebuild): in three steps it is
the group a rebuild at once gives (the same record), and a rebuild not yet computed has no
key."""

import pytest
from support.addon_steps import apply_pipeline


def test_a_rebuild_in_steps_is_the_rebuild_at_once(sphere):
    import bpy

    from makeup_skin_addon import groups, nodes, rebuild

    material, _ = apply_pipeline(sphere, "LAYERED", foundation="light_ivory")
    material.makeup_skin.live_update = False
    material.makeup_skin.foundation = "clarins_112"
    steps = rebuild.prepare_rebuild(bpy.context, material, "preview")
    with pytest.raises(AssertionError):
        steps.key  # noqa: B018 - raises before the compute
    work = steps.compute()
    assert steps.key == work.key
    in_steps = bpy.data.node_groups.new("in steps", "ShaderNodeTree")
    rebuild.finish_rebuild(bpy.context, material, in_steps, steps)
    assert groups.group_of(material).node_tree == in_steps
    at_once = bpy.data.node_groups.new("at once", "ShaderNodeTree")
    rebuild.rebuild_from_settings(bpy.context, material, at_once, "preview")
    assert groups.group_of(material).node_tree == at_once
    first, second = nodes.read_meta(in_steps), nodes.read_meta(at_once)
    for key in ("key", "tier", "parameters", "resolution", "measured"):
        assert first.get(key) == second.get(key), key
