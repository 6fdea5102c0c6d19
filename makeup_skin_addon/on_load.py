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

- :func:`damaged_groups` -- the add-on's groups whose images are missing or damaged (no decode).
- :func:`repair_file` -- repair the materials using them; the sentences.
- :func:`check_on_load` -- the persistent ``load_post`` handler.
- :func:`notice` -- the panel's one line about a material repaired (or not) on opening.
"""

from __future__ import annotations

import bpy

from . import material as made_up
from . import nodes, storage
from .keys import FIT_KEY

__all__ = ["damaged_groups", "repair_file", "check_on_load", "notice", "register",
           "unregister"]

REPAIRED = "Repaired damaged lookup image on load"
NOT_REPAIRED = "Damaged lookup image on load: not repaired (see the console)"

_notices: dict[str, str] = {}
"""Material name -> the panel's line about what happened to it when the file was opened."""


def _problems(group) -> list[str]:
    """What is wrong with the images ``group`` records, found without decoding them."""
    return storage.image_problems(nodes.read_meta(group).get("images", ()), decode=False)


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
        node = made_up.group_of(material)
        group = node.node_tree if node is not None else None
        if group not in damaged:
            continue
        del damaged[group]
        try:
            sentence = made_up.check_material(context, material)[1]
        except (ValueError, RuntimeError) as error:
            sentence = f"{material.name!r} could not be repaired: {error}"
        node = made_up.group_of(material)
        repaired = node is not None and not _problems(node.node_tree)
        _notices[material.name] = REPAIRED if repaired else NOT_REPAIRED
        sentences.append(sentence)
    return sentences


@bpy.app.handlers.persistent
def check_on_load(*_args) -> None:
    """The ``load_post`` handler: :func:`repair_file`, each sentence printed on the console."""
    _notices.clear()
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
