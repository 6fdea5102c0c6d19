"""The one binary codec of baked tables: the atlas layout, its packing and unpacking, the
content hash and the sidecar data (numpy only: the add-on uses it inside Blender; the files on
disk are :mod:`lut_baker.offline.exr_files`).

The atlas is one RGB image holding every table, so a shader needs one image texture (linear
interpolation, extension EXTEND, colour space Non-Color).  Rows are counted from the bottom,
as Blender's pixel rows are; pixel ``(x, y)`` has its centre at texture coordinates
``((x + 0.5) / width, (y + 0.5) / height)``.  Blocks, bottom-up:

- each angular table (``path3_gloss``, then ``inter_reflection`` if baked; format version 1
  also held ``film_gloss`` before and ``skin_gloss`` after ``path3_gloss``, which reading skips:
  the surface gloss is a closed form of the parameters): ``n_theta`` rows; pixel
  ``(j n_phi + k, row + i)`` holds ``table[theta_i = i, theta_o = j, phi = k]``.  Within a
  block a bilinear fetch interpolates ``theta_i`` and the azimuth coordinate; ``theta_o``
  takes two fetches (columns ``j`` and ``j + 1``) mixed by its fraction;
- one row per directional table (``DIRECTIONAL`` order): pixel ``(i, row)`` = ``table[i]``;
- one row for ``profile``: pixel ``(r, row)``;
- one row of constants (``CONSTANT`` order): pixel ``(c, row)``;
- with the film as a slab (``tables.slab``, :class:`lut_baker.tables.slab_tables.SlabTables`),
  its blocks on its own grids (``K`` thicknesses, ``n`` polar, ``p`` azimuth nodes):
  ``slab_top``, ``K n`` rows, pixel ``(theta_o p + phi, row + k n + theta_i)``; ``slab_top_albedo``,
  ``slab_through``, ``slab_film_albedo``, ``K`` rows each, pixel ``(theta, row + k)``;
  ``slab_through_mean``, ``slab_below`` and ``slab_body_gloss``, one row each, pixel
  ``(k, row)``.  The tables of the paper's film have none, and their atlas and hash are those
  of every earlier version.

The sidecar data hold the format version, the layout (first row and row count of each block),
the grids and their closed forms (the slab's under ``"slab"``: its thickness axis as
:func:`~lut_baker.tables.slab_tables.thickness_nodes`' closed form, its angular grid, the
absorption baked into it and the surface's share of the gloss), units, the made-up skin's
parameters (with K) and
``sha256``, the hash of the atlas's float32 pixels in the row order above (C order,
little-endian).

Functions
---------
- :func:`atlas_layout` -- first row and row count of each block, and the image size.
- :func:`atlas`, :func:`tables_from_atlas` -- tables packed into the atlas pixels, and back.
- :func:`pixel_hash`, :func:`content_hash` -- the hash of float32 pixels, and of tables.
- :func:`sidecar_data`, :func:`check_sidecar`, :func:`check_layout` -- the sidecar's data, and
  its checks.
- :class:`TableFileError` -- a corrupt, truncated, mismatched or unsupported table file.
- :class:`TableWriteError` -- tables that could not be written, said in plain words.
"""

from __future__ import annotations

import hashlib
from typing import Any

import numpy as np

from .slab_tables import SlabTables, thickness_nodes
from .table_set import ANGULAR, CONSTANT, DIRECTIONAL, FORMAT_VERSION, RADIAL, Tables

__all__ = ["atlas_layout", "atlas", "tables_from_atlas", "pixel_hash", "content_hash",
           "sidecar_data", "check_sidecar", "check_layout", "TableFileError",
           "TableWriteError", "FORMAT_NAME", "UNITS", "READABLE_VERSIONS", "SLAB_ANGULAR",
           "SLAB_DIRECTIONAL", "SLAB_PER_THICKNESS"]

FORMAT_NAME = "makeup-skin-tables"
UNITS = {
    "theta_deg": "degrees from the normal",
    "phi_deg": "degrees (azimuth coordinate, see phi_spacing)",
    "radius_mm": "mm",
    "angular tables": "1/sr",
    "film_transmittance, transmission_factor, albedos": "dimensionless",
    "film_diffuse, skin_diffuse": "1/sr",
    "total_reflectance": "dimensionless",
    "film_transmittance_integral": "sr",
    "profile": "1/mm^2",
    "K": "counts per second per unit albedo",
    "slab_top": "1/sr",
    "slab_top_albedo, slab_through, slab_through_mean, slab_below, slab_film_albedo, "
    "slab_body_gloss, slab surface_share":
        "dimensionless",
    "slab thickness_um": "micrometres",
}


class TableFileError(ValueError):
    """A table file that cannot be used: missing, corrupt, truncated, from another bake or
    of an unsupported format version.  The message says which file and what is wrong."""


class TableWriteError(OSError):
    """Tables that could not be written: a file where a folder should be, a folder without
    write permission, a full disk, any other failed write.  The message is one line naming the
    file and saying what is wrong."""


READABLE_VERSIONS = (1, FORMAT_VERSION)
"""Format versions :func:`check_sidecar` accepts."""
VERSION_1_ANGULAR = ("film_gloss", "path3_gloss", "skin_gloss")
"""The angular blocks of format version 1, in order."""
SLAB_ANGULAR = ("top",)
"""The slab's tables ``(K, n, n, p, 3)`` (blocks ``slab_<name>``)."""
SLAB_DIRECTIONAL = ("top_albedo", "through", "film_albedo")
"""The slab's tables ``(K, n, 3)``."""
SLAB_PER_THICKNESS = ("through_mean", "below", "body_gloss")
"""The slab's tables ``(K, 3)``."""


def _angular_names(tables: Tables) -> tuple[str, ...]:
    return ANGULAR + (("inter_reflection",) if tables.inter_reflection is not None else ())


def atlas_layout(n_theta: int, n_phi: int, n_radius: int, angular: tuple[str, ...],
                 slab: tuple[int, int, int] | None = None) -> dict:
    """First row and row count of each block (rows from the bottom), and the image size
    (pixels), of the atlas of ``angular`` tables on the given grid sizes; ``slab``: the slab's
    ``(K, n, p)`` (thicknesses, polar and azimuth nodes), or None (no slab)."""
    blocks, row = {}, 0
    for name in angular:
        blocks[name] = {"row": row, "rows": n_theta, "columns": n_theta * n_phi,
                        "pixel": "(theta_o * n_phi + phi, row + theta_i)"}
        row += n_theta
    for name in DIRECTIONAL:
        blocks[name] = {"row": row, "rows": 1, "columns": n_theta, "pixel": "(theta, row)"}
        row += 1
    for name in RADIAL:
        blocks[name] = {"row": row, "rows": 1, "columns": n_radius, "pixel": "(radius, row)"}
        row += 1
    blocks["constants"] = {"row": row, "rows": 1, "columns": len(CONSTANT),
                           "pixel": "(index in order, row)", "order": list(CONSTANT)}
    row += 1
    width = max(n_theta * n_phi, n_theta, n_radius, len(CONSTANT))
    if slab is not None:
        k, n, p = slab
        for name in SLAB_ANGULAR:
            blocks[f"slab_{name}"] = {"row": row, "rows": k * n, "columns": n * p,
                                      "pixel": "(theta_o * n_phi + phi, row + k * n_theta "
                                               "+ theta_i)"}
            row += k * n
        for name in SLAB_DIRECTIONAL:
            blocks[f"slab_{name}"] = {"row": row, "rows": k, "columns": n,
                                      "pixel": "(theta, row + k)"}
            row += k
        for name in SLAB_PER_THICKNESS:
            blocks[f"slab_{name}"] = {"row": row, "rows": 1, "columns": k, "pixel": "(k, row)"}
            row += 1
        width = max(width, n * p, n, k)
    return {"width": width, "height": row, "blocks": blocks}


def _slab_shape(slab: SlabTables | None) -> tuple[int, int, int] | None:
    if slab is None:
        return None
    return slab.thickness_um.size, slab.theta_deg.size, slab.phi_deg.size


def atlas(tables: Tables) -> tuple[np.ndarray, dict]:
    """``(pixels, layout)``: the float32 atlas ``(height, width, 3)`` with row 0 at the
    bottom, and its layout (see the module docstring)."""
    n_theta, n_phi = tables.theta_deg.size, tables.phi_deg.size
    slab = tables.slab
    layout = atlas_layout(n_theta, n_phi, tables.radius_mm.size, _angular_names(tables),
                          _slab_shape(slab))
    pixels = np.zeros((layout["height"], layout["width"], 3), np.float32)
    blocks = layout["blocks"]
    for name in _angular_names(tables):
        row = blocks[name]["row"]
        pixels[row:row + n_theta, :n_theta * n_phi] = np.reshape(
            np.asarray(getattr(tables, name)), (n_theta, n_theta * n_phi, 3))
    for name in DIRECTIONAL + RADIAL:
        values = np.asarray(getattr(tables, name))
        pixels[blocks[name]["row"], :values.shape[0]] = values
    pixels[blocks["constants"]["row"], :len(CONSTANT)] = [getattr(tables, name)
                                                          for name in CONSTANT]
    if slab is not None:
        for name in SLAB_ANGULAR + SLAB_DIRECTIONAL + SLAB_PER_THICKNESS:
            block = blocks[f"slab_{name}"]
            values = np.reshape(np.asarray(getattr(slab, name)), (block["rows"], -1, 3))
            pixels[block["row"]:block["row"] + block["rows"], :values.shape[1]] = values
    return pixels, layout


def content_hash(tables: Tables) -> str:
    """sha256 (hex) of the float32 atlas of ``tables``: equal hashes, equal stored tables."""
    return pixel_hash(atlas(tables)[0])


def pixel_hash(pixels: np.ndarray) -> str:
    """sha256 (hex) of ``pixels`` as little-endian float32 in C order."""
    return hashlib.sha256(np.ascontiguousarray(pixels, "<f4").tobytes()).hexdigest()


def sidecar_data(tables: Tables, layout: dict, digest: str, image_name: str) -> dict:
    """The sidecar of the atlas of ``tables`` (plain data): its ``layout``, ``digest``
    (:func:`pixel_hash`), the image's file name, grids, units and the skin's parameters."""
    return {
        "format": FORMAT_NAME,
        "format_version": FORMAT_VERSION,
        "image": image_name,
        "width": layout["width"],
        "height": layout["height"],
        "channels": ["R", "G", "B"],
        "rows": "counted from the bottom (Blender); the EXR stores them top-down",
        "texel_centre": "(x + 0.5) / width, (y + 0.5) / height",
        "sha256": digest,
        "layout": layout["blocks"],
        "grids": {
            "theta_deg": tables.theta_deg.tolist(),
            "phi_deg": tables.phi_deg.tolist(),
            "radius_mm": tables.radius_mm.tolist(),
            **tables.spacings,
        },
        "units": UNITS,
        "parameters": tables.parameters,
        "K": tables.parameters.get("K"),
        **({} if tables.slab is None else {"slab": _slab_grids(tables.slab)}),
    }


def _slab_grids(slab: SlabTables) -> dict:
    """The slab's grids in the sidecar: the thickness axis by its closed form (it ends in
    ``inf``, which JSON does not hold), the angular grid and its spacings, the absorption, the
    surface's share of the gloss.  Tables at one thickness (a preview's) have no axis to
    write: ValueError."""
    if slab.one_thickness:
        raise ValueError("the slab's tables at one thickness are not written (a preview's): "
                         "bake the whole thickness axis to write them")
    return {"thickness_nodes": int(slab.thickness_um.size),
            "thickness_min_um": float(slab.thickness_um[0]),
            "thickness_max_um": float(slab.thickness_um[-2]),
            "theta_deg": slab.theta_deg.tolist(), "phi_deg": slab.phi_deg.tolist(),
            "theta_spacing": slab.theta_spacing, "theta_offset": slab.theta_offset,
            "phi_spacing": slab.phi_spacing,
            "absorption": np.asarray(slab.absorption, float).tolist(),
            "surface_share": np.asarray(slab.surface_share, float).tolist()}


def _stored_slab_shape(meta: dict) -> tuple[int, int, int] | None:
    """The slab's ``(K, n, p)`` in sidecar data, or None."""
    slab = meta.get("slab")
    if slab is None:
        return None
    return int(slab["thickness_nodes"]), len(slab["theta_deg"]), len(slab["phi_deg"])


def check_sidecar(meta: object, where: str) -> dict:
    """``meta`` if it is sidecar data of this format version; else :class:`TableFileError`
    naming ``where`` (the sidecar's file)."""
    if not isinstance(meta, dict) or meta.get("format") != FORMAT_NAME:
        raise TableFileError(f"{where!r} is not a {FORMAT_NAME} sidecar")
    if meta.get("format_version") not in READABLE_VERSIONS:
        raise TableFileError(f"{where!r} has format version {meta.get('format_version')!r}; "
                             f"this lut_baker reads versions "
                             f"{', '.join(map(str, READABLE_VERSIONS))}: re-bake the tables")
    return meta


def _grids(meta: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(theta_deg, phi_deg, radius_mm)`` of sidecar data."""
    grids = meta["grids"]
    theta, phi, radius = (np.asarray(grids[k], float) for k in ("theta_deg", "phi_deg",
                                                              "radius_mm"))
    return theta, phi, radius


def _stored_angular_names(meta: dict) -> tuple[str, ...]:
    """The angular blocks the sidecar data's layout holds, in their order."""
    names = VERSION_1_ANGULAR if meta.get("format_version") == 1 else ANGULAR
    return tuple(name for name in names + ("inter_reflection",) if name in meta["layout"])


def check_layout(meta: dict, where: str) -> None:
    """:class:`TableFileError` naming ``where`` unless the sidecar data's layout and image size
    are :func:`atlas_layout` of its grids (``KeyError``, ``TypeError`` or ``ValueError`` when an
    entry is missing or malformed)."""
    theta, phi, radius = _grids(meta)
    expected = atlas_layout(theta.size, phi.size, radius.size, _stored_angular_names(meta),
                            _stored_slab_shape(meta))
    if expected["blocks"] != meta["layout"] or (expected["width"], expected["height"]) != (
            meta["width"], meta["height"]):
        raise TableFileError(f"{where!r}: layout does not match its grids")


def tables_from_atlas(pixels: np.ndarray, meta: dict) -> Tables:
    """The tables stored in atlas ``pixels`` ``(height, width, 3)`` (row 0 at the bottom)
    described by sidecar data ``meta`` (checked by :func:`check_layout`): the stored float32
    values as float64 arrays (``KeyError``, ``TypeError`` or ``ValueError`` when an entry is
    missing or malformed)."""
    theta, phi, radius = _grids(meta)
    angular = [name for name in _stored_angular_names(meta)
               if name in ANGULAR + ("inter_reflection",)]
    pixels = np.asarray(pixels, np.float32).astype(float)
    blocks = meta["layout"]
    n, p = theta.size, phi.size
    arrays: dict[str, Any] = {
        name: pixels[blocks[name]["row"]:blocks[name]["row"] + n, :n * p].reshape(n, n, p, 3)
        for name in angular}
    arrays.update({name: pixels[blocks[name]["row"], :blocks[name]["columns"]]
                   for name in DIRECTIONAL + RADIAL})
    constants = pixels[blocks["constants"]["row"], :len(CONSTANT)]
    arrays.update({name: constants[i] for i, name in enumerate(CONSTANT)})
    grids = meta["grids"]
    spacing = {k: grids[k] for k in ("theta_spacing", "theta_offset", "phi_spacing",
                                     "radius_spacing")}
    return Tables(theta_deg=theta, phi_deg=phi, radius_mm=radius, **arrays,
                  parameters=meta["parameters"], **spacing,
                  slab=_slab_from_atlas(pixels, meta))


def _slab_from_atlas(pixels: np.ndarray, meta: dict) -> SlabTables | None:
    """The slab's tables in atlas ``pixels`` (float64), or None when the sidecar has none."""
    shape = _stored_slab_shape(meta)
    if shape is None:
        return None
    k, n, p = shape
    grids, blocks = meta["slab"], meta["layout"]

    def block(name: str, *dims: int) -> np.ndarray:
        where = blocks[f"slab_{name}"]
        rows = pixels[where["row"]:where["row"] + where["rows"], :where["columns"]]
        return rows.reshape(*dims, 3)

    return SlabTables(
        thickness_um=thickness_nodes(k, float(grids["thickness_min_um"]),
                                     float(grids["thickness_max_um"])),
        theta_deg=np.asarray(grids["theta_deg"], float),
        phi_deg=np.asarray(grids["phi_deg"], float),
        top=block("top", k, n, n, p),
        **{name: block(name, k, n) for name in SLAB_DIRECTIONAL},
        **{name: block(name, k) for name in SLAB_PER_THICKNESS},
        absorption=np.asarray(grids["absorption"], float),
        surface_share=np.asarray(grids["surface_share"], float),
        theta_spacing=grids["theta_spacing"], theta_offset=float(grids["theta_offset"]),
        phi_spacing=grids["phi_spacing"])
