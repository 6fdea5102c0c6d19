"""Opening a file (makeup_skin_addon.on_load): a packed lookup image damaged in the .blend is
repaired before the first render, reported on the console and in the panel; without the
add-on the same file renders magenta; intact files and files without a made-up material are
left as they are, nothing decoded."""

import numpy as np
import pytest
from support.addon_steps import apply_pipeline, render, view_images

REPAIRED_LINE = "Made-up Skin: on opening the file: 'Skin': its lookup image "


def magenta(pixels: np.ndarray) -> float:
    """Fraction of the lit pixels that are magenta (Blender's colour for an image it cannot
    load, (1, 0, 1), showing through the group: red and blue alike, green far below them)."""
    red, green, blue = np.moveaxis(pixels, -1, 0)
    lit = red + green + blue > 0.05
    pink = (green < 0.5 * np.minimum(red, blue)) & (np.abs(red - blue) < 0.1 * (red + blue))
    return float(pink[lit].mean()) if lit.any() else 0.0


def damage(path, packed: bytes) -> None:
    """Rename the OpenEXR header attribute ``channels`` of the image packed in the .blend at
    ``path``: Blender then says "imb_load_openexr: Invalid or missing attribute" and renders
    the image as missing (as a file damaged on a user's disk did)."""
    data = bytearray(path.read_bytes())
    at = data.index(b"channels\x00chlist\x00", data.index(packed))
    data[at:at + len(b"channels")] = b"chbnnels"
    path.write_bytes(bytes(data))


@pytest.fixture
def damaged_file(sphere, tmp_path):
    """``(path, pixels)``: a made-up sphere (Layered: it reads a packed image) saved with that
    image damaged, and its render before the damage."""
    import bpy

    apply_pipeline(sphere, "LAYERED")
    before = render(tmp_path, "before")
    packed = bytes(view_images()[0].packed_file.data)
    path = tmp_path / "damaged.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), compress=False)
    damage(path, packed)
    return path, before


@pytest.mark.slow  # three renders
def test_a_damaged_image_is_repaired_on_opening_and_renders_no_magenta(damaged_file, tmp_path,
                                                                      capsys):
    import bpy

    import makeup_skin_addon
    from makeup_skin_addon import on_load

    path, before = damaged_file
    assert magenta(before) == 0.0
    makeup_skin_addon.unregister()  # as where the add-on is not installed: the damage shows
    try:
        bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
        without = render(tmp_path, "without")
        # Wrong (Blender's magenta for an unreadable image, each row held within its range as
        # baked), but not blown out.
        assert np.abs(without - before).max() > 0.1 * before.max()
        assert np.all(np.isfinite(without)) and without.max() < 3.0 * before.max() + 0.5
    finally:
        makeup_skin_addon.register()
    capsys.readouterr()
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    lines = [line for line in capsys.readouterr().out.splitlines()
             if line.startswith("Made-up Skin")]
    assert len(lines) == 1 and lines[0].startswith(REPAIRED_LINE), lines
    assert "damaged in the file" in lines[0] and lines[0].endswith("rebuilt it from a re-bake.")
    assert on_load.notice(bpy.data.materials["Skin"]) == on_load.REPAIRED
    after = render(tmp_path, "after")
    assert magenta(after) == 0.0
    np.testing.assert_allclose(after, before, rtol=0, atol=1e-4 * before.max())
    assert on_load.damaged_groups() == {}


def test_an_intact_file_is_left_alone_and_nothing_is_decoded(sphere, tmp_path, capsys):
    import bpy

    from makeup_skin_addon import on_load

    apply_pipeline(sphere, "LAYERED")
    path = tmp_path / "intact.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    capsys.readouterr()
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    (image,) = view_images()
    assert not image.has_data  # checked by its packed bytes only: not decoded
    assert on_load.notice(bpy.data.materials["Skin"]) is None
    assert "Made-up Skin" not in capsys.readouterr().out


def test_a_file_without_a_made_up_material_is_left_alone(addon, blank_scene, tmp_path):
    import bpy

    from makeup_skin_addon import on_load

    bpy.data.node_groups.new("Made-up Skin look-alike", "ShaderNodeTree").use_fake_user = True
    bpy.data.materials.new("Someone's material").use_fake_user = True
    path = tmp_path / "plain.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    assert "Made-up Skin look-alike" in bpy.data.node_groups  # no record: not the add-on's
    assert on_load.damaged_groups() == {} and on_load.repair_file(bpy.context) == []
    assert on_load.notice(bpy.data.materials["Someone's material"]) is None


@pytest.mark.parametrize("version", [2, 3])
def test_a_file_made_before_the_film_at_a_thickness_was_the_default_keeps_its_film(
        sphere, tmp_path, version):
    """A material of settings version 2 (made before the Film setting) or 3 (the paper's film
    the default), its file storing no Film: opened, it keeps the paper's film (its look, its
    group untouched: Check Tables finds it intact, nothing pending), stamped this version; a
    new material's Film is the film at a thickness."""
    import bpy

    from makeup_skin_addon import apply, groups, live, on_load
    from makeup_skin_addon.keys import SETTINGS_VERSION

    material, _ = apply_pipeline(sphere, "LAYERED", film_mode="PAPER")
    group_name = groups.group_of(material).node_tree.name
    settings = material.makeup_skin
    for name in ("film_mode", "thickness_um"):
        settings.property_unset(name)
    settings.settings_version = version
    path = tmp_path / f"version{version}.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    material = bpy.data.materials["Skin"]
    settings = material.makeup_skin
    assert settings.film_mode == "PAPER" and settings.settings_version == SETTINGS_VERSION == 4
    assert groups.group_of(material).node_tree.name == group_name and not live.pending()
    assert apply.check_material(bpy.context, material)[0]
    assert on_load.upgrade_file() == []
    assert bpy.data.materials.new("New").makeup_skin.film_mode == "SLAB"  # the default


def test_settings_of_an_older_file_are_upgraded(sphere, tmp_path):
    """A file of the previous version (its settings as that version stored them: no settings
    version, Shade By Color meaning the colour the pigment passes, the film's width in degrees
    under Override Film, Coverage and Shade By left at their old defaults 1 and Absorption):
    opened, the settings mean what they meant, and Apply's sockets are those it had."""
    import math

    import bpy

    from lut_baker.model import roughness
    from makeup_skin_addon.keys import SETTINGS_VERSION

    material, _ = apply_pipeline(sphere, "PRINCIPLED", film_mode="PAPER")
    settings = material.makeup_skin
    settings.live_update = False
    settings.absorption_mode = "COLOUR"
    settings.foundation_colour = (0.9, 0.8, 0.7)
    settings.override_film = True
    settings.film_lobe_width = math.radians(20.0)
    node = material.node_tree.nodes["Made-up Skin"]
    node.inputs["Coverage"].default_value = 1.0
    node.inputs["Foundation Absorption"].default_value = (0.1, 0.2, 0.3, 1.0)
    for name in ("settings_version", "coverage", "film_roughness", "skin_roughness",
                 "shade_colour", "film_mode", "thickness_um"):
        settings.property_unset(name)
    path = tmp_path / "old.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    material = bpy.data.materials["Skin"]
    settings = material.makeup_skin
    assert settings.settings_version == SETTINGS_VERSION
    assert settings.is_property_set("settings_version")
    assert settings.film_mode == "PAPER"
    assert settings.coverage == 1.0
    assert tuple(settings.absorption) == pytest.approx((0.1, 0.2, 0.3), abs=1e-6)
    assert settings.film_roughness == pytest.approx(float(roughness.roughness_for_width(20.0)),
                                                    abs=1e-6)
    node = material.node_tree.nodes["Made-up Skin"]
    assert node.inputs["Coverage"].default_value == 1.0
    assert tuple(node.inputs["Foundation Absorption"].default_value)[:3] == pytest.approx(
        (0.1, 0.2, 0.3), abs=1e-6)
    # Opened again, nothing more to upgrade.
    from makeup_skin_addon import on_load

    assert on_load.upgrade_file() == []


def test_a_version_3_file_that_chose_the_film_at_a_thickness_keeps_it(addon, blank_scene,
                                                                      tmp_path):
    """Version 3 stored a Film chosen by hand: opened, it is kept (only an unset Film meant
    the old default)."""
    import bpy

    from makeup_skin_addon import on_load

    settings = bpy.data.materials.new("Chosen").makeup_skin
    with_paper = bpy.data.materials.new("Unset").makeup_skin
    settings.film_mode = "SLAB"  # chosen (its update stamps this version: set 3 after)
    with_paper.property_unset("film_mode")
    for one in (settings, with_paper):
        one.is_made_up = True
        one.settings_version = 3
    assert on_load.upgrade_settings(settings) and on_load.upgrade_settings(with_paper)
    assert settings.film_mode == "SLAB" and with_paper.film_mode == "PAPER"
