"""A mesh's faces measured from its arrays (makeup_skin_addon.face_geometry): known areas and
normals of flat faces of 3 to 7 corners in any mix and order, chunks that change nothing, and
the fan triangles' cumulative areas (against Blender's own, test_surface_points)."""

import numpy as np
import pytest


@pytest.fixture
def face_geometry(bpy_factory):
    """The module (importing the add-on imports bpy: the fixture marks the tests ``bpy``)."""
    from makeup_skin_addon import face_geometry

    return face_geometry


def _regular_faces(rng, count: int):
    """``count`` regular polygons of 3 to 7 corners in random order, each turned and moved at
    random: ``(positions, corner_verts, loop_start, loop_total, areas, normals, radii)``."""
    corners = rng.integers(3, 8, count).astype(np.int32)
    positions, normals, areas, radii = [], [], [], []
    for k in corners:
        radius = rng.uniform(0.5, 2.0)
        angle = 2 * np.pi * np.arange(k) / k
        flat = np.column_stack([radius * np.cos(angle), radius * np.sin(angle), np.zeros(k)])
        turn, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        positions.append(flat @ turn.T + rng.normal(size=3))
        normals.append(turn[:, 2])
        areas.append(0.5 * k * radius ** 2 * np.sin(2 * np.pi / k))
        radii.append(radius)
    loop_start = np.concatenate([[0], np.cumsum(corners)[:-1]]).astype(np.int32)
    corner_verts = np.arange(corners.sum(), dtype=np.int32)
    return (np.concatenate(positions).astype(np.float32), corner_verts, loop_start, corners,
            np.array(areas), np.array(normals), np.array(radii))


def test_regular_faces_in_any_mix(face_geometry, monkeypatch):
    """Flat regular faces: their areas and unit normals within float32 rounding; the counts
    from the first corners; by chunks of 7 faces the very numbers of one chunk (each face is
    computed by the same operations whatever its chunk)."""
    rng = np.random.default_rng(11)
    positions, corner_verts, loop_start, loop_total, areas, normals, _ = _regular_faces(rng, 300)
    np.testing.assert_array_equal(face_geometry.corner_counts(loop_start, len(corner_verts)),
                                  loop_total)
    area = face_geometry.face_areas(positions, corner_verts, loop_start, loop_total)
    np.testing.assert_allclose(area, areas, rtol=2e-6)
    normal = face_geometry.face_normals(positions, corner_verts, loop_start, loop_total)
    np.testing.assert_allclose(normal, normals, atol=2e-6)
    some = rng.integers(0, 300, 50)
    np.testing.assert_array_equal(
        face_geometry.face_normals(positions, corner_verts, loop_start, loop_total, some),
        normal[some])
    monkeypatch.setattr(face_geometry, "CHUNK", 7)
    np.testing.assert_array_equal(
        face_geometry.face_areas(positions, corner_verts, loop_start, loop_total), area)
    np.testing.assert_array_equal(
        face_geometry.face_normals(positions, corner_verts, loop_start, loop_total), normal)


def test_fan_areas_add_up_to_the_face(face_geometry):
    """A regular face's fan from its first corner: triangle j (corners 0, j, j + 1) has area
    r^2 (sin(s) + sin(j s) - sin((j + 1) s)) / 2 (s the angle between two corners); the last
    cumulative area is the face's."""
    rng = np.random.default_rng(12)
    positions, corner_verts, loop_start, loop_total, areas, _, radii = _regular_faces(rng, 40)
    for k in np.unique(loop_total):
        which = np.flatnonzero(loop_total == k)
        fans = face_geometry.fan_areas(positions, corner_verts,
                                       loop_start[which][None, :] + np.arange(k)[:, None])
        assert fans.shape == (len(which), k - 2)
        step = 2 * np.pi / k
        j = np.arange(1, k - 1)
        triangle = 0.5 * (np.sin(step) + np.sin(j * step) - np.sin((j + 1) * step))
        np.testing.assert_allclose(fans, radii[which, None] ** 2 * np.cumsum(triangle),
                                   rtol=2e-6)
        np.testing.assert_allclose(fans[:, -1], areas[which], rtol=2e-6)
