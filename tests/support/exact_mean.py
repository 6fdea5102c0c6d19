"""The exact area-weighted mean of an sRGB image over a mesh object's surface, reckoned
independently of :mod:`makeup_skin_addon.skin_sampling` (tests/makeup_skin_addon/
test_skin_sampling.py, bench/skin_colour.py): every loop triangle (not the faces) at the
centroids of its ``grid`` x ``grid`` subdivision (a grid, not random points), weighted by its
world area, read nearest in the whole image, linearised (the texture repeated).

- :func:`exact_mean` -- ``(mean (3,), the whole image linear (h, w, 3))``.
- :func:`srgb_to_linear` -- the sRGB curve undone.
- :func:`grid_weights` -- barycentric weights of a triangle's subdivision's centroids.
"""

from __future__ import annotations

import numpy as np

__all__ = ["exact_mean", "srgb_to_linear", "grid_weights"]

CHUNK = 100_000
"""Triangles read at a time (a million-triangle head stays within a few hundred MB)."""


def srgb_to_linear(values):
    values = np.asarray(values, float)
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


def grid_weights(grid: int) -> np.ndarray:
    """``(grid^2, 3)`` barycentric weights: the centroids of the ``grid^2`` triangles a
    triangle splits into when each side is cut in ``grid``."""
    centres = []
    for i in range(grid):
        for j in range(grid - i):
            centres.append(((i + 1 / 3) / grid, (j + 1 / 3) / grid))
            if i + j < grid - 1:
                centres.append(((i + 2 / 3) / grid, (j + 2 / 3) / grid))
    centres = np.array(centres)
    return np.column_stack([1 - centres.sum(axis=1), centres])


def exact_mean(obj, image, uv_name: str, grid: int) -> tuple[np.ndarray, np.ndarray]:
    """The mean of ``image`` (8-bit sRGB, linearised) over ``obj``'s surface at the UV map
    ``uv_name``, and the whole image linear."""
    width, height = image.size
    values = np.empty(width * height * image.channels, np.float32)
    image.pixels.foreach_get(values)
    pixels = srgb_to_linear(values.reshape(height, width, -1)[..., :3])
    del values
    mesh = obj.data
    mesh.calc_loop_triangles()
    count = len(mesh.loop_triangles)
    loops = np.empty(3 * count, np.int64)
    mesh.loop_triangles.foreach_get("loops", loops)
    loops = loops.reshape(-1, 3)
    vertex = np.empty(len(mesh.loops), np.int64)
    mesh.loops.foreach_get("vertex_index", vertex)
    position = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", position)
    position = position.reshape(-1, 3) @ np.array(obj.matrix_world)[:3, :3].T
    uv = np.empty(2 * len(mesh.loops))
    mesh.uv_layers[uv_name].data.foreach_get("uv", uv)
    uv = uv.reshape(-1, 2)
    weights = grid_weights(grid)
    total, area_sum = np.zeros(3), 0.0
    for start in range(0, count, CHUNK):
        chunk = loops[start:start + CHUNK]
        corners = position[vertex[chunk]]
        area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                             corners[:, 2] - corners[:, 0]), axis=-1)
        at = np.einsum("sk,tkc->tsc", weights, uv[chunk])
        at -= np.floor(at)
        column = np.clip((at[..., 0] * width).astype(np.int64), 0, width - 1)
        row = np.clip((at[..., 1] * height).astype(np.int64), 0, height - 1)
        total += area @ pixels[row, column].mean(axis=1)
        area_sum += area.sum()
    return total / area_sum, pixels
