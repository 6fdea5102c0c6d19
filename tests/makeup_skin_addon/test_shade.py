"""The shade, the film and the skin (makeup_skin_addon.shade): the colour seen picked and solved,
the roughness settings in the model, the skin's own colour (a value, an image's mean over the
material's faces), Match Skin and the shade steps, and the first Apply's match; rendered, the
made-up skin keeps the bare skin's colour and loses its blotches (Cycles, under uniform white
light: the light the match is defined for)."""

import numpy as np
import pytest
from support.addon_steps import apply_operator, apply_pipeline, group_node

from lut_baker.model import presets, roughness, thick_layer
from lut_baker.tables import uniform_light

PRODUCTS = ("clarins_103", "clarins_105", "clarins_108", "clarins_112")


def _settings(obj):
    settings = obj.active_material.makeup_skin
    settings.live_update = False
    return settings


@pytest.mark.parametrize("name", PRODUCTS)
def test_picking_a_products_colour_gives_its_preset(sphere, name):
    """The measured product's own colour (its bottle) picked in Colour mode: the preset's
    absorption, and the group node has it at once."""
    material, _ = apply_pipeline(sphere, "PRINCIPLED")
    settings = material.makeup_skin
    settings.absorption_mode = "COLOUR"
    settings.shade_colour = presets.FOUNDATIONS[name]["colour"]
    expected = presets.FOUNDATIONS[name]["absorption"]
    # The panel stores float32: the colour moved by ~3e-8, the absorption by about as much.
    assert tuple(settings.absorption) == pytest.approx(expected, abs=1e-6)
    assert tuple(group_node(material).inputs["Foundation Absorption"].default_value)[:3] == \
        pytest.approx(expected, abs=1e-6)
    assert settings.shade_source == "USER"
    assert (settings.shade_note != "") == (name == "clarins_105")  # 105's red is beyond reach


def test_a_picked_colour_is_the_thick_layer_of_the_solved_film(addon, blank_scene):
    """Reachable colours come back from the solved film's thick layer to 1e-6; a colour too
    light in red is clamped and the note says so in words; choosing a foundation shows its
    colour."""
    import bpy

    settings = bpy.data.materials.new("Skin").makeup_skin
    rng = np.random.default_rng(3)
    exchange = thick_layer.preset_film_exchange()
    for colour in rng.uniform(exchange.r_gloss + 0.01, 0.8, size=(5, 3)):
        settings.shade_colour = colour
        stored = np.asarray(settings.shade_colour, float)
        np.testing.assert_allclose(thick_layer.stack_reflectance(
            np.asarray(settings.absorption, float), exchange), stored, atol=1e-6)
        assert settings.shade_note == ""
    settings.shade_colour = (0.95, 0.5, 0.3)
    assert settings.absorption[0] == 0.0
    assert settings.shade_note.startswith("Red 0.950 is lighter than the film can be (0.834)")
    assert settings.shade_note.endswith("clamped")
    settings.foundation = "medium_beige"
    np.testing.assert_allclose(settings.shade_colour, thick_layer.stack_reflectance(
        np.asarray(presets.FOUNDATIONS["medium_beige"]["absorption"]), exchange), atol=1e-6)
    assert settings.shade_note == "" and settings.shade_source == "PRESET"
    settings.absorption = (0.2, 0.4, 0.6)  # by hand: the colour follows
    np.testing.assert_allclose(settings.shade_colour, thick_layer.stack_reflectance(
        np.array([0.2, 0.4, 0.6]), exchange), atol=1e-6)


def test_roughness_settings_in_the_model(addon, blank_scene):
    """At the presets' own roughness the layers are the presets' (the same bake key as before
    the setting existed); moved, the lobe follows the GGX width at constant gloss albedo; a
    matte film has nothing to roughen; choosing a foundation or a skin resets them."""
    import bpy

    from makeup_skin_addon import shade

    settings = bpy.data.materials.new("Skin").makeup_skin
    for foundation in ("paper_natural", "clarins_112", "clarins_103"):
        settings.foundation = foundation
        assert settings.film_roughness == pytest.approx(
            roughness.layer_roughness(presets.foundation_film(foundation)), abs=1e-6)
        skin = shade.skin_from_settings(settings)
        reference = presets.made_up_skin(foundation, settings.skin, coverage=1.0,
                                         absorption=0.0)
        assert skin.film.as_dict() == reference.film.as_dict()
        assert skin.skin_reflection.as_dict() == reference.skin_reflection.as_dict()
    settings.film_roughness = 0.4  # a matte product: no gloss, nothing changes
    assert shade.skin_from_settings(settings).film.as_dict() == presets.foundation_film(
        "clarins_103").as_dict()
    settings.foundation = "paper_natural"
    settings.film_roughness = 0.4
    settings.skin = "jensen_skin1"
    assert settings.skin_roughness == pytest.approx(0.616, abs=1e-3)
    settings.skin_roughness = 0.55
    skin = shade.skin_from_settings(settings)
    assert 1.0 / float(skin.film.n) == pytest.approx(float(roughness.lobe_width_deg(0.4)),
                                                     rel=1e-6)
    assert 1.0 / float(skin.skin_reflection.n) == pytest.approx(
        float(roughness.lobe_width_deg(0.55)), rel=1e-6)
    assert float(skin.film.P_s) > float(presets.paper().film.P_s)  # narrower, brighter peak
    settings.foundation = "paper_natural"
    assert settings.film_roughness == pytest.approx(0.7294, abs=1e-4)


def test_the_skin_colour_is_an_images_mean_over_the_faces(addon, blank_scene):
    """A grid whose image is one colour on the left half of the UV square and another on the
    right, its UVs spanning only the left three quarters: the mean is the area-weighted one
    over the faces (2/3 of the first, 1/3 of the second), linearised from sRGB; unlinked,
    Skin Color's value."""
    import bpy

    from makeup_skin_addon import shade

    bpy.ops.mesh.primitive_grid_add(x_subdivisions=40, y_subdivisions=40, size=2.0)
    plane = bpy.context.active_object
    uv = plane.data.uv_layers.active.data
    for loop in uv:
        loop.uv = (loop.uv[0] * 0.75, loop.uv[1])
    image = bpy.data.images.new("Halves", 64, 8)
    pixels = np.ones((8, 64, 4), np.float32)
    pixels[:, :32, :3] = (0.8, 0.5, 0.4)
    pixels[:, 32:, :3] = (0.2, 0.3, 0.9)
    image.pixels.foreach_set(pixels.ravel())
    material = bpy.data.materials.new("Skin")
    plane.data.materials.append(material)
    if material.node_tree is None:
        material.use_nodes = True
    tree = material.node_tree
    principled = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    # Blender's default grey is no skin colour: the panel's Skin Color stands.
    assert shade.skin_colour(material).source == "Skin Color's value"
    principled.inputs["Base Color"].default_value = (0.3, 0.2, 0.1, 1.0)
    found = shade.skin_colour(material)
    assert found.source == "the value of the shader's Base Color"
    np.testing.assert_allclose(found.rgb, (0.3, 0.2, 0.1), atol=1e-6)
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    tree.links.new(texture.outputs["Color"], principled.inputs["Base Color"])

    def linear(c):
        c = np.asarray(c)
        return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)

    expected = (2 * linear([0.8, 0.5, 0.4]) + linear([0.2, 0.3, 0.9])) / 3
    found = shade.skin_colour(material)
    np.testing.assert_allclose(found.rgb, expected, rtol=0.03)
    assert found.source.startswith("the mean of image 'Halves' over the ")


def test_match_skin_and_the_steps(sphere):
    """Match Skin: the covered skin's colour under uniform light equals the bare skin's (so the
    made-up skin has it at every coverage); Lighter / Darker: one step of 10%."""
    import bpy

    from makeup_skin_addon import shade

    material, _ = apply_pipeline(sphere, "LAYERED", skin_colour=(0.45, 0.25, 0.15))
    settings = material.makeup_skin
    assert bpy.ops.makeup_skin.match_skin() == {"FINISHED"}
    assert settings.shade_source == "MATCH" and settings.shade_note == ""
    light = shade.light_for(settings)
    skin = np.array([0.45, 0.25, 0.15])
    absorption = np.asarray(settings.absorption, float)
    bare = uniform_light.bare_colour(light, skin)
    np.testing.assert_allclose(uniform_light.covered_colour(light, absorption, skin), bare,
                               rtol=1e-5)
    assert tuple(group_node(material).inputs["Foundation Absorption"].default_value)[:3] == \
        pytest.approx(tuple(absorption), abs=1e-6)
    np.testing.assert_allclose(settings.shade_colour, shade.colour_seen(absorption), atol=1e-6)
    assert bpy.ops.makeup_skin.shade_step(direction="LIGHTER") == {"FINISHED"}
    lighter = uniform_light.covered_colour(light, np.asarray(settings.absorption), skin)
    np.testing.assert_allclose(lighter, 1.1 * bare, rtol=1e-5)
    assert bpy.ops.makeup_skin.shade_step(direction="DARKER") == {"FINISHED"}
    np.testing.assert_allclose(settings.absorption, absorption, atol=1e-5)


def test_the_first_apply_matches_the_skin(head):
    """Every setting at its default: the first Apply matches the shade to the mean of the
    albedo texture (the head's red is beyond the film: said so), coverage 0.6, the film's
    normal a weaker copy of the skin's; a chosen foundation is kept as chosen."""
    material = head.active_material
    settings = material.makeup_skin
    assert settings.shade_source == "DEFAULT" and settings.coverage == pytest.approx(0.6)
    import bpy

    bpy.context.view_layer.objects.active = head
    settings.resolution = "preview"
    assert bpy.ops.makeup_skin.apply() == {"FINISHED"}
    assert settings.shade_source == "MATCH" and settings.foundation == "paper_natural"
    assert settings.absorption[0] == 0.0 and 0.3 < settings.absorption[1] < settings.absorption[2]
    assert settings.shade_note.startswith("Red out of the film's reach")
    assert group_node(material).inputs["Film Normal"].is_linked


def test_a_dark_skin_gets_the_matte_film(addon, blank_scene):
    """Skin darker in blue than the paper film's own gloss: the first Apply takes the matte
    film, and its match reaches every channel."""
    import bpy

    from makeup_skin_addon import shade

    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.03)
    obj = bpy.context.active_object
    material, messages = apply_pipeline(obj, "PRINCIPLED", skin_colour=(0.25, 0.11, 0.06))
    settings = material.makeup_skin
    assert settings.foundation == shade.MATTE_FILM and settings.shade_note == ""
    assert any(m.startswith("Chose Clarins 103 (matte, measured)'s matte film") for m in messages)


def _mean(pixels, mask):
    return pixels[mask].mean(axis=0)


def _uniform_white(scene):
    """A white world (uniform light) and no lamps."""
    world = scene.world
    if world.node_tree is None:  # 4.5's black world is its colour alone
        world.use_nodes = True
    for node in world.node_tree.nodes:
        if node.type == "BACKGROUND":
            node.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
            node.inputs["Strength"].default_value = 1.0
    for obj in scene.objects:
        if obj.type == "LIGHT":
            obj.hide_render = True


def _render_rgba(tmp_path, name):
    import bpy
    from support import sphere_scene

    scene = bpy.context.scene
    scene.render.film_transparent = True
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = str(tmp_path / f"{name}.exr")
    bpy.ops.render.render(write_still=True)
    return sphere_scene.image_pixels(scene.render.filepath)


COVERAGES = (0.3, 0.6, 1.0)


@pytest.mark.slow  # eight renders
def test_rendered_the_match_keeps_the_sphere_colour(sphere, tmp_path):
    """A sphere of one skin colour under uniform white light, matched: the made-up skin's mean
    colour is within 3% of the bare skin's (coverage 0) in every channel at coverage 0.3, 0.6
    and 1 (Cycles; Layered and Principled tiers)."""
    import bpy

    scene = bpy.context.scene
    _uniform_white(scene)
    scene.cycles.samples = 64
    for tier in ("LAYERED", "PRINCIPLED"):
        material, _ = apply_pipeline(sphere, tier, skin_colour=(0.45, 0.25, 0.15))
        settings = material.makeup_skin
        settings.live_update = False
        assert bpy.ops.makeup_skin.match_skin() == {"FINISHED"}
        settings.coverage = 0.0
        bare_rgba = _render_rgba(tmp_path, f"{tier}_bare")
        mask = bare_rgba[..., 3] > 0.999
        bare = _mean(bare_rgba[..., :3], mask)
        for coverage in COVERAGES:
            settings.coverage = coverage
            made_up = _mean(_render_rgba(tmp_path, f"{tier}_{coverage}")[..., :3], mask)
            np.testing.assert_allclose(made_up, bare, rtol=0.03, err_msg=f"{tier} {coverage}")


@pytest.mark.slow  # twelve renders
def test_rendered_the_match_keeps_the_heads_colour_and_evens_its_blotches(head, tmp_path):
    """The textured head under uniform white light after the first Apply (matched to the mean
    of its albedo texture): green and blue within 3% of the bare skin's at every coverage; red,
    beyond the film's reach, within 1.5% of the shortfall Match Skin reported; and the blotches'
    contrast (the std of the luminance of the render over the render with Skin Color at the
    texture's mean) falls with coverage, to under a fifth at full coverage."""
    import bpy

    from makeup_skin_addon import shade

    scene = bpy.context.scene
    _uniform_white(scene)
    scene.cycles.samples = 64
    material = apply_operator(head, tier="AUTO")
    settings = material.makeup_skin
    settings.live_update = False
    light = shade.light_for(settings)
    skin = shade.skin_colour(material).rgb
    predicted = (uniform_light.covered_colour(light, np.asarray(settings.absorption), skin)
                 / uniform_light.bare_colour(light, skin))
    node = group_node(material)
    albedo = node.inputs["Skin Color"].links[0].from_socket
    means, contrast = {}, {}
    for coverage in (0.0,) + COVERAGES:
        settings.coverage = coverage
        textured = _render_rgba(tmp_path, f"tex_{coverage}")
        material.node_tree.links.remove(node.inputs["Skin Color"].links[0])
        node.inputs["Skin Color"].default_value = (*skin, 1.0)
        flat = _render_rgba(tmp_path, f"flat_{coverage}")
        material.node_tree.links.new(albedo, node.inputs["Skin Color"])
        mask = (textured[..., 3] > 0.999) & (flat[..., 3] > 0.999)
        means[coverage] = _mean(textured[..., :3], mask)
        weights = np.array([0.2126, 0.7152, 0.0722])
        contrast[coverage] = float(np.std((textured[mask][:, :3] @ weights)
                                          / (flat[mask][:, :3] @ weights)))
    for coverage in COVERAGES:
        ratio = means[coverage] / means[0.0]
        np.testing.assert_allclose(ratio[1:], 1.0, atol=0.03, err_msg=str(coverage))
        expected_red = 1.0 + coverage * (predicted[0] - 1.0)
        assert ratio[0] == pytest.approx(expected_red, abs=0.015), coverage
    values = [contrast[c] for c in (0.0,) + COVERAGES]
    assert all(b < a for a, b in zip(values, values[1:], strict=False)), values
    assert values[-1] < 0.2 * values[0], values
