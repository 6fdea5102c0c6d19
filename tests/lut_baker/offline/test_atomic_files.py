"""Files written whole or not at all (lut_baker.offline.atomic_files): the new content
replaces the old at once; an error or an interrupt while writing leaves the earlier file and
no temporary; a writer that goes by the suffix (matplotlib) still sees it."""

import os

import pytest

from lut_baker.offline import atomic_files


def test_write_text_replaces_the_file_and_leaves_no_temporary(tmp_path):
    path = tmp_path / "fit.toml"
    path.write_text("old\n")
    assert atomic_files.write_text(path, "new, é\n") == path
    assert path.read_text(encoding="utf-8") == "new, é\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fit.toml"]


@pytest.mark.parametrize("stop", [KeyboardInterrupt, OSError])
@pytest.mark.parametrize("earlier", [True, False])
def test_a_write_stopped_midway_leaves_the_earlier_file(tmp_path, stop, earlier):
    path = tmp_path / "presets.json"
    if earlier:
        path.write_text("earlier\n")
    with pytest.raises(stop):
        with atomic_files.replacing(path) as temporary:
            temporary.write_text("half of the")
            raise stop()
    assert sorted(p.name for p in tmp_path.iterdir()) == (["presets.json"] if earlier else [])
    if earlier:
        assert path.read_text() == "earlier\n"


def test_a_failed_flush_leaves_the_earlier_file(tmp_path, monkeypatch):
    path = tmp_path / "truth.toml"
    path.write_text("earlier\n")

    def full_disk(descriptor):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(atomic_files.os, "fsync", full_disk)
    with pytest.raises(OSError):
        atomic_files.write_text(path, "new\n")
    assert os.listdir(tmp_path) == ["truth.toml"] and path.read_text() == "earlier\n"


def test_the_temporary_keeps_the_suffix_and_is_hidden_beside_the_file(tmp_path):
    with atomic_files.replacing(tmp_path / "fig05.png") as temporary:
        assert temporary.parent == tmp_path and temporary.suffix == ".png"
        assert temporary.name.startswith(".fig05.")
        temporary.write_bytes(b"png")
    assert (tmp_path / "fig05.png").read_bytes() == b"png"
