"""The live preview (makeup_skin_addon.live): a setting that changes the tables re-bakes at
preview resolution, and no timer is left behind."""

import json

import pytest
from support.addon_steps import apply_pipeline

from lut_baker.model import presets


def test_live_update_rebakes_at_preview_resolution(sphere):
    import bpy

    from makeup_skin_addon import live

    material, _ = apply_pipeline(sphere, "PRINCIPLED", resolution="preview")
    node = material.node_tree.nodes["Made-up Skin"]
    before = node.node_tree["makeup_skin_fit"]
    material.makeup_skin.skin = "jensen_skin2"  # changes the tables
    assert material.name in live.pending()
    assert live.flush(bpy.context) == []
    assert not live.pending()
    after = node.node_tree["makeup_skin_fit"]
    assert json.loads(after)["key"] != json.loads(before)["key"]
    assert not bpy.app.timers.is_registered(live.rebake_timer)


def test_choosing_a_foundation_updates_its_gloss_live(sphere):
    """The Foundation dropdown sets everything the product is: its absorption at once (the
    paper's film: its own), its gloss (the film's lobe: roughness, index) by the debounced
    preview re-fit."""
    from makeup_skin_addon import groups, live, nodes

    material, _ = apply_pipeline(sphere, "LAYERED", foundation="clarins_103", film_mode="PAPER")
    matte = nodes.read_meta(groups.group_of(material).node_tree)
    material.makeup_skin.foundation = "clarins_112"
    assert material.name in live.pending()
    assert list(material.makeup_skin.absorption) == pytest.approx(
        presets.FOUNDATIONS["clarins_112"]["absorption"])
    live.flush()
    dewy = nodes.read_meta(groups.group_of(material).node_tree)
    assert dewy["parameters"]["film"] != matte["parameters"]["film"]
    assert dewy["parameters"]["film"]["P_s"] > 0.0 == matte["parameters"]["film"]["P_s"]
    assert dewy["glossy"]["film_gloss"] != matte["glossy"]["film_gloss"]


def test_roughness_moves_the_gloss_live_and_a_picked_colour_at_once(sphere):
    """Film and Skin Roughness re-fit the preview (the film's and the skin's lobe in the bake);
    with the paper's film a colour picked sets the group's absorption at once, with no
    re-bake (a film at a thickness bakes its absorption:
    test_a_thickness_moves_the_film_live_without_fitting)."""
    from support.addon_steps import counts

    from makeup_skin_addon import groups, live, nodes

    material, _ = apply_pipeline(sphere, "LAYERED", resolution="preview", film_mode="PAPER")
    settings = material.makeup_skin
    before = nodes.read_meta(groups.group_of(material).node_tree)["parameters"]
    settings.film_roughness = 0.4
    settings.skin_roughness = 0.55
    assert material.name in live.pending()
    live.flush()
    after = nodes.read_meta(groups.group_of(material).node_tree)["parameters"]
    assert after["film"]["n"] > before["film"]["n"] and after["skin"]["n"] > before["skin"]["n"]
    before_groups = counts()[0]
    settings.absorption_mode = "COLOUR"
    settings.shade_colour = presets.FOUNDATIONS["clarins_108"]["colour"]
    node = groups.group_of(material)
    assert tuple(node.inputs["Foundation Absorption"].default_value)[:3] == pytest.approx(
        presets.FOUNDATIONS["clarins_108"]["absorption"], abs=1e-6)
    assert not live.pending() and counts()[0] == before_groups


def _fingerprint(group):
    """Every node of ``group`` and its parts in order (type, label, operation or distribution,
    image name),
    the values of its unlinked inputs (rounded far below a render's precision) and its
    links: two groups of the same fingerprint render alike."""
    def value(item):
        data = getattr(item, "default_value", None)
        if data is None or isinstance(data, str):
            return None
        try:
            return tuple(round(float(v), 9) for v in data)
        except TypeError:
            return round(float(data), 9)

    from makeup_skin_addon import group_parts

    trees = [group, *group_parts.parts_of(group)]
    every = group_parts.nodes_of(group)
    index = {node.as_pointer(): i for i, node in enumerate(every)}
    nodes = [(node.bl_idname, node.label, getattr(node, "operation", None),
              getattr(node, "distribution", None),
              getattr(getattr(node, "image", None), "name", None),
              tuple((item.identifier, value(item)) for item in node.inputs
                    if not item.is_linked and item.enabled))
             for node in every]
    links = sorted((index[link.from_node.as_pointer()], link.from_socket.identifier,
                    index[link.to_node.as_pointer()], link.to_socket.identifier)
                   for tree in trees for link in tree.links)
    return nodes, links


def _rebuilt_in_background(material):
    """Set the pending rebuild off on a worker (what the debounce timer does), wait for it
    and swap it in (what the poll timer does)."""
    import bpy

    from makeup_skin_addon import live

    assert live.start(bpy.context) == []
    assert material.name in live.in_flight()
    assert live.wait(60.0)
    assert live.poll(bpy.context) == []
    assert material.name not in live.pending()


@pytest.mark.parametrize("tier", ["PRINCIPLED", "LAYERED", "EEVEE"])
def test_a_rebuild_in_the_background_gives_the_synchronous_group(sphere, tier):
    """A Foundation pick rebuilt on a worker thread and swapped in gives the group a
    synchronous rebuild gives: the same nodes, values and links, the same record.  The
    worker's group takes the group's own nodes again where its structure allows (the Layered
    tier's does here: its first node is the one it had), the synchronous one is built anew in
    a new group."""
    import bpy

    from makeup_skin_addon import groups, live, nodes, rebuild

    material, _ = apply_pipeline(sphere, tier, foundation="light_ivory")
    groups.group_of(material).node_tree.nodes[0]["first"] = True
    material.makeup_skin.foundation = "clarins_112"
    _rebuilt_in_background(material)
    group = groups.group_of(material).node_tree
    if tier == "LAYERED":
        assert group.nodes[0].get("first")  # its nodes taken again, values set anew
    background = _fingerprint(group), nodes.read_meta(group)
    fresh = bpy.data.node_groups.new("fresh", "ShaderNodeTree")
    rebuild.rebuild_from_settings(bpy.context, material, fresh, live.PREVIEW)
    assert groups.group_of(material).node_tree == fresh
    assert _fingerprint(fresh) == background[0]
    meta = nodes.read_meta(fresh)
    for key in ("key", "tier", "parameters", "glossy", "eevee_glossy", "measured"):
        assert meta.get(key) == background[1].get(key), key


def test_a_newer_change_supersedes_a_rebuild_in_flight(sphere):
    """A change while a rebuild is in flight stops it and drops its result (never swapped
    in, even when it finished first); the newer settings' rebuild is what the material gets.
    Apply and Revert drop what is pending too."""
    import bpy

    from makeup_skin_addon import groups, live, nodes

    material, _ = apply_pipeline(sphere, "LAYERED")
    settings = material.makeup_skin
    before = nodes.read_meta(groups.group_of(material).node_tree)["key"]
    settings.foundation = "clarins_105"
    live.start(bpy.context)
    settings.foundation = "deep_mocha"  # supersedes clarins_105's rebuild
    assert live.in_flight() == set() and material.name in live.pending()
    assert live.wait(60.0)
    live.poll(bpy.context)
    assert nodes.read_meta(groups.group_of(material).node_tree)["key"] == before
    _rebuilt_in_background(material)
    meta = nodes.read_meta(groups.group_of(material).node_tree)
    assert meta["parameters"]["film"] == nodes.read_meta(groups.group_of(
        apply_pipeline(sphere, "LAYERED")[0]).node_tree)["parameters"]["film"]
    assert meta["key"] != before
    settings.foundation = "clarins_108"
    live.start(bpy.context)
    live.cancel(material)  # what Apply and Revert do first
    assert live.pending() == set()
    assert live.wait(60.0) and live.poll(bpy.context) == []
    assert nodes.read_meta(groups.group_of(material).node_tree)["key"] == meta["key"]


def test_flush_waits_for_a_rebuild_in_flight(sphere):
    """Headless, flush does everything at once: a rebuild in flight is waited for and
    swapped in, one only marked is computed there."""
    import bpy

    from makeup_skin_addon import groups, live, nodes

    material, _ = apply_pipeline(sphere, "PRINCIPLED")
    material.makeup_skin.foundation = "medium_beige"
    live.start(bpy.context)
    assert material.name in live.in_flight()
    assert live.flush(bpy.context) == []
    assert live.pending() == set()
    meta = nodes.read_meta(groups.group_of(material).node_tree)
    assert meta["parameters"]["film"] == nodes.read_meta(groups.group_of(apply_pipeline(
        sphere, "PRINCIPLED", foundation="medium_beige")[0]).node_tree)["parameters"]["film"]


def test_an_apply_at_preview_first_is_refined_in_the_background(sphere):
    """With an event loop Apply bakes a new bake at preview resolution first, and the
    settings' resolution follows from a worker (:func:`live.refine`): the same group as an
    Apply at that resolution.  An Apply whose bake the file has is not done twice."""
    import bpy

    from makeup_skin_addon import apply, groups, live, nodes

    sphere.data.materials.append(bpy.data.materials.new("Skin"))
    settings = sphere.active_material.makeup_skin
    settings.tier, settings.resolution = "LAYERED", "default"
    material, report = apply.apply_to_object(bpy.context, sphere, preview_first=True)
    group = groups.group_of(material).node_tree
    assert report.refine == "default" and nodes.read_meta(group)["resolution"] == "preview"
    assert any("preview resolution first" in sentence for sentence in report)
    live.refine(bpy.context, material, report.refine)
    live.wait(60.0)
    live.poll(bpy.context)
    refined = groups.group_of(material).node_tree
    meta = nodes.read_meta(refined)
    assert meta["resolution"] == "default" and refined == group  # rebuilt in place
    again, report = apply.apply_to_object(bpy.context, sphere, preview_first=True)
    assert report.refine is None and groups.group_of(again).node_tree == refined
    assert nodes.read_meta(refined)["key"] == meta["key"]


def test_unregister_leaves_no_worker_or_timer(addon, bpy_factory):
    """Unregistering while a rebuild is in flight stops its worker and waits for it: no
    thread, timer or pending material is left behind (bpy 4.5 hangs at exit otherwise)."""
    import threading

    import bpy
    from support import sphere_scene

    from makeup_skin_addon import live

    sphere = sphere_scene.add_sphere(bpy.context.scene, 0.03, size=32, samples=1)
    material, _ = apply_pipeline(sphere, "LAYERED")
    material.makeup_skin.foundation = "deep_mocha"
    live.start(bpy.context)
    assert material.name in live.in_flight()
    addon.unregister()
    try:
        assert not any(thread.name.startswith("Made-up Skin") for thread in
                       threading.enumerate())
        assert not bpy.app.timers.is_registered(live.rebake_timer)
        assert not bpy.app.timers.is_registered(live.poll_timer)
        assert live.pending() == set()
    finally:
        addon.register()


def test_a_thickness_moves_the_film_live_without_fitting(sphere, monkeypatch):
    """With the film at a thickness, a Thickness change re-reads the slab's tables baked for
    another thickness (no bake) and moves the fit there (no fit: the lobes kept,
    lut_baker.closures.fitting.at_thickness); the group's record keeps the new thickness.
    A picked colour (the absorption, baked) marks a rebuild."""
    from makeup_skin_addon import bakes, groups, live, nodes
    from makeup_skin_addon.core import bake, fitting

    material, _ = apply_pipeline(sphere, "LAYERED", resolution="preview", film_mode="SLAB")
    settings = material.makeup_skin
    assert settings.film_mode == "SLAB"
    settings.live_update = True
    calls = []
    monkeypatch.setattr(bake, "bake", lambda *a, **k: calls.append("bake"))
    monkeypatch.setattr(fitting, "fit_closures", lambda *a, **k: calls.append("fit"))
    settings.thickness_um = 40.0
    assert material.name in live.pending()
    live.flush()
    meta = nodes.read_meta(groups.group_of(material).node_tree)
    assert calls == [] and meta["film_thickness_um"] == 40.0
    assert meta["glossy"]["path3_gloss"]["roughness"] > 0.0
    monkeypatch.undo()
    settings.shade_colour = (0.5, 0.4, 0.3)
    assert material.name in live.pending()
    live.flush()
    after = nodes.read_meta(groups.group_of(material).node_tree)
    assert after["parameters"]["absorption"] == pytest.approx(list(settings.absorption),
                                                              abs=1e-7)
    bakes.clear()


def test_a_thickness_move_is_swapped_in_first_and_measured_after(sphere, monkeypatch):
    """Tier Auto, the film at a thickness: a Thickness move's rebuild measures nothing (the
    group of the tier chosen last, its fit moved, swapped in at once; no tier errors), and a
    rebuild that measures follows it once swapped in: the group's record and the material's
    tier errors then hold the new thickness's measurement."""
    from makeup_skin_addon import bakes, groups, live, nodes
    from makeup_skin_addon.keys import ERRORS_KEY

    material, _ = apply_pipeline(sphere, "AUTO", resolution="preview", film_mode="SLAB")
    settings = material.makeup_skin
    settings.live_update = True
    tier = nodes.read_meta(groups.group_of(material).node_tree)["tier"]
    measured = []
    original = bakes.measure
    monkeypatch.setattr(bakes, "measure", lambda *a, **k: measured.append(1) or original(
        *a, **k))
    settings.thickness_um = 40.0
    live.start()
    live.wait()
    live.poll()
    meta = nodes.read_meta(groups.group_of(material).node_tree)
    assert measured == [] and meta["film_thickness_um"] == 40.0 and meta["tier"] == tier
    assert meta["measured"] is None and material.name in live.pending()
    live.flush()
    meta = nodes.read_meta(groups.group_of(material).node_tree)
    assert measured and meta["film_thickness_um"] == 40.0 and meta["measured"]["errors"]
    errors = json.loads(material[ERRORS_KEY])
    assert {e["key"] for e in errors.values()} == {meta["key"]}
    assert live.pending() == set()
    bakes.clear()


def test_a_shade_step_at_a_thickness_shows_at_preview_first_then_refines(sphere, monkeypatch):
    """With the film at a thickness a shade change rebuilds the group (its absorption is
    baked): with an event loop, a bake the file has not seen goes at preview resolution first
    (the slab at its thickness alone) and the settings' resolution follows once it is swapped
    in; a shade whose bake the file has goes straight to it."""
    import bpy

    from makeup_skin_addon import apply, bakes, groups, live, nodes

    material, _ = apply_pipeline(sphere, "LAYERED", resolution="default", film_mode="SLAB",
                                 skin_colour=(0.45, 0.25, 0.15))
    material.makeup_skin.live_update = False
    assert bpy.ops.makeup_skin.match_skin() == {"FINISHED"}  # headless: rebuilt at once
    before = nodes.read_meta(groups.group_of(material).node_tree)["key"]
    shade = list(material.makeup_skin.absorption)
    monkeypatch.setattr(live, "can_refine", lambda: True)  # as with a window
    assert bpy.ops.makeup_skin.shade_step(direction="LIGHTER") == {"FINISHED"}
    assert material.name in live.in_flight()
    assert live.wait(60.0) and live.poll(bpy.context) == []
    shown = nodes.read_meta(groups.group_of(material).node_tree)
    assert shown["resolution"] == "preview" and shown["key"] != before
    assert bakes._BAKES.get(shown["key"]).one.slab.one_thickness  # its thickness alone
    assert material.name in live.in_flight()  # the refinement, set off by the swap
    assert live.wait(60.0) and live.poll(bpy.context) == []
    refined = nodes.read_meta(groups.group_of(material).node_tree)
    assert refined["resolution"] == "default" and not live.pending()
    assert not apply.preview_first(material)
    assert bpy.ops.makeup_skin.shade_step(direction="DARKER") == {"FINISHED"}
    assert apply.preview_first(material)  # the group was rebuilt in place: no first bake
    live.flush(bpy.context)  # flush follows the refinement too
    assert not live.pending()
    back = nodes.read_meta(groups.group_of(material).node_tree)
    assert back["resolution"] == "default" and back["key"] != refined["key"]
    assert list(material.makeup_skin.absorption) == pytest.approx(shade, abs=1e-6)


def test_a_preview_first_apply_at_a_thickness_bakes_it_alone(sphere):
    """With the film at a thickness an Apply at preview first bakes the slab's tables at that
    thickness only (lut_baker.bake.bake's one_thickness), kept apart from the axis's: its
    group is the one the axis's tables give (they are equal there).  A Thickness move before
    the refinement bakes the axis then and gives the film an Apply at preview resolution gives
    after the same move."""
    import bpy
    from support.addon_steps import cold_caches

    from makeup_skin_addon import apply, bakes, groups, live, nodes

    def moved(name, preview_first):
        material = bpy.data.materials.new(name)
        sphere.data.materials.clear()
        sphere.data.materials.append(material)
        settings = material.makeup_skin
        settings.tier, settings.film_mode, settings.thickness_um = "LAYERED", "SLAB", 9.6
        settings.resolution = "default" if preview_first else "preview"
        cold_caches()
        material, report = apply.apply_to_object(bpy.context, sphere,
                                                 preview_first=preview_first)
        group = groups.group_of(material).node_tree
        meta = nodes.read_meta(group)
        entry = bakes._BAKES.get(meta["key"])
        shown = _fingerprint(group), meta
        settings.live_update = True
        settings.thickness_um = 40.0
        assert material.name in live.pending()
        live.flush(bpy.context)
        group = groups.group_of(material).node_tree
        after = _fingerprint(group), nodes.read_meta(group)
        bpy.data.materials.remove(material)
        bpy.data.node_groups.remove(group)
        return report, entry, shown, after

    report, entry, shown, after = moved("Quick", True)
    assert report.refine == "default" and shown[1]["resolution"] == "preview"
    assert entry.tables is None and entry.one.slab.one_thickness
    assert entry.one.slab.thickness_um.tolist() == [shown[1]["film_thickness_um"]]
    assert after[1]["film_thickness_um"] == 40.0 and after[1]["resolution"] == "preview"
    _, series, shown_series, after_series = moved("Series", False)
    assert series.tables is not None and series.one is None
    assert series.tables.slab.thickness_um.size > 2
    for (fingerprint, meta), (expected, expected_meta) in ((shown, shown_series),
                                                          (after, after_series)):
        assert fingerprint == expected
        for key in ("key", "tier", "parameters", "glossy", "measured"):
            assert meta.get(key) == expected_meta.get(key), key
    cold_caches()
