"""Render the four measured foundations on the three skins, on spheres and on the textured head.

Usage::

    "$(tools/venv.sh)/bin/python" tools/render_foundations.py [--out docs/renders/foundations]
        [--sphere-size 144 --character-size 224 --samples 64 --resolution default]

One process, Cycles CPU, view transform Standard, no denoiser, coverage 1, tier Layered.
Writes two grids to ``--out`` (rows: the skins of ``presets.SKINS``, top to bottom
``paper_bioplate``, ``jensen_skin1``, ``jensen_skin2``; columns: the products, left to right
``clarins_103`` matte, ``clarins_105`` dewy, ``clarins_108`` matte, ``clarins_112`` dewy;
white gaps, no text):

- ``spheres.png`` -- the reference sphere of ``tools/render_sphere.py`` (30 mm radius,
  orthographic camera, one sun ``--light-deg`` from the view, black world), each product
  baked here on each skin, Skin Color set to the skin's albedo as the panel does
  (``--resolution`` tables, "default" by default: every product bakes and fits in well under a
  second, whatever its gloss);
- ``character.png`` -- the textured head of ``tests/support/character.py`` after Apply with
  each product, the panel's skin set to each skin, as ``tools/render_character.py --skin``
  does: the head's albedo texture stays linked to Skin Color, so the skin preset changes the
  subsurface radius and the skin's gloss, not its colour.  A leading column holds the
  artist's own material before Apply in the top row (the cells below it are white).

The single tiles are not kept.  Prints one line per bake or Apply and per render with its
time and the mean colour of the tile's central 30% square (sRGB, 0-255), then the total;
exits non-zero with a message if anything fails (a render that is black, not finite, or
missing; an Apply that is not FINISHED or loses the texture links).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

REPO_ROOT = Path(__file__).resolve().parent.parent
for _path in (REPO_ROOT, REPO_ROOT / "tests", REPO_ROOT / "tools"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

import render_character  # noqa: E402  (tools/render_character.py: Apply and its checks)
from render_character import apply_foundation, check, run_reporting  # noqa: E402
from support import character, sphere_scene  # noqa: E402  (tests/support/)

__all__ = ["main", "PRODUCTS"]

PRODUCTS = ("clarins_103", "clarins_105", "clarins_108", "clarins_112")
"""The measured foundations (lut_baker/model/measured_foundations.json), the grids' columns."""
GAP_PX = render_character.GAP_PX


def _tile(path: Path, name: str, what: str, seconds: float, scene) -> np.ndarray:
    """Read the render ``path`` (PNG, float EXR beside it), check it, drop the files, and
    print one line; returns the PNG's pixels (rows bottom-up)."""
    exr = path.with_suffix(".exr")
    check(path.is_file() and exr.is_file(), f"the render of {name} wrote no {path}")
    linear = sphere_scene.image_pixels(exr)[..., :3]
    pixels = sphere_scene.image_pixels(path)
    path.unlink()
    exr.unlink()
    check(bool(np.isfinite(linear).all()),
           f"{name}: {int((~np.isfinite(linear)).sum())} non-finite values in the render")
    h, w = pixels.shape[:2]
    centre = pixels[int(0.35 * h):int(0.65 * h), int(0.35 * w):int(0.65 * w), :3]
    mean = centre.reshape(-1, 3).mean(axis=0)  # the middle of the sphere or the face
    check(float(mean.max()) > 0.02,
           f"{name}: the render is black (mean sRGB {tuple(round(float(v), 4) for v in mean)})")
    srgb = "(" + ", ".join(f"{round(255 * float(v)):3d}" for v in mean) + ")"
    print(f"render_foundations: {name:<36} {scene.render.resolution_x}x"
          f"{scene.render.resolution_y} px, {scene.cycles.samples} samples: {seconds:6.2f} s"
          f"  mean sRGB {srgb}  ({what})", flush=True)
    return pixels


def _shoot(tmp: Path, name: str, what: str) -> np.ndarray:
    import bpy

    path = tmp / f"{name}.png"
    seconds = sphere_scene.render(path)
    return _tile(path, name, what, seconds, bpy.context.scene)


def _grid(rows, out_path: Path, gap: int = GAP_PX) -> None:
    """Tiles ``rows`` (lists of equal-sized pixel arrays, top row first; None: a white cell)
    as a grid with ``gap`` white pixels between cells, written as a PNG through a bpy image."""
    grid = sphere_scene.tile(rows, gap)
    height, width = grid.shape[:2]
    columns = max(len(row) for row in rows)
    sphere_scene.save_png(grid, out_path)
    print(f"render_foundations: {out_path.name:<36} {len(rows)} rows x {columns} columns, "
          f"{width}x{height} px", flush=True)


def spheres(args, skins, tmp: Path) -> list[list[np.ndarray]]:
    """The sphere grid's tiles, one row per skin."""
    from lut_baker import bake
    from lut_baker.model import presets
    from makeup_skin_addon import groups

    sphere = sphere_scene.build_scene(size=args.sphere_size, samples=args.samples,
                                      light_deg=args.light_deg, seed=args.seed)
    rows = []
    with sphere_scene.addon_registered():
        for skin in skins:
            row = []
            for product in PRODUCTS:
                start = time.perf_counter()
                tables = bake.bake(presets.made_up_skin(product, skin, coverage=1.0),
                                   args.resolution)
                print(f"render_foundations: bake {product} on {skin:<14} ({args.resolution} "
                      f"tables): {time.perf_counter() - start:6.2f} s", flush=True)
                sphere.data.materials.clear()
                material = sphere_scene.made_up_material(sphere, tables, "LAYERED",
                                                         coverage=1.0)
                # made_up_material leaves Skin Color at the first preset's albedo; the panel
                # sets the chosen skin's (properties._update_skin), and so does this grid.
                albedo = presets.skin_albedo(skin)
                material.makeup_skin.skin_colour = albedo.tolist()
                groups.group_of(material).inputs["Skin Color"].default_value = (*albedo, 1.0)
                row.append(_shoot(tmp, f"sphere {product} on {skin}", "sphere, Layered"))
            rows.append(row)
    return rows


def characters(args, skins, tmp: Path) -> list[list[np.ndarray | None]]:
    """The character grid's tiles: before Apply, then one row per skin."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    head = character.build_character(seed=args.seed)
    character.portrait_camera_and_lights(scene, head, size=args.character_size,
                                         samples=args.samples, seed=args.seed)
    before = _shoot(tmp, "head before Apply", "the artist's own material")
    rows = []
    with sphere_scene.addon_registered():
        for r, skin in enumerate(skins):
            row = [before if r == 0 else None]
            for product in PRODUCTS:
                settings = SimpleNamespace(skin=skin, resolution=args.resolution)
                apply_foundation(head, product, settings)
                row.append(_shoot(tmp, f"head {product} on {skin}", "after Apply, Layered"))
            rows.append(row)
    return rows


def run(args) -> None:
    from lut_baker.model import presets

    missing = [p for p in PRODUCTS if p not in presets.FOUNDATIONS]
    check(not missing, f"no foundation preset {missing} in lut_baker.model.presets")
    skins = tuple(presets.SKINS)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="render_foundations_") as tmp:
        if not args.skip_spheres:
            _grid(spheres(args, skins, Path(tmp)), out / "spheres.png")
        if not args.skip_character:
            _grid(characters(args, skins, Path(tmp)), out / "character.png")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(REPO_ROOT / "docs" / "renders" / "foundations"),
                        help="output folder (default docs/renders/foundations)")
    parser.add_argument("--sphere-size", type=int, default=144,
                        help="sphere tile, pixels (square), default 144")
    parser.add_argument("--character-size", type=int, default=224,
                        help="character tile, pixels (square), default 224")
    parser.add_argument("--samples", type=int, default=64, help="Cycles samples, default 64")
    parser.add_argument("--light-deg", type=float, default=45.0,
                        help="spheres: angle between light and view direction, default 45")
    parser.add_argument("--resolution", default="default",
                        choices=("preview", "default", "high"),
                        help="tables baked for the spheres and by Apply, default 'default'")
    parser.add_argument("--skip-spheres", action="store_true", help="no spheres.png")
    parser.add_argument("--skip-character", action="store_true", help="no character.png")
    parser.add_argument("--seed", type=int, default=0, help="texture and Cycles seed")
    args = parser.parse_args(argv)
    return run_reporting("render_foundations", run, args)

if __name__ == "__main__":
    sys.exit(main())
