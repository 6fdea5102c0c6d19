"""The nodes that give the Made-up Skin group, over the artist's shader, the skin under the film
(:func:`carry_skin`, for :func:`.convert.install`): they follow the shader's own structure.

Its Skin Color is fed by nodes added in a frame (:data:`.keys.SKIN_FRAME_NAME`): each skin
BSDF's Base Color source scaled by the share of it that BSDF renders as body colour, mixed as
its Mix Shaders mix (the same factors) and added as its Add Shaders add; its Normal,
Subsurface Radius (times Subsurface Scale) and Subsurface Weight are the dominant skin BSDF's.
What is computed inside the artist's node groups is brought out by copying the nodes that
compute it (:mod:`.node_copy`); the groups are never edited.  When the skin's Normal comes from
a Normal Map (or Bump) node and no Coat Normal is linked, the film gets its own copy of that
node at a fraction of its strength (:data:`.keys.FILM_NORMAL_NODE`).

- :func:`carry_skin` -- the skin under the film fed to the group node; :class:`Carried` what
  was carried over.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import bpy
import numpy as np

from . import node_copy
from .artist_shader import Add, Leaf, Source, source
from .keys import BASE_STRENGTH_KEY, FILM_NORMAL_NODE, SKIN_FRAME_LABEL, SKIN_FRAME_NAME

__all__ = ["Carried", "carry_skin"]


@dataclass
class Carried:
    """What :func:`carry_skin` carried over: ``carried`` (sentences' parts, e.g. "Normal ->
    Normal"), ``film_normal`` (a sentence about the film's normal, or ""), ``missing`` (what
    was not carried over and what is used instead)."""

    carried: list[str] = field(default_factory=list)
    film_normal: str = ""
    missing: list[str] = field(default_factory=list)


class _SkinNodes:
    """Adds the nodes that give the group the skin under the film, inside their frame."""

    def __init__(self, tree, location):
        self.tree = tree
        frame = tree.nodes.new("NodeFrame")
        frame.name, frame.label = SKIN_FRAME_NAME, SKIN_FRAME_LABEL
        node_copy.mark(frame)
        self.frame = frame
        self.location = location
        self.count = 0
        self.copier = node_copy.copier(tree, (location[0] - 600.0, location[1]))

    def node(self, kind: str, label: str, **props):
        node = self.tree.nodes.new(kind)
        node_copy.mark(node)
        node.label = label
        node.location = (self.location[0] - 220.0 * (self.count % 3),
                         self.location[1] - 200.0 * (self.count // 3))
        self.count += 1
        for name, value in props.items():
            setattr(node, name, value)
        return node

    def out(self, where: Source):
        """A socket of the material's tree (or a value) giving ``where``."""
        value = node_copy.bring_out(where, self.tree, copier=self.copier)
        return value

    def finish(self) -> None:
        for node in list(self.copier.copies.values()):
            node.parent = self.frame
        if not any(n.parent == self.frame for n in self.tree.nodes):
            self.tree.nodes.remove(self.frame)


def _is_socket(value) -> bool:
    return isinstance(value, bpy.types.NodeSocket)


def _rgb(value) -> np.ndarray:
    array = np.asarray(value if value is not None else 0.0, float).ravel()
    return np.repeat(array[:1], 3) if array.size == 1 else array[:3]


def _mix_colour(nodes: _SkinNodes, blend: str, factor, a, b, label: str):
    """``a`` and ``b`` (sockets or RGB values) blended by a Mix node (``blend``: ``"MIX"`` by
    ``factor``, ``"ADD"``, ``"MULTIPLY"`` at factor 1); constants fold."""
    if not any(_is_socket(v) for v in (factor, a, b)):
        f = float(np.clip(float(factor), 0.0, 1.0))
        a, b = _rgb(a), _rgb(b)
        return {"MIX": a + f * (b - a), "ADD": a + b, "MULTIPLY": a * b}[blend]

    def constant(value, number: float) -> bool:
        return not _is_socket(value) and bool(np.all(_rgb(value) == number))

    if blend == "ADD" and constant(b, 0.0) or blend == "MULTIPLY" and constant(b, 1.0):
        return a
    if blend == "ADD" and constant(a, 0.0):
        return b
    if blend == "MIX" and not _is_socket(factor) and float(factor) in (0.0, 1.0):
        return a if float(factor) <= 0.0 else b
    node = nodes.node("ShaderNodeMix", label, data_type="RGBA", blend_type=blend)
    node.clamp_factor = True
    for identifier, value in (("Factor_Float", factor), ("A_Color", a), ("B_Color", b)):
        target = next(s for s in node.inputs if s.identifier == identifier)
        if _is_socket(value):
            nodes.tree.links.new(value, target)
        elif identifier == "Factor_Float":
            target.default_value = float(value)
        else:
            target.default_value = (*map(float, _rgb(value)), 1.0)
    return next(s for s in node.outputs if s.identifier == "Result_Color")


def _body_colour(nodes: _SkinNodes, shader, reading):
    """The body colour of ``shader`` (a shader tree) as nodes: each skin leaf's Base Color
    source times its factor (:class:`.artist_skin.LeafReading`), the Mix Shaders' mixes and
    the Add Shaders' sums of them; a leaf without a body is black."""
    if shader is None:
        return np.zeros(3)
    if isinstance(shader, Leaf):
        factor = reading.factor_of(shader)
        name = "Base Color" if shader.node.type == "BSDF_PRINCIPLED" else "Color"
        if factor is None or not np.any(factor) or name not in shader.node.inputs:
            return np.zeros(3)
        base = nodes.out(source(shader.node.inputs[name], shader.groups))
        return _mix_colour(nodes, "MULTIPLY", 1.0, base, factor,
                           f"{shader.node.name}: body color")
    first = _body_colour(nodes, shader.first, reading)
    second = _body_colour(nodes, shader.second, reading)
    if isinstance(shader, Add):
        return _mix_colour(nodes, "ADD", 1.0, first, second, f"{shader.node.name}: sum")
    return _mix_colour(nodes, "MIX", nodes.out(shader.factor), first, second,
                       f"{shader.node.name}: mix")


def _link_or_set(tree, value, target) -> None:
    if _is_socket(value):
        tree.links.new(value, target)
    elif value is not None and hasattr(target, "default_value"):
        current = target.default_value
        if isinstance(current, (int, float)):
            target.default_value = float(np.ravel(value)[0])
        else:
            target.default_value = (*map(float, _rgb(value)), 1.0)[:len(current)]


def _radius(nodes: _SkinNodes, node, groups):
    """The dominant skin BSDF's Subsurface Radius times Subsurface Scale (scene units), a
    socket or a value."""
    radius_name = "Subsurface Radius" if node.type == "BSDF_PRINCIPLED" else "Radius"
    scale_name = "Subsurface Scale" if node.type == "BSDF_PRINCIPLED" else "Scale"
    radius = nodes.out(source(node.inputs[radius_name], groups))
    scale = nodes.out(source(node.inputs[scale_name], groups))
    if not _is_socket(radius) and not _is_socket(scale):
        return _rgb(radius) * float(scale)
    product = nodes.node("ShaderNodeVectorMath", f"{node.name}: radius x scale",
                         operation="SCALE")
    _link_or_set(nodes.tree, radius, product.inputs[0])
    scale_input = next(s for s in product.inputs if s.identifier == "Scale")
    _link_or_set(nodes.tree, scale, scale_input)
    return product.outputs["Vector"]


def carry_skin(tree: Any, node: Any, shader: Any, reading: Any, film_strength: float,
               film_follows: bool) -> Carried:
    """Feed the group node ``node`` (over the artist's shader) the skin under the film read
    from ``shader`` (:class:`.artist_skin.SkinReading` ``reading``), and the film a weaker
    copy of the skin's normal map (``film_strength`` of it; linked if ``film_follows``).
    Returns what was carried over."""
    installed = Carried()
    nodes = _SkinNodes(tree, (node.location.x - 300.0, node.location.y - 500.0))
    colour = _body_colour(nodes, shader, reading)
    _link_or_set(tree, colour, node.inputs["Skin Color"])
    installed.carried.append("the shader's body color -> Skin Color")
    dominant = reading.dominant
    if dominant is not None:
        groups = dominant.groups
        normal = nodes.out(source(dominant.node.inputs["Normal"], groups))
        if _is_socket(normal):
            tree.links.new(normal, node.inputs["Normal"])
            installed.carried.append("Normal -> Normal")
        if dominant.node.type != "BSDF_DIFFUSE":
            _link_or_set(tree, _radius(nodes, dominant.node, groups),
                         node.inputs["Subsurface Radius"])
            installed.carried.append("Subsurface Radius x Scale -> Subsurface Radius")
        weight = (nodes.out(source(dominant.node.inputs["Subsurface Weight"], groups))
                  if dominant.node.type == "BSDF_PRINCIPLED" else reading.subsurface_weight)
        _link_or_set(tree, weight, node.inputs["Subsurface Weight"])
        coat = dominant.node.inputs.get("Coat Normal")
        coat = nodes.out(source(coat, groups)) if coat is not None else None
        if _is_socket(coat):
            tree.links.new(coat, node.inputs["Film Normal"])
            installed.carried.append("Coat Normal -> Film Normal")
        elif _is_socket(normal):
            installed.film_normal = _film_normal(tree, normal, node, film_strength,
                                                 film_follows)
    nodes.finish()
    installed.missing = list(reading.warnings)
    return installed


def _copy_input(tree, source_socket, target) -> None:
    """Give ``target`` (an input) what ``source_socket`` (the same input of another node)
    has: its link, else its value."""
    if source_socket.is_linked:
        tree.links.new(source_socket.links[0].from_socket, target)
    elif hasattr(source_socket, "default_value"):
        target.default_value = source_socket.default_value


def _film_normal(tree, skin_normal, node, strength: float, follows: bool) -> str:
    """Give the film a normal from the skin's (``skin_normal``, the output feeding the
    group's Normal): a copy of its Normal Map or Bump node at ``strength`` times its own, or
    the same output when it has no strength to lower.  Returns the report's sentence."""
    skin_map = skin_normal.node
    if skin_map.type not in {"NORMAL_MAP", "BUMP"}:
        if follows:
            tree.links.new(skin_normal, node.inputs["Film Normal"])
        return (f"Film Normal follows the skin's normal from {skin_map.name!r} at its full "
                f"strength (a Normal Map or Bump node could be weakened)")
    copy = tree.nodes.new("ShaderNodeNormalMap" if skin_map.type == "NORMAL_MAP"
                          else "ShaderNodeBump")
    node_copy.mark(copy)
    copy.name = copy.label = FILM_NORMAL_NODE
    copy.location = (skin_map.location.x, skin_map.location.y - 200.0)
    if skin_map.type == "NORMAL_MAP":
        copy.space, copy.uv_map = skin_map.space, skin_map.uv_map
    else:
        copy.invert = skin_map.invert
    for socket in skin_map.inputs:
        if socket.name != "Strength" and socket.name in copy.inputs:
            _copy_input(tree, socket, copy.inputs[socket.name])
    base = skin_map.inputs["Strength"]
    copy[BASE_STRENGTH_KEY] = float(base.default_value)
    copy.inputs["Strength"].default_value = float(base.default_value) * strength
    if follows:
        tree.links.new(copy.outputs["Normal"], node.inputs["Film Normal"])
    return (f"Film Normal from a copy of {skin_map.name!r} at {strength:g} of its strength "
            f"(the film softens the pores; Film Follows Pores off makes it fill them)")
