"""Reduced images kept on disk between sessions (makeup_skin_addon.image_store): a file image
read once is not decoded again in a later session (its reduced pixels equal, to the bit: a
float32 array written and read back), until its file, colour space or size changes; nothing
else is kept; the store stays bounded, skips what it cannot read, and keeps nothing without a
folder."""

import os

import numpy as np
import pytest
from support.two_faces import linear


@pytest.fixture
def store(addon, tmp_path):
    from makeup_skin_addon import image_store, image_texels

    image_texels.clear_cache()
    image_store.set_directory(tmp_path / "store")
    yield tmp_path / "store"
    image_store.set_directory(None)
    image_texels.clear_cache()


def _png(bpy, path, codes):
    """An image file of byte ``codes`` ((h, w, 4), rows bottom-up), loaded as sRGB."""
    height, width = codes.shape[:2]
    source = bpy.data.images.new("Source", width, height, alpha=True)
    source.pixels.foreach_set((codes / 255).astype(np.float32).ravel())
    source.filepath_raw = str(path)
    source.file_format = "PNG"
    source.save()
    bpy.data.images.remove(source)
    image = bpy.data.images.load(str(path), check_existing=False)
    image.colorspace_settings.name = "sRGB"
    return image


def _codes(seed, height=12, width=20):
    codes = np.random.default_rng(seed).integers(0, 256, (height, width, 4))
    codes[..., 3] = 255
    return codes


def _session_ends():
    """What a new session starts without: the reduced images in memory."""
    from makeup_skin_addon import image_texels

    image_texels.clear_cache()


def test_a_file_image_is_not_decoded_again_in_a_later_session(store, tmp_path, monkeypatch):
    import bpy

    from makeup_skin_addon import image_texels

    codes = _codes(1)
    image = _png(bpy, tmp_path / "skin.png", codes)
    first = image_texels.reduced_image(image).pixels
    np.testing.assert_allclose(first, linear(codes[..., :3] / 255), rtol=1e-6, atol=1e-9)
    assert len(list(store.glob("*.npz"))) == 1
    _session_ends()
    read = image_texels._read
    monkeypatch.setattr(image_texels, "_read", lambda *args: pytest.fail("decoded again"))
    np.testing.assert_array_equal(image_texels.reduced_image(image).pixels, first)
    # The file written anew (another date): read again, and kept beside the old entry.
    monkeypatch.setattr(image_texels, "_read", read)
    new = _codes(2)
    _png(bpy, tmp_path / "skin.png", new)
    os.utime(tmp_path / "skin.png", ns=(10**9, 10**9))
    image.reload()
    _session_ends()
    np.testing.assert_allclose(image_texels.reduced_image(image).pixels,
                               linear(new[..., :3] / 255), rtol=1e-6, atol=1e-9)
    assert len(list(store.glob("*.npz"))) == 2


def test_the_key_follows_what_the_pixels_depend_on(store, tmp_path):
    """Another colour space, reduction size or file gives another key, a packed image its
    bytes' (the same bytes packed twice, one key); an image that is not a file image
    (generated, painted and not saved) has none."""
    import bpy

    from makeup_skin_addon import image_store

    image = _png(bpy, tmp_path / "skin.png", _codes(1))
    key = image_store.key(image, 512)
    assert key is not None and image_store.key(image, 512) == key
    assert image_store.key(image, 256) != key
    other = _png(bpy, tmp_path / "other.png", _codes(1))
    assert image_store.key(other, 512) != key
    image.colorspace_settings.name = "Non-Color"
    assert image_store.key(image, 512) != key
    assert image_store.key(bpy.data.images.new("Generated", 4, 4), 512) is None
    other.pack()
    packed = image_store.key(other, 512)
    assert packed is not None and packed != key
    again = _png(bpy, tmp_path / "again.png", _codes(1))  # the same bytes, elsewhere
    again.pack()
    assert image_store.key(again, 512) == packed
    third = _png(bpy, tmp_path / "third.png", _codes(4))  # other bytes
    third.pack()
    assert image_store.key(third, 512) not in (None, packed)
    image.pixels[0] = 0.5
    assert image.is_dirty and image_store.key(image, 512) is None


def test_a_packed_image_is_not_decoded_again_in_a_later_session(store, tmp_path,
                                                                monkeypatch):
    import bpy

    from makeup_skin_addon import image_texels

    image = _png(bpy, tmp_path / "skin.png", _codes(5))
    image.pack()
    os.remove(tmp_path / "skin.png")  # only the packed bytes are left
    first = image_texels.reduced_image(image).pixels
    assert first is not None
    _session_ends()
    monkeypatch.setattr(image_texels, "_read", lambda *args: pytest.fail("decoded again"))
    np.testing.assert_array_equal(image_texels.reduced_image(image).pixels, first)


def test_the_store_is_bounded_and_skips_what_it_cannot_read(store, tmp_path, monkeypatch):
    from makeup_skin_addon import image_store

    monkeypatch.setattr(image_store, "MAX_ENTRIES", 2)
    pixels = np.zeros((2, 2, 3), np.float32)
    for step, name in enumerate(("a", "b", "c")):
        image_store.save(name, pixels + step, "")
        os.utime(store / f"{name}.npz", ns=(step * 10**9, step * 10**9))
    image_store.save("c", pixels + 2, "")  # pruned after each write: the oldest goes
    assert sorted(path.stem for path in store.glob("*.npz")) == ["b", "c"]
    assert image_store.load("a") is None
    loaded, note = image_store.load("b")
    np.testing.assert_array_equal(loaded, pixels + 1)
    whole = (store / "c.npz").read_bytes()
    (store / "c.npz").write_bytes(whole[: len(whole) // 2])  # cut short
    assert image_store.load("c") is None
    (store / "b.npz").write_bytes(b"not an entry")
    assert image_store.load("b") is None
    assert not list(store.glob("*.partial"))


def test_without_a_folder_nothing_is_kept(store, tmp_path):
    import bpy

    from makeup_skin_addon import image_store, image_texels

    image_store.set_directory(None)
    image = _png(bpy, tmp_path / "skin.png", _codes(3))
    assert image_texels.reduced_image(image).pixels is not None
    assert image_store.load(image_store.key(image, 512)) is None
    assert not store.exists()
