"""A script that imports bpy run in its own Python process, to see that the process ends.

pip ``bpy`` 4.5 hangs at interpreter exit while a class, app handler or timer is still
registered; a test runs a pipeline script that never unregisters the add-on and asserts that
it ends (:func:`run_to_exit`).

- :data:`EXIT_LIMIT_S` -- how long the script may take, import and exit included.
- :func:`bpy_importable` -- whether this Python has ``bpy`` (the script's Python is this one).
- :func:`run_to_exit` -- run the script with this Python and a temporary Blender user folder;
  its completed process (a hang fails the calling test).
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import textwrap
from pathlib import Path

__all__ = ["EXIT_LIMIT_S", "bpy_importable", "run_to_exit"]

EXIT_LIMIT_S = 60.0
"""Seconds a script that imports bpy may run: a bare ``import bpy`` and exit takes 1-8 s on
a busy 2-core machine (4.5 cold is the slowest), a hang lasts forever."""
REPO_ROOT = Path(__file__).resolve().parents[2]


def bpy_importable() -> bool:
    """Whether ``bpy`` can be imported by this Python (located, not imported)."""
    return importlib.util.find_spec("bpy") is not None


def run_to_exit(script: str, user_folder: Path, *args: str) -> subprocess.CompletedProcess:
    """Run ``script`` (dedented) with this Python in the repository root, the repository on
    ``PYTHONPATH`` and ``BLENDER_USER_RESOURCES`` at ``user_folder`` (the user's own Blender
    config is never touched); returns the completed process, its output as text.  A process
    still running after :data:`EXIT_LIMIT_S` is killed and raises ``AssertionError``."""
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(user_folder),
               PYTHONPATH=os.pathsep.join(filter(None, [str(REPO_ROOT),
                                                         os.environ.get("PYTHONPATH")])))
    try:
        return subprocess.run([sys.executable, "-c", textwrap.dedent(script), *args],
                              cwd=REPO_ROOT, env=env, capture_output=True, text=True,
                              timeout=EXIT_LIMIT_S, check=False)
    except subprocess.TimeoutExpired as error:
        printed = error.stdout or b""  # bytes, whatever ``text`` says
        raise AssertionError(f"the script did not end within {EXIT_LIMIT_S:g} s (bpy hangs at "
                             f"exit while something is registered); it printed: "
                             f"{printed.decode(errors='replace')[-500:]!r}") from None
