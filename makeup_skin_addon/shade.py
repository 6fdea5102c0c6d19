"""The panel's shade and roughness: the foundation's colour seen and picked, the presets' own
roughness and its range, the settings the add-on assigns (no bpy).

- The roughness range (:data:`ROUGHNESS_MAX`, :data:`FILM_ROUGHNESS_MIN`,
  :data:`SKIN_ROUGHNESS_MIN`) and the presets' own (:func:`foundation_roughness`,
  :func:`skin_roughness`, :func:`has_film_gloss`): Blender roughness,
  :mod:`lut_baker.model.roughness`.  The settings as the model: :mod:`.skin_model`.
- The colour seen (:func:`colour_seen`, :func:`absorption_for_colour`): a shade picked by the
  colour the product has in the bottle.  With the paper's film, the thick layer of
  :mod:`lut_baker.model.thick_layer` against the exchange the measured presets were derived
  with (nothing is integrated); with the film at a thickness, the slab infinitely thick under
  the foundation's surface, read from its shipped table (:mod:`lut_baker.model.slab_shade`;
  :func:`slab_foundation` says which applies).  The presets' own absorption is the paper
  film's; at a thickness it is the one whose thick limit has the preset's colour
  (:func:`preset_absorption`).
- :func:`assigning`: settings the add-on assigns, not the user (the update callbacks leave the
  shade's origin alone).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

import numpy as np

from .core import presets, roughness, slab_shade, thick_layer
from .keys import PAPER_FILM

__all__ = [
    "ROUGHNESS_TOLERANCE",
    "ROUGHNESS_MAX",
    "FILM_ROUGHNESS_MIN",
    "SKIN_ROUGHNESS_MIN",
    "foundation_roughness",
    "skin_roughness",
    "has_film_gloss",
    "slab_foundation",
    "colour_seen",
    "absorption_for_colour",
    "preset_colour",
    "preset_absorption",
    "colour_note",
    "assigning",
    "is_assigning",
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
_assigning = [0]


# -- the presets' roughness ---------------------------------------------------------------

def foundation_roughness(name: str) -> float:
    """The Film Roughness of a foundation preset: its surface gloss's lobe as a roughness."""
    return roughness.layer_roughness(presets.foundation_film(name))


def skin_roughness(name: str) -> float:
    """The Skin Roughness of a skin preset."""
    return roughness.layer_roughness(presets.skin_layers(name)[0])


def has_film_gloss(name: str) -> bool:
    """Whether a foundation's film has a surface gloss to roughen (a matte product has none)."""
    return bool(np.any(presets.foundation_film(name).P_s > 0.0))


# -- the colour seen ---------------------------------------------------------------------------

def slab_foundation(settings: Any) -> str | None:
    """The foundation whose slab gives the bottle's colour (the settings' Foundation with the
    film at a thickness), or None (the paper's film: the stacked thick layer)."""
    if getattr(settings, "film_mode", PAPER_FILM) == PAPER_FILM:
        return None
    return str(settings.foundation)


def colour_seen(absorption: Any, slab: str | None = None) -> np.ndarray:
    """The colour of the foundation's thick layer at ``absorption`` (linear Rec.709 under
    uniform white light: the bottle, a swatch): :func:`lut_baker.model.thick_layer.
    stack_reflectance`, or with ``slab`` (a foundation preset's name) its slab's thick limit
    (:func:`lut_baker.model.slab_shade.preset_curve`)."""
    if slab is not None:
        return slab_shade.preset_curve(slab).colour(absorption)
    return thick_layer.stack_reflectance(np.asarray(absorption, float),
                                         thick_layer.preset_film_exchange())


def absorption_for_colour(colour: Any, slab: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(absorption, clamped)`` per channel whose thick layer (with ``slab``: that
    foundation's slab, infinitely thick) has ``colour``."""
    if slab is not None:
        return slab_shade.preset_curve(slab).absorption(np.asarray(colour, float)[:3])
    return thick_layer.solve_absorption(np.asarray(colour, float)[:3],
                                        thick_layer.preset_film_exchange())


def preset_colour(name: str) -> np.ndarray:
    """A foundation preset's colour seen: a measured product's measured colour, else the thick
    layer of its absorption (the paper's film: what it was defined by)."""
    entry = presets.FOUNDATIONS[name]
    if "colour" in entry:
        return np.asarray(entry["colour"], float)
    return colour_seen(entry["absorption"])


def preset_absorption(name: str, slab: bool) -> np.ndarray:
    """A foundation preset's absorption: its own (derived on the paper's film), or with the
    film at a thickness (``slab``) the one whose slab, infinitely thick, has the preset's
    colour (docs/model.md, "The thick limit"; a channel out of reach at its limit)."""
    if not slab:
        return np.asarray(presets.FOUNDATIONS[name]["absorption"], float) * np.ones(3)
    return absorption_for_colour(preset_colour(name), name)[0]


def colour_note(colour: Any, clamped: Any, slab: str | None = None) -> str:
    """The panel's words for a picked colour the film cannot reach (per channel), or ""
    (``slab``: as :func:`colour_seen`)."""
    if not np.any(clamped):
        return ""
    lightest = np.broadcast_to(colour_seen(np.zeros(3), slab), (3,))
    darkest = np.broadcast_to(colour_seen(np.ones(3), slab), (3,))
    parts = []
    for c, (name, value, out) in enumerate(zip(CHANNELS, np.asarray(colour, float)[:3],
                                               clamped, strict=True)):
        if out and value > lightest[c]:
            parts.append(f"{name} {value:.3f} is lighter than the film can be "
                         f"({lightest[c]:.3f})")
        elif out:
            parts.append(f"{name} {value:.3f} is darker than the film can be "
                         f"({darkest[c]:.3f}: its gloss alone)")
    return "; ".join(parts) + ": clamped"


@contextlib.contextmanager
def assigning() -> Iterator[None]:
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
