"""The nested groups a made-up skin group is built as (:class:`.node_algebra.Parts`): how they
are told apart from any other group, and removed with the group.

- :data:`PART_KEY` -- the custom property that marks a part.
- :func:`part_holders` -- the group nodes holding them; :func:`parts_of` -- the parts nested in
  a group.
- :func:`remove_parts` -- remove those nothing uses any more; :func:`remove_group` -- a group
  with its parts.
- :func:`nodes_of` -- the nodes of a group and of its parts.
"""

from __future__ import annotations

import bpy

__all__ = ["PART_KEY", "part_holders", "parts_of", "remove_parts", "remove_group", "nodes_of"]

PART_KEY = "makeup_skin_part"
"""A part's custom property: it marks the add-on's nested groups."""


def part_holders(tree) -> list:
    """The group nodes of ``tree`` that hold its parts, in the order they were made."""
    return [node for node in tree.nodes if node.type == "GROUP"
            and node.node_tree is not None and PART_KEY in node.node_tree]


def parts_of(tree) -> list:
    """The part groups nested in ``tree``, in the order they were made."""
    return [node.node_tree for node in part_holders(tree)]


def remove_parts(parts) -> list[str]:
    """Remove the part groups ``parts`` that nothing uses any more; their names."""
    unused = [part for part in parts if part.users == 0]
    names = [part.name for part in unused]
    for part in unused:
        bpy.data.node_groups.remove(part)
    return names


def remove_group(tree) -> list[str]:
    """Remove the group ``tree`` and the parts nested in it that nothing else uses; the names
    removed."""
    parts, name = parts_of(tree), tree.name
    bpy.data.node_groups.remove(tree)
    return [name, *remove_parts(parts)]


def nodes_of(tree) -> list:
    """The nodes of ``tree`` and of the parts nested in it."""
    return [*tree.nodes, *(node for part in parts_of(tree) for node in part.nodes)]
