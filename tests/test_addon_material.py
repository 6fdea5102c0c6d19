"""The add-on from the source tree, headless: Apply, render, reuse, save/reload, repair, live.

Renders are Cycles CPU, 64x64 px, 16 samples (about 0.3 s each).  The add-on is registered
from this checkout (``makeup_skin_addon`` as a top-level package) for the module and always
unregistered after it: bpy 4.5 hangs at exit while an add-on's classes stay registered.
"""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))  # scripts, no package
import render_sphere  # noqa: E402

SIZE = 64


@pytest.fixture(scope="module")
def addon(bpy_factory):
    import makeup_skin_addon

    makeup_skin_addon.register()
    yield makeup_skin_addon
    makeup_skin_addon.unregister()


@pytest.fixture
def sphere(addon, blank_scene):
    """A smooth sphere (radius 3 cm), tools/render_sphere.py's camera and sun (60 degrees off
    the view towards +x), black world, Cycles CPU at 16 samples."""
    return render_sphere.add_sphere(blank_scene, 0.03, light_deg=60.0, size=SIZE, samples=16)


def _render(tmp_path, name="render"):
    """Render the scene to a float EXR and return its RGB pixels (rows bottom-up)."""
    return render_sphere.render_pixels(tmp_path / f"{name}.exr")


def _apply(obj, tier="PRINCIPLED", resolution="preview", **settings):
    """Apply through the operator; returns the material.  The operator's reports go to the
    returned material's ``last_messages`` list (warnings only)."""
    import bpy

    from makeup_skin_addon import material as made_up

    if obj.active_material is None:
        obj.data.materials.append(bpy.data.materials.new("Skin"))
    values = obj.active_material.makeup_skin
    values.tier = tier
    values.resolution = resolution
    for name, value in settings.items():
        setattr(values, name, value)
    material, messages = made_up.apply_to_object(bpy.context, obj)
    _apply.messages = messages
    return material


def _counts():
    import bpy

    return (len(bpy.data.node_groups), len(bpy.data.images), len(bpy.data.materials))


@pytest.mark.parametrize("tier", ["PRINCIPLED", "LAYERED"])
def test_apply_and_render(sphere, tmp_path, tier):
    material = _apply(sphere, tier)
    assert material.makeup_skin.is_made_up
    group = material.node_tree.nodes["Made-up Skin"].node_tree
    assert group.name.startswith(f"Made-up Skin {tier.title()}")
    meta = json.loads(group["makeup_skin_fit"])
    assert meta["tier"] == tier and meta["subsurface_method"] in ("BURLEY", "RANDOM_WALK_SKIN")
    errors = json.loads(material["makeup_skin_errors"])
    assert set(errors) == {"PRINCIPLED", "LAYERED"}
    pixels = _render(tmp_path)
    assert np.all(np.isfinite(pixels)) and pixels.min() >= 0.0
    disc = pixels.mean(axis=-1) > 1e-4
    assert 0.4 < disc.mean() < 0.9  # the sphere fills the middle of the frame
    # Plausible brightness: a sun of irradiance pi on a surface of albedo ~0.7.
    assert 0.05 < pixels[disc].mean() < 0.8
    # The sun is 60 degrees towards +x: the right half is brighter than the left.
    left, right = pixels[:, : SIZE // 2][disc[:, : SIZE // 2]], pixels[:, SIZE // 2:][
        disc[:, SIZE // 2:]]
    assert right.mean() > 1.5 * left.mean()


def test_apply_operator_and_twice_creates_no_duplicates(sphere):
    import bpy

    sphere.data.materials.append(bpy.data.materials.new("Skin"))
    sphere.active_material.makeup_skin.tier = "LAYERED"
    sphere.active_material.makeup_skin.resolution = "preview"
    assert bpy.ops.makeup_skin.apply() == {"FINISHED"}
    before = _counts()
    material = _apply(sphere, "LAYERED")
    assert _apply.messages == []  # the stored tables were found intact
    assert _counts() == before
    assert sphere.active_material == material
    assert len(sphere.material_slots) == 1


def test_coverage_and_absorption_are_sockets(sphere):
    material = _apply(sphere, "PRINCIPLED")
    node = material.node_tree.nodes["Made-up Skin"]
    groups = _counts()[0]
    material.makeup_skin.coverage = 0.25
    material.makeup_skin.absorption = (0.1, 0.3, 0.5)
    assert node.inputs["Coverage"].default_value == pytest.approx(0.25)
    assert tuple(node.inputs["Foundation Absorption"].default_value)[:3] == pytest.approx(
        (0.1, 0.3, 0.5))
    material.makeup_skin.foundation = "deep_mocha"  # sets the shade's absorption
    from lut_baker.model.presets import FOUNDATIONS

    assert tuple(node.inputs["Foundation Absorption"].default_value)[:3] == pytest.approx(
        FOUNDATIONS["deep_mocha"]["absorption"])
    assert _counts()[0] == groups  # no re-bake for socket-level settings


def test_scene_unit_scale_sets_the_blur(sphere):
    import bpy

    bpy.context.scene.unit_settings.scale_length = 0.01  # modelled in centimetres
    material = _apply(sphere, "PRINCIPLED")
    node = material.node_tree.nodes["Made-up Skin"]
    assert node.inputs["Units per mm"].default_value == pytest.approx(0.1)


def _lut_images():
    import bpy

    return [image for image in bpy.data.images if image.name.startswith("MakeupSkin LUT")]


def test_save_reload_renders_the_same_and_keeps_only_what_the_render_reads(sphere, tmp_path):
    import bpy

    from makeup_skin_addon import material as made_up

    name = _apply(sphere, "LAYERED").name
    first = _render(tmp_path, "first")
    path = tmp_path / "made_up.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    luts = _lut_images()
    assert len(luts) == 1 and luts[0].packed_file is not None
    saved = [i.name for i in bpy.data.images if i.type != "RENDER_RESULT"]
    assert saved == [luts[0].name]  # no tables travel in the file
    assert luts[0].size[0] * luts[0].size[1] <= 64 * 8
    material = bpy.data.materials[name]
    assert made_up.check_material(bpy.context, material) == (
        True, f"{material.name!r}: intact.")  # re-bakes to the recorded hash
    second = _render(tmp_path, "second")
    np.testing.assert_array_equal(first, second)


def test_altered_lookup_image_is_found_and_rebuilt(sphere, tmp_path):
    import bpy

    from makeup_skin_addon import material as made_up

    material = _apply(sphere, "LAYERED")
    before = _render(tmp_path, "before")
    lut = _lut_images()[0]
    lut.pixels.foreach_set(np.zeros(len(lut.pixels), np.float32))  # what the render reads
    intact, sentence = made_up.check_material(bpy.context, material)
    assert not intact and "was altered" in sentence and "rebuilt it from a re-bake" in sentence
    assert made_up.check_material(bpy.context, material)[0]
    np.testing.assert_array_equal(_render(tmp_path, "after"), before)
    # Deleted: the operator reports it in one sentence and rebuilds it, never raises.
    bpy.data.images.remove(_lut_images()[0])
    assert bpy.ops.makeup_skin.check_tables() == {"FINISHED"}
    assert len(_lut_images()) == 1 and made_up.check_material(bpy.context, material)[0]
    group = material.node_tree.nodes["Made-up Skin"].node_tree
    textures = [n for n in group.nodes if n.type == "TEX_IMAGE"]
    assert textures and all(n.image == _lut_images()[0] for n in textures)


def test_apply_rebuilds_a_damaged_group_instead_of_reusing_it(sphere):
    import bpy

    from makeup_skin_addon import material as made_up

    material = _apply(sphere, "LAYERED")
    lut = _lut_images()[0]
    lut.pixels.foreach_set(np.zeros(len(lut.pixels), np.float32))
    _apply(sphere, "LAYERED")  # must not raise, nor reuse the zeroed image
    assert len(_apply.messages) == 1 and "was altered" in _apply.messages[0]
    assert made_up.check_material(bpy.context, material)[0]
    assert np.asarray(_lut_images()[0].pixels[:]).max() > 0.0


def test_check_tables_reports_one_sentence_per_material(sphere):
    import bpy

    from makeup_skin_addon import material as made_up
    from makeup_skin_addon import nodes

    material = _apply(sphere, "PRINCIPLED")
    group = material.node_tree.nodes["Made-up Skin"].node_tree
    meta = json.loads(group[nodes.FIT_KEY])
    meta["parameters"]["film"]["n"] = "not a number"
    group[nodes.FIT_KEY] = json.dumps(meta)
    intact, sentence = made_up.check_material(bpy.context, material)
    assert not intact and sentence.startswith(f"{material.name!r}: its bake record cannot be "
                                              f"re-baked")
    assert sentence.endswith("re-baked it from the panel's settings.")
    assert "\n" not in sentence and "Traceback" not in sentence
    assert "parameters" in json.loads(group[nodes.FIT_KEY])  # repaired: a readable record


def test_live_update_rebakes_at_preview_resolution(sphere):
    import bpy

    from makeup_skin_addon import live

    material = _apply(sphere, "PRINCIPLED", resolution="preview")
    node = material.node_tree.nodes["Made-up Skin"]
    before = node.node_tree["makeup_skin_fit"]
    material.makeup_skin.skin = "jensen_skin2"  # changes the tables
    assert material.name in live.pending()
    assert live.flush(bpy.context) == []
    assert not live.pending()
    after = node.node_tree["makeup_skin_fit"]
    assert json.loads(after)["key"] != json.loads(before)["key"]
    assert not bpy.app.timers.is_registered(live.rebake_timer)


def test_unregister_leaves_nothing(addon, bpy_factory):
    import bpy

    from makeup_skin_addon import live

    def ours():
        # Panels and menus by class name; operators by bl_idname (MAKEUP_SKIN_OT_apply).
        return [name for name in dir(bpy.types) if name.startswith(("MAKEUPSKIN", "MAKEUP_SKIN"))]

    assert len(ours()) == 8 and hasattr(bpy.types.Material, "makeup_skin")  # + Fit to Scene, Revert
    addon.unregister()
    try:
        assert not hasattr(bpy.types.Material, "makeup_skin")
        assert ours() == []
        assert not bpy.app.timers.is_registered(live.rebake_timer)
        assert live.pending() == set()
    finally:
        addon.register()


def test_forced_subsurface_method_gets_its_own_group(sphere):
    material = _apply(sphere, "PRINCIPLED")
    auto = material.node_tree.nodes["Made-up Skin"].node_tree
    material = _apply(sphere, "PRINCIPLED", subsurface_method="RANDOM_WALK_SKIN")
    group = material.node_tree.nodes["Made-up Skin"].node_tree
    assert group != auto and " RW Skin " in group.name
    principled = next(n for n in group.nodes if n.type == "BSDF_PRINCIPLED")
    assert principled.subsurface_method == "RANDOM_WALK_SKIN"
    meta = json.loads(group["makeup_skin_fit"])
    radius = meta["profiles"]["RANDOM_WALK_SKIN"]["radius_mm"]
    assert tuple(next(s for s in principled.inputs if s.identifier == "Subsurface Radius")
                 .default_value) == pytest.approx(radius)


def test_presets_save_and_load_a_parameter_set(sphere):
    import bpy

    from makeup_skin_addon.operators import PRESET_SUBDIR

    material = _apply(sphere, "PRINCIPLED")
    settings = material.makeup_skin
    settings.foundation = "deep_mocha"
    settings.coverage = 0.35
    settings.subsurface_scale = 2.5
    assert bpy.ops.makeup_skin.add_preset(name="Test Shade") == {"FINISHED"}
    folder = bpy.utils.user_resource("SCRIPTS", path=f"presets/{PRESET_SUBDIR}")
    path = f"{folder}/Test_Shade.py"  # Blender's file name for the preset "Test Shade"
    settings.foundation = "light_ivory"
    settings.coverage = 1.0
    settings.subsurface_scale = 1.0
    assert bpy.ops.script.execute_preset(filepath=path,
                                         menu_idname="MAKEUPSKIN_MT_presets") == {"FINISHED"}
    assert (settings.foundation, settings.coverage, settings.subsurface_scale) == (
        "deep_mocha", pytest.approx(0.35), pytest.approx(2.5))
    node = material.node_tree.nodes["Made-up Skin"]
    assert node.inputs["Coverage"].default_value == pytest.approx(0.35)  # live to the socket
