"""Plane-parallel layers by adding and doubling, per azimuthal Fourier order (van de Hulst 1980,
"Multiple Light Scattering", ch. 4; Prahl 1995, "The adding-doubling method", in Welch & van
Gemert, "Optical-Thermal Response of Laser-Irradiated Tissue"; docs/model.md, "The film as a
slab").

A layer is described, per Fourier order ``m`` of the relative azimuth, by reflection and
transmission matrices between the polar nodes of a :class:`~lut_baker.numerics.quadrature.
HemisphereGrid`.  They are held in the *star form*: a kernel ``K_m(theta_a, theta_b)`` (1/sr,
the cosine coefficients of a BRDF-like kernel, :func:`~lut_baker.numerics.quadrature.
fourier_kernel`) times ``sqrt(c_m w_a) sqrt(c_m w_b)``, with ``w`` the grid's projected-solid-
angle weights and ``c_m`` the azimuth factor (2 pi at m = 0, pi otherwise).  Then chaining two
kernels over the hemisphere is a plain matrix product, the identity is light passing straight
through (a delta kernel), reciprocity makes every matrix of a layer symmetric (the transmission
upward is the transpose of the one downward), and the dimensionless matrices keep the
quadrature out of every formula.  Every direction is an upward-pointing one, as in path 3
(docs/model.md §3): straight transmission is the relative azimuth 0, a mirror reflection the
relative azimuth pi, whose coefficients are ``(-1)^m``.

Thickness.  A homogeneous symmetric slab obeys a transport equation with constant coefficients;
in the star form its half-slab responses over a mirror and over an "anti-mirror" satisfy two
Riccati equations whose closed-form solution (hyperbolic functions of one symmetric eigenproblem)
gives the slab at any thickness.  The same solution inverts the doubling relation: from the
slab at one thickness it yields the slab at half (and at any other) thickness, and doubling the
half slab gives the slab back to rounding.  :func:`slab_generator` computes it, :func:`slab`
evaluates it.

Functions and types
-------------------
- :func:`star_scale` -- ``sqrt(c_m w_j)`` per order and node.
- :func:`to_star`, :func:`from_star` -- kernels (1/sr) to the star form and back.
- :func:`star_albedo` -- the directional albedo (or transmittance) of an order-0 star matrix.
- :func:`mirror` -- a specular reflector of given albedo per node, all orders.
- :class:`Layer` -- reflection from above and below, transmission downward.
- :func:`add_layers` -- the adding equations (one layer over another).
- :func:`double_slab` -- a symmetric slab on itself (doubling).
- :class:`SlabGenerator`, :func:`slab_generator` -- a homogeneous symmetric slab from its
  matrices at one thickness (the inverted doubling relation).
- :func:`generator_matrices`, :func:`generator_from_matrices` -- its transport matrices P, Q.
- :func:`absorption_per_direction` -- the energy the slab's transport equation removes per unit
  thickness from light along each node (order 0).
- :func:`passive_generator` -- the generator with no negative absorption;
  :func:`passive_family` -- for several reliefs, sharing the work.
- :func:`slab` -- the slab at any thickness; :func:`thick_slab` -- at infinite thickness.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .quadrature import HemisphereGrid, azimuth_convolution_factor

__all__ = [
    "star_scale",
    "to_star",
    "from_star",
    "star_albedo",
    "mirror",
    "Layer",
    "add_layers",
    "double_slab",
    "SlabGenerator",
    "slab_generator",
    "generator_matrices",
    "generator_from_matrices",
    "absorption_per_direction",
    "passive_generator",
    "passive_family",
    "slab",
    "thick_slab",
]


def star_scale(grid: HemisphereGrid) -> NDArray[np.float64]:
    """``sqrt(c_m w_j)``: shape ``(orders, N)``, with ``w`` the grid's polar weights
    (``cos theta sin theta d theta``, sr) and ``c_m`` the azimuth factor (2 pi, then pi)."""
    factor = azimuth_convolution_factor(grid.orders)
    return np.sqrt(factor[:, None] * grid.weight[None, :])


def to_star(kernel: NDArray[np.float64], scale: NDArray[np.float64]) -> NDArray[np.float64]:
    """Kernel coefficients ``(..., orders, N, N)`` (1/sr) into the star form (dimensionless):
    ``s_m,a K_m,ab s_m,b``; ``scale`` from :func:`star_scale` (its orders may be fewer)."""
    orders = kernel.shape[-3]
    s = scale[:orders]
    return s[:, :, None] * kernel * s[:, None, :]


def from_star(star: NDArray[np.float64], scale: NDArray[np.float64]) -> NDArray[np.float64]:
    """The inverse of :func:`to_star`: kernel coefficients in 1/sr."""
    orders = star.shape[-3]
    s = scale[:orders]
    return star / (s[:, :, None] * s[:, None, :])


def star_albedo(star0: NDArray[np.float64], scale0: NDArray[np.float64]) -> NDArray[np.float64]:
    """The directional albedo (dimensionless) of an order-0 star matrix ``(..., N, N)`` at each
    incident node: ``2 pi sum_b K_0,ab w_b`` (the light leaving into the whole hemisphere).

    >>> from lut_baker.numerics.quadrature import hemisphere_panels
    >>> grid = hemisphere_panels(1, 4, 3)  # 4 polar nodes, azimuth orders 0 and 1
    >>> scale = star_scale(grid)
    >>> lambert = np.zeros((2, 4, 4))
    >>> lambert[0] = 0.3 / np.pi  # a Lambertian reflector of albedo 0.3 (1/sr, order 0 only)
    >>> print(np.round(star_albedo(to_star(lambert, scale)[0], scale[0]), 4))
    [0.3 0.3 0.3 0.3]
    """
    return (star0 @ scale0) / scale0


def mirror(albedo: ArrayLike, orders: int) -> NDArray[np.float64]:
    """A specular reflector of albedo ``albedo`` ``(..., N)`` at each node: ``(-1)^m diag(a)``,
    shape ``(..., orders, N, N)`` (the mirror direction is the relative azimuth pi).

    >>> print(np.diagonal(mirror([0.04, 0.5], 2), axis1=-2, axis2=-1))  # orders 0 and 1
    [[ 0.04  0.5 ]
     [-0.04 -0.5 ]]
    """
    albedo = np.asarray(albedo, float)
    signs = (-1.0) ** np.arange(orders)
    eye = np.eye(albedo.shape[-1])
    return signs[:, None, None] * (albedo[..., None, None, :] * eye)


class Layer(NamedTuple):
    """One layer in the star form, each ``(..., orders, N, N)``: ``top`` its reflection of light
    from above, ``bottom`` of light from below, ``down`` its transmission downward (upward it
    is the transpose, by reciprocity)."""

    top: NDArray[np.float64]
    bottom: NDArray[np.float64]
    down: NDArray[np.float64]


def _t(a: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.swapaxes(a, -1, -2)


def add_layers(upper: Layer, lower: Layer, *, symmetric: bool = False) -> Layer:
    """``upper`` lying on ``lower``: the adding equations (van de Hulst 1980, eq. 4.15; Prahl
    1995, eqs. 26-29), every inter-reflection between the two summed::

        R_top    = R1 + T1 (I - R2 R1')^-1 R2 T1^T
        T_down   = T1 (I - R2 R1')^-1 T2
        R_bottom = R2' + T2^T (I - R1' R2)^-1 R1' T2

    with ``R1 = upper.top``, ``R1' = upper.bottom``, ``R2 = lower.top``, ``R2' =
    lower.bottom``, ``T1``, ``T2`` their transmissions downward (row vectors: light enters on
    the left).  ``symmetric=True`` is the caller's guarantee that ``R1'`` and ``R2`` are
    symmetric (exactly, as a slab's reflections and a mirror are): then ``(I - R2 R1')^T =
    I - R1' R2`` and the two systems are solved as one, with both right-hand sides.

    >>> generator = slab_generator(np.array([[0.2]]), np.array([[0.7]]))  # one node
    >>> r, t = slab(generator, 0.5)
    >>> half = Layer(top=r, bottom=r, down=t)  # half the slab on the other half: the slab
    >>> whole = add_layers(half, half, symmetric=True)
    >>> print(np.round(whole.top, 6), np.round(whole.down, 6))
    [[0.2]] [[0.7]]
    """
    eye = np.eye(upper.top.shape[-1])
    reflected = upper.bottom @ lower.down  # R1' T2
    if symmetric:
        # One factorisation of I - R1' R2 for (I - R2 R1')^-1 from the right (the transposed
        # system) and (I - R1' R2)^-1 R1' T2.
        matrix = eye - upper.bottom @ lower.top
        first = _t(upper.down)
        lead = np.broadcast_shapes(matrix.shape[:-2], first.shape[:-2], reflected.shape[:-2])
        both = np.linalg.solve(matrix, np.concatenate(
            [np.broadcast_to(first, lead + first.shape[-2:]),
             np.broadcast_to(reflected, lead + reflected.shape[-2:])], axis=-1))
        inner = np.ascontiguousarray(both[..., :first.shape[-1]])
        back = np.ascontiguousarray(both[..., first.shape[-1]:])
    else:
        # (I - R2 R1')^-1 applied from the right, as a solve of the transposed system.
        inner = np.linalg.solve(_t(eye - lower.top @ upper.bottom), _t(upper.down))
        back = np.linalg.solve(eye - upper.bottom @ lower.top, reflected)
    through = _t(inner)  # T1 (I - R2 R1')^-1
    top = upper.top + through @ lower.top @ _t(upper.down)
    down = through @ lower.down
    bottom = lower.bottom + _t(lower.down) @ back
    return Layer(top=top, bottom=bottom, down=down)


def double_slab(reflection: NDArray[np.float64], transmission: NDArray[np.float64]
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A symmetric slab ``(R, T)`` on itself (the doubling step, van de Hulst 1980, eq. 4.17;
    Prahl 1995, eq. 30): ``R2 = R + T (I - R R)^-1 R T``, ``T2 = T (I - R R)^-1 T``.

    >>> r2, t2 = double_slab(np.array([[0.2]]), np.array([[0.7]]))  # one node
    >>> print(np.round(r2, 6), np.round(t2, 6))  # 0.2 + 0.7 0.2 0.7 / 0.96, 0.49 / 0.96
    [[0.302083]] [[0.510417]]
    """
    eye = np.eye(reflection.shape[-1])
    through = _t(np.linalg.solve(eye - reflection @ reflection, transmission))
    return reflection + through @ reflection @ transmission, through @ transmission


@dataclass(frozen=True, eq=False)
class SlabGenerator:
    """A homogeneous symmetric slab at every thickness, per order (and any leading axes):
    ``basis`` ``B`` ``(..., N, N)`` and ``rates`` ``lambda`` ``(..., N)`` (per unit of the
    reference thickness) with, at thickness ``x`` (in those units),
    ``Y(x) = B tanh(lambda x) B^T`` and ``Z(x) = B^-T tanh(lambda x) B^-1``; see :func:`slab`."""

    basis: NDArray[np.float64]
    rates: NDArray[np.float64]

    @cached_property
    def inverse(self) -> NDArray[np.float64]:
        """``B^-1`` (computed once)."""
        return np.linalg.inv(self.basis)


def _symmetric(a: NDArray[np.float64]) -> NDArray[np.float64]:
    return 0.5 * (a + _t(a))


def _cayley(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(I - a)(I + a)^-1`` of a symmetric matrix (symmetric itself: the factors commute)."""
    eye = np.eye(a.shape[-1])
    return _symmetric(np.linalg.solve(eye + a, eye - a))


def _sqrt_and_inverse(a: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``a^(1/2)`` and ``a^(-1/2)`` of symmetric positive definite matrices."""
    values, vectors = np.linalg.eigh(a)
    if np.any(values <= 0.0):
        raise ValueError("the slab's half-responses are not those of a slab: a matrix that "
                         "must be positive definite is not (is R + T or R - T outside (-1, 1)?)")
    root = np.sqrt(values)[..., None, :]
    return (vectors * root) @ _t(vectors), (vectors / root) @ _t(vectors)


def slab_generator(reflection: NDArray[np.float64], transmission: NDArray[np.float64], *,
                   max_rate: float = np.inf) -> SlabGenerator:
    """The homogeneous symmetric slab whose matrices at unit thickness are ``(R, T)`` (star form,
    symmetric, ``(..., N, N)``): the doubling relation inverted, for every thickness at once.

    With ``S = R + T`` and ``D = R - T`` (the half slab over a mirror, and over an anti-mirror,
    at thickness 1/2), ``Z = (I - S)(I + S)^-1`` and ``Y = (I + D)(I - D)^-1`` solve
    ``dZ/dx = Q - Z P Z`` and ``dY/dx = P - Y Q Y`` (the Riccati equations of the half slab,
    van de Hulst 1980, ch. 4), so ``Y Z = tanh^2(sqrt(P Q))`` at unit thickness: one symmetric
    eigenproblem, ``Y^(1/2) Z Y^(1/2) = U theta U^T``, gives ``lambda = artanh(sqrt(theta))``
    and ``B = Y^(1/2) U tanh(lambda)^(-1/2)``.  A mode the slab extinguishes completely
    (``theta`` at or beyond 1 within rounding, or measured slightly negative) is given the rate
    ``max_rate``: ``rates`` never exceed it (for light straight through an absorbing slab of
    optical thickness ``tau``, ``max_rate = tau / 2``, the transmission ``exp(-2 lambda x)``);
    a capped mode keeps ``Y`` and ``Z`` in proportion, so it stays pure loss where ``Y = Z``.

    >>> generator = slab_generator(np.array([[0.2]]), np.array([[0.7]]))  # one node
    >>> r, t = slab(generator, 1.0)  # the reference thickness: the slab given back
    >>> print(np.round(r, 6), np.round(t, 6))
    [[0.2]] [[0.7]]
    """
    eye = np.eye(reflection.shape[-1])
    even = _symmetric(reflection + transmission)
    odd = _symmetric(reflection - transmission)
    z = _cayley(even)
    y = _symmetric(np.linalg.solve(eye - odd, eye + odd))
    y_half, _ = _sqrt_and_inverse(y)
    measured, vectors = np.linalg.eigh(_symmetric(y_half @ z @ y_half))
    ceiling = np.tanh(min(float(max_rate), 18.0)) ** 2  # tanh(18)^2 = 1 - 1e-15
    theta = np.clip(measured, np.finfo(float).tiny, ceiling)
    root = np.sqrt(theta)
    rates = np.arctanh(root)
    # A mode capped at the ceiling keeps Y and Z in proportion (each scaled by root over the
    # measured root): one extinguished alike over a mirror and an anti-mirror (Y = Z) stays pure
    # loss (P = Q, no back-scattering).  Normalised by the capped root, Y would stay as measured
    # and Z alone shrink, which puts back-scattering ``lambda (1/root - root) / 2`` on the
    # identity of the capped modes: a retro-reflected delta.
    basis = (y_half @ vectors) / np.sqrt(np.sqrt(np.maximum(measured, theta)))[..., None, :]
    return SlabGenerator(basis=basis, rates=rates)


def generator_matrices(generator: SlabGenerator) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(P, Q)``: the transport matrices per unit thickness, ``P = B lambda B^T``,
    ``Q = B^-T lambda B^-1`` (``P = alpha + beta``, ``Q = alpha - beta`` with ``alpha`` the
    loss along a direction and ``beta`` the scattering back; symmetric)."""
    b = generator.basis
    b_inv = generator.inverse
    lam = generator.rates
    return (_symmetric((b * lam[..., None, :]) @ _t(b)),
            _symmetric(_t(b_inv) @ (lam[..., :, None] * b_inv)))


def generator_from_matrices(p: NDArray[np.float64], q: NDArray[np.float64]) -> SlabGenerator:
    """The slab of transport matrices ``(P, Q)``: ``P^(1/2) Q P^(1/2) = U lambda^2 U^T``,
    ``B = P^(1/2) U lambda^(-1/2)`` (so that ``Y(x) = P f(Q P)``, ``f(z) = tanh(x sqrt z) /
    sqrt z``)."""
    p_half, _ = _sqrt_and_inverse(_symmetric(p))
    lam2, vectors = np.linalg.eigh(_symmetric(p_half @ q @ p_half))
    rates = np.sqrt(np.maximum(lam2, np.finfo(float).tiny))
    return SlabGenerator(basis=(p_half @ vectors) / np.sqrt(rates)[..., None, :], rates=rates)


def absorption_per_direction(generator: SlabGenerator, scale0: NDArray[np.float64]
                             ) -> NDArray[np.float64]:
    """Energy removed per unit thickness from light along each node, order 0: ``(Q s) / s``
    with ``s`` the order-0 :func:`star_scale` (the net flux through the slab falls by
    ``s^T Q (d + u)`` per unit thickness, ``d``, ``u`` the down- and upgoing radiance in the
    star form).  Negative where the transport equation would create light.  ``generator``
    holds order 0 (``(..., N, N)``)."""
    _, q = generator_matrices(generator)
    return (q @ scale0) / scale0


def passive_generator(generator: SlabGenerator, scale0: NDArray[np.float64], relief: ArrayLike = 0.0
                      ) -> SlabGenerator:
    """The slab made passive: with ``a`` the absorption per direction
    (:func:`absorption_per_direction`, order 0), ``d = max(0, -a) - relief max(0, a)`` is added
    as pure absorption, ``alpha += diag(d)``, to every order (absorption does not depend on
    azimuth), so the absorption becomes ``(1 - relief) max(0, a) >= 0``.  ``relief`` in [0, 1]
    (per leading index, e.g. per channel) lets the directions that absorb give up part of it
    for those that would create light.  ``generator``'s arrays are ``(..., orders, N, N)``
    with order 0 first; a slab with no negative absorption is returned as it is, and so is
    every leading index without any (whatever its ``relief``: a slab that only absorbs, such as
    a pure absorber, has nothing to give up for).  :func:`passive_family` for several
    ``relief``."""
    return passive_family(generator, scale0)(relief)


def passive_family(generator: SlabGenerator, scale0: NDArray[np.float64]
                   ) -> Callable[[ArrayLike], SlabGenerator]:
    """``relief -> passive_generator(generator, scale0, relief)``, the work that does not
    depend on ``relief`` (the absorption per direction, the transport matrices) done once."""
    order0 = SlabGenerator(basis=generator.basis[..., 0, :, :], rates=generator.rates[..., 0, :])
    absorption = absorption_per_direction(order0, scale0)  # (..., N)
    creates = np.any(absorption < 0.0, axis=-1)  # (...,)
    if not np.any(creates):
        return lambda relief: generator
    p, q = generator_matrices(generator)
    eye = np.eye(absorption.shape[-1])

    def at(relief: ArrayLike) -> SlabGenerator:
        share = np.where(creates, np.asarray(relief, float), 0.0)[..., None]
        change = np.maximum(0.0, -absorption) - share * np.maximum(0.0, absorption)
        extra = change[..., None, :, None] * eye  # (..., 1, N, N)
        made = generator_from_matrices(p + extra, q + extra)
        if np.all(creates):
            return made
        return SlabGenerator(basis=np.where(creates[..., None, None, None], made.basis,
                                            generator.basis),
                             rates=np.where(creates[..., None, None], made.rates,
                                            generator.rates))

    return at


def slab(generator: SlabGenerator, thickness: float
         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(R, T)`` of the slab at ``thickness`` (in units of the reference thickness, >= 0):
    ``S = (I - Z)(I + Z)^-1``, ``D = (Y - I)(Y + I)^-1``, ``R = (S + D)/2``, ``T = (S - D)/2``.
    Thickness 0 gives ``R = 0``, ``T = I`` exactly.

    >>> generator = slab_generator(np.array([[0.2, 0.1], [0.1, 0.3]]),  # two nodes
    ...                            np.array([[0.5, 0.1], [0.1, 0.4]]))
    >>> r, t = slab(generator, 0.0)  # no slab: nothing reflected, everything straight through
    >>> print(r, t)
    [[0. 0.]
     [0. 0.]] [[1. 0.]
     [0. 1.]]
    >>> r2, t2 = double_slab(*slab(generator, 0.5))  # the half slab doubled: the slab
    >>> print(np.round(r2, 6), np.round(t2, 6))
    [[0.2 0.1]
     [0.1 0.3]] [[0.5 0.1]
     [0.1 0.4]]
    """
    if not thickness >= 0.0:
        raise ValueError(f"thickness must be >= 0, got {thickness!r}")
    b = generator.basis
    b_inv = generator.inverse
    th = np.tanh(generator.rates * float(thickness))
    y = _symmetric((b * th[..., None, :]) @ _t(b))
    z = _symmetric(_t(b_inv) @ (th[..., :, None] * b_inv))
    even = _cayley(z)
    odd = -_cayley(y)
    return 0.5 * (even + odd), 0.5 * (even - odd)


def thick_slab(generator: SlabGenerator) -> NDArray[np.float64]:
    """The reflection of the slab at infinite thickness: ``(B B^T - I)(B B^T + I)^-1`` (its
    transmission is 0).

    >>> generator = slab_generator(np.array([[0.2]]), np.array([[0.7]]))  # one node
    >>> print(np.round(thick_slab(generator), 6))  # Kubelka-Munk: a - sqrt(a^2 - 1) ...
    [[0.431271]]
    >>> a = (1 + 0.2**2 - 0.7**2) / (2 * 0.2)  # ... with a = (1 + R^2 - T^2) / (2 R)
    >>> round(a - (a * a - 1) ** 0.5, 6)
    0.431271
    """
    b = generator.basis
    return -_cayley(_symmetric(b @ _t(b)))
