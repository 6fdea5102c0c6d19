"""lut_baker as the add-on imports it (makeup_skin_addon.core): from a source checkout the
top-level package's own runtime modules, never an offline one (installed, the relative branch
is exercised by tests/test_extension_package.py)."""

import importlib


def test_core_hands_out_the_runtime_modules_of_this_checkout(bpy_factory):
    # the add-on's package imports bpy: only through the fixture (tests/conftest.py)
    from makeup_skin_addon import core, package

    assert not package.INSTALLED
    for name in core.__all__:
        module = getattr(core, name)
        assert module.__name__.startswith("lut_baker.")
        assert ".offline" not in module.__name__
        assert importlib.import_module(module.__name__) is module
