"""The panel's shade and roughness: the foundation's colour seen and picked, the presets' own
roughness and its range, the settings the add-on assigns (no bpy).

- The roughness range (:data:`ROUGHNESS_MAX`, :data:`FILM_ROUGHNESS_MIN`,
  :data:`SKIN_ROUGHNESS_MIN`) and the presets' own (:func:`foundation_roughness`,
  :func:`skin_roughness`, :func:`has_film_gloss`): Blender roughness,
  :mod:`lut_baker.model.roughness`.  The settings as the model: :mod:`.skin_model`.
- The colour seen (:func:`colour_seen`, :func:`absorption_for_colour`): a shade picked by the
  colour the product has in the bottle, the thick layer of :mod:`lut_baker.model.thick_layer`
  against the exchange the measured presets were derived with (nothing is integrated).
- :func:`assigning`: settings the add-on assigns, not the user (the update callbacks leave the
  shade's origin alone).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

import numpy as np

from .core import presets, roughness, thick_layer

__all__ = [
    "ROUGHNESS_TOLERANCE",
    "ROUGHNESS_MAX",
    "FILM_ROUGHNESS_MIN",
    "SKIN_ROUGHNESS_MIN",
    "foundation_roughness",
    "skin_roughness",
    "has_film_gloss",
    "colour_seen",
    "absorption_for_colour",
    "preset_colour",
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

def colour_seen(absorption: Any) -> np.ndarray:
    """The colour of the foundation's thick layer at ``absorption`` (linear Rec.709 under
    uniform white light: the bottle, a swatch), :func:`lut_baker.model.thick_layer.
    stack_reflectance`."""
    return thick_layer.stack_reflectance(np.asarray(absorption, float),
                                         thick_layer.preset_film_exchange())


def absorption_for_colour(colour: Any) -> tuple[np.ndarray, np.ndarray]:
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


def colour_note(colour: Any, clamped: Any) -> str:
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
