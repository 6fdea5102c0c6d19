"""A Principled BSDF's bihemispherical albedo rendered: a large sphere under a uniform white
sky, its mean colour over the disc it covers.

Shared by ``tools/measure_principled_albedo.py`` (which writes the table of
:mod:`lut_baker.closures.principled_albedo`) and its test.

The scene: a smooth UV sphere of radius 1 m (:data:`SEGMENTS` segments), an orthographic
camera framing it exactly (``ortho_scale`` = its diameter), a world of colour 1 and strength 1
and nothing else; transparent film, so that the sky is black in the image and a pixel's
alpha is the share of it the sphere covers; Cycles' box filter (each pixel averages its own
area), no denoiser, no clamping, adaptive sampling off, float32 EXR.  A convex object lit by
a uniform sky sees only the sky, so the radiance it sends towards the camera at a point is
the shader's directional albedo at that view, and the area-weighted mean over the projected
disc, ``sum(RGB) / sum(alpha)`` (partially covered edge pixels hold colour times coverage),
weights each view by its projected area ``2 cos(theta) d cos(theta)``: the bihemispherical
albedo.

The Principled BSDF: Metallic, Transmission, Coat, Sheen, Emission 0; Specular IOR Level 0.5,
Specular Tint white, Diffuse Roughness 0; Subsurface Radius (1, 1, 1) x Scale
:data:`SUBSURFACE_SCALE_M` (3 mm against the 1 m sphere), so that the three channels are
three independent points of the same grid (the random walk's channels share paths but not
their expectations).

Functions
---------
- :func:`build_scene` -- the scene in a fresh file (Cycles or EEVEE); returns the material's
  Principled BSDF node.
- :func:`set_principled` -- set the node's inputs for one render.
- :func:`disc_mean` -- the mean colour over the disc and its standard error, from RGBA pixels.
- :func:`render_albedo` -- render (Blender's log silenced) and measure: ``(mean RGB, standard
  error RGB, seconds)``.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

__all__ = ["SEGMENTS", "SUBSURFACE_SCALE_M", "RADIUS_M", "build_scene", "set_principled",
           "disc_mean", "render_albedo", "engine_id"]

RADIUS_M = 1.0
"""The sphere's radius (m)."""
SEGMENTS = 256
"""UV sphere segments (rings: half of it): the silhouette's area and the smooth normals are
then within ~1e-4 of a sphere's."""
SUBSURFACE_SCALE_M = 0.003
"""Subsurface Radius x Scale (m) of every channel: 3 mm, small against the sphere."""
RING_COUNT = 32
"""Rings of equal width in ``cos(theta)`` over which :func:`disc_mean` estimates the noise."""


def engine_id(engine: str) -> str:
    """Blender's identifier of ``engine`` (``CYCLES`` or ``EEVEE``) in the running version:
    EEVEE is ``BLENDER_EEVEE_NEXT`` in 4.2-4.5 and ``BLENDER_EEVEE`` from 5.0."""
    import bpy

    if engine == "CYCLES":
        return "CYCLES"
    if engine != "EEVEE":
        raise ValueError(f"engine must be CYCLES or EEVEE, got {engine!r}")
    return "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else "BLENDER_EEVEE_NEXT"


def build_scene(*, size: int = 128, samples: int = 64, engine: str = "CYCLES", seed: int = 0):
    """The scene of the module docstring in a fresh file, ``size`` x ``size`` pixels,
    ``samples`` per pixel; returns the Principled BSDF node of the sphere's material."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.unit_settings.system = "METRIC"
    scene.unit_settings.scale_length = 1.0

    bpy.ops.mesh.primitive_uv_sphere_add(segments=SEGMENTS, ring_count=SEGMENTS // 2,
                                         radius=RADIUS_M)
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()

    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 2.0 * RADIUS_M
    camera.data.clip_start = 0.1 * RADIUS_M
    camera.data.clip_end = 100.0 * RADIUS_M
    camera.location = (0.0, -10.0 * RADIUS_M, 0.0)
    camera.rotation_euler = (np.pi / 2, 0.0, 0.0)
    scene.camera = camera

    world = bpy.data.worlds.new("White sky")
    world.color = (1.0, 1.0, 1.0)
    if world.node_tree is None and bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    background = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    background.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    background.inputs["Strength"].default_value = 1.0
    scene.world = world

    material = bpy.data.materials.new("Principled")
    if material.node_tree is None and bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    principled = tree.nodes.new("ShaderNodeBsdfPrincipled")
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(principled.outputs["BSDF"], output.inputs["Surface"])
    sphere.data.materials.append(material)
    principled.inputs["Subsurface Radius"].default_value = (1.0, 1.0, 1.0)
    principled.inputs["Subsurface Scale"].default_value = SUBSURFACE_SCALE_M

    render = scene.render
    render.resolution_x = render.resolution_y = size
    render.resolution_percentage = 100
    render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    render.image_settings.file_format = "OPEN_EXR"
    render.image_settings.color_mode = "RGBA"
    render.image_settings.color_depth = "32"
    render.engine = engine_id(engine)
    if engine == "CYCLES":
        cycles = scene.cycles
        cycles.device = "CPU"
        cycles.samples = samples
        cycles.seed = seed
        cycles.use_denoising = False
        cycles.use_adaptive_sampling = False
        cycles.film_exposure = 1.0
        cycles.pixel_filter_type = "BOX"
        cycles.sample_clamp_direct = 0.0
        cycles.sample_clamp_indirect = 0.0
    else:
        scene.eevee.taa_render_samples = samples
        render.filter_size = 1.0
    return principled


def set_principled(node, base_color, roughness: float, ior: float, *,
                   subsurface_weight: float = 0.0, method: str = "RANDOM_WALK",
                   distribution: str = "MULTI_GGX") -> None:
    """Set the Principled BSDF ``node`` for one render (``base_color`` RGB)."""
    node.distribution = distribution
    node.subsurface_method = method
    node.inputs["Base Color"].default_value = (*[float(c) for c in base_color], 1.0)
    node.inputs["Roughness"].default_value = float(roughness)
    node.inputs["IOR"].default_value = float(ior)
    node.inputs["Subsurface Weight"].default_value = float(subsurface_weight)


def disc_mean(rgba, rings: int = RING_COUNT):
    """``(mean RGB, standard error RGB)`` over the disc of an RGBA image whose alpha is the
    sphere's coverage (module docstring).  The standard error comes from the pixels' scatter
    within rings of equal width in the view cosine (the signal is nearly constant in a ring,
    so the scatter there is the Monte Carlo noise; pixels are sampled independently)."""
    rgba = np.asarray(rgba, np.float64)
    colour, alpha = rgba[..., :3], rgba[..., 3]
    coverage = alpha.sum()
    mean = colour.sum(axis=(0, 1)) / coverage
    size = rgba.shape[0]
    centres = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    r2 = centres[:, None] ** 2 + centres[None, :] ** 2
    inside = (r2 < 1.0) & (alpha > 0.999)
    cos_view = np.sqrt(np.clip(1.0 - r2, 0.0, 1.0))[inside]
    values = colour[inside]
    ring = np.minimum((cos_view * rings).astype(int), rings - 1)
    variance = np.zeros(3)
    for k in range(rings):
        members = values[ring == k]
        if len(members) > 1:
            variance += len(members) * members.var(axis=0, ddof=1)
    return mean, np.sqrt(variance) / coverage


@contextlib.contextmanager
def _quiet():
    """Blender's render log (a line per sample batch and per saved file) sent to /dev/null."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def render_albedo():
    """Render the current scene and measure it: ``(mean RGB, standard error RGB, seconds)``."""
    import bpy

    from support.sphere_scene import image_pixels

    scene = bpy.context.scene
    with tempfile.TemporaryDirectory(prefix="furnace_albedo_") as folder:
        path = Path(folder) / "render.exr"
        scene.render.filepath = str(path)
        start = time.perf_counter()
        with _quiet():
            bpy.ops.render.render(write_still=True)
        seconds = time.perf_counter() - start
        pixels = image_pixels(path)
    mean, error = disc_mean(pixels)
    return mean, error, seconds
