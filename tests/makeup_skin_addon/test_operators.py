"""The operators (makeup_skin_addon.operators): presets save and load a parameter set; the
whole walk (Apply, a live re-bake, Revert, Check Tables, Fit to Scene) leaves every
datablock of the artist's with a user; Apply pushes an undo step."""

import pytest
from support.addon_steps import apply_operator, apply_pipeline, tree_state


def test_presets_save_and_load_a_parameter_set(sphere):
    import bpy

    from makeup_skin_addon.operators import PRESET_SUBDIR

    material, _ = apply_pipeline(sphere, "PRINCIPLED")
    settings = material.makeup_skin
    settings.foundation = "deep_mocha"
    settings.coverage = 0.35
    settings.subsurface_scale = 2.5
    settings.film_roughness, settings.skin_roughness = 0.5, 0.6
    settings.film_follows_pores = False
    assert bpy.ops.makeup_skin.add_preset(name="Test Shade") == {"FINISHED"}
    folder = bpy.utils.user_resource("SCRIPTS", path=f"presets/{PRESET_SUBDIR}")
    path = f"{folder}/Test_Shade.py"  # Blender's file name for the preset "Test Shade"
    settings.foundation = "light_ivory"
    settings.coverage = 1.0
    settings.subsurface_scale = 1.0
    settings.film_roughness, settings.skin_roughness = 0.7, 0.7
    settings.film_follows_pores = True
    assert bpy.ops.script.execute_preset(filepath=path,
                                         menu_idname="MAKEUPSKIN_MT_presets") == {"FINISHED"}
    assert (settings.foundation, settings.coverage, settings.subsurface_scale) == (
        "deep_mocha", pytest.approx(0.35), pytest.approx(2.5))
    # Saved after the foundation, the roughness it set is overridden as it was saved.
    assert (settings.film_roughness, settings.skin_roughness) == (pytest.approx(0.5),
                                                                  pytest.approx(0.6))
    assert not settings.film_follows_pores
    node = material.node_tree.nodes["Made-up Skin"]
    assert node.inputs["Coverage"].default_value == pytest.approx(0.35)  # live to the socket


USER_DATA = ("materials", "images", "node_groups", "meshes", "objects", "textures")


def _user_data():
    """Every datablock of the kinds an artist owns, by kind and name (the add-on's own groups
    and lookup images are left out)."""
    import bpy

    return {(kind, block.name) for kind in USER_DATA for block in getattr(bpy.data, kind)
            if not block.name.startswith(("Made-up Skin ", "MakeupSkin "))}


def _orphans(names):
    import bpy

    return [(kind, name) for kind, name in names
            if getattr(bpy.data, kind).get(name) is None
            or getattr(bpy.data, kind)[name].users == 0]


@pytest.mark.slow  # the whole walk
def test_no_user_datablock_loses_its_last_user(head, tmp_path):
    import bpy

    from makeup_skin_addon import live

    names = _user_data()
    material = apply_operator(head)
    material.makeup_skin.tier = "PRINCIPLED"  # a live re-bake of the group
    live.flush(bpy.context)
    apply_operator(head, "LAYERED")
    assert bpy.ops.makeup_skin.revert() == {"FINISHED"}
    apply_operator(head)
    assert bpy.ops.makeup_skin.check_tables() == {"FINISHED"}
    assert bpy.ops.makeup_skin.fit_to_scene() == {"FINISHED"}
    assert _orphans(names) == []
    path = tmp_path / "head.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    assert _orphans(names) == []  # all saved: nothing dropped by the save


@pytest.mark.slow  # a head: ~1 s
def test_undo_restores_the_material_apply_changed(head):
    """Apply pushes an undo step (run with ``undo=True``, as the UI runs operators); undoing it
    gives the artist's tree back."""
    import bpy

    before = tree_state(head.active_material)
    head.active_material.makeup_skin.resolution = "preview"
    bpy.ops.ed.undo_push(message="before Apply")  # headless Blender starts with undo off
    assert bpy.ops.makeup_skin.apply("EXEC_DEFAULT", True) == {"FINISHED"}
    assert tree_state(bpy.data.materials["Head Skin"]) != before
    bpy.ops.ed.undo()
    assert tree_state(bpy.data.materials["Head Skin"]) == before
