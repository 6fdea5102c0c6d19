"""What the add-on's tests do in Blender: apply Made-up Skin (through the operator, as the panel
does, or through the pipeline), render, and read node trees and images back.

- :data:`SPHERE_PX`, :data:`HEAD_PX` -- render sizes of the sphere and the head scenes
  (tests/makeup_skin_addon/conftest.py's ``sphere`` and ``head``).
- :func:`apply_operator` -- ``bpy.ops.makeup_skin.apply()`` on an object with preview tables.
- :func:`apply_pipeline` -- :func:`makeup_skin_addon.material.apply_to_object`; returns the
  material and the warnings it reported.
- :func:`render` -- render the scene to a float EXR and return its RGB pixels.
- :func:`tree_state` -- a material's nodes and links, comparable.
- :func:`group_node` -- a material's Made-up Skin group node.
- :func:`lut_images` -- the add-on's view-angle images.
- :func:`counts` -- how many node groups, images and materials the file holds.
- :func:`session_caches` -- the add-on's session caches (re-baked tables, closure fits).
- :func:`cold_caches` -- empty them: the next Apply bakes and fits.
"""

from __future__ import annotations

from support import sphere_scene

__all__ = ["SPHERE_PX", "HEAD_PX", "apply_operator", "apply_pipeline", "render", "tree_state",
           "group_node", "lut_images", "counts", "session_caches", "cold_caches"]

SPHERE_PX = 64
"""The sphere scene's size (px): Cycles CPU at 16 samples, about 0.3 s a render."""
HEAD_PX = 48
"""The head scene's size (px): Cycles CPU at 16 samples."""


def apply_operator(obj, tier="LAYERED", **settings):
    """Apply through the operator (as the panel does) with preview tables; returns the
    object's active material."""
    import bpy

    values = obj.active_material.makeup_skin
    values.tier, values.resolution = tier, "preview"
    for name, value in settings.items():
        setattr(values, name, value)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.makeup_skin.apply() == {"FINISHED"}
    return obj.active_material


def apply_pipeline(obj, tier="PRINCIPLED", resolution="preview", **settings):
    """Apply through :func:`makeup_skin_addon.material.apply_to_object` (a new material
    ``Skin`` if the object has none): ``(material, messages)``, the operator's reports
    (warnings only)."""
    import bpy

    from makeup_skin_addon import material as made_up

    if obj.active_material is None:
        obj.data.materials.append(bpy.data.materials.new("Skin"))
    values = obj.active_material.makeup_skin
    values.tier = tier
    values.resolution = resolution
    for name, value in settings.items():
        setattr(values, name, value)
    return made_up.apply_to_object(bpy.context, obj)


def render(tmp_path, name="render"):
    """Render the scene to a float EXR and return its RGB pixels (rows bottom-up)."""
    return sphere_scene.render_pixels(tmp_path / f"{name}.exr")


def tree_state(material):
    """Nodes (name, type, parent, location) and links of a material's tree, comparable."""
    tree = material.node_tree
    nodes = sorted((n.name, n.bl_idname, n.parent.name if n.parent else None,
                    tuple(round(v, 3) for v in n.location)) for n in tree.nodes)
    links = sorted((link.from_node.name, link.from_socket.identifier, link.to_node.name,
                    link.to_socket.identifier) for link in tree.links)
    return nodes, links


def group_node(material):
    """The material's Made-up Skin group node."""
    return material.node_tree.nodes["Made-up Skin"]


def lut_images():
    """The add-on's view-angle images in the file."""
    import bpy

    return [image for image in bpy.data.images if image.name.startswith("MakeupSkin LUT")]


def counts():
    """``(node groups, images, materials)`` in the file."""
    import bpy

    return (len(bpy.data.node_groups), len(bpy.data.images), len(bpy.data.materials))


def session_caches() -> dict:
    """The add-on's session caches by name: ``tables`` (re-baked, :mod:`makeup_skin_addon.storage`)
    and ``fits`` (closure fits, :mod:`makeup_skin_addon.fits`), both keyed by bake key."""
    from makeup_skin_addon import fits, storage

    return {"tables": storage._TABLES, "fits": fits._FITS}


def cold_caches():
    """Empty the add-on's session caches: the next Apply bakes and fits (the fixture ``addon``
    carries them over from one test to the next)."""
    for cache in session_caches().values():
        cache.clear()
