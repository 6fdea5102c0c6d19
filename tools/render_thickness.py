"""Sheer to full on the textured head: the pictures and figures of docs/addon.md ("Thickness:
sheer to full") and the README.

Usage::

    "$(tools/venv.sh)/bin/python" tools/render_thickness.py [--out docs/renders/thickness]
        [--size 160 --samples 48] [--measure-size 80 --measure-samples 96]
        [--tones medium darker lighter] [--thicknesses 2 9.6 50] [--json FILE]

One process, Cycles CPU, view transform Standard, no denoiser.  For each skin tone of
tests/support/character.py it builds the textured head with its portrait camera and lights,
renders ``<tone>_before.png`` (the artist's own material), presses Apply with the film at a
thickness (every other setting at its default) and sets Covered Area to 1 (the film
everywhere: what it hides is its thickness alone); then, at each thickness, presses Match
Skin (the shade a makeup artist would pick for that thickness) and renders
``<tone>_<thickness>um.png``.  It composes ``thickness_strip.png`` (one row per tone: before,
then each thickness).

Measured at each thickness under uniform white light (a white world, lamps off) and under the
portrait lights: the head's mean colour against the artist's render, and the blotches'
contrast (the luminance of the render over that of the same head with its albedo at the mean:
``render_match.blotch_contrast``), so that thickness can be read beside the areal mix of
``tools/render_match.py``.  Prints a Markdown table and writes the figures to ``--json``
(default ``<out>/thickness.json``).  Exits non-zero with a message if a step fails.
"""

from __future__ import annotations

import json
import sys
import traceback
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parent.parent
for _path in (REPO_ROOT, REPO_ROOT / "tests", REPO_ROOT / "tools"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

import render_match  # noqa: E402  (tools/render_match.py)
from support import artist_skins  # noqa: E402  (tests/support/)

__all__ = ["main", "THICKNESSES_UM"]

THICKNESSES_UM = (2.0, 9.6, 50.0)
"""Sheer, a typical application (the default), full."""


def _mean(scene, work: Path, tag: str) -> list[float]:
    return artist_skins.face_mean(render_match._render_rgba(scene, work / f"{tag}.exr")).tolist()


def _contrast(scene, material, settings, work: Path, tag: str) -> float:
    """The blotches' contrast at the current settings, Covered Area 1."""
    return render_match.blotch_contrast(scene, material, settings, work, tag, (1.0,))[1.0]


def run_tone(tone: str, args, out: Path, work: Path) -> dict:
    """Build the head of one tone, render and measure it (see the module docstring)."""
    import bpy

    from makeup_skin_addon import live

    scene, material = render_match.head_scene(tone, args)
    before = out / f"{tone}_before.png"
    scene.render.film_transparent = False
    render_match._save_png(before, scene)
    figures: dict = {"tone": tone, "pictures": {"before": str(before)}, "at": {}}
    scene.render.resolution_x = scene.render.resolution_y = args.measure_size
    scene.cycles.samples = args.measure_samples
    for lighting in ("uniform", "portrait"):
        render_match.uniform_light(scene, lighting == "uniform")
        figures[f"artist_{lighting}"] = _mean(scene, work, f"{tone}_{lighting}_artist")
    render_match.uniform_light(scene, False)
    settings = material.makeup_skin
    settings.live_update = False
    settings.film_mode = "SLAB"
    if bpy.ops.makeup_skin.apply() != {"FINISHED"}:
        raise RuntimeError(f"Apply on the {tone} head failed")
    settings.coverage = 1.0
    for thickness in args.thicknesses:
        settings.thickness_um = thickness
        live.flush()
        if bpy.ops.makeup_skin.match_skin() != {"FINISHED"}:
            raise RuntimeError(f"Match Skin on the {tone} head at {thickness} um failed")
        live.flush()
        at: dict = {"absorption": list(settings.absorption), "note": settings.shade_note}
        scene.render.resolution_x = scene.render.resolution_y = args.size
        scene.cycles.samples = args.samples
        picture = out / f"{tone}_{thickness:g}um.png"
        scene.render.film_transparent = False
        render_match._save_png(picture, scene)
        figures["pictures"][f"{thickness:g}"] = str(picture)
        scene.render.resolution_x = scene.render.resolution_y = args.measure_size
        scene.cycles.samples = args.measure_samples
        for lighting in ("uniform", "portrait"):
            render_match.uniform_light(scene, lighting == "uniform")
            at[f"mean_{lighting}"] = _mean(scene, work, f"{tone}_{lighting}_{thickness:g}")
            at[f"blotch_{lighting}"] = _contrast(scene, material, settings, work,
                                                 f"{tone}_{lighting}_{thickness:g}")
        render_match.uniform_light(scene, False)
        figures["at"][f"{thickness:g}"] = at
        print(f"render_thickness: {tone} at {thickness:g} um: absorption "
              f"{np.round(settings.absorption, 3).tolist()}", flush=True)
    return figures


def _table(results, thicknesses) -> str:
    lines = ["| skin | light | artist's render | " + " | ".join(
        f"{t:g} µm: colour (against the artist's), blotch contrast" for t in thicknesses) + " |",
             "|---|---|---|" + "---|" * len(thicknesses)]
    for figures in results:
        for lighting in ("uniform", "portrait"):
            artist = np.array(figures[f"artist_{lighting}"])
            cells = []
            for t in thicknesses:
                at = figures["at"][f"{t:g}"]
                value = np.array(at[f"mean_{lighting}"])
                moved = " / ".join(f"{m:+.1f}%" for m in 100.0 * (value / artist - 1.0))
                cells.append(f"{moved}, {at[f'blotch_{lighting}']:.4f}")
            lines.append(f"| {figures['tone']} | {lighting} | "
                         + ", ".join(f"{v:.3f}" for v in artist) + " | " + " | ".join(cells)
                         + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = render_match.head_arguments(__doc__, "thickness", 160, 48, 80, 96)
    parser.add_argument("--thicknesses", nargs="+", type=float, default=list(THICKNESSES_UM))
    args = parser.parse_args(argv)
    try:
        results = render_match.measure_tones(run_tone, args)
        rows = [[Path(f["pictures"]["before"])] + [Path(f["pictures"][f"{t:g}"])
                                                   for t in args.thicknesses] for f in results]
        render_match._strip(rows, args.out / "thickness_strip.png")
    except Exception:  # noqa: BLE001  (a tool: say what failed and exit non-zero)
        traceback.print_exc()
        return 1
    print(_table(results, args.thicknesses))
    path = args.json or args.out / "thickness.json"
    path.write_text(json.dumps(results, indent=1, default=str) + "\n")
    print(f"render_thickness: figures -> {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
