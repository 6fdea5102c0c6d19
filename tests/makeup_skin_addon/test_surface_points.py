"""Points on a material's faces (makeup_skin_addon.surface_points): kept for the session until
the mesh, its slots or its UVs change, and read again then (the mean follows)."""

import numpy as np
import pytest
from support.two_faces import exact_two_faces


def test_the_cache_is_kept_until_the_mesh_changes(two_faces):
    """A second call reuses the points; moving a vertex (the standing face made twice as tall),
    reassigning a face's slot or changing the UVs reads the mesh again, and the mean follows."""
    import bpy

    from makeup_skin_addon import skin_sampling, surface_points

    obj, skin, texture = two_faces
    layer = obj.data.uv_layers["UVMap"]
    points = surface_points.object_points(obj, skin, layer)
    assert surface_points.object_points(obj, skin, layer) is points
    mesh = obj.data
    for i in (2, 3):
        mesh.vertices[i].co.z = 2.0
    mesh.update()
    moved = surface_points.object_points(obj, skin, layer)
    assert moved is not points and moved.area == pytest.approx(5.0, rel=1e-6)
    np.testing.assert_allclose(skin_sampling.surface_mean(texture.image, skin).rgb,
                               exact_two_faces(2.0, 3.0), atol=2e-5)
    mesh.polygons[1].material_index = 1  # the rectangle now in the other slot
    mesh.update()
    mean = skin_sampling.surface_mean(texture.image, skin)
    assert mean.faces == 1
    np.testing.assert_allclose(mean.rgb, exact_two_faces(1.0, 0.0), atol=1e-6)
    uv = np.empty(2 * len(mesh.loops), np.float32)
    layer.data.foreach_get("uv", uv)
    uv[:8:2] += 1 / 3  # the standing face's UVs moved onto the second band
    layer.data.foreach_set("uv", uv)
    mesh.update()
    np.testing.assert_allclose(skin_sampling.surface_mean(texture.image, skin).rgb,
                               exact_two_faces(0.0, 1.0), atol=1e-6)
    assert bpy.data.images.get("Bands") is texture.image
