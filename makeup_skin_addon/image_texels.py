"""An image as its texture node reads it, box-filtered small: the skin's mean colour and the
artist's shader read at points of the surface (:mod:`.skin_sampling`).

The image is read box-filtered to at most :data:`IMAGE_SIZE` texels across (a temporary copy
scaled down, removed at once), never as the whole float buffer, and linearised as the texture
node does.  The reduced pixels are cached for the session until the image changes (source,
file and its date, packed data, colour space).  An image with unsaved changes (painted in
Blender) has nothing but its pixels to tell one paint stroke from the next: its float buffer
is read whole at each call and reduced again only when its CRC-32 changed.

- :func:`reduced_image` -- an image box-filtered to at most :data:`IMAGE_SIZE`, linear
  (cached, :class:`ReducedImage`); :func:`is_cached` -- whether it is.
- :func:`reduced_tiles`, :func:`tile_files` -- a tiled (UDIM) image's tiles, each reduced
  from its file.
- :func:`box_factor`, :func:`box_reduce` -- the filter in numpy; :func:`srgb_to_linear` -- the
  sRGB curve; :func:`srgb_codes_to_linear` -- the same on a byte image's codes, by table.
- :func:`finite_values` -- a reduced image's texels (or any values) that are not finite
  replaced.
- :func:`read_texels` -- a reduced image at UVs, wrapped as the texture's extension says.
- :func:`clear_cache` -- forget the reduced images.
"""

from __future__ import annotations

import os
import zlib
from dataclasses import dataclass
from typing import Any

import bpy
import numpy as np

from . import image_store, pages
from .core import cache
from .progress import report

__all__ = ["IMAGE_SIZE", "ReducedImage", "reduced_image", "reduced_tiles", "tile_files",
           "is_cached", "box_factor",
           "box_reduce", "srgb_to_linear", "srgb_codes_to_linear", "finite_values",
           "read_texels", "clear_cache"]

IMAGE_SIZE = 512
"""The longest side, in texels, the image is box-filtered down to before it is read."""
LINEAR_SPACES = frozenset({"Linear Rec.709", "scene_linear", "Non-Color"})
"""Colour spaces whose values a texture node reads as they are (Blender's scene linear)."""
IMAGES_CACHE_SIZE = 8
"""Reduced images (or tiles of one) kept (3 MB each at :data:`IMAGE_SIZE`); beyond them, a
file image is read again from its store on disk (:mod:`.image_store`)."""

_IMAGES = cache.LRUCache(IMAGES_CACHE_SIZE)


@dataclass(frozen=True)
class ReducedImage:
    """An image as its texture node reads it, box-filtered: ``pixels`` ((h, w, 3) float32,
    linear; None when the image has none), a ``note`` on how it was read (or "") and the
    ``problem`` that left it without pixels (or "")."""

    pixels: np.ndarray | None
    note: str = ""
    problem: str = ""


def srgb_to_linear(values: np.ndarray) -> np.ndarray:
    """The sRGB curve undone (IEC 61966-2-1), as Blender linearises an sRGB texture.  Worked
    on a contiguous copy: numpy's vectorised power needs one (on the RGB view of RGBA
    pixels it is six times slower)."""
    values = np.ascontiguousarray(values)  # float32 stays float32
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


_SRGB_CODES = srgb_to_linear(np.arange(256, dtype=np.float32) / np.float32(255.0))
""":func:`srgb_to_linear` of the 256 byte codes (float32)."""


def srgb_codes_to_linear(values: np.ndarray) -> np.ndarray:
    """:func:`srgb_to_linear` of a byte buffer's values (each ``code / 255``, as Blender
    gives a byte image's pixels) by a table of the 256 codes: the same values, a third of the
    time of the curve on a 4096 px image, float32."""
    codes = np.multiply(values, np.float32(255.0), dtype=np.float32)
    codes += np.float32(0.5)  # in place: one float buffer the image's size at a time
    index = codes.astype(np.uint8)
    del codes
    return _SRGB_CODES[index]  # a byte index (``np.take`` would copy it as 8-byte integers)


def box_factor(width: int, height: int, size: int) -> int:
    """The smallest whole factor that brings both sides to at most ``size``."""
    return max(1, -(-max(width, height) // size))


def box_reduce(pixels: np.ndarray, factor: int) -> np.ndarray:
    """``pixels`` ((h, w, c)) averaged over boxes of ``factor`` x ``factor`` texels (boxes at
    the far edges may be smaller), float32."""
    if factor == 1:
        return np.asarray(pixels, np.float32)
    height, width = pixels.shape[:2]
    if height % factor == 0 and width % factor == 0:  # whole boxes: two reshaped sums
        rows = pixels.reshape(height // factor, factor, width, -1).sum(axis=1, dtype=float)
        return (rows.reshape(height // factor, width // factor, factor, -1).sum(axis=2)
                / factor**2).astype(np.float32)
    rows = np.arange(0, height, factor)
    columns = np.arange(0, width, factor)
    summed = np.add.reduceat(np.add.reduceat(pixels, rows, axis=0, dtype=float), columns,
                             axis=1)
    counts = np.diff(rows, append=height)[:, None] * np.diff(columns, append=width)[None, :]
    return (summed / counts[..., None]).astype(np.float32)


def _rgb(pixels: np.ndarray) -> np.ndarray:
    """Pixels ``(height, width, channels)`` of any channel count as (height, width, 3): grey
    repeated."""
    return pixels[..., :3] if pixels.shape[-1] >= 3 else np.repeat(pixels[..., :1], 3, axis=-1)


def _linearised(pixels: np.ndarray, is_float: bool, settings) -> tuple[np.ndarray, str]:
    """``(linear values, note)``: as a texture node reads pixels of this colour space (every
    channel, before :func:`_rgb` picks them: the whole pixel is contiguous, its RGB view is
    not, and the codes are computed several times faster on it).  Float buffers are scene
    linear once loaded; byte buffers keep their colour space's encoding (their values are byte
    codes: linearised by :func:`srgb_codes_to_linear`)."""
    space = settings.name
    if is_float or settings.is_data or space in LINEAR_SPACES:
        return pixels, ""
    if space.startswith("Linear") or space in {"ACEScg", "ACES2065-1"}:
        return pixels, f"its colour space {space!r} was read as Linear Rec.709"
    note = "" if space == "sRGB" else f"its colour space {space!r} was read as sRGB"
    return srgb_codes_to_linear(pixels), note


def _whole(image, size: int) -> ReducedImage:
    """A generated image, whose pixels live only in memory (a copy would not have them), or
    one loaded already at most ``size`` across (a copy would decode its file again, for the
    same pixels): read whole (16 bytes a texel), linearised and box-filtered."""
    pixels = _float_buffer(image)
    return _no_pixels(image) if pixels is None else _reduced_buffer(image, pixels, size)


def _no_pixels(image) -> ReducedImage:
    return ReducedImage(None, problem=f"image {image.name!r} has no pixels")


def _float_buffer(image) -> np.ndarray | None:
    """``image``'s pixels ((h, w, channels) float32, Blender's whole float buffer), None when
    it has none."""
    width, height = image.size
    if width * height == 0:
        return None
    values = np.empty(width * height * image.channels, np.float32)
    image.pixels.foreach_get(values)
    return values.reshape(height, width, -1)


def _reduced_buffer(image, pixels: np.ndarray, size: int) -> ReducedImage:
    """``image``'s float buffer ``pixels`` linearised and box-filtered a band of rows at a
    time."""
    height, width = pixels.shape[:2]
    factor = box_factor(width, height, size)
    band = factor * max(1, (1 << 20) // (factor * width))
    parts, note = [], ""
    for start in range(0, height, band):
        linear, note = _linearised(pixels[start:start + band], image.is_float,
                                   image.colorspace_settings)
        parts.append(_rgb(box_reduce(linear, factor)))  # every channel: no strided copy
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
    linear, note = _linearised(values.reshape(height, width, -1), is_float,
                               image.colorspace_settings)
    return ReducedImage(np.ascontiguousarray(_rgb(linear), np.float32), note)


def _image_fingerprint(image) -> tuple:
    """What an image's pixels depend on, without decoding it: its source, file (path, date,
    size), packed data, colour space, generated settings, alpha."""
    stat = None
    if image.source in {"FILE", "SEQUENCE", "MOVIE", "TILED"} and not image.packed_files:
        stat = _file_stamp(bpy.path.abspath(image.filepath, library=image.library))
    packed = tuple((p.packed_file.size, p.packed_file.as_pointer()) for p in image.packed_files)
    generated = ((image.generated_width, image.generated_height, image.generated_type,
                  tuple(image.generated_color), image.use_generated_float)
                 if image.source == "GENERATED" else None)
    return (image.source, image.filepath_raw, stat, packed, image.colorspace_settings.name,
            image.alpha_mode, generated, image.is_dirty)


@pages.ordinary()
def reduced_image(image, size: int = IMAGE_SIZE) -> ReducedImage:
    """``image`` as its texture node reads it (linear), box-filtered down to at most ``size``
    texels across; kept until the image changes (an image with unsaved changes: until its
    pixels do, :func:`_painted`)."""
    if image.is_dirty and image.source != "VIEWER":
        return _painted(image, size)
    reduced = _cached_image(image, size)
    if reduced is None:
        reduced = _stored_or_read(image, size)
        _IMAGES.put((image.session_uid, size), (_image_fingerprint(image), reduced))
    return reduced


def _painted(image, size: int) -> ReducedImage:
    """An image with unsaved changes: its float buffer read whole (nothing cheaper tells a
    paint stroke happened: Blender reads a single texel as the whole buffer too), reduced again
    only when its CRC-32 (60 ms for a 4096 px image) differs from the last read's."""
    pixels = _float_buffer(image)
    if pixels is None:
        return _no_pixels(image)
    fingerprint = (_image_fingerprint(image), zlib.crc32(pixels.data))
    entry = _IMAGES.get((image.session_uid, size))
    if entry is not None and entry[0] == fingerprint:
        return entry[1]
    report(0.0, f"Reading image {image.name!r}")
    reduced = _finished(image, _reduced_buffer(image, pixels, size))
    _IMAGES.put((image.session_uid, size), (fingerprint, reduced))
    return reduced


def _stored_or_read(image, size: int) -> ReducedImage:
    """``image`` reduced, from :mod:`.image_store` when an earlier session kept it, else read
    (and kept there when it is a file image)."""
    name = image_store.key(image, size)
    stored = image_store.load(name) if name is not None else None
    if stored is not None:
        return ReducedImage(*stored)
    report(0.0, f"Reading image {image.name!r}")
    reduced = _read(image, size)
    if name is not None and reduced.pixels is not None:
        image_store.save(name, reduced.pixels, reduced.note)
    return reduced


def tile_files(image) -> dict[int, str]:
    """The file of each tile of a tiled (UDIM) image, by tile number (absolute paths: its
    path's ``<UDIM>`` or ``<UVTILE>`` token replaced), or {} when its tiles are not files
    (packed, generated)."""
    if image.source != "TILED" or image.packed_files:
        return {}
    path = bpy.path.abspath(image.filepath, library=image.library)
    if "<UDIM>" not in path and "<UVTILE>" not in path:
        return {}
    return {tile.number: path.replace("<UDIM>", str(tile.number)).replace(
        "<UVTILE>", f"u{(tile.number - 1001) % 10 + 1}_v{(tile.number - 1001) // 10 + 1}")
        for tile in image.tiles}


@pages.ordinary()
def reduced_tiles(image, size: int = IMAGE_SIZE) -> dict[int, ReducedImage]:
    """The tiles of a tiled image whose tiles are files (:func:`tile_files`), each reduced as
    a file image of its own (kept in memory until its file changes, and on disk between
    sessions), by tile number; {} when its tiles are not files."""
    return {number: _tile(image, path, size) for number, path in tile_files(image).items()}


def _file_stamp(path: str) -> tuple[int, int] | None:
    """A file's ``(date in ns, size)``, None when it cannot be read."""
    try:
        info = os.stat(path)
    except OSError:
        return None
    return info.st_mtime_ns, info.st_size


def _tile(image, path: str, size: int) -> ReducedImage:
    stat = _file_stamp(path)
    key = (image.session_uid, size, path)
    fingerprint = (stat, image.colorspace_settings.name, image.alpha_mode)
    entry = _IMAGES.get(key)
    if entry is not None and entry[0] == fingerprint:
        return entry[1]
    if stat is None:
        reduced = ReducedImage(None, problem=f"image {image.name!r} has no file {path!r} for "
                                             f"a tile")
    else:
        tile = bpy.data.images.load(path, check_existing=False)  # its own, removed at once
        try:
            tile.colorspace_settings.name = image.colorspace_settings.name
            tile.alpha_mode = image.alpha_mode
            reduced = _stored_or_read(tile, size)
        finally:
            bpy.data.images.remove(tile)
    _IMAGES.put(key, (fingerprint, reduced))
    return reduced


def is_cached(image: Any, size: int = IMAGE_SIZE) -> bool:
    """Whether :func:`reduced_image` has ``image`` at ``size`` and it has not changed since."""
    return _cached_image(image, size) is not None


def _cached_image(image: Any, size: int) -> ReducedImage | None:
    entry = _IMAGES.get((image.session_uid, size))
    if entry is None or image.is_dirty or entry[0] != _image_fingerprint(image):
        return None
    return entry[1]


def _read(image, size: int) -> ReducedImage:
    return _finished(image, _read_pixels(image, size))


def _finished(image, reduced: ReducedImage) -> ReducedImage:
    """``reduced`` as it is kept: its texels made finite (:func:`finite_values`), with a note
    saying so, and one when ``image`` is tiled (its first tile stands for all)."""
    if reduced.pixels is None:
        return reduced
    pixels, bad = finite_values(reduced.pixels)
    notes = [reduced.note]
    if bad:
        notes.append(f"image {image.name!r} is not finite in {bad} of its {len(pixels[0])} x "
                     f"{len(pixels)} reduced texels (NaN or infinite texels): taken as the "
                     f"mean of the others")
    if image.source == "TILED":  # its tiles are not files (else read by reduced_tiles)
        notes.append(f"image {image.name!r} is tiled, its tiles not files: taken as its first "
                     f"tile at every UV")
    return ReducedImage(pixels, "; ".join(n for n in notes if n))


def finite_values(pixels: np.ndarray) -> tuple[np.ndarray, int]:
    """``(pixels, count)``: ``pixels`` (``(..., c)``: a reduced image's texels, or any values
    by row) with each one that is not finite in some channel (a NaN or an infinity in the
    image, spread by the box filter) replaced by the mean of the finite ones (0 without any),
    and how many there were."""
    bad = ~np.all(np.isfinite(pixels), axis=-1)
    count = int(np.count_nonzero(bad))
    if count == 0:
        return pixels, 0
    fixed = np.array(pixels)
    good = fixed[~bad]
    fixed[bad] = good.mean(axis=0) if len(good) else 0.0
    return fixed, count


def _loaded_small(image, size: int) -> bool:
    """Whether ``image`` is a file image loaded already (its size known without decoding it)
    and at most ``size`` across (nothing to scale)."""
    if image.source != "FILE" or not image.has_data:
        return False
    width, height = image.size
    return box_factor(width, height, size) == 1


def _read_pixels(image, size: int) -> ReducedImage:
    if image.source == "VIEWER":
        return ReducedImage(None, problem=f"image {image.name!r} is a render result")
    if image.source in {"SEQUENCE", "MOVIE"}:
        kind = "an image sequence" if image.source == "SEQUENCE" else "a movie"
        return ReducedImage(None, problem=f"image {image.name!r} is {kind}: its frames are "
                                          f"not read")
    if image.source == "GENERATED" or _loaded_small(image, size):
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
    # One gather of whole texels by their flat index (indexing rows and columns apart
    # gathers several times slower).
    values = pixels.reshape(height * width, -1).take(row * width + column, axis=0).astype(float)
    if extension == "CLIP":
        outside = (uv < 0.0) | (uv > 1.0)
        values[outside[:, 0] | outside[:, 1]] = 0.0
    return values


def clear_cache() -> None:
    """Forget the reduced images."""
    _IMAGES.clear()
