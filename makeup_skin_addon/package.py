"""Names of the installed packages, without bpy.

Installed as an extension the add-on is ``bl_ext.<repo>.makeup_skin.makeup_skin_addon``; as a
legacy add-on folder it is ``makeup_skin.makeup_skin_addon``. Blender identifies the add-on (its
preferences, ``bpy.utils.extension_path_user``) by the *root* package, the parent of this one.

- :data:`ADDON_PACKAGE` -- this package's full dotted name.
- :func:`root_package` -- the parent package name of a dotted package name.
- :data:`ROOT_PACKAGE` -- the add-on's root package, e.g. ``bl_ext.user_default.makeup_skin``.
- :data:`INSTALLED` -- whether the add-on runs inside its extension package (``lut_baker`` is
  then its sibling, imported relatively by :mod:`.core`) or from a source checkout, where
  ``makeup_skin_addon`` and ``lut_baker`` are both top level (the tests, the tools).
"""

__all__ = ["ADDON_PACKAGE", "ROOT_PACKAGE", "INSTALLED", "root_package"]


def root_package(addon_package: str) -> str:
    """Return the parent of a dotted package name, or the name itself at top level.

    Examples
    --------
    >>> root_package("bl_ext.user_default.makeup_skin.makeup_skin_addon")
    'bl_ext.user_default.makeup_skin'
    >>> root_package("makeup_skin_addon")
    'makeup_skin_addon'
    """
    parent, _, _ = addon_package.rpartition(".")
    return parent or addon_package


ADDON_PACKAGE: str = __package__ or __name__.rpartition(".")[0]
ROOT_PACKAGE: str = root_package(ADDON_PACKAGE)
INSTALLED: bool = ROOT_PACKAGE != ADDON_PACKAGE
