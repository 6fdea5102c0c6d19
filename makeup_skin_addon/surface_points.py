"""Points on a material's faces, spread in proportion to their area in the world: where the
skin's mean colour and the artist's shader are read (:mod:`.skin_sampling`).

A fixed budget of points (:data:`BUDGET` in all) is spread over the faces of the material's
slots on every mesh object that uses it: stratified along the faces' cumulative area, with a
fixed seed (:data:`SEED`), so the same mesh gives the same points on every run and machine.
Only what the points need is read: the faces' first corners and material indices, the
corners' vertices, the positions and UVs (Blender's attribute arrays, copied whole: not the
loop triangles nor the faces' own areas and normals, docs/addon.md "Match Skin"); the faces'
areas and normals are computed from them as Blender computes them (:mod:`.face_geometry`).  An
object's points are cached for the session until its mesh, material slots or transform change
or a UV they are read from (a CRC of the arrays and of the UVs at the points' corners, read
again at each call: 7 ms of CPU on a million-triangle head, 10 ms over the whole UV map).

- :func:`sampled_triangles` -- area-weighted, stratified points over given faces
  (:class:`Triangles`: their faces, triangles and barycentric weights; numpy only).
- :func:`object_points` -- the points of one object's faces of the material (cached);
  :class:`Surface` -- one object's faces at a UV map, their area read once.
- :func:`shares` -- the budget split between objects by area.
- :func:`users` -- the mesh objects whose slots hold a material.
- :func:`corner_verts`, :func:`corner_faces` -- each corner's vertex and face.
- :func:`clear_cache` -- forget the cached points.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field

import bpy
import numpy as np

from . import face_geometry
from .core import cache

__all__ = ["BUDGET", "SEED", "Points", "Surface", "Triangles", "sampled_triangles",
           "object_points", "shares", "users", "corner_verts", "corner_faces", "clear_cache"]

BUDGET = 1 << 16
"""Points in all, split between the objects by area: the mean's standard error is the texture's
spread over the surface divided by 256 (0.06-0.13% on the production head of docs/addon.md
"Match Skin"; the points, stratified, err by a third of that)."""
SEED = 20251203
"""The points' seed: the same mesh gives the same points, hence the same mean, everywhere."""
POINTS_CACHE_SIZE = 128
"""Objects (per material and UV map) whose points are kept: 56 bytes a point (the UV, position,
normal, the three corners of its triangle and its weights there), 3.7 MB per material however
many objects share it; a material on more objects than this is read again at each click."""

_POINTS = cache.LRUCache(POINTS_CACHE_SIZE)


@dataclass(frozen=True)
class Points:
    """Points on one object's faces of a material: their UVs ``uv`` ((n, 2) float32, in the UV
    map read), the faces' world area ``area`` (square metres) and how many faces ``faces``;
    ``position`` and ``normal`` ((n, 3) float32, the object's own space: the point and its
    face's normal), or None; ``corners`` and ``weights`` ((3, n) int32 and float32): the
    corners of each point's triangle and its barycentric weights there (what a corner's or a
    vertex's attribute is interpolated by, :meth:`interpolated`)."""

    uv: np.ndarray
    area: float
    faces: int
    position: np.ndarray | None = None
    normal: np.ndarray | None = None
    corners: np.ndarray = field(default_factory=lambda: np.empty((3, 0), np.int32))
    weights: np.ndarray = field(default_factory=lambda: np.empty((3, 0), np.float32))

    def interpolated(self, values: np.ndarray, corner_index: np.ndarray | None = None
                     ) -> np.ndarray:
        """``values`` ((m, c): per corner, or per vertex with the corners' vertices
        ``corner_index``) at the points, ``(n, c)`` float32."""
        out = np.empty((len(self.uv), values.shape[1]), np.float32)
        corners = tuple(self.corners if corner_index is None else corner_index[self.corners])
        _interpolated(tuple(self.weights.astype(float)), values, corners, out)
        return out


def users(material) -> list:
    """The mesh objects with ``material`` in one of their slots."""
    return [obj for obj in bpy.data.objects if obj.type == "MESH"
            and any(slot.material == material for slot in obj.material_slots)]


@dataclass(frozen=True)
class Triangles:
    """Where points fell: each point's ``face`` (n,), the corners of its triangle of that face's
    fan ``corners`` (three (n,) int64: the first corner, then two consecutive ones) and its
    barycentric ``weights`` there (three (n,) float64)."""

    face: np.ndarray
    corners: tuple
    weights: tuple

    def interpolated(self, values: np.ndarray, out: np.ndarray,
                     corner_index: np.ndarray | None = None) -> np.ndarray:
        """``out`` ((n, c) float32) filled with ``values`` ((m, c)) interpolated at the points:
        ``values`` per corner, or per vertex with the corners' vertices ``corner_index``."""
        corners = self.corners if corner_index is None else tuple(
            corner_index[c] for c in self.corners)
        _interpolated(self.weights, values, corners, out)
        return out


def sampled_triangles(face_area, loop_start, loop_total, corner_vert, positions, count: int,
                      seed: int = SEED) -> Triangles:
    """``count`` points spread over the faces in proportion to ``face_area`` (zero: a face not
    counted), uniform within each face (:class:`Triangles`): stratified along the cumulative
    area (point i falls in the i-th of ``count`` equal shares, at a random place in it), then a
    triangle of the face's fan from its first corner by its area (``positions`` of the corners
    ``corner_vert``), then a uniform point in it.  Faces are given by ``loop_start`` and
    ``loop_total`` (corners); fans assume convex faces."""
    rng = np.random.default_rng(seed)
    draws = rng.random((4, count))
    face_area = np.asarray(face_area, float)
    cumulative = np.cumsum(face_area)
    shares = (np.arange(count) + draws[0]) * (cumulative[-1] / count)
    last = np.flatnonzero(face_area > 0.0)[-1]  # a share rounded up to the total lands here
    face = np.minimum(np.searchsorted(cumulative, shares, side="right"), last)
    del cumulative, shares
    first = np.asarray(loop_start)[face].astype(np.int64)  # the fan's first corner
    corners = np.asarray(loop_total)[face]
    second = first + 1  # the fan triangle's second corner (the first triangle's)
    for k in np.flatnonzero(np.bincount(corners)[4:]) + 4:  # faces of more than 3 corners
        pick = np.flatnonzero(corners == k)
        partial = _fan_partial(face[pick], first[pick], loop_start, loop_total, corner_vert,
                               positions, k)
        # The triangles whose cumulative area lies below the point's share of the face (the
        # last, the whole face, never does).
        below = partial[:, :-1] < draws[1, pick, None] * partial[:, -1:]
        second[pick] += below.sum(axis=1)
    root = np.sqrt(draws[2])
    weights = (1.0 - root, root * (1.0 - draws[3]), root * draws[3])
    return Triangles(face, (first, second, second + 1), weights)


def _fan_partial(faces: np.ndarray, first: np.ndarray, loop_start, loop_total, corner_vert,
                 positions, k: int) -> np.ndarray:
    """The cumulative areas of the fan triangles (:func:`.face_geometry.fan_areas`) of the
    faces ``faces`` of ``k`` corners that points fell in (their first corners ``first``), one
    row a point: computed once per face of ``k`` corners when the mesh has fewer of them than
    there are points (the same numbers, row by row), else per point."""
    with_k = np.asarray(loop_total) == k
    if np.count_nonzero(with_k) >= len(faces):
        return face_geometry.fan_areas(positions, corner_vert,
                                       first[None, :] + np.arange(k)[:, None])
    with_k = np.flatnonzero(with_k)
    row = np.zeros(len(loop_total), np.int64)
    row[with_k] = np.arange(len(with_k))
    own = np.asarray(loop_start)[with_k].astype(np.int64)[None, :] + np.arange(k)[:, None]
    return face_geometry.fan_areas(positions, corner_vert, own)[row[faces]]


def _interpolated(weights: tuple, values: np.ndarray, corners: tuple, out: np.ndarray) -> None:
    """``out`` (``(n, c)`` float32) = ``sum_t weights[t] values[corners[t]]`` over a triangle's
    three corners (``weights`` three ``(n,)`` float64, ``corners`` three ``(n,)`` indices into
    ``values`` ``(m, c)``), in float64: a column at a time, the products of whole columns (what
    broadcasting ``(n, 1) * (n, c)`` gives, several times faster)."""
    for j in range(values.shape[1]):
        column = values[:, j]
        out[:, j] = (weights[0] * column[corners[0]] + weights[1] * column[corners[1]]
                     + weights[2] * column[corners[2]])


def _array(collection, name: str, count: int, dtype) -> np.ndarray:
    values = np.empty(count, dtype)
    collection.foreach_get(name, values)
    return values


def _attribute(mesh, name: str, fallback, field_name: str, width: int, dtype) -> np.ndarray:
    """A mesh attribute's values, copied whole (Blender's arrays, no per-item access), or
    ``fallback()`` when the attribute is absent."""
    attribute = mesh.attributes.get(name)
    if attribute is None:
        return fallback()
    return _array(attribute.data, field_name, len(attribute.data) * width, dtype)


def _positions(mesh) -> np.ndarray:
    count = len(mesh.vertices)
    return _attribute(mesh, "position", lambda: _array(mesh.vertices, "co", 3 * count,
                                                       np.float32),
                      "vector", 3, np.float32).reshape(-1, 3)


def _corner_verts(mesh) -> np.ndarray:
    count = len(mesh.loops)
    return _attribute(mesh, ".corner_vert", lambda: _array(mesh.loops, "vertex_index", count,
                                                           np.int32), "value", 1, np.int32)


def corner_verts(mesh) -> np.ndarray:
    """The vertex of each of ``mesh``'s corners ((corners,) int32)."""
    return _corner_verts(mesh)


def corner_faces(mesh) -> np.ndarray:
    """The face of each of ``mesh``'s corners ((corners,) int64)."""
    loop_start, loop_total = _loop_starts(mesh)
    return np.repeat(np.arange(len(loop_start)), loop_total)


def _material_indices(mesh) -> np.ndarray:
    count = len(mesh.polygons)
    return _attribute(mesh, "material_index", lambda: np.zeros(count, np.int32), "value", 1,
                      np.int32)


def _corner_uvs(layer) -> np.ndarray:
    return _array(layer.uv, "vector", 2 * len(layer.uv), np.float32).reshape(-1, 2)


def _slots(obj, material) -> tuple:
    return tuple(i for i, slot in enumerate(obj.material_slots) if slot.material == material)


def _linear_part(obj) -> np.ndarray:
    return np.array(obj.matrix_world, float)[:3, :3]


class _MeshArrays:
    """A mesh's arrays for one read of its faces, each copied out of Blender once: the
    fingerprint, the areas and the points all need the positions and the corners' vertices
    (read three times, a cold read of a million triangles took 13 ms more)."""

    def __init__(self, mesh):
        self.mesh = mesh
        self._arrays: dict = {}

    def get(self, read) -> np.ndarray:
        """``read(mesh)`` (:func:`_positions`, :func:`_corner_verts`,
        :func:`_material_indices`), read at the first call."""
        if read not in self._arrays:
            self._arrays[read] = read(self.mesh)
        return self._arrays[read]

    def release(self) -> None:
        """Let the arrays go (read again if asked for)."""
        self._arrays.clear()


def _fingerprint(obj, layer, slots: tuple, arrays: _MeshArrays) -> tuple:
    """What the points of ``obj`` depend on but the UVs, cheaply: the counts, the UV map's name,
    the slots, the transform's linear part and a CRC-32 of the positions, corners' vertices and
    material indices (Blender's arrays copied whole: 4.5 ms on a million triangles).  The UVs
    are checked where the points read them (:func:`_uv_checksum`)."""
    mesh = obj.data
    crc = 0
    for read in (_positions, _corner_verts, _material_indices):
        crc = zlib.crc32(np.ascontiguousarray(arrays.get(read)).data, crc)
    return (len(mesh.vertices), len(mesh.loops), len(mesh.polygons), layer.name, slots,
            tuple(_linear_part(obj).ravel()), crc)


def _uv_checksum(corner_uv: np.ndarray, corners: np.ndarray) -> int:
    """A CRC-32 of the UVs ``corner_uv`` ((m, 2) float32) at the corners ``corners`` (the
    points' triangles' corners, all of the UV map the points depend on): 65,536 points in
    0.8 ms, a fifth of the whole map's on a million triangles."""
    return zlib.crc32(np.take(corner_uv.view(np.uint64).reshape(-1), corners).data)


def _loop_starts(mesh) -> tuple[np.ndarray, np.ndarray]:
    """``(loop_start, loop_total)`` of the faces (int32): their first corners and their corner
    counts.  Blender keeps no array of the first corners that Python can copy (read a face at
    a time: 15 ms on a million triangles), but it does of its triangles' faces: a face of
    ``n`` corners has ``n - 2`` triangles, in face order, so a face's first corner is its
    first triangle's index plus twice its own (5-10 ms).  Read a face at a time where the
    triangles do not add up so."""
    faces, corners = len(mesh.polygons), len(mesh.loops)
    of_triangles = getattr(mesh, "loop_triangle_polygons", None)  # Blender 3.6 on
    triangles = (np.empty(0, np.int32) if of_triangles is None else
                 _array(of_triangles, "value", len(of_triangles), np.int32))
    first = np.flatnonzero(triangles[1:] != triangles[:-1]) + 1  # faces 1.. their first
    if faces > 0 and len(triangles) == corners - 2 * faces and len(first) == faces - 1:
        loop_start = np.empty(faces, np.int32)
        loop_start[0] = 0
        loop_start[1:] = first
        loop_start += 2 * np.arange(faces, dtype=np.int32)
    else:
        loop_start = _array(mesh.polygons, "loop_start", faces, np.int32)
    return loop_start, face_geometry.corner_counts(loop_start, corners)


def _face_areas(obj, slots: tuple, loop_start: np.ndarray, loop_total: np.ndarray,
                arrays: _MeshArrays) -> tuple[np.ndarray, int]:
    """``(areas, faces)``: the world areas (square metres, float64) of ``obj``'s faces, zero
    for faces of other slots, and how many faces the slots have (a material index beyond the
    slots counts as the last slot, as Blender draws it).  The areas are Blender's
    (:func:`.face_geometry.face_areas`)."""
    area = np.empty(len(loop_start))  # kept: allocated before the temporaries (_points)
    positions, corner_verts = arrays.get(_positions), arrays.get(_corner_verts)
    face_geometry.face_areas(positions, corner_verts, loop_start, loop_total, out=area)
    index = np.minimum(arrays.get(_material_indices), max(len(obj.material_slots) - 1, 0))
    used = np.isin(index, slots)
    area[~used] = 0.0
    faces = int(np.count_nonzero(used))
    linear = _linear_part(obj)
    gram = linear.T @ linear
    scale = np.trace(gram) / 3.0
    if np.allclose(gram, scale * np.eye(3), rtol=0.0, atol=1e-9 * max(scale, 1e-30)):
        area *= scale  # a rotation and a uniform scale: areas times its square
        return area, faces
    # Otherwise a face's area grows by |cof(M) n| along its unit normal n, cof(M) = det(M)
    # M^-T, whose columns are the cross products of M's (defined for a flattened M too).
    normal = face_geometry.face_normals(positions, corner_verts, loop_start, loop_total)
    a, b, c = linear.T
    cofactor = np.column_stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)])
    return area * np.linalg.norm(normal @ cofactor.T, axis=1), faces


def _points(layer, area: np.ndarray, faces: int, count: int, loop_start: np.ndarray,
            loop_total: np.ndarray, arrays: _MeshArrays) -> tuple[Points, np.ndarray, int]:
    """``(points, corners, checksum)``: ``count`` points of the faces by ``area``, the corners
    their UVs are read at ((3, count) int32) and those UVs' :func:`_uv_checksum`.  The UV map
    is read last, once the mesh's arrays are let go (a lower peak)."""
    # What is kept is allocated before the temporaries: freed, these then leave the top of the
    # heap free (allocated after them, a kept array holds them resident below it).
    uv = np.empty((count, 2), np.float32)
    position, normal = np.empty((count, 3), np.float32), np.empty((count, 3), np.float32)
    corners, weights = np.empty((3, count), np.int32), np.empty((3, count), np.float32)
    positions, corner_verts = arrays.get(_positions), arrays.get(_corner_verts)
    triangles = sampled_triangles(area, loop_start, loop_total, corner_verts, positions, count)
    triangles.interpolated(positions, position, corner_verts)
    face_geometry.face_normals(positions, corner_verts, loop_start, loop_total, triangles.face,
                               out=normal)
    del positions, corner_verts
    arrays.release()
    for row, corner in zip(corners, triangles.corners, strict=True):
        row[:] = corner
    for row, weight in zip(weights, triangles.weights, strict=True):
        row[:] = weight
    corner_uv = _corner_uvs(layer)
    triangles.interpolated(corner_uv, uv)
    checksum = _uv_checksum(corner_uv, corners)
    return (Points(uv, float(area.sum()), faces, position, normal, corners, weights), corners,
            checksum)


@dataclass(frozen=True)
class _Entry:
    """A cached object's points: the mesh's :func:`_fingerprint`, the corners the points' UVs
    are read at and those UVs' checksum."""

    fingerprint: tuple
    corners: np.ndarray
    uv_checksum: int
    points: Points

    def matches(self, fingerprint: tuple, layer) -> bool:
        return (fingerprint == self.fingerprint
                and _uv_checksum(_corner_uvs(layer), self.corners) == self.uv_checksum)


class Surface:
    """One object's faces of a material at a UV map: their fingerprint, and their points from
    the cache while it matches."""

    def __init__(self, obj, material, layer):
        self.obj, self.layer = obj, layer
        self.slots = _slots(obj, material)
        self.key = (obj.session_uid, material.session_uid, layer.name)
        self._arrays = _MeshArrays(obj.data)
        self.fingerprint = _fingerprint(obj, layer, self.slots, self._arrays)
        entry = _POINTS.get(self.key)
        self.cached = (entry.points if entry is not None
                       and entry.matches(self.fingerprint, layer) else None)
        if self.cached is not None:
            self._arrays.release()
        self._faces: tuple | None = None
        self._areas: tuple[np.ndarray, int] | None = None

    def _loop_starts(self) -> tuple[np.ndarray, np.ndarray]:
        if self._faces is None:
            self._faces = _loop_starts(self.obj.data)
        return self._faces

    def areas(self) -> tuple[np.ndarray, int]:
        """``(areas, faces)`` of :func:`_face_areas`, read once."""
        if self._areas is None:
            self._areas = _face_areas(self.obj, self.slots, *self._loop_starts(), self._arrays)
        return self._areas

    def area(self) -> float:
        """The faces' world area, from the cache when it holds them."""
        return self.cached.area if self.cached is not None else float(self.areas()[0].sum())

    def points(self, count: int) -> Points:
        if self.cached is not None and len(self.cached.uv) == count:
            return self.cached
        areas, faces = self.areas()
        if count > 0 and areas.sum() > 0.0:
            points, corners, checksum = _points(self.layer, areas, faces, count,
                                                *self._loop_starts(), self._arrays)
        else:
            points = Points(np.empty((0, 2), np.float32), float(areas.sum()), faces)
            corners, checksum = np.empty((3, 0), np.int32), 0
        self._arrays.release()
        _POINTS.put(self.key, _Entry(self.fingerprint, corners, checksum, points))
        self.cached = points
        return points


def object_points(obj, material, layer, count: int = BUDGET) -> Points:
    """``count`` points of ``obj``'s faces that use ``material``, at the UV map ``layer``
    (:func:`sampled_triangles`), kept until the mesh, its slots or transform change or a UV
    the points are read at.  Faces of other slots do not count."""
    return Surface(obj, material, layer).points(int(count))


def shares(areas: list[float], budget: int) -> list[int]:
    """The budget split by area (largest remainders), at least one point per object with
    area."""
    total = sum(areas)
    if total <= 0.0:
        return [0] * len(areas)
    exact = [budget * a / total for a in areas]
    counts = [int(e) for e in exact]
    order = sorted(range(len(areas)), key=lambda i: counts[i] - exact[i])
    for i in order[:budget - sum(counts)]:
        counts[i] += 1
    return [max(c, 1) if a > 0.0 else 0 for c, a in zip(counts, areas, strict=True)]


def clear_cache() -> None:
    """Forget the cached points."""
    _POINTS.clear()
