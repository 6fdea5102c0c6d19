"""Baked tables and lookup images inside the .blend file.

Tables are stored as a float image (packed into the .blend, which Blender saves as OpenEXR and
reads back bit-exact): every table of :class:`lut_baker.tables.Tables` flattened as float32 into
the RGBA pixels, with a JSON description (layout, grids at full precision, parameters, SHA-256
of the payload) in the image's custom property :data:`META_KEY`.  Names carry the content
hash, so the same tables are found again instead of being baked twice.

- :func:`tables_key` -- content hash of tables (hex; :func:`lut_baker.io.content_hash`).
- :func:`tables_image_name`, :func:`lut_image_name` -- datablock names from a key.
- :func:`pack_tables` -- tables -> packed image (reused when it exists and is intact).
- :func:`unpack_tables` -- packed image -> tables, or :class:`StorageError` saying what is wrong.
- :func:`lut_image` -- the LAYERED tier's view-angle image (float, Non-Color, Linear, EXTEND).
"""

from __future__ import annotations

import hashlib
import json

import bpy
import numpy as np

from .package import lut_baker

__all__ = [
    "META_KEY",
    "StorageError",
    "tables_key",
    "tables_image_name",
    "lut_image_name",
    "pack_tables",
    "unpack_tables",
    "find_tables_image",
    "lut_image",
    "write_pixels",
]

META_KEY = "makeup_skin_tables"
"""Custom property of a tables image holding its JSON description."""
FORMAT = 2
"""Version of the in-.blend layout."""
ATLAS_WIDTH = 1024
"""Pixels per row of a tables image."""
TABLES_PREFIX = "MakeupSkin Tables "
LUT_PREFIX = "MakeupSkin LUT "


class StorageError(ValueError):
    """Tables in the .blend are missing, truncated or altered; the message says which."""


GRIDS = ("theta_deg", "phi_deg", "radius_mm")
"""Grid arrays, kept in the JSON description at full precision (their closed forms are
checked to 1e-9) rather than in the float32 payload."""


def _payload(tables) -> tuple[list, np.ndarray]:
    """``(layout, float32 payload)``: every table of ``tables`` flattened, in name order."""
    layout, parts, offset = [], [], 0
    for name, value in sorted(tables.arrays.items()):
        if name in GRIDS:
            continue
        array = np.ascontiguousarray(value, dtype=np.float32)
        layout.append({"name": name, "shape": list(array.shape), "offset": offset})
        parts.append(array.ravel())
        offset += array.size
    return layout, np.concatenate(parts) if parts else np.zeros(0, np.float32)


def _describe(tables) -> dict:
    return {"parameters": tables.parameters, "spacings": tables.spacings,
            "grids": {name: np.asarray(getattr(tables, name), float).tolist()
                      for name in GRIDS}}


def tables_key(tables) -> str:
    """The tables' content hash (SHA-256 hex of their float32 atlas, :mod:`lut_baker.io`)."""
    return lut_baker("io").content_hash(tables)


def tables_image_name(key: str) -> str:
    return TABLES_PREFIX + key[:16]


def lut_image_name(key: str, tier: str = "LAYERED") -> str:
    return f"{LUT_PREFIX}{tier.title()} {key[:16]}"


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


def _read_pixels(image: bpy.types.Image) -> np.ndarray:
    width, height = image.size
    pixels = np.empty(width * height * image.channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    return pixels


def find_tables_image(key: str):
    """The tables image of ``key`` in this file, or None."""
    return bpy.data.images.get(tables_image_name(key))


def pack_tables(tables, key: str | None = None) -> bpy.types.Image:
    """Store ``tables`` in a packed float image named from their hash; an existing intact
    image of the same key is reused (a damaged one is rewritten)."""
    key = key or tables_key(tables)
    image = find_tables_image(key)
    if image is not None:
        try:
            unpack_tables(image)
            return image
        except StorageError:
            pass
    layout, payload = _payload(tables)
    height = max(1, -(-payload.size // (4 * ATLAS_WIDTH)))
    rgba = np.zeros(height * ATLAS_WIDTH * 4, np.float32)
    rgba[: payload.size] = payload
    if image is None or tuple(image.size) != (ATLAS_WIDTH, height):
        if image is not None:
            bpy.data.images.remove(image)
        image = _new_float_image(tables_image_name(key), ATLAS_WIDTH, height)
    image[META_KEY] = json.dumps({
        "format": FORMAT,
        "key": key,
        "layout": layout,
        "size": int(payload.size),
        "sha256": hashlib.sha256(payload.tobytes()).hexdigest(),
        **_describe(tables),
    }, default=float)
    write_pixels(image, rgba.reshape(height, ATLAS_WIDTH, 4))
    return image


def unpack_tables(image):
    """The :class:`lut_baker.tables.Tables` stored in ``image``.

    Raises
    ------
    StorageError
        If the image is missing, has no or an unreadable description, holds fewer pixels than
        described, or its payload does not match the stored SHA-256 (the message names which).
    """
    Tables = lut_baker("tables").Tables

    if image is None:
        raise StorageError("the tables image is missing from this file")
    text = image.get(META_KEY)
    if not isinstance(text, str):
        raise StorageError(f"image {image.name!r} has no Made-up Skin description")
    try:
        meta = json.loads(text)
        layout, size, digest = meta["layout"], int(meta["size"]), meta["sha256"]
    except (ValueError, KeyError, TypeError) as error:
        raise StorageError(f"image {image.name!r}: unreadable description ({error})") from None
    if meta.get("format") != FORMAT:
        raise StorageError(f"image {image.name!r}: layout version {meta.get('format')!r}, "
                           f"expected {FORMAT}")
    if not image.has_data and image.packed_file is None and not image.filepath:
        raise StorageError(f"image {image.name!r} holds no pixels")
    pixels = _read_pixels(image)
    if pixels.size < size:
        raise StorageError(f"image {image.name!r} is truncated ({pixels.size} of {size} values)")
    payload = np.ascontiguousarray(pixels[:size])
    if hashlib.sha256(payload.tobytes()).hexdigest() != digest:
        raise StorageError(f"image {image.name!r}: the tables were altered (checksum mismatch)")
    try:
        arrays = {name: np.asarray(values, float) for name, values in meta["grids"].items()}
    except (KeyError, AttributeError, TypeError, ValueError) as error:
        raise StorageError(f"image {image.name!r}: unreadable grids ({error})") from None
    for entry in layout:
        count = int(np.prod(entry["shape"])) if entry["shape"] else 1
        chunk = payload[entry["offset"]: entry["offset"] + count]
        arrays[entry["name"]] = chunk.astype(np.float64).reshape(entry["shape"])
    try:
        return Tables(**arrays, parameters=meta.get("parameters", {}),
                      **meta.get("spacings", {}))
    except (TypeError, ValueError) as error:
        raise StorageError(f"image {image.name!r}: {error}") from None


def lut_image(name: str, rows: np.ndarray) -> bpy.types.Image:
    """The view-angle image ``name``: ``rows`` ``(n_rows, size, 3)``, row ``j`` at texel row
    ``j`` from the bottom (sample it at ``v = (j + 0.5) / n_rows``); float, Non-Color, linear
    filtering, EXTEND, packed.  An existing image of that name is updated in place."""
    rows = np.asarray(rows, np.float32)
    n_rows, size, _ = rows.shape
    image = bpy.data.images.get(name)
    if image is None or tuple(image.size) != (size, n_rows):
        if image is not None:
            bpy.data.images.remove(image)
        image = _new_float_image(name, size, n_rows)
    rgba = np.ones((n_rows, size, 4), np.float32)
    rgba[..., :3] = rows
    write_pixels(image, rgba)
    return image
