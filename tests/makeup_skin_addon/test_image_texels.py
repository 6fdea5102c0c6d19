"""An image as its texture node reads it, box-filtered (makeup_skin_addon.image_texels): kept
until the image changes (a file rewritten and reloaded, its colour space, unsaved edits: their
pixels checked at every call), and its texels read at UVs as the texture's extension wraps
them."""

import numpy as np
from support.two_faces import LEFT_BYTES, RIGHT_BYTES, exact_two_faces, linear


def test_the_cache_is_kept_until_the_image_changes(two_faces, tmp_path):
    """An image from a file is read once (the same reduced pixels twice); written again and
    reloaded, or its colour space changed, it is read again; an image edited in Blender
    (unsaved) is read at every call, with its edits, and reduced again only when they changed
    its pixels."""
    import bpy

    from makeup_skin_addon import image_texels, skin_sampling

    obj, skin, texture = two_faces
    generated = texture.image
    path = str(tmp_path / "bands.png")
    generated.filepath_raw = path
    generated.file_format = "PNG"
    generated.save()  # now a file image, "Bands"
    image = bpy.data.images.load(path, check_existing=False)
    image.colorspace_settings.name = "sRGB"
    texture.image = image
    first = image_texels.reduced_image(image)
    assert image_texels.reduced_image(image) is first
    np.testing.assert_allclose(skin_sampling.surface_mean(image, skin).rgb,
                               exact_two_faces(1.0, 3.0), atol=2e-5)
    # The file painted over elsewhere (the left band now grey 128) and reloaded.
    pixels = np.empty(len(generated.pixels), np.float32)
    generated.pixels.foreach_get(pixels)
    pixels = pixels.reshape(8, 48, 4)
    pixels[:, :16, :3] = 128 / 255
    generated.pixels.foreach_set(pixels.ravel())
    generated.save()
    image.reload()
    grey = linear(np.full(3, 128 / 255))
    right = linear(np.asarray(RIGHT_BYTES) / 255)
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
                                   (grey + 3 * linear(np.full(3, value))) / 4, atol=2e-5)
        painted = image_texels.reduced_image(image)
        image.pixels.foreach_set(pixels.ravel())  # the same pixels painted again
        assert image_texels.reduced_image(image) is painted
    pixels[0, 0, 0] = 0.9  # one texel's red
    image.pixels.foreach_set(pixels.ravel())
    changed = image_texels.reduced_image(image)
    assert changed is not painted and not np.array_equal(changed.pixels, painted.pixels)
    image.save()  # saved: read from its file again, the same pixels
    assert not image.is_dirty
    np.testing.assert_allclose(image_texels.reduced_image(image).pixels, changed.pixels,
                               atol=1e-6)


def test_texels_wrap_as_the_texture_extension_does(addon):
    """REPEAT wraps, MIRROR reflects, EXTEND clamps, CLIP is black outside the image."""
    from makeup_skin_addon import image_texels

    pixels = np.arange(1, 5, dtype=np.float32).reshape(1, 4, 1).repeat(3, axis=2)
    uv = np.array([[0.1, 0.5], [1.1, 0.5], [-0.1, 0.5], [1.6, 0.5]])
    expected = {"REPEAT": (1, 1, 4, 3), "MIRROR": (1, 4, 1, 2), "EXTEND": (1, 4, 1, 4),
                "CLIP": (1, 0, 0, 0)}
    for extension, values in expected.items():
        read = image_texels.read_texels(pixels, uv, extension)
        np.testing.assert_allclose(read, np.repeat(np.array(values, float)[:, None], 3, 1),
                                   atol=1e-12, err_msg=extension)


def test_the_srgb_curve_of_rgba_pixels_read_as_rgb(addon):
    """The RGB view of RGBA pixels (not contiguous) is linearised as float32 values, within
    single-precision rounding of the IEC 61966-2-1 curve in double precision."""
    from makeup_skin_addon import image_texels

    rng = np.random.default_rng(3)
    levels = np.arange(256, dtype=np.float32) * np.float32(1.0 / 255.0)
    rgba = np.concatenate([levels[rng.integers(0, 256, 4000)],
                           rng.random(4000).astype(np.float32)]).reshape(-1, 4)
    read = image_texels.srgb_to_linear(rgba[:, :3])
    assert read.dtype == np.float32 and read.shape == (2000, 3)
    np.testing.assert_allclose(read, linear(rgba[:, :3].astype(float)), rtol=1e-6, atol=1e-9)


def test_a_byte_images_codes_linearised_by_table_as_by_the_curve(addon):
    """A byte image's values (each code times 1/255, as Blender gives them, or code / 255)
    linearised through the 256-code table equal the curve's, within float32 rounding."""
    from makeup_skin_addon import image_texels

    codes = np.random.default_rng(4).integers(0, 256, (500, 3))
    for values in (codes.astype(np.float32) * np.float32(1.0 / 255.0),
                   (codes / 255.0).astype(np.float32)):
        read = image_texels.srgb_codes_to_linear(values)
        assert read.dtype == np.float32 and read.shape == (500, 3)
        np.testing.assert_allclose(read, linear(codes / 255.0), rtol=1e-6, atol=1e-9)


def test_the_box_filter_averages_whole_and_partial_boxes(addon):
    """Boxes that tile the image (the reshaped sums) and boxes cut at the far edges (the
    reduceat path) both average exactly the texels they cover."""
    from makeup_skin_addon import image_texels

    pixels = np.random.default_rng(5).random((12, 8, 3)).astype(np.float32)
    whole = image_texels.box_reduce(pixels, 4)
    assert whole.shape == (3, 2, 3)
    np.testing.assert_allclose(whole[1, 1], pixels[4:8, 4:8].mean(axis=(0, 1)), rtol=1e-6)
    cut = image_texels.box_reduce(pixels[:10, :7], 4)
    assert cut.shape == (3, 2, 3)
    np.testing.assert_allclose(cut[2, 1], pixels[8:10, 4:7].mean(axis=(0, 1)), rtol=1e-6)
    np.testing.assert_allclose(cut[0, 0], whole[0, 0], rtol=1e-6)


def test_texels_that_are_not_finite_are_the_others_mean_and_said(addon, blank_scene):
    """A float image with NaN and infinite texels (a bad bake): its reduced image is finite,
    those texels the mean of the others, and its note says how many (a note of a value
    assumed: the first Apply warns)."""
    import bpy

    from makeup_skin_addon import image_texels, surface_values

    pixels = np.ones((64, 64, 4), np.float32) * np.float32([0.5, 0.3, 0.2, 1.0])
    pixels[10:12, 10:12, :3] = np.nan
    pixels[30, 30, 1] = np.inf
    image = bpy.data.images.new("Bad Bake", 64, 64, float_buffer=True)
    image.pixels.foreach_set(pixels.ravel())
    reduced = image_texels.reduced_image(image)
    assert np.all(np.isfinite(reduced.pixels))
    np.testing.assert_allclose(reduced.pixels, np.broadcast_to([0.5, 0.3, 0.2], (64, 64, 3)),
                               rtol=1e-4)  # a float32 mean of some 4000 texels
    assert reduced.note == ("image 'Bad Bake' is not finite in 5 of its 64 x 64 reduced texels "
                            "(NaN or infinite texels): taken as the mean of the others")
    assert surface_values.assumed(reduced.note)
    fixed, count = image_texels.finite_values(np.full((2, 2, 3), np.nan))
    assert count == 4 and np.all(fixed == 0.0)


def test_a_small_image_loaded_already_reads_as_its_file_does(addon, tmp_path):
    """An image file at most 512 px across that Blender has loaded is read from memory (no
    copy decoding its file again): the same reduced pixels as the same file not yet loaded,
    read through a copy, and as the pixels written to it, linearised."""
    import bpy

    from makeup_skin_addon import image_texels

    rng = np.random.default_rng(11)
    codes = rng.integers(0, 256, (24, 40, 4))
    source = bpy.data.images.new("Codes", 40, 24, alpha=True)
    source.pixels.foreach_set((codes / 255).astype(np.float32).ravel())
    path = str(tmp_path / "codes.png")
    source.filepath_raw = path
    source.file_format = "PNG"
    source.save()
    read = {}
    for loaded in (False, True):
        image = bpy.data.images.load(path, check_existing=False)
        image.colorspace_settings.name = "sRGB"
        if loaded:
            assert image.size[0] == 40  # loads it
        assert image.has_data == loaded
        read[loaded] = image_texels.reduced_image(image).pixels
    assert np.array_equal(read[True], read[False])
    np.testing.assert_allclose(read[True], linear(codes[..., :3] / 255), rtol=1e-6, atol=1e-9)


def _tile_files(tmp_path, colours: dict) -> str:
    """8-bit PNG tiles ``skin.<number>.png`` of one colour each (bytes): the first's path."""
    import bpy

    for number, colour in colours.items():
        image = bpy.data.images.new(f"tile {number}", 8, 8)
        pixels = np.ones((8, 8, 4), np.float32)
        pixels[..., :3] = np.asarray(colour) / 255.0
        image.pixels.foreach_set(pixels.ravel())
        image.filepath_raw = str(tmp_path / f"skin.{number}.png")
        image.file_format = "PNG"
        image.save()
        bpy.data.images.remove(image)
    return str(tmp_path / f"skin.{min(colours)}.png")


def test_a_tiled_image_is_read_tile_by_tile(two_faces, tmp_path):
    """A UDIM image whose tiles are files: each UV is read in the tile it falls in (the
    standing face's in 1001, the lying face's moved to 1002: the mean is the faces' by area,
    1:3), by the artist's shader's points and by Skin Color's mean alike; UVs outside every
    tile are taken as 0.5 and said so."""
    import bpy

    from makeup_skin_addon import image_texels, skin_sampling

    obj, skin, texture = two_faces
    first = _tile_files(tmp_path, {1001: LEFT_BYTES, 1002: RIGHT_BYTES})
    image = bpy.data.images.load(first)
    image.source = "TILED"  # Blender finds 1002 beside it
    texture.image = image
    assert sorted(image_texels.tile_files(image)) == [1001, 1002]
    layer = obj.data.uv_layers[0]
    uv = np.array([d.uv[:] for d in layer.data])
    uv[4:8] = uv[0:4] + (1.0, 0.0)  # the lying face's corners into tile 1002
    layer.data.foreach_set("uv", uv.ravel())

    def mean():
        samples = skin_sampling.surface_samples(skin)
        values = samples.image(image, samples.uv(""), "REPEAT")[:, :3]
        return np.average(values, axis=0, weights=samples.weights), samples.notes

    rgb, notes = mean()
    np.testing.assert_allclose(rgb, exact_two_faces(1.0, 3.0), atol=2e-5)
    assert notes == []
    skin_colour = skin_sampling.surface_mean(image, skin)  # the skin preset's path, the same
    np.testing.assert_allclose(skin_colour.rgb, exact_two_faces(1.0, 3.0), atol=2e-5)
    uv[4:8] = uv[0:4] + (2.0, 0.0)  # tile 1003: none
    layer.data.foreach_set("uv", uv.ravel())
    rgb, notes = mean()
    np.testing.assert_allclose(rgb, (linear(np.asarray(LEFT_BYTES) / 255) + 3 * 0.5) / 4,
                               atol=2e-5)
    assert any(note.endswith(f"fall outside the tiles of image {image.name!r}: taken as 0.5")
               for note in notes), notes


def test_the_files_of_uv_tiles(addon):
    from types import SimpleNamespace

    from makeup_skin_addon import image_texels

    image = SimpleNamespace(source="TILED", packed_files=[], library=None,
                            filepath="/textures/skin.<UVTILE>.exr",
                            tiles=[SimpleNamespace(number=n) for n in (1001, 1012)])
    assert image_texels.tile_files(image) == {1001: "/textures/skin.u1_v1.exr",
                                              1012: "/textures/skin.u2_v2.exr"}
    image.packed_files = ["packed"]  # packed tiles are not files
    assert image_texels.tile_files(image) == {}
