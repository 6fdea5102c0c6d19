"""What a made-up material keeps in the .blend: the images its render reads and their hashes,
never the tables themselves (those are re-baked from the group's bake record, :mod:`.bakes`).

The images a group reads (the Layered and EEVEE tiers' view-angle image) are packed, and the
group records the SHA-256 of their pixels and of their packed bytes (:func:`image_record`), so
damage is found before Blender decodes the image (:func:`image_problem`).

- :func:`view_image` -- a tier's view-angle image (named by :func:`.keys.view_image_name`).
- :func:`image_record`, :func:`image_problem` -- an image's hashes, and what is wrong with it;
  :func:`image_problems` for a group's images.
- :func:`write_pixels` -- pixels into an image, packed.
"""

from __future__ import annotations

import hashlib
from typing import Any

import bpy
import numpy as np

from .core import codec

__all__ = [
    "view_image",
    "image_record",
    "image_problem",
    "image_problems",
    "write_pixels",
]


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


def _pixel_digest(image: Any) -> str:
    width, height = image.size
    pixels = np.empty(width * height * image.channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    return codec.pixel_hash(pixels)


def _packed_digest(image: Any) -> str | None:
    packed = image.packed_file
    return None if packed is None else hashlib.sha256(bytes(packed.data)).hexdigest()


def image_record(image: Any) -> dict:
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


def image_problems(records: Any, *, decode: bool = True) -> list[str]:
    """:func:`image_problem` of each record, the intact ones left out."""
    problems = (image_problem(record, decode=decode) for record in records)
    return [problem for problem in problems if problem]


def view_image(name: str, rows: np.ndarray) -> bpy.types.Image:
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
