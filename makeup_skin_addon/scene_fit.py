"""Fit to Scene: the Auto tier chosen from the scene.

What the scene looks like to the model (:class:`lut_baker.auto_tier.SceneDescription`) comes
from the active camera, the render resolution, the objects wearing the material (the nearest
one: the largest on screen), the lights and the render engine; what the material is
(:class:`lut_baker.auto_tier.MaterialTraits`) from its tables (re-baked from its group's
record) and the tiers' errors of its last Apply.  :func:`lut_baker.auto_tier.choose` then
picks the cheapest candidate within the tolerance.

- :func:`units_per_mm` -- scene units in one millimetre, from the scene's unit scale.
- :func:`auto_tier` -- the tier for ``Tier = Auto`` (called by
  :func:`makeup_skin_addon.material.resolve_tier`; quick, never raises).
- :func:`describe_scene` -- the scene as the model sees it (None without a camera or object).
- :func:`material_traits` -- the material as the model sees it (cached per tables).
- :func:`choose_for` -- the choice for a material in a scene.
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

from . import convert, nodes, storage
from .keys import CHOICE_KEY, ERRORS_KEY, SAVED_GLOSS_KEY, SAVED_SCALE_KEY
from .package import lut_baker

__all__ = ["ENVIRONMENT_LIGHT_DEG", "units_per_mm", "auto_tier", "describe_scene",
           "material_traits", "choose_for", "set_choice", "record_choice", "last_choice",
           "register", "unregister"]

ENVIRONMENT_LIGHT_DEG = 45.0
"""Light angle (degrees from the view) assumed when the scene has no lamp (world light)."""
UNKNOWN_SCENE = {"object_size_mm": 100.0, "footprint_mm": 0.01}
"""Without a camera or an object wearing the material: a close-up (everything resolved)."""


def units_per_mm(scene) -> float:
    """Scene units in one millimetre: ``0.001 / unit_settings.scale_length`` (a scene in
    metres gives 0.001, one modelled in centimetres with scale 0.01 gives 0.1)."""
    scale = float(scene.unit_settings.scale_length) or 1.0
    return 0.001 / scale


def _engine(scene) -> str:
    return "CYCLES" if scene.render.engine == "CYCLES" else "EEVEE"


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
    sm = lut_baker("auto_tier")
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
        footprint = sm.pixel_footprint_mm("ORTHO", max(int(resolution), 1),
                                          ortho_scale_mm=data.ortho_scale * mm_per_unit)
        return footprint, axis
    offset = camera.matrix_world.translation - centre
    depth = max(offset.dot(axis), 1e-9)
    footprint = sm.pixel_footprint_mm("PERSP", max(int(resolution), 1),
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
    sm = lut_baker("auto_tier")
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
    return sm.SceneDescription(object_size_mm=size, footprint_mm=footprint,
                               lights_deg=_light_angles(scene, item, toward_camera),
                               engine=_engine(scene), samples=samples, denoise=denoise)


TRAITS_CACHE_SIZE = 16
"""Material traits kept in this session (:func:`material_traits`, by all they depend on)."""
_TRAITS = lut_baker("numerics.cache").LRUCache(TRAITS_CACHE_SIZE)


def _stored_errors(material, coverage, absorption, key=None):
    """``(tier errors (rms), gloss omissions or None)`` of the last Apply if measured at this
    coverage and absorption (and, when stored, for the tables ``key``: a preview re-bake
    since then changed the tables), else ``(None, None)``."""
    try:
        errors = json.loads(material.get(ERRORS_KEY, "{}"))
    except ValueError:
        return None, None
    if not errors:
        return None, None
    first = next(iter(errors.values()))
    same = (first.get("key", key) == key
            and math.isclose(first.get("coverage", -1.0), coverage, abs_tol=1e-6)
            and all(math.isclose(a, b, abs_tol=1e-6)
                    for a, b in zip(first.get("absorption", []), absorption, strict=False)))
    if not same:
        return None, None
    omission = {tier: {float(angle): float(value)
                       for angle, value in e["gloss_omission"].items()}
                for tier, e in errors.items() if "gloss_omission" in e}
    return ({tier: float(e["rms"]) for tier, e in errors.items()},
            omission if len(omission) == len(errors) else None)


def _meta(material) -> dict:
    """The material's group's record (its bake, subsurface method, profile fits), or {}."""
    node = convert.group_node(material)
    return nodes.read_meta(node.node_tree) if node is not None else {}


def _tables(meta):
    """The tables re-baked from the record, or None if it has none or cannot be re-baked."""
    try:
        return storage.rebake(meta)[0]
    except storage.StorageError:
        return None


def material_traits(material, *, refit: bool = False, may_fit: bool = True):
    """The :class:`lut_baker.auto_tier.MaterialTraits` of a made-up material at its coverage
    and absorption, the Subsurface Scale and Gloss applied (the values Fit to Scene saved if
    it set them to 0).  From its re-baked tables: the profile, the shares of gloss and skin
    light, the profile mismatch of the group's subsurface method; the tier errors and gloss
    omissions of the last Apply, or (``refit``, or none stored for this coverage and
    absorption) of a new closure fit (a few seconds; without ``may_fit``, as when a panel
    draws, the paper preset's tier errors and the tables' gloss share instead).  Without
    tables: the paper preset's traits."""
    sm = lut_baker("auto_tier")
    settings = material.makeup_skin
    coverage = float(settings.coverage)
    absorption = [float(a) for a in settings.effective_absorption()]
    scale = _kept_value(material, "subsurface_scale", SAVED_SCALE_KEY)
    gloss = _kept_value(material, "gloss", SAVED_GLOSS_KEY)
    meta = _meta(material)
    errors, omission = (None, None) if refit else _stored_errors(material, coverage,
                                                                 absorption, meta.get("key"))
    key = (meta.get("key"), meta.get("subsurface_method"), coverage, tuple(absorption),
           None if errors is None else tuple(sorted(errors.items())), omission is not None,
           scale, gloss, may_fit)
    traits = _TRAITS.get(key)
    tables = _tables(meta) if traits is None and meta else None
    if traits is None and tables is None:
        traits = (sm.paper_traits() if (scale, gloss) == (1.0, 1.0)
                  else sm.paper_traits().scaled(scale, gloss))
    elif traits is None:
        if errors is None and may_fit:
            fit = lut_baker("closures.fitting").fit_closures(tables,
                                                        errors_at=(coverage, absorption))
            errors = {tier: float(e.rms) for tier, e in fit.errors.items()}
            omission = sm.gloss_omissions(tables, fit, coverage, absorption)
        elif errors is None:
            errors = dict(sm.PAPER_TIER_ERRORS)
        method = meta.get("subsurface_method")
        profile_error = meta.get("profiles", {}).get(method, {}).get("error", [0.0])
        shares = {angle: sm.gloss_and_skin_shares(tables, angle, coverage, absorption)
                  for angle in sm.SHARE_LIGHTS_DEG}
        traits = sm.MaterialTraits(
            tier_errors=errors, radius_mm=tables.radius_mm, profile=tables.profile,
            profile_mismatch=sm.profile_mismatch(tables, profile_error),
            skin_share={a: v[1] for a, v in shares.items()},
            gloss_share={a: v[0] for a, v in shares.items()}, subsurface_scale=scale,
            gloss_omission=omission, gloss_scale=gloss)
    _TRAITS.put(key, traits)
    return traits


def choose_for(material, scene, *, obj=None, tolerance=None, refit=False, may_fit=True):
    """``(Choice, SceneDescription or None)`` for ``material`` in ``scene`` (an unknown scene
    counts as a close-up: :data:`UNKNOWN_SCENE`); ``refit``, ``may_fit``: as
    :func:`material_traits`."""
    sm = lut_baker("auto_tier")
    description = describe_scene(scene, material, obj)
    chosen_scene = description
    if chosen_scene is None:
        samples, denoise = _samples(scene)
        chosen_scene = sm.SceneDescription(engine=_engine(scene), samples=samples,
                                           denoise=denoise, **UNKNOWN_SCENE)
    tolerance = sm.DEFAULT_TOLERANCE if tolerance is None else tolerance
    choice = sm.choose(chosen_scene, material_traits(material, refit=refit, may_fit=may_fit),
                       tolerance=tolerance)
    return choice, description


def auto_tier(settings, scene) -> str:
    """The add-on tier of the Auto choice for the material of ``settings`` in ``scene``
    (:func:`choose_for`); on any failure the former rule: Layered in Cycles, else
    Principled."""
    material = settings.id_data
    try:
        return choose_for(material, scene, may_fit=False)[0].candidate.tier
    except Exception:  # the panel calls this while drawing: never fail there
        return "LAYERED" if scene.render.engine == "CYCLES" else "PRINCIPLED"


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
    """Forget the session's material traits."""
    _TRAITS.clear()
