"""The pixel-footprint blur argument: how much leaving the subsurface closure out changes an
image, from the profile's blur of a sphere's shading averaged over each pixel.

- :func:`blur_kernel` -- the profile as a convolution kernel on a grid of cells.
- :func:`fft_size` -- a fast FFT length.
- :func:`subsurface_omission_error` -- the relative change of a sphere's image without the
  spread, at a pixel footprint and object size.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.geometry import sphere_normals

__all__ = ["blur_kernel", "fft_size", "subsurface_omission_error", "SUPERSAMPLE", "MAX_CELLS",
           "KERNEL_SUBSAMPLES"]


SUPERSAMPLE = 4
"""Cells per pixel side in :func:`subsurface_omission_error`."""
MAX_CELLS = 192
"""Largest grid side (cells) of :func:`subsurface_omission_error`: bigger objects are modelled
with coarser cells (never coarser than a pixel of the real image when it fits).  192 rather
than 384 costs a quarter (FFTs of 200-216 instead of 400-432 a side: 0.04-0.1 s of a first
Apply down to 0.01-0.02 s).  Over the 216 scenes of ``bench/omission_grid.py`` the error moves
by 1.5% (median; at most 13% where it is over 1%), and by at most 0.04 points where the spread
is under half a pixel, where it decides whether the closure is left out (against the Auto
tier's 2% tolerance); a grid twice as fine each way (8 cells per pixel, 768 a side) moves it
further (median 2.5%, at most 14% and 0.45 points)."""
KERNEL_SUBSAMPLES = 4
"""Sub-samples per cell side when integrating the profile over a kernel cell."""


def blur_kernel(cell_mm: float, radius_mm: ArrayLike, profile: ArrayLike
                ) -> NDArray[np.float64]:
    """The normalised profile integrated over square cells of ``cell_mm``: ``(2h+1, 2h+1, C)``
    weights summing to 1 per channel, ``h`` cells reaching the profile's last distance.  The
    centre cell takes what the others leave (the profile's peak at 0 is integrable but not
    sampleable)."""
    d = np.asarray(radius_mm, float)
    p = np.reshape(np.asarray(profile, float), (d.size, -1))
    h = int(min(math.ceil(d[-1] / cell_mm), MAX_CELLS))
    offsets = (np.arange(KERNEL_SUBSAMPLES) + 0.5) / KERNEL_SUBSAMPLES - 0.5
    centres = np.arange(-h, h + 1, dtype=float)
    x = (centres[:, None] + offsets[None, :]).ravel() * cell_mm
    r = np.hypot(x[:, None], x[None, :])
    values = np.stack([np.interp(r, d, p[:, c], right=0.0) for c in range(p.shape[1])], -1)
    n = 2 * h + 1
    cells = values.reshape(n, KERNEL_SUBSAMPLES, n, KERNEL_SUBSAMPLES, -1).mean(axis=(1, 3))
    cells *= cell_mm**2
    cells[h, h] = 0.0
    cells = np.minimum(cells, 1.0)
    total = cells.sum(axis=(0, 1))
    scale = np.where(total > 1.0, 1.0 / np.maximum(total, 1e-300), 1.0)
    cells = cells * scale
    cells[h, h] = 1.0 - cells.sum(axis=(0, 1))
    return cells


def fft_size(length: int) -> int:
    """The smallest ``n >= length`` whose prime factors are 2, 3 and 5 (a fast FFT length).

    >>> fft_size(769), fft_size(1152)
    (800, 1152)
    """
    best = 1 << max(int(length) - 1, 0).bit_length()  # the next power of two
    power5 = 1
    while power5 < best:
        odd = power5
        while odd < best:
            n = odd
            while n < length:
                n *= 2
            best = min(best, n)
            odd *= 3
        power5 *= 5
    return best


def _convolved(images: list[NDArray[np.float64]], kernels: NDArray[np.float64]
               ) -> NDArray[np.float64]:
    """Each of ``images`` (m, m) convolved with each of ``kernels`` (k, k, C), same size,
    zero outside: ``(len(images), C, m, m)``.  One FFT per image and per kernel, on a fast
    length of at least ``m + k // 2``: the circular wrap then misses the kept window."""
    m, k = images[0].shape[0], kernels.shape[0]
    h = k // 2
    size = fft_size(m + h)
    image_spectra = np.fft.rfft2(np.stack(images), (size, size))  # (I, s, s')
    kernel_spectra = np.fft.rfft2(np.moveaxis(kernels, -1, 0), (size, size))  # (C, s, s')
    full = np.fft.irfft2(image_spectra[:, None] * kernel_spectra[None], (size, size))
    return full[..., h:h + m, h:h + m]


def subsurface_omission_error(footprint_mm: float, object_size_mm: float, light_deg: float,
                              radius_mm: ArrayLike, profile: ArrayLike,
                              skin_share: float = 1.0) -> float:
    """Relative RMS change of a sphere's image (diameter ``object_size_mm``, pixels of
    ``footprint_mm``, one distant light ``light_deg`` from the view) when the part of its
    radiance that spreads under the skin (``skin_share`` of it) stays where it entered
    instead of spreading with the normalised ``profile`` on ``radius_mm`` (mm).

    The shading is Lambertian (``max(0, N.L)``) on cells of a pixel / :data:`SUPERSAMPLE`
    (coarser for objects over :data:`MAX_CELLS` cells), blurred in the image plane with
    :func:`blur_kernel` renormalised to the object's disk (light stays on the surface), both
    images averaged over each pixel (the pixel footprint) before they are compared.  A
    spread under half a pixel mostly stays inside the pixel it entered."""
    radius_obj = 0.5 * float(object_size_mm)
    cell = max(footprint_mm / SUPERSAMPLE, object_size_mm / MAX_CELLS)
    per_pixel = max(int(round(footprint_mm / cell)), 1)
    pixels = max(int(math.ceil(object_size_mm / (cell * per_pixel))), 1)
    m = pixels * per_pixel
    normals, inside = sphere_normals(m, 0.5 * m * cell / radius_obj)
    disk = inside.astype(float)
    x, z = normals[..., 0], normals[..., 2]
    a = math.radians(light_deg)
    shading = np.clip(x * math.sin(a) + z * math.cos(a), 0.0, None) * disk
    if not np.any(shading > 0):
        return 0.0
    kernel = blur_kernel(cell, radius_mm, profile)

    def pixel_mean(image: NDArray[np.float64]) -> NDArray[np.float64]:
        return image.reshape(pixels, per_pixel, pixels, per_pixel).mean(axis=(1, 3))

    seen = pixel_mean(disk) > 0.0
    sharp = pixel_mean(shading)
    spread, reach = _convolved([shading, disk], kernel)
    errors = []
    for c in range(kernel.shape[-1]):
        blurred = np.where(disk > 0, spread[c] / np.maximum(reach[c], 1e-12), 0.0)
        errors.append(pixel_mean(blurred)[seen] - sharp[seen])
    difference = np.stack(errors)
    return float(skin_share * np.sqrt(np.mean(difference**2)) / np.sqrt(np.mean(sharp[seen]**2)))
