"""The skin's mean colour on a production head: the colour sampling's time, memory and accuracy,
and the operators that use it end to end (a benchmark, not a test).

    python bench/skin_colour.py [--repo CHECKOUT] [--cache DIR] [--rebuild] [--json FILE]
                                [--parts sampling accuracy operators] [--write-docs]
                                [--idle SECONDS]

The head (built once into ``--cache``, default bench/results/skin_colour_cache/, not committed;
``--rebuild`` builds it again): the textured head of tests/support/character.py (Suzanne, its
own Principled material) with its Subdivision Surface at level 5 applied (503,808 quads,
1,007,616 triangles) and its albedo generated at 4096 x 4096
(:func:`support.character.albedo_pixels`) in an external 8-bit PNG beside the .blend, as a
production texture is; a second PNG, the same with its left half darkened, stands for the file
painted over elsewhere.

Parts, each in fresh Blender processes (so the first call is truly cold), this checkout's add-on
(``--repo``: another checkout's, for the operators only):

- ``sampling`` -- :func:`makeup_skin_addon.skin_sampling.surface_mean` on the head: the cold
  first call, a warm repeat (median of 5), after a mesh edit (a vertex in twenty moved), after
  the image file was rewritten and reloaded, after a paint stroke in Blender (unsaved: the image
  is read whole), and again with nothing painted since (read whole, its checksum unchanged).
  Per step: wall seconds, CPU seconds (the process's, every thread), the memory
  added (the resident set's high-water mark, VmHWM reset before the step through
  /proc/self/clear_refs, minus the resident set before it: tracemalloc misses C allocations).
- ``accuracy`` -- the mean against the exact full-resolution one
  (:func:`support.exact_mean.exact_mean`: every loop triangle at the 16 centroids of its 4 x 4
  subdivision, weighted by its area, read in the whole image linearised); ours at 2^16 points
  in the image reduced to 512 px, and each error apart: 2^16 points in the whole image (the
  points' error), 2^20 points in reduced images of 256-2048 px (the box filter's bias, sRGB
  bytes averaged before they are linearised).
- ``operators`` -- end to end on the head with the add-on registered: ``bpy.ops.makeup_skin.
  match_skin()`` (the first: the colour cold, the session's uniform-light tables baked),
  ``shade_step(direction="LIGHTER")``, ``shade_step(direction="DARKER")``, Match Skin again;
  and, in another process, a first Apply at the defaults as the button makes it in a window
  (``bpy.ops.makeup_skin.apply()``: the match, then the bake and fit at preview resolution,
  refined on a worker and swapped in), and in a third the same with the texture read in an
  earlier session (kept on disk by the add-on's image store, the mesh read cold).  Each
  with the part spent in reading the skin's colour (over the artist's shader
  ``artist_skin.read_material``; an older checkout's ``skin_sampling.surface_mean`` or
  ``shade.image_mean``) and, for Apply, in the match (``matching.first_shade``, or
  ``shade.first_shade``).  Match Skin waits for Apply: the head is applied first and the
  colour's caches in memory emptied, as in a made-up file opened anew on the machine that
  made it up (the reduced image kept on disk, ``image_store``, as the installed extension
  keeps it: each process has a new, empty folder, so the first Apply decodes the texture).
  The clicks are measured as in
  Blender with a window: with the film at a thickness (the default Film) a shade change
  rebuilds the group, whose absorption is baked, on a worker thread; the step is the click
  (what the interface waits for), and the rebuild is then polled as the add-on's timer does
  (``checkout.swapped_in``): when the material shows the new shade, the worker's CPU and the
  main thread's longest block.

Every time is also printed times 3 (a machine three times slower), against the targets: Match
Skin, Lighter, Darker and the first Apply's match (the colour read and the shade solved) at
most 0.2 s and 100 MB on this head (the MB are the whole step's); the whole first Apply at
most 0.3 s of CPU here and 1 s three times slower.  The
machine's load is printed: runs vary with it.  ``--write-docs`` puts the table of the sampling
and the operators into docs/addon.md ("Match Skin").

Run with the venv's python of the Blender line to measure (``$(tools/venv.sh)/bin/python``).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from checkout import (
    MB,
    OWN_ROOT,
    Memory,
    addon_attribute,
    commit,
    machine_load,
    swapped_in,
    use_checkout,
    write_figures,
)
from doc_block import replace_block

HERE = Path(__file__).resolve()
DEFAULT_CACHE = HERE.parent / "results" / "skin_colour_cache"
ALBEDO_PX = 4096
LEVELS = 5
WARM_REPEATS = 5
TARGET_S = 0.2
TARGET_MB = 100.0
APPLY_CPU_S = 0.3
APPLY_SLOWER_S = 1.0
"""The first Apply's own targets, on top of its match's (``TARGET_S``, ``TARGET_MB``): at most
0.3 s of CPU here and 1 s on a machine three times slower."""
SLOWER = 3.0
PARTS = ("sampling", "accuracy", "operators")
IDLE_S = 0.0
"""Seconds of nothing before each step (``--idle``), as an artist's clicks come: memory the
process freed may have gone back to the system by then (a virtual machine's free-page
reporting, the kernel's huge pages) and costs more to take again."""
DOC = OWN_ROOT / "docs" / "addon.md"
BEGIN, END = "<!-- skin-colour:begin -->", "<!-- skin-colour:end -->"
SAMPLING_ROWS = {"cold": "the colour, cold (the first click)", "warm": "again (warm)",
                 "mesh edit": "after a mesh edit (a vertex in 20 moved)",
                 "image file edit": "after the image file changed (reloaded)",
                 "image painted": "after a paint stroke in Blender (unsaved)",
                 "image painted, again": "again, nothing painted since (its pixels checked)"}
OPERATOR_ROWS = {"match_skin": "Match Skin, the first (the file opened anew)", "lighter": "Lighter",
                 "darker": "Darker", "match_skin again": "Match Skin again",
                 "first apply": "first Apply (bake and fit included; the texture never "
                                "read before)",
                 "first apply, texture known": "first Apply (the same; the texture read in an "
                                               "earlier session)"}
FIRST_APPLY = {"apply": "first apply", "apply_known": "first apply, texture known"}
"""The operators part's first Apply by worker: the texture never read on the machine, or read
in an earlier session (kept on disk by the add-on's image store)."""


# -- the production head ------------------------------------------------------------------------

def _bpy():
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="bench_skin_"))
    import bpy

    return bpy


def build(cache: Path) -> None:
    """The head and its two albedo files into ``cache`` (about a minute and 2 GB: the 4096 px
    albedo's noise is generated by FFTs)."""
    bpy = _bpy()
    use_checkout(OWN_ROOT, ("lut_baker", "makeup_skin_addon"), who="skin_colour")
    from support import character

    cache.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    obj = character.build_character("Head")
    pixels = character.albedo_pixels(0, ALBEDO_PX)
    edited = pixels.copy()
    edited[:, : ALBEDO_PX // 2, :3] *= 0.8
    for name, values in (("albedo.png", pixels), ("albedo_edited.png", edited)):
        image = bpy.data.images.new(name, ALBEDO_PX, ALBEDO_PX, alpha=False)
        image.pixels.foreach_set(values.ravel())
        image.filepath_raw = str(cache / name)
        image.file_format = "PNG"
        image.save()
        bpy.data.images.remove(image)
    del pixels, edited
    albedo = bpy.data.images.load(str(cache / "albedo.png"))
    albedo.colorspace_settings.name = "sRGB"
    obj.active_material.node_tree.nodes["Albedo"].image = albedo
    obj.modifiers["Subdivision"].levels = LEVELS
    bpy.ops.object.modifier_apply(modifier="Subdivision")
    for image in list(bpy.data.images):
        if image.users == 0:
            bpy.data.images.remove(image)
    bpy.ops.wm.save_as_mainfile(filepath=str(cache / "head.blend"))
    print(f"built {cache / 'head.blend'}: {len(obj.data.polygons)} faces, "
          f"{sum(len(p.vertices) - 2 for p in obj.data.polygons)} triangles")


def _open(cache: Path, repo: Path):
    """``(bpy, head)``: the head's file opened, the add-on of ``repo`` imported (not
    registered)."""
    bpy = _bpy()
    use_checkout(repo, ("lut_baker", "makeup_skin_addon"), who="skin_colour")
    bpy.ops.wm.open_mainfile(filepath=str(cache / "head.blend"))
    head = bpy.data.objects["Head"]
    bpy.context.view_layer.objects.active = head
    return bpy, head


class _Step:
    """Wall and CPU seconds and the memory added (:class:`checkout.Memory`) of a step, after
    :data:`IDLE_S` seconds of nothing (``--idle``)."""

    def __enter__(self):
        time.sleep(IDLE_S)
        self.memory = Memory().__enter__()
        self.wall, self.cpu = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc):
        self.wall_s = time.perf_counter() - self.wall
        self.cpu_s = time.process_time() - self.cpu
        self.memory.__exit__(*exc)
        return False

    def figures(self, **more) -> dict:
        return dict(wall_s=self.wall_s, cpu_s=self.cpu_s, mb=self.memory.added_mb, **more)


def _timed(module, name: str, spent: dict):
    """Replace ``module.name`` by itself timed (wall seconds summed into ``spent[name]``)."""
    original = getattr(module, name)

    def timed(*args, **kwargs):
        start = time.perf_counter()
        try:
            return original(*args, **kwargs)
        finally:
            spent[name] = spent.get(name, 0.0) + time.perf_counter() - start

    setattr(module, name, timed)



def _sampling_parts():
    """``(points, image)``: the modules of the measured checkout that spread the points and
    reduce the image (``surface_points`` and ``image_texels``; ``skin_sampling`` both, before
    they were split from it)."""
    if importlib.util.find_spec("makeup_skin_addon.image_texels") is None:
        from makeup_skin_addon import skin_sampling

        return skin_sampling, skin_sampling
    from makeup_skin_addon import image_texels, surface_points

    return surface_points, image_texels


# -- the workers (one fresh process each) -------------------------------------------------------

def sampling_worker(cache: Path, repo: Path) -> dict:
    import numpy as np

    bpy, head = _open(cache, repo)
    from makeup_skin_addon import skin_sampling

    material = head.active_material
    texture = material.node_tree.nodes["Albedo"]
    working = cache / "albedo_now.png"  # a file this run rewrites
    shutil.copyfile(cache / "albedo.png", working)
    texture.image.filepath = str(working)

    spent: dict = {}
    _timed(_sampling_parts()[1], "reduced_image", spent)

    def mean():
        spent.clear()
        return skin_sampling.surface_mean(texture.image, material, reader=texture.name)

    out = {}
    with _Step() as step:
        result = mean()
    out["cold"] = step.figures(image_s=spent["reduced_image"],
                               rgb=[float(c) for c in result.rgb],
                               error=[float(e) for e in result.error], faces=result.faces)
    warm = []
    for _ in range(WARM_REPEATS):
        with _Step() as step:
            mean()
        warm.append(step.figures(image_s=spent["reduced_image"]))
    out["warm"] = {key: statistics.median(w[key] for w in warm) for key in warm[0]}
    mesh = head.data
    attribute = mesh.attributes["position"]
    positions = np.empty(3 * len(mesh.vertices), np.float32)
    attribute.data.foreach_get("vector", positions)
    positions = positions.reshape(-1, 3)
    positions[::20] *= 1.01  # a vertex in twenty moved out by 1%
    attribute.data.foreach_set("vector", positions.ravel())
    mesh.update()
    with _Step() as step:
        mean()
    out["mesh edit"] = step.figures(image_s=spent["reduced_image"])
    shutil.copyfile(cache / "albedo_edited.png", working)  # the file painted over elsewhere
    texture.image.reload()
    with _Step() as step:
        edited = mean()
    out["image file edit"] = step.figures(image_s=spent["reduced_image"],
                                          rgb=[float(c) for c in edited.rgb])
    texture.image.pixels[0] = 0.5  # one texel painted in Blender: unsaved, read whole
    with _Step() as step:
        mean()
    out["image painted"] = step.figures(image_s=spent["reduced_image"])
    with _Step() as step:
        mean()
    out["image painted, again"] = step.figures(image_s=spent["reduced_image"])
    os.remove(working)
    out["images after"] = sorted(image.name for image in bpy.data.images)
    return out


def accuracy_worker(cache: Path, repo: Path) -> dict:
    bpy, head = _open(cache, repo)
    from makeup_skin_addon import skin_sampling

    material = head.active_material
    image = material.node_tree.nodes["Albedo"].image
    layer = next(layer for layer in head.data.uv_layers if layer.active_render)
    from support import exact_mean

    exact, full = exact_mean.exact_mean(head, image, layer.name, grid=4)

    def relative(values):
        return [float(v) for v in values / exact - 1.0]

    ours = skin_sampling.surface_mean(image, material)
    out = {"exact": [float(c) for c in exact], "ours": relative(ours.rgb),
           "its standard error (2^16 points)": relative(exact + ours.error)}
    spread, texels = _sampling_parts()
    points = spread.object_points(head, material, layer, spread.BUDGET)
    out["points in the whole image"] = relative(
        texels.read_texels(full, points.uv).mean(axis=0))
    many = spread.object_points(head, material, layer, 1 << 20)
    out["2^20 points in the whole image"] = relative(
        texels.read_texels(full, many.uv).mean(axis=0))
    for size in (256, 512, 1024, 2048):
        reduced = texels.reduced_image(image, size)
        out[f"2^20 points at {size} px"] = relative(
            texels.read_texels(reduced.pixels, many.uv).mean(axis=0))
    return out


def operators_worker(cache: Path, repo: Path, which: str) -> dict:
    bpy, head = _open(cache, repo)
    import makeup_skin_addon
    from makeup_skin_addon import shade

    apply_to_object = addon_attribute("apply_to_object")
    if importlib.util.find_spec("makeup_skin_addon.image_store") is not None:
        # As installed: reduced images kept in the extension's folder (new and empty here).
        from makeup_skin_addon import image_store

        image_store.set_directory(tempfile.mkdtemp(prefix="bench_store_"))

    spent: dict = {}
    over_shader = importlib.util.find_spec("makeup_skin_addon.artist_skin") is not None
    if over_shader:  # the film over the artist's shader: the skin read from it
        from makeup_skin_addon import artist_skin, matching, skin_sampling

        _timed(artist_skin, "read_material", spent)
        sampling, match = "read_material", "first_shade"
        _timed(matching, match, spent)
    else:
        sampling = "image_mean" if hasattr(shade, "image_mean") else "surface_mean"
        if sampling == "surface_mean":
            from makeup_skin_addon import skin_sampling

            _timed(skin_sampling, sampling, spent)
        else:
            _timed(shade, sampling, spent)
        match = "first_shade"
        _timed(shade, match, spent)
    makeup_skin_addon.register()
    live = importlib.import_module("makeup_skin_addon.live")
    if hasattr(live, "can_refine"):  # as with a window: a rebuild goes to a worker thread
        live.can_refine = lambda: True
    try:
        material = head.active_material
        material.makeup_skin.live_update = False
        if which == "match" and over_shader:
            # Match Skin waits for Apply (greyed out before): Apply, then forget the colour
            # read in memory (a made-up file opened anew: its mesh read cold, its texture
            # from the store the Apply filled).
            apply_to_object(bpy.context, head)
            skin_sampling.clear_cache()
            _forget_slab_colours()
        if which == "apply_known" and importlib.util.find_spec(
                "makeup_skin_addon.image_store") is not None:
            # The texture read in an earlier session on this machine: kept on disk, not in
            # memory (the mesh read cold).
            from makeup_skin_addon import image_texels, skin_sampling

            image_texels.reduced_image(material.node_tree.nodes["Albedo"].image)
            skin_sampling.clear_cache()
            _forget_slab_colours()
        steps = ([("match_skin", lambda: bpy.ops.makeup_skin.match_skin()),
                  ("lighter", lambda: bpy.ops.makeup_skin.shade_step(direction="LIGHTER")),
                  ("darker", lambda: bpy.ops.makeup_skin.shade_step(direction="DARKER")),
                  ("match_skin again", lambda: bpy.ops.makeup_skin.match_skin())]
                 if which == "match" else
                 [(FIRST_APPLY[which], lambda: bpy.ops.makeup_skin.apply())])  # the button's
        out = {}
        for name, run in steps:
            spent.clear()
            with _Step() as step:
                result = run()
            if isinstance(result, set) and result != {"FINISHED"}:
                raise SystemExit(f"skin_colour: {name} returned {result}")
            out[name] = step.figures(sampling_s=spent.get(sampling, 0.0),
                                     match_s=spent.get(match))
            if material.name in getattr(live, "in_flight", set)():
                # The film at a thickness bakes its absorption: the group follows the click
                # from a worker thread, polled as the add-on's timer does.
                rebuild = swapped_in(bpy, live, material.name, lambda: None,
                                     watch=lambda: _group_bake(material))
                shown = [(step.wall_s + seconds, resolution)
                         for seconds, (_, resolution) in rebuild["changes"]]
                out[name].update(shown_after_s=shown[0][0] if shown else step.wall_s,
                                 shown=shown, rebuild_cpu_s=rebuild["worker_cpu_s"],
                                 worst_block_s=rebuild["worst_block_s"])
        out["source"] = (matching.skin_target(material).source if over_shader
                         else shade.skin_colour(material).source)
    finally:
        makeup_skin_addon.unregister()
    return out


def _forget_slab_colours() -> None:
    """Forget the slab's colours kept in memory (a session of its own: the file opened anew),
    where the checkout keeps them."""
    slab_skin = importlib.import_module("lut_baker.model.slab_skin")
    if hasattr(slab_skin, "_COLOURS"):
        slab_skin._COLOURS.clear()


WORKERS = {"sampling": sampling_worker, "accuracy": accuracy_worker}


def worker_main(args) -> int:
    if args.worker == "build":
        build(args.cache)
        return 0
    if args.worker in WORKERS:
        out = WORKERS[args.worker](args.cache, args.repo)
    else:
        out = operators_worker(args.cache, args.repo, args.worker)
    print("RESULT " + json.dumps(out))
    return 0


# -- the runner ---------------------------------------------------------------------------------

def _run(args, worker: str) -> dict:
    repo = args.repo if worker in ("match", *FIRST_APPLY) else OWN_ROOT
    command = [sys.executable, str(HERE), "--worker", worker, "--cache", str(args.cache),
               "--repo", str(repo), "--idle", str(args.idle)]
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    line = next((line for line in reversed(result.stdout.splitlines())
                 if line.startswith("RESULT ")), None)
    if result.returncode != 0 or (line is None and worker != "build"):
        raise SystemExit(f"skin_colour: worker {worker} failed ({result.returncode}):\n"
                         f"{result.stdout[-2000:]}\n{result.stderr[-4000:]}")
    return json.loads(line[len("RESULT "):]) if line else {}


def _met(ok: bool) -> str:
    return "met" if ok else "missed"


def _verdicts(figures: dict) -> tuple[str, str]:
    """Whether a step meets its targets here and on a machine three times slower: a click at
    most 0.2 s and 100 MB; a first Apply's match (the colour read and the shade solved) the
    same, and the whole Apply at most 0.3 s of CPU (1 s three times slower)."""
    small = figures["mb"] <= TARGET_MB
    if figures.get("match_s") is None:
        return (_met(figures["wall_s"] <= TARGET_S and small),
                _met(SLOWER * figures["wall_s"] <= TARGET_S and small))
    match = figures["sampling_s"] + figures["match_s"]
    whole = figures["cpu_s"]
    here = (f"match {_met(match <= TARGET_S and small)}, "
            f"Apply {_met(whole <= APPLY_CPU_S)}")
    slower = (f"match {_met(SLOWER * match <= TARGET_S and small)}, "
              f"Apply {_met(SLOWER * whole <= APPLY_SLOWER_S)}")
    return here, slower


def _row(name: str, figures: dict, extra: str = "") -> str:
    here, slower = _verdicts(figures)
    return (f"  {name:<28} {figures['wall_s']:8.3f} {figures['cpu_s']:8.3f} "
            f"{figures['mb']:8.1f} {SLOWER * figures['wall_s']:8.3f}  "
            f"{here} | {slower} |{extra}")


HEADER = (f"  {'step':<28} {'wall s':>8} {'CPU s':>8} {'MB added':>8} {'wall x3':>8}  "
          f"target | x3 |")


def print_sampling(figures: dict) -> None:
    print("\nskin_sampling.surface_mean on the head (image s: the part reading the image)")
    print(HEADER + " image s")
    for name in SAMPLING_ROWS:
        print(_row(name, figures[name], f" {figures[name]['image_s']:.3f}"))
    cold = figures["cold"]
    print(f"  mean {', '.join(f'{c:.5f}' for c in cold['rgb'])} +- "
          f"{', '.join(f'{e:.5f}' for e in cold['error'])} over {cold['faces']} faces; after "
          f"the file edit {', '.join(f'{c:.5f}' for c in figures['image file edit']['rgb'])}")
    print(f"  images in the file after: {figures['images after']}")


def print_accuracy(figures: dict) -> None:
    print("\nagainst the exact full-resolution mean (relative, R G B)")
    print(f"  exact {', '.join(f'{c:.5f}' for c in figures['exact'])}")
    for name, values in figures.items():
        if name != "exact":
            print(f"  {name:<32} " + "  ".join(f"{100 * v:+.4f}%" for v in values))


def print_operators(figures: dict) -> None:
    print("\noperators end to end (sampling: the part in the colour sampling)")
    print(HEADER + " sampling s (match s)")
    for name, values in figures.items():
        if name == "source":
            continue
        match = values.get("match_s")
        extra = f" {values['sampling_s']:.3f}" + (f" ({match:.3f})" if match else "")
        print(_row(name, values, extra + _shown(values)))
    print(f"  Skin Color: {figures['source']}")


def _group_bake(material) -> tuple:
    """``(key, resolution)`` of the bake of ``material``'s group (what a swap changes)."""
    from makeup_skin_addon import groups, nodes

    meta = nodes.read_meta(groups.group_of(material).node_tree)
    return meta.get("key"), meta.get("resolution")


def _shown(figures: dict) -> str:
    """When the click's rebuild went to a worker: when the material showed it (at each
    resolution), the workers' CPU and the main thread's longest block."""
    if "shown_after_s" not in figures:
        return ""
    steps = ", ".join(f"{resolution} after {seconds:.2f} s"
                      for seconds, resolution in figures.get("shown") or [])
    return (f"; shown {steps or 'at once'} (rebuilt on a worker, "
            f"{figures['rebuild_cpu_s']:.2f} s of its CPU; the interface blocked "
            f"{figures['worst_block_s']:.3f} s at most)")


def markdown(results: dict) -> str:
    """The sampling's and the operators' figures as the table of docs/addon.md."""
    lines = ["| step | wall s | CPU s | MB added | target | wall s x 3 | target x 3 | "
             "colour sampling s |", "|---|---|---|---|---|---|---|---|"]

    def row(label, figures, part):
        here, slower = _verdicts(figures)
        lines.append(f"| {label} | {figures['wall_s']:.3f} | {figures['cpu_s']:.3f} | "
                     f"{figures['mb']:.0f} | {here} | {SLOWER * figures['wall_s']:.2f} | "
                     f"{slower} | {part} |")

    for name, label in SAMPLING_ROWS.items():
        figures = results["sampling"][name]
        row(label, figures, f"all (the image {figures['image_s']:.3f})")
    for name, label in OPERATOR_ROWS.items():
        figures = results["operators"][name]
        match = figures.get("match_s")
        row(label, figures, f"{figures['sampling_s']:.3f}"
            + (f" (the match {match:.3f})" if match else "") + _shown(figures))
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", type=Path, default=OWN_ROOT,
                        help="the checkout whose add-on is measured (operators only)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE)
    parser.add_argument("--rebuild", action="store_true")
    parser.add_argument("--parts", nargs="+", choices=PARTS, default=list(PARTS))
    parser.add_argument("--json", type=Path)
    parser.add_argument("--write-docs", action="store_true",
                        help="put the sampling's and the operators' table into docs/addon.md")
    parser.add_argument("--idle", type=float, default=0.0,
                        help="seconds of nothing before each step, as an artist clicks")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    args.cache = args.cache.resolve()
    args.repo = args.repo.resolve()
    global IDLE_S
    IDLE_S = args.idle
    if args.worker:
        return worker_main(args)
    if args.rebuild or not (args.cache / "head.blend").exists():
        print(f"building the head into {args.cache} ...", flush=True)
        _run(args, "build")
    results = {"commit": commit(args.repo), "load_before": machine_load()}
    print(f"{args.repo} at {results['commit']}; load {results['load_before']}")
    if "sampling" in args.parts:
        results["sampling"] = _run(args, "sampling")
        print_sampling(results["sampling"])
    if "accuracy" in args.parts:
        results["accuracy"] = _run(args, "accuracy")
        print_accuracy(results["accuracy"])
    if "operators" in args.parts:
        results["operators"] = {**_run(args, "match"), **_run(args, "apply"),
                                **_run(args, "apply_known")}
        print_operators(results["operators"])
    results["load_after"] = machine_load()
    print(f"\nload after {results['load_after']} (MB: {MB:.0e} bytes)")
    write_figures(args.json, results)
    if args.write_docs and {"sampling", "operators"} <= set(args.parts):
        replace_block(DOC, markdown(results), BEGIN, END)
    return 0


if __name__ == "__main__":
    sys.exit(main())
