"""What feeds an input inside the artist's node groups, brought out into the material's own tree
by copying the nodes that compute it (the artist's groups are never edited).

The made-up skin links the artist's albedo, normal map and subsurface radius into its group
node, which sits in the material's tree; when they are computed inside a node group of the
artist's, a link cannot reach them.  :func:`bring_out` copies the nodes that feed such a
socket, inside the groups entered, into the material's tree: each node as a new node of the
same type with the same settings and unlinked values, a node group node pointing at the same
group (its tree is shared, never copied or changed), and a Group Input replaced by what feeds
that group node's input outside.  Every copy is marked as the add-on's own
(:data:`.keys.OWNED_KEY`), so Revert removes the copies and nothing else.

- :func:`bring_out` -- a socket of the material's tree (or a value) giving what a
  :class:`.artist_shader.Source` gives.
- :func:`copy_node` -- one node copied into another tree (settings and unlinked values).
- :func:`mark` -- mark a node as the add-on's own.
"""

from __future__ import annotations

import bpy

from .artist_shader import Source, source
from .keys import OWNED_KEY

__all__ = ["bring_out", "copy_node", "mark", "SKIPPED_PROPERTIES"]

SKIPPED_PROPERTIES = frozenset({
    "rna_type", "name", "label", "location", "location_absolute", "width", "height",
    "dimensions", "parent", "select", "show_options", "show_preview", "show_texture", "hide",
    "mute", "use_custom_color", "color", "bl_idname", "bl_label", "bl_description",
    "bl_icon", "bl_static_type", "bl_width_default", "bl_width_min", "bl_width_max",
    "bl_height_default", "bl_height_min", "bl_height_max", "type", "inputs", "outputs",
    "internal_links", "is_active_output", "warning_propagation", "color_tag",
})
"""Node properties that are placement or identity, not what the node computes."""


def mark(node) -> None:
    """Mark ``node`` as the add-on's own (Revert removes it)."""
    node[OWNED_KEY] = 1


def _copy_struct(source, target) -> None:
    """Copy the writable plain properties of a nested struct (texture mapping, colour
    mapping, image user)."""
    for prop in source.bl_rna.properties:
        if prop.is_readonly or prop.identifier in SKIPPED_PROPERTIES:
            continue
        try:
            setattr(target, prop.identifier, getattr(source, prop.identifier))
        except (AttributeError, TypeError, ValueError):
            pass


def _copy_ramp(source, target) -> None:
    ramp, copy = source.color_ramp, target.color_ramp
    copy.interpolation = ramp.interpolation
    copy.color_mode = ramp.color_mode
    while len(copy.elements) > 1:
        copy.elements.remove(copy.elements[-1])
    copy.elements[0].position = ramp.elements[0].position
    copy.elements[0].color = ramp.elements[0].color
    for element in ramp.elements[1:]:
        copy.elements.new(element.position).color = element.color


def _copy_curves(source, target) -> None:
    curves, copy = source.mapping, target.mapping
    for name in ("use_clip", "clip_min_x", "clip_min_y", "clip_max_x", "clip_max_y",
                 "black_level", "white_level"):
        if hasattr(curves, name):
            setattr(copy, name, getattr(curves, name))
    for curve, into in zip(curves.curves, copy.curves, strict=True):
        while len(into.points) > len(curve.points):
            into.points.remove(into.points[-1])
        while len(into.points) < len(curve.points):
            into.points.new(0.0, 0.0)
        for point, to in zip(curve.points, into.points, strict=True):
            to.location = tuple(point.location)
            to.handle_type = point.handle_type
    copy.update()


def copy_node(node, tree):
    """A copy of ``node`` in ``tree``: the same type, settings and unlinked input values
    (links are the caller's), marked as the add-on's own."""
    copy = tree.nodes.new(node.bl_idname)
    mark(copy)
    for prop in node.bl_rna.properties:
        identifier = prop.identifier
        if prop.is_readonly or identifier in SKIPPED_PROPERTIES:
            if prop.type == "POINTER" and identifier in {"texture_mapping", "color_mapping",
                                                          "image_user"}:
                _copy_struct(getattr(node, identifier), getattr(copy, identifier))
            continue
        try:
            setattr(copy, identifier, getattr(node, identifier))
        except (AttributeError, TypeError, ValueError):
            pass
    if hasattr(node, "color_ramp") and node.color_ramp is not None:
        _copy_ramp(node, copy)
    if getattr(node, "mapping", None) is not None and hasattr(node.mapping, "curves"):
        _copy_curves(node, copy)
    for original, into in zip(node.inputs, copy.inputs, strict=False):
        value = getattr(original, "default_value", None)
        if value is not None and into.identifier == original.identifier:
            try:
                into.default_value = value
            except (AttributeError, TypeError, ValueError):
                pass
    copy.label = node.label or node.name
    return copy


class _Copier:
    """Copies nodes out of groups into ``tree``, each (node, groups entered) once."""

    def __init__(self, tree, location):
        self.tree = tree
        self.copies: dict = {}
        self.location = location
        self.count = 0

    def socket(self, where: Source):
        """A socket of ``tree`` giving ``where`` (linked sources), or its value."""
        if not where.linked:
            return where.value
        if not where.groups:
            return where.socket
        return self.output(where.socket, where.groups)

    def output(self, socket, groups):
        node = self.node(socket.node, groups)
        return next(s for s in node.outputs if s.identifier == socket.identifier)

    def node(self, node, groups):
        key = (node.as_pointer(), tuple(g.as_pointer() for g in groups))
        copy = self.copies.get(key)
        if copy is not None:
            return copy
        copy = copy_node(node, self.tree)
        copy.location = (self.location[0] - 220 * (self.count // 8),
                         self.location[1] - 180 * (self.count % 8))
        self.count += 1
        self.copies[key] = copy
        for original, into in zip(node.inputs, copy.inputs, strict=False):
            if original.identifier != into.identifier or not original.is_linked:
                continue
            value = self.socket(source(original, groups))
            if isinstance(value, bpy.types.NodeSocket):
                self.tree.links.new(value, into)
            elif value is not None and hasattr(into, "default_value"):
                try:
                    into.default_value = value
                except (TypeError, ValueError):
                    pass
        return copy


def bring_out(where: Source, tree, location=(0.0, 0.0), copier=None):
    """A socket of the material's ``tree`` that gives what ``where`` gives: the socket itself
    when it is in that tree already, a copy of the nodes feeding it when it is inside node
    groups (:func:`copy_node`; a Group Input becomes what feeds the group node outside), or
    the unlinked value.  ``copier``: share copies between calls (a node feeding two inputs is
    copied once); from :func:`copier`."""
    copier = copier or _Copier(tree, location)
    return copier.socket(where)


def copier(tree, location=(0.0, 0.0)) -> _Copier:
    """A copier for several :func:`bring_out` calls into ``tree``."""
    return _Copier(tree, location)
