"""The panel's settings as the made-up skin (makeup_skin_addon.skin_model): the presets' own
layers at their own roughness, the lobes moved with Film and Skin Roughness."""

import pytest

from lut_baker.model import presets, roughness


def test_roughness_settings_in_the_model(addon, blank_scene):
    """At the presets' own roughness the layers are the presets' (the same bake key as before
    the setting existed); moved, the lobe follows the GGX width at constant gloss albedo; a
    matte film has nothing to roughen; choosing a foundation or a skin resets them."""
    import bpy

    from makeup_skin_addon import skin_model

    settings = bpy.data.materials.new("Skin").makeup_skin
    for foundation in ("paper_natural", "clarins_112", "clarins_103"):
        settings.foundation = foundation
        assert settings.film_roughness == pytest.approx(
            roughness.layer_roughness(presets.foundation_film(foundation)), abs=1e-6)
        skin = skin_model.skin_from_settings(settings)
        reference = presets.made_up_skin(foundation, settings.skin, coverage=1.0,
                                         absorption=0.0)
        assert skin.film.as_dict() == reference.film.as_dict()
        assert skin.skin_reflection.as_dict() == reference.skin_reflection.as_dict()
    settings.film_roughness = 0.4  # a matte product: no gloss, nothing changes
    assert skin_model.skin_from_settings(settings).film.as_dict() == presets.foundation_film(
        "clarins_103").as_dict()
    settings.foundation = "paper_natural"
    settings.film_roughness = 0.4
    settings.skin = "jensen_skin1"
    assert settings.skin_roughness == pytest.approx(0.616, abs=1e-3)
    settings.skin_roughness = 0.55
    skin = skin_model.skin_from_settings(settings)
    assert 1.0 / float(skin.film.n) == pytest.approx(float(roughness.lobe_width_deg(0.4)),
                                                     rel=1e-6)
    assert 1.0 / float(skin.skin_reflection.n) == pytest.approx(
        float(roughness.lobe_width_deg(0.55)), rel=1e-6)
    assert float(skin.film.P_s) > float(presets.paper().film.P_s)  # narrower, brighter peak
    settings.foundation = "paper_natural"
    assert settings.film_roughness == pytest.approx(0.7294, abs=1e-4)
