"""The Blender side of Made-up Skin: the only package that imports bpy.

Each submodule owns its classes and has its own ``register()``/``unregister()``; this package
registers them in the order of :data:`modules` and unregisters them in reverse. Add operators and
panels as new submodules and append them to :data:`modules`.

``lut_baker`` (bpy-free) is reached relatively and lazily, inside the functions that need it::

    from .. import lut_baker
"""

from . import live, operators, properties, scene_fit, ui

__all__ = ["modules", "register", "unregister"]

modules = (properties, operators, ui, live, scene_fit)


def register():
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


def unregister():
    for module in reversed(modules):
        module.unregister()
