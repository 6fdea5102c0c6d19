"""What the film over the artist's shader costs to render, beside the artist's shader alone and
the tiers over the skin preset.

A benchmark, not a test::

    python bench/render_cost.py          # docs/render_cost.png, a table in speed_accuracy.md
    python bench/render_cost.py --quick  # fewer repeats (a smoke run)
    python bench/render_cost.py --replot # the chart and table again from the results file

Scene: the bench sphere (``tests/support/bench_scene.py``: 10 mm, orthographic, a sun 45 degrees
from the view, Cycles CPU, adaptive sampling off), 64 x 64 px.  The artist's shader is a
Principled BSDF skin (``tests/support/artist_skins.py``, "pale_value": Base Color (0.7, 0.5,
0.4), Subsurface Weight 1, Random Walk, radius (1, 0.2, 0.1) x 5 mm, Roughness 0.45).  Configs:

- ``artist``: the artist's shader alone (before Apply);
- ``<tier> over shader, coverage c``: Apply over it (the group's Skin Shader is the artist's
  shader), Tier fixed, Coverage 1 (where the film covers: Cycles skips a Mix Shader's input of
  weight 0, so the artist's shader costs nothing there), 0.6 (the default: both are evaluated)
  and 0 (bare: the film's closures cost nothing);
- ``<tier> preset, coverage c``: the tier's group over the skin preset (the skin preset's bare
  skin), as every material was before the film went over the artist's shader (its subsurface
  method the fit's, Christensen-Burley; "Random Walk": the artist's method forced on it, the
  like-for-like cost of a covered area).

Each config renders at :data:`SAMPLES` samples, seeds 0.. (:data:`REPEATS`), configurations
interleaved so that the load of a shared machine falls on all alike; the time per frame is the
median, given also relative to the artist's shader alone.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _path in (ROOT, ROOT / "bench", ROOT / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from doc_block import replace_block  # noqa: E402  (bench/doc_block.py)

DOCS = ROOT / "docs"
RESULTS = ROOT / "bench" / "results" / "render_cost.json"
MARKERS = ("<!-- render-cost:begin -->", "<!-- render-cost:end -->")
SIZE = 64
SAMPLES = 128
REPEATS = 5
TIERS = ("PRINCIPLED", "LAYERED")
COVERAGES = (1.0, 0.6, 0.0)


def _configs() -> list[tuple[str, str | None, float | None, bool, str | None]]:
    """``(name, tier, coverage, over the shader, forced subsurface method of the preset)``."""
    configs: list = [("artist", None, None, True, None)]
    for tier in TIERS:
        for over in (True, False):
            for coverage in COVERAGES:
                where = "over shader" if over else "preset"
                configs.append((f"{tier.title()} {where}, coverage {coverage:g}", tier,
                                coverage, over, None))
        configs.append((f"{tier.title()} preset, Random Walk, coverage 1", tier, 1.0, False,
                        "RANDOM_WALK"))
    return configs


def measure(repeats: int) -> list[dict]:
    """Median seconds per frame of every config (module docstring)."""
    import bpy
    import numpy as np
    from support import artist_skins, bench_scene, sphere_scene

    sphere = bench_scene.sphere_scene(size=SIZE, samples=SAMPLES)
    scene = bpy.context.scene
    scene.render.use_persistent_data = False
    artist = artist_skins.artist_material("pale_value")
    bench_scene.set_material(sphere, artist)
    materials = {"artist": (artist, None)}
    with sphere_scene.addon_registered():
        from makeup_skin_addon import apply, groups

        for name, tier, coverage, over, method in _configs()[1:]:
            if over:
                material = artist.copy()
                material.name = name
                bench_scene.set_material(sphere, material)
                material.makeup_skin.tier = tier
                bpy.context.view_layer.objects.active = sphere
                apply.apply_to_object(bpy.context, sphere)
            else:
                sphere.data.materials.clear()
                sphere.data.materials.append(bpy.data.materials.new(name))
                material = sphere.active_material
                material.makeup_skin.tier = tier
                if method is not None:
                    material.makeup_skin.subsurface_method = method
                apply.apply_to_object(bpy.context, sphere)
            material.makeup_skin.coverage = coverage
            groups.update_sockets(material)
            materials[name] = (material, coverage)
        times: dict = {name: [] for name in materials}
        for seed in range(repeats):
            for name, (material, _) in materials.items():
                bench_scene.set_material(sphere, material)
                bench_scene.set_samples(scene, SAMPLES, seed)
                seconds, _ = bench_scene.render_image()
                times[name].append(seconds)
    artist_time = float(np.median(times["artist"]))
    return [{"config": name, "seconds": float(np.median(values)),
             "relative": float(np.median(values)) / artist_time, "runs": len(values)}
            for name, values in times.items()]


def markdown(rows) -> str:
    lines = [f"Time per frame, median of {rows[0]['runs']} ({SIZE} x {SIZE} px, {SAMPLES} "
             f"samples, Cycles CPU; `python bench/render_cost.py`):", "",
             "| config | seconds | relative to the artist's shader |", "|---|---|---|"]
    lines += [f"| {r['config']} | {r['seconds']:.3f} | {r['relative']:.2f} |" for r in rows]
    return "\n".join(lines)


def chart(rows, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.0, 4.6))
    names = ["the artist's shader alone" if r["config"] == "artist" else r["config"]
             for r in rows]
    colours = ["tab:grey" if r["config"] == "artist" else "tab:orange"
               if "over shader" in r["config"] else "tab:blue" for r in rows]
    ax.barh(range(len(rows)), [r["relative"] for r in rows], color=colours)
    ax.set_yticks(range(len(rows)), names, fontsize=8)
    ax.invert_yaxis()
    ax.axvline(1.0, color="k", linewidth=0.6)
    ax.set_xlabel("time per frame relative to the artist's shader alone")
    ax.set_title("Render cost of the film over the artist's shader (orange)\nand over the "
                 "skin preset (blue), Cycles CPU", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2 repeats")
    parser.add_argument("--no-docs", action="store_true", help="print only")
    parser.add_argument("--replot", action="store_true",
                        help="the chart and table from bench/results/render_cost.json")
    args = parser.parse_args(argv)
    if args.replot:
        rows = json.loads(RESULTS.read_text())
    else:
        os.environ.setdefault("BLENDER_USER_RESOURCES",
                              tempfile.mkdtemp(prefix="render_cost_"))
        rows = measure(2 if args.quick else REPEATS)
        if not args.quick:
            RESULTS.write_text(json.dumps(rows, indent=1) + "\n")
    text = markdown(rows)
    print(text)
    if not args.no_docs:
        chart(rows, DOCS / "render_cost.png")
        replace_block(DOCS / "speed_accuracy.md", text, *MARKERS)
    return 0


if __name__ == "__main__":
    sys.exit(main())
