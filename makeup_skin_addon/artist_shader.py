"""The artist's surface shader as the made-up skin reads it (reads only, changes nothing).

Where the film does not cover, the made-up material renders the artist's own surface shader,
whatever it is; under the film it needs the skin that shader describes (docs/addon.md, "Over
the artist's skin").  :func:`read` follows the Material Output's Surface down through reroutes,
Mix Shaders, Add Shaders and node groups (into the group, out through its Group Output) and
returns the shader as a small tree (:class:`Mix`, :class:`Add`, :class:`Leaf`): the BSDFs at its
leaves, with the node groups entered on the way (``groups``, outermost first), so that what
feeds an input inside a group can be followed out again (:func:`source`).

A leaf's ``role`` says what it gives the skin: ``"skin"`` (a Principled BSDF, a Diffuse BSDF, a
Subsurface Scattering BSDF: a body colour, and the Principled a gloss), ``"gloss"`` (a Glossy
BSDF: gloss only) or ``"other"`` (emission, translucency, anything else: rendered as it is where
the film does not cover, not followed under it).

- :class:`Source` -- where an input's value comes from: a value, or a socket of some tree
  inside the groups entered.
- :class:`Leaf`, :class:`Mix`, :class:`Add` -- the shader tree.
- :func:`read` -- the tree behind a material's surface, or None (no surface, or Blender's own
  untouched default Principled BSDF: no skin of the artist's, :func:`is_untouched_default`).
- :func:`behind` -- the tree linked into an input of the material's tree.
- :func:`source` -- where an input (inside the groups entered) gets its value.
- :func:`leaves` -- the leaves of a tree with their shares (the Mix Shaders' factors along the
  way, a linked factor counted by a caller-given mean).
- :func:`is_untouched_default` -- a Principled BSDF exactly as Blender creates it.
- :func:`render_output`, :func:`surface_output` -- the Material Output the scene's engine
  renders (its own, else the one for all engines); :func:`other_outputs` -- those another
  engine renders instead; :func:`engines_rendering` -- the engines an output is for.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import bpy

__all__ = ["Source", "Leaf", "Mix", "Add", "Shader", "SKIN_TYPES", "GLOSS_TYPES", "read",
           "behind", "source", "leaves", "is_untouched_default", "surface_output",
           "render_output", "other_outputs", "engines_rendering", "scene_engine",
           "ENGINE_TARGETS", "TARGET_NAMES"]

SKIN_TYPES = ("BSDF_PRINCIPLED", "BSDF_DIFFUSE", "SUBSURFACE_SCATTERING")
"""Node types with a body colour: a skin under the film."""
GLOSS_TYPES = ("BSDF_GLOSSY",)
"""Node types that only reflect at their surface (a gloss, no body)."""


@dataclass(frozen=True)
class Source:
    """Where an input's value comes from: ``value`` (an unlinked input's, all the way out of
    the groups), or ``socket`` (an output socket of a node of the tree inside ``groups``, the
    group nodes entered, outermost first: ``()`` is the material's own tree)."""

    value: Any = None
    socket: Any = None
    groups: tuple = ()

    @property
    def linked(self) -> bool:
        return self.socket is not None

    @property
    def inside_group(self) -> bool:
        return self.socket is not None and bool(self.groups)


@dataclass(frozen=True)
class Leaf:
    """A shader node at the end of the route: ``node``, the ``groups`` entered to reach it,
    ``role`` (``"skin"``, ``"gloss"`` or ``"other"``) and ``route`` (the nodes passed, for
    sentences)."""

    node: Any
    groups: tuple
    role: str
    route: tuple = ()


@dataclass(frozen=True)
class Mix:
    """A Mix Shader: ``first`` where ``factor`` is 0, ``second`` where it is 1 (either None
    when unlinked: no closure)."""

    node: Any
    groups: tuple
    factor: Source
    first: Any
    second: Any


@dataclass(frozen=True)
class Add:
    """An Add Shader: ``first`` plus ``second`` (either None when unlinked)."""

    node: Any
    groups: tuple
    first: Any
    second: Any


Shader = Leaf | Mix | Add


ENGINE_TARGETS = {"CYCLES": "CYCLES", "BLENDER_EEVEE": "EEVEE", "BLENDER_EEVEE_NEXT": "EEVEE"}
"""A render engine's Material Output target (Blender's own; other engines read the output for
all)."""
TARGET_NAMES = {"CYCLES": "Cycles", "EEVEE": "EEVEE"}
"""The engines that render an output of their own target, as the report names them."""


def scene_engine() -> str:
    """The current scene's render engine ("" without a scene)."""
    scene = getattr(bpy.context, "scene", None)
    return scene.render.engine if scene is not None else ""


def render_output(tree, engine: str | None = None):
    """The Material Output of ``tree`` whose Surface ``engine`` renders (default the scene's):
    the engine's own output if the tree has one, else the one for all engines, else any
    other (Blender's choice, ``get_output_node``); None when there is none."""
    target = ENGINE_TARGETS.get(scene_engine() if engine is None else engine, "ALL")
    return (tree.get_output_node(target) or tree.get_output_node("ALL")
            or tree.get_output_node("CYCLES") or tree.get_output_node("EEVEE"))


def surface_output(material, engine: str | None = None):
    """The Material Output of ``material`` whose Surface ``engine`` renders
    (:func:`render_output`), or None."""
    tree = material.node_tree if material is not None else None
    return render_output(tree, engine) if tree is not None else None


def engines_rendering(tree, output) -> list[str]:
    """The engines (:data:`TARGET_NAMES`) that render ``output`` of ``tree``."""
    return [name for target, name in TARGET_NAMES.items()
            if tree.get_output_node(target) == output]


def other_outputs(tree, output) -> list[tuple[str, Any]]:
    """``[(target, node)]``: the outputs of ``tree`` with a surface that an engine renders
    instead of ``output`` (an output for that engine alone; target "CYCLES" or "EEVEE")."""
    others = []
    for target in TARGET_NAMES:
        node = tree.get_output_node(target)
        if node is not None and node != output and node.inputs["Surface"].is_linked:
            others.append((target, node))
    return others


def _active_group_output(tree):
    outputs = [node for node in tree.nodes if node.type == "GROUP_OUTPUT"]
    return next((node for node in outputs if node.is_active_output), outputs[0] if outputs
                else None)


def source(socket, groups: tuple) -> Source:
    """Where the input ``socket`` (of a node inside ``groups``) gets its value: followed
    through reroutes and out of groups through their Group Input, to an output socket of some
    tree (:class:`Source` with ``socket``), or to an unlinked input's value."""
    while True:
        if not socket.is_linked:
            value = getattr(socket, "default_value", None)
            if value is not None and not isinstance(value, (int, float)):
                value = tuple(value)
            return Source(value=value)
        origin = socket.links[0].from_socket
        node = origin.node
        if node.type == "REROUTE":
            socket = node.inputs[0]
        elif node.type == "GROUP_INPUT" and groups:
            outer = groups[-1]
            socket = next((s for s in outer.inputs if s.identifier == origin.identifier), None)
            if socket is None:
                return Source(value=None)
            groups = groups[:-1]
        else:
            return Source(socket=origin, groups=groups)


def _role(node) -> str:
    if node.type in SKIN_TYPES:
        return "skin"
    if node.type in GLOSS_TYPES:
        return "gloss"
    return "other"


def _walk(socket, groups: tuple, route: tuple, seen: frozenset):
    """The shader tree behind the output socket ``socket``."""
    node = socket.node
    if node.as_pointer() in seen:
        return None
    seen = seen | {node.as_pointer()}
    if node.type == "REROUTE":
        return _linked(node.inputs[0], groups, route, seen)
    if node.type == "MIX_SHADER":
        route = route + (f"Mix Shader {node.name!r}",)
        return Mix(node, groups, source(node.inputs[0], groups),
                   _linked(node.inputs[1], groups, route, seen),
                   _linked(node.inputs[2], groups, route, seen))
    if node.type == "ADD_SHADER":
        route = route + (f"Add Shader {node.name!r}",)
        return Add(node, groups, _linked(node.inputs[0], groups, route, seen),
                   _linked(node.inputs[1], groups, route, seen))
    if node.type == "GROUP" and node.node_tree is not None:
        inner = _active_group_output(node.node_tree)
        target = (next((s for s in inner.inputs if s.identifier == socket.identifier), None)
                  if inner is not None else None)
        if target is None:
            return None
        return _linked(target, groups + (node,), route + (f"node group "
                                                            f"{node.node_tree.name!r}",), seen)
    if node.type == "GROUP_INPUT" and groups:
        outer = groups[-1]
        target = next((s for s in outer.inputs if s.identifier == socket.identifier), None)
        return _linked(target, groups[:-1], route, seen) if target is not None else None
    return Leaf(node, groups, _role(node), route)


def _linked(input_socket, groups, route, seen):
    if input_socket is None or not input_socket.is_linked:
        return None
    return _walk(input_socket.links[0].from_socket, groups, route, seen)


_DEFAULTS: dict = {}


def _principled_defaults() -> dict:
    """Input values of a Principled BSDF as this Blender creates it (read once from a node in
    a temporary group, removed at once)."""
    if not _DEFAULTS:
        group = bpy.data.node_groups.new("Made-up Skin: defaults (temporary)", "ShaderNodeTree")
        try:
            node = group.nodes.new("ShaderNodeBsdfPrincipled")
            for socket in node.inputs:
                value = getattr(socket, "default_value", None)
                if value is not None:
                    _DEFAULTS[socket.identifier] = (value if isinstance(value, (int, float))
                                                    else tuple(value))
            _DEFAULTS["__method__"] = node.subsurface_method
        finally:
            bpy.data.node_groups.remove(group)
    return _DEFAULTS


def is_untouched_default(node) -> bool:
    """Whether ``node`` is a Principled BSDF exactly as Blender creates it (nothing linked,
    every value the default): a material never shaded, not the artist's skin."""
    if node is None or node.type != "BSDF_PRINCIPLED":
        return False
    defaults = _principled_defaults()
    if node.subsurface_method != defaults["__method__"]:
        return False
    for socket in node.inputs:
        if socket.is_linked:
            return False
        value = getattr(socket, "default_value", None)
        if value is None:
            continue
        value = value if isinstance(value, (int, float)) else tuple(value)
        expected = defaults.get(socket.identifier)
        if isinstance(value, tuple):
            if expected is None or any(abs(a - b) > 1e-6 for a, b in zip(value, expected,
                                                                          strict=True)):
                return False
        elif expected is None or abs(value - expected) > 1e-6:
            return False
    return True


def behind(input_socket):
    """The shader tree linked into ``input_socket`` (an input of the material's own tree, such
    as the group's Skin Shader), or None."""
    return _linked(input_socket, (), (), frozenset())


def read(material):
    """The shader tree behind ``material``'s surface (:data:`Shader`), or None when there is
    no surface, or it is Blender's own untouched Principled BSDF (no skin of the artist's: the
    made-up skin then uses its skin preset)."""
    output = surface_output(material)
    if output is None or not output.inputs["Surface"].is_linked:
        return None
    tree = _linked(output.inputs["Surface"], (), (), frozenset())
    if isinstance(tree, Leaf) and not tree.groups and is_untouched_default(tree.node):
        return None
    return tree


def leaves(tree, factor_mean: Callable[[Source], float], share: float = 1.0) -> list:
    """``[(leaf, share)]`` of a shader tree: each leaf with the product of the Mix Shaders'
    factors on its way (``1 - f`` for the first input, ``f`` for the second), a linked factor
    counted as ``factor_mean(source)`` (its mean over the surface), clamped to [0, 1]."""
    if tree is None or share <= 0.0:
        return []
    if isinstance(tree, Leaf):
        return [(tree, share)]
    if isinstance(tree, Add):
        return leaves(tree.first, factor_mean, share) + leaves(tree.second, factor_mean, share)
    factor = tree.factor
    f = factor_mean(factor) if factor.linked else float(factor.value or 0.0)
    f = min(max(float(f), 0.0), 1.0)
    return (leaves(tree.first, factor_mean, share * (1.0 - f))
            + leaves(tree.second, factor_mean, share * f))
