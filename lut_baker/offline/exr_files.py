"""Baked tables on disk: one float32 OpenEXR atlas plus a JSON sidecar (docs/baking.md).

The atlas and the sidecar's data are those of :mod:`lut_baker.tables.codec` (layout, content
hash).  The EXR file stores the atlas's rows top-down (row ``r`` from the bottom is the file's
scanline ``height - 1 - r``); the sidecar has the image's name with ``.json``.  The EXR header
repeats version and hash (``makeup_skin:format_version``, ``makeup_skin:sha256``) so that an
image and a sidecar from different bakes are caught.  Reading and writing the image take
OpenImageIO (Blender ships it as the ``OpenImageIO`` module).

Writing is atomic: both files go to temporaries in the target folder, are flushed to disk and
renamed into place (image first); a crash never leaves a partial file under the final name.  A
write that fails or is interrupted (``KeyboardInterrupt`` or any other exception, at any point,
also just as a rename's system call returns) removes its temporaries and the folders it made,
and leaves an earlier pair as it was (if the sidecar was not renamed after the image, the
earlier image is put back) or the whole new pair (if both renames went through).  Only a crash
between the two renames can leave a new image beside an old sidecar, and loading then reports
the mismatch.

Functions
---------
- :func:`save_tables`, :func:`load_tables` -- write and read (validated) tables.
- :func:`check_target` -- whether tables can be written to a path (before a long bake).
- :func:`sidecar_path` -- the sidecar of an image path.
- :func:`require_oiio` -- the OpenImageIO module, or an ``ImportError`` saying how to get it.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import shutil
from pathlib import Path

import numpy as np

from ..tables.codec import (
    TableFileError,
    TableWriteError,
    atlas,
    check_layout,
    check_sidecar,
    pixel_hash,
    sidecar_data,
    tables_from_atlas,
)
from ..tables.table_set import FORMAT_VERSION, Tables

__all__ = ["save_tables", "load_tables", "check_target", "sidecar_path", "require_oiio",
           "WRITE_PROBLEMS"]

WRITE_PROBLEMS = {
    errno.ENOSPC: "no space left on the disk",
    errno.EDQUOT: "the disk quota is used up",
    errno.EROFS: "{folder!r} is on a read-only file system",
    errno.EACCES: "no permission to write in {folder!r}",
    errno.EPERM: "no permission to write in {folder!r}",
    errno.ENAMETOOLONG: "the file name is too long",
}
"""errno -> what went wrong, in words (``folder``: the nearest existing output folder)."""


def _one_line(message: object) -> str:
    """OpenImageIO's (multi-line) error text as one line."""
    return " ".join(str(message).split())[:400]


def require_oiio():
    """The OpenImageIO module; ``ImportError`` saying how to install it if it is missing."""
    try:
        import OpenImageIO
    except ImportError as error:  # pragma: no cover - the test venv has it
        raise ImportError(
            "lut_baker.offline.exr_files needs OpenImageIO to read and write .exr tables "
            "(pip install OpenImageIO; Blender ships it as the OpenImageIO module)"
        ) from error
    return OpenImageIO


def sidecar_path(path) -> Path:
    """The JSON sidecar of an atlas path (same name, ``.json``)."""
    return Path(path).with_suffix(".json")


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _nearest_existing(folder: Path) -> Path:
    """``folder`` or its nearest ancestor that exists (as anything)."""
    for part in (folder, *folder.parents):
        if part.exists():
            return part
    return folder


def _target_problem(path: Path) -> str | None:
    """What stands in the way of writing ``path`` and its sidecar, found without writing."""
    existing = _nearest_existing(path.parent)
    if existing.exists() and not existing.is_dir():
        return f"{str(existing)!r} is a file, not a folder"
    for target in (path, sidecar_path(path)):
        if target.is_dir():
            return f"{str(target)!r} is a folder, not a file"
    if existing.is_dir() and not os.access(existing, os.W_OK | os.X_OK):
        return WRITE_PROBLEMS[errno.EACCES].format(folder=str(existing))
    return None


def _write_error(path: Path, error: OSError) -> TableWriteError:
    """``error`` from writing ``path`` as a :class:`TableWriteError` in plain words."""
    if isinstance(error, TableWriteError):
        return error
    try:
        reason, folder = _target_problem(path), _nearest_existing(path.parent)
    except OSError:  # the folders cannot even be looked at: say what the system said
        reason, folder = None, path.parent
    if reason is None and error.errno in WRITE_PROBLEMS:
        reason = WRITE_PROBLEMS[error.errno].format(folder=str(folder))
    return TableWriteError(f"cannot write {str(path)!r}: "
                           f"{reason or _one_line(error.strerror or error)}")


def _image_path(path) -> Path:
    """``path`` as a Path; ``ValueError`` unless it ends in ``.exr``."""
    path = Path(path)
    if path.suffix.lower() != ".exr":
        raise ValueError(f"table image must end in .exr, got {str(path)!r}")
    return path


def check_target(path) -> Path:
    """``path`` (an ``.exr``) if tables can be written there as far as can be told without
    writing anything; else :class:`TableWriteError` (a file where a folder should be, a folder
    under the image's or the sidecar's name, no write permission).  Run it before a long bake."""
    path = _image_path(path)
    try:
        problem = _target_problem(path)
    except OSError as error:
        raise _write_error(path, error) from None
    if problem is not None:
        raise TableWriteError(f"cannot write {str(path)!r}: {problem}")
    return path


def _missing_folders(folder: Path) -> list[Path]:
    """``folder`` and those of its parents that do not exist yet, innermost first."""
    missing = []
    for part in (folder, *folder.parents):
        if part.exists():
            break
        missing.append(part)
    return missing


def _remove_folders(folders: list[Path]) -> None:
    """Remove the (empty) folders a failed write made, innermost first."""
    for folder in folders:
        with contextlib.suppress(OSError):
            folder.rmdir()


def _write_image(pixels: np.ndarray, digest: str, path: Path) -> None:
    """The atlas (row 0 at the bottom) as a float32 EXR with version and hash in its header."""
    oiio = require_oiio()
    height, width = pixels.shape[:2]
    spec = oiio.ImageSpec(width, height, 3, oiio.FLOAT)
    spec.attribute("compression", "zip")
    spec.attribute("makeup_skin:format_version", FORMAT_VERSION)
    spec.attribute("makeup_skin:sha256", digest)
    out = oiio.ImageOutput.create(str(path))
    if out is None or not out.open(str(path), spec):
        raise OSError(_one_line(oiio.geterror()))
    ok = out.write_image(np.ascontiguousarray(pixels[::-1]))
    error = out.geterror()
    out.close()
    if not ok:
        raise OSError(_one_line(error))


def _write_sidecar(meta: dict, path: Path) -> None:
    """The sidecar's data as indented JSON."""
    path.write_text(json.dumps(meta, indent=1))


def _keep_copy(path: Path, copy: Path) -> bool:
    """Keep the current ``path`` under the name ``copy`` (a hard link, else a copy); False
    when there is no file at ``path``."""
    if not path.is_file():
        return False
    try:
        os.link(path, copy)
    except OSError:  # a file system without hard links
        shutil.copy2(path, copy)
    return True


def _replace_pair(image_tmp: Path, json_tmp: Path, path: Path, backup: Path) -> None:
    """Rename the temporaries onto ``path`` and its sidecar, image first.  If anything stops it
    between the two renames, the earlier image is put back (the new one removed if there was
    none), so an earlier pair is never left half-replaced.  An interrupt can also arrive just
    after a rename went through (as the system call returns): so what was renamed is read off
    the temporaries left, not off where the exception came from; once both renames are done
    the new pair stands."""
    had_image = _keep_copy(path, backup)
    try:
        os.replace(image_tmp, path)
        os.replace(json_tmp, sidecar_path(path))
    except BaseException:
        if json_tmp.exists() and not image_tmp.exists():  # the image went in, the sidecar not
            if had_image:
                os.replace(backup, path)
            else:
                path.unlink(missing_ok=True)
        raise


def save_tables(tables: Tables, path) -> Path:
    """Write ``tables`` to ``path`` (an ``.exr``) and its sidecar ``path.json``, atomically
    (see the module docstring).  Returns the image path.

    Raises :class:`TableWriteError` (an ``OSError``) naming the file and the problem when the
    tables cannot be written; then no temporary is left and an earlier pair is unchanged, as
    also when the write is interrupted."""
    require_oiio()
    path = check_target(path)
    pixels, layout = atlas(tables)
    digest = pixel_hash(pixels)
    tag = f".{path.stem}.{os.getpid()}"
    image_tmp, json_tmp, backup = (path.with_name(tag + end)
                                   for end in (".tmp.exr", ".tmp.json", ".old.exr"))
    made = _missing_folders(path.parent)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _write_image(pixels, digest, image_tmp)
        _write_sidecar(sidecar_data(tables, layout, digest, path.name), json_tmp)
        for tmp in (image_tmp, json_tmp):
            _fsync(tmp)
        _replace_pair(image_tmp, json_tmp, path, backup)
    except BaseException as error:
        for tmp in (image_tmp, json_tmp, backup):
            tmp.unlink(missing_ok=True)
        _remove_folders(made)
        if isinstance(error, OSError):
            raise _write_error(path, error) from error
        raise
    finally:  # also when an interrupt comes just as the pair is in place
        backup.unlink(missing_ok=True)
    with contextlib.suppress(OSError):  # the pair is in place; not every system syncs folders
        _fsync(path.parent)
    return path


def _read_sidecar(path: Path) -> dict:
    side = sidecar_path(path)
    try:
        meta = json.loads(side.read_text())
    except FileNotFoundError:
        raise TableFileError(f"{str(side)!r}: the sidecar of {path.name!r} is missing; "
                             "re-bake the tables") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise TableFileError(f"{str(side)!r} is not a readable sidecar: {error}") from None
    return check_sidecar(meta, str(side))


def _read_pixels(path: Path, meta: dict) -> np.ndarray:
    oiio = require_oiio()
    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise TableFileError(f"{str(path)!r} cannot be read as an image: "
                             f"{_one_line(oiio.geterror())}")
    try:
        spec = image.spec()
        shape = (spec.height, spec.width, spec.nchannels)
        if spec.getattribute("makeup_skin:sha256") != meta["sha256"]:
            raise TableFileError(f"{str(path)!r} and its sidecar come from different bakes "
                                 "(their hashes differ); re-bake the tables")
        if shape != (meta["height"], meta["width"], 3):
            raise TableFileError(f"{str(path)!r} is {shape[1]} x {shape[0]} x {shape[2]}, its "
                                 f"sidecar says {meta['width']} x {meta['height']} x 3")
        pixels = image.read_image(oiio.FLOAT)
        if pixels is None or image.has_error:
            raise TableFileError(f"{str(path)!r} is truncated or corrupt: "
                                 f"{_one_line(image.geterror())}")
    finally:
        image.close()
    pixels = np.asarray(pixels, np.float32).reshape(shape)[::-1]
    if pixel_hash(pixels) != meta["sha256"]:
        raise TableFileError(f"{str(path)!r} is corrupt: its pixels do not match the sidecar's "
                             "sha256; re-bake the tables")
    return pixels


def load_tables(path) -> Tables:
    """Read tables written by :func:`save_tables` (the ``.exr`` or its ``.json``).

    Validates format version, image size, layout, grids and the content hash; raises
    :class:`TableFileError` naming the file and the problem otherwise.  Values are the stored
    float32 numbers (as float64 arrays)."""
    path = Path(path)
    path = path.with_suffix(".exr") if path.suffix.lower() == ".json" else path
    if not path.is_file():
        raise TableFileError(f"{str(path)!r} does not exist")
    meta = _read_sidecar(path)
    try:
        check_layout(meta, str(sidecar_path(path)))
        return tables_from_atlas(_read_pixels(path, meta), meta)
    except TableFileError:
        raise
    except (KeyError, TypeError, ValueError) as error:
        raise TableFileError(f"{str(sidecar_path(path))!r} is inconsistent: {error}") from None
