"""The apply pipeline (makeup_skin_addon.apply), headless: Apply and render every tier on
a sphere, the report when a tier is not made for the scene's engine, reuse without
duplicates, the scene's unit scale; on the textured head, a shared material converted once,
the active slot only, linked library data refused, and the progress through bake and fit.
Cycles CPU at 16 samples."""

import json

import numpy as np
import pytest
from support import character
from support.addon_steps import (
    SPHERE_PX,
    apply_operator,
    apply_pipeline,
    cold_caches,
    counts,
    group_node,
    render,
    tree_state,
)


@pytest.mark.parametrize("tier", ["PRINCIPLED", "LAYERED", "EEVEE"])
def test_apply_and_render(sphere, tmp_path, tier):
    from lut_baker.closures.tier_registry import tier as registered

    material, messages = apply_pipeline(sphere, tier)
    assert material.makeup_skin.is_made_up
    group = material.node_tree.nodes["Made-up Skin"].node_tree
    assert group.name.startswith(f"Made-up Skin {registered(tier).label} ")
    meta = json.loads(group["makeup_skin_fit"])
    assert meta["tier"] == tier and meta["subsurface_method"] in ("BURLEY", "RANDOM_WALK_SKIN")
    if tier == "EEVEE":  # EEVEE's screen-space subsurface is Burley's
        assert meta["subsurface_method"] == "BURLEY"
    errors = json.loads(material["makeup_skin_errors"])
    # A Cycles scene: the Cycles tiers are fitted and measured, and the tier chosen (the
    # session's fit may hold more: test_apply_fits_the_engines_tiers... starts cold).
    assert {"PRINCIPLED", "LAYERED", tier} <= set(errors)
    # The scene renders with Cycles: the EEVEE tier is reported as made for EEVEE.
    assert any("made for EEVEE" in m for m in messages) == (tier == "EEVEE"), messages
    pixels = render(tmp_path)
    assert np.all(np.isfinite(pixels)) and pixels.min() >= 0.0
    disc = pixels.mean(axis=-1) > 1e-4
    assert 0.4 < disc.mean() < 0.9  # the sphere fills the middle of the frame
    # Plausible brightness: a sun of irradiance pi on a surface of albedo ~0.7.
    assert 0.05 < pixels[disc].mean() < 0.8
    # The sun is 60 degrees towards +x: the right half is brighter than the left.
    half = SPHERE_PX // 2
    left, right = pixels[:, :half][disc[:, :half]], pixels[:, half:][disc[:, half:]]
    assert right.mean() > 1.5 * left.mean()


def test_report_says_when_a_tier_is_not_made_for_the_engine(sphere):
    """In EEVEE a Cycles tier is built as asked and the report names the EEVEE tier and its
    error; Auto takes the EEVEE tier and says nothing; back in Cycles the EEVEE tier is
    reported the other way round.  Nothing is rendered."""
    import bpy

    scene = bpy.context.scene
    scene.render.engine = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else \
        "BLENDER_EEVEE_NEXT"
    material, messages = apply_pipeline(sphere, "LAYERED")
    assert group_node(material).node_tree["makeup_skin_fit"]  # built all the same
    note = [m for m in messages if "made for Cycles" in m]
    assert len(note) == 1 and "the EEVEE tier is fitted to EEVEE (" in note[0], messages
    error = json.loads(material["makeup_skin_errors"])["EEVEE"]["rms"]
    assert f"{100 * error:.1f}% angular error" in note[0]
    material, messages = apply_pipeline(sphere, "AUTO")
    assert json.loads(group_node(material).node_tree["makeup_skin_fit"])["tier"] == "EEVEE"
    assert not any("made for" in m for m in messages), messages
    scene.render.engine = "CYCLES"
    _, messages = apply_pipeline(sphere, "EEVEE")
    assert any("made for EEVEE" in m and "the Layered tier is fitted to Cycles" in m
               for m in messages), messages


def test_apply_fits_the_engines_tiers_and_another_when_it_is_asked_for(sphere):
    """Apply fits and measures the tiers made for the scene's engine (in Cycles not the
    EEVEE tier's film pair); switched to EEVEE, Tier Auto fits the EEVEE tier then, onto the
    same fit, and chooses it."""
    import bpy

    from makeup_skin_addon import bakes, nodes

    cold_caches()
    material, _ = apply_pipeline(sphere, "AUTO")
    meta = nodes.read_meta(group_node(material).node_tree)
    assert set(json.loads(material["makeup_skin_errors"])) == {"PRINCIPLED", "LAYERED"}
    assert bakes.cached(meta, tiers=("PRINCIPLED", "LAYERED")) is not None
    assert bakes.cached(meta, tiers=("EEVEE",)) is None
    bpy.context.scene.render.engine = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else \
        "BLENDER_EEVEE_NEXT"
    material, _ = apply_pipeline(sphere, "AUTO")
    assert nodes.read_meta(group_node(material).node_tree)["tier"] == "EEVEE"
    assert set(json.loads(material["makeup_skin_errors"])) == {"PRINCIPLED", "LAYERED",
                                                                "EEVEE"}
    assert bakes.cached(meta, tiers=("PRINCIPLED", "LAYERED", "EEVEE")) is not None


def test_apply_operator_and_twice_creates_no_duplicates(sphere):
    import bpy

    sphere.data.materials.append(bpy.data.materials.new("Skin"))
    sphere.active_material.makeup_skin.tier = "LAYERED"
    sphere.active_material.makeup_skin.resolution = "preview"
    assert bpy.ops.makeup_skin.apply() == {"FINISHED"}
    before = counts()
    material, messages = apply_pipeline(sphere, "LAYERED")
    assert messages == []  # the stored tables were found intact
    assert counts() == before
    assert sphere.active_material == material
    assert len(sphere.material_slots) == 1


def test_scene_unit_scale_sets_the_blur(sphere):
    import bpy

    bpy.context.scene.unit_settings.scale_length = 0.01  # modelled in centimetres
    material, _ = apply_pipeline(sphere, "PRINCIPLED")
    node = material.node_tree.nodes["Made-up Skin"]
    assert node.inputs["Units per mm"].default_value == pytest.approx(0.1)


@pytest.mark.slow  # heads: ~1 s each
def test_shared_material_is_converted_once_and_reported(head, capfd):
    import bpy

    twin = character.build_character("Twin", location=(0.3, 0.0, 0.0))
    twin.data.materials[0] = head.active_material  # two characters, one material
    material = apply_operator(head)
    assert "shared by 2 objects" in capfd.readouterr().out
    assert twin.active_material == material == head.active_material
    nodes = len(material.node_tree.nodes)
    apply_operator(twin)
    assert len(material.node_tree.nodes) == nodes  # not converted twice
    assert len([m for m in bpy.data.materials if m.makeup_skin.is_made_up]) == 1


@pytest.mark.slow  # heads: ~1 s each
def test_multi_slot_object_converts_only_the_active_slot(head):
    import bpy

    eyes = bpy.data.materials.new("Eyes")
    if bpy.app.version < (5, 0, 0):
        eyes.use_nodes = True
    head.data.materials.append(eyes)
    untouched = tree_state(head.data.materials[0])
    head.active_material_index = 1
    apply_operator(head)
    assert [slot.material for slot in head.material_slots] == [
        bpy.data.materials["Head Skin"], eyes]
    assert tree_state(head.data.materials[0]) == untouched
    assert group_node(eyes) is not None


def _library_with_material(tmp_path):
    """A .blend holding the textured head's material, saved as a library."""
    import bpy

    obj = character.build_character("Lib")
    path = tmp_path / "library.blend"
    bpy.data.libraries.write(str(path), {obj.active_material}, fake_user=True)
    return path, obj.active_material.name


@pytest.mark.slow  # heads: ~1 s each
def test_linked_material_is_refused(head, tmp_path):
    import bpy

    path, name = _library_with_material(tmp_path)
    with bpy.data.libraries.load(str(path), link=True) as (source, target):
        target.materials = [name]
    linked = next(m for m in bpy.data.materials if m.library is not None and m.name == name)
    head.data.materials[0] = linked
    before = tree_state(linked)
    bpy.context.view_layer.objects.active = head
    for operator in (bpy.ops.makeup_skin.apply, bpy.ops.makeup_skin.fit_to_scene):
        # The poll's reason (Blender cuts it at 200 characters here; the tooltip has it all).
        with pytest.raises(RuntimeError, match=r"is linked from the library '.*library\.blend'"):
            operator()
    assert tree_state(linked) == before and not linked.makeup_skin.is_made_up
    assert not [g for g in bpy.data.node_groups if g.name.startswith("Made-up Skin")]


@pytest.mark.slow  # heads: ~1 s each
def test_apply_progress_covers_bake_and_fit(head):
    """The progress bar rises through the closure fit, not only the bake."""
    import bpy

    from makeup_skin_addon import apply, bakes

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

    cold_caches()  # so that the bake and the fit run
    head.active_material.makeup_skin.resolution = "preview"
    apply.apply_to_object(Context, head)
    values = Context.window_manager.values
    bake_share = 100 * bakes.BAKE_SHARE
    assert values == sorted(values) and values[-1] == 100
    assert len([v for v in values if bake_share < v < 100]) >= 3  # the fit's stages


def test_auto_decides_from_the_foundation_being_applied(sphere):
    """Tier Auto judges the foundation it applies, not the one the material had: after
    another foundation, two Applies of the same settings build the same group."""
    from makeup_skin_addon import groups

    apply_pipeline(sphere, "AUTO", foundation="paper_natural")
    first, _ = apply_pipeline(sphere, "AUTO", foundation="clarins_103")
    first_group = groups.group_of(first).node_tree.name
    second, _ = apply_pipeline(sphere, "AUTO", foundation="clarins_103")
    assert groups.group_of(second).node_tree.name == first_group
