"""Reduced images kept on disk between sessions: a file opened anew does not decode its skin's
texture again for the first Match Skin (decoding a 4096 px PNG is 0.3-0.4 s and about 125 MB,
reading it back from here a few milliseconds and 3 MB).

An entry is the reduced image of :mod:`.image_texels` (its pixels and its note) under a key that
changes whenever the pixels could: the file's absolute path, date and size (a packed image's:
its bytes' SHA-256), the colour space and alpha mode it is read with, the reduction's size,
Blender's version and :data:`FORMAT`.  Only file images are kept, on disk or packed (not
generated ones, nor one painted and unsaved).  The entries live in the extension's own user
folder (``bpy.utils.extension_path_user``, removed with the extension), at most
:data:`MAX_ENTRIES` (the least recently used go first), each written whole or not at all; an
entry that cannot be read is a miss.  Run from a source
checkout (no extension folder) nothing is kept unless :func:`set_directory` names a folder.

- :func:`key` -- an image's key, or None when it is not kept.
- :func:`load`, :func:`save` -- an entry read, written.
- :func:`directory`, :func:`set_directory` -- where the entries live.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import tempfile
import zipfile
from pathlib import Path

import bpy
import numpy as np

from .package import INSTALLED, ROOT_PACKAGE

__all__ = ["FORMAT", "MAX_ENTRIES", "key", "load", "save", "directory", "set_directory"]

FORMAT = 1
"""The entries' format and the reduction's method: a change to either changes every key."""
MAX_ENTRIES = 32
"""Entries kept (about 3 MB each at 512 px)."""
_FOLDER = "reduced_images"
_UNSET = object()
_directory: object = _UNSET


def set_directory(path: str | os.PathLike | None) -> None:
    """Keep the entries in ``path`` (created when needed); None keeps nothing."""
    global _directory
    _directory = Path(path) if path is not None else None


def directory() -> Path | None:
    """Where the entries live: the folder :func:`set_directory` named, else the extension's
    user folder; None when there is none (a source checkout)."""
    global _directory
    if _directory is _UNSET:
        _directory = None
        if INSTALLED and ROOT_PACKAGE.startswith("bl_ext."):
            with contextlib.suppress(ValueError, OSError):
                _directory = Path(bpy.utils.extension_path_user(ROOT_PACKAGE, path=_FOLDER,
                                                                create=True))
    return _directory if isinstance(_directory, Path) else None


def key(image, size: int) -> str | None:
    """The key of ``image`` reduced to ``size`` (hex digest), or None when it is not kept: not
    a file image (on disk, or packed in the .blend), or with unsaved changes."""
    if image.source != "FILE" or image.is_dirty:
        return None
    content = _content(image)
    if content is None:
        return None
    parts = (FORMAT, tuple(bpy.app.version), content, image.colorspace_settings.name,
             image.alpha_mode, size)
    return hashlib.sha256(repr(parts).encode()).hexdigest()


def _content(image) -> tuple | None:
    """What identifies the bytes an image is decoded from: a packed image's SHA-256 (about 18
    ms for a 7.6 MB PNG, against some 0.35 s to decode it), a file's real path, date and size;
    None when there is neither (no file, or a packed image of several files)."""
    if image.packed_files:
        if len(image.packed_files) != 1:
            return None
        return ("packed", hashlib.sha256(image.packed_file.data).hexdigest())
    path = bpy.path.abspath(image.filepath, library=image.library)
    try:
        info = os.stat(path)
    except OSError:
        return None
    return ("file", os.path.realpath(path), info.st_mtime_ns, info.st_size)


def _entry(name: str) -> Path | None:
    folder = directory()
    return folder / f"{name}.npz" if folder is not None else None


def load(name: str) -> tuple[np.ndarray, str] | None:
    """``(pixels, note)`` of the entry ``name``, or None (none, or unreadable)."""
    path = _entry(name)
    if path is None or not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as entry:
            pixels, note = entry["pixels"], str(entry["note"])
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None
    if pixels.dtype != np.float32 or pixels.ndim != 3 or pixels.shape[2] != 3:
        return None
    with contextlib.suppress(OSError):
        os.utime(path)  # recently used
    return pixels, note


def save(name: str, pixels: np.ndarray, note: str) -> None:
    """Write the entry ``name`` (whole or not at all) and drop the least recently used beyond
    :data:`MAX_ENTRIES`; a folder that cannot be written keeps nothing."""
    path = _entry(name)
    if path is None:
        return
    partial = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, partial = tempfile.mkstemp(dir=path.parent, suffix=".partial")
        with os.fdopen(handle, "wb") as file:
            np.savez(file, pixels=np.asarray(pixels, np.float32), note=np.array(note))
        os.replace(partial, path)
    except OSError:
        if partial is not None:
            with contextlib.suppress(OSError):
                os.remove(partial)
        return
    _prune(path.parent)


def _prune(folder: Path) -> None:
    """Remove the least recently used entries beyond :data:`MAX_ENTRIES`."""
    entries = []
    for path in folder.glob("*.npz"):
        with contextlib.suppress(OSError):
            entries.append((path.stat().st_mtime_ns, path))
    for _, path in sorted(entries, reverse=True)[MAX_ENTRIES:]:
        with contextlib.suppress(OSError):
            path.unlink()
