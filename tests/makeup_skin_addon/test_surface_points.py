"""Points on a material's faces (makeup_skin_addon.surface_points): the faces measured as
Blender measures them, and the points kept for the session until the mesh, its slots or the
UVs they are read at change, and read again then (the mean follows)."""

import numpy as np
import pytest
from support.two_faces import OTHER_BYTES, exact_two_faces, linear


def _blender_faces(mesh):
    """Blender's own ``(area, normal, loop_total)`` of every face (read a face at a time)."""
    count = len(mesh.polygons)
    area, normal = np.empty(count, np.float32), np.empty(3 * count, np.float32)
    total = np.empty(count, np.int32)
    mesh.polygons.foreach_get("area", area)
    mesh.polygons.foreach_get("normal", normal)
    mesh.polygons.foreach_get("loop_total", total)
    return area, normal.reshape(-1, 3), total


def test_areas_normals_and_corners_as_blender_gives_them(blank_scene):
    """Triangles, quads and larger faces, bent out of their planes and at sizes from a
    millimetre to a kilometre, and degenerate ones: each face's first corner (found from
    Blender's triangles) and corner count exactly as Blender's, its area and normal within
    float32 rounding of Blender's (the same formulas in float32, in Blender's order: equal to
    the last bit on this x86-64 machine, whose Blender fuses no multiply-add; a build that
    fuses them may differ by a few units in the last place, hence the tolerances, not
    equality)."""
    import bpy

    from makeup_skin_addon import face_geometry, surface_points

    add = bpy.ops.mesh
    shapes = [(add.primitive_uv_sphere_add, {"segments": 17, "ring_count": 9}),
              (add.primitive_monkey_add, {}), (add.primitive_cylinder_add, {"vertices": 13}),
              (add.primitive_circle_add, {"fill_type": "NGON", "vertices": 40})]
    rng = np.random.default_rng(7)
    meshes = []
    for operator, options in shapes:
        operator(**options)
        mesh = bpy.context.object.data
        positions = surface_points._positions(mesh)
        positions += rng.normal(0.0, 0.03, positions.shape).astype(np.float32)
        positions *= np.float32(10.0 ** rng.uniform(-3, 3))
        mesh.attributes["position"].data.foreach_set("vector", positions.ravel())
        mesh.update()
        meshes.append(mesh)
    degenerate = bpy.data.meshes.new("Degenerate")  # a line: no area, normals +Z
    degenerate.from_pydata([(0, 0, 0), (1, 0, 0), (2, 0, 0), (3, 0, 0), (4, 0, 0)], [],
                           [(0, 1, 2), (0, 1, 2, 3), (0, 1, 2, 3, 4)])
    meshes.append(degenerate)
    for mesh in meshes:
        area, normal, total = _blender_faces(mesh)
        loop_start, loop_total = surface_points._loop_starts(mesh)  # from the triangles
        first = np.empty(len(mesh.polygons), np.int32)
        mesh.polygons.foreach_get("loop_start", first)
        np.testing.assert_array_equal(loop_start, first)
        np.testing.assert_array_equal(loop_total, total)
        positions = surface_points._positions(mesh)
        corner_verts = surface_points._corner_verts(mesh)
        ours = face_geometry.face_areas(positions, corner_verts, loop_start, loop_total)
        assert ours.dtype == np.float32
        np.testing.assert_allclose(ours, area, rtol=1e-6, atol=0.0)
        np.testing.assert_allclose(
            face_geometry.face_normals(positions, corner_verts, loop_start, loop_total),
            normal, rtol=0.0, atol=1e-6)
        some = rng.integers(0, len(area), 7)  # the faces points fell in, in any order
        np.testing.assert_allclose(
            face_geometry.face_normals(positions, corner_verts, loop_start, loop_total, some),
            normal[some], rtol=0.0, atol=1e-6)
    assert len(np.unique(np.concatenate([_blender_faces(m)[2] for m in meshes]))) >= 4
    empty = bpy.data.meshes.new("Empty")  # no faces: nothing to read
    assert all(len(a) == 0 for a in surface_points._loop_starts(empty))


def test_the_cache_follows_every_change(two_faces):
    """The points are read again when a vertex moves (the standing face made twice as tall), a
    UV they are read at changes or a face changes slot, and the mean follows; a changed image
    is read again with the points kept.  Nothing else reads them again: a repeat, the object
    moved, a vertex selected, a UV of the other slot's face, an attribute added."""
    import bpy

    from makeup_skin_addon import skin_sampling, surface_points

    obj, skin, texture = two_faces
    mesh, image = obj.data, texture.image
    layer = mesh.uv_layers["UVMap"]

    def points():
        return surface_points.object_points(obj, skin, layer)

    def mean():
        return skin_sampling.surface_mean(image, skin).rgb

    def set_uv(change):
        uv = np.empty((len(mesh.loops), 2), np.float32)
        layer.data.foreach_get("uv", uv.ravel())
        change(uv)
        layer.data.foreach_set("uv", uv.ravel())
        mesh.update()

    def kept(change):
        before = points()
        change()
        assert points() is before

    first = points()
    kept(lambda: None)
    kept(lambda: setattr(obj, "location", (1.0, 2.0, 3.0)))
    kept(lambda: setattr(mesh.vertices[0], "select", not mesh.vertices[0].select))
    kept(lambda: set_uv(lambda uv: uv.__setitem__((slice(8, 12), 1), 0.5)))
    kept(lambda: mesh.attributes.new("Wetness", "FLOAT", "POINT"))

    for i in (2, 3):
        mesh.vertices[i].co.z = 2.0
    mesh.update()
    moved = points()
    assert moved is not first and moved.area == pytest.approx(5.0, rel=1e-6)
    np.testing.assert_allclose(mean(), exact_two_faces(2.0, 3.0), atol=2e-5)

    set_uv(lambda uv: uv.__setitem__((slice(0, 4), 0), uv[0:4, 0] + 1 / 3))
    assert points() is not moved  # the standing face's UVs on the second band
    np.testing.assert_allclose(mean(), exact_two_faces(0.0, 1.0), atol=1e-6)

    reread = points()
    mesh.polygons[0].material_index = 1  # the standing face now in the other slot
    mesh.update()
    assert points() is not reread
    result = skin_sampling.surface_mean(image, skin)
    assert result.faces == 1
    np.testing.assert_allclose(result.rgb, exact_two_faces(0.0, 1.0), atol=1e-6)

    slots = points()
    pixels = np.empty((image.size[1], image.size[0], 4), np.float32)
    image.pixels.foreach_get(pixels.ravel())
    pixels[:, 16:32, :3] = np.asarray(OTHER_BYTES) / 255.0  # the second band repainted
    image.pixels.foreach_set(pixels.ravel())
    image.update()
    np.testing.assert_allclose(mean(), linear(np.asarray(OTHER_BYTES) / 255.0), atol=1e-6)
    assert points() is slots
    assert bpy.data.images.get("Bands") is image
