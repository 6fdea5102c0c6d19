"""Panels: Material properties and the shader editor's sidebar (tab "Made-up Skin").

Both draw :func:`draw_settings` (the settings, Apply and Revert, the group's record and
errors, a repair made when the file was opened) and then :func:`draw_fit` (the Fit to Scene
button and the last choice).
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import bpy

from . import groups, on_load, shade, tier_choice
from .core import presets
from .keys import AUTO_KEY, CLASS_PREFIX, ERRORS_KEY, FIT_KEY
from .operators import (
    MAKEUPSKIN_MT_presets,
    MAKEUPSKIN_OT_add_preset,
    MAKEUPSKIN_OT_apply,
    MAKEUPSKIN_OT_check_tables,
    MAKEUPSKIN_OT_fit_to_scene,
    MAKEUPSKIN_OT_match_skin,
    MAKEUPSKIN_OT_revert,
    MAKEUPSKIN_OT_shade_step,
)
from .skin_model import PAPER_FILM

__all__ = ["MAKEUPSKIN_PT_material", "MAKEUPSKIN_PT_node_editor", "draw_settings", "draw_fit",
           "register", "unregister"]


def _errors_text(material) -> list[str]:
    lines = []
    try:
        errors = json.loads(material.get(ERRORS_KEY, "{}"))
    except ValueError:
        errors = {}
    for tier, error in errors.items():
        lines.append(f"{tier.title()}: {100 * error['rms']:.1f}% RMS, "
                     f"albedo {100 * error['albedo']:.1f}%")
    return lines


def _auto_text(material) -> str:
    """What Tier = Auto chose at the last Apply (:data:`.keys.AUTO_KEY`): the panel shows it,
    it never chooses (choosing may need a bake)."""
    try:
        auto = json.loads(material.get(AUTO_KEY, "{}"))
    except ValueError:
        auto = {}
    if "tier" not in auto:
        return "Auto: chosen at Apply"
    return f"Auto: {auto['tier'].title()} (at the last Apply)"


def node_input_linked(node, name: str) -> bool:
    """Whether the group node's input ``name`` is linked (a texture drives it)."""
    socket = node.inputs.get(name) if node is not None else None
    return bool(socket is not None and socket.is_linked)


def _draw_shade(col, settings) -> None:
    """Shade By, the colour or the absorption, Match Skin and the steps, and what the last
    pick or match could not reach (stored when it ran: nothing is solved here)."""
    col.prop(settings, "absorption_mode", expand=True)
    if settings.absorption_mode == "COLOUR":
        col.prop(settings, "shade_colour")
    else:
        col.prop(settings, "absorption", text="Absorption RGB")
    row = col.row(align=True)
    row.operator(MAKEUPSKIN_OT_match_skin.bl_idname, icon="EYEDROPPER")
    row.operator(MAKEUPSKIN_OT_shade_step.bl_idname, text="Lighter").direction = "LIGHTER"
    row.operator(MAKEUPSKIN_OT_shade_step.bl_idname, text="Darker").direction = "DARKER"
    if settings.shade_source == "DEFAULT":
        col.label(text="Shade: matched to the skin at the first Apply", icon="INFO")
    elif settings.shade_source == "MATCH":
        col.label(text="Shade: matched to the skin", icon="INFO")
    if settings.shade_note:
        col.label(text=settings.shade_note, icon="ERROR")


def _draw_film(col, settings) -> None:
    """Film Roughness (inactive for a matte product: no surface gloss), the film's normal,
    the index and its override."""
    rough = col.row()
    matte = settings.foundation in presets.FOUNDATIONS and not shade.has_film_gloss(
        settings.foundation)
    rough.active = not matte
    rough.prop(settings, "film_roughness", slider=True,
               **({"text": "Film Roughness (matte: no gloss)"} if matte else {}))
    col.prop(settings, "film_follows_pores")
    strength = col.row()
    strength.active = settings.film_follows_pores
    strength.prop(settings, "film_normal_strength", slider=True)
    col.prop(settings, "override_film")
    ior = col.row()
    ior.active = settings.override_film
    ior.prop(settings, "film_ior")


def _draw_skin_from_shader(col, settings) -> None:
    """The skin under the film as Apply read it from the artist's shader (greyed: the next
    Apply reads it again; edit the shader)."""
    col.label(text="Skin: the material's own shader (bare, and under the film)",
              icon="SHADING_RENDERED")
    taken = col.column()
    taken.enabled = False
    taken.prop(settings, "skin_roughness", text="Skin Roughness (from the shader)",
               slider=True)
    taken.prop(settings, "skin_ior", text="Skin IOR (from the shader)")
    taken.prop(settings, "subsurface_method", text="Subsurface (from the shader)")


def draw_settings(layout, context) -> None:
    """The panel body, shared by both panels (the active object's material)."""
    obj = context.active_object
    material = obj.active_material if obj is not None else None
    row = layout.row(align=True)
    row.menu(MAKEUPSKIN_MT_presets.__name__, text=MAKEUPSKIN_MT_presets.bl_label)
    row.operator(MAKEUPSKIN_OT_add_preset.bl_idname, text="", icon="ADD")
    row.operator(MAKEUPSKIN_OT_add_preset.bl_idname, text="", icon="REMOVE").remove_active = True
    if material is None:
        layout.label(text="No material: Apply creates one")
        layout.operator(MAKEUPSKIN_OT_apply.bl_idname, icon="MATERIAL")
        return
    settings = material.makeup_skin
    layout.use_property_split = True
    layout.use_property_decorate = False
    col = layout.column()
    col.prop(settings, "foundation")
    col.prop(settings, "film_mode")
    thickness = col.row()
    thickness.active = settings.film_mode != PAPER_FILM
    thickness.prop(settings, "thickness_um", text="Thickness (µm)")
    col.prop(settings, "coverage", slider=True)
    _draw_shade(col, settings)
    col.separator()
    if settings.over_shader:
        _draw_skin_from_shader(col, settings)
    else:
        col.prop(settings, "skin")
        colour = col.row()
        linked = node_input_linked(groups.group_of(material), "Skin Color")
        colour.enabled = not linked
        colour.prop(settings, "skin_colour", **({"text": "Skin Color (linked)"} if linked
                                                 else {}))
        col.prop(settings, "skin_roughness", slider=True)
        col.prop(settings, "subsurface_method")
    col.prop(settings, "subsurface_scale")
    col.prop(settings, "gloss", slider=True)
    col.separator()
    _draw_film(col, settings)
    col.separator()
    col.prop(settings, "tier")
    if settings.tier == "AUTO":
        col.label(text=_auto_text(material), icon="INFO")
    col.prop(settings, "resolution")
    col.prop(settings, "live_update")
    row = layout.row(align=True)
    row.operator(MAKEUPSKIN_OT_apply.bl_idname, icon="MATERIAL")
    row.operator(MAKEUPSKIN_OT_revert.bl_idname, text="", icon="LOOP_BACK")
    node = groups.group_of(material)
    if node is not None and node.node_tree is not None:
        box = layout.box()
        box.label(text=f"Group: {node.node_tree.name}", icon="NODETREE")
        try:
            meta = json.loads(node.node_tree.get(FIT_KEY, "{}"))
        except ValueError:
            meta = {}
        if meta:
            radius = meta.get("profiles", {}).get(meta.get("subsurface_method"), {})
            radius = radius.get("radius_mm", [])
            box.label(text=f"Subsurface: {meta.get('subsurface_method', '?').title()}, radius "
                           + " ".join(f"{r:.2f}" for r in radius) + " mm")
        lines = _errors_text(material)
        if lines:
            box.label(text="Angular error against the tables:")
            for line in lines:
                box.label(text=line)
        notice = on_load.notice(material)  # set when the file was opened: nothing computed
        if notice is not None:
            box.label(text=notice, icon="ERROR")
        box.operator(MAKEUPSKIN_OT_check_tables.bl_idname, icon="CHECKMARK")


def draw_fit(layout, context) -> None:
    """The Fit to Scene button and the last choice (:func:`.tier_choice.last_choice`), below
    :func:`draw_settings` in both panels."""
    layout.operator(MAKEUPSKIN_OT_fit_to_scene.bl_idname, icon="SCENE_DATA")
    last = tier_choice.last_choice(context.material)
    if last is None:
        return
    box = layout.box()
    box.label(text=f"Fit to Scene: {last['candidate']}", icon="INFO")
    box.label(text=f"Predicted error {100 * last['error']:.1f}%, cost {last['cost']:.2f}")


class _SettingsPanel:
    """Shared body: :func:`draw_settings`, then :func:`draw_fit`."""

    bl_label = "Made-up Skin"
    bl_description = ("Foundation on skin: the active object's material made up (Apply, "
                      "Revert), its settings, and Fit to Scene")
    if TYPE_CHECKING:  # bpy.types.Panel's, given by the panel class it is mixed into (an
        layout: Any    # annotation at run time would be taken for a property)

    def draw(self, context: Any) -> None:
        draw_settings(self.layout, context)
        draw_fit(self.layout, context)


class MAKEUPSKIN_PT_material(_SettingsPanel, bpy.types.Panel):
    bl_idname = f"{CLASS_PREFIX}_PT_material"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return context.active_object is not None


class MAKEUPSKIN_PT_node_editor(_SettingsPanel, bpy.types.Panel):
    bl_idname = f"{CLASS_PREFIX}_PT_node_editor"
    bl_space_type = "NODE_EDITOR"
    bl_region_type = "UI"
    bl_category = "Made-up Skin"

    @classmethod
    def poll(cls, context):
        space = context.space_data
        return (space is not None and getattr(space, "tree_type", "") == "ShaderNodeTree"
                and context.active_object is not None)


classes = (MAKEUPSKIN_PT_material, MAKEUPSKIN_PT_node_editor)
register, unregister = bpy.utils.register_classes_factory(classes)
