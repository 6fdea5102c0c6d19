"""Made-up Skin over the artist's own material (makeup_skin_addon.convert), on the textured head
of tests/support/character.py: Apply keeps the artist's shader as the bare skin (linked into
the group's Skin Shader), feeds the skin under the film from it (its Base Color's source scaled
by what the shader renders of it, mixed as its Mix Shaders mix, brought out of node groups by
copies, the artist's groups untouched), its normal map and a weaker copy for the film, says
what it could not follow; a material without a shader of the artist's gets the skin preset;
Revert restores the tree."""

import numpy as np
import pytest
from support.addon_steps import apply_operator, apply_pipeline, group_node, tree_state


def _owned(material):
    return [n for n in material.node_tree.nodes if n.get("makeup_skin_owned")]


def _body_colour_node(group):
    """The node feeding the group's Skin Color (the skin under the film's body color)."""
    return group.inputs["Skin Color"].links[0].from_node


def _input(node, identifier):
    return next(s for s in node.inputs if s.identifier == identifier)


def test_apply_goes_over_the_artists_shader(head):
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
    # The artist's shader is the bare skin: linked, unframed, its own links intact.
    assert group.inputs["Skin Shader"].links[0].from_node == principled
    assert principled.parent is None
    assert principled.inputs["Base Color"].links[0].from_socket == albedo
    # Under the film: the albedo texture times what the shader renders of it (a Mix node,
    # multiply, its factor the body color over the Base Color: below 1, about 0.9-1).
    body = _body_colour_node(group)
    assert body.get("makeup_skin_owned") and body.blend_type == "MULTIPLY"
    assert _input(body, "A_Color").links[0].from_socket == albedo
    factor = np.array(_input(body, "B_Color").default_value[:3])
    assert np.all((factor > 0.7) & (factor < 1.0)), factor
    assert group.inputs["Normal"].links[0].from_socket == normal
    radius = np.array(principled.inputs["Subsurface Radius"].default_value)
    scale = principled.inputs["Subsurface Scale"].default_value
    np.testing.assert_allclose(group.inputs["Subsurface Radius"].default_value, radius * scale,
                               rtol=1e-6)
    assert group.inputs["Subsurface Weight"].default_value == pytest.approx(
        principled.inputs["Subsurface Weight"].default_value)
    # The film gets a copy of the skin's Normal Map at half its strength (pores softened).
    film = group.inputs["Film Normal"].links[0].from_node
    assert film.name == "Made-up Skin Film Normal" and film.type == "NORMAL_MAP"
    skin_map = normal.node
    colour = skin_map.inputs["Color"].links[0].from_socket
    assert film.inputs["Color"].links[0].from_socket == colour
    assert film.inputs["Strength"].default_value == pytest.approx(
        0.5 * skin_map.inputs["Strength"].default_value, rel=1e-6)


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


def test_behind_a_mix_shader_the_skin_under_the_film_mixes_as_the_shader_does(head):
    """Principled + 10% Translucent: the skin under the film is the Principled's body color
    at 90% (the translucency is rendered bare, not followed under the film: a warning)."""
    material = head.active_material
    albedo, normal = _skin_shader_tree(material, "mix")
    material, report = apply_pipeline(head, tier="LAYERED")
    group = group_node(material)
    assert group.inputs["Skin Shader"].links[0].from_node.type == "MIX_SHADER"
    mix = _body_colour_node(group)
    assert mix.blend_type == "MIX"
    assert _input(mix, "Factor_Float").default_value == pytest.approx(0.1)
    body = _input(mix, "A_Color").links[0].from_node
    assert _input(body, "A_Color").links[0].from_socket == albedo
    assert tuple(_input(mix, "B_Color").default_value)[:3] == (0.0, 0.0, 0.0)
    assert group.inputs["Normal"].links[0].from_socket == normal
    assert [w for w in report.warnings if "Translucent" in w and "weight 0.1 " in w]


def test_inside_a_node_group_what_feeds_the_skin_is_followed(head):
    """The Principled inside the artist's node group, its Base Color and Normal from the
    group's inputs linked outside: followed out to the albedo and the normal map."""
    material = head.active_material
    albedo, normal = _skin_shader_tree(material, "group")
    material, report = apply_pipeline(head, tier="LAYERED")
    group = group_node(material)
    assert _input(_body_colour_node(group), "A_Color").links[0].from_socket == albedo
    assert group.inputs["Normal"].links[0].from_socket == normal
    assert not report.warnings


def test_a_texture_inside_the_artists_group_is_copied_out_and_the_group_untouched(head):
    import bpy

    material = head.active_material
    _skin_shader_tree(material, "inside")
    artist_group = bpy.data.node_groups["Skin Shader"]
    inside = sorted((n.name, n.bl_idname) for n in artist_group.nodes), len(artist_group.links)
    material, report = apply_pipeline(head, tier="LAYERED")
    assert (sorted((n.name, n.bl_idname) for n in artist_group.nodes),
            len(artist_group.links)) == inside
    copy = _input(_body_colour_node(group_node(material)), "A_Color").links[0].from_node
    assert copy.type == "TEX_IMAGE" and copy.get("makeup_skin_owned")
    assert copy.image == material.node_tree.nodes["Albedo"].image
    assert copy.parent is not None and copy.parent.name == "Made-up Skin: skin under the film"
    assert not report.warnings


def test_an_unlinked_base_colour_gives_a_value(head):
    """Base Color (0.6, 0.4, 0.3) unlinked: the skin under the film is a value, that color
    times what the shader renders of it."""
    from makeup_skin_addon import artist_skin

    material = head.active_material
    _skin_shader_tree(material, "value")
    reading = artist_skin.read_material(material)
    material, _ = apply_pipeline(head, tier="LAYERED")
    group = group_node(material)
    assert not group.inputs["Skin Color"].is_linked
    np.testing.assert_allclose(group.inputs["Skin Color"].default_value[:3], reading.body,
                               rtol=1e-6)
    np.testing.assert_allclose(reading.leaves[0].base, (0.6, 0.4, 0.3), rtol=1e-6)


def test_a_shader_without_skin_is_kept_and_named(head):
    """An Emission alone: it stays the bare skin; the skin under the film is the skin preset's,
    and the report warns and says so."""
    material = head.active_material
    _skin_shader_tree(material, "emission")
    material, report = apply_pipeline(head, tier="LAYERED")
    group = group_node(material)
    assert group.inputs["Skin Shader"].links[0].from_node.type == "EMISSION"
    assert any("no skin BSDF" in w and "skin preset" in w for w in report.warnings)


def test_what_the_match_cannot_evaluate_is_a_warning(head):
    """A Noise Texture mixed into the Base Color: the render follows it (linked), the match
    takes it as 0.5, and the report warns so (counted with what was not carried over)."""
    material = head.active_material
    tree = material.node_tree
    principled = tree.nodes["Principled BSDF"]
    noise = tree.nodes.new("ShaderNodeTexNoise")
    mix = tree.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    tree.links.new(principled.inputs["Base Color"].links[0].from_socket, mix.inputs[6])
    tree.links.new(noise.outputs["Color"], mix.inputs[7])
    tree.links.new(mix.outputs[2], principled.inputs["Base Color"])
    _, report = apply_pipeline(head, tier="LAYERED")
    assert [w for w in report.warnings if w.startswith("Not followed by the match")] == [
        f"Not followed by the match: {noise.name!r} (Noise Texture) is not evaluated: taken as "
        f"0.5 (the shade is matched as if so; the made-up skin renders the shader as it is)"]


def test_an_object_without_material_gets_one_and_is_told(addon, blank_scene):
    import bpy

    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.03)
    obj = bpy.context.active_object
    material, messages = _apply_without_material(obj)
    assert obj.active_material == material and material.name == "Made-up Skin"
    assert messages[0] == ("'Sphere' had no material: created 'Made-up Skin' with the skin "
                           "preset's Skin Color.")
    assert "Skin Shader" not in group_node(material).inputs  # the preset's bare skin


def test_blenders_untouched_default_shader_is_no_skin_of_the_artists(addon, blank_scene):
    """A new material's own Principled BSDF, untouched: the skin preset's made-up skin, the
    default shader kept framed and disconnected."""
    import bpy

    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.03)
    obj = bpy.context.active_object
    material, _ = apply_pipeline(obj, tier="LAYERED")
    group = group_node(material)
    assert "Skin Shader" not in group.inputs
    principled = next(n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    assert not principled.outputs[0].is_linked and principled.parent is not None


def _eevee() -> str:
    import bpy

    return "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else "BLENDER_EEVEE_NEXT"


def test_an_output_for_each_engine_the_scenes_is_made_up_the_other_kept(head):
    """A material with an output for Cycles (the textured Principled) and one for EEVEE alone
    (a Diffuse BSDF): Apply in an EEVEE scene goes over EEVEE's output, the Cycles output keeps
    its shader and the report warns, naming it; Apply again in a Cycles scene keeps to the
    output it made up (the Cycles output's link untouched); Revert gives the tree back."""
    import bpy

    material = head.active_material
    tree = material.node_tree
    cycles = tree.get_output_node("ALL")
    cycles.target = "CYCLES"
    principled = cycles.inputs["Surface"].links[0].from_node
    eevee = tree.nodes.new("ShaderNodeOutputMaterial")
    eevee.target = "EEVEE"
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.6, 0.35, 0.25, 1.0)
    tree.links.new(diffuse.outputs[0], eevee.inputs["Surface"])
    before = tree_state(material)
    bpy.context.scene.render.engine = _eevee()
    _, report = apply_pipeline(head, tier="LAYERED")
    group = group_node(material)
    assert eevee.inputs["Surface"].links[0].from_node == group
    assert group.inputs["Skin Shader"].links[0].from_node == diffuse
    assert cycles.inputs["Surface"].links[0].from_node == principled
    assert any(repr(cycles.name) in w and "Cycles renders" in w for w in report.warnings), \
        report.warnings
    bpy.context.scene.render.engine = "CYCLES"
    _, report = apply_pipeline(head, tier="LAYERED")
    assert eevee.inputs["Surface"].links[0].from_node == group
    assert cycles.inputs["Surface"].links[0].from_node == principled
    assert any(repr(cycles.name) in w and "the one EEVEE renders" in w
               for w in report.warnings), report.warnings
    assert bpy.ops.makeup_skin.revert() == {"FINISHED"}
    assert tree_state(material) == before


def _apply_without_material(obj):
    import bpy

    from makeup_skin_addon import apply

    return apply.apply_to_object(bpy.context, obj, resolution="preview")


@pytest.mark.slow  # a second head: ~1 s
def test_revert_restores_the_previous_surface(head):
    import bpy

    material = head.active_material
    before = tree_state(material)
    apply_operator(head)
    assert _owned(material)
    assert bpy.ops.makeup_skin.revert() == {"FINISHED"}
    assert tree_state(material) == before
    assert not material.makeup_skin.is_made_up and not _owned(material)
    assert bpy.ops.makeup_skin.revert.poll() is False  # nothing left to revert
    apply_operator(head)  # and again: converts once more
    assert group_node(material).inputs["Skin Color"].is_linked
