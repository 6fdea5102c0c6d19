"""The panels (makeup_skin_addon.ui), drawn into a stand-in layout (headless Blender draws no
panels): Apply before, Revert after, and a linked Skin Color shown as linked."""

from support.addon_steps import apply_operator
from support.panel_layout import RecordingLayout


def test_panel_shows_revert_and_a_linked_skin_colour(head):
    import bpy

    from makeup_skin_addon import ui

    layout = RecordingLayout()
    ui.draw_settings(layout, bpy.context)
    assert ("operator", "makeup_skin.apply") in layout.drawn
    apply_operator(head)
    layout = RecordingLayout()
    ui.draw_settings(layout, bpy.context)
    assert ("operator", "makeup_skin.revert") in layout.drawn
    assert ("prop", "skin_colour", "Skin Color (linked)", False) in layout.drawn
