"""The Blender side of Made-up Skin: the only package that imports bpy.

The modules form layers, lowest first; a module imports add-on modules only from layers below
its own, and only at module level (no import inside a function, no cycle):

1. ``keys`` -- every name stored in users' files: custom-property keys, node group, node, frame,
   material and image names, the ``bl_idname`` prefixes, the presets folder (no bpy).
2. ``package`` -- the add-on's package names, and whether it runs installed (no bpy).
   ``core`` -- lut_baker's runtime modules, imported by ordinary statements, from beside the
   add-on when installed, top level from a checkout (no bpy).  ``progress`` -- where a slow
   step's progress goes.
3. The artist's material: ``artist_shader`` (its shader read as a tree), ``node_maths`` and
   ``surface_values`` (what feeds an input, evaluated with numpy), ``node_copy``,
   ``skin_nodes`` and ``convert`` (the material converted in place and back).
4. The session's bakes: ``storage`` (the images the .blend keeps, their hashes), ``bakes`` (a
   bake's key and record, one cache of tables and closure fits, :class:`.bakes.Bake`).
5. The skin: ``face_geometry`` (the faces' areas and normals as Blender's),
   ``surface_points``, ``image_texels`` and ``skin_sampling`` (an image's mean over a
   material's faces), ``sky_visibility`` (what the mesh hides of a uniform sky from its
   skin), ``skin_colour`` (the skin preset's own colour), ``artist_skin`` (the
   skin the artist's shader describes), ``shade`` and ``skin_model`` (the settings as the
   model), ``matching`` (Match Skin, Lighter / Darker).
6. The group: ``node_algebra`` and ``nodes`` (built from closure fits), ``tier_choice`` (the
   tiers fitted, Tier Auto's choice, Fit to Scene's settings), ``groups`` (reused or built,
   made a material's surface), ``rebuild`` (from the settings, in steps).
7. ``apply`` -- Apply step by step, Revert, Check Tables.
8. ``live`` -- the live preview: socket updates at once, rebuilds on a worker thread.
9. ``on_load`` -- on opening a file, older settings upgraded and the made-up materials'
   images checked (packed bytes' hashes) and repaired before the first render (a
   ``load_post`` handler).
10. ``properties`` -- the panel's settings (PropertyGroup); their ``update=`` callbacks call
    ``live``.
11. ``operators`` -- Apply, Revert, Check Tables, Fit to Scene, Match Skin, Lighter / Darker,
    the preset menu and its operator.
12. ``ui`` -- the panels: settings, buttons, the group's record and errors, Fit to Scene, a
    repair on opening.

The exact order is ``tools/check_imports.py``'s; docs/architecture.md follows Foundation from
the panel to the node group through them.

This package (the top) registers the modules with classes or session state in that order
(:data:`modules`) and unregisters them in reverse.  A new operator goes into ``operators``, a
new panel or section into ``ui``; a new module takes its own place in the list above.

:func:`register` also registers :func:`unregister` with :mod:`atexit` (and :func:`unregister`
drops it): pip ``bpy`` 4.5 hangs at interpreter exit while any class, app handler or timer is
still registered, so a pipeline script that imports bpy and registers the add-on without ever
unregistering it would never end.  In Blender itself add-ons are disabled before Python
finalizes, and the hook goes with them.  :func:`unregister` does nothing when the add-on is not
registered: enabled as an extension in pip ``bpy``, the hook unregisters it and then Blender's
own exit disables it again.
"""

import atexit

from . import live, on_load, operators, properties, tier_choice, ui

__all__ = ["modules", "register", "unregister"]

modules = (tier_choice, live, on_load, properties, operators, ui)

_registered = False
"""Whether :func:`register` ran and :func:`unregister` has not since."""


def register():
    global _registered
    if _registered:
        return
    done = []
    try:
        for module in modules:
            module.register()
            done.append(module)
    except Exception:
        # Leave Blender as it was: a half-registered add-on cannot be disabled cleanly.
        for module in reversed(done):
            module.unregister()
        raise
    _registered = True
    atexit.register(unregister)


def unregister():
    """Unregister every module, in reverse; each is tried even if one before it fails (what is
    left registered hangs bpy 4.5 at exit), then the first error is raised.  Not registered:
    nothing to do."""
    global _registered
    atexit.unregister(unregister)
    if not _registered:
        return
    _registered = False
    first_error = None
    for module in reversed(modules):
        try:
            module.unregister()
        except Exception as error:  # noqa: BLE001 - raised below, after the others
            first_error = first_error or error
    if first_error is not None:
        raise first_error
