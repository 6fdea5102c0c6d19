"""What the add-on's check on opening a file costs (a benchmark, not a test).

    python bench/on_load_check.py [--out DIR] [--repeats 3] [--json FILE]

Times :func:`makeup_skin_addon.on_load.check_on_load`, the ``load_post`` handler, called
directly on files opened with the handler detached (so only its own work is timed), and
the opening itself for scale:

- ``empty`` -- a factory-empty file;
- ``plain 1000`` -- 1000 materials and 200 node groups, none made up (what a large scene of
  someone else's pays: one pass over the node groups);
- ``head`` -- the textured head of tests/support/character.py, not made up;
- ``head, made up`` -- the same after Apply (Layered, default tables), intact: the group's
  record read and its image's packed bytes hashed (5.7 kB);
- ``head, damaged`` -- the same file with the packed image's OpenEXR header damaged: the
  check finds it and repairs it (a re-bake and a closure fit, as Check Tables); timed in a
  fresh process per repeat, as a user opening the file in a new Blender would pay it.

Medians: over 1000 calls for the intact files (microseconds), over ``--repeats`` fresh
processes for the repair (seconds).  Run with the venv's python of the Blender line.
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

ROOT = Path(__file__).resolve().parents[1]
CALLS = 1000


def _setup():
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="on_load_check_"))
    sys.path[:0] = [str(ROOT), str(ROOT / "tests")]
    import bpy

    import makeup_skin_addon
    from makeup_skin_addon import on_load

    bpy.ops.wm.read_factory_settings(use_empty=True)
    makeup_skin_addon.register()
    bpy.app.handlers.load_post.remove(on_load.check_on_load)  # timed by hand below
    return bpy, makeup_skin_addon, on_load


def _open(bpy, path: Path) -> float:
    start = time.perf_counter()
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    return time.perf_counter() - start


def _intact(bpy, on_load, path: Path) -> dict:
    """Open ``path`` (seconds), then the handler's median over :data:`CALLS` calls (us)."""
    opening = _open(bpy, path)
    times = []
    for _ in range(CALLS):
        start = time.perf_counter()
        on_load.check_on_load()
        times.append(time.perf_counter() - start)
    assert on_load.damaged_groups() == {}
    return {"open_s": opening, "check_us": 1e6 * statistics.median(times),
            "materials": len(bpy.data.materials), "node_groups": len(bpy.data.node_groups)}


def _damage(path: Path, packed: bytes) -> None:
    """The OpenEXR header attribute ``channels`` of the packed image renamed (Blender:
    "Invalid or missing attribute", the image renders magenta)."""
    data = bytearray(path.read_bytes())
    at = data.index(b"channels\x00chlist\x00", data.index(packed))
    data[at:at + len(b"channels")] = b"chbnnels"
    path.write_bytes(bytes(data))


def make_files(bpy, out: Path) -> dict:
    """Write the files; returns ``{name: path}``."""
    from support import character

    out.mkdir(parents=True, exist_ok=True)
    files = {}

    def save(name):
        files[name] = out / f"{name.replace(' ', '_').replace(',', '')}.blend"
        bpy.ops.wm.save_as_mainfile(filepath=str(files[name]), compress=False)

    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    save("empty")
    for i in range(1000):
        bpy.data.materials.new(f"Material {i}").use_fake_user = True
    for i in range(200):
        bpy.data.node_groups.new(f"Group {i}", "ShaderNodeTree").use_fake_user = True
    save("plain 1000")
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    head = character.build_character("Head", seed=0)
    save("head")
    bpy.context.view_layer.objects.active = head
    head.active_material.makeup_skin.tier = "LAYERED"
    head.active_material.makeup_skin.resolution = "default"
    assert bpy.ops.makeup_skin.apply() == {"FINISHED"}
    save("head, made up")
    packed = next(bytes(image.packed_file.data) for image in bpy.data.images
                  if image.name.startswith("MakeupSkin LUT"))
    save("head, damaged")
    _damage(files["head, damaged"], packed)
    return files


def repair_worker(path: Path) -> dict:
    """In a fresh process: open the damaged file, time one check (the repair)."""
    bpy, addon, on_load = _setup()
    opening = _open(bpy, path)
    start = time.perf_counter()
    on_load.check_on_load()
    seconds = time.perf_counter() - start
    assert on_load.damaged_groups() == {}
    addon.unregister()  # bpy 4.5 hangs at exit while an add-on's classes are registered
    return {"open_s": opening, "repair_s": seconds}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=None, help="folder for the .blend files")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--repair-worker", type=Path, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.repair_worker is not None:
        print("RESULT " + json.dumps(repair_worker(args.repair_worker)))
        return 0
    out = args.out or Path(tempfile.mkdtemp(prefix="on_load_check_"))
    bpy, addon, on_load = _setup()
    files = make_files(bpy, out)
    results = {name: _intact(bpy, on_load, path) for name, path in files.items()
               if name != "head, damaged"}
    runs = []
    for _ in range(args.repeats):
        run = subprocess.run([sys.executable, __file__, "--repair-worker",
                              str(files["head, damaged"])],
                             capture_output=True, text=True, check=True)
        line = next(x for x in run.stdout.splitlines() if x.startswith("RESULT "))
        runs.append(json.loads(line[len("RESULT "):]))
    results["head, damaged"] = {key: statistics.median(run[key] for run in runs)
                                for key in runs[0]}
    print(f"Blender {bpy.app.version_string}; handler alone (opening for scale)")
    for name, facts in results.items():
        if "check_us" in facts:
            print(f"  {name:<15} check {facts['check_us']:8.1f} us   open "
                  f"{1e3 * facts['open_s']:7.1f} ms   ({facts['materials']} materials, "
                  f"{facts['node_groups']} node groups)")
        else:
            print(f"  {name:<15} repair {facts['repair_s']:6.2f} s   open "
                  f"{1e3 * facts['open_s']:7.1f} ms   (median of {args.repeats} processes)")
    if args.json is not None:
        args.json.write_text(json.dumps(results, indent=1))
    addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
