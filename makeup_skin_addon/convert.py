"""Made-up Skin in the artist's own material, and back: nothing of theirs is lost.

:func:`install` puts the Made-up Skin group node into a material's node tree and makes it the
Material Output's Surface.  How depends on what the surface was (docs/addon.md, "Over the
artist's skin"):

- **The artist's shader** (anything but Blender's untouched default Principled BSDF,
  :func:`.artist_shader.read`): it stays linked, into the group's Skin Shader input, and
  renders as it is wherever the film does not cover (Coverage 0 renders as before Apply).  The
  group is one built over a shader (:func:`.nodes.over_shader`).  Under the film the group
  takes the skin that shader describes (:mod:`.artist_skin`): its Skin Color is fed by nodes
  the add-on adds (in a frame, :data:`.keys.SKIN_FRAME_NAME`) that follow the shader's own
  structure: each skin BSDF's Base Color source scaled by the share of it that BSDF renders as
  body colour, mixed as its Mix Shaders mix (the same factors) and added as its Add Shaders
  add; its Normal, Subsurface Radius (times Subsurface Scale) and Subsurface Weight are the
  dominant skin BSDF's.  What is computed inside the artist's node groups is brought out by
  copying the nodes that compute it (:mod:`.node_copy`); the groups are never edited.  When
  the skin's Normal comes from a Normal Map (or Bump) node and no Coat Normal is linked, the
  film gets its own copy of that node at a fraction of its strength
  (:data:`.keys.FILM_NORMAL_NODE`; :func:`set_film_normal`).
- **No shader of the artist's** (no surface, or Blender's own untouched default): the group is
  the skin preset's made-up skin, bare skin included; a default shader that was there stays
  in the tree, disconnected, inside a frame (:data:`.keys.FRAME_LABEL`).

Every node the add-on adds carries :data:`.keys.OWNED_KEY`.  The material records the previous
surface (:data:`.keys.RECORD_KEY`), and :func:`revert` reconnects it, removes the add-on's own
nodes (and nothing else), and removes the node group and images the material's made-up skin
leaves unused.  The Material Output's other inputs (Volume, Displacement) are never touched.

- :func:`group_node` -- the material's Made-up Skin group node, or None.
- :func:`linked_library` -- why a datablock cannot be changed here (linked data), or None.
- :func:`material_output` -- the output node Apply uses.
- :func:`artist_tree` -- the artist's shader tree of a material, converted or not.
- :func:`install` -- the group node in place of the surface; returns what was carried over.
- :func:`set_film_normal` -- the film's normal node's strength, linked or not.
- :func:`revert` -- the previous surface back.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import bpy

from . import artist_shader, group_parts, node_copy, skin_nodes
from .keys import (
    BASE_STRENGTH_KEY,
    FILM_NORMAL_NODE,
    FIT_KEY,
    FRAME_LABEL,
    FRAME_NAME,
    GROUP_NODE,
    OWNED_KEY,
    RECORD_KEY,
    VIEW_IMAGE_PREFIX,
)

__all__ = ["Installed", "group_node", "linked_library", "material_output", "artist_tree",
           "install", "set_film_normal", "film_normal_node", "revert", "can_revert",
           "owned_nodes", "RECORD_VERSION"]

GAP = 60.0
"""Space (node-editor units) between the nodes Apply places."""
RECORD_VERSION = 2
"""What the record of the previous surface means: 2, the group goes over the artist's shader
(its Skin Shader input); absent (1), an earlier add-on framed and disconnected the shader."""


@dataclass
class Installed:
    """What :func:`install` did, for the report: ``carried`` (sentences' parts, e.g. "Base
    Color -> Skin Color"), ``values`` (group input -> value taken from the shader, the skin
    preset's groups only), ``missing`` (what was not carried over and what is used instead),
    ``film_normal`` (a sentence about the film's normal, or ""), ``first`` (the material was
    converted now), ``over_shader`` (the artist's shader is the bare skin)."""

    carried: list = field(default_factory=list)
    values: dict = field(default_factory=dict)
    missing: list = field(default_factory=list)
    film_normal: str = ""
    first: bool = False
    over_shader: bool = False


def group_node(material):
    """The made-up group node of a material, or None."""
    tree = material.node_tree if material is not None else None
    if tree is None:
        return None
    node = tree.nodes.get(GROUP_NODE)
    return node if node is not None and node.type == "GROUP" else None


def linked_library(datablock, kind: str) -> str | None:
    """A sentence saying why ``datablock`` (a material, node group or mesh, named ``kind``)
    cannot be changed here, or None if it is local and editable.  The library is named by its
    file name: Blender cuts a greyed-out button's reason at 200 characters."""
    if datablock is None:
        return None
    library = datablock.library
    if library is None and datablock.override_library is not None:
        reference = datablock.override_library.reference
        library = reference.library if reference is not None else None
        if library is not None:
            return (f"{kind} {datablock.name!r} is a library override of data in "
                    f"{bpy.path.basename(library.filepath)!r}: its nodes are not saved; make "
                    f"it local (Object > Library Override > Make Local)")
    if library is None:
        return None
    return (f"{kind} {datablock.name!r} is linked from the library "
            f"{bpy.path.basename(library.filepath)!r}: changes are not saved; make it local "
            f"(Object > Relations > Make Local)")


def material_output(tree):
    """The Material Output node the scene's engine renders
    (:func:`.artist_shader.render_output`); a new one if the tree has none."""
    output = artist_shader.render_output(tree)
    if output is None:
        output = tree.nodes.new("ShaderNodeOutputMaterial")
        output.location = (400.0, 0.0)
        output.is_active_output = True
    return output


def owned_nodes(material) -> list:
    """The nodes of ``material``'s tree the add-on added (:data:`.keys.OWNED_KEY`)."""
    tree = material.node_tree if material is not None else None
    return [node for node in tree.nodes if node.get(OWNED_KEY)] if tree is not None else []


def artist_tree(material):
    """The artist's shader tree of ``material`` (:func:`.artist_shader.read`): behind its
    surface before Apply, behind the group's Skin Shader input after; None when there is
    none."""
    node = group_node(material)
    if node is None:
        return artist_shader.read(material)
    shader = node.inputs.get("Skin Shader")
    if shader is None or not shader.is_linked:
        return None
    return artist_shader.behind(shader)


def film_normal_node(material):
    """The film's own normal node (:data:`.keys.FILM_NORMAL_NODE`) in ``material``, or None."""
    tree = material.node_tree if material is not None else None
    return tree.nodes.get(FILM_NORMAL_NODE) if tree is not None else None


# -- the film's normal ----------------------------------------------------------------------

def set_film_normal(material, follows: bool, strength: float) -> None:
    """The film's normal node (:func:`film_normal_node`) at ``strength`` times the skin's
    strength, linked to the group's Film Normal when ``follows`` (else the film is smooth:
    the pores filled).  A material without that node is left alone."""
    copy = film_normal_node(material)
    node = group_node(material)
    if copy is None or node is None:
        return
    base = float(copy.get(BASE_STRENGTH_KEY, copy.inputs["Strength"].default_value))
    copy.inputs["Strength"].default_value = base * float(strength)
    target = node.inputs["Film Normal"]
    linked_here = target.is_linked and target.links[0].from_node == copy
    if follows and not target.is_linked:
        material.node_tree.links.new(copy.outputs["Normal"], target)
    elif not follows and linked_here:
        material.node_tree.links.remove(target.links[0])


# -- install and revert -------------------------------------------------------------------------

def _frame(tree, node) -> None:
    frame = tree.nodes.new("NodeFrame")
    frame.name = FRAME_NAME
    frame.label = FRAME_LABEL
    node_copy.mark(frame)
    location = node.location.copy()
    node.parent = frame
    node.location = location  # parenting keeps the location relative to the frame: restore


def _remove_skin_nodes(material) -> None:
    """The add-on's nodes that feed the group the skin (everything it owns but the group
    node and the frame of an untouched default shader), removed before they are built again."""
    tree = material.node_tree
    for node in owned_nodes(material):
        if node.name != FRAME_NAME:
            tree.nodes.remove(node)


def install(material, group, *, over_shader: bool, reading=None, film_strength: float = 0.5,
            film_follows: bool = True) -> Installed:
    """Make the group ``group`` (a node group) the surface of ``material``, converting the
    artist's tree in place (see the module docstring); a material already converted gets its
    group node pointed at ``group`` and, over the artist's shader, the skin under the film
    read again (``reading``: :class:`.artist_skin.SkinReading` of :func:`artist_tree`).
    ``over_shader``: ``group`` is one built over the artist's shader
    (:func:`.nodes.over_shader`); ``film_strength``, ``film_follows``: the film's normal node
    (:func:`set_film_normal`).  Returns what was carried over (:class:`Installed`)."""
    if material.node_tree is None and bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    node = group_node(material)
    record = (json.loads(material[RECORD_KEY]) if node is not None and material.get(RECORD_KEY)
              else None)
    if record is not None and record.get("version") != RECORD_VERSION and over_shader:
        revert(material, remove_unused=False)  # an earlier add-on's conversion: again, over
        node = record = None
    output = (_recorded_output(tree, record.get("output")) if record is not None
              else material_output(tree))
    surface = output.inputs["Surface"]
    installed = Installed(over_shader=over_shader)
    if node is None:
        installed.first = True
        node = tree.nodes.new("ShaderNodeGroup")
        node.name = node.label = GROUP_NODE
        node.width = 240
        node.node_tree = group
        previous = surface.links[0] if surface.is_linked else None
        record = {"output": output.name, "version": RECORD_VERSION}
        node.location = (output.location.x - node.width - 2 * GAP, output.location.y)
        if previous is not None:
            shader, socket = previous.from_node, previous.from_socket
            record.update(node=shader.name, socket=socket.identifier,
                          parent=shader.parent.name if shader.parent else None,
                          location=list(shader.location))
            tree.links.remove(previous)
            if over_shader:
                tree.links.new(socket, node.inputs["Skin Shader"])
            elif shader.parent is None:
                _frame(tree, shader)
        material[RECORD_KEY] = json.dumps(record)
    node.node_tree = group
    if not (surface.is_linked and surface.links[0].from_node == node):
        tree.links.new(node.outputs["Shader"], surface)
    if over_shader and reading is not None:
        _remove_skin_nodes(material)
        carried = skin_nodes.carry_skin(tree, node, artist_tree(material), reading,
                                        film_strength, film_follows)
        installed.carried += carried.carried
        installed.film_normal = carried.film_normal
        installed.missing = carried.missing
    for target, other in artist_shader.other_outputs(tree, output):
        installed.missing.append(_other_output_sentence(tree, target, other, output))
    return installed


def _other_output_sentence(tree, target: str, other, output) -> str:
    engine = artist_shader.TARGET_NAMES[target]
    preview = " (and so does the viewport's Material Preview)" if target == "EEVEE" else ""
    made_up = " and ".join(artist_shader.engines_rendering(tree, output)) or "no engine"
    return (f"the output {other.name!r}, which {engine} renders{preview}: it keeps its own "
            f"shader, without the film, which went over {output.name!r}, the one {made_up} "
            f"renders (to make up the other instead: Revert, set the scene's engine to "
            f"{engine}, Apply)")


def _recorded_output(tree, name: str | None):
    """The Material Output a converted material's group feeds, ``name`` in its record (else
    the one the scene's engine renders): a later Apply in another engine's scene keeps to it."""
    output = tree.nodes.get(name or "")
    return output if output is not None and output.type == "OUTPUT_MATERIAL" \
        else material_output(tree)


def can_revert(material) -> bool:
    """Whether ``material`` was converted by :func:`install` and can go back."""
    return material is not None and RECORD_KEY in material and group_node(material) is not None


def _remove_unused(group) -> list[str]:
    """Remove the add-on's node group ``group`` if nothing uses it any more, and the
    view-angle images it read if nothing else does; the names removed."""
    if group is None or group.users > 0 or FIT_KEY not in group:
        return []
    try:
        images = [entry.get("name") for entry in json.loads(group[FIT_KEY]).get("images", [])]
    except (TypeError, ValueError, AttributeError):
        images = []
    removed = group_parts.remove_group(group)
    for name in images:
        image = bpy.data.images.get(name or "")
        if image is not None and image.name.startswith(VIEW_IMAGE_PREFIX) and image.users == 0:
            removed.append(image.name)
            bpy.data.images.remove(image)
    return removed


def revert(material, *, remove_unused: bool = True) -> str:
    """Reconnect the surface ``material`` had before :func:`install`, remove the add-on's own
    nodes (the group node, the skin under the film's, the film's normal, frames) and, with
    ``remove_unused``, the node group and view-angle images no other material uses.  Returns
    what was restored, for the report.

    Raises
    ------
    ValueError
        If the material was not converted, or its previous surface was deleted since.
    """
    if not can_revert(material):
        raise ValueError(f"material {material.name!r} has no surface from before Made-up Skin "
                         f"to restore")
    try:
        record = json.loads(material[RECORD_KEY])
    except (TypeError, ValueError):
        raise ValueError(f"material {material.name!r}: the record of its previous surface is "
                         f"unreadable") from None
    tree = material.node_tree
    shader = tree.nodes.get(record.get("node") or "")
    if record.get("node") and shader is None:
        raise ValueError(f"material {material.name!r}: its previous surface "
                         f"{record['node']!r} was deleted; nothing was changed")
    output = _recorded_output(tree, record.get("output"))
    node = group_node(material)
    group = node.node_tree
    frame = tree.nodes.get(FRAME_NAME)
    if shader is not None and frame is not None and shader.parent == frame:
        shader.parent = tree.nodes.get(record.get("parent") or "")
        shader.location = record.get("location", list(shader.location))
    tree.nodes.remove(node)
    for owned in owned_nodes(material):
        tree.nodes.remove(owned)
    frame = tree.nodes.get(FRAME_NAME)  # an earlier add-on's frame is not marked as owned
    if frame is not None and not any(n.parent == frame for n in tree.nodes):
        tree.nodes.remove(frame)
    if shader is not None:
        socket = next((s for s in shader.outputs if s.identifier == record.get("socket")),
                      shader.outputs[0])
        tree.links.new(socket, output.inputs["Surface"])
    del material[RECORD_KEY]
    removed = _remove_unused(group) if remove_unused else []
    restored = f"{shader.name!r} is the surface again" if shader is not None else "no surface"
    if removed:
        restored += f"; removed {', '.join(repr(n) for n in removed)}, which nothing else uses"
    return restored
