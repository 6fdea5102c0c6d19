"""What feeds an input evaluated at points of the surface (makeup_skin_addon.surface_values):
the common colour nodes as Blender computes them, an image at its UVs, node groups, and a node
it cannot evaluate taken as 0.5 with a note."""

import numpy as np
import pytest


class Points:
    """Three points whose UVs fall in three columns of a 3 x 1 image."""

    count = 3
    weights = None

    def __init__(self):
        self.uv_read = []

    def uv(self, name, reader=""):
        self.uv_read.append(name)
        return np.array([[0.1, 0.5], [0.5, 0.5], [0.9, 0.5]])

    def image(self, image, uv, extension):
        columns = (uv[:, 0] * 3).astype(int)
        palette = np.array([[0.2, 0.4, 0.6, 1.0], [0.4, 0.4, 0.4, 1.0], [0.9, 0.1, 0.3, 1.0]])
        return palette[columns]


def _source_of(socket):
    from makeup_skin_addon import artist_shader

    return artist_shader.source(socket, ())


@pytest.fixture
def tree(addon, blank_scene):
    import bpy

    group = bpy.data.node_groups.new("Evaluated", "ShaderNodeTree")
    target = group.nodes.new("ShaderNodeBsdfDiffuse")
    return group, target.inputs["Color"]


def test_an_image_tinted_by_a_multiply_mix(tree):
    import bpy

    from makeup_skin_addon import surface_values

    group, colour = tree
    texture = group.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.new("Any", 3, 1)
    mix = group.nodes.new("ShaderNodeMix")
    mix.data_type, mix.blend_type = "RGBA", "MULTIPLY"
    mix.inputs["Factor"].default_value = 0.5
    next(s for s in mix.inputs if s.identifier == "B_Color").default_value = (0.5, 1.0, 0.0, 1)
    group.links.new(texture.outputs["Color"], next(s for s in mix.inputs
                                                   if s.identifier == "A_Color"))
    group.links.new(next(s for s in mix.outputs if s.identifier == "Result_Color"), colour)
    notes = []
    points = Points()
    values = surface_values.values(_source_of(colour), points, notes)
    image = Points().image(None, points.uv(""), "REPEAT")[:, :3]
    expected = image * (0.5 + 0.5 * np.array([0.5, 1.0, 0.0]))
    np.testing.assert_allclose(values, expected, atol=1e-6)
    np.testing.assert_allclose(surface_values.mean(_source_of(colour), points, notes),
                               expected.mean(axis=0), atol=1e-6)
    assert notes == [] and "" in points.uv_read  # an unlinked Vector: the render UV map


@pytest.mark.parametrize("operation, expected", [("MULTIPLY", 0.8), ("ADD", 2.4),
                                                 ("POWER", 4.0), ("MAXIMUM", 2.0)])
def test_math(tree, operation, expected):
    from makeup_skin_addon import surface_values

    group, colour = tree
    math = group.nodes.new("ShaderNodeMath")
    math.operation = operation
    math.inputs[0].default_value, math.inputs[1].default_value = 2.0, 0.4 if operation != \
        "POWER" else 2.0
    group.links.new(math.outputs[0], colour)
    assert surface_values.mean(_source_of(colour), Points(), [], "VALUE") == pytest.approx(
        expected)


def test_a_ramp_inverted_and_a_hue_shift(tree):
    """A Color Ramp (black to red, linear) at 0.25, inverted at factor 1: (0.75, 1, 1); a
    Hue/Saturation/Value at neutral settings gives its colour back."""
    from makeup_skin_addon import surface_values

    group, colour = tree
    ramp = group.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[1].color = (1.0, 0.0, 0.0, 1.0)
    ramp.inputs["Fac"].default_value = 0.25
    invert = group.nodes.new("ShaderNodeInvert")
    hue = group.nodes.new("ShaderNodeHueSaturation")
    group.links.new(ramp.outputs["Color"], invert.inputs["Color"])
    group.links.new(invert.outputs["Color"], hue.inputs["Color"])
    group.links.new(hue.outputs["Color"], colour)
    np.testing.assert_allclose(surface_values.mean(_source_of(colour), Points(), []),
                               (0.75, 1.0, 1.0), atol=1e-6)


def test_a_node_group_is_evaluated_inside(tree):
    import bpy

    from makeup_skin_addon import surface_values

    group, colour = tree
    inner = bpy.data.node_groups.new("Tint", "ShaderNodeTree")
    inner.interface.new_socket("In", in_out="INPUT", socket_type="NodeSocketColor")
    inner.interface.new_socket("Out", in_out="OUTPUT", socket_type="NodeSocketColor")
    inputs, outputs = inner.nodes.new("NodeGroupInput"), inner.nodes.new("NodeGroupOutput")
    gamma = inner.nodes.new("ShaderNodeGamma")
    gamma.inputs["Gamma"].default_value = 2.0
    inner.links.new(inputs.outputs["In"], gamma.inputs["Color"])
    inner.links.new(gamma.outputs["Color"], outputs.inputs["Out"])
    node = group.nodes.new("ShaderNodeGroup")
    node.node_tree = inner
    node.inputs["In"].default_value = (0.5, 0.2, 1.0, 1.0)
    group.links.new(node.outputs["Out"], colour)
    np.testing.assert_allclose(surface_values.mean(_source_of(colour), Points(), []),
                               (0.25, 0.04, 1.0), atol=1e-6)


def test_what_cannot_be_evaluated_is_half_and_said(tree):
    from makeup_skin_addon import surface_values

    group, colour = tree
    noise = group.nodes.new("ShaderNodeTexNoise")
    group.links.new(noise.outputs["Color"], colour)
    notes = []
    np.testing.assert_allclose(surface_values.mean(_source_of(colour), Points(), notes),
                               (0.5, 0.5, 0.5))
    assert notes == [f"{noise.name!r} (Noise Texture) is not evaluated: taken as 0.5"]


def test_an_images_alpha_is_said_to_be_taken_as_1(tree):
    """A texture's Alpha (a mask in the albedo's alpha mixing two skins): the reduced images
    keep colour only, so it is 1, and the note says so (a value assumed: the first Apply
    warns); an image without alpha says nothing."""
    import bpy

    from makeup_skin_addon import surface_values

    group, colour = tree
    texture = group.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.new("Masked", 3, 1, alpha=True)
    group.links.new(texture.outputs["Alpha"], colour)
    notes = []
    assert surface_values.mean(_source_of(colour), Points(), notes, "VALUE") == 1.0
    assert notes == ["'Image Texture''s Alpha (of image 'Masked') is not read: taken as 1"]
    assert surface_values.assumed(notes[0])
    texture.image.alpha_mode = "NONE"
    notes = []
    surface_values.mean(_source_of(colour), Points(), notes, "VALUE")
    assert notes == []


def _emission_seen_flat(scene, obj, *, size: int, samples: int, ortho_scale: float):
    """``obj`` given a material whose surface is an Emission, seen by an orthographic camera
    from +Z in Cycles (``size`` px square, ``samples``, the Standard view: a pixel is the
    emission's value): ``(the material's tree, the Emission node)``."""
    import bpy

    scene.render.engine = "CYCLES"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    material = bpy.data.materials.new("Seen Flat")
    if material.node_tree is None:  # 4.5: a new material has no tree
        material.use_nodes = True
    obj.data.materials.append(material)
    tree = material.node_tree
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(emission.outputs[0], tree.get_output_node("ALL").inputs["Surface"])
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.type, camera.data.ortho_scale = "ORTHO", ortho_scale
    camera.location = (0.0, 0.0, 5.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    return tree, emission


def test_rgb_curves_as_cycles_renders_them(addon, blank_scene, tmp_path):
    """An RGB Curves node (its C curve bent, then a channel's own; Factor 0.8) on a constant
    colour feeding an Emission seen flat by an orthographic camera: Cycles renders the value
    the evaluation gives, within 1e-3 (the curves' own tables)."""
    import bpy
    from support.addon_steps import render

    from makeup_skin_addon import surface_values

    bpy.ops.mesh.primitive_plane_add(size=40.0)  # fills the frame
    tree, emission = _emission_seen_flat(blank_scene, bpy.context.active_object, size=4,
                                         samples=1, ortho_scale=6.0)
    curves = tree.nodes.new("ShaderNodeRGBCurve")
    curves.inputs["Color"].default_value = (0.2, 0.5, 0.8, 1.0)
    next(s for s in curves.inputs if s.identifier == "Fac").default_value = 0.8
    mapping = curves.mapping
    mapping.curves[3].points.new(0.5, 0.75)  # C
    mapping.curves[0].points.new(0.3, 0.1)  # R
    mapping.curves[2].points.new(0.6, 0.9)  # B
    mapping.update()
    tree.links.new(curves.outputs["Color"], emission.inputs["Color"])
    rendered = render(tmp_path, "curves").reshape(-1, 3).mean(axis=0)
    notes = []
    evaluated = surface_values.mean(_source_of(emission.inputs["Color"]), Points(), notes)
    assert notes == []
    np.testing.assert_allclose(evaluated, rendered, atol=1e-3)
    assert not np.allclose(evaluated, (0.2, 0.5, 0.8), atol=0.05)  # the curves did bend it


def test_fresnel_and_layer_weight_as_their_average_over_a_sphere(addon, blank_scene, tmp_path):
    """Fresnel and Layer Weight feeding a Mix Shader's factor count by their average under
    uniform light, over the directions the surface is seen from: what Cycles renders of them
    as an emission over a smooth sphere seen orthographically (a disc whose area is spread as
    2 cos dcos; its edge pixels counted by their coverage), within 1%."""
    import bpy

    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=128, ring_count=64)
    bpy.ops.object.shade_smooth()
    blank_scene.render.film_transparent = True
    tree, emission = _emission_seen_flat(blank_scene, bpy.context.active_object, size=96,
                                         samples=16, ortho_scale=2.2)
    fresnel = tree.nodes.new("ShaderNodeFresnel")
    fresnel.inputs["IOR"].default_value = 1.45
    weight = tree.nodes.new("ShaderNodeLayerWeight")
    for output, blend in (("Fresnel", 0.6), ("Facing", 0.3), ("Facing", 0.8)):
        weight.inputs["Blend"].default_value = blend
        tree.links.new(next(s for s in weight.outputs if s.identifier == output),
                       emission.inputs["Color"])
        _check_disc(tmp_path, emission, f"{output} {blend}")
    tree.links.new(fresnel.outputs[0], emission.inputs["Color"])
    _check_disc(tmp_path, emission, "Fresnel node")


def _check_disc(tmp_path, emission, name):
    """The render's mean over the disc (by coverage) is the evaluation's, within 1%."""
    from support import sphere_scene
    from support.addon_steps import render

    from makeup_skin_addon import surface_values

    path = tmp_path / f"{name}.exr"
    render(tmp_path, name)
    pixels = sphere_scene.image_pixels(str(path))
    rendered = pixels[..., 0].sum() / pixels[..., 3].sum()  # premultiplied: edges by coverage
    notes = []
    evaluated = surface_values.mean(_source_of(emission.inputs["Color"]), Points(), notes,
                                    "VALUE")
    assert notes == [], name
    assert evaluated == pytest.approx(rendered, rel=0.01), name
