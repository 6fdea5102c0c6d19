"""Live update while sliders move.

Socket-level settings (coverage, absorption, skin colour, subsurface scale, gloss) go straight
to the material's group node.  Settings that change the tables (skin, film overrides, tier) mark the
material dirty and start one debounce timer (:func:`rebake_timer`); when it fires, every dirty
material is re-baked at preview resolution and its group rebuilt in place (copied first if other
materials share it).
Without an event loop (headless) timers never fire: :func:`flush` does the same work at once.
:func:`unregister` removes the timer, so none is left behind (bpy 4.5 hangs at exit otherwise).
"""

from __future__ import annotations

import bpy

from . import material as made_up

__all__ = ["DEBOUNCE_S", "sockets_changed", "tables_changed", "flush", "pending",
           "rebake_timer", "register", "unregister"]

DEBOUNCE_S = 0.3
"""Seconds without a further change before a preview re-bake runs."""
PREVIEW = "preview"

_dirty: set[str] = set()
_messages: list[str] = []


def _material_of(settings):
    material = settings.id_data
    return material if isinstance(material, bpy.types.Material) else None


def sockets_changed(settings) -> None:
    """A socket-level setting moved: set the group node's sockets."""
    material = _material_of(settings)
    if material is not None and settings.is_made_up:
        made_up.update_sockets(material)


def tables_changed(settings) -> None:
    """A setting the tables depend on moved: schedule a preview re-bake (debounced)."""
    material = _material_of(settings)
    if material is None or not settings.is_made_up or not settings.live_update:
        return
    _dirty.add(material.name)
    if bpy.app.background:
        return  # no event loop: flush() runs the re-bake when asked
    if bpy.app.timers.is_registered(rebake_timer):
        bpy.app.timers.unregister(rebake_timer)
    bpy.app.timers.register(rebake_timer, first_interval=DEBOUNCE_S)


def pending() -> set[str]:
    """Names of materials waiting for a preview re-bake."""
    return set(_dirty)


def rebake_timer():
    """The debounce timer's function (registered with ``bpy.app.timers``): :func:`flush`,
    once."""
    flush()
    return None  # one shot


def flush(context=None) -> list[str]:
    """Re-bake every dirty material at preview resolution now; returns report messages."""
    context = context or bpy.context
    messages = []
    while _dirty:
        material = bpy.data.materials.get(_dirty.pop())
        if material is None or not material.makeup_skin.is_made_up:
            continue
        try:
            made_up.refuse_linked(None, material)
        except made_up.LinkedDataError as error:
            messages.append(f"Made-up Skin: no preview: {error}.")
            continue
        node = made_up.group_of(material)
        group = node.node_tree if node is not None else None
        if group is not None and group.users > 1:
            group = group.copy()  # others keep their look; this material gets its own
        try:
            made_up.rebuild_from_settings(context, material, group, PREVIEW)
        except (ValueError, RuntimeError) as error:
            messages.append(f"Made-up Skin: the preview of {material.name!r} failed: {error}.")
    _messages.extend(messages)
    return messages


def register():
    _dirty.clear()


def unregister():
    if bpy.app.timers.is_registered(rebake_timer):
        bpy.app.timers.unregister(rebake_timer)
    _dirty.clear()
    _messages.clear()
    made_up.clear_cache()
