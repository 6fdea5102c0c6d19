"""Numpy replicas of the Cycles closures the add-on fits to the tables (Blender 4.2 - 5.0).

The replicas follow Cycles' kernel (``intern/cycles/kernel/closure/bsdf_microfacet.h``,
``bssrdf.h``, ``svm/closure.h``); each function names what it copies.  Directions are unit
vectors ``(..., 3)`` in the local frame (normal +z); ``wi`` points to the light, ``wo`` to the
viewer, as in the rest of ``lut_baker``.  BRDF values are without the cosine, in 1/sr.  Radii
are in millimetres: the caller converts them to scene units.

Functions
---------
- :func:`ggx_distribution`, :func:`beckmann_distribution` -- normal distributions ``D(h)``
  (``alpha = roughness^2``, as Blender maps its Roughness socket).
- :func:`ggx_lambda`, :func:`beckmann_lambda` -- their Smith ``Lambda`` (Beckmann: Cycles'
  rational approximation).
- :func:`ashikhmin_shirley_reflection` -- Cycles' Ashikhmin-Shirley Glossy lobe.
- :func:`microfacet_shadowing` -- height-correlated ``G2 = 1 / (1 + Lambda_i + Lambda_o)``.
- :func:`microfacet_reflection` -- microfacet BRDF ``D G2 F / (4 cos_i cos_o)`` with a Fresnel
  callable (Glossy BSDF: none; coat: dielectric; Principled specular: generalised Schlick);
  :class:`DirectionPairs`, :func:`pair_reflection` -- the same for lobes sharing their pairs;
  :func:`microfacet_from_cosines` -- the Fresnel-free lobe from the four cosines it needs
  (:class:`LobeCosines`, :func:`lobe_from_cosines`: what depends on them alone made once).
- :func:`dielectric_fresnel`, :func:`schlick_ior_fresnel` -- the Fresnel terms Cycles uses.
- :func:`directional_albedo` -- ``Int f cos(theta_i) dwi`` of any BRDF at view angles.
- :func:`microfacet_albedo` -- the same for a microfacet lobe, by quadrature over normals (views
  in chunks of :data:`ALBEDO_CHUNK` nodes); :func:`microfacet_albedos` -- without and with a
  Fresnel term from one pass.
- :func:`layering_albedo` -- Cycles' albedo estimate that attenuates the layers below a coat or
  a specular layer (``bsdf_microfacet_estimate_albedo``).
- :func:`dielectric_fss`, :func:`ggx_energy_compensation` (:func:`ggx_energy_scale` from
  precomputed albedos, :func:`ggx_average_albedo`), :func:`coat_view_terms` -- the
  multiple-scattering compensation Cycles gives the Principled coat.
- :func:`lambert_reflection` -- ``albedo / pi``.
- :func:`view_table` -- a smooth function of the view cosine, tabulated and interpolated.
- :func:`principled_reflection` -- the Principled BSDF's coat, specular and diffuse layers
  (``svm_node_closure_bsdf``), for the inputs in :class:`PrincipledInputs`;
  :func:`principled_uniform` -- its colour under uniform light, split into gloss and base.
- :func:`burley_profile` -- Christensen-Burley radial profile as Cycles scales it.
- :func:`random_walk_scale` -- the measured radius factor that makes a Burley profile match a
  random walk's (Cycles' random walk is a Monte Carlo simulation with no closed form).
- :func:`subsurface_profile` -- the profile of any of Blender's three methods.

References
----------
Walter et al. 2007 (GGX); Heitz 2014 (height-correlated Smith); Christensen, Burley 2015
("Approximate Reflectance Profiles for Efficient Subsurface Scattering"); Chiang, Kutz, Burley
2016 (random walk).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.microfacet import fresnel_reflectance
from ..numerics import Real
from ..numerics.geometry import direction, half_vector
from ..numerics.quadrature import gauss_legendre, hemisphere_grid, midpoint_nodes

__all__ = [
    "DISTRIBUTIONS",
    "ggx_distribution",
    "beckmann_distribution",
    "ggx_lambda",
    "beckmann_lambda",
    "GLOSSY_DISTRIBUTIONS",
    "ashikhmin_shirley_exponent",
    "ashikhmin_shirley_reflection",
    "microfacet_shadowing",
    "microfacet_reflection",
    "DirectionPairs",
    "pair_reflection",
    "microfacet_from_cosines",
    "LobeCosines",
    "lobe_from_cosines",
    "principled_uniform",
    "dielectric_fss",
    "ggx_energy_compensation",
    "ggx_energy_scale",
    "ggx_average_albedo",
    "coat_view_terms",
    "dielectric_fresnel",
    "schlick_ior_fresnel",
    "directional_albedo",
    "microfacet_albedo",
    "microfacet_albedos",
    "ALBEDO_CHUNK",
    "layering_albedo",
    "lambert_reflection",
    "view_table",
    "PrincipledInputs",
    "principled_reflection",
    "burley_profile",
    "BURLEY_MFP_SCALE",
    "RANDOM_WALK_BURLEY_SCALE",
    "random_walk_scale",
    "subsurface_profile",
    "SUBSURFACE_METHODS",
]

BURLEY_MFP_SCALE = 0.25 / np.pi
"""Cycles multiplies Subsurface Radius x Scale by ``1/(4 pi)`` before using it as the Burley
shape length ``d`` and as the Random Walk mean free path (``bssrdf_setup_radius``)."""
BURLEY_TRUNCATE = 16.0
"""Cycles cuts the Burley profile at ``16 d``."""
SUBSURFACE_METHODS = ("BURLEY", "RANDOM_WALK", "RANDOM_WALK_SKIN")
"""Blender's ``subsurface_method`` identifiers."""
ROUGHNESS_EPS = 1e-3
"""Roughness below this is a mirror Cycles cannot evaluate; the replicas clamp to it."""

OfCosine = Callable[[NDArray[np.float64]], ArrayLike]
"""A factor of a cosine array (a Fresnel term of ``h.wi``, a function of the view cosine)."""


# --------------------------------------------------------------------------------------------
# GGX microfacet model (bsdf_microfacet.h)
# --------------------------------------------------------------------------------------------
def ggx_distribution(cos_h: ArrayLike, alpha: Real) -> NDArray[np.float64]:
    """GGX ``D = alpha^2 / (pi ((1 - c^2) + alpha^2 c^2)^2)`` at ``c = N.H`` (Walter 2007)."""
    c2 = np.minimum(np.square(np.asarray(cos_h, float)), 1.0)
    return _ggx_d(c2, 1.0 - c2, np.square(alpha))


def _ggx_d(c2: Any, one_minus: Any, a2: Any) -> NDArray[np.float64]:
    """:func:`ggx_distribution` from ``c^2``, ``1 - c^2`` and ``alpha^2``."""
    return a2 / (np.pi * np.square(one_minus + a2 * c2))


def beckmann_distribution(cos_h: ArrayLike, alpha: Real) -> NDArray[np.float64]:
    """Beckmann ``D = exp(-tan^2 / alpha^2) / (pi alpha^2 c^4)`` at ``c = N.H``."""
    c2 = np.clip(np.square(np.asarray(cos_h, float)), 1e-300, 1.0)
    return _beckmann_d(c2, 1.0 - c2, np.square(alpha))


def _beckmann_d(c2: Any, one_minus: Any, a2: Any) -> NDArray[np.float64]:
    """:func:`beckmann_distribution` from ``c^2``, ``1 - c^2`` and ``alpha^2``."""
    with np.errstate(over="ignore"):
        return np.exp(-one_minus / (c2 * a2)) / (np.pi * a2 * c2 * c2)


def _in_place(values: object) -> bool:
    """Whether ``values`` is an array the caller owns, to be worked on in place (the same
    operations in the same order as on fresh arrays: the same numbers, without a temporary
    array per step on the quadratures' large grids)."""
    return isinstance(values, np.ndarray) and values.ndim > 0


def _tan2(cos_theta: ArrayLike) -> NDArray[np.float64]:
    """``tan^2(theta)`` at ``cos(theta)`` (0 for a cosine of 1 or more)."""
    t2 = np.square(np.asarray(cos_theta, float))
    if not _in_place(t2):
        return np.maximum(1.0 / np.maximum(t2, 1e-300) - 1.0, 0.0)
    np.maximum(t2, 1e-300, out=t2)
    np.divide(1.0, t2, out=t2)
    t2 -= 1.0
    np.maximum(t2, 0.0, out=t2)
    return t2


def _alpha_tan2(cos_theta: ArrayLike, alpha: Real) -> NDArray[np.float64]:
    """``alpha^2 tan^2(theta)`` at ``cos(theta)`` (0 for a cosine of 1 or more)."""
    t2 = _tan2(cos_theta)
    if not _in_place(t2):
        return np.square(alpha) * t2
    t2 *= np.square(alpha)
    return t2


def ggx_lambda(cos_theta: ArrayLike, alpha: Real) -> NDArray[np.float64]:
    """Smith ``Lambda = (sqrt(1 + alpha^2 tan^2) - 1) / 2`` of GGX (Heitz 2014, eq. 72)."""
    return _ggx_lambda_of(_alpha_tan2(cos_theta, alpha))


def _ggx_lambda_of(value: Any) -> NDArray[np.float64]:
    """:func:`ggx_lambda` from ``alpha^2 tan^2`` (an array is worked on in place)."""
    if not _in_place(value):
        return 0.5 * (np.sqrt(1.0 + value) - 1.0)
    value += 1.0
    np.sqrt(value, out=value)
    value -= 1.0
    value *= 0.5
    return value


def beckmann_lambda(cos_theta: ArrayLike, alpha: Real) -> NDArray[np.float64]:
    """Smith ``Lambda`` of Beckmann, the rational approximation Cycles uses (0 where
    ``alpha^2 tan^2 < 0.39``)."""
    return _beckmann_lambda_of(_alpha_tan2(cos_theta, alpha))


def _beckmann_lambda_of(t2: Any) -> NDArray[np.float64]:
    """:func:`beckmann_lambda` from ``alpha^2 tan^2``."""
    a = 1.0 / np.sqrt(np.maximum(t2, 1e-300))
    value = ((0.396 * a - 1.259) * a + 1.0) / ((2.181 * a + 3.535) * a)
    return np.where(t2 < 0.39, 0.0, value)


DISTRIBUTIONS = {"GGX": (ggx_distribution, ggx_lambda),
                 "BECKMANN": (beckmann_distribution, beckmann_lambda)}
"""Blender's microfacet distributions replicated: ``(D, Lambda)`` by identifier."""
_LAMBDA_OF_TAN2 = {"GGX": _ggx_lambda_of, "BECKMANN": _beckmann_lambda_of}
GLOSSY_DISTRIBUTIONS = ("GGX", "BECKMANN", "ASHIKHMIN_SHIRLEY")
"""The Glossy BSDF's distributions the replicas cover (Multiscatter GGX is left out)."""


def ashikhmin_shirley_exponent(roughness: Real) -> NDArray[np.float64]:
    """Phong exponent ``2 / alpha^2 - 2`` of Cycles' Ashikhmin-Shirley lobe, ``alpha =
    roughness^2`` clamped to [1e-4, 1] (``bsdf_ashikhmin_shirley_roughness_to_exponent``)."""
    alpha = np.clip(np.square(roughness), 1e-4, 1.0)
    return 2.0 / (alpha * alpha) - 2.0


def ashikhmin_shirley_reflection(wi: ArrayLike, wo: ArrayLike,
                                 roughness: float) -> NDArray[np.float64]:
    """Isotropic Ashikhmin-Shirley lobe without Fresnel (Cycles ``bsdf_ashikhmin_shirley_eval``)
    at unit vectors: :func:`microfacet_from_cosines` with ``ASHIKHMIN_SHIRLEY``."""
    return microfacet_reflection(wi, wo, roughness, distribution="ASHIKHMIN_SHIRLEY")


class LobeCosines:
    """What :func:`microfacet_from_cosines` computes of its cosines alone, whatever the
    roughness: made once where many lobes are evaluated on the same pairs (a fit's view grid,
    :meth:`lut_baker.closures.view_grid.ViewGrid.lobe`), each part when first needed.
    ``cos_h`` (``n.h``), ``cos_hi`` (``h.wi``), ``cos_i``, ``cos_o``, broadcasting."""

    def __init__(self, cos_h: NDArray[np.float64], cos_hi: NDArray[np.float64],
                 cos_i: ArrayLike, cos_o: ArrayLike) -> None:
        self.cos_h, self.cos_hi = cos_h, cos_hi
        self.cos_i, self.cos_o = np.asarray(cos_i, float), np.asarray(cos_o, float)
        self.upper = (self.cos_i > 0.0) & (self.cos_o > 0.0)

    @cached_property
    def safe_i(self) -> NDArray[np.float64]:
        """``cos_i``, 1 where a direction is below the surface (each cosine kept at its own
        shape: a view's Lambda once per view, not per pair; where the other one is below the
        surface the value is dropped anyway)."""
        cos_i, cos_o = self.cos_i, self.cos_o
        return (np.where(self.upper, cos_i, 1.0) if cos_i.size >= cos_o.size
                else np.where(cos_i > 0.0, cos_i, 1.0))

    @cached_property
    def safe_o(self) -> NDArray[np.float64]:
        """``cos_o``, 1 where it is below the surface (as :attr:`safe_i`)."""
        cos_i, cos_o = self.cos_i, self.cos_o
        return (np.where(self.upper, cos_o, 1.0) if cos_o.size > cos_i.size
                else np.where(cos_o > 0.0, cos_o, 1.0))

    @cached_property
    def tan2(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``tan^2`` of :attr:`safe_i` and :attr:`safe_o`."""
        return _tan2(self.safe_i), _tan2(self.safe_o)

    @cached_property
    def denominator(self) -> NDArray[np.float64]:
        """``4 cos_i cos_o`` (safe)."""
        return 4.0 * self.safe_i * self.safe_o

    @cached_property
    def ggx_c2(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(c^2, 1 - c^2)`` of ``n.h`` as :func:`ggx_distribution` clamps it."""
        c2 = np.minimum(np.square(np.asarray(self.cos_h, float)), 1.0)
        return c2, 1.0 - c2

    @cached_property
    def beckmann_c2(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(c^2, 1 - c^2)`` of ``n.h`` as :func:`beckmann_distribution` clamps it."""
        c2 = np.clip(np.square(np.asarray(self.cos_h, float)), 1e-300, 1.0)
        return c2, 1.0 - c2


def microfacet_from_cosines(cos_h: NDArray[np.float64], cos_hi: NDArray[np.float64],
                            cos_i: ArrayLike, cos_o: ArrayLike, roughness: float,
                            distribution: str = "GGX") -> NDArray[np.float64]:
    """A Glossy lobe without Fresnel (no cosine, 1/sr) from the cosines ``n.h``, ``h.wi``,
    ``n.wi``, ``n.wo`` (broadcasting; ``roughness`` Blender's socket, clamped to
    :data:`ROUGHNESS_EPS`); 0 where either direction is below the surface.

    - ``GGX``, ``BECKMANN``: ``D G2 / (4 cos_i cos_o)`` (Cycles ``bsdf_microfacet_eval``);
    - ``ASHIKHMIN_SHIRLEY``: ``(e + 1) / (8 pi) (n.h)^e / ((h.wi) max(cos_i, cos_o))``
      (``bsdf_ashikhmin_shirley_eval``).
    """
    return lobe_from_cosines(LobeCosines(cos_h, cos_hi, cos_i, cos_o), roughness,
                             distribution)


def lobe_from_cosines(cosines: LobeCosines, roughness: float,
                      distribution: str = "GGX") -> NDArray[np.float64]:
    """:func:`microfacet_from_cosines` from its cosines' :class:`LobeCosines` (the same
    numbers; what depends on the cosines alone computed once for many lobes)."""
    cos_i, cos_o, upper = cosines.cos_i, cosines.cos_o, cosines.upper
    if distribution == "ASHIKHMIN_SHIRLEY":
        e = ashikhmin_shirley_exponent(roughness)
        h_dot_i = np.maximum(np.abs(cosines.cos_hi), 1e-6)
        h_dot_n = np.maximum(cosines.cos_h, 1e-6)
        pump = 1.0 / np.maximum(1e-6, h_dot_i * np.maximum(np.maximum(cos_i, cos_o), 1e-6))
        return np.where(upper, (e + 1.0) / (8.0 * np.pi) * h_dot_n**e * pump, 0.0)
    if distribution not in DISTRIBUTIONS:
        raise ValueError(f"distribution must be one of {GLOSSY_DISTRIBUTIONS}, got "
                         f"{distribution!r}")
    alpha = np.square(max(float(roughness), ROUGHNESS_EPS))
    a2 = np.square(alpha)
    if distribution == "GGX":
        d = _ggx_d(*cosines.ggx_c2, a2)
    else:
        d = _beckmann_d(*cosines.beckmann_c2, a2)
    lambda_of = _LAMBDA_OF_TAN2[distribution]
    tan2_i, tan2_o = cosines.tan2
    shadowing = _shadowing_of(lambda_of(tan2_i * a2), lambda_of(tan2_o * a2))
    value = d * shadowing / cosines.denominator
    return np.where(upper, value, 0.0)


def microfacet_shadowing(cos_i: ArrayLike, cos_o: ArrayLike, alpha: Real,
                         distribution: str = "GGX") -> NDArray[np.float64]:
    """Height-correlated masking-shadowing ``G2 = 1 / (1 + Lambda_i + Lambda_o)``
    (Cycles ``bsdf_G``)."""
    lam = DISTRIBUTIONS[distribution][1]
    return _shadowing_of(lam(cos_i, alpha), lam(cos_o, alpha))


def _shadowing_of(lam_i: Any, lam_o: Any) -> NDArray[np.float64]:
    """:func:`microfacet_shadowing` from the two Lambdas (the first worked on in place when
    it is an array of the result's shape)."""
    if not (_in_place(lam_i) and lam_i.shape == np.broadcast_shapes(lam_i.shape,
                                                                    np.shape(lam_o))):
        return 1.0 / (1.0 + lam_i + lam_o)
    lam_i += 1.0
    lam_i += lam_o
    return np.divide(1.0, lam_i, out=lam_i)


def dielectric_fresnel(cos_theta: ArrayLike, eta: ArrayLike) -> NDArray[np.float64]:
    """Cycles' ``fresnel_dielectric_cos``: the model's ``F_r`` (eq. 2,
    :func:`~lut_baker.model.microfacet.fresnel_reflectance`) at cosines clipped to [0, 1]
    (Cycles alone gives 1 at eta = 1 and grazing, the model 0)."""
    return fresnel_reflectance(np.clip(np.asarray(cos_theta, float), 0.0, 1.0),
                               np.asarray(eta, float))


def f0_from_ior(eta: ArrayLike) -> NDArray[np.float64]:
    """Normal-incidence reflectance ``((eta - 1) / (eta + 1))^2``."""
    return np.square((np.asarray(eta, float) - 1.0) / (np.asarray(eta, float) + 1.0))


def ior_from_f0(f0: ArrayLike) -> NDArray[np.float64]:
    """Inverse of :func:`f0_from_ior` (Cycles ``ior_from_F0``), for ``f0`` in [0, 1)."""
    root = np.sqrt(np.clip(f0, 0.0, 0.999999))
    return (1.0 + root) / (1.0 - root)


def schlick_ior_fresnel(cos_theta: ArrayLike, eta: ArrayLike,
                        f0: ArrayLike) -> NDArray[np.float64]:
    """The Principled specular's Fresnel: generalised Schlick with a negative exponent, i.e.
    ``mix(f0, 1, s)`` with ``s = (F(c, eta) - F0(eta)) / (1 - F0(eta))`` from the real curve.
    ``f0`` may be RGB (Specular Tint); the result then has a trailing channel axis."""
    real0 = f0_from_ior(eta)
    s = np.clip((dielectric_fresnel(cos_theta, eta) - real0) / (1.0 - real0), 0.0, 1.0)
    start = np.asarray(f0, float)
    if start.ndim:
        s = s[..., None]
    return start + (1.0 - start) * s


class DirectionPairs:
    """Light and view directions (unit vectors ``(..., 3)``, broadcast) and, made when first
    asked for, the :class:`LobeCosines` of their half vectors: what every microfacet lobe at
    these pairs shares (:func:`pair_reflection`)."""

    def __init__(self, wi: ArrayLike, wo: ArrayLike) -> None:
        self.wi, self.wo = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))

    @cached_property
    def cosines(self) -> LobeCosines:
        """``n.h``, ``h.wi``, ``n.wi``, ``n.wo`` of the pairs' half vectors."""
        h = half_vector(self.wi, self.wo)
        cos_hi = np.sum(h * self.wi, axis=-1)
        return LobeCosines(h[..., 2], cos_hi, self.wi[..., 2], self.wo[..., 2])


def microfacet_reflection(wi: ArrayLike, wo: ArrayLike, roughness: float,
                          fresnel: OfCosine | None = None,
                          distribution: str = "GGX") -> NDArray[np.float64]:
    """Microfacet reflection ``F(H.wi) D G2 / (4 cos_i cos_o)`` (Cycles
    ``bsdf_microfacet_eval``).

    ``roughness``: Blender's Roughness socket (``alpha = roughness^2``, clamped to
    :data:`ROUGHNESS_EPS`); ``fresnel``: ``None`` (Glossy BSDF: F = 1) or a callable of
    ``cos(H, wi)`` returning the Fresnel factor (any trailing channel axis is kept);
    ``distribution``: ``GGX``, ``BECKMANN`` or ``ASHIKHMIN_SHIRLEY`` (which takes no Fresnel).
    0 where either direction is below the surface.
    """
    return pair_reflection(DirectionPairs(wi, wo), roughness, fresnel, distribution)


def pair_reflection(pairs: DirectionPairs, roughness: float, fresnel: OfCosine | None = None,
                    distribution: str = "GGX") -> NDArray[np.float64]:
    """:func:`microfacet_reflection` at :class:`DirectionPairs` (their cosines shared by every
    lobe drawn there)."""
    if distribution == "ASHIKHMIN_SHIRLEY" and fresnel is not None:
        raise ValueError("the Ashikhmin-Shirley lobe takes no Fresnel in Cycles")
    cosines = pairs.cosines
    value = lobe_from_cosines(cosines, roughness, distribution)
    if fresnel is None:
        return value
    f = np.asarray(fresnel(np.clip(cosines.cos_hi, 0.0, 1.0)))
    return (value[..., None] if f.ndim > value.ndim else value) * f


def lambert_reflection(albedo: ArrayLike) -> NDArray[np.float64]:
    """Lambertian BRDF ``albedo / pi`` (Diffuse BSDF at roughness 0)."""
    return np.asarray(albedo, float) / np.pi


def directional_albedo(brdf: Callable[[NDArray[np.float64], NDArray[np.float64]], ArrayLike],
                       cos_theta: ArrayLike, *, lobe_width_deg: float = 20.0,
                       level: int = 0) -> NDArray[np.float64]:
    """``Int brdf(w, v) cos(theta_w) dw`` for view directions ``v`` at ``cos_theta`` (any
    shape), by the hemisphere quadrature of :mod:`lut_baker.numerics.quadrature`.

    ``brdf(w, v)`` takes direction arrays ``(..., 3)`` and returns ``(...)`` or ``(..., C)``.
    """
    cosines = np.asarray(cos_theta, float)
    grid = hemisphere_grid(lobe_width_deg, level)
    w = direction(grid.theta[:, None], grid.phi[None, :])  # (N, P, 3)
    theta_v = np.arccos(np.clip(cosines.ravel(), 0.0, 1.0))
    v = direction(theta_v, 0.0)[:, None, None, :]  # (V, 1, 1, 3)
    values = np.asarray(brdf(w[None], v))
    weights = grid.weight[None, :, None] * grid.phi_weight
    if values.ndim == 4:
        total = np.einsum("vnpc,vnp->vc", values, np.broadcast_to(weights, values.shape[:3]))
        return total.reshape(cosines.shape + (values.shape[-1],))
    return np.sum(values * weights, axis=(1, 2)).reshape(cosines.shape)


def microfacet_albedo(cos_view: ArrayLike, roughness: float, fresnel: OfCosine | None = None,
                      distribution: str = "GGX", *, n_u: int = 48,
                      n_phi: int = 32) -> NDArray[np.float64]:
    """Albedo ``Int f cos(theta_i) dwi`` of :func:`microfacet_reflection` at view cosines
    ``cos_view`` (any shape; a ``fresnel`` returning RGB adds a channel axis).

    Integrated over microfacet normals: with ``dwi = 4 (h.wo) dwh`` the albedo is
    ``Int D(h) cos(theta_h) [G2 F (h.wo) / (cos_o cos(theta_h))] dwh``; the map
    ``tan^2 theta_h = alpha^2 u / (1 - u)`` (GGX) or ``-alpha^2 log(1 - u)`` (Beckmann) turns
    ``D cos dwh`` into ``du dphi / 2 pi``, so Gauss-Legendre nodes in ``u`` (``n_u``) and
    midpoints in azimuth (``n_phi`` over [0, pi]) resolve a lobe of any roughness.
    Ashikhmin-Shirley: ``h`` has density ``(e + 1) / (2 pi) cos^e`` (``cos = u^(1/(e+1))``) and
    the albedo is the mean of ``cos_i / max(cos_i, cos_o)``.
    """
    return _chunked(cos_view, roughness, fresnel, distribution, n_u, n_phi, False)[0]


def microfacet_albedos(cos_view: ArrayLike, roughness: float, fresnel: OfCosine,
                       distribution: str = "GGX", *, n_u: int = 48, n_phi: int = 32
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(plain, weighted)``: :func:`microfacet_albedo` without Fresnel and with ``fresnel``
    from one pass over the nodes (a layering albedo needs both; the same numbers as two
    calls)."""
    plain, weighted = _chunked(cos_view, roughness, fresnel, distribution, n_u, n_phi, True)
    return plain, weighted


def _chunked(cos_view: ArrayLike, roughness: float, fresnel: OfCosine | None,
             distribution: str, n_u: int, n_phi: int,
             both: bool) -> tuple[NDArray[np.float64], ...]:
    """:func:`_albedo_views` over the views in chunks (:data:`ALBEDO_CHUNK`), reshaped; the
    half vectors (:func:`_half_vectors`) made once for every chunk."""
    views = np.asarray(cos_view, float)
    flat = views.ravel()
    step = max(ALBEDO_CHUNK // (n_u * n_phi), 1)
    nodes = _half_vectors(roughness, distribution, n_u, n_phi)
    parts = [_albedo_views(flat[k:k + step], nodes, fresnel, both)
             for k in range(0, flat.size, step)] or [_albedo_views(flat, nodes, fresnel, both)]
    out = []
    for index in range(len(parts[0])):
        total = np.concatenate([part[index] for part in parts], axis=0)
        out.append(total.reshape(views.shape + total.shape[1:]))
    return tuple(out)


ALBEDO_CHUNK = 65536
"""Quadrature nodes :func:`microfacet_albedo` works on at once: the views in chunks of about
this many nodes, so that its arrays stay in the processor's cache (a Glossy lobe's final
albedo at 64 texels, 393 216 nodes: 14 -> 5 ms); each view's sum is the same to the last bit
whatever the chunk."""


@lru_cache(maxsize=8)
def _albedo_nodes(n_u: int, n_phi: int
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``(u (U,), weights (1, U, 1), cos(phi) (1, 1, P))`` of :func:`microfacet_albedo`'s
    quadrature: ``n_u`` Gauss-Legendre nodes in ``u`` with their weights over ``n_phi``, the
    cosines of ``n_phi`` midpoints in azimuth over [0, pi] (read-only; the same for every
    roughness, made once per resolution)."""
    u, w_u = gauss_legendre(n_u)
    weights = w_u[None, :, None] / n_phi
    cos_phi = np.cos(midpoint_nodes(n_phi, 0.0, np.pi))[None, None, :]
    weights.setflags(write=False)
    cos_phi.setflags(write=False)
    return u, weights, cos_phi


class _HalfVectors(NamedTuple):
    """:func:`microfacet_albedo`'s microfacet normals at one roughness: ``alpha``, ``hx``
    ``(1, U, P)`` and ``hz`` ``(1, U, 1)`` (the normals' x and z; the view in x-z), the
    quadrature's ``weights`` ``(1, U, 1)``, the ``distribution``."""

    alpha: float
    hx: NDArray[np.float64]
    hz: NDArray[np.float64]
    weights: NDArray[np.float64]
    distribution: str


def _half_vectors(roughness: float, distribution: str, n_u: int, n_phi: int) -> _HalfVectors:
    """:class:`_HalfVectors` of ``distribution`` at ``roughness`` on :func:`_albedo_nodes`:
    ``tan^2 theta_h = alpha^2 u / (1 - u)`` (GGX), ``-alpha^2 log(1 - u)`` (Beckmann),
    ``cos theta_h = u^(1/(e+1))`` (Ashikhmin-Shirley)."""
    alpha = np.square(max(float(roughness), ROUGHNESS_EPS))
    u, weights, cos_phi = _albedo_nodes(n_u, n_phi)
    if distribution == "GGX":
        tan2 = alpha * alpha * u / (1.0 - u)
    elif distribution == "BECKMANN":
        tan2 = -alpha * alpha * np.log1p(-u)
    elif distribution == "ASHIKHMIN_SHIRLEY":
        c = u ** (1.0 / (ashikhmin_shirley_exponent(roughness) + 1.0))
        tan2 = (1.0 - c * c) / np.maximum(c * c, 1e-300)
    else:
        raise ValueError(f"distribution must be one of {list(DISTRIBUTIONS)}, got "
                         f"{distribution!r}")
    cos_h = 1.0 / np.sqrt(1.0 + tan2)
    sin_h = np.sqrt(tan2) * cos_h
    return _HalfVectors(alpha, sin_h[None, :, None] * cos_phi, cos_h[None, :, None], weights,
                        distribution)


def _albedo_views(views: NDArray[np.float64], nodes: _HalfVectors, fresnel: OfCosine | None,
                  both: bool = False) -> tuple[NDArray[np.float64], ...]:
    """:func:`microfacet_albedo` at 1-D ``views`` on ``nodes`` (:func:`_half_vectors`):
    ``((V,),)``, or ``((V, C),)`` for an RGB ``fresnel``; ``both``: the Fresnel-free albedo
    first, then the one with ``fresnel``."""
    hx, hz, distribution = nodes.hx, nodes.hz, nodes.distribution
    mu_o = np.clip(views, 1e-6, 1.0)[:, None, None]
    sin_o = np.sqrt(1.0 - mu_o * mu_o)
    h_dot_o = hx * sin_o + hz * mu_o
    mu_i = h_dot_o * (2.0 * hz) - mu_o  # 2 h.wo n.h - n.wo (doubling is exact)
    valid = (h_dot_o > 0.0) & (mu_i > 0.0)
    if distribution == "ASHIKHMIN_SHIRLEY":
        value = np.where(valid, mu_i / np.maximum(mu_i, mu_o), 0.0)
    else:
        g2 = microfacet_shadowing(np.where(valid, mu_i, 1.0), mu_o, nodes.alpha, distribution)
        g2 *= h_dot_o  # g2 h.wo / (n.wo n.h), in place (a new full-size array)
        g2 /= mu_o * hz
        value = np.where(valid, g2, 0.0)
    weights = nodes.weights
    if fresnel is None:
        return (np.sum(value * weights, axis=(1, 2)),)
    weighted = value * weights
    f = np.asarray(fresnel(np.clip(h_dot_o, 0.0, 1.0)))
    if f.ndim > value.ndim:
        with_fresnel = np.einsum("vup,vupc->vc", weighted, f)
    else:
        with_fresnel = np.sum(weighted * f, axis=(1, 2))
    return (np.sum(weighted, axis=(1, 2)), with_fresnel) if both else (with_fresnel,)


def layering_albedo(cos_view: ArrayLike, roughness: float, eta: float,
                    f0: ArrayLike | None = None, *,
                    plain: NDArray[np.float64] | None = None,
                    weighted: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """The albedo Cycles attributes to a dielectric GGX layer seen at ``cos_view`` when it
    attenuates the layers below (``bsdf_microfacet_estimate_albedo``): ``mix(f0, 1, s)``.

    Cycles reads ``s`` from a 16^3 table that normalises by the Fresnel-free GGX albedo
    (its comment: the table "assumes energy preservation"); this replica computes the same
    ratio ``E_F / E_1`` by quadrature (:func:`microfacet_albedo`), with ``E_F`` the albedo under the
    real Fresnel at ``eta``.  ``f0`` (default ``F0(eta)``, RGB allowed) rescales the start as
    Specular IOR Level and Specular Tint do.  ``plain``, ``weighted``: ``E_1`` and ``E_F`` at
    these views if already computed (:func:`coat_view_terms` has the first, a caller that
    needs the lobe's own albedo the second).
    """
    views = np.asarray(cos_view, float)
    if weighted is None and plain is None:
        e_1, e_f = microfacet_albedos(views, roughness, lambda c: dielectric_fresnel(c, eta))
    else:
        e_f = (microfacet_albedo(views, roughness, lambda c: dielectric_fresnel(c, eta))
               if weighted is None else weighted)
        e_1 = microfacet_albedo(views, roughness) if plain is None else plain
    real0 = f0_from_ior(eta)
    s = np.clip((e_f / np.maximum(e_1, 1e-12) - real0) / (1.0 - real0), 0.0, 1.0)
    start = real0 if f0 is None else np.asarray(f0, float)
    if np.ndim(start):
        s = s[..., None]
    return start + (1.0 - start) * s


def dielectric_fss(eta: ArrayLike) -> NDArray[np.float64]:
    """Cycles' average single-scattering dielectric Fresnel ``Int 2 mu F(mu) dmu`` at ``eta``
    (``fresnel_dielectric_Fss``: Kulla and Conty's fit; exact to ~1e-3)."""
    index = np.asarray(eta, float)
    below = 0.997118 + index * (0.1014 - index * (0.965241 + index * 0.130607))
    return np.where(index < 1.0, below, (index - 1.0) / (4.08567 + 1.00071 * index))


def ggx_energy_compensation(cos_view: ArrayLike, roughness: float, fss: Real
                            ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(scale, darkening)`` Cycles applies to a GGX lobe with Fresnel (the Principled coat:
    ``microfacet_ggx_preserve_energy``), at view cosines ``cos_view``.

    With ``E`` the Fresnel-free single-scattering albedo at the view (:func:`microfacet_albedo`;
    Cycles reads a 32^2 table of it) and ``E_avg`` its cosine-weighted mean: the lobe's value is
    multiplied by ``scale = 1 + F_ms (1 - E) / E`` with ``F_ms = F_ss E_avg / (1 - F_ss (1 -
    E_avg))``, of which ``darkening = scale E`` sits in the closure's weight (so in the albedo
    that attenuates the layers below) and ``1 / E`` in its evaluation.
    """
    return ggx_energy_scale(microfacet_albedo(np.asarray(cos_view, float), roughness),
                            ggx_average_albedo(float(roughness)), fss)


def ggx_energy_scale(albedo: ArrayLike, average_albedo: float, fss: Real
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`ggx_energy_compensation` from the Fresnel-free albedo ``E`` at the views and its
    cosine-weighted mean ``E_avg`` (so that a fit varying only the Fresnel reuses them)."""
    e = np.asarray(albedo, float)
    missing = (1.0 - e) / np.maximum(e, 1e-6)
    f_ms = fss * average_albedo / (1.0 - fss * (1.0 - average_albedo))
    scale = 1.0 + f_ms * missing
    return scale, scale / (1.0 + missing)


def coat_view_terms(cos_view: ArrayLike, roughness: float, ior: float, *,
                    weighted: NDArray[np.float64] | None = None,
                    plain: NDArray[np.float64] | None = None
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(scale, layering albedo)`` of the Principled coat at view cosines ``cos_view``: the
    factor :func:`ggx_energy_compensation` puts on its lobe, and the albedo by which it
    attenuates the layers below, ``darkening * layering_albedo`` (Cycles' ``bsdf_albedo``
    reads the closure's weight, which holds the darkening).  The Fresnel-free albedo both
    need is computed once, with the lobe's albedo with its Fresnel
    (:func:`microfacet_albedos`); ``weighted``, ``plain``: these at these views, if the caller
    has them (:func:`layering_albedo`)."""
    views = np.asarray(cos_view, float)
    if plain is None and weighted is None:
        plain, weighted = microfacet_albedos(views, roughness,
                                             lambda c: dielectric_fresnel(c, ior))
    elif plain is None:
        plain = microfacet_albedo(views, roughness)
    scale, darkening = ggx_energy_scale(plain, ggx_average_albedo(float(roughness)),
                                        float(dielectric_fss(ior)))
    return scale, darkening * layering_albedo(cos_view, roughness, ior, plain=plain,
                                              weighted=weighted)


@lru_cache(maxsize=64)
def ggx_average_albedo(roughness: float) -> float:
    """``2 Int E(mu) mu dmu`` of the Fresnel-free GGX albedo (Cycles' ``ggx_Eavg``)."""
    mu, w = gauss_legendre(32)
    return float(2.0 * np.sum(w * mu * microfacet_albedo(mu, roughness)))


# --------------------------------------------------------------------------------------------
# Principled BSDF (svm_node_closure_bsdf, CLOSURE_BSDF_PRINCIPLED_ID, distribution GGX)
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PrincipledInputs:
    """The Principled BSDF sockets the replica uses (others at their defaults: metallic 0,
    transmission 0, sheen 0, coat tint white, diffuse roughness 0, distribution GGX).

    ``base_color``: RGB; ``roughness``, ``ior``, ``specular_ior_level`` (0.5 = IOR as given),
    ``specular_tint`` RGB; ``coat_weight``, ``coat_roughness``, ``coat_ior``.
    """

    base_color: tuple = (0.8, 0.8, 0.8)
    roughness: float = 0.5
    ior: float = 1.5
    specular_ior_level: float = 0.5
    specular_tint: tuple = (1.0, 1.0, 1.0)
    coat_weight: float = 0.0
    coat_roughness: float = 0.03
    coat_ior: float = 1.5
    extra: dict = field(default_factory=dict)

    def specular_eta_f0(self) -> tuple[float, NDArray[np.float64]]:
        """``(eta', f0 per channel)`` after Specular IOR Level and Tint (Cycles' "IOR
        adjustment"): ``f0 = F0(ior) 2 level``, ``eta' = ior_from_F0(f0)``."""
        f0 = float(f0_from_ior(self.ior))
        eta = self.ior
        if self.specular_ior_level != 0.5:
            f0 *= 2.0 * self.specular_ior_level
            eta = float(ior_from_f0(f0))
        return eta, f0 * np.asarray(self.specular_tint, float)


def principled_reflection(wi: ArrayLike, wo: ArrayLike, inputs: PrincipledInputs, *,
                          pairs: DirectionPairs | None = None) -> NDArray[np.float64]:
    """The Principled BSDF's reflection (no cosine), RGB ``(..., 3)``, as Cycles layers it:

    ``w_c k(wo) coat(wi, wo) + a_c(wo) [spec(wi, wo) + a_s(wo) base / pi]``

    with the coat's multiple-scattering compensation ``k`` (:func:`ggx_energy_compensation`:
    Cycles applies it to the coat whatever the distribution), ``a_c = 1 - w_c d(wo)
    E_coat(wo)`` (``d`` its darkening) and ``a_s = 1 - max_c E_spec(wo)`` from
    :func:`layering_albedo` (``closure_layering_weight``): the attenuation depends on the view
    only, so the model is not reciprocal, like Cycles.  Subsurface counts as its albedo in
    ``base_color`` leaving Lambertian-like (its spread is separate, see the profiles).
    ``pairs``: :class:`DirectionPairs` of ``(wi, wo)``, if made (shared with other lobes).
    """
    pairs = DirectionPairs(wi, wo) if pairs is None else pairs
    cos_o = np.clip(pairs.wo[..., 2], 0.0, 1.0)
    eta, f0 = inputs.specular_eta_f0()
    base = lambert_reflection(np.minimum(np.maximum(inputs.base_color, 0.0), 1.0))
    if eta == 1.0:  # Specular IOR Level 0: Cycles allocates no specular closure
        lower = base * np.ones(cos_o.shape + (1,))
    else:
        spec = pair_reflection(pairs, inputs.roughness,
                               lambda c: schlick_ior_fresnel(c, eta, f0))
        a_s = 1.0 - np.max(view_table(cos_o, _layering_nodes(
            float(inputs.roughness), float(eta), tuple(np.atleast_1d(f0).tolist()))), axis=-1)
        lower = spec + a_s[..., None] * base
    if inputs.coat_weight <= 0.0:
        return lower
    coat = pair_reflection(pairs, inputs.coat_roughness,
                           lambda c: dielectric_fresnel(c, inputs.coat_ior))
    terms = view_table(cos_o, _coat_nodes(float(inputs.coat_roughness),
                                          float(inputs.coat_ior)))
    a_c = np.clip(1.0 - inputs.coat_weight * terms[..., 1], 0.0, 1.0)
    return (inputs.coat_weight * (coat * terms[..., 0])[..., None]
            + a_c[..., None] * lower)


def principled_uniform(inputs: PrincipledInputs, nodes: int = 24
                       ) -> tuple[NDArray[np.float64], float]:
    """``(gloss, W)`` of :func:`principled_reflection` under uniform white light: its colour
    is ``gloss + W base_color`` (unclipped Base Color), ``gloss`` (RGB) its coat's and
    specular's albedo, ``W`` what its layers leave the base, both ``2 Int (.) mu dmu`` over
    the view (``nodes`` Gauss-Legendre nodes; each lobe's albedo by
    :func:`microfacet_albedo`, so that a narrow lobe costs no finer grid)."""
    mu, weight = gauss_legendre(nodes)
    mean = 2.0 * weight * mu
    eta, f0 = inputs.specular_eta_f0()
    if eta == 1.0:
        gloss, passed = np.zeros((mu.size, 3)), np.ones(mu.size)
    else:
        gloss = microfacet_albedo(mu, inputs.roughness,
                                  lambda c: schlick_ior_fresnel(c, eta, f0)) * np.ones(3)
        passed = 1.0 - np.max(np.atleast_2d(layering_albedo(
            mu, inputs.roughness, eta, f0).T).T, axis=-1)
    if inputs.coat_weight > 0.0:
        coat, layered = _coat_uniform(float(inputs.coat_roughness), float(inputs.coat_ior),
                                      nodes)
        below = np.clip(1.0 - inputs.coat_weight * layered, 0.0, 1.0)
        gloss = inputs.coat_weight * coat[:, None] + below[:, None] * gloss
        passed = below * passed
    return mean @ gloss, float(mean @ passed)


@lru_cache(maxsize=64)
def _coat_uniform(roughness: float, ior: float, nodes: int
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The coat's compensated albedo and its layering albedo at :func:`principled_uniform`'s
    view nodes (cached: a fit moved to another thickness keeps its coat)."""
    mu, _ = gauss_legendre(nodes)
    plain, weighted = microfacet_albedos(mu, roughness, lambda c: dielectric_fresnel(c, ior))
    scale, layered = coat_view_terms(mu, roughness, ior, weighted=weighted, plain=plain)
    albedo = scale * weighted
    albedo.setflags(write=False)
    layered.setflags(write=False)
    return albedo, layered


VIEW_TABLE_SIZE = 64
"""Nodes of :func:`view_table` on ``cos(theta_o)`` in [0, 1]."""


@lru_cache(maxsize=64)
def _layering_nodes(roughness: float, eta: float, f0: tuple) -> np.ndarray:
    """:func:`layering_albedo` at :func:`view_table`'s nodes (cached: replicas of one fit
    evaluate it many times)."""
    reflectance = f0[0] if len(f0) == 1 else np.asarray(f0)
    return layering_albedo(np.linspace(0.0, 1.0, VIEW_TABLE_SIZE), roughness, eta, reflectance)


@lru_cache(maxsize=64)
def _coat_nodes(roughness: float, ior: float) -> np.ndarray:
    """:func:`coat_view_terms` at :func:`view_table`'s nodes, ``(size, 2)`` (cached)."""
    return np.stack(coat_view_terms(np.linspace(0.0, 1.0, VIEW_TABLE_SIZE), roughness, ior),
                    axis=-1)


def view_table(cos_view: NDArray[np.float64], function: OfCosine | ArrayLike,
               size: int = VIEW_TABLE_SIZE) -> NDArray[np.float64]:
    """``function`` of the view cosine, tabulated on ``size`` nodes and interpolated linearly
    (the layering albedos are smooth; tabulating keeps a replica of a large grid cheap);
    ``function`` may also be the table itself, at those nodes."""
    nodes = np.linspace(0.0, 1.0, size)
    table = np.asarray(function(nodes) if callable(function) else function)
    if table.ndim == 1:
        return np.interp(cos_view, nodes, table)
    return np.stack([np.interp(cos_view, nodes, table[:, c]) for c in range(table.shape[1])],
                    axis=-1)


# --------------------------------------------------------------------------------------------
# Subsurface radial profiles (bssrdf.h, subsurface_random_walk.h)
# --------------------------------------------------------------------------------------------
def burley_profile(r_mm: ArrayLike, radius_mm: ArrayLike) -> NDArray[np.float64]:
    """Christensen-Burley profile as Cycles evaluates it, normalised to ``Int P 2 pi r dr = 1``
    (1/mm^2): ``P = (exp(-r/d) + exp(-r/(3d))) / (8 pi d r)`` with ``d = radius / (4 pi)``
    (``bssrdf_setup_radius``; ``radius`` = Subsurface Radius x Scale), cut at ``16 d`` and
    renormalised as ``bssrdf_burley_pdf`` does.  ``radius_mm`` scalar or RGB (trailing axis)."""
    r = np.asarray(r_mm, float)
    d = np.asarray(radius_mm, float) * BURLEY_MFP_SCALE
    if d.ndim:
        r = r[..., None]
    r_safe = np.maximum(r, 1e-12)
    value = (np.exp(-r_safe / d) + np.exp(-r_safe / (3.0 * d))) / (8.0 * np.pi * d * r_safe)
    cdf = 1.0 - 0.25 * np.exp(-BURLEY_TRUNCATE) - 0.75 * np.exp(-BURLEY_TRUNCATE / 3.0)
    return np.where(r < BURLEY_TRUNCATE * d, value / cdf, 0.0)


RANDOM_WALK_BURLEY_SCALE = {
    # surface albedo -> k, measured on Cycles 5.0.1 (4.5.15 agrees at 0.8) by
    # tools/calibrate_subsurface.py: a slab lit up to a straight shadow edge, the rendered edge
    # response (256 samples, rows averaged) against the Burley replica's, k on a 1.08-ratio grid.
    "RANDOM_WALK": ((0.2, 0.325), (0.5, 0.562), (0.8, 1.05), (0.95, 1.33)),
    "RANDOM_WALK_SKIN": ((0.2, 3.13), (0.5, 1.81), (0.8, 0.898), (0.95, 0.445)),
}
"""Random walks replicated as a Burley profile of radius ``k(albedo) x radius``: the
rendered edge responses match that shape within 0.6-1.3% of the lit level (the Burley closure
itself within 0.3-0.4%, the Monte Carlo noise); ``k`` is interpolated linearly in albedo and
held beyond the measured range."""


def random_walk_scale(surface_albedo: ArrayLike,
                      method: str = "RANDOM_WALK_SKIN") -> NDArray[np.float64]:
    """The measured ``k`` of :data:`RANDOM_WALK_BURLEY_SCALE` at a surface albedo (colour)."""
    if method not in RANDOM_WALK_BURLEY_SCALE:
        raise ValueError(f"method must be one of {list(RANDOM_WALK_BURLEY_SCALE)}, "
                         f"got {method!r}")
    albedo, scale = np.array(RANDOM_WALK_BURLEY_SCALE[method]).T
    return np.interp(np.asarray(surface_albedo, float), albedo, scale)


def subsurface_profile(r_mm: ArrayLike, radius_mm: ArrayLike, surface_albedo: ArrayLike = 0.8,
                       method: str = "BURLEY") -> NDArray[np.float64]:
    """Radial profile (1/mm^2, unit area) of a Blender subsurface method at Subsurface Radius x
    Scale ``radius_mm`` (scalar or RGB) and colour ``surface_albedo``: :func:`burley_profile`,
    for the random walks with the measured scale :func:`random_walk_scale`."""
    if method == "BURLEY":
        return burley_profile(r_mm, radius_mm)
    return burley_profile(r_mm, np.asarray(radius_mm, float)
                          * random_walk_scale(surface_albedo, method))
