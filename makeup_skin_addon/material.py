"""Apply: bake, fit, build or reuse the node group, and make it the surface of the artist's
own material (converted in place, :mod:`.convert`); Revert and Check Tables.

- :func:`skin_from_settings` -- the panel's settings as a :class:`MadeUpSkin` (coverage 1,
  absorption 0: those two are socket values, applied after the bake).
- :func:`resolve_tier` -- the tier for the settings and scene (Auto: from the scene).
- :func:`socket_values` -- the settings' group-node socket values; :func:`update_sockets`
  sets them on a material's group node.
- :func:`refuse_linked` -- :class:`LinkedDataError` for data linked from a library.
- :func:`group_for_tables` -- the group for baked tables (reused when the same tables, tier and
  method were built before and its images are intact).
- :func:`ensure_group` -- bake, then :func:`group_for_tables`.
- :func:`apply_to_object` -- the Apply operator's work; :func:`revert_material` Revert's.
- :func:`check_material` -- verify a made-up material against its bake record, repair it.
"""

from __future__ import annotations

import dataclasses
import json
import math

import bpy

from . import convert, nodes, scene_fit, storage
from .keys import ERRORS_KEY, MATERIAL_NAME, group_name
from .package import lut_baker
from .scene_fit import units_per_mm

__all__ = [
    "LinkedDataError",
    "refuse_linked",
    "revert_material",
    "rebuild_from_settings",
    "skin_from_settings",
    "resolve_tier",
    "forced_method",
    "group_for_tables",
    "ensure_group",
    "group_of",
    "apply_to_object",
    "setup_material",
    "check_material",
    "clear_cache",
    "update_sockets",
    "socket_values",
]


def skin_from_settings(settings):
    """The made-up skin the settings describe, at coverage 1 and absorption 0."""
    presets = lut_baker("model.presets")
    skin = presets.made_up_skin(settings.foundation, settings.skin, coverage=1.0,
                                absorption=0.0)
    if settings.override_film:
        width_deg = math.degrees(settings.film_lobe_width)
        reflection_n = 1.0 / width_deg
        ratio = reflection_n / float(skin.film.n)
        skin = skin.replace(
            film=skin.film.scaled(n=ratio, eta=settings.film_ior / float(skin.film.eta)),
            film_transmission=skin.film_transmission.scaled(
                n=ratio, eta=settings.film_ior / float(skin.film_transmission.eta)))
    return skin


def resolve_tier(settings, scene) -> str:
    """The tier to build: the settings' own, or for Auto the one
    :func:`scene_fit.auto_tier` picks from the scene (:mod:`lut_baker.auto_tier`: the
    cheapest within the tolerance of the best predicted error; EEVEE: Principled)."""
    if settings.tier != "AUTO":
        return settings.tier
    return scene_fit.auto_tier(settings, scene)


def forced_method(settings):
    """The subsurface method the settings force, or None (Auto: the fit's best)."""
    return None if settings.subsurface_method == "AUTO" else settings.subsurface_method


class LinkedDataError(ValueError):
    """The data Apply or Fit to Scene would change is linked from a library."""


def refuse_linked(obj, material) -> None:
    """Raise :class:`LinkedDataError` (naming the library and how to make the data local) if
    ``material``, its Made-up Skin group, or (when Apply must add a material) ``obj``'s mesh is
    linked: changes to linked data are lost when the file is saved."""
    node = convert.group_node(material)
    checks = [(material, "material"), (node.node_tree if node else None, "node group")]
    if material is None and obj is not None:
        checks.append((obj.data, "mesh"))
    for datablock, kind in checks:
        reason = convert.linked_library(datablock, kind)
        if reason is not None:
            raise LinkedDataError(reason)


class _Progress:
    """``window_manager.progress_*`` from 0 to 100 over Apply's stages (does nothing
    headless); ``stage(start, end)`` maps a stage's own 0..1 onto its share."""

    def __init__(self, context):
        self.wm = getattr(context, "window_manager", None)

    def __enter__(self):
        if self.wm is not None:
            self.wm.progress_begin(0, 100)
        return self

    def stage(self, start: float, end: float):
        def report(fraction: float, message: str = "") -> None:
            if self.wm is not None:
                self.wm.progress_update(int(100 * (start + (end - start) * fraction)))
        return report

    def __exit__(self, *exc):
        if self.wm is not None:
            self.wm.progress_end()
        return False


BAKE_SHARE = 0.2
"""Share of Apply's progress bar the bake takes (the closure fit takes the rest: 0.1-0.2 s
against 1-3 s)."""


def _stage(progress, start, end):
    return progress.stage(start, end) if progress is not None else None


def _reusable(group, key: str, tier: str, method, messages: list) -> bool:
    """Whether ``group`` was built from these tables, tier and method by this version and its
    images are intact; a damaged image is reported in ``messages``."""
    meta = nodes.read_meta(group)
    if (meta.get("key"), meta.get("tier"), meta.get("forced_method")) != (key, tier, method):
        return False
    if not nodes.has_interface(group) or "parameters" not in meta:  # an older add-on's
        return False
    problems = storage.image_problems(meta.get("images", []))
    for problem in problems:
        messages.append(f"Group {group.name!r}: {problem}; rebuilt it.")
    return not problems


def group_for_tables(tables, tier: str, *, bake=None, group=None, errors_at=None,
                     method=None, progress=None, messages=None):
    """``(group, fit or None)`` of ``tier`` for baked ``tables``.

    A group already built from the same tables, tier and ``method`` (a forced subsurface
    method, or None for the fit's choice) whose images are intact is reused (no fit) unless
    ``group`` is given, which is then rebuilt in place.  ``bake``: the tables' record
    (:func:`storage.bake_record`; default: from the tables' own parameters at resolution
    "default").  ``errors_at``: ``(coverage, absorption)`` at which to measure the tiers'
    errors when fitting (default: the bake's).  ``progress(fraction, message)``: the fit's.
    ``messages``: a list that gets a sentence for each damaged image found (then rebuilt).
    """
    messages = [] if messages is None else messages
    if bake is None:
        skin = lut_baker("model.params_file").skin_from_dict(tables.parameters)
        bake = storage.bake_record(skin, "default", tables)
    key = bake["key"]
    existing = bpy.data.node_groups.get(group_name(tier, key, method))
    if group is None and existing is not None and _reusable(existing, key, tier, method,
                                                            messages):
        return existing, None
    fit = _fit(tables, key, errors_at, progress)
    target = group if group is not None else existing
    return nodes.build_group(tier, bake, fit, target, method=method), fit


FIT_CACHE_SIZE = 8
"""Closure fits kept per tables key in this session (a fit takes seconds, a bake 0.2 s)."""
_FITS = lut_baker("numerics.cache").LRUCache(FIT_CACHE_SIZE)


def clear_cache() -> None:
    """Forget the session's fits and re-baked tables (the add-on's unregister calls it)."""
    _FITS.clear()
    storage.clear_cache()


def _fit(tables, key: str, errors_at, progress=None):
    """The closure fit of ``tables`` (cached by key), its errors measured at ``errors_at``."""
    cf = lut_baker("closures.fitting")
    fit = _FITS.get(key)
    if fit is None:
        fit = cf.fit_closures(tables, errors_at=errors_at, progress=progress)
    elif errors_at is not None:
        fit = dataclasses.replace(fit, errors=cf.tier_errors(fit, tables, *errors_at))
    _FITS.put(key, fit)
    return fit


def ensure_group(skin, tier: str, resolution: str = "default", *, progress=None, **options):
    """Bake ``skin`` at ``resolution`` and return ``(group, tables, fit or None)``
    (:func:`group_for_tables` for the rest); ``progress``: a :class:`_Progress` or None."""
    tables = lut_baker("bake").bake(skin, resolution, progress=_stage(progress, 0.0,
                                                                      BAKE_SHARE))
    bake = storage.bake_record(skin, resolution, tables)
    group, fit = group_for_tables(tables, tier, bake=bake,
                                  progress=_stage(progress, BAKE_SHARE, 1.0), **options)
    return group, tables, fit


def group_of(material):
    """The made-up group node of a material, or None."""
    return convert.group_node(material)


def setup_material(material, group, scene) -> list[str]:
    """Make ``group`` the surface of ``material`` (:func:`convert.install`: the artist's tree is
    converted in place, their shader kept and framed) and set the group node's inputs from the
    settings.  Returns the inputs carried over from the previous shader."""
    carried = convert.install(material, group)
    nodes.set_inputs(group_of(material), {"Units per mm": units_per_mm(scene)})
    update_sockets(material)
    return carried


def socket_values(settings) -> dict:
    """Group-node socket values of the settings (by socket name)."""
    return {
        "Coverage": settings.coverage,
        "Foundation Absorption": tuple(settings.effective_absorption()),
        "Skin Color": tuple(settings.skin_colour),
        "Subsurface Scale": settings.subsurface_scale,
        "Gloss": settings.gloss,
    }


def update_sockets(material) -> None:
    """Copy the material's socket-level settings onto its group node."""
    node = group_of(material)
    if node is not None:
        nodes.set_inputs(node, socket_values(material.makeup_skin))


def _users(material) -> list:
    """Objects whose slots hold ``material``."""
    return [obj for obj in bpy.data.objects
            if any(slot.material == material for slot in getattr(obj, "material_slots", ()))]


def _material_for(obj):
    """The object's active material, or a new one in its active slot (the object had none)."""
    material = obj.active_material
    if material is not None:
        return material
    material = bpy.data.materials.new(MATERIAL_NAME)
    if obj.material_slots:
        obj.active_material = material
    else:
        obj.data.materials.append(material)
    return material


def apply_to_object(context, obj, *, resolution=None) -> tuple:
    """Bake, fit, build or reuse the group, and make it the surface of ``obj``'s active
    material, converted in place (:func:`setup_material`); an object without a material
    gets a new one.  Returns ``(material, messages)``: the report's sentences (what was
    carried over, how many objects share the material).

    Raises
    ------
    LinkedDataError
        If the material, its group, or the mesh that would get a new material is linked from
        a library (nothing is changed).
    """
    refuse_linked(obj, obj.active_material)
    material = _material_for(obj)
    settings = material.makeup_skin
    first = not settings.is_made_up or group_of(material) is None
    scene = context.scene
    tier = resolve_tier(settings, scene)
    absorption = settings.effective_absorption()
    messages = []
    with _Progress(context) as progress:
        group, tables, fit = ensure_group(
            skin_from_settings(settings), tier, resolution or settings.resolution,
            progress=progress, errors_at=(settings.coverage, absorption),
            method=forced_method(settings), messages=messages)
    if fit is not None:
        omission = lut_baker("auto_tier").gloss_omissions(tables, fit, settings.coverage,
                                                            absorption)
        key = nodes.read_meta(group)["key"]  # the group's bake: no second hash of the tables
        material[ERRORS_KEY] = json.dumps({name: {"rms": e.rms, "albedo": e.albedo,
                                                  "coverage": e.coverage,
                                                  "absorption": list(e.absorption),
                                                  "gloss_omission": omission[name],
                                                  "key": key}
                                           for name, e in fit.errors.items()})
    carried = setup_material(material, group, scene)
    settings.is_made_up = True
    if first:
        kept = ("its previous surface is kept, framed and disconnected (Revert restores it)"
                if convert.can_revert(material) else "it had no surface before")
        linked = f"; linked {', '.join(carried)}" if carried else ""
        messages.append(f"Converted {material.name!r} in place: {kept}{linked}.")
    users = len(_users(material))
    if users > 1:
        messages.append(f"{material.name!r} is shared by {users} objects: all of them show "
                        f"the made-up skin.")
    return material, messages


def revert_material(material) -> str:
    """Give ``material`` back the surface it had before Apply (:func:`convert.revert`); its
    Made-up Skin settings stay for a later Apply.  Returns the report's sentence."""
    reason = convert.linked_library(material, "material")
    if reason is not None:
        raise LinkedDataError(reason)
    restored = convert.revert(material)
    material.makeup_skin.is_made_up = False
    return f"Reverted {material.name!r}: {restored}."


def rebuild_from_settings(context, material, group, resolution: str) -> None:
    """Bake the material's settings at ``resolution``, rebuild ``group`` (its group, or a copy
    of it) in place and make it the material's surface: the live preview's re-bake, and Check
    Tables' repair when the group's record cannot be used."""
    settings = material.makeup_skin
    with _Progress(context) as progress:
        group, _, _ = ensure_group(skin_from_settings(settings),
                                   resolve_tier(settings, context.scene), resolution,
                                   progress=progress, group=group,
                                   method=forced_method(settings))
    setup_material(material, group, context.scene)


def check_material(context, material) -> tuple[bool, str]:
    """Verify a made-up material: its group's record re-bakes to the recorded tables and every
    image the render reads matches its recorded hash; repair what is not by re-baking.
    Returns ``(intact, one sentence for the report)``."""
    name = material.name
    node = group_of(material)
    if node is None or node.node_tree is None:
        return False, (f"{name!r}: its Made-up Skin node is gone from the node tree; Apply "
                       f"puts it back.")
    group = node.node_tree
    reason = convert.linked_library(group, "node group")
    if reason is not None:
        return False, f"{name!r}: not checked: {reason}."
    meta = nodes.read_meta(group)
    if "parameters" not in meta:
        rebuild_from_settings(context, material, group, material.makeup_skin.resolution)
        return False, (f"{name!r}: its group's record is unreadable or from an older "
                       f"version; re-baked it from the panel's settings.")
    try:
        tables, key = storage.rebake(meta)
    except storage.StorageError as error:
        rebuild_from_settings(context, material, group, material.makeup_skin.resolution)
        return False, f"{name!r}: {error}; re-baked it from the panel's settings."
    problems = storage.image_problems(meta.get("images", []))
    note = ("" if key == meta.get("key") else
            " (the tables re-baked here differ from the recorded ones in their last bits: this "
            "numpy rounds differently)")
    if not problems and nodes.has_interface(group):
        return True, f"{name!r}: intact{note}."
    bake = {"key": key, "parameters": meta["parameters"],
            "resolution": meta.get("resolution", "default")}
    group_for_tables(tables, meta.get("tier", "LAYERED"), bake=bake, group=group,
                     method=meta.get("forced_method"))
    what = "; ".join(problems) if problems else "its inputs were of an older version"
    return False, f"{name!r}: {what}; rebuilt it from a re-bake{note}."
