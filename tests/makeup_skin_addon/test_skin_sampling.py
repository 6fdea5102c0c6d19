"""The mean of an image over a material's surface (makeup_skin_addon.skin_sampling): within its
sampling error of the exact area-weighted mean on the textured head and on two faces of known
areas and colours (world scale applied, faces of another slot left out); the points and the
reduced image cached, and read again after a mesh edit, an image edit, a file reloaded; the
messages for a missing UV map, a material without faces, a missing file; nothing left in
bpy.data; progress reported only when something is read."""

import numpy as np
from support import exact_mean
from support.two_faces import (
    RIGHT_BYTES,
    build_two_faces,
    exact_two_faces,
    linear,
)


def test_two_faces_of_known_areas_and_colours(two_faces):
    """Every point reads its face's colour, so the mean misses the exact one only by how the
    points split between the faces (at most one point in 2^16 of the colours' difference):
    1:3 by area, then 3:3 once the object is scaled 3 times along Z (the standing face grows),
    0:3 flattened along Z;
    the third face, of another slot, does not count, nor in the faces reported."""
    import bpy

    from makeup_skin_addon import skin_sampling

    obj, skin, texture = two_faces
    mean = skin_sampling.surface_mean(texture.image, skin, reader=texture.name)
    assert mean.problem == "" and mean.faces == 2 and mean.objects == ("Two Faces",)
    np.testing.assert_allclose(mean.rgb, exact_two_faces(1.0, 3.0), atol=2e-5)
    obj.scale = (1.0, 1.0, 3.0)
    bpy.context.view_layer.update()
    mean = skin_sampling.surface_mean(texture.image, skin)
    np.testing.assert_allclose(mean.rgb, exact_two_faces(3.0, 3.0), atol=2e-5)
    obj.scale = (1.0, 1.0, 0.0)  # flattened: the standing face has no area left
    bpy.context.view_layer.update()
    mean = skin_sampling.surface_mean(texture.image, skin)
    np.testing.assert_allclose(mean.rgb, exact_two_faces(0.0, 3.0), atol=1e-6)


def test_the_heads_mean_is_within_its_sampling_error(head):
    """The textured head (its 500 faces, 512 px albedo): the mean of 2^16 points is within four
    of its standard errors of the exact mean (:func:`support.exact_mean.exact_mean`), channel
    by channel (measured: 0.3-0.6 of one);
    read through a copy reduced to 128 px (a box filter in sRGB bytes, then linearised),
    within 0.2% (measured: 0.03-0.06%); the Base Color the artist's shader is read with
    (:func:`.artist_skin.read_material`) is this mean."""
    import bpy

    from makeup_skin_addon import artist_skin, skin_sampling

    material = head.active_material
    texture = material.node_tree.nodes["Albedo"]
    layer = next(layer for layer in head.data.uv_layers if layer.active_render)
    # 6 x 6 points a triangle would miss by about one standard error of 2^16 points; 48 x 48
    # moves 24 x 24's by a tenth of one.
    exact, _ = exact_mean.exact_mean(head, texture.image, layer.name, grid=24)
    mean = skin_sampling.surface_mean(texture.image, material, reader=texture.name)
    assert mean.faces == len(head.data.polygons)
    assert np.all(mean.error < 2e-3 * exact)  # 2^16 points: a tight estimate
    assert np.all(np.abs(mean.rgb - exact) < 4 * mean.error), (mean.rgb, exact, mean.error)
    reduced = skin_sampling.surface_mean(texture.image, material, size=128)
    np.testing.assert_allclose(reduced.rgb, exact, rtol=2e-3)
    scene = bpy.context.scene
    scene.camera = None  # with a camera, the points count by how much of them it sees
    reading = artist_skin.read_material(material, scene)
    np.testing.assert_allclose(reading.leaves[0].base, mean.rgb, rtol=1e-9)
    assert reading.notes == []


def test_the_same_mesh_gives_the_same_points(head):
    """Cleared caches, the same head gives the same mean (a fixed seed)."""
    from makeup_skin_addon import skin_sampling

    material = head.active_material
    image = material.node_tree.nodes["Albedo"].image
    first = skin_sampling.surface_mean(image, material).rgb
    skin_sampling.clear_cache()
    np.testing.assert_allclose(skin_sampling.surface_mean(image, material).rgb, first,
                               rtol=1e-12)


def test_nothing_is_left_in_the_file(head):
    """Reading the head's albedo through a reduced copy leaves bpy.data's images as they were,
    the image itself untouched (not dirty, same size)."""
    import bpy

    from makeup_skin_addon import skin_sampling

    material = head.active_material
    image = material.node_tree.nodes["Albedo"].image
    assert image.source == "FILE" and not image.is_dirty  # read through a copy
    before = sorted(i.name for i in bpy.data.images)
    size = tuple(image.size)
    mean = skin_sampling.surface_mean(image, material, size=64)
    assert mean.rgb is not None
    assert sorted(i.name for i in bpy.data.images) == before
    assert tuple(image.size) == size and not image.is_dirty


SOURCE = "the artist's shader under uniform light"


def _source(material):
    from makeup_skin_addon import matching

    return matching.skin_target(material).source


def test_messages(two_faces):
    """Why there is no mean, in the words of Skin Color's source: a UV map the texture reads
    that the mesh lacks (named), a mesh without UVs, a material no face uses, no object, an
    image whose file is missing or whose frames are not read (taken as 0.5, neither black nor
    Blender's magenta); an object without the UV map (or in Edit Mode) beside one with it is
    left out and said so."""
    import bpy

    from makeup_skin_addon import skin_sampling

    obj, skin, texture = two_faces
    uv_node = skin.node_tree.nodes.new("ShaderNodeUVMap")
    uv_node.uv_map = "UVMap.001"
    skin.node_tree.links.new(uv_node.outputs["UV"], texture.inputs["Vector"])
    assert _source(skin) == (f"{SOURCE}; 'Two Faces' has no UV map 'UVMap.001' (read by "
                             f"{texture.name!r}): read at UV (0, 0)")
    skin.node_tree.links.remove(texture.inputs["Vector"].links[0])
    bare = build_two_faces(skin)
    bare.name = "Bare"
    bare.data.uv_layers.remove(bare.data.uv_layers[0])
    assert f"; 'Bare' has no UV map (read by {texture.name!r}): left out" in _source(skin)
    bpy.data.objects.remove(bare)
    editing = build_two_faces(skin)  # in Edit Mode Blender gives Python none of its UVs
    editing.name = "Editing"
    for other in bpy.context.selected_objects:
        other.select_set(False)
    editing.select_set(True)
    bpy.context.view_layer.objects.active = editing
    bpy.ops.object.mode_set(mode="EDIT")
    left_out = "'Editing' is in Edit Mode, where Blender gives Python no UVs: left out"
    assert f"; {left_out}" in _source(skin)
    mean = skin_sampling.surface_mean(texture.image, skin, reader=texture.name)
    assert mean.objects == ("Two Faces",) and left_out in mean.notes
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.data.objects.remove(editing)
    for polygon in obj.data.polygons:
        polygon.material_index = 1
    assert _source(skin) == (f"{SOURCE}; no face uses 'Skin': the shader's inputs are read at "
                             f"UV (0, 0)")
    for polygon in obj.data.polygons:
        polygon.material_index = 0
    obj.data.uv_layers.remove(obj.data.uv_layers[0])
    assert _source(skin) == (f"{SOURCE}; 'Two Faces' has no UV map (read by {texture.name!r}):"
                             f" read at UV (0, 0)")
    obj.data.materials.clear()
    assert _source(skin) == (f"{SOURCE}; no mesh object uses 'Skin': the shader's inputs are "
                             f"read at UV (0, 0)")
    obj.data.materials.append(skin)
    obj.data.uv_layers.new(name="UVMap")
    missing = bpy.data.images.new("Gone", 4, 4)
    missing.source = "FILE"  # no file behind it: no pixels
    missing.filepath = "//gone.png"
    texture.image = missing
    assert _source(skin) == (f"{SOURCE} over the 3 faces that use it; image 'Gone' has no "
                             f"pixels (its file '//gone.png' is missing): taken as 0.5")
    missing.source = "SEQUENCE"  # frames are not read (it said the file was missing)
    assert _source(skin) == (f"{SOURCE} over the 3 faces that use it; image 'Gone' is an "
                             f"image sequence: its frames are not read: taken as 0.5")


def test_with_a_camera_the_points_count_by_what_it_sees(two_faces):
    """A camera looking straight down at the lying face (the standing one is seen edge on):
    the shader is read as the camera sees it, the lying face's colour; turned away, over the
    whole surface (and said)."""
    import bpy

    from makeup_skin_addon import artist_skin

    obj, skin, texture = two_faces
    scene = bpy.context.scene
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 2.0
    camera.location = (3.5, 0.5, 5.0)
    scene.camera = camera
    scene.render.resolution_x = scene.render.resolution_y = 64
    seen = artist_skin.read_material(skin, scene).leaves[0].base
    np.testing.assert_allclose(seen, linear(np.asarray(RIGHT_BYTES) / 255), atol=2e-5)
    scene.camera = None
    everywhere = artist_skin.read_material(skin, scene).leaves[0].base
    np.testing.assert_allclose(everywhere, exact_two_faces(1.0, 3.0), atol=1e-4)
    scene.camera = camera
    camera.rotation_euler = (3.14159, 0.0, 0.0)  # looking up, away from the faces
    away = artist_skin.read_material(skin, scene)
    np.testing.assert_allclose(away.leaves[0].base, everywhere, atol=1e-6)
    assert any("sees none of it" in note for note in away.notes)



def test_only_the_objects_that_render_count(two_faces):
    """Copies of the mesh disabled in renders, in another scene, in a collection disabled in
    renders or excluded from the view layer, their UVs in another band of the image: left out
    of the mean, and said so (the match's too); with nothing in the scene rendering the
    material, every object that uses it counts, and that is said."""
    import bpy

    from makeup_skin_addon import skin_sampling

    obj, skin, texture = two_faces
    alone = skin_sampling.surface_mean(texture.image, skin).rgb

    def copy(name):
        other = build_two_faces(skin)
        other.name = name
        layer = other.data.uv_layers[0]
        uv = np.array([d.uv[:] for d in layer.data])
        uv[:8, 0] = uv[8:, 0].mean()  # the skin faces read the third band
        layer.data.foreach_set("uv", uv.ravel())
        return other

    copy("Hidden").hide_render = True
    elsewhere = copy("Elsewhere")
    bpy.context.scene.collection.objects.unlink(elsewhere)
    bpy.data.scenes.new("Other").collection.objects.link(elsewhere)
    scene = bpy.context.scene.name
    mean = skin_sampling.surface_mean(texture.image, skin)
    np.testing.assert_allclose(mean.rgb, alone, atol=1e-9)
    left_out = [f"'Hidden' does not render in scene {scene!r}: left out",
                f"'Elsewhere' does not render in scene {scene!r}: left out"]
    assert mean.objects == ("Two Faces",) and all(n in mean.notes for n in left_out)
    assert all(n in _source(skin) for n in left_out)
    # A collection disabled in renders, and one excluded from the view layer, hide theirs.
    for name, switch in (("Off", "hide_render"), ("Excluded", "exclude")):
        other = copy(name)
        collection = bpy.data.collections.new(name)
        bpy.context.scene.collection.children.link(collection)
        bpy.context.scene.collection.objects.unlink(other)
        collection.objects.link(other)
        if switch == "hide_render":
            collection.hide_render = True
        else:
            bpy.context.view_layer.layer_collection.children[name].exclude = True
        mean = skin_sampling.surface_mean(texture.image, skin)
        np.testing.assert_allclose(mean.rgb, alone, atol=1e-9)
        assert f"{name!r} does not render in scene {scene!r}: left out" in mean.notes
    obj.hide_render = True
    mean = skin_sampling.surface_mean(texture.image, skin)
    assert len(mean.objects) == 5 and (f"no object in scene {scene!r} renders 'Skin': every "
                                       f"object that uses it counts") in mean.notes
