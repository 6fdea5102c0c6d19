"""What a made-up material keeps in the .blend: the images its render reads and the record of
its bake, never the tables themselves.

A bake is identified by its record (:func:`bake_record`): the made-up skin's parameters, the
resolution name and their key (:func:`bake_key`, a hash of those two and of the tables' format:
the same settings give the same key on any machine, without baking).  Baking is deterministic
and takes a fraction of a second, so the tables are re-baked from the record when Check Tables
or a re-fit needs them (:func:`rebake`, cached for the session) instead of travelling in every
saved file.  The
images a group reads (the Layered tier's view-angle image) are packed, and the group records
the SHA-256 of their pixels and of their packed bytes (:func:`image_record`), so damage is
found before Blender decodes the image (:func:`image_problem`).

- :func:`bake_key`, :func:`bake_record`, :func:`rebake` -- a bake's key and record, and the
  tables again from it.
- :func:`lut_image` -- the Layered tier's view-angle image (named by
  :func:`.keys.lut_image_name`).
- :func:`image_record`, :func:`image_problem` -- an image's hashes, and what is wrong with it;
  :func:`image_problems` for a group's images.
- :func:`write_pixels` -- pixels into an image, packed.
"""

from __future__ import annotations

import hashlib
import json

import bpy
import numpy as np

from .core import bake, cache, codec, params_file, table_set

__all__ = [
    "StorageError",
    "bake_key",
    "bake_record",
    "remember",
    "rebake",
    "clear_cache",
    "lut_image",
    "image_record",
    "image_problem",
    "image_problems",
    "write_pixels",
]

REBAKE_CACHE_SIZE = 8
"""Re-baked tables kept per bake key in this session."""
KEY_LENGTH = 16
"""Hex digits of a bake key (64 bits: no two bakes of one file collide)."""


class StorageError(ValueError):
    """A bake record cannot be re-baked; the message says why, as a sentence's end."""


def bake_key(parameters: dict, resolution: str) -> str:
    """The key of a bake: SHA-256 (first :data:`KEY_LENGTH` hex digits) of the made-up skin's
    ``parameters`` (:func:`lut_baker.model.params_file.skin_to_dict`), the resolution name and
    the tables' format version, as canonical JSON (floats by ``repr``: the same on every
    machine)."""
    version = table_set.FORMAT_VERSION
    text = json.dumps({"parameters": parameters, "resolution": str(resolution),
                       "format": version}, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:KEY_LENGTH]


def bake_record(skin, resolution: str) -> dict:
    """What identifies a bake: ``{"key", "parameters", "resolution"}`` (plain data, no bake
    needed)."""
    parameters = params_file.skin_to_dict(skin)
    return {"key": bake_key(parameters, resolution), "parameters": parameters,
            "resolution": str(resolution)}


_TABLES = cache.LRUCache(REBAKE_CACHE_SIZE)


def clear_cache() -> None:
    """Forget the session's re-baked tables (the add-on's unregister calls it)."""
    _TABLES.clear()


def remember(record: dict, tables) -> None:
    """Keep ``tables`` as this session's bake of ``record`` (for a caller that baked them
    itself: tests and tools)."""
    _TABLES.put(record["key"], tables)


def rebake(record: dict, *, progress=None):
    """The tables of a :func:`bake_record`, baked once per session (cached by key);
    ``progress(fraction, message)``: the bake's, when it runs.

    Raises
    ------
    StorageError
        If the record has no readable parameters or resolution, or its key is not theirs.
    """
    try:
        key = bake_key(record["parameters"], record["resolution"])
    except (KeyError, TypeError, ValueError):
        raise StorageError("its bake record cannot be read (a parameter or the resolution is "
                           "missing)") from None
    if key != record.get("key"):
        raise StorageError("its bake record does not match its key (it was edited, or written "
                           "by another version)")
    tables = _TABLES.get(key)
    if tables is not None:
        return tables
    try:
        skin = params_file.skin_from_dict(record["parameters"])
        tables = bake.bake(skin, record["resolution"], progress=progress)
    except (KeyError, TypeError, ValueError):
        raise StorageError("its bake record cannot be re-baked (a parameter is missing or "
                           "unreadable)") from None
    _TABLES.put(key, tables)
    return tables


def _new_float_image(name: str, width: int, height: int) -> bpy.types.Image:
    image = bpy.data.images.new(name, width=width, height=height, alpha=True, float_buffer=True,
                                is_data=True)
    image.colorspace_settings.name = "Non-Color"
    image.alpha_mode = "CHANNEL_PACKED"
    return image


def write_pixels(image: bpy.types.Image, rgba: np.ndarray) -> None:
    """Set an image's pixels from ``(height, width, 4)`` (row 0 at the bottom) and pack it."""
    image.pixels.foreach_set(np.ascontiguousarray(rgba, dtype=np.float32).ravel())
    image.update()
    image.pack()


def _pixel_digest(image) -> str:
    width, height = image.size
    pixels = np.empty(width * height * image.channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    return codec.pixel_hash(pixels)


def _packed_digest(image) -> str | None:
    packed = image.packed_file
    return None if packed is None else hashlib.sha256(bytes(packed.data)).hexdigest()


def image_record(image) -> dict:
    """``{"name", "sha256", "packed_sha256"}``: the image's name, the SHA-256 of its float32
    pixels and of its packed file's bytes (None if not packed)."""
    return {"name": image.name, "sha256": _pixel_digest(image),
            "packed_sha256": _packed_digest(image)}


def image_problem(record: dict, *, decode: bool = True) -> str | None:
    """What is wrong with the image an :func:`image_record` describes, as the end of a
    sentence ("the view-angle image ... is missing"), or None if it is intact.

    The packed bytes are compared first: an image whose packed file changed is never decoded
    (a damaged OpenEXR header can crash Blender while it reads the pixels).  ``decode=False``
    stops there, never decoding (the check on opening a file: an image just loaded from its
    packed bytes has the pixels those bytes hold)."""
    name = record.get("name", "")
    image = bpy.data.images.get(name)
    if image is None:
        return f"its lookup image {name!r} is missing"
    expected = record.get("packed_sha256")
    if expected is not None and _packed_digest(image) != expected:
        return f"its lookup image {name!r} was damaged in the file (its packed data changed)"
    if not decode:
        return None
    if image.packed_file is None and not image.has_data:
        return f"its lookup image {name!r} holds no pixels"
    if _pixel_digest(image) != record.get("sha256"):
        return f"its lookup image {name!r} was altered (its pixels changed)"
    return None


def image_problems(records, *, decode: bool = True) -> list[str]:
    """:func:`image_problem` of each record, the intact ones left out."""
    problems = (image_problem(record, decode=decode) for record in records)
    return [problem for problem in problems if problem]


def lut_image(name: str, rows: np.ndarray) -> bpy.types.Image:
    """The view-angle image ``name``: ``rows`` ``(n_rows, size, 3)``, row ``j`` at texel row
    ``j`` from the bottom (sample it at ``v = (j + 0.5) / n_rows``); float, Non-Color, linear
    filtering, EXTEND, packed.  An existing image of that name is replaced (it is the add-on's:
    damaged, or of an older layout)."""
    rows = np.asarray(rows, np.float32)
    n_rows, size, _ = rows.shape
    old = bpy.data.images.get(name)
    if old is not None:
        # Never read a possibly damaged image: rename it away, build anew, then drop it.
        old.name = name + " (old)"
    image = _new_float_image(name, size, n_rows)
    rgba = np.ones((n_rows, size, 4), np.float32)
    rgba[..., :3] = rows
    write_pixels(image, rgba)
    if old is not None:
        old.user_remap(image)
        bpy.data.images.remove(old)
    return image
