"""The live preview (makeup_skin_addon.live): a setting that changes the tables re-bakes at
preview resolution, and no timer is left behind."""

import json

from support.addon_steps import apply_pipeline


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
