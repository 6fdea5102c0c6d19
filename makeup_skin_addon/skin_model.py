"""The panel's settings as the made-up skin the tables are baked from (no bpy).

The foundation and skin presets give the layers; Film Roughness and Skin Roughness reshape
their gloss (Blender roughness, :mod:`lut_baker.model.roughness`: the preset's own unless
moved); Film IOR with its override replaces the film's index; over the artist's shader the
skin takes its index.  Coverage and absorption are socket values, applied after the bake: the
skin here has coverage 1 and absorption 0; with the film as a slab (Film: at a thickness) the
absorption is baked (the slab is not linear in it, docs/model.md "The tiers at a thickness"),
so the skin carries it, and the bake's film is the thickness (:func:`film_of`).

- :func:`skin_from_settings` -- the made-up skin of the settings, or of their plain values
  (:class:`SkinSettings`, read by :func:`skin_settings` on the main thread, for a worker).
- :func:`film_of` -- the bake's film: the paper's (``"paper"``) or a thickness;
  :func:`skin_under_of` -- the skin under the film where Match Skin darkened it;
  :func:`skin_albedo_of` -- the skin the film covers, at which a slab's fit is made.
- :func:`clear_cache` -- forget the session's roughened layers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .core import cache, presets, roughness
from .keys import PAPER_FILM, SLAB_FILM
from .shade import ROUGHNESS_TOLERANCE, foundation_roughness, skin_roughness

__all__ = ["SkinSettings", "skin_settings", "skin_from_settings", "film_of", "skin_under_of",
           "skin_albedo_of", "clear_cache",
           "PAPER_FILM", "SLAB_FILM"]

_ROUGHENED = cache.LRUCache(32)


def _roughened(layer: Any, value: float, own: float) -> Any:
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
    film_mode: str = PAPER_FILM
    thickness_um: float = 9.6
    absorption: tuple = (0.0, 0.0, 0.0)
    skin_under: tuple = (1.0, 1.0, 1.0)
    skin_body: tuple = (0.0, 0.0, 0.0)
    skin_colour: tuple = (0.0, 0.0, 0.0)


def skin_settings(settings: Any) -> SkinSettings:
    """The :class:`SkinSettings` of a material's settings now."""
    values = {name: getattr(settings, name) for name in SkinSettings.__dataclass_fields__}
    for name in ("absorption", "skin_under", "skin_body", "skin_colour"):
        values[name] = tuple(float(a) for a in values[name])
    return SkinSettings(**values)


def skin_under_of(settings: Any) -> tuple | None:
    """The skin's albedo under the film relative to Skin Color where Match Skin darkened it
    (the film at a thickness only), or None (unchanged)."""
    if film_of(settings) == "paper":
        return None
    under = tuple(float(u) for u in getattr(settings, "skin_under", (1.0, 1.0, 1.0)))
    return None if all(u == 1.0 for u in under) else under


def skin_albedo_of(settings: Any) -> tuple | None:
    """The skin the film covers, at which the film as a slab's closure fit is made and its
    tiers judged (:func:`lut_baker.closures.fitting.fit_closures`' ``skin_albedo``): over the
    artist's shader the mean body colour of the skin under the film as Apply last read it
    (``skin_body``, :func:`.artist_skin.read_material`), without it the Skin Color value;
    None (the skin preset's albedo) for the paper's film, for a Skin Color that is the
    preset's, or before the artist's shader was read."""
    if film_of(settings) == "paper":
        return None
    if not getattr(settings, "over_shader", False):
        colour = tuple(float(c) for c in getattr(settings, "skin_colour", (0.0, 0.0, 0.0)))
        own = tuple(float(c) for c in presets.skin_albedo(settings.skin))
        return None if max(abs(a - b) for a, b in zip(colour, own, strict=True)) < 1e-6 \
            or max(colour) <= 0.0 else colour
    body = tuple(float(b) for b in getattr(settings, "skin_body", (0.0, 0.0, 0.0)))
    return body if max(body) > 0.0 else None


def film_of(settings: Any) -> Any:
    """The bake's film of the settings (:func:`lut_baker.bake.bake`'s ``film``): ``"paper"``
    for the paper's film, else the Thickness in micrometres."""
    if getattr(settings, "film_mode", PAPER_FILM) == PAPER_FILM:
        return "paper"
    return float(settings.thickness_um)


def skin_from_settings(settings: Any, foundation: str | None = None) -> Any:
    """The made-up skin the settings describe, at coverage 1 and absorption 0 (both are socket
    values, applied after the bake; with the film as a slab the absorption is the settings',
    baked: :func:`film_of`).  Film Roughness reshapes the film surface's gloss and
    Skin Roughness the skin's (eq. 2's lobe, its gloss albedo kept,
    :func:`lut_baker.model.roughness.with_roughness`); a roughness equal to the preset's leaves
    its layer as it is.  Film IOR (with Override Film IOR) replaces the index of the film's
    surface and of its transmission's Fresnel term; the film's transmission lobe stays the
    foundation's, since it is set by the pigment the light crosses, not by the surface
    (docs/model.md §4).  ``foundation``: another foundation preset's film instead of the
    settings' (at its own roughness).  ``settings``: the material's, or their
    :class:`SkinSettings` (no bpy: any thread)."""
    name = settings.foundation if foundation is None else foundation
    absorption = (0.0 if film_of(settings) == "paper"
                  else [float(a) for a in settings.absorption])
    skin = presets.made_up_skin(name, settings.skin, coverage=1.0, absorption=absorption)
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


def clear_cache() -> None:
    """Forget the session's roughened layers (the add-on's unregister calls it)."""
    _ROUGHENED.clear()
