"""Registering the add-on (makeup_skin_addon.register, unregister): unregistering leaves
no class, property or timer behind."""

def test_unregister_leaves_nothing(addon, bpy_factory):
    import bpy

    from makeup_skin_addon import live

    def ours():
        # Panels and menus by class name; operators by bl_idname (MAKEUP_SKIN_OT_apply).
        return [name for name in dir(bpy.types) if name.startswith(("MAKEUPSKIN", "MAKEUP_SKIN"))]

    assert len(ours()) == 8 and hasattr(bpy.types.Material, "makeup_skin")  # + Fit to Scene, Revert
    addon.unregister()
    try:
        assert not hasattr(bpy.types.Material, "makeup_skin")
        assert ours() == []
        assert not bpy.app.timers.is_registered(live.rebake_timer)
        assert live.pending() == set()
    finally:
        addon.register()
