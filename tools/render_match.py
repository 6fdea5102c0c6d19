"""Match Skin on the textured head: the pictures and the figures of docs/addon.md ("Match Skin",
"A first Apply") and the README.

Usage::

    "$(tools/venv.sh)/bin/python" tools/render_match.py [--out docs/renders/match]
        [--size 200 --samples 64] [--measure-size 96 --measure-samples 128]
        [--tones medium darker lighter] [--no-pictures] [--json FILE]
        [--film SLAB|PAPER] [--tier AUTO|PRINCIPLED|LAYERED|...]

One process, Cycles CPU, view transform Standard, no denoiser.  For each skin tone of
tests/support/character.py (``SKIN_TONES``: the head's own, a darker and a lighter skin) it
builds the textured head with its portrait camera and lights and:

- renders ``<tone>_before.png``: the artist's own material (Principled BSDF, albedo texture,
  pore normal map);
- presses Apply with every setting at its default: the first Apply matches the shade to the
  skin (Match Skin: the mean of the albedo texture over the head's faces; it takes the matte
  film when the skin is darker than the default film's own gloss), Film Normal a weaker copy of
  the skin's normal map; then renders ``<tone>_<coverage>_pores.png`` at coverage 0.3, 0.6
  and 1, and ``<tone>_<coverage>_smooth.png`` with Film Follows Pores off (Film Normal
  unlinked: the film fills the pores);
- composes ``match_strip.png`` (one row per tone and film normal: before, 0.3, 0.6, 1) and
  ``first_apply_strip.png`` (each tone before and after the first Apply);
- measures, under uniform white light (a white world, lamps off: the light the match is
  defined for) and under the portrait lights, the head's mean colour
  (:func:`support.artist_skins.face_mean`) at coverage 0 (the artist's own render: the film
  goes over their shader) and of the made-up skin at each coverage, and the blotches'
  contrast: the standard deviation of the luminance of the render divided by the render of
  the same head with its albedo at the mean (the artist's Base Color and the skin under the
  film; same seed, so the noise mostly divides out), at coverage 0, 0.3, 0.6 and 1.

Prints a Markdown table of the figures and writes them to ``--json`` (default
``<out>/match.json``).  Exits non-zero with a message if a step fails.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import traceback
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parent.parent
for _path in (REPO_ROOT, REPO_ROOT / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from support import artist_skins, character, sphere_scene  # noqa: E402  (tests/support/)

__all__ = ["main", "measure_means", "blotch_contrast", "uniform_light", "head_arguments",
           "head_scene", "measure_tones", "COVERAGES"]

COVERAGES = (0.3, 0.6, 1.0)
GROUP_NODE = "Made-up Skin"
GAP_PX = 4
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def _render_rgba(scene, path: Path) -> np.ndarray:
    """Render to a float EXR (film transparent) and return RGBA, rows bottom-up."""
    import bpy

    scene.render.film_transparent = True
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return sphere_scene.image_pixels(path)


def _mask(rgba: np.ndarray) -> np.ndarray:
    return rgba[..., 3] > 0.999


def uniform_light(scene, on: bool) -> None:
    """White world of strength 1 with the lamps hidden (``on``), or the portrait lights back."""
    world = scene.world.node_tree.nodes["Background"]
    world.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0) if on else (0.05, 0.05, 0.05,
                                                                             1.0)
    for obj in scene.objects:
        if obj.type == "LIGHT":
            obj.hide_render = on


def measure_means(scene, settings, work: Path, tag: str) -> dict:
    """The head's mean colour (:func:`support.artist_skins.face_mean`) at coverage 0 (the
    artist's own render: the film goes over their shader) and at :data:`COVERAGES`:
    ``{coverage: [r, g, b]}``."""
    means = {}
    for coverage in (0.0,) + COVERAGES:
        settings.coverage = coverage
        rgba = _render_rgba(scene, work / f"{tag}_{coverage}.exr")
        means[coverage] = artist_skins.face_mean(rgba).tolist()
    return means


def blotch_contrast(scene, material, settings, work: Path, tag: str,
                    coverages: tuple[float, ...] = (0.0,) + COVERAGES) -> dict:
    """``{coverage: contrast}``: the standard deviation over the head's pixels of the
    luminance of the render divided by the render with the albedo at its mean (the artist's
    Base Color and the group's Skin Color, the skin under the film, both set to their means),
    at each of ``coverages``."""
    from makeup_skin_addon import artist_skin

    tree = material.node_tree
    reading = artist_skin.read_material(material, scene)
    sockets = [(tree.nodes[GROUP_NODE].inputs["Skin Color"], reading.body),
               (reading.dominant.node.inputs["Base Color"], reading.leaves[0].base)]
    sources = [socket.links[0].from_socket for socket, _ in sockets]
    contrast = {}
    for coverage in coverages:
        settings.coverage = coverage
        textured = _render_rgba(scene, work / f"{tag}_tex_{coverage}.exr")
        for socket, mean in sockets:
            tree.links.remove(socket.links[0])
            socket.default_value = (*mean, 1.0)
        flat = _render_rgba(scene, work / f"{tag}_flat_{coverage}.exr")
        for (socket, _), source in zip(sockets, sources, strict=True):
            tree.links.new(source, socket)
        mask = _mask(textured) & _mask(flat)
        ratio = (textured[mask][:, :3] @ LUMINANCE) / np.maximum(flat[mask][:, :3] @ LUMINANCE,
                                                                 1e-6)
        contrast[coverage] = float(np.std(ratio))
    return contrast


def _save_png(path: Path, scene) -> float:
    seconds = sphere_scene.render(path)
    path.with_suffix(".exr").unlink(missing_ok=True)
    return seconds


def _strip(rows, out_path: Path) -> None:
    """The PNGs ``rows`` (lists of paths, top row first) as one picture, white gaps between."""
    sphere_scene.save_png(sphere_scene.tile(
        [[sphere_scene.image_pixels(p) for p in row] for row in rows], GAP_PX), out_path)


def head_scene(tone: str, args):
    """``(scene, material)``: a fresh file holding the textured head of ``tone`` with its
    portrait camera and lights, rendering ``args.size`` px at ``args.samples``."""
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    obj = character.build_character("Head", tone=tone)
    character.portrait_camera_and_lights(scene, obj, size=args.size, samples=args.samples)
    return scene, obj.active_material


def run_tone(tone: str, args, out: Path, work: Path) -> dict:
    """Build the head of one tone, render and measure it (see the module docstring)."""
    import bpy

    scene, material = head_scene(tone, args)
    pictures = {}
    if args.pictures:
        pictures["before"] = out / f"{tone}_before.png"
        _save_png(pictures["before"], scene)
    settings = material.makeup_skin
    settings.live_update = False
    settings.film_mode = args.film
    settings.tier = args.tier
    start = time.perf_counter()
    result = bpy.ops.makeup_skin.apply()
    apply_s = time.perf_counter() - start
    if result != {"FINISHED"}:
        raise RuntimeError(f"Apply on the {tone} head returned {result}")
    figures = {"tone": tone, "apply_s": apply_s, "foundation": settings.foundation,
               "absorption": list(settings.absorption), "shade_colour": list(
                   settings.shade_colour), "note": settings.shade_note,
               "tier": settings.tier}
    print(f"render_match: {tone}: first Apply {apply_s:.2f} s, foundation "
          f"{settings.foundation}, absorption {np.round(settings.absorption, 3).tolist()}"
          f"{' (' + settings.shade_note + ')' if settings.shade_note else ''}", flush=True)
    if args.pictures:
        for follows, label in ((True, "pores"), (False, "smooth")):
            settings.film_follows_pores = follows
            for coverage in COVERAGES:
                settings.coverage = coverage
                pictures[(coverage, label)] = out / f"{tone}_{coverage:g}_{label}.png"
                seconds = _save_png(pictures[(coverage, label)], scene)
                print(f"render_match: {pictures[(coverage, label)].name}: {seconds:.1f} s",
                      flush=True)
        settings.film_follows_pores = True
    scene.render.resolution_x = scene.render.resolution_y = args.measure_size
    scene.cycles.samples = args.measure_samples
    for lighting in ("uniform", "portrait"):
        uniform_light(scene, lighting == "uniform")
        figures[f"means_{lighting}"] = measure_means(scene, settings, work, f"{tone}_{lighting}")
        figures[f"blotch_{lighting}"] = blotch_contrast(scene, material, settings, work,
                                                        f"{tone}_{lighting}")
    uniform_light(scene, False)
    figures["pictures"] = {(k if isinstance(k, str) else f"{k[0]:g}_{k[1]}"): str(v)
                           for k, v in pictures.items()}
    return figures


def _table(results) -> str:
    lines = ["| skin | foundation | light | before Apply (coverage 0) | coverage 0.3 | 0.6 | 1 | "
             "blotch contrast 0 / 0.3 / 0.6 / 1 |",
             "|---|---|---|---|---|---|---|---|"]
    for figures in results:
        for lighting in ("uniform", "portrait"):
            means = figures[f"means_{lighting}"]
            bare = np.array(means[0.0] if 0.0 in means else means["0.0"])

            def cell(coverage, bare=bare, means=means):
                value = np.array(means[coverage] if coverage in means else means[str(coverage)])
                moved = 100.0 * (value / bare - 1.0)
                return (", ".join(f"{v:.3f}" for v in value) + " ("
                        + " / ".join(f"{m:+.1f}%" for m in moved) + ")")

            blotch = figures[f"blotch_{lighting}"]
            contrast = " / ".join(f"{blotch[c]:.4f}" for c in blotch)
            lines.append(f"| {figures['tone']} | {figures['foundation']} | {lighting} | "
                         + ", ".join(f"{v:.3f}" for v in bare) + " | "
                         + " | ".join(cell(c) for c in COVERAGES) + f" | {contrast} |")
    return "\n".join(lines)


def first_apply_row(out: Path, tones) -> list[Path]:
    """Each tone before Apply and after the first Apply (every setting at its default:
    coverage 0.6, the film following the pores), side by side: the README's picture."""
    return [out / f"{tone}_{kind}.png" for tone in tones for kind in ("before", "0.6_pores")]


def head_arguments(doc: str, out: str, size: int, samples: int, measure_size: int,
                   measure_samples: int) -> argparse.ArgumentParser:
    """The options every script rendering the textured head's skin tones takes, with its
    defaults: ``--out`` (``docs/renders/<out>``), the pictures' and the measurements' size and
    samples, ``--tones``, ``--json``."""
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=REPO_ROOT / "docs" / "renders" / out)
    parser.add_argument("--size", type=int, default=size)
    parser.add_argument("--samples", type=int, default=samples)
    parser.add_argument("--measure-size", type=int, default=measure_size)
    parser.add_argument("--measure-samples", type=int, default=measure_samples)
    parser.add_argument("--tones", nargs="+", default=list(character.SKIN_TONES),
                        choices=list(character.SKIN_TONES))
    parser.add_argument("--json", type=Path)
    return parser


def measure_tones(run_tone, args) -> list[dict]:
    """``run_tone(tone, args, out, work)`` for each of ``args.tones`` (``args.out`` made),
    the add-on registered and a temporary folder ``work`` for the measurements' renders."""
    import tempfile

    import bpy  # noqa: F401  (Blender as a module)

    args.out.mkdir(parents=True, exist_ok=True)
    with sphere_scene.addon_registered(), tempfile.TemporaryDirectory() as work:
        return [run_tone(tone, args, args.out, Path(work)) for tone in args.tones]


def main(argv=None) -> int:
    parser = head_arguments(__doc__, "match", 200, 64, 96, 128)
    parser.add_argument("--no-pictures", dest="pictures", action="store_false")
    parser.add_argument("--film", default="SLAB",
                        help="the Film setting (SLAB, the default: at a thickness; PAPER)")
    parser.add_argument("--tier", default="AUTO", help="the Tier setting")
    args = parser.parse_args(argv)
    try:
        results = measure_tones(run_tone, args)
        if args.pictures:
            rows = []
            for figures in results:
                pictures = figures["pictures"]
                for label in ("pores", "smooth"):
                    rows.append([Path(pictures["before"])] + [Path(pictures[f"{c:g}_{label}"])
                                                              for c in COVERAGES])
            _strip(rows, args.out / "match_strip.png")
            _strip([first_apply_row(args.out, args.tones)], args.out / "first_apply_strip.png")
    except Exception:  # noqa: BLE001  (a tool: say what failed and exit non-zero)
        traceback.print_exc()
        return 1
    table = _table(results)
    print(table)
    path = args.json or args.out / "match.json"
    path.write_text(json.dumps(results, indent=1, default=str) + "\n")
    print(f"render_match: figures -> {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
