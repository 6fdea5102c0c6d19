"""Render the textured head (tests/support/character.py) as an artist sees it, before and after
Apply.

Usage::

    "$(tools/venv.sh)/bin/python" tools/render_character.py [--out docs/renders/character]
        [--size 320 --samples 64 --skin jensen_skin2 --resolution default]

One process, Cycles CPU, view transform Standard, no denoiser.  Writes PNGs to ``--out`` (the
float EXR beside each only with ``--keep-exr``):

- ``before.png`` -- the artist's own material (Principled BSDF, albedo texture, pore normal
  map), portrait camera and lights of :func:`character.portrait_camera_and_lights`;
- ``light_ivory.png``, ``medium_beige.png``, ``deep_mocha.png`` -- after Apply (tier Layered,
  ``--resolution`` tables) with each foundation, the same material re-applied; the script
  checks that the albedo texture still feeds the group's Skin Color and the normal map its
  Normal after every Apply;
- ``painted_coverage.png`` -- light ivory (``--coverage-foundation``) with the painted coverage
  image (:func:`character.add_coverage_mask`: a bare band and a bare spot, moved on the UVs
  onto the visible face) in the group's Coverage;
- ``film_normal_unlinked.png``, ``film_normal_soft.png``, ``film_normal_full.png`` -- a
  close-up of the forehead under a grazing key light, medium beige: Film Normal unlinked (Film
  Follows Pores off: a smooth film over pore-detailed skin), fed by a second Normal Map node on
  the pore image at strength 0.2 (a softer film bump), and fed by the skin's own normal map
  (the film follows the pores);
- ``character_strip.png`` -- before, the three foundations and the painted coverage side by
  side (composed from the PNGs with numpy, written through a bpy image).

Prints one line per render with its time and exits non-zero with a message if anything fails
(an Apply that is not FINISHED, a texture link that did not carry over, a failed render).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
import traceback
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
for _path in (REPO_ROOT, REPO_ROOT / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from support import character, sphere_scene  # noqa: E402  (tests/support/)

__all__ = ["main", "WorkflowError", "check", "apply_foundation", "run_reporting"]

FOUNDATIONS = ("light_ivory", "medium_beige", "deep_mocha")
COVERAGE_OFFSET = (0.0, 0.35)
"""UV offset of the painted coverage image (see :func:`_paint_coverage`)."""
FILM_FOUNDATION = "medium_beige"
SOFT_FILM_STRENGTH = 0.2
GROUP_NODE = "Made-up Skin"
GAP_PX = 4


class WorkflowError(RuntimeError):
    """The artist's workflow did not do what it should (the script stops with this)."""


def check(condition: bool, message: str) -> None:
    if not condition:
        raise WorkflowError(message)


def _render(out: Path, name: str, what: str, scene, keep_exr: bool = False) -> Path:
    path = out / f"{name}.png"
    seconds = sphere_scene.render(path)
    check(path.is_file(), f"the render of {name} wrote no {path}")
    if not keep_exr:
        path.with_suffix(".exr").unlink(missing_ok=True)
    print(f"render_character: {name + '.png':<26} {scene.render.resolution_x}x"
          f"{scene.render.resolution_y} px, {scene.cycles.samples} samples: {seconds:6.2f} s"
          f"  ({what})", flush=True)
    return path


def _source(socket):
    """The node and output socket feeding ``socket`` (None if unlinked)."""
    return socket.links[0].from_socket if socket.is_linked else None


def apply_foundation(obj, foundation: str, args):
    """Set the panel's settings and press Apply; check the textures are still linked."""
    import bpy

    material = obj.active_material
    settings = material.makeup_skin
    settings.live_update = False
    settings.foundation = foundation
    settings.skin = args.skin
    settings.tier = "LAYERED"
    settings.resolution = args.resolution
    settings.coverage = 1.0
    bpy.context.view_layer.objects.active = obj
    start = time.perf_counter()
    result = bpy.ops.makeup_skin.apply()
    seconds = time.perf_counter() - start
    check(result == {"FINISHED"}, f"Apply with {foundation} returned {result}")
    check(obj.active_material == material,
           f"Apply replaced the material {material.name!r} instead of converting it in place")
    node = material.node_tree.nodes.get(GROUP_NODE)
    check(node is not None and node.type == "GROUP",
           f"after Apply, {material.name!r} has no {GROUP_NODE!r} group node")
    output = material.node_tree.get_output_node("ALL")
    check(output.inputs["Surface"].is_linked
           and output.inputs["Surface"].links[0].from_node == node,
           "after Apply, the group is not the material's surface")
    albedo = material.node_tree.nodes["Albedo"].outputs["Color"]
    normal_map = material.node_tree.nodes["Normal Map"]
    check(_source(node.inputs["Skin Color"]) == albedo,
           f"after Apply with {foundation}, the albedo texture is not linked to Skin Color")
    check(_source(node.inputs["Normal"]) == normal_map.outputs["Normal"],
           f"after Apply with {foundation}, the pore normal map is not linked to Normal")
    print(f"render_character: Apply {foundation:<13} ({args.resolution} tables, Layered): "
          f"{seconds:6.2f} s", flush=True)
    return material, node


def _strip(paths, out_path: Path, gap: int = GAP_PX) -> None:
    """The PNGs ``paths`` side by side, ``gap`` white pixels between them, as a PNG."""
    strip = sphere_scene.tile([[sphere_scene.image_pixels(p) for p in paths]], gap)
    height, width = strip.shape[:2]
    sphere_scene.save_png(strip, out_path)
    print(f"render_character: {out_path.name:<26} {len(paths)} panels, {width}x{height} px",
          flush=True)


def _surface_point(scene, obj, x: float, z: float):
    """Where a ray along +Y at (x, z) first meets ``obj`` (as rendered: subdivided), and the
    mean of the face normals around it (a smooth normal for aiming)."""
    import bpy
    from mathutils import Vector

    depsgraph = bpy.context.evaluated_depsgraph_get()
    forward = Vector((0.0, 1.0, 0.0))

    def cast(px, pz):
        hit, location, normal, _, hit_obj, _ = scene.ray_cast(depsgraph, Vector((px, -1.0, pz)),
                                                              forward)
        return (location, normal) if hit and hit_obj.name == obj.name else (None, None)

    point, _ = cast(x, z)
    check(point is not None, f"no surface of {obj.name!r} at x={x}, z={z} for the close-up")
    normals = [n for dx in (-0.004, 0.0, 0.004) for dz in (-0.004, 0.0, 0.004)
               for _, n in [cast(x + dx, z + dz)] if n is not None]
    return point, sum(normals, Vector()).normalized()


def _close_up(scene, obj, *, spot=(0.0, 0.05), width_m=0.035, lens_mm=100.0,
              view_deg=40.0, light_deg=80.0, energy_w=2.5):
    """A close-up of the forehead (``spot``: x and z of the point, seen from the front): a
    camera ``view_deg`` from the surface normal to one side, ``lens_mm`` lens framing
    ``width_m`` metres; the portrait lights off; one small area light ``energy_w`` watts,
    ``light_deg`` from the normal on the other side (grazing, slightly raised), so the film's
    broad gloss lobe reaches the camera and every bump of the film casts a visible shade."""
    import bpy
    from mathutils import Vector

    point, normal = _surface_point(scene, obj, *spot)
    up = Vector((0, 0, 1))
    side = up.cross(normal).normalized()  # along the surface, horizontal

    def direction(deg, towards):
        """A unit vector ``deg`` degrees from the normal towards ``towards``."""
        a = math.radians(deg)
        return (normal * math.cos(a) + towards * math.sin(a)).normalized()

    camera = bpy.data.objects.new("Close-up Camera", bpy.data.cameras.new("Close-up Camera"))
    scene.collection.objects.link(camera)
    camera.data.lens = lens_mm
    camera.data.sensor_width = 36.0
    camera.data.clip_start = 0.005
    distance = width_m / 2 * lens_mm / (camera.data.sensor_width / 2)
    camera.location = point + distance * direction(view_deg, -side)
    camera.rotation_euler = (point - camera.location).to_track_quat("-Z", "Y").to_euler()
    scene.camera = camera

    for light in (o for o in scene.objects if o.type == "LIGHT"):
        light.hide_render = True
    key = bpy.data.objects.new("Grazing Key", bpy.data.lights.new("Grazing Key", "AREA"))
    scene.collection.objects.link(key)
    key.data.size = 0.02
    key.data.energy = energy_w
    key.location = point + 0.5 * (direction(light_deg, side) + 0.15 * up).normalized()
    key.rotation_euler = (point - key.location).to_track_quat("-Z", "Y").to_euler()
    return camera, key


def _paint_coverage(material, node, seed: int) -> None:
    """Link the painted coverage image (:func:`character.add_coverage_mask`) into the group's
    Coverage, on the UVs moved by :data:`COVERAGE_OFFSET` (a Mapping node): Suzanne's UV
    layout puts the mask's bare band and spot mostly inside the ears and eye sockets; moved,
    the band crosses the muzzle and the brow, where the portrait camera sees them."""
    tree = material.node_tree
    mask = tree.nodes.new("ShaderNodeTexImage")
    mask.name = mask.label = "Coverage Mask"
    mask.image = character.add_coverage_mask(material, seed=seed)
    mask.location = (node.location.x - 400, node.location.y + 300)
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.name = mapping.label = "Coverage Mapping"
    mapping.inputs["Location"].default_value = (*COVERAGE_OFFSET, 0.0)
    mapping.location = (mask.location.x - 250, mask.location.y)
    uv = next(n for n in tree.nodes if n.type == "UVMAP")
    tree.links.new(uv.outputs["UV"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], mask.inputs["Vector"])
    tree.links.new(mask.outputs["Color"], node.inputs["Coverage"])
    check(_source(node.inputs["Coverage"]) == mask.outputs["Color"],
           "the coverage mask is not linked to the group's Coverage")


def _film_normal_renders(shoot, material, node) -> list[Path]:
    """Film Normal unlinked, fed by a soft second Normal Map on the pore image, and by the
    skin's own normal map; ``shoot(name, what)`` renders; returns the three PNGs."""
    tree = material.node_tree
    for link in list(node.inputs["Coverage"].links):
        tree.links.remove(link)
    node.inputs["Coverage"].default_value = 1.0
    skin_normal = _source(node.inputs["Normal"])
    check(skin_normal is not None, "the group's Normal lost its link before the close-up")
    check(node.inputs["Film Normal"].is_linked,
           "Film Normal is not linked after Apply (the film should follow the pores, softened)")
    material.makeup_skin.film_follows_pores = False  # a smooth film: the pores filled
    check(not node.inputs["Film Normal"].is_linked,
           "Film Normal is still linked with Film Follows Pores off")
    pores = tree.nodes["Pores Normal"]
    soft = tree.nodes.new("ShaderNodeNormalMap")
    soft.name = soft.label = "Film Normal (soft)"
    soft.space = "TANGENT"
    soft.inputs["Strength"].default_value = SOFT_FILM_STRENGTH
    soft.location = (node.location.x - 300, node.location.y - 500)
    tree.links.new(pores.outputs["Color"], soft.inputs["Color"])

    paths = [shoot("film_normal_unlinked", "Film Normal unlinked: smooth film")]
    tree.links.new(soft.outputs["Normal"], node.inputs["Film Normal"])
    check(_source(node.inputs["Film Normal"]) == soft.outputs["Normal"],
           "the soft Normal Map is not linked to Film Normal")
    paths.append(shoot("film_normal_soft",
                       f"Film Normal from a Normal Map at strength {SOFT_FILM_STRENGTH:g}"))
    tree.links.new(skin_normal, node.inputs["Film Normal"])
    check(_source(node.inputs["Film Normal"]) == skin_normal,
           "the pore normal map is not linked to Film Normal")
    paths.append(shoot("film_normal_full", "Film Normal = the skin's normal map"))
    return paths


def run(args) -> None:
    import bpy

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    head = character.build_character(seed=args.seed)
    character.portrait_camera_and_lights(scene, head, size=args.size, samples=args.samples,
                                         seed=args.seed)

    def shoot(name, what):
        return _render(out, name, what, scene, args.keep_exr)

    strip = [shoot("before", "the artist's own material")]
    with sphere_scene.addon_registered():
        for foundation in FOUNDATIONS:
            apply_foundation(head, foundation, args)
            strip.append(shoot(foundation, f"after Apply, {foundation}"))

        material, node = apply_foundation(head, args.coverage_foundation, args)
        _paint_coverage(material, node, args.seed)
        strip.append(shoot("painted_coverage", f"{args.coverage_foundation}, painted coverage"))

        material, node = apply_foundation(head, FILM_FOUNDATION, args)
        _close_up(scene, head)
        film = _film_normal_renders(shoot, material, node)

    _strip(strip, out / "character_strip.png")
    check(len(film) == 3, "the Film Normal close-ups are incomplete")


def main(argv=None) -> int:
    from lut_baker.model import presets

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(REPO_ROOT / "docs" / "renders" / "character"),
                        help="output folder (default docs/renders/character)")
    parser.add_argument("--size", type=int, default=320, help="pixels (square), default 320")
    parser.add_argument("--samples", type=int, default=64, help="Cycles samples, default 64")
    parser.add_argument("--skin", default="jensen_skin2", choices=tuple(presets.SKINS),
                        help="skin preset (subsurface radius and gloss; the albedo is the "
                             "texture's), default jensen_skin2")
    parser.add_argument("--resolution", default="default", choices=("preview", "default", "high"),
                        help="tables Apply bakes, default 'default'")
    parser.add_argument("--coverage-foundation", default="light_ivory", choices=FOUNDATIONS,
                        help="foundation of painted_coverage.png, default light_ivory")
    parser.add_argument("--keep-exr", action="store_true",
                        help="keep the float EXR written beside each PNG (default: removed)")
    parser.add_argument("--seed", type=int, default=0, help="texture and Cycles seed")
    args = parser.parse_args(argv)
    return run_reporting("render_character", run, args)


def run_reporting(name: str, run, args) -> int:
    """``run(args)`` in a temporary Blender user folder; one line with the total time, or a
    clear failure (exit 1) whatever went wrong."""
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix=f"{name}_"))
    start = time.perf_counter()
    try:
        run(args)
    except WorkflowError as error:
        print(f"{name}: FAILED: {error}", file=sys.stderr)
        return 1
    except Exception:  # noqa: BLE001 -- any failure must end the run with a clear message
        traceback.print_exc()
        print(f"{name}: FAILED (see the traceback above)", file=sys.stderr)
        return 1
    print(f"{name}: done in {time.perf_counter() - start:.1f} s -> {args.out}")
    return 0

if __name__ == "__main__":
    sys.exit(main())
