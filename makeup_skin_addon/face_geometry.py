"""A mesh's faces measured from its whole arrays, as Blender measures them (numpy only): the
points of :mod:`.surface_points` need every face's area and the normals of the faces they fall
in, and Blender's own per-face attributes (``MeshPolygon.area``, ``.normal``,
``.loop_total``) are read one face at a time (27-42 ms each on half a million faces).

The formulas are Blender's, in float32 and in its order of operations: a triangle's area is
half its edges' cross product's length, a larger face's half its Newell vector's; a
triangle's normal is its edges' cross product divided by its length, a quad's its diagonals'
cross product times the length's reciprocal, a larger face's its Newell vector's likewise; a
zero normal is +Z.  Blender's x86-64 builds, whose baseline has no fused multiply-add, give the
same floats (4.5 and 5.0 checked, docs/addon.md "Match Skin"); a build that fuses them (arm64)
may differ in the last bits.  Faces are taken by their corner count, a chunk of :data:`CHUNK`
at a time (the temporaries stay a few MB); what is kept can be given as ``out``, allocated
before them (:mod:`.surface_points`).

- :func:`corner_counts` -- each face's corners, from the faces' first corners.
- :func:`face_areas` -- every face's area (float32, in the mesh's units squared).
- :func:`face_normals` -- unit normals of given faces (float32).
- :func:`fan_areas` -- the cumulative areas of faces' fan triangles (where a point falls in a
  face).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

__all__ = ["CHUNK", "corner_counts", "face_areas", "face_normals", "fan_areas"]

CHUNK = 1 << 15
"""Faces measured at a time: their temporaries stay in a core's cache (on the production
head 15 ms at 2^14-2^15 faces, 20 ms at 2^16, 31 ms all at once)."""
_TINY = np.float32(1e-35)
"""Blender's threshold on a squared length below which a vector is not normalised."""
_HALF = np.float32(0.5)
_ONE = np.float32(1.0)


def corner_counts(loop_start: np.ndarray, corners: int) -> np.ndarray:
    """Each face's number of corners (int32), from its first corner ``loop_start`` (the faces'
    corners are consecutive and in face order, as Blender stores them) and the mesh's
    ``corners`` in all."""
    total = np.empty(len(loop_start), np.int32)
    np.subtract(loop_start[1:], loop_start[:-1], out=total[:-1])
    total[-1:] = corners - loop_start[-1:]
    return total


def _groups(loop_start: np.ndarray, loop_total: np.ndarray,
            faces: np.ndarray | None) -> Iterator[tuple[slice | np.ndarray, np.ndarray]]:
    """``(rows, corners)`` over the faces ``faces`` (indices; None: all) by corner count and
    chunk: the rows of the result they fill, and their corners ``(k, n)`` (row j: each face's
    j-th corner)."""
    total = loop_total if faces is None else loop_total[faces]
    counts = np.flatnonzero(np.bincount(total))
    for k in counts:
        rows = None if len(counts) == 1 else np.flatnonzero(total == k)
        size = len(total) if rows is None else len(rows)
        for begin in range(0, size, CHUNK):
            end = min(begin + CHUNK, size)
            chunk = slice(begin, end) if rows is None else rows[begin:end]
            which = chunk if faces is None else faces[chunk]
            start = loop_start[which]
            yield chunk, start[None, :] + np.arange(k, dtype=start.dtype)[:, None]


def _coordinates(positions: np.ndarray, corner_verts: np.ndarray,
                 corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x, y, z of the corners ``corners`` (``(k, n)`` each, float32; taken from the positions
    flat, which is faster than from their columns' strided views)."""
    flat = positions.reshape(-1)
    at = np.take(corner_verts, corners) * 3
    return np.take(flat, at), np.take(flat, at + 1), np.take(flat, at + 2)


def _cross(a: tuple, b: tuple) -> tuple:
    """The cross product of two vectors given by their components."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _triangle_cross(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> tuple:
    """A triangle's ``(v0 - v1) x (v1 - v2)`` (twice its area along its normal)."""
    return _cross((x[0] - x[1], y[0] - y[1], z[0] - z[1]),
                  (x[1] - x[2], y[1] - y[2], z[1] - z[2]))


def _newell_term(x: np.ndarray, y: np.ndarray, z: np.ndarray, p: int, c: int) -> tuple:
    """The edge from corner ``p`` to corner ``c``'s part of a Newell vector."""
    return ((y[p] - y[c]) * (z[p] + z[c]), (z[p] - z[c]) * (x[p] + x[c]),
            (x[p] - x[c]) * (y[p] + y[c]))


def _newell(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> tuple:
    """A face's Newell vector (twice its area along its normal), its edges summed from the one
    that closes the face, as Blender sums them."""
    k = len(x)
    total = _newell_term(x, y, z, k - 1, 0)
    for i in range(1, k):
        total = tuple(s + t for s, t in zip(total, _newell_term(x, y, z, i - 1, i),
                                            strict=True))
    return total


def _squared_length(v: tuple) -> np.ndarray:
    return v[0] * v[0] + v[1] * v[1] + v[2] * v[2]


def face_areas(positions: np.ndarray, corner_verts: np.ndarray, loop_start: np.ndarray,
               loop_total: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Every face's area (float32, the units of ``positions`` squared) as Blender's
    ``MeshPolygon.area`` gives it: from the vertices' ``positions`` ``(v, 3)`` float32, the
    corners' vertices ``corner_verts`` and the faces' first corner and corner count; into
    ``out`` if given (float64: the float32 areas, exactly)."""
    area = np.empty(len(loop_start), np.float32) if out is None else out
    for rows, corners in _groups(loop_start, loop_total, None):
        x, y, z = _coordinates(positions, corner_verts, corners)
        twice = _triangle_cross(x, y, z) if len(corners) == 3 else _newell(x, y, z)
        area[rows] = np.sqrt(_squared_length(twice)) * _HALF
    return area


def face_normals(positions: np.ndarray, corner_verts: np.ndarray, loop_start: np.ndarray,
                 loop_total: np.ndarray, faces: np.ndarray | None = None,
                 out: np.ndarray | None = None) -> np.ndarray:
    """Unit normals ``(n, 3)`` float32 of the faces ``faces`` (indices; None: every face) as
    Blender's ``MeshPolygon.normal`` gives them (arguments as :func:`face_areas`), into ``out``
    if given."""
    count = len(loop_start) if faces is None else len(faces)
    normal = np.empty((count, 3), np.float32) if out is None else out
    for rows, corners in _groups(loop_start, loop_total, faces):
        x, y, z = _coordinates(positions, corner_verts, corners)
        k = len(corners)
        if k == 3:
            v = _triangle_cross(x, y, z)
        elif k == 4:
            v = _cross((x[0] - x[2], y[0] - y[2], z[0] - z[2]),
                       (x[1] - x[3], y[1] - y[3], z[1] - z[3]))
        else:
            v = _newell(x, y, z)
        squared = _squared_length(v)
        long = squared > _TINY
        length = np.sqrt(np.where(long, squared, _ONE))
        # A triangle's is divided by its length, the others multiplied by its reciprocal.
        unit = [np.where(long, c / length if k == 3 else c * (_ONE / length), 0.0) for c in v]
        unit[2] = np.where(long, unit[2], _ONE)  # a zero normal is +Z
        normal[rows] = np.stack(unit, axis=1)
    return normal


def fan_areas(positions: np.ndarray, corner_verts: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """The cumulative areas ``(n, k - 2)`` (float32) of the fan triangles from the first corner
    of ``n`` faces of ``k`` corners (their corners ``corners``, ``(k, n)``): each triangle's
    ``|(v_j - v_0) x (v_j+1 - v_0)| / 2``, its squares summed in order, then summed along the
    fan."""
    x, y, z = _coordinates(positions, corner_verts, corners)
    cross = _cross((x[1:-1] - x[0], y[1:-1] - y[0], z[1:-1] - z[0]),
                   (x[2:] - x[0], y[2:] - y[0], z[2:] - z[0]))
    return np.cumsum(np.sqrt(_squared_length(cross)) * _HALF, axis=0).T
