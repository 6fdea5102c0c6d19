"""Apply: bake, pack, fit, build or reuse the node group, and give an object the material.

- :func:`skin_from_settings` -- the panel's settings as a :class:`MadeUpSkin` (coverage 1,
  absorption 0: those two are socket values, applied after the bake).
- :func:`resolve_tier` -- the tier for the settings and scene (Auto: Layered for Cycles).
- :func:`units_per_mm` -- scene units in one millimetre, from the scene's unit scale.
- :func:`group_for_tables` -- the group for baked tables (reused when the same tables and tier
  were built before; damaged stored tables are reported and replaced).
- :func:`ensure_group` -- bake, then :func:`group_for_tables`.
- :func:`apply_to_object` -- the Apply operator's work.
- :func:`check_material` -- verify a made-up material's stored tables, re-bake if broken.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections import OrderedDict

import bpy

from . import nodes, scene_fit, storage
from .package import lut_baker
from .properties import socket_values

__all__ = [
    "GROUP_NODE",
    "MATERIAL_NAME",
    "skin_from_settings",
    "resolve_tier",
    "units_per_mm",
    "forced_method",
    "group_for_tables",
    "ensure_group",
    "group_of",
    "apply_to_object",
    "setup_material",
    "check_material",
    "clear_cache",
    "update_sockets",
]

GROUP_NODE = "Made-up Skin"
"""Name of the group node in a made-up material's node tree."""
MATERIAL_NAME = "Made-up Skin"
ERRORS_KEY = "makeup_skin_errors"
"""Material custom property: the tiers' errors at the settings of the last Apply (JSON): per
tier its angular ``rms`` and ``albedo`` errors, ``gloss_omission`` (per light angle, what
Gloss 0 changes in a sphere's image, :func:`lut_baker.scene_model.gloss_omissions`), the
``coverage``, ``absorption`` and tables ``key`` they were measured for."""


def skin_from_settings(settings):
    """The made-up skin the settings describe, at coverage 1 and absorption 0."""
    presets = lut_baker("presets")
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
    :func:`scene_fit.auto_tier` picks from the scene (:mod:`lut_baker.scene_model`: the
    cheapest within the tolerance of the best predicted error; EEVEE: Principled)."""
    if settings.tier != "AUTO":
        return settings.tier
    return scene_fit.auto_tier(settings, scene)


def forced_method(settings):
    """The subsurface method the settings force, or None (Auto: the fit's best)."""
    return None if settings.subsurface_method == "AUTO" else settings.subsurface_method


def units_per_mm(scene) -> float:
    """Scene units in one millimetre: ``0.001 / unit_settings.scale_length`` (a scene in
    metres gives 0.001, one modelled in centimetres with scale 0.01 gives 0.1)."""
    scale = float(scene.unit_settings.scale_length) or 1.0
    return 0.001 / scale


class _Progress:
    """``window_manager.progress_*`` over one bake (does nothing headless)."""

    def __init__(self, context):
        self.wm = getattr(context, "window_manager", None)

    def __enter__(self):
        if self.wm is not None:
            self.wm.progress_begin(0, 100)
        return self

    def __call__(self, fraction: float, message: str = "") -> None:
        if self.wm is not None:
            self.wm.progress_update(int(100 * fraction))

    def __exit__(self, *exc):
        if self.wm is not None:
            self.wm.progress_end()
        return False


def _intact(image) -> tuple[bool, str]:
    try:
        storage.unpack_tables(image)
        return True, ""
    except storage.StorageError as error:
        return False, str(error)


def _group_matches(group, key: str, tier: str, method) -> bool:
    try:
        meta = json.loads(group.get(nodes.FIT_KEY, "{}"))
    except ValueError:
        return False
    if (meta.get("key"), meta.get("tier"), meta.get("forced_method")) != (key, tier, method):
        return False
    if not nodes.has_interface(group):  # built before a socket existed (Gloss): rebuild
        return False
    if tier == "LAYERED":
        lut = bpy.data.images.get(storage.lut_image_name(key))
        # An image of other rows is from an older add-on (before the gloss companion row).
        return lut is not None and lut.size[1] == len(lut_baker("closure_fit").LUT_ROWS)
    return True


def group_for_tables(tables, tier: str, *, messages=None, group=None, errors_at=None,
                     method=None):
    """``(group, fit or None)`` of ``tier`` for baked ``tables``.

    The tables are packed under their content hash; a group already built from the same
    tables, tier and ``method`` (a forced subsurface method, or None for the fit's choice) is
    reused (no fit) unless ``group`` is given, which is then rebuilt in place.  Stored tables
    of that hash that fail their checks are reported in ``messages`` and replaced.
    ``errors_at``: ``(coverage, absorption)`` at which to measure the tiers'
    errors when fitting (default: the bake's).
    """
    messages = [] if messages is None else messages
    key = storage.tables_key(tables)
    image = storage.find_tables_image(key)
    stored_ok = False
    if image is not None:
        stored_ok, problem = _intact(image)
        if not stored_ok:
            messages.append(f"Made-up Skin: stored tables {image.name!r} were broken "
                            f"({problem}); re-baked them")
    image = storage.pack_tables(tables, key)
    existing = bpy.data.node_groups.get(nodes.group_name(tier, key, method))
    if group is None and existing is not None and stored_ok and _group_matches(
            existing, key, tier, method):
        return existing, None
    fit = _fit(tables, key, errors_at)
    target = group if group is not None else existing
    return nodes.build_group(tier, key, fit, image, target, method=method), fit


_FITS: OrderedDict = OrderedDict()
FIT_CACHE_SIZE = 8
"""Closure fits kept per tables key in this session (a fit takes seconds, a bake 0.2 s)."""


def clear_cache() -> None:
    """Forget the session's fits (the add-on's unregister calls it)."""
    _FITS.clear()


def _fit(tables, key: str, errors_at):
    """The closure fit of ``tables`` (cached by key), its errors measured at ``errors_at``."""
    cf = lut_baker("closure_fit")
    fit = _FITS.pop(key, None)
    if fit is None:
        fit = cf.fit_closures(tables, errors_at=errors_at)
    elif errors_at is not None:
        fit = dataclasses.replace(fit, errors=cf.tier_errors(fit, tables, *errors_at))
    _FITS[key] = fit
    while len(_FITS) > FIT_CACHE_SIZE:
        _FITS.popitem(last=False)
    return fit


def ensure_group(skin, tier: str, resolution: str = "default", *, progress=None, **options):
    """Bake ``skin`` at ``resolution`` and return ``(group, tables, fit or None)``
    (:func:`group_for_tables` for the rest)."""
    tables = lut_baker("bake").bake(skin, resolution, progress=progress)
    group, fit = group_for_tables(tables, tier, **options)
    return group, tables, fit


def group_of(material):
    """The made-up group node of a material, or None."""
    tree = material.node_tree if material is not None else None
    if tree is None:
        return None
    node = tree.nodes.get(GROUP_NODE)
    return node if node is not None and node.type == "GROUP" else None


def setup_material(material, group, scene) -> None:
    """Point the material's group node at ``group`` (creating the node and the output link if
    needed; links into the group's inputs, e.g. a painted coverage, are kept)."""
    if material.node_tree is None and bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    node = group_of(material)
    if node is None:
        for other in list(tree.nodes):
            tree.nodes.remove(other)
        node = tree.nodes.new("ShaderNodeGroup")
        node.name = node.label = GROUP_NODE
        node.width = 220
        output = tree.nodes.new("ShaderNodeOutputMaterial")
        output.location = (400, 0)
    node.node_tree = group
    output = next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL"), None)
    if output is None:
        output = tree.nodes.new("ShaderNodeOutputMaterial")
        output.location = (400, 0)
    if not output.inputs["Surface"].is_linked:
        tree.links.new(node.outputs["Shader"], output.inputs["Surface"])
    nodes.set_inputs(node, {"Units per mm": units_per_mm(scene)})
    update_sockets(material)


def update_sockets(material) -> None:
    """Copy the material's socket-level settings onto its group node."""
    node = group_of(material)
    if node is not None:
        nodes.set_inputs(node, socket_values(material.makeup_skin))


def _copy_settings(source, target) -> None:
    for name in source.bl_rna.properties.keys():
        if name in ("rna_type", "name", "is_made_up"):
            continue
        try:
            setattr(target, name, getattr(source, name))
        except (AttributeError, TypeError):
            pass


def _material_for(obj):
    """The object's made-up material, or a new one (settings copied from its active material)
    assigned to its active slot."""
    current = obj.active_material
    if current is not None and current.makeup_skin.is_made_up:
        return current
    material = bpy.data.materials.new(MATERIAL_NAME)
    if current is not None:
        _copy_settings(current.makeup_skin, material.makeup_skin)
    material.makeup_skin.is_made_up = True
    if obj.material_slots:
        obj.active_material = material
    else:
        obj.data.materials.append(material)
    return material


def apply_to_object(context, obj, *, settings=None, resolution=None) -> tuple:
    """Bake, pack, build or reuse the group, and give ``obj`` the made-up material.

    ``settings``: defaults to the object's active material's (copied to the new material).
    Returns ``(material, messages)``; messages are for the operator's report.
    """
    material = _material_for(obj)
    if settings is not None and settings != material.makeup_skin:
        _copy_settings(settings, material.makeup_skin)
    settings = material.makeup_skin
    settings.is_made_up = True
    scene = context.scene
    tier = resolve_tier(settings, scene)
    messages = []
    absorption = settings.effective_absorption()
    with _Progress(context) as progress:
        group, tables, fit = ensure_group(
            skin_from_settings(settings), tier, resolution or settings.resolution,
            progress=progress, messages=messages, errors_at=(settings.coverage, absorption),
            method=forced_method(settings))
    if fit is not None:
        omission = lut_baker("scene_model").gloss_omissions(tables, fit, settings.coverage,
                                                            absorption)
        key = storage.tables_key(tables)
        material[ERRORS_KEY] = json.dumps({name: {"rms": e.rms, "albedo": e.albedo,
                                                  "coverage": e.coverage,
                                                  "absorption": list(e.absorption),
                                                  "gloss_omission": omission[name],
                                                  "key": key}
                                           for name, e in fit.errors.items()})
    setup_material(material, group, scene)
    return material, messages


def check_material(context, material) -> list[str]:
    """Verify a made-up material's group and stored tables; re-bake what is missing or broken.
    Returns the messages to report (empty when all is well)."""
    node = group_of(material)
    problem = None
    if node is None or node.node_tree is None:
        problem = "its node group is missing"
    else:
        try:
            meta = json.loads(node.node_tree.get(nodes.FIT_KEY, "{}"))
            image = bpy.data.images.get(meta.get("tables", ""))
            storage.unpack_tables(image)
            if meta.get("tier") == "LAYERED" and bpy.data.images.get(
                    storage.lut_image_name(meta.get("key", ""))) is None:
                problem = "its view-angle lookup image is missing"
        except (ValueError, storage.StorageError) as error:
            problem = str(error)
    if problem is None:
        return []
    messages = [f"Made-up Skin: material {material.name!r}: {problem}; re-baking"]
    settings = material.makeup_skin
    tier = resolve_tier(settings, context.scene)
    group = node.node_tree if node is not None else None
    with _Progress(context) as progress:
        group, _, _ = ensure_group(skin_from_settings(settings), tier, settings.resolution,
                                   progress=progress, messages=messages, group=group,
                                   method=forced_method(settings))
    setup_material(material, group, context.scene)
    return messages
