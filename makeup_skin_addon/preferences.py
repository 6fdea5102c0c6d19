"""Add-on preferences (Edit > Preferences > Add-ons > Made-up Skin)."""

import bpy

from .package import ROOT_PACKAGE

__all__ = ["MakeupSkinPreferences", "get_preferences", "register", "unregister"]

LUT_RESOLUTIONS = ("32", "64", "128", "256")


class MakeupSkinPreferences(bpy.types.AddonPreferences):
    """User preferences of the add-on, stored by Blender under the root package name."""

    bl_idname = ROOT_PACKAGE

    lut_resolution: bpy.props.EnumProperty(
        name="LUT Resolution",
        description="Default number of samples per axis of a baked lookup table",
        items=[(r, r, f"{r} samples per axis") for r in LUT_RESOLUTIONS],
        default="64",
    )

    def draw(self, context):
        self.layout.prop(self, "lut_resolution")


def get_preferences(context=None) -> MakeupSkinPreferences:
    """Return this add-on's preferences (the add-on must be enabled)."""
    context = context or bpy.context
    return context.preferences.addons[ROOT_PACKAGE].preferences


classes = (MakeupSkinPreferences,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
