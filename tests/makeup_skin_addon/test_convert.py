"""Made-up Skin in the artist's own material (makeup_skin_addon.convert), on the textured head
of tests/support/character.py: Apply converts the material in place and carries the albedo and
the normal map over, through Mix and Add Shaders and node groups, takes an unlinked Base
Color's value, says what it could not carry, gives the film a weaker copy of the skin's normal
map; Revert restores it."""

import pytest
from support.addon_steps import apply_operator, apply_pipeline, group_node, tree_state


def test_apply_converts_the_artists_material_in_place(head):
    import bpy

    material = head.active_material
    principled = material.node_tree.nodes["Principled BSDF"]
    albedo = principled.inputs["Base Color"].links[0].from_socket
    normal = principled.inputs["Normal"].links[0].from_socket
    materials = len(bpy.data.materials)
    assert apply_operator(head) == material and len(bpy.data.materials) == materials
    group = group_node(material)
    output = material.node_tree.get_output_node("ALL")
    assert output.inputs["Surface"].links[0].from_node == group
    # The artist's shader stays, framed and disconnected, its own links intact.
    assert principled.parent is not None and principled.parent.label.startswith("Before Made-up")
    assert not principled.outputs[0].is_linked
    assert principled.inputs["Base Color"].links[0].from_socket == albedo
    # Albedo and normal map carried over to the group.
    assert group.inputs["Skin Color"].links[0].from_socket == albedo
    assert group.inputs["Normal"].links[0].from_socket == normal
    # The film gets a copy of the skin's Normal Map at half its strength (pores softened).
    film = group.inputs["Film Normal"].links[0].from_node
    assert film.name == "Made-up Skin Film Normal" and film.type == "NORMAL_MAP"
    skin_map = normal.node
    colour = skin_map.inputs["Color"].links[0].from_socket
    assert film.inputs["Color"].links[0].from_socket == colour
    assert film.inputs["Strength"].default_value == pytest.approx(
        0.5 * skin_map.inputs["Strength"].default_value, rel=1e-6)


def test_the_film_normal_follows_the_panel(head):
    """Film Follows Pores off unlinks the film's normal (a smooth film: the pores filled), on
    links it again; its strength is the panel's fraction of the skin's."""
    material = apply_operator(head)
    settings, group = material.makeup_skin, group_node(material)
    film = material.node_tree.nodes["Made-up Skin Film Normal"]
    base = material.node_tree.nodes["Normal Map"].inputs["Strength"].default_value
    settings.film_follows_pores = False
    assert not group.inputs["Film Normal"].is_linked
    settings.film_normal_strength = 0.25
    settings.film_follows_pores = True
    assert group.inputs["Film Normal"].links[0].from_node == film
    assert film.inputs["Strength"].default_value == pytest.approx(0.25 * base, rel=1e-6)


def _skin_shader_tree(material, kind):
    """Rebuild the head's material as ``kind``: "mix" (Principled + 10% Translucent through a
    Mix Shader), "group" (the Principled inside a node group whose Base Color and Normal come
    from the group's inputs, linked outside), "inside" (the texture inside the group), "value"
    (Base Color unlinked, 0.6, 0.4, 0.3) or "emission" (no skin shader)."""
    import bpy

    tree = material.node_tree
    principled = tree.nodes["Principled BSDF"]
    output = tree.get_output_node("ALL")
    albedo = tree.nodes["Albedo"].outputs["Color"]
    normal = tree.nodes["Normal Map"].outputs["Normal"]
    if kind == "mix":
        translucent = tree.nodes.new("ShaderNodeBsdfTranslucent")
        mix = tree.nodes.new("ShaderNodeMixShader")
        mix.inputs[0].default_value = 0.1
        tree.links.new(principled.outputs[0], mix.inputs[1])
        tree.links.new(translucent.outputs[0], mix.inputs[2])
        tree.links.new(mix.outputs[0], output.inputs["Surface"])
    elif kind in ("group", "inside"):
        group = bpy.data.node_groups.new("Skin Shader", "ShaderNodeTree")
        group.interface.new_socket("Albedo", in_out="INPUT", socket_type="NodeSocketColor")
        group.interface.new_socket("Bump", in_out="INPUT", socket_type="NodeSocketVector")
        group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
        inputs, outputs = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
        inner = group.nodes.new("ShaderNodeBsdfPrincipled")
        add = group.nodes.new("ShaderNodeAddShader")
        emission = group.nodes.new("ShaderNodeEmission")
        emission.inputs["Strength"].default_value = 0.0
        group.links.new(inner.outputs[0], add.inputs[0])
        group.links.new(emission.outputs[0], add.inputs[1])
        group.links.new(add.outputs[0], outputs.inputs[0])
        group.links.new(inputs.outputs["Bump"], inner.inputs["Normal"])
        if kind == "group":
            group.links.new(inputs.outputs["Albedo"], inner.inputs["Base Color"])
        else:
            texture = group.nodes.new("ShaderNodeTexImage")
            texture.image = tree.nodes["Albedo"].image
            group.links.new(texture.outputs["Color"], inner.inputs["Base Color"])
        node = tree.nodes.new("ShaderNodeGroup")
        node.node_tree = group
        tree.links.new(albedo, node.inputs["Albedo"])
        tree.links.new(normal, node.inputs["Bump"])
        tree.links.new(node.outputs[0], output.inputs["Surface"])
    elif kind == "value":
        tree.links.remove(principled.inputs["Base Color"].links[0])
        principled.inputs["Base Color"].default_value = (0.6, 0.4, 0.3, 1.0)
    elif kind == "emission":
        emission = tree.nodes.new("ShaderNodeEmission")
        tree.links.new(emission.outputs[0], output.inputs["Surface"])
    return albedo, normal


@pytest.mark.parametrize("kind", ["mix", "group"])
def test_the_skin_shader_is_found_behind_mixes_and_groups(head, kind):
    """Principled + 10% Translucent (a skin with a little translucency), and a Principled
    inside a node group (with an Add Shader) fed from outside: albedo and normal map carried
    over."""
    material = head.active_material
    albedo, normal = _skin_shader_tree(material, kind)
    material, messages = apply_pipeline(head, tier="LAYERED")
    group = group_node(material)
    assert group.inputs["Skin Color"].links[0].from_socket == albedo
    assert group.inputs["Normal"].links[0].from_socket == normal
    assert any("linked Base Color -> Skin Color, Normal -> Normal" in m for m in messages)
    assert not any("Not carried over" in m for m in messages)


def test_an_unlinked_base_colour_becomes_the_skin_colour(head):
    material = head.active_material
    _skin_shader_tree(material, "value")
    material, messages = apply_pipeline(head, tier="LAYERED")
    assert tuple(material.makeup_skin.skin_colour) == pytest.approx((0.6, 0.4, 0.3), abs=1e-6)
    assert tuple(group_node(material).inputs["Skin Color"].default_value)[:3] == pytest.approx(
        (0.6, 0.4, 0.3), abs=1e-6)
    assert any("Skin Color is the value of its Base Color (0.600, 0.400, 0.300)" in m
               for m in messages)


@pytest.mark.parametrize("kind", ["inside", "emission"])
def test_what_cannot_be_carried_is_named(head, kind):
    material = head.active_material
    _skin_shader_tree(material, kind)
    material, messages = apply_pipeline(head, tier="LAYERED")
    group = group_node(material)
    assert not group.inputs["Skin Color"].is_linked
    sentence = next(m for m in messages if m.startswith("Not carried over"))
    assert "Skin Color" in sentence
    if kind == "inside":
        assert "inside node group 'Skin Shader'" in sentence
        assert group.inputs["Normal"].is_linked  # the normal comes from outside: carried
    else:
        assert "no Principled or Diffuse BSDF" in sentence and "Normal" in sentence


def test_an_object_without_material_gets_one_and_is_told(addon, blank_scene):
    import bpy

    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.03)
    obj = bpy.context.active_object
    material, messages = _apply_without_material(obj)
    assert obj.active_material == material and material.name == "Made-up Skin"
    assert messages[0] == ("'Sphere' had no material: created 'Made-up Skin' with the skin "
                           "preset's Skin Color.")


def _apply_without_material(obj):
    import bpy

    from makeup_skin_addon import material as made_up

    return made_up.apply_to_object(bpy.context, obj, resolution="preview")


@pytest.mark.slow  # a second head: ~1 s
def test_revert_restores_the_previous_surface(head):
    import bpy

    material = head.active_material
    before = tree_state(material)
    apply_operator(head)
    assert bpy.ops.makeup_skin.revert() == {"FINISHED"}
    assert tree_state(material) == before
    assert not material.makeup_skin.is_made_up
    assert bpy.ops.makeup_skin.revert.poll() is False  # nothing left to revert
    apply_operator(head)  # and again: converts once more
    assert group_node(material).inputs["Skin Color"].is_linked
