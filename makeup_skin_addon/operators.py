"""Operators: Apply, Revert, Check Tables, and the preset menu's add/remove operator."""

from __future__ import annotations

import bpy
from bl_operators.presets import AddPresetBase

from . import convert
from . import material as made_up
from .package import lut_baker

__all__ = ["MAKEUPSKIN_OT_apply", "MAKEUPSKIN_OT_revert", "MAKEUPSKIN_OT_check_tables",
           "MAKEUPSKIN_OT_add_preset", "MAKEUPSKIN_MT_presets", "PRESET_SUBDIR", "register",
           "unregister"]

PRESET_SUBDIR = "makeup_skin"
"""Folder under Blender's ``presets`` where parameter sets are saved."""


class _ObjectPoll:
    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type in {"MESH", "CURVE", "SURFACE", "META", "FONT"}


class MAKEUPSKIN_OT_apply(_ObjectPoll, bpy.types.Operator):
    """Bake and fit the made-up skin and make it the surface of the active object's material,
    converted in place: the previous surface shader is kept, framed and disconnected, and its
    albedo and normal links are carried over"""

    bl_idname = "makeup_skin.apply"
    bl_label = "Apply Made-up Skin"
    bl_options = {"REGISTER", "UNDO"}

    resolution: bpy.props.EnumProperty(
        name="Resolution", items=(("SETTINGS", "From Settings", "The material's bake resolution"),
                                  ("preview", "Preview", ""), ("default", "Default", ""),
                                  ("high", "High", "")),
        default="SETTINGS", options={"SKIP_SAVE"})

    def execute(self, context):
        obj = context.active_object
        resolution = None if self.resolution == "SETTINGS" else self.resolution
        try:
            material, messages = made_up.apply_to_object(context, obj, resolution=resolution)
        except (ValueError, RuntimeError) as error:
            self.report({"ERROR"}, f"Made-up Skin: {_sentence(error)}")
            return {"CANCELLED"}
        for message in messages:
            self.report({"INFO"}, f"Made-up Skin: {message}")
        self.report({"INFO"}, f"Made-up Skin: {material.name!r} on {obj.name!r} is made up.")
        return {"FINISHED"}


class MAKEUPSKIN_OT_revert(bpy.types.Operator):
    """Give the active material back the surface shader it had before Apply and remove the
    Made-up Skin node (the settings stay for a later Apply)"""

    bl_idname = "makeup_skin.revert"
    bl_label = "Revert to Previous Surface"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and convert.can_revert(obj.active_material)

    def execute(self, context):
        try:
            message = made_up.revert_material(context.active_object.active_material)
        except ValueError as error:
            self.report({"ERROR"}, f"Made-up Skin: {_sentence(error)}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Made-up Skin: {message}")
        return {"FINISHED"}


class MAKEUPSKIN_OT_check_tables(bpy.types.Operator):
    """Check every Made-up Skin material against the record of its bake and the hashes of the
    images its render reads; repair what is missing or damaged by re-baking"""

    bl_idname = "makeup_skin.check_tables"
    bl_label = "Check Made-up Skin Tables"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        checked = 0
        for material in list(bpy.data.materials):
            if not material.makeup_skin.is_made_up:
                continue
            checked += 1
            try:
                intact, sentence = made_up.check_material(context, material)
            except (ValueError, RuntimeError) as error:
                intact = False
                sentence = f"{material.name!r} could not be repaired: {_sentence(error)}"
            self.report({"INFO" if intact else "WARNING"}, f"Made-up Skin: {sentence}")
        if not checked:
            self.report({"INFO"}, "Made-up Skin: no made-up material in this file.")
        return {"FINISHED"}


def _sentence(error) -> str:
    """An exception's message as a sentence: capital first letter, final full stop."""
    text = str(error).strip() or type(error).__name__
    text = text[0].upper() + text[1:]
    return text if text.endswith((".", "!", "?")) else text + "."


class MAKEUPSKIN_MT_presets(bpy.types.Menu):
    bl_label = "Made-up Skin Presets"
    preset_subdir = PRESET_SUBDIR
    preset_operator = "script.execute_preset"
    draw = bpy.types.Menu.draw_preset


class MAKEUPSKIN_OT_add_preset(AddPresetBase, bpy.types.Operator):
    """Save or remove a Made-up Skin parameter set"""

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.active_material is not None

    bl_idname = "makeup_skin.add_preset"
    bl_label = "Add Made-up Skin Preset"
    preset_menu = "MAKEUPSKIN_MT_presets"
    preset_subdir = PRESET_SUBDIR
    # The active object's material: also defined in the shader editor, unlike context.material.
    preset_defines = ["settings = bpy.context.object.active_material.makeup_skin"]
    preset_values = [
        "settings.foundation", "settings.skin", "settings.coverage", "settings.absorption_mode",
        "settings.absorption", "settings.foundation_colour", "settings.skin_colour",
        "settings.subsurface_scale", "settings.gloss", "settings.subsurface_method",
        "settings.override_film", "settings.film_lobe_width", "settings.film_ior",
        "settings.tier", "settings.resolution",
    ]


classes = (MAKEUPSKIN_OT_apply, MAKEUPSKIN_OT_revert, MAKEUPSKIN_OT_check_tables,
           MAKEUPSKIN_MT_presets,
           MAKEUPSKIN_OT_add_preset)


_register, unregister = bpy.utils.register_classes_factory(classes)


def register():
    lut_baker()  # fail early (and clearly) if the bundled lut_baker cannot be imported
    _register()
