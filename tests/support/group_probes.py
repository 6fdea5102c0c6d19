"""Probes of a made-up skin group for tests: a copy of the group with copies of the parts it
is built as (makeup_skin_addon.node_algebra.Parts), edited to output what a test reads.

- :func:`copy_with_parts` -- the copy, its edits kept from the group.
- :func:`to_output` -- link a shader socket of the copy or of one of its parts to its output.
"""

from __future__ import annotations

__all__ = ["copy_with_parts", "to_output"]


def copy_with_parts(group, name):
    """A copy of ``group`` with copies of the parts it is built as, so that a probe's edits
    stay in the probe."""
    from makeup_skin_addon import group_parts

    probe = group.copy()
    probe.name = name
    for holder in probe.nodes:
        if holder.type == "GROUP" and holder.node_tree in group_parts.parts_of(group):
            holder.node_tree = holder.node_tree.copy()
    return probe


def to_output(probe, shader):
    """Link the shader output socket ``shader`` (of the probe or of one of its parts) to the
    probe's Group Output."""
    output = next(node for node in probe.nodes if node.type == "GROUP_OUTPUT")
    part = shader.id_data
    if part != probe:
        item = part.interface.new_socket("probe", in_out="OUTPUT",
                                         socket_type="NodeSocketShader")
        inner = next(node for node in part.nodes if node.type == "GROUP_OUTPUT")
        part.links.new(shader, next(s for s in inner.inputs if s.identifier == item.identifier))
        holder = next(node for node in probe.nodes if node.type == "GROUP"
                      and node.node_tree == part)
        shader = next(s for s in holder.outputs if s.identifier == item.identifier)
    probe.links.new(shader, output.inputs["Shader"])
