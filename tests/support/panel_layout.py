"""A stand-in for Blender's ``UILayout`` (headless Blender draws no panels): the add-on's panel
draw functions (makeup_skin_addon/ui.py) draw into it, and it records what they drew.

Used by tests/makeup_skin_addon/test_ui.py (what the panel shows) and bench/apply.py (how long
one draw takes).
"""

from __future__ import annotations

__all__ = ["RecordingLayout"]


class RecordingLayout:
    """Records ``("prop", name, text, enabled)``, ``("label", text)``, ``("operator",
    idname)`` and ``("menu",)`` in ``drawn`` (shared with the rows, columns and boxes it
    hands out); ignores separators."""

    def __init__(self, drawn=None):
        self.drawn = [] if drawn is None else drawn
        self.use_property_split = self.use_property_decorate = False
        self.enabled = self.active = True

    def _child(self, *args, **kwargs):
        return RecordingLayout(self.drawn)

    row = column = box = _child

    def prop(self, data, name, **kwargs):
        self.drawn.append(("prop", name, kwargs.get("text"), self.enabled))

    def label(self, text="", **kwargs):
        self.drawn.append(("label", text))

    def operator(self, idname, **kwargs):
        self.drawn.append(("operator", idname))
        return type("Properties", (), {})()

    def menu(self, *args, **kwargs):
        self.drawn.append(("menu",))

    def separator(self, *args, **kwargs):
        pass
