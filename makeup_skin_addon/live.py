"""Live update while sliders move, with the bake and the fit off the main thread.

Socket-level settings (coverage, absorption, skin colour, subsurface scale, gloss) go straight
to the material's group node.  Settings that change the tables (foundation, skin, Film and
Skin Roughness, Film IOR, tier, subsurface method) mark the material and start one debounce
timer (:func:`rebake_timer`); when it fires, each marked material's rebuild at preview
resolution is prepared on the main thread (its settings read:
:func:`.rebuild.prepare_rebuild`) and computed on a worker thread (bake, fit, measurement:
numpy only, no bpy), and a poll timer (:func:`poll_timer`) swaps the new group in on the main
thread when it is ready (:func:`.rebuild.finish_rebuild`: the group rebuilt in place, copied
first if other materials share it).  So the interface never waits for a bake or a fit: the
main thread only reads the settings, polls and builds the group.  A newer change supersedes a
rebuild in flight: the worker stops at its next step and its result is dropped, as is one
whose material was removed, reverted or re-applied (:func:`cancel`) meanwhile.

A Thickness move measures nothing (the slab's tables are shared, its fit moves in
milliseconds: :attr:`.rebuild.Rebuild.unmeasured`): the group of the tier the material has is
swapped in at once, and a rebuild that measures (the tiers' errors, Tier Auto's choice) follows
it once the slider rests (:data:`DEBOUNCE_S`), superseded by the next move.

An Apply at preview resolution is refined the same way (:func:`refine`: the settings'
resolution computed on a worker, swapped in when ready).  A preview that a refinement follows
(:func:`refine`'s ``then``) bakes the film's slab at its thickness only, as Apply's does
(:class:`.bakes.Bake`'s ``one_thickness``).

Without an event loop (headless) timers never fire: :func:`flush` does the whole work at once,
waiting for the rebuilds in flight.  :func:`unregister` removes the timers and stops and joins
the workers, so that nothing is left behind (bpy 4.5 hangs at exit otherwise).

- :func:`sockets_changed`, :func:`tables_changed` -- the settings' update callbacks.
- :func:`start` -- the marked materials' rebuilds set off (what the debounce timer does);
  :func:`poll` -- the finished ones swapped in (what the poll timer does).
- :func:`refine` -- a material's rebuild at a resolution set off now; :func:`can_refine` --
  whether it will be swapped in by itself.
- :func:`flush` -- everything at once; :func:`wait` -- wait for the workers (tests, scripts).
- :func:`pending`, :func:`in_flight` -- what is marked or computing; :func:`cancel` -- drop a
  material's; :func:`forget` -- drop everything (a file opened).
"""

from __future__ import annotations

import threading

import bpy

from . import apply, groups
from .rebuild import Rebuild, finish_rebuild, prepare_rebuild

__all__ = ["DEBOUNCE_S", "THICKNESS_DEBOUNCE_S", "POLL_S", "JOIN_TIMEOUT_S", "sockets_changed",
           "tables_changed",
           "start", "poll", "refine", "can_refine", "flush", "wait", "pending", "in_flight",
           "cancel", "forget",
           "rebake_timer", "poll_timer", "register", "unregister"]

DEBOUNCE_S = 0.3
"""Seconds without a further change before a preview rebuild is set off."""
THICKNESS_DEBOUNCE_S = 0.02
"""The debounce of a Thickness change: its rebuild re-reads the slab's tables and moves the fit
(no bake, no fit: :func:`.bakes.baked`), some 0.1 s of a worker's CPU, so it may follow a
slider closely."""
POLL_S = 0.05
"""Seconds between two looks at the rebuilds in flight."""
JOIN_TIMEOUT_S = 10.0
"""Longest wait for a stopped worker at unregister (it stops at its next step, well within
a second)."""
PREVIEW = apply.PREVIEW

_dirty: dict[str, str] = {}
"""Materials marked for a rebuild, by name: the resolution to rebuild at."""
_unmeasured: set[str] = set()
"""Marked materials whose rebuild measures nothing (a Thickness move), by name."""
_then: dict[str, str] = {}
"""Materials whose rebuild in flight is refined once swapped in, by name: the resolution to
rebuild at then (:func:`refine`'s ``then``)."""
_jobs: dict[str, _Job] = {}
"""The rebuild in flight of each material, by name."""
_stopped: list[_Job] = []
"""Superseded rebuilds whose worker may still be running (joined at unregister)."""
_messages: list[str] = []


class _Superseded(Exception):
    """Raised inside a worker whose rebuild a newer change superseded."""


class _Job:
    """A material's rebuild (:class:`.rebuild.Rebuild`) computed by its own worker thread;
    :meth:`stop` makes the worker stop at its next step."""

    def __init__(self, rebuild: Rebuild):
        self.rebuild = rebuild
        self.error: BaseException | None = None
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self.run, daemon=True,
                                       name=f"Made-up Skin rebuild of {rebuild.material!r}")

    def run(self) -> None:
        """Compute the rebuild (the worker's function; or on the caller's thread)."""
        try:
            self.rebuild.compute(self._check)
        except _Superseded:
            pass
        except Exception as error:  # noqa: BLE001 - reported on the main thread
            self.error = error

    def _check(self) -> None:
        if self._stop.is_set():
            raise _Superseded

    def stop(self) -> None:
        self._stop.set()

    @property
    def stopped(self) -> bool:
        return self._stop.is_set()

    @property
    def done(self) -> bool:
        return not self.thread.is_alive()


def _material_of(settings):
    material = settings.id_data
    return material if isinstance(material, bpy.types.Material) else None


def sockets_changed(settings) -> None:
    """A socket-level setting moved: set the group node's sockets."""
    material = _material_of(settings)
    if material is not None and settings.is_made_up:
        groups.update_sockets(material)


def _supersede(name: str) -> None:
    """Stop the rebuild in flight of material ``name``, if any: its result is dropped."""
    job = _jobs.pop(name, None)
    if job is not None:
        job.stop()
        _stopped.append(job)


def tables_changed(settings, debounce_s: float = DEBOUNCE_S, *,
                   measure_later: bool = False) -> None:
    """A setting the tables depend on moved: supersede the material's rebuild in flight and
    schedule a preview rebuild (debounced by ``debounce_s``: :data:`THICKNESS_DEBOUNCE_S` for
    a Thickness change, whose rebuild bakes and fits nothing; ``measure_later``: and measures
    nothing, a measuring rebuild following it)."""
    material = _material_of(settings)
    if material is None or not settings.is_made_up or not settings.live_update:
        return
    _supersede(material.name)
    _then.pop(material.name, None)
    _mark(material.name, PREVIEW, measure_later, debounce_s)


def _mark(name: str, resolution: str, measure_later: bool, debounce_s: float) -> None:
    """Mark material ``name`` for a rebuild at ``resolution`` and (with an event loop) set the
    debounce timer off anew."""
    _dirty[name] = resolution
    if measure_later and resolution == PREVIEW:
        _unmeasured.add(name)
    else:
        _unmeasured.discard(name)
    if bpy.app.background:
        return  # no event loop: flush() runs the rebuild when asked
    if bpy.app.timers.is_registered(rebake_timer):
        bpy.app.timers.unregister(rebake_timer)
    bpy.app.timers.register(rebake_timer, first_interval=debounce_s)


def pending() -> set[str]:
    """Names of materials waiting for a rebuild: marked, or computing."""
    return set(_dirty) | set(_jobs)


def can_refine() -> bool:
    """Whether a rebuild set off now will be swapped in by itself: an event loop runs the
    poll timer (not headless)."""
    return not bpy.app.background


def in_flight() -> set[str]:
    """Names of materials whose rebuild a worker is computing (or has computed, not yet
    swapped in)."""
    return set(_jobs)


def cancel(material) -> None:
    """Drop what is pending for ``material`` (an Apply or a Revert makes it stale)."""
    _dirty.pop(material.name, None)
    _unmeasured.discard(material.name)
    _then.pop(material.name, None)
    _supersede(material.name)


def forget() -> None:
    """Drop everything pending (another file was opened: its materials are not these)."""
    _dirty.clear()
    _unmeasured.clear()
    _then.clear()
    for name in list(_jobs):
        _supersede(name)


def _usable(material) -> str | None:
    """Why ``material``'s group cannot be rebuilt now, or None."""
    if material is None or not material.makeup_skin.is_made_up:
        return "gone"
    try:
        apply.refuse_linked(None, material)
    except apply.LinkedDataError as error:
        return f"Made-up Skin: no preview: {error}."
    return None


def _prepared(context, name: str, resolution: str) -> _Job | str | None:
    """A job for material ``name``'s rebuild at ``resolution`` (its settings read now;
    measuring nothing if it was so marked), or the sentence saying why not, or None (the
    material is gone or no longer made up)."""
    measure = name not in _unmeasured
    _unmeasured.discard(name)
    material = bpy.data.materials.get(name)
    reason = _usable(material)
    if reason is not None:
        return None if reason == "gone" else reason
    then = _then.get(name)  # a refinement follows: the preview's slab at its thickness will do
    try:
        return _Job(prepare_rebuild(context, material, resolution, measure=measure,
                                    one_thickness=then is not None and then != resolution))
    except (ValueError, RuntimeError) as error:
        return f"Made-up Skin: the preview of {name!r} failed: {error}."


def start(context=None) -> list[str]:
    """Set off the rebuild of every marked material on a worker thread (what the debounce
    timer does) and the poll timer that swaps them in; returns report messages."""
    context = context or bpy.context
    messages = []
    while _dirty:
        name, resolution = _dirty.popitem()
        job = _prepared(context, name, resolution)
        if isinstance(job, _Job):
            _supersede(name)
            _jobs[name] = job
            job.thread.start()
        elif job is not None:
            messages.append(job)
    if _jobs and not bpy.app.background and not bpy.app.timers.is_registered(poll_timer):
        bpy.app.timers.register(poll_timer, first_interval=POLL_S)
    _messages.extend(messages)
    return messages


def refine(context, material, resolution: str, *, then: str | None = None) -> None:
    """Set off the rebuild of ``material``'s group at ``resolution`` now (after an Apply at
    preview resolution): swapped in by the poll timer, or by :func:`flush`.  ``then``: once
    swapped in, rebuild at that resolution too (a shade change with the film at a thickness:
    shown at preview resolution first)."""
    _supersede(material.name)
    _dirty[material.name] = resolution
    _unmeasured.discard(material.name)
    _then.pop(material.name, None)
    if then is not None and then != resolution:
        _then[material.name] = then
    start(context)


def _swap(context, job: _Job) -> list[str]:
    """Build the group of a computed rebuild and make it its material's surface (main
    thread), unless the rebuild was superseded or its material changed meanwhile."""
    rebuild = job.rebuild
    then = _then.pop(rebuild.material, None)
    material = bpy.data.materials.get(rebuild.material)
    if material is None or material.session_uid != rebuild.uid:  # renamed meanwhile?
        material = next((m for m in bpy.data.materials if m.session_uid == rebuild.uid), None)
    if job.stopped or material is None:
        return []
    reason = _usable(material)
    if reason is not None:
        return [] if reason == "gone" else [reason]
    if job.error is not None:
        return [f"Made-up Skin: the preview of {rebuild.material!r} failed: {job.error}."]
    node = groups.group_of(material)
    group = node.node_tree if node is not None else None
    if group is not None and group.users > 1:
        group = group.copy()  # others keep their look; this material gets its own
    try:
        finish_rebuild(context, material, group, rebuild)
    except (ValueError, RuntimeError) as error:
        return [f"Made-up Skin: the preview of {rebuild.material!r} failed: {error}."]
    if rebuild.unmeasured is not None and material.name not in _dirty:
        _mark(material.name, rebuild.resolution, False, DEBOUNCE_S)  # now measure it
    if then is not None and material.name not in _dirty:
        refine(context, material, then)
    return []


def _forget_stopped() -> None:
    _stopped[:] = [job for job in _stopped if not job.done]


def poll(context=None) -> list[str]:
    """Swap in every rebuild whose worker has finished (what the poll timer does); returns
    report messages."""
    context = context or bpy.context
    messages = []
    for name, job in list(_jobs.items()):
        if job.done and _jobs.get(name) is job:
            del _jobs[name]
            messages += _swap(context, job)
    _forget_stopped()
    _messages.extend(messages)
    return messages


def rebake_timer():
    """The debounce timer's function (registered with ``bpy.app.timers``): :func:`start`,
    once."""
    start()
    return None  # one shot


def poll_timer():
    """The poll timer's function: :func:`poll`, again after :data:`POLL_S` while rebuilds
    are in flight."""
    poll()
    return POLL_S if _jobs else None


def wait(timeout: float | None = None) -> bool:
    """Wait for the workers in flight to finish (not swapping them in); whether they all
    did within ``timeout`` seconds."""
    for job in list(_jobs.values()) + list(_stopped):
        job.thread.join(timeout)
    return not any(not job.done for job in list(_jobs.values()) + list(_stopped))


def flush(context=None) -> list[str]:
    """Do every pending rebuild now, on this thread: those in flight waited for, those
    marked computed here; each swapped in.  Returns report messages."""
    context = context or bpy.context
    wait()
    messages = poll(context)
    while _dirty or _jobs:
        if not _dirty:  # a refinement a swap set off (``then``)
            wait()
            messages += poll(context)
            continue
        name, resolution = _dirty.popitem()
        job = _prepared(context, name, resolution)
        if isinstance(job, _Job):
            job.run()
            messages += _swap(context, job)
        elif job is not None:
            messages.append(job)
    _messages.extend(messages)
    return messages


def register():
    _dirty.clear()
    _unmeasured.clear()


def unregister():
    for timer in (rebake_timer, poll_timer):
        if bpy.app.timers.is_registered(timer):
            bpy.app.timers.unregister(timer)
    for name in list(_jobs):
        _supersede(name)
    for job in _stopped:
        job.thread.join(JOIN_TIMEOUT_S)
    _stopped.clear()
    _dirty.clear()
    _unmeasured.clear()
    _then.clear()
    _messages.clear()
    apply.clear_cache()
