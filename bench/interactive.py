"""How long the interface waits: the first Apply, and every Foundation pick and roughness
change with Live Update (a benchmark, not a test).

    python bench/interactive.py --repo CHECKOUT [--json FILE] [--repeats 1]
                                [--cases NAME ...] [--no-live]

Measures the add-on of ``CHECKOUT`` (first on ``sys.path``: bench/checkout.py; an older
checkout without the worker thread is measured as it worked) on this repository's scenes,
each case in a fresh process (so that the first Apply is truly cold: bake, fits, the Auto
tier's choice, the skin's sampling):

- ``defaults/KIND``: every setting at its default on the textured head of
  tests/support/artist_skins.py with the artist's material ``KIND`` (principled, in_group,
  two_principled, mix_glossy, dark_value, pale_value; Cycles, a uniform white world, 128 px,
  64 samples), and ``defaults/sphere``: the sphere of tests/support/sphere_scene.py without a
  material (Apply makes one with the skin preset);
- ``slab/KIND``, ``slab/sphere``: the same with the film at a thickness chosen (Film: At a
  Thickness, 9.6 um: the default, so these are ``defaults/`` by another name, kept for
  comparing with earlier runs);
- ``paper/KIND``, ``paper/sphere``: the same with the paper's film as published (Film: Paper
  Film; the default before the film at a thickness);
- ``OBJECT/FOUNDATION``: a foundation preset chosen in the panel before Apply (its own shade),
  on the sphere (a new material: the skin preset's made-up skin) and on the ``principled``
  head (over the artist's shader);
- ``OBJECT/film_min``, ``film_max``, ``skin_min``, ``skin_max``: Film or Skin Roughness at an
  end of its range (the skin's on the sphere only: over the artist's shader Apply takes the
  shader's roughness).

Each first Apply is measured two ways, each in its own process: ``full``, what a script (no
event loop) gets, everything at the settings' resolution (default) before Apply returns; and
``preview``, what the Apply button does in Blender (``apply_to_object(...,
preview_first=True)`` then ``live.refine``): the bake and fit at preview resolution, then the
settings' resolution on a worker thread.  For each: Apply's CPU (``time.process_time``:
every thread), its main thread's (``time.thread_time``) and wall seconds; for ``preview`` also
the refine's: the worker's wall and CPU seconds (process
CPU minus the main thread's, ``time.thread_time``) and every main-thread step (``start``:
setting the worker off; ``poll``: each look at it, every ``checkout.POLL_S`` s as the poll timer
does; ``swap``: the look that builds the group and installs it), the longest being the worst
block.

With ``--live`` (default on) the ``full`` process of ``defaults/sphere``,
``defaults/principled``, ``slab/sphere`` and ``slab/principled`` then moves the Thickness (2,
50, 1, 300, 1000, 9.6 um, where the film is at a thickness; a rebuild that follows a move to
measure it, ``then measured``, timed on its own), picks every foundation in turn and sets each
roughness to each end (Live Update on), each change measured like the refine: ``update``
(the property's assignment and its callbacks), ``start``, ``poll``, ``swap``, the worker's
CPU and wall.  A checkout without the worker thread blocks for the whole rebuild in
``live.flush()`` (what its debounce timer ran): that is its ``flush`` step.

Every figure also times 3 (``x3``): a machine three times slower.  The measured processes run
with one BLAS thread (``--blas-threads``): numpy's OpenBLAS threads spin between the bake's
matrix products, and ``time.process_time`` counts that spinning as CPU (on an idle core up to
twice the computation; the wall time hardly moves).  Blender's own task threads do the same
around its node-tree updates (each node and link the group's build adds: ``sched_yield`` in
``perf``), which no setting of an add-on's reaches: the main thread's CPU is printed beside the
process's.  Run with the venv's python of the Blender
line to measure (``$(tools/venv.sh)/bin/python``); the machine's load is recorded at the start
and the end.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from checkout import (  # bench/checkout.py
    Clock,
    addon_attribute,
    commit,
    machine_load,
    swapped_in,
    timed,
    use_checkout,
    write_figures,
)

HERE = Path(__file__).resolve()
KINDS = ("principled", "in_group", "two_principled", "mix_glossy", "dark_value", "pale_value")
ROUGHNESS_ENDS = ("film_min", "film_max", "skin_min", "skin_max")
"""Seconds between two polls (the add-on's poll timer's interval)."""
SLOWER = 3.0
"""How much slower the machine of the ``x3`` figures is."""
BLOCK_GOAL_S = 0.1
APPLY_GOAL_CPU_S = 0.3


def _setup(repo: Path):
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="bench_live_"))
    import bpy

    use_checkout(repo, ("lut_baker", "makeup_skin_addon"), who="interactive")
    from support import artist_skins, sphere_scene

    return bpy, artist_skins, sphere_scene


def _foundations() -> list[str]:
    from lut_baker.model import presets

    return list(presets.FOUNDATIONS)


def cases(foundations) -> list[str]:
    """Every case name (module docstring)."""
    out = [f"defaults/{kind}" for kind in KINDS] + ["defaults/sphere"]
    out += [f"slab/{kind}" for kind in KINDS] + ["slab/sphere"]
    out += [f"paper/{kind}" for kind in KINDS] + ["paper/sphere"]
    for obj in ("sphere", "principled"):
        out += [f"{obj}/{name}" for name in foundations]
        out += [f"{obj}/{end}" for end in ROUGHNESS_ENDS
                if not (obj == "principled" and end.startswith("skin"))]
    return out


def _roughness(settings, end: str) -> tuple[str, float]:
    """``(property, value)`` of a roughness at an end of its range."""
    name = "film_roughness" if end.startswith("film") else "skin_roughness"
    prop = settings.bl_rna.properties[name]
    return name, float(prop.hard_min if end.endswith("min") else prop.hard_max)


def _scene(bpy, artist_skins, sphere_scene, case: str):
    """The object of ``case`` in a fresh file, its settings set; returns it."""
    obj_name, what = case.split("/")
    film = {"slab": "SLAB", "paper": "PAPER"}.get(obj_name)
    if film is not None:
        obj_name = "defaults"
    if obj_name == "sphere" or what == "sphere":
        obj = sphere_scene.build_scene(size=128, samples=64)
        if what != "sphere":  # a setting chosen before Apply needs a material to hold it
            obj.data.materials.append(bpy.data.materials.new("Skin"))
    else:
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        obj = artist_skins.head_with(what if obj_name == "defaults" else "principled")
        artist_skins.uniform_white(bpy.context.scene, obj, size=128, samples=64)
    for other in bpy.context.view_layer.objects:
        other.select_set(other == obj)
    bpy.context.view_layer.objects.active = obj
    if film is not None:
        if obj.active_material is None:  # the setting needs a material to hold it
            obj.data.materials.append(bpy.data.materials.new("Skin"))
        obj.active_material.makeup_skin.film_mode = film
    if obj_name != "defaults":
        settings = obj.active_material.makeup_skin
        if what in ROUGHNESS_ENDS:
            name, value = _roughness(settings, what)
            setattr(settings, name, value)
        else:
            settings.foundation = what
    return obj


def first_apply(bpy, support, case: str, mode: str) -> dict:
    """One case's first Apply in this (fresh) process, ``full`` or ``preview``."""
    from makeup_skin_addon import live

    apply_to_object, group_of = addon_attribute("apply_to_object"), addon_attribute("group_of")

    obj = _scene(bpy, *support, case)
    out: dict = {"case": case, "mode": mode}
    if mode == "preview":
        if not hasattr(live, "refine"):
            return {**out, "unavailable": "no worker thread in this checkout"}
        with Clock() as clock:
            material, report = apply_to_object(bpy.context, obj, preview_first=True)
        out.update(apply_cpu_s=clock.cpu, apply_wall_s=clock.wall, apply_main_s=clock.main,
                   refined=report.refine)
        if report.refine is not None:
            out["refine"] = swapped_in(bpy, live, material.name, lambda: live.refine(
                bpy.context, material, report.refine))
    else:
        with Clock() as clock:
            material, _ = apply_to_object(bpy.context, obj)
        out.update(apply_cpu_s=clock.cpu, apply_wall_s=clock.wall, apply_main_s=clock.main)
    meta = json.loads(group_of(material).node_tree["makeup_skin_fit"])
    out.update(tier=meta["tier"], resolution=meta["resolution"],
               fitted=sorted(json.loads(material["makeup_skin_errors"])))
    return out


THICKNESS_CHANGES = (2.0, 50.0, 1.0, 300.0, 1000.0, 9.6)
"""Thickness changes (micrometres) measured first where the film is at a thickness."""


def live_changes(bpy, material) -> list[dict]:
    """Each Thickness change (the film at a thickness), every foundation pick, then each
    roughness end, with Live Update: the main-thread steps and the worker's time of each."""
    from makeup_skin_addon import live

    settings = material.makeup_skin
    settings.live_update = True
    thickness = ([("thickness_um", value) for value in THICKNESS_CHANGES]
                 if getattr(settings, "film_mode", "PAPER") == "SLAB" else [])
    changes = thickness + [("foundation", name) for name in _foundations()
                           if name != settings.foundation] + [_roughness(settings, end)
                                                              for end in ROUGHNESS_ENDS]
    out = []
    for name, value in changes:
        with Clock() as clock:
            update_s, _ = timed(setattr, settings, name, value)
        row = {"change": f"{name}={value}", "update_s": update_s, "update_cpu_s": clock.cpu}
        if hasattr(live, "start"):
            row.update(swapped_in(bpy, live, material.name, lambda: live.start(bpy.context)))
            row["worst_block_s"] = max(row["worst_block_s"], update_s)
            if material.name in live.pending():  # a rebuild that measures follows the swap
                then = swapped_in(bpy, live, material.name, lambda: live.start(bpy.context))
                row["then"] = then
        else:  # the old add-on's debounce timer ran the whole rebuild on the main thread
            with Clock() as clock:
                live.flush(bpy.context)
            row.update(flush_s=clock.wall, flush_cpu_s=clock.cpu,
                       worst_block_s=max(clock.wall, update_s))
        out.append(row)
    return out


def worker(bpy, support, case: str, mode: str, with_live: bool) -> dict:
    out = first_apply(bpy, support, case, mode)
    if with_live and mode == "full" and case in LIVE_CASES:
        obj = bpy.context.view_layer.objects.active
        out["live"] = live_changes(bpy, obj.active_material)
        assert addon_attribute("group_of")(obj.active_material) is not None
    return out


LIVE_CASES = ("defaults/sphere", "defaults/principled", "slab/sphere", "slab/principled")


BLAS_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def _run(repo: Path, case: str, mode: str, with_live: bool, blas_threads) -> dict:
    command = [sys.executable, str(HERE), "--repo", str(repo), "--worker", case, mode]
    if not with_live:
        command.append("--no-live")
    env = dict(os.environ)
    if blas_threads is not None:
        env.update({name: str(blas_threads) for name in BLAS_VARIABLES})
    result = subprocess.run(command, capture_output=True, text=True, check=False, env=env)
    for line in result.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[len("RESULT "):])
    raise SystemExit(f"interactive: {case} {mode} failed:\n{result.stdout}\n{result.stderr}")


def _median_runs(runs: list[dict]) -> dict:
    """The run whose Apply CPU is the median (its other figures with it)."""
    ordered = sorted(runs, key=lambda run: run.get("apply_cpu_s", 0.0))
    return {**ordered[len(ordered) // 2], "runs": len(runs),
            "apply_cpu_all_s": [run.get("apply_cpu_s") for run in runs]}


def measure(repo: Path, names: list[str], repeats: int, with_live: bool,
            blas_threads=1) -> dict:
    results: dict = {"repo": str(repo), "commit": commit(repo), "load_start": machine_load(),
                     "blas_threads": blas_threads, "cases": []}
    for case in names:
        for mode in ("full", "preview"):
            runs = [_run(repo, case, mode, with_live, blas_threads)]
            if "unavailable" not in runs[0]:
                runs += [_run(repo, case, mode, with_live, blas_threads)
                         for _ in range(repeats - 1)]
            row = _median_runs(runs)
            results["cases"].append(row)
            print(_apply_line(row), flush=True)
    results["load_end"] = machine_load()
    return results


def _x3(seconds) -> str:
    return "-" if seconds is None else f"{seconds:.3f} ({SLOWER * seconds:.2f})"


def _apply_line(row: dict) -> str:
    if "unavailable" in row:
        return f"{row['case']:<28} {row['mode']:<7} {row['unavailable']}"
    refine = row.get("refine")
    tail = "" if refine is None else (
        f"  refine: worker {refine['worker_cpu_s']:.3f} s CPU / {refine['worker_wall_s']:.3f} s"
        f", worst block {_x3(refine['worst_block_s'])} (swap {refine['swap_s']:.3f})")
    main = row.get("apply_main_s")
    main_part = "" if main is None else f" (main thread {main:.3f})"
    return (f"{row['case']:<28} {row['mode']:<7} Apply CPU {_x3(row['apply_cpu_s'])}{main_part} "
            f"wall {_x3(row['apply_wall_s'])}  {row['tier']} at {row['resolution']}" + tail)


def print_report(results: dict) -> None:
    print(f"\n{results['repo']} ({results['commit']}), load {results['load_start']} -> "
          f"{results['load_end']}, BLAS threads {results.get('blas_threads') or 'default'}; "
          f"seconds (x{SLOWER:g} in brackets)\n")
    print("First Apply: CPU (every thread) and wall; preview: Apply at preview resolution, "
          "then the refine on a worker")
    for row in results["cases"]:
        print("  " + _apply_line(row))
    for mode in ("full", "preview"):
        cpu = [row["apply_cpu_s"] for row in results["cases"]
               if row["mode"] == mode and "apply_cpu_s" in row]
        if cpu:
            over = sum(c > APPLY_GOAL_CPU_S for c in cpu)
            print(f"  {mode}: Apply CPU {min(cpu):.3f}-{max(cpu):.3f} s (median "
                  f"{statistics.median(cpu):.3f}); {over} of {len(cpu)} over "
                  f"{APPLY_GOAL_CPU_S} s")
            main = [row["apply_main_s"] for row in results["cases"]
                    if row["mode"] == mode and "apply_main_s" in row]
            if main:
                print(f"  {mode}: of it the main thread {min(main):.3f}-{max(main):.3f} s "
                      f"(median {statistics.median(main):.3f}; the rest Blender's own worker "
                      f"threads)")
    blocks = [row["refine"]["worst_block_s"] for row in results["cases"] if row.get("refine")]
    if blocks:
        print(f"  refine: worst main-thread block {_x3(max(blocks))}")
    for row in results["cases"]:
        if not row.get("live"):
            continue
        print(f"\nLive Update after the first Apply of {row['case']}: main-thread steps")
        for change in row["live"]:
            steps = ("update_s", "start_s", "poll_max_s", "swap_s", "flush_s")
            parts = "  ".join(f"{key[:-2]} {change[key]:.3f}" for key in steps if key in change)
            worker_part = (f"  worker {change['worker_cpu_s']:.3f} s CPU / "
                           f"{change['worker_wall_s']:.3f} s" if "worker_cpu_s" in change
                           else "")
            print(f"  {change['change']:<32} {parts}{worker_part}  worst "
                  f"{_x3(change['worst_block_s'])}")
            then = change.get("then")
            if then:
                print(f"  {'  then measured':<32} start {then['start_s']:.3f}  poll_max "
                      f"{then['poll_max_s']:.3f}  swap {then['swap_s']:.3f}  worker "
                      f"{then['worker_cpu_s']:.3f} s CPU / {then['worker_wall_s']:.3f} s  "
                      f"worst {_x3(then['worst_block_s'])}")
        worst = max(max(change["worst_block_s"], (change.get("then") or {}).get(
            "worst_block_s", 0.0)) for change in row["live"])
        print(f"  worst main-thread block {_x3(worst)} (goal {BLOCK_GOAL_S} s)")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", type=Path, required=True,
                        help="checkout whose makeup_skin_addon/ and lut_baker/ are measured")
    parser.add_argument("--cases", nargs="+", metavar="NAME",
                        help="cases to measure (default: every case; module docstring)")
    parser.add_argument("--repeats", type=int, default=1,
                        help="fresh processes per case and mode (default 1)")
    parser.add_argument("--no-live", action="store_true", help="leave out the live changes")
    parser.add_argument("--blas-threads", default="1",
                        help="BLAS threads of the measured processes (default 1: numpy's "
                             "OpenBLAS threads spin between calls, which process_time counts "
                             "as CPU; 'default' leaves the environment as it is)")
    parser.add_argument("--json", type=Path, help="write the figures here")
    parser.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    repo = args.repo.resolve()
    if not (repo / "makeup_skin_addon").is_dir():
        parser.error(f"{repo} has no makeup_skin_addon/")
    if args.worker is not None:
        bpy, *support = _setup(repo)
        with support[1].addon_registered():  # unregistered at the end: bpy 4.5 hangs otherwise
            result = worker(bpy, support, *args.worker, not args.no_live)
        print("RESULT " + json.dumps(result))
        return 0
    use_checkout(repo, ("lut_baker",), who="interactive")
    names = args.cases or cases(_foundations())
    threads = None if args.blas_threads == "default" else int(args.blas_threads)
    results = measure(repo, names, args.repeats, not args.no_live, threads)
    print_report(results)
    write_figures(args.json, results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
