"""Where a slow step's progress goes (makeup_skin_addon.progress): a cold read of the mesh and
the image reports, a warm one does not; a window manager's counter begins on the first report
and ends after."""


def test_progress_is_reported_only_when_something_is_read(two_faces, tmp_path):
    """A cold call reports progress (the image, then the faces), a warm one nothing; a window
    manager's progress is begun on the first report and ended after."""
    from makeup_skin_addon import progress, skin_sampling

    obj, skin, texture = two_faces
    texture.image.filepath_raw = str(tmp_path / "bands.png")
    texture.image.file_format = "PNG"
    texture.image.save()  # a file image, not dirty: cached once read
    reports = []
    with progress.reporting(lambda fraction, message="": reports.append(fraction)):
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
    with progress.progress_bar(manager):
        skin_sampling.surface_mean(texture.image, skin)
    assert manager.calls == []
    skin_sampling.clear_cache()
    with progress.progress_bar(manager):
        skin_sampling.surface_mean(texture.image, skin)
    assert manager.calls == [("begin", 0, 100), ("update", 0), ("update", 60), ("update", 100),
                             ("end",)]
