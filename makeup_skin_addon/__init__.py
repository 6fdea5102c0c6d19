"""The Blender side of Made-up Skin: the only package that imports bpy.

The modules form layers, lowest first; a module imports add-on modules only from layers below
its own, and only at module level (no import inside a function, no cycle):

1. ``keys`` -- every name stored in users' files: custom-property keys, node group, node, frame,
   material and image names, the ``bl_idname`` prefixes, the presets folder (no bpy).
2. ``package`` -- the add-on's package names, and whether it runs installed (no bpy).
   ``core`` -- lut_baker's runtime modules, imported by ordinary statements, from beside the
   add-on when installed, top level from a checkout (no bpy).
3. ``convert`` -- the artist's material converted in place and back (install, revert): the
   skin shader followed through mixes and groups, its albedo, normal and film normal carried.
4. ``storage`` -- what the .blend keeps: bake records, re-bakes, packed images and their hashes.
   ``fits`` -- the session's tables and closure fits by bake key.
   ``skin_sampling`` -- the mean of an image over a material's surface (points on its faces,
   the image reduced), cached per mesh and per image.
   ``shade`` -- the settings as the model (roughness, IOR), the colour seen, the skin's own
   colour, Match Skin and the shade steps.
5. ``nodes`` -- the node groups built from closure fits, and their records.
6. ``scene_fit`` -- the scene and the material as the Auto tier sees them, the choice, and its
   settings (units per mm, Auto tier, Fit to Scene's settings and record).
7. ``material`` -- the apply pipeline: Apply, Revert, Check Tables, the rebuild from settings.
8. ``live`` -- the live preview: socket updates at once, debounced preview re-bakes.
9. ``on_load`` -- on opening a file, older settings upgraded and the made-up materials'
   images checked (packed bytes' hashes) and repaired before the first render (a
   ``load_post`` handler).
10. ``properties`` -- the panel's settings (PropertyGroup); their ``update=`` callbacks call
    ``live``.
11. ``operators`` -- Apply, Revert, Check Tables, Fit to Scene, Match Skin, Lighter / Darker,
    the preset menu and its operator.
12. ``ui`` -- the panels: settings, buttons, the group's record and errors, Fit to Scene, a
    repair on opening.

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

from . import live, on_load, operators, properties, scene_fit, ui

__all__ = ["modules", "register", "unregister"]

modules = (scene_fit, live, on_load, properties, operators, ui)

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
