"""A foundation's shade with the film as a slab: the colour it has in the bottle, the film
infinitely thick under its surface, against its absorption, and back (docs/model.md, "The
thick limit").

The thick limit's colour under uniform light falls with the absorption ``A`` in each channel
on its own (the film is grey but for ``A``), so it is tabulated once per foundation on
:data:`CURVE_NODES` absorptions and read both ways by interpolation: what a picked bottle
colour or a measured product's colour means with the film at a thickness, in microseconds,
where the exact root (:func:`lut_baker.model.film_slab.increasing_root` on the slab) takes a
fifth of a second, and the table itself as long.  The foundation presets' tables are shipped
(:data:`SHADES_FILE`, written by ``tools/slab_shades.py``; a test holds them to a fresh
computation), so that picking a preset or a colour costs nothing in the panel.

- :data:`CURVE_NODES`, :data:`CURVE_GRID` -- the table's absorptions and quadrature.
- :class:`ThickLimitCurve` -- the table, with :meth:`~ThickLimitCurve.colour` and
  :meth:`~ThickLimitCurve.absorption`.
- :func:`thick_limit_colours` -- the thick limit's colour at absorptions (exact, order 0).
- :func:`thick_limit_curve` -- the table of a foundation (cached per film).
- :data:`SHADES_FILE`, :func:`preset_curves`, :func:`curves_data`, :func:`read_curves`,
  :func:`preset_curve` -- the presets' tables: computed, as plain data, read back, and the
  shipped one of a preset (computed when missing).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.cache import LRUCache
from ..numerics.quadrature import HemisphereGrid, hemisphere_panels
from .film_slab import face_albedo, thick_limit_colour
from .layers import ReflectionLayer, TransmissionLayer
from .presets import FOUNDATIONS, foundation_film, paper
from .slab_skin import measured_film

__all__ = ["CURVE_NODES", "CURVE_GRID", "ThickLimitCurve", "thick_limit_colours",
           "thick_limit_curve", "SHADES_FILE", "preset_curves", "curves_data", "read_curves",
           "preset_curve"]

CURVE_NODES = 121
"""Absorptions the curve is tabulated on, evenly over [0, 1]: read back by linear
interpolation, an absorption within 1.5e-4 of the exact root (its colour within 1e-4;
tests/lut_baker/model/test_slab_shade.py)."""
CURVE_GRID = (3, 10, 33)
"""The quadrature (:func:`~lut_baker.numerics.quadrature.hemisphere_panels`' panels, points,
azimuths) of the default bake, on which the slab is derived."""
_CURVES = LRUCache(16)
SHADES_FILE = Path(__file__).with_name("slab_shades.json")
"""The foundation presets' :class:`ThickLimitCurve` (``tools/slab_shades.py`` writes it)."""
_SHIPPED: dict[str, ThickLimitCurve] = {}


@dataclass(frozen=True)
class ThickLimitCurve:
    """The thick limit's colour under uniform light ``colours`` ``(N, 3)`` at absorptions
    ``absorption_nodes`` ``(N,)`` (increasing; the colours decrease)."""

    absorption_nodes: NDArray[np.float64]
    colours: NDArray[np.float64]

    def colour(self, absorption: ArrayLike) -> NDArray[np.float64]:
        """The bottle's colour (RGB) at ``absorption`` (scalar or RGB in [0, 1])."""
        a = np.broadcast_to(np.clip(np.asarray(absorption, float), 0.0, 1.0), (3,))
        return np.array([np.interp(a[c], self.absorption_nodes, self.colours[:, c])
                         for c in range(3)])

    def absorption(self, colour: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """``(A, clamped)`` per channel: the absorption whose thick limit has ``colour`` (RGB);
        a colour lighter than the unabsorbed film or darker than the fully absorbing one is
        out of reach: ``A`` 0 or 1, ``clamped``."""
        wanted = np.broadcast_to(np.asarray(colour, float)[..., :3], (3,))
        lightest, darkest = self.colours[0], self.colours[-1]
        a = np.array([np.interp(-wanted[c], -self.colours[:, c], self.absorption_nodes)
                      for c in range(3)])
        return a, (wanted > lightest) | (wanted < darkest)


def thick_limit_colours(film: ReflectionLayer, transmission: TransmissionLayer,
                        grid: HemisphereGrid, absorptions: ArrayLike) -> NDArray[np.float64]:
    """The colour under uniform light ``(N, 3)`` of the foundation (``film``: its top
    reflection, whose surface it keeps; its body the paper film's,
    :func:`~lut_baker.model.slab_skin.measured_film`) infinitely thick, at each of
    ``absorptions`` ``(N,)`` (the same in every channel), order 0 only.  A grey film's channels
    differ only by their absorption, so three absorptions are evaluated at once."""
    a = np.atleast_1d(np.asarray(absorptions, float))
    face = face_albedo(film, grid)
    grey = face.shape[0] == 1 and np.ndim(film.P_d) == 0 and np.ndim(transmission.P_d) == 0
    out = np.empty((a.size, 3))
    step = 3 if grey else 1
    for start in range(0, a.size, step):
        chunk = a[start:start + step]
        shades = np.resize(chunk, 3) if grey else np.full(3, chunk[0])
        limit = np.broadcast_to(thick_limit_colour(measured_film(film), transmission, grid,
                                                   shades, face=face), (3,))
        out[start:start + chunk.size] = (limit[:chunk.size, None] * np.ones(3) if grey
                                         else limit)
    return out


def thick_limit_curve(film: ReflectionLayer, transmission: TransmissionLayer,
                      nodes: int = CURVE_NODES) -> ThickLimitCurve:
    """:class:`ThickLimitCurve` of a foundation on ``nodes`` absorptions (cached per film).

    >>> from lut_baker.model import presets
    >>> paper = presets.paper()
    >>> curve = thick_limit_curve(paper.film, paper.film_transmission)
    >>> print(np.round(curve.colour(0.0), 3))  # the unabsorbed film in the bottle
    [0.828 0.828 0.828]
    >>> a, clamped = curve.absorption([0.7, 0.55, 0.45])
    >>> print(np.round(a, 3), clamped)
    [0.077 0.23  0.365] [False False False]
    """
    key = (repr(film.as_dict()), repr(transmission.as_dict()), int(nodes))

    def compute() -> ThickLimitCurve:
        grid = hemisphere_panels(*CURVE_GRID)
        absorptions = np.linspace(0.0, 1.0, int(nodes))
        colours = thick_limit_colours(film, transmission, grid, absorptions)
        absorptions.setflags(write=False)
        colours.setflags(write=False)
        return ThickLimitCurve(absorptions, colours)

    return _CURVES.get_or_compute(key, compute)


def preset_curves() -> dict[str, ThickLimitCurve]:
    """Every foundation preset's :class:`ThickLimitCurve` (its own film's surface, the paper
    film's transmission), computed."""
    transmission = paper().film_transmission
    return {name: thick_limit_curve(foundation_film(name), transmission)
            for name in sorted(FOUNDATIONS)}


def curves_data(curves: dict[str, ThickLimitCurve]) -> dict[str, Any]:
    """``curves`` as plain data (JSON): per preset its absorptions and colours."""
    return {"what": "the colour under uniform light of each foundation preset's film, "
                    "infinitely thick (the film as a slab), against its absorption: "
                    "lut_baker.model.slab_shade, written by tools/slab_shades.py",
            "presets": {name: {"absorption_nodes": curve.absorption_nodes.tolist(),
                               "colours": curve.colours.tolist()}
                        for name, curve in curves.items()}}


def read_curves(path: Path = SHADES_FILE) -> dict[str, ThickLimitCurve]:
    """The curves stored at ``path`` (:func:`curves_data`'s form); empty if there is none."""
    if not path.is_file():
        return {}
    data = json.loads(path.read_text())["presets"]
    return {name: ThickLimitCurve(np.asarray(entry["absorption_nodes"], float),
                                  np.asarray(entry["colours"], float))
            for name, entry in data.items()}


def preset_curve(name: str) -> ThickLimitCurve:
    """A foundation preset's shipped :class:`ThickLimitCurve` (computed, and kept, if the file
    does not hold it)."""
    if not _SHIPPED:
        _SHIPPED.update(read_curves())
    if name not in _SHIPPED:
        if name not in FOUNDATIONS:
            raise ValueError(f"foundation must be one of {sorted(FOUNDATIONS)}, got {name!r}")
        _SHIPPED[name] = thick_limit_curve(foundation_film(name), paper().film_transmission)
    return _SHIPPED[name]
