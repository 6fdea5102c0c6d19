"""How much of a uniform sky the mesh leaves to each part of the skin's reflection, as the camera
sees it (docs/addon.md, "A first Apply").

Under a uniform white world a surface renders its albedo only where nothing hides the sky: in
a head's hollows (the eye sockets, the nostrils, under the chin) part of what a point reflects
comes from the head instead, darker than the sky.  A gloss lobe, whose reflections at grazing
views fall into those hollows, loses more of it than a diffuse surface, and a sharp lobe more
than a broad one; so a skin whose colour is largely its gloss (a dark skin's blue) renders
darker on a head than a film of the same colour under uniform light that scatters more
broadly.  The match (:mod:`.matching`) weighs each part of the colour by what it keeps here.

What it keeps is measured on the material's surface points (:mod:`.skin_sampling`, the ones
the artist's shader is read at, counted by what the camera sees): the points, splatted into a
grid of :data:`GRID` cells along the longest side, are what hides the sky; :data:`POINTS`
points, picked by their weights, cast :data:`RAYS` rays each (a fixed pattern and seed: the
same mesh and camera give the same figures) along the lobe (cosine-weighted for the diffuse
part, GGX about the mirror direction for a gloss, Schlick's Fresnel at index 1.5) and the
grid is marched along them.  A ray that meets the grid sees the skin, one bounce:
:meth:`SkyVisibility.kept` counts it by the skin's own colour.  Cached per mesh and camera.

- :class:`SkyVisibility` -- the sky a diffuse and a gloss lobe see, and what each keeps.
- :func:`sky_visibility` -- of a material's surface samples (None without a camera or points).
- :func:`occupancy` -- points splatted into a grid; :func:`clearance` -- how far each cell is
  from the nearest occupied one; :func:`unhidden` -- rays marched through the grid;
  :func:`diffuse_rays`, :func:`gloss_rays` -- the lobes' directions and weights (numpy).
- :func:`clear_cache` -- forget what was measured.
"""

from __future__ import annotations

import zlib

import numpy as np

from .core import cache, cycles

__all__ = ["GRID", "POINTS", "RAYS", "SkyVisibility", "sky_visibility", "occupancy",
           "clearance", "unhidden", "diffuse_rays", "gloss_rays", "clear_cache"]

GRID = 64
"""Cells of the occupancy grid along the bounding box's longest side (3.4 mm on a 0.22 m
head: the hollows that matter are centimetres)."""
POINTS = 256
"""Surface points that cast rays, picked by the camera's weights."""
RAYS = 16
"""Rays per point and lobe (a stratified 4 x 4 pattern, turned at random per point)."""
OFFSET_CELLS = 1.5
"""A ray starts this many cells off its point along the normal (clear of its own cell)."""
STEP_CELLS = 0.5
"""The march's step, in cells."""
CLEARANCE_CAP = 8
"""The longest leap a march takes, plus 1.5 cells (where no occupied cell is nearer)."""
SEED = 20251204
FRESNEL_F0 = 0.04
"""Schlick's normal reflectance, index 1.5 (the artist's and the film's gloss alike)."""
_CACHE = cache.LRUCache(16)


def occupancy(positions: np.ndarray, cells: int = GRID) -> tuple[np.ndarray, np.ndarray, float]:
    """``(grid, origin, size)``: the world ``positions`` ``(n, 3)`` splatted into a boolean
    grid of ``cells`` cells along the longest side of their bounding box (padded by two
    cells), its corner ``origin`` and cell ``size`` (metres)."""
    positions = np.asarray(positions, np.float32)
    by_axis = np.ascontiguousarray(positions.T)  # a reduction along rows of 3 is slow
    low, high = by_axis.min(axis=1), by_axis.max(axis=1)
    size = float(max(high - low)) / cells or 1.0
    origin = low - 2.0 * size
    shape = np.ceil((high - origin) / size).astype(int) + 3
    grid = np.zeros(shape, bool)
    # Every point lies two cells inside the corner: truncation is the floor.
    index = ((positions - origin) / size).astype(np.intp)
    grid.reshape(-1)[(index[:, 0] * shape[1] + index[:, 1]) * shape[2] + index[:, 2]] = True
    return grid, origin, size


def clearance(grid: np.ndarray, cap: int = CLEARANCE_CAP) -> np.ndarray:
    """Per cell, its chessboard distance in cells to the nearest occupied cell of ``grid``
    (``cap`` at most; uint8): how far a march may leap from there."""
    distance = np.full(grid.shape, cap, np.uint8)
    distance[grid] = 0
    reached = grid.copy()
    for k in range(1, cap):
        for axis in range(3):
            grown = reached.copy()
            ahead = [slice(None)] * 3
            behind = [slice(None)] * 3
            ahead[axis], behind[axis] = slice(1, None), slice(None, -1)
            grown[tuple(ahead)] |= reached[tuple(behind)]
            grown[tuple(behind)] |= reached[tuple(ahead)]
            reached = grown
        distance[reached & (distance == cap)] = k
    return distance


def unhidden(grid: np.ndarray, origin: np.ndarray, size: float, starts: np.ndarray,
             directions: np.ndarray, distance: np.ndarray | None = None) -> np.ndarray:
    """Whether each ray (``starts``, unit ``directions``, ``(m, 3)``) leaves the grid without
    meeting an occupied cell: marched by :data:`STEP_CELLS` near the surface, by leaps as long
    as the ``distance`` (:func:`clearance`) allows away from it, the rays still going kept
    together (each step costs what is left)."""
    if distance is None:
        distance = clearance(grid)
    shape = np.array(grid.shape, np.uintp)
    flat = distance.reshape(-1)
    free = np.ones(len(starts), bool)
    # The rays still going, one column each: position (in cells) over direction.
    state = np.empty((6, len(starts)), np.float32)
    state[:3] = ((starts - origin) / size).T
    state[3:] = directions.T
    ray = np.arange(len(starts))
    for _ in range(int(np.ceil(np.linalg.norm(grid.shape) / STEP_CELLS)) + 1):
        # Below 0 wraps to a huge index (unsigned), so one comparison per axis bounds it.
        x, y, z = np.floor(state[:3]).astype(np.intp).view(np.uintp)
        inside = (x < shape[0]) & (y < shape[1]) & (z < shape[2])
        # Outside, the cell is any (clipped): only the inside's are used.
        clear = flat.take(((x * shape[1] + y) * shape[2] + z).view(np.intp), mode="clip")
        free[ray[inside & (clear == 0)]] = False
        going = inside & (clear != 0)
        if not np.any(going):
            break
        state, ray = state[:, going], ray[going]
        state[:3] += np.maximum(clear[going].astype(np.float32) - 1.5, STEP_CELLS) * state[3:]
    return free


def _frames(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents per unit normal, a right-handed frame."""
    axis = np.where(np.abs(normals[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    first = np.cross(normals, axis)
    first /= np.linalg.norm(first, axis=1, keepdims=True)
    return first, np.cross(normals, first)


def _pattern(count: int, rays: int) -> tuple[np.ndarray, np.ndarray]:
    """``(u, phi)``, ``(count, rays)``: a stratified pattern in the unit square per point, its
    second coordinate an angle turned at random per point (fixed seed)."""
    side = int(round(np.sqrt(rays)))
    rng = np.random.default_rng(SEED)
    i, j = np.divmod(np.arange(side * side), side)
    u = (i + rng.random(side * side)) / side
    v = (j + rng.random(side * side)) / side
    turn = rng.random((count, 1))
    return np.broadcast_to(u, (count, u.size)), 2.0 * np.pi * ((v + turn) % 1.0)


def _along(normals, first, second, cos_theta, phi) -> np.ndarray:
    """Directions ``(count, rays, 3)`` at polar ``cos_theta`` and azimuth ``phi`` about the
    normals."""
    sin_theta = np.sqrt(np.maximum(1.0 - cos_theta ** 2, 0.0))
    return (sin_theta[..., None] * (np.cos(phi)[..., None] * first[:, None]
                                    + np.sin(phi)[..., None] * second[:, None])
            + cos_theta[..., None] * normals[:, None])


def diffuse_rays(normals: np.ndarray, rays: int = RAYS) -> tuple[np.ndarray, np.ndarray]:
    """``(directions (n, rays, 3), weights (n, rays))``: cosine-weighted about ``normals``."""
    first, second = _frames(normals)
    u, phi = _pattern(len(normals), rays)
    return _along(normals, first, second, np.sqrt(1.0 - u), phi), np.ones(u.shape)


def _smith_g1(cos_theta, alpha: float):
    """Smith's masking of GGX, ``1 / (1 + Lambda)`` (:func:`lut_baker.closures.cycles.
    ggx_lambda`, the lobe the closures fit)."""
    return 1.0 / (1.0 + cycles.ggx_lambda(cos_theta, alpha))


def gloss_rays(normals: np.ndarray, views: np.ndarray, roughness: float, rays: int = RAYS
               ) -> tuple[np.ndarray, np.ndarray]:
    """``(directions (n, rays, 3), weights (n, rays))``: a GGX lobe of Blender ``roughness``
    (alpha its square) about the mirror of the unit ``views`` (towards the camera), the
    microfacet normals sampled by their distribution; a ray's weight is its share of the
    lobe's reflectance (Smith's shadowing, Schlick's Fresnel; 0 below the surface)."""
    alpha = max(float(roughness) ** 2, 1e-3)
    alpha2 = alpha ** 2
    first, second = _frames(normals)
    u, phi = _pattern(len(normals), rays)
    cos_h = 1.0 / np.sqrt(1.0 + alpha2 * u / np.maximum(1.0 - u, 1e-12))
    half = _along(normals, first, second, cos_h, phi)
    v_h = np.sum(half * views[:, None], axis=2)
    directions = 2.0 * v_h[..., None] * half - views[:, None]
    n_v = np.maximum(np.sum(normals * views, axis=1), 1e-3)[:, None]
    n_l = np.sum(directions * normals[:, None], axis=2)
    fresnel = FRESNEL_F0 + (1.0 - FRESNEL_F0) * (1.0 - np.clip(v_h, 0.0, 1.0)) ** 5
    weights = np.where((n_l > 0.0) & (v_h > 0.0), fresnel * _smith_g1(n_v, alpha)
                       * _smith_g1(np.clip(n_l, 0.0, 1.0), alpha) * v_h / (n_v * cos_h), 0.0)
    return directions, weights


class SkyVisibility:
    """What a uniform sky leaves to the surface's ``normals`` seen along ``views`` (world
    space, unit, ``(n, 3)``) at ``positions``, whose points ``all_positions`` hide it."""

    def __init__(self, positions, normals, views, all_positions):
        self.positions, self.normals, self.views = positions, normals, views
        self.grid, self.origin, self.size = occupancy(all_positions)
        self.distance = clearance(self.grid)
        self._shown: np.ndarray | None = None
        self._seen: dict = {}

    def seen(self, *roughnesses: float) -> tuple[float, list[float]]:
        """``(diffuse, glosses)``: the share of the sky a diffuse (cosine-weighted) lobe sees,
        and the share of a GGX gloss lobe's reflectance (per Blender roughness) that comes
        from the sky, over the points the camera sees (a point hidden from the camera is left
        out: the points' weights do not look).  Each lobe is marched once, those not yet
        measured together."""
        key = [round(float(r), 4) for r in roughnesses]
        missing = sorted({r for r in key if r not in self._seen})
        if self._shown is None or missing:
            lobes = ([] if "diffuse" in self._seen else [("diffuse", diffuse_rays(self.normals))]
                     ) + [(r, gloss_rays(self.normals, self.views, r)) for r in missing]
            first = self._shown is None
            directions = np.concatenate(([self.views[:, None]] if first else [])
                                        + [d for _, (d, _) in lobes], axis=1)
            starts = np.broadcast_to((self.positions + OFFSET_CELLS * self.size
                                      * self.normals)[:, None], directions.shape)
            free = unhidden(self.grid, self.origin, self.size, starts.reshape(-1, 3),
                            directions.reshape(-1, 3), self.distance
                            ).reshape(directions.shape[:2])
            if first:
                self._shown = free[:, 0] if np.any(free[:, 0]) else np.ones(len(free), bool)
            at = 1 if first else 0
            for name, (_, weights) in lobes:
                part, weights = free[self._shown, at:at + weights.shape[1]], weights[self._shown]
                total = float(weights.sum())
                self._seen[name] = float(np.sum(weights * part) / total) if total > 0.0 else 1.0
                at += weights.shape[1]
        return self._seen["diffuse"], [self._seen[r] for r in key]

    @staticmethod
    def kept(sky: float, colour) -> np.ndarray:
        """What a lobe keeps of its uniform-light colour when it sees ``sky`` of the sky and
        the skin (of ``colour`` under uniform light, RGB: one bounce) elsewhere."""
        return sky + (1.0 - sky) * np.clip(np.asarray(colour, float), 0.0, 1.0)


def _picked(weights: np.ndarray, count: int) -> np.ndarray:
    """``count`` indices drawn by ``weights``, stratified along their cumulative sum."""
    cumulative = np.cumsum(weights)
    at = (np.arange(count) + 0.5) / count * cumulative[-1]
    return np.minimum(np.searchsorted(cumulative, at), len(weights) - 1)


def sky_visibility(samples) -> SkyVisibility | None:
    """What a uniform sky leaves to ``samples``' surface (:class:`.skin_sampling.
    SurfaceSamples` read, with their points and a camera), cached per points and camera; None
    without a camera or points."""
    camera = getattr(samples, "camera", None)
    if camera is not None and getattr(samples, "weights", None) is None and hasattr(samples,
                                                                                    "uv"):
        samples.uv("")  # a shader of plain values read no UV: the points are still needed
    picked = getattr(samples, "picked", None)
    weights = getattr(samples, "weights", None)
    if not picked or camera is None or weights is None or not samples.seen_by:
        return None
    positions, normals = [], []
    for obj, points in picked:
        if points.position is None:
            return None
        matrix = np.array(obj.matrix_world, np.float32)
        positions.append(points.position @ matrix[:3, :3].T + matrix[:3, 3])
        normals.append(points.normal @ np.linalg.inv(matrix[:3, :3]))  # inverse transpose
    everywhere = np.concatenate(positions)
    eye = np.array(camera.matrix_world, float)
    key = (zlib.crc32(everywhere.tobytes()), eye.tobytes(),
           camera.data.type)
    found = _CACHE.get(key)
    if found is not None:
        return found
    chosen = _picked(np.asarray(weights, float), POINTS)
    at, normal = everywhere[chosen].astype(float), np.concatenate(normals)[chosen].astype(float)
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-30)
    if camera.data.type == "ORTHO":
        views = np.broadcast_to(eye[:3, 2], at.shape)
    else:
        views = eye[:3, 3] - at
        views = views / np.maximum(np.linalg.norm(views, axis=1, keepdims=True), 1e-30)
    visibility = SkyVisibility(at, normal, views, everywhere)
    _CACHE.put(key, visibility)
    return visibility


def clear_cache() -> None:
    """Forget the measured surfaces."""
    _CACHE.clear()
