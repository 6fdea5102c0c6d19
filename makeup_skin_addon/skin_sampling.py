"""The mean of an image over a material's surface, read as its texture node reads it there: the
skin's own colour of Match Skin, Lighter / Darker and the first Apply (:mod:`.shade`).

The mean is estimated from a fixed budget of points (:data:`BUDGET` in all), spread over the
faces of the material's slots on every mesh object that uses it, in proportion to their area in
the world: stratified along the faces' cumulative area, with a fixed seed (:data:`SEED`), so the
same mesh gives the same points on every run and machine.  Only what the points need is read:
the faces' areas and material indices, their corners, positions and UVs (Blender's attribute
arrays, copied whole: not the loop triangles, docs/addon.md "Match Skin").  The image is read
box-filtered to at most :data:`IMAGE_SIZE` texels across (a temporary copy scaled down, removed
at once), never as the whole float buffer, and linearised as the texture node does.

Both halves are cached for the session: an object's points until its mesh, UVs, material
slots or transform change (a CRC of the arrays, read again at each call: about 15 ms on a
million-triangle head), an image's reduced pixels until the image changes (source, file and its
date, packed data, colour space; an image with unsaved changes is read again each time).

- :func:`surface_mean` -- the mean (:class:`SurfaceMean`): its standard error, the faces it
  covers, what was said about it, or why there is none.
- :func:`object_points` -- the points of one object's faces of the material (cached).
- :func:`face_points` -- area-weighted, stratified points over given faces and their UVs
  (numpy only).
- :func:`reduced_image` -- an image box-filtered to at most :data:`IMAGE_SIZE`, linear
  (cached); :func:`box_reduce` the filter in numpy, :func:`srgb_to_linear` the sRGB curve.
- :func:`read_texels` -- a reduced image at UVs, wrapped as the texture's extension says.
- :func:`users` -- the mesh objects whose slots hold a material.
- :func:`reporting`, :func:`progress_bar` -- where a slow step's progress goes (a callback, the
  window manager's progress).
- :func:`clear_cache` -- forget both caches (the add-on's unregister calls it).
"""

from __future__ import annotations

import contextlib
import os
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field

import bpy
import numpy as np

from .core import cache

__all__ = [
    "BUDGET",
    "SEED",
    "IMAGE_SIZE",
    "Points",
    "ReducedImage",
    "SurfaceMean",
    "surface_mean",
    "object_points",
    "face_points",
    "reduced_image",
    "box_factor",
    "box_reduce",
    "srgb_to_linear",
    "read_texels",
    "users",
    "reporting",
    "progress_bar",
    "clear_cache",
]

BUDGET = 1 << 16
"""Points in all, split between the objects by area: the mean's standard error is the texture's
spread over the surface divided by 256 (0.06-0.13% on the production head of docs/addon.md
"Match Skin"; the points, stratified, err by a third of that)."""
SEED = 20251203
"""The points' seed: the same mesh gives the same points, hence the same mean, everywhere."""
IMAGE_SIZE = 512
"""The longest side, in texels, the image is box-filtered down to before it is read."""
LINEAR_SPACES = frozenset({"Linear Rec.709", "scene_linear", "Non-Color"})
"""Colour spaces whose values a texture node reads as they are (Blender's scene linear)."""
POINTS_CACHE_SIZE = 128
"""Objects (per material and UV map) whose points are kept: 8 bytes a point, 0.5 MB per
material however many objects share it, 64 MB at most; a material on more objects than this is
read again at each click."""
IMAGES_CACHE_SIZE = 4
"""Reduced images kept (3 MB each at :data:`IMAGE_SIZE`)."""

Report = Callable[..., None]
"""A progress callback: ``report(fraction, message="")``, fraction from 0 to 1."""

_POINTS = cache.LRUCache(POINTS_CACHE_SIZE)
_IMAGES = cache.LRUCache(IMAGES_CACHE_SIZE)
_REPORTS: list[Report] = []


# -- results ------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Points:
    """Points on one object's faces of a material: their UVs ``uv`` ((n, 2) float32, in the UV
    map read), the faces' world area ``area`` (square metres) and how many faces ``faces``;
    ``position`` and ``normal`` ((n, 3) float32, the object's own space: the point and its
    face's normal), or None."""

    uv: np.ndarray
    area: float
    faces: int
    position: np.ndarray | None = None
    normal: np.ndarray | None = None


@dataclass(frozen=True)
class ReducedImage:
    """An image as its texture node reads it, box-filtered: ``pixels`` ((h, w, 3) float32,
    linear; None when the image has none), a ``note`` on how it was read (or "") and the
    ``problem`` that left it without pixels (or "")."""

    pixels: np.ndarray | None
    note: str = ""
    problem: str = ""


@dataclass
class SurfaceMean:
    """The mean of an image over a material's faces: ``rgb`` (linear, or None when there is
    none, ``problem`` says why), its standard error ``error`` per channel (of the points'
    sampling; the box filter's bias is apart, docs/addon.md), the material's faces counted
    ``faces``, the objects read ``objects`` and ``notes`` (sentence ends: a colour space read as
    sRGB, an object left out)."""

    rgb: np.ndarray | None
    error: np.ndarray | None
    faces: int
    objects: tuple = ()
    notes: list = field(default_factory=list)
    problem: str = ""


# -- progress -----------------------------------------------------------------------------------

@contextlib.contextmanager
def reporting(report: Report):
    """Send the progress of slow steps run inside (a cold mesh, an image decoded) to
    ``report(fraction, message)``."""
    _REPORTS.append(report)
    try:
        yield
    finally:
        _REPORTS.pop()


@contextlib.contextmanager
def progress_bar(window_manager):
    """Route the progress of what runs inside to ``window_manager.progress_update`` (the
    cursor's counter), begun on the first report only: a click that reads nothing shows
    nothing.  ``window_manager`` None, or headless: nothing is shown."""
    begun = []

    def report(fraction: float, message: str = "") -> None:
        if window_manager is None:
            return
        if not begun:
            window_manager.progress_begin(0, 100)
            begun.append(True)
        window_manager.progress_update(int(round(100 * min(max(fraction, 0.0), 1.0))))

    with reporting(report):
        try:
            yield
        finally:
            if begun:
                window_manager.progress_end()


def _report(fraction: float, message: str) -> None:
    if _REPORTS:
        _REPORTS[-1](fraction, message)


def clear_cache() -> None:
    """Forget the cached points and reduced images."""
    _POINTS.clear()
    _IMAGES.clear()


# -- points on the faces ------------------------------------------------------------------------

def users(material) -> list:
    """The mesh objects with ``material`` in one of their slots."""
    return [obj for obj in bpy.data.objects if obj.type == "MESH"
            and any(slot.material == material for slot in obj.material_slots)]


def face_points(face_area, loop_start, loop_total, corner_vert, positions, corner_uv,
                count: int, seed: int = SEED, *, with_positions: bool = False):
    """UVs ((count, 2) float32) of ``count`` points spread over the faces in proportion to
    ``face_area`` (zero: a face not counted), uniform within each face: stratified along the
    cumulative area (point i falls in the i-th of ``count`` equal shares, at a random place in
    it), then a triangle of the face's fan from its first corner by its area (``positions`` of
    the corners ``corner_vert``), then a uniform point in it, its UV interpolated from the
    corners' ``corner_uv``.  Faces are given by ``loop_start`` and ``loop_total`` (corners);
    fans assume convex faces.  ``with_positions``: ``(uv, position (count, 3), face index
    (count,))``."""
    rng = np.random.default_rng(seed)
    draws = rng.random((4, count))
    face_area = np.asarray(face_area, float)
    cumulative = np.cumsum(face_area)
    shares = (np.arange(count) + draws[0]) * (cumulative[-1] / count)
    last = np.flatnonzero(face_area > 0.0)[-1]  # a share rounded up to the total lands here
    face = np.minimum(np.searchsorted(cumulative, shares, side="right"), last)
    start = np.asarray(loop_start)[face].astype(np.int64)
    corners = np.asarray(loop_total)[face]
    uv = np.empty((count, 2), np.float32)
    xyz = np.empty((count, 3), np.float32) if with_positions else None
    for k in np.unique(corners):
        pick = np.flatnonzero(corners == k)
        loops = start[pick, None] + np.arange(k)
        second = np.ones(len(pick), np.int64)
        if k > 3:
            p = positions[corner_vert[loops]]
            fan = 0.5 * np.linalg.norm(np.cross(p[:, 1:-1] - p[:, :1], p[:, 2:] - p[:, :1]),
                                       axis=-1)
            partial = np.cumsum(fan, axis=1)
            below = partial < draws[1, pick, None] * partial[:, -1:]
            second += np.minimum(below.sum(axis=1), k - 3)
        rows = np.arange(len(pick))
        root = np.sqrt(draws[2, pick])
        weights = np.stack([1.0 - root, root * (1.0 - draws[3, pick]), root * draws[3, pick]])
        triangle = np.stack([loops[:, 0], loops[rows, second], loops[rows, second + 1]])
        uv[pick] = _interpolated(weights, corner_uv[triangle])
        if xyz is not None:
            xyz[pick] = _interpolated(weights, positions[corner_vert[triangle]])
    return (uv, xyz, face) if with_positions else uv


def _interpolated(weights: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """``sum_t weights[t, n] corners[t, n, :]`` over a triangle's three corners (``(3, n)``,
    ``(3, n, c)``): what ``einsum("tn,tnc->nc")`` gives, ten times faster on mixed
    precisions."""
    return (weights[0, :, None] * corners[0] + weights[1, :, None] * corners[1]
            + weights[2, :, None] * corners[2])


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


def _fingerprint(obj, layer, slots: tuple) -> tuple:
    """What the points of ``obj`` depend on, cheaply: the counts, the UV map's name, the slots,
    the transform's linear part and a CRC-32 of the positions, corners, material indices and
    UVs (the arrays copied whole: about 15 ms on a million triangles)."""
    mesh = obj.data
    crc = 0
    for read in (_positions, _corner_verts, _material_indices):  # one array at a time
        crc = zlib.crc32(np.ascontiguousarray(read(mesh)).data, crc)
    crc = zlib.crc32(_corner_uvs(layer).data, crc)
    return (len(mesh.vertices), len(mesh.loops), len(mesh.polygons), layer.name, slots,
            tuple(_linear_part(obj).ravel()), crc)


def _face_areas(obj, slots: tuple) -> tuple[np.ndarray, int]:
    """``(areas, faces)``: the world areas (square metres, float64) of ``obj``'s faces, zero
    for faces of other slots, and how many faces the slots have (a material index beyond the
    slots counts as the last slot, as Blender draws it)."""
    mesh = obj.data
    count = len(mesh.polygons)
    area = _array(mesh.polygons, "area", count, np.float32).astype(float)
    index = np.minimum(_material_indices(mesh), max(len(obj.material_slots) - 1, 0))
    used = np.isin(index, slots)
    area[~used] = 0.0
    faces = int(np.count_nonzero(used))
    linear = _linear_part(obj)
    gram = linear.T @ linear
    scale = np.trace(gram) / 3.0
    if np.allclose(gram, scale * np.eye(3), rtol=0.0, atol=1e-9 * max(scale, 1e-30)):
        return area * scale, faces  # a rotation and a uniform scale: areas times its square
    # Otherwise a face's area grows by |cof(M) n| along its unit normal n, cof(M) = det(M)
    # M^-T, whose columns are the cross products of M's (defined for a flattened M too).
    normal = _array(mesh.polygons, "normal", 3 * count, np.float32).reshape(-1, 3)
    a, b, c = linear.T
    cofactor = np.column_stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)])
    return area * np.linalg.norm(normal @ cofactor.T, axis=1), faces


def _points(obj, layer, area: np.ndarray, faces: int, count: int) -> Points:
    mesh = obj.data
    loop_start = _array(mesh.polygons, "loop_start", len(mesh.polygons), np.int32)
    if np.all(np.diff(loop_start) > 0):
        loop_total = np.diff(loop_start, append=len(mesh.loops))
    else:
        loop_total = _array(mesh.polygons, "loop_total", len(mesh.polygons), np.int32)
    uv, position, face = face_points(area, loop_start, loop_total, _corner_verts(mesh),
                                     _positions(mesh), _corner_uvs(layer), count,
                                     with_positions=True)
    normal = _array(mesh.polygons, "normal", 3 * len(mesh.polygons), np.float32).reshape(-1, 3)
    return Points(uv, float(area.sum()), faces, position, normal[face])


class _Surface:
    """One object's faces of a material at a UV map: their fingerprint, and their points from
    the cache while it matches."""

    def __init__(self, obj, material, layer):
        self.obj, self.layer = obj, layer
        self.slots = _slots(obj, material)
        self.key = (obj.session_uid, material.session_uid, layer.name)
        self.fingerprint = _fingerprint(obj, layer, self.slots)
        entry = _POINTS.get(self.key)
        self.cached = entry[1] if entry is not None and entry[0] == self.fingerprint else None
        self._areas: tuple[np.ndarray, int] | None = None

    def areas(self) -> tuple[np.ndarray, int]:
        """``(areas, faces)`` of :func:`_face_areas`, read once."""
        if self._areas is None:
            self._areas = _face_areas(self.obj, self.slots)
        return self._areas

    def area(self) -> float:
        """The faces' world area, from the cache when it holds them."""
        return self.cached.area if self.cached is not None else float(self.areas()[0].sum())

    def points(self, count: int) -> Points:
        if self.cached is not None and len(self.cached.uv) == count:
            return self.cached
        areas, faces = self.areas()
        points = (_points(self.obj, self.layer, areas, faces, count)
                  if count > 0 and areas.sum() > 0.0
                  else Points(np.empty((0, 2), np.float32), float(areas.sum()), faces))
        _POINTS.put(self.key, (self.fingerprint, points))
        self.cached = points
        return points


def object_points(obj, material, layer, count: int = BUDGET) -> Points:
    """``count`` points of ``obj``'s faces that use ``material``, at the UV map ``layer``
    (:func:`face_points`), kept until the mesh, its UVs, slots or transform change.  Faces of
    other slots do not count."""
    return _Surface(obj, material, layer).points(int(count))


def _shares(areas: list[float], budget: int) -> list[int]:
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


# -- the image ----------------------------------------------------------------------------------

def srgb_to_linear(values: np.ndarray) -> np.ndarray:
    """The sRGB curve undone (IEC 61966-2-1), as Blender linearises an sRGB texture.  Worked
    on a contiguous copy: numpy's vectorised power needs one (on the RGB view of RGBA
    pixels it is six times slower)."""
    values = np.ascontiguousarray(values)  # float32 stays float32
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


def box_factor(width: int, height: int, size: int) -> int:
    """The smallest whole factor that brings both sides to at most ``size``."""
    return max(1, -(-max(width, height) // size))


def box_reduce(pixels: np.ndarray, factor: int) -> np.ndarray:
    """``pixels`` ((h, w, c)) averaged over boxes of ``factor`` x ``factor`` texels (boxes at
    the far edges may be smaller), float32."""
    if factor == 1:
        return np.asarray(pixels, np.float32)
    height, width = pixels.shape[:2]
    rows = np.arange(0, height, factor)
    columns = np.arange(0, width, factor)
    summed = np.add.reduceat(np.add.reduceat(pixels, rows, axis=0, dtype=float), columns,
                             axis=1)
    counts = np.diff(rows, append=height)[:, None] * np.diff(columns, append=width)[None, :]
    return (summed / counts[..., None]).astype(np.float32)


def _rgb(values: np.ndarray, width: int, height: int) -> np.ndarray:
    """Flat pixels of any channel count as (height, width, 3): grey repeated."""
    pixels = values.reshape(height, width, -1)
    return pixels[..., :3] if pixels.shape[-1] >= 3 else np.repeat(pixels[..., :1], 3, axis=-1)


def _linearised(rgb: np.ndarray, is_float: bool, settings) -> tuple[np.ndarray, str]:
    """``(linear values, note)``: as a texture node reads pixels of this colour space.  Float
    buffers are scene linear once loaded; byte buffers keep their colour space's encoding."""
    space = settings.name
    if is_float or settings.is_data or space in LINEAR_SPACES:
        return rgb, ""
    if space.startswith("Linear") or space in {"ACEScg", "ACES2065-1"}:
        return rgb, f"its colour space {space!r} was read as Linear Rec.709"
    note = "" if space == "sRGB" else f"its colour space {space!r} was read as sRGB"
    return srgb_to_linear(rgb), note


def _whole(image, size: int) -> ReducedImage:
    """An image whose pixels live only in memory (generated, or with unsaved changes), which a
    copy would not have: read whole (16 bytes a texel), linearised and box-filtered a band of
    rows at a time."""
    width, height = image.size
    if width * height == 0:
        return ReducedImage(None, problem=f"image {image.name!r} has no pixels")
    values = np.empty(width * height * image.channels, np.float32)
    image.pixels.foreach_get(values)
    rgb = _rgb(values, width, height)
    factor = box_factor(width, height, size)
    band = factor * max(1, (1 << 20) // (factor * width))
    parts, note = [], ""
    for start in range(0, height, band):
        linear, note = _linearised(rgb[start:start + band], image.is_float,
                                   image.colorspace_settings)
        parts.append(box_reduce(linear, factor))
    return ReducedImage(np.concatenate(parts), note)


def _scaled_copy(image, size: int) -> ReducedImage | None:
    """An image read through a temporary copy scaled down by Blender's box filter (never the
    whole float buffer), the copy removed whatever happens; None when the copy has no pixels
    (the file is missing)."""
    copy = image.copy()
    try:
        width, height = copy.size
        if width * height == 0:
            return None
        factor = box_factor(width, height, size)
        if factor > 1:
            width, height = -(-width // factor), -(-height // factor)
            copy.scale(width, height)
        values = np.empty(width * height * copy.channels, np.float32)
        copy.pixels.foreach_get(values)
        is_float = copy.is_float
    finally:
        bpy.data.images.remove(copy)
    linear, note = _linearised(_rgb(values, width, height), is_float, image.colorspace_settings)
    return ReducedImage(np.ascontiguousarray(linear, np.float32), note)


def _image_fingerprint(image) -> tuple:
    """What an image's pixels depend on, without decoding it: its source, file (path, date,
    size), packed data, colour space, generated settings, alpha."""
    stat = None
    if image.source in {"FILE", "SEQUENCE", "MOVIE", "TILED"} and not image.packed_files:
        with contextlib.suppress(OSError):
            info = os.stat(bpy.path.abspath(image.filepath, library=image.library))
            stat = (info.st_mtime_ns, info.st_size)
    packed = tuple((p.packed_file.size, p.packed_file.as_pointer()) for p in image.packed_files)
    generated = ((image.generated_width, image.generated_height, image.generated_type,
                  tuple(image.generated_color), image.use_generated_float)
                 if image.source == "GENERATED" else None)
    return (image.source, image.filepath_raw, stat, packed, image.colorspace_settings.name,
            image.alpha_mode, generated, image.is_dirty)


def reduced_image(image, size: int = IMAGE_SIZE) -> ReducedImage:
    """``image`` as its texture node reads it (linear), box-filtered down to at most ``size``
    texels across; kept until the image changes (an image with unsaved changes is read again
    each time: nothing cheap tells a second paint stroke from the first)."""
    reduced = _cached_image(image, size)
    if reduced is None:
        _report(0.0, f"Reading image {image.name!r}")
        reduced = _read(image, size)
        _IMAGES.put((image.session_uid, size), (_image_fingerprint(image), reduced))
    return reduced


def _cached_image(image, size: int) -> ReducedImage | None:
    entry = _IMAGES.get((image.session_uid, size))
    if entry is None or image.is_dirty or entry[0] != _image_fingerprint(image):
        return None
    return entry[1]


def _read(image, size: int) -> ReducedImage:
    reduced = _read_pixels(image, size)
    if image.source == "TILED" and reduced.pixels is not None:
        tiled = f"image {image.name!r} is tiled: its first tile was read for every UV"
        return ReducedImage(reduced.pixels, "; ".join(n for n in (reduced.note, tiled) if n))
    return reduced


def _read_pixels(image, size: int) -> ReducedImage:
    if image.source == "VIEWER":
        return ReducedImage(None, problem=f"image {image.name!r} is a render result")
    if image.is_dirty or image.source == "GENERATED":
        return _whole(image, size)
    reduced = _scaled_copy(image, size)
    if reduced is not None:
        return reduced
    if image.has_data:  # loaded before its file went missing
        return _whole(image, size)
    path = f" {image.filepath!r}" if image.filepath else ""
    return ReducedImage(None, problem=f"image {image.name!r} has no pixels (its file{path} is "
                                      f"missing)")


def read_texels(pixels: np.ndarray, uv: np.ndarray, extension: str = "REPEAT") -> np.ndarray:
    """The texels of ``pixels`` ((h, w, 3), rows bottom-up) nearest each UV ((n, 2)), the UVs
    wrapped as an image texture's ``extension`` does: REPEAT, MIRROR, EXTEND (clamped) or CLIP
    (black outside the image)."""
    height, width = pixels.shape[:2]
    uv = np.asarray(uv, float)
    if extension == "REPEAT":
        wrapped = uv - np.floor(uv)
    elif extension == "MIRROR":
        wrapped = 1.0 - np.abs(np.mod(uv, 2.0) - 1.0)
    else:
        wrapped = uv
    column = np.clip((wrapped[:, 0] * width).astype(np.int64), 0, width - 1)
    row = np.clip((wrapped[:, 1] * height).astype(np.int64), 0, height - 1)
    values = pixels[row, column].astype(float)
    if extension == "CLIP":
        values[np.any((uv < 0.0) | (uv > 1.0), axis=1)] = 0.0
    return values


# -- the mean -----------------------------------------------------------------------------------

def _uv_layer(mesh, uv_map: str):
    if uv_map:
        return mesh.uv_layers.get(uv_map)
    return next((layer for layer in mesh.uv_layers if layer.active_render), None)


def _missing_uv(obj, uv_map: str, reader: str) -> str:
    by = f" (read by {reader!r})" if reader else ""
    return f"{obj.name!r} has no UV map {uv_map!r}{by}" if uv_map else \
        f"{obj.name!r} has no UV map{by}"


def surface_mean(image, material, *, uv_map: str = "", extension: str = "REPEAT",
                 reader: str = "", budget: int = BUDGET, size: int = IMAGE_SIZE) -> SurfaceMean:
    """The mean of ``image`` over the faces that use ``material`` on every mesh object, weighted
    by their area in the world: ``budget`` points split between the objects by area
    (:func:`object_points`), read at the UV map ``uv_map`` (the active render map when empty)
    in the image box-filtered to ``size`` (:func:`reduced_image`) with the texture's
    ``extension``.  ``reader``: the texture node's name, for the messages.  An object without
    that UV map is left out (said in ``notes``); with no face left, ``rgb`` is None and
    ``problem`` says why."""
    objects = users(material)
    if not objects:
        return SurfaceMean(None, None, 0, problem=f"no mesh object uses {material.name!r}")
    notes, missing, readable = [], [], []
    for obj in objects:
        if obj.mode == "EDIT":
            obj.update_from_editmode()  # the mesh as it is being edited
        layer = _uv_layer(obj.data, uv_map)
        if layer is None:
            missing.append(_missing_uv(obj, uv_map, reader))
        else:
            readable.append((obj, layer))
    if not readable:
        return SurfaceMean(None, None, 0, problem="; ".join(missing))
    notes += [f"{text}: left out" for text in missing]
    slow = _cached_image(image, size) is None
    reduced = reduced_image(image, size)  # first: its decoder's peak is the call's
    if reduced.pixels is None:
        return SurfaceMean(None, None, 0, notes=notes, problem=reduced.problem)
    surfaces = [_Surface(obj, material, layer) for obj, layer in readable]
    cold = [surface for surface in surfaces if surface.cached is None]
    for step, surface in enumerate(cold):
        _report(0.6 + 0.4 * step / len(cold), f"Reading the faces of {surface.obj.name!r}")
        surface.areas()
    counts = _shares([surface.area() for surface in surfaces], budget)
    every = [(surface.obj, surface.points(n)) for surface, n in zip(surfaces, counts,
                                                                    strict=True)]
    faces = sum(points.faces for _, points in every)
    picked = [(obj, points) for obj, points in every if len(points.uv)]
    if not picked:
        why = (f"the {faces} faces that use {material.name!r} have no area" if faces else
               f"no face uses {material.name!r}")
        return SurfaceMean(None, None, faces, notes=notes, problem=why)
    total = sum(points.area for _, points in picked)
    rgb, variance = np.zeros(3), np.zeros(3)
    for _, points in picked:
        values = read_texels(reduced.pixels, points.uv, extension)
        share = points.area / total
        rgb += share * values.mean(axis=0)
        variance += share ** 2 * values.var(axis=0) / len(values)
    if slow or cold:
        _report(1.0, "")
    if reduced.note:
        notes.insert(0, reduced.note)
    return SurfaceMean(rgb, np.sqrt(variance), faces, tuple(obj.name for obj, _ in picked),
                       notes)



# -- points for evaluating the artist's shader ---------------------------------------------------

class SurfaceSamples:
    """The points of a material's surface as :mod:`.surface_values` evaluates the artist's
    shader at them (:class:`.surface_values.Samples`): the same points (faces and places in
    them: the seed and the areas fix them) at every UV map, ``weights`` (each point's share of
    the area), image values read from the reduced image (:func:`reduced_image`).

    An object without a UV map a texture reads is left out for that map (said in ``notes``);
    with no face to read (``problem`` says why: no object, no face of the material, no UV
    map), one point at UV (0, 0) stands for the surface."""

    def __init__(self, material, budget: int = BUDGET, scene=None):
        self.material = material
        self.scene = scene
        self.camera = scene.camera if scene is not None else None
        self.objects = users(material)
        for obj in self.objects:
            if obj.mode == "EDIT":
                obj.update_from_editmode()
        self._uv: dict = {}
        self.budget = budget
        self.count = 0
        self.weights: np.ndarray | None = None
        self.notes: list[str] = []
        self.faces = 0
        self.seen_by = ""
        self.problem = "" if self.objects else f"no mesh object uses {material.name!r}"

    def _note(self, sentence: str) -> None:
        if sentence and sentence not in self.notes:
            self.notes.append(sentence)

    def uv(self, name: str, reader: str = "") -> np.ndarray:
        """``(count, 2)`` UVs of the map ``name`` (``""``: each mesh's active render map);
        the objects without it are left out (noted)."""
        if name in self._uv:
            return self._uv[name]
        surfaces, missing = [], []
        for obj in self.objects:
            layer = _uv_layer(obj.data, name)
            if layer is None:
                missing.append(_missing_uv(obj, name, reader))
            else:
                surfaces.append(_Surface(obj, self.material, layer))
        counts = _shares([surface.area() for surface in surfaces], self.budget)
        picked = [(surface.points(n), n) for surface, n in zip(surfaces, counts, strict=True)
                  if n > 0]
        if not picked:
            faces = sum(surface.areas()[1] for surface in surfaces)
            if missing and not surfaces:
                self._note(f"{'; '.join(missing)}: read at UV (0, 0)")
            elif self.objects:
                self.problem = (f"no face uses {self.material.name!r}" if not faces else
                                f"the {faces} faces that use {self.material.name!r} have no "
                                f"area")
            return self._remember(name, np.zeros((1, 2)), np.ones(1))
        for sentence in missing:
            self._note(f"{sentence}: left out")
        uv = np.concatenate([points.uv for points, _ in picked]).astype(float)
        weights = np.concatenate([np.full(len(points.uv), points.area / n)
                                  for points, n in picked])
        if self.weights is None:
            self.faces = sum(points.faces for points, _ in picked)
        if self.camera is not None and self.weights is None:
            seen = np.concatenate([_seen(surface.obj, points, self.camera, self.scene)
                                   for surface, (points, _) in zip(
                                       [s for s, n in zip(surfaces, counts, strict=True)
                                        if n > 0], picked, strict=True)])
            if np.any(seen > 0.0):
                weights = weights * seen
                self.seen_by = self.camera.name
            else:
                self._note(f"the camera {self.camera.name!r} sees none of it: the whole "
                           f"surface counts")
        return self._remember(name, uv, weights)

    def _remember(self, name: str, uv, weights):
        if self.weights is None:
            self.weights, self.count = weights, len(uv)
        elif len(uv) != self.count:  # the objects left out differ between maps
            uv = np.broadcast_to(uv.mean(axis=0), (self.count, 2))
            self._note(f"UV map {name!r} read at its mean (not every object has it)")
        self._uv[name] = uv
        return uv

    def image(self, image, uv: np.ndarray, extension: str) -> np.ndarray:
        """``(count, 4)`` linear RGBA of ``image`` at ``uv`` (alpha 1)."""
        reduced = reduced_image(image)
        if reduced.pixels is None:
            self._note(reduced.problem)
            return np.zeros((len(uv), 4))
        self._note(reduced.note)
        rgb = read_texels(reduced.pixels, uv, extension)
        return np.concatenate([rgb, np.ones((len(rgb), 1))], axis=1)


def _seen(obj, points: Points, camera, scene) -> np.ndarray:
    """How much of each point the camera sees: its area's projection towards the camera (the
    cosine between its face's normal and the direction to the camera, 0 facing away) where it
    falls inside the camera's frame and in front of it, else 0 (hidden surfaces are not
    looked for)."""
    matrix = np.array(obj.matrix_world, float)
    position = points.position @ matrix[:3, :3].T + matrix[:3, 3]
    normal = points.normal @ np.linalg.inv(matrix[:3, :3])  # the inverse transpose, by rows
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-30)
    view = np.array(camera.matrix_world, float)
    local = (position - view[:3, 3]) @ view[:3, :3]  # in the camera's frame (looks down -z)
    frame = np.array([tuple(corner) for corner in camera.data.view_frame(scene=scene)])
    if camera.data.type == "ORTHO":
        towards = np.broadcast_to(view[:3, 2], position.shape)
        x, y = local[:, 0], local[:, 1]
        inside = np.ones(len(local), bool)
    else:
        towards = view[:3, 3] - position
        towards = towards / np.maximum(np.linalg.norm(towards, axis=1, keepdims=True), 1e-30)
        depth = -local[:, 2]
        inside = depth > 0.0
        scale = -frame[0, 2] / np.where(inside, depth, 1.0)
        x, y = local[:, 0] * scale, local[:, 1] * scale
    inside &= ((x >= frame[:, 0].min()) & (x <= frame[:, 0].max())
               & (y >= frame[:, 1].min()) & (y <= frame[:, 1].max()))
    return np.where(inside, np.maximum(np.sum(normal * towards, axis=1), 0.0), 0.0)


def surface_samples(material, progress: Report | None = None, scene=None) -> SurfaceSamples:
    """The points of ``material``'s surface for evaluating its shader
    (:class:`SurfaceSamples`; their UVs are read, and cached, when first asked for); with a
    ``scene`` that has a camera, each point counts by how much of it the camera sees
    (:func:`_seen`: the skin as the camera shows it), else by its area."""
    if scene is not None and scene.camera is not None and scene == bpy.context.scene:
        bpy.context.view_layer.update()  # matrices follow moves only after an update
    samples = SurfaceSamples(material, scene=scene)
    if progress is not None:
        with reporting(progress):
            samples.uv("")
    return samples
