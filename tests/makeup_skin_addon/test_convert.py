"""Made-up Skin in the artist's own material (makeup_skin_addon.convert), on the textured head
of tests/support/character.py: Apply converts the material in place and carries the
albedo and the normal map over; Revert restores it."""

import pytest
from support.addon_steps import apply_operator, group_node, tree_state


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
    assert not group.inputs["Film Normal"].is_linked  # foundation fills the pores


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
