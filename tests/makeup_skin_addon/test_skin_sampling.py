"""The mean of an image over a material's surface (makeup_skin_addon.skin_sampling): within its
sampling error of the exact area-weighted mean on the textured head and on two faces of known
areas and colours (world scale applied, faces of another slot left out); the points and the
reduced image cached, and read again after a mesh edit, an image edit, a file reloaded; the
messages for a missing UV map, a material without faces, a missing file; nothing left in
bpy.data; progress reported only when something is read."""

import numpy as np
import pytest
from support import exact_mean

# Two faces of a hand-made mesh: colours as sRGB bytes (exact in an 8-bit image).
LEFT_BYTES = (200, 120, 90)
RIGHT_BYTES = (60, 90, 220)
OTHER_BYTES = (10, 250, 10)


_linear = exact_mean.srgb_to_linear


def _image(name, columns, height=8, colorspace="sRGB"):
    """An 8-bit image of vertical bands, one per colour of ``columns`` (bytes), 16 texels
    each."""
    import bpy

    width = 16 * len(columns)
    image = bpy.data.images.new(name, width, height)
    image.colorspace_settings.name = colorspace  # first: it regenerates the pixels
    pixels = np.ones((height, width, 4), np.float32)
    for i, colour in enumerate(columns):
        pixels[:, 16 * i:16 * (i + 1), :3] = np.asarray(colour) / 255.0
    image.pixels.foreach_set(pixels.ravel())
    return image


def _textured(material, image, uv_map=None):
    """``material``'s Base Color fed by an Image Texture of ``image`` (through a UV Map node
    reading ``uv_map`` if given); returns the texture node."""
    tree = material.node_tree
    principled = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    tree.links.new(texture.outputs["Color"], principled.inputs["Base Color"])
    if uv_map is not None:
        node = tree.nodes.new("ShaderNodeUVMap")
        node.uv_map = uv_map
        tree.links.new(node.outputs["UV"], texture.inputs["Vector"])
    return texture


def _material(name):
    import bpy

    material = bpy.data.materials.new(name)
    if material.node_tree is None:  # 4.5: a new material has no tree
        material.use_nodes = True
    return material


def _two_faces(skin, other=None):
    """A mesh of three quads: a unit square standing in the XZ plane (UVs in the first band),
    a 3 x 1 rectangle lying in the XY plane (second band), and, in a second slot holding
    ``other``, a 10 x 10 square (third band).  Returns the object."""
    import bpy

    vertices = [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1),
                (2, 0, 0), (5, 0, 0), (5, 1, 0), (2, 1, 0),
                (0, 5, 0), (10, 5, 0), (10, 15, 0), (0, 15, 0)]
    faces = [(0, 1, 2, 3), (4, 5, 6, 7), (8, 9, 10, 11)]
    mesh = bpy.data.meshes.new("Two Faces")
    mesh.from_pydata(vertices, [], faces)
    layer = mesh.uv_layers.new(name="UVMap")
    square = [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)]
    uv = [(u / 3 + band / 3, v) for band in range(3) for u, v in square]
    layer.data.foreach_set("uv", np.ravel(uv))
    mesh.materials.append(skin)
    if other is not None:
        mesh.materials.append(other)
        mesh.polygons[2].material_index = 1
    obj = bpy.data.objects.new("Two Faces", mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


@pytest.fixture
def two_faces(addon, blank_scene):
    """``(object, skin material, texture node)``: :func:`_two_faces` with its image."""
    skin, other = _material("Skin"), _material("Other")
    obj = _two_faces(skin, other)
    texture = _textured(skin, _image("Bands", (LEFT_BYTES, RIGHT_BYTES, OTHER_BYTES)))
    return obj, skin, texture


def _exact_two_faces(left_area, right_area):
    left, right = _linear(np.asarray(LEFT_BYTES) / 255), _linear(np.asarray(RIGHT_BYTES) / 255)
    return (left_area * left + right_area * right) / (left_area + right_area)


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
    np.testing.assert_allclose(mean.rgb, _exact_two_faces(1.0, 3.0), atol=2e-5)
    obj.scale = (1.0, 1.0, 3.0)
    bpy.context.view_layer.update()
    mean = skin_sampling.surface_mean(texture.image, skin)
    np.testing.assert_allclose(mean.rgb, _exact_two_faces(3.0, 3.0), atol=2e-5)
    obj.scale = (1.0, 1.0, 0.0)  # flattened: the standing face has no area left
    bpy.context.view_layer.update()
    mean = skin_sampling.surface_mean(texture.image, skin)
    np.testing.assert_allclose(mean.rgb, _exact_two_faces(0.0, 3.0), atol=1e-6)


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


def test_the_cache_is_kept_until_the_mesh_changes(two_faces):
    """A second call reuses the points; moving a vertex (the standing face made twice as tall),
    reassigning a face's slot or changing the UVs reads the mesh again, and the mean follows."""
    import bpy

    from makeup_skin_addon import skin_sampling

    obj, skin, texture = two_faces
    layer = obj.data.uv_layers["UVMap"]
    points = skin_sampling.object_points(obj, skin, layer)
    assert skin_sampling.object_points(obj, skin, layer) is points
    mesh = obj.data
    for i in (2, 3):
        mesh.vertices[i].co.z = 2.0
    mesh.update()
    moved = skin_sampling.object_points(obj, skin, layer)
    assert moved is not points and moved.area == pytest.approx(5.0, rel=1e-6)
    np.testing.assert_allclose(skin_sampling.surface_mean(texture.image, skin).rgb,
                               _exact_two_faces(2.0, 3.0), atol=2e-5)
    mesh.polygons[1].material_index = 1  # the rectangle now in the other slot
    mesh.update()
    mean = skin_sampling.surface_mean(texture.image, skin)
    assert mean.faces == 1
    np.testing.assert_allclose(mean.rgb, _exact_two_faces(1.0, 0.0), atol=1e-6)
    uv = np.empty(2 * len(mesh.loops), np.float32)
    layer.data.foreach_get("uv", uv)
    uv[:8:2] += 1 / 3  # the standing face's UVs moved onto the second band
    layer.data.foreach_set("uv", uv)
    mesh.update()
    np.testing.assert_allclose(skin_sampling.surface_mean(texture.image, skin).rgb,
                               _exact_two_faces(0.0, 1.0), atol=1e-6)
    assert bpy.data.images.get("Bands") is texture.image


def test_the_cache_is_kept_until_the_image_changes(two_faces, tmp_path):
    """An image from a file is read once (the same reduced pixels twice); written again and
    reloaded, or its colour space changed, it is read again; an image edited in Blender
    (unsaved) is read at every call, with its edits."""
    import bpy

    from makeup_skin_addon import skin_sampling

    obj, skin, texture = two_faces
    generated = texture.image
    path = str(tmp_path / "bands.png")
    generated.filepath_raw = path
    generated.file_format = "PNG"
    generated.save()  # now a file image, "Bands"
    image = bpy.data.images.load(path, check_existing=False)
    image.colorspace_settings.name = "sRGB"
    texture.image = image
    first = skin_sampling.reduced_image(image)
    assert skin_sampling.reduced_image(image) is first
    np.testing.assert_allclose(skin_sampling.surface_mean(image, skin).rgb,
                               _exact_two_faces(1.0, 3.0), atol=2e-5)
    # The file painted over elsewhere (the left band now grey 128) and reloaded.
    pixels = np.empty(len(generated.pixels), np.float32)
    generated.pixels.foreach_get(pixels)
    pixels = pixels.reshape(8, 48, 4)
    pixels[:, :16, :3] = 128 / 255
    generated.pixels.foreach_set(pixels.ravel())
    generated.save()
    image.reload()
    grey = _linear(np.full(3, 128 / 255))
    right = _linear(np.asarray(RIGHT_BYTES) / 255)
    np.testing.assert_allclose(skin_sampling.surface_mean(image, skin).rgb,
                               (grey + 3 * right) / 4, atol=2e-5)
    image.colorspace_settings.name = "Non-Color"
    np.testing.assert_allclose(skin_sampling.surface_mean(image, skin).rgb,
                               (128 / 255 + 3 * np.asarray(RIGHT_BYTES) / 255) / 4, atol=2e-5)
    # Painted in Blender, not saved: read again at each call.
    image.colorspace_settings.name = "sRGB"
    for value in (0.2, 0.6):
        pixels[:, 16:32, :3] = value
        image.pixels.foreach_set(pixels.ravel())
        assert image.is_dirty
        np.testing.assert_allclose(skin_sampling.surface_mean(image, skin).rgb,
                                   (grey + 3 * _linear(np.full(3, value))) / 4, atol=2e-5)


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
    image whose file is missing; an object without the UV map beside one with it is left out
    and said so."""
    import bpy

    obj, skin, texture = two_faces
    uv_node = skin.node_tree.nodes.new("ShaderNodeUVMap")
    uv_node.uv_map = "UVMap.001"
    skin.node_tree.links.new(uv_node.outputs["UV"], texture.inputs["Vector"])
    assert _source(skin) == (f"{SOURCE}; 'Two Faces' has no UV map 'UVMap.001' (read by "
                             f"{texture.name!r}): read at UV (0, 0)")
    skin.node_tree.links.remove(texture.inputs["Vector"].links[0])
    bare = _two_faces(skin)
    bare.name = "Bare"
    bare.data.uv_layers.remove(bare.data.uv_layers[0])
    assert f"; 'Bare' has no UV map (read by {texture.name!r}): left out" in _source(skin)
    bpy.data.objects.remove(bare)
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
                             f"pixels (its file '//gone.png' is missing)")


def test_progress_is_reported_only_when_something_is_read(two_faces, tmp_path):
    """A cold call reports progress (the image, then the faces), a warm one nothing; a window
    manager's progress is begun on the first report and ended after."""
    from makeup_skin_addon import skin_sampling

    obj, skin, texture = two_faces
    texture.image.filepath_raw = str(tmp_path / "bands.png")
    texture.image.file_format = "PNG"
    texture.image.save()  # a file image, not dirty: cached once read
    reports = []
    with skin_sampling.reporting(lambda fraction, message="": reports.append(fraction)):
        skin_sampling.surface_mean(texture.image, skin)
        assert len(reports) == 3 and reports[0] == 0.0 and reports[-1] == 1.0
        reports.clear()
        skin_sampling.surface_mean(texture.image, skin)
        assert reports == []

    class Manager:
        def __init__(self):
            self.calls = []

        def progress_begin(self, low, high):
            self.calls.append(("begin", low, high))

        def progress_update(self, value):
            self.calls.append(("update", value))

        def progress_end(self):
            self.calls.append(("end",))

    manager = Manager()
    with skin_sampling.progress_bar(manager):
        skin_sampling.surface_mean(texture.image, skin)
    assert manager.calls == []
    skin_sampling.clear_cache()
    with skin_sampling.progress_bar(manager):
        skin_sampling.surface_mean(texture.image, skin)
    assert manager.calls == [("begin", 0, 100), ("update", 0), ("update", 60), ("update", 100),
                             ("end",)]


def test_texels_wrap_as_the_texture_extension_does(addon):
    """REPEAT wraps, MIRROR reflects, EXTEND clamps, CLIP is black outside the image."""
    from makeup_skin_addon import skin_sampling

    pixels = np.arange(1, 5, dtype=np.float32).reshape(1, 4, 1).repeat(3, axis=2)
    uv = np.array([[0.1, 0.5], [1.1, 0.5], [-0.1, 0.5], [1.6, 0.5]])
    expected = {"REPEAT": (1, 1, 4, 3), "MIRROR": (1, 4, 1, 2), "EXTEND": (1, 4, 1, 4),
                "CLIP": (1, 0, 0, 0)}
    for extension, values in expected.items():
        read = skin_sampling.read_texels(pixels, uv, extension)
        np.testing.assert_allclose(read, np.repeat(np.array(values, float)[:, None], 3, 1),
                                   atol=1e-12, err_msg=extension)


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
    np.testing.assert_allclose(seen, _linear(np.asarray(RIGHT_BYTES) / 255), atol=2e-5)
    scene.camera = None
    everywhere = artist_skin.read_material(skin, scene).leaves[0].base
    np.testing.assert_allclose(everywhere, _exact_two_faces(1.0, 3.0), atol=1e-4)
    scene.camera = camera
    camera.rotation_euler = (3.14159, 0.0, 0.0)  # looking up, away from the faces
    away = artist_skin.read_material(skin, scene)
    np.testing.assert_allclose(away.leaves[0].base, everywhere, atol=1e-6)
    assert any("sees none of it" in note for note in away.notes)


def test_the_srgb_curve_of_rgba_pixels_read_as_rgb(addon):
    """The RGB view of RGBA pixels (not contiguous) is linearised as float32 values, within
    single-precision rounding of the IEC 61966-2-1 curve in double precision."""
    from makeup_skin_addon import skin_sampling

    rng = np.random.default_rng(3)
    levels = np.arange(256, dtype=np.float32) * np.float32(1.0 / 255.0)
    rgba = np.concatenate([levels[rng.integers(0, 256, 4000)],
                           rng.random(4000).astype(np.float32)]).reshape(-1, 4)
    read = skin_sampling.srgb_to_linear(rgba[:, :3])
    assert read.dtype == np.float32 and read.shape == (2000, 3)
    np.testing.assert_allclose(read, _linear(rgba[:, :3].astype(float)), rtol=1e-6, atol=1e-9)
