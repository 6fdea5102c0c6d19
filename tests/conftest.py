"""Shared pytest fixtures.

bpy is imported only by the fixtures below, on first use: tests of ``lut_baker`` never load it.

- ``bpy_factory`` (session): the ``bpy`` module, imported with ``BLENDER_USER_RESOURCES`` pointing
  at a temporary folder (the user's own Blender config is never read or written), after one
  ``read_factory_settings(use_empty=True)``. Skips the test if bpy cannot be imported.
- ``blank_scene`` (function): ``read_homefile(use_empty=True, use_factory_startup=True)``, which
  keeps enabled add-ons; returns the (empty) ``bpy.context.scene``.
- ``paper_tables``, ``paper_fit`` (module): the paper preset's preview tables and their closure
  fit; ``matte`` (module): ``(skin, tables, fit)`` of :func:`matte_film`, the paper's film at
  index 1.01 (the Auto tier's tests, with and without Blender).

Tests that use either fixture get the ``bpy`` marker automatically (select them with
``pytest -m bpy``, leave them out with ``-m "not bpy"``).
"""

import os
import sys
import warnings

import pytest

from lut_baker import bake
from lut_baker.closures import fitting
from lut_baker.model import presets

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


@pytest.fixture(scope="module")
def paper_tables():
    return bake.bake(presets.made_up_skin("paper_natural", "paper_bioplate"), "preview")


@pytest.fixture(scope="module")
def paper_fit(paper_tables):
    return fitting.fit_closures(paper_tables)


def matte_film(ior=1.01, coverage=1.0):
    """The paper's film with its index set to ``ior`` (the panel's Override Film, Film IOR:
    1.01 is its smallest), both lobes as measured: its gloss all but vanishes."""
    skin = presets.made_up_skin("paper_natural", "paper_bioplate", coverage=coverage)
    return skin.replace(
        film=skin.film.scaled(eta=ior / float(skin.film.eta)),
        film_transmission=skin.film_transmission.scaled(
            eta=ior / float(skin.film_transmission.eta)))


@pytest.fixture(scope="module")
def matte():
    """``(skin, tables, fit)`` of :func:`matte_film` (preview bake)."""
    skin = matte_film()
    tables = bake.bake(skin, "preview")
    return skin, tables, fitting.fit_closures(tables)
