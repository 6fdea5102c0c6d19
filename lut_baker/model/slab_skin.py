"""Made-up skin at a thickness in the closed form the tables hold: the film as a slab over the
skin, every inter-reflection summed, split so that the skin's diffuse albedo stays free
(docs/model.md, "The film as a slab", "Made-up skin at a thickness").

The film (its surface over its body at a thickness, :mod:`lut_baker.model.film_slab`) reflects
``R`` from above, ``R'`` from below and transmits ``T`` (star form, per Fourier order).  The skin
reflects its gloss ``S_g`` (eq. 2's specular term) and its diffuse light, Lambertian of albedo
``a`` (the dipole's light included, docs/model.md §4): ``a u u^T`` in the star form, at order 0
only, with ``u = s / sqrt(pi)`` (``s`` the order-0 star weights, ``u^T u = 1``).  The adding
equation ``R + T (I - S R')^-1 S T^T`` with ``S = S_g + a u u^T`` is, by the Sherman-Morrison
identity, exactly::

    top + a / (1 - a c) v v^T,      top = R + T (I - S_g R')^-1 S_g T^T,
                                    v = T (I - S_g R')^-1 u,   c = u^T R' (I - S_g R')^-1 u

so made-up skin is a part that does not depend on the skin's albedo (``top``: the film's own
reflection and the skin's gloss through it, every order) plus a rank-one diffuse part: as a BRDF
``a t(theta_i) t(theta_o) / (pi (1 - a c))`` with ``t = sqrt(pi) v / s`` the film's directional
transmittance into the skin's diffuse light (the skin's gloss between them included) and ``c``
the film's hemispherical reflectance seen from the skin (likewise).  Without skin gloss ``t`` is
the film's transmittance and ``c`` its reflectance from below, the closed form of a Lambertian
skin under any layer.  The diffuse part is what the dipole spreads (its amount ``a t t / (1 - a
c)``, its spread the normalised profile): the light that scattered under the skin, with all its
returns from the film's underside.

The body is derived from the measured free film (:func:`measured_film`): the film's ``P_d``, the
share of the paper film's gloss its surface does not reflect, and its transmission (eq. 4) under
the paper film's surface, whatever the foundation's own gloss; on skin the foundation's own
surface (``face``: its gloss times the share an interface of the vehicle reflects,
:func:`~lut_baker.model.film_slab.face_albedo`) lies on that body.

Functions and types
-------------------
- :func:`measured_film` -- the free film a foundation's body is derived from.
- :func:`foundation_slab` -- a foundation's body at every thickness, with its absorption.
- :class:`SlabSkinParts`, :func:`slab_skin_parts` -- ``top``, ``t``, ``c`` and the surface's
  gloss albedo at one thickness.
- :func:`body_gloss_weight` -- how much of eq. 2's gloss lobe the film's body returns at a
  thickness (what the tiers draw as gloss).
- :func:`parts_matrices` -- made-up skin (star form) from the parts and a skin albedo.
- :func:`parts_albedo`, :func:`parts_colour` -- its directional albedo (gloss included) and its
  colour under uniform light.
- :func:`slab_colour` -- the colour of a foundation at a thickness on a skin, exactly.
- :func:`channel_colours` -- the same for three channels, each channel kept for the session.
- :data:`ABSORPTION_POWER`, :func:`absorption_along` -- the variable Match Skin searches in.
- :func:`matching_absorption` -- the absorption whose made-up skin at a thickness has a
  target colour (Match Skin), and the colour it reaches.
- :func:`matching_skin_albedo` -- the skin albedo under the film that gives a target colour
  (closed form).
- :func:`matching_shade` -- Match Skin at a thickness: the absorption, and where even full
  absorption leaves the made-up skin too light, the skin under the film darkened.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.adding_doubling import Layer, star_albedo, star_scale
from ..numerics.cache import LRUCache
from ..numerics.quadrature import HemisphereGrid
from .film_slab import (
    ROOT_STEPS,
    FilmSlab,
    bihemispherical_on_grid,
    body,
    face_albedo,
    face_layer,
    film_slab,
    increasing_root,
    relative_thickness,
    skin_star,
    surface_on_body,
)
from .layers import ReflectionLayer, TransmissionLayer

__all__ = [
    "measured_film",
    "foundation_slab",
    "SlabSkinParts",
    "slab_skin_parts",
    "body_gloss_weight",
    "parts_matrices",
    "parts_albedo",
    "parts_colour",
    "slab_colour",
    "channel_colours",
    "COLOURS_CACHE_SIZE",
    "ABSORPTION_POWER",
    "absorption_along",
    "matching_absorption",
    "matching_skin_albedo",
    "matching_shade",
]


def measured_film(film: ReflectionLayer) -> ReflectionLayer:
    """The free film a foundation's body is derived from: ``film``'s diffuse ``P_d`` with the
    paper film's gloss (the gloss it was measured with, paper 4.1.1; its surface's share on the
    surface, the rest the body's).  The presets share the paper film's ``P_d`` and transmission
    and differ in their surface only (docs/model.md §4), so every foundation's body is the paper
    film's, absorbed by its shade."""
    from .presets import paper  # the paper's layers, in albedo units

    surface = paper().film
    return ReflectionLayer(P_d=film.P_d, P_s=surface.P_s, n=surface.n, eta=surface.eta)


def foundation_slab(film: ReflectionLayer, transmission: TransmissionLayer, grid: HemisphereGrid,
                    absorption: ArrayLike = 0.0, *, orders: int | None = None) -> FilmSlab:
    """The body of a foundation (``film``: its top reflection; ``transmission``: eq. 4) at
    every thickness with ``absorption`` (scalar or RGB), passive: :func:`film_slab
    <lut_baker.model.film_slab.film_slab>` of :func:`measured_film`."""
    return film_slab(measured_film(film), transmission, grid, absorption=absorption,
                     orders=orders)


class SlabSkinParts(NamedTuple):
    """Made-up skin at one thickness, per channel ``C`` on a grid of ``N`` polar nodes.

    ``top`` ``(C, orders, N, N)``: star form, what does not depend on the skin's albedo (the
    film's body through its surface, the skin's gloss through the film, every inter-reflection;
    the surface's own gloss left out).  ``through`` ``(C, N)``: ``t(theta)``, dimensionless.
    ``below`` ``(C,)``: ``c``.  ``face`` ``(C, N)``: the surface's gloss albedo ``a_g``.
    ``film`` ``(C, N)``: the film's own directional albedo from above (its body through its
    surface, the surface's gloss left out): the part of ``top``'s albedo that is not the skin's
    gloss (the tiers' film body, docs/model.md "The tiers at a thickness").  ``film_top``
    ``(C, orders, N, N)``: the film's own reflection from above, star form (what
    :func:`body_gloss_weight` weighs)."""

    top: NDArray[np.float64]
    through: NDArray[np.float64]
    below: NDArray[np.float64]
    face: NDArray[np.float64]
    film: NDArray[np.float64] | None = None
    film_top: NDArray[np.float64] | None = None


def _film_layer(film: FilmSlab, thickness: float, face: NDArray[np.float64]) -> Layer:
    """The film on skin (its surface over its body at ``thickness``, paper-film units)."""
    r, t = body(film, thickness)
    return surface_on_body(face_layer(face, film.orders), Layer(top=r, bottom=r, down=t))


def slab_skin_parts(film: FilmSlab, thickness: float, skin: ReflectionLayer,
                    face: ArrayLike | None = None) -> SlabSkinParts:
    """The parts of made-up skin (module docstring) of ``film`` at ``thickness`` (in units of
    the paper's film, :func:`~lut_baker.model.film_slab.relative_thickness`; ``np.inf``: the
    thick limit) on a skin whose gloss is ``skin``'s specular term (its ``P_d`` is left out:
    the albedo is free).  ``face``: the surface's ``a_g`` ``(C, N)``, default the measured
    film's."""
    grid = film.grid
    face_a = film.measured_face if face is None else np.asarray(face, float)
    gloss = ReflectionLayer(P_d=0.0, P_s=skin.P_s, n=skin.n, eta=skin.eta)
    s_g = skin_star(gloss, grid)[:, :film.orders]
    layer = _film_layer(film, float(thickness), face_a)
    channels = max(layer.top.shape[0], s_g.shape[0])
    eye = np.eye(grid.theta.size)
    r_up = np.broadcast_to(layer.bottom, (channels,) + layer.bottom.shape[1:])
    s_g = np.broadcast_to(s_g, (channels,) + s_g.shape[1:])
    # G^T = (I - R' S_g)^-1; the rows of T G are solves of G^T x = T^T.
    g_t = eye - r_up @ s_g
    through_film = np.swapaxes(np.linalg.solve(g_t, np.swapaxes(layer.down, -1, -2)), -1, -2)
    top = layer.top + through_film @ s_g @ np.swapaxes(layer.down, -1, -2)
    s0 = star_scale(grid)[0]
    u = s0 / np.sqrt(np.pi)
    gu = np.linalg.solve(np.swapaxes(g_t[:, 0], -1, -2), np.broadcast_to(u, (channels, u.size))
                         [..., None])[..., 0]  # G u, with G = (I - S_g R')^-1
    v = through_film[:, 0] @ u
    below = np.einsum("j,cjk,ck->c", u, r_up[:, 0], gu)
    film_albedo = np.broadcast_to(star_albedo(layer.top[:, 0], s0), (channels, u.size))
    return SlabSkinParts(top=top, through=np.sqrt(np.pi) * v / s0, below=below,
                         face=np.broadcast_to(face_a, (channels, face_a.shape[-1])),
                         film=film_albedo, film_top=layer.top)


def body_gloss_weight(film: FilmSlab, thickness: float, face: ArrayLike,
                      lobe: NDArray[np.float64], *,
                      film_top: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """``(C,)``: the weight ``w`` of eq. 2's gloss lobe ``lobe`` (star form, ``(C', orders, N,
    N)``, its whole ``P_s``) in the film's own reflection at ``thickness`` (its body through its
    surface ``face``), least squares over the Fourier orders above 0, where a Lambertian body
    has nothing: the body's share of the measured gloss, about ``1 - k`` at the paper's
    thickness without absorption and fading with it as the film thins.  ``film_top``: that
    reflection if already computed (:attr:`SlabSkinParts.film_top` of the same film, thickness
    and face), else computed here."""
    if film_top is None:
        film_top = _film_layer(film, float(thickness), np.asarray(face, float)).top
    top = film_top[:, 1:]
    shape = lobe[:, 1:top.shape[1] + 1]
    return (np.einsum("cmij,cmij->c", top, np.broadcast_to(shape, top.shape))
            / np.maximum(np.einsum("cmij,cmij->c", shape, shape), 1e-300))


def _diffuse_weight(parts: SlabSkinParts, skin_albedo: ArrayLike) -> NDArray[np.float64]:
    """``a / (1 - a c)`` per channel (``a`` and ``c`` broadcast: one channel or three)."""
    a = np.asarray(skin_albedo, float).reshape(-1)
    return a / (1.0 - a * parts.below)


def parts_matrices(parts: SlabSkinParts, skin_albedo: ArrayLike,
                   grid: HemisphereGrid) -> NDArray[np.float64]:
    """Made-up skin without the surface's gloss (star form, ``(C, orders, N, N)``):
    ``top + a / (1 - a c) v v^T`` at order 0, ``v = t s / sqrt(pi)``."""
    s0 = star_scale(grid)[0]
    v = parts.through * s0 / np.sqrt(np.pi)
    weight = _diffuse_weight(parts, skin_albedo)
    out = np.array(np.broadcast_to(parts.top, (max(weight.size, parts.top.shape[0]),)
                                   + parts.top.shape[1:]))
    out[:, 0] += weight[:, None, None] * v[:, :, None] * v[:, None, :]
    return out


def parts_albedo(parts: SlabSkinParts, skin_albedo: ArrayLike,
                 grid: HemisphereGrid) -> NDArray[np.float64]:
    """Directional albedo at the nodes ``(C, N)``: the surface's gloss ``a_g``, ``top``'s
    order 0, and ``a t(theta) t_mean / (1 - a c)`` with ``t_mean = sum 2 w t``."""
    s0 = star_scale(grid)[0]
    t_mean = bihemispherical_on_grid(parts.through, grid)
    diffuse = _diffuse_weight(parts, skin_albedo) * t_mean
    return parts.face + star_albedo(parts.top[:, 0], s0) + diffuse[:, None] * parts.through


def parts_colour(parts: SlabSkinParts, skin_albedo: ArrayLike,
                 grid: HemisphereGrid) -> NDArray[np.float64]:
    """The colour under uniform white light ``(C,)``: :func:`parts_albedo` averaged over
    incidence (``2 cos theta`` weights)."""
    return bihemispherical_on_grid(parts_albedo(parts, skin_albedo, grid), grid)


def slab_colour(film: ReflectionLayer, transmission: TransmissionLayer, skin: ReflectionLayer,
                skin_albedo: ArrayLike, thickness_um: float, grid: HemisphereGrid,
                absorption: ArrayLike = 0.0, face: ArrayLike | None = None) -> NDArray[np.float64]:
    """The colour under uniform white light ``(C,)`` of the foundation (``film``,
    ``transmission``, ``absorption``) ``thickness_um`` micrometres thick (``np.inf``: the
    thick limit) on a skin of gloss ``skin`` and diffuse albedo ``skin_albedo``, every
    inter-reflection included (order 0 only: exact for uniform light).  ``face``: ``film``'s
    :func:`~lut_baker.model.film_slab.face_albedo` on ``grid``, if already computed."""
    slab_a = foundation_slab(film, transmission, grid, absorption, orders=1)
    face_a = face_albedo(film, grid) if face is None else face
    parts = slab_skin_parts(slab_a, _relative(thickness_um), skin, face_a)
    return parts_colour(parts, skin_albedo, grid)


def _relative(thickness_um: float) -> float:
    return np.inf if np.isinf(thickness_um) else relative_thickness(thickness_um)


COLOURS_CACHE_SIZE = 4096
"""Channels' colours :func:`channel_colours` keeps (a search evaluates at most
``ROOT_STEPS + 2`` colours of three channels)."""

_COLOURS = LRUCache(COLOURS_CACHE_SIZE)


def channel_colours(film: ReflectionLayer, transmission: TransmissionLayer,
                    skin: ReflectionLayer, skin_albedo: ArrayLike, thickness_um: float,
                    grid: HemisphereGrid, absorption: ArrayLike,
                    face: ArrayLike | None = None) -> NDArray[np.float64]:
    """:func:`slab_colour` of three channels (``skin_albedo`` and ``absorption`` scalars or
    RGB), ``(3,)``, each channel kept for the session under its own inputs.  The channels are
    independent (a channel's colour is the same to the bit whatever the others are), so a
    channel evaluated in one search is found by the next: Lighter then Darker retrace the
    search that found the shade they return to, and the current shade's colour is its own
    search's last evaluation of each channel."""
    albedo = np.broadcast_to(np.asarray(skin_albedo, float), (3,))
    a = np.broadcast_to(np.asarray(absorption, float), (3,))
    common = (repr(film.as_dict()), repr(transmission.as_dict()), repr(skin.as_dict()),
              float(thickness_um), grid.theta.tobytes(), grid.weight.tobytes(), grid.n_phi)
    keys = [(common, c, float(albedo[c]), float(a[c])) for c in range(3)]
    kept = [_COLOURS.get(key) for key in keys]
    missing = [c for c in range(3) if kept[c] is None]
    if missing:
        # A kept channel is evaluated as a missing one (its own inputs may cost more: a film
        # absorbing little has its passivity solved for) and its result left aside.
        pick = [c if kept[c] is None else missing[0] for c in range(3)]
        colour = np.broadcast_to(slab_colour(film, transmission, skin, albedo[pick],
                                             thickness_um, grid, a[pick], face), (3,))
        for c in missing:
            kept[c] = float(colour[c])
            _COLOURS.put(keys[c], kept[c])
    return np.array(kept, float)


ABSORPTION_POWER = 3
"""The power of :func:`absorption_along`: with it the made-up skin's colour is nearly linear in
``s`` (a film's colour falls fast as the first pigment absorbs, then slowly)."""


def absorption_along(s: ArrayLike) -> NDArray[np.float64]:
    """The absorption ``A = 1 - (1 - s)^p`` (``p``: :data:`ABSORPTION_POWER`) at ``s`` in [0, 1]
    (increasing, 0 and 1 at the ends exactly): the variable Match Skin searches in."""
    return 1.0 - (1.0 - np.asarray(s, float)) ** ABSORPTION_POWER


def matching_absorption(target: ArrayLike, film: ReflectionLayer,
                        transmission: TransmissionLayer, skin: ReflectionLayer,
                        skin_albedo: ArrayLike, thickness_um: float, grid: HemisphereGrid
                        ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """``(A, clamped, colour)`` per channel: the foundation's absorption whose made-up skin at
    ``thickness_um`` has the colour ``target`` (RGB, under uniform light) on the skin under the
    film (``skin``'s gloss, diffuse albedo ``skin_albedo``), and the colour it has there (the
    search's own evaluation: :func:`slab_colour` at ``A``).  :func:`slab_colour` falls as ``A``
    grows, and a bracketed root finds it (:func:`~lut_baker.model.film_slab.increasing_root`)
    in :func:`absorption_along`'s ``s``, where the colour is nearly linear (at the default
    thickness 7-8 evaluations where ``A`` itself takes 9-11).  A target out of the film's reach
    gets ``A = 0`` (too light) or 1 (too dark) and ``clamped``."""
    goal = np.broadcast_to(np.asarray(target, float), (3,))
    face = face_albedo(film, grid)

    def colour(a: NDArray[np.float64]) -> NDArray[np.float64]:
        # kept per channel: the ends, asked twice, are evaluated once, and the root's own
        # channels give the colour reached
        return channel_colours(film, transmission, skin, skin_albedo, thickness_um, grid, a,
                               face)

    along = increasing_root(lambda s: -colour(absorption_along(s)), -goal, ROOT_STEPS)
    absorption = absorption_along(along)
    too_light = goal > colour(np.zeros(3))
    too_dark = goal < colour(np.ones(3))
    return absorption, too_light | too_dark, colour(absorption)


def matching_skin_albedo(parts: SlabSkinParts, target: ArrayLike,
                         grid: HemisphereGrid) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """``(a, clamped)`` per channel: the skin's diffuse albedo under the film whose made-up
    skin (``parts``, at their absorption and thickness) has the colour ``target`` under uniform
    light.  The colour is ``F + a t_mean^2 / (1 - a c)`` (``F`` the colour at ``a = 0``), so
    ``a = (target - F) / (t_mean^2 + c (target - F))``; a target below ``F`` gets 0, one the
    albedo 1 cannot reach gets 1, and ``clamped`` says so."""
    goal = np.asarray(target, float).reshape(-1)
    floor = parts_colour(parts, 0.0, grid)
    t_mean = bihemispherical_on_grid(parts.through, grid)
    rise = goal - floor
    albedo = rise / (t_mean**2 + parts.below * rise)
    clamped = (albedo < 0.0) | (albedo > 1.0)
    return np.clip(albedo, 0.0, 1.0), clamped


def matching_shade(target: ArrayLike, film: ReflectionLayer, transmission: TransmissionLayer,
                   skin: ReflectionLayer, skin_albedo: ArrayLike, thickness_um: float,
                   grid: HemisphereGrid) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                                  NDArray[np.bool_], NDArray[np.float64]]:
    """Match Skin at a thickness: ``(A, a, clamped, colour)`` per channel.  The foundation's
    absorption ``A`` first (:func:`matching_absorption`: the shade is the foundation's, the skin
    under the film is the artist's); where even ``A = 1`` leaves the made-up skin lighter than
    ``target`` (a sheer film whose surface gloss alone adds more than its pigment can take
    away), the skin's albedo under the film ``a`` is lowered until it matches
    (:func:`matching_skin_albedo`), else ``a`` is ``skin_albedo`` unchanged.  ``clamped``: out of
    reach of both.  ``colour``: the made-up skin's at ``A`` and ``a`` (:func:`slab_colour`),
    from the search's evaluations."""
    absorption, clamped, reached = matching_absorption(target, film, transmission, skin,
                                                       skin_albedo, thickness_um, grid)
    albedo = np.array(np.broadcast_to(np.asarray(skin_albedo, float), (3,)))
    goal = np.broadcast_to(np.asarray(target, float), (3,))
    dark = clamped & (absorption == 1.0)
    if np.any(dark):
        slab_1 = foundation_slab(film, transmission, grid, 1.0, orders=1)
        parts = slab_skin_parts(slab_1, _relative(thickness_um), skin, face_albedo(film, grid))
        under, out = matching_skin_albedo(parts, goal, grid)
        albedo = np.where(dark, under, albedo)
        clamped = np.where(dark, out, clamped)
        reached = np.where(dark, parts_colour(parts, albedo, grid), reached)
    return absorption, albedo, clamped, reached
