"""The skin preset's own colour on a material (makeup_skin_addon.skin_colour): Skin Color's
value, or the mean of an image texture that feeds it over the faces that use the material (the
two faces of known areas and colours)."""

import numpy as np
from support.two_faces import (
    LEFT_BYTES,
    OTHER_BYTES,
    RIGHT_BYTES,
    band_image,
    build_two_faces,
    exact_two_faces,
    new_material,
)


def test_skin_color_or_the_mean_of_its_texture(addon, blank_scene):
    import bpy

    from makeup_skin_addon import apply, groups, skin_colour

    skin, other = new_material("Skin"), new_material("Other")  # Blender's default shader
    obj = build_two_faces(skin, other)
    bpy.context.view_layer.objects.active = obj
    skin.makeup_skin.live_update = False
    apply.apply_to_object(bpy.context, obj, resolution="preview")
    value = skin_colour.skin_colour(skin)
    assert value.source == "Skin Color's value"
    np.testing.assert_allclose(value.rgb, tuple(skin.makeup_skin.skin_colour), rtol=1e-6)
    texture = skin.node_tree.nodes.new("ShaderNodeTexImage")
    texture.image = band_image("Bands", (LEFT_BYTES, RIGHT_BYTES, OTHER_BYTES))
    skin.node_tree.links.new(texture.outputs["Color"],
                             groups.group_of(skin).inputs["Skin Color"])
    value = skin_colour.skin_colour(skin)
    np.testing.assert_allclose(value.rgb, exact_two_faces(1.0, 3.0), atol=2e-5)
    assert value.source.startswith("the mean of image 'Bands' over the 2 faces that use 'Skin'")
