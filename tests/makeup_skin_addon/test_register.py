"""Registering the add-on (makeup_skin_addon.register, unregister): unregistering leaves
no class, property, timer or handler behind; a script that registers it and never unregisters
still ends; what the registered classes show (labels, names, tooltips) is complete and spells
"Color" as Blender does."""

import pytest
from support.addon_steps import ui_texts
from support.process_exit import bpy_importable, run_to_exit


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


PIPELINE = """
    import bpy
    import makeup_skin_addon
    from makeup_skin_addon import on_load

    makeup_skin_addon.register()
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)  # load_post runs
    assert on_load.check_on_load in bpy.app.handlers.load_post
    print("registered, never unregistered")
"""


@pytest.mark.bpy
def test_a_script_that_registers_and_never_unregisters_ends(tmp_path):
    """A pipeline script imports bpy, registers the add-on and ends without unregistering it:
    the process ends, exit code 0, nothing raised on the way out (bpy 4.5 hangs at exit while
    the add-on's handler or classes stay registered, unless the add-on's exit hook removes
    them)."""
    if not bpy_importable():  # pragma: no cover - CI has bpy
        pytest.skip("bpy is not importable; run with the venv from tools/venv.sh")
    done = run_to_exit(PIPELINE, tmp_path)
    assert done.returncode == 0, done.stderr
    assert "registered, never unregistered" in done.stdout
    assert "Traceback" not in done.stderr, done.stderr


def test_unregister_twice_and_register_twice_change_nothing(addon, bpy_factory):
    """What the exit hook relies on: enabled as an extension, the add-on is unregistered by
    the hook and then disabled by Blender's own exit, which must do nothing (no error); a
    second register neither raises nor adds a second handler."""
    import bpy

    from makeup_skin_addon import on_load

    addon.register()
    assert bpy.app.handlers.load_post.count(on_load.check_on_load) == 1
    addon.unregister()
    try:
        addon.unregister()
        assert not hasattr(bpy.types.Material, "makeup_skin")
        assert on_load.check_on_load not in bpy.app.handlers.load_post
    finally:
        addon.register()
    assert hasattr(bpy.types.Material, "makeup_skin")


def test_every_property_operator_panel_and_menu_has_a_tooltip(addon):
    """Every registered class of the add-on, walked from Blender's types (property groups and
    their pointers, operators and their properties, panels, menus): a label or name, and a
    tooltip, for the class, each property and each enum item (hidden properties show none)."""
    texts = ui_texts()
    where = {at.split(".")[0].split("[")[0] for at, _, _ in texts}
    assert {"makeup_skin", "MakeupSkinSettings", "Material", "MAKEUPSKIN_PT_material",
            "MAKEUPSKIN_PT_node_editor", "MAKEUPSKIN_MT_presets"} <= where, where
    empty = [(at, kind) for at, kind, text in texts if not text.strip()]
    assert empty == []
    assert ("Material.makeup_skin", "name", "Made-up Skin") in texts


def test_the_interface_spells_color_as_blender_does(addon):
    """Blender's interface says "Color": no label, name or tooltip of the add-on says
    "colour" (identifiers in code are not shown)."""
    texts = ui_texts()
    assert len(texts) > 100
    assert [(at, kind, text) for at, kind, text in texts if "colour" in text.lower()] == []
