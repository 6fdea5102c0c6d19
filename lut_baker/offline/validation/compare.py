"""Comparing rendered sphere images with the reference images of :mod:`.reference`.

Pure numpy: the Blender side (``tests/support/bench_scene.py``) renders, this module measures.  An
image is ``(n, n, 3)`` float, rows top-down as :func:`.reference.sphere_points` lays them
out; a render read from Blender (rows bottom-up) goes through :func:`from_blender_pixels`.

Error measures, all over the sphere's pixels (:func:`sphere_mask`), every
channel pooled, relative to the reference's RMS there:

- error ``e = rms(image - reference) / rms(reference)``;
- Monte Carlo noise floor ``s = rms(a - b) / sqrt(2) / rms(reference)`` from two renders with
  different seeds: the noise of one image (the difference holds the noise twice);
- excess over the floor ``e - s`` (what the speed/accuracy goals bound, docs/speed_accuracy.md) and
  the bias estimate ``sqrt(max(e^2 - s^2, 0))`` (noise and bias add in quadrature).

Functions
---------
- :func:`sphere_mask` -- the pixels whose centre sees the sphere.
- :func:`from_blender_pixels` -- a flat RGBA pixel buffer from Blender as a top-down image.
- :func:`relative_rms`, :func:`noise_floor`, :func:`bias` -- the measures above.
- :func:`lambert_image` -- the analytic image of a Lambertian sphere, ``E a / pi max(0, N.L)``.
- :func:`reference_image` -- the made-up sphere's reference, exact or with paths 1 + 3 read
  from baked tables (same geometry and spread as
  :func:`lut_baker.offline.validation.reference.sphere_image`); from tables holding the film as
  a slab, :func:`slab_reference_image`.
- :func:`slab_reference_image` -- the reference of made-up skin at a thickness (docs/model.md,
  "Made-up skin at a thickness"): the slab's BRDF from the tables, its diffuse term spread.
- :func:`local_image` -- the image of any local reflection function (no spread), at the
  pixels' local light and view directions
  (:func:`lut_baker.numerics.geometry.sphere_directions`).
- :func:`pareto_front` -- the points no other point beats in both cost and error.
"""

from __future__ import annotations

import numpy as np

from ...model.made_up_skin import MadeUpSkin, combine, coverage_weights
from ...numerics.geometry import light_direction, sphere_directions, sphere_normals
from ...tables.slab_tables import slab_diffuse, slab_reflection
from ..validation import reference

__all__ = [
    "sphere_mask",
    "from_blender_pixels",
    "relative_rms",
    "noise_floor",
    "bias",
    "lambert_image",
    "reference_image",
    "slab_reference_image",
    "local_image",
    "pareto_front",
]


def sphere_mask(resolution: int) -> np.ndarray:
    """``(n, n)`` booleans: pixel centres inside the sphere's disk (the reference's mask)."""
    return sphere_normals(resolution)[1]


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
    normals, mask = sphere_normals(resolution)
    cosine = np.clip(normals @ light_direction(light_angle_deg), 0.0, None)
    value = np.where(mask, irradiance * albedo / np.pi * cosine, 0.0)
    return np.repeat(value[..., None], 3, axis=-1)


def reference_image(skin: MadeUpSkin, *, tables=None, resolution: int = 64,
                    radius_mm: float = 10.0, light_angle_deg: float = 45.0,
                    irradiance: float = 1.0, spread: bool = True,
                    samples: int | None = None) -> np.ndarray:
    """The reference image ``(n, n, 3)`` of
    :func:`lut_baker.offline.validation.reference.sphere_image`.

    ``tables=None``: exactly that (paths 1 + 3 by the exact evaluator, ~20 ms per pixel).
    ``tables`` (baked from ``skin``): paths 1 + 3 interpolated from them instead
    (:meth:`lut_baker.tables.table_set.Tables.made_up_reflection`, error <= 1e-3 of the peak at the
    "default" and "high" resolutions, docs/baking.md), everything else the same: the
    skin-diffuse part is spread by :func:`lut_baker.offline.validation.reference.spread_diffuse`
    when ``spread``.  ``tests/makeup_skin_addon/test_render_compare.py`` checks that the two
    agree.  ``tables`` holding the film as a slab (``tables.slab``, as the tiers fitted to them
    shade it): :func:`slab_reference_image` at their baked thickness."""
    if getattr(tables, "slab", None) is not None:
        return slab_reference_image(skin, tables, resolution=resolution, radius_mm=radius_mm,
                                    light_angle_deg=light_angle_deg, irradiance=irradiance,
                                    spread=spread, samples=samples)
    if tables is None:
        return reference.sphere_image(skin, resolution=resolution, radius_mm=radius_mm,
                                      light_angle_deg=light_angle_deg, irradiance=irradiance,
                                      spread=spread, samples=samples)
    image = local_image(lambda wi, wo: tables.made_up_reflection(wi, wo, skin.coverage,
                                                                 skin.absorption),
                        resolution, light_angle_deg, irradiance)
    if spread:
        _, normals, mask = reference.sphere_points(resolution, radius_mm)
        light = light_direction(light_angle_deg)
        points = normals[mask]
        samples = samples or reference.default_samples(skin, radius_mm)
        image[mask] += (reference.spread_diffuse(points, light, skin, radius_mm=radius_mm,
                                                 samples=samples, irradiance=irradiance)
                        - reference.local_diffuse(points, light, skin, irradiance))
    return image


def slab_reference_image(skin: MadeUpSkin, tables, *, thickness_um: float | None = None,
                         resolution: int = 64, radius_mm: float = 10.0,
                         light_angle_deg: float = 45.0, irradiance: float = 1.0,
                         spread: bool = True, samples: int | None = None) -> np.ndarray:
    """The reference image ``(n, n, 3)`` of made-up skin with the film as a slab at
    ``thickness_um`` (default the tables' baked one), from ``tables`` baked from ``skin`` with
    a film thickness, at the skin's coverage (the slab's absorption is baked).

    ``spread=False``: :func:`lut_baker.tables.slab_tables.slab_reflection` ``E cos(theta_i)``
    per pixel.  ``spread=True``: its diffuse term (:func:`lut_baker.tables.slab_tables.
    slab_diffuse`) is what scattered under the skin, so it leaves spread by the dipole's
    normalised profile (:func:`lut_baker.offline.validation.reference.spread_sums`, ``samples``
    entry points, default :func:`lut_baker.offline.validation.reference.default_samples`)::

        L = E f_local cos(theta_i) + w a/(pi (1 - a c)) t(wo) sum_i E cos(theta_i) t(wi) R(d)/Rd dA
            + (1 - w) a/pi sum_i E cos(theta_i) R(d)/Rd dA

    (``f_local``: ``slab_reflection`` without its diffuse term)."""
    def local(diffuse: bool) -> np.ndarray:
        return local_image(lambda wi, wo: slab_reflection(tables, wi, wo, thickness_um,
                                                          coverage=skin.coverage,
                                                          diffuse=diffuse),
                           resolution, light_angle_deg, irradiance)

    if not spread:
        return local(True)
    image = local(False)
    _, normals, mask = reference.sphere_points(resolution, radius_mm)
    terms = slab_diffuse(tables, thickness_um)
    through, bare = reference.spread_sums(
        normals[mask], light_direction(light_angle_deg), skin, terms.through,
        radius_mm=radius_mm, samples=samples or reference.default_samples(skin, radius_mm),
        irradiance=irradiance)
    image[mask] += combine(coverage_weights(skin.coverage, 0.0), top=terms.covered * through,
                           bare=terms.bare * bare)
    return image


def local_image(reflection, resolution: int, light_angle_deg: float,
                irradiance: float = 1.0) -> np.ndarray:
    """The sphere's image ``(n, n, 3)`` under one distant light when every point reflects
    locally: ``E f(wi, wo) cos(theta_i)`` per pixel centre, ``reflection(wi, wo) -> (P, 3)``
    taking local unit directions ``(P, 3)`` of the lit, visible points (normal = +z).  The
    sphere's size does not enter (no spread)."""
    lit, wi, wo = sphere_directions(resolution, light_angle_deg)
    image = np.zeros((resolution, resolution, 3))
    image[lit] = irradiance * np.asarray(reflection(wi, wo)) * wi[:, 2:3]
    return image


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
