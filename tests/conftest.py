"""Shared pytest fixtures.

bpy is imported only by the fixtures below, on first use: tests of ``lut_baker`` never load it.

- ``bpy_factory`` (session): the ``bpy`` module, imported with ``BLENDER_USER_RESOURCES`` pointing
  at a temporary folder (the user's own Blender config is never read or written), after one
  ``read_factory_settings(use_empty=True)``. Skips the test if bpy cannot be imported.
- ``blank_scene`` (function): ``read_homefile(use_empty=True, use_factory_startup=True)``, which
  keeps enabled add-ons; returns the (empty) ``bpy.context.scene``.
- ``paper_tables``, ``paper_fit`` (session): the paper preset's preview tables and their
  closure fit; ``matte`` (session): ``(skin, tables, fit)`` of :func:`matte_film`, the paper's
  film at index 1.01 (the Auto tier's tests, with and without Blender).  Baked and fitted once
  per process (a bake and fit take ~0.5 s, and some twenty test files read them); their arrays
  are made read-only (:func:`read_only`), so a test that changed them would fail, not pass a
  changed fixture on to the next file.

Tests that use either fixture get the ``bpy`` marker automatically (select them with
``pytest -m bpy``, leave them out with ``-m "not bpy"``).
"""

import dataclasses
import os
import sys
import warnings

import numpy as np
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


def read_only(value):
    """``value`` with every array it holds (in dataclass fields, dicts, lists and tuples, at
    any depth) made read-only, so that fixtures shared by many tests cannot be changed by
    one."""
    if isinstance(value, np.ndarray):
        value.flags.writeable = False
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for field in dataclasses.fields(value):
            read_only(getattr(value, field.name))
    elif isinstance(value, dict):
        for item in value.values():
            read_only(item)
    elif isinstance(value, (list, tuple)):
        for item in value:
            read_only(item)
    return value


@pytest.fixture(scope="session")
def paper_tables():
    return read_only(bake.bake(presets.made_up_skin("paper_natural", "paper_bioplate"),
                               "preview"))


@pytest.fixture(scope="session")
def paper_fit(paper_tables):
    return read_only(fitting.fit_closures(paper_tables))


def matte_film(ior=1.01, coverage=1.0):
    """The paper's film with its index set to ``ior`` (the panel's Override Film, Film IOR:
    1.01 is its smallest), both lobes as measured: its gloss all but vanishes."""
    skin = presets.made_up_skin("paper_natural", "paper_bioplate", coverage=coverage)
    return skin.replace(
        film=skin.film.scaled(eta=ior / float(skin.film.eta)),
        film_transmission=skin.film_transmission.scaled(
            eta=ior / float(skin.film_transmission.eta)))


@pytest.fixture(scope="session")
def matte():
    """``(skin, tables, fit)`` of :func:`matte_film` (preview bake), read-only."""
    skin = matte_film()
    tables = bake.bake(skin, "preview")
    return read_only((skin, tables, fitting.fit_closures(tables)))
