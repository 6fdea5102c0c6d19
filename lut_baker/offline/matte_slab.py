"""A thick scattering slab under a rough dielectric surface, for the matte products' angular
data (docs/model.md, "The matte products as a slab under a surface"; docs/foundations/README.md).

An experiment (the presets do not use it): the product as an infinitely thick homogeneous
medium (a single-scattering albedo per channel, a two-lobe Henyey-Greenstein phase function)
under a surface of refractive index ``eta`` and GGX roughness ``alpha``, evaluated per azimuthal
Fourier order by adding (:mod:`lut_baker.numerics.adding_doubling`).

The surface, as the film's surface of :mod:`lut_baker.model.film_slab` but refracting:

- from above it reflects the GGX lobe (Walter et al. 2007, "Microfacet models for refraction
  through rough surfaces", eqs. 20, 33, 34; Smith masking-shadowing, height-correlated, Heitz
  2014, "Understanding the masking-shadowing function", eq. 99), white, with the dielectric
  Fresnel factor of ``eta``; it is evaluated in closed form where it is read
  (:func:`ggx_reflection`), and its directional albedo ``a_g`` (:func:`ggx_albedo`) is what
  cannot enter the medium;
- the rest, ``1 - a_g``, is refracted (Snell) into the medium; inside, light reaching the
  surface at a direction that refracts back out is reflected specularly by ``a_g`` of that
  direction and leaves by ``1 - a_g``; beyond the critical angle it is totally reflected.
  Lossless and reciprocal; for ``alpha -> 0`` it is the smooth Fresnel interface.

Inside, the polar nodes are the outside nodes refracted (:func:`refracted_grid`: Snell maps
``[0, 90]`` degrees outside onto ``[0, theta_c]`` inside, the projected solid angle shrinking by
``1/eta^2``) plus Gauss-Legendre nodes over the totally reflected range ``[theta_c, 90]``.  In
the star form with the measure ``eta^2 cos dw`` (radiance over ``eta^2`` is conserved along a
refracted ray), a refracted node has the star weight of its outside node, so straight
refracted transmission is a diagonal matrix (:func:`under_surface`).

Functions
---------
- :func:`ggx_distribution` -- GGX normal distribution ``D(h)`` (1/sr).
- :func:`smith_lambda` -- GGX's Smith ``Lambda`` of a direction.
- :func:`ggx_reflection` -- the surface's reflection BRDF (1/sr) from cosines.
- :func:`ggx_albedo` -- its directional albedo at given incidences.
- :func:`refracted_grid` -- the inside polar nodes and weights.
- :func:`henyey_greenstein` -- the Henyey-Greenstein phase function (1/sr).
- :func:`phase_orders` -- a two-lobe HG phase function's cosine coefficients between nodes.
- :func:`transport_generator` -- a medium's slab generator (its transport matrices).
- :func:`thick_medium` -- the infinitely thick medium's reflection (star form).
- :func:`under_surface` -- the medium's reflection seen through the surface (star form, outside
  grid).
- :func:`flake_extinction`, :func:`flake_orders` -- specular flakes (platelets) with GGX
  normals: their projected area and scattering kernel.
- :func:`cone_distribution` -- flake normals on a cone about the vertical (a Gaussian in the
  polar angle, Lanza et al. 2024's tilted platelets made azimuthally isotropic).
- :func:`projected_area` -- any such distribution's projected area (azimuth in closed form).
- :func:`kernel_orders` -- any such distribution's specular kernel ``D(h) / 4`` per order.
- :class:`MatteSlab` -- the parameters.
- :func:`medium_generator`, :func:`medium_reflection` -- the medium of spheres and flakes:
  its generator (any thickness) and its thick limit.
- :func:`matte_slab_kernel` -- the model on one grid: parameters to the reflection kernel per
  channel and order.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..model.microfacet import fresnel_reflectance
from ..numerics import adding_doubling as AD
from ..numerics.quadrature import HemisphereGrid, gauss_legendre, uniform_azimuths

__all__ = [
    "ggx_distribution",
    "smith_lambda",
    "ggx_reflection",
    "ggx_albedo",
    "refracted_grid",
    "henyey_greenstein",
    "phase_orders",
    "flake_extinction",
    "flake_orders",
    "cone_distribution",
    "projected_area",
    "kernel_orders",
    "transport_generator",
    "thick_medium",
    "under_surface",
    "MatteSlab",
    "medium_generator",
    "medium_reflection",
    "matte_slab_kernel",
]

ALBEDO_POINTS = 48
"""Gauss-Legendre points per axis of :func:`ggx_albedo`'s half-vector quadrature."""
CONE_POINTS = 256
"""Gauss-Legendre points in the normal's polar angle of :func:`cone_distribution`'s
normalisation and of :func:`projected_area`."""


def ggx_distribution(cos_h, alpha):
    """GGX (Trowbridge-Reitz) distribution of microfacet normals, 1/sr (Walter et al. 2007,
    eq. 33): ``alpha^2 / (pi cos^4 (alpha^2 + tan^2)^2)``, normalised so that
    ``Int D cos_h dw = 1``; ``cos_h`` the normal's cosine with the macro normal (> 0)."""
    c2 = np.asarray(cos_h, float) ** 2
    a2 = np.asarray(alpha, float) ** 2
    return a2 / (np.pi * (c2 * (a2 - 1.0) + 1.0) ** 2)


def smith_lambda(mu, alpha):
    """GGX's Smith ``Lambda`` of a direction at cosine ``mu`` in (0, 1] (Heitz 2014, eq. 72):
    ``(sqrt(1 + alpha^2 tan^2) - 1) / 2``; the masking is ``1 / (1 + Lambda)``."""
    mu = np.asarray(mu, float)
    tan2 = np.maximum(1.0 - mu * mu, 0.0) / (mu * mu)
    return 0.5 * (np.sqrt(1.0 + np.asarray(alpha, float) ** 2 * tan2) - 1.0)


def ggx_reflection(mu_i, mu_o, cos_dphi, alpha, eta):
    """The surface's reflection BRDF (1/sr) between directions at cosines ``mu_i``, ``mu_o``
    (> 0) and relative azimuth ``dphi`` (0: the same side of the normal, pi: the mirror side):
    ``F(i.h, eta) D(h) G2 / (4 mu_i mu_o)`` (Walter et al. 2007, eq. 20) with the
    height-correlated ``G2 = 1 / (1 + Lambda_i + Lambda_o)`` (Heitz 2014, eq. 99).  Symmetric in
    ``i``, ``o`` (reciprocal)."""
    mu_i = np.asarray(mu_i, float)
    mu_o = np.asarray(mu_o, float)
    sin_i = np.sqrt(np.maximum(1.0 - mu_i * mu_i, 0.0))
    sin_o = np.sqrt(np.maximum(1.0 - mu_o * mu_o, 0.0))
    # i = (sin_i, 0, mu_i), o = (sin_o cos dphi, sin_o sin dphi, mu_o); h = (i + o) / |i + o|.
    i_dot_o = mu_i * mu_o + sin_i * sin_o * np.asarray(cos_dphi, float)
    length = np.sqrt(np.maximum(2.0 + 2.0 * i_dot_o, 1e-300))
    cos_h = (mu_i + mu_o) / length
    i_dot_h = np.sqrt(np.maximum(0.5 + 0.5 * i_dot_o, 0.0))
    g2 = 1.0 / (1.0 + smith_lambda(mu_i, alpha) + smith_lambda(mu_o, alpha))
    return (fresnel_reflectance(i_dot_h, eta) * ggx_distribution(cos_h, alpha) * g2
            / (4.0 * mu_i * mu_o))


def ggx_albedo(mu, alpha, eta, points: int = ALBEDO_POINTS):
    """Directional albedo of :func:`ggx_reflection` at incidence cosines ``mu`` ``(N,)``:
    ``Int f cos_o dw_o`` over the half vector, ``dw_o = 4 (i.h) dw_h``, with ``cos^2 theta_h``
    mapped from ``u`` in [0, 1] by GGX's own distribution (``tan^2 = alpha^2 u / (1 - u)``:
    ``D cos_h dw_h = du dphi / 2 pi``), Gauss-Legendre in ``u`` and in the azimuth over a half
    turn (the integrand is even).  Directions reflected below the horizon count nothing."""
    mu = np.asarray(mu, float)[:, None, None]
    u, wu = gauss_legendre(points, 0.0, 1.0)
    phi, wphi = gauss_legendre(points, 0.0, np.pi)
    tan2 = np.asarray(alpha, float) ** 2 * u / (1.0 - u)
    cos_h = (1.0 / np.sqrt(1.0 + tan2))[None, :, None]
    sin_h = np.sqrt(1.0 - cos_h * cos_h)
    sin_i = np.sqrt(np.maximum(1.0 - mu * mu, 0.0))
    i_dot_h = mu * cos_h + sin_i * sin_h * np.cos(phi)[None, None, :]
    mu_o = 2.0 * i_dot_h * cos_h - mu
    visible = (i_dot_h > 0.0) & (mu_o > 0.0)
    safe_o = np.where(visible, mu_o, 1.0)
    g2 = 1.0 / (1.0 + smith_lambda(mu, alpha) + smith_lambda(safe_o, alpha))
    value = np.where(visible, fresnel_reflectance(np.clip(i_dot_h, 0.0, 1.0), eta) * g2
                     * i_dot_h / (mu * cos_h), 0.0)
    # du dphi / (2 pi) over a full turn: twice the half turn.
    return np.einsum("nuk,u,k->n", value, wu, wphi) / np.pi


def refracted_grid(grid: HemisphereGrid, eta: float, tir_points: int) -> HemisphereGrid:
    """The polar nodes inside a medium of relative index ``eta`` > 1 under ``grid``: first the
    outside nodes refracted (``sin theta' = sin theta / eta``, weights ``w / eta^2``: Snell keeps
    ``eta^2 cos sin dtheta``), then ``tir_points`` Gauss-Legendre nodes over the totally
    reflected range ``[theta_c, 90]`` degrees (weights ``cos sin dtheta``); ``grid``'s azimuths."""
    if not eta > 1.0:
        raise ValueError(f"eta must be > 1, got {eta!r}")
    inside = np.arcsin(np.sin(grid.theta) / eta)
    critical = np.arcsin(1.0 / eta)
    extra, dtheta = gauss_legendre(tir_points, critical, 0.5 * np.pi)
    theta = np.concatenate([inside, extra])
    weight = np.concatenate([np.asarray(grid.weight) / eta**2,
                             np.cos(extra) * np.sin(extra) * dtheta])
    return HemisphereGrid(theta=theta, weight=weight, n_phi=grid.n_phi)


def henyey_greenstein(g, cos_angle):
    """The Henyey-Greenstein phase function (1/sr, integrating to 1 over the sphere) at the
    cosine of the scattering angle: ``(1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^1.5)``."""
    g = np.asarray(g, float)
    return (1.0 - g * g) / (4.0 * np.pi * (1.0 + g * g - 2.0 * g * cos_angle) ** 1.5)


def phase_orders(grid: HemisphereGrid, g1: float, g2: float, weight: float):
    """``(forward, back)``: cosine coefficients per order ``(orders, N, N)`` (1/sr) of the
    two-lobe phase function ``w HG(g1) + (1 - w) HG(g2)`` between two downgoing nodes
    (straight on at relative azimuth 0) and between a downgoing and an upgoing one."""
    mu = np.cos(grid.theta)
    sin = np.sin(grid.theta)
    cos_between = (mu[:, None, None] * mu[None, :, None]
                   + sin[:, None, None] * sin[None, :, None] * np.cos(uniform_azimuths(grid.n_phi)))

    def orders(cos_angle):
        values = (weight * henyey_greenstein(g1, cos_angle)
                  + (1.0 - weight) * henyey_greenstein(g2, cos_angle))
        spectrum = np.fft.rfft(values, axis=-1).real / grid.n_phi
        spectrum[..., 1:] *= 2.0
        return np.moveaxis(spectrum, -1, 0)

    return orders(cos_between), orders(-cos_between)


def flake_extinction(mu, alpha):
    """Projected area of two-sided flakes whose normals follow GGX of roughness ``alpha`` about
    the vertical, seen along a direction at cosine ``mu`` (relative to it seen from above):
    ``Int |w.m| D(m) dm = mu (1 + 2 Lambda(mu))`` (Smith: the facets facing ``w`` project
    ``mu (1 + Lambda)``, those facing away ``mu Lambda``; Heitz et al. 2015, "The SGGX
    microflake distribution", eq. 4).  It tends to ``alpha`` at grazing."""
    mu = np.asarray(mu, float)
    return mu * (1.0 + 2.0 * smith_lambda(mu, alpha))


def flake_orders(grid: HemisphereGrid, alpha: float):
    """``(forward, back)``: cosine coefficients per order ``(orders, N, N)`` (1/sr per unit
    flake density) of the scattering kernel of specular two-sided flakes with GGX normals of
    roughness ``alpha`` about the vertical (:func:`kernel_orders` of :func:`ggx_distribution`);
    it integrates to :func:`flake_extinction` over the sphere."""
    return kernel_orders(grid, lambda cos_h: ggx_distribution(cos_h, alpha))


def kernel_orders(grid: HemisphereGrid, distribution):
    """``(forward, back)``: cosine coefficients per order ``(orders, N, N)`` (1/sr per unit
    flake density) of the scattering kernel of specular two-sided flakes whose normals follow
    ``distribution`` (a function of the normal's ``|cos|`` with the vertical, 1/sr, normalised
    as GGX is: ``Int_H D cos dm = 1``), ``D(h) / 4`` with ``h`` the flake normal that reflects
    one direction into the other (Heitz et al. 2015, eq. 9: ``sigma(w) p(w -> w') = D(h) / 4``,
    symmetric), between two downgoing nodes (straight on at relative azimuth 0) and between a
    downgoing and an upgoing one; it integrates to :func:`projected_area` over the sphere."""
    mu = np.cos(grid.theta)
    sin = np.sin(grid.theta)
    dot = (mu[:, None, None] * mu[None, :, None]
           + sin[:, None, None] * sin[None, :, None] * np.cos(uniform_azimuths(grid.n_phi)))
    # Back: the incident light's upward direction and the outgoing one (their half vector);
    # forward: the difference of the two propagation directions (edge-on flakes).
    back = (mu[:, None, None] + mu[None, :, None]) / np.sqrt(np.maximum(2.0 + 2.0 * dot, 1e-300))
    gap = 2.0 - 2.0 * dot
    forward = np.where(gap > 1e-12, np.abs(mu[:, None, None] - mu[None, :, None])
                       / np.sqrt(np.maximum(gap, 1e-300)), 0.0)

    def orders(cos_h):
        values = 0.25 * distribution(np.clip(cos_h, 0.0, 1.0))
        spectrum = np.fft.rfft(values, axis=-1).real / grid.n_phi
        spectrum[..., 1:] *= 2.0
        return np.moveaxis(spectrum, -1, 0)

    return orders(forward), orders(back)


def _cone_weight(theta, cone, spread):
    """Unnormalised density (per solid angle) of flake normals at polar angle ``theta``
    (radians, in [0, pi/2]): the Gaussian ``exp(-(theta - cone)^2 / (2 spread^2))`` wrapped
    modulo pi and mirrored about the pole, so that it is even about the pole and about the
    horizon (a flake's axis at ``theta`` and at ``pi - theta`` is the same flake)."""
    theta = np.asarray(theta, float)
    total = np.zeros_like(theta)
    for k in range(-2, 3):
        for centre in (cone, -cone):
            total = total + np.exp(-0.5 * ((theta - centre + np.pi * k) / spread) ** 2)
    return total


def cone_distribution(cos_h, cone_deg: float, spread_deg: float, points: int = CONE_POINTS):
    """Flake normals on a cone about the vertical, 1/sr, at the normal's ``|cos|``
    ``cos_h``: density per solid angle ``exp(-(theta - cone)^2 / (2 spread^2))`` in the
    normal's polar angle ``theta`` (wrapped and mirrored, :func:`_cone_weight`), uniform in
    azimuth, normalised as :func:`ggx_distribution` is (``Int_H D cos dm = 1``: the flakes'
    projected area seen from straight above is 1).  Lanza et al. 2024 (their pbrt-v4 plugin,
    ``media.h``, ``SGGXPhaseFunctionMixedRefl::SampleMicroflakeOrientation``) tilt each flake
    by a Gaussian angle (``means_or``, ``stds_or``, degrees) about one fixed horizontal axis;
    here the tilt's azimuth is uniform (a film has no preferred direction), and the spread is
    the whole of the normals' spread (their flakes add an SGGX roughness of their own)."""
    cone = np.radians(cone_deg)
    spread = np.radians(spread_deg)
    theta, weight = gauss_legendre(points, 0.0, 0.5 * np.pi)
    norm = 2.0 * np.pi * np.sum(weight * _cone_weight(theta, cone, spread)
                                * np.cos(theta) * np.sin(theta))
    polar = np.arccos(np.clip(np.abs(np.asarray(cos_h, float)), 0.0, 1.0))
    return _cone_weight(polar, cone, spread) / norm


def projected_area(mu, distribution, points: int = CONE_POINTS):
    """Projected area ``Int_H |w.m| D(m) dm`` of two-sided flakes whose normals follow the
    azimuthally uniform ``distribution`` (a function of the normal's cosine, 1/sr, normalised
    as :func:`kernel_orders` takes it) seen along directions at cosines ``mu``: Gauss-Legendre
    in the normal's polar angle, the azimuth in closed form (``Int_0^2pi |a + b cos phi| dphi
    = 2 pi a - 4 a (pi - phi_0) + 4 b sin phi_0``, ``cos phi_0 = -a / b``, for ``0 <= a < b``;
    ``2 pi a`` for ``a >= b``).  For GGX it is :func:`flake_extinction`."""
    mu = np.asarray(mu, float)[..., None]
    theta, weight = gauss_legendre(points, 0.0, 0.5 * np.pi)
    a = mu * np.cos(theta)
    b = np.sqrt(np.maximum(1.0 - mu * mu, 0.0)) * np.sin(theta)
    ratio = np.where(b > a, a / np.maximum(b, 1e-300), 1.0)
    phi0 = np.arccos(-ratio)
    ring = (2.0 * np.pi * a - 4.0 * a * (np.pi - phi0)
            + 4.0 * b * np.sqrt(np.maximum(1.0 - ratio * ratio, 0.0)))
    return np.sum(weight * np.sin(theta) * distribution(np.cos(theta)) * ring, axis=-1)


def transport_generator(grid: HemisphereGrid, albedo, forward, back, extinction=None):
    """The slab generator (:func:`~lut_baker.numerics.adding_doubling.generator_from_matrices`,
    thickness in units of the spheres' extinction) of a medium of single-scattering albedo
    ``albedo`` ``(C,)``, extinction ``extinction`` per node (relative, default 1: isotropic)
    and scattering coefficients ``forward``, ``back`` per unit of it (:func:`phase_orders`,
    :func:`flake_orders`; ``(orders, N, N)``, or per channel with the albedo in them and
    ``albedo`` ones): its transport matrices, loss ``e / mu - a p_forward`` and
    back-scattering ``a p_back`` in the star form."""
    mu = np.cos(grid.theta)
    e = np.ones(mu.size) if extinction is None else np.asarray(extinction, float)
    s = AD.star_scale(grid)
    k = s[:, :, None] * s[:, None, :] / np.outer(mu, mu)
    single = np.asarray(albedo, float)[:, None, None, None]
    loss = np.diag(e / mu) - single * forward * k
    scatter = single * back * k
    return AD.generator_from_matrices(0.5 * (loss + scatter), 0.5 * (loss - scatter))


def thick_medium(grid: HemisphereGrid, albedo, forward, back, extinction=None) -> np.ndarray:
    """Reflection (star form on ``grid``, ``(C, orders, N, N)``) of the infinitely thick medium
    of :func:`transport_generator` (the slab's limit,
    :func:`~lut_baker.numerics.adding_doubling.thick_slab`)."""
    return AD.thick_slab(transport_generator(grid, albedo, forward, back, extinction))


def under_surface(body: np.ndarray, surface_albedo: np.ndarray) -> np.ndarray:
    """The medium's reflection seen through the surface, star form on the outside grid
    ``(C, orders, N, N)``: ``T (I - R rho)^-1 R T^T`` with ``R`` = ``body`` (on the
    :func:`refracted_grid`, its first N nodes the refracted ones), ``T = [diag(1 - a_g), 0]``
    and ``rho`` the surface from inside, specular, ``a_g`` on the refracted nodes and 1 beyond
    the critical angle (the mirror's ``(-1)^m`` per order)."""
    n_out = surface_albedo.shape[-1]
    n_in = body.shape[-1]
    orders = body.shape[-3]
    inside = np.concatenate([surface_albedo, np.ones(n_in - n_out)])
    rho = AD.mirror(inside, orders)
    eye = np.eye(n_in)
    body_seen = np.linalg.solve(eye - body @ rho, body)  # (I - R rho)^-1 R
    t = 1.0 - surface_albedo
    return t[:, None] * body_seen[..., :n_out, :n_out] * t[None, :]


@dataclass(frozen=True, eq=False)
class MatteSlab:
    """The model's parameters: ``albedo`` (single scattering, RGB, shared by the two kinds of
    particle), the spheres' phase function ``g1``, ``g2`` and the weight of ``g1`` (``weight``),
    the fraction of the extinction seen from above that is due to flakes (``flakes``) and their
    GGX roughness (``flake_alpha``) or, if ``cone_spread_deg > 0``, their normals on a cone
    (:func:`cone_distribution`: ``cone_deg`` from the vertical, spread ``cone_spread_deg``; a
    share ``flat`` of them lying flat instead, their normals about the vertical with the spread
    ``flat_spread_deg``), the flakes' own single-scattering albedo (``flake_albedo``; None:
    ``albedo``), the surface's index ``eta`` (1: no surface), its GGX roughness ``alpha`` and
    the fraction of the area it covers (``coverage``; the rest is the bare medium, in patches
    wider than the light's path in the medium: :func:`matte_slab_kernel`), and optionally a
    second kind of surface patch, roughness ``alpha2`` over ``coverage2`` of the area; a top
    layer of the medium ``top_thickness`` thick absorbing ``top_absorption`` times as much
    (:func:`medium_reflection`); the medium ``thickness`` thick over a black base (0: infinitely
    thick; a drawdown thin enough that light reaches what it is drawn on)."""

    albedo: np.ndarray
    g1: float = 0.0
    g2: float = 0.0
    weight: float = 1.0
    flakes: float = 0.0
    flake_alpha: float = 0.5
    cone_deg: float = 0.0
    cone_spread_deg: float = 0.0
    flat: float = 0.0
    flat_spread_deg: float = 20.0
    flake_albedo: np.ndarray | None = None
    eta: float = 1.0
    alpha: float = 0.3
    coverage: float = 1.0
    alpha2: float = 0.3
    coverage2: float = 0.0
    top_thickness: float = 0.0
    top_absorption: float = 1.0
    thickness: float = 0.0

    def surface_patches(self) -> list[tuple[float, float]]:
        """``(alpha, coverage)`` of each kind of surface patch: ``alpha`` over ``coverage`` and,
        if ``coverage2 > 0``, a second roughness ``alpha2`` over ``coverage2`` (the bare medium
        over the rest)."""
        patches = [(float(self.alpha), float(self.coverage))]
        if self.coverage2 > 0.0:
            patches.append((float(self.alpha2), float(self.coverage2)))
        return patches


def medium_generator(grid: HemisphereGrid, model: MatteSlab):
    """The medium's slab generator (:func:`transport_generator`): spheres (two-lobe HG,
    extinction the same every way) and flakes (GGX or on a cone: :func:`kernel_orders`,
    :func:`projected_area`) mixed, the flakes ``model.flakes`` of the extinction seen from
    above, each kind with its single-scattering albedo."""
    forward, back = phase_orders(grid, model.g1, model.g2, model.weight)
    f = float(model.flakes)
    extinction = np.ones(grid.theta.size)
    albedo = np.asarray(model.albedo, float)
    if f > 0.0:
        mu = np.cos(grid.theta)
        if model.cone_spread_deg > 0.0:
            def distribution(cos_h):
                tilted = cone_distribution(cos_h, model.cone_deg, model.cone_spread_deg)
                if model.flat <= 0.0:
                    return tilted
                flat = cone_distribution(cos_h, 0.0, model.flat_spread_deg)
                return (1.0 - model.flat) * tilted + model.flat * flat

            flake_forward, flake_back = kernel_orders(grid, distribution)
            flake_area = projected_area(mu, distribution)
        else:
            flake_forward, flake_back = flake_orders(grid, model.flake_alpha)
            flake_area = flake_extinction(mu, model.flake_alpha)
        extinction = (1.0 - f) + f * flake_area
        if model.flake_albedo is None:
            forward = (1.0 - f) * forward + f * flake_forward
            back = (1.0 - f) * back + f * flake_back
        else:
            # Each kind scatters with its own albedo: the albedo goes into the kernels.
            spheres = albedo[:, None, None, None] * (1.0 - f)
            flakes = np.asarray(model.flake_albedo, float)[:, None, None, None] * f
            forward = spheres * forward + flakes * flake_forward
            back = spheres * back + flakes * flake_back
            albedo = np.ones(albedo.size)
    return transport_generator(grid, albedo, forward, back, extinction)


def medium_reflection(grid: HemisphereGrid, model: MatteSlab) -> np.ndarray:
    """The medium's reflection (star form on ``grid``): :func:`medium_generator`'s
    infinite-thickness limit or, if ``model.thickness`` > 0, the medium that thick over a black
    base (nothing returns from below it); under a top layer of the same particles absorbing
    ``model.top_absorption`` times as much (single-scattering albedo ``1 - k (1 - albedo)``),
    ``model.top_thickness`` thick (units of the spheres' extinction), if that is > 0."""
    generator = medium_generator(grid, model)
    body = (AD.slab(generator, model.thickness)[0] if model.thickness > 0.0
            else AD.thick_slab(generator))
    if not model.top_thickness > 0.0:
        return body
    top_albedo = 1.0 - model.top_absorption * (1.0 - np.asarray(model.albedo, float))
    top = replace(model, albedo=top_albedo, top_thickness=0.0)
    r, t = AD.slab(medium_generator(grid, top), model.top_thickness)
    # The medium is even in the vertical (HG and two-sided flakes): the top layer reflects the
    # same from below; only the body's reflection from above counts beneath it (what leaves it
    # downward is lost, into the thick medium or the black base).
    return AD.add_layers(AD.Layer(top=r, bottom=r, down=t),
                         AD.Layer(top=body, bottom=body, down=np.zeros_like(body)),
                         symmetric=True).top


def matte_slab_kernel(grid: HemisphereGrid, model: MatteSlab, tir_points: int = 8):
    """``(kernel, a_g)``: the light the medium returns (through the surface, if ``eta > 1``) as
    a kernel per channel and order on ``grid`` (1/sr, ``(C, orders, N, N)``; the surface's own
    reflection, :func:`ggx_reflection` times each patch's coverage, is added in closed form
    where it is read) and the surface's directional albedo at the nodes, each patch's by its
    coverage ``(N,)`` (zeros without a surface).  A partial surface (coverages below 1,
    :meth:`MatteSlab.surface_patches`) is patches of surface and of bare medium each wide
    enough that light leaves by the patch it entered: their reflections weighted by their
    areas."""
    scale = AD.star_scale(grid)
    if not model.eta > 1.0:
        return AD.from_star(medium_reflection(grid, model), scale), np.zeros(grid.theta.size)
    inside = refracted_grid(grid, model.eta, tir_points)
    body = medium_reflection(inside, model)
    patches = model.surface_patches()
    albedos = [ggx_albedo(np.cos(grid.theta), alpha, model.eta) for alpha, _ in patches]
    star = sum(w * under_surface(body, a) for (_, w), a in zip(patches, albedos, strict=True))
    a_g = sum(w * a for (_, w), a in zip(patches, albedos, strict=True))
    bare = 1.0 - sum(w for _, w in patches)
    if bare > 0.0:
        star = star + bare * medium_reflection(grid, model)
    return AD.from_star(np.asarray(star), scale), np.asarray(a_g)
