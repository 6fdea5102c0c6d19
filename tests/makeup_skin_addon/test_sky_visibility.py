"""What a uniform sky leaves to the skin's lobes (makeup_skin_addon.sky_visibility) and the
match that weighs the artist's colour by it (makeup_skin_addon.matching.seen_target): a convex
surface sees the whole sky, the bottom of a well the cone of its opening, a gloss seen at a
grazing view mirrors into the wall; the colour matched renders as the artist's."""

import numpy as np
import pytest

RADIUS = 0.02
"""The well's radius and depth (metres): its floor's centre sees the sky within 45 degrees."""


def _sphere_points(count=40_000, radius=0.1):
    i = np.arange(count) + 0.5
    z = 1.0 - 2.0 * i / count
    phi = np.pi * (1.0 + 5 ** 0.5) * i
    r = np.sqrt(1.0 - z ** 2)
    normals = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
    return radius * normals, normals


def _well(spacing=0.001):
    """Points of a round well of radius and depth :data:`RADIUS` in a square plane three radii
    across (the ground at z = 0, the floor at -RADIUS)."""
    grid = np.arange(-3 * RADIUS, 3 * RADIUS, spacing)
    x, y = np.meshgrid(grid, grid)
    x, y = x.ravel(), y.ravel()
    out = np.hypot(x, y) > RADIUS
    ground = np.stack([x[out], y[out], np.zeros(out.sum())], axis=1)
    floor = np.stack([x[~out], y[~out], np.full((~out).sum(), -RADIUS)], axis=1)
    angle = np.arange(0.0, 2 * np.pi, spacing / RADIUS)
    depth = np.arange(-RADIUS, 0.0, spacing)
    a, d = np.meshgrid(angle, depth)
    wall = np.stack([RADIUS * np.cos(a.ravel()), RADIUS * np.sin(a.ravel()), d.ravel()], axis=1)
    return np.concatenate([ground, floor, wall])


def _floor_centre(views):
    """Points near the well floor's centre, facing up, seen along ``views``."""
    rng = np.random.default_rng(0)
    at = np.concatenate([rng.uniform(-0.05, 0.05, (64, 2)) * RADIUS,
                         np.full((64, 1), -RADIUS)], axis=1)
    normals = np.broadcast_to([0.0, 0.0, 1.0], at.shape).copy()
    return at, normals, np.broadcast_to(views, at.shape).copy()


def test_a_sphere_sees_the_whole_sky(bpy_factory):
    from makeup_skin_addon import sky_visibility

    positions, normals = _sphere_points()
    front = normals[:, 1] < -0.2  # the half the camera (along -y) sees
    views = np.array([0.0, -1.0, 0.0]) * 1.0 - positions[front] / 10.0
    views /= np.linalg.norm(views, axis=1, keepdims=True)
    sky = sky_visibility.SkyVisibility(positions[front][::50], normals[front][::50],
                                       views[::50], positions)
    diffuse, glosses = sky.seen(0.2, 0.45, 0.73)
    assert diffuse > 0.995
    assert min(glosses) > 0.995


def test_a_well_floor_sees_its_opening_and_a_grazing_gloss_the_wall(bpy_factory):
    """The floor's centre of a well as deep as it is wide sees half the sky (cosine-weighted:
    sin^2 of its 45-degree cone); a sharp gloss seen from straight above mirrors out of it,
    seen at 70 degrees into the wall."""
    from makeup_skin_addon import sky_visibility

    walls = _well()
    above = sky_visibility.SkyVisibility(*_floor_centre([0.0, 0.0, 1.0]), walls)
    diffuse, (sharp,) = above.seen(0.2)
    assert diffuse == pytest.approx(0.5, abs=0.05)
    assert sharp > 0.95
    tilt = np.radians(70.0)
    grazing = sky_visibility.SkyVisibility(
        *_floor_centre([np.sin(tilt), 0.0, np.cos(tilt)]), walls)
    diffuse_too, (sharp_grazing, broad_grazing) = grazing.seen(0.2, 0.7)
    assert diffuse_too == pytest.approx(diffuse, abs=1e-9)  # the view does not move it
    assert sharp_grazing < 0.1
    assert sharp_grazing < broad_grazing < diffuse


def test_what_a_lobe_keeps_counts_the_hidden_sky_by_the_skins_colour(bpy_factory):
    from makeup_skin_addon import sky_visibility

    np.testing.assert_allclose(sky_visibility.SkyVisibility.kept(0.8, [0.0, 0.5, 1.0]),
                               [0.8, 0.9, 1.0])


def test_the_colour_matched_renders_as_the_artists_in_the_hollows(bpy_factory):
    """The covered colour :func:`seen_target` gives, its film gloss and the rest each kept
    as the mesh leaves them, is what the artist's gloss and body keep: without a sky it is the
    artist's colour under uniform light."""
    from makeup_skin_addon import matching, sky_visibility

    tilt = np.radians(60.0)
    sky = sky_visibility.SkyVisibility(*_floor_centre([np.sin(tilt), 0.0, np.cos(tilt)]),
                                       _well())
    target = np.array([0.37, 0.18, 0.13])
    glosses = [(np.full(3, 0.05), 0.45), (np.full(3, 0.015), 0.2)]
    film_gloss, film_roughness = 0.077, 0.73
    skin = matching.SkinTarget(target, target - 0.065, "test", glosses, sky)
    seen, sentence = matching.seen_target(skin, film_gloss, film_roughness)
    diffuse, (g1, g2, film) = sky.seen(0.45, 0.2, film_roughness)
    assert film < diffuse
    kept = sky.kept
    artist = kept(diffuse, target) * (target - 0.065) + kept(g1, target) * 0.05 \
        + kept(g2, target) * 0.015
    made_up = kept(film, target) * film_gloss + kept(diffuse, target) * (seen - film_gloss)
    np.testing.assert_allclose(made_up, artist, rtol=1e-12)
    assert "uniform sky" in sentence
    bare = matching.SkinTarget(target, target - 0.065, "test", glosses, None)
    np.testing.assert_array_equal(matching.seen_target(bare, film_gloss, film_roughness)[0],
                                  target)
