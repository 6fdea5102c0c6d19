"""File sizes and Apply timings of Made-up Skin on an artist's character (a benchmark, not a test).

    python bench/character_files.py --repo CHECKOUT --out DIR [--json FILE] [--repeats 3]

Measures the add-on of ``CHECKOUT`` (its ``makeup_skin_addon`` and ``lut_baker`` are imported: the
checkout goes first on ``sys.path``) on the scene of *this* script's repository
(``tests/support/character.py``, imported after the add-on with this repository's ``tests`` last on
``sys.path``), so an old and a new checkout are measured on the same scene. Uses only what every
checkout has: ``bpy.ops.makeup_skin.apply()`` on the active, selected object, and the settings
``material.makeup_skin.<tier|skin|foundation|resolution>`` of the object's active material (set
before Apply). Whether Apply gives the object a new material or converts the artist's own one, the
script just calls it and measures.

(a) Saved .blend sizes (``save_as_mainfile(compress=False)``, written to ``--out``):

- ``empty`` -- a factory-empty file;
- ``1 char`` -- one character (tests/support/character.py, seed 0), no Made-up Skin;
- ``1 char, applied`` -- the same after Apply (default settings, tier Layered);
- ``3 chars`` -- three characters (seeds 0, 1, 2: each its own material and textures);
- ``3 chars, applied`` -- the same after Apply: skins ``paper_bioplate``, ``paper_bioplate``,
  ``jensen_skin1`` (two different tables), tier Layered.

For each: materials with zero users after Apply (orphaned: an artist's material the object no
longer uses; Blender does not save them), materials and packed images in memory, the bytes of
packed images, and the materials and images the saved file has when reopened.

(b) Apply timings, wall clock, median over ``--repeats`` fresh Blender processes (one worker
process per repeat and bake resolution, so the first call is truly cold), tier Layered:

- ``cold`` -- the first Apply in the process: imports, bake, closure fit, group, material;
- ``reuse`` -- Apply on a second character with the same settings (tables and group reused);
- ``new skin`` -- Apply on a third character with another skin (``jensen_skin1``), in the same,
  now warm, process: a bake and a fit without first-call costs.

Run with the venv's python of the Blender line to measure (``$(tools/venv.sh)/bin/python``).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from checkout import commit, use_checkout, write_figures  # bench/checkout.py

HERE = Path(__file__).resolve()
TIER = "LAYERED"
RESOLUTIONS = ("preview", "default")
THREE_SKINS = ("paper_bioplate", "paper_bioplate", "jensen_skin1")


def _setup(repo: Path):
    """Import the add-on and lut_baker from ``repo`` (:func:`checkout.use_checkout`), then
    tests/support/character.py of this script's repository; returns ``(bpy, addon,
    character)``.  BLENDER_USER_RESOURCES goes to a temporary folder before bpy is imported."""
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="character_files_"))
    import bpy

    _, makeup_skin_addon = use_checkout(repo, ("lut_baker", "makeup_skin_addon"),
                                        who="character_files")
    from support import character

    return bpy, makeup_skin_addon, character


def _new_file(bpy) -> None:
    """An empty file that keeps the registered add-on."""
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)


def _apply(bpy, obj, *, skin=None, resolution="default") -> float:
    """Make ``obj`` the only selected and the active object, set the tier (and skin and
    resolution) on its active material, run Apply; returns wall seconds."""
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    settings = obj.active_material.makeup_skin
    settings.tier = TIER
    settings.resolution = resolution
    if skin is not None:
        settings.skin = skin
    start = time.perf_counter()
    result = bpy.ops.makeup_skin.apply()
    seconds = time.perf_counter() - start
    if result != {"FINISHED"}:
        raise SystemExit(f"character_files: Apply on {obj.name!r} returned {result}")
    return seconds


def _file_facts(bpy, path: Path) -> dict:
    """Save without compression; size, orphaned materials, materials, packed images."""
    bpy.ops.wm.save_as_mainfile(filepath=str(path), compress=False)
    size = path.stat().st_size
    packed = {image.name: image.packed_file.size for image in bpy.data.images
              if image.packed_file is not None}
    return {
        "file": str(path),
        "bytes": size,
        "mb": size / 1e6,
        "orphaned_materials": sorted(m.name for m in bpy.data.materials if m.users == 0),
        "materials": sorted(m.name for m in bpy.data.materials),
        "objects": sorted(o.name for o in bpy.data.objects),
        "packed_images": packed,
        "packed_bytes": sum(packed.values()),
        "node_groups": sorted(g.name for g in bpy.data.node_groups),
    }


def measure_sizes(bpy, character, out: Path) -> dict:
    """The five files of (a); returns ``{configuration: facts}``."""
    out.mkdir(parents=True, exist_ok=True)
    sizes = {}
    _new_file(bpy)
    sizes["empty"] = _file_facts(bpy, out / "empty.blend")

    _new_file(bpy)
    head = character.build_character("Head", seed=0)
    sizes["1 char"] = _file_facts(bpy, out / "one_character.blend")
    _apply(bpy, head)
    sizes["1 char, applied"] = _file_facts(bpy, out / "one_character_applied.blend")

    _new_file(bpy)
    heads = [character.build_character(f"Head {i + 1}", location=(0.3 * i, 0.0, 0.0), seed=i)
             for i in range(len(THREE_SKINS))]
    sizes["3 chars"] = _file_facts(bpy, out / "three_characters.blend")
    for head, skin in zip(heads, THREE_SKINS, strict=True):
        _apply(bpy, head, skin=skin)
    sizes["3 chars, applied"] = _file_facts(bpy, out / "three_characters_applied.blend")
    for facts in sizes.values():  # what a reopened file still has
        bpy.ops.wm.open_mainfile(filepath=facts["file"], load_ui=False)
        facts["reloaded_materials"] = sorted(m.name for m in bpy.data.materials)
        facts["reloaded_images"] = sorted(i.name for i in bpy.data.images)
    return sizes


def timing_worker(bpy, character, resolution: str) -> dict:
    """One repeat of (b) in this (fresh) process: cold, reuse, new skin."""
    _new_file(bpy)
    heads = [character.build_character(f"Head {i + 1}", location=(0.3 * i, 0.0, 0.0), seed=0)
             for i in range(3)]
    return {"cold": _apply(bpy, heads[0], resolution=resolution),
            "reuse": _apply(bpy, heads[1], resolution=resolution),
            "new skin": _apply(bpy, heads[2], skin="jensen_skin1", resolution=resolution)}


def measure_timings(repo: Path, repeats: int) -> dict:
    """Run :func:`timing_worker` in ``repeats`` fresh processes per resolution; returns
    ``{resolution: {step: {"median": s, "runs": [s, ...]}}}``."""
    timings = {}
    for resolution in RESOLUTIONS:
        runs = []
        for _ in range(repeats):
            result = subprocess.run(
                [sys.executable, str(HERE), "--repo", str(repo), "--worker", resolution],
                capture_output=True, text=True, check=False)
            line = next((line for line in reversed(result.stdout.splitlines())
                         if line.startswith("TIMINGS ")), None)
            if result.returncode != 0 or line is None:
                raise SystemExit(f"character_files: timing worker failed ({result.returncode}):"
                                 f"\n{result.stdout[-2000:]}\n{result.stderr[-4000:]}")
            runs.append(json.loads(line[len("TIMINGS "):]))
        timings[resolution] = {step: {"median": statistics.median(run[step] for run in runs),
                                      "runs": [run[step] for run in runs]}
                               for step in runs[0]}
    return timings


def print_report(results: dict) -> None:
    print(f"\nMade-up Skin on tests/support/character.py heads -- Blender {results['blender']}, "
          f"checkout {results['repo']} at {results['commit']}")
    print(f"\n{'file':<18} {'bytes':>11} {'MB':>8} {'packed MB':>10} {'materials':>9} "
          f"{'images':>6} {'orphaned':>8}")
    for name, facts in results["sizes"].items():
        print(f"{name:<18} {facts['bytes']:>11,d} {facts['mb']:>8.3f} "
              f"{facts['packed_bytes'] / 1e6:>10.3f} {len(facts['materials']):>9d} "
              f"{len(facts['packed_images']):>6d} {len(facts['orphaned_materials']):>8d}")
    for name, facts in results["sizes"].items():
        orphans = facts["orphaned_materials"]
        print(f"{name}: orphaned materials: {len(orphans)}" + (
            f" ({', '.join(orphans)})" if orphans else "")
              + f"; reopened: {len(facts['reloaded_materials'])} materials, "
                f"{len(facts['reloaded_images'])} images")
    base = results["sizes"]
    for plain, applied in (("1 char", "1 char, applied"), ("3 chars", "3 chars, applied")):
        added = base[applied]["bytes"] - base[plain]["bytes"]
        print(f"Apply adds {added / 1e6:+.3f} MB to '{plain}' "
              f"({added / base[plain]['bytes']:+.1%})")
        for image, size in sorted(base[applied]["packed_images"].items()):
            if image not in base[plain]["packed_images"]:
                print(f"  packed by Apply: {image!r} {size / 1e6:.3f} MB")
    runs = len(next(iter(next(iter(results["timings"].values())).values()))["runs"])
    print(f"\nApply wall time, s (median of {runs} fresh processes; tier {TIER})")
    print(f"{'resolution':<10} {'cold':>8} {'reuse':>8} {'new skin':>9}")
    for resolution, steps in results["timings"].items():
        print(f"{resolution:<10} " + " ".join(f"{steps[s]['median']:>{w}.3f}" for s, w in
                                              (("cold", 8), ("reuse", 8), ("new skin", 9))))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", required=True, type=Path,
                        help="checkout whose makeup_skin_addon/ and lut_baker/ are measured")
    parser.add_argument("--out", type=Path, help="folder for the .blend files")
    parser.add_argument("--json", type=Path, help="also write the numbers here")
    parser.add_argument("--repeats", type=int, default=3, help="timing repeats (default 3)")
    parser.add_argument("--worker", choices=RESOLUTIONS, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    repo = args.repo.resolve()
    if not (repo / "makeup_skin_addon").is_dir():
        parser.error(f"{repo} has no makeup_skin_addon/")
    if args.worker is None and args.out is None:
        parser.error("--out is required")
    bpy, addon, character = _setup(repo)
    addon.register()
    try:
        if args.worker is not None:
            print("TIMINGS " + json.dumps(timing_worker(bpy, character, args.worker)))
            return 0
        results = {"blender": bpy.app.version_string, "repo": str(repo),
                   "commit": commit(repo), "character_py": character.__file__,
                   "sizes": measure_sizes(bpy, character, args.out.resolve())}
    finally:
        addon.unregister()  # bpy 4.5 hangs at exit while an add-on stays registered
    results["timings"] = measure_timings(repo, args.repeats)
    print_report(results)
    write_figures(args.json, results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
