"""On opening a file: the made-up materials' lookup images checked, and repaired, before the
first render.

A packed view-angle image damaged in the file renders magenta (Blender's missing-texture
colour) until Check Tables rebuilds it.  A ``load_post`` handler (:func:`check_on_load`) looks at
every group the add-on built (a node group with the :data:`.keys.FIT_KEY` record) and compares
its images' packed bytes with the recorded hashes (:func:`.storage.image_problems` with
``decode=False``: nothing is decoded, a damaged image least of all).  A material whose group has
a missing or damaged image is repaired as Check Tables does (:func:`.material.check_material`: a
re-bake, 0.02-3 s, and the group rebuilt in place); the add-on's own generated image is all that
changes.  Each repair is printed as one line on the console and kept for the panel
(:func:`notice`), since a handler has no operator report.  A file without a made-up group costs
one pass over its node groups.

The same handler first upgrades the settings of files saved by an earlier add-on
(:func:`upgrade_settings`, :data:`.keys.SETTINGS_VERSION`): their Shade By Color meant the
colour the pigment passes (now the colour seen), their film width was in degrees under Override
Film (now Film Roughness, always on), and their Coverage and Shade By defaulted to 1 and
Absorption; every value they meant is kept, and every material made before the film at a
thickness became the default (versions 1-3) keeps the Film it had: the paper's, unless a
version-3 file chose another.

- :func:`upgrade_settings` -- one material's settings of an older file, upgraded.
- :func:`damaged_groups` -- the add-on's groups whose images are missing or damaged (no decode).
- :func:`repair_file` -- repair the materials using them; the sentences.
- :func:`check_on_load` -- the persistent ``load_post`` handler.
- :func:`notice` -- the panel's one line about a material repaired (or not) on opening.
"""

from __future__ import annotations

import math

import bpy

from . import apply, groups, live, nodes, shade, skin_model, storage
from .core import presets, roughness
from .keys import FIT_KEY, SETTINGS_VERSION

__all__ = ["upgrade_settings", "upgrade_file", "damaged_groups", "repair_file", "check_on_load",
           "notice", "register", "unregister"]

OLD_DEFAULTS = {"coverage": 1.0, "absorption_mode": "ABSORPTION"}
"""Settings whose default changed with version 2, and their version-1 defaults."""
OLD_PROPERTIES = ("is_made_up", "foundation", "skin", "coverage", "absorption_mode",
                  "absorption", "foundation_colour", "override_film", "film_lobe_width",
                  "film_ior", "skin_colour", "gloss", "subsurface_scale", "tier")
"""A version-1 material's settings hold at least one of these."""

REPAIRED = "Repaired damaged lookup image on load"
NOT_REPAIRED = "Damaged lookup image on load: not repaired (see the console)"

_notices: dict[str, str] = {}
"""Material name -> the panel's line about what happened to it when the file was opened."""


def _problems(group) -> list[str]:
    """What is wrong with the images ``group`` records, found without decoding them."""
    return storage.image_problems(nodes.read_meta(group).get("images", ()), decode=False)


def _paper_film(settings) -> None:
    """Settings of a version before the Film setting keep the paper's film (their look)."""
    settings.film_mode = skin_model.PAPER_FILM


def upgrade_settings(settings) -> bool:
    """Upgrade one material's settings written by an earlier add-on to
    :data:`.keys.SETTINGS_VERSION`, keeping what they meant; returns whether it did.  Version 1
    (no ``settings_version``, some setting stored): the colour passed, the film width, the old
    defaults; versions 1 and 2: the paper's film (the Film setting came with version 3);
    version 3: the paper's film unless the file stores another Film (it was the default
    until version 4, whose default is the film at a thickness: a file stores only what was
    set).  Settings of this version, or never touched, are left alone."""
    if settings.is_property_set("settings_version"):
        if settings.settings_version >= SETTINGS_VERSION:
            return False
        with shade.assigning():
            if settings.settings_version < 3 or not settings.is_property_set("film_mode"):
                _paper_film(settings)
            settings.settings_version = SETTINGS_VERSION
        return True
    if not any(settings.is_property_set(name) for name in OLD_PROPERTIES):
        return False
    with shade.assigning():
        _paper_film(settings)
        for name, value in OLD_DEFAULTS.items():
            if not settings.is_property_set(name):
                setattr(settings, name, value)
        if settings.absorption_mode == "COLOUR":  # it meant the colour passed: 1 - A
            settings.absorption = [1.0 - c for c in settings.foundation_colour]
        settings.shade_colour = [float(c) for c in shade.colour_seen(settings.absorption)]
        if settings.foundation in presets.FOUNDATIONS:
            own = shade.foundation_roughness(settings.foundation)
            if settings.override_film and settings.is_property_set("film_lobe_width"):
                width = min(max(math.degrees(settings.film_lobe_width), 1.0), 60.0)
                own = float(roughness.roughness_for_width(width))
            settings.film_roughness = own
        if settings.skin in presets.SKINS:
            settings.skin_roughness = shade.skin_roughness(settings.skin)
        settings.shade_source = "USER"
        settings.settings_version = SETTINGS_VERSION
    return True


def upgrade_file() -> list[str]:
    """:func:`upgrade_settings` for every local material; the names of those upgraded."""
    return [material.name for material in bpy.data.materials
            if material.library is None and upgrade_settings(material.makeup_skin)]


def damaged_groups() -> dict:
    """``{group: [problem, ...]}``: the add-on's local groups (those with a record) whose
    images are missing or whose packed bytes differ from the record; none is decoded."""
    damaged = {}
    for group in bpy.data.node_groups:
        if FIT_KEY in group and group.library is None:
            problems = _problems(group)
            if problems:
                damaged[group] = problems
    return damaged


def repair_file(context) -> list[str]:
    """Repair every material whose group :func:`damaged_groups` finds (one material per group:
    the group is rebuilt in place for all that share it) with :func:`.material.check_material`.
    Returns one sentence per material, and keeps the panel's line (:func:`notice`)."""
    damaged = damaged_groups()
    if not damaged:
        return []
    sentences = []
    for material in bpy.data.materials:
        node = groups.group_of(material)
        group = node.node_tree if node is not None else None
        if group not in damaged:
            continue
        del damaged[group]
        try:
            sentence = apply.check_material(context, material)[1]
        except (ValueError, RuntimeError) as error:
            sentence = f"{material.name!r} could not be repaired: {error}"
        node = groups.group_of(material)
        repaired = node is not None and not _problems(node.node_tree)
        _notices[material.name] = REPAIRED if repaired else NOT_REPAIRED
        sentences.append(sentence)
    return sentences


@bpy.app.handlers.persistent
def check_on_load(*_args) -> None:
    """The ``load_post`` handler: :func:`upgrade_file`, then :func:`repair_file`, each
    sentence printed on the console; the live rebuilds pending for the file before are
    dropped (:func:`.live.forget`)."""
    live.forget()
    _notices.clear()
    upgraded = upgrade_file()
    live.forget()  # upgraded settings mean what their groups were built from: nothing to redo
    if upgraded:
        print(f"Made-up Skin: on opening the file: upgraded the settings of "
              f"{', '.join(repr(name) for name in upgraded)} from an earlier version.")
    for sentence in repair_file(bpy.context):
        print(f"Made-up Skin: on opening the file: {sentence}")


def notice(material) -> str | None:
    """The panel's line about ``material`` being repaired when the file was opened, or None."""
    return _notices.get(material.name) if material is not None else None


def register():
    if check_on_load not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(check_on_load)


def unregister():
    while check_on_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(check_on_load)
    _notices.clear()
