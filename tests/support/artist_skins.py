"""The artist's own skin shaders that Made-up Skin must go over, on the textured head.

A skin artist's material is rarely one Principled BSDF with default values: its albedo comes
from a texture, sometimes inside a node group of their own, the skin may be mixed with a glossy
layer or with a second skin, or coloured by a plain value.  Each kind here is a material built
on the head of :mod:`support.character` (its albedo and pore normal textures), with the skin
values of a typical subsurface skin: Subsurface Weight 1, Radius (1, 0.2, 0.1), Scale 5 mm,
Roughness 0.45.

- :data:`KINDS` -- the kinds, by name, with a line saying what each is.
- :func:`artist_material` -- a new material of one kind.
- :func:`head_with` -- the textured head with a material of one kind;
  :func:`vertex_colours` -- a mesh's colour attribute, the skin tone blotched per vertex.
- :func:`uniform_white` -- the scene lit by a uniform white world and nothing else, framed by
  the portrait camera: the light under which a surface shows its albedo.
- :func:`face_mean` -- the object's mean colour in a render (its pixels weighted by alpha).
- :func:`blurred` -- the object's pixels blurred (noise averaged, detail kept at a few pixels).
"""

from __future__ import annotations

import numpy as np

from support import character

__all__ = ["KINDS", "artist_material", "head_with", "vertex_colours", "uniform_white",
           "face_mean", "blurred", "SKIN_VALUES"]

KINDS = {
    "principled": "a Principled BSDF fed by the albedo texture and the pore normal map",
    "mix_glossy": "the same behind a Mix Shader with a white glossy Principled at 0.25",
    "in_group": "the textures and the Principled BSDF inside a node group of the artist's",
    "dark_value": "a Principled BSDF whose Base Color is a value, dark (0.36, 0.14, 0.08)",
    "pale_value": "a Principled BSDF whose Base Color is a value, pale (0.70, 0.50, 0.40)",
    "two_principled": "two Principled skins behind a Mix Shader whose factor is a texture",
    "vertex_colour": "a Principled BSDF whose Base Color is the mesh's colour attribute "
                     "(vertex colours: the skin tone, blotched vertex by vertex)",
}
"""The artist's materials the tests render, by kind."""
SKIN_VALUES = {"Subsurface Weight": 1.0, "Subsurface Radius": (1.0, 0.2, 0.1),
               "Subsurface Scale": 0.005, "Roughness": 0.45}
"""A subsurface skin's values (scene in metres: a radius of 5 mm in red)."""
BASE_VALUES = {"dark_value": (0.36, 0.14, 0.08), "pale_value": (0.70, 0.50, 0.40)}


def _principled(tree, location, values: dict):
    node = tree.nodes.new("ShaderNodeBsdfPrincipled")
    node.location = location
    node.subsurface_method = "RANDOM_WALK"
    for name, value in values.items():
        socket = node.inputs[name]
        socket.default_value = (*value, 1.0) if socket.type == "RGBA" else value
    return node


def _textures(tree, x: float, y: float):
    """UV map, albedo and pore normal map nodes in ``tree``: ``(albedo colour output, normal
    output)``."""
    nodes, links = tree.nodes, tree.links
    uv = nodes.new("ShaderNodeUVMap")
    uv.location = (x - 650, y - 150)
    albedo = nodes.new("ShaderNodeTexImage")
    albedo.name = albedo.label = "Albedo"
    albedo.image = character.skin_albedo_image(0)
    albedo.location = (x - 350, y + 100)
    pores = nodes.new("ShaderNodeTexImage")
    pores.name = pores.label = "Pores Normal"
    pores.image = character.pore_normal_image(0)
    pores.interpolation = "Cubic"
    pores.location = (x - 350, y - 250)
    normal_map = nodes.new("ShaderNodeNormalMap")
    normal_map.space = "TANGENT"
    normal_map.inputs["Strength"].default_value = 0.6
    normal_map.location = (x - 50, y - 300)
    links.new(uv.outputs["UV"], albedo.inputs["Vector"])
    links.new(uv.outputs["UV"], pores.inputs["Vector"])
    links.new(pores.outputs["Color"], normal_map.inputs["Color"])
    return albedo.outputs["Color"], normal_map.outputs["Normal"]


def _textured_skin(tree, location=(300, 300)):
    bsdf = _principled(tree, location, SKIN_VALUES)
    colour, normal = _textures(tree, *location)
    tree.links.new(colour, bsdf.inputs["Base Color"])
    tree.links.new(normal, bsdf.inputs["Normal"])
    return bsdf


def _skin_group():
    """The artist's node group: the textures and a Principled BSDF inside, a Shader output."""
    import bpy

    group = bpy.data.node_groups.new("Artist Skin", "ShaderNodeTree")
    group.interface.new_socket(name="Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    output = group.nodes.new("NodeGroupOutput")
    output.location = (700, 300)
    bsdf = _textured_skin(group)
    group.links.new(bsdf.outputs[0], output.inputs["Shader"])
    return group


def artist_material(kind: str, name: str | None = None):
    """A new material of ``kind`` (:data:`KINDS`), named ``name`` (default ``Artist <kind>``)."""
    import bpy

    if kind not in KINDS:
        raise ValueError(f"kind must be one of {sorted(KINDS)}, got {kind!r}")
    material = bpy.data.materials.new(name or f"Artist {kind}")
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    for node in [n for n in tree.nodes if n.type != "OUTPUT_MATERIAL"]:
        tree.nodes.remove(node)
    output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
    output.location = (1100, 300)
    links = tree.links
    if kind in ("principled", "mix_glossy"):
        surface = _textured_skin(tree).outputs[0]
        if kind == "mix_glossy":
            glossy = _principled(tree, (300, -500), {"Base Color": (1.0, 1.0, 1.0),
                                                     "Roughness": 0.2})
            mix = tree.nodes.new("ShaderNodeMixShader")
            mix.location = (800, 300)
            mix.inputs[0].default_value = 0.25
            links.new(surface, mix.inputs[1])
            links.new(glossy.outputs[0], mix.inputs[2])
            surface = mix.outputs[0]
    elif kind == "in_group":
        node = tree.nodes.new("ShaderNodeGroup")
        node.node_tree = _skin_group()
        node.location = (800, 300)
        surface = node.outputs[0]
    elif kind in BASE_VALUES or kind == "vertex_colour":
        bsdf = _principled(tree, (300, 300), {**SKIN_VALUES,
                                              "Base Color": BASE_VALUES.get(kind, (0.5,) * 3)})
        _, normal = _textures(tree, 300, 300)
        links.new(normal, bsdf.inputs["Normal"])
        if kind == "vertex_colour":
            colours = tree.nodes.new("ShaderNodeVertexColor")  # the render colour attribute
            colours.location = (0, 500)
            links.new(colours.outputs["Color"], bsdf.inputs["Base Color"])
        surface = bsdf.outputs[0]
    else:  # two_principled
        first = _textured_skin(tree)
        second = _principled(tree, (300, -500), {**SKIN_VALUES, "Roughness": 0.35,
                                                 "Subsurface Radius": (0.8, 0.3, 0.15)})
        tint = tree.nodes.new("ShaderNodeMix")
        tint.data_type = "RGBA"
        tint.blend_type = "MULTIPLY"
        tint.location = (0, -500)
        tint.inputs["Factor"].default_value = 1.0
        tint.inputs[7].default_value = (0.85, 0.75, 0.72, 1.0)  # B of the colour mix
        links.new(first.inputs["Base Color"].links[0].from_socket, tint.inputs[6])
        links.new(tint.outputs[2], second.inputs["Base Color"])
        links.new(first.inputs["Normal"].links[0].from_socket, second.inputs["Normal"])
        mask = tree.nodes.new("ShaderNodeTexNoise")
        mask.location = (300, 0)
        mask.inputs["Scale"].default_value = 3.0
        mix = tree.nodes.new("ShaderNodeMixShader")
        mix.location = (800, 300)
        links.new(mask.outputs["Fac"], mix.inputs[0])
        links.new(first.outputs[0], mix.inputs[1])
        links.new(second.outputs[0], mix.inputs[2])
        surface = mix.outputs[0]
    links.new(surface, output.inputs["Surface"])
    return material


def head_with(kind: str, name: str = "Head"):
    """The textured head (:func:`support.character.build_character`) with a material of
    ``kind`` in place of its own; returns the object."""
    import bpy

    obj = character.build_character(name, size_m=0.22)
    own = obj.data.materials[0]
    obj.data.materials[0] = artist_material(kind)
    bpy.data.materials.remove(own)
    if kind == "vertex_colour":
        vertex_colours(obj.data)
    return obj


def vertex_colours(mesh, seed: int = 0, spread: float = 0.15):
    """A colour attribute ``Skin`` on ``mesh``'s vertices (float, the one to render): the
    skin tone (:data:`support.character.SKIN_SRGB`, linear) times ``1 + spread u`` per vertex
    and channel, ``u`` uniform in [-1, 1] from ``seed``; returns the attribute."""
    rng = np.random.default_rng(seed)
    tone = np.where(np.array(character.SKIN_SRGB) <= 0.04045, np.array(character.SKIN_SRGB)
                    / 12.92, ((np.array(character.SKIN_SRGB) + 0.055) / 1.055) ** 2.4)
    rgb = tone * (1.0 + spread * rng.uniform(-1.0, 1.0, (len(mesh.vertices), 3)))
    rgba = np.concatenate([rgb, np.ones((len(rgb), 1))], axis=1).astype(np.float32)
    attribute = mesh.color_attributes.new("Skin", "FLOAT_COLOR", "POINT")
    attribute.data.foreach_set("color", rgba.ravel())
    mesh.color_attributes.render_color_index = mesh.color_attributes.find("Skin")
    return attribute


def uniform_white(scene, obj, *, size: int = 128, samples: int = 64, seed: int = 0) -> None:
    """Frame ``obj`` with the portrait camera and light it by a uniform white world of
    strength 1 only (no lamps): every surface shows its albedo."""
    import bpy

    character.portrait_camera_and_lights(scene, obj, size=size, samples=samples, seed=seed)
    for light in [o for o in scene.objects if o.type == "LIGHT"]:
        bpy.data.objects.remove(light)
    for node in scene.world.node_tree.nodes:
        if node.type == "BACKGROUND":
            node.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
            node.inputs["Strength"].default_value = 1.0
    scene.world.color = (1.0, 1.0, 1.0)
    scene.render.film_transparent = True


def face_mean(pixels: np.ndarray) -> np.ndarray:
    """The object's mean RGB in an RGBA render with a transparent film (Blender's alpha is
    premultiplied): the sum of its colour over the sum of its alpha, so a pixel the object
    covers in part counts by its share.  Its edges, seen at grazing angles, count as much as
    their area: leaving them out would weigh a shader by how bright it is face on."""
    return pixels[..., :3].reshape(-1, 3).sum(axis=0) / pixels[..., 3].sum()


def blurred(pixels: np.ndarray, sigma_px: float = 1.5) -> tuple[np.ndarray, np.ndarray]:
    """``(rgb, mask)``: the RGB of an RGBA render blurred by a Gaussian of ``sigma_px`` within
    the object (normalised by the blurred mask, so the background does not bleed in), and the
    mask of pixels at least 3 sigma inside the object."""
    mask = (pixels[..., 3] > 0.999).astype(float)
    radius = int(np.ceil(3 * sigma_px))
    x = np.arange(-radius, radius + 1)
    kernel = np.exp(-0.5 * (x / sigma_px) ** 2)
    kernel /= kernel.sum()

    def blur(image):
        for axis in (0, 1):
            image = np.apply_along_axis(lambda v: np.convolve(v, kernel, mode="same"), axis,
                                        image)
        return image

    weight = blur(mask)
    rgb = np.stack([blur(pixels[..., c] * mask) for c in range(3)], axis=-1)
    rgb = rgb / np.maximum(weight, 1e-9)[..., None]
    inside = blur(mask) > 0.999
    return rgb, inside
