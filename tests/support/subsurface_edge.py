"""Cycles' subsurface blur of a shadow edge, against the replicas in lut_baker.closures.cycles
(Burley's profile at d = radius / (4 pi); random walks as a Burley profile of radius
k(albedo) x radius, k measured by tools/calibrate_subsurface.py).

Scene: a thick slab (20 radii deep) with a Subsurface Scattering material of colour A and
radius R = 10 mm, lit from straight above by a sun (angle 0, irradiance pi) whose light a black
plane, invisible to the camera, stops over x < 0; an orthographic camera looks down on a strip
8 radii long across the edge (256 x 8 px, rows averaged).  The rendered profile, divided by its
lit plateau, is the edge response :func:`lut_baker.closures.profiles.edge_response` of the
method's radial profile.

Functions: :func:`edge_scene`, :func:`render_edge` (rendered response), :func:`replica_edge`.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from support.sphere_scene import black_world, cycles_settings

__all__ = ["RADIUS_M", "WIDTH", "HEIGHT", "edge_scene", "render_edge", "replica_edge"]

RADIUS_M = 0.01
"""Subsurface Radius x Scale of the test material, metres (10 mm)."""
WIDTH, HEIGHT = 256, 8


def _material(name: str, kind: str):
    import bpy

    material = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    shader = tree.nodes.new(kind)
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(shader.outputs[0], output.inputs[0])
    return material, shader


def edge_scene(method: str, albedo: float, samples: int) -> None:
    """The slab, occluder, sun and camera of the module docstring, in a fresh file."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    r = RADIUS_M
    bpy.ops.mesh.primitive_cube_add(size=1)
    slab = bpy.context.active_object
    slab.scale = (40 * r, 40 * r, 20 * r)
    slab.location = (0.0, 0.0, -10 * r)
    material, sss = _material("Subsurface", "ShaderNodeSubsurfaceScattering")
    sss.falloff = method
    sss.inputs["Color"].default_value = (albedo, albedo, albedo, 1.0)
    sss.inputs["Radius"].default_value = (1.0, 1.0, 1.0)
    sss.inputs["Scale"].default_value = r
    slab.data.materials.append(material)
    bpy.ops.mesh.primitive_plane_add(size=1)
    occluder = bpy.context.active_object
    occluder.scale = (40 * r, 80 * r, 1.0)
    occluder.location = (-20 * r, 0.0, 2 * r)
    black, diffuse = _material("Black", "ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    occluder.data.materials.append(black)
    occluder.visible_camera = False
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 8 * r
    camera.location = (0.0, 0.0, 10 * r)
    scene.camera = camera
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.data.energy = math.pi
    sun.data.angle = 0.0
    black_world(scene)
    cycles_settings(scene, size=WIDTH, height=HEIGHT, samples=samples)
    scene.cycles.max_bounces = 1
    scene.cycles.diffuse_bounces = 0
    scene.render.filter_size = 0.01


def render_edge(method: str, albedo: float, samples: int = 256, folder=None):
    """``(x_mm, response)``: the rendered edge response (lit plateau = 1) across the edge at
    x = 0 (lit for x > 0), from a render of :func:`edge_scene`."""
    import bpy

    edge_scene(method, albedo, samples)
    folder = Path(folder or tempfile.mkdtemp(prefix="edge_"))
    scene = bpy.context.scene
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = str(folder / f"edge_{method}.exr")
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath)
    pixels = np.array(image.pixels[:], dtype=float).reshape(HEIGHT, WIDTH, 4)[..., 0].mean(0)
    bpy.data.images.remove(image)
    x_mm = ((np.arange(WIDTH) + 0.5) / WIDTH - 0.5) * 8 * RADIUS_M * 1e3
    plateau = pixels[x_mm > 3 * RADIUS_M * 1e3].mean()
    return x_mm, pixels / plateau


def replica_edge(x_mm, method: str, albedo: float, scale: float = 1.0) -> np.ndarray:
    """The replica's edge response at ``x_mm`` (lit for x > 0), radius x ``scale``."""
    from lut_baker.closures import cycles, profiles

    radius_mm = RADIUS_M * 1e3 * scale
    if method != "BURLEY":
        radius_mm *= float(cycles.random_walk_scale(albedo, method))
    r = np.concatenate([[0.0], np.geomspace(1e-4, 40.0 * radius_mm, 3000)])
    profile = cycles.burley_profile(r, radius_mm)
    tail = profiles.edge_response(r, profile, np.abs(x_mm))
    return np.where(x_mm < 0, tail, 1.0 - tail)
