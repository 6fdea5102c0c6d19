"""Fit to Scene (makeup_skin_addon.tier_choice) and the Auto tier's choices rendered.

A distant scene renders with the chosen and the fullest candidate (Cycles CPU, 48 px, 256
samples) against lut_baker's reference: bare skin (the subsurface left out), a film whose
gloss is below the noise (Gloss 0 chosen) and the paper's (gloss kept).  The operator runs
on a close-up and a distant scene, on a film of index 1.01 and in EEVEE (the EEVEE tier).
tests/lut_baker/auto_tier/ tests the model without Blender.
"""

import math

import numpy as np
import pytest
from support import bench_scene, sphere_scene

from lut_baker import auto_tier, bake
from lut_baker.auto_tier import SceneDescription
from lut_baker.model import presets
from lut_baker.offline.validation import compare

SIZE, SAMPLES, DISTANT_RADIUS_MM = 48, 256, 150.0
DISTANT_SPHERE = SceneDescription(object_size_mm=2 * DISTANT_RADIUS_MM,
                                  footprint_mm=2 * DISTANT_RADIUS_MM / SIZE, samples=SAMPLES)


@pytest.fixture(scope="module")
def stage(bpy_factory):
    """One tests/support/bench_scene.py Stage (the reference's scene; ~6 s to build) for this
    module's renders: the 300 mm sphere 48 px across at 256 samples, the add-on registered
    while it lives."""
    with sphere_scene.addon_registered():
        yield bench_scene.Stage(size=SIZE, samples=SAMPLES, radius_mm=DISTANT_RADIUS_MM)


def _render(stage, tables, candidates):
    """The image of each candidate, by candidate.  Their render times are a benchmark's
    (``python bench/stability_sweep.py --costs``, docs/stability.md), not a test's: a busy
    machine moves them more than the candidates differ."""
    return {c: stage.render(tables, c)[1] for c in candidates}


@pytest.mark.slow
def test_distant_choice_is_within_tolerance(stage):
    """Bare skin (where the subsurface is most of the image and of the cost) on a 300 mm
    sphere 48 px across (6.25 mm per px; the skin's mean spread 1.15 mm = 0.18 px): the Auto
    choice is a cheaper way by the measured costs, and its error against the reference stays
    within the tolerance of the fullest one's."""
    from lut_baker.closures import fitting

    skin = presets.made_up_skin("paper_natural", "paper_bioplate", coverage=0.0)
    tables = bake.bake(skin, "preview")
    traits = auto_tier.traits_from_tables(tables, fitting.fit_closures(tables))
    choice = auto_tier.choose(DISTANT_SPHERE, traits)
    assert not choice.candidate.subsurface and choice.chosen.cost < 0.8
    # The spread is far below a pixel here (the predicted omission error is < 0.1%), and
    # the spread reference would need ~2e7 entry points: compare with the local reference.
    assert choice.prediction(choice.candidate).subsurface < 1e-3
    ref = compare.reference_image(skin, tables=tables, resolution=SIZE,
                                  radius_mm=DISTANT_RADIUS_MM, spread=False,
                                  irradiance=math.pi)
    images = _render(stage, tables, (choice.candidate, auto_tier.FULLEST))
    errors = {c.name: compare.relative_rms(image, ref) for c, image in images.items()}
    report = f"errors {errors}"
    chosen, fullest = choice.candidate.name, auto_tier.FULLEST.name
    assert all(np.all(np.isfinite(image)) and image.min() >= 0.0 for image in images.values())
    assert errors[chosen] <= errors[fullest] + choice.tolerance, report
    assert errors[chosen] <= choice.chosen.error, report  # the prediction bounds it


@pytest.mark.slow
def test_gloss_below_the_noise_is_left_out_measured(stage, paper_tables, paper_fit, matte):
    """A film of index 1.01 (Override Film's smallest Film IOR), whose gloss lobes make 0.9%
    of the image, on the distant sphere above: under the noise of the fullest tier (1.5% at
    256 samples) and the tolerance, so the Auto choice has Gloss 0 (and no subsurface).
    Rendered, it errs within the tolerance of the fullest tier, at a lower measured cost.
    The paper's film (its gloss 19% of the image) keeps its gloss in the same scene, and the
    same way without it errs as much as predicted (within a fifth)."""
    def setup(skin, tables, fit):
        ref = compare.reference_image(skin, tables=tables, resolution=SIZE,
                                      radius_mm=DISTANT_RADIUS_MM, spread=False,
                                      irradiance=math.pi)
        return tables, auto_tier.traits_from_tables(tables, fit), ref

    tables, traits, ref = setup(*matte)
    choice = auto_tier.choose(DISTANT_SPHERE, traits)
    assert not choice.candidate.gloss and not choice.candidate.subsurface, choice.reasons
    assert choice.chosen.gloss < 0.015 and "left out" in choice.reasons[2]
    assert choice.chosen.cost < 0.8  # by the measured costs
    images = _render(stage, tables, (choice.candidate, auto_tier.FULLEST))
    errors = {c: compare.relative_rms(image, ref) for c, image in images.items()}
    report = f"errors { {c.name: e for c, e in errors.items()} }"
    assert all(np.all(np.isfinite(image)) and image.min() >= 0.0 for image in images.values())
    assert errors[choice.candidate] <= errors[auto_tier.FULLEST] + choice.tolerance, report

    tables, traits, ref = setup(presets.made_up_skin("paper_natural", "paper_bioplate"),
                                paper_tables, paper_fit)
    strong = auto_tier.choose(DISTANT_SPHERE, traits)
    assert strong.candidate.gloss and not strong.candidate.subsurface, strong.reasons
    dropped = auto_tier.Candidate(strong.candidate.tier, subsurface=False, gloss=False)
    predicted = strong.prediction(dropped)
    assert predicted.error > strong.best_error + strong.tolerance
    measured = {c: compare.relative_rms(stage.render(tables, c)[1], ref)
                for c in (strong.candidate, dropped)}
    report = f"measured { {c.name: e for c, e in measured.items()} }, predicted {predicted}"
    assert measured[dropped] > measured[strong.candidate] + strong.tolerance, report
    assert measured[dropped] == pytest.approx(predicted.error, rel=0.2), report


def _scene_with_sphere(radius_mm, size, camera_distance_mm=None):
    """A low-poly sphere (the operator needs no render), a perspective camera
    ``camera_distance_mm`` away on -y (50 mm lens, 36 mm sensor), a sun, Cycles."""
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8, radius=radius_mm * 1e-3)
    sphere = bpy.context.active_object
    sphere_scene.light_and_camera(scene, radius_mm * 1e-3, 30.0)
    camera = scene.camera
    camera.data.type = "PERSP"
    camera.data.lens, camera.data.sensor_width, camera.data.sensor_fit = 50.0, 36.0, "AUTO"
    camera.location = (0.0, -camera_distance_mm * 1e-3, 0.0)
    sphere_scene.cycles_settings(scene, size=size, samples=128)
    material = bpy.data.materials.new("Skin")
    sphere.data.materials.append(material)
    material.makeup_skin.resolution = "preview"
    bpy.context.view_layer.objects.active = sphere
    return scene, sphere


def test_fit_to_scene_operator(addon):
    import json

    import bpy

    from makeup_skin_addon import groups, tier_choice

    # Close-up: a 60 mm sphere 300 mm from a 50 mm lens at 1000 px (0.216 mm per px).
    scene, sphere = _scene_with_sphere(30.0, 1000, camera_distance_mm=300.0)
    bpy.context.view_layer.update()  # matrix_world follows location only after an update
    described = tier_choice.describe_scene(scene, obj=sphere)
    assert described.footprint_mm == pytest.approx((300.0 - 0.0) * 36.0 / (50.0 * 1000.0),
                                                   rel=1e-3)
    assert described.object_size_mm == pytest.approx(60.0, rel=1e-3)
    assert described.lights_deg == (30.0,)
    assert bpy.ops.makeup_skin.fit_to_scene() == {"FINISHED"}
    material = sphere.active_material
    close = json.loads(material[tier_choice.CHOICE_KEY])
    assert close["subsurface"] and material.makeup_skin.subsurface_scale == 1.0
    assert groups.group_of(material).node_tree.name.startswith(
        f"Made-up Skin {close['tier'].title()}")
    # The same sphere 50 m away (36 mm per px): no subsurface, a cheaper choice.
    sphere.location.y = 50.0 - 0.3
    bpy.context.view_layer.update()
    assert bpy.ops.makeup_skin.fit_to_scene() == {"FINISHED"}
    far = json.loads(material[tier_choice.CHOICE_KEY])
    assert not far["subsurface"] and far["cost"] < close["cost"]
    assert far["gloss"] and material.makeup_skin.gloss == 1.0  # the paper's gloss: 19%
    assert material.makeup_skin.subsurface_scale == 0.0
    assert material[tier_choice.SAVED_SCALE_KEY] == 1.0
    node = groups.group_of(material)
    assert node.inputs["Subsurface Scale"].default_value == 0.0
    # Back to the close-up: the subsurface and the artist's scale come back.
    sphere.location.y = 0.0
    bpy.context.view_layer.update()
    assert bpy.ops.makeup_skin.fit_to_scene() == {"FINISHED"}
    assert material.makeup_skin.subsurface_scale == 1.0
    assert tier_choice.SAVED_SCALE_KEY not in material
    # A film of index 1.01 (its gloss 0.9% of the image, under the noise): Gloss 0 on the
    # material and its group node, the value before kept; the change re-bakes first (the
    # panel's live update, which the operator flushes).  The paper's film again: Gloss 1.
    # (The paper's film as published: a film at a thickness lets the skin's own gloss
    # through, 4.9% of the image, and keeps its Gloss.)
    settings = material.makeup_skin
    settings.film_mode = "PAPER"
    settings.override_film, settings.film_ior = True, 1.01
    assert bpy.ops.makeup_skin.fit_to_scene() == {"FINISHED"}
    matte = json.loads(material[tier_choice.CHOICE_KEY])
    assert matte["subsurface"] and not matte["gloss"], matte["reasons"]
    assert settings.gloss == 0.0 and material[tier_choice.SAVED_GLOSS_KEY] == 1.0
    assert groups.group_of(material).inputs["Gloss"].default_value == 0.0
    settings.override_film = False
    assert bpy.ops.makeup_skin.fit_to_scene() == {"FINISHED"}
    assert json.loads(material[tier_choice.CHOICE_KEY])["gloss"] and settings.gloss == 1.0
    assert tier_choice.SAVED_GLOSS_KEY not in material
    assert groups.group_of(material).inputs["Gloss"].default_value == 1.0
    # EEVEE: the EEVEE tier, through Auto as well.
    scene.render.engine = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else \
        "BLENDER_EEVEE_NEXT"
    material.makeup_skin.tier = "AUTO"
    assert tier_choice.resolve_tier(material.makeup_skin, scene) == "EEVEE"
    assert bpy.ops.makeup_skin.fit_to_scene(apply=False) == {"FINISHED"}
    assert json.loads(material[tier_choice.CHOICE_KEY])["tier"] == "EEVEE"
