"""Directions in a surface's local frame, and the framing of the reference sphere.

Directions are unit vectors ``(..., 3)`` in the local frame (normal +z, docs/model.md §1);
``wi`` points to the light, ``wo`` to the viewer.  The reference sphere is a sphere seen by an
orthographic camera looking down -z (every view direction is :data:`VIEW`, +z) under one
distant light in the x-z plane; its image's pixel centres span the sphere's disk, rows
top-down.

Functions
---------
- :func:`direction` -- unit vectors from polar and azimuth angles (radians).
- :func:`polar_angle_deg` -- polar angle of unit vectors (degrees).
- :func:`relative_azimuth`, :func:`folded_azimuth_deg` -- azimuth of ``wi`` relative to ``wo``
  (radians), and folded into [0, 180] degrees.
- :func:`half_vector` -- the normalised ``wi + wo``.
- :func:`light_direction` -- a distant light at an angle from the view (world frame).
- :func:`sphere_normals` -- the sphere's normals at the pixel centres, and the disk's mask.
- :func:`tangent_frame`, :func:`local_directions` -- world directions in each normal's frame.
- :func:`sphere_directions` -- the local ``wi``, ``wo`` of the lit pixels (the sphere's
  frames made once per resolution, :func:`_sphere_frames`).
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "VIEW",
    "direction",
    "polar_angle_deg",
    "relative_azimuth",
    "folded_azimuth_deg",
    "half_vector",
    "light_direction",
    "sphere_normals",
    "tangent_frame",
    "local_directions",
    "sphere_directions",
]

VIEW = np.array([0.0, 0.0, 1.0])
"""Direction toward the orthographic camera, world frame."""


def direction(theta: ArrayLike, phi: ArrayLike) -> NDArray[np.float64]:
    """Unit vectors ``(..., 3)`` for polar angle ``theta`` and azimuth ``phi`` (radians)."""
    theta, phi = np.broadcast_arrays(np.asarray(theta, float), np.asarray(phi, float))
    s = np.sin(theta)
    return np.stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)], axis=-1)


def polar_angle_deg(w: np.ndarray) -> np.ndarray:
    """Polar angle (degrees from the normal) of unit vectors ``w`` ``(..., 3)``."""
    return np.degrees(np.arccos(np.clip(w[..., 2], -1.0, 1.0)))


def relative_azimuth(wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """Azimuth of ``wi`` minus that of ``wo`` (radians); 0 where either is the normal."""
    return np.arctan2(wi[..., 1], wi[..., 0]) - np.arctan2(wo[..., 1], wo[..., 0])


def folded_azimuth_deg(wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """:func:`relative_azimuth` folded into [0, 180] degrees."""
    return np.abs(np.mod(np.degrees(relative_azimuth(wi, wo)) + 180.0, 360.0) - 180.0)


def half_vector(wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """``(wi + wo) / |wi + wo|`` ``(..., 3)``; the normal ``(0, 0, 1)`` where ``wi + wo``
    vanishes (an opposite pair on the horizon: its limit from above the surface)."""
    h = np.asarray(wi, float) + np.asarray(wo, float)
    length = np.linalg.norm(h, axis=-1, keepdims=True)
    safe = length > 1e-12
    return np.where(safe, h / np.where(safe, length, 1.0), np.array([0.0, 0.0, 1.0]))


def light_direction(angle_from_view_deg: float) -> np.ndarray:
    """Unit vector toward a light ``angle_from_view_deg`` (degrees) from the view, in x-z."""
    a = np.radians(angle_from_view_deg)
    return np.array([np.sin(a), 0.0, np.cos(a)])


def sphere_normals(resolution: int, extent: float = 1.0
                   ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """``(normals (n, n, 3), mask (n, n))`` at the pixel centres of a ``resolution`` x
    ``resolution`` image spanning ``extent`` sphere radii either side of the centre (1: the
    sphere's disk exactly).  Rows run top-down (+y first) as images do; ``mask`` marks the
    centres inside the disk, outside it the normals are 0."""
    centres = ((np.arange(resolution) + 0.5) / resolution * 2.0 - 1.0) * extent
    x, y = np.meshgrid(centres, -centres)
    r2 = x * x + y * y
    mask = r2 < 1.0
    z = np.sqrt(np.clip(1.0 - r2, 0.0, None))
    return np.where(mask[..., None], np.stack([x, y, z], axis=-1), 0.0), mask


def tangent_frame(normals: np.ndarray) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """An orthonormal tangent and bitangent per normal (any: the model is isotropic)."""
    helper = np.where(np.abs(normals[..., 2:3]) < 0.9, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    tangent = np.cross(helper, normals)
    tangent /= np.linalg.norm(tangent, axis=-1, keepdims=True)
    return tangent, np.cross(normals, tangent)


def local_directions(world: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """World unit vectors ``(..., 3)`` in each normal's local frame (normal = +z)."""
    return _in_frame(world, *tangent_frame(normals), normals)


def _in_frame(world: np.ndarray, tangent: np.ndarray, bitangent: np.ndarray,
              normals: np.ndarray) -> np.ndarray:
    """World unit vectors ``(..., 3)`` in the frames ``(tangent, bitangent, normals)``,
    renormalised."""
    local = np.stack([np.sum(world * tangent, -1), np.sum(world * bitangent, -1),
                      np.sum(world * normals, -1)], axis=-1)
    return local / np.linalg.norm(local, axis=-1, keepdims=True)


class _SphereFrames(NamedTuple):
    """The reference sphere's points inside its disk at one resolution, light aside: the
    disk's ``mask`` (n, n), the ``normals`` there (P, 3, row-major), their
    :func:`tangent_frame` and the view ``wo`` in each frame (all read-only)."""

    mask: NDArray[np.bool_]
    normals: NDArray[np.float64]
    tangent: NDArray[np.float64]
    bitangent: NDArray[np.float64]
    wo: NDArray[np.float64]


@lru_cache(maxsize=4)
def _sphere_frames(resolution: int) -> _SphereFrames:
    """:class:`_SphereFrames` at ``resolution`` (made once: every light shares them)."""
    normals, mask = sphere_normals(resolution)
    points = normals[mask]
    tangent, bitangent = tangent_frame(points)
    wo = _in_frame(np.broadcast_to(VIEW, points.shape), tangent, bitangent, points)
    frames = _SphereFrames(mask, points, tangent, bitangent, wo)
    for array in frames:
        array.setflags(write=False)
    return frames


def sphere_directions(resolution: int, light_angle_deg: float
                      ) -> tuple[NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64]]:
    """``(lit (n, n) booleans, wi (P, 3), wo (P, 3))`` of the reference sphere's image under a
    distant light ``light_angle_deg`` (degrees) from the view: the pixels whose centre sees a
    lit point of the sphere, and at those points (row-major order) the local unit directions
    to the light and to the camera (normal = +z)."""
    frames = _sphere_frames(int(resolution))
    points = frames.normals
    wi = _in_frame(np.broadcast_to(light_direction(light_angle_deg), points.shape),
                   frames.tangent, frames.bitangent, points)
    seen = (wi[:, 2] > 0.0) & (frames.wo[:, 2] > 0.0)
    lit = np.zeros_like(frames.mask)
    lit[frames.mask] = seen
    return lit, wi[seen], frames.wo[seen]
