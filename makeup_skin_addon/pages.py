"""Large arrays without huge pages: numpy's request for them turned off while Blender's data is
copied out and worked on (:func:`ordinary`).

numpy asks Linux for huge pages for every array of 4 MB and more (``madvise``).  Where the
kernel must first find or take back whole huge pages, the first touch of such an array stalls:
on the virtual machine the benchmarks run on, which hands its free memory back to the host, a
4096 px image's float buffer (268 MB) took 1.9-2.2 s after a few seconds idle against 0.13 s in
ordinary pages, and a million-triangle mesh's arrays 0.03-0.18 s against a steady 0.04 s
(``python bench/skin_colour.py --idle 5``).  numpy's switch for it is process-wide: it is
turned off for the block on the interface's thread and set back as it was after.

- :func:`ordinary` -- a block (or, as a decorator, a function) whose new numpy arrays use
  ordinary pages.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator

import numpy as np

__all__ = ["ordinary"]


def _switch() -> Callable[[bool], bool] | None:
    """numpy's ``_set_madvise_hugepage`` (it returns the setting it replaced), where this numpy
    has it (1.20 on, Linux; ``numpy._core`` from 2.0), else None."""
    for name in ("_core", "core"):
        module = getattr(np, name, None)
        switch = getattr(getattr(module, "multiarray", None), "_set_madvise_hugepage", None)
        if switch is not None:
            return switch
    return None


@contextlib.contextmanager
def ordinary() -> Iterator[None]:
    """A block whose new numpy arrays use ordinary pages (no huge-page request); the setting
    set back as it was after, whatever happens.  On the interface's thread only: a worker's
    block is left as it is (two threads setting one switch back could leave it off)."""
    switch = _switch()
    if switch is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    before = switch(False)
    try:
        yield
    finally:
        switch(before)
