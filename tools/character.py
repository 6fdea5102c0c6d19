"""Render the artist's textured head (tests/support/character.py) to check it (bpy as a module).

Usage::

    python tools/character.py --out /tmp/head.png [--size 256 --samples 32 --seed 0]

Builds the head (subdivided Suzanne with its own Principled material: a packed albedo texture
and a pore normal map) with :func:`support.character.build_character`, lights and frames it
with :func:`support.character.portrait_camera_and_lights`, renders it (Cycles CPU) to the PNG
and a float EXR beside it, and prints one line with the render time.  Run it with the venv's
python (``$(tools/venv.sh)/bin/python``).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
for _path in (REPO_ROOT, REPO_ROOT / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from support.character import build_character, portrait_camera_and_lights  # noqa: E402
from support.sphere_scene import render  # noqa: E402

__all__ = ["main"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True, metavar="PNG", help="output PNG (EXR beside)")
    parser.add_argument("--size", type=int, default=256, help="pixels (square), default 256")
    parser.add_argument("--samples", type=int, default=32, help="Cycles samples, default 32")
    parser.add_argument("--seed", type=int, default=0, help="texture seed, default 0")
    args = parser.parse_args(argv)
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="character_"))
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    head = build_character(seed=args.seed)
    portrait_camera_and_lights(scene, head, size=args.size, samples=args.samples,
                               seed=args.seed)
    seconds = render(args.out)
    print(f"character: {args.size}x{args.size} px, {args.samples} samples: {seconds:.2f} s "
          f"-> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
