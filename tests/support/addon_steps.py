"""What the add-on's tests do in Blender: apply Made-up Skin (through the operator, as the panel
does, or through the pipeline), render, and read node trees and images back.

- :data:`SPHERE_PX`, :data:`HEAD_PX` -- render sizes of the sphere and the head scenes
  (tests/makeup_skin_addon/conftest.py's ``sphere`` and ``head``).
- :func:`apply_operator` -- ``bpy.ops.makeup_skin.apply()`` on an object with preview tables.
- :func:`apply_pipeline` -- :func:`makeup_skin_addon.apply.apply_to_object`; returns the
  material and the warnings it reported.
- :func:`render` -- render the scene to a float EXR and return its RGB pixels.
- :func:`tree_state` -- a material's nodes and links, comparable.
- :func:`group_node` -- a material's Made-up Skin group node.
- :func:`view_images` -- the add-on's view-angle images.
- :func:`counts` -- how many node groups, images and materials the file holds.
- :func:`session_caches` -- the add-on's session cache (re-baked tables and closure fits).
- :func:`cold_caches` -- empty them: the next Apply bakes and fits.
- :func:`registered_classes` -- the classes of a package registered with Blender.
- :func:`ui_texts` -- every text the add-on's registered classes show (labels, names,
  tooltips), by where it shows.
"""

from __future__ import annotations

from support import sphere_scene

__all__ = ["SPHERE_PX", "HEAD_PX", "apply_operator", "apply_pipeline", "render", "tree_state",
           "group_node", "view_images", "counts", "session_caches", "cold_caches",
           "registered_classes", "ui_texts"]

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
    """Apply through :func:`makeup_skin_addon.apply.apply_to_object` (a new material
    ``Skin`` if the object has none): ``(material, messages)``, the operator's reports
    (warnings only)."""
    import bpy

    from makeup_skin_addon import apply

    if obj.active_material is None:
        obj.data.materials.append(bpy.data.materials.new("Skin"))
    values = obj.active_material.makeup_skin
    values.tier = tier
    values.resolution = resolution
    for name, value in settings.items():
        setattr(values, name, value)
    return apply.apply_to_object(bpy.context, obj)


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


def view_images():
    """The add-on's view-angle images in the file."""
    import bpy

    from makeup_skin_addon.keys import VIEW_IMAGE_PREFIX

    return [image for image in bpy.data.images if image.name.startswith(VIEW_IMAGE_PREFIX)]


def counts():
    """``(node groups, images, materials)`` in the file."""
    import bpy

    return (len(bpy.data.node_groups), len(bpy.data.images), len(bpy.data.materials))


def session_caches() -> dict:
    """The add-on's session caches by name (:mod:`makeup_skin_addon.bakes`): ``bakes``
    (re-baked tables and their closure fits, keyed by bake key), ``slabs`` and ``slab_fits``
    (the slab's tables and fits every thickness shares).  All of them or none: a session
    never has a bake's fit without its slab's, and a test that carried one over without the
    other would see what no session does (a Thickness move fitting again)."""
    from makeup_skin_addon import bakes

    return {"bakes": bakes._BAKES, "slabs": bakes._SLABS, "slab_fits": bakes._SLAB_FITS}


def cold_caches():
    """Empty the add-on's session caches: the next Apply bakes and fits (the fixture ``addon``
    carries them over from one test to the next)."""
    for cache in session_caches().values():
        cache.clear()


def registered_classes(module_prefix: str) -> list:
    """The classes defined under ``module_prefix`` that are registered with Blender
    (operators, panels, menus, property groups, preferences...), walked from ``bpy_struct``'s
    subclasses: a class missing from its module's list is found all the same."""
    import bpy

    found, stack, seen = [], [bpy.types.bpy_struct], set()
    while stack:
        for sub in stack.pop().__subclasses__():
            if sub in seen:
                continue
            seen.add(sub)
            stack.append(sub)
            if sub.__module__.startswith(module_prefix) and getattr(sub, "is_registered", False):
                found.append(sub)
    return found


def _deferred(cls, identifier: str):
    """The ``bpy.props`` definition of ``identifier`` in ``cls`` or a base: its annotation,
    evaluated in its module as Blender does when the annotation is a string (a module with
    ``from __future__ import annotations``)."""
    import sys

    for base in cls.__mro__:
        annotation = vars(base).get("__annotations__", {}).get(identifier)
        if isinstance(annotation, str):
            return eval(annotation, vars(sys.modules[base.__module__]))  # noqa: S307
        if annotation is not None:
            return annotation
    raise LookupError(f"{cls.__name__} defines no property {identifier!r}")


def _property_texts(where: str, cls, rna, inherited) -> list[tuple[str, str, str]]:
    """``(where, kind, text)`` of each property of ``rna`` not in ``inherited`` (Blender's own)
    and not hidden: its name and tooltip, each enum item's name and tooltip (a dynamic enum's
    items from its ``items`` function)."""
    import bpy

    texts = []
    for prop in rna.properties:
        if prop.identifier in inherited or prop.is_hidden:
            continue
        at = f"{where}.{prop.identifier}"
        texts += [(at, "name", prop.name), (at, "description", prop.description)]
        if prop.type != "ENUM":
            continue
        items = [(item.identifier, item.name, item.description) for item in prop.enum_items]
        if not items:  # dynamic: Blender lists its items only for a context
            items = [item[:3] for item in
                     _deferred(cls, prop.identifier).keywords["items"](None, bpy.context)]
        for identifier, name, description in items:
            texts += [(f"{at}[{identifier}]", "name", name),
                      (f"{at}[{identifier}]", "description", description)]
    return texts


def ui_texts(module_prefix: str = "makeup_skin_addon") -> list[tuple[str, str, str]]:
    """``(where, kind, text)`` for every text the classes registered from ``module_prefix``
    show: each operator's label and tooltip (a dynamic one for each value of its enum
    properties) and its properties, each panel's and menu's label and tooltip, each property
    group's properties, and the pointers they are registered under on Blender's types.
    ``kind`` is ``label``, ``description`` or ``name``."""
    import bpy

    texts = []
    for cls in registered_classes(module_prefix):
        if issubclass(cls, bpy.types.Operator):
            module, _, name = cls.bl_idname.partition(".")
            rna = getattr(getattr(bpy.ops, module), name).get_rna_type()
            texts += [(cls.bl_idname, "label", rna.name),
                      (cls.bl_idname, "description", rna.description)]
            texts += _property_texts(cls.bl_idname, cls, rna, {"rna_type"})
            if "description" in vars(cls):  # a tooltip that depends on the properties
                for prop in rna.properties:
                    for item in prop.enum_items if prop.type == "ENUM" else ():
                        values = type("Properties", (), {prop.identifier: item.identifier})
                        texts.append((f"{cls.bl_idname}({item.identifier})", "description",
                                      cls.description(bpy.context, values)))
        elif issubclass(cls, (bpy.types.Panel, bpy.types.Menu)):
            texts += [(cls.__name__, "label", cls.bl_label),
                      (cls.__name__, "description", getattr(cls, "bl_description", ""))]
        elif issubclass(cls, bpy.types.PropertyGroup):
            inherited = {p.identifier for p in bpy.types.PropertyGroup.bl_rna.properties}
            texts += _property_texts(cls.__name__, cls, cls.bl_rna, inherited)
            for owner in (bpy.types.ID, bpy.types.Material, bpy.types.Object, bpy.types.Scene,
                          bpy.types.WindowManager):
                texts += [(f"{owner.__name__}.{p.identifier}", kind, getattr(p, kind))
                          for p in owner.bl_rna.properties if p.type == "POINTER"
                          and p.fixed_type.identifier == cls.bl_rna.identifier
                          for kind in ("name", "description")]
        else:  # a kind of class this walk does not know: say so rather than skip it
            texts.append((cls.__name__, "unknown kind of class", ""))
    return texts
