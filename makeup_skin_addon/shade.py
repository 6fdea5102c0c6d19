"""What the panel's shade, film and skin settings mean in the model.

- The settings as a made-up skin (:func:`skin_from_settings`, of the settings or of their
  plain values, :func:`skin_settings`): the foundation and skin presets,
  Film Roughness and Skin Roughness (Blender roughness, :mod:`lut_baker.model.roughness`: the
  preset's own unless moved), Film IOR with its override, and over the artist's shader its
  skin's index.
- The colour seen (:func:`colour_seen`, :func:`absorption_for_colour`): a shade picked by the
  colour the product has in the bottle, the thick layer of :mod:`lut_baker.model.thick_layer`
  against the exchange the measured presets were derived with (nothing is integrated).
- The skin preset's own colour (:func:`skin_colour`): Skin Color's value or, when an image
  texture feeds it, the mean of the image over the faces that use the material
  (:func:`.skin_sampling.surface_mean`: area-weighted, read at the faces' UVs, linear).
- :func:`assigning`: settings the add-on assigns, not the user (the update callbacks leave the
  shade's origin alone).
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

import numpy as np

from . import convert, skin_sampling
from .core import cache, presets, roughness, thick_layer

__all__ = [
    "ROUGHNESS_TOLERANCE",
    "ROUGHNESS_MAX",
    "FILM_ROUGHNESS_MIN",
    "SKIN_ROUGHNESS_MIN",
    "SkinColour",
    "foundation_roughness",
    "skin_roughness",
    "has_film_gloss",
    "skin_from_settings",
    "SkinSettings",
    "skin_settings",
    "colour_seen",
    "absorption_for_colour",
    "preset_colour",
    "colour_note",
    "skin_colour",
    "assigning",
    "is_assigning",
    "clear_cache",
]

ROUGHNESS_MAX = float(roughness.roughness_for_width(60.0))
"""The roughest lobe the panel offers (0.856: 60 degrees wide); beyond it the Layered tier's
film lobe breaks the white furnace (docs/stability.md, the "rougher" regime)."""
FILM_ROUGHNESS_MIN = float(roughness.roughness_for_width(1.0))
"""The smoothest film gloss (0.147: a lobe 1 degree wide)."""
SKIN_ROUGHNESS_MIN = 0.5
"""The smoothest skin gloss (a lobe 12 degrees wide): path 3 goes through the skin's gloss, so
a narrower lobe scales the bake's grids (``bake.path3_width_deg``); at 0.5 a first Apply still
takes under a second (docs/addon.md, "Skin Roughness")."""

ROUGHNESS_TOLERANCE = 1e-5
"""A roughness this close to the preset's is the preset's (the panel stores float32)."""
CHANNELS = ("Red", "Green", "Blue")
_ROUGHENED = cache.LRUCache(32)
_assigning = [0]


# -- the settings as a made-up skin --------------------------------------------------------

def foundation_roughness(name: str) -> float:
    """The Film Roughness of a foundation preset: its surface gloss's lobe as a roughness."""
    return roughness.layer_roughness(presets.foundation_film(name))


def skin_roughness(name: str) -> float:
    """The Skin Roughness of a skin preset."""
    return roughness.layer_roughness(presets.skin_layers(name)[0])


def has_film_gloss(name: str) -> bool:
    """Whether a foundation's film has a surface gloss to roughen (a matte product has none)."""
    return bool(np.any(presets.foundation_film(name).P_s > 0.0))


def _roughened(layer, value: float, own: float):
    """``layer`` at roughness ``value`` unless that is its own ``own`` (kept for the session:
    a repeated Apply integrates nothing)."""
    if abs(float(value) - own) <= ROUGHNESS_TOLERANCE:
        return layer
    key = (repr(sorted(layer.as_dict().items())), float(value))
    return _ROUGHENED.get_or_compute(key, lambda: roughness.with_roughness(layer, float(value)))


@dataclass(frozen=True)
class SkinSettings:
    """What :func:`skin_from_settings` reads of the panel's settings, as plain values (read on
    the main thread, the skin made from them on a worker: :func:`skin_settings`)."""

    foundation: str
    skin: str
    film_roughness: float
    skin_roughness: float
    over_shader: bool
    skin_ior: float
    override_film: bool
    film_ior: float


def skin_settings(settings) -> SkinSettings:
    """The :class:`SkinSettings` of a material's settings now."""
    return SkinSettings(**{name: getattr(settings, name)
                           for name in SkinSettings.__dataclass_fields__})


def skin_from_settings(settings, foundation: str | None = None):
    """The made-up skin the settings describe, at coverage 1 and absorption 0 (both are socket
    values, applied after the bake).  Film Roughness reshapes the film surface's gloss and
    Skin Roughness the skin's (eq. 2's lobe, its gloss albedo kept,
    :func:`lut_baker.model.roughness.with_roughness`); a roughness equal to the preset's leaves
    its layer as it is.  Film IOR (with Override Film IOR) replaces the index of the film's
    surface and of its transmission's Fresnel term; the film's transmission lobe stays the
    foundation's, since it is set by the pigment the light crosses, not by the surface
    (docs/model.md §4).  ``foundation``: another foundation preset's film instead of the
    settings' (at its own roughness).  ``settings``: the material's, or their
    :class:`SkinSettings` (no bpy: any thread)."""
    name = settings.foundation if foundation is None else foundation
    skin = presets.made_up_skin(name, settings.skin, coverage=1.0, absorption=0.0)
    own = foundation_roughness(name)
    film = _roughened(skin.film, settings.film_roughness if foundation is None else own, own)
    surface = _roughened(skin.skin_reflection, settings.skin_roughness,
                         skin_roughness(settings.skin))
    skin = skin.replace(film=film, skin_reflection=surface)
    if settings.over_shader:
        # The skin under the film has the artist's index (docs/addon.md, "Over the artist's
        # skin"): its surface's Fresnel term, and the dipole's boundary.
        eta = max(float(settings.skin_ior), 1.0)
        skin = skin.replace(
            skin_reflection=skin.skin_reflection.scaled(
                eta=eta / float(skin.skin_reflection.eta)),
            dipole=skin.dipole.scaled(eta=eta / float(skin.dipole.eta)))
    if settings.override_film:
        skin = skin.replace(
            film=skin.film.scaled(eta=settings.film_ior / float(skin.film.eta)),
            film_transmission=skin.film_transmission.scaled(
                eta=settings.film_ior / float(skin.film_transmission.eta)))
    return skin


# -- the colour seen ---------------------------------------------------------------------------

def colour_seen(absorption) -> np.ndarray:
    """The colour of the foundation's thick layer at ``absorption`` (linear Rec.709 under
    uniform white light: the bottle, a swatch), :func:`lut_baker.model.thick_layer.
    stack_reflectance`."""
    return thick_layer.stack_reflectance(np.asarray(absorption, float),
                                         thick_layer.preset_film_exchange())


def absorption_for_colour(colour) -> tuple[np.ndarray, np.ndarray]:
    """``(absorption, clamped)`` per channel whose thick layer has ``colour``."""
    return thick_layer.solve_absorption(np.asarray(colour, float)[:3],
                                        thick_layer.preset_film_exchange())


def preset_colour(name: str) -> np.ndarray:
    """A foundation preset's colour seen: a measured product's measured colour, else the thick
    layer of its absorption."""
    entry = presets.FOUNDATIONS[name]
    if "colour" in entry:
        return np.asarray(entry["colour"], float)
    return colour_seen(entry["absorption"])


def colour_note(colour, clamped) -> str:
    """The panel's words for a picked colour the film cannot reach (per channel), or ""."""
    if not np.any(clamped):
        return ""
    exchange = thick_layer.preset_film_exchange()
    lightest = float(thick_layer.stack_reflectance(0.0, exchange))
    parts = []
    for name, value, out in zip(CHANNELS, np.asarray(colour, float)[:3], clamped, strict=True):
        if out and value > lightest:
            parts.append(f"{name} {value:.3f} is lighter than the film can be ({lightest:.3f})")
        elif out:
            parts.append(f"{name} {value:.3f} is darker than its gloss alone "
                         f"({exchange.r_gloss:.3f})")
    return "; ".join(parts) + ": clamped"


# -- the skin's own colour ------------------------------------------------------------------

@dataclass
class SkinColour:
    """The skin's own diffuse albedo ``rgb`` (linear) and where it came from (``source``, the
    end of a sentence)."""

    rgb: np.ndarray
    source: str


def _image_feeding(socket):
    """``(image texture node, route)`` feeding ``socket`` through reroutes, or, further up,
    the first image texture behind colour nodes (route: their names), or ``(None, ...)``."""
    route = []
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


def _uv_map(texture) -> tuple[str, str]:
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


def skin_colour(material) -> SkinColour:
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


@contextlib.contextmanager
def assigning():
    """Settings assigned inside are the add-on's, not the user's: the properties' update
    callbacks leave the shade's origin alone (:func:`is_assigning`)."""
    _assigning[0] += 1
    try:
        yield
    finally:
        _assigning[0] -= 1


def is_assigning() -> bool:
    """Whether the add-on itself is assigning settings (:func:`assigning`)."""
    return _assigning[0] > 0


def clear_cache() -> None:
    """Forget the session's roughened layers (the add-on's unregister calls it)."""
    _ROUGHENED.clear()

