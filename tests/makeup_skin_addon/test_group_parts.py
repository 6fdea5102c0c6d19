"""The made-up skin group built as nested parts (makeup_skin_addon.node_algebra.Parts,
makeup_skin_addon.group_parts): no tree over the part size, a rebuild of the same structure
takes the parts again, another structure replaces them, and nothing is left behind when the
group goes.  That the parts compute what one tree would is tests/makeup_skin_addon/
test_node_mix.py's (every tier's group against the tier formulas)."""

import pytest
from support.addon_steps import apply_pipeline


def _part_names(bpy):
    from makeup_skin_addon import group_parts

    return sorted(g.name for g in bpy.data.node_groups if group_parts.PART_KEY in g)


def test_no_tree_of_the_group_is_over_the_part_size(sphere):
    from makeup_skin_addon import group_parts, node_algebra

    material, _ = apply_pipeline(sphere, "LAYERED")
    group = material.node_tree.nodes["Made-up Skin"].node_tree
    parts = group_parts.parts_of(group)
    assert len(parts) > 1  # the Layered group needs several
    assert all(len(tree.nodes) <= node_algebra.PART_NODES for tree in (group, *parts))
    assert all(part.name.startswith(".") for part in parts)  # out of the Add > Group menu
    assert len(group_parts.nodes_of(group)) == len(group.nodes) + sum(
        len(part.nodes) for part in parts)


def test_a_rebuild_takes_the_parts_again_or_replaces_them(addon, blank_scene):
    """The same tier built again into its group takes the same parts (the same datablocks,
    the group's first node too); another tier's build into that group replaces them, the old
    ones removed."""
    import bpy

    from lut_baker import bake
    from lut_baker.closures import fitting
    from lut_baker.model import presets
    from makeup_skin_addon import bakes, group_parts, nodes

    skin = presets.paper()
    tables = bake.bake(skin, "preview")
    fit = fitting.fit_closures(tables, tiers=("LAYERED", "PRINCIPLED"), preview=True)
    record = bakes.bake_record(skin, "preview")
    group = nodes.build_group("LAYERED", record, fit)
    parts = group_parts.parts_of(group)
    assert len(parts) > 1
    group.nodes[0]["first"] = True
    for part in parts:
        part["mark"] = True
    assert nodes.build_group("LAYERED", record, fit, group) == group
    assert group_parts.parts_of(group) == parts and all(p.get("mark") for p in parts)
    assert group.nodes[0].get("first")  # taken again, not rebuilt
    nodes.build_group("PRINCIPLED", record, fit, group)
    assert not group.nodes[0].get("first")  # rebuilt
    for part in parts:  # removed
        with pytest.raises(ReferenceError):
            part.name  # noqa: B018
    left = [g for g in bpy.data.node_groups if group_parts.PART_KEY in g]
    assert left == group_parts.parts_of(group) and not any(p.get("mark") for p in left)


def test_removing_the_group_removes_its_parts(sphere):
    import bpy

    from makeup_skin_addon import group_parts

    apply_pipeline(sphere, "LAYERED")
    assert _part_names(bpy)
    assert bpy.ops.makeup_skin.revert() == {"FINISHED"}
    assert _part_names(bpy) == []
    group = bpy.data.node_groups.new("Made-up Skin test", "ShaderNodeTree")
    part = bpy.data.node_groups.new("Made-up Skin test part 1", "ShaderNodeTree")
    part[group_parts.PART_KEY] = True
    group.nodes.new("ShaderNodeGroup").node_tree = part
    assert group_parts.remove_group(group) == ["Made-up Skin test", "Made-up Skin test part 1"]
    assert _part_names(bpy) == []
