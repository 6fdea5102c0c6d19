"""The panel's settings: one :class:`MakeupSkinSettings` per material (``material.makeup_skin``).

Coverage, absorption, skin colour, subsurface scale and gloss are socket values of the material's
group node: moving them updates the material at once.  Foundation and skin presets, film overrides,
tier and resolution change the tables: with live update on, moving them schedules a preview
re-bake (:mod:`.live`); Apply bakes at full resolution.  The settings are registered as
``Material.makeup_skin`` (:data:`.keys.SETTINGS_ATTRIBUTE`).
"""

from __future__ import annotations

import math

import bpy

from . import live
from .core import presets
from .keys import SETTINGS_ATTRIBUTE

__all__ = ["MakeupSkinSettings", "register", "unregister", "TIER_ITEMS"]

TIER_ITEMS = (
    ("AUTO", "Auto", "The cheapest tier within 2% of the best one's error in this scene (camera, "
                     "resolution, object size, lights, engine, samples); Fit to Scene also "
                     "drops the subsurface and gloss the scene does not need"),
    ("PRINCIPLED", "Principled", "One Principled BSDF: coat = film, subsurface = skin; cheapest, "
                                 "no images"),
    ("LAYERED", "Layered", "Glossy, Diffuse and Subsurface closures with view-angle weights "
                           "from a lookup image; closest to the tables in Cycles"),
    ("EEVEE", "EEVEE", "The Layered closures fitted as EEVEE renders them (GGX lobes, its "
                       "own lookup image, Burley subsurface); closest to the tables in EEVEE"),
)
SUBSURFACE_ITEMS = (
    ("AUTO", "Auto", "The method whose shadow-edge blur is closest to the skin's (Burley)"),
    ("BURLEY", "Christensen-Burley", "Burley's profile: Cycles and EEVEE, fitted exactly"),
    ("RANDOM_WALK", "Random Walk", "Cycles' volume random walk (radius = mean free path)"),
    ("RANDOM_WALK_SKIN", "Random Walk (Skin)", "Cycles' random walk with radius adjusted by "
                                               "colour, as Principled skin presets use"),
)
RESOLUTION_ITEMS = (
    ("preview", "Preview", "Coarse tables (fast bake, under 1% error)"),
    ("default", "Default", "The bake's default resolution"),
    ("high", "High", "Finer tables (slower bake)"),
)


def _foundation_items(self, context):
    return [(key, value["label"], f"Foundation shade {value['label']}")
            for key, value in presets.FOUNDATIONS.items()]


def _skin_items(self, context):
    return [(key, value["label"], f"Skin {value['label']}") for key, value in
            presets.SKINS.items()]


def _first_skin_albedo() -> tuple:
    """The albedo of the first skin preset: Skin Color's default."""
    return tuple(presets.skin_albedo(next(iter(presets.SKINS))))


# Enum items must stay referenced while Blender shows them.
_ITEMS_CACHE: dict[str, list] = {}


def _cached(name, function):
    def items(self, context):
        _ITEMS_CACHE[name] = function(self, context)
        return _ITEMS_CACHE[name]

    return items


def _update_sockets(self, context):
    live.sockets_changed(self)


def _update_tables(self, context):
    live.tables_changed(self)


def _update_skin(self, context):
    if self.skin in presets.SKINS:
        # The preset's albedo goes to the socket at once (a linked texture overrides it).
        self.skin_colour = presets.skin_albedo(self.skin).tolist()
    _update_tables(self, context)


def _update_foundation(self, context):
    entry = presets.FOUNDATIONS.get(self.foundation)
    if entry is not None:
        # Assigning runs _update_sockets once more: the shade reaches the material at once.
        self.absorption = entry["absorption"]
        self.foundation_colour = [1.0 - a for a in entry["absorption"]]
    # The film's gloss, roughness and index change the tables: a debounced preview re-fit.
    _update_tables(self, context)


class MakeupSkinSettings(bpy.types.PropertyGroup):
    """Made-up skin parameters of one material."""

    is_made_up: bpy.props.BoolProperty(
        name="Made-up Skin Material", default=False,
        description="This material's node tree was made by Apply (internal)")
    foundation: bpy.props.EnumProperty(
        name="Foundation", items=_cached("foundation", _foundation_items),
        description="Foundation preset: the paper's measured film and its shades",
        update=_update_foundation)
    skin: bpy.props.EnumProperty(
        name="Skin", items=_cached("skin", _skin_items),
        description="Skin under the film: the paper's bio-plate or measured human skin (sets "
                    "Skin Color to its albedo)",
        update=_update_skin)
    coverage: bpy.props.FloatProperty(
        name="Coverage", default=1.0, min=0.0, max=1.0, subtype="FACTOR",
        description="Fraction of the surface the film covers (0 bare skin, 1 full film); link "
                    "a texture to the group's Coverage socket to paint it",
        update=_update_sockets)
    absorption_mode: bpy.props.EnumProperty(
        name="Shade By", items=(("ABSORPTION", "Absorption", "Pigment absorption per channel"),
                                ("COLOUR", "Colour", "Colour the pigment passes (1 - absorption)")),
        default="ABSORPTION", update=_update_sockets)
    absorption: bpy.props.FloatVectorProperty(
        name="Absorption", size=3, default=(0.0, 0.0, 0.0), min=0.0, max=1.0, subtype="NONE",
        description="Fraction of the light crossing the film's pigment absorbed, per R, G, B "
                    "(the foundation's shade)", update=_update_sockets)
    foundation_colour: bpy.props.FloatVectorProperty(
        name="Foundation Colour", size=3, default=(1.0, 1.0, 1.0), min=0.0, max=1.0,
        subtype="COLOR", description="Colour the pigment lets through (1 - absorption)",
        update=_update_sockets)
    skin_colour: bpy.props.FloatVectorProperty(
        name="Skin Color", size=3, min=0.0, max=1.0,
        default=_first_skin_albedo(),
        subtype="COLOR",
        description="The skin's diffuse albedo (the skin preset's by default); an albedo "
                    "texture linked to the group's Skin Color input replaces it",
        update=_update_sockets)
    subsurface_scale: bpy.props.FloatProperty(
        name="Subsurface Scale", default=1.0, min=0.0, soft_max=4.0, max=100.0,
        description="Multiplies the subsurface radius fitted to the skin's measured profile "
                    "(1 = as measured, in millimetres converted by the scene's unit scale)",
        update=_update_sockets)
    gloss: bpy.props.FloatProperty(
        name="Gloss", default=1.0, min=0.0, max=1.0, subtype="FACTOR",
        description="Multiplies the gloss lobes (film, skin through the film, bare skin): 1 = "
                    "as measured, 0 leaves them out and Cycles allocates none (cheaper; Fit "
                    "to Scene sets 0 when the gloss is below the noise)",
        update=_update_sockets)
    override_film: bpy.props.BoolProperty(
        name="Override Film", default=False,
        description="Replace the film's measured roughness and index of refraction",
        update=_update_tables)
    film_lobe_width: bpy.props.FloatProperty(
        name="Film Roughness", default=math.radians(30.4), min=math.radians(5.0),
        max=math.radians(60.0), subtype="ANGLE", unit="ROTATION",
        description="Width of the film's surface gloss (1/n of the paper's Torrance-Sparrow "
                    "lobe; measured 30.4 degrees); the light crossing the film keeps the "
                    "foundation's spread",
        update=_update_tables)
    film_ior: bpy.props.FloatProperty(
        name="Film IOR", default=1.19, min=1.01, max=2.5,
        description="Film index of refraction (measured 1.19)", update=_update_tables)
    subsurface_method: bpy.props.EnumProperty(
        name="Subsurface", items=SUBSURFACE_ITEMS, default="AUTO",
        description="Blender subsurface method (its radius is fitted to the skin's profile)",
        update=_update_tables)
    tier: bpy.props.EnumProperty(
        name="Tier", items=TIER_ITEMS, default="AUTO",
        description="Node group tier (cost against accuracy)", update=_update_tables)
    resolution: bpy.props.EnumProperty(
        name="Bake Resolution", items=RESOLUTION_ITEMS, default="default",
        description="Resolution of the tables Apply bakes")
    live_update: bpy.props.BoolProperty(
        name="Live Update", default=True,
        description="Re-bake at preview resolution while sliders move (Apply bakes in full)")

    def effective_absorption(self):
        """Absorption per channel, from the absorption or the colour field."""
        if self.absorption_mode == "COLOUR":
            return [1.0 - c for c in self.foundation_colour]
        return list(self.absorption)


classes = (MakeupSkinSettings,)


_register_classes, _unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    _register_classes()
    setattr(bpy.types.Material, SETTINGS_ATTRIBUTE,
            bpy.props.PointerProperty(type=MakeupSkinSettings))


def unregister():
    delattr(bpy.types.Material, SETTINGS_ATTRIBUTE)
    _unregister_classes()
    _ITEMS_CACHE.clear()
