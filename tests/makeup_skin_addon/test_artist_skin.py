"""What the made-up skin takes from the artist's shader (makeup_skin_addon.artist_skin): the
Base Color read as the mean over the faces, each skin BSDF's body colour as the shader renders
it (:func:`lut_baker.closures.principled_albedo.principled_albedo`), the leaves weighted by the
Mix Shaders, the dominant BSDF's roughness, index and subsurface, the target colour, and what
is not followed said."""

import numpy as np
import pytest

from lut_baker.closures import principled_albedo


def _principled_material(base=(0.6, 0.4, 0.3)):
    import bpy

    material = bpy.data.materials.new("Skin")
    if material.node_tree is None:
        material.use_nodes = True
    principled = next(n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    principled.inputs["Base Color"].default_value = (*base, 1.0)
    principled.inputs["Roughness"].default_value = 0.4
    principled.inputs["IOR"].default_value = 1.45
    principled.inputs["Subsurface Weight"].default_value = 0.3
    principled.subsurface_method = "RANDOM_WALK_SKIN"
    return material, principled


@pytest.fixture
def plane(addon, blank_scene):
    import bpy

    blank_scene.render.engine = "CYCLES"  # the albedo Cycles renders
    bpy.ops.mesh.primitive_plane_add()
    return bpy.context.active_object


def test_a_principled_skin(plane):
    """One Principled BSDF: its body and total as principled_albedo gives them, its values
    for the bake."""
    from makeup_skin_addon import artist_skin

    material, principled = _principled_material()
    plane.data.materials.append(material)
    reading = artist_skin.read_material(material)
    expected = principled_albedo.principled_albedo(np.array([0.6, 0.4, 0.3]), 0.4, 1.45, 0.3,
                                                   "RANDOM_WALK_SKIN")
    np.testing.assert_allclose(reading.body, expected.body, rtol=1e-5)
    np.testing.assert_allclose(reading.target, expected.total, rtol=1e-5)
    np.testing.assert_allclose(reading.leaves[0].factor, expected.body / [0.6, 0.4, 0.3],
                               rtol=1e-5)
    assert reading.dominant.node == principled
    assert (reading.roughness, reading.ior, reading.subsurface_weight, reading.method) == \
        pytest.approx((0.4, 1.45, 0.3, "RANDOM_WALK_SKIN"))
    assert reading.warnings == []


def test_two_skins_mixed_and_a_metallic_one_warned(plane):
    """Mix Shader at 0.25 of a Principled (0.6, 0.4, 0.3) and a Diffuse (0.2, 0.2, 0.2): the
    body and target are their shares' sums, the dominant is the Principled; a metallic
    Principled is said not to be followed under the film."""
    from makeup_skin_addon import artist_skin

    material, principled = _principled_material()
    plane.data.materials.append(material)
    tree = material.node_tree
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.2, 0.2, 0.2, 1.0)
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs[0].default_value = 0.25
    tree.links.new(principled.outputs[0], mix.inputs[1])
    tree.links.new(diffuse.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], tree.get_output_node("ALL").inputs["Surface"])
    reading = artist_skin.read_material(material)
    alone = principled_albedo.principled_albedo(np.array([0.6, 0.4, 0.3]), 0.4, 1.45, 0.3,
                                                "RANDOM_WALK_SKIN")
    np.testing.assert_allclose(reading.body, 0.75 * alone.body + 0.25 * 0.2, rtol=1e-5)
    np.testing.assert_allclose(reading.target, 0.75 * alone.total + 0.25 * 0.2, rtol=1e-5)
    assert reading.dominant.node == principled
    principled.inputs["Metallic"].default_value = 0.5
    reading = artist_skin.read_material(material)
    assert len(reading.warnings) == 1 and "metallic 0.5" in reading.warnings[0]


def test_no_skin_bsdf(plane):
    import bpy

    from makeup_skin_addon import artist_skin

    material = bpy.data.materials.new("Glow")
    if material.node_tree is None:
        material.use_nodes = True
    tree = material.node_tree
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(emission.outputs[0], tree.get_output_node("ALL").inputs["Surface"])
    plane.data.materials.append(material)
    reading = artist_skin.read_material(material)
    assert reading.dominant is None
    assert any("Emission" in w for w in reading.warnings)
    assert any("skin preset" in w for w in reading.warnings)
def test_the_base_colour_read_is_an_images_mean_over_the_faces(addon, blank_scene):
    """A grid whose image is one colour on the left half of the UV square and another on the
    right, its UVs spanning only the left three quarters: the Base Color read from the
    artist's shader is the area-weighted mean over the faces (2/3 of the first, 1/3 of the
    second), linearised from sRGB; a value is read as it is; Blender's untouched default
    shader is no skin of the artist's."""
    import bpy

    from makeup_skin_addon import artist_skin

    bpy.ops.mesh.primitive_grid_add(x_subdivisions=40, y_subdivisions=40, size=2.0)
    plane = bpy.context.active_object
    uv = plane.data.uv_layers.active.data
    for loop in uv:
        loop.uv = (loop.uv[0] * 0.75, loop.uv[1])
    image = bpy.data.images.new("Halves", 64, 8)
    pixels = np.ones((8, 64, 4), np.float32)
    pixels[:, :32, :3] = (0.8, 0.5, 0.4)
    pixels[:, 32:, :3] = (0.2, 0.3, 0.9)
    image.pixels.foreach_set(pixels.ravel())
    material = bpy.data.materials.new("Skin")
    plane.data.materials.append(material)
    if material.node_tree is None:
        material.use_nodes = True
    tree = material.node_tree
    principled = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    assert artist_skin.read_material(material) is None
    principled.inputs["Base Color"].default_value = (0.3, 0.2, 0.1, 1.0)
    np.testing.assert_allclose(artist_skin.read_material(material).leaves[0].base,
                               (0.3, 0.2, 0.1), atol=1e-6)
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    tree.links.new(texture.outputs["Color"], principled.inputs["Base Color"])

    def linear(c):
        c = np.asarray(c)
        return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)

    expected = (2 * linear([0.8, 0.5, 0.4]) + linear([0.2, 0.3, 0.9])) / 3
    reading = artist_skin.read_material(material)
    np.testing.assert_allclose(reading.leaves[0].base, expected, rtol=0.03)
    assert reading.notes == []




def test_the_engine_as_the_model_names_it(addon, blank_scene):
    """One name per engine for the tiers fitted and the artist's shader read: Cycles is Cycles,
    either EEVEE is EEVEE, and Workbench (which shows the material through EEVEE's Material
    Preview) is EEVEE too; without a scene, Cycles."""
    from makeup_skin_addon import artist_skin

    names = {}
    for engine in ("CYCLES", "BLENDER_EEVEE_NEXT", "BLENDER_EEVEE", "BLENDER_WORKBENCH"):
        try:
            blank_scene.render.engine = engine
        except TypeError:  # BLENDER_EEVEE_NEXT in 4.2-4.5, BLENDER_EEVEE in 5.0
            continue
        names[engine] = artist_skin.render_engine(blank_scene)
    assert names.pop("CYCLES") == "CYCLES" and names.pop("BLENDER_WORKBENCH") == "EEVEE"
    assert list(names.values()) == ["EEVEE"]
    assert artist_skin.render_engine(None) == "CYCLES"
