"""Made-up Skin in the artist's own material, and back: nothing of theirs is lost.

:func:`install` puts the Made-up Skin group node into a material's node tree and makes it the
Material Output's Surface.  The shader that was the surface stays in the tree, disconnected,
inside a frame labelled :data:`.keys.FRAME_LABEL`, with every link and value it had; what was linked
into its Base Color, Normal and (a Principled BSDF's) Coat Normal is also linked into the
group's Skin Color, Normal and Film Normal, so an albedo texture and a normal map carry over.
The material records the previous surface (:data:`.keys.RECORD_KEY`), and :func:`revert` reconnects
it and removes the group node and the frame (the add-on's own nodes), leaving the tree as it
was.  The Material Output's other inputs (Volume, Displacement) are never touched.

- :func:`group_node` -- the material's Made-up Skin group node, or None.
- :func:`linked_library` -- why a datablock cannot be changed here (linked data), or None.
- :func:`material_output` -- the output node Apply uses.
- :func:`install` -- the group node in place of the surface; returns the carried-over inputs.
- :func:`revert` -- the previous surface back.
"""

from __future__ import annotations

import json

import bpy

from .keys import FRAME_LABEL, FRAME_NAME, GROUP_NODE, RECORD_KEY

__all__ = ["CARRIED_INPUTS", "group_node", "linked_library", "material_output", "install",
           "revert", "can_revert"]

CARRIED_INPUTS = (
    # (the previous shader's inputs, by name in order of preference) -> the group's input
    (("Base Color", "Color"), "Skin Color"),
    (("Normal",), "Normal"),
    (("Coat Normal",), "Film Normal"),
)
"""Links copied from the previous surface shader's inputs to the group's."""
GAP = 60.0
"""Space (node-editor units) between the group node and the framed previous shader."""


def group_node(material):
    """The made-up group node of a material, or None."""
    tree = material.node_tree if material is not None else None
    if tree is None:
        return None
    node = tree.nodes.get(GROUP_NODE)
    return node if node is not None and node.type == "GROUP" else None


def linked_library(datablock, kind: str) -> str | None:
    """A sentence saying why ``datablock`` (a material, node group or mesh, named ``kind``)
    cannot be changed here, or None if it is local and editable."""
    if datablock is None:
        return None
    library = datablock.library
    if library is None and datablock.override_library is not None:
        reference = datablock.override_library.reference
        library = reference.library if reference is not None else None
        if library is not None:
            return (f"{kind} {datablock.name!r} is a library override of data in "
                    f"{library.filepath!r}: changes to its nodes are not saved; make it local "
                    f"first (Object > Library Override > Make Local, or Object > Relations > "
                    f"Make Local) and try again")
    if library is None:
        return None
    return (f"{kind} {datablock.name!r} is linked from the library {library.filepath!r}: "
            f"changes to it are not saved in this file; make it local first (Object > Relations "
            f"> Make Local > Selected Objects, Data and Materials) and try again")


def material_output(tree):
    """The Material Output node the render uses (the active one for all engines, else
    Cycles'); a new one if the tree has none."""
    output = tree.get_output_node("ALL") or tree.get_output_node("CYCLES")
    if output is None:
        output = tree.nodes.new("ShaderNodeOutputMaterial")
        output.location = (400.0, 0.0)
        output.is_active_output = True
    return output


def _first_input(node, names):
    for name in names:
        socket = node.inputs.get(name)
        if socket is not None and socket.enabled:
            return socket
    return None


def _carry_links(tree, previous, group) -> list[str]:
    """Link what feeds ``previous``'s carried inputs into ``group``'s as well."""
    carried = []
    for names, target in CARRIED_INPUTS:
        source = _first_input(previous, names)
        if source is None or not source.is_linked or group.inputs[target].is_linked:
            continue
        link = source.links[0]
        tree.links.new(link.from_socket, group.inputs[target])
        carried.append(f"{source.name} -> {target}")
    return carried


def _frame(tree, node) -> None:
    frame = tree.nodes.new("NodeFrame")
    frame.name = FRAME_NAME
    frame.label = FRAME_LABEL
    location = node.location.copy()
    node.parent = frame
    node.location = location  # parenting keeps the location relative to the frame: restore


def install(material, group) -> list[str]:
    """Make the group ``group`` (a node group) the surface of ``material``, converting the
    artist's tree in place (see the module docstring); a material already converted only gets
    its group node pointed at ``group``.  Returns the inputs carried over (for the report),
    e.g. ``["Base Color -> Skin Color", "Normal -> Normal"]``."""
    if material.node_tree is None and bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    node = group_node(material)
    output = material_output(tree)
    surface = output.inputs["Surface"]
    carried = []
    if node is None:
        node = tree.nodes.new("ShaderNodeGroup")
        node.name = node.label = GROUP_NODE
        node.width = 240
        node.node_tree = group
        previous = surface.links[0] if surface.is_linked else None
        record = {"output": output.name}
        if previous is not None:
            shader = previous.from_node
            record.update(node=shader.name, socket=previous.from_socket.identifier,
                          parent=shader.parent.name if shader.parent else None,
                          location=list(shader.location))
            node.location = (shader.location.x, shader.location.y + shader.dimensions.y
                             + node.dimensions.y + 4 * GAP)
            tree.links.remove(previous)
            carried = _carry_links(tree, shader, node)
            if shader.parent is None:
                _frame(tree, shader)
        else:
            node.location = (output.location.x - node.width - 2 * GAP, output.location.y)
        material[RECORD_KEY] = json.dumps(record)
    node.node_tree = group
    if not (surface.is_linked and surface.links[0].from_node == node):
        tree.links.new(node.outputs["Shader"], surface)
    return carried


def can_revert(material) -> bool:
    """Whether ``material`` was converted by :func:`install` and can go back."""
    return material is not None and RECORD_KEY in material and group_node(material) is not None


def revert(material) -> str:
    """Reconnect the surface ``material`` had before :func:`install` and remove the group node
    and its frame.  Returns what was restored, for the report.

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
    output = tree.nodes.get(record.get("output") or "") or material_output(tree)
    node = group_node(material)
    tree.nodes.remove(node)
    frame = tree.nodes.get(FRAME_NAME)
    if shader is not None:
        socket = next((s for s in shader.outputs if s.identifier == record.get("socket")),
                      shader.outputs[0])
        if frame is not None and shader.parent == frame:
            shader.parent = tree.nodes.get(record.get("parent") or "")
            shader.location = record.get("location", list(shader.location))
        tree.links.new(socket, output.inputs["Surface"])
    if frame is not None and not any(n.parent == frame for n in tree.nodes):
        tree.nodes.remove(frame)
    del material[RECORD_KEY]
    return f"{shader.name!r} is the surface again" if shader is not None else "no surface"
