"""Made-up Skin: Blender extension entry point.

Blender loads this file because it sits next to ``blender_manifest.toml``; it only forwards
``register``/``unregister`` to ``makeup_skin_addon``, where the add-on lives (the bpy-free maths
is ``lut_baker``). Imports must stay relative: installed, this package is
``bl_ext.<repo>.makeup_skin``.

The import happens on call, not at import time, so that importing this file never loads bpy:
pytest imports it when collecting the repository (the root folder is a package to pytest), and
tests of ``lut_baker`` must run without bpy.
"""

__all__ = ["register", "unregister"]


def register():
    from .makeup_skin_addon import register

    register()


def unregister():
    from .makeup_skin_addon import unregister

    unregister()
