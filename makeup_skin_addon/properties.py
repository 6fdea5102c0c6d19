"""The panel's settings: one :class:`MakeupSkinSettings` per material (``material.makeup_skin``).

Covered Area (the areal mix, ``coverage``), absorption (or the foundation's colour, solved
into it), skin colour, subsurface scale, gloss and the film's normal are socket values of the
material's group node (or of its nodes): moving them updates the material at once (with the
film at a thickness the absorption is baked too).  Film (at a Thickness, or the paper's film
as published) and Thickness change the tables.  Foundation and skin presets, Film and Skin
Roughness, the film's index, tier and resolution change the tables: with live update on, moving
them schedules a preview re-bake (:mod:`.live`); Apply bakes at full resolution.  The settings
are registered as ``Material.makeup_skin`` (:data:`.keys.SETTINGS_ATTRIBUTE`).

The shade is kept as its absorption; the Foundation Color is its colour seen (the thick
layer, :func:`.shade.colour_seen`) and picking a colour solves the absorption
(:func:`.shade.absorption_for_colour`), both at once in the update callbacks, never while the
panel draws.  Choosing a foundation sets its shade, colour and film roughness; choosing a skin
its albedo and roughness.  Every change stamps :data:`SETTINGS_VERSION`; :mod:`.on_load`
upgrades the settings of older files (whose Colour meant the colour the pigment passes, and
whose film width was in degrees).
"""

from __future__ import annotations

import math

import bpy

from . import live, shade
from .core import film_slab, presets, slab_tables, tier_registry
from .keys import SETTINGS_ATTRIBUTE, SETTINGS_VERSION
from .shade import FILM_ROUGHNESS_MIN, ROUGHNESS_MAX, SKIN_ROUGHNESS_MIN
from .skin_model import PAPER_FILM, SLAB_FILM

__all__ = ["MakeupSkinSettings", "register", "unregister", "AUTO_TIER", "tier_items",
           "SUBSURFACE_ITEMS",
           "RESOLUTION_ITEMS", "SETTINGS_VERSION", "ROUGHNESS_MAX", "FILM_ROUGHNESS_MIN",
           "SKIN_ROUGHNESS_MIN"]

AUTO_TIER = ("AUTO", "Auto", "The cheapest tier within 2% of the best one's error in this "
                             "scene (camera, resolution, object size, lights, engine, "
                             "samples); Fit to Scene also drops the subsurface and gloss the "
                             "scene does not need", "NONE", 0)
"""The Tier setting's first item (stored as 0, as files keep it)."""


def tier_items(self=None, context=None) -> list:
    """The Tier setting's items: Auto, then every registered tier
    (:mod:`lut_baker.closures.tier_registry`) with its label, description and stored
    number."""
    return [AUTO_TIER, *((t.name, t.label, t.description, "NONE", t.number)
                         for t in map(tier_registry.tier, tier_registry.TIERS))]
SUBSURFACE_ITEMS = (
    ("AUTO", "Auto", "The method whose shadow-edge blur is closest to the skin's (Burley)"),
    ("BURLEY", "Christensen-Burley", "Burley's profile: Cycles and EEVEE, fitted exactly"),
    ("RANDOM_WALK", "Random Walk", "Cycles' volume random walk (radius = mean free path)"),
    ("RANDOM_WALK_SKIN", "Random Walk (Skin)", "Cycles' random walk with radius adjusted by "
                                               "color, as Principled skin presets use"),
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


FIRST_FOUNDATION = next(iter(presets.FOUNDATIONS))
"""The default foundation (the first preset: the paper's film, matched to the skin at the first
Apply, docs/addon.md "A first Apply")."""
FIRST_SKIN = next(iter(presets.SKINS))
DEFAULT_THICKNESS_UM = float(film_slab.DEFAULT_THICKNESS_UM)
THICKNESS_MIN_UM = float(slab_tables.THICKNESS_MIN_UM)
"""The thinnest film: the slab tables' axis begins there (thinner would be read as it)."""
"""The Thickness setting's default: a typical application on a face (docs/model.md, "The film
as a slab")."""
# Enum items must stay referenced while Blender shows them.
_ITEMS_CACHE: dict[str, list] = {}


def _cached(name, function):
    def items(self, context):
        _ITEMS_CACHE[name] = function(self, context)
        return _ITEMS_CACHE[name]

    return items


def _stamp(settings) -> None:
    """Mark the settings as of this version (a change made here, not in an older file)."""
    if settings.settings_version != SETTINGS_VERSION or not settings.is_property_set(
            "settings_version"):
        settings.settings_version = SETTINGS_VERSION


def _update_sockets(self, context):
    _stamp(self)
    live.sockets_changed(self)


def _update_tables(self, context):
    _stamp(self)
    live.tables_changed(self)


def _update_shade(self, context):
    """The shade reaches the sockets at once; with the film as a slab it is baked too, and a
    shade set by hand leaves the skin under the film as it is (Match Skin may darken it)."""
    if not shade.is_assigning():
        _reset_skin_under(self)
    _update_sockets(self, context)
    if self.film_mode != PAPER_FILM:
        live.tables_changed(self)


def _reset_skin_under(settings) -> None:
    if tuple(settings.skin_under) != (1.0, 1.0, 1.0):
        settings.skin_under = (1.0, 1.0, 1.0)


def _update_film(self, context):
    """Film changes the tables; the skin under the film Match Skin darkened for another film
    is the skin's own again, and the shade keeps its colour in the bottle (:func:`_reshade`)."""
    if not shade.is_assigning():
        _reset_skin_under(self)
        _reshade(self)
    _update_tables(self, context)


def _reshade(settings) -> None:
    """The shade in the Film now: a preset's is its own (its colour's absorption with the film
    at a thickness, :func:`.shade.preset_absorption`); a colour picked or matched keeps its
    colour in the bottle, its absorption solved for this film; an absorption typed by hand
    (or never chosen) keeps its value, and its colour in the bottle is this film's."""
    slab = shade.slab_foundation(settings)
    with shade.assigning():
        source = settings.shade_source
        if source == "PRESET" and settings.foundation in presets.FOUNDATIONS:
            settings.absorption = [float(a) for a in shade.preset_absorption(
                settings.foundation, slab is not None)]
        elif source == "MATCH" or (source == "USER" and settings.absorption_mode == "COLOUR"):
            absorption, clamped = shade.absorption_for_colour(settings.shade_colour, slab)
            settings.absorption = [float(a) for a in absorption]
            settings.shade_note = shade.colour_note(settings.shade_colour, clamped, slab)
        else:
            settings.shade_colour = [float(c) for c in shade.colour_seen(settings.absorption,
                                                                         slab)]


def _update_thickness(self, context):
    """A Thickness change re-reads the slab's tables (no bake, no fit): a short debounce."""
    if not shade.is_assigning():
        _reset_skin_under(self)
    _stamp(self)
    live.tables_changed(self, live.THICKNESS_DEBOUNCE_S, measure_later=True)


def _update_absorption(self, context):
    if not shade.is_assigning():
        with shade.assigning():
            self.shade_colour = [float(c) for c in shade.colour_seen(
                self.absorption, shade.slab_foundation(self))]
            self.shade_note = ""
            self.shade_source = "USER"
    _update_shade(self, context)


def _update_shade_colour(self, context):
    if shade.is_assigning():
        return
    slab = shade.slab_foundation(self)
    absorption, clamped = shade.absorption_for_colour(self.shade_colour, slab)
    with shade.assigning():
        self.absorption = [float(a) for a in absorption]
        self.shade_note = shade.colour_note(self.shade_colour, clamped, slab)
        self.shade_source = "USER"
    _update_shade(self, context)


def _update_skin_colour(self, context):
    """Skin Color reaches the sockets at once; with the film as a slab the fit is made on it
    (:func:`.skin_model.skin_albedo_of`), so the group is rebuilt too."""
    _update_sockets(self, context)
    if self.film_mode != PAPER_FILM and not self.over_shader:
        live.tables_changed(self)


def _update_skin(self, context):
    if self.skin in presets.SKINS:
        with shade.assigning():
            # The preset's albedo and roughness go to the settings at once (a linked texture
            # overrides the albedo).
            self.skin_colour = presets.skin_albedo(self.skin).tolist()
            self.skin_roughness = shade.skin_roughness(self.skin)
    _update_tables(self, context)


def _update_foundation(self, context):
    if self.foundation in presets.FOUNDATIONS and not shade.is_assigning():
        with shade.assigning():
            # The preset's shade reaches the material at once (its sockets), its colour seen
            # and its film's own roughness come with it.
            self.absorption = [float(a) for a in shade.preset_absorption(
                self.foundation, self.film_mode != PAPER_FILM)]
            self.shade_colour = [float(c) for c in shade.preset_colour(self.foundation)]
            self.film_roughness = shade.foundation_roughness(self.foundation)
            self.shade_note = ""
            self.shade_source = "PRESET"
            _reset_skin_under(self)
        _update_sockets(self, context)
    # The film's gloss, roughness and index change the tables: a debounced preview re-fit.
    _update_tables(self, context)


class MakeupSkinSettings(bpy.types.PropertyGroup):
    """Made-up skin parameters of one material."""

    is_made_up: bpy.props.BoolProperty(
        name="Made-up Skin Material", default=False,
        description="This material's node tree was made by Apply (internal)")
    settings_version: bpy.props.IntProperty(
        name="Settings Version", default=SETTINGS_VERSION, min=0,
        description="What the settings mean (internal: files of older add-ons are upgraded "
                    "when opened)")
    foundation: bpy.props.EnumProperty(
        name="Foundation", items=_cached("foundation", _foundation_items),
        description="Foundation preset: the paper's measured film, its shades and measured "
                    "products (sets the shade, and the film's gloss and roughness)",
        update=_update_foundation)
    skin: bpy.props.EnumProperty(
        name="Skin", items=_cached("skin", _skin_items),
        description="Skin under the film: the paper's bio-plate or measured human skin (sets "
                    "Skin Color to its albedo and Skin Roughness to its own)",
        update=_update_skin)
    film_mode: bpy.props.EnumProperty(
        name="Film", items=(
            (SLAB_FILM, "At a Thickness", "The foundation as a film of the Thickness below "
                                          "over the skin: every inter-reflection, the skin "
                                          "showing through a sheer film (docs: the film as "
                                          "a slab)"),
            (PAPER_FILM, "Paper Film (as Published)", "The paper's measured free film, about "
                                                      "150 micrometres, paths 1 + 3 as "
                                                      "published (files made before the "
                                                      "film at a thickness was the default "
                                                      "keep it)")),
        default=SLAB_FILM,
        description="How the foundation's film is modelled: at a thickness, or the paper's "
                    "free film as published", update=_update_film)
    thickness_um: bpy.props.FloatProperty(
        name="Thickness", default=DEFAULT_THICKNESS_UM, min=THICKNESS_MIN_UM,
        soft_max=300.0, max=10000.0, precision=1,
        description="The film's thickness in micrometres: how much it hides (sheer a few, "
                    "9.6 a typical application of liquid foundation on a face, 0.96 mg/cm2; "
                    "the paper's free film 150)", update=_update_thickness)
    skin_under: bpy.props.FloatVectorProperty(
        name="Skin Under the Film", size=3, default=(1.0, 1.0, 1.0), min=0.0, max=1.0,
        description="The skin's albedo under the film relative to Skin Color, per channel: "
                    "where a sheer film's gloss adds more than full absorption takes away, "
                    "Match Skin darkens the skin under it (1: the skin's own; internal, reset "
                    "by a shade or film set by hand)")
    skin_body: bpy.props.FloatVectorProperty(
        name="Skin Body Color", size=3, default=(0.0, 0.0, 0.0), min=0.0, max=1.0,
        description="The mean body color of the skin under the film as Apply last read it "
                    "from the artist's shader: the film at a thickness is fitted on it (0: "
                    "not read; internal)")
    coverage: bpy.props.FloatProperty(
        name="Covered Area", default=0.6, min=0.0, max=1.0, subtype="FACTOR",
        description="Fraction of the surface the film lies on, as an areal mix of made-up "
                    "and bare skin (0 bare skin, 1 the film everywhere): for painting where "
                    "the foundation is (link a texture to the group's Coverage socket); how "
                    "much the film hides is its Thickness",
        update=_update_sockets)
    absorption_mode: bpy.props.EnumProperty(
        name="Shade By", items=(
            ("ABSORPTION", "Absorption", "Pigment absorption per channel"),
            ("COLOUR", "Color", "The color the foundation has in the bottle or as a swatch "
                                "(linear; sample a product photo with the picker)")),
        default="COLOUR",
        description="How the foundation's shade is given: by its color in the bottle (the "
                    "absorption is solved from it) or by the pigment's absorption",
        update=_update_sockets)
    absorption: bpy.props.FloatVectorProperty(
        name="Absorption", size=3, default=(0.0, 0.0, 0.0), min=0.0, max=1.0, subtype="NONE",
        description="Fraction of the light crossing the film's pigment absorbed, per R, G, B "
                    "(the foundation's shade)", update=_update_absorption)
    shade_colour: bpy.props.FloatVectorProperty(
        name="Foundation Color", size=3, min=0.0, max=1.0, subtype="COLOR",
        default=tuple(float(c) for c in shade.colour_seen((0.0, 0.0, 0.0))),
        description="The color of a thick layer of the foundation (in the bottle, a swatch on "
                    "a card), linear: the absorption is solved so that the film stacked on "
                    "itself has it; colors the film cannot reach are clamped (the panel says "
                    "so)", update=_update_shade_colour)
    foundation_colour: bpy.props.FloatVectorProperty(
        name="Color Passed (old)", size=3, default=(1.0, 1.0, 1.0), min=0.0, max=1.0,
        subtype="COLOR", description="Files of older versions: the color the pigment let "
                                     "through (1 - absorption); upgraded when opened")
    shade_note: bpy.props.StringProperty(
        name="Shade Note", default="",
        description="What the last color pick or match could not reach (internal, shown)")
    shade_source: bpy.props.EnumProperty(
        name="Shade Source", items=(
            ("DEFAULT", "Default", "Never chosen: the first Apply matches the skin"),
            ("PRESET", "Preset", "The foundation preset's"),
            ("MATCH", "Match Skin", "Matched to the skin, or stepped from there"),
            ("USER", "User", "Set by hand")),
        default="DEFAULT", description="Where the shade came from (internal)")
    shade_base: bpy.props.FloatVectorProperty(
        name="Shade Base", size=3, default=(0.0, 0.0, 0.0), min=0.0,
        description="The covered color the last Match Skin aimed at, from which Lighter and "
                    "Darker count their steps (internal)")
    shade_steps: bpy.props.IntProperty(
        name="Shade Steps", default=0,
        description="Lighter (+1) and Darker (-1) steps since the last Match Skin (internal)")
    over_shader: bpy.props.BoolProperty(
        name="Over the Artist's Shader", default=False,
        description="The film goes over the material's own shader, which stays the bare skin "
                    "and gives the skin under the film (set by Apply; internal)")
    skin_ior: bpy.props.FloatProperty(
        name="Skin IOR", default=1.4, min=1.01, max=2.5,
        description="Index of refraction of the skin under the film (Apply takes the "
                    "artist's shader's IOR)", update=_update_tables)
    skin_colour: bpy.props.FloatVectorProperty(
        name="Skin Color", size=3, min=0.0, max=1.0,
        default=_first_skin_albedo(),
        subtype="COLOR",
        description="The skin's diffuse albedo (the skin preset's by default, or the value of "
                    "the artist's Base Color); an albedo texture linked to the group's Skin "
                    "Color input replaces it",
        update=_update_skin_colour)
    skin_roughness: bpy.props.FloatProperty(
        name="Skin Roughness", default=shade.skin_roughness(FIRST_SKIN),
        min=SKIN_ROUGHNESS_MIN, max=ROUGHNESS_MAX, subtype="FACTOR",
        description="Roughness of the skin's gloss, as Blender shows roughness (the skin "
                    "preset's by default); the gloss keeps its strength, only its spread "
                    "changes", update=_update_tables)
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
    film_roughness: bpy.props.FloatProperty(
        name="Film Roughness", default=shade.foundation_roughness(FIRST_FOUNDATION),
        min=FILM_ROUGHNESS_MIN, max=ROUGHNESS_MAX, subtype="FACTOR",
        description="Roughness of the film's surface gloss, as Blender shows roughness (the "
                    "foundation's own by default, reset by choosing it); the gloss keeps its "
                    "strength, the light crossing the film keeps the foundation's spread. A "
                    "matte product has no surface gloss: nothing to roughen",
        update=_update_tables)
    override_film: bpy.props.BoolProperty(
        name="Override Film IOR", default=False,
        description="Replace the film's measured index of refraction",
        update=_update_tables)
    film_lobe_width: bpy.props.FloatProperty(
        name="Film Lobe Width (old)", default=math.radians(30.4), min=math.radians(5.0),
        max=math.radians(60.0), subtype="ANGLE", unit="ROTATION",
        description="Files of older versions: the film's gloss width in degrees, with Override "
                    "Film; upgraded to Film Roughness when opened")
    film_ior: bpy.props.FloatProperty(
        name="Film IOR", default=1.19, min=1.01, max=2.5,
        description="Film index of refraction (measured 1.19)", update=_update_tables)
    film_follows_pores: bpy.props.BoolProperty(
        name="Film Follows Pores", default=True,
        description="The film takes a weaker copy of the skin's normal map (the pores show "
                    "through, softened); off: a smooth film that fills the pores",
        update=_update_sockets)
    film_normal_strength: bpy.props.FloatProperty(
        name="Film Normal Strength", default=0.5, min=0.0, max=1.0, subtype="FACTOR",
        description="Strength of the film's normal map relative to the skin's",
        update=_update_sockets)
    subsurface_method: bpy.props.EnumProperty(
        name="Subsurface", items=SUBSURFACE_ITEMS, default="AUTO",
        description="Blender subsurface method (its radius is fitted to the skin's profile)",
        update=_update_tables)
    tier: bpy.props.EnumProperty(
        name="Tier", items=_cached("tier", tier_items), default=0,
        description="Node group tier (cost against accuracy)", update=_update_tables)
    resolution: bpy.props.EnumProperty(
        name="Bake Resolution", items=RESOLUTION_ITEMS, default="default",
        description="Resolution of the tables Apply bakes")
    live_update: bpy.props.BoolProperty(
        name="Live Update", default=True,
        description="Re-bake at preview resolution while sliders move (Apply bakes in full)")


classes = (MakeupSkinSettings,)


_register_classes, _unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    _register_classes()
    setattr(bpy.types.Material, SETTINGS_ATTRIBUTE, bpy.props.PointerProperty(
        type=MakeupSkinSettings, name="Made-up Skin",
        description="This material's Made-up Skin settings: foundation, coverage, shade, skin, "
                    "film, tier"))


def unregister():
    delattr(bpy.types.Material, SETTINGS_ATTRIBUTE)
    _unregister_classes()
    _ITEMS_CACHE.clear()
