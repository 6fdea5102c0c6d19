"""Registering the add-on (makeup_skin_addon.register, unregister): unregistering leaves
no class, property, timer or handler behind."""

def test_unregister_leaves_nothing(addon, bpy_factory):
    import bpy

    from makeup_skin_addon import live, on_load

    def ours():
        # Panels and menus by class name; operators by bl_idname (MAKEUP_SKIN_OT_apply).
        return [name for name in dir(bpy.types) if name.startswith(("MAKEUPSKIN", "MAKEUP_SKIN"))]

    def our_handlers():
        lists = [getattr(bpy.app.handlers, name) for name in dir(bpy.app.handlers)
                 if isinstance(getattr(bpy.app.handlers, name), list)]
        return [handler for handlers in lists for handler in handlers
                if getattr(handler, "__module__", "").startswith("makeup_skin_addon")]

    # Apply, Revert, Check Tables, Fit to Scene, Match Skin, Shade Step, the preset operator and
    # menu, two panels.
    assert len(ours()) == 10 and hasattr(bpy.types.Material, "makeup_skin")
    assert our_handlers() == [on_load.check_on_load]
    addon.unregister()
    try:
        assert not hasattr(bpy.types.Material, "makeup_skin")
        assert ours() == []
        assert our_handlers() == []
        assert not bpy.app.timers.is_registered(live.rebake_timer)
        assert live.pending() == set()
    finally:
        addon.register()
