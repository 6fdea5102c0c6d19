"""lut_baker.closures.principled_albedo: a Principled BSDF's albedo under uniform white light,
its split into gloss and body, the measured subsurface ratios and the inverse; one render
check (Cycles) of the function against tests/support/furnace_albedo.py's sphere."""

import itertools

import numpy as np
import pytest

from lut_baker.closures import cycles as cc
from lut_baker.closures import principled_albedo as pa

METHODS = cc.SUBSURFACE_METHODS
CASES = list(itertools.product(METHODS, pa.ENGINES, pa.DISTRIBUTIONS))
TABLE_NOISE = max(entry["standard_error"]
                  for entry in pa.albedo_table()["cycles"]["subsurface_ratio"].values())
"""The table's largest standard error of a ratio (Base Colors from 0.06 up), as measured."""
REPLICA_RESIDUAL = 0.0025
"""Cycles' gloss and W against the replicas': renders agree within 0.25% (measured by
tools/measure_principled_albedo.py, docs/principled_albedo.md)."""


def test_broadcasts_over_leading_axes():
    rng = np.random.default_rng(3)
    base = rng.uniform(0.0, 1.0, (4, 5, 3))
    whole = pa.principled_albedo(base, 0.45, 1.4, 1.0, "RANDOM_WALK")
    for part in (whole.total, whole.gloss, whole.body):
        assert part.shape == (4, 5, 3)
    one = pa.principled_albedo(base[2, 3], 0.45, 1.4, 1.0, "RANDOM_WALK")
    np.testing.assert_allclose(whole.total[2, 3], one.total, rtol=1e-12)
    with pytest.raises(ValueError, match="RGB"):
        pa.principled_albedo(np.ones((3, 2)), 0.5, 1.4)


@pytest.mark.parametrize("method, engine, distribution", CASES)
def test_black_base_gives_the_gloss_alone(method, engine, distribution):
    albedo = pa.principled_albedo(np.zeros(3), 0.4, 1.45, 1.0, method, engine, distribution)
    assert np.all(albedo.body == 0.0)
    np.testing.assert_allclose(albedo.total, albedo.gloss, rtol=1e-12)
    assert 0.0 < albedo.gloss[0] < 0.1 and np.ptp(albedo.gloss) == 0.0


@pytest.mark.parametrize("method, engine, distribution", CASES)
def test_body_grows_with_base_color_and_the_split_adds_up(method, engine, distribution):
    """Strictly, up to Base Color 0.9 (and to 1 without subsurface); above ~0.92 Cycles' random
    walks keep their single-scattering albedo at its ceiling, and their body stops growing."""
    base = np.linspace(0.0, 1.0, 401)[:, None] * np.ones(3)
    for roughness, ior, weight in itertools.product((0.0, 0.35, 0.75, 1.0), (1.3, 1.47, 1.6),
                                                    (0.0, 0.5, 1.0)):
        albedo = pa.principled_albedo(base, roughness, ior, weight, method, engine,
                                      distribution)
        grows = np.diff(albedo.body[:, 0]) > 0.0
        assert np.all(grows if weight == 0.0 else grows[base[1:, 0] <= 0.9]), (
            roughness, ior, weight)
        np.testing.assert_allclose(albedo.gloss + albedo.body, albedo.total, rtol=1e-12)
        np.testing.assert_allclose(albedo.gloss, albedo.gloss[0, 0])


def test_random_walk_bodies_level_off_near_white():
    top = np.array([0.93, 0.96, 1.0])
    for method in ("RANDOM_WALK", "RANDOM_WALK_SKIN"):
        body = pa.principled_albedo(top, 0.5, 1.45, 1.0, method).body
        assert np.ptp(body) < 0.01 * body.max(), (method, body)
    burley = pa.principled_albedo(top, 0.5, 1.45, 1.0, "BURLEY").body
    assert np.ptp(burley) > 0.05


@pytest.mark.parametrize("method, engine, distribution", CASES)
def test_total_stays_at_most_one_for_base_colors_up_to_one(method, engine, distribution):
    """Energy: no Base Color in [0, 1] reflects more than the sky sends (within the table's
    measured noise: EEVEE's gloss and W are measured too)."""
    base = np.linspace(0.0, 1.0, 201)[:, None] * np.ones(3)
    for roughness, ior in itertools.product(np.linspace(0.0, 1.0, 11), (1.2, 1.3, 1.45, 1.6)):
        total = pa.principled_albedo(base, roughness, ior, 1.0, method, engine,
                                     distribution).total
        assert total.max() <= 1.0 + TABLE_NOISE, (roughness, ior, total.max())


def test_multiscatter_conserves_energy_and_ggx_loses_some():
    for roughness, ior in itertools.product((0.0, 0.3, 0.6, 1.0), (1.3, 1.5, 1.6)):
        gloss, passed = pa.specular_layer(roughness, ior)
        assert gloss + passed == pytest.approx(1.0, abs=1e-6)
        gloss_ggx, passed_ggx = pa.specular_layer(roughness, ior, "GGX")
        assert gloss_ggx <= gloss + 1e-12 and passed_ggx < passed
    # Rougher or lower index: less gloss
    assert pa.specular_layer(0.7, 1.45)[0] < pa.specular_layer(0.3, 1.45)[0]
    assert pa.specular_layer(0.5, 1.3)[0] < pa.specular_layer(0.5, 1.6)[0]
    assert pa.specular_layer(0.5, 1.0) == (0.0, 1.0)  # Cycles allocates no specular closure
    with pytest.raises(ValueError, match="ior"):
        pa.specular_layer(0.5, 0.9)
    with pytest.raises(ValueError, match="distribution"):
        pa.specular_layer(0.5, 1.4, "BECKMANN")


def test_diffuse_body_is_the_base_color_under_the_layer():
    """No subsurface: the layer passes W of a Lambertian Base Color (unclamped above 1, as
    Cycles' diffuse closure); the 'Lambert + gloss' reading overestimates by (1 - W) base."""
    base = np.array([[0.1, 0.5, 1.3]])
    gloss, passed = pa.rendered_layer(0.5, 1.45)
    albedo = pa.principled_albedo(base, 0.5, 1.45)
    np.testing.assert_allclose(albedo.body, passed * base, rtol=1e-12)
    np.testing.assert_allclose(base + gloss - albedo.total, (1.0 - passed) * base, rtol=1e-12)
    assert 0.04 < 1.0 - passed < 0.07


@pytest.mark.parametrize("distribution", pa.DISTRIBUTIONS)
def test_cycles_layer_is_the_replicas_within_their_measured_residual(distribution):
    for roughness, ior in itertools.product((0.0, 0.33, 0.5, 0.9), (1.3, 1.42, 1.6)):
        rendered = pa.rendered_layer(roughness, ior, distribution)
        replica = pa.specular_layer(roughness, ior, distribution)
        np.testing.assert_allclose(rendered, replica, rtol=REPLICA_RESIDUAL)
        assert rendered != replica


def test_subsurface_weight_mixes_linearly():
    base = np.array([0.07, 0.3, 0.65])
    half, diffuse, subsurface = (
        pa.principled_albedo(base, 0.4, 1.4, w, "RANDOM_WALK").total for w in (0.5, 0.0, 1.0))
    np.testing.assert_allclose(half, 0.5 * (diffuse + subsurface), rtol=1e-12)


def test_measured_ratios_follow_the_methods():
    """Random Walk (Skin) and Christensen-Burley stay near Base Color between 0.06 and 0.88;
    Random Walk, entering through a smooth interface, falls short at dark colours and recovers
    with Roughness; every random walk loses light near Base Color 1, Burley does not."""
    mid = np.linspace(0.06, 0.88, 30)
    for method in ("RANDOM_WALK_SKIN", "BURLEY"):
        ratio = pa.subsurface_ratio(mid, 0.5, 1.45, method)
        assert np.all(np.abs(ratio - 1.0) < 0.015), (method, ratio)
    smooth = pa.subsurface_ratio(0.1, 0.25, 1.45, "RANDOM_WALK")
    assert smooth < 0.92 < pa.subsurface_ratio(0.1, 1.0, 1.45, "RANDOM_WALK")
    for method in ("RANDOM_WALK", "RANDOM_WALK_SKIN"):
        assert pa.subsurface_ratio(1.0, 0.5, 1.45, method) < 0.95
    assert pa.subsurface_ratio(1.0, 0.5, 1.45, "BURLEY") > 0.99
    # Beyond the measured IOR range the ratio is held; EEVEE's subsurface is as bright as
    # diffuse
    assert pa.subsurface_ratio(0.3, 0.4, 1.8) == pa.subsurface_ratio(0.3, 0.4, 1.6)
    np.testing.assert_array_equal(pa.subsurface_ratio(mid, 0.4, 1.4, engine="EEVEE"), 1.0)
    with pytest.raises(ValueError, match="method"):
        pa.subsurface_ratio(0.3, 0.4, 1.4, "CUBIC")
    with pytest.raises(ValueError, match="engine"):
        pa.subsurface_ratio(0.3, 0.4, 1.4, engine="WORKBENCH")


def test_eevee_reflects_less_gloss_the_rougher_the_layer():
    """EEVEE's split-sum specular reflects less than Cycles' under a uniform sky, near equal for
    a mirror and ~25% less at Roughness 1 (measured); its body passes the rest."""
    for ior in (1.35, 1.55):
        ratios = []
        for roughness in (0.0, 0.5, 1.0):
            cycles = pa.principled_albedo(np.full(3, 0.4), roughness, ior)
            eevee = pa.principled_albedo(np.full(3, 0.4), roughness, ior, engine="EEVEE")
            ratios.append(eevee.gloss[0] / cycles.gloss[0])
            assert eevee.body[0] > cycles.body[0]
        assert 1.0 > ratios[0] > ratios[1] > ratios[2] > 0.6, (ior, ratios)


@pytest.mark.parametrize("method, engine", list(itertools.product(METHODS, pa.ENGINES)))
@pytest.mark.parametrize("weight", [0.0, 0.6, 1.0])
def test_base_color_for_body_inverts_the_body(method, engine, weight):
    base = np.array([[0.02, 0.3, 0.7], [0.11, 0.5, 0.9]])
    body = pa.principled_albedo(base, 0.45, 1.42, weight, method, engine).body
    found = pa.base_color_for_body(body, 0.45, 1.42, weight, method, engine)
    np.testing.assert_allclose(found, base, atol=2e-3)


def test_base_color_for_body_beyond_base_color_one():
    """Past Base Color 1 only the diffuse share grows: reachable unless the weight is 1."""
    body = pa.principled_albedo(np.array([1.2, 1.0, 0.5]), 0.5, 1.4, 0.5, "BURLEY").body
    np.testing.assert_allclose(pa.base_color_for_body(body, 0.5, 1.4, 0.5, "BURLEY"),
                               [1.2, 1.0, 0.5], atol=2e-3)
    top = pa.principled_albedo(np.ones(3), 0.5, 1.4, 1.0, "BURLEY").body
    np.testing.assert_allclose(pa.base_color_for_body(top * 1.1, 0.5, 1.4, 1.0, "BURLEY"), 1.0)


# --------------------------------------------------------------------------------------------
# Render check
# --------------------------------------------------------------------------------------------
RENDER_POINTS = (
    # (method, Subsurface Weight, Roughness, IOR, Base Color): off the table's nodes
    ("RANDOM_WALK", 1.0, 0.45, 1.38, (0.08, 0.27, 0.61)),
    ("RANDOM_WALK_SKIN", 1.0, 0.3, 1.35, (0.55, 0.33, 0.25)),
    ("RANDOM_WALK", 0.0, 0.3, 1.55, (0.08, 0.35, 0.7)),
)
NOISE_SIGMAS = 4.0
"""The render's own noise enters at this many standard errors (its estimate was checked
against two seeds by the tool)."""


@pytest.mark.slow
def test_renders_match_the_function(bpy_factory):
    """The sphere under a white sky, 96 px, 64 samples (Cycles CPU, ~10 s): the function within
    the render's noise (4 standard errors), the table's and the replicas' measured residual."""
    from support import furnace_albedo as fa

    node = fa.build_scene(size=96, samples=64)
    for method, weight, roughness, ior, base in RENDER_POINTS:
        fa.set_principled(node, base, roughness, ior, subsurface_weight=weight, method=method)
        total, error, _ = fa.render_albedo()
        predicted = pa.principled_albedo(base, roughness, ior, weight, method).total
        tolerance = NOISE_SIGMAS * error / total + TABLE_NOISE * weight + REPLICA_RESIDUAL
        relative = predicted / total - 1.0
        print(method, weight, base, "relative error", relative.round(4), "tolerance",
              tolerance.round(4))
        assert np.all(np.abs(relative) < tolerance), (method, relative, tolerance)
