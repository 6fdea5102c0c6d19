"""Tables on disk (lut_baker.offline.exr_files, with the atlas and hash of
lut_baker.tables.codec): float32 OpenEXR atlas + JSON sidecar."""

import errno
import json
import os

import numpy as np
import OpenImageIO as oiio
import pytest

from lut_baker import bake
from lut_baker.model import presets
from lut_baker.offline import exr_files
from lut_baker.tables import codec
from lut_baker.tables.table_set import ANGULAR, CONSTANT, DIRECTIONAL


@pytest.fixture(scope="module")
def baked():
    skin = presets.made_up_skin("medium_beige", "jensen_skin1", coverage=0.7)
    return bake.bake(skin, "preview", inter_reflection=True)


@pytest.fixture
def saved(baked, tmp_path):
    return exr_files.save_tables(baked, tmp_path / "skin.exr")


def test_round_trip_is_float32_exact(baked, saved):
    loaded = exr_files.load_tables(saved)
    for name, value in baked.arrays.items():
        stored = np.asarray(getattr(loaded, name))
        if name in ("theta_deg", "phi_deg", "radius_mm"):
            np.testing.assert_array_equal(stored, value)  # grids: exact float64 in the sidecar
        else:
            np.testing.assert_array_equal(stored, np.asarray(value, np.float32), err_msg=name)
    assert loaded.parameters == baked.parameters
    assert loaded.spacings == baked.spacings
    assert codec.content_hash(loaded) == codec.content_hash(baked)
    # float32 storage moves values by at most half an ulp: ~6e-8 relative
    relative = (np.abs(loaded.path3_gloss - baked.path3_gloss)
                / np.maximum(baked.path3_gloss, 1e-30))
    assert relative.max() < 6e-8


def test_sidecar_describes_the_file(baked, saved):
    meta = json.loads(saved.with_suffix(".json").read_text())
    assert meta["format_version"] == 2 and meta["image"] == "skin.exr"
    assert meta["K"] == pytest.approx(presets.paper().K)
    assert meta["parameters"]["coverage"] == 0.7
    assert meta["grids"]["phi_spacing"] == "half_vector"
    assert {"theta_deg", "radius_mm", "profile"} <= set(meta["units"]) | set(meta["layout"])
    assert meta["sha256"] == codec.content_hash(baked)


def test_atlas_layout_as_documented(baked, saved):
    """Pixel (j n_phi + k, row + i) of an angular block is table[i, j, k]; rows count from the
    bottom, so Blender's row r is the EXR's scanline height - 1 - r."""
    meta = json.loads(saved.with_suffix(".json").read_text())
    image = oiio.ImageInput.open(str(saved))
    pixels = image.read_image(oiio.FLOAT)
    image.close()
    height, n_phi = meta["height"], baked.phi_deg.size
    i, j, k = 5, 7, 11
    for name in ANGULAR + ("inter_reflection",):
        row = meta["layout"][name]["row"] + i
        np.testing.assert_array_equal(pixels[height - 1 - row, j * n_phi + k],
                                      np.asarray(getattr(baked, name), np.float32)[i, j, k])
    for name in DIRECTIONAL:
        row = meta["layout"][name]["row"]
        np.testing.assert_array_equal(pixels[height - 1 - row, 3],
                                      np.asarray(getattr(baked, name), np.float32)[3])
    row = meta["layout"]["constants"]["row"]
    assert meta["layout"]["constants"]["order"] == list(CONSTANT)
    np.testing.assert_array_equal(pixels[height - 1 - row, 1],
                                  np.asarray(baked.skin_diffuse, np.float32))
    assert pixels.shape == (height, meta["width"], 3)


def _flip_byte(path, offset):
    data = bytearray(path.read_bytes())
    data[offset] ^= 0xFF
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("where", [0.05, 0.5, 0.95])
def test_corrupt_byte_is_reported(saved, where):
    _flip_byte(saved, int(where * saved.stat().st_size))
    with pytest.raises(codec.TableFileError, match="skin.exr"):
        exr_files.load_tables(saved)


@pytest.mark.parametrize("keep", [0.0, 0.5, 0.99])
def test_truncated_file_is_reported(saved, keep):
    data = saved.read_bytes()
    saved.write_bytes(data[:int(keep * len(data))])
    with pytest.raises(codec.TableFileError, match="skin.exr"):
        exr_files.load_tables(saved)


def test_wrong_version_is_reported(saved):
    side = saved.with_suffix(".json")
    meta = json.loads(side.read_text())
    meta["format_version"] = 99
    side.write_text(json.dumps(meta))
    with pytest.raises(codec.TableFileError, match="version 99"):
        exr_files.load_tables(saved)


def test_missing_sidecar_is_reported(saved):
    saved.with_suffix(".json").unlink()
    with pytest.raises(codec.TableFileError, match="sidecar.*missing"):
        exr_files.load_tables(saved)


def test_missing_image_is_reported(tmp_path):
    with pytest.raises(codec.TableFileError, match="does not exist"):
        exr_files.load_tables(tmp_path / "none.exr")


def test_image_and_sidecar_of_different_bakes_are_reported(baked, saved, tmp_path):
    other = exr_files.save_tables(bake.bake(presets.paper(), "preview", inter_reflection=True),
                                  tmp_path / "other.exr")
    saved.with_suffix(".json").write_text(other.with_suffix(".json").read_text())
    with pytest.raises(codec.TableFileError):
        exr_files.load_tables(saved)


def test_edited_sidecar_values_are_reported(saved):
    side = saved.with_suffix(".json")
    meta = json.loads(side.read_text())
    meta["grids"]["theta_deg"] = meta["grids"]["theta_deg"][:-1]
    side.write_text(json.dumps(meta))
    with pytest.raises(codec.TableFileError, match="layout|grid"):
        exr_files.load_tables(saved)
    side.write_text("{ not json")
    with pytest.raises(codec.TableFileError, match="not a readable sidecar"):
        exr_files.load_tables(saved)


def test_a_crash_mid_write_leaves_the_old_files_intact(baked, saved, monkeypatch):
    before = {p.name: p.read_bytes() for p in saved.parent.iterdir()}
    real_replace = os.replace
    calls = []

    def crash_on_second(src, dst):  # the image is in place, the sidecar not yet
        calls.append(dst)
        if len(calls) == 1:
            raise OSError("simulated crash")
        real_replace(src, dst)

    monkeypatch.setattr(exr_files.os, "replace", crash_on_second)
    with pytest.raises(OSError, match="simulated"):
        exr_files.save_tables(bake.bake(presets.paper(), "preview"), saved)
    after = {p.name: p.read_bytes() for p in saved.parent.iterdir()}
    assert after == before  # no temporary left, nothing half-written under the final names
    assert codec.content_hash(exr_files.load_tables(saved)) == codec.content_hash(baked)


def _fail_sidecar_rename(monkeypatch, error):
    """Make the rename of the sidecar (the second one) raise ``error``."""
    real_replace = os.replace

    def replace(src, dst):
        if str(dst).endswith(".json"):
            raise error
        real_replace(src, dst)

    monkeypatch.setattr(exr_files.os, "replace", replace)


@pytest.mark.parametrize("error", [OSError(errno.EIO, "Input/output error"), KeyboardInterrupt()])
def test_a_failure_between_the_renames_puts_the_old_image_back(baked, saved, monkeypatch, error):
    """Image replaced, sidecar not: the old image comes back, so the old pair still loads."""
    before = {p.name: p.read_bytes() for p in saved.parent.iterdir()}
    _fail_sidecar_rename(monkeypatch, error)
    with pytest.raises(type(error)):
        exr_files.save_tables(bake.bake(presets.paper(), "preview"), saved)
    assert {p.name: p.read_bytes() for p in saved.parent.iterdir()} == before
    assert codec.content_hash(exr_files.load_tables(saved)) == codec.content_hash(baked)


def test_a_failure_between_the_renames_of_a_new_pair_leaves_nothing(baked, tmp_path,
                                                                    monkeypatch):
    _fail_sidecar_rename(monkeypatch, OSError(errno.EIO, "Input/output error"))
    with pytest.raises(codec.TableWriteError, match="skin.exr.*Input/output error"):
        exr_files.save_tables(baked, tmp_path / "skin.exr")
    assert list(tmp_path.iterdir()) == []


def test_a_pair_torn_by_a_crash_is_detected(baked, saved, tmp_path):
    """A crash between the renames (nothing runs to put the old image back): the pair no
    longer matches and loading says so."""
    other = exr_files.save_tables(bake.bake(presets.paper(), "preview", inter_reflection=True),
                                  tmp_path / "other" / "skin.exr")
    os.replace(other, saved)
    with pytest.raises(codec.TableFileError, match="different bakes"):
        exr_files.load_tables(saved)


@pytest.mark.parametrize("error", [OSError(errno.ENOSPC, "No space left on device"),
                                   KeyboardInterrupt()])
def test_a_failed_or_interrupted_write_leaves_no_temporary(baked, saved, monkeypatch, error):
    """The failure comes while the temporaries are flushed (both are written by then)."""
    before = {p.name: p.read_bytes() for p in saved.parent.iterdir()}
    seen = []

    def fail(fd):
        seen.extend(sorted(p.name for p in saved.parent.iterdir()))
        raise error

    monkeypatch.setattr(exr_files.os, "fsync", fail)
    with pytest.raises(type(error)):
        exr_files.save_tables(bake.bake(presets.paper(), "preview"), saved)
    assert len(seen) == 4  # the old pair and two temporaries
    assert {p.name: p.read_bytes() for p in saved.parent.iterdir()} == before


@pytest.mark.parametrize("error, words", [
    (OSError(errno.ENOSPC, "No space left on device"), "no space left on the disk"),
    (OSError(errno.EDQUOT, "Disk quota exceeded"), "disk quota"),
    (PermissionError(errno.EACCES, "Permission denied"), "no permission to write in"),
    (OSError(errno.EROFS, "Read-only file system"), "read-only file system"),
    (OSError(errno.EIO, "Input/output error"), "Input/output error"),
])
def test_write_errors_say_what_is_wrong_in_one_line(baked, tmp_path, monkeypatch, error, words):
    def fail(fd):
        raise error

    monkeypatch.setattr(exr_files.os, "fsync", fail)
    target = tmp_path / "new" / "skin.exr"
    with pytest.raises(codec.TableWriteError) as raised:
        exr_files.save_tables(baked, target)
    message = str(raised.value)
    assert isinstance(raised.value, OSError) and "\n" not in message
    assert message.startswith(f"cannot write '{target}': ") and words in message
    assert list(tmp_path.iterdir()) == []  # the folder it made is gone too


def test_target_problems_are_found_before_writing(tmp_path):
    (tmp_path / "afile").write_text("x")
    with pytest.raises(codec.TableWriteError, match="'.*afile' is a file, not a folder"):
        exr_files.check_target(tmp_path / "afile" / "deeper" / "skin.exr")
    (tmp_path / "skin.exr").mkdir()
    with pytest.raises(codec.TableWriteError, match="skin.exr' is a folder"):
        exr_files.check_target(tmp_path / "skin.exr")
    with pytest.raises(ValueError, match=".exr"):
        exr_files.check_target(tmp_path / "skin.png")
    assert exr_files.check_target(tmp_path / "new" / "skin.exr") == tmp_path / "new" / "skin.exr"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "skin.exr"]  # made nothing


def test_only_exr_paths_are_written(baked, tmp_path):
    with pytest.raises(ValueError, match=".exr"):
        exr_files.save_tables(baked, tmp_path / "skin.png")


def test_load_accepts_the_sidecar_path(baked, saved):
    loaded = exr_files.load_tables(saved.with_suffix(".json"))
    assert codec.content_hash(loaded) == codec.content_hash(baked)


def test_the_slab_round_trips_through_the_file(tmp_path):
    """Tables baked with the film at a thickness keep their slab on disk: the same made-up
    skin read back from the file (float32) at every thickness of the axis."""
    from lut_baker.model import film_slab
    from lut_baker.tables import slab_tables

    skin = presets.made_up_skin("paper_natural", "jensen_skin1", absorption=[0.1, 0.3, 0.5])
    tables = bake.bake(skin, "preview", film=film_slab.DEFAULT_THICKNESS_UM)
    loaded = exr_files.load_tables(exr_files.save_tables(tables, tmp_path / "slab.exr"))
    assert loaded.parameters["film_thickness_um"] == film_slab.DEFAULT_THICKNESS_UM
    for um in (1.0, film_slab.DEFAULT_THICKNESS_UM, 150.0, np.inf):
        np.testing.assert_allclose(slab_tables.slab_colour(loaded, um),
                                   slab_tables.slab_colour(tables, um), rtol=1e-6)
