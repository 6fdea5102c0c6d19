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


def _why_greyed_out(operator) -> str | None:
    """The reason a greyed-out button's tooltip gives (None: the button is active), read as
    headless Blender gives it: calling an operator whose poll fails raises
    ``RuntimeError("Operator bpy.ops.<name>.poll() <reason>")``."""
    if operator.poll():
        return None
    with pytest.raises(RuntimeError) as raised:
        operator()
    return str(raised.value).partition(".poll() ")[2]


def _reasons() -> dict:
    """Every operator with a poll: its reason for being greyed out now (or None)."""
    import bpy

    ops = bpy.ops.makeup_skin
    return {name: _why_greyed_out(getattr(ops, name)) for name in (
        "apply", "revert", "fit_to_scene", "match_skin", "shade_step", "add_preset")}


def _linked(tmp_path, material, mesh):
    """``material`` and ``mesh`` written to a library .blend and linked back: their linked
    copies."""
    import bpy

    path = tmp_path / "library.blend"
    bpy.data.libraries.write(str(path), {material, mesh}, fake_user=True)
    with bpy.data.libraries.load(str(path), link=True) as (_, target):
        target.materials, target.meshes = [material.name], [mesh.name]
    return (next(m for m in bpy.data.materials if m.library and m.name == material.name),
            next(m for m in bpy.data.meshes if m.library and m.name == mesh.name))


def test_every_greyed_out_button_says_why(sphere, tmp_path):
    """Each operator's poll refuses with the reason in the tooltip (``poll_message_set``): no
    active object, an object that is not a mesh, no material, a material not made up (Match
    Skin, the steps, Revert), a mesh in Edit Mode (what reads the skin), nothing to revert,
    data linked from a library."""
    import bpy

    from makeup_skin_addon import convert
    from makeup_skin_addon.keys import RECORD_KEY

    view_layer = bpy.context.view_layer
    view_layer.objects.active = None
    assert set(_reasons().values()) == {"No active object: select a mesh",
                                        "No active object: select an object with a material"}

    view_layer.objects.active = bpy.data.objects["Camera"]
    reasons = _reasons()
    assert reasons["apply"] == reasons["fit_to_scene"] == (
        "The active object is a camera: select a mesh")
    assert reasons["revert"] == "The active object 'Camera' has no material: nothing to revert"
    assert reasons["match_skin"] == reasons["shade_step"] == (
        "The active object 'Camera' has no material: Apply first")
    assert reasons["add_preset"] == ("The active object 'Camera' has no material: a preset "
                                     "holds a material's settings")
    view_layer.objects.active = bpy.data.objects["Sun"]
    assert _reasons()["apply"] == "The active object is a light: select a mesh"

    bpy.ops.curve.primitive_bezier_curve_add()  # Apply makes up a curve; Fit to Scene does not
    assert _reasons()["apply"] is None
    assert _reasons()["fit_to_scene"] == "The active object is a curve: select a mesh"

    view_layer.objects.active = sphere  # no material yet: Apply and Fit to Scene give it one
    reasons = _reasons()
    assert reasons["apply"] is None and reasons["fit_to_scene"] is None
    assert reasons["match_skin"] == "The active object 'Sphere' has no material: Apply first"

    sphere.data.materials.append(bpy.data.materials.new("Skin"))
    reasons = _reasons()
    assert reasons["revert"] == "Material 'Skin' is not made up: nothing to revert"
    assert reasons["match_skin"] == reasons["shade_step"] == (
        "Material 'Skin' is not made up: Apply first (it matches the skin)")
    assert reasons["apply"] is reasons["add_preset"] is None

    material, _ = apply_pipeline(sphere)
    assert set(_reasons().values()) == {None}
    view_layer.objects.active = sphere
    bpy.ops.object.mode_set(mode="EDIT")  # the mesh's UVs are Blender's alone there
    reasons = _reasons()
    assert reasons["apply"] == reasons["match_skin"] == reasons["shade_step"] == (
        "'Sphere' is in Edit Mode, where Blender gives Python no UVs: leave Edit Mode (Tab) "
        "to read the skin")
    assert reasons["fit_to_scene"] is reasons["revert"] is None
    bpy.ops.object.mode_set(mode="OBJECT")
    assert set(_reasons().values()) == {None}
    record = material.pop(RECORD_KEY)
    assert _reasons()["revert"] == ("Material 'Skin' has no record of its surface before "
                                    "Apply: nothing to revert to")
    material[RECORD_KEY] = record

    linked_material, linked_mesh = _linked(tmp_path, material, bpy.data.meshes.new("Lib Mesh"))
    sphere.data.materials[0] = linked_material
    reasons = _reasons()
    # The sentence Apply's error gives (headless Blender cuts the message at 200 characters).
    sentence = convert.linked_library(linked_material, "material")
    assert "library.blend" in sentence and "Make Local" in sentence
    for name in ("apply", "fit_to_scene", "match_skin", "shade_step", "revert"):
        assert len(reasons[name]) > 100, name
        assert ("M" + sentence[1:]).startswith(reasons[name]), name
    assert reasons["add_preset"] is None  # saving a preset reads the settings only

    obj = bpy.data.objects.new("Linked Mesh", linked_mesh)  # no material: Apply would add one
    bpy.context.scene.collection.objects.link(obj)
    view_layer.objects.active = obj
    assert _reasons()["apply"].startswith("Mesh 'Lib Mesh' is linked from the library ")
