"""Made-up Skin in the artist's own material, and back: nothing of theirs is lost.

:func:`install` puts the Made-up Skin group node into a material's node tree and makes it the
Material Output's Surface.  The shader that was the surface stays in the tree, disconnected,
inside a frame labelled :data:`.keys.FRAME_LABEL`, with every link and value it had.

What the artist's skin shader takes is carried over (:func:`surface_sources`): the surface is
followed through Mix Shaders (the input with the larger share), Add Shaders, reroutes and node
groups (into the group, and back out through its Group Input) down to a Principled BSDF (or a
Diffuse BSDF).  What is linked into its Base Color (Diffuse: Color), Normal and (Principled)
Coat Normal is linked into the group's Skin Color, Normal and Film Normal; an unlinked Base
Color's value becomes the Skin Color; what cannot be carried (a texture inside a node group,
no such shader at all) is named in the report.  When the skin's Normal comes from a Normal
Map (or Bump) node and no Coat Normal is linked, the film gets its own copy of that node at a
fraction of its strength (:data:`.keys.FILM_NORMAL_NODE`; the panel's Film Normal settings,
:func:`set_film_normal`): a film that softens the pores without filling them.

The material records the previous surface (:data:`.keys.RECORD_KEY`), and :func:`revert`
reconnects it and removes the group node, the film's normal node and the frame (the add-on's
own nodes), leaving the tree as it was.  The Material Output's other inputs (Volume,
Displacement) are never touched.

- :func:`group_node` -- the material's Made-up Skin group node, or None.
- :func:`linked_library` -- why a datablock cannot be changed here (linked data), or None.
- :func:`material_output` -- the output node Apply uses.
- :func:`surface_sources` -- what the artist's surface gives the group's inputs.
- :func:`install` -- the group node in place of the surface; returns what was carried over.
- :func:`set_film_normal` -- the film's normal node's strength, linked or not.
- :func:`revert` -- the previous surface back.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import bpy

from .keys import (
    BASE_STRENGTH_KEY,
    FILM_NORMAL_NODE,
    FRAME_LABEL,
    FRAME_NAME,
    GROUP_NODE,
    RECORD_KEY,
)

__all__ = ["CARRIED_INPUTS", "SKIN_SHADERS", "Sources", "Installed", "group_node",
           "linked_library", "material_output", "surface_sources", "install",
           "set_film_normal", "film_normal_node", "revert", "can_revert"]

CARRIED_INPUTS = (
    # (the skin shader's inputs, by name in order of preference) -> the group's input
    (("Base Color", "Color"), "Skin Color"),
    (("Normal",), "Normal"),
    (("Coat Normal",), "Film Normal"),
)
"""Inputs of the artist's skin shader carried over to the group's."""
SKIN_SHADERS = ("BSDF_PRINCIPLED", "BSDF_DIFFUSE")
"""Node types whose Base Color (or Color) is the skin's albedo."""
GAP = 60.0
"""Space (node-editor units) between the group node and the framed previous shader."""


@dataclass
class Sources:
    """What the artist's surface gives the group's inputs (:func:`surface_sources`).

    ``shader``: the skin shader found (None if none), ``route``: the nodes passed on the way
    from the output (Mix Shader, node groups...), ``links``: group input -> the socket of the
    material's own tree to link from, with the shader's input name, ``values``: group input ->
    value (an unlinked Base Color), ``missing``: group input -> why it is not carried."""

    shader: object = None
    route: list = field(default_factory=list)
    links: dict = field(default_factory=dict)
    values: dict = field(default_factory=dict)
    missing: dict = field(default_factory=dict)


@dataclass
class Installed:
    """What :func:`install` did, for the report: ``carried`` (sentences' parts, e.g. "Base
    Color -> Skin Color"), ``values`` (group input -> value taken from the shader),
    ``missing`` (sentences: what was not carried over and why), ``film_normal`` (a sentence
    about the film's normal, or ""), ``first`` (the material was converted now)."""

    carried: list = field(default_factory=list)
    values: dict = field(default_factory=dict)
    missing: list = field(default_factory=list)
    film_normal: str = ""
    first: bool = False


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


def _active_group_output(tree):
    """The active Group Output node of a node group's tree, or None."""
    outputs = [node for node in tree.nodes if node.type == "GROUP_OUTPUT"]
    return next((node for node in outputs if node.is_active_output), outputs[0] if outputs
                else None)


def _shaders(socket, groups: tuple, weight: float, route: tuple, seen: set):
    """``[(shader node, groups, weight, route)]``: the skin shaders behind the output socket
    ``socket`` (a node's output): through reroutes, Mix Shaders (weights ``1 - Fac`` and
    ``Fac``, 1/2 each when Fac is linked), Add Shaders and node groups (``groups``: the group
    nodes entered, outermost first)."""
    node = socket.node
    if node.as_pointer() in seen:
        return []
    seen = seen | {node.as_pointer()}
    if node.type in SKIN_SHADERS:
        return [(node, groups, weight, route)]
    if node.type == "REROUTE":
        return _linked_shaders(node.inputs[0], groups, weight, route, seen)
    if node.type == "MIX_SHADER":
        fac = node.inputs[0]
        share = 0.5 if fac.is_linked else min(max(float(fac.default_value), 0.0), 1.0)
        route = route + (f"Mix Shader {node.name!r}",)
        return (_linked_shaders(node.inputs[1], groups, weight * (1.0 - share), route, seen)
                + _linked_shaders(node.inputs[2], groups, weight * share, route, seen))
    if node.type == "ADD_SHADER":
        route = route + (f"Add Shader {node.name!r}",)
        return (_linked_shaders(node.inputs[0], groups, weight, route, seen)
                + _linked_shaders(node.inputs[1], groups, weight, route, seen))
    if node.type == "GROUP" and node.node_tree is not None:
        inner = _active_group_output(node.node_tree)
        target = (next((s for s in inner.inputs if s.identifier == socket.identifier), None)
                  if inner is not None else None)
        if target is None:
            return []
        return _linked_shaders(target, groups + (node,), weight,
                               route + (f"node group {node.node_tree.name!r}",), seen)
    return []


def _linked_shaders(input_socket, groups, weight, route, seen):
    if not input_socket.is_linked or weight <= 0.0:
        return []
    return _shaders(input_socket.links[0].from_socket, groups, weight, route, seen)


def _source(socket, groups: tuple):
    """``("link", socket)`` of the material's own tree feeding ``socket`` (an input inside the
    ``groups`` entered), ``("value", value)`` when it is unlinked all the way out, or
    ``("missing", why)``."""
    if not socket.is_linked:
        value = getattr(socket, "default_value", None)
        return ("value", tuple(value)[:3]) if value is not None else ("missing", "no value")
    origin = socket.links[0].from_socket
    node = origin.node
    if node.type == "REROUTE":
        return _source(node.inputs[0], groups)
    if node.type == "GROUP_INPUT" and groups:
        outer = groups[-1]
        outer_input = next((s for s in outer.inputs if s.identifier == origin.identifier), None)
        if outer_input is None:
            return "missing", f"node group {outer.node_tree.name!r} has no such input"
        return _source(outer_input, groups[:-1])
    if groups:
        return "missing", (f"it is fed by {node.name!r} inside node group "
                           f"{groups[-1].node_tree.name!r}, which cannot be linked from outside")
    return "link", origin


def surface_sources(material) -> Sources:
    """What the surface of ``material`` gives the group's inputs: the skin shader found behind
    the active Material Output's Surface (the one with the largest share, a Principled BSDF
    first among equals) and, per :data:`CARRIED_INPUTS`, the socket to link from, the value
    (Base Color only), or why neither can be carried."""
    sources = Sources()
    tree = material.node_tree if material is not None else None
    output = (tree.get_output_node("ALL") or tree.get_output_node("CYCLES")) if tree else None
    if output is None or not output.inputs["Surface"].is_linked:
        return sources
    candidates = _linked_shaders(output.inputs["Surface"], (), 1.0, (), set())
    if not candidates:
        shader = output.inputs["Surface"].links[0].from_node
        for _, target in CARRIED_INPUTS[:2]:
            sources.missing[target] = (f"no Principled or Diffuse BSDF behind the surface "
                                       f"({shader.name!r})")
        return sources
    best = max(candidates, key=lambda c: (c[2], c[0].type == "BSDF_PRINCIPLED"))
    sources.shader, groups, _, route = best
    sources.route = list(route)
    for names, target in CARRIED_INPUTS:
        socket = _first_input(sources.shader, names)
        if socket is None:
            continue
        kind, what = _source(socket, groups)
        if kind == "link":
            sources.links[target] = (socket.name, what)
        elif kind == "value" and target == "Skin Color":
            sources.values[target] = what
        elif kind == "missing" and (socket.is_linked or target == "Skin Color"):
            sources.missing[target] = f"{socket.name}: {what}"
    return sources


def film_normal_node(material):
    """The film's own normal node (:data:`.keys.FILM_NORMAL_NODE`) in ``material``, or None."""
    tree = material.node_tree if material is not None else None
    return tree.nodes.get(FILM_NORMAL_NODE) if tree is not None else None


def _copy_input(tree, source, target) -> None:
    """Give ``target`` (an input) what ``source`` (the same input of another node) has: its
    link, else its value."""
    if source.is_linked:
        tree.links.new(source.links[0].from_socket, target)
    elif hasattr(source, "default_value"):
        target.default_value = source.default_value


def _film_normal(tree, skin_normal, node, strength: float, follows: bool) -> str:
    """Give the film a normal from the skin's (``skin_normal``, the output feeding the
    group's Normal): a copy of its Normal Map or Bump node at ``strength`` times its own, or
    the same output when it has no strength to lower.  Returns the report's sentence."""
    source = skin_normal.node
    if source.type not in {"NORMAL_MAP", "BUMP"}:
        if follows:
            tree.links.new(skin_normal, node.inputs["Film Normal"])
        return (f"Film Normal follows the skin's normal from {source.name!r} at its full "
                f"strength (a Normal Map or Bump node could be weakened)")
    copy = tree.nodes.new("ShaderNodeNormalMap" if source.type == "NORMAL_MAP"
                          else "ShaderNodeBump")
    copy.name = copy.label = FILM_NORMAL_NODE
    copy.location = (source.location.x, source.location.y - 200.0)
    if source.type == "NORMAL_MAP":
        copy.space, copy.uv_map = source.space, source.uv_map
    else:
        copy.invert = source.invert
    for socket in source.inputs:
        if socket.name != "Strength" and socket.name in copy.inputs:
            _copy_input(tree, socket, copy.inputs[socket.name])
    base = source.inputs["Strength"]
    copy[BASE_STRENGTH_KEY] = float(base.default_value)
    copy.inputs["Strength"].default_value = float(base.default_value) * strength
    if follows:
        tree.links.new(copy.outputs["Normal"], node.inputs["Film Normal"])
    return (f"Film Normal from a copy of {source.name!r} at {strength:g} of its strength (the "
            f"film softens the pores; Film Follows Pores off makes it fill them)")


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


def _carry(tree, sources: Sources, node, installed: Installed, film_strength: float,
           film_follows: bool) -> None:
    """Link and take over what ``sources`` found into the group node ``node``."""
    for target, (name, origin) in sources.links.items():
        if not node.inputs[target].is_linked:
            tree.links.new(origin, node.inputs[target])
            installed.carried.append(f"{name} -> {target}")
    installed.values = dict(sources.values)
    for target, why in sources.missing.items():
        installed.missing.append(f"{target} ({why})")
    normal = sources.links.get("Normal")
    if normal is not None and "Film Normal" not in sources.links:
        installed.film_normal = _film_normal(tree, normal[1], node, film_strength,
                                             film_follows)


def _frame(tree, node) -> None:
    frame = tree.nodes.new("NodeFrame")
    frame.name = FRAME_NAME
    frame.label = FRAME_LABEL
    location = node.location.copy()
    node.parent = frame
    node.location = location  # parenting keeps the location relative to the frame: restore


def install(material, group, *, film_strength: float = 0.5,
            film_follows: bool = True) -> Installed:
    """Make the group ``group`` (a node group) the surface of ``material``, converting the
    artist's tree in place (see the module docstring); a material already converted only gets
    its group node pointed at ``group``.  ``film_strength``, ``film_follows``: the film's
    normal node (:func:`set_film_normal`).  Returns what was carried over
    (:class:`Installed`)."""
    if material.node_tree is None and bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    node = group_node(material)
    output = material_output(tree)
    surface = output.inputs["Surface"]
    installed = Installed()
    if node is None:
        installed.first = True
        sources = surface_sources(material)
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
            _carry(tree, sources, node, installed, film_strength, film_follows)
            if shader.parent is None:
                _frame(tree, shader)
        else:
            node.location = (output.location.x - node.width - 2 * GAP, output.location.y)
        material[RECORD_KEY] = json.dumps(record)
    node.node_tree = group
    if not (surface.is_linked and surface.links[0].from_node == node):
        tree.links.new(node.outputs["Shader"], surface)
    return installed


def can_revert(material) -> bool:
    """Whether ``material`` was converted by :func:`install` and can go back."""
    return material is not None and RECORD_KEY in material and group_node(material) is not None


def revert(material) -> str:
    """Reconnect the surface ``material`` had before :func:`install` and remove the group node,
    the film's normal node and the frame.  Returns what was restored, for the report.

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
    copy = film_normal_node(material)
    if copy is not None:
        tree.nodes.remove(copy)
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
