"""An artist's textured character for scenes and benchmarks (bpy as a module).

Builds, in the current scene, what a skin artist typically starts from before applying Made-up
Skin: a head (Suzanne, subdivided, smooth, about 0.2 m across) with its own material, a
Principled BSDF fed by a painted albedo texture and a tangent-space pore normal map, both
packed into the .blend.  Everything is generated with numpy from a seed (nothing is
downloaded), so two runs build byte-identical images.

Functions (all take or return ``bpy`` data; ``bpy`` is imported inside them):

- :func:`build_character` -- the head object with its skin material; returns the object.
- :func:`skin_albedo_image` / :func:`pore_normal_image` -- the two packed textures (found by
  name and reused when already present).
- :func:`add_coverage_mask` -- a packed, soft-edged foundation coverage image to link to the
  made-up group's ``Coverage`` input; returns the image.
- :func:`portrait_camera_and_lights` -- perspective camera from the front-left, key and fill
  lights, a dim grey world, Cycles CPU settings (:func:`support.sphere_scene.cycles_settings`).

The pure numpy generators (:func:`albedo_pixels`, :func:`pore_normal_pixels`,
:func:`coverage_pixels`) return ``(height, width, 4)`` float32 arrays, rows bottom-up as
Blender stores pixels, and need no bpy.

Check it renders::

    python tools/character.py --out /tmp/head.png [--size 256 --samples 32 --seed 0]

Importing this module changes nothing on ``sys.path`` (bench/character_files.py imports the
add-on from another checkout first and then this module).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from support.sphere_scene import cycles_settings

__all__ = ["build_character", "skin_albedo_image", "pore_normal_image", "add_coverage_mask",
           "portrait_camera_and_lights", "albedo_pixels", "pore_normal_pixels",
           "coverage_pixels", "SKIN_SRGB", "SKIN_TONES"]

SKIN_SRGB = (0.85, 0.64, 0.53)
"""Mean skin tone of the albedo texture, sRGB-encoded (a light-medium warm skin)."""
SKIN_TONES = {
    "medium": SKIN_SRGB,
    "darker": (0.58, 0.40, 0.30),
    "lighter": (0.92, 0.75, 0.66),
}
"""Skin tones of the albedo texture by name (sRGB-encoded): the head's own, a darker (brown)
and a lighter (fair) skin, for the pictures and figures of Match Skin."""

ALBEDO_SIZE = 512
NORMAL_SIZE = 1024
COVERAGE_SIZE = 256


# -- numpy generators (no bpy) -----------------------------------------------------------------

def _smooth_noise(rng, size: int, sigma_px: float) -> np.ndarray:
    """White noise low-passed by a Gaussian of ``sigma_px`` pixels (periodic, via FFT),
    normalised to zero mean and unit standard deviation."""
    white = rng.standard_normal((size, size))
    frequencies = np.fft.fftfreq(size)
    f2 = frequencies[:, None] ** 2 + frequencies[None, :] ** 2
    field = np.fft.ifft2(np.fft.fft2(white) * np.exp(-2.0 * (math.pi * sigma_px) ** 2 * f2)).real
    return (field - field.mean()) / (field.std() + 1e-12)


def _splat(size: int, rows, cols, weights, sigma_px: float) -> np.ndarray:
    """Impulses of ``weights`` at (rows, cols), blurred by a periodic Gaussian of ``sigma_px``
    (each impulse becomes a spot of peak about weight / (2 pi sigma^2))."""
    impulses = np.zeros((size, size))
    np.add.at(impulses, (rows % size, cols % size), weights)
    frequencies = np.fft.fftfreq(size)
    f2 = frequencies[:, None] ** 2 + frequencies[None, :] ** 2
    return np.fft.ifft2(np.fft.fft2(impulses) * np.exp(-2.0 * (math.pi * sigma_px) ** 2 * f2)).real


def _rgba(rgb: np.ndarray) -> np.ndarray:
    out = np.ones(rgb.shape[:2] + (4,), np.float32)
    out[..., :3] = np.clip(rgb, 0.0, 1.0)
    return out


def albedo_pixels(seed: int = 0, size: int = ALBEDO_SIZE, tone=SKIN_SRGB) -> np.ndarray:
    """A skin albedo texture, sRGB-encoded: ``tone`` (default :data:`SKIN_SRGB`) with blotchy
    variation at two scales, patches of redness, and freckles (small brown spots of varied size
    and depth)."""
    rng = np.random.default_rng([seed, 1])
    scale = size / 512.0
    tone = np.array(tone, float)
    blotch = 0.6 * _smooth_noise(rng, size, 24 * scale) + 0.4 * _smooth_noise(rng, size, 6 * scale)
    rgb = tone * (1.0 + 0.045 * blotch[..., None])
    # Redness: a warm, slightly darker flush where a low-frequency field is high.
    red = np.clip(_smooth_noise(rng, size, 40 * scale) - 0.3, 0.0, None)
    red = (red / (red.max() + 1e-12))[..., None]
    rgb = rgb * (1.0 - 0.16 * red * np.array([0.0, 1.0, 0.8]))
    # Freckles: about 900 spots, clustered where a freckle-density field is high.
    count = int(900 * scale * scale)
    density = np.exp(1.2 * _smooth_noise(rng, size, 30 * scale))
    probability = (density / density.sum()).ravel()
    where = rng.choice(size * size, size=count, p=probability)
    rows, cols = np.divmod(where, size)
    freckles = np.zeros((size, size))
    for sigma in (0.8, 1.3, 2.0):
        pick = rng.random(count) < 1 / 3
        depth = rng.uniform(0.3, 1.0, pick.sum()) * 2 * math.pi * (sigma * scale) ** 2
        freckles += _splat(size, rows[pick], cols[pick], depth, sigma * scale)
    freckles = np.clip(freckles, 0.0, 1.0)[..., None]
    freckle_colour = tone * np.array([0.72, 0.55, 0.45])  # brown: more red kept than blue
    rgb = rgb * (1.0 - 0.55 * freckles) + freckle_colour * 0.55 * freckles
    return _rgba(rgb)


def pore_height(seed: int = 0, size: int = NORMAL_SIZE) -> np.ndarray:
    """A skin height field (about -1..0.3): many small pore dimples from a random point field
    (Poisson, denser and deeper where a slow field says so), on a faint bumpy ground."""
    rng = np.random.default_rng([seed, 2])
    scale = size / 1024.0
    count = int(24000 * scale * scale)
    rows = rng.integers(0, size, count)
    cols = rng.integers(0, size, count)
    depth = rng.uniform(0.5, 1.0, count) * (1.0 + 0.5 * np.tanh(
        _smooth_noise(rng, size, 50 * scale)[rows, cols]))
    sigma = 1.1 * scale
    pores = _splat(size, rows, cols, depth * 2 * math.pi * sigma * sigma, sigma)
    ground = 0.25 * _smooth_noise(rng, size, 3 * scale) + 0.15 * _smooth_noise(rng, size,
                                                                               12 * scale)
    return ground - np.clip(pores, 0.0, 1.5)


def pore_normal_pixels(seed: int = 0, size: int = NORMAL_SIZE, strength: float = 1.0) -> np.ndarray:
    """A tangent-space normal map (Non-Color, +X along U, +Y along V, OpenGL convention) from
    the derivative of :func:`pore_height` (central differences, periodic), encoded ``n/2 + 1/2``.
    ``strength`` scales the height's slope (1: a pore of depth 1 is as deep as about 1.5 px)."""
    height = pore_height(seed, size)
    # Rows are bottom-up (row index grows with V), columns grow with U.
    d_u = (np.roll(height, -1, axis=1) - np.roll(height, 1, axis=1)) / 2.0
    d_v = (np.roll(height, -1, axis=0) - np.roll(height, 1, axis=0)) / 2.0
    normal = np.stack([-strength * d_u, -strength * d_v, np.ones_like(height)], axis=-1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    return _rgba(normal * 0.5 + 0.5)


def coverage_pixels(seed: int = 0, size: int = COVERAGE_SIZE) -> np.ndarray:
    """A painted foundation coverage (0..1, grey in RGB): full cover with brush-stroke
    unevenness (0.85-1), except a soft-edged bare band across V (about 0.42-0.58: a bare
    stripe, as if wiped off) and a soft-edged bare spot near (U, V) = (0.3, 0.7)."""
    rng = np.random.default_rng([seed, 3])
    v = (np.arange(size) + 0.5) / size
    u = v.copy()
    uu, vv = np.meshgrid(u, v)  # rows are V (bottom-up), columns U

    def smoothstep(edge0, edge1, x):
        t = np.clip((x - edge0) / (edge1 - edge0), 0.0, 1.0)
        return t * t * (3 - 2 * t)

    wobble = 0.03 * _smooth_noise(rng, size, 16)
    band = 1.0 - smoothstep(0.05, 0.11, np.abs(vv - 0.5 + wobble))  # 1 on the band's centre
    spot = 1.0 - smoothstep(0.06, 0.14, np.hypot(uu - 0.3, vv - 0.7))
    strokes = 0.925 + 0.075 * np.tanh(_smooth_noise(rng, size, 4))
    cover = strokes * (1.0 - band) * (1.0 - spot)
    return _rgba(np.repeat(cover[..., None], 3, axis=-1))


# -- bpy ----------------------------------------------------------------------------------------

_PNG_BYTES: dict = {}
"""The PNG files :func:`_packed_image` packed, by ``(name, colorspace, source)``: a fresh file
repacks the same bytes instead of encoding the pixels again (~0.05 s a megapixel)."""


def _png_image(name: str, width: int, height: int, colorspace: str):
    """A new byte image ``name`` (no alpha) in colour space ``colorspace``, saved as PNG."""
    import bpy

    image = bpy.data.images.new(name, width, height, alpha=False, float_buffer=False)
    image.colorspace_settings.name = colorspace
    image.file_format = "PNG"
    return image


def _packed_image(name: str, pixels, colorspace: str, source=None):
    """The image ``name`` if present (reused as is), else a new byte image from ``pixels``
    (rows bottom-up; or a function that returns them), colour space ``colorspace``, packed
    into the .blend as PNG.  ``source``: a hashable name of the pixels (such as the arguments
    that made them); with it the PNG is encoded once per process and packed again as is
    into later files (the same image: pixels, size, format and colour space)."""
    import bpy

    image = bpy.data.images.get(name)
    if image is not None:
        return image
    key = None if source is None else (name, colorspace, source)
    data = _PNG_BYTES.get(key) if key is not None else None
    if data is not None:
        image = _png_image(name, *data[1], colorspace)
        image.pack(data=data[0], data_len=len(data[0]))
        image.source = "FILE"  # read from the packed PNG, as an image packed from pixels is
        return image
    pixels = pixels() if callable(pixels) else pixels
    height, width = pixels.shape[:2]
    image = _png_image(name, width, height, colorspace)
    image.pixels.foreach_set(np.ascontiguousarray(pixels, np.float32).ravel())
    image.pack()
    if key is not None:
        _PNG_BYTES[key] = (bytes(image.packed_file.data), (width, height))
    return image


@functools.lru_cache(maxsize=8)
def _texture_pixels(kind: str, seed: int, size: int, tone: str = "medium") -> np.ndarray:
    """:func:`albedo_pixels` (of the named :data:`SKIN_TONES` tone) or
    :func:`pore_normal_pixels`, generated once per process (~0.35 s for both; a test builds a
    new head after each fresh file).  Never changed by its callers."""
    if kind == "albedo":
        return albedo_pixels(seed, size, SKIN_TONES[tone])
    return pore_normal_pixels(seed, size)


def skin_albedo_image(seed: int = 0, size: int = ALBEDO_SIZE, tone: str = "medium"):
    """The packed sRGB albedo ``Skin Albedo {seed}`` (``Skin Albedo {seed} {tone}`` for a tone
    other than the head's own, :data:`SKIN_TONES`; :func:`albedo_pixels`), reused by name."""
    name = f"Skin Albedo {seed}" + ("" if tone == "medium" else f" {tone}")
    return _packed_image(name, lambda: _texture_pixels("albedo", seed, size, tone), "sRGB",
                         source=("albedo", seed, size, tone))


def pore_normal_image(seed: int = 0, size: int = NORMAL_SIZE):
    """The packed Non-Color normal map ``Skin Pores Normal {seed}`` (:func:`pore_normal_pixels`),
    reused by name."""
    return _packed_image(f"Skin Pores Normal {seed}", lambda: _texture_pixels("normal", seed, size),
                         "Non-Color", source=("normal", seed, size))


def _input(node, name):
    """A node input by name (Principled inputs were renamed across versions: take the first
    of several names that exists)."""
    for candidate in ((name,) if isinstance(name, str) else name):
        if candidate in node.inputs:
            return node.inputs[candidate]
    raise KeyError(f"{node.name} has none of the inputs {name!r}")


def skin_material(name: str, seed: int = 0, *, normal_strength: float = 0.6,
                  tone: str = "medium"):
    """A new material ``name``: Principled BSDF with Base Color from the albedo texture, Normal
    from a Normal Map node (tangent space, the mesh's UVs) fed by the pore normal map, Roughness
    0.45, Subsurface Weight 0.1 (radius a skin's red-scattering-furthest default, scale 5 mm),
    IOR 1.4.  Both textures use the active UV map."""
    import bpy

    material = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):  # always true, and deprecated, from 5.0 on
        material.use_nodes = True
    tree = material.node_tree
    nodes, links = tree.nodes, tree.links
    bsdf = next(node for node in nodes if node.type == "BSDF_PRINCIPLED")
    bsdf.location = (300, 300)
    output = next(node for node in nodes if node.type == "OUTPUT_MATERIAL")
    output.location = (650, 300)

    uv = nodes.new("ShaderNodeUVMap")
    uv.location = (-650, 150)
    albedo = nodes.new("ShaderNodeTexImage")
    albedo.name = albedo.label = "Albedo"
    albedo.image = skin_albedo_image(seed, tone=tone)
    albedo.location = (-350, 400)
    normal_texture = nodes.new("ShaderNodeTexImage")
    normal_texture.name = normal_texture.label = "Pores Normal"
    normal_texture.image = pore_normal_image(seed)
    normal_texture.interpolation = "Cubic"  # smoother slopes when magnified
    normal_texture.location = (-350, 50)
    normal_map = nodes.new("ShaderNodeNormalMap")
    normal_map.space = "TANGENT"
    normal_map.inputs["Strength"].default_value = normal_strength
    normal_map.location = (0, 0)
    links.new(uv.outputs["UV"], albedo.inputs["Vector"])
    links.new(uv.outputs["UV"], normal_texture.inputs["Vector"])
    links.new(albedo.outputs["Color"], bsdf.inputs["Base Color"])
    links.new(normal_texture.outputs["Color"], normal_map.inputs["Color"])
    links.new(normal_map.outputs["Normal"], bsdf.inputs["Normal"])

    _input(bsdf, "Roughness").default_value = 0.45
    _input(bsdf, ("IOR",)).default_value = 1.4
    _input(bsdf, ("Subsurface Weight", "Subsurface")).default_value = 0.1
    _input(bsdf, "Subsurface Radius").default_value = (1.0, 0.2, 0.1)
    if "Subsurface Scale" in bsdf.inputs:
        bsdf.inputs["Subsurface Scale"].default_value = 0.005  # metres: the scene is in metres
    return material


def build_character(name: str = "Head", location=(0.0, 0.0, 0.0), size_m: float = 0.2,
                    seed: int = 0, tone: str = "medium"):
    """Add a textured head to the current scene and return the object.

    Suzanne (``primitive_monkey_add`` with UVs), its mesh scaled so its widest extent is
    ``size_m`` metres (object scale stays 1), at ``location``, facing -Y; a Subdivision Surface
    modifier (levels 2, render 2), shaded smooth.  Its own material ``f"{name} Skin"``
    (:func:`skin_material`) uses the packed images ``Skin Albedo {seed}`` and ``Skin Pores
    Normal {seed}``, generated once per seed and shared by characters of the same seed.  The
    object is left selected and active (and the only one selected).
    """
    import bpy
    from mathutils import Matrix

    if bpy.context.mode != "OBJECT":
        bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.object.select_all(action="DESELECT")
    bpy.ops.mesh.primitive_monkey_add(size=2.0, calc_uvs=True, location=location)
    obj = bpy.context.active_object
    obj.name = name
    obj.data.name = name
    obj.data.transform(Matrix.Scale(size_m / max(obj.dimensions), 4))
    obj.data.update()
    bpy.ops.object.shade_smooth()
    subsurf = obj.modifiers.new("Subdivision", "SUBSURF")
    subsurf.levels = 2
    subsurf.render_levels = 2
    obj.data.materials.append(skin_material(f"{name} Skin", seed, tone=tone))
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    return obj


def add_coverage_mask(material_or_obj, seed: int = 0, size: int = COVERAGE_SIZE):
    """A painted coverage image for a material (or an object's active material), named
    ``f"{material.name} Coverage"`` and reused by name: ``size`` x ``size``, Non-Color, packed
    (:func:`coverage_pixels`: foundation everywhere but a soft bare band and spot).  Returns the
    image; link it (through an Image Texture on the UVs) to the made-up group's ``Coverage``."""
    material = getattr(material_or_obj, "active_material", material_or_obj)
    if material is None:
        raise ValueError(f"{material_or_obj.name!r} has no material to name the mask after")
    return _packed_image(f"{material.name} Coverage", coverage_pixels(seed, size), "Non-Color")


def _aim(obj, target) -> None:
    """Rotate ``obj`` so its -Z axis points at ``target`` with +Y up as far as possible."""
    from mathutils import Vector

    direction = Vector(target) - obj.location
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def portrait_camera_and_lights(scene, obj, *, size: int = 256, samples: int = 32,
                               seed: int = 0, lens_mm: float = 85.0):
    """Light and frame ``obj`` (a head from :func:`build_character`) for a portrait render.

    - Camera: perspective, ``lens_mm`` lens on a 36 mm sensor, 30 degrees to the viewer's left
      of the head's front (-Y) and 8 degrees above, at the distance that frames the head's
      widest extent with a 40% margin; made the scene camera.
    - Key: an area light 0.3 m square, 45 degrees to the viewer's right and 35 above, 1 m away.
    - Fill: an area light 0.6 m square from the camera's side, at a fifth of the key's power.
    - World: uniform grey 0.05 (a dim ambient).
    - Render: :func:`support.sphere_scene.cycles_settings` (Cycles CPU, ``samples``, no
      denoiser, view transform Standard), ``size`` x ``size`` pixels.

    Returns the camera object.
    """
    import bpy
    from mathutils import Vector

    centre = obj.matrix_world @ (sum((Vector(c) for c in obj.bound_box), Vector()) / 8.0)
    extent = max(obj.dimensions)

    def around(azimuth_deg, elevation_deg, distance):
        a, e = math.radians(azimuth_deg), math.radians(elevation_deg)
        # Azimuth 0 is the head's front (-Y); positive turns to the viewer's left (-X).
        return centre + distance * Vector((-math.sin(a) * math.cos(e),
                                           -math.cos(a) * math.cos(e), math.sin(e)))

    camera = bpy.data.objects.new("Portrait Camera", bpy.data.cameras.new("Portrait Camera"))
    scene.collection.objects.link(camera)
    camera.data.lens = lens_mm
    camera.data.sensor_width = 36.0
    camera.data.clip_start = 0.01
    half_fov = math.atan(camera.data.sensor_width / 2 / lens_mm)
    camera.location = around(30.0, 8.0, 0.55 * extent / math.tan(half_fov))
    _aim(camera, centre)
    scene.camera = camera

    def area(name, azimuth, elevation, distance, side, power):
        light = bpy.data.objects.new(name, bpy.data.lights.new(name, "AREA"))
        scene.collection.objects.link(light)
        light.data.size = side
        light.data.energy = power
        light.location = around(azimuth, elevation, distance)
        _aim(light, centre)
        return light

    area("Key Light", -45.0, 35.0, 1.0, 0.3, 20.0)
    area("Fill Light", 40.0, 5.0, 1.2, 0.6, 4.0 * 1.44)

    world = bpy.data.worlds.new("Dim Grey")
    world.color = (0.05, 0.05, 0.05)
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    for node in world.node_tree.nodes:
        if node.type == "BACKGROUND":
            node.inputs["Color"].default_value = (0.05, 0.05, 0.05, 1.0)
            node.inputs["Strength"].default_value = 1.0
    scene.world = world
    cycles_settings(scene, size=size, samples=samples, seed=seed)
    return camera
