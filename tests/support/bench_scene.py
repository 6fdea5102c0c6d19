"""A Blender scene that matches :func:`lut_baker.offline.validation.reference.sphere_image` pixel
for pixel, and a :class:`Stage` of it built once and changed between renders.

Built on :func:`support.sphere_scene.build_scene` (sphere, orthographic camera, sun of
angle 0 and strength ``IRRADIANCE`` = pi W/m^2, black world, Cycles CPU, no denoiser, film
exposure 1, Standard view transform, a seed), then made to match the reference exactly:

- camera ``ortho_scale = 2 R``: the image spans the sphere's disk, so pixel centres are those of
  :func:`lut_baker.offline.validation.reference.sphere_points`; clipping from ``R`` to ``100 R``
  in front of it (the default clip start, 0.1 m, hides spheres under 10 mm at build_scene's
  distance of 10 R);
- the UV sphere refined to :data:`SEGMENTS` x :data:`SEGMENTS`/2, smooth (tessellation error
  2.8e-4 relative on a Lambert sphere at 64 px, against 1.0e-3 for build_scene's 128 x 64);
- Gaussian pixel filter of width 0.01 px: point samples at pixel centres (Cycles' box filter
  would average whole pixels, BLENDER_NOTES);
- adaptive sampling off: every pixel takes the samples asked for (Blender's default stops at a
  noise threshold of 0.01, so "1024 samples" rendered faster than 256);
- float32 EXR read back with rows flipped
  (:func:`lut_baker.offline.validation.compare.from_blender_pixels`).

Units: the scene is in metres (``unit_settings.scale_length = 1``), the sphere's radius is
``radius_mm * 1e-3``; the add-on's "Units per mm" and the baseline's Subsurface Scale come
from :func:`makeup_skin_addon.tier_choice.units_per_mm` of the scene (0.001), so a radius of
``R`` mm in the reference is ``R`` mm in the render.

Functions
---------
- :func:`sphere_scene` -- the scene in a fresh file; returns the sphere.
- :func:`set_material` -- give the sphere one material.
- :func:`shader_material` -- a material of one BSDF node with given inputs.
- :func:`lambert_material`, :func:`baseline_material` -- the check's and the baseline's
  (a stock Principled BSDF with :mod:`lut_baker.offline.validation.baseline`'s fitted sockets).
- :func:`tier_material` -- the add-on's node group of a tier (register the add-on around it:
  :func:`support.sphere_scene.addon_registered`).
- :func:`set_samples` -- samples and seed of the engine in use.
- :func:`use_cycles`, :func:`use_eevee` -- switch the render engine (EEVEE: shadows off).
- :func:`render_image` -- render; ``(seconds, (n, n, 3) image, rows top-down)``.
- :class:`Stage` -- one scene built once, changed between renders (radius, light, seed,
  white furnace: no light, world colour 1); used by bench/stability_sweep.py and the
  add-on's render tests.
- :func:`candidate_material` -- the made-up material of an Auto-tier candidate.
- :func:`furnace_rings` -- a furnace image averaged over rings of the view angle.
- :func:`exact_image` -- the exact model's image of this scene (the reference, spread on).
"""

from __future__ import annotations

import importlib
import math
import tempfile
from pathlib import Path

import numpy as np

from lut_baker.offline.validation import compare, reference
from support import sphere_scene as base_scene

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
    "Stage",
    "candidate_material",
    "furnace_rings",
    "FURNACE_RINGS",
]

IRRADIANCE = base_scene.IRRADIANCE
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
    import bpy

    bmesh = importlib.import_module("bmesh")  # Blender's own: importable once bpy is

    sphere = base_scene.build_scene(size=size, samples=samples, radius_mm=radius_mm,
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
    """A stock Principled BSDF with the sockets of a
    :class:`lut_baker.offline.validation.baseline.Baseline` (its subsurface method; distribution
    GGX, which the fit's replica models: the default Multiscatter GGX would add ~1% to its specular;
    Subsurface Scale = the scene's units per mm)."""
    try:
        from makeup_skin_addon.tier_choice import units_per_mm
    except ImportError:  # a checkout before Apply was split by job (bench --repo)
        from makeup_skin_addon.material import units_per_mm

    inputs = dict(baseline.socket_values(), **{"Subsurface Scale": units_per_mm(scene)})
    return shader_material("Baseline", "ShaderNodeBsdfPrincipled", inputs,
                           subsurface_method=baseline.subsurface_method, distribution="GGX")


def tier_material(obj, tables, tier: str):
    """Give ``obj`` the add-on's material of ``tier`` for ``tables`` (the add-on must be
    registered); returns the material."""
    obj.data.materials.clear()
    return base_scene.made_up_material(obj, tables, tier)


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
    """Render the scene (:func:`support.sphere_scene.render`: PNG and float32 EXR at ``path``, a
    temporary file by default) and read the EXR back: ``(seconds, image (n, n, 3))``."""
    import bpy

    scene = bpy.context.scene
    size = scene.render.resolution_x
    with tempfile.TemporaryDirectory(prefix="bench_scene_") as folder:
        png = Path(path) if path is not None else Path(folder) / "render.png"
        seconds = base_scene.render(png)
        image = bpy.data.images.load(str(png.with_suffix(".exr")))
        try:
            pixels = compare.from_blender_pixels(image.pixels[:], size)
        finally:
            bpy.data.images.remove(image)
    return seconds, pixels


class Stage:
    """One :func:`sphere_scene` built once (it takes 10-15 s on this machine: the 256-segment
    sphere) and changed between renders: sphere radius (the mesh rescaled, camera reframed as
    sphere_scene frames it), light angle, seed, samples, white furnace."""

    def __init__(self, *, size=32, samples=128, radius_mm=10.0):
        import bpy

        self.sphere = sphere_scene(size=size, samples=samples, radius_mm=radius_mm)
        self.scene = bpy.context.scene
        self.radius_mm = radius_mm
        self.sun = self.scene.objects["Sun"]
        self.background = next((n for n in (self.scene.world.node_tree.nodes
                                             if self.scene.world.node_tree else ())
                                if n.type == "BACKGROUND"), None)

    def frame(self, radius_mm: float) -> None:
        """Rescale the sphere to ``radius_mm`` and reframe the camera (ortho 2R at -10R)."""
        from mathutils import Matrix

        if radius_mm != self.radius_mm:
            self.sphere.data.transform(Matrix.Scale(radius_mm / self.radius_mm, 4))
            self.sphere.data.update()
            self.radius_mm = radius_mm
        radius = radius_mm * 1e-3
        camera = self.scene.camera
        camera.location = (0.0, -10.0 * radius, 0.0)
        camera.data.ortho_scale = 2.0 * radius
        camera.data.clip_start = radius
        camera.data.clip_end = 100.0 * radius

    def light(self, light_deg: float) -> None:
        """The sun ``light_deg`` from the view towards +x (as :mod:`support.sphere_scene`)."""
        self.sun.rotation_euler = (math.pi / 2, 0.0, math.radians(light_deg))

    def furnace(self, on: bool) -> None:
        """White furnace (no light, world colour 1) or the sun in a black world."""
        self.sun.hide_render = on
        value = 1.0 if on else 0.0
        self.scene.world.color = (value,) * 3
        if self.background is not None:
            self.background.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
            self.background.inputs["Strength"].default_value = value

    def render(self, tables, candidate, *, seed=0, samples=None):
        """Render ``candidate`` (:func:`candidate_material`): ``(seconds, image)``."""
        set_samples(self.scene, samples or self.scene.cycles.samples, seed)
        candidate_material(self.sphere, tables, candidate)
        return render_image()


def candidate_material(sphere, tables, candidate):
    """The made-up material of a :class:`lut_baker.auto_tier.Candidate` on ``sphere`` (the
    add-on registered), as Fit to Scene realises it: its tier; ``subsurface=False`` sets
    Subsurface Scale 0 (Cycles then shades the subsurface closures as diffuse ones);
    ``gloss=False`` sets the group's Gloss input to 0 (Cycles then allocates no gloss
    closure)."""
    material = tier_material(sphere, tables, candidate.tier)
    node = material.node_tree.nodes["Made-up Skin"]
    if not candidate.subsurface:
        material.makeup_skin.subsurface_scale = 0.0
        node.inputs["Subsurface Scale"].default_value = 0.0
    if not candidate.gloss:
        material.makeup_skin.gloss = 0.0
        node.inputs["Gloss"].default_value = 0.0
    return material


FURNACE_RINGS = 8
"""Rings of equal width in ``cos(theta_o)`` over which :func:`furnace_rings` averages."""

def furnace_rings(image, rings: int = FURNACE_RINGS):
    """``(cos_view centres, ring means (rings, 3), ring standard errors (rings, 3))`` of a
    white-furnace image over rings of the view cosine (pixel centres of the sphere)."""
    size = image.shape[0]
    centres = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x, y = np.meshgrid(centres, -centres)
    r2 = x * x + y * y
    mask = r2 < 1.0
    cos_view = np.sqrt(np.clip(1.0 - r2, 0.0, None))[mask]
    values = np.asarray(image, float)[mask]
    ring = np.minimum((cos_view * rings).astype(int), rings - 1)
    means = np.stack([values[ring == k].mean(axis=0) for k in range(rings)])
    errors = np.stack([values[ring == k].std(axis=0) / np.sqrt(max((ring == k).sum(), 1))
                       for k in range(rings)])
    return (np.arange(rings) + 0.5) / rings, means, errors


def exact_image(skin, tables, *, size: int, light_deg: float, radius_mm: float,
                spread_per_mean_free_path: float):
    """The exact model's image of this scene (:func:`lut_baker.offline.validation.compare.
    reference_image` from ``tables``, the skin's spread on), its spread drawn with
    ``spread_per_mean_free_path`` entry samples per mean free path."""
    samples = reference.default_samples(skin, radius_mm, spread_per_mean_free_path)
    return compare.reference_image(skin, tables=tables, resolution=size, radius_mm=radius_mm,
                                   light_angle_deg=light_deg, irradiance=IRRADIANCE,
                                   samples=samples)
