"""What weighing the head's hollows costs the match (makeup_skin_addon.sky_visibility): on the
production head of bench/skin_colour.py (1,007,616 triangles, built there into its cache), the
grid of the skin's surface points and the rays of the diffuse lobe and two gloss lobes, cold
and cached (a benchmark, not a test).

    python bench/sky_visibility.py [--cache DIR] [--repeats 9]

The head is framed by the portrait camera of tests/support/character.py (its file has none);
the surface points are read first (what reading the artist's shader does anyway; printed: a
shader of plain values pays them for the sky alone).  Per step the process's CPU seconds (one
BLAS thread), the least and the median over ``--repeats`` (the cache emptied before each cold
one), and the shares of the sky measured.  Run with the venv's python of the Blender line.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
HERE = Path(__file__).resolve()
REPO = HERE.parent.parent
for _path in (REPO, REPO / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))
DEFAULT_CACHE = HERE.parent / "results" / "skin_colour_cache"
ROUGHNESSES = (0.45, 0.729)
"""The artist's gloss (tests/support/artist_skins.py) and the default film's."""


def _cpu(step) -> tuple[float, object]:
    start = time.process_time()
    value = step()
    return time.process_time() - start, value


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE)
    parser.add_argument("--repeats", type=int, default=9)
    args = parser.parse_args(argv)
    head = args.cache / "head.blend"
    if not head.exists():
        print(f"{head} missing: run bench/skin_colour.py first (it builds the head)")
        return 1
    import bpy

    bpy.ops.wm.open_mainfile(filepath=str(head))
    from support import character

    from makeup_skin_addon import skin_sampling, sky_visibility

    scene = bpy.context.scene
    obj = next(o for o in bpy.data.objects if o.type == "MESH")
    if scene.camera is None:
        character.portrait_camera_and_lights(scene, obj, size=96, samples=8)
    material = obj.active_material
    triangles = sum(len(p.vertices) - 2 for p in obj.data.polygons)
    points_s, samples = _cpu(lambda: skin_sampling.surface_samples(material, scene=scene))
    uv_s, _ = _cpu(lambda: samples.uv(""))
    print(f"{obj.name}: {triangles} triangles; surface points read (cold) {points_s + uv_s:.3f}"
          f" s CPU")
    grid, rays, cached = [], [], []
    for _ in range(args.repeats):
        sky_visibility.clear_cache()
        seconds, sky = _cpu(lambda: sky_visibility.sky_visibility(samples))
        grid.append(seconds)
        seconds, seen = _cpu(lambda measured=sky: measured.seen(*ROUGHNESSES))
        rays.append(seconds)
        cached.append(_cpu(lambda: sky_visibility.sky_visibility(samples).seen(*ROUGHNESSES))
                      [0])
    for name, values in (("grid (cold)", grid), ("rays: diffuse + 2 glosses", rays),
                         ("again (cached)", cached)):
        print(f"  {name:28s} CPU min {min(values) * 1e3:6.1f} ms, median "
              f"{statistics.median(values) * 1e3:6.1f} ms")
    diffuse, glosses = seen
    print(f"  sky seen: diffuse {diffuse:.3f}, " + ", ".join(
        f"gloss at {r:g} {g:.3f}" for r, g in zip(ROUGHNESSES, glosses, strict=True)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
