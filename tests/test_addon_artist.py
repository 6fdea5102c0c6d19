"""The artist's workflow on a textured character (tools/character.py: subdivided Suzanne whose
own Principled material has an albedo texture and a pore normal map).

Apply converts that material in place and carries the albedo and the normal map over; Revert
restores it; nothing of the artist's loses its last user; Normal, Film Normal and Skin Color
reach every closure; linked library data is refused; a .blend made up and reopened without the
add-on renders the same.  Cycles CPU, 48 px, 16 samples.
"""

import dataclasses
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))  # scripts, no package
import character  # noqa: E402
import render_sphere  # noqa: E402

SIZE = 48
USER_DATA = ("materials", "images", "node_groups", "meshes", "objects", "textures")


@pytest.fixture
def addon(bpy_factory):
    with render_sphere.addon_registered():
        yield


@pytest.fixture
def head(addon, blank_scene):
    """The textured head, a camera and lights, Cycles at 16 samples."""
    obj = character.build_character("Head")
    character.portrait_camera_and_lights(blank_scene, obj, size=SIZE, samples=16)
    return obj


def _apply(obj, tier="LAYERED", **settings):
    """Apply through the operator (as the panel does) with preview tables."""
    import bpy

    values = obj.active_material.makeup_skin
    values.tier, values.resolution = tier, "preview"
    for name, value in settings.items():
        setattr(values, name, value)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.makeup_skin.apply() == {"FINISHED"}
    return obj.active_material


def _render(tmp_path, name):
    return render_sphere.render_pixels(tmp_path / f"{name}.exr")


def _tree_state(material):
    """Nodes (name, type, parent, location) and links of a material's tree, comparable."""
    tree = material.node_tree
    nodes = sorted((n.name, n.bl_idname, n.parent.name if n.parent else None,
                    tuple(round(v, 3) for v in n.location)) for n in tree.nodes)
    links = sorted((link.from_node.name, link.from_socket.identifier, link.to_node.name,
                    link.to_socket.identifier) for link in tree.links)
    return nodes, links


def _group_node(material):
    return material.node_tree.nodes["Made-up Skin"]


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


def test_apply_converts_the_artists_material_in_place(head):
    import bpy

    material = head.active_material
    principled = material.node_tree.nodes["Principled BSDF"]
    albedo = principled.inputs["Base Color"].links[0].from_socket
    normal = principled.inputs["Normal"].links[0].from_socket
    materials = len(bpy.data.materials)
    assert _apply(head) == material and len(bpy.data.materials) == materials
    group = _group_node(material)
    output = material.node_tree.get_output_node("ALL")
    assert output.inputs["Surface"].links[0].from_node == group
    # The artist's shader stays, framed and disconnected, its own links intact.
    assert principled.parent is not None and principled.parent.label.startswith("Before Made-up")
    assert not principled.outputs[0].is_linked
    assert principled.inputs["Base Color"].links[0].from_socket == albedo
    # Albedo and normal map carried over to the group.
    assert group.inputs["Skin Color"].links[0].from_socket == albedo
    assert group.inputs["Normal"].links[0].from_socket == normal
    assert not group.inputs["Film Normal"].is_linked  # foundation fills the pores


def test_revert_restores_the_previous_surface(head):
    import bpy

    material = head.active_material
    before = _tree_state(material)
    _apply(head)
    assert bpy.ops.makeup_skin.revert() == {"FINISHED"}
    assert _tree_state(material) == before
    assert not material.makeup_skin.is_made_up
    assert bpy.ops.makeup_skin.revert.poll() is False  # nothing left to revert
    _apply(head)  # and again: converts once more
    assert _group_node(material).inputs["Skin Color"].is_linked


def test_shared_material_is_converted_once_and_reported(head, capfd):
    import bpy

    twin = character.build_character("Twin", location=(0.3, 0.0, 0.0))
    twin.data.materials[0] = head.active_material  # two characters, one material
    material = _apply(head)
    assert "shared by 2 objects" in capfd.readouterr().out
    assert twin.active_material == material == head.active_material
    nodes = len(material.node_tree.nodes)
    _apply(twin)
    assert len(material.node_tree.nodes) == nodes  # not converted twice
    assert len([m for m in bpy.data.materials if m.makeup_skin.is_made_up]) == 1


def test_multi_slot_object_converts_only_the_active_slot(head):
    import bpy

    eyes = bpy.data.materials.new("Eyes")
    if bpy.app.version < (5, 0, 0):
        eyes.use_nodes = True
    head.data.materials.append(eyes)
    untouched = _tree_state(head.data.materials[0])
    head.active_material_index = 1
    _apply(head)
    assert [slot.material for slot in head.material_slots] == [
        bpy.data.materials["Head Skin"], eyes]
    assert _tree_state(head.data.materials[0]) == untouched
    assert _group_node(eyes) is not None


def test_no_user_datablock_loses_its_last_user(head, tmp_path):
    import bpy

    from makeup_skin_addon import live

    names = _user_data()
    material = _apply(head)
    material.makeup_skin.tier = "PRINCIPLED"  # a live re-bake of the group
    live.flush(bpy.context)
    _apply(head, "LAYERED")
    assert bpy.ops.makeup_skin.revert() == {"FINISHED"}
    _apply(head)
    assert bpy.ops.makeup_skin.check_tables() == {"FINISHED"}
    assert bpy.ops.makeup_skin.fit_to_scene() == {"FINISHED"}
    assert _orphans(names) == []
    path = tmp_path / "head.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    assert _orphans(names) == []  # all saved: nothing dropped by the save


def _unlinked_against_no_normal_links(head, tmp_path, tier):
    """``(render with Normal and Film Normal unlinked, render of the same group with no link
    from those inputs inside)``: the second is the group before it had the inputs."""
    material = _apply(head, tier)
    node = _group_node(material)
    for name in ("Normal", "Film Normal", "Skin Color"):
        for link in list(node.inputs[name].links):
            material.node_tree.links.remove(link)
    node.inputs["Skin Color"].default_value = (0.6, 0.45, 0.4, 1.0)
    with_inputs = _render(tmp_path, f"{tier}_inputs")
    bare = node.node_tree.copy()
    group_input = next(n for n in bare.nodes if n.type == "GROUP_INPUT")
    for name in ("Normal", "Film Normal"):
        for link in list(group_input.outputs[name].links):
            bare.links.remove(link)
    node.node_tree = bare
    return with_inputs, _render(tmp_path, f"{tier}_bare")


def test_unlinked_normals_render_as_the_shading_normal(head, tmp_path):
    """Leaving Normal and Film Normal unlinked renders exactly as a group whose closures have
    no Normal link at all, in both tiers (Cycles)."""
    for tier in ("LAYERED", "PRINCIPLED"):
        with_inputs, bare = _unlinked_against_no_normal_links(head, tmp_path, tier)
        np.testing.assert_array_equal(bare, with_inputs)


@pytest.mark.slow
def test_unlinked_normals_in_eevee(head, tmp_path):
    """The same in EEVEE, Principled tier (the one Auto gives EEVEE): a hidden-value group input
    stays unlinked inside the group, where a visible one would hand the BSDF a zero normal
    (flat shading in EEVEE 5.0)."""
    import bpy

    scene = bpy.context.scene
    scene.render.engine = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else \
        "BLENDER_EEVEE_NEXT"
    scene.eevee.taa_render_samples = 4
    for light in (obj.data for obj in scene.objects if obj.type == "LIGHT"):
        light.use_shadow = False  # software OpenGL: ~45 s a render with shadows
    _render(tmp_path, "warm_up")  # a process's first EEVEE render differs (by up to 0.03)
    with_inputs, bare = _unlinked_against_no_normal_links(head, tmp_path, "PRINCIPLED")
    assert with_inputs.mean() > 0.1
    np.testing.assert_allclose(bare, with_inputs, atol=1e-4)  # a zero normal: ~0.5


def test_every_closure_reads_a_normal_input(head, tmp_path):
    from makeup_skin_addon import nodes

    for tier in ("LAYERED", "PRINCIPLED"):
        group = _group_node(_apply(head, tier)).node_tree
        closures = [n for n in group.nodes if n.type.startswith(("BSDF", "SUBSURFACE"))]
        assert closures
        for closure in closures:
            sources = {link.from_socket.name for name in ("Normal", "Coat Normal")
                       if name in closure.inputs for link in closure.inputs[name].links}
            assert sources and sources <= set(nodes.NORMAL_INPUTS), closure.name
    # A bump on the film changes the render; on neither input it does not.
    material = head.active_material
    node = _group_node(material)
    smooth = _render(tmp_path, "smooth")
    material.node_tree.links.new(node.inputs["Normal"].links[0].from_socket,
                                 node.inputs["Film Normal"])
    assert np.abs(_render(tmp_path, "bumped") - smooth).max() > 1e-3


@pytest.mark.parametrize("tier", ["LAYERED", "PRINCIPLED"])
def test_skin_colour_texture_matches_a_bake_at_that_albedo(addon, blank_scene, tmp_path, tier):
    """An albedo texture in Skin Color renders as the tables baked with that albedo: the skin's
    diffuse term is linear, so the texture scales every skin closure exactly."""
    import bpy

    from lut_baker import bake
    from lut_baker.model import presets
    from makeup_skin_addon import material as made_up

    colour = np.array([0.62, 0.41, 0.33])
    obj = render_sphere.add_sphere(blank_scene, 0.03, light_deg=40.0, size=SIZE, samples=16)
    skin = presets.made_up_skin("medium_beige", "jensen_skin2", absorption=0.0)
    tables = bake.bake(skin, "preview")
    material = render_sphere.made_up_material(obj, tables, tier, coverage=0.7,
                                              absorption=[0.1, 0.24, 0.42])
    texture = material.node_tree.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.new("flat albedo", 4, 4, float_buffer=True)
    texture.image.colorspace_settings.name = "Non-Color"
    texture.image.pixels.foreach_set(np.tile([*colour, 1.0], 16).astype(np.float32))
    material.node_tree.links.new(texture.outputs["Color"],
                                 made_up.group_of(material).inputs["Skin Color"])
    textured = _render(tmp_path, "textured")

    own = skin.replace(skin=dataclasses.replace(skin.skin, P_d=colour / np.pi))
    group, _ = made_up.group_for_tables(bake.bake(own, "preview"), tier)
    material.node_tree.nodes.remove(texture)
    made_up.group_of(material).node_tree = group
    made_up.group_of(material).inputs["Skin Color"].default_value = (*colour, 1.0)
    baked = _render(tmp_path, "baked")
    assert np.abs(textured - baked).max() < 1e-5 * max(baked.max(), 1.0)


def _library_with_material(tmp_path):
    """A .blend holding the textured head's material, saved as a library."""
    import bpy

    obj = character.build_character("Lib")
    path = tmp_path / "library.blend"
    bpy.data.libraries.write(str(path), {obj.active_material}, fake_user=True)
    return path, obj.active_material.name


def test_linked_material_is_refused(head, tmp_path):
    import bpy

    path, name = _library_with_material(tmp_path)
    with bpy.data.libraries.load(str(path), link=True) as (source, target):
        target.materials = [name]
    linked = next(m for m in bpy.data.materials if m.library is not None and m.name == name)
    head.data.materials[0] = linked
    before = _tree_state(linked)
    bpy.context.view_layer.objects.active = head
    for operator in (bpy.ops.makeup_skin.apply, bpy.ops.makeup_skin.fit_to_scene):
        with pytest.raises(RuntimeError, match="library.blend.*Make Local"):
            operator()
    assert _tree_state(linked) == before and not linked.makeup_skin.is_made_up
    assert not [g for g in bpy.data.node_groups if g.name.startswith("Made-up Skin")]


def test_apply_progress_covers_bake_and_fit(head):
    """The progress bar rises through the closure fit, not only the bake."""
    import bpy

    from makeup_skin_addon import material as made_up

    class WindowManager:
        def __init__(self):
            self.values = []

        def progress_begin(self, low, high):
            pass

        def progress_update(self, value):
            self.values.append(value)

        def progress_end(self):
            pass

    class Context:
        scene = bpy.context.scene
        window_manager = WindowManager()

    head.active_material.makeup_skin.resolution = "preview"
    made_up.apply_to_object(Context, head)
    values = Context.window_manager.values
    bake_share = 100 * made_up.BAKE_SHARE
    assert values == sorted(values) and values[-1] == 100
    assert len([v for v in values if bake_share < v < 100]) >= 3  # the fit's stages


def test_whole_walk_reopened_without_the_addon_renders_the_same(head, tmp_path):
    """Textured material, Apply, albedo and normal still linked, save, reopen where the add-on
    is not installed: the same pixels (what a render farm sees)."""
    import bpy

    import makeup_skin_addon

    material = _apply(head, coverage=0.8, foundation="medium_beige")
    node = _group_node(material)
    assert node.inputs["Skin Color"].is_linked and node.inputs["Normal"].is_linked
    before = _render(tmp_path, "before")
    path = tmp_path / "walk.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    makeup_skin_addon.unregister()
    try:
        bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
        assert not hasattr(bpy.types.Material, "makeup_skin")
        after = _render(tmp_path, "after")
    finally:
        makeup_skin_addon.register()
    np.testing.assert_array_equal(after, before)
    assert json.loads(bpy.data.materials["Head Skin"].node_tree.nodes["Made-up Skin"]
                      .node_tree["makeup_skin_fit"])["images"]


def test_apply_adds_little_to_the_file(head, tmp_path):
    """The .blend keeps the bake's record and the view-angle image (5.7 kB), not the tables:
    Apply adds a few hundred kilobytes per skin, not the 21.6 MB of tables it used to pack."""
    import bpy

    def saved_size(name):
        path = tmp_path / f"{name}.blend"
        bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True, compress=False)
        return path.stat().st_size

    other = character.build_character("Other", location=(0.3, 0.0, 0.0))
    before = saved_size("before")
    _apply(head)
    _apply(other, "LAYERED", skin="jensen_skin1")  # two skins: two groups, two images
    assert saved_size("after") - before < 600e3  # measured 2 x 237 kB: the groups' nodes
    assert len([image for image in bpy.data.images if image.name.startswith("MakeupSkin")]) == 2


def test_undo_restores_the_material_apply_changed(head):
    """Apply pushes an undo step (run with ``undo=True``, as the UI runs operators); undoing it
    gives the artist's tree back."""
    import bpy

    before = _tree_state(head.active_material)
    head.active_material.makeup_skin.resolution = "preview"
    bpy.ops.ed.undo_push(message="before Apply")  # headless Blender starts with undo off
    assert bpy.ops.makeup_skin.apply("EXEC_DEFAULT", True) == {"FINISHED"}
    assert _tree_state(bpy.data.materials["Head Skin"]) != before
    bpy.ops.ed.undo()
    assert _tree_state(bpy.data.materials["Head Skin"]) == before


CHECK_DAMAGED = """
import json, os, sys, tempfile
os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp()
sys.path[:0] = [{root!r}, {tools!r}]
import bpy
bpy.ops.wm.open_mainfile(filepath={path!r}, load_ui=False)
import render_sphere
with render_sphere.addon_registered():
    from makeup_skin_addon import material as made_up
    material = bpy.data.materials["Head Skin"]
    found = made_up.check_material(bpy.context, material)
    again = made_up.check_material(bpy.context, material)
    print("RESULT", json.dumps([found, again]))
"""


def test_damaged_packed_image_is_repaired_without_a_crash(head, tmp_path):
    """A .blend whose packed view-angle image has a damaged OpenEXR header (a channel list of
    absurd size: Blender 5.0.1 aborts when it decodes it): Check Tables finds it by the packed
    bytes' hash, never decodes it, and rebuilds it.  In a subprocess, so an abort fails only
    this test."""
    import subprocess

    import bpy

    _apply(head)
    packed = bytes(_lut_images()[0].packed_file.data)
    path = tmp_path / "damaged.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), compress=False)
    data = bytearray(path.read_bytes())
    start = data.index(packed)
    # The attribute "channels": its name, its type "chlist", then its size (4 bytes).
    size_at = data.index(b"chlist\x00", start) + len(b"chlist\x00")
    data[size_at:size_at + 4] = (0x7FFFFFFF).to_bytes(4, "little")
    path.write_bytes(bytes(data))
    repo = Path(__file__).resolve().parent.parent
    script = CHECK_DAMAGED.format(root=str(repo), tools=str(repo / "tools"), path=str(path))
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    line = next(x for x in run.stdout.splitlines() if x.startswith("RESULT "))
    (intact, sentence), (repaired, _) = json.loads(line[len("RESULT "):])
    assert not intact and "damaged in the file" in sentence and "rebuilt it" in sentence
    assert repaired


def _lut_images():
    import bpy

    return [image for image in bpy.data.images if image.name.startswith("MakeupSkin LUT")]


class _Layout:
    """A stand-in for Blender's UILayout that records what a panel draws (headless Blender
    draws no panels)."""

    def __init__(self, drawn=None):
        self.drawn = [] if drawn is None else drawn
        self.use_property_split = self.use_property_decorate = False
        self.enabled = self.active = True

    def _child(self, *args, **kwargs):
        return _Layout(self.drawn)

    row = column = box = _child

    def prop(self, data, name, **kwargs):
        self.drawn.append(("prop", name, kwargs.get("text"), self.enabled))

    def label(self, text="", **kwargs):
        self.drawn.append(("label", text))

    def operator(self, idname, **kwargs):
        self.drawn.append(("operator", idname))
        return type("Properties", (), {})()

    def menu(self, *args, **kwargs):
        self.drawn.append(("menu",))

    def separator(self, *args, **kwargs):
        pass


def test_panel_shows_revert_and_a_linked_skin_colour(head):
    import bpy

    from makeup_skin_addon import ui

    layout = _Layout()
    ui.draw_settings(layout, bpy.context)
    assert ("operator", "makeup_skin.apply") in layout.drawn
    _apply(head)
    layout = _Layout()
    ui.draw_settings(layout, bpy.context)
    assert ("operator", "makeup_skin.revert") in layout.drawn
    assert ("prop", "skin_colour", "Skin Color (linked)", False) in layout.drawn
