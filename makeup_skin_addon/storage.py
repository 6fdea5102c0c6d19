"""What a made-up material keeps in the .blend: the images its render reads and the record of
its bake, never the tables themselves.

A bake is identified by its record (:func:`bake_record`): the made-up skin's parameters, the
resolution name and the tables' content hash.  Baking is deterministic and takes a fraction of
a second, so the tables are re-baked from the record when Check Tables or a re-fit needs them
(:func:`rebake`, cached for the session) instead of travelling in every saved file.  The
images a group reads (the Layered tier's view-angle image) are packed, and the group records
the SHA-256 of their pixels and of their packed bytes (:func:`image_record`), so damage is
found before Blender decodes the image (:func:`image_problem`).

- :func:`tables_key` -- content hash of tables (hex; :func:`lut_baker.tables.codec.content_hash`).
- :func:`bake_record`, :func:`rebake` -- a bake's record, and the tables again from it.
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

from .package import lut_baker

__all__ = [
    "StorageError",
    "tables_key",
    "bake_record",
    "rebake",
    "clear_cache",
    "lut_image",
    "image_record",
    "image_problem",
    "image_problems",
    "write_pixels",
]

REBAKE_CACHE_SIZE = 8
"""Re-baked tables kept per content hash in this session."""


class StorageError(ValueError):
    """A bake record cannot be re-baked; the message says why, as a sentence's end."""


def tables_key(tables) -> str:
    """The tables' content hash (SHA-256 hex of their float32 atlas,
    :mod:`lut_baker.tables.codec`)."""
    return lut_baker("tables.codec").content_hash(tables)


def bake_record(skin, resolution: str, tables) -> dict:
    """What identifies a bake: ``{"key", "parameters", "resolution"}`` (plain data)."""
    return {"key": tables_key(tables),
            "parameters": lut_baker("model.params_file").skin_to_dict(skin),
            "resolution": str(resolution)}


_TABLES = lut_baker("numerics.cache").LRUCache(REBAKE_CACHE_SIZE)


def clear_cache() -> None:
    """Forget the session's re-baked tables (the add-on's unregister calls it)."""
    _TABLES.clear()


def rebake(record: dict):
    """``(tables, key)``: the tables re-baked from a :func:`bake_record` and their content hash,
    which a different numpy build may round to other than the recorded ``record["key"]``.

    Raises
    ------
    StorageError
        If the record has no readable parameters or resolution.
    """
    key = record.get("key")
    cache_key = json.dumps([key, record.get("parameters"), record.get("resolution")],
                           sort_keys=True, default=str)
    cached = _TABLES.get(cache_key)
    if cached is not None:
        return cached, key
    try:
        skin = lut_baker("model.params_file").skin_from_dict(record["parameters"])
        tables = lut_baker("bake").bake(skin, record["resolution"])
    except (KeyError, TypeError, ValueError):
        raise StorageError("its bake record cannot be re-baked (a parameter is missing or "
                           "unreadable)") from None
    rebaked = tables_key(tables)
    if rebaked == key:
        _TABLES.put(cache_key, tables)
    return tables, rebaked


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
    return lut_baker("tables.codec").pixel_hash(pixels)


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
