"""Comparing rendered sphere images with the reference images of :mod:`lut_baker.reference`.

Pure numpy: the Blender side (``bench/blender_scene.py``) renders, this module measures.  An
image is ``(n, n, 3)`` float, rows top-down as :func:`lut_baker.reference.sphere_points` lays
them out; a render read from Blender (rows bottom-up) goes through :func:`from_blender_pixels`.

Error measures (issue 5, item 2), all over the sphere's pixels (:func:`sphere_mask`), every
channel pooled, relative to the reference's RMS there:

- error ``e = rms(image - reference) / rms(reference)``;
- Monte Carlo noise floor ``s = rms(a - b) / sqrt(2) / rms(reference)`` from two renders with
  different seeds: the noise of one image (the difference holds the noise twice);
- excess over the floor ``e - s`` (what issue 5's goal bounds) and the bias estimate
  ``sqrt(max(e^2 - s^2, 0))`` (noise and bias add in quadrature).

Functions
---------
- :func:`sphere_mask` -- the pixels whose centre sees the sphere.
- :func:`from_blender_pixels` -- a flat RGBA pixel buffer from Blender as a top-down image.
- :func:`relative_rms`, :func:`noise_floor`, :func:`bias` -- the measures above.
- :func:`lambert_image` -- the analytic image of a Lambertian sphere, ``E a / pi max(0, N.L)``.
- :func:`reference_image` -- the made-up sphere's reference, exact or with paths 1 + 3 read
  from baked tables (same geometry and spread as :func:`lut_baker.reference.sphere_image`).
- :func:`made_up_diffuse_albedo` -- the diffuse colour of the made-up skin from its tables.
- :func:`diffuse_mean_free_path_mm` -- the dipole's ``1 / sigma_tr`` per channel.
- :func:`ts_roughness` -- the Blender Roughness of a Torrance-Sparrow lobe by a simple rule.
- :func:`baseline_inputs` -- the stock Principled BSDF a user would set up without the add-on.
- :func:`pareto_front` -- the points no other point beats in both cost and error.
"""

from __future__ import annotations

import numpy as np

from . import reference
from .model import Dipole
from .normalise import MadeUpSkin

__all__ = [
    "sphere_mask",
    "from_blender_pixels",
    "relative_rms",
    "noise_floor",
    "bias",
    "lambert_image",
    "reference_image",
    "made_up_diffuse_albedo",
    "diffuse_mean_free_path_mm",
    "ts_roughness",
    "baseline_inputs",
    "pareto_front",
]


def sphere_mask(resolution: int) -> np.ndarray:
    """``(n, n)`` booleans: pixel centres inside the sphere's disk (the reference's mask)."""
    return reference.sphere_points(resolution, 1.0)[2]


def from_blender_pixels(pixels, resolution: int) -> np.ndarray:
    """Blender's flat RGBA buffer (``image.pixels``, rows bottom-up) as an ``(n, n, 3)``
    float64 image with rows top-down, like the reference's."""
    flat = np.asarray(pixels, dtype=np.float64)
    if flat.size != resolution * resolution * 4:
        raise ValueError(f"expected {resolution}x{resolution} RGBA pixels, got {flat.size} values")
    return flat.reshape(resolution, resolution, 4)[::-1, :, :3].copy()


def _masked(image, mask) -> np.ndarray:
    image = np.asarray(image, dtype=np.float64)
    if image.shape[:2] != mask.shape:
        raise ValueError(f"image {image.shape} does not match the mask {mask.shape}")
    return image[mask]


def _reference_rms(ref, mask) -> float:
    level = float(np.sqrt(np.mean(np.square(_masked(ref, mask)))))
    if not level > 0.0:
        raise ValueError("the reference is black over the sphere: no relative error")
    return level


def _mask_for(ref, mask) -> np.ndarray:
    return sphere_mask(np.shape(ref)[0]) if mask is None else np.asarray(mask, bool)


def _rms_difference(a, b, mask) -> float:
    return float(np.sqrt(np.mean(np.square(_masked(a, mask) - _masked(b, mask)))))


def relative_rms(image, ref, mask=None) -> float:
    """``rms(image - ref) / rms(ref)`` over the sphere's pixels (``mask``, default
    :func:`sphere_mask`), channels pooled."""
    mask = _mask_for(ref, mask)
    return _rms_difference(image, ref, mask) / _reference_rms(ref, mask)


def noise_floor(image_a, image_b, ref, mask=None) -> float:
    """The Monte Carlo noise of one render relative to ``ref``: ``rms(a - b) / sqrt(2) /
    rms(ref)`` for two renders ``a``, ``b`` that differ only in their seed."""
    mask = _mask_for(ref, mask)
    return _rms_difference(image_a, image_b, mask) / np.sqrt(2.0) / _reference_rms(ref, mask)


def bias(error: float, floor: float) -> float:
    """The part of a relative error that is not noise: ``sqrt(max(e^2 - s^2, 0))``."""
    return float(np.sqrt(max(error * error - floor * floor, 0.0)))


def lambert_image(resolution: int, light_angle_deg: float, albedo: float = 0.8,
                  irradiance: float = 1.0) -> np.ndarray:
    """The analytic image of a Lambertian sphere: ``E albedo / pi max(0, N.L)`` per pixel
    centre (the light ``light_angle_deg`` degrees from the view), ``(n, n, 3)``."""
    _, normals, mask = reference.sphere_points(resolution, 1.0)
    cosine = np.clip(normals @ reference.light_direction(light_angle_deg), 0.0, None)
    value = np.where(mask, irradiance * albedo / np.pi * cosine, 0.0)
    return np.repeat(value[..., None], 3, axis=-1)


def reference_image(skin: MadeUpSkin, *, tables=None, resolution: int = 64,
                    radius_mm: float = 10.0, light_angle_deg: float = 45.0,
                    irradiance: float = 1.0, spread: bool = True,
                    samples: int | None = None) -> np.ndarray:
    """The reference image ``(n, n, 3)`` of :func:`lut_baker.reference.sphere_image`.

    ``tables=None``: exactly that (paths 1 + 3 by the exact evaluator, ~20 ms per pixel).
    ``tables`` (baked from ``skin``): paths 1 + 3 interpolated from them instead
    (:meth:`lut_baker.tables.Tables.made_up_reflection`, error <= 1e-3 of the peak at the
    "default" and "high" resolutions, docs/baking.md), everything else the same: the
    skin-diffuse part is spread by :func:`lut_baker.reference.spread_diffuse` when
    ``spread``.  ``tests/test_render_compare.py`` checks that the two agree."""
    if tables is None:
        return reference.sphere_image(skin, resolution=resolution, radius_mm=radius_mm,
                                      light_angle_deg=light_angle_deg, irradiance=irradiance,
                                      spread=spread, samples=samples)
    _, normals, mask = reference.sphere_points(resolution, radius_mm)
    light = reference.light_direction(light_angle_deg)
    points = normals[mask]
    wi = reference.local_directions(np.broadcast_to(light, points.shape), points)
    wo = reference.local_directions(np.broadcast_to(reference.VIEW, points.shape), points)
    lit = (wi[:, 2] > 0.0) & (wo[:, 2] > 0.0)
    radiance = np.zeros(points.shape)
    f = tables.made_up_reflection(wi[lit], wo[lit], skin.coverage, skin.absorption)
    radiance[lit] = irradiance * f * wi[lit, 2:3]
    if spread:
        samples = samples or reference.default_samples(skin, radius_mm)
        radiance = (radiance - reference.local_diffuse(points, light, skin, irradiance)
                    + reference.spread_diffuse(points, light, skin, radius_mm=radius_mm,
                                               samples=samples, irradiance=irradiance))
    image = np.zeros((resolution, resolution, 3))
    image[mask] = radiance
    return image


def made_up_diffuse_albedo(tables, coverage=None, absorption=None,
                           theta_deg: float = 0.0) -> np.ndarray:
    """The diffuse albedo (RGB) of the made-up skin lit from ``theta_deg`` (degrees; default
    head-on, the colour a user would measure), from baked ``tables`` (:mod:`lut_baker.tables`)::

        w [(1 - A) pi P_d,f + (1 - A)^2 P_d,s T(theta) Int T cos dw] + (1 - w) pi P_d,s

    ``coverage`` ``w`` and ``absorption`` ``A`` default to the tables'."""
    w = float(tables.parameters.get("coverage", 1.0) if coverage is None else coverage)
    a = tables.parameters.get("absorption", 0.0) if absorption is None else absorption
    through = 1.0 - np.broadcast_to(np.asarray(a, float), (3,))
    film = np.pi * np.asarray(tables.film_diffuse, float)
    skin = np.asarray(tables.skin_diffuse, float)
    crossing = tables.directional("film_transmittance", theta_deg) * np.asarray(
        tables.film_transmittance_integral, float)
    return w * (through * film + through**2 * skin * crossing) + (1.0 - w) * np.pi * skin


def diffuse_mean_free_path_mm(dipole: Dipole) -> np.ndarray:
    """``1 / sigma_tr`` (mm) per channel, ``sigma_tr = sqrt(3 sigma_a sigma_t')``,
    ``sigma_t' = sigma_s (1 - g) + sigma_a`` (Jensen et al. 2001): the length over which the
    dipole's profile falls by ``e`` far from the light (SPEC 2.3)."""
    reduced = np.asarray(dipole.sigma_s) * (1.0 - np.asarray(dipole.g)) + np.asarray(
        dipole.sigma_a)
    sigma_tr = np.sqrt(3.0 * np.asarray(dipole.sigma_a) * reduced)
    return np.broadcast_to(1.0 / sigma_tr, (3,)).astype(float)


def ts_roughness(n_per_deg) -> float:
    """Blender Roughness for a Torrance-Sparrow lobe ``D = exp(-(alpha n)^2)`` (alpha in
    degrees, SPEC 2.1), by the rule a user would apply: near the peak a Beckmann lobe is
    ``exp(-tan^2(alpha) / m^2) ~ exp(-(alpha / m)^2)`` with ``alpha`` in radians, so the slope
    ``m`` is the lobe's 1/e half-width ``1/n`` degrees in radians; GGX alpha = m, and Blender's
    Roughness is ``sqrt(alpha)``.  Clamped to [0, 1]; channels averaged."""
    width_rad = np.radians(1.0 / float(np.mean(n_per_deg)))
    return float(np.clip(np.sqrt(width_rad), 0.0, 1.0))


def baseline_inputs(skin: MadeUpSkin, diffuse_albedo) -> dict:
    """The stock Principled BSDF a user would set up for ``skin`` without the add-on (socket
    name -> value; ``Subsurface Radius`` in mm, the caller sets ``Subsurface Scale`` to scene
    units per mm).  The rule, one line per socket:

    - Base Color = ``diffuse_albedo`` (RGB): the made-up skin's diffuse colour
      (:func:`made_up_diffuse_albedo`: film diffuse + skin seen through the film + bare skin by
      coverage), clamped to [0, 1];
    - Roughness, IOR = the skin gloss's :func:`ts_roughness` and ``eta``; Specular IOR Level
      0.5 (F0 from the IOR, the Torrance-Sparrow ``P_s`` has no socket);
    - Coat Weight = coverage ``w``; Coat Roughness, Coat IOR = the film's :func:`ts_roughness`
      and ``eta``;
    - Subsurface Weight 1, Subsurface Radius = :func:`diffuse_mean_free_path_mm` of the skin's
      dipole; the Principled's default method (Random Walk, whose index is the IOR above:
      Subsurface IOR is a socket of Random Walk Skin only).
    """
    albedo = np.clip(np.broadcast_to(np.asarray(diffuse_albedo, float), (3,)), 0.0, 1.0)
    return {
        "Base Color": tuple(float(a) for a in albedo),
        "Roughness": ts_roughness(skin.skin.n),
        "IOR": float(np.mean(skin.skin.eta)),
        "Specular IOR Level": 0.5,
        "Coat Weight": float(skin.coverage),
        "Coat Roughness": ts_roughness(skin.film.n),
        "Coat IOR": float(np.mean(skin.film.eta)),
        "Subsurface Weight": 1.0,
        "Subsurface Radius": tuple(float(r) for r in diffuse_mean_free_path_mm(skin.dipole)),
    }


def pareto_front(cost, error) -> np.ndarray:
    """Booleans: the points that no other point beats, i.e. none has ``cost <=`` and ``error
    <=`` with one of them strictly less (both minimised).  NaN points are never on it."""
    cost, error = np.asarray(cost, float), np.asarray(error, float)
    if cost.shape != error.shape or cost.ndim != 1:
        raise ValueError("cost and error must be 1-D arrays of one length")
    valid = np.isfinite(cost) & np.isfinite(error)
    c, e = cost[:, None], error[:, None]
    dominated = ((cost[None, :] <= c) & (error[None, :] <= e)
                 & ((cost[None, :] < c) | (error[None, :] < e)) & valid[None, :])
    return valid & ~np.any(dominated, axis=1)
