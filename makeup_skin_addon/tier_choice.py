"""The tier for a material in a scene: Tier Auto's choice (Fit to Scene's too), the tiers Apply
fits.

What the scene looks like to the model (:class:`lut_baker.auto_tier.SceneDescription`) comes
from the active camera, the render resolution, the objects wearing the material (the nearest
one: the largest on screen), the lights and the render engine; what the material is
(:class:`lut_baker.auto_tier.MaterialTraits`) from what its closure fit measured at its
coverage and absorption (kept in its group's record, :mod:`.bakes`).
:func:`lut_baker.auto_tier.choose` then picks the cheapest candidate within the tolerance.

- :func:`resolve_tier` -- the tier Apply builds for the settings and scene (Auto: from a
  measurement); :func:`fitted_tiers` -- the tiers Apply fits: the scene engine's and the
  settings' own; :func:`forced_method` -- the subsurface method the settings force.
- :func:`units_per_mm` -- scene units in one millimetre, from the scene's unit scale.
- :func:`describe_scene` -- the scene as the model sees it (None without a camera or object).
- :func:`material_traits` -- the material as the model sees it.
- :func:`choose_with` -- the choice for a material of given traits in a scene (Apply's Auto
  tier: the traits of the foundation being applied); :func:`choose_for` -- the same with the
  material's own traits (Fit to Scene); :func:`choice_scene` -- what the choice reads of
  Blender, so that a worker thread can make it (:class:`ChoiceScene`).
- :func:`set_choice` -- a choice's settings on the material: the tier, Subsurface Scale 0 when
  the scene does not resolve the subsurface, Gloss 0 when the gloss lobes change the image by
  less than the tolerance allows (below the noise); the values before are kept and given back
  when a later fit needs them.
- :func:`record_choice`, :func:`last_choice` -- the last choice, kept on the material for the
  panel (:data:`.keys.CHOICE_KEY`).

This module changes settings and custom properties only: the Fit to Scene operator
(:class:`makeup_skin_addon.operators.MAKEUPSKIN_OT_fit_to_scene`) applies the choice, and the
panels (:func:`makeup_skin_addon.ui.draw_fit`) show it.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

from . import bakes, convert, nodes
from .artist_skin import render_engine
from .core import auto_tier, closure_fit, tiers
from .keys import CHOICE_KEY, SAVED_GLOSS_KEY, SAVED_SCALE_KEY

__all__ = ["ENVIRONMENT_LIGHT_DEG", "resolve_tier", "auto_choice", "fitted_tiers",
           "forced_method", "units_per_mm", "describe_scene",
           "material_traits", "choose_with", "choose_for", "ChoiceScene", "choice_scene",
           "set_choice", "record_choice", "last_choice", "register", "unregister"]

ENVIRONMENT_LIGHT_DEG = 45.0
"""Light angle (degrees from the view) assumed when the scene has no lamp (world light)."""
UNKNOWN_SCENE = {"object_size_mm": 100.0, "footprint_mm": 0.01}
"""Without a camera or an object wearing the material: a close-up (everything resolved)."""


def resolve_tier(settings: Any, scene: Any, measured: dict | None = None) -> str:
    """The tier to build: the settings' own, or for Auto the one :func:`choose_with` picks in
    ``scene`` for a material whose fit measured ``measured`` (:func:`.bakes.measure`; default:
    what the material's group keeps, never a new bake; in EEVEE the EEVEE tier)."""
    if settings.tier != "AUTO":
        return settings.tier
    return auto_choice(settings.id_data, scene, measured)[0]


def auto_choice(material: Any, scene: Any, measured: dict | None) -> tuple[str, dict]:
    """``(tier, record for the panel)`` of the Auto choice for ``material`` in ``scene``
    (``measured``: :func:`.bakes.measure`, else what its group keeps)."""
    traits = bakes.traits(measured) if measured is not None else None
    if traits is None:
        traits = material_traits(material, may_fit=False, scene=scene)
    choice, _ = choose_with(traits, material, scene)
    chosen = choice.chosen
    return chosen.candidate.tier, {"tier": chosen.candidate.tier, "error": chosen.error,
                                   "engine": scene.render.engine}


def fitted_tiers(settings: Any, scene: Any, also: tuple[str, ...] = ()) -> tuple[str, ...]:
    """The tiers Apply fits for ``settings`` in ``scene``: those made for the scene's engine
    (:data:`lut_baker.auto_tier.ENGINE_TIERS`, among which Tier Auto chooses), the settings'
    tier when it is fixed to another, and ``also``; in :data:`lut_baker.closures.tiers.TIERS`
    order.  A tier asked for later (another tier or engine chosen) is fitted then."""
    wanted = {*auto_tier.ENGINE_TIERS[render_engine(scene)], *also}
    if settings.tier in tiers.TIERS:
        wanted.add(settings.tier)
    return tuple(tier for tier in tiers.TIERS if tier in wanted)


def forced_method(settings: Any) -> str | None:
    """The subsurface method the settings force, or None (Auto: the fit's best)."""
    return None if settings.subsurface_method == "AUTO" else settings.subsurface_method


def units_per_mm(scene) -> float:
    """Scene units in one millimetre: ``0.001 / unit_settings.scale_length`` (a scene in
    metres gives 0.001, one modelled in centimetres with scale 0.01 gives 0.1)."""
    scale = float(scene.unit_settings.scale_length) or 1.0
    return 0.001 / scale


def _samples(scene) -> tuple[int, bool]:
    if scene.render.engine == "CYCLES":
        return int(scene.cycles.samples), bool(scene.cycles.use_denoising)
    return int(getattr(scene.eevee, "taa_render_samples", 64)), False


def _wearers(material, scene) -> list:
    return [obj for obj in scene.objects
            if obj.type == "MESH" and any(slot.material == material
                                          for slot in obj.material_slots)]


def _centre(obj):
    from mathutils import Vector

    corners = [obj.matrix_world @ Vector(corner) for corner in obj.bound_box]
    return sum(corners, Vector()) / 8.0


def _footprint_mm(scene, obj, mm_per_unit: float):
    """``(mm per pixel at the object, unit vector from the object to the camera)``."""
    camera = scene.camera
    data = camera.data
    scale = scene.render.resolution_percentage / 100.0
    res_x, res_y = scene.render.resolution_x * scale, scene.render.resolution_y * scale
    fit = data.sensor_fit
    if fit == "AUTO":
        resolution, sensor = max(res_x, res_y), data.sensor_width
    elif fit == "HORIZONTAL":
        resolution, sensor = res_x, data.sensor_width
    else:
        resolution, sensor = res_y, data.sensor_height
    axis = camera.matrix_world.to_3x3().col[2].normalized()  # the camera looks along -Z
    centre = _centre(obj)
    if data.type == "ORTHO":
        footprint = auto_tier.pixel_footprint_mm("ORTHO", max(int(resolution), 1),
                                          ortho_scale_mm=data.ortho_scale * mm_per_unit)
        return footprint, axis
    offset = camera.matrix_world.translation - centre
    depth = max(offset.dot(axis), 1e-9)
    footprint = auto_tier.pixel_footprint_mm("PERSP", max(int(resolution), 1),
                                      distance_mm=depth * mm_per_unit, sensor_mm=sensor,
                                      focal_mm=data.lens)
    return footprint, offset.normalized()


def _light_angles(scene, obj, toward_camera) -> tuple:
    centre = _centre(obj)
    angles = []
    for light in scene.objects:
        if light.type != "LIGHT" or light.hide_render or light.data.energy <= 0.0:
            continue
        if light.data.type == "SUN":
            toward = light.matrix_world.to_3x3().col[2].normalized()  # shines along -Z
        else:
            toward = (light.matrix_world.translation - centre).normalized()
        cosine = max(-1.0, min(1.0, toward.dot(toward_camera)))
        angles.append(round(math.degrees(math.acos(cosine)), 1))
    return tuple(sorted(set(angles))) or (ENVIRONMENT_LIGHT_DEG,)


def describe_scene(scene, material=None, obj=None):
    """The :class:`lut_baker.auto_tier.SceneDescription` of ``scene`` for ``obj`` (default:
    the nearest object wearing ``material``), or None without a camera or an object."""
    samples, denoise = _samples(scene)
    objects = [obj] if obj is not None else (_wearers(material, scene) if material else [])
    if scene.camera is None or not objects:
        return None
    mm_per_unit = 1.0 / units_per_mm(scene)
    best = None
    for item in objects:
        size = max(item.dimensions) * mm_per_unit
        if not size > 0:
            continue
        footprint, toward_camera = _footprint_mm(scene, item, mm_per_unit)
        if best is None or footprint < best[1]:
            best = (item, footprint, size, toward_camera)
    if best is None:
        return None
    item, footprint, size, toward_camera = best
    return auto_tier.SceneDescription(object_size_mm=size, footprint_mm=footprint,
                               lights_deg=_light_angles(scene, item, toward_camera),
                               engine=render_engine(scene), samples=samples, denoise=denoise)


def _meta(material) -> dict:
    """The material's group's record (its bake, subsurface method, measurement), or {}."""
    node = convert.group_node(material)
    return nodes.read_meta(node.node_tree) if node is not None else {}


def _measurement(meta: dict, coverage: float, absorption, *, may_fit: bool, tiers):
    """What the group's fit measured at this coverage and absorption, of ``tiers`` at least:
    kept in its record, or measured now from this session's fit, or (``may_fit``) from a new
    bake and fit (or the missing tiers fitted onto it); None when none of these can be
    had."""
    measured = bakes.measured_at(meta, coverage, absorption, with_traits=True, tiers=tiers)
    if measured is not None or "parameters" not in meta:
        return measured
    method = meta.get("forced_method")
    over = bool(meta.get("over_shader"))
    try:
        got = bakes.cached(meta, method, tiers=tiers, over_shader=over)
        if got is None and may_fit:
            got = bakes.baked(meta, method=method, tiers=tiers, over_shader=over,
                             errors_at=(coverage, absorption))
    except bakes.BakeRecordError:
        return None
    if got is None:
        return None
    return bakes.measure(*got, coverage, absorption, method=meta.get("subsurface_method"),
                        over_shader=over, resolution=meta.get("resolution"))


def material_traits(material, *, refit: bool = False, may_fit: bool = True, scene=None):
    """The :class:`lut_baker.auto_tier.MaterialTraits` of a made-up material at its coverage
    and absorption, the Subsurface Scale and Gloss applied (the values Fit to Scene saved if
    it set them to 0): what its group's fit measured there, of the tiers made for ``scene``'s
    engine (default: every tier) (:mod:`.bakes`; ``refit``: measured again rather than read
    from the record; without ``may_fit`` never a new bake or fit).  Without either: the
    paper preset's traits."""
    settings = material.makeup_skin
    coverage = float(settings.coverage)
    absorption = [float(a) for a in settings.absorption]
    scale = _kept_value(material, "subsurface_scale", SAVED_SCALE_KEY)
    gloss = _kept_value(material, "gloss", SAVED_GLOSS_KEY)
    meta = _meta(material)
    if refit:
        meta = {key: value for key, value in meta.items() if key != "measured"}
    tiers = (auto_tier.ENGINE_TIERS[render_engine(scene)] if scene is not None
             else closure_fit.TIERS)
    measured = _measurement(meta, coverage, absorption, may_fit=may_fit, tiers=tiers)
    traits = bakes.traits(measured) if measured is not None else None
    return (traits or auto_tier.paper_traits()).scaled(scale, gloss)


def _unknown_scene(scene):
    samples, denoise = _samples(scene)
    return auto_tier.SceneDescription(
        object_size_mm=UNKNOWN_SCENE["object_size_mm"],
        footprint_mm=UNKNOWN_SCENE["footprint_mm"], engine=render_engine(scene),
        samples=samples, denoise=denoise)


@dataclass(frozen=True)
class ChoiceScene:
    """What the Auto tier's choice for a material reads of Blender: ``used``, the scene it
    judges in (the described scene, or a close-up), ``described`` (None: the scene was
    unknown), and the material's Subsurface Scale and Gloss (:func:`_kept_value`)."""

    used: auto_tier.SceneDescription
    described: auto_tier.SceneDescription | None
    scale: float
    gloss: float

    def choose(self, traits, tolerance=None):
        """The choice for a material of ``traits`` here (no bpy: any thread may ask)."""
        tolerance = auto_tier.DEFAULT_TOLERANCE if tolerance is None else tolerance
        return auto_tier.choose(self.used, traits.scaled(self.scale, self.gloss),
                                tolerance=tolerance)


def choice_scene(material, scene, *, obj=None) -> ChoiceScene:
    """The :class:`ChoiceScene` of ``material`` in ``scene`` (for ``obj``, default the nearest
    object wearing it; an unknown scene counts as a close-up: :data:`UNKNOWN_SCENE`)."""
    description = describe_scene(scene, material, obj)
    return ChoiceScene(used=description or _unknown_scene(scene), described=description,
                       scale=_kept_value(material, "subsurface_scale", SAVED_SCALE_KEY),
                       gloss=_kept_value(material, "gloss", SAVED_GLOSS_KEY))


def choose_with(traits, material, scene, *, obj=None, tolerance=None):
    """``(Choice, SceneDescription or None)`` for a material of ``traits`` (the Subsurface
    Scale and Gloss of its settings applied here) in ``scene`` (:func:`choice_scene`)."""
    where = choice_scene(material, scene, obj=obj)
    return where.choose(traits, tolerance), where.described


def choose_for(material, scene, *, obj=None, tolerance=None, refit=False, may_fit=True):
    """:func:`choose_with` the material's own traits (:func:`material_traits`; ``refit``,
    ``may_fit`` as there)."""
    description = describe_scene(scene, material, obj)
    tolerance = auto_tier.DEFAULT_TOLERANCE if tolerance is None else tolerance
    choice = auto_tier.choose(description or _unknown_scene(scene),
                       material_traits(material, refit=refit, may_fit=may_fit, scene=scene),
                       tolerance=tolerance)
    return choice, description


def set_choice(material, candidate) -> list[str]:
    """Set the tier, the Subsurface Scale and the Gloss of the choice's ``candidate`` on
    ``material``'s settings (the caller then Applies).  Returns what changed, for the
    report."""
    settings = material.makeup_skin
    changes = []
    live = settings.live_update
    settings.live_update = False  # a tier change would otherwise schedule a preview re-bake
    try:
        if settings.tier != candidate.tier:
            changes.append(f"tier {settings.tier.title()} -> {candidate.tier.title()}")
            settings.tier = candidate.tier
    finally:
        settings.live_update = live
    for on, attribute, key, label in (
            (candidate.subsurface, "subsurface_scale", SAVED_SCALE_KEY, "Subsurface Scale"),
            (candidate.gloss, "gloss", SAVED_GLOSS_KEY, "Gloss")):
        change = _switch(material, attribute, key, label, on)
        if change:
            changes.append(change)
    return changes


def record_choice(material, choice, description) -> None:
    """Keep a :func:`choose_for` result on the material (:data:`.keys.CHOICE_KEY`, JSON) for
    the panel; ``description`` None: the scene was unknown."""
    chosen = choice.chosen
    material[CHOICE_KEY] = json.dumps({
        "candidate": chosen.candidate.name, "tier": chosen.candidate.tier,
        "subsurface": chosen.candidate.subsurface, "gloss": chosen.candidate.gloss,
        "error": chosen.error,
        "best_error": choice.best_error, "cost": chosen.cost,
        "tolerance": choice.tolerance, "reasons": list(choice.reasons),
        "known_scene": description is not None})


def last_choice(material) -> dict | None:
    """The choice :func:`record_choice` kept on ``material``, or None (none, or unreadable)."""
    if material is None or CHOICE_KEY not in material:
        return None
    try:
        return json.loads(material[CHOICE_KEY])
    except ValueError:
        return None


def _kept_value(material, attribute: str, key: str) -> float:
    """A setting Fit to Scene may switch off (Subsurface Scale, Gloss): its value, or the one
    saved under ``key`` while it is off."""
    value = float(getattr(material.makeup_skin, attribute))
    if value <= 0.0 and key in material:
        value = float(material[key])
    return value


def _switch(material, attribute: str, key: str, label: str, on: bool) -> str | None:
    """Switch a setting off (0, its value saved under ``key`` on the material) or back on
    (the saved value restored); the change for the report, or None."""
    settings = material.makeup_skin
    value = float(getattr(settings, attribute))
    if not on and value > 0.0:
        material[key] = value
        setattr(settings, attribute, 0.0)
        return f"{label} {value:g} -> 0"
    if on and value <= 0.0 and key in material:
        setattr(settings, attribute, float(material[key]))
        del material[key]
        return f"{label} 0 -> {getattr(settings, attribute):g}"
    return None


def register():
    """Nothing to register: the Fit to Scene operator is in :mod:`.operators`."""


def unregister():
    """Nothing to forget: the session's fits are :mod:`.bakes`'."""
