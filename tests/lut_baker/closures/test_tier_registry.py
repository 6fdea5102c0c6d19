"""The tier registry (lut_baker.closures.tier_registry): the built-in tiers as registered, and a
toy tier registered from here, with no other file edited, seen by the panel's Tier items, the
Auto tier's candidates, the fit and the replicas, rendered in Cycles as its replica says, and
gone without a trace once unregistered."""

import contextlib

import numpy as np
import pytest
from support import bench_scene, sphere_scene

from lut_baker import auto_tier
from lut_baker.bake import bake
from lut_baker.closures import fitting, tier_registry, tiers
from lut_baker.closures.tier_formulas import Closure, ViewWeightedClosures, assemble
from lut_baker.model import presets
from lut_baker.model.made_up_skin import combine, coverage_weights, mix_slots
from lut_baker.offline.validation import compare

TOY = "TOY_DIFFUSE"


def _diffuse_only(fit, x, ops, subsurface_weight=None):
    """The made-up skin's diffuse albedo alone: one Diffuse closure where the film is (its
    diffuse and the skin's light through it), one on bare skin (the skin's colour)."""
    film = combine(coverage_weights(1.0, x.absorption), **mix_slots(
        film_diffuse=fit.film_albedo, through_film=x.skin_color * fit.transmittance_mean**2))
    return assemble(ViewWeightedClosures(
        covered=(Closure("diffuse", "made-up diffuse", film, "film"),),
        bare=(Closure("diffuse", "bare skin", x.skin_color, "skin"),),
        coverage=x.coverage), ops)


def _toy() -> tier_registry.Tier:
    return tier_registry.Tier(
        name=TOY, label="Toy Diffuse", description="The diffuse albedo alone (a test's tier)",
        number=99, engines=("CYCLES",), fullness=9,
        fit=lambda targets, over_shader: {"extra": {TOY: {}}},
        holds=lambda fit: TOY in fit.extra, shader=_diffuse_only,
        costs=tier_registry.Costs(relative_cost=0.2, noise_k=0.05))


@contextlib.contextmanager
def _registered():
    toy = tier_registry.register(_toy())
    try:
        yield toy
    finally:
        tier_registry.unregister(TOY)


@pytest.fixture(scope="module")
def preview_tables():
    return bake(presets.paper(), "preview")


def test_the_builtin_tiers_are_registered():
    """Three tiers, the two made for Cycles cheapest first, then EEVEE's; each engine's fullest
    first; numbers as files keep them."""
    assert tuple(tiers.TIERS) == ("PRINCIPLED", "LAYERED", "EEVEE")
    assert auto_tier.ENGINE_TIERS["CYCLES"] == ("LAYERED", "PRINCIPLED")
    assert auto_tier.ENGINE_TIERS["EEVEE"] == ("EEVEE",)
    assert [tier_registry.tier(name).number for name in tiers.TIERS] == [1, 2, 3]
    with pytest.raises(ValueError, match="is registered already"):
        tier_registry.register(_toy().__class__(**{**_toy().__dict__, "name": "LAYERED"}))
    with pytest.raises(ValueError, match="tier must be one of"):
        tier_registry.tier(TOY)


def test_a_toy_tier_is_fitted_and_measured(preview_tables):
    """Registered, a tier is one of the Auto tier's candidates (with its own costs), fitted on
    request (alone or onto a fit), measured, and its replica is its shader in numpy; once
    unregistered nothing lists it."""
    w, a = 0.5, 0.3
    with _registered():
        assert TOY in tiers.TIERS and auto_tier.ENGINE_TIERS["CYCLES"][-1] == TOY
        toy_candidates = [c for c in auto_tier.candidates("CYCLES") if c.tier == TOY]
        assert len(toy_candidates) == 4 and toy_candidates[0].name == "Toy Diffuse"
        assert auto_tier.relative_cost(toy_candidates[0]) == 0.2
        assert auto_tier.noise(toy_candidates[0], 25) == pytest.approx(0.01)
        fit = fitting.fit_closures(preview_tables, tiers=(TOY,), errors_at=(w, a))
        assert fit.tiers == (TOY,) and set(fit.errors) == {TOY} and fit.coat is None
        onto = fitting.fit_closures(preview_tables, tiers=("PRINCIPLED",), errors_at=(w, a))
        both = fitting.fit_closures(preview_tables, tiers=(TOY, "PRINCIPLED"), onto=onto)
        assert both.tiers == ("PRINCIPLED", TOY) and both.coat is onto.coat
        assert both.errors[TOY].rms == pytest.approx(fit.errors[TOY].rms, rel=1e-12)
        wi, wo = preview_tables.node_directions()
        skin = fit.skin_albedo
        film = fit.film_albedo * (1 - a) + skin * fit.transmittance_mean**2 * (1 - a)**2
        expected = (w * film + (1 - w) * skin) / np.pi
        replica = tiers.tier_replica(fit, preview_tables, TOY, w, a, 1.0, (wi, wo))
        np.testing.assert_allclose(replica, np.broadcast_to(expected, replica.shape),
                                   rtol=1e-12)
        assert 0.0 < fit.errors[TOY].rms < 1.0
    assert TOY not in tiers.TIERS and TOY not in auto_tier.ENGINE_TIERS["CYCLES"]
    assert all(c.tier != TOY for c in auto_tier.candidates("CYCLES"))


SIZE, SAMPLES, LIGHT_DEG = 32, 16, 45.0
RENDER_BOUND = 0.03
"""The toy tier's render (Lambertian closures only, a sun, no world) against its replica:
Cycles' noise at 16 samples and the sphere's silhouette."""


def test_a_toy_tier_is_in_the_panel_and_renders_as_its_replica(bpy_factory, preview_tables,
                                                                tmp_path):
    """The toy tier is an item of the Tier setting, Apply's path builds its group with no
    other file edited, Cycles renders it as its replica; unregistered, it is no item and the
    built-in tiers render as before."""
    from makeup_skin_addon import group_parts, groups, nodes, properties

    bpy = bpy_factory
    sphere = bench_scene.sphere_scene(size=SIZE, samples=SAMPLES, radius_mm=10.0)
    scene = bpy.context.scene
    scene.objects["Sun"].rotation_euler = (np.pi / 2, 0.0, np.radians(LIGHT_DEG))
    w, a = 0.5, 0.3
    with sphere_scene.addon_registered():
        with _registered():
            items = properties.tier_items()
            assert (TOY, "Toy Diffuse") in [item[:2] for item in items]
            material = sphere_scene.made_up_material(sphere, preview_tables, TOY, coverage=w,
                                                     absorption=a)
            assert material.makeup_skin.tier == TOY
            group = groups.group_of(material)
            assert nodes.read_meta(group.node_tree)["tier"] == TOY
            fit = fitting.fit_closures(preview_tables, tiers=(TOY,), errors_at=(w, a))
            nodes.set_inputs(group, {"Skin Color": tuple(map(float, fit.skin_albedo))})
            bench_scene.set_material(sphere, material)
            image = bench_scene.render_image()[1]
            replica = compare.local_image(
                lambda wi, wo: tiers.tier_replica(fit, preview_tables, TOY, w, a, 1.0,
                                                  (wi, wo)),
                SIZE, LIGHT_DEG, bench_scene.IRRADIANCE)
            error = compare.relative_rms(image, replica)
            print(f"the toy tier's render against its replica: {100 * error:.2f}%")
            assert error < RENDER_BOUND
            tree = group.node_tree
            bpy.data.materials.remove(material)
            group_parts.remove_group(tree)
        assert TOY not in [item[0] for item in properties.tier_items()]
        assert not [g for g in bpy.data.node_groups if "Toy Diffuse" in g.name]
