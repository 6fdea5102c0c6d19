"""Operators: Apply, Revert, Check Tables, Fit to Scene, Match Skin and the shade steps
(Lighter / Darker), and the preset menu with its add/remove operator.  Each operator's work is
a function of a lower module (:mod:`.apply`, :mod:`.tier_choice`, :mod:`.live`,
:mod:`.shade`); here it is run and reported.  Idnames are
``makeup_skin.<name>`` (:data:`.keys.OPERATOR_PREFIX`).

A button Blender greys out says why in its tooltip: every ``poll`` that can refuse gives its
reason with ``poll_message_set`` (:func:`_allowed`; the reasons: :func:`_object_reason`,
:func:`_material_reason`, :func:`_linked_reason`, :func:`_revert_reason`,
:func:`_edit_reason`)."""

from __future__ import annotations

import bpy
from bl_operators.presets import AddPresetBase

from . import apply, convert, groups, live, matching, skin_model, skin_sampling, tier_choice
from .keys import OPERATOR_PREFIX, PRESET_SUBDIR, SETTINGS_ATTRIBUTE
from .progress import progress_bar
from .properties import RESOLUTION_ITEMS

__all__ = ["MAKEUPSKIN_OT_apply", "MAKEUPSKIN_OT_revert", "MAKEUPSKIN_OT_check_tables",
           "MAKEUPSKIN_OT_fit_to_scene", "MAKEUPSKIN_OT_match_skin", "MAKEUPSKIN_OT_shade_step",
           "MAKEUPSKIN_OT_add_preset", "MAKEUPSKIN_MT_presets", "PRESET_SUBDIR", "register",
           "unregister"]


SURFACE_TYPES = frozenset({"MESH", "CURVE", "SURFACE", "META", "FONT"})
"""Object types with a surface and material slots: what Apply makes up."""


def _allowed(cls, reason: str | None) -> bool:
    """Whether the operator can run (``reason`` is None); if not, the greyed-out button's
    tooltip says ``reason`` (``poll_message_set``, capitalised as Blender's own)."""
    if reason is not None:
        cls.poll_message_set(reason[0].upper() + reason[1:])
    return reason is None


def _a(noun: str) -> str:
    return f"{'an' if noun[0] in 'aeiou' else 'a'} {noun}"


def _object_reason(obj, types=SURFACE_TYPES, wanted: str = "a mesh") -> str | None:
    """Why ``obj`` (the active object) cannot be used: none, or of a type outside ``types``."""
    if obj is None:
        return f"no active object: select {wanted}"
    if obj.type not in types:
        kind = obj.bl_rna.properties["type"].enum_items[obj.type].name  # Blender's: "Text"
        return f"the active object is {_a(kind.lower())}: select {wanted}"
    return None


def _material_reason(obj, then: str) -> str | None:
    """Why ``obj``'s active material cannot be used: no object or no material (``then``:
    what to do about the missing material)."""
    if obj is None:
        return "no active object: select an object with a material"
    if obj.active_material is None:
        return f"the active object {obj.name!r} has no material: {then}"
    return None


def _linked_reason(obj, material) -> str | None:
    """Why the data Apply, Fit to Scene or a shade would change cannot be changed here: the
    material, its group, or (no material) ``obj``'s mesh linked from a library."""
    try:
        apply.refuse_linked(obj, material)
    except apply.LinkedDataError as error:
        return str(error)
    return None


def _edit_reason(obj) -> str | None:
    """Why the skin of ``obj``'s material cannot be read now: its mesh is in Edit Mode."""
    if obj is None or obj.type != "MESH" or obj.mode != "EDIT":
        return None
    return f"{skin_sampling.in_edit_mode(obj)}: leave Edit Mode (Tab) to read the skin"


def _made_up_reason(material) -> str | None:
    """Why a shade cannot be set on ``material``: it is not made up yet.  The first Apply
    matches the skin itself (choosing a matte film when the skin is darker than the default
    film's gloss); a shade set before it would be kept as chosen, and skip that."""
    if not material.makeup_skin.is_made_up:
        return f"material {material.name!r} is not made up: Apply first (it matches the skin)"
    return None


def _revert_reason(material) -> str | None:
    """Why ``material`` cannot be reverted: nothing to revert to, or linked."""
    if not convert.can_revert(material):
        if convert.group_node(material) is None:
            return f"material {material.name!r} is not made up: nothing to revert"
        return (f"material {material.name!r} has no record of its surface before Apply: "
                f"nothing to revert to")
    return convert.linked_library(material, "material")


class MAKEUPSKIN_OT_apply(bpy.types.Operator):
    """Bake and fit the made-up skin and lay it over the active object's material, converted
    in place: its own surface shader stays, the bare skin where the film does not cover, and
    gives the skin under the film its color, normal and subsurface"""

    bl_idname = f"{OPERATOR_PREFIX}.apply"
    bl_label = "Apply Made-up Skin"
    bl_options = {"REGISTER", "UNDO"}

    resolution: bpy.props.EnumProperty(
        name="Resolution",
        items=(("SETTINGS", "From Settings", "The material's Bake Resolution"),
               *RESOLUTION_ITEMS),
        default="SETTINGS", options={"SKIP_SAVE"},
        description="Resolution of the tables this Apply bakes")

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return _allowed(cls, _object_reason(obj) or _edit_reason(obj)
                        or _linked_reason(obj, obj.active_material))

    def execute(self, context):
        obj = context.active_object
        resolution = None if self.resolution == "SETTINGS" else self.resolution
        if obj.active_material is not None:
            live.cancel(obj.active_material)  # a live rebuild in flight is stale now
        try:
            # With an event loop, a new bake is done at preview resolution first and refined
            # on a worker thread (docs/addon.md, "Apply and Live Update, timed").
            material, messages = apply.apply_to_object(
                context, obj, resolution=resolution, preview_first=live.can_refine())
        except (ValueError, RuntimeError) as error:
            self.report({"ERROR"}, f"Made-up Skin: {_sentence(error)}")
            return {"CANCELLED"}
        if messages.refine is not None:
            live.refine(context, material, messages.refine)
        warnings = getattr(messages, "warnings", [])
        for message in messages:
            self.report({"WARNING"} if message in warnings else {"INFO"},
                        f"Made-up Skin: {message}")
        left = (f" ({len(warnings)} thing{'s' if len(warnings) != 1 else ''} of its shader "
                f"not carried over: see the warnings)" if warnings else "")
        self.report({"INFO"}, f"Made-up Skin: {material.name!r} on {obj.name!r} is made "
                              f"up{left}.")
        return {"FINISHED"}


class MAKEUPSKIN_OT_revert(bpy.types.Operator):
    """Give the active material back the surface shader it had before Apply and remove the
    Made-up Skin node (the settings stay for a later Apply)"""

    bl_idname = f"{OPERATOR_PREFIX}.revert"
    bl_label = "Revert to Previous Surface"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        reason = _material_reason(obj, "nothing to revert")
        return _allowed(cls, reason or _revert_reason(obj.active_material))

    def execute(self, context):
        try:
            live.cancel(context.active_object.active_material)
            message = apply.revert_material(context.active_object.active_material)
        except ValueError as error:
            self.report({"ERROR"}, f"Made-up Skin: {_sentence(error)}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Made-up Skin: {message}")
        return {"FINISHED"}


class MAKEUPSKIN_OT_check_tables(bpy.types.Operator):
    """Check every Made-up Skin material against the record of its bake and the hashes of the
    images its render reads; repair what is missing or damaged by re-baking"""

    bl_idname = f"{OPERATOR_PREFIX}.check_tables"
    bl_label = "Check Made-up Skin Tables"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        checked = 0
        for material in list(bpy.data.materials):
            if not material.makeup_skin.is_made_up:
                continue
            checked += 1
            try:
                intact, sentence = apply.check_material(context, material)
            except (ValueError, RuntimeError) as error:
                intact = False
                sentence = f"{material.name!r} could not be repaired: {_sentence(error)}"
            self.report({"INFO" if intact else "WARNING"}, f"Made-up Skin: {sentence}")
        if not checked:
            self.report({"INFO"}, "Made-up Skin: no made-up material in this file.")
        return {"FINISHED"}


class MAKEUPSKIN_OT_fit_to_scene(bpy.types.Operator):
    """Choose the cheapest Made-up Skin tier that stays within the tolerance in this scene
    (camera, resolution, object size, lights, engine, samples), report it with its predicted
    error, and apply it"""

    bl_idname = f"{OPERATOR_PREFIX}.fit_to_scene"
    bl_label = "Fit to Scene"
    bl_options = {"REGISTER", "UNDO"}

    tolerance: bpy.props.FloatProperty(
        name="Tolerance", default=0.02, min=0.0, max=1.0, subtype="FACTOR",
        description="Error a cheaper tier may add to the best tier's (relative RMS)")
    apply: bpy.props.BoolProperty(
        name="Apply", default=True,
        description="Set the chosen tier and subsurface on the material (else only report)")

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return _allowed(cls, _object_reason(obj, {"MESH"})
                        or _linked_reason(obj, obj.active_material))

    def execute(self, context):
        obj = context.active_object
        material = obj.active_material
        context.view_layer.update()  # object matrices follow moves only after an update
        try:
            apply.refuse_linked(obj, material)
            if material is None or not material.makeup_skin.is_made_up:
                material, _ = apply.apply_to_object(context, obj)
            elif material.name in live.pending():
                live.flush(context)  # judge the tables the settings describe now
            choice, description = tier_choice.choose_for(material, context.scene, obj=obj,
                                                       tolerance=self.tolerance)
            changes = []
            if self.apply:
                changes = tier_choice.set_choice(material, choice.candidate)
                apply.apply_to_object(context, obj)
        except (ValueError, RuntimeError) as error:
            self.report({"ERROR"}, f"Made-up Skin: Fit to Scene changed nothing: {error}.")
            return {"CANCELLED"}
        chosen = choice.chosen
        tier_choice.record_choice(material, choice, description)
        if description is None:
            self.report({"WARNING"}, "Made-up Skin: no camera or object in the scene: assumed "
                                     "a close-up")
        self.report({"INFO"}, f"Made-up Skin: Fit to Scene chose {chosen.candidate.name}: "
                              f"predicted error {100 * chosen.error:.1f}% (best "
                              f"{100 * choice.best_error:.1f}% + {100 * choice.tolerance:.0f}%)"
                              f", cost {chosen.cost:.2f} of the fullest tier"
                              + (f"; {', '.join(changes)}" if changes else ""))
        for line in choice.reasons[:3]:
            self.report({"INFO"}, f"Made-up Skin: {line}")
        return {"FINISHED"}


class _ShadePoll:
    """Match Skin and the shade steps: the active object's material, made up and local."""

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        reason = _material_reason(obj, "Apply first")
        if reason is None:
            reason = (_linked_reason(None, obj.active_material)
                      or _made_up_reason(obj.active_material) or _edit_reason(obj))
        return _allowed(cls, reason)


def _set_shade(operator, context, solve) -> set:
    """Solve a shade for the active material with ``solve(material)`` (:func:`.shade.matched`
    or a step), store it and report; the material's group takes it at once (with the film at
    a thickness, whose absorption is baked, once rebuilt)."""
    material = context.active_object.active_material
    try:
        apply.refuse_linked(None, material)
        with progress_bar(context.window_manager):
            result = solve(material)
    except (ValueError, RuntimeError) as error:
        operator.report({"ERROR"}, f"Made-up Skin: {_sentence(error)}")
        return {"CANCELLED"}
    matching.assign(material.makeup_skin, result, "MATCH")
    groups.update_sockets(material)
    if skin_model.film_of(material.makeup_skin) != "paper":
        # The film at a thickness has its absorption baked: its group is rebuilt (on a
        # worker, swapped in when ready, at preview resolution first when the bake is new;
        # at once without an event loop).
        target = material.makeup_skin.resolution
        if live.can_refine() and apply.preview_first(material):
            live.refine(context, material, apply.PREVIEW, then=target)
        else:
            live.refine(context, material, target)
        if not live.can_refine():
            live.flush(context)
    for sentence in result.sentences:
        operator.report({"WARNING"} if "out of reach" in sentence else {"INFO"},
                        f"Made-up Skin: {sentence}")
    return {"FINISHED"}


class MAKEUPSKIN_OT_match_skin(_ShadePoll, bpy.types.Operator):
    """Set the shade so that the made-up skin has the color of the skin before Apply at any
    coverage: the artist's shader under uniform light, its textures averaged over the faces
    that use the material (Skin Color's value without one)"""

    bl_idname = f"{OPERATOR_PREFIX}.match_skin"
    bl_label = "Match Skin"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        return _set_shade(self, context, matching.matched)


class MAKEUPSKIN_OT_shade_step(_ShadePoll, bpy.types.Operator):
    """One shade lighter or darker: the covered skin's color 10% up or down in luminance"""

    bl_idname = f"{OPERATOR_PREFIX}.shade_step"
    bl_label = "Shade Step"
    bl_options = {"REGISTER", "UNDO"}

    direction: bpy.props.EnumProperty(
        name="Direction", items=(("LIGHTER", "Lighter", "One shade lighter"),
                                 ("DARKER", "Darker", "One shade darker")),
        default="LIGHTER", description="Which way the shade steps")

    @classmethod
    def description(cls, context, properties):
        return (f"One shade {properties.direction.lower()}: the covered skin's color "
                f"{'times' if properties.direction == 'LIGHTER' else 'divided by'} "
                f"{matching.SHADE_STEP:g}")

    def execute(self, context):
        steps = 1 if self.direction == "LIGHTER" else -1
        return _set_shade(self, context, lambda material: matching.stepped(material, steps))


def _sentence(error) -> str:
    """An exception's message as a sentence: capital first letter, final full stop."""
    text = str(error).strip() or type(error).__name__
    text = text[0].upper() + text[1:]
    return text if text.endswith((".", "!", "?")) else text + "."


class MAKEUPSKIN_MT_presets(bpy.types.Menu):
    bl_label = "Made-up Skin Presets"
    bl_description = "Saved Made-up Skin parameter sets: pick one to load it into the material"
    preset_subdir = PRESET_SUBDIR
    preset_operator = "script.execute_preset"
    draw = bpy.types.Menu.draw_preset


class MAKEUPSKIN_OT_add_preset(AddPresetBase, bpy.types.Operator):
    """Save or remove a Made-up Skin parameter set"""

    @classmethod
    def poll(cls, context):
        return _allowed(cls, _material_reason(
            context.object, "a preset holds a material's settings"))

    bl_idname = f"{OPERATOR_PREFIX}.add_preset"
    bl_label = "Add Made-up Skin Preset"
    preset_menu = MAKEUPSKIN_MT_presets.__name__
    preset_subdir = PRESET_SUBDIR
    # The active object's material: also defined in the shader editor, unlike context.material.
    preset_defines = [f"settings = bpy.context.object.active_material.{SETTINGS_ATTRIBUTE}"]
    preset_values = [
        "settings.foundation", "settings.skin", "settings.coverage", "settings.absorption_mode",
        "settings.absorption", "settings.skin_colour", "settings.skin_roughness",
        "settings.subsurface_scale", "settings.gloss", "settings.subsurface_method",
        "settings.film_roughness", "settings.override_film", "settings.film_ior",
        "settings.film_follows_pores", "settings.film_normal_strength",
        "settings.tier", "settings.resolution",
    ]


classes = (MAKEUPSKIN_OT_apply, MAKEUPSKIN_OT_revert, MAKEUPSKIN_OT_check_tables,
           MAKEUPSKIN_OT_fit_to_scene, MAKEUPSKIN_OT_match_skin, MAKEUPSKIN_OT_shade_step,
           MAKEUPSKIN_MT_presets, MAKEUPSKIN_OT_add_preset)


_register, unregister = bpy.utils.register_classes_factory(classes)


def register():
    _register()
