"""Render the textured head in Cycles and in EEVEE, made up by Tier Auto, and the Layered tier in
EEVEE as it was (one Linear lookup per view-angle row) and as it is now.

Usage::

    "$(tools/venv.sh)/bin/python" tools/render_eevee.py [--out docs/renders/eevee]
        [--size 128 --samples 64 --eevee-samples 16 --foundation medium_beige
         --skin jensen_skin2]

The head of tests/support/character.py with its portrait camera and lights (an area key light
45 degrees to the side and 35 above, a fill, a dim world) and a sphere sharing its material
beside it; Apply with Tier Auto (default tables, coverage 1).  The lights cast no shadows, in
both engines (the pictures compare shading, not shadows), and the pictures are 128 px: on
software OpenGL here a 128 px EEVEE frame takes ~30 s, a 256 px one did not finish in 10
minutes with or without shadows.  Writes to ``--out``:

- ``cycles_auto.png`` -- Cycles: Auto gives the Layered tier;
- ``eevee_auto.png`` -- EEVEE (16 samples: its images move by 0.2% from 16 to 64): Auto
  gives the EEVEE tier;
- ``eevee_layered_linear_lookup.png`` -- EEVEE, the Layered tier reading its view-angle rows
  by one Linear lookup, as before: EEVEE samples that image through mipmaps, which mix its
  rows where cos(theta_o) changes fast across the screen (the pores' normal map): bright,
  hard-edged patches;
- ``eevee_layered.png`` -- EEVEE, the Layered tier as now (two Closest texels mixed);
- ``eevee_strip.png`` -- the four side by side.
Prints each render's time and the mean skin brightness of each picture against Cycles'.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parent.parent
for _path in (REPO_ROOT, REPO_ROOT / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from support import character, sphere_scene  # noqa: E402  (tests/support/)

from lut_baker.closures import tier_formulas  # noqa: E402

GROUP_NODE = "Made-up Skin"
GAP_PX = 4


def linear_lookups(group) -> None:
    """Make ``group`` read every view-angle row by one Linear lookup at ``u = cos(theta_o)``
    (the Layered tier's lookup before the two-texel one), in place."""
    for mix in [n for n in group.nodes if n.type == "MIX" and n.label.startswith("row ")]:
        row = mix.label[len("row "):]
        texture = next(n for n in group.nodes if n.type == "TEX_IMAGE" and n.label == row)
        coordinate = texture.inputs["Vector"].links[0].from_node
        cos_label = f"cos theta_o ({tier_formulas.ROW_SURFACE.get(row, 'film')})"
        cos = next(n for n in group.nodes if n.label == cos_label).outputs[0]
        lookup_at = group.nodes.new("ShaderNodeCombineXYZ")
        group.links.new(cos, lookup_at.inputs["X"])
        lookup_at.inputs["Y"].default_value = coordinate.inputs["Y"].default_value
        lookup = group.nodes.new("ShaderNodeTexImage")
        lookup.image, lookup.interpolation, lookup.extension = texture.image, "Linear", "EXTEND"
        group.links.new(lookup_at.outputs[0], lookup.inputs["Vector"])
        output = next(s for s in mix.outputs if s.enabled and s.is_linked)
        for link in list(output.links):
            group.links.new(lookup.outputs["Color"], link.to_socket)


def use_engine(scene, engine: str, samples: int) -> None:
    import bpy

    if engine == "CYCLES":
        scene.render.engine = "CYCLES"
        scene.cycles.samples = samples
        return
    scene.render.engine = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else \
        "BLENDER_EEVEE_NEXT"
    scene.eevee.taa_render_samples = samples


def apply(obj, args) -> None:
    import bpy

    settings = obj.active_material.makeup_skin
    settings.live_update = False
    settings.foundation, settings.skin = args.foundation, args.skin
    settings.tier, settings.resolution, settings.coverage = args.tier, "default", 1.0
    bpy.context.view_layer.objects.active = obj
    result = bpy.ops.makeup_skin.apply()
    if result != {"FINISHED"}:
        raise SystemExit(f"render_eevee: Apply returned {result}")


def render(out: Path, name: str, scene) -> np.ndarray:
    path = out / f"{name}.png"
    seconds = sphere_scene.render(path)
    pixels = sphere_scene.image_pixels(path.with_suffix(".exr"))
    path.with_suffix(".exr").unlink(missing_ok=True)
    print(f"render_eevee: {name + '.png':<36} {scene.render.engine:<18} {seconds:7.1f} s",
          flush=True)
    return pixels


def strip(panels, path: Path) -> None:
    sphere_scene.save_png(sphere_scene.tile([[np.clip(p, 0.0, 1.0) for p in panels]], GAP_PX),
                          path)
    print(f"render_eevee: {path.name:<36} {len(panels)} panels", flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=REPO_ROOT / "docs" / "renders" / "eevee")
    parser.add_argument("--size", type=int, default=128,
                        help="pixels (square); EEVEE frames of 128 px take ~30 s here, 256 px "
                        "ones did not finish in 10 minutes on software OpenGL")
    parser.add_argument("--samples", type=int, default=64, help="Cycles samples")
    parser.add_argument("--eevee-samples", type=int, default=16,
                        help="EEVEE samples (its images move by 0.2%% from 16 to 64)")
    parser.add_argument("--foundation", default="medium_beige")
    parser.add_argument("--skin", default="jensen_skin2")
    parser.add_argument("--tier", default="AUTO", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="render_eevee_"))
    import bpy

    import makeup_skin_addon

    args.out.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    head = character.build_character("Head")
    character.portrait_camera_and_lights(scene, head, size=args.size, samples=args.samples)
    for light in bpy.data.lights:  # both engines alike: see the module docstring
        light.use_shadow = False
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=0.045,
                                         location=(0.15, 0.05, -0.06))
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    ball.data.materials.append(head.active_material)
    start = time.perf_counter()
    makeup_skin_addon.register()
    try:
        panels = []
        apply(head, args)
        use_engine(scene, "CYCLES", args.samples)
        panels.append(render(args.out, "cycles_auto", scene))
        use_engine(scene, "EEVEE", args.eevee_samples)
        apply(head, args)  # Auto in EEVEE: the EEVEE tier
        panels.append(render(args.out, "eevee_auto", scene))
        args.tier = "LAYERED"
        apply(head, args)
        group = head.active_material.node_tree.nodes[GROUP_NODE].node_tree
        linear = group.copy()
        linear_lookups(linear)
        head.active_material.node_tree.nodes[GROUP_NODE].node_tree = linear
        panels.append(render(args.out, "eevee_layered_linear_lookup", scene))
        head.active_material.node_tree.nodes[GROUP_NODE].node_tree = group
        panels.append(render(args.out, "eevee_layered", scene))
        strip(panels, args.out / "eevee_strip.png")
        skin = panels[0][..., :3].mean(axis=-1) > 0.02
        for name, panel in zip(("Cycles, Auto (Layered)", "EEVEE, Auto (EEVEE tier)",
                                "EEVEE, Layered, Linear lookup", "EEVEE, Layered"), panels,
                               strict=True):
            ratio = panel[..., :3][skin].mean() / panels[0][..., :3][skin].mean()
            print(f"render_eevee: {name:<32} mean brightness {ratio:.3f} of Cycles'")
    finally:
        makeup_skin_addon.unregister()
    print(f"render_eevee: done in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
