"""A hand-made mesh of known areas and colours for the add-on's sampling tests: three quads
whose UVs fall in three bands of an 8-bit image (exact in sRGB bytes), and the exact
area-weighted mean they give.

- :func:`build_two_faces` -- the mesh's object, its third face in another slot.
- :func:`band_image`, :func:`textured`, :func:`new_material` -- the image of bands, a
  material's Base Color fed by it, a material with a node tree.
- :func:`exact_two_faces` -- the exact mean over the two faces of the skin slot.
"""

import numpy as np

from . import exact_mean

__all__ = ["LEFT_BYTES", "RIGHT_BYTES", "OTHER_BYTES", "linear", "band_image", "textured",
           "new_material", "build_two_faces", "exact_two_faces"]

# Two faces of a hand-made mesh: colours as sRGB bytes (exact in an 8-bit image).
LEFT_BYTES = (200, 120, 90)
RIGHT_BYTES = (60, 90, 220)
OTHER_BYTES = (10, 250, 10)


linear = exact_mean.srgb_to_linear


def band_image(name, columns, height=8, colorspace="sRGB"):
    """An 8-bit image of vertical bands, one per colour of ``columns`` (bytes), 16 texels
    each."""
    import bpy

    width = 16 * len(columns)
    image = bpy.data.images.new(name, width, height)
    image.colorspace_settings.name = colorspace  # first: it regenerates the pixels
    pixels = np.ones((height, width, 4), np.float32)
    for i, colour in enumerate(columns):
        pixels[:, 16 * i:16 * (i + 1), :3] = np.asarray(colour) / 255.0
    image.pixels.foreach_set(pixels.ravel())
    return image


def textured(material, image, uv_map=None):
    """``material``'s Base Color fed by an Image Texture of ``image`` (through a UV Map node
    reading ``uv_map`` if given); returns the texture node."""
    tree = material.node_tree
    principled = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    tree.links.new(texture.outputs["Color"], principled.inputs["Base Color"])
    if uv_map is not None:
        node = tree.nodes.new("ShaderNodeUVMap")
        node.uv_map = uv_map
        tree.links.new(node.outputs["UV"], texture.inputs["Vector"])
    return texture


def new_material(name):
    import bpy

    material = bpy.data.materials.new(name)
    if material.node_tree is None:  # 4.5: a new material has no tree
        material.use_nodes = True
    return material


def build_two_faces(skin, other=None):
    """A mesh of three quads: a unit square standing in the XZ plane (UVs in the first band),
    a 3 x 1 rectangle lying in the XY plane (second band), and, in a second slot holding
    ``other``, a 10 x 10 square (third band).  Returns the object."""
    import bpy

    vertices = [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1),
                (2, 0, 0), (5, 0, 0), (5, 1, 0), (2, 1, 0),
                (0, 5, 0), (10, 5, 0), (10, 15, 0), (0, 15, 0)]
    faces = [(0, 1, 2, 3), (4, 5, 6, 7), (8, 9, 10, 11)]
    mesh = bpy.data.meshes.new("Two Faces")
    mesh.from_pydata(vertices, [], faces)
    layer = mesh.uv_layers.new(name="UVMap")
    square = [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)]
    uv = [(u / 3 + band / 3, v) for band in range(3) for u, v in square]
    layer.data.foreach_set("uv", np.ravel(uv))
    mesh.materials.append(skin)
    if other is not None:
        mesh.materials.append(other)
        mesh.polygons[2].material_index = 1
    obj = bpy.data.objects.new("Two Faces", mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def exact_two_faces(left_area, right_area):
    left, right = linear(np.asarray(LEFT_BYTES) / 255), linear(np.asarray(RIGHT_BYTES) / 255)
    return (left_area * left + right_area * right) / (left_area + right_area)
