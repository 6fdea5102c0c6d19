"""A mesh's attribute at points of its surface, as an Attribute or a Color Attribute node
reads it: what :mod:`.surface_values` evaluates a skin painted in vertex colours by.

An attribute is found by name among the mesh's attributes (an empty name: the colour attribute
set to render, as the Color Attribute node reads it), copied out of Blender whole and
interpolated over each point's triangle (:class:`.surface_points.Points`: its corners and
weights), a corner's value or its vertex's; a face's value is the face's.  Colours are linear
(Blender's float and byte colours alike), RGBA; a vector is XYZ (a 2D one's Z 0), a number is
grey, each with alpha 1.

- :class:`Found` -- an attribute's values at the points, or why there are none.
- :func:`at_points` -- one object's attribute at its points.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .surface_points import Points, corner_faces, corner_verts

__all__ = ["Found", "at_points", "DOMAINS"]

DOMAINS = ("POINT", "CORNER", "FACE")
"""The domains read (an edge's value is not on a face)."""

_FIELDS = {"FLOAT_COLOR": ("color", 4, np.float32), "BYTE_COLOR": ("color", 4, np.float32),
           "FLOAT_VECTOR": ("vector", 3, np.float32), "FLOAT2": ("vector", 2, np.float32),
           "FLOAT": ("value", 1, np.float32), "INT": ("value", 1, np.int32),
           "INT8": ("value", 1, np.int32), "BOOLEAN": ("value", 1, np.bool_)}
"""Data types read: the field their values are copied by, its width and type (a byte colour's
``color`` is linear, as its float's)."""


@dataclass(frozen=True)
class Found:
    """``values`` ((n, 4) float: RGBA, XYZ and 1, or grey and 1) and the attribute's
    ``colour`` (whether it holds colours), or ``problem`` (why not: the values are then None)."""

    values: np.ndarray | None
    colour: bool = False
    problem: str = ""


def _named(mesh, name: str):
    if not name:
        attributes = mesh.color_attributes
        index = attributes.render_color_index
        return attributes[index] if 0 <= index < len(attributes) else None
    return mesh.attributes.get(name)


def at_points(obj, name: str, points: Points) -> Found:
    """The attribute ``name`` of ``obj``'s mesh ("": its render colour attribute) at
    ``points`` (:class:`Found`)."""
    mesh = obj.data
    attribute = _named(mesh, name)
    label = repr(name) if name else "to render"
    if attribute is None:
        return Found(None, problem=f"{obj.name!r} has no attribute {label}")
    kind = _FIELDS.get(attribute.data_type)
    if kind is None or attribute.domain not in DOMAINS:
        return Found(None, problem=f"{obj.name!r}'s attribute {attribute.name!r} is "
                                   f"{attribute.data_type} on {attribute.domain}: not read")
    field, width, dtype = kind
    raw = np.empty(len(attribute.data) * width, dtype)
    attribute.data.foreach_get(field, raw)
    values = raw.astype(np.float32).reshape(-1, width)
    if attribute.domain == "CORNER":
        picked = points.interpolated(values)
    elif attribute.domain == "POINT":
        picked = points.interpolated(values, corner_verts(mesh))
    else:  # a face's value: every corner of the point's triangle is of its face
        picked = values[corner_faces(mesh)[points.corners[0]]]
    out = np.zeros((len(picked), 4))
    out[:, 3] = 1.0
    if width == 1:
        out[:, :3] = picked
    else:
        out[:, :width] = picked
    return Found(out, colour=field == "color")
