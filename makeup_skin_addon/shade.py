"""What the panel's shade, film and skin settings mean in the model, and the shade that matches
the skin (Match Skin, Lighter / Darker).

- The settings as a made-up skin (:func:`skin_from_settings`): the foundation and skin presets,
  Film Roughness and Skin Roughness (Blender roughness, :mod:`lut_baker.model.roughness`: the
  preset's own unless moved), Film IOR with its override.
- The colour seen (:func:`colour_seen`, :func:`absorption_for_colour`): a shade picked by the
  colour the product has in the bottle, the thick layer of :mod:`lut_baker.model.thick_layer`
  against the exchange the measured presets were derived with (nothing is integrated).
- The skin's own colour (:func:`skin_colour`): Skin Color's value or, when an image texture
  feeds it, the mean of the image over the faces that use the material
  (:func:`.skin_sampling.surface_mean`: area-weighted, read at the faces' UVs, linear).
- The shade that matches (:func:`matched`, :func:`stepped`): the absorption whose made-up skin
  has the skin's own colour under uniform light (:mod:`lut_baker.tables.uniform_light`, from
  the settings' tables), or one step (10% in luminance) lighter or darker than the current
  shade; :func:`assign` stores a shade on the settings without marking it the user's
  (:func:`assigning`).
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field

import numpy as np

from . import convert, skin_sampling, storage
from .core import cache, presets, roughness, thick_layer, uniform_light

__all__ = [
    "SHADE_STEP",
    "ROUGHNESS_TOLERANCE",
    "SkinColour",
    "Shade",
    "foundation_roughness",
    "skin_roughness",
    "has_film_gloss",
    "skin_from_settings",
    "colour_seen",
    "absorption_for_colour",
    "preset_colour",
    "colour_note",
    "skin_colour",
    "base_colour_value",
    "BLENDER_DEFAULT_BASE",
    "light_for",
    "matched",
    "first_shade",
    "stepped",
    "assign",
    "assigning",
    "is_assigning",
    "clear_cache",
]

SHADE_STEP = 1.1
"""One shade step of Lighter / Darker: the covered skin's colour times this (10% in
luminance)."""
ROUGHNESS_TOLERANCE = 1e-5
"""A roughness this close to the preset's is the preset's (the panel stores float32)."""
CHANNELS = ("Red", "Green", "Blue")
_LIGHT = cache.LRUCache(8)
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


def skin_from_settings(settings, foundation: str | None = None):
    """The made-up skin the settings describe, at coverage 1 and absorption 0 (both are socket
    values, applied after the bake).  Film Roughness reshapes the film surface's gloss and
    Skin Roughness the skin's (eq. 2's lobe, its gloss albedo kept,
    :func:`lut_baker.model.roughness.with_roughness`); a roughness equal to the preset's leaves
    its layer as it is.  Film IOR (with Override Film IOR) replaces the index of the film's
    surface and of its transmission's Fresnel term; the film's transmission lobe stays the
    foundation's, since it is set by the pigment the light crosses, not by the surface
    (docs/model.md §4).  ``foundation``: another foundation preset's film instead of the
    settings' (at its own roughness)."""
    name = settings.foundation if foundation is None else foundation
    skin = presets.made_up_skin(name, settings.skin, coverage=1.0, absorption=0.0)
    own = foundation_roughness(name)
    film = _roughened(skin.film, settings.film_roughness if foundation is None else own, own)
    surface = _roughened(skin.skin_reflection, settings.skin_roughness,
                         skin_roughness(settings.skin))
    skin = skin.replace(film=film, skin_reflection=surface)
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


BLENDER_DEFAULT_BASE = (0.8, 0.8, 0.8)
"""The Base Color of a new Principled BSDF: a material never coloured, not a skin colour."""


def base_colour_value(settings, sources) -> tuple | None:
    """The unlinked Base Color value the artist's shader gives Skin Color
    (:func:`.convert.surface_sources`), or None: none, Blender's default grey
    (:data:`BLENDER_DEFAULT_BASE`), or Skin Color (or the skin) already set in the panel."""
    value = sources.values.get("Skin Color")
    if value is None or settings.is_property_set("skin_colour"):
        return None
    if np.allclose(value, BLENDER_DEFAULT_BASE, atol=1e-6):
        return None
    return tuple(min(max(float(c), 0.0), 1.0) for c in value)


def skin_colour(material) -> SkinColour:
    """The skin's own diffuse albedo: what feeds the group's Skin Color (or, before Apply, the
    artist's Base Color, :func:`.convert.surface_sources`): an image texture's mean over the
    faces that use the material (:func:`.skin_sampling.surface_mean`), else Skin Color's
    value."""
    settings = material.makeup_skin
    value = SkinColour(np.asarray(settings.skin_colour, float), "Skin Color's value")
    node = convert.group_node(material)
    socket = node.inputs["Skin Color"] if node is not None else None
    if socket is None:
        sources = convert.surface_sources(material)
        base = base_colour_value(settings, sources)
        if base is not None:
            return SkinColour(np.asarray(base, float), "the value of the shader's Base Color")
        link = sources.links.get("Skin Color")
        socket = link[1].links[0].to_socket if link is not None and link[1].links else None
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


# -- matching -------------------------------------------------------------------------------

def light_for(settings, foundation: str | None = None):
    """The settings' made-up skin (with ``foundation``'s film instead, if given) under uniform
    light (:func:`lut_baker.tables.uniform_light.uniform_light` of their tables, re-baked once
    per session)."""
    record = storage.bake_record(skin_from_settings(settings, foundation), settings.resolution)
    return _LIGHT.get_or_compute(record["key"],
                                 lambda: uniform_light.uniform_light(storage.rebake(record)))


@dataclass
class Shade:
    """A shade solved for the covered skin to have ``target``: ``absorption`` and
    ``clamped`` per channel, the covered colour ``reached``, the skin's colour ``skin``, the
    bare skin's colour ``bare`` and the report's ``sentences``."""

    absorption: np.ndarray
    clamped: np.ndarray
    target: np.ndarray
    reached: np.ndarray
    skin: SkinColour
    bare: np.ndarray
    sentences: list = field(default_factory=list)

    def note(self) -> str:
        """The panel's short line about channels out of reach, or ""."""
        out = [name for name, c in zip(CHANNELS, self.clamped, strict=True) if c]
        if not out:
            return ""
        return (f"{' and '.join(out)} out of the film's reach: "
                + ", ".join(f"{name[0]} {r:.3f} for {t:.3f}" for name, r, t, c in
                            zip(CHANNELS, self.reached, self.target, self.clamped, strict=True)
                            if c))


def _solve(settings, light, target, skin: SkinColour) -> Shade:
    gloss = float(settings.gloss)
    absorption, clamped = uniform_light.matching_absorption(light, target, skin.rgb, gloss)
    reached = uniform_light.covered_colour(light, absorption, skin.rgb, gloss)
    bare = uniform_light.bare_colour(light, skin.rgb, gloss)
    return Shade(absorption, clamped, np.asarray(target, float), reached, skin, bare)


def _reach_sentences(shade: Shade, light, gloss: float) -> list[str]:
    sentences = []
    for c, name in enumerate(CHANNELS):
        if not shade.clamped[c]:
            continue
        if shade.absorption[c] == 0.0:
            sentences.append(
                f"{name} is out of reach: the film over this skin reflects at most "
                f"{shade.reached[c]:.3f} (no absorption) against {shade.target[c]:.3f}: the "
                f"made-up skin is that much darker where the film covers it.")
        else:
            floor = gloss * float(light.film_gloss[c])
            sentences.append(
                f"{name} is out of reach: the film's own gloss reflects {floor:.3f} and the "
                f"covered skin at least {shade.reached[c]:.3f} (full absorption) against "
                f"{shade.target[c]:.3f}; a matte product (no gloss: Clarins 103, 108) comes "
                f"closer.")
    return sentences


def matched(material, foundation: str | None = None, skin: SkinColour | None = None) -> Shade:
    """The shade whose made-up skin has the skin's own colour under uniform light at any
    coverage (:func:`lut_baker.tables.uniform_light.matching_absorption` with the bare skin's
    colour as the target: the made-up colour is the areal mix of the bare and the covered
    skin), with the report's sentences; ``foundation``: on that preset's film instead of the
    settings'; ``skin``: the skin's colour if known (:func:`skin_colour`)."""
    settings = material.makeup_skin
    light = light_for(settings, foundation)
    skin = skin_colour(material) if skin is None else skin
    bare = uniform_light.bare_colour(light, skin.rgb, float(settings.gloss))
    shade = _solve(settings, light, bare, skin)
    shade.sentences.append(
        f"Matched the shade to the skin's own colour ({_rgb(bare)} with its gloss; its diffuse "
        f"albedo {_rgb(skin.rgb)} is {skin.source}): absorption {_rgb(shade.absorption)}, "
        f"in the bottle {_rgb(colour_seen(shade.absorption))}.")
    shade.sentences += _reach_sentences(shade, light, float(settings.gloss))
    return shade


MATTE_FILM = "clarins_103"
"""The matte film a first Apply turns to when the skin is darker than the default film's own
gloss (any matte product's film is the same: no surface gloss; this is the first)."""


def _shortfall(shade: Shade) -> float:
    """How far a shade's covered colour misses its target, relative, summed over channels."""
    return float(np.sum(np.abs(shade.reached - shade.target) / np.maximum(shade.target, 1e-6)))


def first_shade(material) -> tuple[str | None, Shade]:
    """The first Apply's shade (docs/addon.md, "A first Apply"): :func:`matched` on the
    settings' film; when the skin is darker than that film's own gloss in some channel (clamped
    at full absorption) and the matte film (:data:`MATTE_FILM`) reaches it better, matched on
    that instead, and its name returned (else None)."""
    skin = skin_colour(material)
    shade = matched(material, skin=skin)
    too_dark = np.any(shade.clamped & (shade.absorption == 1.0))
    if not too_dark or material.makeup_skin.foundation == MATTE_FILM:
        return None, shade
    matte = matched(material, MATTE_FILM, skin)
    if _shortfall(matte) >= _shortfall(shade):
        return None, shade
    label = presets.FOUNDATIONS[MATTE_FILM]["label"]
    matte.sentences.insert(0, f"Chose {label}'s matte film: this skin is darker than the "
                              f"{presets.FOUNDATIONS[material.makeup_skin.foundation]['label']} "
                              f"film's own gloss reaches.")
    return MATTE_FILM, matte


def stepped(material, steps: int) -> Shade:
    """The shade ``steps`` shade steps lighter (positive) or darker than the current one: the
    covered skin's colour times :data:`SHADE_STEP` per step."""
    settings = material.makeup_skin
    light = light_for(settings)
    skin = skin_colour(material)
    gloss = float(settings.gloss)
    current = uniform_light.covered_colour(light, settings.effective_absorption(), skin.rgb,
                                           gloss)
    shade = _solve(settings, light, current * SHADE_STEP ** int(steps), skin)
    word = "lighter" if steps > 0 else "darker"
    shade.sentences.append(
        f"One shade {word}: the covered skin {_rgb(current)} -> {_rgb(shade.reached)}, "
        f"absorption {_rgb(shade.absorption)}, in the bottle "
        f"{_rgb(colour_seen(shade.absorption))}.")
    shade.sentences += _reach_sentences(shade, light, gloss)
    return shade


def _rgb(values) -> str:
    return "(" + ", ".join(f"{float(v):.3f}" for v in values) + ")"


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


def assign(settings, shade: Shade, source: str) -> None:
    """Store ``shade`` on the settings: the absorption, its colour seen, the panel's note and
    where the shade came from (``source``: ``"MATCH"``)."""
    with assigning():
        settings.absorption = [float(a) for a in shade.absorption]
        settings.shade_colour = [float(c) for c in colour_seen(shade.absorption)]
        settings.shade_note = shade.note()
        settings.shade_source = source


def clear_cache() -> None:
    """Forget the session's uniform-light parts and roughened layers (the add-on's unregister
    calls it)."""
    _LIGHT.clear()
    _ROUGHENED.clear()

