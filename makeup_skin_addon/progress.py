"""Where a slow step's progress goes: a callback ``report(fraction, message="")``, the window
manager's progress counter, or a check that stops the work (no bpy: the window manager is
passed in).

Two ways of reporting, for two kinds of work:

- A click that may read a mesh or an image (Match Skin, the first Apply's match): the reading
  code calls :func:`report` wherever it is, and whoever asked routes it with :func:`reporting`
  (to a callback) or :func:`progress_bar` (to the window manager, begun on the first report
  only: a click that reads nothing shows nothing).
- Apply's bake, fit and measurement (:class:`.bakes.Bake`): a :class:`Stages` maps each
  stage's own 0..1 onto its share of the bar (:class:`Progress`), or checks at every step
  whether a newer change superseded the work (:class:`Checked`, the live preview's worker).

- :data:`Report`, :class:`Stages` -- the two shapes of progress.
- :func:`reporting`, :func:`progress_bar`, :func:`report` -- the first way.
- :class:`Progress`, :class:`Checked`, :func:`stage` -- the second.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from typing import Any, Protocol

__all__ = ["Report", "Stages", "reporting", "progress_bar", "report", "Progress", "Checked",
           "stage"]

Report = Callable[..., None]
"""A progress callback: ``report(fraction, message="")``, fraction from 0 to 1."""

_REPORTS: list[Report] = []


class Stages(Protocol):
    """A progress over stages: ``stage(start, end)`` is the :data:`Report` of one stage, its
    own 0..1 mapped onto ``start..end`` of the whole."""

    def stage(self, start: float, end: float) -> Report: ...


@contextlib.contextmanager
def reporting(callback: Report) -> Iterator[None]:
    """Send the progress of slow steps run inside (a cold mesh, an image decoded) to
    ``callback(fraction, message)``."""
    _REPORTS.append(callback)
    try:
        yield
    finally:
        _REPORTS.pop()


@contextlib.contextmanager
def progress_bar(window_manager: Any) -> Iterator[None]:
    """Route the progress of what runs inside to ``window_manager.progress_update`` (the
    cursor's counter), begun on the first report only: a click that reads nothing shows
    nothing.  ``window_manager`` None, or headless: nothing is shown."""
    begun: list[bool] = []

    def update(fraction: float, message: str = "") -> None:
        if window_manager is None:
            return
        if not begun:
            window_manager.progress_begin(0, 100)
            begun.append(True)
        window_manager.progress_update(int(round(100 * min(max(fraction, 0.0), 1.0))))

    with reporting(update):
        try:
            yield
        finally:
            if begun:
                window_manager.progress_end()


def report(fraction: float, message: str) -> None:
    """Report progress to the innermost :func:`reporting` (nothing outside one)."""
    if _REPORTS:
        _REPORTS[-1](fraction, message)


class Progress:
    """``window_manager.progress_*`` from 0 to 100 over Apply's stages (does nothing
    headless: ``context`` without a window manager), as a context manager."""

    def __init__(self, context: Any):
        self.wm = getattr(context, "window_manager", None)

    def __enter__(self) -> Progress:
        if self.wm is not None:
            self.wm.progress_begin(0, 100)
        return self

    def stage(self, start: float, end: float) -> Report:
        def update(fraction: float, message: str = "") -> None:
            if self.wm is not None:
                self.wm.progress_update(int(100 * (start + (end - start) * fraction)))
        return update

    def __exit__(self, *exc: object) -> None:
        if self.wm is not None:
            self.wm.progress_end()


class Checked:
    """Stages that report nothing but call ``check()`` at every step (which raises to stop
    the work)."""

    def __init__(self, check: Callable[[], None]):
        self.check = check

    def stage(self, start: float, end: float) -> Report:
        def update(fraction: float, message: str = "") -> None:
            self.check()
        return update


def stage(progress: Stages | None, start: float, end: float) -> Report | None:
    """``progress.stage(start, end)``, or None without a progress."""
    return progress.stage(start, end) if progress is not None else None
