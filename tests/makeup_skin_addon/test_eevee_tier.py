"""The EEVEE tier rendered in EEVEE against the exact model's sphere images, per light and
coverage (the reference's scene, tests/support/bench_scene.py: 48 x 48 px, a 256 x 128 mesh
sphere of 10 mm, the paper preset, a sun 0, 45 and 75 degrees from the view; EEVEE at 16
samples, shadows off: a convex sphere shadows nothing).

The reference is :func:`lut_baker.offline.validation.compare.reference_image` from "default"
tables with the skin's spread at a quarter of its entry samples (as test_render_compare.py);
the full-size measurement (64 px, "high" tables, every preset) is bench/eevee_tier.py's
(docs/speed_accuracy.md, "EEVEE").  EEVEE's images move by 0.2% between 16 and 64 samples,
so one render per case is its error.  Bounds: measured on 5.0.1 with margin for the other
Blender line and a busy machine.  Nine EEVEE renders of one shader: ~75 s per Blender line
on 2 shared cores (each render after the first takes ~10 s on software OpenGL)."""

import dataclasses

import numpy as np
import pytest
from support import bench_scene as scene_module
from support import sphere_scene

from lut_baker import bake
from lut_baker.closures import cycles as cc
from lut_baker.closures import fitting, tier_registry, tiers
from lut_baker.model import presets
from lut_baker.offline.validation import compare

pytestmark = pytest.mark.slow  # EEVEE renders on software OpenGL

SIZE = 48
SAMPLES = 16
RADIUS_MM = 10.0
LIGHTS_DEG = (0.0, 45.0, 75.0)
COVERAGES = (0.0, 0.5, 1.0)
SPREAD_PER_MEAN_FREE_PATH = 0.75
BIAS_BOUND = {0.0: 0.035, 0.5: 0.03, 1.0: 0.04}
"""Relative RMS against the exact image per coverage, any light: measured 2.1-2.8% on bare
skin (EEVEE's screen-space subsurface at the terminator), 2.1-2.4% at coverage 0.5 and
2.6-3.2% at full coverage (the paper film's gloss, which no sum of lobes EEVEE can render
follows closer than 2.1-3.0%: docs/speed_accuracy.md, "How close EEVEE's closures can come").
The goal was 2% on every image; where it is missed is measured by bench/eevee_tier.py and
listed in docs/addon.md, "Not done"."""
MEAN_BOUND = 0.03
"""The image's mean against the exact image's: measured 0.988-1.021 (the film gloss's
albedo may give 5% where that follows its shape closer, lobes.PAIR_ALBEDO_SLACK; most at
grazing light)."""
REPLICA_BOUND = 0.01
"""Full coverage against the tier's replica (:func:`lut_baker.closures.tiers.
eevee_tier_reflection`, no spread; the film hides the skin's): measured 0.3-0.5%, against
1.8-2.6% for the same lobes as Cycles renders them."""


@pytest.fixture(scope="module")
def made_up():
    """``(skin, tables, fit)`` of the paper preset (default tables)."""
    skin = presets.paper()
    tables = bake.bake(skin, "default")
    return skin, tables, fitting.fit_closures(tables)


@pytest.fixture(scope="module")
def renders(bpy_factory, made_up):
    """``{(coverage, light): image}``: the EEVEE tier in EEVEE."""
    skin, tables, _ = made_up
    sphere = scene_module.sphere_scene(size=SIZE, samples=SAMPLES, radius_mm=RADIUS_MM)
    scene = bpy_factory.context.scene
    sun = scene.objects["Sun"]
    out = {}
    with sphere_scene.addon_registered():
        materials = {}
        for coverage in COVERAGES:
            sphere.data.materials.clear()
            materials[coverage] = sphere_scene.made_up_material(sphere, tables, "EEVEE",
                                                                coverage=coverage)
        scene_module.use_eevee(scene, SAMPLES)
        for light in LIGHTS_DEG:
            sun.rotation_euler = (np.pi / 2, 0.0, np.radians(light))
            for coverage, material in materials.items():
                scene_module.set_material(sphere, material)
                out[coverage, light] = scene_module.render_image()[1]
    return out


@pytest.fixture(scope="module")
def references(made_up):
    """``{(coverage, light): image}``: the exact model's images."""
    skin, tables, _ = made_up
    out = {}
    for coverage in COVERAGES:
        at = skin.replace(coverage=coverage)
        for light in LIGHTS_DEG:
            out[coverage, light] = scene_module.exact_image(
                at, tables, size=SIZE, light_deg=light, radius_mm=RADIUS_MM,
                spread_per_mean_free_path=SPREAD_PER_MEAN_FREE_PATH)
    return out


@pytest.mark.parametrize("light", LIGHTS_DEG)
@pytest.mark.parametrize("coverage", COVERAGES)
def test_eevee_tier_against_the_exact_image(renders, references, coverage, light):
    image = renders[coverage, light]
    ref = references[coverage, light]
    mask = compare.sphere_mask(SIZE)
    assert np.all(np.isfinite(image)) and np.all(image >= 0.0)
    assert np.sum(image[~mask]) < 1e-3 * np.sum(image[mask])
    error = compare.relative_rms(image, ref)
    print(f"coverage {coverage:g}, light {light:g}: {100 * error:.2f}% against the exact image, "
          f"mean {image[mask].mean() / ref[mask].mean():.3f} of it")
    assert error < BIAS_BOUND[coverage]
    assert image[mask].mean() == pytest.approx(ref[mask].mean(), rel=MEAN_BOUND)


@pytest.mark.parametrize("light", LIGHTS_DEG)
def test_eevee_renders_the_tier_as_its_replica(renders, made_up, light):
    """At full coverage (the skin under the film, so the spread hardly shows) EEVEE renders the
    tier as the replica its lobes were fitted with, several times closer than as the same
    lobes rendered by Cycles (GGX exactly)."""
    _, tables, fit = made_up
    image = renders[1.0, light]

    def replica(reflection):
        return compare.local_image(
            lambda wi, wo: reflection(fit, tables, 1.0, 0.0, 1.0, (wi, wo)), SIZE, light,
            scene_module.IRRADIANCE)

    error = compare.relative_rms(image, replica(
        lambda fit_, tables_, *rest: tiers.tier_replica(fit_, tables_, "EEVEE", *rest)))
    print(f"light {light:g}: {100 * error:.2f}% against the replica")
    assert error < REPLICA_BOUND

    in_cycles = dataclasses.replace(
        tier_registry.EEVEE,
        glossy=lambda pairs, lobe: cc.pair_reflection(pairs, lobe.roughness))

    def as_cycles(fit_, tables_, coverage, absorption, gloss, directions):
        return tiers.tier_replica(fit_, tables_, in_cycles, coverage, absorption, gloss,
                                  directions)

    assert error < 0.4 * compare.relative_rms(image, replica(as_cycles))
