"""Nodes inside the artist's groups brought out into the material's tree
(makeup_skin_addon.node_copy): copies with the same settings and values, a Group Input resolved
to what feeds the group node outside, a nested group node pointing at the same group, every copy
marked as the add-on's own, the artist's group unchanged."""

import pytest


def _group_with_texture():
    """A group: Image Texture (Closest, Mirror) -> Mix (multiply by the group's Tint input) ->
    a nested group (Gamma 2) -> Principled Base Color."""
    import bpy

    nested = bpy.data.node_groups.new("Gamma", "ShaderNodeTree")
    nested.interface.new_socket("In", in_out="INPUT", socket_type="NodeSocketColor")
    nested.interface.new_socket("Out", in_out="OUTPUT", socket_type="NodeSocketColor")
    n_in, n_out = nested.nodes.new("NodeGroupInput"), nested.nodes.new("NodeGroupOutput")
    gamma = nested.nodes.new("ShaderNodeGamma")
    gamma.inputs["Gamma"].default_value = 2.0
    nested.links.new(n_in.outputs["In"], gamma.inputs["Color"])
    nested.links.new(gamma.outputs["Color"], n_out.inputs["Out"])

    group = bpy.data.node_groups.new("Artist Skin", "ShaderNodeTree")
    group.interface.new_socket("Tint", in_out="INPUT", socket_type="NodeSocketColor")
    group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    inputs, outputs = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    texture = group.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.new("Albedo", 4, 4)
    texture.interpolation, texture.extension = "Closest", "MIRROR"
    mix = group.nodes.new("ShaderNodeMix")
    mix.data_type, mix.blend_type = "RGBA", "MULTIPLY"
    inner = group.nodes.new("ShaderNodeGroup")
    inner.node_tree = nested
    principled = group.nodes.new("ShaderNodeBsdfPrincipled")
    colour = next(s for s in mix.inputs if s.identifier == "A_Color")
    group.links.new(texture.outputs["Color"], colour)
    group.links.new(inputs.outputs["Tint"], next(s for s in mix.inputs
                                                 if s.identifier == "B_Color"))
    group.links.new(next(s for s in mix.outputs if s.identifier == "Result_Color"),
                    inner.inputs["In"])
    group.links.new(inner.outputs["Out"], principled.inputs["Base Color"])
    group.links.new(principled.outputs[0], outputs.inputs[0])
    return group, principled


def _material_with(group):
    """A new material whose tree holds a node of ``group``: ``(tree, group node)``."""
    import bpy

    material = bpy.data.materials.new("Skin")
    if material.node_tree is None:
        material.use_nodes = True
    tree = material.node_tree
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    return tree, node


def _state(group):
    return (sorted((n.name, n.bl_idname) for n in group.nodes),
            sorted((link.from_node.name, link.to_node.name) for link in group.links))


def test_bring_out_copies_the_nodes_and_resolves_the_group_input(addon, blank_scene):
    import bpy

    from makeup_skin_addon import artist_shader, node_copy

    group, principled = _group_with_texture()
    tree, node = _material_with(group)
    rgb = tree.nodes.new("ShaderNodeRGB")
    tree.links.new(rgb.outputs[0], node.inputs["Tint"])
    before = _state(group), _state(group.nodes["Group"].node_tree)
    where = artist_shader.source(principled.inputs["Base Color"], (node,))
    assert where.inside_group
    out = node_copy.bring_out(where, tree)
    assert out.node.id_data == tree and out.node.type == "GROUP"
    assert out.node.node_tree == group.nodes["Group"].node_tree  # the nested group, shared
    mix = out.node.inputs["In"].links[0].from_node
    assert mix.blend_type == "MULTIPLY"
    texture = next(s for s in mix.inputs if s.identifier == "A_Color").links[0].from_node
    assert (texture.type, texture.interpolation, texture.extension) == ("TEX_IMAGE", "Closest",
                                                                         "MIRROR")
    assert texture.image == bpy.data.images["Albedo"]
    assert next(s for s in mix.inputs if s.identifier == "B_Color").links[0].from_node == rgb
    assert all(n.get("makeup_skin_owned") for n in (out.node, mix, texture))
    assert (_state(group), _state(group.nodes["Group"].node_tree)) == before


def test_a_copier_copies_each_node_once(addon, blank_scene):

    from makeup_skin_addon import artist_shader, node_copy

    group, principled = _group_with_texture()
    group.links.new(group.nodes["Image Texture"].outputs["Alpha"],
                    principled.inputs["Roughness"])
    tree, node = _material_with(group)
    copier = node_copy.copier(tree)
    base = node_copy.bring_out(artist_shader.source(principled.inputs["Base Color"], (node,)),
                               tree, copier=copier)
    roughness = node_copy.bring_out(artist_shader.source(principled.inputs["Roughness"],
                                                         (node,)), tree, copier=copier)
    assert roughness.node.type == "TEX_IMAGE"
    assert sum(1 for n in tree.nodes if n.type == "TEX_IMAGE") == 1
    assert base.node != roughness.node


def test_copy_node_keeps_a_ramp(addon, blank_scene):
    import bpy

    from makeup_skin_addon import node_copy

    group = bpy.data.node_groups.new("Ramps", "ShaderNodeTree")
    ramp = group.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.interpolation = "CONSTANT"
    ramp.color_ramp.elements.new(0.3).color = (0.2, 0.5, 0.1, 1.0)
    into = bpy.data.node_groups.new("Into", "ShaderNodeTree")
    copy = node_copy.copy_node(ramp, into)
    assert copy.color_ramp.interpolation == "CONSTANT"
    assert [round(e.position, 6) for e in copy.color_ramp.elements] == [0.0, 0.3, 1.0]
    assert tuple(copy.color_ramp.elements[1].color) == pytest.approx((0.2, 0.5, 0.1, 1.0))
