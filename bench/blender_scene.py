"""A Blender scene that matches :func:`lut_baker.offline.validation.reference.sphere_image` pixel for pixel.

Built on ``tools/render_sphere.py``'s :func:`build_scene` (sphere, orthographic camera, sun of
angle 0 and strength ``IRRADIANCE`` = pi W/m^2, black world, Cycles CPU, no denoiser, film
exposure 1, Standard view transform, a seed), then made to match the reference exactly:

- camera ``ortho_scale = 2 R``: the image spans the sphere's disk, so pixel centres are those of
  :func:`lut_baker.offline.validation.reference.sphere_points`; clipping from ``R`` to ``100 R`` in front of it
  (the default clip start, 0.1 m, hides spheres under 10 mm at build_scene's distance of 10 R);
- the UV sphere refined to :data:`SEGMENTS` x :data:`SEGMENTS`/2, smooth (tessellation error
  2.8e-4 relative on a Lambert sphere at 64 px, against 1.0e-3 for build_scene's 128 x 64);
- Gaussian pixel filter of width 0.01 px: point samples at pixel centres (Cycles' box filter
  would average whole pixels, BLENDER_NOTES);
- adaptive sampling off: every pixel takes the samples asked for (Blender's default stops at a
  noise threshold of 0.01, so "1024 samples" rendered faster than 256);
- float32 EXR read back with rows flipped (:func:`lut_baker.offline.validation.compare.from_blender_pixels`).

Units: the scene is in metres (``unit_settings.scale_length = 1``), the sphere's radius is
``radius_mm * 1e-3``; the add-on's "Units per mm" and the baseline's Subsurface Scale come
from :func:`makeup_skin_addon.material.units_per_mm` of the scene (0.001), so a radius of
``R`` mm in the reference is ``R`` mm in the render.

Functions
---------
- :func:`sphere_scene` -- the scene in a fresh file; returns the sphere.
- :func:`set_material` -- give the sphere one material.
- :func:`shader_material` -- a material of one BSDF node with given inputs.
- :func:`lambert_material`, :func:`baseline_material` -- the check's and the baseline's
  (a stock Principled BSDF with :mod:`lut_baker.offline.validation.baseline`'s fitted sockets).
- :func:`tier_material` -- the add-on's node group of a tier (register the add-on around it:
  :func:`render_sphere.addon_registered`).
- :func:`set_samples` -- samples and seed of the engine in use.
- :func:`use_cycles`, :func:`use_eevee` -- switch the render engine (EEVEE: shadows off).
- :func:`render_image` -- render; ``(seconds, (n, n, 3) image, rows top-down)``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _path in (ROOT, ROOT / "tools"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

import render_sphere  # noqa: E402  (tools/render_sphere.py)

from lut_baker.offline.validation import compare  # noqa: E402

__all__ = [
    "IRRADIANCE",
    "SEGMENTS",
    "FILTER_WIDTH_PX",
    "sphere_scene",
    "set_material",
    "shader_material",
    "lambert_material",
    "baseline_material",
    "tier_material",
    "set_samples",
    "use_cycles",
    "use_eevee",
    "eevee_engine_id",
    "render_image",
]

IRRADIANCE = render_sphere.IRRADIANCE
"""Sun strength = irradiance (W/m^2) at normal incidence: pass it to the reference."""
SEGMENTS = 256
"""UV sphere segments (rings: half of it)."""
FILTER_WIDTH_PX = 0.01
"""Gaussian pixel filter width (px): a point sample at the pixel centre."""


def sphere_scene(*, size: int = 64, samples: int = 64, radius_mm: float = 10.0,
                 light_deg: float = 45.0, seed: int = 0, segments: int = SEGMENTS):
    """The reference's scene in a fresh file (module docstring); returns the sphere object.
    ``light_deg``: angle (degrees) between the light and the view direction, towards image
    +x, as :func:`lut_baker.numerics.geometry.light_direction`."""
    import bmesh
    import bpy

    sphere = render_sphere.build_scene(size=size, samples=samples, radius_mm=radius_mm,
                                       light_deg=light_deg, seed=seed)
    radius = radius_mm * 1e-3
    mesh = bmesh.new()
    bmesh.ops.create_uvsphere(mesh, u_segments=segments, v_segments=segments // 2,
                              radius=radius)
    for face in mesh.faces:
        face.smooth = True
    mesh.to_mesh(sphere.data)
    mesh.free()
    scene = bpy.context.scene
    camera = scene.camera.data
    camera.ortho_scale = 2.0 * radius
    camera.clip_start = radius
    camera.clip_end = 100.0 * radius
    scene.cycles.pixel_filter_type = "GAUSSIAN"
    scene.cycles.filter_width = FILTER_WIDTH_PX
    scene.cycles.use_adaptive_sampling = False
    return sphere


def set_material(obj, material) -> None:
    """Make ``material`` the object's only material."""
    obj.data.materials.clear()
    obj.data.materials.append(material)


def shader_material(name: str, node_type: str, inputs: dict, **properties):
    """A material whose output is one shader node of ``node_type`` with socket values
    ``inputs`` (by socket identifier; 3-tuples to colour sockets get alpha 1) and node
    ``properties``."""
    import bpy

    from makeup_skin_addon.nodes import socket

    material = bpy.data.materials.new(name)
    if material.node_tree is None and bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    shader = tree.nodes.new(node_type)
    for key, value in properties.items():
        setattr(shader, key, value)
    for key, value in inputs.items():
        # By identifier: a socket its method leaves unavailable is not found by name in 5.0.
        target = socket(shader.inputs, key)
        if target.type == "RGBA" and len(value) == 3:
            value = (*value, 1.0)
        target.default_value = value
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(shader.outputs[0], output.inputs["Surface"])
    return material


def lambert_material(albedo: float = 0.8):
    """Diffuse BSDF (Lambert: roughness 0) of a grey ``albedo``."""
    return shader_material("Lambert", "ShaderNodeBsdfDiffuse",
                           {"Color": (albedo,) * 3, "Roughness": 0.0})


def baseline_material(baseline, scene):
    """A stock Principled BSDF with the sockets of a :class:`lut_baker.offline.validation.baseline.Baseline`
    (its subsurface method; distribution GGX, which the fit's replica models: the default
    Multiscatter GGX would add ~1% to its specular; Subsurface Scale = the scene's units per
    mm)."""
    from makeup_skin_addon.material import units_per_mm

    inputs = dict(baseline.socket_values(), **{"Subsurface Scale": units_per_mm(scene)})
    return shader_material("Baseline", "ShaderNodeBsdfPrincipled", inputs,
                           subsurface_method=baseline.subsurface_method, distribution="GGX")


def tier_material(obj, tables, tier: str):
    """Give ``obj`` the add-on's material of ``tier`` for ``tables`` (the add-on must be
    registered); returns the material."""
    obj.data.materials.clear()
    return render_sphere.made_up_material(obj, tables, tier)


def eevee_engine_id() -> str:
    """``BLENDER_EEVEE`` from Blender 5.0 on, ``BLENDER_EEVEE_NEXT`` in 4.2-4.5."""
    import bpy

    return "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else "BLENDER_EEVEE_NEXT"


def set_samples(scene, samples: int, seed: int = 0) -> None:
    """Samples (and, in Cycles, the seed) of the scene's engine."""
    if scene.render.engine == "CYCLES":
        scene.cycles.samples = samples
        scene.cycles.seed = seed
    else:
        scene.eevee.taa_render_samples = samples


def use_cycles(scene, samples: int, seed: int = 0) -> None:
    """Cycles CPU with ``samples`` and ``seed`` (the rest as :func:`sphere_scene` set it)."""
    scene.render.engine = "CYCLES"
    set_samples(scene, samples, seed)


def use_eevee(scene, samples: int) -> None:
    """EEVEE with ``samples``, lights' shadows off (a convex sphere shadows nothing; with
    shadows on, software OpenGL takes ~45 s a render, BLENDER_NOTES) and a 0.01 px filter."""
    scene.render.engine = eevee_engine_id()
    set_samples(scene, samples)
    scene.render.filter_size = FILTER_WIDTH_PX
    for light in (obj.data for obj in scene.objects if obj.type == "LIGHT"):
        light.use_shadow = False


def render_image(path=None) -> tuple[float, object]:
    """Render the scene (:func:`render_sphere.render`: PNG and float32 EXR at ``path``, a
    temporary file by default) and read the EXR back: ``(seconds, image (n, n, 3))``."""
    import bpy

    scene = bpy.context.scene
    size = scene.render.resolution_x
    with tempfile.TemporaryDirectory(prefix="blender_scene_") as folder:
        png = Path(path) if path is not None else Path(folder) / "render.png"
        seconds = render_sphere.render(png)
        image = bpy.data.images.load(str(png.with_suffix(".exr")))
        try:
            pixels = compare.from_blender_pixels(image.pixels[:], size)
        finally:
            bpy.data.images.remove(image)
    return seconds, pixels

