"""Files written whole or not at all: what the commands write (fits, measurements, figures,
the runtime's preset file) goes to a temporary beside its final name, is flushed to disk and
renamed into place.  A write that fails or is interrupted (``KeyboardInterrupt``, SIGINT or
SIGTERM through the command line) removes the temporary and leaves an earlier file as it was;
a crash never leaves a partial file under the final name.  (The tables' image and sidecar, a
pair, have their own rules: :mod:`.exr_files`.)

- :func:`replacing` -- a temporary path to write, renamed onto the final one at the end;
- :func:`write_text` -- a text file (UTF-8) written that way.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

__all__ = ["replacing", "write_text"]


@contextlib.contextmanager
def replacing(path) -> Iterator[Path]:
    """Yield a hidden temporary path beside ``path`` with its suffix (``.NAME.PID.tmp.png``:
    writers that go by the suffix still do) to write the file to; when the block ends, the
    temporary is flushed to disk and renamed onto ``path``.  If the block raises anything, the
    temporary is removed and ``path`` is as it was."""
    path = Path(path)
    temporary = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        yield temporary
        descriptor = os.open(temporary, os.O_RDONLY)
        try:
            os.fsync(descriptor)
        finally:
            os.close(descriptor)
        os.replace(temporary, path)
    finally:  # after the rename there is nothing left to remove
        temporary.unlink(missing_ok=True)


def write_text(path, text: str) -> Path:
    """Write ``text`` to ``path`` (UTF-8) whole or not at all (:func:`replacing`); the path."""
    path = Path(path)
    with replacing(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
    return path
