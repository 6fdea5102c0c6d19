"""The panels (makeup_skin_addon.ui), drawn into a stand-in layout (headless Blender draws no
panels): Apply before, Revert after, and a linked Skin Color shown as linked."""

from types import SimpleNamespace

from support.addon_steps import apply_operator, view_images
from support.panel_layout import RecordingLayout


def test_panel_shows_revert_and_the_skin_from_the_shader(head):
    """Before Apply the skin preset's settings; over the artist's shader, the skin read from it
    (greyed: the next Apply reads it again) and no skin preset."""
    import bpy

    from makeup_skin_addon import ui

    layout = RecordingLayout()
    ui.draw_settings(layout, bpy.context)
    assert ("operator", "makeup_skin.apply") in layout.drawn
    apply_operator(head)
    layout = RecordingLayout()
    ui.draw_settings(layout, bpy.context)
    assert ("operator", "makeup_skin.revert") in layout.drawn
    labels = [item[1] for item in layout.drawn if item[0] == "label"]
    assert "Skin: the material's own shader (bare, and under the film)" in labels
    assert ("prop", "skin_roughness", "Skin Roughness (from the shader)", False) in layout.drawn
    assert not any(item[:2] == ("prop", "skin") for item in layout.drawn)


def test_drawing_the_panel_computes_nothing(head, monkeypatch):
    """The panel only reads what Apply stored: drawing it (Tier Auto included) bakes, fits,
    measures and chooses nothing, and says what the last Apply chose."""
    import bpy

    from lut_baker import auto_tier, bake
    from lut_baker.closures import fitting, tiers
    from makeup_skin_addon import ui

    apply_operator(head, tier="AUTO", foundation="clarins_112")
    calls = []
    for module, name in ((bake, "bake"), (fitting, "fit_closures"), (tiers, "tier_errors"),
                         (auto_tier, "choose"), (auto_tier, "traits_from_tables")):
        original = getattr(module, name)
        monkeypatch.setattr(module, name, lambda *a, _n=name, _f=original, **k: (
            calls.append(_n), _f(*a, **k))[1])
    layout = RecordingLayout()
    ui.draw_settings(layout, bpy.context)
    # the Properties editor's context has the material; the test's does not
    ui.draw_fit(layout, SimpleNamespace(material=head.active_material))
    assert calls == []
    chosen = [text for kind, *rest in layout.drawn if kind == "label"
              for text in rest[:1] if text.startswith("Auto: ")]
    assert chosen and "(at the last Apply)" in chosen[0], layout.drawn


def test_panel_says_when_the_file_was_repaired_on_opening(head, tmp_path):
    """The image deleted before saving: opening the file repairs it (makeup_skin_addon.on_load)
    and the panel shows one line about it, read from what the repair kept."""
    import bpy

    from makeup_skin_addon import on_load, ui

    apply_operator(head)
    layout = RecordingLayout()
    ui.draw_settings(layout, bpy.context)
    assert ("label", on_load.REPAIRED) not in layout.drawn
    bpy.data.images.remove(view_images()[0])
    path = tmp_path / "missing_image.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    assert len(view_images()) == 1  # rebuilt on opening
    layout = RecordingLayout()
    ui.draw_settings(layout, bpy.context)
    assert ("label", on_load.REPAIRED) in layout.drawn


def test_panel_shows_the_shade_buttons_and_what_is_out_of_reach(head):
    """Match Skin, Lighter and Darker beside the shade, Film and Thickness beside the
    foundation; after the first Apply matched a fair head with the paper's film (whose red it
    cannot reach) the panel says so in words, read from what Apply stored; a matte product's
    Film Roughness says it has no gloss to roughen."""
    import bpy
    from support import character

    from makeup_skin_addon import ui

    fair = character.skin_albedo_image(0, tone="lighter")
    head.active_material.node_tree.nodes["Albedo"].image = fair
    material = apply_operator(head, film_mode="PAPER")
    layout = RecordingLayout()
    ui.draw_settings(layout, bpy.context)
    assert ("operator", "makeup_skin.match_skin") in layout.drawn
    assert sum(1 for item in layout.drawn if item[:2] == ("operator", "makeup_skin.shade_step"))\
        == 2
    labels = [item[1] for item in layout.drawn if item[0] == "label"]
    assert "Shade: matched to the skin" in labels
    assert any(text.startswith("Red out of the film's reach") for text in labels), labels
    props = [item[1] for item in layout.drawn if item[0] == "prop"]
    assert "film_mode" in props and "thickness_um" in props
    material.makeup_skin.foundation = "clarins_103"
    layout = RecordingLayout()
    ui.draw_settings(layout, bpy.context)
    assert ("prop", "film_roughness", "Film Roughness (matte: no gloss)", True) in layout.drawn
