"""A thick layer of foundation, what the product looks like in the bottle or as a swatch: the
film stacked on itself without end (the adding equation's fixed point), and the absorption
whose thick layer has a given colour (docs/model.md §4, "Presets from measured thick layers"
and "The colour seen"; paper eqs. 2 and 4 integrated over the hemisphere).

Under uniform (cosine-weighted) incident light a film exchanges light through three numbers
(:class:`FilmExchange`): its gloss albedo ``r_gloss`` (eq. 2's specular term, reflected before
any pigment, not absorbed), its diffuse albedo ``r_diffuse = pi P_d`` and its transmittance
``t_0`` (eq. 4), the last two crossing the pigment.  With absorption ``A`` (per channel) it
reflects ``r(A) = r_gloss + (1 - A) r_diffuse`` and transmits ``t(A) = (1 - A) t_0``; films
stacked without end reflect ``R_inf``, the root below 1 of ``r R^2 - (1 + r^2 - t^2) R + r =
0``, which falls monotonically from ``R_inf(0)`` to ``r_gloss`` at ``A = 1``.

Which film is stacked: the measured presets were derived by stacking the paper's film as
measured (its diffuse part, its broad 30-degree lobe and its transmission,
:func:`paper_film_exchange`), and the colour a user picks is read the same way, so that a
measured product's own colour gives back its preset.  :func:`film_exchange` takes any film.

Numpy only: the add-on solves a picked colour with it at Apply and on live update, and
``lut_baker.offline.foundation_presets`` derives the shipped presets with the same functions.

Functions and types
-------------------
- :class:`FilmExchange` -- ``r_gloss``, ``r_diffuse``, ``t_0`` of a film, and ``r(A)``,
  ``t(A)``.
- :func:`film_exchange` -- those three for any film (reflection and transmission layers),
  computed once per film.
- :func:`paper_film_exchange` -- the paper's film's: what the thick layer stacks.
- :func:`preset_film_exchange` -- the same as the shipped presets were derived with (stored
  beside them): what the panel solves a picked colour against.
- :func:`stack_reflectance` -- ``R_inf(A)``, the film stacked on itself without end.
- :func:`solve_absorption` -- ``A`` per channel whose ``R_inf`` is a target (bisection),
  clamped to [0, 1] where out of reach.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics import Real
from ..numerics.cache import LRUCache
from .albedo import bihemispherical, reflection_albedo, transmission_albedo
from .layers import ReflectionLayer, TransmissionLayer

__all__ = [
    "FilmExchange",
    "film_exchange",
    "paper_film_exchange",
    "preset_film_exchange",
    "stack_reflectance",
    "solve_absorption",
    "BISECTION_STEPS",
]

BISECTION_STEPS = 80
"""Bisection steps of :func:`solve_absorption` (the interval halves each time: 2^-80)."""
EXCHANGE_CACHE_SIZE = 16
"""Films whose :class:`FilmExchange` is kept in this process."""


@dataclass(frozen=True)
class FilmExchange:
    """A film's bihemispherical reflectance split into its gloss ``r_gloss`` (not absorbed)
    and diffuse ``r_diffuse = pi P_d`` parts, and its transmittance ``t_0``, all without
    absorption (docs/model.md §4); floats, or RGB arrays for a film with RGB parameters."""

    r_gloss: Real
    r_diffuse: Real
    t_0: Real

    def r(self, absorption: ArrayLike) -> NDArray[np.float64]:
        """``r(A) = r_gloss + (1 - A) r_diffuse``: the film's reflectance at absorption ``A``."""
        return self.r_gloss + (1.0 - np.asarray(absorption, float)) * self.r_diffuse

    def t(self, absorption: ArrayLike) -> NDArray[np.float64]:
        """``t(A) = (1 - A) t_0``: the film's transmittance at absorption ``A``."""
        return (1.0 - np.asarray(absorption, float)) * self.t_0


_EXCHANGES = LRUCache(EXCHANGE_CACHE_SIZE)


def _number(values: ArrayLike) -> Real:
    """A float for a scalar film, else the per-channel array."""
    array = np.asarray(values, float)
    return float(array) if array.ndim == 0 else array


def film_exchange(film: ReflectionLayer, transmission: TransmissionLayer) -> FilmExchange:
    """:class:`FilmExchange` of a film: ``r_gloss`` the bihemispherical albedo of eq. 2's
    specular term (``film`` with ``P_d = 0``: :func:`lut_baker.model.albedo.reflection_albedo`,
    which integrates lobes narrower than 10 degrees through the half vector,
    :func:`~lut_baker.model.albedo.specular_albedo`), ``r_diffuse = pi P_d`` and ``t_0`` the
    bihemispherical transmittance of ``transmission`` (eq. 4).  Computed once per film (about
    0.1-0.3 s) and kept (:data:`EXCHANGE_CACHE_SIZE` films)."""
    key = (tuple(sorted((k, repr(v)) for k, v in film.as_dict().items())),
           tuple(sorted((k, repr(v)) for k, v in transmission.as_dict().items())))

    def compute() -> FilmExchange:
        gloss = film.scaled(P_d=0.0)
        r_gloss = (0.0 if not np.any(gloss.P_s > 0.0)
                   else bihemispherical(lambda t: reflection_albedo(t, gloss)))
        return FilmExchange(
            r_gloss=_number(r_gloss),
            r_diffuse=_number(np.pi * film.P_d),
            t_0=_number(bihemispherical(lambda t: transmission_albedo(t, transmission))),
        )

    return _EXCHANGES.get_or_compute(key, compute)


def paper_film_exchange() -> FilmExchange:
    """:func:`film_exchange` of the paper's normalised film (docs/model.md §4, §5): the film a
    thick layer stacks, for the measured presets and for a picked colour alike."""
    from .presets import paper  # presets reads the measured presets this module derives

    base = paper()
    return film_exchange(base.film, base.film_transmission)


def preset_film_exchange() -> FilmExchange:
    """The exchange the shipped measured presets were derived with
    (:data:`lut_baker.model.presets.MEASURED_FILM_EXCHANGE`, written by the derivation from
    :func:`paper_film_exchange`, which it equals): read, not integrated, so a colour picked in
    the panel costs nothing to solve and a measured product's own colour gives back its preset
    to the last bit.  Without a preset file, :func:`paper_film_exchange`."""
    from .presets import MEASURED_FILM_EXCHANGE

    if MEASURED_FILM_EXCHANGE is None:
        return paper_film_exchange()
    return FilmExchange(**MEASURED_FILM_EXCHANGE)


def stack_reflectance(absorption: ArrayLike, exchange: FilmExchange) -> NDArray[np.float64]:
    """``R_inf(A)``: the film stacked on itself without end (the adding equation's fixed point,
    the root below 1 of ``r R^2 - (1 + r^2 - t^2) R + r = 0``).

    >>> lossless = FilmExchange(r_gloss=0.0, r_diffuse=0.5, t_0=0.5)  # r + t = 1 at A = 0
    >>> round(float(stack_reflectance(0.0, lossless)), 6)  # a thick stack reflects it all
    1.0
    >>> film = FilmExchange(r_gloss=0.04, r_diffuse=0.5, t_0=0.4)
    >>> print(np.round(stack_reflectance([0.0, 0.5, 1.0], film), 4))  # down to r_gloss
    [0.735  0.3033 0.04  ]
    """
    r = exchange.r(absorption)
    t = exchange.t(absorption)
    b = 1.0 + r**2 - t**2
    disc = np.sqrt(np.maximum(b**2 - 4.0 * r**2, 0.0))
    # 2r / (b + sqrt(...)) is the smaller root without cancellation; r = 0 gives 0.
    return 2.0 * r / (b + disc)


def solve_absorption(target: ArrayLike, exchange: FilmExchange
                     ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """``(A, clamped)`` per entry of ``target``: ``R_inf(A) = target`` by bisection on [0, 1]
    (``R_inf`` falls with ``A``).  Targets above ``R_inf(0)`` give ``A = 0``, below
    ``R_inf(1) = r_gloss`` give ``A = 1``; ``clamped`` marks them.

    >>> film = FilmExchange(r_gloss=0.04, r_diffuse=0.5, t_0=0.4)
    >>> absorption, clamped = solve_absorption([0.3, 0.9, 0.01], film)
    >>> print(np.round(absorption, 4), clamped)  # 0.9 is out of reach, and 0.01 below the gloss
    [0.5057 0.     1.    ] [False  True  True]
    >>> print(np.round(stack_reflectance(absorption, film), 4))
    [0.3   0.735 0.04 ]
    """
    goal = np.asarray(target, dtype=float)
    low = np.zeros_like(goal)
    high = np.ones_like(goal)
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (low + high)
        above = stack_reflectance(mid, exchange) > goal
        low = np.where(above, mid, low)
        high = np.where(above, high, mid)
    absorption = 0.5 * (low + high)
    too_light = goal > stack_reflectance(0.0, exchange)
    too_dark = goal < stack_reflectance(1.0, exchange)
    absorption = np.where(too_light, 0.0, np.where(too_dark, 1.0, absorption))
    return absorption, too_light | too_dark
