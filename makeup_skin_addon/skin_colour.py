"""The skin preset's own colour on a material: Skin Color's value or, when an image texture
feeds it, the mean of the image over the faces that use the material
(:func:`.skin_sampling.surface_mean`: area-weighted, read at the faces' UVs, linear).  Over
the artist's shader the skin is read from the shader instead (:mod:`.artist_skin`).

- :func:`skin_colour` -- the colour and where it came from (:class:`SkinColour`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from . import convert, skin_sampling

__all__ = ["SkinColour", "skin_colour"]


@dataclass
class SkinColour:
    """The skin's own diffuse albedo ``rgb`` (linear) and where it came from (``source``, the
    end of a sentence)."""

    rgb: np.ndarray
    source: str


def _image_feeding(socket: Any) -> tuple[Any, list[str]]:
    """``(image texture node, route)`` feeding ``socket`` through reroutes, or, further up,
    the first image texture behind colour nodes (route: their names), or ``(None, ...)``."""
    route: list[str] = []
    node = socket.links[0].from_node if socket.is_linked else None
    while node is not None and node.type == "REROUTE":
        node = node.inputs[0].links[0].from_node if node.inputs[0].is_linked else None
    frontier = [node] if node is not None else []
    seen = set()
    while frontier:
        current = frontier.pop(0)
        if current.as_pointer() in seen:
            continue
        seen.add(current.as_pointer())
        if current.type == "TEX_IMAGE" and current.image is not None:
            return current, route
        if current.type != "REROUTE":
            route.append(current.name)
        frontier.extend(link.from_node for s in current.inputs if s.is_linked
                        for link in s.links if s.type in {"RGBA", "VALUE"})
    return None, route


def _uv_map(texture: Any) -> tuple[str, str]:
    """The UV map an image texture reads and a note when it cannot be followed."""
    vector = texture.inputs["Vector"]
    if not vector.is_linked:
        return "", ""
    node = vector.links[0].from_node
    if node.type == "UVMAP":
        return node.uv_map, ""
    if node.type == "TEX_COORD" and vector.links[0].from_socket.name == "UV":
        return "", ""
    return "", f"; its coordinates come from {node.name!r}: read at the mesh's UVs"


def skin_colour(material: Any) -> SkinColour:
    """The diffuse albedo of the skin preset's made-up skin (a material without a shader of
    the artist's; over one, :mod:`.artist_skin` reads the skin): what feeds the group's Skin
    Color, an image texture's mean over the faces that use the material
    (:func:`.skin_sampling.surface_mean`), else Skin Color's value."""
    settings = material.makeup_skin
    value = SkinColour(np.asarray(settings.skin_colour, float), "Skin Color's value")
    node = convert.group_node(material)
    socket = node.inputs["Skin Color"] if node is not None else None
    if socket is None or not socket.is_linked:
        return value
    texture, route = _image_feeding(socket)
    if texture is None:
        value.source = (f"Skin Color's value (Skin Color is fed by {route[0]!r}, whose mean "
                        f"this does not read)" if route else value.source)
        return value
    uv_map, uv_note = _uv_map(texture)
    mean = skin_sampling.surface_mean(texture.image, material, uv_map=uv_map,
                                      extension=texture.extension, reader=texture.name)
    if mean.rgb is None:
        value.source = f"Skin Color's value ({mean.problem})"
        return value
    through = f" through {', '.join(repr(n) for n in route)}" if route else ""
    note = "".join(f"; {n}" for n in mean.notes)
    return SkinColour(mean.rgb, f"the mean of image {texture.image.name!r} over the "
                                f"{mean.faces} faces that use {material.name!r}{through}{note}"
                                f"{uv_note}")
