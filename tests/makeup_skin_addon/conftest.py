"""Fixtures of the add-on's tests (Blender, headless).

- ``addon`` -- the add-on from this checkout (``makeup_skin_addon`` as a top-level package),
  registered for the test and unregistered after it (bpy 4.5 hangs at exit while an add-on's
  classes stay registered).  Yields the package.  Its session cache (re-baked tables and
  closure fits, by bake key: :mod:`makeup_skin_addon.bakes`)
  carry over from the test before, as they do in Blender from one file to the next: the
  same settings are baked and fitted once per process, not once per test (a preview fit
  takes ~0.25 s).  A test about what a cold session bakes or fits clears them first
  (:func:`support.addon_steps.cold_caches`).
- ``sphere`` -- a smooth sphere (radius 3 cm), the camera and sun of
  tests/support/sphere_scene.py (60 degrees off the view towards +x), black world, Cycles CPU
  at 16 samples, :data:`support.addon_steps.SPHERE_PX` px.
- ``two_faces`` -- ``(object, skin material, texture node)``: the mesh of
  tests/support/two_faces.py, its skin slot's Base Color fed by the image of bands.
- ``head`` -- the textured head of tests/support/character.py (its own Principled material
  with an albedo texture and a pore normal map), a portrait camera and lights, Cycles at 16
  samples, :data:`support.addon_steps.HEAD_PX` px.
"""

import pytest
from support import character, sphere_scene
from support import two_faces as faces
from support.addon_steps import HEAD_PX, SPHERE_PX, session_caches

_SESSION: dict = {}
"""The add-on's session caches (re-baked tables, closure fits) as the last test left them."""


@pytest.fixture
def addon(bpy_factory):
    import makeup_skin_addon

    with sphere_scene.addon_registered():
        for name, cache in session_caches().items():
            for key, value in _SESSION.get(name, {}).items():  # oldest first, as they were
                cache.put(key, value)
        yield makeup_skin_addon
        _SESSION.update({name: dict(cache._values) for name, cache in session_caches().items()})


@pytest.fixture
def sphere(addon, blank_scene):
    return sphere_scene.add_sphere(blank_scene, 0.03, light_deg=60.0, size=SPHERE_PX,
                                   samples=16)


@pytest.fixture
def head(addon, blank_scene):
    obj = character.build_character("Head")
    character.portrait_camera_and_lights(blank_scene, obj, size=HEAD_PX, samples=16)
    return obj


@pytest.fixture
def two_faces(addon, blank_scene):
    """``(object, skin material, texture node)``: :func:`support.two_faces.build_two_faces`
    with its image of bands."""
    skin, other = faces.new_material("Skin"), faces.new_material("Other")
    obj = faces.build_two_faces(skin, other)
    image = faces.band_image("Bands", (faces.LEFT_BYTES, faces.RIGHT_BYTES, faces.OTHER_BYTES))
    return obj, skin, faces.textured(skin, image)
