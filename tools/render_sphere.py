"""Render a reference sphere with the Made-up Skin node group (Cycles, CPU, bpy as a module).

Usage::

    python tools/render_sphere.py --tables out/ --out out/sphere.png [--tier LAYERED]
    python tools/render_sphere.py --foundation medium_beige --skin jensen_skin1 --out x.png

``--tables`` takes a folder (its one ``*.exr`` + ``*.json`` pair written by ``python -m
lut_baker bake``) or the ``.exr`` itself; without it the tables are baked from
``--foundation``/``--skin``.  Writes the PNG (view transform Standard) and a float32 OpenEXR
beside it (same stem), then prints one line with the render time.  Run it with the venv's
python (``$(tools/venv.sh)/bin/python``).

Scene (tests/support/sphere_scene.py, shared with the tests and the benchmarks): a smooth UV
sphere of ``--radius-mm`` millimetres (scene in metres), an orthographic camera looking at it,
one sun (angle 0, irradiance ``pi`` W/m^2, so a white Lambertian surface facing it is 1.0)
``--light-deg`` degrees from the view direction towards +x, black world, no denoiser, film
exposure 1.
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

from support.sphere_scene import (  # noqa: E402  (tests/support/sphere_scene.py)
    addon_registered,
    build_scene,
    coverage_ramp,
    made_up_material,
    render,
)

__all__ = ["load_or_bake", "main"]


def load_or_bake(tables_path=None, foundation="paper_natural", skin="paper_bioplate",
                 resolution="default"):
    """Tables from a file or folder written by ``python -m lut_baker bake``, else baked."""
    from lut_baker import bake
    from lut_baker.model import presets
    from lut_baker.offline import exr_files
    from lut_baker.tables import codec

    if tables_path is not None:
        path = Path(tables_path)
        if path.is_dir():  # the tables are the .exr files with a .json sidecar
            found = sorted(p.with_suffix(".exr") for p in path.glob("*.json")
                           if p.with_suffix(".exr").is_file())
            if len(found) != 1:
                raise SystemExit(f"render_sphere: expected one baked table (.exr + .json) in "
                                 f"{path}, found {len(found)}; pass the .exr itself")
            path = found[0]
        try:
            return exr_files.load_tables(path)
        except codec.TableFileError as error:
            raise SystemExit(f"render_sphere: {error}") from None
    return bake.bake(presets.made_up_skin(foundation, skin), resolution)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tables", metavar="PATH",
                        help="tables folder or .exr from 'python -m lut_baker bake'")
    parser.add_argument("--foundation", default="paper_natural",
                        help="foundation preset when baking here (default paper_natural)")
    parser.add_argument("--skin", default="paper_bioplate",
                        help="skin preset when baking here (default paper_bioplate)")
    parser.add_argument("--out", required=True, metavar="PNG", help="output PNG (EXR beside)")
    parser.add_argument("--tier", default="LAYERED", choices=("PRINCIPLED", "LAYERED"))
    parser.add_argument("--coverage", type=float, help="0..1 (default: the tables')")
    parser.add_argument("--absorption", type=float, nargs=3, metavar=("R", "G", "B"),
                        help="per-channel absorption 0..1 (default: the tables')")
    parser.add_argument("--size", type=int, default=128, help="pixels (square), default 128")
    parser.add_argument("--samples", type=int, default=64, help="Cycles samples, default 64")
    parser.add_argument("--radius-mm", type=float, default=30.0,
                        help="sphere radius in millimetres, default 30")
    parser.add_argument("--light-deg", type=float, default=45.0,
                        help="angle between light and view direction, degrees, default 45")
    parser.add_argument("--seed", type=int, default=0, help="Cycles seed")
    parser.add_argument("--coverage-ramp", action="store_true",
                        help="coverage from 0 (left) to 1 (right), as a painted texture would")
    args = parser.parse_args(argv)
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="render_sphere_"))
    tables = load_or_bake(args.tables, args.foundation, args.skin)
    sphere = build_scene(size=args.size, samples=args.samples, radius_mm=args.radius_mm,
                         light_deg=args.light_deg, seed=args.seed)
    with addon_registered():
        material = made_up_material(sphere, tables, args.tier, coverage=args.coverage,
                                    absorption=args.absorption)
        if args.coverage_ramp:
            coverage_ramp(material, sphere)
        seconds = render(args.out)
    print(f"render_sphere: {args.tier} {args.size}x{args.size} px, {args.samples} samples, "
          f"light {args.light_deg:g} deg: {seconds:.2f} s -> {args.out} + "
          f"{Path(args.out).with_suffix('.exr').name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
