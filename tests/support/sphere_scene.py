"""The reference sphere scene with the Made-up Skin node group (Cycles, CPU, bpy as a module).

Scene: a smooth UV sphere (scene in metres), an orthographic camera looking at it, one sun
(angle 0, irradiance ``pi`` W/m^2, so a white Lambertian surface facing it is 1.0)
``light_deg`` degrees from the view direction towards +x, black world, no denoiser, film
exposure 1.  ``tools/render_sphere.py`` renders it from the command line.

Functions (for the tests, the benchmarks and the scripts):

- :func:`add_sphere` -- a smooth sphere with that camera, sun and render settings in a scene.
- :func:`build_scene` -- the sphere, camera, sun and render settings in a fresh file, from
  :func:`light_and_camera`, :func:`black_world` and :func:`cycles_settings` (also used alone
  by the tests and :mod:`support.subsurface_edge`).
- :func:`addon_registered` -- the add-on from this checkout, registered for a ``with`` block.
- :func:`made_up_material` -- a material with the group for given tables and tier.
- :func:`coverage_ramp` -- coverage painted as a left-to-right ramp.
- :func:`render` -- render to PNG and EXR; returns seconds.
- :func:`render_pixels` -- render to a float EXR and return its pixels; :func:`image_pixels`
  an image file's pixels.
- :func:`tile` -- pictures as a grid with white gaps; :func:`save_png` -- pixels as a PNG.
"""

from __future__ import annotations

import contextlib
import math
import time
from pathlib import Path

__all__ = ["build_scene", "light_and_camera", "black_world", "cycles_settings",
           "addon_registered", "made_up_material", "coverage_ramp", "render", "render_pixels",
           "image_pixels", "add_sphere", "tile", "save_png", "IRRADIANCE"]

IRRADIANCE = math.pi
"""Sun strength (W/m^2): a white Lambertian surface facing the sun renders as 1.0."""


def light_and_camera(scene, radius: float, light_deg: float = 45.0) -> None:
    """An orthographic camera on -y looking at a sphere of ``radius`` (scene units) at the
    origin, framing it with 10% margin, and a sun (angle 0, irradiance :data:`IRRADIANCE`)
    from the camera's side, turned ``light_deg`` degrees towards +x about the vertical."""
    import bpy

    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 2.2 * radius
    camera.location = (0.0, -10.0 * radius, 0.0)
    camera.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.camera = camera
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.data.energy = IRRADIANCE
    sun.data.angle = 0.0
    sun.rotation_euler = (math.pi / 2, 0.0, math.radians(light_deg))  # shines along its -Z


def black_world(scene) -> None:
    """A black world (5.0 gives new worlds a Background node, 4.5 uses the world colour)."""
    import bpy

    world = bpy.data.worlds.new("Black")
    world.color = (0.0, 0.0, 0.0)
    for node in (world.node_tree.nodes if world.node_tree is not None else ()):
        if node.type == "BACKGROUND":
            node.inputs["Strength"].default_value = 0.0
    scene.world = world


def cycles_settings(scene, *, size: int, samples: int, seed: int = 0,
                    height: int | None = None) -> None:
    """Cycles on the CPU, no denoiser, film exposure 1, view transform Standard."""
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.seed = seed
    scene.cycles.use_denoising = False
    scene.cycles.film_exposure = 1.0
    scene.render.resolution_x = size
    scene.render.resolution_y = size if height is None else height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"


def build_scene(*, size=128, samples=64, radius_mm=30.0, light_deg=45.0, seed=0):
    """Sphere, camera, sun and Cycles settings in a fresh file; returns the sphere object."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.unit_settings.system = "METRIC"
    scene.unit_settings.scale_length = 1.0
    return add_sphere(scene, radius_mm * 1e-3, light_deg=light_deg, size=size, samples=samples,
                      seed=seed, segments=128)


def add_sphere(scene, radius: float, *, light_deg=45.0, size=64, samples=16, seed=0,
               segments=48):
    """A smooth UV sphere of ``radius`` (scene units) at the origin of ``scene``, with
    :func:`light_and_camera`, :func:`black_world` and :func:`cycles_settings`; returns it."""
    import bpy

    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=segments // 2,
                                         radius=radius)
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    light_and_camera(scene, radius, light_deg)
    black_world(scene)
    cycles_settings(scene, size=size, samples=samples, seed=seed)
    return sphere


@contextlib.contextmanager
def addon_registered():
    """The add-on from this checkout registered for the duration (bpy 4.5 hangs at exit while
    an add-on's classes stay registered, so always leave through here)."""
    import bpy

    import makeup_skin_addon

    if hasattr(bpy.types.Material, "makeup_skin"):
        yield
        return
    makeup_skin_addon.register()
    try:
        yield
    finally:
        makeup_skin_addon.unregister()


def made_up_material(obj, tables, tier="LAYERED", *, coverage=None, absorption=None):
    """Give ``obj`` a material with the Made-up Skin group for ``tables`` (the add-on must be
    registered: :func:`addon_registered`).  Coverage and absorption default to the tables';
    tables baked with a film thickness give the slab's tiers at it (Film: at a thickness)."""
    import bpy

    from makeup_skin_addon import groups, keys

    material = bpy.data.materials.new(keys.MATERIAL_NAME)
    obj.data.materials.append(material)
    settings = material.makeup_skin
    settings.is_made_up = True
    settings.live_update = False
    settings.tier = tier
    thickness = tables.parameters.get("film_thickness_um")
    if thickness is not None:  # the film as a slab: the panel says so, as Apply's would
        settings.film_mode = "SLAB"
        settings.thickness_um = thickness
    settings.coverage = tables.parameters.get("coverage", 1.0) if coverage is None else coverage
    absorption = tables.parameters.get("absorption", 0.0) if absorption is None else absorption
    settings.absorption = [absorption] * 3 if isinstance(absorption, float) else absorption
    group, _ = groups.group_for_tables(tables, tier, errors_at=(settings.coverage,
                                                                 list(settings.absorption)))
    groups.setup_material(material, group, bpy.context.scene)
    return material


def coverage_ramp(material, obj) -> None:
    """Link a left-to-right ramp (coverage 0 at the sphere's left edge, 1 at its right) into
    the group's Coverage socket: what a painted coverage texture does."""
    from makeup_skin_addon import groups

    tree = material.node_tree
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    separate = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(coordinates.outputs["Object"], separate.inputs[0])
    ramp = tree.nodes.new("ShaderNodeMapRange")
    ramp.clamp = True
    tree.links.new(separate.outputs["X"], ramp.inputs["Value"])
    radius = max(obj.dimensions) / 2
    ramp.inputs["From Min"].default_value = -radius
    ramp.inputs["From Max"].default_value = radius
    tree.links.new(ramp.outputs["Result"], groups.group_of(material).inputs["Coverage"])


def render(png_path) -> float:
    """Render the current scene; write ``png_path`` and the float EXR beside it; seconds."""
    import bpy

    scene = bpy.context.scene
    png_path = Path(png_path)
    png_path.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    bpy.ops.render.render()
    seconds = time.perf_counter() - start
    result = bpy.data.images["Render Result"]
    settings = scene.render.image_settings
    settings.file_format = "PNG"
    settings.color_mode = "RGBA"
    settings.color_depth = "8"
    result.save_render(str(png_path), scene=scene)
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    result.save_render(str(png_path.with_suffix(".exr")), scene=scene)
    return seconds


def image_pixels(path):
    """The pixels of the image file ``path``, ``(height, width, 4)`` float32, row 0 at the
    bottom (Blender's order)."""
    import bpy
    import numpy as np

    image = bpy.data.images.load(str(path), check_existing=False)
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)


def render_pixels(exr_path):
    """Render the current scene to the float32 OpenEXR ``exr_path`` and return its RGB pixels,
    ``(height, width, 3)`` with row 0 at the bottom (Blender's order)."""
    import bpy

    scene = bpy.context.scene
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = str(exr_path)
    bpy.ops.render.render(write_still=True)
    return image_pixels(scene.render.filepath)[..., :3]


def tile(rows, gap: int = 4):
    """``rows`` of pixel arrays ``(height, width, >=3)`` (top row first; ``None``: a white
    cell; cells of a row side by side, as wide as they are) as one RGBA array with ``gap``
    white pixels between cells and rows, rows bottom-up (Blender's order).  Every cell is as
    high as the first."""
    import numpy as np

    first = next(t for row in rows for t in row if t is not None)
    cell_height = first.shape[0]
    if any(t is not None and t.shape[0] != cell_height for row in rows for t in row):
        raise ValueError("the cells differ in height")
    cell_width = first.shape[1]

    def width_of(t):
        return cell_width if t is None else t.shape[1]

    width = max(sum(width_of(t) for t in row) + gap * (len(row) - 1) for row in rows)
    height = len(rows) * cell_height + gap * (len(rows) - 1)
    out = np.ones((height, width, 4), np.float32)
    for r, row in enumerate(rows):
        y = height - (r + 1) * cell_height - r * gap
        x = 0
        for cell in row:
            if cell is not None:
                out[y:y + cell_height, x:x + cell.shape[1], :3] = cell[..., :3]
            x += width_of(cell) + gap
    return out


def save_png(rgba, out_path) -> None:
    """Write ``rgba`` ``(height, width, 4)`` (rows bottom-up, as Blender's) as a PNG through a
    temporary bpy image, which is removed again."""
    import bpy
    import numpy as np

    height, width = rgba.shape[:2]
    image = bpy.data.images.new(Path(out_path).stem, width, height, alpha=True,
                                float_buffer=False)
    try:
        image.pixels.foreach_set(np.ascontiguousarray(rgba, np.float32).ravel())
        image.filepath_raw = str(out_path)
        image.file_format = "PNG"
        image.save()
    finally:
        bpy.data.images.remove(image)
    if not Path(out_path).is_file():
        raise OSError(f"{out_path} was not written")
