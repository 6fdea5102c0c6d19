"""Shared pytest fixtures.

bpy is imported only by the fixtures below, on first use: tests of ``lut_baker`` never load it.

- ``bpy_factory`` (session): the ``bpy`` module, imported with ``BLENDER_USER_RESOURCES`` pointing
  at a temporary folder (the user's own Blender config is never read or written), after one
  ``read_factory_settings(use_empty=True)``. Skips the test if bpy cannot be imported.
- ``blank_scene`` (function): ``read_homefile(use_empty=True, use_factory_startup=True)``, which
  keeps enabled add-ons; returns the (empty) ``bpy.context.scene``.

Tests that use either fixture get the ``bpy`` marker automatically (select them with
``pytest -m bpy``, leave them out with ``-m "not bpy"``).
"""

import os
import sys
import warnings

import pytest

BPY_FIXTURES = frozenset({"bpy_factory", "blank_scene"})


@pytest.fixture(scope="session")
def bpy_factory(tmp_path_factory):
    if "bpy" not in sys.modules:
        # Blender reads the variable when bpy is imported: it must be set before that.
        resources = tmp_path_factory.mktemp("blender_user_resources")
        os.environ["BLENDER_USER_RESOURCES"] = str(resources)
    elif "BLENDER_USER_RESOURCES" not in os.environ:
        warnings.warn(
            "bpy was imported before the bpy_factory fixture: Blender uses the real user "
            "config folder; import bpy only through the fixtures",
            stacklevel=1,
        )
    try:
        import bpy
    except ImportError as exc:  # pragma: no cover - CI has bpy
        pytest.skip(f"bpy is not importable ({exc}); run with the venv from tools/venv.sh")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy


@pytest.fixture
def blank_scene(bpy_factory):
    bpy = bpy_factory
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    return bpy.context.scene


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    # tryfirst: add the marker before pytest's own hook deselects by "-m".
    for item in items:
        if BPY_FIXTURES.intersection(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.bpy)
