"""Parameter presets: the paper's fitted layers (docs/model.md §5), skins from the literature,
shades.

Paper values are 16-bit pixel counts (red channel, applied to all three); they become albedo
units through :func:`lut_baker.model.made_up_skin.from_paper_counts`.  Literature skins are given
directly in albedo units (1/sr) on the same scale.

Functions
---------
- :func:`paper_layers` -- the four layers of docs/model.md §5 in counts.
- :func:`paper` -- the paper's made-up skin (foundation "natural" on the bio-plate), normalised.
- :func:`skin_layers` -- (surface reflection, dipole) of a named skin, albedo units.
- :func:`skin_albedo` -- a named skin's diffuse albedo ``pi P_d`` per RGB channel.
- :func:`made_up_skin` -- a named foundation on a named skin with coverage.
- :func:`foundation_film` -- a named foundation's top-surface reflection (its gloss).

Foundations are the paper's film with a per-channel absorption (docs/model.md §4): three shades
picked by hand, and four products measured as thick layers (Lanza et al. 2024), whose thin film
is derived offline (docs/model.md §4, "Presets from measured thick layers";
lut_baker/offline/foundation_presets.py) and read here from :data:`MEASURED_FOUNDATIONS_FILE`.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from .dipole import dipole_total_reflectance
from .layers import Dipole, ReflectionLayer, TransmissionLayer
from .made_up_skin import MadeUpSkin, from_paper_counts

__all__ = [
    "PAPER_FILM_REFLECTION",
    "PAPER_FILM_TRANSMISSION",
    "PAPER_SKIN_REFLECTION",
    "PAPER_SKIN_DIPOLE",
    "FOUNDATIONS",
    "MEASURED_FOUNDATIONS_FILE",
    "read_measured_foundations",
    "read_measured_film_exchange",
    "MEASURED_FILM_EXCHANGE",
    "SKINS",
    "paper",
    "paper_layers",
    "skin_layers",
    "skin_albedo",
    "made_up_skin",
    "foundation_film",
]

# Baba, Mukaigawa, Yagi, section 4.1.1: liquid foundation ("natural"), reflection, 3 s shutter.
PAPER_FILM_REFLECTION = ReflectionLayer(P_d=1.29e4, P_s=8.93e5, n=3.29e-2, eta=1.19)
# Section 4.1.2: the same film, transmission, 10 s shutter.
PAPER_FILM_TRANSMISSION = TransmissionLayer(P_d=2.64e4, P_t=1.08e4, n=3.46e-2, eta=1.19)
# Section 4.2.1: skin substitute (white bio-plate), reflection, 3 s shutter.
PAPER_SKIN_REFLECTION = ReflectionLayer(P_d=2.00e4, P_s=2.05e5, n=4.00e-2, eta=1.26)
# Section 4.2.2: the bio-plate's dipole (1/mm); the paper gives no g, so g = 0 (docs/model.md §2.3).
PAPER_SKIN_DIPOLE = Dipole(sigma_s=2.83, sigma_a=2.82e-2, g=0.0, eta=1.26)

FOUNDATIONS: dict[str, dict] = {
    # The paper's film, measured in red only; no absorption is known, so none is applied.
    "paper_natural": {"absorption": (0.0, 0.0, 0.0), "label": "Paper (natural, as measured)"},
    # Shades: the paper's film with pigment absorption per RGB channel (docs/model.md §4,
    # "Absorption"). Chosen by hand so the film's diffuse colour over white reads as the named
    # shade.
    "light_ivory": {"absorption": (0.04, 0.10, 0.22), "label": "Light ivory"},
    "medium_beige": {"absorption": (0.10, 0.24, 0.42), "label": "Medium beige"},
    "deep_mocha": {"absorption": (0.38, 0.56, 0.70), "label": "Deep mocha"},
}
# The hand-picked shades stay beside the measured products below: the golden values, tests and
# docs use them, and they cover shades the four products lack: deep_mocha absorbs far more red
# (0.38) than any of them (at most 0.27), a deep brown rather than a beige.

MEASURED_FOUNDATIONS_FILE = Path(__file__).with_name("measured_foundations.json")
"""Foundations derived from measured thick layers (docs/model.md §4, "Presets from measured
thick layers"), written by ``python -m lut_baker foundations``."""


def read_measured_foundations(path: Path) -> dict[str, dict]:
    """The entries of the measured presets' file: label, absorption, the film's gloss
    ``{"P_s", "n", "eta"}`` (1/sr, 1/degree, -) and ``colour``, the measured thick layer's
    colour under uniform light (linear Rec.709: what the product looks like in the bottle, the
    target its absorption was solved for) per product."""
    if not path.is_file():
        return {}
    entries = json.loads(path.read_text(encoding="utf-8"))["foundations"]
    return {name: {"absorption": tuple(float(a) for a in entry["absorption"]),
                   "label": str(entry["label"]),
                   "film": {key: float(entry["film"][key]) for key in ("P_s", "n", "eta")},
                   "colour": tuple(float(c) for c in entry["target"])}
            for name, entry in entries.items()}


def read_measured_film_exchange(path: Path) -> dict | None:
    """The film exchange ``{"r_gloss", "r_diffuse", "t_0"}`` the measured presets were derived
    with (:func:`lut_baker.model.thick_layer.paper_film_exchange`, stored beside them), or None
    without a preset file."""
    if not path.is_file():
        return None
    stored = json.loads(path.read_text(encoding="utf-8")).get("film_exchange")
    return None if stored is None else {key: float(stored[key])
                                        for key in ("r_gloss", "r_diffuse", "t_0")}


MEASURED_FILM_EXCHANGE = read_measured_film_exchange(MEASURED_FOUNDATIONS_FILE)
"""The film exchange the shipped measured presets were derived with, or None."""

# An entry's optional "film" replaces the paper film's top-surface lobe (P_s, n, eta of eq. 2);
# P_d and the transmission (eq. 4) stay the paper film's.
FOUNDATIONS.update(read_measured_foundations(MEASURED_FOUNDATIONS_FILE))


@lru_cache(maxsize=1)
def paper() -> MadeUpSkin:
    """The paper's made-up skin: foundation "natural" on the bio-plate, coverage 1, albedo
    units with K from docs/model.md §4."""
    film, film_transmission, skin, dipole = paper_layers()
    return from_paper_counts(film, film_transmission, skin, dipole, name="paper")


def paper_layers() -> tuple[ReflectionLayer, TransmissionLayer, ReflectionLayer, Dipole]:
    """``(film reflection, film transmission, skin reflection, skin dipole)`` in counts."""
    return PAPER_FILM_REFLECTION, PAPER_FILM_TRANSMISSION, PAPER_SKIN_REFLECTION, PAPER_SKIN_DIPOLE


def _literature_skin(sigma_s_reduced: tuple[float, float, float],
                     sigma_a: tuple[float, float, float],
                     eta: float = 1.3) -> tuple[ReflectionLayer, Dipole]:
    """Surface layer and dipole of a skin given by reduced scattering and absorption (1/mm).

    Diffuse: ``P_d = Rd / pi`` (the dipole's closed-form total reflectance is the skin's diffuse
    albedo, docs/model.md §4).  Gloss: Weyrich et al. 2006 (SIGGRAPH, "Analysis of human faces using
    a measurement-based skin reflectance model") fit Beckmann roughness m ~ 0.35 to faces; the
    Torrance-Sparrow lobe with the same 1/e half-width, atan(0.35) = 19.3 degrees, has
    n = 0.052 / degree.  Its strength is the bio-plate's (normalised), as no TS fit in the
    paper's form is published for real skin.
    """
    dipole = Dipole(sigma_s=sigma_s_reduced, sigma_a=sigma_a, g=0.0, eta=eta)
    p_d = dipole_total_reflectance(dipole) / np.pi
    bioplate = paper().skin_reflection
    surface = ReflectionLayer(P_d=p_d, P_s=float(bioplate.P_s), n=1.0 / 19.3, eta=eta)
    return surface, dipole


SKINS: dict[str, dict] = {
    "paper_bioplate": {"label": "Bio-plate (paper)"},
    # Jensen, Marschner, Levoy, Hanrahan 2001, table of measured parameters: "Skin1",
    # sigma_s' = (0.74, 0.88, 1.01) /mm, sigma_a = (0.032, 0.17, 0.48) /mm, eta = 1.3.
    "jensen_skin1": {"label": "Skin 1 (Jensen 2001)",
                     "sigma_s": (0.74, 0.88, 1.01), "sigma_a": (0.032, 0.17, 0.48)},
    # Same table, "Skin2": sigma_s' = (1.09, 1.59, 1.79) /mm, sigma_a = (0.013, 0.070, 0.145).
    "jensen_skin2": {"label": "Skin 2 (Jensen 2001)",
                     "sigma_s": (1.09, 1.59, 1.79), "sigma_a": (0.013, 0.070, 0.145)},
}


def skin_layers(name: str) -> tuple[ReflectionLayer, Dipole]:
    """``(surface ReflectionLayer, Dipole)`` of a named skin, in albedo units."""
    if name not in SKINS:
        raise ValueError(f"skin must be one of {sorted(SKINS)}, got {name!r}")
    if name == "paper_bioplate":
        base = paper()
        return base.skin_reflection, base.dipole
    entry = SKINS[name]
    return _literature_skin(entry["sigma_s"], entry["sigma_a"])


def skin_albedo(name: str) -> np.ndarray:
    """The diffuse albedo ``pi P_d`` (RGB, dimensionless) of a named skin's surface layer: what
    the node group's Skin Color input defaults to."""
    surface, _ = skin_layers(name)
    return np.broadcast_to(np.pi * np.asarray(surface.P_d, float), (3,)).copy()


def made_up_skin(foundation: str = "paper_natural", skin: str = "paper_bioplate", *,
                 coverage: float = 1.0, absorption: ArrayLike | None = None) -> MadeUpSkin:
    """A named foundation on a named skin.  ``absorption`` (scalar or RGB in [0, 1]) overrides
    the shade's own."""
    if foundation not in FOUNDATIONS:
        raise ValueError(f"foundation must be one of {sorted(FOUNDATIONS)}, got {foundation!r}")
    surface, dipole = skin_layers(skin)
    shade = FOUNDATIONS[foundation]["absorption"] if absorption is None else absorption
    base = paper()
    changes = {}
    if "film" in FOUNDATIONS[foundation]:
        changes["film"] = foundation_film(foundation)
    return base.replace(skin_reflection=surface, dipole=dipole, coverage=coverage, absorption=shade,
                        name=f"{foundation}+{skin}", **changes)


def foundation_film(foundation: str) -> ReflectionLayer:
    """A named foundation's top-surface reflection in albedo units (eq. 2, docs/model.md §4):
    the paper film's ``P_d`` with the entry's own gloss ``P_s``, ``n``, ``eta`` where it has one
    (the measured products), else the paper film's."""
    if foundation not in FOUNDATIONS:
        raise ValueError(f"foundation must be one of {sorted(FOUNDATIONS)}, got {foundation!r}")
    film = paper().film
    gloss = FOUNDATIONS[foundation].get("film")
    if gloss is None:
        return film
    return ReflectionLayer(P_d=film.P_d, P_s=gloss["P_s"], n=gloss["n"], eta=gloss["eta"])
