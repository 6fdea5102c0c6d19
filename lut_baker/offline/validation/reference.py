"""Reference images of the exact model: a sphere under a distant light.

The scene: a sphere of radius ``radius_mm`` seen by an orthographic camera looking down -z
(every view direction is +z), one distant light from direction ``light`` with irradiance
``irradiance`` (radiance units per 1/sr, e.g. W/m^2), black surroundings.  Per pixel centre the
radiance of paths 1 + 3 (docs/model.md §3, eq. 9) is evaluated exactly.  With ``spread=True`` the
skin's diffuse part of path 3 -- ``w (1 - A)^2 P_d,s T(wi) T(wo) E cos(theta_i)`` -- is not returned
where it entered but spread over the lit surface by the dipole's normalised profile
``R(d) / Rd`` (docs/model.md §4), with the chord distance between surface points.

Functions
---------
- :func:`sphere_points` -- pixel centres on the sphere: positions (mm), normals, mask (the
  framing of :mod:`lut_baker.numerics.geometry`, which also takes world directions into each
  point's tangent frame).
- :func:`fibonacci_sphere` -- near-uniform surface samples with equal areas (mm^2).
- :func:`local_radiance` -- radiance of paths 1 + 3 at each point (nothing spread).
- :func:`local_diffuse` -- the skin-diffuse part of paths 1 + 3 where it entered.
- :func:`spread_sums` -- the dipole profile's spread of the light entering the lit sphere, through
  a film's transmittance given and through bare skin (k-d tree over samples).
- :func:`spread_diffuse` -- the skin-diffuse part spread by the dipole profile (the paper's film).
- :func:`default_samples` -- entry samples fine enough for the profile's depth scale.
- :func:`sphere_image` -- the whole image, ``(n, n, 3)``.
- :func:`spread_convergence` -- relative change of the spread image when samples double.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...evaluate.made_up import made_up_reflection
from ...model.albedo import film_transmittance
from ...model.dipole import dipole_profile, dipole_total_reflectance
from ...model.made_up_skin import (
    MadeUpSkin,
    combine,
    coverage_weights,
    film_transmission_layer,
)
from ...numerics.cache import LRUCache
from ...numerics.geometry import VIEW, direction, light_direction, local_directions, sphere_normals
from ...numerics.quadrature import cumulative_trapezoid

if TYPE_CHECKING:
    from scipy.spatial import cKDTree

__all__ = [
    "sphere_points",
    "fibonacci_sphere",
    "local_radiance",
    "local_diffuse",
    "default_samples",
    "spread_sums",
    "spread_diffuse",
    "sphere_image",
    "spread_convergence",
    "profile_cutoff_mm",
]


def sphere_points(resolution: int, radius_mm: float):
    """Pixel centres of a ``resolution`` x ``resolution`` image spanning the sphere's disk.

    Returns ``(positions_mm (n, n, 3), normals (n, n, 3), mask (n, n))``; rows run top-down
    (+y first) as images do.  Outside the disk positions and normals are 0.
    """
    if resolution < 1 or not radius_mm > 0:
        raise ValueError("resolution must be >= 1 and radius_mm > 0 (mm)")
    normals, mask = sphere_normals(resolution)
    return normals * radius_mm, normals, mask


def fibonacci_sphere(count: int, radius_mm: float):
    """``count`` near-uniform points on the sphere: ``(positions_mm, normals, area_mm2)``."""
    i = np.arange(count) + 0.5
    z = 1.0 - 2.0 * i / count
    phi = np.pi * (1.0 + 5.0**0.5) * i
    r = np.sqrt(1.0 - z * z)
    normals = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)
    return normals * radius_mm, normals, 4.0 * np.pi * radius_mm**2 / count


def local_radiance(normals: np.ndarray, light: np.ndarray, skin: MadeUpSkin,
                   irradiance: float = 1.0, *, level: int = 0) -> np.ndarray:
    """Radiance of paths 1 + 3 at points with ``normals`` (P, 3): ``E f(wi, wo) cos(theta_i)``
    with the exact evaluator; 0 where the light is below the horizon.  Shape (P, 3)."""
    wi = local_directions(np.broadcast_to(light, normals.shape), normals)
    wo = local_directions(np.broadcast_to(VIEW, normals.shape), normals)
    lit = (wi[:, 2] > 0.0) & (wo[:, 2] > 0.0)
    out = np.zeros(normals.shape[:-1] + (3,))
    if np.any(lit):
        f = made_up_reflection(wi[lit], wo[lit], skin, level=level)
        out[lit] = irradiance * f * wi[lit, 2:3]
    return out


EXIT_CHUNK = 64
"""Exit points whose neighbour lists are held at once (bounds memory)."""


def profile_cutoff_mm(skin: MadeUpSkin, lost_fraction: float = 1e-3) -> float:
    """Distance (mm) within which the dipole profile holds all but ``lost_fraction`` of its
    total ``Rd = 2 pi Int R(d) d dd`` in every channel."""
    d = np.concatenate([[0.0], np.geomspace(1e-4, 1e4, 4000)])
    profile = np.reshape(dipole_profile(d, skin.dipole), (d.size, -1))
    captured = 2.0 * np.pi * cumulative_trapezoid(profile * d[:, None], d)
    rd = np.reshape(dipole_total_reflectance(skin.dipole), (1, -1))
    inside = np.all(captured >= (1.0 - lost_fraction) * rd, axis=1)
    return float(d[1:][np.argmax(inside)]) if np.any(inside) else float(d[-1])


TRANSMITTANCE_NODES = 1025
"""Polar nodes (0..90 degrees) on which ``T`` is tabulated once and interpolated: T is smooth,
so the interpolation error (< 1e-7 relative) stays far below the reference's tolerance."""


_TRANSMITTANCE_CACHE = LRUCache(8)
"""``T`` on the polar nodes per film layer (keyed by its parameters, at most 8 kept): the
tabulation takes seconds and one spread image needs it four times."""


def _film_transmittance_rgb(local: np.ndarray, skin: MadeUpSkin) -> np.ndarray:
    """``(1 - A) T(w)`` per point for local directions (P, 3): the film crossed once, RGB."""
    film_transmission = film_transmission_layer(skin)
    theta = np.linspace(0.0, np.pi / 2, TRANSMITTANCE_NODES)
    nodes = _TRANSMITTANCE_CACHE.get_or_compute(repr(film_transmission.as_dict()),
                                                lambda: np.reshape(
        film_transmittance(direction(theta, 0.0), film_transmission), (theta.size, -1)))
    polar = np.arccos(np.clip(local[:, 2], 0.0, 1.0))
    t = np.stack([np.interp(polar, theta, nodes[:, c % nodes.shape[1]]) for c in range(3)], -1)
    return np.where(local[:, 2:3] > 0.0, t, 0.0)


def local_diffuse(normals: np.ndarray, light: np.ndarray, skin: MadeUpSkin,
                  irradiance: float = 1.0) -> np.ndarray:
    """The skin-diffuse part of paths 1 + 3 where it entered (docs/model.md §4), radiance (P, 3):
    ``P_d,s [w T_A(wi) T_A(wo) + (1 - w)] E cos(theta_i)`` with ``T_A = (1 - A) T`` (the
    weights of :func:`~lut_baker.model.made_up_skin.coverage_weights`)."""
    wi = local_directions(np.broadcast_to(light, normals.shape), normals)
    wo = local_directions(np.broadcast_to(VIEW, normals.shape), normals)
    through = _film_transmittance_rgb(wi, skin) * _film_transmittance_rgb(wo, skin)
    lit = ((wi[:, 2] > 0.0) & (wo[:, 2] > 0.0))[:, None]
    # T_A holds the absorption already: the light through the film is "top".
    weights = coverage_weights(skin.coverage, skin.absorption)
    p_d = np.asarray(skin.skin_reflection.P_d) * np.ones(3)
    return np.where(lit, combine(weights, top=p_d * through, bare=p_d) * irradiance
                    * wi[:, 2:3], 0.0)


def spread_sums(exit_normals: np.ndarray, light: np.ndarray, skin: MadeUpSkin,
                transmittance, *, radius_mm: float, samples: int,
                irradiance: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The spread under the skin (docs/model.md §4) at exit points with ``exit_normals``
    (P, 3), before the skin's albedo: ``(through, bare)``, each (P, 3)::

        through(x_o) = t(wo) sum_i E cos(theta_i) t(wi) R(|x_i - x_o|)/Rd dA
        bare(x_o)    =       sum_i E cos(theta_i)       R(|x_i - x_o|)/Rd dA

    over ``samples`` Fibonacci entry points on the lit sphere within the profile's cutoff,
    found with a k-d tree (chord distances, mm); ``transmittance(local (N, 3)) -> (N, 3)`` is
    the film's on the way in and out (the same function both ways: reciprocity), at the
    entry's local light direction and the exit's local view direction.  0 where the exit
    faces away from the view.  The paper's film (:func:`spread_diffuse`) and the film as a
    slab (:func:`lut_baker.offline.validation.compare.slab_reference_image`) weight the two
    sums by their coverage and albedo terms."""
    entry_pos, entry_normals, area = fibonacci_sphere(samples, radius_mm)
    cos_i = entry_normals @ light
    lit = cos_i > 0.0
    entry_pos, entry_normals, cos_i = entry_pos[lit], entry_normals[lit], cos_i[lit]
    power = (irradiance * cos_i * area)[:, None]  # (I, 1)
    entry_film = transmittance(
        local_directions(np.broadcast_to(light, entry_normals.shape), entry_normals))
    exit_local = local_directions(np.broadcast_to(VIEW, exit_normals.shape), exit_normals)
    exit_film = transmittance(exit_local)
    rd = np.atleast_1d(dipole_total_reflectance(skin.dipole)) * np.ones(3)
    from scipy.spatial import cKDTree  # here: importing scipy.spatial takes ~0.3 s

    tree = cKDTree(entry_pos)
    exit_pos = exit_normals * radius_mm
    cutoff = profile_cutoff_mm(skin)
    through = np.zeros((exit_pos.shape[0], 3))
    bare = np.zeros((exit_pos.shape[0], 3))
    for start in range(0, exit_pos.shape[0], EXIT_CHUNK):
        chunk = slice(start, start + EXIT_CHUNK)
        owner, neighbours = _pairs_within(tree, entry_pos, exit_pos[chunk], cutoff)
        if owner.size == 0:
            continue
        d = np.linalg.norm(entry_pos[neighbours] - exit_pos[chunk][owner], axis=-1)
        kernel = np.reshape(dipole_profile(d, skin.dipole), (d.size, -1)) / rd
        kernel = kernel * power[neighbours]
        rows = exit_pos[chunk].shape[0]
        for c in range(3):
            k = kernel[:, c % kernel.shape[1]]
            bare[chunk, c] = np.bincount(owner, k, rows)
            through[chunk, c] = np.bincount(owner, k * entry_film[neighbours, c], rows)
    facing = exit_local[:, 2:3] > 0.0
    return np.where(facing, exit_film * through, 0.0), np.where(facing, bare, 0.0)


def spread_diffuse(exit_normals: np.ndarray, light: np.ndarray, skin: MadeUpSkin, *,
                   radius_mm: float, samples: int, irradiance: float = 1.0) -> np.ndarray:
    """The skin-diffuse part after spreading under the surface (docs/model.md §4), radiance (P, 3)::

        L(x_o) = P_d,s sum_i E cos(theta_i) [w T_A(wi) T_A(wo) + (1 - w)] R(|x_i - x_o|)/Rd dA

    (:func:`spread_sums` with ``T_A = (1 - A) T``).  Entry and exit through the film and
    through bare skin are summed apart, so the coverage mix is the one of
    :func:`local_diffuse`.
    """
    through, bare = spread_sums(exit_normals, light, skin,
                                lambda local: _film_transmittance_rgb(local, skin),
                                radius_mm=radius_mm, samples=samples, irradiance=irradiance)
    weights = coverage_weights(skin.coverage, skin.absorption)
    p_d = np.asarray(skin.skin_reflection.P_d) * np.ones(3)
    return combine(weights, top=p_d * through, bare=p_d * bare)


def _pairs_within(tree: cKDTree, entry_pos: np.ndarray, exit_pos: np.ndarray, cutoff: float):
    """Index pairs ``(exit, entry)`` closer than ``cutoff`` (mm).  The k-d tree prunes when
    the cutoff is small against the sphere; when it would return most points anyway, a dense
    chunked distance test is faster than building Python lists."""
    if cutoff**2 < 0.05 * tree.maxes.max() ** 2:  # the cutoff disk covers < ~5% of the box
        lists = tree.query_ball_point(exit_pos, r=cutoff, return_sorted=False)
        counts = np.array([len(n) for n in lists], dtype=np.intp)
        owner = np.repeat(np.arange(counts.size), counts)
        neighbours = np.fromiter((i for n in lists for i in n), np.intp, counts.sum())
        return owner, neighbours
    d2 = np.sum((exit_pos[:, None, :] - entry_pos[None, :, :]) ** 2, axis=-1)
    return np.nonzero(d2 < cutoff * cutoff)


def default_samples(skin: MadeUpSkin, radius_mm: float, per_mean_free_path: float = 3.0) -> int:
    """Entry samples so that their spacing is ``z_r / per_mean_free_path`` (z_r = 1/sigma_t',
    the dipole's real-source depth in mm, of the channel that scatters the shortest)."""
    reduced = skin.dipole.sigma_s * (1.0 - skin.dipole.g) + skin.dipole.sigma_a
    spacing = 1.0 / float(np.max(reduced)) / per_mean_free_path
    return int(np.ceil(4.0 * np.pi * radius_mm**2 / spacing**2))


def sphere_image(skin: MadeUpSkin, *, resolution: int = 64, radius_mm: float = 50.0,
                 light_angle_deg: float = 45.0, irradiance: float = 1.0,
                 spread: bool = False, samples: int | None = None, level: int = 0):
    """Reference image ``(n, n, 3)`` of a made-up sphere (see the module docstring).

    ``spread=False``: every path returns where it entered (the local BRDF).  ``spread=True``:
    the skin-diffuse part is replaced by its spread over the surface with ``samples`` entry
    points (default :func:`default_samples`)."""
    _, normals, mask = sphere_points(resolution, radius_mm)
    light = light_direction(light_angle_deg)
    image = np.zeros((resolution, resolution, 3))
    points = normals[mask]
    radiance = local_radiance(points, light, skin, irradiance, level=level)
    if spread:
        samples = samples or default_samples(skin, radius_mm)
        radiance = (radiance - local_diffuse(points, light, skin, irradiance)
                    + spread_diffuse(points, light, skin, radius_mm=radius_mm, samples=samples,
                                     irradiance=irradiance))
    image[mask] = radiance
    return image


def spread_convergence(skin: MadeUpSkin, *, resolution: int = 32, radius_mm: float = 10.0,
                       light_angle_deg: float = 45.0, samples: int | None = None) -> float:
    """Relative RMS change of the spread image over the sphere when entry samples double: the
    reference's own convergence check."""
    samples = samples or default_samples(skin, radius_mm)
    _, normals, mask = sphere_points(resolution, radius_mm)
    light = light_direction(light_angle_deg)
    points = normals[mask]
    coarse = spread_diffuse(points, light, skin, radius_mm=radius_mm, samples=samples)
    fine = spread_diffuse(points, light, skin, radius_mm=radius_mm, samples=2 * samples)
    return float(np.sqrt(np.mean((coarse - fine) ** 2)) / np.sqrt(np.mean(fine**2)))
