"""The made-up skin's colour under uniform light, from the tables, and the shade that gives a
colour: what Match Skin and the Lighter / Darker steps solve (docs/model.md §4, "Matching the
skin"; docs/addon.md, "Match Skin").

Under uniform white light (every direction equally bright, cosine-weighted) a surface's colour
is its bihemispherical albedo: the directional albedo averaged over incidence with weight
``2 cos(theta)``, which is also the mean colour a convex object shows under a uniform sky.  The
tables' 1-D albedos (:meth:`~lut_baker.tables.table_set.Tables.directional_albedo`'s parts)
averaged so (:class:`UniformLight`) give it per channel as the one mixing rule
(:func:`lut_baker.model.made_up_skin.combine`)::

    colour = w [film_gloss + (1 - A) film_diffuse + (1 - A)^2 (path3_gloss + a through_film)]
             + (1 - w) [skin_gloss + a]

with ``a`` the skin's diffuse albedo (the node group's Skin Color, which replaces the preset's
``pi P_d``; for an albedo texture the mean of its pixels, the colour being linear in ``a``),
``w`` the coverage, ``A`` the absorption, and the gloss parts times the Gloss setting.  The
covered part (``w = 1``) falls monotonically with ``A``; it is quadratic in ``1 - A``, so
:func:`matching_absorption` solves it in closed form per channel, clamped to [0, 1] (and
saying so) where the film cannot reach the target.

The skin's own colour is the bare part (``w = 0``); since the made-up colour is the areal mix
of it and the covered part, a covered part equal to it gives the skin's colour at every
coverage.

Functions and types
-------------------
- :class:`UniformLight` -- the parts' bihemispherical albedos (per channel).
- :func:`uniform_light` -- those of baked tables.
- :func:`made_up_colour`, :func:`covered_colour`, :func:`bare_colour` -- the colour at a
  coverage, fully covered, bare.
- :func:`matching_absorption` -- the absorption whose covered colour is a target.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.albedo import bihemispherical
from ..model.made_up_skin import combine, coverage_weights, mix_slots
from .table_set import Tables

__all__ = [
    "UniformLight",
    "uniform_light",
    "made_up_colour",
    "covered_colour",
    "bare_colour",
    "matching_absorption",
]


@dataclass(frozen=True)
class UniformLight:
    """Bihemispherical albedos of the made-up skin's parts, each ``(3,)``: the film's gloss
    (path 1, not absorbed), its diffuse ``pi P_d`` (absorbed once), path 3's gloss and the
    skin's diffuse light through the film per unit skin albedo (absorbed twice: ``T_mean^2``,
    the film's transmittance averaged over incidence and over exit), and the bare skin's
    gloss."""

    film_gloss: np.ndarray
    film_diffuse: np.ndarray
    path3_gloss: np.ndarray
    through_film: np.ndarray
    skin_gloss: np.ndarray


def uniform_light(tables: Tables) -> UniformLight:
    """The :class:`UniformLight` parts of baked ``tables`` (their 1-D albedo tables averaged
    over incidence, :func:`lut_baker.model.albedo.bihemispherical`; the transmittance's mean
    over exit as the tables store it)."""
    def average(name: str) -> NDArray[np.float64]:
        return bihemispherical(lambda theta: tables.directional(name, theta))

    return UniformLight(
        film_gloss=average("film_gloss_albedo"),
        film_diffuse=np.pi * np.asarray(tables.film_diffuse, float),
        path3_gloss=average("path3_gloss_albedo"),
        # T(theta_i) averaged over incidence as every part is (so the colour stays the
        # directional albedo's average), T's mean over exit as the tables store it.
        through_film=average("film_transmittance") * tables.film_transmittance_mean,
        skin_gloss=average("skin_gloss_albedo"),
    )


def _parts(light: UniformLight, skin_albedo: ArrayLike,
           gloss: float) -> dict[str, NDArray[np.float64]]:
    """The mixing rule's parts for skin albedo ``skin_albedo`` (RGB) and gloss factor ``gloss``."""
    a = np.broadcast_to(np.asarray(skin_albedo, float), (3,))
    return mix_slots(film_gloss=gloss * light.film_gloss, film_diffuse=light.film_diffuse,
                     path3_gloss=gloss * light.path3_gloss, through_film=a * light.through_film,
                     skin_gloss=gloss * light.skin_gloss, skin=a)


def made_up_colour(light: UniformLight, coverage: float, absorption: ArrayLike,
                   skin_albedo: ArrayLike, gloss: float = 1.0) -> NDArray[np.float64]:
    """The made-up skin's colour (linear RGB, ``(3,)``) under uniform white light at
    ``coverage`` and ``absorption``, on skin of diffuse albedo ``skin_albedo``, gloss lobes
    times ``gloss`` (the node group's Gloss).

    >>> light = UniformLight(film_gloss=np.full(3, 0.03), film_diffuse=np.full(3, 0.5),
    ...                      path3_gloss=np.full(3, 0.01), through_film=np.full(3, 0.3),
    ...                      skin_gloss=np.full(3, 0.04))
    >>> skin = [0.6, 0.4, 0.3]
    >>> print(np.round(made_up_colour(light, 0.0, 0.0, skin), 4))  # bare: gloss + albedo
    [0.64 0.44 0.34]
    >>> print(np.round(made_up_colour(light, 1.0, [0.2, 0.4, 0.6], skin), 4))
    [0.5516 0.3768 0.246 ]
    >>> print(np.round(made_up_colour(light, 0.5, [0.2, 0.4, 0.6], skin), 4))  # half of each
    [0.5958 0.4084 0.293 ]
    """
    weights = coverage_weights(coverage, np.broadcast_to(np.asarray(absorption, float), (3,)))
    return combine(weights, **_parts(light, skin_albedo, gloss))


def covered_colour(light: UniformLight, absorption: ArrayLike, skin_albedo: ArrayLike,
                   gloss: float = 1.0) -> NDArray[np.float64]:
    """:func:`made_up_colour` at full coverage: the film over the skin."""
    return made_up_colour(light, 1.0, absorption, skin_albedo, gloss)


def bare_colour(light: UniformLight, skin_albedo: ArrayLike,
                gloss: float = 1.0) -> NDArray[np.float64]:
    """:func:`made_up_colour` at coverage 0: the skin's own colour (its gloss and diffuse
    albedo)."""
    return made_up_colour(light, 0.0, 0.0, skin_albedo, gloss)


def matching_absorption(light: UniformLight, target: ArrayLike, skin_albedo: ArrayLike,
                        gloss: float = 1.0) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """``(A, clamped)`` per channel: the absorption whose covered colour
    (:func:`covered_colour`) is ``target`` (linear RGB).  With ``x = 1 - A`` the covered colour
    is ``top + once x + twice x^2``, increasing in ``x`` on [0, 1], so ``x`` is the quadratic's
    root there; a target above the covered colour at ``A = 0`` gets ``A = 0``, one below it at
    ``A = 1`` (the film's gloss alone) gets ``A = 1``, and ``clamped`` marks them.

    >>> light = UniformLight(film_gloss=np.full(3, 0.03), film_diffuse=np.full(3, 0.5),
    ...                      path3_gloss=np.full(3, 0.01), through_film=np.full(3, 0.3),
    ...                      skin_gloss=np.full(3, 0.04))
    >>> skin = [0.6, 0.4, 0.3]
    >>> colour = covered_colour(light, [0.2, 0.4, 0.6], skin)
    >>> absorption, clamped = matching_absorption(light, colour, skin)
    >>> print(np.round(absorption, 6), clamped)
    [0.2 0.4 0.6] [False False False]
    >>> absorption, clamped = matching_absorption(light, [0.9, 0.3, 0.01], skin)
    >>> print(np.round(absorption, 4), clamped)  # red out of reach, blue below the gloss
    [0.     0.5199 1.    ] [ True False  True]
    """
    parts = _parts(light, skin_albedo, gloss)
    top, once, twice = parts["top"], parts["once"], parts["twice"]
    goal = np.broadcast_to(np.asarray(target, float), (3,))
    rise = np.maximum(goal - top, 0.0)
    # x = (-once + sqrt(once^2 + 4 twice rise)) / (2 twice), written without cancellation.
    denominator = once + np.sqrt(once**2 + 4.0 * twice * rise)
    x = np.divide(2.0 * rise, denominator, out=np.zeros(3), where=denominator > 0.0)
    too_light = goal > top + once + twice
    too_dark = goal < top
    absorption = np.where(too_light, 0.0, np.where(too_dark, 1.0, np.clip(1.0 - x, 0.0, 1.0)))
    return absorption, too_light | too_dark
