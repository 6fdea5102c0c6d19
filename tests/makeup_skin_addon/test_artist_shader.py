"""The artist's surface shader read as a tree (makeup_skin_addon.artist_shader): Mix and Add
Shaders, node groups entered and left through their outputs and inputs, reroutes, the role of
each leaf, the shares of the leaves, where an input's value comes from, and Blender's untouched
default Principled BSDF told apart from an artist's."""

import pytest


def _material():
    import bpy

    material = bpy.data.materials.new("Skin")
    if material.node_tree is None:
        material.use_nodes = True
    return material


def test_an_untouched_default_is_no_shader_of_the_artists(addon, blank_scene):
    from makeup_skin_addon import artist_shader

    material = _material()
    principled = next(n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    assert artist_shader.is_untouched_default(principled)
    assert artist_shader.read(material) is None
    principled.inputs["Roughness"].default_value = 0.45
    assert not artist_shader.is_untouched_default(principled)
    tree = artist_shader.read(material)
    assert isinstance(tree, artist_shader.Leaf) and tree.node == principled
    assert tree.role == "skin" and tree.groups == ()


def test_mixes_adds_groups_and_reroutes(addon, blank_scene):
    """Output <- Mix (0.25) of [a reroute to a Principled] and [a node group whose output is
    Add(Glossy, Emission)]: the tree, the leaves' roles and their shares."""
    import bpy

    from makeup_skin_addon import artist_shader

    material = _material()
    tree = material.node_tree
    output = tree.get_output_node("ALL")
    principled = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    reroute = tree.nodes.new("NodeReroute")
    tree.links.new(principled.outputs[0], reroute.inputs[0])
    group = bpy.data.node_groups.new("Sheen", "ShaderNodeTree")
    group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    inner_out = group.nodes.new("NodeGroupOutput")
    add = group.nodes.new("ShaderNodeAddShader")
    glossy = group.nodes.new("ShaderNodeBsdfGlossy")
    emission = group.nodes.new("ShaderNodeEmission")
    group.links.new(glossy.outputs[0], add.inputs[0])
    group.links.new(emission.outputs[0], add.inputs[1])
    group.links.new(add.outputs[0], inner_out.inputs[0])
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs[0].default_value = 0.25
    tree.links.new(reroute.outputs[0], mix.inputs[1])
    tree.links.new(node.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    shader = artist_shader.read(material)
    assert isinstance(shader, artist_shader.Mix) and shader.factor.value == pytest.approx(0.25)
    assert isinstance(shader.second, artist_shader.Add)
    assert shader.second.groups == (node,)
    leaves = artist_shader.leaves(shader, lambda source: 0.5)
    assert [(leaf.node.name, leaf.role, round(share, 6)) for leaf, share in leaves] == [
        (principled.name, "skin", 0.75), (glossy.name, "gloss", 0.25),
        (emission.name, "other", 0.25)]
    assert leaves[1][0].groups == (node,)


def test_a_linked_factor_counts_by_its_mean(addon, blank_scene):
    from makeup_skin_addon import artist_shader

    material = _material()
    tree = material.node_tree
    output = tree.get_output_node("ALL")
    principled = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    value = tree.nodes.new("ShaderNodeValue")
    mix = tree.nodes.new("ShaderNodeMixShader")
    tree.links.new(value.outputs[0], mix.inputs[0])
    tree.links.new(principled.outputs[0], mix.inputs[1])
    tree.links.new(diffuse.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    shader = artist_shader.read(material)
    assert shader.factor.linked and shader.factor.socket == value.outputs[0]
    shares = [share for _, share in artist_shader.leaves(shader, lambda source: 0.8)]
    assert shares == pytest.approx([0.2, 0.8])
    shares = [share for _, share in artist_shader.leaves(shader, lambda source: 1.7)]
    assert shares == pytest.approx([1.0])  # clamped: the first input has no share left


def test_a_source_is_followed_out_of_groups(addon, blank_scene):
    """An input inside a group fed by the Group Input: its source is what feeds the group
    node's input outside (a link, or the outer value); a node inside the group is a socket of
    the group's tree with the groups entered."""
    import bpy

    from makeup_skin_addon import artist_shader

    material = _material()
    tree = material.node_tree
    group = bpy.data.node_groups.new("Skin", "ShaderNodeTree")
    group.interface.new_socket("Albedo", in_out="INPUT", socket_type="NodeSocketColor")
    group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    inputs, outputs = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    inner = group.nodes.new("ShaderNodeBsdfPrincipled")
    rgb = group.nodes.new("ShaderNodeRGB")
    group.links.new(inputs.outputs["Albedo"], inner.inputs["Base Color"])
    group.links.new(rgb.outputs[0], inner.inputs["Normal"])  # any linked input inside
    group.links.new(inner.outputs[0], outputs.inputs[0])
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    tree.links.new(node.outputs[0], tree.get_output_node("ALL").inputs["Surface"])
    node.inputs["Albedo"].default_value = (0.6, 0.4, 0.3, 1.0)
    leaf = artist_shader.read(material)
    base = artist_shader.source(inner.inputs["Base Color"], leaf.groups)
    assert not base.linked and base.value == pytest.approx((0.6, 0.4, 0.3, 1.0))
    texture = tree.nodes.new("ShaderNodeTexImage")
    tree.links.new(texture.outputs["Color"], node.inputs["Albedo"])
    base = artist_shader.source(inner.inputs["Base Color"], leaf.groups)
    assert base.socket == texture.outputs["Color"] and base.groups == ()
    normal = artist_shader.source(inner.inputs["Normal"], leaf.groups)
    assert normal.inside_group and normal.socket.node == rgb and normal.groups == (node,)
