"""The foundation film as a slab with a thickness: a surface on top, a body beneath
(docs/model.md, "The film as a slab"; paper 4.1 for the film measured, eqs. 2 and 4).

The film is made of

- its **surface**: an interface of the film's vehicle (:data:`VEHICLE_INDEX`).  It reflects
  eq. 2's specular lobe of the film (its gloss, path 1) scaled by the share ``k`` an interface
  of the vehicle reflects under uniform light (:func:`surface_share`, :func:`surface_layer`):
  the fraction ``a_g(theta)`` of the light falling on it (:func:`face_albedo`); the rest,
  ``1 - a_g``, crosses it straight (the film does not refract, docs/model.md §2.2); light
  reaching it from inside is reflected back by the same fraction, specularly, and crosses it by
  ``1 - a_g``.  It is lossless and reciprocal;
- its **body**: a homogeneous symmetric slab (the pigment), whose reflection and transmission
  per Fourier order come from :mod:`lut_baker.numerics.adding_doubling`.

The free film the paper measured (foundation filling a hole in a 0.15 mm cover glass, paper
4.1) is surface, body, surface (air on both sides): its reflection is eq. 2 (the gloss and
``P_d``) and its transmission eq. 4.  The share of the gloss the surface does not reflect,
``1 - k``, is the body's: the free film's reflection below its surface's is ``P_d`` and ``1 - k``
of the gloss lobe (:func:`measured_body_matrices`).  The body at that thickness is what remains
when the two faces are taken off those measurements (:func:`remove_faces`, exact), and the body
at any other thickness
follows from the doubling relation inverted (:func:`body_generator`).  On skin the film is its
surface and its body (no air under it), over the skin with every inter-reflection summed
(:func:`made_up_matrices`).

Absorption ``A`` (per channel, docs/model.md §4) keeps its meaning at the paper's thickness: the
measured film's reflection below its surface (``P_d`` and the body's share of the gloss) and its
transmission are scaled by ``1 - A`` before the body is derived, so the free film of the paper's
thickness reflects and transmits exactly what it did, the body's share of the gloss absorbed (up
to :func:`passive` below); the thickness then decides how much a film absorbs.

Functions and types
-------------------
- :data:`PAPER_FILM_THICKNESS_UM`, :data:`APPLIED_MASS_MG_PER_CM2`,
  :data:`FOUNDATION_DENSITY_G_PER_CM3`, :data:`DEFAULT_THICKNESS_UM`,
  :data:`PAPER_FILM_OPTICAL_THICKNESS` -- the thicknesses and their sources.
- :func:`thickness_from_mass` -- micrometres of film from mass per area and density.
- :func:`relative_thickness` -- a thickness in units of the paper's film.
- :data:`VEHICLE_INDEX` -- the refractive index of the film's vehicle, its source.
- :func:`interface_albedo` -- a smooth dielectric interface's reflectance under uniform light.
- :func:`surface_share`, :func:`surface_layer` -- the share ``k`` of eq. 2's gloss the film's
  surface reflects, and the surface as a layer (eq. 2's gloss times ``k``);
  :data:`SHARE_LEVEL`, :data:`SHARE_NODES` -- the integral ``k`` divides, its accuracy.
- :func:`face_albedo` -- ``a_g`` of a film's surface at the grid's nodes.
- :func:`face_layer` -- the surface as a layer (star form, its gloss left out).
- :func:`measured_body_matrices` -- the free film's reflection below its surface's and its
  transmission (eq. 2's ``P_d`` and ``1 - k`` of its gloss, eq. 4) in the star form.
- :func:`remove_faces` -- the body inside a symmetric free film, its two faces taken off.
- :class:`FilmSlab`, :func:`film_slab` -- the body at every thickness, with absorption.
- :func:`body` -- the body's ``(R, T)`` at a thickness.
- :func:`surface_on_body` -- the surface over the body (the adding equations, their two
  systems solved as one).
- :func:`free_film_matrices` -- the free film (face, body, face) at a thickness.
- :func:`made_up_matrices`, :func:`made_up_albedo` -- the film on skin (surface, body, skin,
  every inter-reflection), its directional albedo with the surface's gloss.
- :func:`thick_limit_albedo` -- the film at infinite thickness (what a product looks like in
  the bottle), directional.
- :func:`bihemispherical_on_grid` -- a directional albedo at the nodes averaged over uniform
  light.
- :func:`thick_limit_colour` -- that film's colour under uniform light at an absorption.
- :func:`solve_thick_absorption` -- the absorption whose thick film has a target colour.
- :func:`skin_star` -- a skin's eq. 2 kernel in the star form (cached per skin and grid).
- :func:`increasing_root` -- per entry, where an increasing function of [0, 1] meets a target
  (Chandrupatla's method, vectorised).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.adding_doubling import (
    Layer,
    SlabGenerator,
    absorption_per_direction,
    add_layers,
    mirror,
    passive_family,
    passive_generator,
    slab,
    slab_generator,
    star_albedo,
    star_scale,
    thick_slab,
    to_star,
)
from ..numerics.cache import LRUCache
from ..numerics.quadrature import HemisphereGrid
from .albedo import bihemispherical, layer_fourier_kernel, specular_albedo
from .layers import ReflectionLayer, TransmissionLayer
from .microfacet import fresnel_reflectance

__all__ = [
    "PAPER_FILM_THICKNESS_UM",
    "APPLIED_MASS_MG_PER_CM2",
    "FOUNDATION_DENSITY_G_PER_CM3",
    "DEFAULT_THICKNESS_UM",
    "ON_SKIN_OPTICAL_THICKNESS",
    "PAPER_FILM_OPTICAL_THICKNESS",
    "thickness_from_mass",
    "relative_thickness",
    "VEHICLE_INDEX",
    "interface_albedo",
    "surface_share",
    "SHARE_LEVEL",
    "SHARE_NODES",
    "surface_layer",
    "face_albedo",
    "face_layer",
    "measured_body_matrices",
    "remove_faces",
    "FilmSlab",
    "film_slab",
    "body",
    "surface_on_body",
    "free_film_matrices",
    "made_up_matrices",
    "made_up_albedo",
    "thick_limit_albedo",
    "bihemispherical_on_grid",
    "thick_limit_colour",
    "solve_thick_absorption",
    "skin_star",
    "increasing_root",
    "ROOT_STEPS",
]

PAPER_FILM_THICKNESS_UM = 150.0
"""The film the paper measured: foundation filling a hole in a cover glass about 0.15 mm thick
(paper 4.1, fig. 4), micrometres."""

APPLIED_MASS_MG_PER_CM2 = 540.0 / 565.0
"""Liquid foundation applied to a face, mg/cm^2: 0.54 g per application (geometric mean over
about 300 US women weighing their own product for two weeks, Loretz et al. 2006, Food Chem.
Toxicol. 44(12):2008-2018; median 0.36 g) over a face of 565 cm^2 (the face area of the SCCS
Notes of Guidance for cosmetic exposure)."""

FOUNDATION_DENSITY_G_PER_CM3 = 1.0
"""Density of a liquid foundation, g/cm^3: an emulsion of water, oils and silicones (about 1)
with some 10-20% pigment; taken as 1 (the pigment would raise it by some 10%)."""


def thickness_from_mass(mass_mg_per_cm2: ArrayLike,
                        density_g_per_cm3: ArrayLike = FOUNDATION_DENSITY_G_PER_CM3
                        ) -> NDArray[np.float64]:
    """Film thickness in micrometres of a mass per area (mg/cm^2) at a density (g/cm^3):
    ``10 m / rho`` (1 mg/cm^2 at 1 g/cm^3 is 10 micrometres).

    >>> float(thickness_from_mass(1.0))  # mg/cm^2, at 1 g/cm^3
    10.0
    >>> print(np.round(thickness_from_mass([0.5, APPLIED_MASS_MG_PER_CM2]), 2))  # on a face
    [5.   9.56]
    """
    return 10.0 * np.asarray(mass_mg_per_cm2, float) / np.asarray(density_g_per_cm3, float)


DEFAULT_THICKNESS_UM = float(thickness_from_mass(APPLIED_MASS_MG_PER_CM2))
"""A typical application on a face, micrometres (about 9.6): :data:`APPLIED_MASS_MG_PER_CM2`
at :data:`FOUNDATION_DENSITY_G_PER_CM3`, as applied (before anything evaporates; the paper's
film is measured as filled in, likewise)."""

ON_SKIN_OPTICAL_THICKNESS = 0.5
"""Optical thickness of foundation on skin in Lanza et al. 2024's renderings (their fig. 10
scripts, about 0.51), taken as that of :data:`DEFAULT_THICKNESS_UM`."""

PAPER_FILM_OPTICAL_THICKNESS = (ON_SKIN_OPTICAL_THICKNESS * PAPER_FILM_THICKNESS_UM
                                / DEFAULT_THICKNESS_UM)
"""Optical thickness of the paper's film (about 7.8): how fast light the measured film
extinguishes entirely (below what eq. 4 resolves) fades with thickness, the unscattered light's
``exp(-tau x)`` (:func:`lut_baker.numerics.adding_doubling.slab_generator`'s ``max_rate``)."""

ROOT_STEPS = 30
"""Steps of the root finder (:func:`increasing_root`) of :func:`solve_thick_absorption`, of the
passive slab's relief and of Match Skin at a thickness: it reaches rounding within some 3-12
steps."""
RELIEF_STEPS = ROOT_STEPS
ROOT_TOLERANCE = 1e-13
"""The root finder stops when every entry is within this of its target, or its bracket is
this narrow."""
MEASURED_CACHE_SIZE = 8
"""Films and grids whose measured matrices are kept in this process."""


def relative_thickness(thickness_um: float) -> float:
    """A thickness in micrometres in units of the paper's film (:data:`PAPER_FILM_THICKNESS_UM`).

    >>> relative_thickness(15.0)  # a tenth of the film the paper measured
    0.1
    """
    value = float(thickness_um)
    if not value >= 0.0:
        raise ValueError(f"thickness must be >= 0 micrometres, got {thickness_um!r}")
    return value / PAPER_FILM_THICKNESS_UM


def _channels_first(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(..., C)`` to ``(C, ...)``."""
    return np.moveaxis(values, -1, 0)


VEHICLE_INDEX = 1.40
"""Refractive index of a liquid foundation's vehicle, the medium its surface is an interface
of: the silicones that carry most liquid foundations' pigment, cyclopentasiloxane (1.397 at
25 C, Dow's XIAMETER PMX-0245 data sheet) and dimethicone (about 1.40, Dow's PMX-200 fluids);
emollient oils lie near 1.45.  An interface of 1.40 reflects 2.8% at normal incidence and
7.7% under uniform light (:func:`interface_albedo`)."""


def interface_albedo(eta: float) -> float:
    """A smooth dielectric interface's reflectance under uniform light from outside, ``2 Int
    F_r(mu, eta) mu dmu`` (its bihemispherical albedo; the unpolarised Fresnel reflectance).

    >>> round(interface_albedo(VEHICLE_INDEX), 4)  # the vehicle's interface
    0.0768
    >>> round(interface_albedo(1.5), 4)  # glass
    0.0918
    """
    return float(bihemispherical(lambda theta_deg: fresnel_reflectance(
        np.cos(np.radians(theta_deg)), float(eta))))


SHARE_LEVEL = 1
"""Level of :func:`~lut_baker.model.albedo.specular_albedo` in :func:`surface_share`'s
integral (twice :data:`~lut_baker.model.albedo.SPECULAR_POINTS`' nodes)."""
SHARE_NODES = 16
"""Gauss-Legendre incidences of :func:`surface_share`'s integral.  With
:data:`SHARE_LEVEL`, the gloss albedo under uniform light is within 2.1e-5 (relative) of the
Fourier grid's order 0 at 48 incidences (itself within about 1e-5 of converged) for lobes 2 to
30 degrees wide, 6e-5 at 45 and 1.3e-4 at 60, in 0.01 s where that grid takes 0.1 s for the
paper film's 30-degree lobe (``bench/film_surface.py --share``)."""


def surface_share(film: ReflectionLayer, vehicle_index: float = VEHICLE_INDEX
                  ) -> NDArray[np.float64]:
    """``k``: the share of eq. 2's gloss (the specular term of ``film``) that the film's surface
    reflects, ``min(1, F / a_g)`` with ``F`` the vehicle's :func:`interface_albedo` and ``a_g``
    the gloss's albedo under uniform light (docs/model.md, "The film as a slab"; integrated
    through the half vector, :data:`SHARE_NODES`); 1 for a film without gloss.  Shaped as
    ``film.P_s`` (a scalar or per channel).  ``a_g`` is linear in ``P_s``: computed once per
    lobe (``n``, ``eta``).

    >>> paper_film = ReflectionLayer(P_d=0.155, P_s=10.7, n=0.033, eta=1.19)  # albedo units
    >>> print(np.round(surface_share(paper_film), 3))  # a_g 0.14: the interface reflects 55%
    0.549
    >>> dewy = ReflectionLayer(P_d=0.155, P_s=0.5, n=0.17, eta=1.09)  # a_g 0.013 < F
    >>> print(surface_share(dewy))
    1.0
    """
    p_s = np.asarray(film.P_s, float)
    if not np.any(p_s > 0.0):  # no gloss: nothing to integrate
        return np.ones(p_s.shape)
    albedo = p_s * _unit_gloss_albedo(film)
    interface = interface_albedo(vehicle_index)
    return np.where(albedo > interface, interface / np.where(albedo > 0.0, albedo, 1.0), 1.0)


def _unit_gloss_albedo(film: ReflectionLayer) -> NDArray[np.float64]:
    """The albedo under uniform light of ``film``'s gloss lobe at ``P_s = 1`` (a scalar, or
    per channel), once per lobe."""
    unit = ReflectionLayer(P_d=0.0, P_s=1.0, n=film.n, eta=film.eta)

    def compute() -> NDArray[np.float64]:
        value = np.asarray(bihemispherical(
            lambda theta: specular_albedo(theta, unit, level=SHARE_LEVEL), SHARE_NODES), float)
        value = value if unit.channels else value[..., 0]
        value.setflags(write=False)
        return value

    return _SHARES.get_or_compute(repr(unit.as_dict()), compute)


def surface_layer(film: ReflectionLayer) -> ReflectionLayer:
    """The film's surface as eq. 2's layer: ``film``'s specular term times
    :func:`surface_share` (its ``P_s`` scaled; its ``P_d`` 0, the body's)."""
    return film.scaled(P_d=0.0, P_s=surface_share(film))


def face_albedo(film: ReflectionLayer, grid: HemisphereGrid) -> NDArray[np.float64]:
    """``a_g``: the directional albedo of the film's surface (:func:`surface_layer`: eq. 2's
    specular term times :func:`surface_share`) at the grid's polar nodes, ``(C, N)`` (C = 1 for
    a scalar film), through the half vector (:func:`~lut_baker.model.albedo.specular_albedo`,
    as the bake's gloss tables); zeros for a film without gloss (``P_s = 0``).  Computed once
    per surface and grid (a read-only array: Match Skin and the bake ask for it again and
    again)."""
    gloss = film.scaled(P_d=0.0)
    channels = 3 if film.channels else 1

    def compute() -> NDArray[np.float64]:
        if not np.any(np.asarray(gloss.P_s) > 0.0):
            values = np.zeros((channels, grid.theta.size))
        else:
            values = _channels_first(specular_albedo(np.degrees(grid.theta),
                                                     surface_layer(film)))
        values.setflags(write=False)
        return values

    return _FACES.get_or_compute((repr(gloss.as_dict()), channels, *_grid_key(grid)), compute)


def _grid_key(grid: HemisphereGrid) -> tuple[bytes, bytes, int]:
    """What identifies a grid in this module's caches."""
    return grid.theta.tobytes(), grid.weight.tobytes(), grid.n_phi


def face_layer(albedo: ArrayLike, orders: int) -> Layer:
    """The surface in the star form, ``(C, orders, N, N)``: from above it reflects nothing here
    (its gloss, eq. 2's specular term, is the closed form added outside the grid), transmits
    ``1 - a_g`` straight; from below it reflects ``a_g`` specularly."""
    albedo = np.asarray(albedo, float)
    eye = np.eye(albedo.shape[-1])
    down = np.broadcast_to((1.0 - albedo)[:, None, None, :] * eye,
                           albedo.shape[:1] + (orders,) + eye.shape)
    return Layer(top=np.zeros(down.shape), bottom=mirror(albedo, orders), down=down)


def measured_body_matrices(film: ReflectionLayer, transmission: TransmissionLayer,
                           grid: HemisphereGrid) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The measured free film's reflection below its surface's and its transmission (eq. 4) in
    the star form, each ``(C, orders, N, N)``: eq. 2's ``P_d`` (Lambertian) and the share of
    its gloss lobe the surface does not reflect (:func:`_body_gloss`), the light the body
    returns."""
    scale = star_scale(grid)
    t = _channels_first(layer_fourier_kernel(transmission, grid.theta, grid.theta, grid.n_phi))
    gloss = _body_gloss(film, grid)
    p_d = np.asarray(film.P_d, float).reshape(-1)
    channels = max(t.shape[0], p_d.size, gloss.shape[0])
    r = np.array(np.broadcast_to(gloss, (channels,) + t.shape[1:]))
    r[:, 0] += np.broadcast_to(p_d, (channels,))[:, None, None] * scale[0][:, None] * scale[0]
    return r, to_star(np.broadcast_to(t, (channels,) + t.shape[1:]), scale)


def _body_gloss(film: ReflectionLayer, grid: HemisphereGrid) -> NDArray[np.float64]:
    """The share of eq. 2's gloss lobe the surface does not reflect, ``1 - k``
    (:func:`surface_share`), in the star form, ``(C, orders, N, N)`` (every order; zeros, one
    channel, where the surface reflects it all): the measured film's gloss the body returns."""
    rest = 1.0 - surface_share(film)
    if not np.any(rest > 0.0):
        return np.zeros((1, grid.orders, grid.theta.size, grid.theta.size))
    lobe = film.scaled(P_d=0.0, P_s=rest)
    kernel = layer_fourier_kernel(lobe, grid.theta, grid.theta, grid.n_phi)
    return to_star(_channels_first(kernel), star_scale(grid))


def remove_faces(reflection: NDArray[np.float64], transmission: NDArray[np.float64],
                 albedo: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The body inside a symmetric free film (surface, body, surface) whose reflection without
    its gloss is ``reflection`` and whose transmission is ``transmission`` (star form,
    ``(C, orders, N, N)``), the surfaces reflecting ``a_g = albedo`` ``(C, N)``.

    The film lit alike from both sides (``S = R + T``), and in antiphase (``D = R - T``), is
    half the film over a mirror, and over an anti-mirror; for either, with ``F = diag(1 -
    a_g)`` and ``rho`` the surface's reflection from below,
    ``S_film - gloss = F (I - S_body rho)^-1 S_body F``, hence ``X = F^-1 (S_film - gloss)
    F^-1`` and ``S_body = X (I + rho X)^-1`` (likewise ``D``); ``R = (S + D) / 2``,
    ``T = (S - D) / 2``.  Exact; symmetric matrices in, symmetric out."""
    albedo = np.asarray(albedo, float)
    orders = reflection.shape[-3]
    inv = 1.0 / (1.0 - albedo)
    rho = mirror(albedo, orders)
    eye = np.eye(albedo.shape[-1])

    def inner(film: NDArray[np.float64]) -> NDArray[np.float64]:
        x = inv[:, None, :, None] * film * inv[:, None, None, :]
        # X (I + rho X)^-1, solved from the right.
        return np.swapaxes(np.linalg.solve(np.swapaxes(eye + rho @ x, -1, -2),
                                           np.swapaxes(x, -1, -2)), -1, -2)

    even = inner(reflection + transmission)
    odd = inner(reflection - transmission)
    return 0.5 * (even + odd), 0.5 * (even - odd)


@dataclass(frozen=True, eq=False)
class FilmSlab:
    """The film's body at every thickness, per channel (``(C, orders, N, N)``): ``generator``
    (:class:`~lut_baker.numerics.adding_doubling.SlabGenerator`, thickness in units of the
    paper's film), on ``grid``, with ``absorption`` ``(C,)`` and ``measured_face`` ``(C, N)``,
    the surface the body was derived under (the measured film's)."""

    grid: HemisphereGrid
    generator: SlabGenerator
    absorption: NDArray[np.float64]
    measured_face: NDArray[np.float64]

    @property
    def orders(self) -> int:
        """Fourier orders held."""
        return self.generator.rates.shape[-2]

    @property
    def scale(self) -> NDArray[np.float64]:
        """:func:`~lut_baker.numerics.adding_doubling.star_scale` of the grid."""
        return star_scale(self.grid)


_MEASURED = LRUCache(MEASURED_CACHE_SIZE)
_FACES = LRUCache(MEASURED_CACHE_SIZE)
_SHARES = LRUCache(MEASURED_CACHE_SIZE)


def _measured(film: ReflectionLayer, transmission: TransmissionLayer, grid: HemisphereGrid
              ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """:func:`measured_body_matrices` and :func:`face_albedo`, computed once per film and grid."""
    key = (repr(film.as_dict()), repr(transmission.as_dict()), *_grid_key(grid))

    def compute() -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        arrays = (*measured_body_matrices(film, transmission, grid), face_albedo(film, grid))
        for array in arrays:
            array.setflags(write=False)
        return arrays

    return _MEASURED.get_or_compute(key, compute)


def _free_film_albedo(face: NDArray[np.float64], scale0: NDArray[np.float64],
                      grid: HemisphereGrid) -> Callable[[SlabGenerator], NDArray[np.float64]]:
    """``generator -> `` the bihemispherical ``R + T`` (gloss left out) of the free film of unit
    thickness, order 0 (:func:`free_film_matrices`), its two faces built once."""
    faces = _free_film_faces(face, 1)

    def albedo(generator: SlabGenerator) -> NDArray[np.float64]:
        order0 = SlabGenerator(basis=generator.basis[..., :1, :, :],
                               rates=generator.rates[..., :1, :])
        r, t = slab(order0, 1.0)
        top, down = _free_film(faces, Layer(top=r, bottom=r, down=t))
        return bihemispherical_on_grid(star_albedo(top[:, 0], scale0)
                                       + star_albedo(down[:, 0], scale0), grid)

    return albedo


def _passive(generator: SlabGenerator, target: ArrayLike, face: NDArray[np.float64],
             grid: HemisphereGrid) -> SlabGenerator:
    """:func:`~lut_baker.numerics.adding_doubling.passive_generator` with the ``relief`` per
    channel (a root on [0, 1], :func:`increasing_root`) at which the free film of unit
    thickness keeps, under uniform light, the measured film's ``R + T`` (``target``): passive,
    and absorbing what the measured film absorbs.  The root's generators share their work
    (:func:`~lut_baker.numerics.adding_doubling.passive_family`)."""
    scale0 = star_scale(grid)[0]
    first = SlabGenerator(basis=generator.basis[..., 0, :, :], rates=generator.rates[..., 0, :])
    if not np.any(absorption_per_direction(first, scale0) < 0.0):
        return generator  # passive already: any relief leaves it as it is
    order0 = SlabGenerator(basis=generator.basis[..., :1, :, :], rates=generator.rates[..., :1, :])
    family = passive_family(order0, scale0)
    albedo = _free_film_albedo(face, scale0, grid)
    relief = increasing_root(lambda r: albedo(family(r)),
                             np.broadcast_to(np.asarray(target, float), (face.shape[0],)),
                             RELIEF_STEPS)
    if generator.rates.shape[-2] == 1:  # order 0 only: the root's family
        return family(relief)
    return passive_generator(generator, scale0, relief)


def increasing_root(function: Callable[[NDArray[np.float64]], NDArray[np.float64]],
                    target: NDArray[np.float64], steps: int) -> NDArray[np.float64]:
    """Per entry, ``x`` in [0, 1] with ``function(x) = target`` for an increasing ``function``
    (vectorised over the entries), by Chandrupatla's method (false position first, then inverse
    quadratic interpolation where the last three points allow it, else bisection: the bracket
    always holds the root, and it shrinks superlinearly, in about half the steps of the
    Illinois variant of false position) until :data:`ROOT_TOLERANCE` (the value, or the
    bracket); 0 or 1 when the target lies outside ``[function(0), function(1)]``.

    >>> print(increasing_root(lambda x: x**2, np.array([0.25, 0.5, 2.0]), ROOT_STEPS))
    [0.5        0.70710678 1.        ]
    """
    a, b = np.zeros(target.shape), np.ones(target.shape)  # a: the newest point, b: the other end
    f_a, f_b = function(a) - target, function(b) - target
    below, above = f_a >= 0.0, f_b <= 0.0
    done = below | above
    c, f_c = b, f_b  # the point before (unused by the first step)
    best = a
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(done, 0.5, f_a / (f_a - f_b))  # false position
        for _ in range(steps):
            if np.all(done):  # every target out of reach (or met): no step to take
                break
            least = np.minimum(0.5 * ROOT_TOLERANCE / np.abs(b - a), 0.5)
            x = a + np.clip(np.where(np.isfinite(t), t, 0.5), least, 1.0 - least) * (b - a)
            f_x = function(x) - target
            same = np.sign(f_x) == np.sign(f_a)
            moving = ~done
            c, f_c = (np.where(moving, np.where(same, a, b), c),
                      np.where(moving, np.where(same, f_a, f_b), f_c))
            b, f_b = np.where(moving & ~same, a, b), np.where(moving & ~same, f_a, f_b)
            a, f_a = np.where(moving, x, a), np.where(moving, f_x, f_a)
            closer = np.abs(f_a) < np.abs(f_b)
            best = np.where(closer, a, b)
            done = done | (np.minimum(np.abs(f_a), np.abs(f_b)) <= ROOT_TOLERANCE) \
                | (np.abs(b - a) <= ROOT_TOLERANCE)
            xi, phi = (a - b) / (c - b), (f_a - f_b) / (f_c - f_b)
            quadratic = (phi**2 < xi) & ((1.0 - phi)**2 < 1.0 - xi)
            t = np.where(quadratic, f_a / (f_b - f_a) * f_c / (f_b - f_c)
                         + (c - a) / (b - a) * f_a / (f_c - f_a) * f_b / (f_c - f_b), 0.5)
    return np.where(below, 0.0, np.where(above, 1.0, best))


def film_slab(film: ReflectionLayer, transmission: TransmissionLayer, grid: HemisphereGrid, *,
              absorption: ArrayLike = 0.0,
              optical_thickness: float = PAPER_FILM_OPTICAL_THICKNESS,
              passive: bool = True, orders: int | None = None) -> FilmSlab:
    """The body of a measured film (``film``: eq. 2, gloss and ``P_d``; ``transmission``:
    eq. 4; in albedo units) at every thickness, with absorption ``A`` (scalar or RGB in
    [0, 1]).

    At the measured thickness the free film's reflection below its surface
    (:func:`measured_body_matrices`) and transmission times ``1 - A`` are the target; its faces
    (:func:`surface_layer` of ``film``) are taken off
    (:func:`remove_faces`) and the doubling relation inverted
    (:func:`~lut_baker.numerics.adding_doubling.slab_generator`, light the film extinguishes
    fading as ``exp(-optical_thickness x)``).  ``passive``: no direction may gain light
    (:func:`~lut_baker.numerics.adding_doubling.passive_generator`, with the relief that keeps
    the free film's absorption under uniform light; docs/model.md, "The film as a slab": the
    measured film, normalised to be lossless at normal incidence, is not quite a passive slab
    under a lossless surface).  ``orders``: keep the first orders only (1 for albedos under
    uniform light).

    >>> from lut_baker.numerics.quadrature import hemisphere_panels
    >>> grid = hemisphere_panels(1, 4, 3)  # 4 polar nodes, azimuth orders 0 and 1
    >>> film = ReflectionLayer(P_d=0.155, P_s=10.7, n=0.033, eta=1.19)  # eq. 2, albedo units
    >>> through = TransmissionLayer(P_d=0.095, P_t=0.039, n=0.035, eta=1.19)  # eq. 4
    >>> dark = film_slab(film, through, grid, absorption=[0.0, 0.2, 0.5], passive=False)
    >>> r, t = free_film_matrices(dark, 1.0)  # at the measured thickness: 1 - A of it
    >>> r_measured, t_measured = measured_body_matrices(film, through, grid)
    >>> print(np.round(star_albedo(r[:, 0], dark.scale[0])
    ...                / star_albedo(r_measured[:, 0], dark.scale[0]), 3))
    [[1.  1.  1.  1. ]
     [0.8 0.8 0.8 0.8]
     [0.5 0.5 0.5 0.5]]
    """
    a = np.atleast_1d(np.asarray(absorption, float))
    if a.shape not in ((1,), (3,)) or np.any(a < 0.0) or np.any(a > 1.0):
        raise ValueError(f"absorption must be a float or RGB in [0, 1], got {absorption!r}")
    if not optical_thickness > 0.0:
        raise ValueError(f"optical_thickness must be > 0, got {optical_thickness!r}")
    r, t, face = _measured(film, transmission, grid)
    if orders is not None:
        r, t = r[:, :orders], t[:, :orders]
    channels = max(r.shape[0], face.shape[0], a.size)
    once = (1.0 - a)[:, None, None, None]
    # The pigment absorbs all the body returns: P_d and the body's share of the gloss
    # (docs/model.md, "The film as a slab").
    r = np.broadcast_to(r, (channels,) + r.shape[1:]) * once
    t = np.broadcast_to(t, (channels,) + t.shape[1:]) * once
    face = np.broadcast_to(face, (channels, face.shape[-1]))
    body_r, body_t = remove_faces(r, t, face)
    generator = slab_generator(body_r, body_t, max_rate=0.5 * float(optical_thickness))
    if passive:
        scale0 = star_scale(grid)[0]
        target = bihemispherical_on_grid(star_albedo(r[:, 0], scale0)
                                         + star_albedo(t[:, 0], scale0), grid)
        generator = _passive(generator, target, face, grid)
    return FilmSlab(grid=grid, generator=generator,
                    absorption=np.broadcast_to(a, (channels,)).copy(), measured_face=face)


def body(film: FilmSlab, thickness: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The body's ``(R, T)`` (star form, ``(C, orders, N, N)``) at ``thickness`` in units of
    the paper's film (:func:`relative_thickness`).

    >>> from lut_baker.numerics.quadrature import hemisphere_panels
    >>> grid = hemisphere_panels(1, 4, 3)  # 4 polar nodes, azimuth orders 0 and 1
    >>> film = ReflectionLayer(P_d=0.155, P_s=10.7, n=0.033, eta=1.19)  # eq. 2, albedo units
    >>> through = TransmissionLayer(P_d=0.095, P_t=0.039, n=0.035, eta=1.19)  # eq. 4
    >>> r, t = body(film_slab(film, through, grid), 0.0)  # no film: R = 0, T = I
    >>> print(np.abs(r).max(), np.abs(t - np.eye(4)).max())
    0.0 0.0
    """
    return slab(film.generator, thickness)


def surface_on_body(surface: Layer, body_layer: Layer) -> Layer:
    """The surface (:func:`face_layer`) over the body (:func:`body` or :func:`thick_slab
    <lut_baker.numerics.adding_doubling.thick_slab>`): the surface's reflection from below is a
    mirror (diagonal) and the body's from above a slab's (symmetric by construction), so the
    adding equations solve their two systems as one (``add_layers(..., symmetric=True)``)."""
    return add_layers(surface, body_layer, symmetric=True)


def _body_layer(film: FilmSlab, thickness: float) -> Layer:
    r, t = body(film, thickness)
    return Layer(top=r, bottom=r, down=t)


def free_film_matrices(film: FilmSlab, thickness: float, face: ArrayLike | None = None
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The free film (surface, body, surface; air on both sides) at ``thickness``: its
    reflection without the top surface's gloss and its transmission, star form.  ``face``: the
    surfaces' ``a_g`` ``(C, N)`` (default: the measured film's)."""
    face = film.measured_face if face is None else np.asarray(face, float)
    return _free_film(_free_film_faces(face, film.orders), _body_layer(film, thickness))


def _free_film_faces(face: ArrayLike, orders: int) -> tuple[Layer, Layer]:
    """The free film's upper and lower surfaces (:func:`face_layer`; the lower one the upper
    turned over)."""
    upper = face_layer(face, orders)
    return upper, Layer(top=upper.bottom, bottom=upper.top, down=upper.down)


def _free_film(faces: tuple[Layer, Layer], body_layer: Layer
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(R, T)`` of the surfaces ``faces`` (:func:`_free_film_faces`) either side of
    ``body_layer``: :func:`free_film_matrices` of a body."""
    upper, lower = faces
    stack = add_layers(surface_on_body(upper, body_layer), lower)
    return stack.top, stack.down


_SKINS = LRUCache(MEASURED_CACHE_SIZE)


def skin_star(skin: ReflectionLayer, grid: HemisphereGrid) -> NDArray[np.float64]:
    """The skin's eq. 2 kernel in the star form, ``(C, orders, N, N)``, once per skin and grid."""
    key = (repr(skin.as_dict()), *_grid_key(grid))

    def compute() -> NDArray[np.float64]:
        kernel = layer_fourier_kernel(skin, grid.theta, grid.theta, grid.n_phi)
        star = to_star(_channels_first(kernel), star_scale(grid))
        star.setflags(write=False)
        return star

    return _SKINS.get_or_compute(key, compute)


def _skin_layer(skin_star: NDArray[np.float64]) -> Layer:
    zeros = np.zeros_like(skin_star)
    return Layer(top=skin_star, bottom=zeros, down=zeros)


def made_up_matrices(film: FilmSlab, thickness: float, skin: ReflectionLayer,
                     face: ArrayLike | None = None) -> NDArray[np.float64]:
    """Made-up skin without its top gloss (star form, ``(C, orders, N, N)``): the film's
    surface (``face``, default the measured film's) over its body at ``thickness`` over the
    skin's surface reflection (eq. 2, gloss and diffuse part), every inter-reflection summed
    (the adding equations).  Add the surface's gloss (eq. 2's specular term, closed form) for
    the whole BRDF."""
    face = film.measured_face if face is None else np.asarray(face, float)
    skin_matrix = skin_star(skin, film.grid)[:, :film.orders]
    stack = add_layers(surface_on_body(face_layer(face, film.orders),
                                        _body_layer(film, thickness)), _skin_layer(skin_matrix))
    return stack.top


def made_up_albedo(film: FilmSlab, thickness: float, skin: ReflectionLayer,
                   face: ArrayLike | None = None) -> NDArray[np.float64]:
    """Directional albedo of made-up skin at the grid's nodes, ``(C, N)``: the surface's gloss
    ``a_g`` plus :func:`made_up_matrices`' order 0.

    >>> from lut_baker.numerics.quadrature import hemisphere_panels
    >>> grid = hemisphere_panels(1, 4, 3)  # 4 polar nodes, azimuth orders 0 and 1
    >>> film = ReflectionLayer(P_d=0.155, P_s=10.7, n=0.033, eta=1.19)  # eq. 2, albedo units
    >>> through = TransmissionLayer(P_d=0.095, P_t=0.039, n=0.035, eta=1.19)  # eq. 4
    >>> slab_of = film_slab(film, through, grid)
    >>> skin = ReflectionLayer(P_d=0.1, P_s=0.0, n=0.05, eta=1.3)  # matte, albedo 0.31
    >>> for micrometres in (0.0, DEFAULT_THICKNESS_UM, 150.0, 1500.0):  # under uniform light
    ...     albedo = made_up_albedo(slab_of, relative_thickness(micrometres), skin)
    ...     print(np.round(bihemispherical_on_grid(albedo, grid), 4))
    [0.351]
    [0.3877]
    [0.6451]
    [0.7804]
    >>> print(np.round(bihemispherical_on_grid(thick_limit_albedo(slab_of), grid), 4))
    [0.7805]
    """
    face = film.measured_face if face is None else np.asarray(face, float)
    top = made_up_matrices(film, thickness, skin, face)
    return face + star_albedo(top[:, 0], film.scale[0])


def thick_limit_albedo(film: FilmSlab, face: ArrayLike | None = None) -> NDArray[np.float64]:
    """Directional albedo at the nodes ``(C, N)`` of the film at infinite thickness under its
    surface (``face``, default the measured film's): the gloss ``a_g`` plus
    ``F (I - R_inf rho)^-1 R_inf F``'s order 0."""
    face = film.measured_face if face is None else np.asarray(face, float)
    r_inf = thick_slab(film.generator)
    zeros = np.zeros_like(r_inf)
    stack = surface_on_body(face_layer(face, film.orders),
                             Layer(top=r_inf, bottom=r_inf, down=zeros))
    return face + star_albedo(stack.top[:, 0], film.scale[0])


def bihemispherical_on_grid(albedo: ArrayLike, grid: HemisphereGrid) -> NDArray[np.float64]:
    """``2 Int a(mu) mu dmu`` from a directional albedo at the grid's polar nodes (``(..., N)``):
    ``sum 2 w_j a_j`` (the weights are ``cos sin dtheta``).

    >>> from lut_baker.numerics.quadrature import hemisphere_panels
    >>> grid = hemisphere_panels(3, 10, 33)  # the bake's quadrature, 30 polar nodes
    >>> round(float(bihemispherical_on_grid(np.full(30, 0.3), grid)), 6)  # a constant albedo
    0.3
    """
    return np.asarray(albedo, float) @ (2.0 * grid.weight)


def thick_limit_colour(film: ReflectionLayer, transmission: TransmissionLayer,
                       grid: HemisphereGrid, absorption: ArrayLike, *,
                       face: ArrayLike | None = None,
                       optical_thickness: float = PAPER_FILM_OPTICAL_THICKNESS,
                       passive: bool = True) -> NDArray[np.float64]:
    """The bihemispherical albedo ``(C,)`` of the film of ``film`` and ``transmission`` at
    ``absorption`` (scalar or RGB), infinitely thick under its surface (``face``: ``a_g``
    ``(C, N)``, default the measured film's): :func:`thick_limit_albedo` of the body's order 0
    under uniform light."""
    slab_a = film_slab(film, transmission, grid, absorption=absorption,
                       optical_thickness=optical_thickness, passive=passive, orders=1)
    return bihemispherical_on_grid(thick_limit_albedo(slab_a, face), grid)


def solve_thick_absorption(target: ArrayLike, film: ReflectionLayer,
                           transmission: TransmissionLayer, grid: HemisphereGrid, *,
                           face: ArrayLike | None = None,
                           optical_thickness: float = PAPER_FILM_OPTICAL_THICKNESS,
                           passive: bool = True) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """``(A, clamped)`` per channel of ``target`` (a colour under uniform light, RGB): the
    absorption whose film, infinitely thick under its surface (``face``: ``a_g`` ``(C, N)``,
    default the measured film's), has that bihemispherical albedo, by a root on [0, 1]
    (order 0 only; the thick film darkens as ``A`` grows).  Out of reach: ``A = 0`` or 1 and
    ``clamped``.

    >>> from lut_baker.numerics.quadrature import hemisphere_panels
    >>> grid = hemisphere_panels(1, 4, 3)  # 4 polar nodes, azimuth orders 0 and 1
    >>> film = ReflectionLayer(P_d=0.155, P_s=10.7, n=0.033, eta=1.19)  # eq. 2, albedo units
    >>> through = TransmissionLayer(P_d=0.095, P_t=0.039, n=0.035, eta=1.19)  # eq. 4
    >>> a, clamped = solve_thick_absorption([0.6, 0.5, 0.4], film, through, grid)
    >>> print(np.round(a, 4), clamped)
    [0.1468 0.2698 0.4183] [False False False]
    >>> thick = film_slab(film, through, grid, absorption=a, orders=1)
    >>> print(np.round(bihemispherical_on_grid(thick_limit_albedo(thick), grid), 4))
    [0.6 0.5 0.4]
    """
    wanted = np.atleast_1d(np.asarray(target, float))

    def limit(a: NDArray[np.float64]) -> NDArray[np.float64]:
        return thick_limit_colour(film, transmission, grid, a, face=face,
                                  optical_thickness=optical_thickness, passive=passive)

    absorption = increasing_root(lambda a: -limit(a), -wanted, ROOT_STEPS)
    too_light = wanted > limit(np.zeros_like(wanted))
    too_dark = wanted < limit(np.ones_like(wanted))
    return absorption, too_light | too_dark
