"""Measuring another checkout: the benchmarks' ``--repo CHECKOUT`` (bench/character_files.py,
bench/apply.py, bench/tier_accuracy.py).

- :func:`use_checkout` -- put a checkout first on ``sys.path``, import packages from it and
  check they came from there; then this repository's ``tests`` (for ``support``) last.
- :func:`commit` -- the checkout's ``HEAD``, marked ``+changes`` when its packages differ from it;
  :func:`packages_commit` -- the last commit that changed its packages.
- :func:`addon_attribute` -- a function of the measured checkout's add-on, wherever that
  checkout keeps it.
- :func:`machine_load` -- the load averages, recorded beside the figures.
- :func:`write_figures` -- a benchmark's results as JSON (``--json FILE``).
- :class:`Memory` -- the memory a step adds: its peak resident set (VmHWM, reset before it)
  and what it keeps, in :data:`MB`.
- :class:`Clock`, :func:`timed` -- CPU and wall seconds of a stretch, of a call;
  :func:`swapped_in` -- a rebuild on the add-on's worker thread polled until its group is
  swapped in, as the add-on's timers would (each main-thread step timed).
"""

from __future__ import annotations

import gc
import importlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

OWN_ROOT = Path(__file__).resolve().parents[1]
OWN_TESTS = OWN_ROOT / "tests"

__all__ = ["OWN_ROOT", "OWN_TESTS", "MB", "use_checkout", "commit", "packages_commit",
           "addon_attribute", "machine_load", "write_figures", "Memory", "Clock", "timed",
           "swapped_in", "POLL_S"]

MB = 1e6


def use_checkout(repo: Path, packages=("lut_baker",), *, who: str = "bench") -> list:
    """Put ``repo`` first on ``sys.path``, import ``packages`` from it (``SystemExit`` naming
    ``who`` if one comes from elsewhere), then append this repository's ``tests`` folder, after
    everything the packages came from, so that ``support`` (tests/support) is this
    repository's.  Returns the imported modules."""
    repo = Path(repo).resolve()
    sys.path.insert(0, str(repo))
    modules = [importlib.import_module(name) for name in packages]
    for module in modules:
        if not Path(module.__file__).resolve().is_relative_to(repo):
            raise SystemExit(f"{who}: {module.__name__} came from {module.__file__}, "
                             f"not from {repo}")
    if str(OWN_TESTS) not in sys.path:
        sys.path.append(str(OWN_TESTS))
    return modules


def commit(repo: Path, packages=("makeup_skin_addon", "lut_baker")) -> str:
    """``git rev-parse HEAD`` of the checkout, with ``+changes`` when ``packages`` differ from
    it; ``unknown`` outside git."""
    try:
        head = subprocess.run(["git", "-C", str(repo), "rev-parse", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(repo), "status", "--porcelain", "--",
                                *packages], capture_output=True,
                               text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+changes" if dirty else "")


def packages_commit(repo: Path, packages=("makeup_skin_addon", "lut_baker")) -> str:
    """The last commit of the checkout that changed ``packages`` (what was measured, when
    later commits touched only benchmarks or docs); ``unknown`` outside git."""
    try:
        return subprocess.run(["git", "-C", str(repo), "log", "-1", "--format=%H", "--",
                               *packages], capture_output=True, text=True,
                              check=True).stdout.strip() or "unknown"
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


ADDON_MODULES = ("apply", "groups", "tier_choice", "rebuild", "bakes", "material")
"""Where the add-on's Apply functions may live: its modules now, then ``material``, which held
them all before Apply was split by job."""


def addon_attribute(name: str):
    """``name`` (a function, a class) of the add-on imported (the measured checkout's), from
    the first of :data:`ADDON_MODULES` that the checkout has and that holds it."""
    for module in ADDON_MODULES:
        try:
            found = importlib.import_module(f"makeup_skin_addon.{module}")
        except ImportError:
            continue
        if hasattr(found, name):
            return getattr(found, name)
    raise AttributeError(f"the add-on has no {name!r} in {ADDON_MODULES}")


def machine_load() -> list[float]:
    """The 1, 5 and 15 minute load averages (rounded): how busy the machine was."""
    return [round(x, 2) for x in os.getloadavg()]


def write_figures(path: Path | None, results: dict) -> None:
    """Write ``results`` to ``path`` as indented JSON (folders created) and say so; nothing
    when ``path`` is None."""
    if path is None:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(results, indent=1) + "\n")
    print(f"\n-> {path}")


def _status_kb(field: str) -> int | None:
    """A ``kB`` field of /proc/self/status (``VmRSS``, ``VmHWM``), or None off Linux."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith(field + ":"):
                return int(line.split()[1])
    except OSError:
        return None
    return None


def _reset_peak() -> bool:
    """Reset VmHWM to the current resident set (``5`` to /proc/self/clear_refs); whether it
    worked."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        return False
    return True


def _maxrss_kb() -> int:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # kB on Linux


class Memory:
    """Resident set before a step, and the peak and the resident set after it (bytes)."""

    def __enter__(self):
        gc.collect()
        self.reset = _reset_peak()
        self.before = (_status_kb("VmRSS") or 0) * 1024
        return self

    def __exit__(self, *exc):
        peak_kb = _status_kb("VmHWM") if self.reset else None
        self.peak = (peak_kb if peak_kb is not None else _maxrss_kb()) * 1024
        self.after = (_status_kb("VmRSS") or 0) * 1024
        return False

    @property
    def added_mb(self) -> float:
        return max(self.peak - self.before, 0) / MB

    @property
    def kept_mb(self) -> float:
        return (self.after - self.before) / MB


POLL_S = 0.05
"""Seconds between two looks at a rebuild in flight (the add-on's poll timer's)."""


class Clock:
    """CPU (every thread) and wall seconds of a stretch, and the main thread's CPU."""

    def __enter__(self):
        self.cpu, self.wall, self.main = time.process_time(), time.perf_counter(), \
            time.thread_time()
        return self

    def __exit__(self, *exc):
        self.cpu = time.process_time() - self.cpu
        self.wall = time.perf_counter() - self.wall
        self.main = time.thread_time() - self.main
        return False


def timed(function, *args, **kwargs) -> tuple[float, object]:
    """``(wall seconds, result)`` of ``function(*args, **kwargs)``."""
    start = time.perf_counter()
    result = function(*args, **kwargs)
    return time.perf_counter() - start, result


def swapped_in(bpy, live, name: str, start, poll_s: float = POLL_S, watch=None) -> dict:
    """Set a worker off with ``start()`` (or nothing: ``lambda: None`` when it is already off)
    and poll it until material ``name``'s group is swapped in (and any rebuild a swap sets
    off after it), as the add-on's timers would: each main-thread step's wall seconds, the
    worker's CPU and wall; with ``watch`` (a function of nothing), the wall seconds at which
    its value changed, and the values (``changes``: when a preview showed, when its
    refinement did)."""
    seen = watch() if watch is not None else None
    changes = []
    with Clock() as clock:
        start_s, _ = timed(start)
        polls = []
        while name in live.in_flight():
            time.sleep(poll_s)
            seconds, messages = timed(live.poll, bpy.context)
            polls.append(seconds)
            if messages:
                raise SystemExit(f"bench: {messages}")
            if watch is not None and (now := watch()) != seen:
                seen = now
                changes.append((time.perf_counter() - clock.wall, now))
    swap = polls[-1] if polls else 0.0
    waits = polls[:-1]
    return {"start_s": start_s, "poll_max_s": max(waits, default=0.0), "polls": len(polls),
            "swap_s": swap, "worker_wall_s": clock.wall, "worker_cpu_s": clock.cpu - clock.main,
            "main_cpu_s": clock.main, "worst_block_s": max([start_s, swap, *waits]),
            "changes": changes}
