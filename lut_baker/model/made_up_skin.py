"""From the paper's pixel counts to albedo units, and the made-up skin bundle (SPEC section 4).

The paper's fitted values are 16-bit counts at two shutter times.  Dividing each layer by its
shutter time puts them on one scale (counts per second); dividing by one constant ``K`` makes
them albedos.  ``K`` is chosen so that the film as measured is lossless where it is brightest:
``K = max over theta_i of [reflection albedo (counts/s) + transmission albedo (counts/s)]``.

Functions and types
-------------------
- :func:`normalisation_constant` -- ``K`` from the film's two measured layers (SPEC 4).
- :func:`per_second` -- a layer divided by its shutter time.
- :class:`MadeUpSkin` -- the bundle in albedo units: film, skin, dipole, coverage, absorption.
- :func:`from_paper_counts` -- build a :class:`MadeUpSkin` from layers in pixel counts.
- :func:`film_reflection_layer`, :func:`film_transmission_layer` -- the film with its pigment
  absorption applied.
- :func:`made_up_reflection` -- paths 1 + 3 with coverage (paper eq. 9, SPEC 4), 1/sr.
- :func:`directional_albedo` -- paths 1 + 3 integrated over the view hemisphere.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..evaluate.two_layer import (
    grid_for,
    layered_fourier_matrices,
    layered_reflection,
    reflection_albedo,
    transmission_albedo,
)
from ..numerics.optimise import golden_minimum
from .layers import (
    Dipole,
    ReflectionLayer,
    TransmissionLayer,
    _parameter,
    _ts_reflection,
    check_directions,
)

__all__ = [
    "REFLECTION_SHUTTER_S",
    "TRANSMISSION_SHUTTER_S",
    "normalisation_constant",
    "per_second",
    "MadeUpSkin",
    "from_paper_counts",
    "film_reflection_layer",
    "film_transmission_layer",
    "made_up_reflection",
    "directional_albedo",
]

REFLECTION_SHUTTER_S = 3.0
"""Shutter time of the paper's reflection measurements (4.1.1, 4.2.1), seconds."""
TRANSMISSION_SHUTTER_S = 10.0
"""Shutter time of the paper's transmission measurement (4.1.2), seconds."""


def per_second(layer, shutter_s: float):
    """``layer`` with its intensity scales (``P_d``, ``P_s``/``P_t``) divided by ``shutter_s``."""
    if not shutter_s > 0:
        raise ValueError(f"shutter_s must be > 0 seconds, got {shutter_s!r}")
    lobe = "P_s" if isinstance(layer, ReflectionLayer) else "P_t"
    return layer.scaled(P_d=1.0 / shutter_s, **{lobe: 1.0 / shutter_s})


def normalisation_constant(film_reflection: ReflectionLayer,
                           film_transmission: TransmissionLayer) -> tuple[float, float]:
    """``K`` (SPEC 4): the largest total directional albedo of the film over incidence.

    Both layers in the same unit per second (see :func:`per_second`).  Returns ``(K,
    theta_max_deg)``, where ``theta_max_deg`` is the incidence at which the film is brightest.
    For RGB layers the brightest channel sets ``K``.
    """

    def total(theta_deg):
        value = reflection_albedo(theta_deg, film_reflection) + transmission_albedo(
            theta_deg, film_transmission
        )
        return float(np.max(value))

    theta, value = golden_minimum(lambda t: -total(t), 0.0, 89.9, tol=1e-5, coarse=91)
    return float(-value), float(theta)


@dataclass(frozen=True, eq=False)
class MadeUpSkin:
    """Made-up skin in albedo units (1/sr): the film over the skin, plus coverage and absorption.

    ``film``: the film's top-surface reflection (path 1); ``film_transmission``: the film's
    transmission (paths 3 and 4); ``skin``: the skin surface's Torrance-Sparrow reflection;
    ``dipole``: the skin's subsurface scattering (its profile shape spreads the skin's diffuse
    light); ``coverage`` in [0, 1]: 0 bare skin, 1 the full two-layer result, areal mix between;
    ``absorption`` in [0, 1] per channel: the fraction of light crossing the film's pigment
    (its diffuse reflection and its transmission) that is absorbed; ``K``: the normalisation
    constant these values were divided by (counts per second per unit albedo), if any.
    """

    film: ReflectionLayer
    film_transmission: TransmissionLayer
    skin: ReflectionLayer
    dipole: Dipole
    coverage: float = 1.0
    absorption: object = 0.0
    K: float | None = None
    name: str = field(default="custom")

    def __post_init__(self):
        coverage = _parameter("coverage", self.coverage, 0.0, 1.0, low_open=False, high_open=False)
        if coverage.shape != ():
            raise ValueError("coverage must be a float in [0, 1]")
        object.__setattr__(self, "coverage", float(coverage))
        absorption = _parameter("absorption", self.absorption, 0.0, 1.0,
                                low_open=False, high_open=False)
        object.__setattr__(self, "absorption", absorption)
        for name, kind in (("film", ReflectionLayer), ("film_transmission", TransmissionLayer),
                           ("skin", ReflectionLayer), ("dipole", Dipole)):
            if not isinstance(getattr(self, name), kind):
                raise ValueError(f"{name} must be a {kind.__name__}")

    def replace(self, **changes) -> MadeUpSkin:
        """A copy with some fields changed (validated again)."""
        values = {name: getattr(self, name) for name in self.__dataclass_fields__}
        values.update(changes)
        return MadeUpSkin(**values)


def from_paper_counts(film: ReflectionLayer, film_transmission: TransmissionLayer,
                      skin: ReflectionLayer, dipole: Dipole, *,
                      reflection_shutter_s: float = REFLECTION_SHUTTER_S,
                      transmission_shutter_s: float = TRANSMISSION_SHUTTER_S,
                      **options) -> MadeUpSkin:
    """Layers in the paper's pixel counts -> :class:`MadeUpSkin` in albedo units (SPEC 4)."""
    film_s = per_second(film, reflection_shutter_s)
    transmission_s = per_second(film_transmission, transmission_shutter_s)
    skin_s = per_second(skin, reflection_shutter_s)
    k, _ = normalisation_constant(film_s, transmission_s)
    return MadeUpSkin(
        film=film_s.scaled(P_d=1 / k, P_s=1 / k),
        film_transmission=transmission_s.scaled(P_d=1 / k, P_t=1 / k),
        skin=skin_s.scaled(P_d=1 / k, P_s=1 / k),
        dipole=dipole,
        K=k,
        **options,
    )


def film_reflection_layer(skin: MadeUpSkin) -> ReflectionLayer:
    """The film's top reflection with pigment absorption on its diffuse part (SPEC 4)."""
    return skin.film.scaled(P_d=1.0 - skin.absorption)


def film_transmission_layer(skin: MadeUpSkin) -> TransmissionLayer:
    """The film's transmission with pigment absorption on all of it (SPEC 4)."""
    return skin.film_transmission.scaled(P_d=1.0 - skin.absorption, P_t=1.0 - skin.absorption)


def made_up_reflection(wi, wo, skin: MadeUpSkin, *, level: int = 0):
    """Made-up skin BRDF, paths 1 + 3 (paper eq. 9) mixed with bare skin by coverage (SPEC 4).

    ``(1 - w) f_r,s + w (f_r,c + f_cs)``, in 1/sr, RGB: shape ``(..., 3)``.
    """
    wi = check_directions("wi", wi)
    wo = check_directions("wo", wo)
    film = film_reflection_layer(skin)
    film_t = film_transmission_layer(skin)
    bare = _rgb(_ts_reflection(wi, wo, skin.skin), skin.skin)
    top = _rgb(_ts_reflection(wi, wo, film), film)
    path3 = _rgb(layered_reflection(wi, wo, film_t, skin.skin, level=level), film_t, skin.skin)
    return (1.0 - skin.coverage) * bare + skin.coverage * (top + path3)


def _rgb(values: np.ndarray, *layers) -> np.ndarray:
    """Broadcast a result of ``layers`` to RGB: ``(...)`` for scalar layers -> ``(..., 3)``."""
    values = np.asarray(values)
    rgb = any(layer.channels for layer in layers)
    return values if rgb else np.repeat(values[..., None], 3, axis=-1)


def directional_albedo(theta_i_deg, skin: MadeUpSkin, *, level: int = 0) -> np.ndarray:
    """Paths 1 + 3 (with coverage) integrated over the view hemisphere, per RGB channel:
    ``Int f(wi, wo) cos(theta_o) dwo`` at incidence ``theta_i_deg`` (degrees).  A white
    furnace test asserts it is <= 1.  Shape ``theta_i_deg.shape + (3,)``."""
    theta = np.radians(np.atleast_1d(np.asarray(theta_i_deg, float)))
    film_t = film_transmission_layer(skin)
    grid = grid_for(film_t, skin.skin, skin.film, level=level)
    path3 = layered_fourier_matrices(theta, grid.theta, film_t, skin.skin, grid,
                                     orders=1)[0]  # (P, N, C)
    path3 = 2.0 * np.pi * np.einsum("pnc,n->pc", path3, grid.weight)
    path3 = path3 if (film_t.channels or skin.skin.channels) else path3[..., 0]
    film = film_reflection_layer(skin)
    top = reflection_albedo(np.degrees(theta), film, level=level)
    bare = reflection_albedo(np.degrees(theta), skin.skin, level=level)
    total = (1.0 - skin.coverage) * _rgb(bare, skin.skin) + skin.coverage * (
        _rgb(top, film) + _rgb(path3, film_t, skin.skin)
    )
    return total.reshape(np.shape(theta_i_deg) + (3,))

